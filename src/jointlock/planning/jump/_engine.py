"""Simulation engine: the batched explicit-Euler integrator of the law and its run outputs."""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from ...derivatives import cross3, generalized_jacobian_derivatives, linear_jacobian_derivatives
from ...errors import InfeasibleError, ModelError, ScenarioError, SingularityWarning
from ...kinematics import base_jacobian, chain_state, generalized_jacobian, system_com
from ...model import ArmModel, FloatArray
from ...spatial import axis_angle_rotation
from ._control import compensated_rates
from ._path import cartesian_trapezoid
from ._task import JumpScenario

#: Relative slack on the velocity/acceleration/deviation limits (round-off only) [-].
LIMIT_RTOL = 1e-9
#: Manipulability below which a run counts as singular (masked out of searches) [m^3].
SINGULAR_W = 1e-6


# -- simulation engine ----------------------------------------------------------------------


@dataclass
class _Problem:
    model: ArmModel
    scenario: JumpScenario
    floating: bool
    n: int
    N: int
    t: FloatArray
    x_nom: FloatArray  # (N+1, 3)
    xd_nom: FloatArray  # (N, 3) feed-forward per control step
    q0: FloatArray
    com0: FloatArray  # floating: system centre of mass at t=0 (inertial origin offset)
    lock_col: int

    def evaluate(
        self, q: FloatArray, rb: FloatArray | None
    ) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray | None]:
        """x (B,3), J (B,3,n), dJ (B,n,3,n), base angular Jacobian (B,3,n) or None."""
        model = self.model
        if not self.floating:
            state = chain_state(model, q)
            lin = cross3(state.axes, state.ee_position[..., None, :] - state.positions)  # (B, n, 3)
            jac = np.swapaxes(lin, -1, -2)
            djac = linear_jacobian_derivatives(state.axes, jac)
            return state.ee_position, jac, djac, None
        assert rb is not None  # a floating base always carries its attitude
        state = chain_state(model, q)
        jg = generalized_jacobian(model, q, state=state)[..., :3, :]
        djg = generalized_jacobian_derivatives(model, q)[..., :3, :]
        jb = base_jacobian(model, q, state)[..., 3:, :]
        rel = state.ee_position - system_com(model, q, state)
        x = self.com0 + np.einsum("...ij,...j->...i", rb, rel)
        jac = rb @ jg
        djac = np.einsum("...ab,...ibk->...iak", rb, djg)
        return x, jac, djac, jb

    def position(self, q: FloatArray, rb: FloatArray | None) -> FloatArray:
        state = chain_state(self.model, q)
        if not self.floating:
            return state.ee_position
        assert rb is not None  # a floating base always carries its attitude
        rel = state.ee_position - system_com(self.model, q, state)
        return self.com0 + np.einsum("...ij,...j->...i", rb, rel)


def _problem(model: ArmModel, scenario: JumpScenario) -> _Problem:
    if not isinstance(scenario, JumpScenario):
        raise ScenarioError(f"scenario must be a JumpScenario; got {type(scenario).__name__}")
    if len(scenario.q0) != model.dof:
        default = scenario.q0 == JumpScenario().q0
        raise ScenarioError(
            f"q0 has {len(scenario.q0)} angles but model {model.name!r} has {model.dof} movable joints "
            f"{list(model.joint_numbers)}"
            + (
                " (q0 is the default task's, NOTES-001's start for canadarm7: give a JumpScenario with "
                f"q0 = {model.dof} angles [rad], or in a task file q0_deg [deg])"
                if default
                else ""
            )
        )
    floating = scenario.base == "floating"
    if floating and not model.floating:
        raise ModelError(
            f"base='floating' needs a free-floating model (load_robot(..., base='floating')); "
            f"model {model.name!r} has a fixed base"
        )
    if not floating:
        model = model.fixed()
    lock_col = model.index_of(scenario.lock_joint)
    q0 = np.asarray(scenario.q0, dtype=float)
    state = chain_state(model, q0)
    com0 = system_com(model, q0, state) if floating else np.zeros(3)
    x0 = state.ee_position
    t = scenario.times
    path = cartesian_trapezoid(x0, scenario.dx, t, duration=scenario.duration, blend=scenario.blend)
    if scenario.feedforward == "step":
        xd_ff = np.diff(path.x, axis=0) / scenario.dt
    else:
        xd_ff = path.xd[:-1]
    return _Problem(
        model, scenario, floating, model.dof, scenario.n_steps, t, path.x, xd_ff, q0, com0, lock_col
    )


@dataclass
class _RunOut:
    max_vel: FloatArray  # (B,) max |qdot| [rad/s]
    max_acc: FloatArray  # (B,) max |qddot| [rad/s^2] (failure steps excluded)
    max_dev: FloatArray  # (B,) max ||x - x_nom|| [m]
    min_w: FloatArray  # (B,)
    max_null: FloatArray  # (B,) max |(I - J+J) grad w|_inf at kappa = 1
    q: FloatArray | None = None  # (B, N+1, n)
    rb: FloatArray | None = None  # (B, N+1, 3, 3)
    qd: FloatArray | None = None  # (B, N, n)
    dev: FloatArray | None = None  # (B, N+1)
    x: FloatArray | None = None  # (B, N+1, 3)
    qd_plus: FloatArray | None = None  # (B, N, n) reduced law at the same state
    task_plus: FloatArray | None = None  # (B, N, 3) J (qd_plus - qd)
    task_noreplan: FloatArray | None = None  # (B, N, 3) -J_j qd_j


#: A run has diverged when a joint rate exceeds this many times the speed limit (and at least
#: :data:`DIVERGED_RATE_MIN`): the resolved-rate law has left every physical range.
DIVERGED_FACTOR = 100.0
#: Smallest divergence threshold [rad/s] (~57,000 deg/s).
DIVERGED_RATE_MIN = 1e3


def _stop_diverged(qd: np.ndarray, kappa: np.ndarray, t: float, limit: float) -> np.ndarray:
    """(m,) runs of a step whose joint rates passed ``limit`` [rad/s] (a compensation
    coefficient far too large makes the resolved-rate law diverge).  They break the speed limit
    already, so they are infeasible; their rates are zeroed from here on (``qd`` in place) so
    that nothing overflows into inf/NaN.  When every run of the batch diverged -- a kappa
    given by the user, not one among a search's candidates -- raise :class:`InfeasibleError`
    saying so in one line."""
    peak = np.abs(qd).max(-1)
    diverged = peak > limit
    if diverged.all():
        run = int(np.argmax(peak))
        cause = (
            "the task itself is too fast for this arm (dx_m, duration_s, kp), even without compensation"
            if float(kappa[run]) == 0.0
            else "kappa is far too large for this task (the search keeps it within +-2 vmax / |grad w|)"
        )
        raise InfeasibleError(
            f"the motion diverges at t = {t:.6g} s: a joint rate reaches {peak[run]:.3g} rad/s (> 100x the "
            f"speed limit) with kappa = {float(kappa[run]):.6g} rad^2/(s m^3): {cause}"
        )
    qd[diverged] = 0.0
    return diverged


# Long on purpose: one explicit-Euler loop over all batched runs, whose per-step state is shared.
def _integrate(
    prob: _Problem,
    kappa: FloatArray,
    q_init: FloatArray,
    rb_init: FloatArray | None,
    k_start: np.ndarray,
    fail_steps: np.ndarray,
    fail_cols: Sequence[int],
    *,
    record: bool = False,
    jump_col: int | None = None,
    k_stop: int | None = None,
    null_norm: bool = False,
    progress: Any = None,
) -> _RunOut:
    """Integrate B runs together.  Runs must be sorted by ``k_start`` (ascending); run ``b``
    is idle before ``k_start[b]`` and then follows the law with the columns ``fail_cols[l]``
    locked from step ``fail_steps[b, l]`` on.  ``kappa`` is (B, N)."""
    sc = prob.scenario
    n, N, dt = prob.n, prob.N, sc.dt
    B = q_init.shape[0]
    k_stop = N if k_stop is None else min(int(k_stop), N)
    q = q_init.copy()
    rb = (
        None
        if not prob.floating
        else (np.broadcast_to(np.eye(3), (B, 3, 3)).copy() if rb_init is None else rb_init.copy())
    )
    qd_prev = np.zeros((B, n))
    max_vel = np.zeros(B)
    diverged_rate = max(DIVERGED_RATE_MIN, DIVERGED_FACTOR * sc.vmax)
    max_acc = np.zeros(B)
    max_dev = np.zeros(B)
    min_w = np.full(B, np.inf)
    max_null = np.zeros(B)
    fail_steps = np.asarray(fail_steps, dtype=int).reshape(B, -1)
    onehot = np.zeros((len(fail_cols), n), dtype=bool)
    for l, c in enumerate(fail_cols):
        onehot[l, c] = True
    out = _RunOut(max_vel, max_acc, max_dev, min_w, max_null)
    if record:
        out.q = np.repeat(q_init[:, None, :], N + 1, axis=1)
        out.qd = np.zeros((B, N, n))
        out.dev = np.zeros((B, N + 1))
        out.x = np.zeros((B, N + 1, 3))
        if rb is not None:  # prob.floating
            out.rb = np.repeat(rb[:, None], N + 1, axis=1)
        if jump_col is not None:
            out.qd_plus = np.zeros((B, N, n))
            out.task_plus = np.zeros((B, N, 3))
            out.task_noreplan = np.zeros((B, N, 3))
    k0 = int(k_start.min()) if B else k_stop
    for k in range(k0, k_stop):
        m = int(np.searchsorted(k_start, k, side="right"))
        sl = slice(0, m)
        failed = fail_steps[sl] <= k  # (m, L)
        mask = ~np.any(failed[:, :, None] & onehot[None], axis=1)  # (m, n)
        changed = np.any(fail_steps[sl] == k, axis=1)
        rbm = None if rb is None else rb[sl]
        x, jac, djac, jb = prob.evaluate(q[sl], rbm)
        err = prob.x_nom[k] - x
        xdc = prob.xd_nom[k] + sc.kp * err
        qd, w = compensated_rates(jac, djac, xdc, kappa[sl, k], mask)
        dev = np.linalg.norm(err, axis=-1)
        max_dev[sl] = np.maximum(max_dev[sl], dev)
        max_vel[sl] = np.maximum(max_vel[sl], np.abs(qd).max(-1))
        min_w[sl] = np.minimum(min_w[sl], w)
        if null_norm:
            null, _ = compensated_rates(jac, djac, np.zeros(3), np.ones(m), mask)
            max_null[sl] = np.maximum(max_null[sl], np.abs(null).max(-1))
        acc = np.abs(qd - qd_prev[sl]).max(-1) / dt
        first = k_start[sl] == k
        check = ~first & ~changed
        if sc.rest_transitions:
            check |= first & (k == 0)
        max_acc[sl] = np.where(check, np.maximum(max_acc[sl], acc), max_acc[sl])
        if record:
            assert out.qd is not None and out.dev is not None and out.x is not None
            out.qd[sl, k] = qd
            out.dev[sl, k] = dev
            out.x[sl, k] = x
            if jump_col is not None:
                mask2 = mask.copy()
                mask2[:, jump_col] = False
                qd2, _ = compensated_rates(jac, djac, xdc, kappa[sl, k], mask2)
                assert out.qd_plus is not None and out.task_plus is not None
                assert out.task_noreplan is not None
                out.qd_plus[sl, k] = qd2
                out.task_plus[sl, k] = np.einsum("...rc,...c->...r", jac, qd2 - qd)
                out.task_noreplan[sl, k] = -jac[..., jump_col] * qd[:, jump_col, None]
        if m and np.abs(qd).max() > diverged_rate:
            _stop_diverged(qd, kappa[sl, k], k * dt, diverged_rate)
        qd_prev[sl] = qd
        q[sl] = q[sl] + dt * qd
        if rb is not None:
            assert jb is not None  # evaluate() returns it for a floating base
            omega = np.einsum("...ij,...j->...i", jb, qd) * dt
            angle = np.linalg.norm(omega, axis=-1)
            axis = omega / np.where(angle > 0, angle, 1.0)[:, None]
            rb[sl] = rb[sl] @ axis_angle_rotation(axis, angle)
        if record:
            assert out.q is not None
            out.q[sl, k + 1] = q[sl]
            if rb is not None:
                assert out.rb is not None
                out.rb[sl, k + 1] = rb[sl]
        if progress is not None:
            progress.update()
    if k_stop == N and B:
        x_end = prob.position(q, rb)
        dev_end = np.linalg.norm(prob.x_nom[N] - x_end, axis=-1)
        max_dev[:] = np.maximum(max_dev, dev_end)
        if record:
            assert out.dev is not None and out.x is not None
            out.dev[:, N] = dev_end
            out.x[:, N] = x_end
        if sc.rest_transitions:
            max_acc[:] = np.maximum(max_acc, np.abs(qd_prev).max(-1) / dt)
    if np.any(min_w < SINGULAR_W):
        warnings.warn(
            f"{int(np.sum(min_w < SINGULAR_W))} of {B} runs passed within w < {SINGULAR_W:g} of a "
            "singular configuration; they are marked infeasible",
            SingularityWarning,
            stacklevel=3,
        )
    return out


def _kappa_rows(prob: _Problem, kappa: ArrayLike) -> FloatArray:
    """Constant kappa (K,) or schedules (K, N) -> (K, N), real and finite.  (A user's kappa is
    bounded where it is given -- ``jump.kappa``, ``--kappa``; the search's own candidates scale
    with ``vmax / |grad w|`` and may be large.)"""
    raw = np.asarray(kappa)
    if raw.dtype.kind not in "iuf":
        raise ScenarioError(f"kappa must be real numbers [rad^2/(s m^3)]; got dtype {raw.dtype}")
    arr = raw.astype(float)
    bad = ~np.isfinite(arr) | (np.abs(arr) > 1e100)  # 1e100: products with it still fit a float
    if np.any(bad):
        raise ScenarioError(f"kappa must be finite and within +-1e100 [rad^2/(s m^3)]; got {arr[bad].ravel()[0]:g}")
    if arr.ndim == 0:
        arr = arr[None]
    if arr.ndim == 1:
        return np.repeat(arr[:, None], prob.N, axis=1)
    if arr.ndim == 2 and arr.shape[1] == prob.N:
        return arr
    raise ScenarioError(
        f"kappa must be a number, (K,) values or (K, {prob.N}) schedules; got shape {arr.shape}"
    )


def _ok(prob: _Problem, out: _RunOut) -> np.ndarray:
    sc = prob.scenario
    slack = 1.0 + LIMIT_RTOL
    return (
        (out.max_vel <= sc.vmax * slack)
        & (out.max_acc <= sc.amax * slack)
        & (out.max_dev <= sc.eps * slack)
        & (out.min_w >= SINGULAR_W)
    )



def _healthy_runs(
    prob: _Problem, krows: FloatArray, *, k_stop: int | None = None, progress: Any = None
) -> _RunOut:
    K = krows.shape[0]
    return _integrate(
        prob,
        krows,
        np.repeat(prob.q0[None], K, axis=0),
        None,
        np.zeros(K, dtype=int),
        np.full((K, 1), prob.N + 1),
        [prob.lock_col],
        record=True,
        jump_col=prob.lock_col,
        k_stop=k_stop,
        progress=progress,
    )


def _post_runs(
    prob: _Problem,
    krows: FloatArray,
    healthy: _RunOut,
    kidx: np.ndarray,
    fsteps: np.ndarray,
    progress: Any = None,
) -> tuple[_RunOut, np.ndarray]:
    """Runs after a failure of the lock joint at ``fsteps`` (R,) with kappa rows ``kidx`` (R,),
    started from the healthy history.  Returns the outputs in sorted order and the order."""
    order = np.argsort(fsteps, kind="stable")
    ks, fs = kidx[order], fsteps[order]
    assert healthy.q is not None  # _healthy_runs records
    q_init = healthy.q[ks, fs]
    rb_init = None if healthy.rb is None else healthy.rb[ks, fs]
    out = _integrate(prob, krows[ks], q_init, rb_init, fs, fs[:, None], [prob.lock_col], progress=progress)
    return out, order


def _unsort(values: FloatArray, order: np.ndarray) -> FloatArray:
    res = np.empty_like(values)
    res[order] = values
    return res
