"""Small batched helpers for rotations and homogeneous transforms.

Every function accepts leading batch dimensions.  Poses are 4x4 homogeneous matrices
``T_a_b`` mapping points in frame ``b`` to frame ``a``.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

FloatArray = NDArray[np.float64]


def rot_x(angle: ArrayLike) -> FloatArray:
    """(..., 4, 4) rotation about x by ``angle`` [rad]."""
    return _rot(np.asarray(angle, dtype=float), 0)


def rot_y(angle: ArrayLike) -> FloatArray:
    """(..., 4, 4) rotation about y by ``angle`` [rad]."""
    return _rot(np.asarray(angle, dtype=float), 1)


def rot_z(angle: ArrayLike) -> FloatArray:
    """(..., 4, 4) rotation about z by ``angle`` [rad]."""
    return _rot(np.asarray(angle, dtype=float), 2)


def _rot(angle: FloatArray, axis: int) -> FloatArray:
    c, s = np.cos(angle), np.sin(angle)
    out = np.zeros(angle.shape + (4, 4))
    out[..., 3, 3] = 1.0
    i, j = [(1, 2), (2, 0), (0, 1)][axis]
    out[..., axis, axis] = 1.0
    out[..., i, i] = c
    out[..., j, j] = c
    out[..., i, j] = -s
    out[..., j, i] = s
    return out


def translation(xyz: ArrayLike) -> FloatArray:
    """(..., 4, 4) pure translation by ``xyz`` (..., 3) [m]."""
    xyz = np.asarray(xyz, dtype=float)
    out = np.zeros(xyz.shape[:-1] + (4, 4))
    out[..., [0, 1, 2, 3], [0, 1, 2, 3]] = 1.0
    out[..., :3, 3] = xyz
    return out


def skew(v: ArrayLike) -> FloatArray:
    """(..., 3, 3) cross-product matrix of ``v`` (..., 3): ``skew(a) @ b == cross(a, b)``."""
    v = np.asarray(v, dtype=float)
    out = np.zeros(v.shape[:-1] + (3, 3))
    out[..., 0, 1] = -v[..., 2]
    out[..., 0, 2] = v[..., 1]
    out[..., 1, 0] = v[..., 2]
    out[..., 1, 2] = -v[..., 0]
    out[..., 2, 0] = -v[..., 1]
    out[..., 2, 1] = v[..., 0]
    return out


def axis_angle_rotation(axis: ArrayLike, angle: ArrayLike) -> FloatArray:
    """Rodrigues' formula: (..., 3, 3) rotation by ``angle`` (...) [rad] about unit ``axis`` (..., 3)."""
    axis = np.asarray(axis, dtype=float)
    angle = np.asarray(angle, dtype=float)[..., None, None]
    k = skew(axis)
    return np.eye(3) + np.sin(angle) * k + (1.0 - np.cos(angle)) * (k @ k)


def quaternion_matrix(quaternion: ArrayLike) -> FloatArray:
    """(..., 3, 3) rotation of unit quaternions (..., 4) ``(w, x, y, z)`` (Hamilton, active)."""
    qt = np.asarray(quaternion, dtype=float)
    qt = qt / np.linalg.norm(qt, axis=-1, keepdims=True)
    w, x, y, z = np.moveaxis(qt, -1, 0)
    rows = [
        [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
    ]
    return np.stack([np.stack(r, axis=-1) for r in rows], axis=-2)


def rpy_matrix(rpy: ArrayLike) -> FloatArray:
    """URDF roll-pitch-yaw (fixed axes x, y, z): ``R = Rz(yaw) Ry(pitch) Rx(roll)``, (..., 3, 3)."""
    rpy = np.asarray(rpy, dtype=float)
    return (rot_z(rpy[..., 2]) @ rot_y(rpy[..., 1]) @ rot_x(rpy[..., 0]))[..., :3, :3]


def pose(rotation: ArrayLike, position: ArrayLike) -> FloatArray:
    """(..., 4, 4) homogeneous transform from rotation (..., 3, 3) and position (..., 3)."""
    rotation = np.asarray(rotation, dtype=float)
    position = np.asarray(position, dtype=float)
    shape = np.broadcast_shapes(rotation.shape[:-2], position.shape[:-1])
    out = np.zeros(shape + (4, 4))
    out[..., :3, :3] = rotation
    out[..., :3, 3] = position
    out[..., 3, 3] = 1.0
    return out


def invert(transform: ArrayLike) -> FloatArray:
    """Inverse of homogeneous transforms (..., 4, 4)."""
    t = np.asarray(transform, dtype=float)
    rt = np.swapaxes(t[..., :3, :3], -1, -2)
    return pose(rt, -np.einsum("...ij,...j->...i", rt, t[..., :3, 3]))


def rotation_log(rotation: ArrayLike) -> FloatArray:
    """Log map SO(3) -> rotation vector (..., 3) [rad], robust near 0 and pi."""
    r = np.asarray(rotation, dtype=float)
    cos_angle = np.clip((np.trace(r, axis1=-2, axis2=-1) - 1.0) / 2.0, -1.0, 1.0)
    vee = np.stack(
        [r[..., 2, 1] - r[..., 1, 2], r[..., 0, 2] - r[..., 2, 0], r[..., 1, 0] - r[..., 0, 1]],
        axis=-1,
    )
    sin_angle = 0.5 * np.linalg.norm(vee, axis=-1)  # exact sin, not sin(arccos(.))
    angle = np.arctan2(sin_angle, cos_angle)
    small = sin_angle < 1e-6
    scale = np.where(small, 0.5 + angle**2 / 12.0, angle / (2.0 * np.where(small, 1.0, sin_angle)))
    out = scale[..., None] * vee
    # Near pi the antisymmetric part vanishes: take the axis from the symmetric part.
    near_pi = small & (cos_angle < 0)
    if np.any(near_pi):
        sym = (r[near_pi] + np.swapaxes(r[near_pi], -1, -2)) / 2.0 - np.eye(3) * cos_angle[near_pi][
            ..., None, None
        ]
        col = np.argmax(np.linalg.norm(sym, axis=-2), axis=-1)
        axis = np.take_along_axis(sym, col[..., None, None], axis=-1)[..., 0]
        axis /= np.linalg.norm(axis, axis=-1, keepdims=True)
        sign = np.sign(np.einsum("...i,...i->...", axis, vee[near_pi]))
        axis *= np.where(sign == 0, 1.0, sign)[..., None]
        out[near_pi] = axis * angle[near_pi][..., None]
    return out


def pose_error(target: ArrayLike, actual: ArrayLike) -> tuple[FloatArray, FloatArray]:
    """Position error [m] and rotation-angle error [rad] between poses (..., 4, 4)."""
    target = np.asarray(target, dtype=float)
    actual = np.asarray(actual, dtype=float)
    dp = np.linalg.norm(target[..., :3, 3] - actual[..., :3, 3], axis=-1)
    dr = np.swapaxes(target[..., :3, :3], -1, -2) @ actual[..., :3, :3]
    return dp, np.linalg.norm(rotation_log(dr), axis=-1)


def _wrap(angle: ArrayLike) -> NDArray[np.float64]:
    """Angles wrapped to [-pi, pi) [rad]."""
    return (np.asarray(angle, dtype=float) + np.pi) % (2.0 * np.pi) - np.pi


def turns_into_limits(angle: ArrayLike, lower: ArrayLike, upper: ArrayLike) -> NDArray[np.float64]:
    """Angles (..., n) [rad] moved by whole turns into their limits ``[lower, upper]`` (n,),
    which may lie past +-pi: an angle inside stays as it is, one outside takes the smallest
    move that lands it inside; where no move does (a range under one turn), the angle is
    wrapped to the turn centred on its range.  A joint without limits is wrapped to
    [-pi, pi) (one representative; nothing bounds it).  Nothing is clipped: the pose is kept."""
    q = np.asarray(angle, dtype=float)
    lo = np.broadcast_to(np.asarray(lower, dtype=float), q.shape)
    hi = np.broadcast_to(np.asarray(upper, dtype=float), q.shape)
    turn = 2.0 * np.pi
    with np.errstate(invalid="ignore"):  # NaN angles (invalid IK branches) stay NaN
        up = np.where(np.isfinite(lo), q + turn * np.ceil((lo - q) / turn), q)  # smallest >= lo
        down = np.where(np.isfinite(hi), q - turn * np.ceil((q - hi) / turn), q)  # largest <= hi
    moved = np.where(q < lo, up, down)
    fits = (moved >= lo) & (moved <= hi)
    both, free = np.isfinite(lo) & np.isfinite(hi), ~np.isfinite(lo) & ~np.isfinite(hi)
    lo_f, hi_f = np.where(np.isfinite(lo), lo, 0.0), np.where(np.isfinite(hi), hi, 0.0)
    mid = np.where(both, 0.5 * (lo_f + hi_f), np.where(np.isfinite(lo), lo_f + np.pi, np.where(free, 0.0, hi_f - np.pi)))
    inside = (q >= lo) & (q <= hi) & ~free
    return np.where(inside, q, np.where(fits & ~free, moved, _wrap(q - mid) + mid))
