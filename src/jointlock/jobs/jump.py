"""The velocity-jump study of seed 001 as one library call (``jointlock jump``).

Three modes, as the command has them:

* ``fail_at`` -- one failure time: the jump with and without compensation, the optimal kappa
  (or a given one) and its feasible interval, the limits kept (:func:`jump_at_time`);
* ``sweep`` -- sampled failure times: the optimal kappa per time, the fitted piecewise kappa(t)
  and its verification with the failure injected at every control step, plus a fix of kappa(t)
  when asked or needed (:func:`study_jump`);
* ``constant`` -- a constant kappa verified at every control step (:func:`verify_kappa`).

:func:`run_jump_study` runs one of them on an arm and a :class:`JumpScenario`; its
:class:`JumpJobResult` gives the command's JSON (:meth:`~JumpJobResult.to_dict`), text
(:meth:`~JumpJobResult.summary`) and files (:meth:`~JumpJobResult.write`).
:func:`jump_from_scenario` runs the ``[jump]`` job of a ``jointlock run`` scenario.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any, ClassVar, Literal

import numpy as np

from ..errors import ScenarioError
from ..io.files import atomic_write_bytes, atomic_write_json, atomic_write_text, figure_png
from ..model import ArmModel
from ..planning.jump import (
    JumpAtTime,
    JumpScenario,
    JumpStudy,
    LimitReport,
    Trajectory,
    Verification,
    jump_at_time,
    scenario_from_mapping,
    simulate,
    study_jump,
    verify_kappa,
)
from ..plots._common import offscreen_figure
from ..plots.jump import (
    KAPPA_UNIT,
    plot_joint_rates,
    plot_jump_vs_failure_time,
    plot_kappa_fit,
    plot_objective_vs_kappa,
    plot_position_deviation,
)
from ..progress import Progress
from ._common import JobResult

#: Largest polynomial order of kappa(t) (the scenario schema's ``jump.order`` cap).
MAX_ORDER = 9

#: Default number of sampled failure times of the sweep (001: 40).
DEFAULT_SWEEP = 40
#: Default polynomial order of kappa(t) (001: 5).
DEFAULT_ORDER = 5

Mode = Literal["fail_at", "sweep", "constant"]
Fix = Literal["auto", "clip", "ramp", "clip+ramp"]

#: Names of the figures ``write`` draws (PNG files in the output folder).
FIG_OBJECTIVE = "fig5_objective_vs_kappa.png"
FIG_JOINT_RATES = "fig6_joint_velocities.png"
FIG_DEVIATION = "fig7_position_deviation.png"
FIG_KAPPA_FIT = "fig8_kappa_fit.png"
FIG_JUMP = "fig9_jump_vs_failure_time.png"


# -- the job -------------------------------------------------------------------------------------


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

    @property
    def kappa_given(self) -> bool:
        """kappa was given, not searched."""
        return self.kappa is not None

    def to_dict(self) -> dict[str, Any]:
        """The JSON object of ``jointlock jump --json`` (jumps in rad/s, as the keys say)."""
        robot, sc = self.model.name, self.task
        if self.mode == "fail_at":
            assert self.at_time is not None
            return _single_json(robot, sc, self.at_time)
        assert self.verification is not None
        if self.mode == "constant":
            assert self.kappa is not None
            return _constant_json(robot, sc, self.kappa, self.verification)
        assert self.study is not None
        return _study_json(robot, sc, self.study)

    def summary(self) -> list[str]:
        """The lines ``jointlock jump`` prints (jumps in deg/s)."""
        return summary_lines(self.to_dict(), kappa_given=self.kappa_given)

    def runs(self) -> tuple[Trajectory, Trajectory, float]:
        """The runs of the figures: the failure with kappa = 0 and with the compensation, and
        the failure time [s] (``fail_at``: the failure time and kappa used; otherwise the
        verified schedule with the failure at the control step nearest the task's middle)."""
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
                names.append(_save(out, FIG_OBJECTIVE, ax.figure))
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
            names.append(_save(out, FIG_OBJECTIVE, ax.figure))
            ax = plot_kappa_fit(s, st.fit, self.task.duration, ax=_axes())
            names.append(_save(out, FIG_KAPPA_FIT, ax.figure))
        names += self._write_runs(out)
        fixed = st.verification_fixed if st is not None else None
        ax = plot_jump_vs_failure_time(ver, fixed, ax=_axes((7, 3.6)))
        names.append(_save(out, FIG_JUMP, ax.figure))
        return names

    def _write_runs(self, out: Path) -> list[str]:
        """fig6 (joint rates) and fig7 (position deviation) of :meth:`runs`."""
        r0, r1, t_fail = self.runs()
        fig = plot_joint_rates(self.model, self.task.lock_joint, r0, r1, t_fail, fig=offscreen_figure((10, 3.6)))
        names = [_save(out, FIG_JOINT_RATES, fig)]
        ax = plot_position_deviation(r0, r1, t_fail, self.task.eps, ax=_axes())
        return names + [_save(out, FIG_DEVIATION, ax.figure)]


def run_jump_study(
    model: ArmModel,
    task: JumpScenario | None = None,
    *,
    fail_at: float | None = None,
    sweep: int = DEFAULT_SWEEP,
    kappa: float | None = None,
    order: int = DEFAULT_ORDER,
    fix: Fix | None = "auto",
    single: bool = False,
    progress: bool = False,
) -> JumpJobResult:
    """The velocity jump of seed 001 when ``task.lock_joint`` locks (``jointlock jump``).

    Parameters
    ----------
    model
        The arm, ``model.dof`` movable joints (free-floating when ``task.base == "floating"``).
    task
        Start, straight line, timing, the joint that locks, limits, gain
        (:class:`~jointlock.planning.jump.JumpScenario`; NOTES-001's task when omitted).
    fail_at
        One failure time [s] in ``[0, task.duration)`` (mode ``fail_at``); ``None``: the sweep,
        or the constant kappa verified at every step when ``kappa`` is given.
    sweep
        Number of sampled failure times of the sweep (>= 1; used without ``fail_at`` and
        ``kappa``).
    kappa
        A constant kappa [rad^2/(s m^3)] instead of the search (with ``fail_at``: the jump at
        that time with it; without: mode ``constant``).
    order
        Polynomial order of kappa(t), 1..:data:`MAX_ORDER` (sweep with the search only).
    fix
        Fix of kappa(t) verified as well: ``"auto"`` (``"clip+ramp"`` only when kappa(t) breaks a
        limit), ``"clip"``, ``"ramp"``, ``"clip+ramp"`` or ``None`` (sweep with the search only).
    single
        One polynomial for kappa(t) (001's form) instead of one piece per branch of the optimum
        (sweep with the search only).
    progress
        Show progress bars on stderr (when it is a terminal).

    Returns
    -------
    JumpJobResult
        Its ``mode`` says which of the three ran.
    """
    sc = JumpScenario() if task is None else task
    _check_inputs(model, sc, fail_at=fail_at, sweep=sweep, kappa=kappa, order=order, fix=fix)

    def bar(total: int, desc: str) -> Progress:
        return Progress(total, desc, enabled=None if progress else False)

    given = None if kappa is None else float(kappa)
    if fail_at is not None:
        p = bar(2 * sc.n_steps, "kappa search")
        res = jump_at_time(model, sc, fail_at, kappa=given, progress=p)
        p.close()
        return JumpJobResult("fail_at", model, sc, at_time=res, kappa=given)
    if given is not None:
        ver = verify_kappa(model, sc, given)
        return JumpJobResult("constant", model, sc, verification=ver, kappa=given)
    study = study_jump(
        model,
        sc,
        n_samples=sweep,
        order=order,
        fix=fix,
        fit_options={"piecewise": not single},
        progress_factory=bar if progress else None,
    )
    return JumpJobResult("sweep", model, sc, study=study, verification=study.verification)


def _check_inputs(
    model: ArmModel,
    sc: JumpScenario,
    *,
    fail_at: float | None,
    sweep: int,
    kappa: float | None,
    order: int,
    fix: str | None,
) -> None:
    if len(sc.q0) != model.dof:
        raise ScenarioError(
            f"task.q0 has {len(sc.q0)} angles but model {model.name!r} has {model.dof} movable joints "
            f"{list(model.joint_numbers)}"
        )
    if kappa is not None and not math.isfinite(kappa):
        raise ScenarioError(f"kappa must be a finite number [{KAPPA_UNIT}]; got {kappa!r}")
    if fail_at is not None and not math.isfinite(fail_at):
        raise ScenarioError(f"fail_at must be a finite failure time [s]; got {fail_at!r}")
    if isinstance(sweep, bool) or not isinstance(sweep, (int, np.integer)) or sweep < 1:
        raise ScenarioError(f"sweep must be an integer >= 1; got {sweep!r}")
    if isinstance(order, bool) or not isinstance(order, (int, np.integer)) or not 1 <= order <= MAX_ORDER:
        raise ScenarioError(f"order must be an integer 1..{MAX_ORDER}; got {order!r}")
    if fix not in (None, "auto", "clip", "ramp", "clip+ramp"):
        raise ScenarioError(f"fix must be None, 'auto', 'clip', 'ramp' or 'clip+ramp'; got {fix!r}")


def jump_from_scenario(
    data: Mapping[str, Any], previous: Mapping[str, JobResult], *, progress: bool = False
) -> JumpJobResult:
    """Run the ``[jump]`` job of a resolved ``jointlock run`` scenario (``Scenario.data``).

    The task is :func:`jointlock.scenario.jump_fields` of ``data`` (limits from ``[limits]``, the
    locking joint from ``failure.joint``, the base from ``jump.base`` else the top level); the
    mode from ``jump.fail_at`` / ``jump.kappa`` / ``jump.sweep`` (with ``jump.order`` and
    ``jump.fix`` for the sweep), as ``jointlock run`` has always run ``jointlock jump``.
    ``previous`` is not used (the job needs no earlier result).
    """
    from ..robots import load_robot
    from ..scenario import jump_fields

    del previous
    t = data["jump"]
    sc = task_as_the_command_reads_it(scenario_from_mapping(jump_fields(data), source="[jump]"))
    model = load_robot(data["robot"], base=sc.base)
    if t["fail_at"] is not None:
        return run_jump_study(model, sc, fail_at=t["fail_at"], kappa=t["kappa"], progress=progress)
    if t["kappa"] is not None:
        return run_jump_study(model, sc, kappa=t["kappa"], progress=progress)
    fix = None if t["fix"] == "none" else t["fix"]
    return run_jump_study(model, sc, sweep=t["sweep"], order=t["order"], fix=fix, progress=progress)


def task_as_the_command_reads_it(task: JumpScenario) -> JumpScenario:
    """``task`` passed once through its file form (:meth:`JumpScenario.to_fields`, degrees) and
    back, as ``jointlock jump`` reads every task; converting radians -> degrees -> radians can
    move an angle or a limit by one unit in the last place, and once through it is stable."""
    return scenario_from_mapping(task.to_fields(), source="task")


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
        "kappa": r.kappa,
        "kappa_unit": KAPPA_UNIT,
        "kappa_interval": r.interval,
        "jump_before": r.jump_before,
        "jump_after": r.jump_after,
        "mean_reduction": r.reduction,
        "share_improved": float(r.jump_after < r.jump_before),
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


# -- text ----------------------------------------------------------------------------------------


def _less(reduction: float | None) -> str:
    """``"12.3 % less"``; ``"34x larger"`` (or ``"5.0 % larger"``) when the compensation makes
    the jump larger; ``"reduction n/a"`` when it is undefined (no jump before)."""
    if reduction is None or not math.isfinite(reduction):
        return "reduction n/a: no jump without compensation"
    if reduction >= 0:
        return f"{100 * reduction:.1f} % less"
    ratio = 1.0 - reduction  # after / before
    return f"{ratio:.3g}x larger" if ratio >= 2 else f"{-100 * reduction:.1f} % larger"


def _deg(rad_s: float) -> float:
    return math.degrees(rad_s)


def _kappa(value: float) -> str:
    return f"{value:.6g} {KAPPA_UNIT}"


def _interval_text(r: dict, given: bool) -> str:
    lo, hi = (np.nan, np.nan) if r["kappa_interval"] is None else r["kappa_interval"]
    lo = np.nan if lo is None else lo
    hi = np.nan if hi is None else hi
    if np.isfinite(lo) and np.isfinite(hi):
        return f"feasible [{lo:.4g}, {hi:.4g}]"
    return "given, feasible interval not searched" if given else "no feasible kappa"


def _points_text(points: list) -> str:
    """001's segment points [s]; NaN (kappa falls back to 0 over the whole task) -> none."""
    vals = [np.nan if p is None else float(p) for p in points]
    if not any(np.isfinite(vals)):
        return "none (kappa = 0 everywhere)"
    return ", ".join(f"{v:.3g} s" if np.isfinite(v) else "none" for v in vals)


def summary_lines(r: Mapping[str, Any], *, kappa_given: bool = False) -> list[str]:
    """The text of ``jointlock jump`` from its JSON object ``r`` (:meth:`JumpJobResult.to_dict`)."""
    sc = r["scenario"]
    lines = [
        f"{r['robot']}: joint {r['lock_joint']} locks; task {sc['duration_s']:g} s, dt {sc['dt_s']:g} s, "
        f"limits {sc['vmax_deg_s']:g} deg/s, {sc['amax_deg_s2']:g} deg/s^2, {1e3 * sc['eps_m']:g} mm, "
        f"base {sc['base']}"
    ]
    if r["mode"] == "fail_at":
        la = r["limits_after"]
        lines += [
            f"failure at {r['fail_time_s']:g} s, kappa = {_kappa(r['kappa'])} "
            f"({_interval_text(dict(r), kappa_given)})",
            f"joint jump ||dq||: {_deg(r['jump_before']):.5g} -> {_deg(r['jump_after']):.5g} deg/s "
            f"({_less(r['mean_reduction'])})",
            f"without re-planning: locked joint stops from {_deg(r['joint_jump_noreplan_before']):.5g} / "
            f"{_deg(r['joint_jump_noreplan_after']):.5g} deg/s; task jump {r['task_jump_noreplan_before_m_s']:.4g} / "
            f"{r['task_jump_noreplan_after_m_s']:.4g} m/s (re-planned: {r['task_jump_replan_after_m_s']:.2g} m/s)",
            f"limits kept: {la['ok']} (max {la['max_velocity_deg_s']:.3f} deg/s, "
            f"{la['max_acceleration_deg_s2']:.3f} deg/s^2, {la['max_deviation_mm']:.3f} mm)",
        ]
        return lines
    if "kappa_fit" in r:
        f = r["kappa_fit"]
        k = np.asarray([np.nan if v is None else v for v in r["kappa"]], dtype=float)
        feasible = int(np.sum(np.isfinite(k)))
        if feasible:
            lines.append(
                f"optimal kappa at {len(k)} failure times: {np.nanmin(k):.4g} .. {np.nanmax(k):.4g} "
                f"{KAPPA_UNIT} ({feasible} feasible)"
            )
        else:
            lines.append(f"no feasible kappa at any of the {len(k)} failure times")
        lines.append(
            f"kappa(t): order {f['order']}, SSR {f['ssr']:.3g} (threshold {f['threshold']:.3g}, "
            f"accepted {f['accepted']}), segment points {_points_text(f['segment_points_s'])}"
        )
        if len(f.get("breaks_s", [])):
            lines.append(
                f"  optimal kappa jumps at {', '.join(f'{b:.3g}' for b in f['breaks_s'])} s (piecewise fit)"
            )
        for seg in f.get("segments", []):
            lines.append(f"  segment {seg['start_s']:.3g}..{seg['end_s']:.3g} s: {seg['decision']}")
        for pc in f.get("pieces", []):
            lines.append(
                f"  piece {pc['start_s']:.3g}..{pc['end_s']:.3g} s: order {pc['order']}, {pc['n_samples']} samples, "
                f"SSR {pc['ssr']:.3g} (threshold {pc['threshold']:.3g}), {pc['source']}"
            )
    elif r["kappa"] is not None and np.ndim(r["kappa"]) == 0:
        lines.append(f"constant kappa = {_kappa(r['kappa'])}")
    for key in ("verification", "verification_fixed"):
        if key not in r:
            continue
        v = r[key]
        label = "kappa(t)" if v["fix"] is None else f"kappa(t) with fix {v['fix']}"
        lines.append(
            f"{label}, failure at every step: mean jump {_deg(v['mean_jump_before']):.5g} -> "
            f"{_deg(v['mean_jump_after']):.5g} deg/s ({_less(v['mean_reduction'])}), improved at "
            f"{100 * v['share_improved']:.1f} % of steps, limits kept: {v['limits_ok']}"
        )
        if not v["limits_ok"]:
            times = v["broken_failure_times_s"]
            lines.append(
                f"  broken: {'; '.join(v['limits']['broken'])}"
                + (
                    f" (failure times {times[0]:g}..{times[-1]:g} s)"
                    if len(times)
                    else " (run without failure)"
                )
            )
    return lines


# -- files ---------------------------------------------------------------------------------------


def verification_csv(ver: Verification) -> str:
    """``verification.csv``: per failure time, kappa used, jumps before/after [rad/s], limits kept."""
    rows = ["t_fail_s,kappa,jump_before_rad_s,jump_after_rad_s,limits_ok"]
    rows += [
        f"{t:.6g},{k:.9g},{b:.9g},{a:.9g},{int(ok)}"
        for t, k, b, a, ok in zip(ver.t, ver.kappa, ver.jump_before, ver.jump_after, ver.limits_ok_per_step)
    ]
    return "\n".join(rows) + "\n"


def _axes(figsize: tuple[float, float] = (6, 3.6)) -> Any:
    """One axis on a new off-screen figure (no pyplot)."""
    return offscreen_figure(figsize).add_subplot()


def _save(out: Path, name: str, fig: Any) -> str:
    atomic_write_bytes(out / name, figure_png(fig))
    return name


__all__ = [
    "KAPPA_UNIT",
    "MAX_ORDER",
    "JumpJobResult",
    "jump_from_scenario",
    "limits_json",
    "run_jump_study",
    "summary_lines",
    "task_as_the_command_reads_it",
    "verification_csv",
]
