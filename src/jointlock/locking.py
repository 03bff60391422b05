"""Locking joints: fold a locked joint into the chain and merge the two bodies it joined.

SPEC piece 2 and 000 §3.1.1: when joint ``l`` locks at angle ``theta_l``, links ``l-1`` and
``l`` become one rigid body: total mass, mass-weighted centre of mass, and inertias moved to
the common centre of mass (parallel-axis theorem) after rotating link ``l``'s inertia into
link ``l-1``'s frame.  000 writes the merge in the inertial frame; here it is done once, in
the parent's body frame, which is equivalent and configuration independent.

The reduced model behaves exactly like the full model with the joint frozen: same link
poses, the same Jacobian without the locked column, the same mass matrix without the locked
row and column.  Locking joint 1 merges link 1 into the root body (the spacecraft, for a
free-floating arm); locking the last joint folds its transform into the tool.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import replace

import numpy as np

from .bounds import as_real
from .errors import ModelError
from .model import ArmModel, LockedJoint
from .spatial import axis_angle_rotation, pose

#: Slack allowed when checking a lock angle against the joint limits [rad].
LOCK_LIMIT_SLACK = 1e-9


def lock(model: ArmModel, joint: int, angle: float, *, check_limits: bool = True) -> ArmModel:
    """Return a new model with joint number ``joint`` locked at ``angle``.

    Parameters
    ----------
    model
        The arm (possibly already with locked joints).
    joint
        The joint's number in the full arm, 1-based as in the papers (numbers do not shift
        after earlier locks).
    angle
        Angle at which it locked [rad].
    check_limits
        Refuse an angle outside the joint's position limits.

    Returns
    -------
    ArmModel
        ``model.dof - 1`` movable joints; ``locked`` gains ``LockedJoint(joint, angle)``;
        ``unlocked`` is the arm before its first lock.
    """
    index, angle = check_lock(model, joint, angle, check_limits=check_limits)
    jnt = model.joints[index]

    # Pose of the locked joint's frame in its parent's frame, now constant.
    frozen = jnt.placement @ pose(axis_angle_rotation(jnt.axis, angle), np.zeros(3))

    joints = list(model.joints)
    bodies = list(model.bodies)
    tool = model.tool
    root_body = model.root_body
    if index + 1 < model.dof:
        nxt = joints[index + 1]
        joints[index + 1] = replace(nxt, placement=frozen @ nxt.placement)
    else:
        tool = frozen @ tool
    if index == 0:
        root_body = root_body.merged(bodies[0], frozen, name=root_body.name)
    else:
        bodies[index - 1] = bodies[index - 1].merged(bodies[index], frozen)
    del joints[index]
    del bodies[index]
    return replace(
        model,
        joints=tuple(joints),
        bodies=tuple(bodies),
        tool=tool,
        root_body=root_body,
        locked=model.locked + (LockedJoint(int(joint), angle),),
        unlocked=model.unlocked if model.locked else model,
    )


def check_lock(model: ArmModel, joint: int, angle: float, *, check_limits: bool = True) -> tuple[int, float]:
    """What :func:`lock` checks, without building the locked model (a scenario's validation,
    once per case of a campaign): ``(index of the joint among the movable ones, angle [rad])``.

    Raises
    ------
    ModelError
        As :func:`lock`: not a joint number of ``model`` (or already locked), the angle not a
        real number or outside the joint's limits, or the joint the only movable one.
    """
    if isinstance(joint, bool) or not isinstance(joint, (int, np.integer)):
        raise ModelError(f"joint must be an integer joint number (1-based); got {joint!r}")
    index = model.index_of(int(joint))
    angle = as_real(angle, f"lock angle of joint {joint}", unit="rad", error=ModelError)
    jnt = model.joints[index]
    if check_limits and not (jnt.lower - LOCK_LIMIT_SLACK <= angle <= jnt.upper + LOCK_LIMIT_SLACK):
        raise ModelError(
            f"lock angle of joint {joint} must lie within its limits "
            f"[{math.degrees(jnt.lower):.10g}, {math.degrees(jnt.upper):.10g}] deg; "
            f"got {math.degrees(angle):.10g} deg"
        )
    if model.dof == 1:
        raise ModelError(f"cannot lock joint {joint}: it is the only movable joint of {model.name!r}")
    return index, angle


def lock_joints(model: ArmModel, locks: Mapping[int, float], *, check_limits: bool = True) -> ArmModel:
    """Lock several joints: ``locks`` maps joint numbers (1-based) to angles [rad]."""
    for number, angle in locks.items():
        model = lock(model, number, angle, check_limits=check_limits)
    return model
