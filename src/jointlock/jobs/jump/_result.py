"""The result of :func:`~jointlock.jobs.jump.run_jump_study`, :class:`JumpJobResult`: the JSON
of ``jointlock jump --json`` (``to_dict()``, built by the ``*_json`` functions here), its text
(``summary()``, :mod:`._text`) and the files of ``--out`` (``write()``)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, ClassVar, Literal

import numpy as np

from ...analysis.spacecraft import SpacecraftResponse, spacecraft_response
from ...collision import clearance, reports_clearance, unread_meshes_line
from ...errors import JointlockError
from ...io.files import atomic_write_json, atomic_write_text, csv_text, write_figure
from ...model import ArmModel
from ...planning.jump import (
    JumpAtTime,
    JumpScenario,
    JumpStudy,
    LimitReport,
    Trajectory,
    Verification,
    improved_share,
    simulate,
)
from ...plots._common import offscreen_figure
from ...plots.jump import (
    KAPPA_UNIT,
    plot_joint_rates,
    plot_jump_vs_failure_time,
    plot_kappa_fit,
    plot_objective_vs_kappa,
    plot_position_deviation,
)
from ...plots.motion import ArmMotion
from ...plots.spacecraft import plot_spacecraft_responses
from ...sweep import swept_clearance
from .._common import JobResult
from .._motions import jump_motions
from ._text import summary_lines

Mode = Literal["fail_at", "sweep", "constant"]

#: Names of the figures ``write`` draws (PNG files in the output folder).
FIG_OBJECTIVE = "fig5_objective_vs_kappa.png"
FIG_JOINT_RATES = "fig6_joint_velocities.png"
FIG_DEVIATION = "fig7_position_deviation.png"
FIG_KAPPA_FIT = "fig8_kappa_fit.png"
FIG_JUMP = "fig9_jump_vs_failure_time.png"
FIG_SPACECRAFT = "spacecraft_attitude.png"


@dataclass(frozen=True, eq=False)
class JumpJobResult(JobResult):
    """Result of :func:`run_jump_study` (one of its three modes).

    Attributes
    ----------
    mode
        ``"fail_at"`` (one failure time), ``"sweep"`` (sampled failure times, fitted kappa(t),
        verification) or ``"constant"`` (a constant kappa verified at every step; its JSON says
        ``"mode": "sweep"``, as the command's does).
    model
        The arm (free-floating when ``task.base == "floating"``).
    task
        The task, the joint that locks and the limits (SI units, radians).
    at_time
        ``fail_at``: the metrics at the failure time (:class:`JumpAtTime`; its ``search`` is
        ``None`` when kappa was given).
    study
        ``sweep``: search, fit, verification and fixed verification (:class:`JumpStudy`).
    verification
        ``sweep`` and ``constant``: kappa(t) (or the constant) checked with the failure at every
        control step (:class:`Verification`).
    kappa
        The given constant kappa [rad^2/(s m^3)] (``fail_at`` with a given kappa, ``constant``);
        ``None`` when it was searched.
    """

    job: ClassVar[str] = "jump"

    mode: Mode
    model: ArmModel
    task: JumpScenario
    at_time: JumpAtTime | None = None
    study: JumpStudy | None = None
    verification: Verification | None = None
    kappa: float | None = None
    _cache: dict = field(default_factory=dict, repr=False)  # the two runs, simulated once

    @property
    def kappa_given(self) -> bool:
        """kappa was given, not searched."""
        return self.kappa is not None

    def to_dict(self) -> dict[str, Any]:
        """The JSON object of ``jointlock jump --json`` (jumps in rad/s, as the keys say)."""
        robot, sc = self.model.name, self.task
        if self.mode == "fail_at":
            assert self.at_time is not None
            out = _single_json(robot, sc, self.at_time)
        elif self.mode == "constant":
            assert self.verification is not None and self.kappa is not None
            out = _constant_json(robot, sc, self.kappa, self.verification)
        else:
            assert self.study is not None
            out = _study_json(robot, sc, self.study)
        responses = self.spacecraft_responses()
        if responses is not None:
            out["spacecraft"] = {"fail_time_s": self.runs()[2], **{k: r.to_dict() for k, r in responses.items()}}
        out["clearance"] = self.clearance()
        return out

    def summary(self) -> list[str]:
        """The lines ``jointlock jump`` prints (jumps in deg/s)."""
        lines = summary_lines(self.to_dict(), kappa_given=self.kappa_given)
        clear = clearance_lines(self.clearance())
        lines = unread_meshes_line(self.model) + [line for line in clear if line.startswith("COLLIDES")] + lines
        lines += [line for line in clear if not line.startswith("COLLIDES")]
        responses = self.spacecraft_responses()
        if responses is not None:
            t_fail = self.runs()[2]
            for label, r in responses.items():
                lines += r.summary(f"spacecraft, failure at {t_fail:g} s, {label}")
        return lines

    def spacecraft_responses(self) -> dict[str, SpacecraftResponse] | None:
        """What the free spacecraft does in :meth:`runs` (free-floating tasks only, else None):
        ``{"uncompensated": ..., "compensated": ...}``, the attitude integrated over the control
        steps as the study's integrator does (:func:`~jointlock.analysis.spacecraft.
        spacecraft_response` with ``rates="hold"``)."""
        if self.task.base != "floating" or not self.model.floating:
            return None
        r0, r1, _ = self.runs()

        def response(run: Trajectory) -> SpacecraftResponse:
            dq = np.concatenate([run.qd, np.zeros((1, run.qd.shape[1]))])  # at rest after the task
            return spacecraft_response(self.model, run.t, run.q, dq, rates="hold")

        return {"uncompensated": response(r0), "compensated": response(r1)}

    def clearance(self) -> dict[str, dict[str, Any]] | None:
        """Clearance of the two runs of :meth:`runs` (issue 27: the 001 runs are collision-aware):
        for ``"uncompensated"`` and ``"compensated"``, the smallest signed distance between the
        arm's links and its spacecraft bus on the control steps (:func:`jointlock.collision.
        clearance`), its pair and time, and a certified bound between the steps
        (:func:`jointlock.sweep.swept_clearance`; the rates are held over each step, so the
        joints move linearly between them).  ``collides``: a pair overlaps that did not at the
        start, or one overlapping at the start goes deeper.  None for a model without shapes,
        or when a run diverges (a kappa far too large)."""
        if not reports_clearance(self.model):
            return None
        if "clearance" not in self._cache:
            try:
                r0, r1, _ = self.runs()
            except JointlockError:  # a kappa far too large: its run diverges (the result says so)
                self._cache["clearance"] = None
            else:
                self._cache["clearance"] = {
                    "uncompensated": _run_clearance(self.model, r0),
                    "compensated": _run_clearance(self.model, r1),
                }
        return self._cache["clearance"]

    def arm_motions(self) -> tuple[ArmModel, list[ArmMotion]]:
        """The two runs of :meth:`runs` to animate (:func:`~jointlock.jobs._motions.jump_motions`)."""
        return jump_motions(self)

    def runs(self) -> tuple[Trajectory, Trajectory, float]:
        """The runs of the figures: the failure with kappa = 0 and with the compensation, and
        the failure time [s] (``fail_at``: the failure time and kappa used; otherwise the
        verified schedule with the failure at the control step nearest the task's middle)."""
        if "runs" in self._cache:
            return self._cache["runs"]
        sc = self.task
        if self.mode == "fail_at":
            assert self.at_time is not None
            kappa: Any = self.at_time.kappa
            t_fail = self.at_time.fail_time
        else:
            assert self.verification is not None
            kappa = self.verification.kappa
            t_fail = float(np.round(sc.duration / 2 / sc.dt) * sc.dt)
        r0 = simulate(self.model, sc, 0.0, failures=[(sc.lock_joint, t_fail)])
        r1 = simulate(self.model, sc, kappa, failures=[(sc.lock_joint, t_fail)])
        self._cache["runs"] = (r0, r1, t_fail)
        return r0, r1, t_fail

    def write(self, out: str | Path) -> list[str]:
        """Write ``results.json`` (:meth:`to_dict`), ``verification.csv`` (sweep and constant
        modes) and the figures (PNG) into the folder ``out``; returns the names written."""
        out = Path(out)
        atomic_write_json(out / "results.json", self.to_dict())
        names = ["results.json"]
        if self.mode == "fail_at":
            res = self.at_time
            assert res is not None
            if res.search is not None:
                ax = plot_objective_vs_kappa(res.search, 0, title=f"failure at {res.fail_time:g} s", ax=_axes())
                names += _save(out, FIG_OBJECTIVE, ax.figure)
            return names + self._write_runs(out)
        ver = self.verification
        assert ver is not None
        atomic_write_text(out / "verification.csv", verification_csv(ver))
        names.append("verification.csv")
        st = self.study
        if st is not None:
            s = st.search
            mid = int(np.argmin(np.abs(s.fail_times - self.task.duration / 2)))
            ax = plot_objective_vs_kappa(s, mid, title=f"failure at {s.fail_times[mid]:g} s", ax=_axes())
            names += _save(out, FIG_OBJECTIVE, ax.figure)
            ax = plot_kappa_fit(s, st.fit, self.task.duration, ax=_axes())
            names += _save(out, FIG_KAPPA_FIT, ax.figure)
        names += self._write_runs(out)
        fixed = st.verification_fixed if st is not None else None
        ax = plot_jump_vs_failure_time(ver, fixed, ax=_axes((7, 3.6)))
        names += _save(out, FIG_JUMP, ax.figure)
        return names

    def _write_runs(self, out: Path) -> list[str]:
        """fig6 (joint rates) and fig7 (position deviation) of :meth:`runs`."""
        r0, r1, t_fail = self.runs()
        fig = plot_joint_rates(self.model, self.task.lock_joint, r0, r1, t_fail, fig=offscreen_figure((10, 3.6)))
        names = _save(out, FIG_JOINT_RATES, fig)
        ax = plot_position_deviation(r0, r1, t_fail, self.task.eps, ax=_axes())
        names += _save(out, FIG_DEVIATION, ax.figure)
        responses = self.spacecraft_responses()
        if responses is not None:
            title = f"spacecraft (free), joint {self.task.lock_joint} locks at {t_fail:g} s"
            names += _save(out, FIG_SPACECRAFT, plot_spacecraft_responses(responses, fig=offscreen_figure((7, 5)), title=title))
        atomic_write_text(out / "runs.csv", runs_csv(self.model, r0, r1))
        return names + ["runs.csv"] + self._write_motions(out)


#: Round-off allowed to a pair in contact at the start of a run [m] (two capsules of an elbow
#: touching along the whole run: distances of +-1e-16 m).
TOUCH_M = 1e-9


def _run_clearance(model: ArmModel, run: Trajectory) -> dict[str, Any]:
    """:meth:`JumpJobResult.clearance` of one run."""
    rates = np.concatenate([run.qd, np.zeros((1, run.qd.shape[1]))])  # at rest after the task
    steps = clearance(model, run.q)
    # no overlap, or none deeper than at the start (a pair touching there may touch to round-off)
    floor = np.minimum(0.0, steps.pair_distance[0]) - TOUCH_M

    def motion(t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        k = np.clip(np.searchsorted(run.t, t, side="right") - 1, 0, run.qd.shape[0] - 1)
        return run.q[k] + rates[k] * (t - run.t[k])[:, None], rates[k], np.zeros((t.size, rates.shape[1]))

    between = swept_clearance(
        model, motion, run.t, floor, sampled=(run.q, rates, np.zeros_like(rates), steps.pair_distance)
    )
    at = steps.worst()
    collides = bool(between.shortfall > 0)
    # the pair that breaks its floor most (on a step first, else between steps); when none does,
    # the smallest bound counted as Clearance.distance counts (a mounted pair only below its floor)
    at_steps = floor - between.grid_min  # > 0: below the floor on a control step
    worst = int(np.argmax(at_steps)) if at_steps.max() > 0 else int(np.argmax(floor - between.lower_bound))
    ranked = np.where(steps.mounted_pairs & (between.lower_bound >= floor - between.tolerance), np.inf, between.lower_bound)
    smallest = worst if collides else int(np.argmin(ranked))
    deepest = int(np.argmin(steps.pair_distance[:, worst]))
    return {
        "min_clearance_m": float(steps.distance[at]),
        "closest_pair": steps.pair_at(at),
        "time_s": float(run.t[at[0]]) if at else 0.0,
        "between_steps_min_m": float(between.lower_bound[smallest]),
        "between_steps_pair": between.names[smallest],
        "collides": collides,
        "colliding_pair": between.names[worst] if collides else None,
        "colliding_min_m": float(steps.pair_distance[deepest, worst]) if collides else None,
        "colliding_time_s": float(run.t[deepest]) if collides else None,
        "colliding_at_steps": bool(at_steps[worst] > 0) if collides else None,
    }


def clearance_lines(data: dict[str, dict[str, Any]] | None) -> list[str]:
    """The summary's clearance lines of :meth:`JumpJobResult.clearance` (a colliding run first)."""
    if not data:
        return []
    first: list[str] = []
    lines: list[str] = []
    for label, c in data.items():
        if c["collides"] and c["colliding_at_steps"]:
            into = f"{-c['colliding_min_m']:.3f} m into" if c["colliding_min_m"] < 0 else f"within {c['colliding_min_m']:.3f} m of"
            first.append(
                f"COLLIDES: the {label} run reaches {into} {c['colliding_pair']} at t = {c['colliding_time_s']:.3g} s"
            )
        elif c["collides"]:
            first.append(
                f"COLLIDES: between its control steps the {label} run may reach {-c['between_steps_min_m']:.3f} m into "
                f"{c['between_steps_pair']} (a bound on how far the links move in a step)"
            )
        lines.append(f"clearance of the {label} run: {c['min_clearance_m']:+.3f} m ({c['closest_pair']}, t = {c['time_s']:.3g} s)")
    return first + lines


# -- JSON ----------------------------------------------------------------------------------------


def limits_json(rep: LimitReport) -> dict[str, Any]:
    """A :class:`LimitReport` in the JSON's units (deg/s, deg/s^2, mm)."""
    return {
        "ok": rep.ok,
        "max_velocity_deg_s": math.degrees(rep.max_velocity),
        "max_acceleration_deg_s2": math.degrees(rep.max_acceleration),
        "max_deviation_mm": 1e3 * rep.max_deviation,
        "broken": rep.broken(),
    }


def _ver_json(v: Verification) -> dict:
    return {
        "fix": v.fix,
        "mean_jump_before": float(v.jump_before.mean()),
        "mean_jump_after": float(v.jump_after.mean()),
        "mean_reduction": v.mean_reduction,
        "share_improved": v.share_improved,
        "limits_ok": v.limits_ok,
        "healthy_run_ok": v.healthy_ok,
        "limits": limits_json(v.limits),
        "broken_failure_times_s": v.broken_steps,
        "sampled_kappas_kept_limits": v.sampled_limits_ok,
        "task_jump_replan_max_m_s": v.task_jump_replan_max,
    }


def _ver_series_json(v: Verification) -> dict:
    """The verification's jumps per failure time, its headline figures and :func:`_ver_json`."""
    return {
        "verification_t_s": v.t,
        "jump_before": v.jump_before,
        "jump_after": v.jump_after,
        "mean_reduction": v.mean_reduction,
        "share_improved": v.share_improved,
        "limits_ok": v.limits_ok,
        "verification": _ver_json(v),
    }


def _single_json(robot: str, sc: JumpScenario, r: JumpAtTime) -> dict:
    return {
        "robot": robot,
        "mode": "fail_at",
        "scenario": sc.to_fields(),
        "lock_joint": sc.lock_joint,
        "fail_time_s": r.fail_time,
        # no kappa keeps the limits (reported): the jump is the uncompensated one, there is no kappa
        "kappa": None if r.infeasible is not None else r.kappa,
        "kappa_unit": KAPPA_UNIT,
        "kappa_interval": r.interval,
        "jump_before": r.jump_before,
        "jump_after": r.jump_after,
        "mean_reduction": None if r.infeasible is not None else r.reduction,
        "share_improved": improved_share(r.jump_before, r.jump_after),
        "limits_ok": r.limits_after.ok,
        "joint_jump_before_rad_s": r.joint_jump_before,
        "joint_jump_after_rad_s": r.joint_jump_after,
        "joint_jump_noreplan_before": r.joint_jump_noreplan_before,
        "joint_jump_noreplan_after": r.joint_jump_noreplan_after,
        "task_jump_noreplan_before_m_s": r.task_jump_noreplan_before,
        "task_jump_noreplan_after_m_s": r.task_jump_noreplan_after,
        "task_jump_replan_before_m_s": r.task_jump_replan_before,
        "task_jump_replan_after_m_s": r.task_jump_replan_after,
        "limits_before": limits_json(r.limits_before),
        "limits_after": limits_json(r.limits_after),
        # only when no kappa keeps the limits and that was to be reported (an audit's cell)
        **({"infeasible": r.infeasible} if r.infeasible is not None else {}),
    }


def _study_json(robot: str, sc: JumpScenario, st: JumpStudy) -> dict:
    s, f, v = st.search, st.fit, st.verification
    out = {
        "robot": robot,
        "mode": "sweep",
        "scenario": sc.to_fields(),
        "lock_joint": sc.lock_joint,
        "fail_times_s": s.fail_times,
        "kappa": s.kappa_opt,
        "kappa_unit": KAPPA_UNIT,
        "kappa_interval": s.interval,
        "objective_opt": s.objective_opt,
        "objective_zero": s.objective_zero,
        "kappa_fit": {
            "order": f.order,
            "coefficients_tau": f.coefficients,
            "tau": "t / duration_s",
            "ssr": f.ssr,
            "threshold": f.threshold,
            "accepted": f.accepted,
            "segment_points_s": f.segment_points,
            "breaks_s": f.breaks,
            "segments": [{"start_s": a, "end_s": b, "decision": d} for a, b, d in f.segments],
            "pieces": [
                {
                    "start_s": pc.start,
                    "end_s": pc.end,
                    "order": pc.order,
                    "coefficients_u": pc.coefficients,
                    "u": f"(t - {pc.center:.6g}) / {pc.half_width:.6g}",
                    "ssr": pc.ssr,
                    "threshold": pc.threshold,
                    "accepted": pc.accepted,
                    "n_samples": pc.n_samples,
                    "source": pc.source,
                }
                for pc in (f.pieces or ())
            ],
        },
        **_ver_series_json(v),
        "elapsed_s": st.elapsed,
    }
    if st.verification_fixed is not None:
        out["verification_fixed"] = _ver_json(st.verification_fixed)
    return out


def _constant_json(robot: str, sc: JumpScenario, kappa: float, v: Verification) -> dict:
    return {
        "robot": robot,
        "mode": "sweep",
        "scenario": sc.to_fields(),
        "lock_joint": sc.lock_joint,
        "kappa": kappa,
        "kappa_unit": KAPPA_UNIT,
        **_ver_series_json(v),
    }


# -- files ---------------------------------------------------------------------------------------


def verification_csv(ver: Verification) -> str:
    """``verification.csv``: per failure time, kappa used, jumps before/after [rad/s], limits kept."""
    rows = ["t_fail_s,kappa,jump_before_rad_s,jump_after_rad_s,limits_ok"]
    rows += [
        f"{t:.6g},{k:.9g},{b:.9g},{a:.9g},{int(ok)}"
        for t, k, b, a, ok in zip(ver.t, ver.kappa, ver.jump_before, ver.jump_after, ver.limits_ok_per_step)
    ]
    return "\n".join(rows) + "\n"


def runs_csv(model: ArmModel, uncompensated: Trajectory, compensated: Trajectory) -> str:
    """``runs.csv``: the two runs of the figures on their time grid, ``t_s``, then per run
    (``k0_`` kappa = 0, ``comp_`` compensated) every joint's angle ``q<N>_deg`` [deg], the end
    effector ``x_m``, ``y_m``, ``z_m`` [m] (inertial frame) and the deviation ``deviation_mm``."""
    cols: dict[str, np.ndarray] = {"t_s": uncompensated.t}
    for tag, run in (("k0", uncompensated), ("comp", compensated)):
        cols.update({f"{tag}_q{n}_deg": np.degrees(run.q[:, j]) for j, n in enumerate(model.joint_numbers)})
        cols.update({f"{tag}_{c}_m": run.x[:, i] for i, c in enumerate("xyz")})
        cols[f"{tag}_deviation_mm"] = 1e3 * run.deviation
    return csv_text(cols)


def _axes(figsize: tuple[float, float] = (6, 3.6)) -> Any:
    """One axis on a new off-screen figure (no pyplot)."""
    return offscreen_figure(figsize).add_subplot()


def _save(out: Path, name: str, fig: Any) -> list[str]:
    """The figure as ``name`` (PNG) and its SVG in ``out``; returns both names."""
    return write_figure(fig, out, name)
