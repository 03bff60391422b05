"""Closed-form IK of 6R arms with a spherical wrist and parallel shoulder-elbow axes (Pieper's
condition; the family of the PUMA with its shoulder and forearm offsets, KUKA KR, ABB IRB,
Staeubli, FANUC: the arms the ``OPW`` parametrisation covers).

The family, decided from the model's own joint axes at ``q = 0`` (never its name or its DH
table): axes 4, 5 and 6 meet in one point (the wrist centre ``c``), axes 2 and 3 are parallel
(same or opposite direction), axis 1 is not parallel to them, and the wrist centre is off axis
3.  Any base transform, any tool, any joint zero and any offsets between the axes are allowed.

The solution works on the product of exponentials ``T(q) = e^{xi1 q1} ... e^{xi6 q6} M`` built
from those axes (Murray, Li & Sastry, *A Mathematical Introduction to Robotic Manipulation*,
1994, §3.3; Paden-Kahan subproblems), batched over targets:

1. The wrist centre of the target, ``c_t = T_t M^-1 c``: rotations 4-6 keep it fixed.
2. ``q1`` (two branches): turns about axes 2 and 3 keep ``h2 . x``, so
   ``h2 . e^{-xi1 q1} c_t = h2 . c`` (one rotation onto a plane: ``A cos + B sin = C``).
3. ``q3`` (two branches): a turn about axis 2 keeps the distance to axis 2, so
   ``dist(e^{xi3 q3} c, axis 2) = dist(y, axis 2)`` with ``y = e^{-xi1 q1} c_t`` (Paden-Kahan
   subproblem 3); then ``q2`` turns ``e^{xi3 q3} c`` onto ``y`` (subproblem 1).
4. The wrist (two branches): ``R4 R5 R6 = R123^T R_t R_M^T``; ``q4, q5`` carry ``h6`` onto its
   target (subproblem 2), ``q6`` is what is left (subproblem 1).

Eight branches in all (shoulder x elbow x wrist); ``q5`` is recomputed from ``q4`` by
subproblem 1, which keeps it exact at the wrist singularity (``h6`` along ``h4``), where
subproblem 2's square root loses half its digits.  A model with one joint locked is solved on
its full arm: its exact solutions are the branches whose locked angle is the lock's (the
others fail the caller's check).  A locked wrist joint is substituted and the other two
solved from it; where joint 1 or 2 is free (the wrist centre on its axis) it takes the lock's
angle when locked, else 0.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .._cache import cached_on
from ..errors import ModelError
from ..kinematics import chain_state, ee_pose
from ..model import ArmModel, FloatArray
from ._pose import check_six_joints

#: Largest distance of the wrist centre from a wrist axis, and largest sine between axes 2 and
#: 3, accepted as the family [m, relative to the arm's size; -].
SPHERICAL_FIT_TOL = 1e-9
#: Sines (or lengths relative to the arm's size) below this make a joint free in a branch.
_FREE_TOL = 1e-12
#: Subproblem 1 takes a joint as free when a vector's part off its axis is below this share of
#: the vector's length (the sine of their angle): the pose error of any angle is then below
#: it, while a larger one still fixes the angle (a wrist at q5 = 1e-7 keeps its q4).
_FREE_SINE = 1e-9


@dataclass(frozen=True)
class SphericalWristGeometry:
    """Joint screws of the full arm at ``q = 0``, in the root frame.

    Attributes
    ----------
    directions
        (6, 3) unit joint axes.
    points
        (6, 3) a point on each axis [m].
    wrist_centre
        (3,) where axes 4-6 meet [m].
    home
        (4, 4) the end-effector pose at ``q = 0`` (tool included) [m].
    """

    directions: FloatArray
    points: FloatArray
    wrist_centre: FloatArray
    home: FloatArray


def spherical_wrist_geometry(model: ArmModel) -> SphericalWristGeometry:
    """The model's screws when it is of the family, else :class:`ModelError` saying which
    condition fails (decided once per model, :func:`jointlock._cache.cached_on`)."""
    return cached_on(model, "spherical_wrist_geometry", lambda: _fit(model))


def _fit(model: ArmModel) -> SphericalWristGeometry:
    if model.locked and model.unlocked is not None and len(model.locked) == 1:
        return spherical_wrist_geometry(model.unlocked)
    check_six_joints(model, "spherical-wrist")
    state = chain_state(model, np.zeros(6))
    h = np.asarray(state.axes, dtype=float)
    p = np.asarray(state.positions, dtype=float)
    home = np.asarray(ee_pose(model, np.zeros(6)), dtype=float)
    size = max(1.0, float(np.max(np.abs(p))), float(np.max(np.abs(home[:3, 3]))))
    name = model.name

    def sine(i: int, j: int) -> float:
        return float(np.linalg.norm(np.cross(h[i], h[j])))

    if sine(1, 2) > SPHERICAL_FIT_TOL:
        raise ModelError(f"model {name!r} is not of the spherical-wrist family (axes 2 and 3 are not parallel)")
    if sine(0, 1) < 1e-6:
        raise ModelError(f"model {name!r} is not of the spherical-wrist family (axis 1 is parallel to axis 2)")
    if sine(3, 4) < 1e-6 or sine(4, 5) < 1e-6:
        raise ModelError(f"model {name!r} is not of the spherical-wrist family (axis 5 is parallel to axis 4 or 6)")
    proj = np.eye(3) - h[3:, :, None] * h[3:, None, :]  # (3, 3, 3): off each wrist axis
    centre = np.linalg.solve(proj.sum(axis=0), np.einsum("kij,kj->i", proj, p[3:]))
    off = np.linalg.norm(np.einsum("kij,kj->ki", proj, centre - p[3:]), axis=-1)
    if np.max(off) > SPHERICAL_FIT_TOL * size:
        raise ModelError(
            f"model {name!r} is not of the spherical-wrist family (axes 4-6 miss a common point by {np.max(off):.3g} m)"
        )
    if _distance_to_axis(centre, p[2], h[2]) < 1e-6 * size:
        raise ModelError(f"model {name!r} is not of the spherical-wrist family (the wrist centre is on axis 3)")
    return SphericalWristGeometry(h, p, centre, home)


def _distance_to_axis(x: FloatArray, point: FloatArray, direction: FloatArray) -> float:
    d = x - point
    return float(np.linalg.norm(d - np.dot(d, direction) * direction))


# -- rotations and subproblems, batched over the leading axes ------------------------------


def _cross_matrix(axis: FloatArray) -> FloatArray:
    """(3, 3) ``K`` with ``K x = axis x x``; for a batch of row vectors ``x @ K.T``."""
    return np.array([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]], [-axis[1], axis[0], 0.0]])


def _rotate(axis: FloatArray, angle: FloatArray, v: FloatArray) -> FloatArray:
    """``v`` (..., 3) turned by ``angle`` (...) [rad] about the unit ``axis`` (3,) (Rodrigues)."""
    c, s = np.cos(angle)[..., None], np.sin(angle)[..., None]
    along = (v @ axis)[..., None] * axis
    return along + c * (v - along) + s * (v @ _cross_matrix(axis).T)


def _rotation(axis: FloatArray, angle: FloatArray) -> FloatArray:
    """(..., 3, 3) rotation by ``angle`` (...) [rad] about the unit ``axis`` (3,):
    ``1 + s K + (1 - c) K^2``, entry by entry (no (..., 3, 3) temporaries per term)."""
    k = _cross_matrix(axis)
    kk = k @ k
    c, s = np.cos(angle), np.sin(angle)
    out = np.empty(np.shape(angle) + (3, 3))
    vers = 1.0 - c
    for i in range(3):
        for j in range(3):
            out[..., i, j] = (1.0 if i == j else 0.0) + s * k[i, j] + vers * kk[i, j]
    return out


def _turn_onto(axis: FloatArray, u: FloatArray, v: FloatArray, free: FloatArray) -> FloatArray:
    """Subproblem 1: the angle (...) [rad] turning ``u`` onto ``v`` (..., 3) about ``axis``
    (through the origin); ``free`` where ``u`` or ``v`` lies on the axis (any angle does)."""
    up = u - (u @ axis)[..., None] * axis
    vp = v - (v @ axis)[..., None] * axis
    sin = np.sum(up * (vp @ _cross_matrix(axis)), axis=-1)  # axis . (up x vp) = up . (vp x axis)
    cos = np.sum(up * vp, axis=-1)
    tol2 = _FREE_SINE * _FREE_SINE
    off_u = np.sum(up * up, axis=-1) > tol2 * np.sum(u * u, axis=-1)
    off_v = np.sum(vp * vp, axis=-1) > tol2 * np.sum(v * v, axis=-1)
    return np.where(off_u & off_v, np.arctan2(sin, cos), free)


def _two_roots(
    a: FloatArray, b: FloatArray, c: FloatArray, free: FloatArray, slack: float
) -> tuple[FloatArray, NDArray[np.bool_]]:
    """Both roots (..., 2) [rad] of ``a cos x + b sin x = c`` and whether they are real
    (``|c| <= r (1 + slack)``, ``r = hypot(a, b)``); where ``r`` vanishes any ``x`` solves
    ``c = 0`` and ``free`` is taken."""
    r = np.hypot(a, b)
    degenerate = r <= _FREE_TOL
    ratio = c / np.where(degenerate, 1.0, r)
    real = np.where(degenerate, np.abs(c) <= slack, np.abs(ratio) <= 1.0 + slack)
    base = np.arctan2(b, a)
    half = np.arccos(np.clip(ratio, -1.0, 1.0))
    roots = np.stack([base + half, base - half], axis=-1)
    return np.where(degenerate[..., None], free[..., None], roots), real


# -- the branches ---------------------------------------------------------------------------


def spherical_wrist_branches(
    geometry: SphericalWristGeometry, target: ArrayLike, lock: tuple[int, float] | None = None
) -> tuple[FloatArray, NDArray[np.bool_]]:
    """Every branch for end-effector targets (tool included).

    Parameters
    ----------
    geometry
        :func:`spherical_wrist_geometry` of the arm.
    target
        (..., 4, 4) poses in the root frame [m].
    lock
        ``(joint number, angle [rad])`` of a locked joint: the angle a free joint takes.

    Returns
    -------
    q_full
        (..., 8, 6) [rad]; branch ``4 i + 2 j + k``: shoulder root ``i`` (joint 1), elbow root
        ``j`` (joint 3), wrist root ``k`` (joint 5's sign).
    valid
        (..., 8): the branch has a real solution (NaN rows where not).
    """
    g = geometry
    h, pts = g.directions, g.points
    t = np.asarray(target, dtype=float)
    batch = t.shape[:-2]
    size = max(1.0, float(np.max(np.abs(pts))))
    slack = 1e-10

    def free_angle(joint: int) -> FloatArray:
        value = lock[1] if lock is not None and lock[0] == joint else 0.0
        return np.full(batch, value)

    # 1. the target's wrist centre
    c_ee = np.linalg.solve(g.home, np.append(g.wrist_centre, 1.0))
    c_t = (t @ c_ee)[..., :3]
    c0 = g.wrist_centre
    # 2. joint 1: h2 . (o1 + R(h1, -q1)(c_t - o1)) = h2 . c0
    x = c_t - pts[0]
    along = (x @ h[0])[..., None] * h[0]
    a = (x - along) @ h[1]
    b = (x @ _cross_matrix(h[0]).T) @ h[1]
    rhs = (c0 - pts[0]) @ h[1] - along @ h[1]
    theta, real1 = _two_roots(a / size, b / size, rhs / size, -free_angle(1), slack)
    q1 = -theta  # (..., 2)
    # 3. joints 3 and 2 for each q1: y = e^{-xi1 q1} c_t
    y = pts[0] + _rotate(h[0], -q1, x[..., None, :])  # (..., 2, 3)
    u = c0 - pts[2]
    u = u - (u @ h[2]) * h[2]
    v = pts[1] - pts[2]
    v = v - (v @ h[2]) * h[2]
    dy = y - pts[1]
    delta2 = np.sum(dy * dy, axis=-1) - (dy @ h[1]) ** 2  # squared distance of y from axis 2
    rhs3 = 0.5 * (u @ u + v @ v - delta2)
    a3 = np.full(rhs3.shape, float(v @ u))
    b3 = np.full(rhs3.shape, float(v @ np.cross(h[2], u)))
    q3, real3 = _two_roots(a3 / size**2, b3 / size**2, rhs3 / size**2, free_angle(3)[..., None], slack)
    # q3 (..., 2 shoulder, 2 elbow)
    w = pts[2] + _rotate(h[2], q3, np.broadcast_to(c0 - pts[2], q3.shape + (3,)))
    yb = np.broadcast_to(y[..., None, :], w.shape)
    q2 = _turn_onto(h[1], w - pts[1], yb - pts[1], free_angle(2)[..., None, None])
    # 4. the wrist
    r123 = _rotation(h[0], q1[..., :, None]) @ _rotation(h[1], q2) @ _rotation(h[2], q3)
    m = np.swapaxes(r123, -1, -2) @ t[..., None, None, :3, :3] @ g.home[:3, :3].T  # (..., 2, 2, 3, 3)
    q4, q5, q6, real_w = _wrist(h[3], h[4], h[5], m, lock)  # (..., 2, 2, 2)
    shape = q4.shape
    q = np.stack(
        [
            np.broadcast_to(q1[..., :, None, None], shape),
            np.broadcast_to(q2[..., None], shape),
            np.broadcast_to(q3[..., None], shape),
            q4,
            q5,
            q6,
        ],
        axis=-1,
    )
    valid = real1[..., None, None, None] & real3[..., :, None, None] & real_w
    q = q.reshape(batch + (8, 6))
    valid = np.broadcast_to(valid, shape).reshape(batch + (8,))
    return np.where(valid[..., None], q, np.nan), valid


def _wrist(
    h4: FloatArray, h5: FloatArray, h6: FloatArray, m: FloatArray, lock: tuple[int, float] | None
) -> tuple[FloatArray, FloatArray, FloatArray, NDArray[np.bool_]]:
    """Joints 4-6 (each (..., 2): the two roots of subproblem 2) from ``R4 R5 R6 = m``
    (..., 3, 3), and whether they are real.  A locked wrist joint is substituted and the
    other two solved by subproblem 1 (one root, given twice): exact at the wrist singularity,
    where subproblem 2's square root loses half the digits of ``q5``."""
    batch = m.shape[:-2]
    two = batch + (2,)
    mb = np.broadcast_to(m[..., None, :, :], two + (3, 3))
    x5, x6 = _perpendicular(h5), _perpendicular(h6)
    zero = np.zeros(two)
    if lock is not None and lock[0] in (4, 6):
        q_lock = np.full(two, lock[1])
        if lock[0] == 4:  # R5 R6 = R4^T m
            rest = _rotation(h4, q_lock).swapaxes(-1, -2) @ mb
            q5 = _turn_onto(h5, np.broadcast_to(h6, two + (3,)), rest @ h6, zero)
            q6 = _turn_onto(h6, np.broadcast_to(x6, two + (3,)), _rotation(h5, q5).swapaxes(-1, -2) @ rest @ x6, zero)
            return q_lock, q5, q6, np.ones(two, dtype=bool)
        rest = mb @ _rotation(h6, q_lock).swapaxes(-1, -2)  # R4 R5 = m R6^T
        q4 = _turn_onto(h4, np.broadcast_to(h5, two + (3,)), rest @ h5, zero)
        q5 = _turn_onto(h5, np.broadcast_to(x5, two + (3,)), _rotation(h4, q4).swapaxes(-1, -2) @ rest @ x5, zero)
        return q4, q5, q_lock, np.ones(two, dtype=bool)
    target = mb @ h6  # R4 R5 h6 = m h6 (R6 keeps h6): z = R5 h6 = R4^T m h6
    if lock is not None and lock[0] == 5:
        q5 = np.full(two, lock[1])
        z = _rotate(h5, q5, np.broadcast_to(h6, two + (3,)))
        real = np.ones(two, dtype=bool)
    else:
        cos45 = float(h4 @ h5)
        k = np.cross(h4, h5)
        denom = 1.0 - cos45 * cos45
        alpha = ((target @ h4) - cos45 * float(h6 @ h5)) / denom
        beta = (float(h6 @ h5) - cos45 * (target @ h4)) / denom
        gamma2 = (1.0 - alpha**2 - beta**2 - 2.0 * alpha * beta * cos45) / float(k @ k)
        real = gamma2 >= -1e-10
        gamma = np.sqrt(np.clip(gamma2, 0.0, None)) * np.array([1.0, -1.0])
        z = alpha[..., None] * h4 + beta[..., None] * h5 + gamma[..., None] * k
    q4 = _turn_onto(h4, z, target, zero)
    if lock is None or lock[0] != 5:
        # q5 again from q4: exact where z is noisy (the singularity: q4 free, any value does)
        q5 = _turn_onto(h5, np.broadcast_to(h6, two + (3,)), (_rotation(h4, q4).swapaxes(-1, -2) @ target[..., None])[..., 0], zero)
    r45 = _rotation(h4, q4) @ _rotation(h5, q5)
    q6 = _turn_onto(h6, np.broadcast_to(x6, two + (3,)), r45.swapaxes(-1, -2) @ mb @ x6, zero)
    return q4, q5, q6, real


def _perpendicular(axis: FloatArray) -> FloatArray:
    """A unit vector perpendicular to the unit ``axis`` (3,)."""
    helper = np.eye(3)[int(np.argmin(np.abs(axis)))]
    out = np.cross(axis, helper)
    return out / np.linalg.norm(out)
