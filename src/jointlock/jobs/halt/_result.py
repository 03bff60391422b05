"""The result of :func:`~jointlock.jobs.halt.plan_halt`, :class:`HaltPlan`: the JSON of
``jointlock halt --json`` (``to_dict()``), its printed lines (``summary()``) and the files of
``--out`` (``write()``)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, ClassVar, cast

import numpy as np

from ..._cache import cached_on
from ...analysis.actuators import ActuatorLoads, actuator_loads
from ...analysis.attitude_control import AttitudeControlCheck, WheelCapacity, attitude_control_check
from ...analysis.spacecraft import SpacecraftResponse, spacecraft_response
from ...collision import Clearance, ClearanceSettings, clearance, reports_clearance, unread_meshes_line
from ...kinematics import generalized_jacobian, jacobian
from ...model import ArmModel
from ...papers import p000
from ...planning.completion import TaskCompletion
from ...planning.halt_config import HaltConfiguration
from ...planning.halt_motion import (
    K_UNIT_SCALE,
    OBJECTIVES,
    HaltMotion,
    HaltProblem,
    base_torque_history,
    halt_objective,
    infeasibility_message,
)
from ...plots.halt import (
    k_text,
)
from ...plots.motion import ArmMotion
from .._common import AT_LIMIT, JobResult, locked_deg, locked_text
from .._motions import halt_motions
from ._clearance import clearance_report, collision_line, minimum_T_clear_lines
from ._files import write_halt_files
from ._inputs import JointLimits, limits_text
from ._text import (
    MOMENT_TEXT,
    OBJECTIVE_TEXT,
    _change_text,
    _jacobian_text,
    _margin_text,
    _none_for_inf,
    _none_for_nan,
    _printed_text,
    _violation,
    limits_table,
)

#: A margin above minus this [-] is round-off of a limit met exactly (the feasibility checks allow
#: a relative 1e-9): shown as 0.
MARGIN_ROUNDOFF = 1e-8

#: A feasible k interval narrower than this share of |k*| is fragile.
FRAGILE_WIDTH = 0.01

#: Longest time step of the spacecraft's attitude integration [s] (the objective's grid may be
#: coarse: 11 samples put 000's 124 deg off by 0.5 deg; 0.02 s keeps it within 1e-3 deg).
SPACECRAFT_STEP_S = 0.02


@dataclass(frozen=True, eq=False)  # arrays inside: compare to_dict() instead
class HaltPlan(JobResult):
    """The result of :func:`plan_halt`: where the arm halts and how it gets there.

    Attributes
    ----------
    motion
        The optimal halt motion (its ``problem`` holds the model, state, halt configuration,
        T and limits).
    limits
        The limits applied and their sources.
    qf_source
        Where the halt configuration came from.
    paper_scenario
        Whether this is 000 §5's scenario (then ``to_dict()["paper"]`` holds 000's numbers).
    configuration
        The halt-configuration search (None when ``qf`` was given).
    reachability
        How the reachability constraint went (None when not searched or not constrained).
    samples
        Monte Carlo samples of the search.
    reachability_requested
        Whether the search was asked to keep to reachable configurations.
    seed
        The seed of the halt-configuration search and the GA (:mod:`jointlock._random`; None
        when a numpy Generator was given).
    state_source
        Where the state at failure came from, in words.
    margin
        Share of each limit kept free (asked; kept when the halt is feasible).
    notes
        Plain-language notes on how the halt was planned (printed with the summary).
    clearance_settings
        The clearance required and the keep-out volumes (:class:`~jointlock.collision.
        ClearanceSettings`); whether the halt keeps it is :attr:`collision_free`
        (:attr:`feasible` is the limits' verdict).
    wheels
        What the spacecraft's attitude control can absorb (:class:`~jointlock.analysis.
        attitude_control.WheelCapacity`); the halt's load on it is :meth:`attitude_control`.
    minimum_T_clear
        With the clearance required, when the smallest feasible halt time was computed
        (``minimum_T``, or an infeasible halt): the smallest halt time [s] whose halt keeps the
        clearance too (:func:`~jointlock.planning.halt_motion.minimum_clear_halt_time`); None
        when none up to twice the longer of ``T`` and the limits' smallest does, or not computed (:attr:`clearance_checked_for_T`).
    task_completion
        With the state at failure taken from a planned motion (a scenario's ``[task]``): could
        the rest of the task be finished with the joint locked instead of halting
        (:func:`jointlock.task_completion`; issue 28); None otherwise.
    """

    job: ClassVar[str] = "halt"

    motion: HaltMotion
    limits: JointLimits
    qf_source: str
    paper_scenario: bool = False
    configuration: HaltConfiguration | None = field(default=None, repr=False)
    reachability: str | None = None
    samples: int = p000.SAMPLES
    reachability_requested: bool = True
    seed: int | None = 0
    state_source: str = "given"
    margin: float = 0.0
    notes: tuple[str, ...] = ()
    clearance_settings: ClearanceSettings = field(default_factory=ClearanceSettings)
    wheels: WheelCapacity = field(default_factory=WheelCapacity)
    task_completion: TaskCompletion | None = field(default=None, repr=False)
    minimum_T_clear: float | None = None

    @property
    def problem(self) -> HaltProblem:
        return self.motion.problem

    @property
    def feasible(self) -> bool:
        """The halt motion keeps every limit (speed, acceleration, torques); whether it keeps
        the clearance is :attr:`collision_free`."""
        return bool(self.motion.feasible)

    @property
    def collision_free(self) -> bool | None:
        """Whether the halt motion keeps the clearance required (0 m when only reported) on
        every sample of the constraint grid, and between its samples to within the tunnelling
        tolerance (:func:`jointlock.sweep.swept_clearance`); a pair already closer at the state at
        failure must not come closer still.  None for a model without collision shapes."""
        data = self._clearance_dict()
        return None if data is None else not data["collides"]

    @property
    def clearance_checked_for_T(self) -> bool:
        """Whether :attr:`minimum_T_clear` was computed: the smallest feasible halt time was, the
        clearance is required, the model has shapes and ``k`` is shared."""
        res = self.motion
        return (
            res.minimum_T is not None
            and self.clearance_settings.required
            and not res.per_joint
            and self.collision_free is not None
        )

    @property
    def k_deg(self) -> Any:
        """The chosen k [deg/s^6] (an array with one k per joint for the vector solver)."""
        return np.asarray(self.motion.k) / K_UNIT_SCALE["deg/s^6"]

    def _notes(self) -> dict[str, Any]:
        """Where the limits and the halt configuration came from (keys in the CLI's order)."""
        notes: dict[str, Any] = {
            "velocity_limit_source": list(self.limits.velocity_source),
            "acceleration_limit_source": list(self.limits.acceleration_source),
            "paper_scenario": self.paper_scenario,
        }
        hc = self.configuration
        if hc is not None and self.reachability is not None:
            notes["reachability"] = self.reachability
            if hc.reachability is not None:
                notes["reachable_samples"] = hc.reachable_samples
        notes["qf_source"] = self.qf_source
        if hc is not None:
            notes["cp_best"] = float(getattr(hc, "cp_best", float("nan")))
            notes["hcom_jacobian"] = hc.jacobian
            notes["hcom_base"] = hc.base
        return notes

    def to_dict(self) -> dict[str, Any]:
        """What ``jointlock halt --json`` prints: degrees, deg/s^6 for k, N m for torques."""
        res, p = self.motion, self.problem
        scale = K_UNIT_SCALE["deg/s^6"]
        _, dq, ddq = res.check_trajectory()
        return {
            "robot": p.model.name,
            "base": p.base,
            "joint_numbers": list(p.model.joint_numbers),
            "locked": locked_deg(p.model),
            "T_s": p.T,
            "k": np.asarray(res.k) / scale,
            "k_unit": "deg/s^6",
            "k_rad": res.k,
            "global_torque_Nm": res.global_torque,
            "global_torque_k0_Nm": res.global_torque_k0,
            "reduction": None if math.isnan(res.reduction) else res.reduction,
            "feasible": res.feasible,
            "collision_free": self.collision_free,
            "violations": [_violation(v) for v in res.violations],
            "violations_k0": [_violation(v) for v in res.violations_k0],
            "k_interval_deg": res.k_interval / scale,
            "k_torque_stretches_deg": None
            if res.k_segments is None
            else [[a / scale, b / scale] for a, b in res.k_segments],
            **({"joint_k_intervals_deg": res.joint_intervals / scale} if res.per_joint else {}),
            "minimum_T_s": res.minimum_T,
            "minimum_T_clear_s": self.minimum_T_clear,
            "q_initial_deg": np.degrees(p.q0),
            "dq_initial_deg_s": np.degrees(p.dq0),
            "ddq_initial_deg_s2": np.degrees(p.ddq0),
            "spacecraft": None if (sc := self.spacecraft_response()) is None else sc.to_dict(),
            "state_source": self.state_source,
            "moment_about": p.moment_about,
            "objective": p.objective,
            "objective_value": res.objective_value,
            "objective_value_k0": res.objective_value_k0,
            "objective_unit": OBJECTIVES[p.objective],
            "k_optimum": None if res.k_optimum is None else res.k_optimum / scale,
            "margin_kept": self.margin,
            "velocity_margin": (m := self.margins())["velocity"],
            "acceleration_margin": m["acceleration"],
            "torque_margin": _none_for_nan(m["torque"]),
            "brake_margin": _none_for_nan(m["brake"]),
            "smallest_margin": (binding := self.binding_limit())[1],
            "binding_limit": binding[0],
            "actuators": None if (loads := self.actuator_loads()) is None else loads.to_dict(),
            "clearance": None
            if (clear := self._clearance_dict()) is None
            else {**clear, "verdict": next(iter(self._collision_line()), None)},
            "attitude_control": self.attitude_control().to_dict(),
            "sigma_min_at_failure": self.sigma_min_at_failure(),
            "task_completion": None if self.task_completion is None else self.task_completion.to_dict(),
            "torque_limit_Nm": _none_for_inf(self.limits.torque),
            "brake_limit_Nm": _none_for_inf(self.limits.brake),
            "torque_limit_source": list(self.limits.torque_source),
            "brake_limit_source": list(self.limits.brake_source),
            "fragile": self.fragile,
            "from_rest": self.from_rest,
            "q_final_deg": np.degrees(p.qf),
            "peak_velocity_deg_s": np.degrees(np.abs(dq).max(axis=0)),
            "peak_acceleration_deg_s2": np.degrees(np.abs(ddq).max(axis=0)),
            "velocity_limit_deg_s": np.degrees(p.dq_max),
            "acceleration_limit_deg_s2": np.degrees(p.ddq_max),
            "solver": res.solver,
            "notes": list(self.notes),  # how it was planned: e.g. a solver's fallback to keep the clearance
            "seed": res.seed,
            # 000's printed numbers, for 000 §5's scenario on halt7 only (None otherwise)
            "paper": dict(p000.HALT_RESULTS) if self.paper_scenario else None,
            **self._notes(),
        }

    def spacecraft_response(self, n: int | None = None) -> SpacecraftResponse | None:
        """What a free spacecraft does during the halt (:func:`~jointlock.analysis.spacecraft.
        spacecraft_response`): attitude, rate and drift on ``n`` time samples (default: a step
        of at most :data:`SPACECRAFT_STEP_S`, at least the objective's grid); None for a model
        without a spacecraft.  With ``base="fixed"`` (000's torque, the spacecraft held) it says
        what the spacecraft would do if it were free."""
        p = self.problem
        if not p.model.floating:
            return None
        t = p.times(n if n is not None else max(p.n_samples, math.ceil(p.T / SPACECRAFT_STEP_S) + 1))
        q, dq, _ = self.motion.trajectory(t)
        return spacecraft_response(p.model, t, q, dq)

    def arm_motions(self) -> tuple[ArmModel, list[ArmMotion]]:
        """The halt to animate (:func:`~jointlock.jobs._motions.halt_motions`)."""
        return halt_motions(self)

    def clearance(self) -> Clearance | None:
        """Clearance of the halt motion (:func:`jointlock.collision.clearance`) on the
        constraint grid (``n_check`` samples, the halt configuration last); None for a model
        without collision shapes.  ``distance`` (n_check,) [m]; negative: the arm overlaps the
        spacecraft bus or itself."""
        p = self.problem
        settings = self.clearance_settings
        if not reports_clearance(p.model, settings.keep_out):
            return None

        def compute() -> Clearance:
            q, _, _ = self.motion.check_trajectory()
            return clearance(p.model, q, keep_out=settings.keep_out, margin=settings.margin)

        return cached_on(self, "clearance", compute)

    def _clearance_dict(self) -> dict[str, Any] | None:
        """:func:`~._clearance.clearance_report` of the halt (None without collision shapes)."""

        def compute() -> dict[str, Any] | None:
            sampled = self.clearance()
            return None if sampled is None else clearance_report(self.motion, self.clearance_settings, sampled)

        return cached_on(self, "clearance_dict", compute)

    def _collision_line(self) -> list[str]:
        """The first line of the summary when the halt comes closer than required."""
        return collision_line(self._clearance_dict(), self.clearance_settings, self.problem.model.name)

    def _minimum_T_clear_lines(self) -> list[str]:
        if not self.clearance_checked_for_T:
            return []
        return minimum_T_clear_lines(self.motion, self.clearance_settings.margin, self.minimum_T_clear)

    def sigma_min_at_failure(self) -> float:
        """Smallest singular value of the locked arm's Jacobian at the state at failure (how
        close to a singularity the arm is when the joint locks; issue 28's audit records it):
        the generalized Jacobian J_F for a free-floating model, else the fixed-base one (000's
        CP basis), linear rows in m/s, angular in rad/s."""
        p = self.problem
        jac = generalized_jacobian(p.model, p.q0) if p.model.floating else jacobian(p.model, p.q0)
        return float(np.linalg.svd(jac, compute_uv=False).min())

    def attitude_control(self) -> AttitudeControlCheck:
        """What the attitude control must absorb to hold the spacecraft during the halt
        (:func:`~jointlock.analysis.attitude_control.attitude_control_check`, issue 28): the
        peak base moment [N m] and the angular momentum handed to the wheels [N m s], about the
        spacecraft's centre of mass, on the constraint grid, against :attr:`wheels`."""
        p = self.problem

        def compute() -> AttitudeControlCheck:
            t = p.times(p.n_check)
            q, dq, ddq = self.motion.check_trajectory()
            return attitude_control_check(p.model, t, q, dq, ddq, self.wheels)

        return cached_on(self, "attitude_control", compute)

    def _attitude_line(self) -> list[str]:
        """The first line of the summary when the halt needs more than the wheels can give."""
        check = self.attitude_control()
        return [check.verdict()] if check.within is False else []

    def actuator_loads(self) -> ActuatorLoads | None:
        """Motor torques of the healthy joints and brake torques of the locked joints over the
        halt (:func:`~jointlock.analysis.actuators.actuator_loads`), with the base of the
        disturbance torque, on the constraint grid; None for a locked model that lost its
        unlocked arm (built by hand)."""
        p = self.problem
        if p.model.locked and p.model.unlocked is None:
            return None
        t = p.times(p.n_check)
        q, dq, ddq = self.motion.check_trajectory()
        return actuator_loads(p.model, t, q, dq, ddq, base=p.base)

    def margins(self) -> dict[str, np.ndarray]:
        """Each limit's margin over the halt, against the limit itself (not the one reduced by
        :attr:`margin`): ``{"velocity": (n,), "acceleration": (n,), "torque": (n,), "brake":
        (n_locked,)}``, ``1 - peak / limit`` (0: at the limit; negative: broken; NaN: no limit)."""
        res, p = self.motion, self.problem
        _, dq, ddq = res.check_trajectory()
        out = {
            "velocity": 1.0 - np.abs(dq).max(axis=0) / self.limits.velocity,
            "acceleration": 1.0 - np.abs(ddq).max(axis=0) / self.limits.acceleration,
            "torque": np.full(p.dof, np.nan),
            "brake": np.full(len(p.model.locked), np.nan),
        }
        loads = (
            self.actuator_loads() if self.limits.torque is not None or self.limits.brake is not None else None
        )
        for key, limits, peaks in (
            ("torque", self.limits.torque, None if loads is None else loads.peak_motor),
            ("brake", self.limits.brake, None if loads is None else loads.peak_brake),
        ):
            if limits is not None and peaks is not None:
                with np.errstate(divide="ignore", invalid="ignore"):
                    out[key] = np.where(np.isfinite(limits), 1.0 - peaks / limits, np.nan)
        # a limit met within the feasibility check's round-off slack is met: margin 0, not -1e-10
        return {key: np.where((m < 0) & (m > -MARGIN_ROUNDOFF), 0.0, m) for key, m in out.items()}

    def binding_limit(self) -> tuple[str, float]:
        """The limit(s) with the smallest margin over the halt, in words (``"joint 3 brake
        torque (locked)"``; ties within 1e-6 joined by "and"), and that margin [-] (:meth:`margins`)."""
        names = {"velocity": "speed", "acceleration": "acceleration", "torque": "motor torque",
                 "brake": "brake torque (locked)"}  # fmt: skip
        numbers = {"brake": [lj.number for lj in self.problem.model.locked]}
        found = [
            (float(value), f"joint {num} {names[key]}")
            for key, values in self.margins().items()
            for num, value in zip(numbers.get(key, self.problem.model.joint_numbers), values)
            if not math.isnan(value)
        ]
        smallest = min(value for value, _ in found)
        return " and ".join(name for value, name in found if value <= smallest + 1e-6), smallest

    @property
    def fragile(self) -> bool:
        """The feasible stretch of k holding k* (:attr:`HaltMotion.feasible_stretch`: with
        torque limits, the stretch that keeps them too) is narrow next to k* (width <
        :data:`FRAGILE_WIDTH` of |k*|): a small error in the model or the timing can break a limit."""
        stretch = self.motion.feasible_stretch
        if stretch is None:
            return False
        return bool(stretch[1] - stretch[0] < FRAGILE_WIDTH * max(abs(float(self.motion.k)), 1e-300))

    @property
    def from_rest(self) -> bool:
        """The arm was at rest when the joint locked (no rate, no acceleration): the "halt" is
        a reconfiguration to the halt configuration."""
        p = self.problem
        return not np.any(p.dq0) and not np.any(p.ddq0)

    def state_lines(self) -> list[str]:
        """The state at failure the halt starts from, and where it comes from."""
        p = self.problem

        def deg(values: np.ndarray) -> str:
            return ", ".join(f"{v:.4g}" for v in np.degrees(values) + 0.0)  # + 0.0: no "-0"

        lines = [
            f"state at failure ({self.state_source}): q0 = [{deg(p.q0)}] deg; dq0 = [{deg(p.dq0)}] deg/s; "
            f"ddq0 = [{deg(p.ddq0)}] deg/s^2"
        ]
        if self.from_rest:
            lines.append("  from rest: the halt is a reconfiguration from q0 to the halt configuration")
        return lines

    def summary(self) -> list[str]:
        """The lines ``jointlock halt`` prints."""
        res, p = self.motion, self.problem
        nums = list(p.model.joint_numbers)
        lines = unread_meshes_line(p.model) + self._collision_line() + self._attitude_line() + [
            f"{p.model.name}: healthy joints {nums}, locked: {locked_text(locked_deg(p.model))}, "
            f"base torque with {p.base} base about {MOMENT_TEXT[p.moment_about]}",
            f"halt configuration ({self.qf_source}): "
            + ", ".join(f"{v:.2f}" for v in np.degrees(p.qf))
            + " deg",
        ]
        hc = self.configuration
        if hc is not None:
            lines.append(
                f"  (CP with the {_jacobian_text(hc.base)}; --base sets the base of the disturbance torque only)"
            )
        if self.reachability is not None:
            lines.append(f"reachability: {self.reachability}")
        lines += self.state_lines()
        lim = self.limits
        lines += [
            f"halt time T = {p.T:g} s",
            f"speed limits: {limits_text(nums, lim.velocity, lim.velocity_source, 'deg/s')}",
            f"acceleration limits: {limits_text(nums, lim.acceleration, lim.acceleration_source, 'deg/s^2')}",
        ]
        if lim.torque is not None:
            lines.append(
                f"motor torque limits: {limits_text(nums, lim.torque, lim.torque_source, 'N m', degrees=False)}"
            )
        if lim.brake is not None:
            locked = [lj.number for lj in p.model.locked]
            lines.append(
                f"brake torque limits: {limits_text(locked, lim.brake, lim.brake_source, 'N m', degrees=False)}"
            )
        scale = K_UNIT_SCALE["deg/s^6"]
        if not res.feasible:
            lines += ["", "INFEASIBLE: " + infeasibility_message(res)] + self._minimum_T_clear_lines()
        elif res.per_joint:  # one k per joint: each within its own joint's interval
            lines += ["", f"feasible k per joint [deg/s^6]; solver {res.solver}"]
            for num, (lo, hi), kj in zip(nums, res.joint_intervals / scale, np.asarray(res.k) / scale):
                lines.append(f"  joint {num}: [{lo:.6g}, {hi:.6g}], k* = {kj:.6g}")
        else:
            lo, hi = res.k_interval / scale
            lines += [
                "",
                f"feasible k: [{lo:.6g}, {hi:.6g}] deg/s^6; solver {res.solver}",
            ]
            if res.k_segments is not None:
                stretches = ", ".join(f"[{a / scale:.6g}, {b / scale:.6g}]" for a, b in res.k_segments)
                lines.append(f"  of which the torque limits keep: {stretches} deg/s^6")
            lines.append(f"k* = {k_text(res)}")
            if res.k_optimum is not None:
                opt = res.k_optimum / scale
                cost = cast(float, res.objective_value) / float(halt_objective(p, res.k_optimum)) - 1.0
                lines.append(
                    f"  (the objective's own optimum is k = {opt:.6g} deg/s^6; this k costs {100 * cost:.2g} % more "
                    f"(at most {100 * res.settings['prefer_margin']:g} %) and keeps larger margins to the limits, "
                    "smallest first)"
                )
        if res.feasible and res.minimum_T is not None:
            lines.append(f"smallest halt time with a feasible k: T = {res.minimum_T:.3f} s")
            lines += self._minimum_T_clear_lines()
        sc = self.spacecraft_response()
        if sc is not None:
            label = (
                "spacecraft (free, zero momentum)"
                if p.base == "floating"
                else "spacecraft if it were free (zero momentum; the torque is for it held)"
            )
            lines += sc.summary(label)
        at = "k*" if res.feasible else "least-violating k (infeasible)"
        lines.append(
            f"global base torque: k = 0: {res.global_torque_k0:.4f} N m; {at}: {res.global_torque:.4f} N m "
            f"({_change_text(res)})"
        )
        if self.attitude_control().within is not False:  # (over capacity: the first line says so)
            lines.append(self.attitude_control().verdict())
        if self.task_completion is not None:
            lines += self.task_completion.summary()
        if p.objective != "mean_torque" and res.objective_value is not None:
            unit = OBJECTIVES[p.objective]
            lines.append(
                f"objective minimised: {OBJECTIVE_TEXT[p.objective]}: k = 0: {res.objective_value_k0:.4g} {unit}; "
                f"k*: {res.objective_value:.4g} {unit}"
            )
        if self.paper_scenario:  # 000's numbers belong to 000 §5's scenario on halt7 only
            lines.append(f"{_printed_text()} -- not reproduced, see docs/halt-motion.md")
        _, dq, ddq = res.check_trajectory()
        peak_v, peak_a = np.degrees(np.abs(dq).max(axis=0)), np.degrees(np.abs(ddq).max(axis=0))
        v_lim, a_lim = np.degrees(lim.velocity), np.degrees(lim.acceleration)
        m = self.margins()
        if self.fragile:
            lo, hi = res.feasible_stretch  # type: ignore[misc]
            lines.append(
                f"FRAGILE: the feasible stretch of k is {100 * (hi - lo) / abs(float(res.k)):.2g} % of k* wide: a small "
                "model or timing error breaks a limit (--margin keeps a share of each limit free)"
            )
        if self.margin:
            verb = "kept" if res.feasible else "asked (not kept: the halt is infeasible)"
            lines.append(
                f"margin {verb}: {100 * self.margin:g} % of each speed, acceleration and torque limit"
            )
        lines += self.notes
        lines += limits_table(nums, (peak_v, v_lim), (peak_a, a_lim), m, self.actuator_loads(), self.limits)
        name, value = self.binding_limit()
        if res.feasible:
            lines.append(
                f"binding limit: {name}, {_margin_text(value)}" + (" margin" if value >= AT_LIMIT else "")
            )
        return "\n".join(lines).split("\n")  # one entry per printed line

    def time_series(self) -> dict[str, np.ndarray]:
        """The halt on the objective's time grid: ``t`` (m,) [s]; ``q``, ``dq``, ``ddq`` (m, n)
        [rad, rad/s, rad/s^2]; base torque ``tau_b`` and ``tau_b_k0`` (at k = 0) (m, 3) [N m]."""
        res, p = self.motion, self.problem
        t = p.times()
        q, dq, ddq = res.trajectory(t)
        tb = base_torque_history(p, res.k, t, per_joint=res.per_joint)
        tb0 = base_torque_history(p, 0.0, t)
        return {"t": t, "q": q, "dq": dq, "ddq": ddq, "tau_b": tb, "tau_b_k0": tb0}

    def write(self, out: str | Path) -> list[str]:
        """Plots like 000 Figs. 8-9, base torque vs time, time series (CSV, NPZ) and
        result.json in ``out`` (:func:`~._files.write_halt_files`); returns the file names."""
        return write_halt_files(self, Path(out))
