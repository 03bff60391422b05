"""Simulated runs and jump tables: :func:`simulate`, :func:`jump_table`, limit reports."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from ...errors import ScenarioError
from ...model import ArmModel, FloatArray
from ._engine import LIMIT_RTOL, _healthy_runs, _integrate, _kappa_rows, _ok, _Problem, _problem, _RunOut
from ._task import JumpScenario

# -- results --------------------------------------------------------------------------------


@dataclass(frozen=True)
class LimitReport:
    """Largest values reached against the scenario's limits (one run or a set of runs).

    Attributes
    ----------
    max_velocity, max_acceleration, max_deviation
        [rad/s], [rad/s^2] (failure steps excluded), [m].
    vmax, amax, eps
        The limits.
    ok
        All three kept (and no singular configuration met).
    """

    max_velocity: float
    max_acceleration: float
    max_deviation: float
    vmax: float
    amax: float
    eps: float
    ok: bool

    def broken(self) -> list[str]:
        """Human-readable list of the limits broken (degrees, millimetres)."""
        msgs = []
        slack = 1.0 + LIMIT_RTOL
        if self.max_velocity > self.vmax * slack:
            msgs.append(
                f"joint speed {math.degrees(self.max_velocity):.4g} deg/s > {math.degrees(self.vmax):.4g} deg/s"
            )
        if self.max_acceleration > self.amax * slack:
            msgs.append(
                f"joint acceleration {math.degrees(self.max_acceleration):.4g} deg/s^2 > "
                f"{math.degrees(self.amax):.4g} deg/s^2"
            )
        if self.max_deviation > self.eps * slack:
            msgs.append(f"position deviation {1e3 * self.max_deviation:.4g} mm > {1e3 * self.eps:.4g} mm")
        return msgs


def _limit_report(
    prob: _Problem, outs: Sequence[_RunOut], select: Sequence[np.ndarray | None]
) -> LimitReport:
    sc = prob.scenario
    vel = acc = dev = 0.0
    ok = True
    for o, sel in zip(outs, select):
        s = slice(None) if sel is None else sel
        vel = max(vel, float(np.max(o.max_vel[s], initial=0.0)))
        acc = max(acc, float(np.max(o.max_acc[s], initial=0.0)))
        dev = max(dev, float(np.max(o.max_dev[s], initial=0.0)))
        ok = ok and bool(np.all(_ok(prob, o)[s]))
    return LimitReport(vel, acc, dev, sc.vmax, sc.amax, sc.eps, ok)


@dataclass(frozen=True)
class Trajectory:
    """One simulated run (:func:`simulate`).

    Attributes
    ----------
    t
        (N + 1,) times [s].
    q
        (N + 1, n) joint angles [rad].
    qd
        (N, n) joint rates applied over ``[t_k, t_k + dt)`` [rad/s].
    x, x_nom
        (N + 1, 3) actual and nominal end-effector positions [m] (inertial frame).
    deviation
        (N + 1,) ``||x - x_nom||`` [m].
    healthy
        (N, n) boolean: joints movable at each step.
    kappa
        (N,) compensation coefficient used at each step.
    failures
        ``(joint number, time [s], step)`` of each lock.
    limits
        :class:`LimitReport` of the run.
    scenario
        The settings.
    """

    t: FloatArray
    q: FloatArray
    qd: FloatArray
    x: FloatArray
    x_nom: FloatArray
    deviation: FloatArray
    healthy: np.ndarray
    kappa: FloatArray
    failures: tuple[tuple[int, float, int], ...]
    limits: LimitReport
    scenario: JumpScenario


def simulate(
    model: ArmModel,
    scenario: JumpScenario | None = None,
    kappa: ArrayLike = 0.0,
    *,
    failures: Sequence[tuple[int, float]] = (),
) -> Trajectory:
    """Simulate the task with global compensation and locks injected at given times.

    Parameters
    ----------
    model
        The arm (full, all joints healthy at the start).
    scenario
        Task and limits; NOTES-001's default when omitted.
    kappa
        Constant coefficient, or (N,) schedule (one value per control step).
    failures
        ``(joint number, time [s])`` pairs; joints lock in sequence, each at the first
        control step at or after its time.  ``scenario.lock_joint`` is not used here.
    """
    sc = JumpScenario() if scenario is None else scenario
    prob = _problem(model, sc)
    krow = _kappa_rows(prob, np.asarray(kappa, dtype=float)[None] if np.ndim(kappa) == 1 else kappa)
    cols, steps, rec = [], [], []
    for number, t_fail in failures:
        c = prob.model.index_of(int(number))
        if c in cols:
            raise ScenarioError(f"failures: joint {number} is listed twice")
        k = int(sc.step_of(t_fail))
        cols.append(c)
        steps.append(k)
        rec.append((int(number), float(t_fail), k))
    if len(cols) >= prob.n:
        raise ScenarioError(f"failures: at least one of the {prob.n} joints must stay healthy")
    fail_steps = np.array([steps], dtype=int).reshape(1, -1) if steps else np.full((1, 1), prob.N + 1)
    fail_cols = cols if cols else [0]
    out = _integrate(
        prob, krow, prob.q0[None], None, np.zeros(1, dtype=int), fail_steps, fail_cols, record=1
    )
    healthy = np.ones((prob.N, prob.n), dtype=bool)
    for c, k in zip(cols, steps):
        healthy[k:, c] = False
    limits = _limit_report(prob, [out], [None])
    assert out.q is not None and out.qd is not None and out.x is not None and out.dev is not None
    return Trajectory(
        prob.t,
        out.q[0],
        out.qd[0],
        out.x[0],
        prob.x_nom,
        out.dev[0],
        healthy,
        krow[0],
        tuple(rec),
        limits,
        sc,
    )


@dataclass(frozen=True)
class JumpTable:
    """Velocity jumps at every control step for K healthy runs (one per kappa row).

    Failure of ``scenario.lock_joint`` at step ``k`` (time ``t[k]``); arrays are (K, N, ...).

    Attributes
    ----------
    t
        (N,) failure times ``k dt`` [s].
    kappa
        (K, N) coefficient schedules.
    joint_jump
        (K, N, n) ``qdot(t_f+) - qdot(t_f-)`` with re-planning (reduced law, padded) [rad/s].
    joint_jump_norm
        (K, N) its 2-norm, the objective of NOTES-001 [rad/s].
    joint_jump_noreplan
        (K, N) without re-planning only the locked joint stops: ``|qdot_j(t_f-)|`` [rad/s].
    task_jump_noreplan
        (K, N) ``||J_j qdot_j(t_f-)||`` [m/s].
    task_jump_replan
        (K, N) ``||J (qdot+ - qdot-)||`` [m/s]; zero (round-off) while ``J_r`` has full row rank.
    healthy_limits_ok
        (K,) the healthy run keeps every limit over the whole task.
    q
        (K, N + 1, n) healthy joint trajectories [rad].
    scenario
        The settings.
    """

    t: FloatArray
    kappa: FloatArray
    joint_jump: FloatArray
    joint_jump_norm: FloatArray
    joint_jump_noreplan: FloatArray
    task_jump_noreplan: FloatArray
    task_jump_replan: FloatArray
    healthy_limits_ok: np.ndarray
    q: FloatArray
    scenario: JumpScenario


def jump_table(model: ArmModel, scenario: JumpScenario | None = None, kappa: ArrayLike = 0.0) -> JumpTable:
    """Velocity jumps for a failure at every control step, from one healthy run per kappa.

    Parameters
    ----------
    model
        The arm.
    scenario
        Task, lock joint and limits (NOTES-001 default when omitted).
    kappa
        Number, (K,) constants or (K, N) schedules.
    """
    sc = JumpScenario() if scenario is None else scenario
    prob = _problem(model, sc)
    krows = _kappa_rows(prob, kappa)
    out = _healthy_runs(prob, krows)
    return _table(prob, krows, out)


def _table(prob: _Problem, krows: FloatArray, out: _RunOut) -> JumpTable:
    # a healthy run (_healthy_runs) records all of these
    assert out.q is not None and out.qd is not None and out.qd_plus is not None
    assert out.task_plus is not None and out.task_noreplan is not None
    jump = out.qd_plus - out.qd
    return JumpTable(
        prob.t[:-1],
        krows,
        jump,
        np.linalg.norm(jump, axis=-1),
        np.abs(out.qd[..., prob.lock_col]),
        np.linalg.norm(out.task_noreplan, axis=-1),
        np.linalg.norm(out.task_plus, axis=-1),
        _ok(prob, out),
        out.q,
        prob.scenario,
    )



#: A joint-rate jump at most this large is round-off, not a jump [rad/s]: the rates are below
#: ~1 rad/s, so their round-off is ~1e-16 rad/s; the jumps 001 is about are 1e-4..1e-1 rad/s.
#: (canadarm7's last joint, which does not move the tool point, "jumps" by 1e-18..1e-17 rad/s.)
NO_JUMP_RAD_S = 1e-12


def jump_reduction(before: ArrayLike, after: ArrayLike) -> Any:
    """Relative jump reduction ``1 - after / before`` (jumps in rad/s).

    Undefined -- NaN, written ``null`` in JSON and ``n/a`` in text -- where ``before`` is at
    most :data:`NO_JUMP_RAD_S`: without compensation there is no jump to reduce (e.g. a task
    that does not move, ``dx_m = [0, 0, 0]``, or a joint that cannot move the tool point), and
    a ratio would be 0/0, a ratio of round-off, or hide a jump the compensation made.
    A float for scalar inputs, an array otherwise; never warns or raises.
    """
    b = np.asarray(before, dtype=float)
    a = np.asarray(after, dtype=float)
    jump = b > NO_JUMP_RAD_S
    with np.errstate(divide="ignore", invalid="ignore"):
        out = np.where(jump, 1.0 - a / np.where(jump, b, 1.0), np.nan)
    return float(out) if out.ndim == 0 else out


def improved_share(before: ArrayLike, after: ArrayLike) -> float:
    """Share of the failure times with a jump (above :data:`NO_JUMP_RAD_S`, without or with
    compensation) whose jump the compensation made smaller: a jump it made where there was
    none counts as not improved.  NaN when no failure time has a jump either way."""
    b = np.atleast_1d(np.asarray(before, dtype=float))
    a = np.atleast_1d(np.asarray(after, dtype=float))
    jump = (b > NO_JUMP_RAD_S) | (a > NO_JUMP_RAD_S)
    return float(np.mean(a[jump] < b[jump])) if jump.any() else math.nan


def uncompensated_violations(model: ArmModel, scenario: JumpScenario | None = None) -> list[str]:
    """Which limits the task breaks with no compensation and no failure (kappa = 0), by how much
    and when: the first thing to know when no kappa is feasible (a task the healthy arm cannot
    follow within its limits leaves nothing for kappa to keep).  One phrase per broken limit,
    in degrees and millimetres; empty when the uncompensated task keeps every limit."""
    sc = JumpScenario() if scenario is None else scenario
    run = simulate(model, sc, 0.0)
    out = []
    rate = np.abs(run.qd)  # (N, n)
    acc = np.abs(np.diff(run.qd, axis=0)) / sc.dt  # (N - 1, n)
    for name, values, limit, unit, scale in (
        ("joint speed", rate, sc.vmax, "deg/s", math.degrees(1.0)),
        ("joint acceleration", acc, sc.amax, "deg/s^2", math.degrees(1.0)),
    ):
        over = values > limit * (1.0 + LIMIT_RTOL)
        if over.any():
            k, j = np.unravel_index(int(np.argmax(values)), values.shape)
            steps = np.flatnonzero(over.any(axis=1))
            out.append(
                f"{name} {values[k, j] * scale:.4g} {unit} > limit {limit * scale:.4g} {unit} (joint "
                f"{model.joint_numbers[j]}, over the limit from t = {run.t[steps[0]]:.3g} to {run.t[steps[-1] + 1]:.3g} s)"
            )
    dev = run.deviation
    if np.any(dev > sc.eps * (1.0 + LIMIT_RTOL)):
        steps = np.flatnonzero(dev > sc.eps * (1.0 + LIMIT_RTOL))
        out.append(
            f"path deviation {1e3 * dev.max():.4g} mm > {1e3 * sc.eps:.4g} mm (t = {run.t[steps[0]]:.3g} to "
            f"{run.t[steps[-1]]:.3g} s)"
        )
    return out
