"""One failure time (:func:`jump_at_time`) and the whole 001 pipeline (:func:`study_jump`)."""

from __future__ import annotations

import logging
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np

from ...errors import InfeasibleError
from ...model import ArmModel, FloatArray
from ._engine import _branched_runs, _kappa_rows, _problem
from ._fit import KappaFit, fit_kappa
from ._search import KappaSearch, search_kappa
from ._simulate import LimitReport, _limit_report, _table, jump_reduction, uncompensated_violations
from ._task import JumpScenario
from ._verify import Verification, _verify_fixes

log = logging.getLogger(__package__)


# -- one failure time and the whole study ----------------------------------------------------


@dataclass(frozen=True)
class JumpAtTime:
    """Everything about one failure time (001 §4.2).

    Attributes
    ----------
    fail_time
        Failure time [s] (a multiple of dt).
    kappa
        The coefficient used (optimal or given).
    interval
        (2,) feasible kappa interval (NaN when not searched or none).
    joint_jump_before, joint_jump_after
        (n,) ``dqdot`` with re-planning at kappa = 0 and at ``kappa`` [rad/s].
    jump_before, jump_after
        Their 2-norms [rad/s].
    joint_jump_noreplan_before, joint_jump_noreplan_after
        ``|qdot_j(t_f-)|`` [rad/s] (only the locked joint stops).
    task_jump_noreplan_before, task_jump_noreplan_after
        ``||J_j qdot_j||`` [m/s].
    task_jump_replan_before, task_jump_replan_after
        ``||J dqdot||`` [m/s] (zero while ``J_r`` has full row rank).
    limits_before, limits_after
        Limits of the healthy run plus the run with the failure.
    search
        The search (None when ``kappa`` was given).
    scenario
        The settings.
    infeasible
        With ``on_infeasible="report"``: why no kappa keeps the limits (the metrics are then those
        of kappa = 0, no compensation); None when one does.
    """

    fail_time: float
    kappa: float
    interval: FloatArray
    joint_jump_before: FloatArray
    joint_jump_after: FloatArray
    jump_before: float
    jump_after: float
    joint_jump_noreplan_before: float
    joint_jump_noreplan_after: float
    task_jump_noreplan_before: float
    task_jump_noreplan_after: float
    task_jump_replan_before: float
    task_jump_replan_after: float
    limits_before: LimitReport
    limits_after: LimitReport
    search: KappaSearch | None
    scenario: JumpScenario
    infeasible: str | None = None

    @property
    def reduction(self) -> float:
        """``1 - jump_after / jump_before``; NaN (undefined) when ``jump_before`` is 0, i.e.
        there is no jump to reduce (:func:`jump_reduction`)."""
        return jump_reduction(self.jump_before, self.jump_after)


def jump_at_time(
    model: ArmModel,
    scenario: JumpScenario | None = None,
    fail_time: float = 6.0,
    *,
    kappa: float | None = None,
    search_options: Mapping[str, Any] | None = None,
    progress: Any = None,
    on_infeasible: Literal["raise", "report"] = "raise",
) -> JumpAtTime:
    """Jump metrics at one failure time, with the optimal kappa (``kappa=None``) or a given one.

    When no kappa keeps every limit: ``on_infeasible="raise"`` raises
    :class:`~jointlock.errors.InfeasibleError` saying why; ``"report"`` returns the metrics of
    kappa = 0 (the uncompensated jump) with the reason in :attr:`JumpAtTime.infeasible` (an
    audit's cell: infeasible is an answer, and the cell's other jobs keep theirs)."""
    sc = JumpScenario() if scenario is None else scenario
    prob = _problem(model, sc)
    k = int(sc.step_of(fail_time))
    search = None
    interval = np.array([np.nan, np.nan])
    infeasible = None
    if kappa is None:
        search = search_kappa(model, sc, [k * sc.dt], progress=progress, **dict(search_options or {}))
        kappa = float(search.kappa_opt[0])
        interval = search.interval[0]
        if not np.isfinite(kappa):
            infeasible = (
                f"no kappa in [{search.probe_range[0]:.4g}, {search.probe_range[1]:.4g}] keeps every limit "
                f"with joint {sc.lock_joint} locking at {k * sc.dt:g} s; {_why_no_kappa(model, sc)}"
            )
            if on_infeasible != "report":
                raise InfeasibleError(infeasible)
            kappa = 0.0
    krows = _kappa_rows(prob, np.array([0.0, float(kappa)]))
    healthy, post = _branched_runs(prob, krows, np.array([0, 1]), np.array([k, k]))
    table = _table(prob, krows, healthy)
    reps = []
    for r in range(2):
        sel = np.zeros(2, dtype=bool)
        sel[r] = True
        reps.append(_limit_report(prob, [healthy, post], [sel, sel]))
    return JumpAtTime(
        k * sc.dt,
        float(kappa),
        interval,
        table.joint_jump[0, k],
        table.joint_jump[1, k],
        float(table.joint_jump_norm[0, k]),
        float(table.joint_jump_norm[1, k]),
        float(table.joint_jump_noreplan[0, k]),
        float(table.joint_jump_noreplan[1, k]),
        float(table.task_jump_noreplan[0, k]),
        float(table.task_jump_noreplan[1, k]),
        float(table.task_jump_replan[0, k]),
        float(table.task_jump_replan[1, k]),
        reps[0],
        reps[1],
        search,
        sc,
        infeasible,
    )


@dataclass(frozen=True)
class JumpStudy:
    """The full 001 pipeline: search over sampled failure times, kappa(t) fit, verification.

    Attributes
    ----------
    search, fit, verification
        The three stages (``search`` includes the failure times :func:`fit_kappa` added
        around the breaks of kappa(t)).
    verification_fixed
        Verification of the fixed kappa(t) (when asked, or automatically when the fitted
        kappa(t) breaks a limit and ``fix="auto"``).
    elapsed
        Wall time [s] per stage: ``{"search": ..., "fit": ..., "verify": ...}``.
    scenario
        The settings.
    """

    search: KappaSearch
    fit: KappaFit
    verification: Verification
    verification_fixed: Verification | None
    elapsed: dict[str, float] = field(default_factory=dict)
    scenario: JumpScenario = field(default_factory=JumpScenario)


def study_jump(
    model: ArmModel,
    scenario: JumpScenario | None = None,
    *,
    n_samples: int = 40,
    order: int = 5,
    max_order: int = 9,
    fix: Literal["auto", "clip", "ramp", "clip+ramp"] | None = "auto",
    search_options: Mapping[str, Any] | None = None,
    fit_options: Mapping[str, Any] | None = None,
    progress_factory: Callable[[int, str], Any] | None = None,
) -> JumpStudy:
    """Run the whole pipeline of 001 on a scenario (search, fit, verification at every step).

    Parameters
    ----------
    model
        The arm.
    scenario
        NOTES-001's default when omitted.
    n_samples
        Sampled failure times for the search (001: 40).
    order, max_order
        Polynomial order of kappa(t) (001: 5) and the largest order allowed.
    fix
        Also verify a fixed kappa(t) (see :func:`verify_kappa`): ``"auto"`` applies
        ``"clip+ramp"`` only when the fitted kappa(t) breaks a limit; ``None``: never.
    search_options
        Extra keyword arguments of :func:`search_kappa`.
    fit_options
        Extra keyword arguments of :func:`fit_kappa` (e.g. ``piecewise=False``).
    progress_factory
        ``(total, description) -> progress`` (e.g. :class:`jointlock.progress.Progress`).
    """
    sc = JumpScenario() if scenario is None else scenario
    N = sc.n_steps

    def bar(total: int, desc: str) -> Any:
        return progress_factory(total, desc) if progress_factory is not None else None

    t0 = time.perf_counter()
    p = bar(N, "kappa search")  # one update per control step of the grid pass
    search = search_kappa(model, sc, n_samples=n_samples, progress=p, **dict(search_options or {}))
    if p is not None:
        p.close()
    t1 = time.perf_counter()
    try:
        fit = fit_kappa(model, search, order=order, max_order=max_order, **dict(fit_options or {}))
    except InfeasibleError as exc:  # say why: usually the task itself, not the failure
        raise InfeasibleError(f"{exc}; {_why_no_kappa(model, sc)}") from None
    if fit.search is not None:  # failure times added around the breaks of kappa(t)
        search = fit.search
    t2 = time.perf_counter()
    p = bar(N, "verification")
    # the fixed schedule does not depend on the first verification: both in one pass ("auto"
    # drops the fixed one when the fit keeps every limit)
    fixes: tuple[Any, ...] = (None,) if fix is None else (None, "clip+ramp" if fix == "auto" else fix)
    ver, *more = _verify_fixes(model, sc, fit, search=search, fixes=fixes, progress=p)
    if p is not None:
        p.close()
    ver_c = more[0] if more and not (fix == "auto" and ver.limits_ok) else None
    t3 = time.perf_counter()
    log.info("jump study: search %.2fs fit %.2fs verify %.2fs", t1 - t0, t2 - t1, t3 - t2)
    return JumpStudy(search, fit, ver, ver_c, {"search": t1 - t0, "fit": t2 - t1, "verify": t3 - t2}, sc)


def _why_no_kappa(model: ArmModel, sc: JumpScenario) -> str:
    """Why no kappa keeps the limits, in words: the limits the task breaks without compensation
    and without a failure (so no compensation can help), else the jump at the failure itself."""
    broken = uncompensated_violations(model, sc)
    base = "the free-floating arm (generalized Jacobian)" if sc.base == "floating" else "the arm"
    if broken:
        return (
            f"with kappa = 0 and no failure, {base} already breaks its limits on this task: "
            + "; ".join(broken)
            + " -- a slower task (duration_s), a shorter line (dx_m) or other limits"
        )
    return f"{base} keeps its limits on this task without a failure: the jump at each failure time breaks them"
