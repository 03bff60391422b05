"""Simulation engine: the batched explicit-Euler integrator of the law and its run outputs.

:func:`_integrate` steps B runs together (one :func:`~._control.law` call per control step for
all of them); a run may start late and branch off another (``parent``), which is how the runs
after a failure are stepped in the same pass as the healthy runs they leave
(:func:`_branched_runs`).  Per-run arrays are batch-first here, ``(B, ...)``; the law's inputs
are batch-last (:class:`~._frames._Frame`)."""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from dataclasses import dataclass, fields
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from ..._chain import kernel_input
from ...compiled import use_compiled
from ...derivatives import generalized_jacobian_derivatives
from ...errors import InfeasibleError, ModelError, ScenarioError, SingularityWarning
from ...forward import COMPILED_MIN_BATCH
from ...kinematics import base_jacobian, chain_state, generalized_jacobian, system_com
from ...model import ArmModel, FloatArray
from ...spatial import axis_angle_rotation
from ._control import SINGULAR_GRAM_RTOL
from ._frames import _FixedChain, _Frame
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
    chain: _FixedChain | None  # fixed base: its forward kinematics, constants folded

    def frame(self, q: FloatArray, rb: FloatArray | None) -> _Frame:
        """Task-space quantities of B runs at joint angles ``q`` (B, n) [rad] and base attitudes
        ``rb`` (B, 3, 3) (floating base only), batch last for :func:`law`."""
        if self.chain is not None:  # fixed base
            return self.chain.frame(q)
        assert rb is not None  # a floating base always carries its attitude
        model = self.model
        state = chain_state(model, q)
        jg = generalized_jacobian(model, q, state=state)[..., :3, :]
        djg = generalized_jacobian_derivatives(model, q)[..., :3, :]
        jb = base_jacobian(model, q, state)[..., 3:, :]
        rel = state.ee_position - system_com(model, q, state)
        x_bf = self.com0 + np.einsum("...ij,...j->...i", rb, rel)
        jac_bf = rb @ jg
        djac_bf = np.einsum("...ab,...ibk->...iak", rb, djg)
        return _Frame(
            np.moveaxis(x_bf, 0, -1), np.moveaxis(jac_bf, 0, -1), djac=np.moveaxis(djac_bf, 0, -1), base_jac=jb
        )

    def position(self, q: FloatArray, rb: FloatArray | None) -> FloatArray:
        """(B, 3) end-effector positions [m] (inertial frame)."""
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
        model,
        scenario,
        floating,
        model.dof,
        scenario.n_steps,
        t,
        path.x,
        xd_ff,
        q0,
        com0,
        lock_col,
        None if floating else _FixedChain.of(model),
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


#: Control steps per compiled call while a progress bar is shown (it moves between calls).
_STEPS_PER_UPDATE = 25
#: Steps in a row the compiled loop leaves to the reference at once (a Gram matrix that stays
#: singular: two joints left of a 3-D task) before :data:`_PYTHON_STEPS_AFTER_REFUSALS` steps
#: are Python's; then the compiled loop is tried again.
_REFUSALS_BEFORE_PYTHON = 8
_PYTHON_STEPS_AFTER_REFUSALS = 64


def _compiled_steps(
    prob: _Problem,
    kappa: FloatArray,
    q: FloatArray,
    qd_prev: FloatArray,
    out: _RunOut,
    first_run: np.ndarray,
    parent: np.ndarray | None,
    locks_at: np.ndarray,
    fail_steps: np.ndarray,
    jump_col: int | None,
    null_norm: bool,
    diverged_rate: float,
) -> Any:
    """:func:`_integrate`'s steps by the compiled loop (:func:`jointlock._kernels.integrate_steps`)
    on these runs' arrays, written in place: ``(k_begin, k_end) -> the first step not taken``
    (one with a singular Gram matrix, every run diverging or a NaN rate is left to the
    reference; a run diverging alone is stopped by the kernel, as the reference stops it).  None where
    the reference takes every step: a floating base (its frame and gradient are numpy's), or
    the compiled kernels not in use for this batch (:func:`jointlock.compiled.use_compiled`; a
    campaign's workers always use them)."""
    B, n = q.shape
    if prob.chain is None or not use_compiled(B, COMPILED_MIN_BATCH):
        return None
    if not all(a.dtype == np.float64 and a.flags.c_contiguous for a in (q, qd_prev)):
        return None  # the kernel writes them in place as float64 rows: the reference's arrays else
    from ... import _kernels  # numba on first use

    sc, chain = prob.scenario, prob.chain
    R = 0 if out.q is None else out.q.shape[0]

    def history(a: FloatArray | None, width: int) -> FloatArray:  # unrecorded: an empty stand-in
        return np.zeros((0, 1, width)) if a is None else a

    def ints(a: np.ndarray) -> np.ndarray:
        return np.ascontiguousarray(a, dtype=np.int64)

    fixed = (
        chain.link_h,
        chain.tool,
        kernel_input(prob.x_nom),
        kernel_input(prob.xd_nom),
        float(sc.kp),
        float(sc.dt),
        kernel_input(kappa),
        ints(first_run),
        np.full(B, -1, dtype=np.int64) if parent is None else ints(parent),
        ints(locks_at),
        ints(fail_steps),
        bool(sc.rest_transitions),
        -1 if jump_col is None or not R else int(jump_col),
        bool(null_norm),
        float(diverged_rate),
        SINGULAR_GRAM_RTOL,
    )
    state = (
        q,
        qd_prev,
        out.max_vel,
        out.max_acc,
        out.max_dev,
        out.min_w,
        out.max_null,
        history(out.q, n),
        history(out.qd, n),
        np.zeros((0, 1)) if out.dev is None else out.dev,
        history(out.x, 3),
        history(out.qd_plus, n),
        history(out.task_plus, 3),
        history(out.task_noreplan, 3),
    )

    def steps(k_begin: int, k_end: int) -> int:
        return int(_kernels.integrate_steps(k_begin, k_end, *fixed, *state))

    return steps


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
    parent: np.ndarray | None = None,
    record: int = 0,
    jump_col: int | None = None,
    k_stop: int | None = None,
    null_norm: bool = False,
    progress: Any = None,
) -> _RunOut:
    """Integrate B runs together, one batched evaluation of the law per control step.

    Parameters
    ----------
    prob
        The problem.
    kappa
        (B, N) compensation schedules [rad^2/(s m^3)].
    q_init, rb_init
        (B, n) start angles [rad] and (B, 3, 3) base attitudes (floating base; None: identity).
    k_start
        (B,) first step of each run, ascending: run ``b`` is idle before ``k_start[b]``.
    fail_steps, fail_cols
        (B, L) steps from which the columns ``fail_cols[l]`` (L,) are locked in run ``b``.
    parent
        (B,) run whose state run ``b`` takes at its first step (-1: its own ``q_init``,
        ``rb_init``); a parent must start no later than its child.  This steps the runs after
        a failure together with the healthy runs they branch from.
    record
        Number of leading runs (all starting at the first step) whose histories are kept.
    jump_col
        Also record, for the recorded runs, the law with this column locked as well (the
        rates right after it fails: ``qd_plus``, ``task_plus``, ``task_noreplan``).
    k_stop
        Stop before this step (default N).
    null_norm
        Keep the largest null-space term ``max_null`` (kappa = 1, no task velocity).
    progress
        ``update()`` once per control step.
    """
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
    diverged_rate = max(DIVERGED_RATE_MIN, DIVERGED_FACTOR * sc.vmax)
    out = _RunOut(np.zeros(B), np.zeros(B), np.zeros(B), np.full(B, np.inf), np.zeros(B))
    fail_steps = np.asarray(fail_steps, dtype=int).reshape(B, -1)
    one_lock = fail_steps.shape[1] == 1
    locks_at = np.full((B, n), np.iinfo(int).max)  # the step from which each joint is locked
    steps = np.broadcast_to(fail_steps, (B, len(fail_cols)))  # one column: every joint at once
    for l, c in enumerate(fail_cols):
        np.minimum(locks_at[:, c], steps[:, l], out=locks_at[:, c])
    R = min(int(record), B)
    if R:
        out.q = np.repeat(q_init[:R, None, :], N + 1, axis=1)
        out.qd = np.zeros((R, N, n))
        out.dev = np.zeros((R, N + 1))
        out.x = np.zeros((R, N + 1, 3))
        if rb is not None:  # prob.floating
            out.rb = np.repeat(rb[:R, None], N + 1, axis=1)
        if jump_col is not None:
            out.qd_plus = np.zeros((R, N, n))
            out.task_plus = np.zeros((R, N, 3))
            out.task_noreplan = np.zeros((R, N, 3))
    k0 = int(k_start.min()) if B else k_stop
    if R and np.any(k_start[:R] != k0):
        raise ValueError("_integrate: the recorded runs must all start at the first step")
    first_run = np.searchsorted(k_start, np.arange(k_stop + 1), side="left")  # first run started at k
    compiled = _compiled_steps(prob, kappa, q, qd_prev, out, first_run, parent, locks_at, fail_steps, jump_col,
                               null_norm, diverged_rate)  # fmt: skip

    def step(k: int) -> None:
        """Control step ``k`` of every run started by then (the reference of the kernel)."""
        m = int(first_run[k + 1])  # the runs started by now
        sl = slice(0, m)
        new = slice(int(first_run[k]), m)  # the runs starting at this step
        if parent is not None and new.start < m:
            src = parent[new]
            take = np.flatnonzero(src >= 0) + new.start
            q[take] = q[parent[take]]
            if rb is not None:
                rb[take] = rb[parent[take]]
        healthy = (locks_at[sl] > k).T  # (n, m)
        changed = fail_steps[sl, 0] == k if one_lock else np.any(fail_steps[sl] == k, axis=1)
        frame = prob.frame(q[sl], None if rb is None else rb[sl])
        err = prob.x_nom[k][:, None] - frame.x  # (3, m)
        xdc = prob.xd_nom[k][:, None] + sc.kp * err
        plus = None
        if R and jump_col is not None:
            plus = healthy[:, :R].copy()
            plus[jump_col] = False
        qd_t, w, null, qd_plus = frame.rates(healthy, xdc, kappa[sl, k], plus)
        qd = qd_t.T  # (m, n)
        dev = np.sqrt(np.einsum("rb,rb->b", err, err))
        np.maximum(out.max_dev[sl], dev, out=out.max_dev[sl])
        peak = np.abs(qd).max(-1)
        np.maximum(out.max_vel[sl], peak, out=out.max_vel[sl])
        np.minimum(out.min_w[sl], w, out=out.min_w[sl])
        if null_norm:
            np.maximum(out.max_null[sl], np.abs(null).max(0), out=out.max_null[sl])
        acc = np.abs(qd - qd_prev[sl]).max(-1) / dt
        check = ~changed
        check[new] = sc.rest_transitions and k == 0  # a run's first step: a jump, or the start from rest
        out.max_acc[sl] = np.where(check, np.maximum(out.max_acc[sl], acc), out.max_acc[sl])
        if R:
            _record_step(out, frame, k, R, qd, dev, qd_plus, jump_col)
        if m and peak.max() > diverged_rate:
            _stop_diverged(qd, kappa[sl, k], k * dt, diverged_rate)
        qd_prev[sl] = qd
        q[sl] += dt * qd
        if rb is not None:
            assert frame.base_jac is not None  # frame() gives it for a floating base
            omega = np.einsum("...ij,...j->...i", frame.base_jac, qd) * dt
            angle = np.linalg.norm(omega, axis=-1)
            axis = omega / np.where(angle > 0, angle, 1.0)[:, None]
            rb[sl] = rb[sl] @ axis_angle_rotation(axis, angle)
        if R:
            assert out.q is not None
            out.q[:, k + 1] = q[:R]
            if rb is not None:
                assert out.rb is not None
                out.rb[:, k + 1] = rb[:R]

    k = k0
    refused = 0  # steps in a row the compiled loop left to the reference at once
    python_until = k0  # after a run of refusals, Python's steps up to here
    while k < k_stop:
        if compiled is not None and k >= python_until:
            # every step in one call; with a progress bar a few at a time, so that it moves
            end = k_stop if progress is None else min(k + _STEPS_PER_UPDATE, k_stop)
            k_next = compiled(k, end)
            for _ in range(k_next - k) if progress is not None else ():
                progress.update()
            refused = refused + 1 if k_next == k else 0
            if refused == _REFUSALS_BEFORE_PYTHON:  # a lasting singularity: the kernel's work is wasted
                refused, python_until = 0, k_next + _PYTHON_STEPS_AFTER_REFUSALS
            k = k_next
            if k == end:
                continue
        step(k)  # a singular Gram matrix, every run diverging, NaN: this step by the reference
        k += 1
        if progress is not None:
            progress.update()
    if k_stop == N and B:
        x_end = prob.position(q, rb)
        dev_end = np.linalg.norm(prob.x_nom[N] - x_end, axis=-1)
        np.maximum(out.max_dev, dev_end, out=out.max_dev)
        if R:
            assert out.dev is not None and out.x is not None
            out.dev[:, N] = dev_end[:R]
            out.x[:, N] = x_end[:R]
        if sc.rest_transitions:
            np.maximum(out.max_acc, np.abs(qd_prev).max(-1) / dt, out=out.max_acc)
    if np.any(out.min_w < SINGULAR_W):
        warnings.warn(
            f"{int(np.sum(out.min_w < SINGULAR_W))} of {B} runs passed within w < {SINGULAR_W:g} of a "
            "singular configuration; they are marked infeasible",
            SingularityWarning,
            stacklevel=3,
        )
    return out


def _record_step(
    out: _RunOut,
    frame: _Frame,
    k: int,
    R: int,
    qd: FloatArray,
    dev: FloatArray,
    qd_plus: FloatArray | None,
    jump_col: int | None,
) -> None:
    """Store step ``k`` of the first ``R`` runs: rates ``qd`` (B, n) [rad/s], deviation ``dev``
    (B,) [m] and, with ``jump_col``, the rates ``qd_plus`` (n, R) with that joint locked too."""
    assert out.qd is not None and out.dev is not None and out.x is not None
    out.qd[:, k] = qd[:R]
    out.dev[:, k] = dev[:R]
    out.x[:, k] = frame.x[:, :R].T
    if jump_col is None:
        return
    assert qd_plus is not None
    assert out.qd_plus is not None and out.task_plus is not None and out.task_noreplan is not None
    jac = frame.jac[..., :R]
    out.qd_plus[:, k] = qd_plus.T
    out.task_plus[:, k] = np.einsum("rcb,cb->br", jac, qd_plus - qd[:R].T)
    out.task_noreplan[:, k] = -(jac[:, jump_col] * qd[:R, jump_col]).T


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
        record=K,
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


def _branched_runs(
    prob: _Problem, krows: FloatArray, kidx: np.ndarray, fsteps: np.ndarray, progress: Any = None
) -> tuple[_RunOut, _RunOut]:
    """The healthy runs of ``krows`` (K, N) and the runs after a failure of the lock joint at
    ``fsteps`` (R,), each branching off healthy run ``kidx`` (R,) at its failure step, stepped
    together in one pass (the same runs as :func:`_healthy_runs` then :func:`_post_runs`).

    Returns the healthy outputs (K runs, recorded) and the post-failure outputs (R runs, in the
    order of ``fsteps``, not recorded).
    """
    K, N = krows.shape[0], prob.N
    kidx = np.asarray(kidx, dtype=int)
    order = np.argsort(fsteps, kind="stable")  # the healthy runs start at 0, before every branch
    ks, fs = kidx[order], np.asarray(fsteps, dtype=int)[order]
    out = _integrate(
        prob,
        np.concatenate([krows, krows[ks]]),
        np.repeat(prob.q0[None], K + ks.size, axis=0),
        None,
        np.concatenate([np.zeros(K, dtype=int), fs]),
        np.concatenate([np.full(K, N + 1), fs])[:, None],
        [prob.lock_col],
        parent=np.concatenate([np.full(K, -1), ks]),
        record=K,
        jump_col=prob.lock_col,
        progress=progress,
    )
    scalars = [f.name for f in fields(_RunOut)[:5]]
    healthy = _RunOut(*(getattr(out, name)[:K] for name in scalars))
    for f in fields(_RunOut)[5:]:
        setattr(healthy, f.name, getattr(out, f.name))
    post = _RunOut(*(_unsort(getattr(out, name)[K:], order) for name in scalars))
    return healthy, post


def _unsort(values: FloatArray, order: np.ndarray) -> FloatArray:
    res = np.empty_like(values)
    res[order] = values
    return res
