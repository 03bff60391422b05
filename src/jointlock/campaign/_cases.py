"""The cases of a campaign: expansion of ``[grid]`` x ``[zip]`` x ``[sample]``, the
``[[exclude]]`` filters, and each case resolved into a validated scenario with its key and seed.

A case's **key** is a hash of its fully resolved inputs (:func:`case_key`): the resolved
scenario (every default filled in, a model file by its content rather than its path) and the
campaign seed.  Editing the campaign file changes only the keys of the cases it changes, so a
new run computes only those.  A case's **seed** (:func:`case_seed`) derives from the key: the
same case gets the same seed, hence the same result, whichever worker runs it and in whatever
order.
"""

from __future__ import annotations

import hashlib
import inspect
import itertools
import json
import math
import re
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import CampaignError, JointlockError
from ..scenario import JOB_ORDER, Scenario, apply_overrides, scenario_from_dict
from ._spec import CONFIRM_CASES, CampaignSpec, SampleSpec

#: Version of the key's recipe: bump it when the inputs hashed change meaning.
KEY_FORMAT = 1


@dataclass(frozen=True)
class Case:
    """One failure case of a campaign.

    Attributes
    ----------
    index
        Position in the campaign's expansion (0-based, after the filters).
    params
        The varied fields' values (``{"failure.joint": 3, ...}``), in file units.
    key
        Hash of the fully resolved inputs (24 hex digits).
    seed
        The case's seed (the scenario's ``seed`` when it runs), from the key.
    """

    index: int
    params: Mapping[str, Any]
    key: str
    seed: int


def expand(spec: CampaignSpec) -> list[dict[str, Any]]:
    """The varied values of every case (``[grid]`` x ``[zip]`` x ``[sample]``, the last
    section varying fastest), the ``[[exclude]]`` filters applied."""
    sections: list[list[dict[str, Any]]] = []
    if spec.grid:
        names = list(spec.grid)
        sections.append([dict(zip(names, combo)) for combo in itertools.product(*spec.grid.values())])
    if spec.zipped:
        sections.append([dict(zip(spec.zipped, row)) for row in zip(*spec.zipped.values())])
    if spec.sample:
        sections.append(draw_sample(spec.sample, spec.seed))
    cases = []
    for parts in itertools.product(*sections):
        params: dict[str, Any] = {}
        for part in parts:
            params.update(part)
        if not any(_matches(params, conditions) for conditions in spec.exclude):
            cases.append(params)
    return cases


def draw_sample(sample: SampleSpec, seed: int) -> list[dict[str, Any]]:
    """``sample.n`` points in ``sample.ranges`` (uniform for ``random``; scrambled Sobol' or
    Latin hypercube from ``scipy.stats.qmc``), seeded by ``seed``; integer fields take integers
    in ``[lo, hi]``, each equally likely."""
    from ..scenario import ALL_TABLES, TOP_FIELDS

    d = len(sample.ranges)
    rng = np.random.default_rng(seed)
    if sample.method == "random":
        u = rng.random((sample.n, d))
    else:
        from scipy.stats import qmc

        cls = qmc.Sobol if sample.method == "sobol" else qmc.LatinHypercube
        # scipy >= 1.15 names the generator `rng`, older releases `seed`
        kw = "rng" if "rng" in inspect.signature(cls).parameters else "seed"
        engine = cls(d, **{kw: rng})
        u = engine.random_base2(int(math.log2(sample.n))) if sample.method == "sobol" else engine.random(sample.n)
    points = []
    for row in u:
        point: dict[str, Any] = {}
        for x, (name, (lo, hi)) in zip(row, sample.ranges.items()):
            table, _, key = name.rpartition(".")
            kind = (ALL_TABLES[table] if table else TOP_FIELDS)[key].kind
            if kind == "int":
                point[name] = int(min(math.floor(lo + x * (hi - lo + 1)), hi))
            else:
                point[name] = float(lo + x * (hi - lo))
        points.append(point)
    return points


def _matches(params: Mapping[str, Any], conditions: Mapping[str, Mapping[str, Any]]) -> bool:
    """Whether ``params`` meets every condition of one ``[[exclude]]`` filter."""
    tests: dict[str, Callable[[Any, Any], bool]] = {
        "eq": lambda a, b: a == b,
        "ne": lambda a, b: a != b,
        "lt": lambda a, b: a < b,
        "le": lambda a, b: a <= b,
        "gt": lambda a, b: a > b,
        "ge": lambda a, b: a >= b,
        "in": lambda a, b: a in (b if isinstance(b, list) else [b]),
    }
    for name, ops in conditions.items():
        value = params[name]
        try:
            if not all(tests[op](value, arg) for op, arg in ops.items()):
                return False
        except TypeError:  # an order comparison between a list or string and a number
            return False
    return True


def case_overrides(spec: CampaignSpec, params: Mapping[str, Any]) -> dict[str, Any]:
    """The overrides of the base scenario that make one case: ``[set]`` then the case's
    varied values."""
    return {**spec.fixed, **params}


def resolve_case(spec: CampaignSpec, overrides: Mapping[str, Any]) -> Scenario:
    """The validated scenario of one case (``overrides`` on the base scenario)."""
    data = apply_overrides(spec.scenario, overrides, source=spec.scenario_source)
    return scenario_from_dict(data, source=spec.scenario_source, base_dir=spec.scenario_dir)


#: Fields added after :data:`KEY_FORMAT` was set (top level, or ``table.field``), left out of a key
#: while unset (None), so that the cases of earlier campaigns keep their keys and seeds (and resume).
UNKEYED_WHEN_UNSET = (
    "compiled",
    "srdf",
    "meshes",
    "jump.on_infeasible",
    "singular.skip_colliding",
    *(f"task.{name}" for name in ("dx_m", "q0_deg", "duration_s", "blend_s", "dt_s", "kp", "feedforward", "base")),
)


def case_key(scenario: Scenario, campaign_seed: int) -> str:
    """Hash (24 hex digits of SHA-256) of a case's fully resolved inputs: the resolved
    scenario without its title, description and output folder (nor the fields of
    :data:`UNKEYED_WHEN_UNSET` while unset), a model file and an SRDF by name and content, the
    campaign seed and :data:`KEY_FORMAT`."""
    # the resolved data as Scenario.to_dict gives it, without copying it: only serialised here
    data = {
        key: value
        for key, value in scenario.data.items()
        if key not in ("title", "description", "out") and not (key in UNKEYED_WHEN_UNSET and value is None)
    }
    for name in UNKEYED_WHEN_UNSET:
        table, _, field = name.partition(".")
        if field and isinstance(data.get(table), dict) and field in data[table] and data[table][field] is None:
            data[table] = {k: v for k, v in data[table].items() if k != field}
    data["jobs"] = list(scenario.jobs)
    robot = Path(str(data["robot"]))
    if robot.suffix.lower() == ".urdf" and data.get("meshes") is None and _has_collision_meshes(str(robot)):
        # unset meant "left out" before meshes were read (and "convex" since): the key says which
        data["meshes"] = "convex"
    if robot.suffix.lower() in (".toml", ".urdf"):
        data["robot"] = {"file": robot.name, "sha256": _file_digest(str(robot))}
    if data.get("srdf"):  # as the robot: by name and content, not where the folder lies
        data["srdf"] = {"file": Path(str(data["srdf"])).name, "sha256": _file_digest(str(data["srdf"]))}
    payload = json.dumps(
        {"format": KEY_FORMAT, "campaign_seed": campaign_seed, "scenario": data},
        sort_keys=True,
        separators=(",", ":"),
        allow_nan=False,
    )
    return hashlib.sha256(payload.encode()).hexdigest()[:24]


#: What a key needs of a file, read once per file version (path, mtime, size): its SHA-256, and
#: whether it has a ``<mesh>`` inside a ``<collision>`` (a URDF's).
_FILES: dict[tuple[str, int, int], tuple[str, bool]] = {}


def _file_facts(path: str) -> tuple[str, bool]:
    stat = Path(path).stat()
    stamp = (path, stat.st_mtime_ns, stat.st_size)
    if stamp not in _FILES:
        text = Path(path).read_bytes()
        meshes = re.search(rb"<collision\b(?:(?!</collision>).)*?<mesh\b", text, re.S) is not None
        _FILES[stamp] = (hashlib.sha256(text).hexdigest(), meshes)
    return _FILES[stamp]


def _file_digest(path: str) -> str:
    return _file_facts(path)[0]


def _has_collision_meshes(path: str) -> bool:
    return _file_facts(path)[1]


def case_seed(key: str) -> int:
    """The seed of the case with ``key`` (which already holds the campaign seed): 32 bits of
    SHA-256 over it, in ``[0, 2**32)``."""
    return int.from_bytes(hashlib.sha256(f"jointlock-case-seed/{key}".encode()).digest()[:4], "big")


@dataclass(frozen=True)
class CasePlan:
    """The cases of a campaign and how they were counted.

    Attributes
    ----------
    cases
        The distinct cases to run, in expansion order.
    described
        Cases the sweep describes before the filters.
    excluded
        Cases dropped by ``[[exclude]]``.
    duplicates
        Cases dropped because an earlier case resolves to the same inputs (e.g. an integer
        field drawn twice by ``[sample]``).
    jobs
        The jobs the cases run (all of them together), in :data:`~jointlock.scenario.JOB_ORDER`.
    """

    cases: tuple[Case, ...]
    described: int
    excluded: int
    duplicates: int
    jobs: tuple[str, ...] = ()

    def __len__(self) -> int:
        return len(self.cases)


def plan_cases(
    spec: CampaignSpec,
    *,
    max_cases: int | None = CONFIRM_CASES,
    progress: Callable[[int], None] | None = None,
) -> CasePlan:
    """Every case of ``spec``, each validated, with its key and seed.

    Parameters
    ----------
    max_cases
        Refuse more cases than this (None: no limit but :data:`~jointlock.campaign.MAX_CASES`);
        the CLI's ``--yes`` lifts it.
    progress
        Called with the number of cases resolved since the last call.

    Raises
    ------
    CampaignError
        Too many cases, or a case whose scenario is invalid (naming the case's values).
    """
    count = spec.count_before_filters()
    if max_cases is not None and count > max_cases:
        raise CampaignError(
            f"{spec.source}: the sweep describes {count:,} cases (more than {max_cases:,}); check the "
            "ranges, then confirm with --yes (Python: max_cases=None)"
        )
    params_list = expand(spec)
    if not params_list:
        raise CampaignError(f"{spec.source}: the [[exclude]] filters drop every case; nothing to run")
    cases: list[Case] = []
    seen: set[str] = set()
    jobs: set[str] = set()
    for position, params in enumerate(params_list):
        try:
            scenario = resolve_case(spec, case_overrides(spec, params))
        except JointlockError as exc:
            advice = (
                f"check the base scenario ({spec.scenario_source}) and [set], then the sweep"
                if position == 0
                else "fix the sweep or drop such cases with an [[exclude]] filter"
            )
            raise CampaignError(
                f"{spec.source}: case {position} ({params_text(params)}) is not a valid scenario: {exc} -- {advice}"
            ) from None
        key = case_key(scenario, spec.seed)
        jobs.update(scenario.jobs)
        if key not in seen:
            seen.add(key)
            cases.append(Case(len(cases), params, key, case_seed(key)))
        if progress is not None and (position + 1) % 100 == 0:
            progress(100)
    if progress is not None and len(params_list) % 100:
        progress(len(params_list) % 100)
    order = tuple(j for j in JOB_ORDER if j in jobs)
    return CasePlan(tuple(cases), count, count - len(params_list), len(params_list) - len(cases), order)


def params_text(params: Mapping[str, Any], *, limit: int = 160) -> str:
    """``"failure.joint=3, halt.T=10"`` (shortened to ``limit`` characters)."""
    text = ", ".join(f"{k}={_short(v)}" for k, v in params.items())
    return text if len(text) <= limit else text[: limit - 3] + "..."


def _short(value: Any) -> str:
    if isinstance(value, float):
        return f"{value:.6g}"
    if isinstance(value, list):
        return "[" + ", ".join(_short(v) for v in value) + "]"
    return repr(value) if isinstance(value, str) else str(value)
