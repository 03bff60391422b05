"""The objective (000 eq. 32): base disturbance torque by batched Newton-Euler and its
time average."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from ..._chain import kernel_input, kernel_link_arrays, kernel_root
from ...analysis.spacecraft import final_attitude_change_deg
from ...compiled import use_compiled
from ...dynamics import rnea
from ...errors import ScenarioError
from ...forward import COMPILED_MIN_BATCH
from ...model import FloatArray
from ._constants import CHUNK_SAMPLES
from ._problem import HaltProblem


def _simpson_mean(values: FloatArray, T: float) -> FloatArray:
    """Time average over the last axis of uniformly sampled values (odd count), Simpson's rule."""
    n = values.shape[-1]
    w = np.ones(n)
    w[1:-1:2] = 4.0
    w[2:-1:2] = 2.0
    return values @ w / (3.0 * (n - 1))


def _compiled_mean_torque(problem: HaltProblem, k: FloatArray, per_joint: bool) -> FloatArray | None:
    """:func:`global_base_torque` of the candidates ``k`` ((m,) shared or (m, n)) by one compiled
    call (:func:`jointlock._kernels.base_moment_norms`: the halts sampled, Newton-Euler and the
    norm, no array of samples) and Simpson's average, where :func:`~jointlock.dynamics.rnea`
    would run the compiled kernels for these samples (``problem.compiled``, or the compiled
    mode): the same numbers to the bit.  None where the numpy route runs, and where a
    sample's torque is not finite or its system inertia singular (the numpy route says
    which)."""
    t, base, shape = problem.profiles()  # the objective's grid
    compiled = problem.compiled
    if compiled is None:
        compiled = use_compiled(k.shape[0] * t.size, COMPILED_MIN_BATCH)
    if not compiled:
        return None
    from ... import _kernels  # numba on first use

    model, floating = problem.model, problem.base == "floating"
    links = (kernel_link_arrays(model, model.root_body.com if floating else np.zeros(3)),
             kernel_root(model) if floating else np.zeros(13))  # fmt: skip
    point = model.root_body.com if problem.moment_point is None else problem.moment_point
    kk = np.ascontiguousarray(k if per_joint else np.broadcast_to(k[:, None], (k.shape[0], problem.dof)), dtype=float)
    norms = np.empty((k.shape[0], t.size))
    samples = tuple(kernel_input(x) for x in (*base, *shape))
    rest = (kk, floating, *links[0], links[1], np.zeros(3), np.array(point, dtype=float), norms)
    with np.errstate(over="ignore", invalid="ignore"):
        bad = _kernels.base_moment_norms(*samples, *rest)
    if bad or not np.all(np.isfinite(norms)):
        return None
    return _simpson_mean(norms, problem.T)


def base_torque_history(
    problem: HaltProblem, k: ArrayLike, t: ArrayLike | None = None, *, per_joint: bool = False
) -> FloatArray:
    """Base disturbance torque ``tau_b(t; k)`` (000 eq. 31), (..., n_t, 3) [N m], root frame."""
    q, dq, ddq = problem.trajectory(k, t, per_joint=per_joint)
    return _base_moment(problem, q, dq, ddq)


def _base_moment(problem: HaltProblem, q: FloatArray, dq: FloatArray, ddq: FloatArray) -> FloatArray:
    """(..., 3) base disturbance torque [N m] of the motion ``q, dq, ddq`` (..., n)."""
    model, base, point = problem.model, problem.base, problem.moment_point
    return rnea(model, q, dq, ddq, base=base, moment_point=point, compiled=problem.compiled).base_moment


def global_base_torque(problem: HaltProblem, k: ArrayLike, *, per_joint: bool = False) -> FloatArray:
    """Global base disturbance torque of 000 eq. 32 for a batch of ``k``.

    ``tau_bar(k) = (1/T) int_0^T ||tau_b(t; k)||_2 dt``, Simpson's rule on
    ``problem.n_samples`` points.  Candidates are processed in chunks of at most
    :data:`CHUNK_SAMPLES` (candidate, time) samples, each chunk one batched :func:`rnea` call.

    Parameters
    ----------
    k
        (...) shared ``k`` [rad/s^6], or (..., n) with ``per_joint=True``.

    Returns
    -------
    (...) [N m].
    """
    k = np.asarray(k, dtype=float)
    if per_joint and (k.ndim == 0 or k.shape[-1] != problem.dof):
        raise ScenarioError(
            f"k with per_joint=True must have shape (..., {problem.dof}) (one k per healthy joint "
            f"{list(problem.model.joint_numbers)}) [rad/s^6]; got shape {k.shape}"
        )
    batch = k.shape[:-1] if per_joint else k.shape
    flat = k.reshape((-1, problem.dof) if per_joint else (-1,))
    t = problem.times()
    step = max(1, CHUNK_SAMPLES // t.size)
    out = np.empty(flat.shape[0])
    for start in range(0, flat.shape[0], step):  # chunks of candidates, not samples
        part = flat[start : start + step]
        fast = _compiled_mean_torque(problem, part, per_joint)
        if fast is None:
            torque = base_torque_history(problem, part, per_joint=per_joint)  # on the cached grid
            fast = _simpson_mean(np.linalg.norm(torque, axis=-1), problem.T)
        out[start : start + step] = fast
    return out.reshape(batch)


#: What the halt can minimise over k (:attr:`HaltProblem.objective`), and in which unit.
OBJECTIVES = {
    "mean_torque": "N m",  # 000 eq. 32: the time average of ||tau_b||
    "peak_torque": "N m",  # the largest ||tau_b|| over the halt
    "attitude_change": "deg",  # the free spacecraft's attitude change at the end of the halt
}


def _per_candidate(problem: HaltProblem, k: ArrayLike, per_joint: bool, reduce) -> FloatArray:
    """``reduce(q, dq, ddq, t)`` -> (chunk,) over the candidates ``k``, in chunks of at most
    :data:`CHUNK_SAMPLES` (candidate, time) samples."""
    k = np.asarray(k, dtype=float)
    batch = k.shape[:-1] if per_joint else k.shape
    flat = k.reshape((-1, problem.dof) if per_joint else (-1,))
    t = problem.times()
    step = max(1, CHUNK_SAMPLES // t.size)
    out = np.empty(flat.shape[0])
    for start in range(0, flat.shape[0], step):
        q, dq, ddq = problem.trajectory(flat[start : start + step], per_joint=per_joint)  # on the cached grid
        out[start : start + step] = reduce(q, dq, ddq, t)
    return out.reshape(batch)


def halt_objective(problem: HaltProblem, k: ArrayLike, *, per_joint: bool = False) -> FloatArray:
    """The quantity the halt minimises (:attr:`HaltProblem.objective`) for a batch of ``k``:
    ``"mean_torque"`` = :func:`global_base_torque` (000 eq. 32) [N m]; ``"peak_torque"`` = the
    largest ``||tau_b(t; k)||`` on the objective's grid [N m]; ``"attitude_change"`` = the free
    spacecraft's attitude change at ``t = T`` [deg]
    (:func:`~jointlock.analysis.spacecraft.final_attitude_change_deg`, zero momentum).
    Returns (...)."""
    if problem.objective == "mean_torque":
        return global_base_torque(problem, k, per_joint=per_joint)
    if problem.objective == "peak_torque":

        def peak(q, dq, ddq, t):
            tau = _base_moment(problem, q, dq, ddq)
            return np.linalg.norm(tau, axis=-1).max(axis=-1)

        return _per_candidate(problem, k, per_joint, peak)
    return _per_candidate(
        problem, k, per_joint, lambda q, dq, ddq, t: final_attitude_change_deg(problem.model, t, q, dq)
    )
