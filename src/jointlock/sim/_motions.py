"""Playing motions in MuJoCo: any ``q(t)`` driven by jointlock's inverse dynamics
(:func:`replay_motion`), waypoints joined by a spline (:func:`replay_waypoints`), and a control
loop's rate steps with momentum-keeping impulses (:func:`replay_steps`)."""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from ..analysis.actuators import actuator_torques
from ..analysis.spacecraft import SpacecraftResponse, spacecraft_response
from ..dynamics import BaseMode, generalized_inertia, mass_matrix, rnea
from ..errors import ConfigurationError
from ..locking import lock_joints
from ..mjcf import TIMESTEP_S
from ..model import ArmModel, FloatArray
from ._player import _check_base, _Player
from ._replay import Replay

#: Bandwidth of the tracking correction [rad/s] (the feed-forward does the work; the correction
#: only holds the joints on the reference against the step's discretisation).
TRACKING_RAD_S = 40.0

#: A trajectory: times (m,) [s] -> q, dq, ddq (m, n) of the healthy joints.
Trajectory = Callable[[FloatArray], tuple[FloatArray, FloatArray, FloatArray]]


def replay_motion(
    model: ArmModel,
    trajectory: Trajectory,
    duration: float,
    *,
    label: str = "motion",
    timestep: float = TIMESTEP_S,
    tracking: float = TRACKING_RAD_S,
    base: str | None = None,
) -> Replay:
    """Play ``trajectory`` (the healthy joints' q, dq, ddq at any times) for ``duration`` [s] in
    MuJoCo on ``model`` (a locked arm with its :attr:`~ArmModel.unlocked` arm; a free
    spacecraft when ``model.floating``, or as ``base`` says: ``"fixed"`` welds a floating model's
    spacecraft, the reading of 000's torques), see the module docstring.

    Raises
    ------
    ConfigurationError
        MuJoCo is not installed (:data:`MUJOCO_MISSING`), or a bad duration or step.
    ModelError
        A locked model without its unlocked arm; a replay that diverged.
    """
    if not (isinstance(duration, (int, float)) and math.isfinite(duration) and duration > 0):
        raise ConfigurationError(f"duration must be a positive number of seconds; got {duration!r}")
    if isinstance(timestep, bool) or not (isinstance(timestep, (int, float)) and 0 < timestep <= min(duration, 1.0)):
        raise ConfigurationError(f"timestep must be in (0, min(duration, 1 s)] [s]; got {timestep!r}")
    floating = _check_base(model, base)
    mode: BaseMode = "floating" if floating else "fixed"
    steps = max(1, math.ceil(duration / timestep - 1e-9))
    timestep = duration / steps  # the replay ends at the motion's end, not past it
    t = np.linspace(0.0, duration, steps + 1)
    q_ref, dq_ref, ddq_ref = trajectory(t)
    q_mid, dq_mid, ddq_mid = trajectory(t[:-1] + 0.5 * timestep)
    feed_now, brake_ref = actuator_torques(model, q_ref, dq_ref, ddq_ref, base=mode)
    feed_mid, _ = actuator_torques(model, q_mid, dq_mid, ddq_mid, base=mode)
    # the correction is an acceleration times the arm's own inertia along the reference (the
    # free-floating H* when the spacecraft floats): critically damped on every joint at once
    inertia = generalized_inertia(model, q_ref) if floating else mass_matrix(model, q_ref)
    kp, kd = tracking**2, 2.0 * tracking

    with _Player(model, floating, timestep, steps + 1) as player:
        data, healthy, healthy_v = player.data, player.healthy, player.healthy - player.shift
        data.qpos[player.braked] = player.lock_angles
        data.qpos[healthy] = q_ref[0]
        data.qvel[healthy_v] = dq_ref[0]
        if floating:  # the twist of zero momentum, at the body origin
            twist = rnea(model, q_ref[0], dq_ref[0], np.zeros(model.dof), base="floating").base_twist
            data.qvel[0:3] = twist[:3] - np.cross(twist[3:], model.root_body.com)
            data.qvel[3:6] = twist[3:]
        for k in range(steps + 1):
            correction = inertia[k] @ (kp * (q_ref[k] - data.qpos[healthy]) + kd * (dq_ref[k] - data.qvel[healthy_v]))
            data.ctrl[:] = feed_now[k] + correction
            if not player.record(k):
                break
            if k < steps:
                player.step(feed_mid[k] + correction)
    reference = spacecraft_response(model, t, q_ref, dq_ref) if floating else None
    return player.result(model, label, t, q_ref, brake_ref, reference)


def replay_waypoints(
    model: ArmModel,
    times: FloatArray,
    q: FloatArray,
    *,
    label: str = "waypoints",
    timestep: float = TIMESTEP_S,
    tracking: float = TRACKING_RAD_S,
) -> Replay:
    """Play waypoints ``q`` (K, n) of the healthy joints at ``times`` (K,) [s], joined by a
    cubic spline (twice differentiable, not-a-knot ends: :class:`scipy.interpolate.CubicSpline`),
    with :func:`replay_motion`.  jointlock's figures in the replay are computed on that spline."""
    from scipy.interpolate import CubicSpline

    times = np.asarray(times, dtype=float)
    if times.ndim != 1 or times.size < 3 or np.any(np.diff(times) <= 0):
        raise ConfigurationError(f"times must be 3 or more increasing times [s]; got shape {times.shape}")
    spline = CubicSpline(times - times[0], np.asarray(q, dtype=float), axis=0)

    def trajectory(t: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
        return spline(t), spline(t, 1), spline(t, 2)

    return replay_motion(
        model, trajectory, float(times[-1] - times[0]), label=label, timestep=timestep, tracking=tracking
    )


def replay_steps(
    model: ArmModel,
    t: FloatArray,
    q: FloatArray,
    qd: FloatArray,
    failures: Sequence[tuple[int, float]],
    *,
    label: str = "control steps",
    timestep: float = TIMESTEP_S,
    tracking: float = TRACKING_RAD_S,
) -> Replay:
    """Play a control loop's run: joint rates ``qd`` (N, n) held over each step
    ``[t_k, t_k+1)`` from ``q`` (N + 1, n) of the whole arm ``model``, each joint of ``failures``
    (``(joint number, time [s])``) locking at its time (rate 0 from that step on, then held by
    its brake: :func:`jointlock.planning.jump.simulate`'s runs).

    At every control step MuJoCo's joint velocities are set to the step's rates (the command of
    an ideal rate servo) and the spacecraft's twist changed by the impulse that keeps the total
    momentum, computed from MuJoCo's own mass matrix (:func:`mujoco.mj_mulM`); within the step
    the motors hold the rates: jointlock's inverse dynamics at zero joint acceleration plus the
    correction of :func:`replay_motion`.  A joint that locks has its brake turned on (a joint
    equality at the angle it has in MuJoCo) and its motor off.  jointlock's figures are the
    spacecraft's response on every MuJoCo step, each control step integrated with its constant
    rates (second order) and the steps chained."""
    t = np.asarray(t, dtype=float)
    q = np.asarray(q, dtype=float)
    qd = np.asarray(qd, dtype=float)
    n_steps = qd.shape[0]
    if t.shape != (n_steps + 1,) or q.shape != (n_steps + 1, model.dof) or qd.shape != (n_steps, model.dof):
        raise ConfigurationError(
            f"t (N+1,), q (N+1, {model.dof}) and qd (N, {model.dof}) must agree; got {t.shape}, {q.shape}, {qd.shape}"
        )
    dt = np.diff(t)
    if n_steps < 1 or not np.allclose(dt, dt[0], rtol=1e-9, atol=0.0) or not dt[0] > 0:
        raise ConfigurationError("the control steps must be equal and positive")
    if model.locked:
        raise ConfigurationError(f"replay_steps takes the whole arm (its joints lock during the run); {model.name!r} is locked")
    floating = _check_base(model, None)
    sub = max(1, math.ceil(dt[0] / timestep - 1e-9))
    h = float(dt[0]) / sub
    lock_steps = {int(j): int(np.searchsorted(t, tf - 1e-9 * dt[0])) for j, tf in failures}
    locked = lock_joints(model, {j: float(q[k, model.joint_numbers.index(j)]) for j, k in lock_steps.items()})
    index = {j: i for i, j in enumerate(model.joint_numbers)}

    # the reference on every MuJoCo step: q linear within each control step, rates constant
    step_of = np.repeat(np.arange(n_steps), sub)
    frac = np.tile(np.arange(sub) * h, n_steps)
    fine_t = np.append(t[0] + np.arange(n_steps * sub) * h, t[-1]) - t[0]
    fine_q = np.vstack([q[step_of] + frac[:, None] * qd[step_of], q[-1:]])
    mid_q = q[step_of] + (frac + 0.5 * h)[:, None] * qd[step_of]
    mode: BaseMode = "floating" if floating else "fixed"
    zero = np.zeros_like(mid_q)
    feed = rnea(model, mid_q, qd[step_of], zero, base=mode).torques
    # the last sample still has the last step's rates (MuJoCo's are not reset after the run)
    loads = rnea(model, fine_q, np.vstack([qd[step_of], qd[-1:]]), np.zeros_like(fine_q), base=mode).torques
    brake_ref = np.zeros((fine_t.size, len(lock_steps)))
    for i, (j, k) in enumerate(lock_steps.items()):
        brake_ref[k * sub :, i] = loads[k * sub :, index[j]]
    inertia = generalized_inertia(model, fine_q[:-1]) if floating else mass_matrix(model, fine_q[:-1])
    kp, kd = tracking**2, 2.0 * tracking

    with _Player(locked, floating, h, fine_t.size, brakes_engaged=False) as player:
        mujoco, mm, data = player.mujoco, player.mm, player.data
        joints_v = player.qpos - player.shift
        data.qpos[player.qpos] = q[0]
        healthy_cols = [index[j] for j in locked.joint_numbers]
        mask = np.ones(model.dof, dtype=bool)
        brake_id = {j: mujoco.mj_name2id(mm, mujoco.mjtObj.mjOBJ_EQUALITY, f"brake{j}") for j in lock_steps}
        stable = True
        for k in range(n_steps):
            for j, kf in lock_steps.items():
                if kf == k:  # the brake engages where the joint is
                    mm.eq_data[brake_id[j], 0] = data.qpos[player.qpos[index[j]]]
                    data.eq_active[brake_id[j]] = 1
                    mask[index[j]] = False
            mujoco.mj_forward(mm, data)
            _set_rates(mujoco, mm, data, joints_v, qd[k], floating)
            for s in range(sub):
                i = k * sub + s
                error = kp * (fine_q[i] - data.qpos[player.qpos]) + kd * (qd[k] - data.qvel[joints_v])
                ctrl = (feed[i] + inertia[i] @ error) * mask
                data.ctrl[:] = ctrl
                if not (stable := player.record(i)):
                    break
                player.step(ctrl)
            if not stable:
                break
        if stable:
            player.record(fine_t.size - 1)
    for i, k in enumerate(lock_steps.values()):
        player.locked_angle[: k * sub, i] = 0.0  # the joint moves until it locks: no brake to give yet
    reference = _stepwise_response(model, fine_t, fine_q, qd, sub) if floating else None
    return player.result(locked, label, fine_t, fine_q[:, healthy_cols], brake_ref, reference)


def _set_rates(mujoco: Any, mm: Any, data: Any, joints_v: np.ndarray, rates: FloatArray, floating: bool) -> None:
    """Set the joints' velocities to ``rates``; a free spacecraft takes the impulse that keeps the
    system's momentum (the base rows of MuJoCo's ``M v``) unchanged."""
    before = data.qvel.copy()
    data.qvel[joints_v] = rates
    if not floating:
        return
    nv = mm.nv
    change = np.zeros(nv)
    change[joints_v] = rates - before[joints_v]
    pushed = np.zeros(nv)
    mujoco.mj_mulM(mm, data, pushed, change)
    block = np.empty((6, 6))
    unit, column = np.zeros(nv), np.zeros(nv)
    for i in range(6):
        unit[:] = 0.0
        unit[i] = 1.0
        mujoco.mj_mulM(mm, data, column, unit)
        block[:, i] = column[:6]
    data.qvel[:6] = before[:6] - np.linalg.solve(block, pushed[:6])


def _stepwise_response(model: ArmModel, t: FloatArray, q: FloatArray, qd: FloatArray, sub: int) -> SpacecraftResponse:
    """The spacecraft's response to rates ``qd`` (N, n) held over control steps of ``sub`` samples
    of ``t``, ``q``: each step integrated with its constant rates (second order,
    :func:`spacecraft_response`), the steps chained (attitude products, drift in the first frame)."""
    from ..analysis.spacecraft import _quaternion_product
    from ..spatial import quaternion_matrix

    attitude = np.empty((t.size, 4))
    drift = np.empty((t.size, 3))
    rate = np.empty((t.size, 3))
    start_q, start_d = np.array([1.0, 0.0, 0.0, 0.0]), np.zeros(3)
    for k in range(qd.shape[0]):
        a, b = k * sub, (k + 1) * sub
        seg = spacecraft_response(model, t[a : b + 1], q[a : b + 1], np.repeat(qd[k : k + 1], b - a + 1, axis=0))
        attitude[a : b + 1] = _quaternion_product(np.broadcast_to(start_q, seg.attitude.shape), seg.attitude)
        drift[a : b + 1] = start_d + seg.com_displacement @ quaternion_matrix(start_q).T
        rate[a : b + 1] = seg.angular_velocity  # a step's end is the next one's start: overwritten there
        start_q, start_d = attitude[b] / np.linalg.norm(attitude[b]), drift[b].copy()
    return SpacecraftResponse(t, attitude, rate, drift)
