"""Result types of :func:`jointlock.planning.replan.replan_line`: the plan and its flagged
steps."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ...model import FloatArray


@dataclass(frozen=True)
class StepFlag:
    """One joint's motion between waypoints ``index`` and ``index + 1`` that is flagged.

    Attributes
    ----------
    index
        The step goes from waypoint ``index`` to ``index + 1``.
    time
        [s] at waypoint ``index``.
    joint
        Full-arm number (1-based) of the joint.
    step
        Its change over the step [rad] (absolute, wrapped).
    rate
        ``step / cycle`` [rad/s].
    limit
        The threshold it exceeds: [rad] for a jump, [rad/s] for a velocity limit.
    """

    index: int
    time: float
    joint: int
    step: float
    rate: float
    limit: float


@dataclass(frozen=True)
class ReplanResult:
    """A straight Cartesian plan executed by the locked arm.

    Attributes
    ----------
    times
        (K,) [s], ``cycle`` apart (002: 250 ms).
    q
        (K, n) movable-joint angles [rad], unwrapped in time.
    q_full
        (K, 6) with the locked joint [rad].
    dq
        (K, n) joint rates [rad/s] (central differences).
    gamma
        (K,) rotation about the tool x axis chosen at each waypoint [rad], within the tolerance.
    absorbed
        (K,) the lock is absorbed exactly: the locked arm reaches ``nominal Rx(gamma)``
        (tracking error within :data:`jointlock.ik.EXACT_POSITION_TOL` /
        :data:`~jointlock.ik.EXACT_ROTATION_TOL`).
    nominal
        (K, 4, 4) the straight-line poses [m].
    target
        (K, 4, 4) ``nominal Rx(gamma)``: what the locked arm is asked to reach.
    actual
        (K, 4, 4) forward kinematics of ``q``.
    position_error, rotation_error
        (K,) actual vs target [m], [rad] (the tracking error).
    position_deviation, rotation_deviation
        (K,) actual vs nominal [m], [rad] (includes the accepted gamma).
    ee_velocity
        (K, 6) end-effector twist ``(v, omega)`` [m/s, rad/s], finite differences, root frame.
    joint, lock_angle, gamma_tolerance, branch, cycle
        The settings (``branch``: the full-arm branch followed at the goal).
    joint_step
        (K-1, n) ``|q[k+1] - q[k]|`` per movable joint [rad].
    velocity_limit
        (n,) the model's joint speed limits [rad/s] (``inf`` when unknown).
    jump_threshold
        A step of any joint above this is a jump [rad].
    jumps
        Every (step, joint) above ``jump_threshold``, in time order.
    over_velocity
        Every (step, joint) whose ``joint_step / cycle`` exceeds the joint's speed limit.
    method
        ``"continuous"`` (gamma and branch chosen along the path) or ``"pointwise"``
        (each waypoint on its own, the first implementation).
    """

    times: FloatArray
    q: FloatArray
    q_full: FloatArray
    dq: FloatArray
    gamma: FloatArray
    absorbed: np.ndarray
    nominal: FloatArray
    target: FloatArray
    actual: FloatArray
    position_error: FloatArray
    rotation_error: FloatArray
    position_deviation: FloatArray
    rotation_deviation: FloatArray
    ee_velocity: FloatArray
    joint: int
    lock_angle: float
    gamma_tolerance: float
    branch: int
    cycle: float
    joint_step: FloatArray = field(default_factory=lambda: np.zeros((0, 0)))
    velocity_limit: FloatArray = field(default_factory=lambda: np.zeros(0))
    jump_threshold: float = math.inf
    jumps: tuple[StepFlag, ...] = ()
    over_velocity: tuple[StepFlag, ...] = ()
    method: str = "pointwise"

    @property
    def max_joint_step(self) -> float:
        """Largest change of any joint between neighbouring waypoints [rad]."""
        return float(self.joint_step.max()) if self.joint_step.size else 0.0

    @property
    def max_joint_step_at(self) -> tuple[int, int]:
        """``(index, joint)``: the step ``index -> index + 1`` and the full-arm joint number
        of :attr:`max_joint_step`."""
        if not self.joint_step.size:
            return (0, 0)
        i, j = np.unravel_index(int(np.argmax(self.joint_step)), self.joint_step.shape)
        numbers = [n for n in range(1, self.q_full.shape[1] + 1) if n != self.joint]
        return int(i), int(numbers[j])

    @property
    def step_rate(self) -> FloatArray:
        """(K-1, n) ``joint_step / cycle`` [rad/s]: the speed each step needs."""
        return self.joint_step / self.cycle
