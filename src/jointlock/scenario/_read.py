"""Reading a scenario: the TOML file, command-line overrides, each value against its field."""

from __future__ import annotations

import copy
import dataclasses
import math
import os
import tomllib
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from .._deprecate import warn_once
from ..bounds import shown
from ..errors import ScenarioError
from ..io.files import path_inside, read_toml_file
from ..robots import BUILTIN_ROBOTS
from ._checks import _check_semantics, _inherit_singular_base, _resolve_robot
from ._fields import (
    ALL_TABLES,
    DEPRECATED_FIELDS,
    JOB_ORDER,
    JOB_TABLES,
    RESOLVED_KEYS,
    SHARED_TABLES,
    TOP_FIELDS,
    Field,
    _hint,
    _spellings,
)
from ._keep_out import check_keep_out
from ._scenario import Scenario
from ._task import resolve_task_file


def load_scenario(path: str | Path, overrides: Mapping[str, Any] | None = None) -> Scenario:
    """Read and validate a scenario file.

    Parameters
    ----------
    path
        The ``.toml`` scenario file; relative paths in it (``robot``, ``out``) are resolved
        against its folder, and its ``out`` must lie inside that folder.
    overrides
        ``{"table.field" or "field": value}`` applied before validation (command-line options);
        an ``"out"`` override is any folder, relative to the working folder (``--out``).

    Raises
    ------
    ScenarioError
        Missing file, invalid TOML, unknown key, wrong type, out-of-range value, missing or
        malformed model file -- the message names the file, the field and what is allowed.
    """
    path = Path(path)
    data = read_toml_file(path, "scenario file", ScenarioError)
    applied: dict[str, Any] = {}
    overrides = dict(overrides or {})
    out_given = overrides.pop("out", None)  # the command line's: any folder, from the working one
    robot = overrides.get("robot")
    if isinstance(robot, str) and Path(robot).suffix.lower() in (".toml", ".urdf") and "\x00" not in robot:
        overrides["robot"] = os.path.abspath(robot)  # the command line's: from the working folder
    if overrides:
        for key, value in overrides.items():
            table, _, name = key.rpartition(".")
            holder = data.get(table, {}) if table else data
            old = None
            if isinstance(holder, dict):  # the file's value, under whichever name the file uses
                old = next((holder[k] for k in _spellings(table, name) if k in holder), None)
            if old is not None or value is not None:  # (None for None: nothing overridden)
                applied[key] = {"file": old, "value": value}
        data = apply_overrides(data, overrides, source=str(path))
    if out_given is not None:  # the file's out is not used: not checked either
        data = {k: v for k, v in data.items() if k != "out"}
    sc = scenario_from_dict(data, source=str(path), base_dir=path.resolve().parent)
    if sc.data.get("out"):  # the file's: relative to its folder, and inside it
        sc.data["out"] = path_inside(path.parent, sc.data["out"], f"{path}: out", ScenarioError)
    if out_given is not None:
        sc.data["out"] = check_value(out_given, TOP_FIELDS["out"], "--out")
        applied["out"] = {"file": data.get("out"), "value": out_given}
    return dataclasses.replace(sc, overrides=applied) if applied else sc


def parse_set(text: str) -> tuple[str, Any]:
    """``"halt.T=12"`` -> ("halt.T", 12): a ``--set`` option, the value read as TOML."""
    if "=" not in text:
        raise ScenarioError(f"--set must look like TABLE.FIELD=VALUE (e.g. halt.T=12); got {text!r}")
    key, raw = (s.strip() for s in text.split("=", 1))
    try:
        value = tomllib.loads(f"v = {raw}")["v"]
    except tomllib.TOMLDecodeError:
        value = raw  # a bare word: a string
    return key, value


def _plain_copy(value: Any) -> Any:
    """A deep copy of parsed TOML (tables, arrays, scalars), several times faster than
    :func:`copy.deepcopy` (a campaign resolves its base scenario once per case); anything
    else goes through :func:`copy.deepcopy`."""
    if isinstance(value, dict):
        return {k: _plain_copy(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_plain_copy(v) for v in value]
    if value is None or isinstance(value, (str, int, float, bool)):
        return value
    return copy.deepcopy(value)


def apply_overrides(data: Mapping[str, Any], overrides: Mapping[str, Any], *, source: str) -> dict[str, Any]:
    """Copy of ``data`` with ``{"table.field": value}`` set (validated later with the rest);
    a value of None removes the field (its default then holds).

    An override replaces the file's field whichever name either uses (a former name of
    :data:`DEPRECATED_FIELDS` or the current one); two overrides of one field under both names
    are an error.
    """
    out = _plain_copy(dict(data))
    seen: dict[tuple[str, str], str] = {}
    for key in overrides:
        table, _, name = key.rpartition(".")
        field = (table, _spellings(table, name)[0])
        if field in seen:
            raise ScenarioError(
                f"{source}: overrides {seen[field]!r} and {key!r} set the same field "
                f"({'.'.join(field)}); give one"
            )
        seen[field] = key
    for key, value in overrides.items():
        parts = key.split(".")
        if len(parts) > 2 or not all(parts):
            raise ScenarioError(f"{source}: override {key!r} must be FIELD or TABLE.FIELD")
        if len(parts) == 1:
            out[parts[0]] = value
            continue
        table = out.setdefault(parts[0], {})
        if not isinstance(table, dict):
            raise ScenarioError(f"{source}: override {key!r}: {parts[0]!r} is not a table")
        names = _spellings(parts[0], parts[1])
        if value is None:  # back to the default (e.g. no also_locked_deg when --lock overrides the failure)
            for n in names:
                table.pop(n, None)
            continue
        if any(n in table for n in names):  # in place, under the override's name: the file's order
            items = [(parts[1] if k in names else k, value if k in names else v) for k, v in table.items()]
            table.clear()
            table.update(items)
        else:
            table[parts[1]] = value
    return out


def check_value(value: Any, spec: Field, where: str) -> Any:
    """Validate one value against its schema field (``where`` names it in the error, e.g.
    ``"run.toml: halt.T"`` or ``"--T"``); returns it as plain data.

    Raises
    ------
    ScenarioError
        One line: ``where``, what the field allows (bounds and unit) and the value received
        (shortened to 80 characters; an integer too large for a float by its digit count).
    """

    def bad(got: str = "") -> ScenarioError:
        return ScenarioError(f"{where} must be {spec.allowed()}; got {shown(value)}{got}")

    def number(v: Any) -> float:
        if isinstance(v, bool) or not isinstance(v, (int, float)):
            raise bad(f" ({type(value).__name__})")
        try:
            x = float(v)
        except OverflowError:
            raise ScenarioError(
                f"{where} must be {spec.allowed()}; got an integer of {len(str(abs(v)))} digits"
            ) from None
        if not math.isfinite(x):
            raise bad()
        if spec.lo is not None and (x <= spec.lo if spec.lo_open else x < spec.lo):
            raise bad()
        if spec.hi is not None and x > spec.hi:
            raise bad()
        return x

    kind = spec.kind
    if kind == "bool":
        if not isinstance(value, bool):
            raise bad(f" ({type(value).__name__})")
        return value
    if kind == "str":
        if not isinstance(value, str):
            raise bad(f" ({type(value).__name__})")
        return value
    if kind == "choice":
        if not isinstance(value, str) or value not in spec.choices:
            raise bad(_hint(value, spec.choices) if isinstance(value, str) else "")
        return value
    if kind == "int":
        if isinstance(value, bool) or not isinstance(value, int):
            raise bad(f" ({type(value).__name__})")
        # compared as integers: a float rounds 2**63 - 1 up (and a 400-digit integer overflows)
        if (spec.lo is not None and (value <= spec.lo if spec.lo_open else value < spec.lo)) or (
            spec.hi is not None and value > spec.hi
        ):
            raise bad(f" ({len(str(abs(value)))} digits)" if abs(value) > 10**20 else "")
        return int(value)
    if kind == "number":
        return number(value)
    if kind == "locks":
        if not isinstance(value, dict) or not value:
            raise bad(f" ({type(value).__name__})" if not isinstance(value, dict) else " (empty)")
        locks = {}
        for key, angle in value.items():
            if not (isinstance(key, str) and key.isdigit() and len(key) <= 4 and key == str(int(key)) and int(key) >= 1):
                raise bad(f" (key {shown(key)} is no joint number >= 1)")
            locks[key] = check_value(angle, dataclasses.replace(spec, kind="number"), f"{where}.{key}")
        return locks
    if kind == "joint_values":
        if not isinstance(value, dict) or not value:
            raise bad(f" ({type(value).__name__})" if not isinstance(value, dict) else " (empty)")
        for key in value:
            if not isinstance(key, str) or not key.strip():
                raise bad(f" (key {shown(key)} is no joint name)")
        number_spec = dataclasses.replace(spec, kind="number")
        return {key: check_value(v, number_spec, f"{where}.{key}") for key, v in value.items()}
    if kind == "rows":
        if not isinstance(value, list) or len(value) < 2:
            raise bad(f" ({type(value).__name__})" if not isinstance(value, list) else f" ({len(value)} row)")
        row_spec = dataclasses.replace(spec, kind="numbers")
        rows = [check_value(row, row_spec, f"{where} row {k + 1}") for k, row in enumerate(value)]
        for k, row in enumerate(rows[1:], start=2):
            if len(row) != len(rows[0]):
                raise ScenarioError(f"{where} row {k} has {len(row)} values; row 1 has {len(rows[0])}")
        return rows
    if kind == "numbers":
        if not isinstance(value, list) or not value:
            raise bad(f" ({type(value).__name__})" if not isinstance(value, list) else " (empty)")
        if spec.length is not None and len(value) != spec.length:
            raise bad(f" ({len(value)} values)")
        return [number(v) for v in value]
    if kind == "strings":
        if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
            raise bad()
        for v in value:
            if v not in spec.choices:
                raise ScenarioError(
                    f"{where}: unknown job {v!r}{_hint(v, spec.choices)}; allowed: {', '.join(spec.choices)}"
                )
        if len(set(value)) != len(value):
            raise bad(" (repeated)")
        return list(value)
    raise AssertionError(kind)  # pragma: no cover - schema error


def _table(raw: Any, name: str, fields: dict[str, Field], source: str) -> dict[str, Any]:
    if not isinstance(raw, dict):
        raise ScenarioError(
            f"{source}: [{name}] must be a table of fields ({', '.join(fields)}); got {type(raw).__name__}"
        )
    former, stored = DEPRECATED_FIELDS.get(name, {}), RESOLVED_KEYS.get(name, {})
    out: dict[str, Any] = {}
    for key, value in raw.items():
        field = former.get(key, key)
        if field not in fields:
            raise ScenarioError(
                f"{source}: [{name}] unknown field {key!r}{_hint(key, fields)}; allowed: {', '.join(fields)}"
            )
        if field != key:
            if field in raw:
                raise ScenarioError(
                    f"{source}: [{name}] gives both {field!r} and {key!r} (its former name) for the "
                    f"same quantity; keep {field!r}"
                )
            _warn_former_name(name, key, field, fields[field], source)
        out[stored.get(field, field)] = check_value(value, fields[field], f"{source}: {name}.{key}")
    for key, spec in fields.items():
        out.setdefault(stored.get(key, key), spec.default)
    return out


def _warn_former_name(table: str, old: str, new: str, spec: Field, source: str) -> None:
    """A ``FutureWarning``, once per process and former name, naming the field's new name."""
    warn_once(
        f"field {table}.{old}",
        f"{source}: {table}.{old} is deprecated: write {table}.{new} instead (the same quantity, in "
        f"{spec.unit}); the old name still works for now",
    )


def scenario_from_dict(
    data: Mapping[str, Any], *, source: str = "scenario", base_dir: str | Path | None = None
) -> Scenario:
    """Validate a scenario given as a mapping (the parsed TOML); see :func:`load_scenario`."""
    if not isinstance(data, Mapping):
        raise ScenarioError(f"{source}: a scenario must be a TOML table; got {type(data).__name__}")
    base_dir = Path.cwd() if base_dir is None else Path(base_dir)
    allowed = list(TOP_FIELDS) + list(ALL_TABLES) + ["keep_out"]
    out: dict[str, Any] = {}
    for key, value in data.items():
        if key == "keep_out":  # [[keep_out]]: an array of tables, each a shape
            out[key] = check_keep_out(value, source)
        elif key in TOP_FIELDS:
            out[key] = check_value(value, TOP_FIELDS[key], f"{source}: {key}")
        elif key in ALL_TABLES:
            out[key] = _table(value, key, ALL_TABLES[key], source)
        else:
            raise ScenarioError(
                f"{source}: unknown key {key!r}{_hint(key, allowed)}; allowed: {', '.join(allowed)}"
            )
    for key, spec in TOP_FIELDS.items():
        out.setdefault(key, spec.default)
    out.setdefault("keep_out", [])
    for name, fields in SHARED_TABLES.items():
        out.setdefault(name, _table({}, name, fields, source))
    if out["robot"] is None:
        raise ScenarioError(
            f"{source}: robot is required: a built-in name ({', '.join(BUILTIN_ROBOTS)}) or a .toml/.urdf file"
        )
    listed = out.get("jobs")
    present = [j for j in JOB_ORDER if j in data]
    jobs = tuple(j for j in JOB_ORDER if j in listed) if listed is not None else tuple(present)
    if not jobs:
        raise ScenarioError(
            f"{source}: no job to run: add at least one job table ({', '.join(f'[{j}]' for j in JOB_ORDER)}) "
            "or a jobs = [...] list"
        )
    for job in jobs:
        out.setdefault(job, _table({}, job, JOB_TABLES[job], source))
    out.pop("jobs", None)
    _inherit_singular_base(out, jobs, given_base="base" in data)
    _resolve_robot(out, source, base_dir)
    resolve_task_file(out, source, base_dir)
    _check_semantics(out, jobs, source)
    return Scenario(data=out, jobs=jobs, source=source, base_dir=base_dir)
