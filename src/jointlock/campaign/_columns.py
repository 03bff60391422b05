"""The result figures a campaign records per case: columns ``"job.path|reducer"`` read from
each job's ``to_dict()`` (the JSON of ``jointlock COMMAND --json``).

``path`` walks dictionaries by key and lists by index (``"halt_config.best.cp"``,
``"halt.q_final_deg.0"``); ``reducer`` (optional) turns a list of numbers into one number
(``max``, ``min``, ``mean``, ``sum``, ``absmax``, ``len``, ``first``, ``last``); a number is
kept as it is, so ``"jump.jump_before|mean"`` is one number whether the job ran one failure
time or a sweep.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..errors import CampaignError
from ._cases import CasePlan
from ._spec import CampaignSpec

#: Headline figures of each job, recorded when a campaign names no ``columns``.
DEFAULT_COLUMNS: dict[str, tuple[str, ...]] = {
    "halt_config": (
        "halt_config.best.cp",
        "halt_config.refinement.gain",
        "halt_config.clearance.best.min_clearance_m",
    ),
    "halt": (
        "halt.feasible",
        "halt.T_s",
        "halt.minimum_T_s",
        "halt.minimum_T_clear_s",
        "halt.k",
        "halt.global_torque_k0_Nm",
        "halt.global_torque_Nm",
        "halt.reduction",
        "halt.violations|len",
        "halt.peak_velocity_deg_s|max",
        "halt.peak_acceleration_deg_s2|max",
        "halt.collision_free",
        "halt.clearance.motion_min_m",
        "halt.clearance.halt_configuration_m",
    ),
    "jump": (
        "jump.kappa|mean",
        "jump.jump_before|mean",
        "jump.jump_after|mean",
        "jump.mean_reduction",
        "jump.share_improved",
        "jump.limits_ok",
        "jump.clearance.compensated.min_clearance_m",
        "jump.clearance.compensated.collides",
    ),
    "tolerance_angle": ("tolerance_angle.roots|len", "tolerance_angle.chosen.gamma_deg"),
    "replan": (
        "replan.absorbed_waypoints",
        "replan.waypoints",
        "replan.max_tracking_position_error_m",
    ),
    "workspace": ("workspace.volume_full_m3", "workspace.volume_locked_m3", "workspace.share_kept"),
    "singular": ("singular.sigma_min", "singular.rank", "singular.singular"),
}

#: Which way is worse for the default columns (ranking the worst cases in the report).
WORSE: dict[str, str] = {
    "halt.feasible": "lower",
    "halt.minimum_T_s": "higher",
    "halt.minimum_T_clear_s": "higher",
    "halt.global_torque_Nm": "higher",
    "halt.global_torque_k0_Nm": "higher",
    "halt.reduction": "lower",
    "halt.violations|len": "higher",
    "halt.peak_velocity_deg_s|max": "higher",
    "halt.peak_acceleration_deg_s2|max": "higher",
    "halt_config.best.cp": "lower",
    "jump.jump_after|mean": "higher",
    "jump.jump_before|mean": "higher",
    "jump.mean_reduction": "lower",
    "jump.share_improved": "lower",
    "jump.limits_ok": "lower",
    "tolerance_angle.roots|len": "lower",
    "replan.max_tracking_position_error_m": "higher",
    "workspace.share_kept": "lower",
    "singular.sigma_min": "lower",
}


def default_columns(jobs: Sequence[str]) -> tuple[str, ...]:
    """The headline columns of ``jobs``."""
    return tuple(col for job in jobs for col in DEFAULT_COLUMNS.get(job, ()))


def column_value(results: Mapping[str, Any], column: str) -> Any:
    """The value of ``column`` in ``{job: to_dict()}`` (None when the job did not run or the
    path is absent in its result)."""
    path, _, reducer = column.partition("|")
    value: Any = results
    for part in path.split("."):
        if isinstance(value, Mapping) and part in value:
            value = value[part]
        elif isinstance(value, list) and part.lstrip("-").isdigit() and -len(value) <= int(part) < len(value):
            value = value[int(part)]
        else:
            return None
    return _reduce(value, reducer) if reducer else value


def _reduce(value: Any, reducer: str) -> Any:
    if isinstance(value, Mapping):  # a value per joint ({"4": 2220.5}): reduced over the joints
        value = list(value.values())
    if not isinstance(value, list):
        return value
    if reducer == "len":
        return len(value)
    numbers = [v for v in value if isinstance(v, (int, float)) and not isinstance(v, bool)]
    if not numbers:
        return None
    if reducer == "first":
        return numbers[0]
    if reducer == "last":
        return numbers[-1]
    arr = np.asarray(numbers, dtype=float)
    reducers: dict[str, Callable[[NDArray[np.float64]], Any]] = {
        "max": np.max,
        "min": np.min,
        "mean": np.mean,
        "sum": np.sum,
        "absmax": lambda a: np.max(np.abs(a)),
    }
    out = reducers[reducer](arr)
    return float(out)


def _paths(value: Any, prefix: str) -> list[str]:
    """Every path below ``value`` (dictionary keys; a list as one path)."""
    if isinstance(value, Mapping):
        out = []
        for key, sub in value.items():
            out += [f"{prefix}.{key}", *_paths(sub, f"{prefix}.{key}")]
        return out
    return []


def missing_columns(results: Mapping[str, Any], columns: Sequence[str]) -> list[str]:
    """The columns whose path is absent from the result of a job that ran (a misspelt key), each
    as ``"'halt.feasable' is not in the halt job's result (did you mean 'halt.feasible'?)"``."""
    import difflib

    out = []
    for col in columns:
        path = col.partition("|")[0]
        job = path.split(".", 1)[0]
        if job not in results:
            continue
        value: Any = results
        for part in path.split("."):
            if value is None:  # a null on the way (e.g. no gamma chosen): this case cannot tell
                break
            if isinstance(value, Mapping) and part in value:
                value = value[part]
            elif isinstance(value, list) and part.lstrip("-").isdigit() and -len(value) <= int(part) < len(value):
                value = value[int(part)]
            elif isinstance(value, list) and part.lstrip("-").isdigit():  # a shorter list in this case
                break
            else:
                known = _paths(results[job], job)
                close = difflib.get_close_matches(path, known, n=1, cutoff=0.6)
                hint = f" (did you mean {close[0]!r}?)" if close else ""
                out.append(f"{col!r} is not in the {job} job's result{hint}")
                break
    return out


def record(results: Mapping[str, Any], columns: Sequence[str]) -> dict[str, Any]:
    """``{column: value}`` for one case."""
    return {col: column_value(results, col) for col in columns}


def is_numeric(values: Sequence[Any]) -> bool:
    """Whether a column holds numbers or booleans (and at least one value)."""
    present = [v for v in values if v is not None]
    return bool(present) and all(isinstance(v, (int, float, bool)) for v in present)


def check_columns(spec: CampaignSpec, plan: CasePlan) -> tuple[str, ...]:
    """The columns to record: the file's (each reading a job that some case runs), else the
    headline columns of the jobs the cases run."""
    if not spec.columns:
        return default_columns(plan.jobs)
    for col in spec.columns:
        job = col.split(".", 1)[0]
        if job not in plan.jobs:
            raise CampaignError(
                f"{spec.source}: columns: {col!r} reads the {job} job, which no case runs (jobs: "
                f"{', '.join(plan.jobs)})"
            )
    return tuple(spec.columns)


def audit_cell_safe(row: Mapping[str, Any] | None) -> bool:
    """A finished audit cell whose halt keeps the limits, the clearance and the wheels' capacity
    (a campaign table's row: ``status`` and the recorded columns)."""
    return (
        row is not None
        and row.get("status") == "ok"
        and row.get("halt.feasible") is True
        and row.get("halt.collision_free") is not False
        and row.get("halt.attitude_control.within") is not False
    )
