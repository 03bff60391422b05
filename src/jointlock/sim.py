"""Replay a motion in MuJoCo and compare what the simulator's spacecraft and brakes do with
what jointlock computes (issue 30; optional extra ``jointlock[mujoco]``).

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
colliding motion should not bounce), control limits are off (a motion over a torque limit is
still replayed; jointlock reports the limit).  MuJoCo integrates with fourth-order Runge-Kutta
at ``timestep`` (default :data:`jointlock.mjcf.TIMESTEP_S`).

MuJoCo is independent of jointlock's dynamics: its own composite-rigid-body algorithm,
constraint solver and integrator.  Agreement is a check of the model transfer, the inverse
dynamics, the zero-momentum spacecraft kinematics and the brake torque at once.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from .analysis.actuators import actuator_torques
from .analysis.spacecraft import SpacecraftResponse, spacecraft_response
from .dynamics import BaseMode, generalized_inertia, mass_matrix, rnea
from .errors import ConfigurationError, ModelError
from .io.files import atomic_write_json, atomic_write_text, csv_text, with_svg, write_figure
from .mjcf import TIMESTEP_S, mjcf_text
from .model import ArmModel, FloatArray

__all__ = ["MUJOCO_MISSING", "REPLAYED_JOBS", "TRACKING_RAD_S", "Replay", "replay_halt", "replay_jobs", "replay_motion"]

#: The one line a user without the extra sees.
MUJOCO_MISSING = "the MuJoCo check needs MuJoCo: pip install 'jointlock[mujoco]' (or pip install mujoco)"
#: Bandwidth of the tracking correction [rad/s] (the feed-forward does the work; the correction
#: only holds the joints on the reference against the step's discretisation).
TRACKING_RAD_S = 40.0

#: A trajectory: times (m,) [s] -> q, dq, ddq (m, n) of the healthy joints.
Trajectory = Callable[[FloatArray], tuple[FloatArray, FloatArray, FloatArray]]


def _mujoco() -> Any:
    try:
        import mujoco
    except ImportError:
        raise ConfigurationError(MUJOCO_MISSING) from None
    return mujoco


@dataclass(frozen=True, eq=False)  # arrays inside
class Replay:
    """A motion played in MuJoCo next to jointlock's own figures of it.

    Attributes
    ----------
    label
        What was replayed (``"halt"``).
    t
        (m,) times [s] (every MuJoCo step).
    joint_numbers, locked_numbers
        The healthy (driven) and the locked (braked) joints, 1-based.
    q, q_ref
        (m, n) healthy-joint angles in MuJoCo and the reference [rad].
    locked_angle
        (m, n_locked) the locked joints' angles in MuJoCo minus their lock angles [rad] (how
        far the brakes give).
    brake, brake_ref
        (m, n_locked) brake torques [N m]: MuJoCo's joint-equality constraint torque and
        jointlock's (:func:`~jointlock.analysis.actuators.actuator_torques`).
    attitude, com_displacement
        (m, 4) MuJoCo's spacecraft attitude ``(w, x, y, z)`` and (m, 3) centre-of-mass
        displacement [m], in the spacecraft's first frame; None with a fixed base.
    angular_velocity
        (m, 3) MuJoCo's spacecraft angular velocity [rad/s], its own frame; None with a fixed base.
    reference
        jointlock's :class:`~jointlock.analysis.spacecraft.SpacecraftResponse` on the same times;
        None with a fixed base.
    timestep
        MuJoCo's step [s].
    mujoco_version
        ``mujoco.__version__``.
    """

    label: str
    t: FloatArray
    joint_numbers: tuple[int, ...]
    locked_numbers: tuple[int, ...]
    q: FloatArray
    q_ref: FloatArray
    locked_angle: FloatArray
    brake: FloatArray
    brake_ref: FloatArray
    attitude: FloatArray | None
    com_displacement: FloatArray | None
    angular_velocity: FloatArray | None
    reference: SpacecraftResponse | None
    timestep: float
    mujoco_version: str

    @property
    def spacecraft(self) -> str:
        """``"free"`` (a free body in MuJoCo) or ``"held"`` (welded to the world)."""
        return "free" if self.attitude is not None else "held"

    @property
    def tracking_error_deg(self) -> float:
        """Largest |q - q_ref| of the driven joints over the replay [deg]."""
        return float(np.degrees(np.abs(self.q - self.q_ref).max())) if self.q.size else 0.0

    @property
    def brake_give_deg(self) -> float:
        """Largest |angle - lock angle| of the braked joints [deg] (the joint equality is soft)."""
        return float(np.degrees(np.abs(self.locked_angle).max())) if self.locked_angle.size else 0.0

    @property
    def attitude_change_deg(self) -> float | None:
        """MuJoCo's final spacecraft attitude change [deg] (None: fixed base)."""
        if self.attitude is None:
            return None
        w = self.attitude[-1]
        return float(np.degrees(2.0 * math.atan2(float(np.linalg.norm(w[1:])), abs(float(w[0])))))

    @property
    def attitude_difference_deg(self) -> float | None:
        """Angle of the rotation between MuJoCo's and jointlock's final attitudes [deg]."""
        if self.attitude is None or self.reference is None:
            return None
        dot = abs(float(np.dot(self.attitude[-1], self.reference.attitude[-1])))
        return float(np.degrees(2.0 * math.acos(min(1.0, dot))))

    def rows(self) -> list[dict[str, Any]]:
        """The comparison: ``{"quantity", "short", "unit", "jointlock", "mujoco", "difference"}``
        per figure (``difference`` = MuJoCo - jointlock; for the attitude, the angle between the
        two final attitudes; ``short``: the name in a one-line summary, empty for the replay's own
        diagnostics: tracking error, brake give)."""
        out: list[dict[str, Any]] = []

        def row(quantity: str, unit: str, ours: float, theirs: float, diff: float | None = None, short: str = "") -> None:
            out.append(
                {
                    "quantity": quantity,
                    "short": short,
                    "unit": unit,
                    "jointlock": ours,
                    "mujoco": theirs,
                    "difference": theirs - ours if diff is None else diff,
                }
            )

        ref = self.reference
        if ref is not None and self.attitude is not None and self.com_displacement is not None:
            assert self.angular_velocity is not None
            row(
                "spacecraft attitude change at the end",
                "deg",
                ref.final_attitude_change_deg,
                float(self.attitude_change_deg or 0.0),
                float(self.attitude_difference_deg or 0.0),
                "attitude change",
            )
            row(
                "spacecraft peak rate",
                "deg/s",
                ref.peak_rate_deg_s,
                float(np.degrees(np.linalg.norm(self.angular_velocity, axis=-1).max())),
                short="peak rate",
            )
            drift = float(np.linalg.norm(self.com_displacement[-1]))
            row("spacecraft centre-of-mass drift", "m", ref.com_drift_m, drift, short="drift")
        for i, j in enumerate(self.locked_numbers):
            row(
                f"peak brake torque, joint {j} (spacecraft {self.spacecraft})",
                "N m",
                float(np.abs(self.brake_ref[:, i]).max()),
                float(np.abs(self.brake[:, i]).max()),
                short=f"brake {j} peak",
            )
        row("joint tracking error (largest)", "deg", 0.0, self.tracking_error_deg)
        if self.locked_numbers:
            row("locked joint give (largest)", "deg", 0.0, self.brake_give_deg)
        return out

    def summary(self) -> list[str]:
        """One line per figure: quantity, jointlock, MuJoCo, difference."""
        lines = [
            f"checked in MuJoCo {self.mujoco_version} ({self.label}: {self.t.size - 1} steps of "
            f"{self.timestep:g} s, RK4, contacts off):"
        ]
        for r in self.rows():
            lines.append(
                f"  {r['quantity']:<46} jointlock {r['jointlock']:>12.6g}  MuJoCo {r['mujoco']:>12.6g}  "
                f"difference {r['difference']:+.3g} {r['unit']}"
            )
        return lines

    def to_dict(self) -> dict[str, Any]:
        """The comparison rows and the replay's settings (plain JSON)."""
        return {
            "simulator": f"MuJoCo {self.mujoco_version}",
            "label": self.label,
            "timestep_s": self.timestep,
            "steps": int(self.t.size - 1),
            "spacecraft": self.spacecraft,
            "rows": self.rows(),
        }

    def time_series(self) -> dict[str, FloatArray]:
        """``t`` [s], MuJoCo's ``attitude_change_deg`` (fixed base: absent) and each
        ``brake{j}_Nm``, for CSV and plots."""
        cols: dict[str, FloatArray] = {"t": self.t}
        if self.attitude is not None:
            half_sin = np.linalg.norm(self.attitude[:, 1:], axis=-1)
            cols["attitude_change_deg"] = np.degrees(2.0 * np.arctan2(half_sin, np.abs(self.attitude[:, 0])))
        for i, j in enumerate(self.locked_numbers):
            cols[f"brake{j}_Nm"] = self.brake[:, i]
        return cols

    def file_names(self, stem: str = "mujoco") -> list[str]:
        """The names :meth:`write` writes."""
        return with_svg([f"{stem}.png"]) + [f"{stem}.csv", f"{stem}.json"]

    def write(self, out: str | Path, stem: str = "mujoco") -> list[str]:
        """Write ``<stem>.png`` (and ``.svg``: :func:`jointlock.plots.sim.plot_replay`),
        ``<stem>.csv`` (MuJoCo's series next to jointlock's: ``t``, ``attitude_change_deg`` and
        ``attitude_change_jointlock_deg``, ``brake{j}_Nm`` and ``brake{j}_jointlock_Nm``) and
        ``<stem>.json`` (:meth:`to_dict`) to the folder ``out``; returns their names."""
        from .plots._common import offscreen_figure
        from .plots.sim import plot_replay

        folder = Path(out)
        folder.mkdir(parents=True, exist_ok=True)
        names = write_figure(plot_replay(self, fig=offscreen_figure((7.0, 5.6))), folder, f"{stem}.png")
        cols = self.time_series()
        if self.reference is not None:
            cols["attitude_change_jointlock_deg"] = self.reference.attitude_change_deg
        for i, j in enumerate(self.locked_numbers):
            cols[f"brake{j}_jointlock_Nm"] = self.brake_ref[:, i]
        atomic_write_text(folder / f"{stem}.csv", csv_text(cols))
        atomic_write_json(folder / f"{stem}.json", self.to_dict())
        return names + [f"{stem}.csv", f"{stem}.json"]


#: The jobs whose motion :func:`replay_jobs` plays.
REPLAYED_JOBS = ("halt",)


def replay_jobs(jobs: Mapping[str, Any], *, timestep: float = TIMESTEP_S) -> dict[str, Replay]:
    """Replay every motion among a run's typed job results (``{job: result}``) that MuJoCo can
    play (:data:`REPLAYED_JOBS`): ``{job: Replay}``.  A halt whose torques hold the spacecraft
    (000's reading) on a model with one is played twice: free (``"halt"``: the attitude, the
    drift) and held (``"halt_held"``: the brake torque 000's reading gives)."""
    out: dict[str, Replay] = {}
    if "halt" in jobs:
        plan = jobs["halt"]
        out["halt"] = replay_halt(plan, timestep=timestep)
        if plan.problem.model.floating and plan.problem.base == "fixed":  # 000's torques: the spacecraft held
            out["halt_held"] = replay_halt(plan, timestep=timestep, base="fixed")
    return out


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
        A locked model without its unlocked arm.
    """
    mujoco = _mujoco()
    if not (isinstance(duration, (int, float)) and math.isfinite(duration) and duration > 0):
        raise ConfigurationError(f"duration must be a positive number of seconds; got {duration!r}")
    if not (isinstance(timestep, (int, float)) and 0 < timestep <= duration):
        raise ConfigurationError(f"timestep must be in (0, duration] [s]; got {timestep!r}")
    if model.locked and model.unlocked is None:
        raise ModelError(f"{model.name!r}: the replay needs the unlocked arm to hold the locked joints by brakes")
    if base not in (None, "fixed", "floating") or (base == "floating" and not model.floating):
        raise ConfigurationError(
            f"base must be 'fixed', or 'floating' for a model with a spacecraft ({model.name!r} floats: "
            f"{model.floating}); got {base!r}"
        )
    chain = model.unlocked if model.locked else model
    assert chain is not None
    floating = model.floating if base is None else base == "floating"
    mode: BaseMode = "floating" if floating else "fixed"
    mm = mujoco.MjModel.from_xml_string(mjcf_text(model, brakes=True, timestep=timestep, base=mode))
    mm.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONTACT
    mm.actuator_ctrllimited[:] = 0
    data = mujoco.MjData(mm)

    free = 7 if floating else 0
    numbers = list(chain.joint_numbers)
    healthy = np.array([free + numbers.index(j) for j in model.joint_numbers], dtype=int)
    braked = np.array([free + numbers.index(lj.number) for lj in model.locked], dtype=int)
    healthy_v = healthy - (1 if floating else 0)  # qvel has 6 free coordinates, qpos 7
    braked_v = braked - (1 if floating else 0)
    lock_angles = np.array([lj.angle for lj in model.locked])

    steps = max(1, round(duration / timestep))
    t = np.linspace(0.0, steps * timestep, steps + 1)
    q_ref, dq_ref, ddq_ref = trajectory(t)
    q_mid, dq_mid, ddq_mid = trajectory(t[:-1] + 0.5 * timestep)
    feed_now, brake_ref = actuator_torques(model, q_ref, dq_ref, ddq_ref, base=mode)
    feed_mid, _ = actuator_torques(model, q_mid, dq_mid, ddq_mid, base=mode)
    # the correction is an acceleration times the arm's own inertia along the reference (the
    # free-floating H* when the spacecraft floats): critically damped on every joint at once
    inertia = generalized_inertia(model, q_ref) if floating else mass_matrix(model, q_ref)
    kp, kd = tracking**2, 2.0 * tracking

    data.qpos[braked] = lock_angles
    data.qpos[healthy] = q_ref[0]
    data.qvel[healthy_v] = dq_ref[0]
    if floating:
        data.qpos[3:7] = [1.0, 0.0, 0.0, 0.0]
        twist = rnea(model, q_ref[0], dq_ref[0], np.zeros(model.dof), base="floating").base_twist
        v_com, omega = twist[:3], twist[3:]
        data.qvel[0:3] = v_com - np.cross(omega, model.root_body.com)  # the body origin's velocity
        data.qvel[3:6] = omega
    base_body = mujoco.mj_name2id(mm, mujoco.mjtObj.mjOBJ_BODY, "base")

    m = steps + 1
    q_out = np.empty((m, model.dof))
    locked_out = np.empty((m, braked.size))
    brake_out = np.empty((m, braked.size))
    attitude = np.empty((m, 4)) if floating else None
    com = np.empty((m, 3)) if floating else None
    rate = np.empty((m, 3)) if floating else None
    caught: list[str] = []
    previous = mujoco.get_mju_user_warning()
    mujoco.set_mju_user_warning(caught.append)  # MuJoCo's warnings here, not in MUJOCO_LOG.TXT
    try:
        for k in range(m):
            correction = inertia[k] @ (kp * (q_ref[k] - data.qpos[healthy]) + kd * (dq_ref[k] - data.qvel[healthy_v]))
            data.ctrl[:] = feed_now[k] + correction
            mujoco.mj_forward(mm, data)  # the constraint (brake) torque at this instant
            q_out[k] = data.qpos[healthy]
            locked_out[k] = data.qpos[braked] - lock_angles
            brake_out[k] = data.qfrc_constraint[braked_v]
            if attitude is not None and com is not None and rate is not None:
                attitude[k] = data.qpos[3:7]
                com[k] = data.xipos[base_body]
                rate[k] = data.qvel[3:6]
            if caught:
                break
            if k < steps:
                data.ctrl[:] = feed_mid[k] + correction
                mujoco.mj_step(mm, data)
    finally:
        mujoco.set_mju_user_warning(previous)
    if caught or not (np.all(np.isfinite(q_out)) and np.all(np.isfinite(brake_out))):
        raise ModelError(
            f"the MuJoCo replay of {label} became unstable ({(caught or ['non-finite state'])[0].strip()}); try a "
            f"smaller timestep than {timestep:g} s"
        )
    reference = None
    if com is not None:
        com = com - com[0]
        reference = spacecraft_response(model, t, q_ref, dq_ref)
    return Replay(
        label=label,
        t=t,
        joint_numbers=model.joint_numbers,
        locked_numbers=tuple(lj.number for lj in model.locked),
        q=q_out,
        q_ref=q_ref,
        locked_angle=locked_out,
        brake=brake_out,
        brake_ref=brake_ref.reshape(m, -1),
        attitude=attitude,
        com_displacement=com,
        angular_velocity=rate,
        reference=reference,
        timestep=float(timestep),
        mujoco_version=str(mujoco.__version__),
    )


def replay_halt(
    plan: Any, *, timestep: float = TIMESTEP_S, tracking: float = TRACKING_RAD_S, base: str | None = None
) -> Replay:
    """Replay a :class:`~jointlock.jobs.HaltPlan`'s halt motion (its polynomial ``q(t)``, exact at
    every step) in MuJoCo.  ``base=None``: the spacecraft free when the plan's model floats,
    whatever base the plan's torques were computed with (000 holds it; the free replay shows what
    a free one does, as :meth:`~jointlock.jobs.HaltPlan.spacecraft_response` does); ``"fixed"``:
    held, the reading of 000's torques (its brake torque is
    :meth:`~jointlock.jobs.HaltPlan.actuator_loads`'s)."""
    problem = plan.problem
    held = base == "fixed" or not problem.model.floating
    return replay_motion(
        problem.model,
        plan.motion.trajectory,
        float(problem.T),
        label="halt, spacecraft held" if held else "halt, spacecraft free",
        timestep=timestep,
        tracking=tracking,
        base=base,
    )
