"""Poses and angles for the inverse kinematics (see :mod:`jointlock.ik`): 002's ZYX Euler
angles, angle wrapping, the check of target poses, and the tolerances that call a pose exact."""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from ..errors import ConfigurationError
from ..model import FloatArray
from ..spatial import pose, rot_x, rot_y, rot_z

#: A branch is *exact* when its position error is below this [m] ...
EXACT_POSITION_TOL = 1e-7
#: ... and its rotation error below this [rad].  Round-off alone gives ~1e-12 away from
#: singularities; at the boundary of reach (``|W| -> 1``) ``sqrt(1 - W^2)`` loses half the
#: digits, hence the margin.
EXACT_ROTATION_TOL = 1e-7


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


def turns_into_limits(angle: ArrayLike, lower: ArrayLike, upper: ArrayLike) -> FloatArray:
    """Angles (..., n) [rad] moved by whole turns into their limits ``[lower, upper]`` (n,),
    which may lie past +-pi: an angle inside stays as it is, one outside takes the smallest
    move that lands it inside; where no move does (a range under one turn), the angle is
    wrapped to the turn centred on its range.  A joint without limits is wrapped to
    [-pi, pi) (one representative; nothing bounds it).  Nothing is clipped: the pose is kept."""
    q = np.asarray(angle, dtype=float)
    lo = np.broadcast_to(np.asarray(lower, dtype=float), q.shape)
    hi = np.broadcast_to(np.asarray(upper, dtype=float), q.shape)
    turn = 2.0 * math.pi
    with np.errstate(invalid="ignore"):  # NaN angles (invalid IK branches) stay NaN
        up = np.where(np.isfinite(lo), q + turn * np.ceil((lo - q) / turn), q)  # smallest >= lo
        down = np.where(np.isfinite(hi), q - turn * np.ceil((q - hi) / turn), q)  # largest <= hi
    moved = np.where(q < lo, up, down)
    fits = (moved >= lo) & (moved <= hi)
    both, free = np.isfinite(lo) & np.isfinite(hi), ~np.isfinite(lo) & ~np.isfinite(hi)
    lo_f, hi_f = np.where(np.isfinite(lo), lo, 0.0), np.where(np.isfinite(hi), hi, 0.0)
    mid = np.where(both, 0.5 * (lo_f + hi_f), np.where(np.isfinite(lo), lo_f + math.pi, np.where(free, 0.0, hi_f - math.pi)))
    inside = (q >= lo) & (q <= hi) & ~free
    return np.where(inside, q, np.where(fits & ~free, moved, wrap_angle(q - mid) + mid))


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
