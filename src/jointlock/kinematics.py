"""Batched kinematics: forward kinematics, geometric Jacobians, free-floating generalized
Jacobian, momentum, and the virtual manipulator.

Every function takes joint arrays of shape ``(..., n)`` (any leading batch shape) and loops
only over the ``n`` joints, never over samples.  Results are expressed in the root (base)
frame.  For a fixed base that is the inertial frame.  For a free-floating base it is the
spacecraft frame at the instant considered: with the spacecraft at attitude ``R_b`` rotate
both 3-blocks of a twist by ``R_b`` to get inertial components (the matrices themselves do
not depend on the base pose).

Twists are ordered ``(v, omega)``: linear velocity of the stated reference point [m/s], then
angular velocity [rad/s].

The forward kinematics (:func:`chain_state`, :func:`ee_pose`, :func:`ee_positions`,
:func:`state_at`) lives in :mod:`jointlock.forward` and is re-exported here.  A function
taking ``q`` and ``state=`` uses the state only at the angles it was computed at
(:func:`state_at`).  The chain arithmetic shared with :mod:`jointlock.dynamics` lives in
:mod:`jointlock._chain`: this module never imports the dynamics.

:func:`jacobian` and :func:`generalized_jacobian` of large batches (from
:data:`jointlock.forward.COMPILED_MIN_BATCH` configurations, or ``compiled=True``) run in
compiled kernels (:mod:`jointlock._kernels`), chunk by chunk: memory holds the result and
little else.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal, cast

import numpy as np
from numpy.typing import ArrayLike

from . import forward as _fk
from ._chain import kernel_input, kernel_mass_program, kernel_program, momentum_matrix_soa
from .bounds import check_overflow
from .compiled import use_compiled
from .errors import ConfigurationError, ModelError
from .forward import DEFAULT_CHUNK, ChainState, chain_state, ee_pose, ee_positions, link_poses, state_at
from .model import ArmModel, FloatArray, as_joint_array

__all__ = [
    "DEFAULT_CHUNK",
    "ChainState",
    "VMWeighting",
    "VirtualManipulator",
    "base_jacobian",
    "chain_state",
    "com_jacobians",
    "com_positions",
    "ee_pose",
    "ee_positions",
    "generalized_jacobian",
    "jacobian",
    "link_poses",
    "momentum",
    "momentum_matrix",
    "state_at",
    "system_com",
    "virtual_link_vectors",
    "virtual_manipulator",
]


def com_positions(model: ArmModel, q: ArrayLike | None, state: ChainState | None = None) -> FloatArray:
    """(..., n, 3) centre of mass of every link in the root frame [m].

    ``state``: a :func:`chain_state` at ``q`` (optional; see :func:`state_at`)."""
    s = state_at(model, q, state)
    coms = np.array([b.com for b in model.bodies])  # (n, 3)
    return s.positions + np.einsum("...nij,nj->...ni", s.rotations, coms)


def _use_kernel(q: ArrayLike | None, frame: str, state: ChainState | None, compiled: bool | None) -> bool:
    """Whether a Jacobian is computed by the compiled kernels: asked for (``compiled=True``),
    or by default from :data:`jointlock.forward.COMPILED_MIN_BATCH` configurations without a
    precomputed state (which already holds the frames)."""
    if compiled is not None and not isinstance(compiled, (bool, np.bool_)):
        raise ConfigurationError(f"compiled must be True, False or None; got {compiled!r}")
    if compiled and (q is None or state is not None):
        raise ConfigurationError(
            "compiled=True computes the Jacobian from the joint angles q: give q, and no state"
        )
    if frame not in ("base", "ee") or compiled is False:
        return False  # the numpy path says what is wrong with frame
    if compiled is None:
        if state is not None or q is None:
            return False
        try:
            shape = np.shape(q)  # validated afterwards, by whichever path runs
        except ValueError:  # ragged: as_joint_array says so
            return False
        return len(shape) >= 1 and use_compiled(math.prod(shape[:-1]), _fk.COMPILED_MIN_BATCH)
    return True


def _kernel_jacobian(model: ArmModel, q: ArrayLike, generalized: bool, frame: str) -> FloatArray:
    """(..., 6, n) Jacobian by :func:`jointlock._kernels.jacobian` or
    :func:`jointlock._kernels.generalized_jacobian`, :data:`DEFAULT_CHUNK` configurations at a
    time (no frames of the whole batch are held); with ``frame="ee"`` each chunk is turned into
    the end-effector frame by the rotation of :func:`ee_pose`."""
    from . import _kernels  # numba is imported on first use, not with the package

    arr = as_joint_array(model, q)
    n = model.dof
    flat = kernel_input(arr.reshape(-1, n))
    out = np.empty((flat.shape[0], 6, n))
    rot, pos, tool, _skip = kernel_program(model)
    masses = kernel_mass_program(model) if generalized else None
    for s0 in range(0, flat.shape[0], DEFAULT_CHUNK):
        part = slice(s0, s0 + DEFAULT_CHUNK)
        if masses is None:
            _kernels.jacobian(flat[part], rot, pos, tool, out[part])
        else:
            _kernels.generalized_jacobian(flat[part], rot, pos, tool, *masses, out[part])
        if frame == "ee":
            out[part] = _rotate_twist(np.swapaxes(ee_pose(model, flat[part])[..., :3, :3], -1, -2), out[part])
    return out.reshape(arr.shape[:-1] + (6, n))


def jacobian(
    model: ArmModel,
    q: ArrayLike | None,
    *,
    frame: Literal["base", "ee"] = "base",
    state: ChainState | None = None,
    compiled: bool | None = None,
) -> FloatArray:
    """Geometric Jacobian of the end effector, fixed base.

    Parameters
    ----------
    model
        The arm.
    q
        (..., n) joint angles [rad].
    frame
        ``"base"``: components in the root frame (the inertial frame for a fixed base);
        ``"ee"``: components in the end-effector frame.
    state
        Precomputed :func:`chain_state` at ``q`` (optional, saves the forward kinematics).
        It must have been computed at ``q`` (:class:`~jointlock.errors.ConfigurationError`
        otherwise); with a state, ``q=None`` means ``state.q``.
    compiled
        True: the compiled kernel (:func:`jointlock._kernels.jacobian`; from ``q``, no
        state), in chunks, so that memory holds the result and little else; False: numpy
        from :func:`chain_state` (the reference the kernel is tested against); None
        (default): the kernel from :data:`jointlock.forward.COMPILED_MIN_BATCH` (200,000)
        configurations on, when no state is given.  Both agree to round-off.

    Returns
    -------
    (..., 6, n) mapping joint rates [rad/s] to the end-effector twist ``(v, omega)``, ``v``
    being the velocity of the end-effector frame's origin [m/s].  Column ``i`` is
    ``(z_i x (p_e - p_i), z_i)``.
    """
    if _use_kernel(q, frame, state, compiled):
        assert q is not None  # state is None here
        return _kernel_jacobian(model, q, generalized=False, frame=frame)
    s = state_at(model, q, state)
    z, p, pe = s.soa_axes, s.soa_positions, s.soa_ee_position
    d = pe[None] - p  # (n, 3, N)
    soa = np.empty((6, model.dof, pe.shape[-1]))
    soa[0] = z[:, 1] * d[:, 2] - z[:, 2] * d[:, 1]
    soa[1] = z[:, 2] * d[:, 0] - z[:, 0] * d[:, 2]
    soa[2] = z[:, 0] * d[:, 1] - z[:, 1] * d[:, 0]
    soa[3:] = np.swapaxes(z, 0, 1)
    jac = np.ascontiguousarray(np.moveaxis(soa, -1, 0)).reshape(s.batch_shape + (6, model.dof))
    if frame == "ee":
        jac = _rotate_twist(np.swapaxes(s.ee_rotation, -1, -2), jac)
    elif frame != "base":
        raise ConfigurationError(f"frame must be 'base' or 'ee'; got {frame!r}")
    return jac


def _rotate_twist(rot: FloatArray, jac: FloatArray) -> FloatArray:
    return np.concatenate([rot @ jac[..., :3, :], rot @ jac[..., 3:, :]], axis=-2)


def com_jacobians(model: ArmModel, q: ArrayLike | None, state: ChainState | None = None) -> FloatArray:
    """(..., n, 6, n): Jacobian of every link's centre-of-mass velocity and angular velocity
    (root frame), fixed base.  ``state``: a :func:`chain_state` at ``q`` (optional; see
    :func:`state_at`)."""
    s = state_at(model, q, state)
    coms = com_positions(model, s.q, s)
    n = model.dof
    lin = np.cross(s.axes[..., None, :, :], coms[..., :, None, :] - s.positions[..., None, :, :])
    ang = np.broadcast_to(s.axes[..., None, :, :], lin.shape).copy()
    mask = np.tril(np.ones((n, n), dtype=bool))  # body i moves with joints j <= i
    lin = np.where(mask[:, :, None], lin, 0.0)
    ang = np.where(mask[:, :, None], ang, 0.0)
    return np.concatenate([np.swapaxes(lin, -1, -2), np.swapaxes(ang, -1, -2)], axis=-2)


def _world_inertias(model: ArmModel, state: ChainState) -> FloatArray:
    inertias = np.array([b.inertia for b in model.bodies])  # (n, 3, 3)
    rot = state.rotations
    return rot @ inertias @ np.swapaxes(rot, -1, -2)


def momentum_matrix(model: ArmModel, q: ArrayLike | None, state: ChainState | None = None) -> FloatArray:
    """Momentum map of the free-floating system.

    ``state``: a :func:`chain_state` at ``q`` (optional; see :func:`state_at`).

    Returns
    -------
    (..., 6, 6 + n) matrix ``H = [H_b | H_bm]`` such that
    ``[P; L] = H @ [v_0; omega_0; dq]``, where ``v_0`` is the velocity of the spacecraft's
    centre of mass [m/s], ``omega_0`` its angular velocity [rad/s], ``P`` the total linear
    momentum [kg m/s] and ``L`` the total angular momentum about the root-frame origin
    [kg m^2/s], all in the root frame.

    Notes
    -----
    Built from composite quantities of the links outboard of each joint ``j`` (suffix sums,
    as in the composite-rigid-body algorithm): mass ``M_j``, first moment ``S_j = sum m_i c_i``
    and inertia about the root origin ``K_j = sum I_i + m_i (|c_i|^2 E - c_i c_i^T)``.  Joint
    ``j`` contributes ``z_j x (S_j - M_j p_j)`` to ``P`` and ``K_j z_j - S_j x (z_j x p_j)`` to
    ``L``.  Computed by :func:`jointlock._chain.momentum_matrix_soa` (composite inertias
    recursively in link frames, batch last).
    """
    s = state_at(model, q, state)
    flat = np.ascontiguousarray(s.q.reshape(-1, model.dof).T)
    soa = momentum_matrix_soa(model, flat, s.soa_rotations, s.soa_positions)
    return np.ascontiguousarray(np.moveaxis(soa, -1, 0)).reshape(s.batch_shape + soa.shape[:2])


def base_jacobian(model: ArmModel, q: ArrayLike | None, state: ChainState | None = None) -> FloatArray:
    """Spacecraft motion caused by the joints with zero total momentum (000 eq. 4, ``J_btheta``).

    ``state``: a :func:`chain_state` at ``q`` (optional; see :func:`state_at`).

    Returns
    -------
    (..., 6, n) mapping joint rates [rad/s] to the spacecraft twist ``(v_0, omega_0)``:
    velocity of its centre of mass [m/s] and angular velocity [rad/s], root frame;
    ``-H_b^{-1} H_bm`` with the blocks of :func:`momentum_matrix`.
    """
    h = momentum_matrix(model, q, state)
    try:
        return cast(FloatArray, -np.linalg.solve(h[..., :, :6], h[..., :, 6:]))  # numpy stubs: floating[Any]
    except np.linalg.LinAlgError:
        raise ModelError(
            f"model {model.name!r}: the free-floating system's inertia is singular (e.g. collinear "
            "point masses on a point-mass spacecraft); the base motion is undefined"
        ) from None


def generalized_jacobian(
    model: ArmModel,
    q: ArrayLike | None,
    *,
    frame: Literal["base", "ee"] = "base",
    state: ChainState | None = None,
    compiled: bool | None = None,
) -> FloatArray:
    """Generalized Jacobian of a free-floating arm with zero momentum (Umetani-Yoshida;
    000 eq. 5, ``J_F = J_theta + J_b J_btheta``).

    Parameters
    ----------
    model
        A free-floating arm (``model.floating``); a fixed-base model gives the ordinary
        Jacobian.
    q
        (..., n) joint angles [rad].
    frame
        ``"base"`` (root/spacecraft frame) or ``"ee"`` (end-effector frame) components.
    state
        Precomputed :func:`chain_state` at ``q`` (optional, saves the forward kinematics).
        It must have been computed at ``q`` (:class:`~jointlock.errors.ConfigurationError`
        otherwise); with a state, ``q=None`` means ``state.q``.
    compiled
        As for :func:`jacobian` (the kernel :func:`jointlock._kernels.generalized_jacobian`).

    Returns
    -------
    (..., 6, n) mapping joint rates to the end-effector twist ``(v, omega)`` in the inertial
    frame (components in the current spacecraft frame), the spacecraft moving so that
    linear and angular momentum stay zero.
    """
    if _use_kernel(q, frame, state, compiled):
        assert q is not None  # state is None here
        return _kernel_jacobian(model, q, generalized=model.floating, frame=frame)
    s = state_at(model, q, state)
    jm = jacobian(model, s.q, state=s)
    if model.floating:
        jb_theta = base_jacobian(model, s.q, s)
        arm = s.ee_position - model.root_body.com
        lin = jb_theta[..., :3, :] - np.cross(
            arm[..., None, :], np.swapaxes(jb_theta[..., 3:, :], -1, -2)
        ).swapaxes(-1, -2)
        jm = jm + np.concatenate([lin, jb_theta[..., 3:, :]], axis=-2)
    if frame == "ee":
        jm = _rotate_twist(np.swapaxes(s.ee_rotation, -1, -2), jm)
    elif frame != "base":
        raise ConfigurationError(f"frame must be 'base' or 'ee'; got {frame!r}")
    return jm


def momentum(model: ArmModel, q: ArrayLike, dq: ArrayLike, base_twist: ArrayLike | None = None) -> FloatArray:
    """Total momentum ``[P; L]`` (..., 6) [kg m/s, kg m^2/s] (``L`` about the root-frame
    origin, root frame) for joint rates ``dq`` (..., n) [rad/s] and spacecraft twist
    ``base_twist`` (..., 6) (centre-of-mass velocity, angular velocity); zero when omitted."""
    dq = as_joint_array(model, dq, "dq")
    h = momentum_matrix(model, q)
    nu = np.zeros(dq.shape[:-1] + (6,)) if base_twist is None else np.asarray(base_twist, dtype=float)
    full = np.concatenate([np.broadcast_to(nu, dq.shape[:-1] + (6,)), dq], axis=-1)
    with np.errstate(over="ignore", invalid="ignore"):
        out = np.einsum("...ij,...j->...i", h, full)
    check_overflow([out], "momentum", dq=dq, base_twist=nu)
    return out


def system_com(model: ArmModel, q: ArrayLike | None, state: ChainState | None = None) -> FloatArray:
    """(..., 3) centre of mass of links plus root body, root frame [m].  ``state``: a
    :func:`chain_state` at ``q`` (optional; see :func:`state_at`)."""
    s = state_at(model, q, state)
    masses = np.array([b.mass for b in model.bodies])
    coms = com_positions(model, s.q, s)
    total = masses.sum() + model.root_body.mass
    if total <= 0:
        raise ModelError(f"model {model.name!r} has no mass: the system centre of mass is undefined")
    return (np.einsum("n,...ni->...i", masses, coms) + model.root_body.mass * model.root_body.com) / total


# -- virtual manipulator (Vafa & Dubowsky; 004 §2-3) ----------------------------------------


VMWeighting = Literal["vafa-dubowsky", "segment"]


def virtual_link_vectors(model: ArmModel, *, weighting: VMWeighting = "vafa-dubowsky") -> FloatArray:
    """Virtual link vectors of the virtual manipulator, each in its own body frame.

    With ``mu_k = (m_0 + ... + m_k) / M`` (``m_0`` the spacecraft), ``a_k`` the vector from
    the origin of link frame ``k`` (on joint ``k``'s axis) to the centre of mass of link
    ``k`` and ``b_k`` from that centre of mass to the origin of frame ``k+1`` (``b_0``:
    spacecraft centre of mass to frame 1; ``b_n``: to the end effector):

    * ``"vafa-dubowsky"`` (default, exact): ``V_0 = mu_0 b_0``,
      ``V_k = mu_{k-1} a_k + mu_k b_k``.  Then ``p_e = r_g + sum_k R_k V_k`` holds exactly for
      any placement of the frame origins along the joint axes.
    * ``"segment"``: 004's formula (text under its eq. 3, Table 2): the whole segment of link
      ``k`` scaled by ``mu_k``, ``V_k = mu_k (a_k + b_k)``.  It reproduces 004's printed
      virtual lengths on ``canadarm7`` but is not the exact virtual manipulator (it moves the
      virtual end point by up to 0.13 m there) and depends on where the frame origins sit
      on the joint axes.

    A fixed base is the limit ``m_0 -> inf``: every ``mu_k = 1`` and the virtual arm is the
    real one.

    Returns
    -------
    (n + 1, 3) [m]; row 0 in the root frame, row ``k`` in link frame ``k``.
    """
    if weighting not in ("vafa-dubowsky", "segment"):
        raise ConfigurationError(f"weighting must be 'vafa-dubowsky' or 'segment'; got {weighting!r}")
    n = model.dof
    masses = np.array([model.root_body.mass] + [b.mass for b in model.bodies])
    if model.floating:
        mu = np.cumsum(masses) / masses.sum()
    else:
        mu = np.ones(n + 1)
    joint_points = [j.placement[:3, 3] for j in model.joints] + [model.tool[:3, 3]]
    vectors = np.empty((n + 1, 3))
    vectors[0] = mu[0] * (joint_points[0] - model.root_body.com)
    for k in range(1, n + 1):
        com = model.bodies[k - 1].com
        if weighting == "segment":
            vectors[k] = mu[k] * joint_points[k]
        else:
            vectors[k] = mu[k - 1] * com + mu[k] * (joint_points[k] - com)
    return vectors


@dataclass(frozen=True)
class VirtualManipulator:
    """The virtual manipulator at a batch of configurations (root frame, spacecraft attitude
    held at the root frame's).

    Attributes
    ----------
    ground
        (..., 3) virtual ground = system centre of mass [m].
    joint_positions
        (..., n, 3) virtual joint positions [m].
    ee_position
        (..., 3) virtual end effector [m]; equals the real one.
    link_vectors
        (..., n + 1, 3) virtual link vectors in the root frame [m].
    jacobian
        (..., 6, n) Jacobian of the virtual arm as a fixed-base chain grounded at the system
        centre of mass: columns ``(z_i x (p_e - p^_i), z_i)``.
    """

    ground: FloatArray
    joint_positions: FloatArray
    ee_position: FloatArray
    link_vectors: FloatArray
    jacobian: FloatArray


def virtual_manipulator(
    model: ArmModel, q: ArrayLike, *, weighting: VMWeighting = "vafa-dubowsky"
) -> VirtualManipulator:
    """Virtual manipulator of a free-floating arm (Vafa-Dubowsky, as used in 004).

    Parameters
    ----------
    model
        The arm; a fixed base gives the real arm back.
    q
        (..., n) joint angles [rad].
    weighting
        See :func:`virtual_link_vectors`; ``"segment"`` is 004's reading.
    """
    s = chain_state(model, q)
    local = virtual_link_vectors(model, weighting=weighting)
    if model.floating:
        ground = system_com(model, s.q, s)
    else:  # m_0 -> inf: the ground is the base's own point, the virtual arm is the real one
        ground = np.broadcast_to(model.root_body.com, s.batch_shape + (3,))
    vec_links = np.einsum("...nij,nj->...ni", s.rotations, local[1:])
    vec0 = np.broadcast_to(local[0], ground.shape)
    vectors = np.concatenate([vec0[..., None, :], vec_links], axis=-2)
    cumulative = ground[..., None, :] + np.cumsum(vectors, axis=-2)
    joints = cumulative[..., :-1, :]
    ee = cumulative[..., -1, :]
    lin = np.cross(s.axes, ee[..., None, :] - joints)
    jac = np.concatenate([np.swapaxes(lin, -1, -2), np.swapaxes(s.axes, -1, -2)], axis=-2)
    return VirtualManipulator(ground, joints, ee, vectors, jac)
