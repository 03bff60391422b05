"""Poses and angles for the inverse kinematics (see :mod:`jointlock.ik`): 002's ZYX Euler
angles, angle wrapping, the check of target poses, and the tolerances that call a pose exact."""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from ..errors import ConfigurationError, ModelError
from ..model import ArmModel, FloatArray
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


def check_six_joints(model: ArmModel, form: str) -> None:
    """A closed form's precondition: six joints, at most one locked (else a ModelError)."""
    if model.full_dof != 6 or len(model.locked) > 1:
        raise ModelError(
            f"model {model.name!r}: the {form} closed form needs a 6-joint arm with at most one locked joint; "
            f"got {model.full_dof} joints, {len(model.locked)} locked"
        )


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
