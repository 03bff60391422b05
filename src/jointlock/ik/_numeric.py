"""Numerical IK of any arm: Levenberg-Marquardt (damped least squares) from several starts,
batched over targets and starts, optionally with the tool-x rotation gamma free (see
:mod:`jointlock.ik`)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .._random import resolve_rng
from ..errors import ConfigurationError
from ..kinematics import ChainState, chain_state, ee_pose, jacobian
from ..model import ArmModel, FloatArray
from ..spatial import pose_error, rot_x, rotation_log, turns_into_limits
from ._pose import EXACT_POSITION_TOL, EXACT_ROTATION_TOL, _as_poses


@dataclass(frozen=True)
class NumericIK:
    """Result of :func:`ik_numeric` for a batch of targets and starts.

    Attributes
    ----------
    q
        (..., S, n) movable-joint angles [rad] reached from each start.
    gamma
        (..., S) rotation about the tool x axis [rad] (0 unless ``free_tool_x``).
    position_error, rotation_error
        (..., S) [m], [rad] against the (gamma-rotated) target.
    exact
        (..., S) within :data:`EXACT_POSITION_TOL` / :data:`EXACT_ROTATION_TOL`.
    iterations
        Iterations run.
    seed
        The seed the random starts were drawn with (``rng`` an int, or the fresh seed drawn
        for ``rng=None``); None when ``rng`` was a Generator (see :mod:`jointlock._random`).
    """

    q: FloatArray
    gamma: FloatArray
    position_error: FloatArray
    rotation_error: FloatArray
    exact: NDArray[np.bool_]
    iterations: int
    seed: int | None = None


def _residual(model: ArmModel, q: FloatArray, target: FloatArray, length: float):
    state = chain_state(model, q)
    e_pos = target[..., :3, 3] - state.ee_position
    e_rot = rotation_log(target[..., :3, :3] @ np.swapaxes(state.ee_rotation, -1, -2))
    return np.concatenate([e_pos, length * e_rot], axis=-1), state


def ik_numeric(
    model: ArmModel,
    target: ArrayLike,
    *,
    q0: ArrayLike | None = None,
    starts: int = 8,
    rng: int | np.random.Generator | None = None,
    free_tool_x: bool = False,
    gamma_bounds: tuple[float, float] = (-math.pi, math.pi),
    length_scale: float = 1.0,
    max_iter: int = 200,
    tol: float = 1e-12,
) -> NumericIK:
    """Damped-least-squares / Levenberg-Marquardt IK from several starts, any arm.

    Parameters
    ----------
    model
        Any chain, locked joints included (``q`` is its healthy vector).
    target
        (..., 4, 4) poses [m].
    q0
        (..., S, n) or (S, n) or (n,) starts [rad]; ``starts`` random ones (uniform within
        the limits, drawn from ``rng``) are appended.
    starts
        Number of random starts.
    rng
        Seed or generator for the random starts (:mod:`jointlock._random`: ``None`` draws a
        fresh seed); the seed used is ``NumericIK.seed``.
    free_tool_x
        Treat ``gamma`` (rotation about the tool x axis, 002 eq. 18) as a free variable: the
        target becomes ``T Rx(gamma)``, ``gamma`` kept within ``gamma_bounds`` [rad].
    length_scale
        ``L`` [m]: the residual is ``(p_t - p, L log(R_t R^T))``.
    max_iter, tol
        Iteration cap; stop once every residual norm is below ``tol`` or no step improves.

    Returns
    -------
    NumericIK
    """
    t = _as_poses(target)
    batch = t.shape[:-2]
    n = model.dof
    gen, seed = resolve_rng(rng)
    q = _initial_q(model, batch, q0, starts, gen)
    s = q.shape[-2]
    tgt = np.broadcast_to(t[..., None, :, :], batch + (s, 4, 4))
    gamma = np.zeros(batch + (s,))
    glo, ghi = gamma_bounds

    def target_of(g: FloatArray) -> FloatArray:
        return tgt @ rot_x(g) if free_tool_x else tgt

    def clamp(qq: FloatArray) -> FloatArray:
        return np.clip(turns_into_limits(qq, model.lower, model.upper), model.lower, model.upper)

    q = clamp(q)
    e, state = _residual(model, q, target_of(gamma), length_scale)
    cost = np.einsum("...i,...i->...", e, e)
    lam = np.full(cost.shape, 1e-3)
    it = 0
    for it in range(1, max_iter + 1):  # noqa: B007 - iterations, not samples
        jac = jacobian(model, q, state=state)
        jac = np.concatenate([jac[..., :3, :], length_scale * jac[..., 3:, :]], axis=-2)
        if free_tool_x:
            x_axis = target_of(gamma)[..., :3, 0]
            col = np.concatenate([np.zeros(x_axis.shape), -length_scale * x_axis], axis=-1)
            jac = np.concatenate([jac, col[..., None]], axis=-1)
        jt = np.swapaxes(jac, -1, -2)
        h = jt @ jac
        g = np.einsum("...ij,...j->...i", jt, e)
        diag = np.einsum("...ii->...i", h) + 1e-9
        a = h + (lam[..., None] * diag)[..., None, :] * np.eye(h.shape[-1])
        step = np.linalg.solve(a, g[..., None])[..., 0]
        q_new = clamp(q + step[..., :n])
        g_new = np.clip(gamma + step[..., n], glo, ghi) if free_tool_x else gamma
        e_new, state_new = _residual(model, q_new, target_of(g_new), length_scale)
        cost_new = np.einsum("...i,...i->...", e_new, e_new)
        accept = cost_new < cost
        q = np.where(accept[..., None], q_new, q)
        gamma = np.where(accept, g_new, gamma)
        e = np.where(accept[..., None], e_new, e)
        cost = np.where(accept, cost_new, cost)
        state = _select_state(accept, state_new, state)
        lam = np.clip(np.where(accept, lam / 3.0, lam * 4.0), 1e-12, 1e8)
        small = np.max(np.abs(step), axis=-1) < 1e-14
        if np.all((cost < tol * tol) | (small & ~accept) | (lam >= 1e8)):
            break
    dp, dr = pose_error(target_of(gamma), ee_pose(model, q))
    exact = (dp <= EXACT_POSITION_TOL) & (dr <= EXACT_ROTATION_TOL)
    return NumericIK(q, gamma, dp, dr, exact, it, seed)


def _initial_q(
    model: ArmModel, batch: tuple[int, ...], q0: ArrayLike | None, starts: int, gen: np.random.Generator
) -> FloatArray:
    """(*batch, S, n) starts [rad]: ``q0`` (broadcast) followed by ``starts`` uniform ones
    within the limits as given (:meth:`ArmModel.angle_range`) drawn from ``gen``."""
    n = model.dof
    lo, hi = model.angle_range()
    parts = []
    if q0 is not None:
        q0a = np.asarray(q0, dtype=float)
        if q0a.shape[-1] != n:
            raise ConfigurationError(f"q0 must have shape (..., {n}); got {q0a.shape}")
        if q0a.ndim == 1:
            q0a = q0a[None]
        parts.append(np.broadcast_to(q0a, batch + q0a.shape[-2:]))
    if starts > 0:
        parts.append(gen.uniform(lo, hi, batch + (starts, n)))
    if not parts:
        raise ConfigurationError("ik_numeric needs q0 or starts > 0")
    return np.concatenate(parts, axis=-2).copy()


def _select_state(mask: FloatArray, a: ChainState, b: ChainState) -> ChainState:
    return ChainState.select(mask, a, b)
