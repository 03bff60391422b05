"""kappa(t) checked with the failure injected at every control step (:func:`verify_kappa`; 001 §4.4)."""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike

from ...errors import InfeasibleError, ScenarioError
from ...model import ArmModel, FloatArray
from ._engine import LIMIT_RTOL, _branched_runs, _ok, _Problem, _problem, _RunOut
from ._fit import KappaFit
from ._search import KappaSearch
from ._simulate import LimitReport, _limit_report, _table, improved_share, jump_reduction
from ._task import JumpScenario

#: The fixes of a fitted kappa(t) that :func:`verify_kappa` offers.
Fix = Literal["clip", "ramp", "clip+ramp"]

# -- verification ---------------------------------------------------------------------------


@dataclass(frozen=True)
class Verification:
    """kappa(t) checked with the failure injected at every control step (001 §4.4).

    Attributes
    ----------
    t
        (N,) failure times ``k dt`` [s].
    kappa
        (N,) the schedule used (after the fix, if any).
    jump_before, jump_after
        (N,) ``||dqdot||`` [rad/s] without (kappa = 0) and with the schedule.
    task_jump_noreplan_before, task_jump_noreplan_after
        (N,) ``||J_j qdot_j||`` [m/s], what the end effector would see without re-planning.
    task_jump_replan_max
        Largest ``||J dqdot||`` with re-planning [m/s] (round-off when ``J_r`` keeps full rank).
    mean_reduction
        ``1 - mean(after) / mean(before)``; NaN (undefined) when ``mean(before)`` is at most
        :data:`~jointlock.planning.jump.NO_JUMP_RAD_S`, round-off (:func:`jump_reduction`).
    share_improved
        Fraction of the failure steps with a jump (either way) where ``after < before``; NaN
        when none has one (:func:`improved_share`).
    limits
        Limits over the no-failure run and every run with a failure, with the schedule.
    healthy_ok
        The run without failure keeps every limit.
    limits_ok_per_step
        (N,) the motion with the failure at step k (healthy before, locked after) keeps
        every limit.
    broken_steps
        Failure times [s] at which a limit breaks.
    sampled_limits_ok
        Every sampled optimal kappa kept every limit (so a break is due to the fitted function).
    fix
        ``None``, ``"clip"`` (to the feasible band), ``"ramp"`` (rate-limited kappa) or
        ``"clip+ramp"``.
    scenario
        The settings.
    """

    t: FloatArray
    kappa: FloatArray
    jump_before: FloatArray
    jump_after: FloatArray
    task_jump_noreplan_before: FloatArray
    task_jump_noreplan_after: FloatArray
    task_jump_replan_max: float
    mean_reduction: float
    share_improved: float
    limits: LimitReport
    healthy_ok: bool
    limits_ok_per_step: np.ndarray
    broken_steps: FloatArray
    sampled_limits_ok: bool
    fix: str | None
    scenario: JumpScenario

    @property
    def limits_ok(self) -> bool:
        """Every limit kept, with or without a failure at any step."""
        return bool(self.healthy_ok and np.all(self.limits_ok_per_step))


def feasible_band(search: KappaSearch, t: ArrayLike) -> FloatArray:
    """(..., 2) feasible kappa interval interpolated linearly between the sampled failure
    times (held constant outside them); samples without a feasible kappa are skipped."""
    ok = np.all(np.isfinite(search.interval), axis=1)
    if not ok.any():
        raise InfeasibleError("feasible_band: no sampled failure time has a feasible kappa")
    ts = search.fail_times[ok]
    t = np.asarray(t, dtype=float)
    return np.stack([np.interp(t, ts, search.interval[ok, 0]), np.interp(t, ts, search.interval[ok, 1])], -1)


def ramp_schedule(kappa: ArrayLike, max_step: float) -> FloatArray:
    """Rate-limit a schedule: ``|kappa_{k+1} - kappa_k| <= max_step`` and ``|kappa'| <= |kappa|``
    (forward/backward min-envelope of the positive and negative parts, so a drop to 0 at a
    segment point starts early instead of happening in one step).

    The envelope of each part is computed in closed form (cumulative minima, no loop over the
    steps); ``kappa`` may carry leading batch axes, the steps run along the last one."""
    kap = np.asarray(kappa, dtype=float)
    shape = kap.shape
    kap = np.atleast_1d(kap)
    c = 0.5 * float(max_step)
    parts = []
    for part in (np.maximum(kap, 0.0), np.maximum(-kap, 0.0)):
        if math.isnan(c) or c == math.inf:  # no rate limit (as the step-by-step recursion)
            parts.append(part)
            continue
        # closed form of env[k] = min(part[k], env[k-1] + c) (forward) and then
        # env[k] = min(env[k], env[k+1] + c) (backward): cumulative minima of part[j] -+ c j;
        # the outer minimum keeps env <= part exactly despite round-off
        ramp = c * np.arange(kap.shape[-1])
        env = np.minimum(part, ramp + np.minimum.accumulate(part - ramp, axis=-1))
        back = np.flip(np.minimum.accumulate(np.flip(env + ramp, -1), axis=-1), -1) - ramp
        parts.append(np.minimum(env, back))
    return (parts[0] - parts[1]).reshape(shape)


def _step_limits(prob: _Problem, out: _RunOut) -> np.ndarray:
    """(B, N) the healthy record keeps every limit at the steps before k (prefix check)."""
    assert out.qd is not None and out.dev is not None  # a recorded run
    sc = prob.scenario
    slack = 1.0 + LIMIT_RTOL
    bad = np.abs(out.qd).max(-1) > sc.vmax * slack
    acc = np.abs(np.diff(out.qd, axis=1)).max(-1) / sc.dt
    bad[:, 1:] |= acc > sc.amax * slack
    if sc.rest_transitions:
        bad[:, 0] |= np.abs(out.qd[:, 0]).max(-1) / sc.dt > sc.amax * slack
    bad |= out.dev[:, :-1] > sc.eps * slack
    # failure at step k: steps 0..k-1 ran healthy; the acceleration into k is the jump (excluded
    # here, as bad[:, k] is not included) and the post-failure run checks k onwards
    before = np.concatenate(
        [np.zeros((bad.shape[0], 1), dtype=bool), np.cumsum(bad, axis=1)[:, :-1] > 0], axis=1
    )
    return ~before


def verify_kappa(
    model: ArmModel,
    scenario: JumpScenario | None,
    schedule: KappaFit | Callable[[FloatArray], FloatArray] | float,
    *,
    search: KappaSearch | None = None,
    fix: Fix | None = None,
    progress: Any = None,
) -> Verification:
    """Inject the failure at every control step with kappa(t) in the law (001 §4.4).

    Two healthy runs (kappa = 0 and kappa(t)) give the jumps before/after at all N steps;
    N post-failure runs (batched) check the limits with kappa(t).

    Parameters
    ----------
    model
        The arm.
    scenario
        Task, lock joint, limits (the search's when ``None`` and ``search`` is given).
    schedule
        :class:`KappaFit`, any callable ``t [s] -> kappa``, or a constant.
    search
        The :class:`KappaSearch` the schedule came from: needed for the fixes and for
        ``sampled_limits_ok``.
    fix
        Offered when the fitted function breaks a limit that the samples kept:
        ``"clip"`` clips kappa(t) to :func:`feasible_band`; ``"ramp"`` rate-limits it
        (:func:`ramp_schedule`) so that its change adds at most ``amax / 2`` of joint
        acceleration (``|dkappa| <= amax dt / (2 null_max)``), which removes the velocity step
        that kappa's drop to 0 at a segment point causes; ``"clip+ramp"`` does both.
    progress
        Optional progress reporter.
    """
    return _verify_fixes(model, scenario, schedule, search=search, fixes=(fix,), progress=progress)[0]


def _verify_fixes(
    model: ArmModel,
    scenario: JumpScenario | None,
    schedule: KappaFit | Callable[[FloatArray], FloatArray] | float,
    *,
    search: KappaSearch | None,
    fixes: Sequence[Fix | None],
    progress: Any = None,
) -> list[Verification]:
    """:func:`verify_kappa` of one schedule under several ``fixes``, in one pass: the kappa = 0
    run, one healthy run per fix and, branching off each, its N runs with the failure."""
    if scenario is None:
        if search is None:
            raise ScenarioError("verify_kappa: give a scenario or a search")
        scenario = search.scenario
    prob = _problem(model, scenario)
    t = prob.t[:-1]
    if callable(schedule):
        kap = np.asarray(schedule(t), dtype=float) * np.ones(prob.N)
    else:
        kap = np.full(prob.N, float(schedule))
    kaps = [_fixed(kap, fix, search, scenario, t) for fix in fixes]
    S, N = len(kaps), prob.N
    krows = np.stack([np.zeros(N), *kaps])
    steps = np.arange(N)
    healthy, post = _branched_runs(prob, krows, np.repeat(np.arange(1, S + 1), N), np.tile(steps, S), progress)
    table = _table(prob, krows, healthy)
    post_ok = _ok(prob, post).reshape(S, N)
    prefix_ok = _step_limits(prob, healthy)
    before = table.joint_jump_norm[0]
    sampled_ok = bool(search is not None and np.all(np.isfinite(search.kappa_opt)))
    results = []
    for j, (fix, kap_j) in enumerate(zip(fixes, kaps), start=1):  # one per schedule, a handful
        ok_steps = post_ok[j - 1] & prefix_ok[j]
        sel = np.arange(S + 1) == j
        post_sel = np.repeat(np.arange(1, S + 1), N) == j
        after = table.joint_jump_norm[j]
        results.append(
            Verification(
                t,
                kap_j,
                before,
                after,
                table.task_jump_noreplan[0],
                table.task_jump_noreplan[j],
                float(max(table.task_jump_replan[0].max(), table.task_jump_replan[j].max())),
                jump_reduction(before.mean(), after.mean()),
                improved_share(before, after),
                _limit_report(prob, [healthy, post], [sel, post_sel]),
                bool(table.healthy_limits_ok[j]),
                ok_steps,
                t[~ok_steps],
                sampled_ok,
                fix,
                scenario,
            )
        )
    return results


def _fixed(
    kap: FloatArray, fix: Fix | None, search: KappaSearch | None, scenario: JumpScenario, t: FloatArray
) -> FloatArray:
    """The (N,) schedule ``kap`` after ``fix`` (see :func:`verify_kappa`)."""
    if fix not in (None, "clip", "ramp", "clip+ramp"):
        raise ScenarioError(f"fix must be None, 'clip', 'ramp' or 'clip+ramp'; got {fix!r}")
    if fix is None:
        return kap
    if search is None:
        raise ScenarioError(f"verify_kappa: fix={fix!r} needs the search (feasible band, kappa scale)")
    if "clip" in fix:
        band = feasible_band(search, t)
        kap = np.clip(kap, band[:, 0], band[:, 1])
    if "ramp" in fix:
        kap = ramp_schedule(kap, scenario.amax * scenario.dt / (2.0 * search.null_max))
    return kap
