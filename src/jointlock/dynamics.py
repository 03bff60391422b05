"""Batched rigid-body dynamics (zero gravity unless stated).

Mass matrices here are built from the centre-of-mass Jacobians (composite form); the
recursive Newton-Euler algorithm and the base wrench of 000 eqs. 28-31 build on the same
chain state.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from .kinematics import ChainState, _world_inertias, chain_state, com_jacobians, com_positions
from .model import ArmModel, FloatArray
from .spatial import skew


def mass_matrix(model: ArmModel, q: ArrayLike, state: ChainState | None = None) -> FloatArray:
    """Joint-space mass matrix of the arm on a fixed base.

    ``M(q) = sum_i m_i Jv_i^T Jv_i + Jw_i^T I_i Jw_i`` over the links (root body excluded).

    Parameters
    ----------
    q
        (..., n) joint angles [rad].

    Returns
    -------
    (..., n, n) [kg m^2], symmetric positive definite when every link has mass and inertia.
    """
    s = chain_state(model, q) if state is None else state
    jcom = com_jacobians(model, q, s)
    masses = np.array([b.mass for b in model.bodies])
    inertia_w = _world_inertias(model, s)
    jv, jw = jcom[..., :3, :], jcom[..., 3:, :]
    return np.einsum("n,...nij,...nik->...jk", masses, jv, jv) + np.einsum(
        "...nij,...nil,...nlk->...jk", jw, inertia_w, jw
    )


def system_mass_matrix(model: ArmModel, q: ArrayLike, state: ChainState | None = None) -> FloatArray:
    """Mass matrix of the free-floating system in the coordinates ``(v_0, omega_0, dq)``
    (spacecraft centre-of-mass velocity, its angular velocity, joint rates; root frame).

    Returns
    -------
    (..., 6 + n, 6 + n) [kg, kg m, kg m^2 blocks]; the kinetic energy is
    ``0.5 x^T M x`` with ``x = [v_0; omega_0; dq]``.
    """
    s = chain_state(model, q) if state is None else state
    n = model.dof
    batch = s.positions.shape[:-2]
    coms = com_positions(model, q, s)
    jcom = com_jacobians(model, q, s)
    r0 = model.root_body.com
    a_lin = np.zeros(batch + (n, 3, 6 + n))
    a_lin[..., :, :, 0:3] = np.eye(3)
    a_lin[..., :, :, 3:6] = -skew(coms - r0)
    a_lin[..., :, :, 6:] = jcom[..., :3, :]
    a_ang = np.zeros(batch + (n, 3, 6 + n))
    a_ang[..., :, :, 3:6] = np.eye(3)
    a_ang[..., :, :, 6:] = jcom[..., 3:, :]
    masses = np.array([b.mass for b in model.bodies])
    inertia_w = _world_inertias(model, s)
    out = np.einsum("n,...nij,...nik->...jk", masses, a_lin, a_lin) + np.einsum(
        "...nij,...nil,...nlk->...jk", a_ang, inertia_w, a_ang
    )
    out[..., 0:3, 0:3] += model.root_body.mass * np.eye(3)
    out[..., 3:6, 3:6] += model.root_body.inertia
    return out


def generalized_inertia(model: ArmModel, q: ArrayLike) -> FloatArray:
    """Generalized inertia matrix of the free-floating arm with zero momentum,
    ``H* = H_m - H_bm^T H_b^{-1} H_bm`` (..., n, n) [kg m^2]."""
    m = system_mass_matrix(model, q)
    hb, hbm, hm = m[..., :6, :6], m[..., :6, 6:], m[..., 6:, 6:]
    return hm - np.swapaxes(hbm, -1, -2) @ np.linalg.solve(hb, hbm)
