"""Auditing a planned motion (issue 28, item 5): every chosen joint locking at every chosen
instant of the scenario's ``[task]``, run as a campaign.

An audit is a campaign whose base scenario is the audited one and whose grid is
``failure.joint`` x ``failure.time_s``: each cell is exactly ``jointlock run SCENARIO --set
failure.joint=J --set failure.time_s=t --seed <the cell's case seed>`` (the halt starting from
the task's state at ``t``, the joint locked at the task's angle: :mod:`jointlock.scenario`'s
``[task]``).  So its folder is a campaign folder: ``jointlock campaign status / export /
report`` work on it, it resumes after Ctrl-C or SIGKILL with every cell exactly once, and it
runs on a process pool or Dask.

:func:`audit_windows` reads the finished cells back: per instant the worst joint, and the
*safe windows*, the stretches of the task where every audited lock leaves a feasible halt
(within the limits, clear of the spacecraft, within the attitude control's capacity).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import CampaignError, JointlockError
from ..io.files import read_toml_file
from ..robots import UrdfChain, load_robot
from ..scenario import load_scenario
from ..scenario._task import scenario_task
from ._columns import audit_cell_safe
from ._read import campaign_from_dict
from ._spec import CampaignSpec

__all__ = [
    "AUDIT_COLUMNS",
    "AUDIT_JUMP_COLUMNS",
    "DEFAULT_AUDIT_TIMES",
    "AuditResult",
    "AuditWindows",
    "audit",
    "audit_campaign",
    "audit_windows",
    "run_audit",
]

#: Instants of the task audited by default (evenly spaced, both ends included).
DEFAULT_AUDIT_TIMES = 11

#: What each cell records: the halt's verdicts and figures, and whether the rest of the task
#: could be finished with the joint locked instead (the halt job's result paths).
AUDIT_COLUMNS = (
    "halt.feasible",
    "halt.collision_free",
    "halt.attitude_control.within",
    "halt.minimum_T_s",
    "halt.minimum_T_clear_s",
    "halt.global_torque_Nm",
    "halt.violations|len",
    "halt.binding_limit",
    "halt.spacecraft.attitude_change_deg",
    "halt.attitude_control.peak_torque_Nm",
    "halt.attitude_control.peak_momentum_Nms",
    "halt.actuators.peak_brake_torque_Nm|max",
    "halt.sigma_min_at_failure",
    "halt.clearance.motion_min_m",
    "halt.task_completion.completable",
    "halt.task_completion.first_unreachable_s",
    "halt.state_source",
)

#: What each cell records besides, when the scenario runs the jump study of a Cartesian task
#: (001: the joint-rate jump at the lock without and with the compensation, whether it keeps the
#: limits); the cells then leave out the task's last instant.
AUDIT_JUMP_COLUMNS = (
    "jump.kappa",
    "jump.jump_before",
    "jump.jump_after",
    "jump.mean_reduction",
    "jump.limits_ok",
    "jump.infeasible",
    "jump.clearance.compensated.collides",
)


def audit_campaign(
    scenario: str | Path,
    *,
    joints: Sequence[int] | None = None,
    times: int | None = None,
    dt: float | None = None,
    seed: int = 0,
    worst: str | None = None,
) -> CampaignSpec:
    """The campaign auditing ``scenario``'s task: ``joints`` (default every joint of the arm)
    x failure instants (``times`` evenly spaced over the task, both ends included, default
    :data:`DEFAULT_AUDIT_TIMES`; or every ``dt`` [s] from 0); ``worst``: the recorded column
    ranking the worst cells in the report (default: the report's choice).

    Raises
    ------
    CampaignError
        A scenario without ``[task]`` or without a ``[halt]`` job, a joint outside the arm,
        both ``times`` and ``dt``, or a bad count or step (one line each).
    """
    path = Path(scenario)
    try:
        raw = read_toml_file(path, "audit: scenario file", CampaignError)
        if not isinstance(raw.get("task"), dict):
            raise CampaignError(f"audit: {path} has no [task] (the planned motion to audit: waypoints or a file)")
        fail: dict[str, Any] = raw["failure"] if isinstance(raw.get("failure"), dict) else {}
        if fail.get("angle_deg") is not None:
            raise CampaignError(
                f"audit: {path}: failure.angle_deg is the task's at each instant; remove it (the joint locks where "
                "the task has it)"
            )
        # the audit sets the joint and the instant of every cell: the file need not
        first = {"failure.joint": fail.get("joint", 1), "failure.time_s": fail.get("time_s", 0.0)}
        base = load_scenario(path, {k: v for k, v in first.items() if k.split(".")[1] not in fail})
    except CampaignError:
        raise
    except JointlockError as exc:
        raise CampaignError(f"audit: {exc}") from None
    task = scenario_task(base.data, str(path))
    if task is None:
        raise CampaignError(f"audit: {path} has no [task] (the planned motion to audit: waypoints or a file)")
    if "halt" not in base.jobs:
        raise CampaignError(f"audit: {path} runs no [halt] job; an audit asks whether each lock leaves a feasible halt")
    dof = load_robot(base.data["robot"], chain=UrdfChain.from_fields(base.data)).dof
    all_joints = list(range(1, dof + 1))
    chosen = list(all_joints if joints is None else joints)
    bad = [j for j in chosen if isinstance(j, bool) or not isinstance(j, int) or j not in all_joints]
    if bad or not chosen or len(set(chosen)) != len(chosen):
        raise CampaignError(
            f"audit: joints must be distinct joint numbers 1..{dof}; got {chosen}" + (f" (not joints: {bad})" if bad else "")
        )
    instants = [round(task.start + v, 9) for v in _instants(task.duration, times, dt)]
    columns = list(AUDIT_COLUMNS)
    fixed: dict[str, Any] = {}
    if "jump" in base.jobs:
        # a lock at the task's very end leaves no motion for the jump study to follow
        instants = [t for t in instants if t < task.end] or instants[:1]
        columns += AUDIT_JUMP_COLUMNS
        fixed["jump.on_infeasible"] = "report"  # no kappa is the jump's answer; the halt keeps its own
    data: dict[str, Any] = {
        "title": f"audit: {base.data.get('title') or path.stem}",
        "scenario": str(path.resolve()),
        "seed": seed,
        "columns": columns,
        **({"set": fixed} if fixed else {}),
        "grid": {"failure.joint": chosen, "failure.time_s": instants},
        # the worst cells: by ``worst``, else the report's first column with a value (the smallest
        # feasible halt time when some cell has one)
        "report": {"x": "failure.time_s", "y": "failure.joint", **({"worst": worst} if worst else {})},
    }
    return campaign_from_dict(data, source=f"audit of {path}", base_dir=path.resolve().parent)


def _instants(duration: float, times: int | None, dt: float | None) -> list[float]:
    if times is not None and dt is not None:
        raise CampaignError("audit: give --times or --dt, not both")
    if dt is not None:
        if not (isinstance(dt, (int, float)) and math.isfinite(dt) and 0 < dt <= duration):
            raise CampaignError(f"audit: dt must be a step in (0, {duration:g}] s (the task's length); got {dt!r}")
        return [round(float(v), 9) for v in np.arange(0.0, duration + 1e-9 * duration, dt)]
    count = DEFAULT_AUDIT_TIMES if times is None else times
    if isinstance(count, bool) or not isinstance(count, int) or not 1 <= count <= 10_000:
        raise CampaignError(f"audit: times must be an integer in 1..10000; got {count!r}")
    # to 1e-9 s: 7.2, not linspace's 7.199999999999999 (the cell's name and its --set value)
    return [round(float(v), 9) for v in np.linspace(0.0, duration, count)] if count > 1 else [0.0]


@dataclass(frozen=True)
class AuditWindows:
    """The audit read back: per instant, whether every audited lock left a safe halt, and the
    worst joint; the safe windows.

    Attributes
    ----------
    times
        (m,) audited instants [s], increasing.
    safe
        (m,) every joint's cell at that instant finished with a feasible, collision-free halt
        within the attitude control's capacity.
    worst_joint
        (m,) the first unsafe joint at that instant, else the joint with the longest smallest
        feasible halt time (None without ``halt.minimum_T_s`` values: ``halt.minimum_T = true``).
    unsafe_joints
        Per instant, the joints whose cell is unsafe (infeasible, colliding, over capacity,
        failed or not run).
    windows
        ``[(start, end)]`` [s]: maximal runs of consecutive safe instants.
    joints
        The audited joints.
    """

    times: tuple[float, ...]
    safe: tuple[bool, ...]
    worst_joint: tuple[int | None, ...]
    unsafe_joints: tuple[tuple[int, ...], ...]
    windows: tuple[tuple[float, float], ...]
    joints: tuple[int, ...] = ()

    def summary(self) -> list[str]:
        lines = []
        if self.windows:
            text = ", ".join(f"[{a:g}, {b:g}] s" if b > a else f"{a:g} s" for a, b in self.windows)
            step = f", instants every {self.times[1] - self.times[0]:.3g} s" if len(self.times) > 1 else ""
            lines.append(f"safe windows (every audited lock leaves a safe halt at every audited instant in them{step}): {text}")
        else:
            lines.append("NO SAFE WINDOW: at every audited instant some lock leaves no safe halt")
        risky = [(t, js) for t, js in zip(self.times, self.unsafe_joints) if js]
        for t, js in risky[:12]:
            lines.append(f"  t = {t:g} s: joint(s) {', '.join(map(str, js))} leave no safe halt")
        if len(risky) > 12:
            lines.append(f"  ... and {len(risky) - 12} more instants")
        return lines

    def to_dict(self) -> dict[str, Any]:
        return {
            "times_s": list(self.times),
            "safe": list(self.safe),
            "worst_joint": list(self.worst_joint),
            "unsafe_joints": [list(j) for j in self.unsafe_joints],
            "windows_s": [list(w) for w in self.windows],
            "joints": list(self.joints),
        }


def audit_windows(rows: Sequence[dict[str, Any]]) -> AuditWindows:
    """The safe windows of an audit's cells: ``rows`` as :func:`~jointlock.campaign.campaign_table`
    gives them (flat: ``failure.joint``, ``failure.time_s``, ``status`` and the
    :data:`AUDIT_COLUMNS`)."""
    cells: dict[float, dict[int, dict[str, Any]]] = {}
    for row in rows:
        t, j = row.get("failure.time_s"), row.get("failure.joint")
        if t is None or j is None:
            continue
        cells.setdefault(float(t), {})[int(j)] = row
    joints = sorted({j for by_joint in cells.values() for j in by_joint})
    times = sorted(cells)
    safe, worst, unsafe = [], [], []
    for t in times:
        by_joint = cells[t]
        bad = tuple(j for j in joints if not audit_cell_safe(by_joint.get(j)))
        unsafe.append(bad)
        safe.append(not bad)
        worst.append(bad[0] if bad else _longest_halt(by_joint))
    windows: list[tuple[float, float]] = []
    start = None
    for k, t in enumerate(times):
        if safe[k] and start is None:
            start = t
        if start is not None and (not safe[k] or k == len(times) - 1):
            end = t if safe[k] else times[k - 1]
            windows.append((start, end))
            start = None
    return AuditWindows(tuple(times), tuple(safe), tuple(worst), tuple(unsafe), tuple(windows), tuple(joints))


def _longest_halt(by_joint: dict[int, dict[str, Any]]) -> int | None:
    best, joint = -math.inf, None
    for j, row in sorted(by_joint.items()):
        value = row.get("halt.minimum_T_s")
        if isinstance(value, (int, float)) and value > best:
            best, joint = float(value), j
    return joint


@dataclass(frozen=True)
class AuditResult:
    """An audit run (:func:`run_audit`): the campaign run, and when it finished, the safe windows
    and the files written (``report.html``, ``audit.json``)."""

    run: Any
    windows: AuditWindows | None
    files: tuple[str, ...] = ()

    def summary(self) -> list[str]:
        lines = list(self.run.summary())
        if self.windows is not None:
            lines += self.windows.summary()
        return lines + [f"  wrote {f}" for f in self.files]

    def to_dict(self) -> dict[str, Any]:
        return self.run.to_dict() | {
            "windows": None if self.windows is None else self.windows.to_dict(),
            "files": list(self.files),
        }


def run_audit(
    scenario: str | Path,
    out: str | Path | None = None,
    *,
    joints: Sequence[int] | None = None,
    times: int | None = None,
    dt: float | None = None,
    seed: int = 0,
    engine: Any = None,
    workers: int | None = None,
    progress: bool = False,
) -> AuditResult:
    """Audit ``scenario``'s task (:func:`audit_campaign`) on the campaign engine
    (:func:`~jointlock.campaign.run_campaign`: a process pool by default, or ``engine``), into
    ``out`` (default ``<scenario stem>-audit``); when every cell is done, write the campaign
    report (heatmaps joint x time, worst cells as scenario files) and ``audit.json`` (the safe
    windows).  Running again resumes the cells not finished."""
    from ..io.files import atomic_write_json
    from ._report import write_campaign_report
    from ._results import campaign_table
    from ._runner import run_campaign

    spec = audit_campaign(scenario, joints=joints, times=times, dt=dt, seed=seed)
    folder = Path(out) if out is not None else Path(f"{Path(scenario).stem}-audit")
    run = run_campaign(spec, folder, engine=engine, workers=workers, progress=progress)
    if run.interrupted or run.remaining:
        return AuditResult(run, None)
    windows = audit_windows(campaign_table(folder).rows)
    atomic_write_json(folder / "audit.json", windows.to_dict())
    written = [str(p) for p in write_campaign_report(folder)]
    return AuditResult(run, windows, (*written, str(folder / "audit.json")))


#: ``jl.audit``: the library's ``jointlock audit`` (:func:`run_audit`).
audit = run_audit
