"""Closed-form IK of the ``puma6`` family (seed 002), the full arm and every locked joint; the
equations and the corrections of 002's printed ones are in :mod:`jointlock.ik`."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .._cache import cached_on
from ..errors import ModelError
from ..kinematics import ee_pose
from ..model import ArmModel, FloatArray
from ..spatial import invert, pose, pose_error, rot_x, rot_z, turns_into_limits
from ._pose import EXACT_POSITION_TOL, EXACT_ROTATION_TOL, _as_poses, check_six_joints, wrap_angle
from ._spherical import spherical_wrist_branches, spherical_wrist_geometry
from ._ur import ur_branches, ur_geometry

#: Largest residual accepted when fitting the puma6 family to a model [m or rad].
FAMILY_FIT_TOL = 1e-9

#: Table 1 twists of the puma6 family [rad] (standard DH).
PUMA6_ALPHA = np.radians([-90.0, 0.0, 90.0, -90.0, 90.0, 0.0])


# -- the puma6 family ----------------------------------------------------------------------


@dataclass(frozen=True)
class Puma6Geometry:
    """Lengths and tool of a ``puma6``-family arm (002 Table 1, standard DH).

    Attributes
    ----------
    a2, d4, d6
        [m]; ``puma6`` has 0.985, -0.765, 0.382.
    tool
        (4, 4) pose of the model's end-effector frame in DH frame 6 [m] (no offset along
        ``z6``: that is folded into ``d6``).
    lock
        ``(joint number, angle [rad])`` of the model's locked joint, or None.
    """

    a2: float
    d4: float
    d6: float
    tool: FloatArray
    lock: tuple[int, float] | None = None


def _dh_chain(a2: float, d4: float, d6: float, q: FloatArray) -> FloatArray:
    """(..., 6, 4, 4) poses ``T_0_i`` of DH frames 1..6 of the family."""
    a = (0.0, a2, 0.0, 0.0, 0.0, 0.0)
    d = (0.0, 0.0, 0.0, d4, 0.0, d6)
    out = np.empty(q.shape[:-1] + (6, 4, 4))
    t = np.broadcast_to(np.eye(4), q.shape[:-1] + (4, 4))
    for i in range(6):
        fixed = np.array([[1.0, 0, 0, a[i]], [0, 1.0, 0, 0], [0, 0, 1.0, d[i]], [0, 0, 0, 1.0]]) @ rot_x(
            PUMA6_ALPHA[i]
        )
        t = t @ rot_z(q[..., i]) @ fixed
        out[..., i, :, :] = t
    return out


def puma6_fk(geometry: Puma6Geometry, q_full: ArrayLike) -> FloatArray:
    """Closed-form forward kinematics of the family, tool included.

    Parameters
    ----------
    geometry
        From :func:`puma6_geometry`.
    q_full
        (..., 6) all six joint angles [rad] (locked joint included).

    Returns
    -------
    (..., 4, 4) ``T_0_6 @ tool`` [m].
    """
    q = np.asarray(q_full, dtype=float)
    return _dh_chain(geometry.a2, geometry.d4, geometry.d6, q)[..., 5, :, :] @ geometry.tool


def puma6_geometry(model: ArmModel) -> Puma6Geometry:
    """Decide whether ``model`` belongs to the ``puma6`` family and return its geometry.

    The position of the end effector is linear in ``(a2, d4, d6, t_x, t_y)`` for given joint
    angles, and its orientation does not depend on the lengths: both are fitted by least
    squares to the model's own forward kinematics at 8 fixed configurations and accepted
    when the residual is below :data:`FAMILY_FIT_TOL`.

    Parameters
    ----------
    model
        Six joints, of which at most one is locked.

    Raises
    ------
    ModelError
        If the model is not of the family (use :func:`ik_numeric` then).

    Notes
    -----
    Fitted once per model and kept on it (:func:`jointlock._cache.cached_on`): a single-pose IK
    call does not fit it again.
    """
    return cached_on(model, "puma6_geometry", lambda: _fit_geometry(model))


def _fit_geometry(model: ArmModel) -> Puma6Geometry:
    check_six_joints(model, "puma6")
    q = np.random.default_rng(6).uniform(-np.pi, np.pi, (8, model.dof))
    actual = ee_pose(model, q)
    q_full = model.expand(q)
    zero = _dh_chain(0.0, 0.0, 0.0, q_full)[..., 5, :, :]
    r06 = zero[..., :3, :3]
    tool_rot = np.swapaxes(r06, -1, -2) @ actual[..., :3, :3]
    if np.max(np.abs(tool_rot - tool_rot[0])) > FAMILY_FIT_TOL * 10:
        raise ModelError(
            f"model {model.name!r} is not of the puma6 family (orientation does not match 002 Table 1)"
        )
    basis = [_dh_chain(a, d, e, q_full)[..., 5, :3, 3] for a, d, e in ((1.0, 0, 0), (0, 1.0, 0), (0, 0, 1.0))]
    cols = basis + [r06[..., :, 0], r06[..., :, 1]]
    mat = np.stack(cols, axis=-1).reshape(-1, 5)
    rhs = actual[..., :3, 3].reshape(-1)
    sol, *_ = np.linalg.lstsq(mat, rhs, rcond=None)
    if np.max(np.abs(mat @ sol - rhs)) > FAMILY_FIT_TOL * max(1.0, float(np.max(np.abs(rhs)))):
        raise ModelError(
            f"model {model.name!r} is not of the puma6 family (positions do not fit 002 Table 1)"
        )
    a2, d4, d6, tx, ty = (float(v) for v in sol)
    if abs(a2) < 1e-9 or abs(d4) < 1e-9:
        raise ModelError(f"model {model.name!r}: puma6 closed form needs a2 != 0 and d4 != 0; got {a2}, {d4}")
    tool = pose(tool_rot[0], np.array([tx, ty, 0.0]))
    lock = (model.locked[0].number, model.locked[0].angle) if model.locked else None
    return Puma6Geometry(a2, d4, d6, tool, lock)


# -- closed-form pieces (batched) ----------------------------------------------------------


def _rot03(a2: float, q1: FloatArray, q2: FloatArray, q3: FloatArray) -> FloatArray:
    """(..., 3, 3) ``R_0_3`` of the family: with twists -90, 0, 90 deg it is
    ``Rot(z, q1) Rot(x, -90) Rot(z, q2 + q3) Rot(x, 90) = Rot(z, q1) Rot(y, q2 + q3)``
    (``a2`` moves no frame's orientation)."""
    c1, s1 = np.cos(q1), np.sin(q1)
    q23 = q2 + q3
    c23, s23 = np.cos(q23), np.sin(q23)
    c1, s1, c23, s23 = np.broadcast_arrays(c1, s1, c23, s23)
    out = np.empty(c1.shape + (3, 3))
    out[..., 0, 0] = c1 * c23
    out[..., 0, 1] = -s1
    out[..., 0, 2] = c1 * s23
    out[..., 1, 0] = s1 * c23
    out[..., 1, 1] = c1
    out[..., 1, 2] = s1 * s23
    out[..., 2, 0] = -s23
    out[..., 2, 1] = 0.0
    out[..., 2, 2] = c23
    return out


def _position_branches(geom: Puma6Geometry, pw: FloatArray, lock: tuple[int, float] | None):
    """Joints 1-3 from the wrist centre ``pw`` (..., 3): arrays (..., B, 3) and validity."""
    a2, d4 = geom.a2, geom.d4
    base = np.arctan2(pw[..., 1], pw[..., 0])
    t1: FloatArray  # (numpy's stubs give np.full(base.shape + (1,), ...) a 0-d shape)
    if lock is not None and lock[0] == 1:
        t1 = np.full(base.shape + (1,), lock[1])
    else:
        t1 = wrap_angle(np.stack([base, base + math.pi], axis=-1))  # eqs. (3), (4)
    c1, s1 = np.cos(t1), np.sin(t1)
    u = c1 * pw[..., None, 0] + s1 * pw[..., None, 1]
    v = -np.broadcast_to(pw[..., None, 2], u.shape)
    if lock is not None and lock[0] == 2:
        t2 = np.full(u.shape + (1,), lock[1])
        valid = np.ones(t2.shape, dtype=bool)
        t1 = t1[..., None]
    elif lock is not None and lock[0] == 3:
        s3, c3 = math.sin(lock[1]), math.cos(lock[1])
        t2 = (np.arctan2(v, u) - math.atan2(-d4 * c3, a2 + d4 * s3))[..., None]
        valid = np.ones(t2.shape, dtype=bool)
        t1 = t1[..., None]
    else:
        rho = np.sqrt(u * u + v * v)
        w = (rho * rho + a2 * a2 - d4 * d4) / (2.0 * a2 * np.where(rho > 0, rho, 1.0))
        ok = (np.abs(w) <= 1.0 + 1e-12) & (rho > 0)
        root = np.sqrt(np.clip(1.0 - w * w, 0.0, None))
        wc = np.clip(w, -1.0, 1.0)
        phi = np.arctan2(u, v)
        t2 = np.stack([np.arctan2(wc, root) - phi, np.arctan2(wc, -root) - phi], axis=-1)  # eq. (16)
        valid = np.stack([ok, ok], axis=-1)
        t1 = np.broadcast_to(t1[..., None], t2.shape)
    u, v = u[..., None], v[..., None]
    c2, s2 = np.cos(t2), np.sin(t2)
    if lock is not None and lock[0] == 3:
        t3 = np.full(t2.shape, lock[1])
    else:
        sgn = math.copysign(1.0, d4)  # corrected eq. (6): divide eq. (5) by d4
        t3 = np.arctan2(sgn * (u * c2 + v * s2 - a2), sgn * (u * s2 - v * c2))
    t1, t2, t3, valid = np.broadcast_arrays(t1, t2, t3, valid)
    shape = t1.shape[:-2] + (t1.shape[-2] * t1.shape[-1],)
    return (
        np.stack([t1.reshape(shape), t2.reshape(shape), t3.reshape(shape)], axis=-1),
        valid.reshape(shape),
    )


def _wrist_branches(m: FloatArray, lock: tuple[int, float] | None) -> FloatArray:
    """Joints 4-6 from ``M = R_0_3^T R_0_6`` (..., 3, 3): (..., W, 3)."""
    if lock is not None and lock[0] == 4:
        mp = rot_z(-lock[1])[:3, :3] @ m
        t5 = np.arctan2(mp[..., 0, 2], mp[..., 2, 2])
        t6 = np.arctan2(mp[..., 1, 0], mp[..., 1, 1])
        return np.stack([np.full(t5.shape, lock[1]), t5, t6], axis=-1)[..., None, :]
    if lock is not None and lock[0] == 6:
        mp = m @ rot_z(-lock[1])[:3, :3]
        t4 = np.arctan2(-mp[..., 0, 1], mp[..., 1, 1])
        t5 = np.arctan2(-mp[..., 2, 0], mp[..., 2, 2])
        return np.stack([t4, t5, np.full(t5.shape, lock[1])], axis=-1)[..., None, :]
    if lock is not None and lock[0] == 5:
        t5 = np.full(m.shape[:-2] + (1,), lock[1])
        sign = np.full(t5.shape, float(np.sign(math.sin(lock[1]))))
    else:
        s5 = np.sqrt(m[..., 0, 2] ** 2 + m[..., 1, 2] ** 2)
        t5 = np.stack([np.arctan2(s5, m[..., 2, 2]), np.arctan2(-s5, m[..., 2, 2])], axis=-1)  # eq. (8)
        sign = np.broadcast_to(np.array([1.0, -1.0]), t5.shape)
    m_b = m[..., None, :, :]
    t4 = np.arctan2(sign * m_b[..., 1, 2], sign * m_b[..., 0, 2])  # eq. (11) (not (17))
    # eqs. (13)-(15): N = Rot(y, -t5) Rot(z, -t4) M, t6 = atan2(N_10, N_00), entries written out
    c4, s4, c5, s5 = np.cos(t4), np.sin(t4), np.cos(t5), np.sin(t5)
    m00, m10, m20 = m_b[..., 0, 0], m_b[..., 1, 0], m_b[..., 2, 0]
    t6 = np.arctan2(c4 * m10 - s4 * m00, c5 * (c4 * m00 + s4 * m10) - s5 * m20)
    return np.stack([t4, t5, t6], axis=-1)


def puma6_branches(geometry: Puma6Geometry, target06: ArrayLike) -> tuple[FloatArray, NDArray[np.bool_]]:
    """Every closed-form branch for targets given as DH frame 6 (tool removed).

    Parameters
    ----------
    geometry
        Family geometry; ``geometry.lock`` selects the locked-joint closed form.
    target06
        (..., 4, 4) targets ``T_0_6`` [m].

    Returns
    -------
    q_full
        (..., B, 6) [rad] in [-pi, pi); ``B = 8`` for the full arm, 4 with a lock.  Branch
        order: full arm ``(theta1 of eq. 3 / eq. 4) x (theta2 with +sqrt / -sqrt) x (theta5
        with +sqrt / -sqrt)``; locked arms the same with the locked joint's factor removed.
    valid
        (..., B) False where the formulas have no real solution (``|W| > 1``); those rows
        hold NaN.
    """
    t = np.asarray(target06, dtype=float)
    lock = geometry.lock
    pw = t[..., :3, 3] - geometry.d6 * t[..., :3, 2]
    pos, valid = _position_branches(geometry, pw, lock)  # (..., P, 3)
    r03 = _rot03(geometry.a2, pos[..., 0], pos[..., 1], pos[..., 2])
    m = np.swapaxes(r03, -1, -2) @ t[..., None, :3, :3]
    wrist = _wrist_branches(m, lock)  # (..., P, W, 3)
    pos_b = np.broadcast_to(pos[..., None, :], wrist.shape)
    q = np.concatenate([pos_b, wrist], axis=-1)
    q = q.reshape(q.shape[:-3] + (-1, 6))
    valid = np.broadcast_to(valid[..., None], wrist.shape[:-1]).reshape(q.shape[:-1])
    q = np.where(valid[..., None], wrap_angle(q), np.nan)
    if lock is not None:
        q[..., lock[0] - 1] = np.where(valid, lock[1], np.nan)
    return q, valid


# -- results -------------------------------------------------------------------------------


@dataclass(frozen=True)
class IKBranches:
    """Closed-form IK of a batch of targets, every branch kept (invalid ones as NaN).

    Attributes
    ----------
    q
        (..., B, n) movable-joint angles [rad] (the model's healthy vector).
    q_full
        (..., B, 6) all joints, locked one included [rad].
    valid
        (..., B) the branch's formulas have a real solution.
    position_error, rotation_error
        (..., B) ``|p - p_target|`` [m] and rotation angle of ``R_target^T R`` [rad], from
        the model's own forward kinematics (``inf`` where invalid).
    exact
        (..., B) both errors below :data:`EXACT_POSITION_TOL` / :data:`EXACT_ROTATION_TOL`.
    """

    q: FloatArray
    q_full: FloatArray
    valid: NDArray[np.bool_]
    position_error: FloatArray
    rotation_error: FloatArray
    exact: NDArray[np.bool_]
    family: str = "puma6"


def closed_form_family(model: ArmModel) -> str:
    """The closed form that solves ``model``, decided from its own kinematics: ``"puma6"``
    (002's family, :func:`puma6_geometry`), ``"ur"`` (three parallel axes,
    :func:`jointlock.ik._ur.ur_geometry`) or ``"spherical-wrist"`` (Pieper's spherical wrist
    with parallel shoulder-elbow axes: PUMA with offsets, KUKA KR, ABB IRB, Staeubli;
    :func:`jointlock.ik._spherical.spherical_wrist_geometry`); :class:`ModelError` saying why
    none does."""
    reasons = []
    for family, fit in (("puma6", puma6_geometry), ("ur", ur_geometry), ("spherical-wrist", spherical_wrist_geometry)):
        try:
            fit(model)
            return family
        except ModelError as error:
            reasons.append(str(error))
    raise ModelError(f"no closed form for {model.name!r}: " + "; ".join(reasons))


def ik_closed_form(model: ArmModel, target: ArrayLike) -> IKBranches:
    """Closed-form IK of a ``puma6``-, UR- or spherical-wrist-family arm, full or with one
    locked joint (batched).

    Parameters
    ----------
    model
        A family member (:func:`closed_form_family` decides), possibly with one joint locked.
    target
        (..., 4, 4) end-effector poses in the root frame [m].

    Returns
    -------
    IKBranches
        ``puma6``: eight branches for the full arm, four with a lock; see the module docstring
        for the equations (002 eqs. 2-17, with eqs. (6)/(16) for theta3 and (17) for theta4
        corrected).  UR and spherical wrist: the full arm's eight branches
        (:func:`jointlock.ik._ur.ur_branches`,
        :func:`jointlock.ik._spherical.spherical_wrist_branches`); with a lock, those whose
        locked angle is the lock's are the exact ones.

    Raises
    ------
    ModelError
        If the model is of no family.
    """
    family = closed_form_family(model)
    t = _as_poses(target)
    if family == "puma6":
        geom = puma6_geometry(model)
        q_full, valid = puma6_branches(geom, t @ invert(geom.tool))
    elif family == "ur":
        ur = ur_geometry(model)
        q_full, valid = ur_branches(ur, t @ invert(ur.tool))
    else:
        lock = (model.locked[0].number, model.locked[0].angle) if model.locked else None
        q_full, valid = spherical_wrist_branches(spherical_wrist_geometry(model), t, lock)
    q = turns_into_limits(model.healthy(q_full), model.lower, model.upper)  # limits past +-pi kept
    q_full = np.where(valid[..., None], model.expand(np.nan_to_num(q)), np.nan)
    actual = ee_pose(model, np.where(valid[..., None], q, 0.0))
    dp, dr = pose_error(t[..., None, :, :], actual)
    dp = np.where(valid, dp, np.inf)
    dr = np.where(valid, dr, np.inf)
    exact = valid & (dp <= EXACT_POSITION_TOL) & (dr <= EXACT_ROTATION_TOL)
    return IKBranches(q, q_full, valid, dp, dr, exact, family)

