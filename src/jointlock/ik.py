"""Inverse kinematics: closed form for the ``puma6`` family (seed 002), numerical otherwise.

Closed form (:func:`ik_closed_form`)
------------------------------------
The ``puma6`` family is every arm whose kinematics equal 002 Table 1 read as standard DH
(``alpha = [-90, 0, 90, -90, 90, 0] deg``, ``a = [0, a2, 0, 0, 0, 0]``,
``d = [0, 0, 0, d4, 0, d6]``, no base transform) followed by any tool transform.  Membership
is decided numerically by :func:`puma6_geometry` (a least-squares fit of ``a2, d4, d6`` and
the tool against the model's own forward kinematics), never by the model's name.

With ``n, o, a, p`` the columns of the target ``T_0_6`` and the wrist centre
``p_w = p - d6 a`` (002 eq. 1 keeps ``A6^-1`` on the left side):

* ``theta1`` from 002 eq. (2): ``-s1 p_wx + c1 p_wy = 0``, the two branches of eqs. (3)/(4)
  (printed in swapped order in eq. (16); both are returned).
* ``U = c1 p_wx + s1 p_wy``, ``V = -p_wz``; 002 eq. (5) reads
  ``d4 s3 = U c2 + V s2 - a2`` and ``d4 c3 = U s2 - V c2``.
* ``theta2 = atan2(W, +-sqrt(1 - W^2)) - atan2(U, V)`` with
  ``W = (U^2 + V^2 + a2^2 - d4^2) / (2 a2 sqrt(U^2 + V^2))`` (002 eq. 16, correct as printed).
* ``theta3`` from eq. (5) -- **corrected**, see below.
* The wrist: ``M = R_0_3^T R_0_6 = Rz(theta4) Ry(theta5) Rz(theta6)`` (ZYZ).  ``theta5 =
  atan2(+-sqrt(1 - h^2), h)`` with ``h = M[2, 2]`` is eq. (8) (its ``h`` is the printed one);
  ``theta4 = atan2(M[1, 2] / s5, M[0, 2] / s5)`` is eq. (11); ``theta6`` is eqs. (13)-(15),
  computed here as the remaining ``Rz`` of ``Ry(-theta5) Rz(-theta4) M`` so that it stays
  exact at the wrist singularity ``s5 = 0``.

Printed 002 equations corrected here (judged by round trips ``FK(IK(T)) = T``, not by the
printed formulas; see ``docs/replan.md``):

1. **theta3, eqs. (6) and (16)** print ``atan2(U c2 + V s2 - a2, U s2 - V c2)``.  That drops
   the factor ``1/d4`` of eq. (5) and is right only for ``d4 > 0``; 002's own numbers force
   ``d4 = -0.765 m`` (with Table 1's ``alpha3 = +90 deg``), where the printed form returns
   ``theta3 + 180 deg`` (e.g. -113.8085 deg instead of eq. (22)'s 66.1915 deg).  Used:
   ``atan2((U c2 + V s2 - a2) / d4, (U s2 - V c2) / d4)``.
2. **theta4, eq. (17)** prints ``atan2(-ax s1 + ay c1, ...)`` without the ``1/s5`` that
   eq. (11) has in the first argument; the quadrant is wrong whenever ``s5 < 0`` (every
   002 example has ``theta5 ~ -120 deg``).  Used: eq. (11).
3. **Eq. (18)** (in :mod:`jointlock.planning.replan`) prints the (1, 1) element of the tool
   rotation as 0; it is 1.

With both fixes every one of the 8 branches round-trips (tests: thousands of seeded random
poses); with either printed form none does.

Locked joints (closed form, 002 §"Analytical inverse kinematics of a 5-DOF manipulator")
-----------------------------------------------------------------------------------------
The locked angle is substituted and a subset of five equations is solved; the pose error of
each branch (from the model's own forward kinematics) tells whether the target is reachable:

* joint 1: ``theta1`` given; ``theta2`` (2 branches) and ``theta3`` as above; wrist 2 branches.
  Eq. (2) is not enforced: its residual (the wrist centre off the arm's plane) is the error.
* joint 2 (002's case): ``theta1`` two branches from eq. (2), ``theta3`` from corrected eq.
  (5)/(6) with the locked ``theta2``; wrist 2 branches.
* joint 3 (derived): eq. (5) says ``[U, V] = Rz(theta2) [a2 + d4 s3, -d4 c3]``, so
  ``theta2 = atan2(V, U) - atan2(-d4 c3, a2 + d4 s3)``; ``theta1`` 2 branches; wrist 2.
* joints 4, 5, 6 (derived): the wrist centre fixes ``theta1..3`` (4 branches); the wrist
  ``Rz(theta4) Ry(theta5) Rz(theta6) = M`` with one angle known gives the other two:
  ``theta5 = atan2(M'[0,2], M'[2,2])``, ``theta6 = atan2(M'[1,0], M'[1,1])`` with
  ``M' = Rz(-theta4) M`` (joint 4); ``theta4 = atan2(sign(s5) M[1,2], sign(s5) M[0,2])``
  (joint 5); ``theta4 = atan2(-M''[0,1], M''[1,1])``, ``theta5 = atan2(-M''[2,0], M''[2,2])``
  with ``M'' = M Rz(-theta6)`` (joint 6).

Each is exact whenever the target is reachable by the locked arm (four branches, of which
the exact ones are flagged).

Numerical fallback (:func:`ik_numeric`)
---------------------------------------
Levenberg-Marquardt (damped least squares with Marquardt's diagonal scaling) on any
:class:`~jointlock.model.ArmModel`, locked or not, from several starts at once (batched over
targets and starts), optionally with the rotation ``gamma`` about the tool x axis as a free
task variable (002 §"Fault-tolerant planning based on the inverse solution of 6-DOF
manipulator"): the target becomes ``T Rx(gamma)``.  The residual is
``(p_t - p, L * log(R_t R^T))`` with a characteristic length ``L`` [m]; when no exact
solution exists it converges to the *nearest reachable pose* in that metric.

Everything here is in SI units and radians; 002's ZYX Euler angles are converted by
:func:`pose_from_zyx` / :func:`zyx_angles`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike

from .errors import ConfigurationError, ModelError
from .kinematics import ChainState, chain_state, ee_pose, jacobian
from .model import ArmModel, FloatArray
from .spatial import invert, pose, pose_error, rot_x, rot_y, rot_z, rotation_log

#: A branch is *exact* when its position error is below this [m] ...
EXACT_POSITION_TOL = 1e-7
#: ... and its rotation error below this [rad].  Round-off alone gives ~1e-12 away from
#: singularities; at the boundary of reach (``|W| -> 1``) ``sqrt(1 - W^2)`` loses half the
#: digits, hence the margin.
EXACT_ROTATION_TOL = 1e-7
#: Largest residual accepted when fitting the puma6 family to a model [m or rad].
FAMILY_FIT_TOL = 1e-9
#: Two solutions closer than this (max wrapped joint difference) [rad] are the same.
DUPLICATE_TOL = 1e-6

#: Table 1 twists of the puma6 family [rad] (standard DH).
PUMA6_ALPHA = np.radians([-90.0, 0.0, 90.0, -90.0, 90.0, 0.0])


# -- Euler angles as 002 prints them ------------------------------------------------------


def pose_from_zyx(position: ArrayLike, yaw_pitch_roll: ArrayLike) -> FloatArray:
    """Pose from a position and 002's Euler angles.

    Parameters
    ----------
    position
        (..., 3) [m].
    yaw_pitch_roll
        (..., 3) ``[yaw, pitch, roll]`` [rad], ``R = Rz(yaw) Ry(pitch) Rx(roll)`` -- the
        convention 002 prints (inferred from its own numbers: eq. (21) gives exactly the
        printed ``[1.5573, -0.1427, -0.0801]``).

    Returns
    -------
    (..., 4, 4) pose.
    """
    e = np.asarray(yaw_pitch_roll, dtype=float)
    rot = (rot_z(e[..., 0]) @ rot_y(e[..., 1]) @ rot_x(e[..., 2]))[..., :3, :3]
    return pose(rot, np.asarray(position, dtype=float))


def zyx_angles(rotation: ArrayLike) -> FloatArray:
    """``[yaw, pitch, roll]`` (..., 3) [rad] of rotations (..., 3, 3), inverse of
    :func:`pose_from_zyx`: ``yaw = atan2(r21, r11)``, ``pitch = -asin(r31)``,
    ``roll = atan2(r32, r33)``."""
    r = np.asarray(rotation, dtype=float)
    pitch = -np.arcsin(np.clip(r[..., 2, 0], -1.0, 1.0))
    return np.stack(
        [np.arctan2(r[..., 1, 0], r[..., 0, 0]), pitch, np.arctan2(r[..., 2, 1], r[..., 2, 2])], -1
    )


def wrap_angle(angle: ArrayLike) -> FloatArray:
    """Angles wrapped to [-pi, pi) [rad]."""
    return (np.asarray(angle, dtype=float) + math.pi) % (2.0 * math.pi) - math.pi


def _as_poses(target: ArrayLike, name: str = "target") -> FloatArray:
    t = np.asarray(target, dtype=float)
    if t.ndim < 2 or t.shape[-2:] != (4, 4):
        raise ConfigurationError(
            f"{name} must be a 4x4 pose or an array of them (..., 4, 4); got shape {t.shape}"
        )
    if not np.all(np.isfinite(t)):
        raise ConfigurationError(f"{name} must be finite")
    rot = t[..., :3, :3]
    if not np.allclose(rot @ np.swapaxes(rot, -1, -2), np.eye(3), atol=1e-6):
        raise ConfigurationError(
            f"{name}: the upper-left 3x3 block is not a rotation matrix (tolerance 1e-6)"
        )
    return t


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
    """
    if model.full_dof != 6 or len(model.locked) > 1:
        raise ModelError(
            f"model {model.name!r}: the puma6 closed form needs a 6-joint arm with at most one "
            f"locked joint; got {model.full_dof} joints, {len(model.locked)} locked"
        )
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
    basis = [_dh_chain(*unit, q_full)[..., 5, :3, 3] for unit in ((1.0, 0, 0), (0, 1.0, 0), (0, 0, 1.0))]
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
    q = np.stack(np.broadcast_arrays(q1, q2, q3, q1 * 0, q1 * 0, q1 * 0), axis=-1)
    return _dh_chain(a2, 0.0, 0.0, q)[..., 2, :3, :3]


def _position_branches(geom: Puma6Geometry, pw: FloatArray, lock: tuple[int, float] | None):
    """Joints 1-3 from the wrist centre ``pw`` (..., 3): arrays (..., B, 3) and validity."""
    a2, d4 = geom.a2, geom.d4
    base = np.arctan2(pw[..., 1], pw[..., 0])
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
    n = rot_y(-t5)[..., :3, :3] @ rot_z(-t4)[..., :3, :3] @ m_b
    t6 = np.arctan2(n[..., 1, 0], n[..., 0, 0])  # eqs. (13)-(15)
    return np.stack([t4, t5, t6], axis=-1)


def puma6_branches(geometry: Puma6Geometry, target06: ArrayLike) -> tuple[FloatArray, FloatArray]:
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
    valid: FloatArray
    position_error: FloatArray
    rotation_error: FloatArray
    exact: FloatArray


def ik_closed_form(model: ArmModel, target: ArrayLike) -> IKBranches:
    """Closed-form IK of a ``puma6``-family arm, full or with one locked joint (batched).

    Parameters
    ----------
    model
        A family member (:func:`puma6_geometry` decides), possibly with one joint locked.
    target
        (..., 4, 4) end-effector poses in the root frame [m].

    Returns
    -------
    IKBranches
        Eight branches for the full arm, four with a lock; see the module docstring for the
        equations (002 eqs. 2-17, with eqs. (6)/(16) for theta3 and (17) for theta4
        corrected).

    Raises
    ------
    ModelError
        If the model is not of the family.
    """
    geom = puma6_geometry(model)
    t = _as_poses(target)
    q_full, valid = puma6_branches(geom, t @ invert(geom.tool))
    q = model.healthy(q_full)
    actual = ee_pose(model, np.where(valid[..., None], q, 0.0))
    dp, dr = pose_error(t[..., None, :, :], actual)
    dp = np.where(valid, dp, np.inf)
    dr = np.where(valid, dr, np.inf)
    exact = valid & (dp <= EXACT_POSITION_TOL) & (dr <= EXACT_ROTATION_TOL)
    return IKBranches(q, q_full, valid, dp, dr, exact)


@dataclass(frozen=True)
class IKSolution:
    """One IK branch.

    Attributes
    ----------
    q
        (n,) movable-joint angles [rad].
    q_full
        (full_dof,) every joint in joint-number order, locked ones included [rad].
    branch
        Closed-form branch index (see :func:`puma6_branches`), or the start index for the
        numerical method.
    position_error
        ``|p - p_target|`` [m].
    rotation_error
        Rotation angle between target and reached orientation [rad].
    exact
        Both errors within :data:`EXACT_POSITION_TOL` / :data:`EXACT_ROTATION_TOL`.
    """

    q: FloatArray
    q_full: FloatArray
    branch: int
    position_error: float
    rotation_error: float
    exact: bool


@dataclass(frozen=True)
class IKResult:
    """Every IK solution of one target.

    Attributes
    ----------
    target
        (4, 4) requested pose [m].
    method
        ``"closed-form"`` or ``"numeric"``.
    solutions
        The exact solutions (distinct), best first.
    candidates
        Every branch computed, exact or not (closed form: all valid branches).
    nearest
        When no exact solution exists: the configuration whose pose is nearest to the target
        in the metric ``sqrt(|dp|^2 + (L dtheta)^2)`` (local optimum of Levenberg-Marquardt
        from every candidate and ``starts`` random starts); None otherwise.
    nearest_pose
        (4, 4) the pose reached by ``nearest`` [m], or None.
    length_scale
        ``L`` [m] of that metric.
    """

    target: FloatArray
    method: Literal["closed-form", "numeric"]
    solutions: tuple[IKSolution, ...]
    candidates: tuple[IKSolution, ...]
    nearest: IKSolution | None
    nearest_pose: FloatArray | None
    length_scale: float

    @property
    def reachable(self) -> bool:
        """True when at least one exact solution exists."""
        return bool(self.solutions)


def _distinct(solutions: list[IKSolution]) -> list[IKSolution]:
    out: list[IKSolution] = []
    for s in solutions:
        if all(np.max(np.abs(wrap_angle(s.q - o.q))) > DUPLICATE_TOL for o in out):
            out.append(s)
    return out


# -- numerical IK (Levenberg-Marquardt, batched) -------------------------------------------


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
    """

    q: FloatArray
    gamma: FloatArray
    position_error: FloatArray
    rotation_error: FloatArray
    exact: FloatArray
    iterations: int


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
        Seed or generator for the random starts.
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
    gen = np.random.default_rng(rng)
    lo = np.maximum(model.lower, -math.pi)
    hi = np.minimum(model.upper, math.pi)
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
    q = np.concatenate(parts, axis=-2).copy()
    s = q.shape[-2]
    tgt = np.broadcast_to(t[..., None, :, :], batch + (s, 4, 4))
    gamma = np.zeros(batch + (s,))
    glo, ghi = gamma_bounds

    def target_of(g: FloatArray) -> FloatArray:
        return tgt @ rot_x(g) if free_tool_x else tgt

    def clamp(qq: FloatArray) -> FloatArray:
        return np.clip(wrap_angle(qq), model.lower, model.upper)

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
    return NumericIK(q, gamma, dp, dr, exact, it)


def _select_state(mask: FloatArray, a: ChainState, b: ChainState) -> ChainState:
    return ChainState.select(mask, a, b)


# -- one target, every solution ------------------------------------------------------------


def solve_ik(
    model: ArmModel,
    target: ArrayLike,
    *,
    method: Literal["auto", "closed-form", "numeric"] = "auto",
    starts: int = 16,
    rng: int | np.random.Generator | None = 0,
    length_scale: float = 1.0,
) -> IKResult:
    """Every IK solution of one target, and the nearest reachable pose when there is none.

    Parameters
    ----------
    model
        Any arm, possibly locked.  ``"auto"`` uses the closed form when the model is of the
        ``puma6`` family (:func:`puma6_geometry`) and Levenberg-Marquardt otherwise.
    target
        (4, 4) pose in the root frame [m].
    starts, rng
        Random starts of the numerical method (also used to search the nearest reachable
        pose of a locked arm).
    length_scale
        ``L`` [m] of the nearest-pose metric ``sqrt(|dp|^2 + (L dtheta)^2)``.

    Returns
    -------
    IKResult
    """
    if method not in ("auto", "closed-form", "numeric"):
        raise ConfigurationError(f"method must be 'auto', 'closed-form' or 'numeric'; got {method!r}")
    t = _as_poses(target)
    if t.shape != (4, 4):
        raise ConfigurationError(
            f"target must be one 4x4 pose; got shape {t.shape} (use ik_closed_form for batches)"
        )
    use_closed = method == "closed-form"
    if method == "auto":
        try:
            puma6_geometry(model)
            use_closed = True
        except ModelError:
            use_closed = False
    cands: list[IKSolution] = []
    if use_closed:
        br = ik_closed_form(model, t)
        for b in np.flatnonzero(br.valid):
            cands.append(
                IKSolution(
                    br.q[b],
                    br.q_full[b],
                    int(b),
                    float(br.position_error[b]),
                    float(br.rotation_error[b]),
                    bool(br.exact[b]),
                )
            )
        kind: Literal["closed-form", "numeric"] = "closed-form"
    else:
        num = ik_numeric(model, t, starts=starts, rng=rng, length_scale=length_scale)
        for k in range(num.q.shape[0]):
            cands.append(
                IKSolution(
                    num.q[k],
                    model.expand(num.q[k]),
                    k,
                    float(num.position_error[k]),
                    float(num.rotation_error[k]),
                    bool(num.exact[k]),
                )
            )
        kind = "numeric"
    exact = _distinct([c for c in cands if c.exact])
    nearest = None
    nearest_pose = None
    if not exact:
        seeds = [c.q for c in cands]
        refined = ik_numeric(
            model,
            t,
            q0=np.array(seeds) if seeds else None,
            starts=starts,
            rng=rng,
            length_scale=length_scale,
        )
        metric = refined.position_error**2 + (length_scale * refined.rotation_error) ** 2
        k = int(np.argmin(metric))
        nearest = IKSolution(
            refined.q[k],
            model.expand(refined.q[k]),
            k,
            float(refined.position_error[k]),
            float(refined.rotation_error[k]),
            bool(refined.exact[k]),
        )
        nearest_pose = ee_pose(model, refined.q[k])
        if nearest.exact:  # the closed form missed it (singular target): report as a solution
            exact = [nearest]
            nearest, nearest_pose = None, None
    return IKResult(t, kind, tuple(exact), tuple(cands), nearest, nearest_pose, float(length_scale))
