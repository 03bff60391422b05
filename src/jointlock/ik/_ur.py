"""Closed-form IK of the three-parallel-axes family (Universal Robots UR3/UR5/UR10 and alike).

The family: six revolute joints in the standard DH table ``alpha = (pi/2, 0, 0, pi/2, -pi/2,
0)``, ``a = (0, a2, a3, 0, 0, 0)``, ``d = (d1, 0, 0, d4, d5, d6)``: joints 2, 3 and 4 are
parallel, so the wrist is not spherical and Pieper's decoupling does not apply.  The solution
(Hawkins, *Analytic Inverse Kinematics for the Universal Robots UR-5/UR-10 Arms*, 2013):
theta1 from the point ``p05`` (two shoulder branches), theta5 from ``p06`` (two wrist branches),
theta6 from the orientation, theta3 from the planar 2R triangle of joints 2-4 (two elbow
branches), then theta2 and theta4: eight branches.  Batched over targets.

:func:`ur_geometry` decides membership from the model's own forward kinematics (lengths fitted
by least squares, a constant tool, tolerance :data:`FAMILY_FIT_TOL`), kept on the model.  A
model with one joint locked is solved on the full arm: its exact solutions are the branches
whose locked angle equals the lock (the others are reported inexact by the caller's check).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .._cache import cached_on
from ..errors import ModelError
from ..kinematics import ee_pose
from ..model import ArmModel, FloatArray
from ..spatial import invert, pose, rot_x, rot_z, translation
from ._pose import check_six_joints, wrap_angle

#: Relative residual of the family fit accepted as membership.
FAMILY_FIT_TOL = 1e-9
#: The family's DH twists.
UR_ALPHA = (math.pi / 2, 0.0, 0.0, math.pi / 2, -math.pi / 2, 0.0)


@dataclass(frozen=True)
class URGeometry:
    """The family's lengths [m] (standard DH) and the tool: ``T = DH(q) @ tool``."""

    d1: float
    a2: float
    a3: float
    d4: float
    d5: float
    d6: float
    tool: FloatArray

    @property
    def lengths(self) -> tuple[float, float, float, float, float, float]:
        """``(d1, a2, a3, d4, d5, d6)`` [m]."""
        return (self.d1, self.a2, self.a3, self.d4, self.d5, self.d6)


def _links(lengths: tuple[float, ...], q: FloatArray) -> list[FloatArray]:
    """The six standard-DH link transforms (..., 4, 4) at ``q`` (..., 6) for the lengths
    ``(d1, a2, a3, d4, d5, d6)``."""
    d1, a2, a3, d4, d5, d6 = lengths
    a = (0.0, a2, a3, 0.0, 0.0, 0.0)
    d = (d1, 0.0, 0.0, d4, d5, d6)
    return [
        rot_z(q[..., i]) @ translation([0.0, 0.0, d[i]]) @ translation([a[i], 0.0, 0.0]) @ rot_x(UR_ALPHA[i])
        for i in range(6)
    ]


def ur_fk(geometry: URGeometry, q_full: ArrayLike) -> FloatArray:
    """(..., 4, 4) end-effector pose of the family's chain at ``q_full`` (..., 6) [rad]."""
    g = geometry
    out = np.broadcast_to(np.eye(4), np.shape(q_full)[:-1] + (4, 4))
    for link in _links(g.lengths, np.asarray(q_full, dtype=float)):
        out = out @ link
    return out @ g.tool


def ur_geometry(model: ArmModel) -> URGeometry:
    """The model's family geometry, or :class:`ModelError` when it is not of the family
    (fitted once per model, :func:`jointlock._cache.cached_on`)."""
    return cached_on(model, "ur_geometry", lambda: _fit(model))


def _fit(model: ArmModel) -> URGeometry:
    if model.locked and model.unlocked is not None and len(model.locked) == 1:
        return ur_geometry(model.unlocked)  # a lock can make two lengths indistinguishable
    check_six_joints(model, "UR")
    q = np.random.default_rng(7).uniform(-np.pi, np.pi, (10, model.dof))
    actual = ee_pose(model, q)
    q_full = model.expand(q)

    def chain(*lengths: float) -> FloatArray:
        out = np.broadcast_to(np.eye(4), q_full.shape[:-1] + (4, 4))
        for link in _links(lengths, q_full):
            out = out @ link
        return out

    zero = chain(0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    tool_rot = np.swapaxes(zero[..., :3, :3], -1, -2) @ actual[..., :3, :3]
    if np.max(np.abs(tool_rot - tool_rot[0])) > FAMILY_FIT_TOL * 1e3:
        raise ModelError(f"model {model.name!r} is not of the UR family (its joint axes are not the UR's)")
    unit = np.eye(6)
    cols = [chain(*unit[k])[..., :3, 3] for k in range(6)] + [zero[..., :3, 0], zero[..., :3, 1]]
    mat = np.stack(cols, axis=-1).reshape(-1, 8)
    rhs = actual[..., :3, 3].reshape(-1)
    sol, _, rank, _ = np.linalg.lstsq(mat, rhs, rcond=None)
    if rank < mat.shape[1]:
        raise ModelError(f"model {model.name!r}: its lengths cannot be told apart (a lock at a special angle)")
    if np.max(np.abs(mat @ sol - rhs)) > FAMILY_FIT_TOL * max(1.0, float(np.max(np.abs(rhs)))):
        raise ModelError(f"model {model.name!r} is not of the UR family (its positions do not fit the UR's lengths)")
    d1, a2, a3, d4, d5, d6, tx, ty = (float(v) for v in sol)
    if abs(a2) < 1e-9 or abs(a3) < 1e-9 or abs(d6) < 1e-9:
        raise ModelError(f"model {model.name!r}: the UR closed form needs a2, a3, d6 != 0; got {a2}, {a3}, {d6}")
    return URGeometry(d1, a2, a3, d4, d5, d6, pose(tool_rot[0], np.array([tx, ty, 0.0])))


def ur_branches(geometry: URGeometry, target06: ArrayLike) -> tuple[FloatArray, NDArray[np.bool_]]:
    """Every branch for targets given as DH frame 6 (tool removed).

    Returns ``q_full`` (..., 8, 6) [rad] in [-pi, pi) (branch order: shoulder +/- x wrist
    +/- x elbow +/-) and ``valid`` (..., 8): False (and NaN) where a branch has no real
    solution.  At a wrist singularity (``sin theta5 = 0``) theta6 is free and 0 is taken; with
    ``d5 != 0`` that choice can leave joints 2-3 out of reach for a few poses, which then have
    no valid branch here (:func:`jointlock.solve_ik` then finds them numerically).
    """
    g = geometry
    t = np.asarray(target06, dtype=float)
    p05 = t[..., :3, 3] - g.d6 * t[..., :3, 2]
    radius = np.hypot(p05[..., 0], p05[..., 1])
    ok_shoulder = np.abs(g.d4) <= radius * (1 + 1e-12)  # the wrist point outside the shoulder's cylinder
    psi = np.arccos(np.clip(g.d4 / np.where(radius > 0, radius, 1.0), -1.0, 1.0))
    phi = np.arctan2(p05[..., 1], p05[..., 0])
    out = np.full(t.shape[:-2] + (8, 6), np.nan)
    valid = np.zeros(t.shape[:-2] + (8,), dtype=bool)
    t60 = invert(t)
    b = 0
    for s1 in (1.0, -1.0):
        th1 = phi + s1 * psi + math.pi / 2
        c1, sn1 = np.cos(th1), np.sin(th1)
        # cos theta5 = z6 . (s1, -c1, 0), sin from the other components of the unit z6: exact
        # at the wrist singularity, where an arccos of positions / d6 loses half the digits
        w5 = t[..., 0, 2] * sn1 - t[..., 1, 2] * c1
        sin5 = np.hypot(t[..., 2, 2], t[..., 0, 2] * c1 + t[..., 1, 2] * sn1)
        ok5 = ok_shoulder
        for s5 in (1.0, -1.0):
            th5 = s5 * np.arctan2(sin5, w5)
            sn5 = np.sin(th5)
            safe5 = np.where(np.abs(sn5) > 1e-12, sn5, 1.0)
            y = (-t60[..., 1, 0] * sn1 + t60[..., 1, 1] * c1) / safe5
            x = (t60[..., 0, 0] * sn1 - t60[..., 0, 1] * c1) / safe5
            th6 = np.where(np.abs(sn5) > 1e-12, np.arctan2(y, x), 0.0)
            q15 = np.stack([th1, th1 * 0, th1 * 0, th1 * 0, th5, th6], axis=-1)
            links = _links(g.lengths, q15)
            t14 = invert(links[0]) @ t @ invert(links[4] @ links[5])
            px, py = t14[..., 0, 3], t14[..., 1, 3]  # in frame 1's x-y plane: the 2R of joints 2-3
            reach = np.hypot(px, py)
            w3 = (reach**2 - g.a2**2 - g.a3**2) / (2 * g.a2 * g.a3)
            ok3 = ok5 & (np.abs(w3) <= 1 + 1e-12)
            for s3 in (1.0, -1.0):
                th3 = s3 * np.arccos(np.clip(w3, -1.0, 1.0))
                th2 = np.arctan2(py, px) - np.arctan2(g.a3 * np.sin(th3), g.a2 + g.a3 * np.cos(th3))
                q123 = np.stack([th1 * 0, th2, th3, th1 * 0, th1 * 0, th1 * 0], axis=-1)
                l2 = _links(g.lengths, q123)
                t34 = invert(l2[1] @ l2[2]) @ t14
                th4 = np.arctan2(t34[..., 1, 0], t34[..., 0, 0])
                q = np.stack([th1, th2, th3, th4, th5, th6], axis=-1)
                out[..., b, :] = np.where(ok3[..., None], wrap_angle(q), np.nan)
                valid[..., b] = ok3
                b += 1
    return out, valid
