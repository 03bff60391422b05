"""What the actuators feel during a motion of a crippled arm: the motor torques of the healthy
joints and the **brake reaction torque** of every locked joint.

A locked joint is held by its brake: the arm is the full arm with that joint's angle frozen
(rate and acceleration zero), and the brake delivers whatever torque about the joint's axis
keeps it there.  That constraint torque is the full arm's inverse dynamics at the locked
joint (000 eqs. 28-29 on the arm before the lock), with the healthy joints' torques the same
as the locked model's (checked in the tests, and against Pinocchio's ``rnea`` on the full
model with the locked joint held, fixed and free-floating).  With a free-floating base the
spacecraft reacts with zero momentum, as in :func:`jointlock.dynamics.rnea`.  No gravity
(orbit).

Sign: the torque the actuator applies to the outboard link about the joint's axis [N m].
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from ..dynamics import BaseMode, rnea
from ..errors import ModelError
from ..model import ArmModel, FloatArray, as_joint_array


def _expand_held(model: ArmModel, values: FloatArray, locked_values: FloatArray) -> FloatArray:
    """(..., n_full) full-arm vector from the healthy joints' (..., n) and the locked ones'
    ``locked_values`` (n_locked,), in joint-number order."""
    numbers = list(model.joint_numbers) + [lj.number for lj in model.locked]
    order = np.argsort(numbers)
    held = np.broadcast_to(locked_values, values.shape[:-1] + (len(model.locked),))
    return np.concatenate([values, held], axis=-1)[..., order]


def actuator_torques(
    model: ArmModel, q: ArrayLike, dq: ArrayLike, ddq: ArrayLike, *, base: BaseMode = "fixed"
) -> tuple[FloatArray, FloatArray]:
    """Motor torques of the healthy joints and brake torques of the locked joints.

    Parameters
    ----------
    model
        The locked arm; its :attr:`~jointlock.model.ArmModel.unlocked` arm (kept by
        :func:`jointlock.locking.lock`) gives the brake torques.
    q, dq, ddq
        (..., n) healthy-joint angles [rad], rates [rad/s], accelerations [rad/s^2].
    base
        ``"fixed"`` (spacecraft held) or ``"floating"`` (zero momentum).

    Returns
    -------
    motor, brake
        (..., n) [N m] in :attr:`ArmModel.joint_numbers` order, and (..., n_locked) [N m] in
        :attr:`ArmModel.locked` order (empty last axis for an arm without locks).

    Raises
    ------
    ModelError
        A locked model without its unlocked arm (e.g. built by hand): the brake cannot be
        computed.
    """
    q = as_joint_array(model, q, "q")
    dq = as_joint_array(model, dq, "dq")
    ddq = as_joint_array(model, ddq, "ddq")
    if not model.locked:
        motor = rnea(model, q, dq, ddq, base=base).torques
        return motor, np.zeros(motor.shape[:-1] + (0,))
    full = model.unlocked
    if full is None:
        raise ModelError(
            f"the brake torques of {model.name!r} need the arm before its locks (ArmModel.unlocked), "
            "which jointlock.lock keeps; this model has locked joints but not that arm"
        )
    angles = np.array([lj.angle for lj in model.locked])
    zeros = np.zeros(len(model.locked))
    torques = rnea(
        full,
        _expand_held(model, q, angles),
        _expand_held(model, dq, zeros),
        _expand_held(model, ddq, zeros),
        base=base,
    ).torques
    motor = torques[..., [full.index_of(n) for n in model.joint_numbers]]
    brake = torques[..., [full.index_of(lj.number) for lj in model.locked]]
    return motor, brake


@dataclass(frozen=True, eq=False)  # arrays inside: compare to_dict() instead
class ActuatorLoads:
    """Motor and brake torques over a motion.

    Attributes
    ----------
    t
        (m,) times [s].
    joint_numbers
        The healthy joints (motors), 1-based.
    motor
        (m, n) motor torques [N m].
    locked_numbers
        The locked joints (brakes), 1-based.
    brake
        (m, n_locked) brake reaction torques [N m].
    base
        ``"fixed"`` or ``"floating"``.
    """

    t: FloatArray
    joint_numbers: tuple[int, ...]
    motor: FloatArray
    locked_numbers: tuple[int, ...]
    brake: FloatArray
    base: str

    @property
    def peak_motor(self) -> FloatArray:
        """(n,) largest |motor torque| of each healthy joint [N m]."""
        return np.abs(self.motor).max(axis=0)

    @property
    def peak_brake(self) -> FloatArray:
        """(n_locked,) largest |brake torque| of each locked joint [N m]."""
        return np.abs(self.brake).max(axis=0) if self.brake.shape[1] else np.zeros(0)

    def to_dict(self) -> dict[str, Any]:
        """Peaks [N m] by joint number."""
        return {
            "base": self.base,
            "peak_motor_torque_Nm": {str(j): float(v) for j, v in zip(self.joint_numbers, self.peak_motor)},
            "peak_brake_torque_Nm": {str(j): float(v) for j, v in zip(self.locked_numbers, self.peak_brake)},
        }

    def columns(self) -> dict[str, FloatArray]:
        """CSV columns: ``tau{j}_Nm`` per motor, ``brake{j}_Nm`` per brake."""
        cols = {f"tau{j}_Nm": self.motor[:, i] for i, j in enumerate(self.joint_numbers)}
        cols.update({f"brake{j}_Nm": self.brake[:, i] for i, j in enumerate(self.locked_numbers)})
        return cols


def actuator_loads(
    model: ArmModel, t: ArrayLike, q: ArrayLike, dq: ArrayLike, ddq: ArrayLike, *, base: BaseMode = "fixed"
) -> ActuatorLoads:
    """:func:`actuator_torques` along a motion sampled at ``t`` (m,) [s], as
    :class:`ActuatorLoads`; ``q``, ``dq``, ``ddq`` are (m, n)."""
    t = np.asarray(t, dtype=float)
    motor, brake = actuator_torques(model, q, dq, ddq, base=base)
    if motor.shape[:-1] != t.shape:
        raise ModelError(f"t must have one time per sample: got {t.shape} for samples {motor.shape[:-1]}")
    return ActuatorLoads(t, model.joint_numbers, motor, tuple(lj.number for lj in model.locked), brake, base)
