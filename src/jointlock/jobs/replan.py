"""Job ``replan``: a straight-line Cartesian plan followed by an arm with a locked joint (002).

The start and goal are the poses of two full-arm configurations; the line between them (002
eqs. 19-20) is followed by the locked arm through its closed-form IK, each waypoint rotated
about the tool x axis by some ``|gamma| <=`` the tolerance
(:func:`jointlock.planning.replan.replan_line` does the planning; this job adds the settings
and the outputs).  The command ``jointlock replan`` is this call plus printing.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, ClassVar, Literal

import numpy as np
from numpy.typing import ArrayLike

from ..analysis.spacecraft import SpacecraftResponse, spacecraft_response
from ..collision import Clearance, clearance, reports_clearance
from ..errors import ScenarioError
from ..io.files import atomic_write_json, atomic_write_text, with_svg, write_figure
from ..kinematics import ee_pose
from ..locking import lock
from ..model import ArmModel
from ..planning.replan import DEFAULT_STEP_WEIGHT, ReplanResult, StepFlag, replan_line
from ..plots.motion import ArmMotion
from ..progress import Progress
from ..robots import UrdfChain, load_robot
from ._common import JobResult, scenario_lock
from ._motions import replan_motions

#: Size of each figure [inch]: the joints, then the two-panel pose, error and velocity figures.
JOINTS_FIGSIZE = (7.0, 4.0)
PANELS_FIGSIZE = (11.0, 4.0)


def step_flag_dict(flag: StepFlag, unit: str) -> dict[str, Any]:
    """One flagged joint step as JSON data (degrees); the limit's key is ``limit_<unit>``
    (``"deg"`` for a jump threshold, ``"deg_s"`` for a speed limit)."""
    return {
        "step": flag.index,
        "time_s": flag.time,
        "joint": flag.joint,
        "step_deg": math.degrees(flag.step),
        "rate_deg_s": math.degrees(flag.rate),
        f"limit_{unit}": math.degrees(flag.limit),
    }


@dataclass(frozen=True, eq=False)  # arrays inside: compare to_dict() instead
class ReplanJobResult(JobResult):
    """A straight-line plan of the locked arm, with the settings that produced it.

    Attributes
    ----------
    robot
        Name of the (full) arm.
    plan
        The plan (times (K,) [s], joints (K, 6) [rad], gamma (K,) [rad], errors, flags...).
    tolerance_deg
        Largest ``|gamma|`` accepted [deg], as given.
    step_weight
        Tracking error [m] traded per rad^2 of joint step (``method="continuous"``).
    model
        The locked arm the plan moves (None when not kept).
    """

    job: ClassVar[str] = "replan"

    robot: str
    plan: ReplanResult
    tolerance_deg: float
    step_weight: float
    model: ArmModel | None = field(default=None, repr=False)

    def spacecraft_response(self) -> SpacecraftResponse | None:
        """What the free spacecraft does while the locked arm follows the plan's waypoints at
        their times (rates by central differences, :func:`~jointlock.analysis.spacecraft.
        spacecraft_response`); None unless the arm is free-floating."""
        if self.model is None or not self.model.floating:
            return None
        return spacecraft_response(self.model, self.plan.times, self.plan.q, self.plan.dq)

    def clearance(self) -> Clearance | None:
        """Clearance of the plan's waypoints (K,) (:func:`jointlock.collision.clearance`;
        negative: the arm overlaps its spacecraft bus or itself); None without the model or its
        collision shapes."""
        if self.model is None or not reports_clearance(self.model):
            return None
        return clearance(self.model, self.plan.q)

    def _clearance_dict(self) -> dict[str, Any] | None:
        clear = self.clearance()
        if clear is None:
            return None
        worst = clear.worst()
        return {
            "min_m": float(clear.distance[worst]),
            "pair": clear.pair_at(worst),
            "time_s": float(self.plan.times[worst]),
            "colliding_waypoints": int(np.count_nonzero(clear.colliding(0.0))),
        }

    def trajectory(self) -> dict[str, np.ndarray]:
        """The time series of the JSON output: ``time_s`` (K,), ``q_deg`` (K, 6), ``gamma_deg``,
        ``absorbed``, ``position_error_m``, ``rotation_error_deg`` (K,)."""
        res = self.plan
        return {
            "time_s": res.times,
            "q_deg": np.degrees(res.q_full),
            "gamma_deg": np.degrees(res.gamma),
            "absorbed": res.absorbed,
            "position_error_m": res.position_error,
            "rotation_error_deg": np.degrees(res.rotation_error),
        }

    def headline(self) -> dict[str, Any]:
        """:meth:`to_dict` without the ``trajectory``."""
        res = self.plan
        step_at, step_joint = res.max_joint_step_at
        return {
            "robot": self.robot,
            "lock": {"joint": res.joint, "angle_deg": math.degrees(res.lock_angle)},
            "waypoints": int(res.times.size),
            "duration_s": float(res.times[-1]),
            "branch": res.branch,
            "tolerance_deg": self.tolerance_deg,
            "absorbed_waypoints": int(res.absorbed.sum()),
            "gamma_deg_range": [float(np.degrees(res.gamma.min())), float(np.degrees(res.gamma.max()))],
            "max_tracking_position_error_m": float(res.position_error.max()),
            "max_tracking_rotation_error_deg": float(np.degrees(res.rotation_error.max())),
            "max_deviation_from_line_m": float(res.position_deviation.max()),
            "max_rotation_deviation_deg": float(np.degrees(res.rotation_deviation.max())),
            "max_joint_rate_deg_s": np.degrees(np.abs(res.dq).max(axis=0)),
            "q_start_deg": np.degrees(res.q_full[0]),
            "q_goal_deg": np.degrees(res.q_full[-1]),
            "gamma_goal_deg": float(np.degrees(res.gamma[-1])),
            "method": res.method,
            "step_weight": self.step_weight,
            "mean_tracking_position_error_m": float(res.position_error.mean()),
            "max_joint_step_deg": math.degrees(res.max_joint_step),
            "max_joint_step_at": {"step": step_at, "time_s": float(res.times[step_at]), "joint": step_joint},
            "max_joint_step_per_joint_deg": np.degrees(res.joint_step.max(axis=0))
            if res.joint_step.size
            else [],
            "max_step_rate_deg_s": np.degrees(res.step_rate.max(axis=0)) if res.joint_step.size else [],
            "velocity_limit_deg_s": [v if math.isfinite(v) else None for v in np.degrees(res.velocity_limit)],
            "jump_threshold_deg": math.degrees(res.jump_threshold),
            "clearance": self._clearance_dict(),
            "jumps": [step_flag_dict(f, "deg") for f in res.jumps],
            "over_velocity": [step_flag_dict(f, "deg_s") for f in res.over_velocity],
        }

    def to_dict(self) -> dict[str, Any]:
        """The JSON object of ``jointlock replan --json`` (without ``files``); ``spacecraft``
        (:meth:`spacecraft_response`) with a free-floating arm."""
        sc = self.spacecraft_response()
        extra = {} if sc is None else {"spacecraft": sc.to_dict()}
        return {**self.headline(), **extra, "trajectory": self.trajectory()}

    def summary(self) -> list[str]:
        """The lines ``jointlock replan`` prints."""
        res = self.plan
        s = self.headline()
        step_at, step_joint = res.max_joint_step_at
        lines = [
            f"{self.robot}, joint {res.joint} locked at {math.degrees(res.lock_angle):g} deg: {res.times.size} "
            f"waypoints over {res.times[-1]:g} s, gamma tolerance {self.tolerance_deg:g} deg",
            f"  waypoints where the lock is absorbed exactly: {s['absorbed_waypoints']}/{res.times.size}",
            f"  gamma used: {s['gamma_deg_range'][0]:.4f} .. {s['gamma_deg_range'][1]:.4f} deg",
            f"  max tracking error: {s['max_tracking_position_error_m'] * 1e3:.4f} mm, "
            f"{s['max_tracking_rotation_error_deg']:.4g} deg",
            f"  largest joint step: {s['max_joint_step_deg']:.4g} deg (joint {step_joint}, waypoint "
            f"{step_at} -> {step_at + 1}, t = {res.times[step_at]:g} s); jump threshold "
            f"{s['jump_threshold_deg']:.4g} deg",
        ]
        for f in res.jumps:
            lines.append(
                f"  JUMP: joint {f.joint} moves {math.degrees(f.step):.4g} deg between t = {f.time:g} s and "
                f"{f.time + res.cycle:g} s ({math.degrees(f.rate):.4g} deg/s)"
            )
        if res.over_velocity:
            worst = max(res.over_velocity, key=lambda f: f.rate / f.limit)
            lines.append(
                f"  {len(res.over_velocity)} joint steps exceed the speed limit; worst: joint {worst.joint} at "
                f"t = {worst.time:g} s needs {math.degrees(worst.rate):.4g} deg/s (limit "
                f"{math.degrees(worst.limit):.4g})"
            )
        elif np.all(np.isfinite(res.velocity_limit)):
            lines.append("  every joint step is within the speed limits at this cycle")
        lines.append("  goal q [deg]: " + " ".join(f"{v:.4f}" for v in s["q_goal_deg"]))
        sc = self.spacecraft_response()
        if sc is not None:
            lines += ["  " + line for line in sc.summary("spacecraft (free, zero momentum)")]
        clear = s["clearance"]
        if clear is not None:
            lines.append(f"  clearance: smallest {clear['min_m']:+.3f} m ({clear['pair']}, t = {clear['time_s']:g} s)")
            if clear["colliding_waypoints"]:
                lines.insert(
                    0,
                    f"COLLIDES: {clear['colliding_waypoints']} of {res.times.size} waypoints overlap the spacecraft "
                    f"bus or the arm itself; deepest {-clear['min_m']:.3f} m into {clear['pair']} at t = {clear['time_s']:g} s",
                )
        return lines

    def trajectory_csv(self) -> str:
        """``trajectory.csv``: time, every joint [deg], gamma [deg], tracking errors [m, deg]."""
        res = self.plan
        header = "time_s," + ",".join(f"q{k + 1}_deg" for k in range(res.q_full.shape[1]))
        header += ",gamma_deg,position_error_m,rotation_error_deg"
        rows = np.column_stack(
            [
                res.times,
                np.degrees(res.q_full),
                np.degrees(res.gamma),
                res.position_error,
                np.degrees(res.rotation_error),
            ]
        )
        lines = [header] + [",".join(f"{v:.9g}" for v in row) for row in rows]
        return "\n".join(lines) + "\n"

    def file_names(self) -> list[str]:
        """The names :meth:`write` writes (its JSON lists them as paths)."""
        names = ["joints.png", "pose.png", "error.png", "velocity.png", "trajectory.csv", "plan.json"]
        names += ["motion.json"] if self.model is not None else []
        return with_svg(names + (["spacecraft_attitude.png"] if self.spacecraft_response() is not None else []))

    def arm_motions(self) -> tuple[ArmModel, list[ArmMotion]] | None:
        """The re-planned path to animate (:func:`~jointlock.jobs._motions.replan_motions`);
        None for a result built without its model."""
        return None if self.model is None else replan_motions(self)

    def write(self, out: str | Path) -> list[str]:
        """Write ``joints.png`` (002 Figs. 11/17), ``pose.png`` (Figs. 12/18), ``error.png``
        (Figs. 13/19), ``velocity.png`` (Figs. 14/20), ``trajectory.csv`` and ``plan.json``
        (:meth:`to_dict`) to the folder ``out``; returns their names."""
        from ..plots._common import offscreen_figure
        from ..plots.replan import (
            plot_replan_errors,
            plot_replan_joints,
            plot_replan_pose,
            plot_replan_velocity,
        )

        folder = Path(out)
        folder.mkdir(parents=True, exist_ok=True)
        fig = offscreen_figure(JOINTS_FIGSIZE)
        plot_replan_joints(self.plan, ax=fig.add_subplot())
        fig.tight_layout()
        write_figure(fig, folder, "joints.png", tight=False)
        for name, plot in (
            ("pose.png", plot_replan_pose),
            ("error.png", plot_replan_errors),
            ("velocity.png", plot_replan_velocity),
        ):
            write_figure(plot(self.plan, fig=offscreen_figure(PANELS_FIGSIZE)), folder, name, tight=False)
        atomic_write_text(folder / "trajectory.csv", self.trajectory_csv())
        atomic_write_json(folder / "plan.json", self.to_dict())
        sc = self.spacecraft_response()
        if sc is not None:
            from ..plots.spacecraft import plot_spacecraft_responses

            fig = plot_spacecraft_responses({"re-planned path": sc}, fig=offscreen_figure((7, 5)))
            write_figure(fig, folder, "spacecraft_attitude.png", tight=False)
        self._write_motions(folder)
        return self.file_names()


def plan_replan(
    model: ArmModel,
    joint: int,
    angle: float,
    q_from: ArrayLike,
    q_to: ArrayLike,
    *,
    steps: int = 40,
    cycle: float = 0.25,
    tolerance_deg: float = 0.0,
    method: Literal["continuous", "pointwise"] = "continuous",
    step_weight: float = DEFAULT_STEP_WEIGHT,
    jump_threshold: float | None = None,
    progress: bool = False,
) -> ReplanJobResult:
    """Re-plan the straight line from the pose of ``q_from`` to that of ``q_to`` for the arm
    with ``joint`` locked at ``angle`` (002 eqs. 19-20 and Figs. 10-21).

    Parameters
    ----------
    model
        A healthy ``puma6``-family arm (6 joints with 002 Table 1's structure).
    joint, angle
        The locked joint (1-based) and its angle [rad].
    q_from, q_to
        (6,) start and goal configurations of the full arm [rad]; their poses (forward
        kinematics) are the ends of the line, and ``q_to`` chooses the IK branch at the goal.
    steps
        Interior points N of 002 eq. (19), >= 1 (the plan has ``steps + 2`` waypoints).
    cycle
        Time between waypoints [s], > 0 (002: 0.25).
    tolerance_deg
        Largest ``|gamma|`` accepted [deg], in [0, 180] (degrees, as the result echoes it).
    method
        ``"continuous"``: gamma and branch chosen along the whole path (no joint jumps);
        ``"pointwise"``: the smallest ``|gamma|`` absorbing the lock at each waypoint alone.
    step_weight
        ``"continuous"``: tracking error [m] traded per rad^2 of joint step, >= 0.
    jump_threshold
        Flag joint steps above this [rad], > 0; None: 5x the median step, between 2 and 30 deg.
    progress
        Show a progress bar on stderr (when it is a terminal).

    Returns
    -------
    ReplanJobResult

    Raises
    ------
    ScenarioError
        A parameter out of range (the message names it).
    ModelError, ConfigurationError
        The lock is invalid, the arm is not of the puma6 family, or a pose is out of reach.
    """
    q_from = np.asarray(q_from, dtype=float).ravel()
    q_to = np.asarray(q_to, dtype=float).ravel()
    for name, q in (("q_from", q_from), ("q_to", q_to)):
        if q.size != model.dof or not np.all(np.isfinite(q)):
            raise ScenarioError(
                f"{name} needs {model.dof} finite values (all joints) [rad]; got {q.tolist()}"
            )
    if not (isinstance(steps, (int, np.integer)) and steps >= 1):
        raise ScenarioError(
            f"steps must be an integer >= 1 (interior points between start and goal); got {steps}"
        )
    if not (math.isfinite(cycle) and cycle > 0):
        raise ScenarioError(f"cycle must be a finite number > 0 [s]; got {cycle}")
    if not (0 <= tolerance_deg <= 180):
        raise ScenarioError(f"tolerance_deg must be in [0, 180]; got {tolerance_deg}")
    if not (math.isfinite(step_weight) and step_weight >= 0):
        raise ScenarioError(f"step_weight must be a finite number >= 0; got {step_weight}")
    if jump_threshold is not None and not (math.isfinite(jump_threshold) and jump_threshold > 0):
        raise ScenarioError(f"jump_threshold must be a finite number > 0 [rad]; got {jump_threshold}")
    if method not in ("continuous", "pointwise"):
        raise ScenarioError(f"method must be 'continuous' or 'pointwise'; got {method!r}")
    locked = lock(model, joint, angle)
    with Progress(1, "replan", enabled=None if progress else False) as bar:
        start, goal = ee_pose(model, q_from), ee_pose(model, q_to)
        plan = replan_line(
            locked,
            start,
            goal,
            steps=int(steps),
            cycle=float(cycle),
            gamma_tolerance=math.radians(tolerance_deg),
            q_ref=q_to,
            method=method,
            step_weight=float(step_weight),
            jump_threshold=jump_threshold,
        )
        bar.update()
    return ReplanJobResult(
        robot=model.name, plan=plan, tolerance_deg=float(tolerance_deg), step_weight=float(step_weight), model=locked
    )


def replan_from_scenario(
    data: Mapping[str, Any], previous: Mapping[str, JobResult], *, progress: bool = False
) -> ReplanJobResult:
    """Run the job for a resolved scenario (``Scenario.data``: the top-level ``robot``, ``base``
    and ``[failure]``, and the ``[replan]`` table, in degrees; ``method``, ``step_weight`` and
    the jump threshold take their defaults); ``previous`` is not used.  Same result as
    ``jointlock replan`` with the scenario's options."""
    joint, angle = scenario_lock(data, "replan")
    t = data["replan"]
    model = load_robot(data["robot"], base=data["base"], chain=UrdfChain.from_fields(data))
    return plan_replan(
        model,
        joint,
        angle,
        np.radians([float(v) for v in t["from_deg"]]),
        np.radians([float(v) for v in t["to_deg"]]),
        steps=int(t["steps"]),
        cycle=float(t["cycle"]),
        tolerance_deg=float(t["tolerance_deg"]),
        progress=progress,
    )
