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
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from .analysis.actuators import actuator_torques
from .analysis.spacecraft import SpacecraftResponse, spacecraft_response
from .dynamics import BaseMode, generalized_inertia, mass_matrix, rnea
from .errors import ConfigurationError, ModelError
from .io.files import atomic_write_json, atomic_write_text, csv_text, with_svg, write_figure
from .locking import lock_joints
from .mjcf import TIMESTEP_S, mjcf_text
from .model import ArmModel, FloatArray

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


def require_mujoco() -> None:
    """Raise :data:`MUJOCO_MISSING` now (before a long computation whose motions would be
    replayed) when MuJoCo is not installed."""
    _mujoco()


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
        a, b = self.attitude[-1], self.reference.attitude[-1]
        # the rotation a^-1 b: its vector part without cancellation (acos of the dot is 0 below 1e-8)
        vector = a[0] * b[1:] - b[0] * a[1:] - np.cross(a[1:], b[1:])
        scalar = float(np.dot(a, b))
        return float(np.degrees(2.0 * math.atan2(float(np.linalg.norm(vector)), abs(scalar))))

    def simulated_response(self) -> SpacecraftResponse | None:
        """MuJoCo's spacecraft as a :class:`~jointlock.analysis.spacecraft.SpacecraftResponse`
        (attitude, rate, drift on :attr:`t`); None with the spacecraft held."""
        if self.attitude is None or self.angular_velocity is None or self.com_displacement is None:
            return None
        return SpacecraftResponse(self.t, self.attitude, self.angular_velocity, self.com_displacement)

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
REPLAYED_JOBS = ("halt", "jump", "replan")


def replay_jobs(jobs: Mapping[str, Any], *, timestep: float = TIMESTEP_S) -> dict[str, Replay]:
    """Replay every motion among a run's typed job results (``{job: result}``) that MuJoCo can
    play (:data:`REPLAYED_JOBS`): ``{key: Replay}``.  A halt whose torques hold the spacecraft
    (000's reading) on a model with one is played twice: free (``"halt"``: the attitude, the
    drift) and held (``"halt_held"``: the brake torque 000's reading gives); the jump study's
    two runs are ``"jump_uncompensated"`` and ``"jump_compensated"``; the re-plan ``"replan"``."""
    out: dict[str, Replay] = {}
    if "halt" in jobs:
        plan = jobs["halt"]
        out["halt"] = replay_halt(plan, timestep=timestep)
        if plan.problem.model.floating and plan.problem.base == "fixed":  # 000's torques: the spacecraft held
            out["halt_held"] = replay_halt(plan, timestep=timestep, base="fixed")
    if "jump" in jobs:
        out.update(replay_jump(jobs["jump"], timestep=timestep))
    if "replan" in jobs and jobs["replan"].model is not None:
        out["replan"] = replay_replan(jobs["replan"], timestep=timestep)
    return out


def replay_jump(result: Any, *, timestep: float = TIMESTEP_S) -> dict[str, Replay]:
    """The jump study's two runs (:meth:`~jointlock.jobs.JumpJobResult.runs`: without and with
    the compensation, the joint locking at the failure instant) played with
    :func:`replay_steps`: ``{"jump_uncompensated": ..., "jump_compensated": ...}``."""
    r0, r1, _ = result.runs()
    return {
        f"jump_{key}": replay_steps(
            result.model,
            run.t,
            run.q,
            run.qd,
            [(int(j), float(t)) for j, t, _ in run.failures],
            label=f"jump, {label}",
            timestep=timestep,
        )
        for key, label, run in (("uncompensated", "kappa = 0", r0), ("compensated", "compensated", r1))
    }


def replay_replan(result: Any, *, timestep: float = TIMESTEP_S) -> Replay:
    """The re-planned waypoints (:class:`~jointlock.jobs.ReplanJobResult`'s ``plan.times`` and
    ``plan.q``) joined by a cubic spline and played with :func:`replay_waypoints`."""
    if result.model is None:
        raise ConfigurationError("this re-plan result has no model to replay (built without one)")
    return replay_waypoints(result.model, result.plan.times, result.plan.q, label="re-plan", timestep=timestep)


class _Player:
    """A locked arm in MuJoCo (:func:`~jointlock.mjcf.mjcf_text` with brakes), contacts and
    control limits off, with the indices a replay needs, and what it records at each instant.
    Used as a context manager: MuJoCo's warnings are caught (no ``MUJOCO_LOG.TXT`` in the
    user's folder) and an unstable replay raises one :class:`ModelError`."""

    def __init__(
        self, model: ArmModel, floating: bool, timestep: float, samples: int, *, brakes_engaged: bool = True
    ) -> None:
        mujoco = self.mujoco = _mujoco()
        chain = model.unlocked if model.locked else model
        assert chain is not None
        mode = "floating" if floating else "fixed"
        text = mjcf_text(model, brakes=True, timestep=timestep, base=mode, brakes_engaged=brakes_engaged)
        try:
            self.mm = mujoco.MjModel.from_xml_string(text)
        except ValueError as exc:  # MuJoCo's compiler refused the model
            raise ModelError(f"MuJoCo cannot load {model.name!r}: {' '.join(str(exc).split())}") from None
        # contacts off (the clearance is jointlock's), and the joint limits: a motion that leaves
        # them is jointlock's to report, not MuJoCo's to stop
        self.mm.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONTACT | mujoco.mjtDisableBit.mjDSBL_LIMIT
        self.mm.actuator_ctrllimited[:] = 0
        self.data = mujoco.MjData(self.mm)
        self.floating, self.timestep = floating, timestep
        free = 7 if floating else 0
        numbers = list(chain.joint_numbers)
        #: qpos index of each joint of the chain (its number's order), and of the model's healthy
        #: and locked joints; qvel has 6 free coordinates where qpos has 7
        self.qpos = np.array([free + numbers.index(j) for j in numbers], dtype=int)
        self.healthy = np.array([free + numbers.index(j) for j in model.joint_numbers], dtype=int)
        self.braked = np.array([free + numbers.index(lj.number) for lj in model.locked], dtype=int)
        self.shift = 1 if floating else 0
        self.lock_angles = np.array([lj.angle for lj in model.locked])
        self.base_body = mujoco.mj_name2id(self.mm, mujoco.mjtObj.mjOBJ_BODY, "base")
        if floating:
            self.data.qpos[3:7] = [1.0, 0.0, 0.0, 0.0]
        self.q = np.empty((samples, self.healthy.size))
        self.locked_angle = np.empty((samples, self.braked.size))
        self.brake = np.empty((samples, self.braked.size))
        self.attitude = np.empty((samples, 4)) if floating else None
        self.com = np.empty((samples, 3)) if floating else None
        self.rate = np.empty((samples, 3)) if floating else None
        self.caught: list[str] = []

    def __enter__(self) -> _Player:
        self._previous = self.mujoco.get_mju_user_warning()
        self.mujoco.set_mju_user_warning(self.caught.append)
        return self

    def __exit__(self, *exc: object) -> None:
        self.mujoco.set_mju_user_warning(self._previous)

    def record(self, k: int) -> bool:
        """Compute the state's forces (:func:`mujoco.mj_forward`: the brake's constraint torque)
        and record sample ``k``; False once MuJoCo has warned (the replay is unstable)."""
        data = self.data
        self.mujoco.mj_forward(self.mm, data)
        self.q[k] = data.qpos[self.healthy]
        self.locked_angle[k] = data.qpos[self.braked] - self.lock_angles
        self.brake[k] = data.qfrc_constraint[self.braked - self.shift]
        if self.attitude is not None and self.com is not None and self.rate is not None:
            self.attitude[k] = data.qpos[3:7]
            self.com[k] = data.xipos[self.base_body]
            self.rate[k] = data.qvel[3:6]
        return not self.caught

    def step(self, ctrl: FloatArray) -> None:
        self.data.ctrl[:] = ctrl
        self.mujoco.mj_step(self.mm, self.data)

    def result(
        self,
        model: ArmModel,
        label: str,
        t: FloatArray,
        q_ref: FloatArray,
        brake_ref: FloatArray,
        reference: SpacecraftResponse | None,
    ) -> Replay:
        """The :class:`Replay` of what was recorded (one :class:`ModelError` if it diverged)."""
        if self.caught or not (np.all(np.isfinite(self.q)) and np.all(np.isfinite(self.brake))):
            raise ModelError(
                f"the MuJoCo replay of {label} became unstable ({(self.caught or ['non-finite state'])[0].strip()}); "
                f"try a smaller timestep than {self.timestep:g} s"
            )
        com = None if self.com is None else self.com - self.com[0]
        return Replay(
            label=label,
            t=t,
            joint_numbers=model.joint_numbers,
            locked_numbers=tuple(lj.number for lj in model.locked),
            q=self.q,
            q_ref=q_ref,
            locked_angle=self.locked_angle,
            brake=self.brake,
            brake_ref=brake_ref.reshape(t.size, -1),
            attitude=self.attitude,
            com_displacement=com,
            angular_velocity=self.rate,
            reference=reference if self.floating else None,
            timestep=float(self.timestep),
            mujoco_version=str(self.mujoco.__version__),
        )


def _check_base(model: ArmModel, base: str | None) -> bool:
    """Whether the replay floats the spacecraft (``base``: None, the model's; or as given)."""
    if base not in (None, "fixed", "floating") or (base == "floating" and not model.floating):
        raise ConfigurationError(
            f"base must be 'fixed', or 'floating' for a model with a spacecraft ({model.name!r} floats: "
            f"{model.floating}); got {base!r}"
        )
    if model.locked and model.unlocked is None:
        raise ModelError(f"{model.name!r}: the replay needs the unlocked arm to hold the locked joints by brakes")
    return model.floating if base is None else base == "floating"


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
    from .analysis.spacecraft import _quaternion_product
    from .spatial import quaternion_matrix

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


def write_attitude_with_replay(plan: Any, replay: Replay, folder: str | Path) -> None:
    """Write a :class:`~jointlock.jobs.HaltPlan`'s ``spacecraft_attitude.png`` (and .svg) into
    ``folder`` again, with the replay's spacecraft (MuJoCo's) dashed on top (issue 30); nothing
    for a held spacecraft."""
    if replay.simulated_response() is None:
        return
    response = plan.spacecraft_response()
    if response is None:
        return
    from .plots._common import offscreen_figure
    from .plots.halt import plot_spacecraft_response

    fig = plot_spacecraft_response(response, fig=offscreen_figure((7, 4)), simulated=replay.simulated_response())
    write_figure(fig, Path(folder), "spacecraft_attitude.png")
