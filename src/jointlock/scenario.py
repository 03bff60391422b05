"""Scenario files (TOML): one description of a locked-joint case and the jobs to run on it.

A scenario names the robot, its base, the failure (which joint, at what angle, at what time),
the state at failure, the limits, and which jobs to run with their settings and seed.  It is
validated here, in one place, before anything runs; every error is a
:class:`~jointlock.errors.ScenarioError` naming the file, the field, the value received and
what is allowed (with a did-you-mean for unknown keys).  The resolved scenario (defaults
filled in, file paths absolute) is plain data: :attr:`Scenario.data`.

Field names are those of the command-line options (``--q0-deg`` is ``q0_deg``, ``--T`` is
``T``); degrees only in fields ending in ``_deg`` (``_deg_s``, ``_deg_s2`` for rates).  The
format reference is ``docs/scenarios.md``::

    title = "000 §5: halt after joint 4 locks"
    robot = "halt7"            # built-in name, or a .toml / .urdf model file (relative to this file)
    base = "floating"          # fixed | floating
    seed = 0

    [failure]
    joint = 4                  # numbered from 1
    angle_deg = 0.0

    [state]                    # at failure: healthy joints (or the full arm)
    q0_deg = [-180, -180, -100, -10, 20, 20]

    [limits]
    vmax_deg = 40.0            # [deg/s]
    amax_deg = 20.0            # [deg/s^2]

    [halt_config]
    samples = 36000

    [halt]
    T = 10.0

Jobs run in the order of :data:`JOB_ORDER`: those whose table is present, or those listed in
``jobs = [...]``.
"""

from __future__ import annotations

import copy
import dataclasses
import difflib
import math
import tomllib
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from .errors import JointlockError, ScenarioError
from .robots import BUILTIN_ROBOTS

#: Jobs a scenario can run, in the order they run (a halt uses the halt configuration found
#: before it).
JOB_ORDER: tuple[str, ...] = (
    "halt_config",
    "halt",
    "jump",
    "tolerance_angle",
    "replan",
    "workspace",
    "singular",
)

#: Which seed paper each job implements (for reports).
JOB_PAPER: dict[str, str] = {
    "halt_config": "000 §3 (HCOM)",
    "halt": "000 §4 (HMOM)",
    "jump": "001 (NOTES-001)",
    "tolerance_angle": "002 (tolerance angle)",
    "replan": "002 (re-planning)",
    "workspace": "002 (workspace)",
    "singular": "004 (singularity)",
}

#: Largest |angle| accepted in an ``*_deg`` field [deg] (one turn either way).
MAX_ABS_DEG = 360.0

#: Fewest ``workspace.samples`` (:data:`jointlock.analysis.workspace.MIN_SAMPLES`).
WORKSPACE_MIN_SAMPLES = 1000


@dataclass(frozen=True)
class Field:
    """Schema of one scenario field.

    ``kind``: ``"int"``, ``"number"``, ``"bool"``, ``"str"``, ``"choice"``, ``"numbers"``
    (list of numbers), ``"strings"`` (list of choices).  ``lo``/``hi`` bound numbers
    (``lo_open``: strictly greater); ``choices`` lists allowed strings.
    """

    kind: str
    default: Any = None
    lo: float | None = None
    hi: float | None = None
    lo_open: bool = False
    choices: tuple[str, ...] = ()
    length: int | None = None
    unit: str = ""
    help: str = ""

    def allowed(self) -> str:
        """What the field accepts, in words."""
        unit = f" [{self.unit}]" if self.unit else ""
        if self.kind == "bool":
            return "true or false"
        if self.kind == "str":
            return "a string" + unit
        if self.kind in ("choice", "strings"):
            opts = ", ".join(repr(c) for c in self.choices)
            return ("one of " if self.kind == "choice" else "a list of ") + opts
        what = {"int": "an integer", "number": "a finite number", "numbers": "a list of finite numbers"}[
            self.kind
        ]
        if self.length is not None:
            what = f"a list of {self.length} finite numbers"
        rng = []
        if self.lo is not None:
            rng.append(f"{'>' if self.lo_open else '>='} {self.lo:g}")
        if self.hi is not None:
            rng.append(f"<= {self.hi:g}")
        each = " each" if self.kind == "numbers" else ""
        return what + (f"{each} " + " and ".join(rng) if rng else "") + unit


def _deg(help_: str, *, unit: str = "deg", lo: float = -MAX_ABS_DEG, hi: float = MAX_ABS_DEG) -> Field:
    return Field("numbers", lo=lo, hi=hi, unit=unit, help=help_)


def _pos(unit: str, help_: str, default: Any = None) -> Field:
    return Field("number", default, lo=0.0, lo_open=True, unit=unit, help=help_)


#: Top-level scalar fields.
TOP_FIELDS: dict[str, Field] = {
    "title": Field("str", "", help="a title for the report"),
    "description": Field("str", "", help="free text shown in the report"),
    "robot": Field("str", None, help="built-in name or model file (.toml DH table, .urdf)"),
    "base": Field("choice", "fixed", choices=("fixed", "floating"), help="spacecraft held or free-floating"),
    "seed": Field("int", 0, lo=0, help="seed of every stochastic job (Monte Carlo, GA)"),
    "out": Field("str", None, help="output folder (default: <scenario name>-results); --out overrides"),
    "jobs": Field("strings", None, choices=JOB_ORDER, help="jobs to run (default: every job table given)"),
}

#: Tables shared by the jobs.
SHARED_TABLES: dict[str, dict[str, Field]] = {
    "failure": {
        "joint": Field("int", None, lo=1, help="the joint that locks, numbered from 1"),
        "angle_deg": Field(
            "number", None, lo=-MAX_ABS_DEG, hi=MAX_ABS_DEG, unit="deg", help="angle it locks at"
        ),
        "time_s": Field("number", None, lo=0.0, unit="s", help="time it locks during a task (jump)"),
    },
    "state": {
        "q0_deg": _deg("angles at failure (healthy joints, or the full arm)"),
        "dq0_deg": _deg("rates at failure", unit="deg/s", lo=-1e4, hi=1e4),
        "ddq0_deg": _deg("accelerations at failure", unit="deg/s^2", lo=-1e5, hi=1e5),
    },
    "limits": {
        "vmax_deg": _pos("deg/s", "joint speed limit [deg/s] (halt, halt_config, jump)"),
        "amax_deg": _pos("deg/s^2", "joint acceleration limit [deg/s^2] (halt, halt_config, jump)"),
        "eps_m": _pos("m", "end-effector position-deviation threshold (jump)"),
    },
}

_BASE2 = ("fixed", "floating")

#: Job tables: field name (as the CLI option, dashes -> underscores) -> schema.
JOB_TABLES: dict[str, dict[str, Field]] = {
    "halt_config": {
        "samples": Field("int", 36000, lo=2, hi=5_000_000, help="Monte Carlo samples K (000: 36000)"),
        "jacobian": Field(
            "choice",
            "generalized",
            choices=("generalized", "fixed"),
            help="Jacobian of the indices: 000's generalized J_F (free-floating; differs from fixed "
            "only with base 'floating') or the fixed-base one",
        ),
        "assignment": Field(
            "choice",
            "equation",
            choices=("equation", "text"),
            help="which index gets AHP weight 1/2: the condition number (000 eq. 19) or the "
            "manipulability (000 §5.1 text)",
        ),
        "renormalize": Field(
            "bool", False, help="divide the combined weights by their sum (000 eq. 18 does not)"
        ),
        "length": _pos("m", "characteristic length dividing the linear rows"),
        "no_refine": Field("bool", False, help="plain Monte Carlo, as 000"),
        "reachable": Field(
            "bool",
            None,
            help="require the halt configuration to be reachable by the halt polynomial from [state] "
            "within halt.T (or halt_time) under the limits; default: yes when the state and a halt "
            "time are given",
        ),
        "halt_time": _pos("s", "halt time of the reachability bound (default: halt.T)"),
        "base": Field("choice", None, choices=_BASE2, help="base of this job (default: the top-level base)"),
    },
    "halt": {
        "T": _pos("s", "halt time (000: 10)"),
        "qf_deg": _deg("halt configuration (default: from halt_config, or a Monte Carlo search)"),
        "paper_qf": Field("bool", False, help="000's printed q_best (halt7 only)"),
        "solver": Field(
            "choice",
            "scan",
            choices=("scan", "ga", "vector"),
            help="scan: exact search of the shared k; ga: 000's adaptive GA; vector: one k per "
            "joint (extension)",
        ),
        "samples": Field("int", 36000, lo=2, hi=5_000_000, help="Monte Carlo samples when no halt_config"),
        "n_samples": Field("int", 501, lo=11, hi=200_001, help="time samples of the objective (odd)"),
        "generations": Field("int", 100, lo=1, hi=100_000, help="GA generations"),
        "population": Field("int", 50, lo=2, hi=100_000, help="GA population"),
        "base": Field(
            "choice",
            None,
            choices=_BASE2,
            help="base of the disturbance torque: 'fixed' = spacecraft held, as 000 (default: the "
            "top-level base)",
        ),
    },
    "jump": {
        "fail_at": Field("number", None, lo=0.0, unit="s", help="one failure time (default failure.time_s)"),
        "sweep": Field("int", None, lo=1, hi=10_000, help="sampled failure times (default 40)"),
        "kappa": Field("number", None, unit="rad^2/(s m^3)", help="constant kappa instead of the search"),
        "order": Field("int", 5, lo=1, hi=9, help="polynomial order of kappa(t)"),
        "fix": Field(
            "choice",
            "auto",
            choices=("auto", "clip", "ramp", "clip+ramp", "none"),
            help="fix of kappa(t) verified as well: clip to the feasible band, ramp (rate-limit "
            "kappa), both, none; auto = clip+ramp only when kappa(t) breaks a limit",
        ),
        "q0_deg": _deg("task start, every joint of the arm"),
        "dx_m": Field(
            "numbers", None, lo=-1e3, hi=1e3, length=3, unit="m", help="straight-line displacement"
        ),
        "duration_s": _pos("s", "task time"),
        "blend_s": _pos("s", "parabolic blend time"),
        "dt_s": _pos("s", "control step"),
        "vmax_deg_s": _pos("deg/s", "joint speed limit (default limits.vmax_deg, else 10)"),
        "amax_deg_s2": _pos("deg/s^2", "joint acceleration limit (default limits.amax_deg, else 5)"),
        "eps_m": _pos("m", "position-deviation threshold (default limits.eps_m, else 0.001)"),
        "kp": Field("number", None, lo=0.0, unit="1/s", help="feedback gain"),
        "rest_transitions": Field(
            "bool", None, help="also check the start from rest and the stop at the end (default false)"
        ),
        "feedforward": Field(
            "choice",
            None,
            choices=("step", "instant"),
            help="feed-forward over a control step: nominal displacement / dt (step, default) or "
            "the nominal velocity at the step's start (instant)",
        ),
        "base": Field("choice", None, choices=_BASE2, help="base of this job (default: the top-level base)"),
    },
    "tolerance_angle": {
        "q_target_deg": _deg("desired joints, every joint of the arm"),
        "gamma_limit_deg": Field(
            "number", 180.0, lo=0.0, lo_open=True, hi=180.0, unit="deg", help="sweep |gamma| <= this"
        ),
        "zoom_deg": Field(
            "number",
            2.0,
            lo=0.0,
            lo_open=True,
            hi=180.0,
            unit="deg",
            help="half-width of the second, narrow gamma range (002 Fig. 6: 2)",
        ),
        "step_deg": Field("number", 0.1, lo=0.0, lo_open=True, hi=180.0, unit="deg", help="gamma sweep step"),
    },
    "replan": {
        "from_deg": _deg("start joints, every joint of the arm"),
        "to_deg": _deg("goal joints, every joint of the arm"),
        "steps": Field("int", 40, lo=1, hi=100_000, help="interior points N of 002 eq. (19)"),
        "cycle": _pos("s", "time between points (002: 0.25)", 0.25),
        "tolerance_deg": Field("number", 0.0, lo=0.0, hi=180.0, unit="deg", help="largest |gamma|"),
    },
    "workspace": {
        "samples": Field(
            "int",
            200_000,
            lo=WORKSPACE_MIN_SAMPLES,
            hi=20_000_000,
            help="configurations per arm (fewer than 1000 say little about a volume)",
        ),
        "voxel": _pos("m", "voxel side (default automatic)"),
    },
    "singular": {
        "verify_conditions": Field("bool", False, help="check 004's Cond1-Cond5"),
        "search": Field("bool", False, help="search for singular configurations"),
        "base": Field(
            "choice",
            None,
            choices=("fixed", "floating", "virtual"),
            help="Jacobian: fixed, floating (generalized) or virtual (004's virtual manipulator); "
            "default: the top-level base if given (floating -> virtual with verify_conditions), "
            "else virtual with verify_conditions and fixed otherwise",
        ),
        "weighting": Field(
            "choice",
            "segment",
            choices=("segment", "vafa-dubowsky"),
            help="virtual link lengths: 004's formula (segment) or the exact Vafa-Dubowsky one",
        ),
        "q_deg": _deg("configuration analysed (default zeros)"),
        "tol": _pos("", "rank tolerance on singular values", 1e-8),
        "length": _pos("m", "characteristic length"),
        "samples": Field("int", None, lo=1, hi=1_000_000, help="samples per condition / search starts"),
    },
}

#: Jobs that need ``[failure] joint`` and ``angle_deg``.
NEEDS_LOCK = ("halt_config", "halt", "tolerance_angle", "replan")

ALL_TABLES: dict[str, dict[str, Field]] = {**SHARED_TABLES, **JOB_TABLES}


@dataclass(frozen=True)
class Scenario:
    """A validated scenario.

    Attributes
    ----------
    data
        The resolved scenario: every table with its defaults, file paths absolute; plain
        data (str, int, float, bool, lists, dicts) in file units (degrees).
    jobs
        Jobs to run, in :data:`JOB_ORDER`.
    source
        The file it came from (or a label such as ``"built-in demo scenario"``).
    overrides
        The command-line overrides applied to the file: ``{"table.field": {"file": value in
        the file or None, "value": value used}}`` (empty when none).
    """

    data: dict[str, Any]
    jobs: tuple[str, ...]
    source: str
    base_dir: Path = field(default_factory=Path.cwd)
    overrides: Mapping[str, Any] = field(default_factory=dict)

    def failure_overridden(self) -> bool:
        """Whether an override changed the file's failure (joint or angle)."""
        return any(
            key in ("failure.joint", "failure.angle_deg") and item["file"] != item["value"]
            for key, item in self.overrides.items()
        )

    def to_dict(self) -> dict[str, Any]:
        return copy.deepcopy(self.data) | {"jobs": list(self.jobs)}

    def table(self, name: str) -> dict[str, Any]:
        return dict(self.data.get(name, {}))

    @property
    def lock(self) -> tuple[int, float] | None:
        """(joint number, angle [deg]) of the failure, or None."""
        f = self.data.get("failure", {})
        if f.get("joint") is None or f.get("angle_deg") is None:
            return None
        return int(f["joint"]), float(f["angle_deg"])


# -- reading -----------------------------------------------------------------------------------


def load_scenario(path: str | Path, overrides: Mapping[str, Any] | None = None) -> Scenario:
    """Read and validate a scenario file.

    Parameters
    ----------
    path
        The ``.toml`` scenario file; relative model paths in it are resolved against its folder.
    overrides
        ``{"table.field" or "field": value}`` applied before validation (command-line options).

    Raises
    ------
    ScenarioError
        Missing file, invalid TOML, unknown key, wrong type, out-of-range value, missing or
        malformed model file -- the message names the file, the field and what is allowed.
    """
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise ScenarioError(f"scenario file {str(path)!r} does not exist") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise ScenarioError(f"cannot read scenario file {str(path)!r}: {exc}") from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ScenarioError(f"{path}: not valid TOML: {exc}") from None
    applied: dict[str, Any] = {}
    if overrides:
        for key, value in overrides.items():
            table, _, name = key.rpartition(".")
            holder = data.get(table, {}) if table else data
            old = holder.get(name) if isinstance(holder, dict) else None
            applied[key] = {"file": old, "value": value}
        data = apply_overrides(data, overrides, source=str(path))
    sc = scenario_from_dict(data, source=str(path), base_dir=path.resolve().parent)
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


def apply_overrides(data: Mapping[str, Any], overrides: Mapping[str, Any], *, source: str) -> dict[str, Any]:
    """Copy of ``data`` with ``{"table.field": value}`` set (validated later with the rest)."""
    out = copy.deepcopy(dict(data))
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
        table[parts[1]] = value
    return out


def _hint(key: str, allowed: Sequence[str]) -> str:
    close = difflib.get_close_matches(key, list(allowed), n=1, cutoff=0.6)
    if close:
        return f" (did you mean {close[0]!r}?)"
    owners = [t for t, fields in ALL_TABLES.items() if key in fields]
    if owners:
        return f" (it belongs in [{owners[0]}])"
    return ""


def _check(value: Any, spec: Field, where: str) -> Any:
    """Validate one value against its schema; returns it as plain data."""

    def bad(got: str = "") -> ScenarioError:
        shown = repr(value) if len(repr(value)) <= 80 else repr(value)[:77] + "..."
        return ScenarioError(f"{where} must be {spec.allowed()}; got {shown}{got}")

    def number(v: Any) -> float:
        if isinstance(v, bool) or not isinstance(v, (int, float)):
            raise bad(f" ({type(value).__name__})")
        x = float(v)
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
        number(value)
        return int(value)
    if kind == "number":
        return number(value)
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
    out: dict[str, Any] = {}
    for key, value in raw.items():
        if key not in fields:
            raise ScenarioError(
                f"{source}: [{name}] unknown field {key!r}{_hint(key, fields)}; allowed: {', '.join(fields)}"
            )
        out[key] = _check(value, fields[key], f"{source}: {name}.{key}")
    for key, spec in fields.items():
        out.setdefault(key, spec.default)
    return out


def scenario_from_dict(
    data: Mapping[str, Any], *, source: str = "scenario", base_dir: str | Path | None = None
) -> Scenario:
    """Validate a scenario given as a mapping (the parsed TOML); see :func:`load_scenario`."""
    if not isinstance(data, Mapping):
        raise ScenarioError(f"{source}: a scenario must be a TOML table; got {type(data).__name__}")
    base_dir = Path.cwd() if base_dir is None else Path(base_dir)
    allowed = list(TOP_FIELDS) + list(ALL_TABLES)
    out: dict[str, Any] = {}
    for key, value in data.items():
        if key in TOP_FIELDS:
            out[key] = _check(value, TOP_FIELDS[key], f"{source}: {key}")
        elif key in ALL_TABLES:
            out[key] = _table(value, key, ALL_TABLES[key], source)
        else:
            raise ScenarioError(
                f"{source}: unknown key {key!r}{_hint(key, allowed)}; allowed: {', '.join(allowed)}"
            )
    for key, spec in TOP_FIELDS.items():
        out.setdefault(key, spec.default)
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
    _check_semantics(out, jobs, source)
    return Scenario(data=out, jobs=jobs, source=source, base_dir=base_dir)


# -- cross-field checks ------------------------------------------------------------------------


def _inherit_singular_base(out: dict[str, Any], jobs: tuple[str, ...], *, given_base: bool) -> None:
    """``singular.base`` falls back to the top-level ``base`` when the file gives one, as every
    other job's base does (with ``verify_conditions``, a floating base is analysed on 004's
    virtual manipulator, the free-floating arm's equivalent).  Without either, the ``singular``
    command's own default holds (virtual with ``verify_conditions``, fixed otherwise)."""
    if "singular" not in jobs or not given_base:
        return
    s = out["singular"]
    if s["base"] is None:
        top = out["base"]
        s["base"] = "virtual" if top == "floating" and s["verify_conditions"] else top


def _resolve_robot(out: dict[str, Any], source: str, base_dir: Path) -> None:
    name = out["robot"]
    if name in BUILTIN_ROBOTS:
        return
    suffix = Path(name).suffix.lower()
    if suffix not in (".toml", ".urdf"):
        raise ScenarioError(
            f"{source}: robot must be a built-in name ({', '.join(BUILTIN_ROBOTS)}) or a .toml/.urdf "
            f"model file; got {name!r}{_hint(name, BUILTIN_ROBOTS)}"
        )
    path = Path(name)
    if not path.is_absolute():
        path = (base_dir / path).resolve()
    if not path.is_file():
        raise ScenarioError(f"{source}: robot: model file {name!r} not found (looked for {path})")
    out["robot"] = str(path)


def _load(out: dict[str, Any], base: str, source: str, cache: dict) -> Any:
    from .robots import load_robot

    key = (out["robot"], base)
    if key not in cache:
        try:
            cache[key] = load_robot(out["robot"], base=base)  # type: ignore[arg-type]
        except JointlockError as exc:
            field = "base" if base == "floating" and "base" in str(exc) else "robot"
            raise ScenarioError(
                f"{source}: {field}: cannot load {out['robot']!r} ({base} base): {exc}"
            ) from None
        except Exception as exc:  # a reader failing on a malformed file it did not anticipate
            raise ScenarioError(
                f"{source}: robot: malformed model file {out['robot']!r}: {type(exc).__name__}: {exc}"
            ) from None
    return cache[key]


def _check_semantics(out: dict[str, Any], jobs: tuple[str, ...], source: str) -> None:
    from .locking import lock

    cache: dict = {}
    model = _load(out, out["base"], source, cache)
    for job in jobs:
        b = out[job].get("base")
        if b in _BASE2:
            _load(out, b, source, cache)
    fail = out["failure"]
    n = model.dof
    if fail["joint"] is not None and not 1 <= fail["joint"] <= n:
        raise ScenarioError(
            f"{source}: failure.joint must be a joint number 1..{n} of {model.name}; got {fail['joint']}"
        )
    if fail["angle_deg"] is not None and fail["joint"] is None:
        raise ScenarioError(f"{source}: failure.angle_deg needs failure.joint (the joint that locks, 1..{n})")
    if fail["joint"] is not None and fail["angle_deg"] is None and set(jobs) - {"jump"}:
        raise ScenarioError(
            f"{source}: failure.joint needs failure.angle_deg (the locked angle [deg]); only [jump] "
            "works without it"
        )
    for job in jobs:
        if job in NEEDS_LOCK and fail["angle_deg"] is None:
            raise ScenarioError(
                f"{source}: job [{job}] needs the failure: set failure.joint (1..{n}) and failure.angle_deg"
            )
    locked = None
    if fail["joint"] is not None and fail["angle_deg"] is not None:
        locked = lock(model, fail["joint"], math.radians(fail["angle_deg"]))
    _defaults_000(out, jobs, model)

    def vector(
        where: str, values: list[float] | None, *, full_only: bool = False, rates: bool = False
    ) -> None:
        """Check a joint vector's length; with every joint given (and a lock), the locked
        joint's entry must equal its lock angle (angles) or be 0 (``rates``: rates and
        accelerations, as a locked joint does not move)."""
        if values is None:
            return
        sizes = {n} if full_only or locked is None else {locked.dof, n}
        if len(values) not in sizes:
            want = " or ".join(str(s) for s in sorted(sizes))
            what = (
                "every joint of the arm" if full_only or locked is None else "healthy joints, or every joint"
            )
            raise ScenarioError(
                f"{source}: {where} needs {want} values ({what} of {model.name}); got {len(values)}"
            )
        if locked is not None and not full_only and len(values) == n:
            j = fail["joint"] - 1
            if rates:
                if not math.isclose(values[j], 0.0, abs_tol=1e-9):
                    raise ScenarioError(
                        f"{source}: {where}: entry {j + 1} (the locked joint) must be 0, as a locked "
                        f"joint does not move; got {values[j]:g} (or give only the healthy joints)"
                    )
                return
            if not math.isclose(values[j], fail["angle_deg"], abs_tol=1e-9):
                raise ScenarioError(
                    f"{source}: {where}: entry {j + 1} (the locked joint) must equal failure.angle_deg = "
                    f"{fail['angle_deg']:g}; got {values[j]:g} (or give only the healthy joints)"
                )

    for key in ("q0_deg", "dq0_deg", "ddq0_deg"):
        vector(f"state.{key}", out["state"][key], rates=key != "q0_deg")
    if "halt" in jobs:
        h = out["halt"]
        vector("halt.qf_deg", h["qf_deg"])
        if h["paper_qf"] and h["qf_deg"] is not None:
            raise ScenarioError(f"{source}: halt.paper_qf and halt.qf_deg exclude each other; give one")
        if h["paper_qf"] and model.name != "halt7":
            raise ScenarioError(f"{source}: halt.paper_qf is 000's q_best for halt7 only; give halt.qf_deg")
        if h["n_samples"] % 2 == 0:
            raise ScenarioError(
                f"{source}: halt.n_samples must be odd (Simpson's rule); got {h['n_samples']}"
            )
        for key in ("q0_deg", "dq0_deg", "ddq0_deg"):
            if out["state"][key] is None:
                raise ScenarioError(f"{source}: job [halt] needs state.{key} (the state at failure)")
        if h["T"] is None:
            raise ScenarioError(f"{source}: job [halt] needs halt.T (halt time [s], 000: 10)")
    if "halt_config" in jobs and out["halt_config"]["reachable"] is None:
        hc = out["halt_config"]
        has_time = hc["halt_time"] is not None or out.get("halt", {}).get("T") is not None
        hc["reachable"] = out["state"]["q0_deg"] is not None and has_time
    if "halt_config" in jobs and out["halt_config"]["reachable"]:
        hc = out["halt_config"]
        if out["state"]["q0_deg"] is None:
            raise ScenarioError(f"{source}: halt_config.reachable needs state.q0_deg")
        if hc["halt_time"] is None and out.get("halt", {}).get("T") is None:
            raise ScenarioError(f"{source}: halt_config.reachable needs halt_config.halt_time or halt.T")
    if "jump" in jobs:
        _check_jump(out, source, model)
    if "tolerance_angle" in jobs:
        t = out["tolerance_angle"]
        if t["q_target_deg"] is None:
            raise ScenarioError(
                f"{source}: job [tolerance_angle] needs tolerance_angle.q_target_deg ({n} values)"
            )
        vector("tolerance_angle.q_target_deg", t["q_target_deg"], full_only=True)
    if "replan" in jobs:
        r = out["replan"]
        for key in ("from_deg", "to_deg"):
            if r[key] is None:
                raise ScenarioError(f"{source}: job [replan] needs replan.{key} ({n} values)")
            vector(f"replan.{key}", r[key], full_only=True)
    if "singular" in jobs:
        s = out["singular"]
        if s["verify_conditions"] and s["search"]:
            raise ScenarioError(
                f"{source}: singular.verify_conditions and singular.search exclude each other"
            )
        if s["verify_conditions"] and s["base"] == "floating":
            raise ScenarioError(
                f"{source}: singular.verify_conditions needs base 'virtual' or 'fixed'; got 'floating'"
            )
        if s["verify_conditions"] and locked is not None:
            raise ScenarioError(
                f"{source}: singular.verify_conditions analyses the whole 7-joint arm; remove [failure] "
                "or set verify_conditions = false"
            )
        if s["base"] in (None, "virtual") and (s["verify_conditions"] or s["base"] == "virtual"):
            _load(out, "floating", source, cache)
        vector("singular.q_deg", s["q_deg"])


def _defaults_000(out: dict[str, Any], jobs: tuple[str, ...], model: Any) -> None:
    """halt7 with joint 4 locked: 000 §5's state and limits where the file gives none."""
    fail = out["failure"]
    if model.name != "halt7" or fail["joint"] != 4 or not ({"halt", "halt_config"} & set(jobs)):
        return
    from .papers.p000 import SCENARIO as PAPER_SCENARIO

    for key in ("q0_deg", "dq0_deg", "ddq0_deg"):
        if out["state"][key] is None:
            out["state"][key] = list(PAPER_SCENARIO[key])
    for key in ("vmax_deg", "amax_deg"):
        if out["limits"][key] is None:
            out["limits"][key] = PAPER_SCENARIO[key]
    if "halt" in jobs and out["halt"]["T"] is None:
        out["halt"]["T"] = PAPER_SCENARIO["T"]


#: JumpScenario fields a [jump] table may set.
JUMP_SCENARIO_FIELDS = (
    "q0_deg",
    "dx_m",
    "duration_s",
    "blend_s",
    "dt_s",
    "vmax_deg_s",
    "amax_deg_s2",
    "eps_m",
    "kp",
    "rest_transitions",
    "feedforward",
)


def jump_fields(out: Mapping[str, Any]) -> dict[str, Any]:
    """The 001 task of a resolved scenario in :func:`jointlock.planning.jump.scenario_from_mapping`
    form (limits fall back to ``[limits]``, the locking joint to ``failure.joint``)."""
    j, lim = out["jump"], out["limits"]
    fields = {k: j[k] for k in JUMP_SCENARIO_FIELDS if j.get(k) is not None}
    for key, shared in (("vmax_deg_s", "vmax_deg"), ("amax_deg_s2", "amax_deg"), ("eps_m", "eps_m")):
        if key not in fields and lim.get(shared) is not None:
            fields[key] = lim[shared]
    if out["failure"]["joint"] is not None:
        fields["lock_joint"] = out["failure"]["joint"]
    fields["base"] = j["base"] or out["base"]
    return fields


def _check_jump(out: dict[str, Any], source: str, model: Any) -> None:
    from .planning.jump import scenario_from_mapping

    j = out["jump"]
    if j["fail_at"] is None and j["sweep"] is None and out["failure"]["time_s"] is not None:
        j["fail_at"] = out["failure"]["time_s"]
    if j["fail_at"] is not None and j["sweep"] is not None:
        raise ScenarioError(f"{source}: jump.fail_at (or failure.time_s) and jump.sweep exclude each other")
    if j["sweep"] is None and j["fail_at"] is None:
        j["sweep"] = 40
    try:
        sc = scenario_from_mapping(jump_fields(out), source=f"{source}: [jump]")
    except JointlockError as exc:
        if str(exc).startswith(source):
            raise

        raise ScenarioError(f"{source}: [jump]: {exc}") from None
    if len(sc.q0) != model.dof:
        raise ScenarioError(
            f"{source}: jump.q0_deg needs {model.dof} values (every joint of {model.name}); got {len(sc.q0)}"
        )
    if not 1 <= sc.lock_joint <= model.dof:
        raise ScenarioError(f"{source}: failure.joint must be 1..{model.dof}; got {sc.lock_joint}")
    if j["fail_at"] is not None and not j["fail_at"] < sc.duration:
        raise ScenarioError(
            f"{source}: jump.fail_at (failure.time_s) must lie in [0, {sc.duration:g}) s; got {j['fail_at']:g}"
        )
    for key, value in sc.to_fields().items():
        if key in JUMP_SCENARIO_FIELDS and j.get(key) is None:
            j[key] = value


def job_lock_args(scenario: Scenario) -> list[str]:
    """``["--lock", "J=DEG"]`` for the failure, or ``[]``."""
    lk = scenario.lock
    return [] if lk is None else ["--lock", f"{lk[0]}={lk[1]!r}"]
