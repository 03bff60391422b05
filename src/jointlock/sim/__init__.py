"""Replay a motion in MuJoCo and compare what the simulator's spacecraft and brakes do with
what jointlock computes (issue 30; optional extra ``jointlock[mujoco]``): a halt
(:func:`replay_halt`), the jump study's runs (:func:`replay_jump`: a control loop's rates,
:func:`replay_steps`), a re-plan (:func:`replay_replan`: waypoints joined by a spline), or any
motion (:func:`replay_motion`); every one of a run (:func:`replay_jobs`).

The arm is written by :func:`jointlock.mjcf.mjcf_text` with ``brakes=True``: the unlocked chain,
each locked joint a hinge held at its lock angle by a joint equality (its constraint torque is
MuJoCo's brake torque), the spacecraft a free body when the model floats (welded otherwise).
The healthy joints are driven by motors whose torque is jointlock's inverse dynamics of the
motion (:func:`jointlock.analysis.actuators.actuator_torques`, the spacecraft free or held as
the model is) plus a stiff tracking correction
``M (w^2 (q_ref - q) + 2 w (dq_ref - dq))`` (critically damped at ``w``, :data:`TRACKING_RAD_S`,
on every joint at once: ``M`` is the arm's inertia along the reference, the free-floating
``H*`` when the spacecraft floats); the feed-forward is sampled at the
middle of each step (second order in the step).  The spacecraft starts with the twist of zero
momentum (what jointlock assumes), contacts are off (the clearance is jointlock's to report: a
colliding motion should not bounce), joint and control limits are off (a motion over a limit is
still replayed; jointlock reports the limit).  MuJoCo integrates with fourth-order Runge-Kutta
at ``timestep`` (default :data:`jointlock.mjcf.TIMESTEP_S`).

MuJoCo is independent of jointlock's dynamics: its own composite-rigid-body algorithm,
constraint solver and integrator.  Agreement is a check of the model transfer, the inverse
dynamics, the zero-momentum spacecraft kinematics and the brake torque at once.

Modules (private; import from ``jointlock.sim``): ``_replay`` (the result), ``_player`` (one arm
in MuJoCo), ``_motions`` (playing a motion), ``_jobs`` (the jobs' motions).
"""

from __future__ import annotations

from ._jobs import (
    REPLAYED_JOBS,
    replay_halt,
    replay_jobs,
    replay_jump,
    replay_replan,
    write_attitude_with_replay,
)
from ._motions import TRACKING_RAD_S, replay_motion, replay_steps, replay_waypoints
from ._player import MUJOCO_MISSING, require_mujoco
from ._replay import Replay

__all__ = [
    "MUJOCO_MISSING",
    "REPLAYED_JOBS",
    "TRACKING_RAD_S",
    "Replay",
    "replay_halt",
    "replay_jobs",
    "replay_jump",
    "replay_motion",
    "replay_replan",
    "replay_steps",
    "replay_waypoints",
    "require_mujoco",
    "write_attitude_with_replay",
]
