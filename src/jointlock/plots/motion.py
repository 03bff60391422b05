"""A motion of the arm to animate: joint angles over time, the spacecraft's pose, the locks.

:class:`ArmMotion` is what the 3-D animation (:mod:`jointlock.plots.animation`) reads and what a
job writes as ``motion.json`` (:meth:`ArmMotion.to_dict`, degrees and metres, names with units):
the full arm's joint angles (the locked joints included, at their angles), the root frame's
pose in the first frame of the motion (a free spacecraft turns and drifts; a fixed base or a
held spacecraft stays at the origin), when each joint locks, and optionally the end effector's
target path.  :func:`motion_points` turns motions into the points drawn on each frame, batched
over the frames (one :func:`~jointlock.kinematics.chain_state` call per motion).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from ..errors import ConfigurationError
from ..kinematics import chain_state, com_positions
from ..model import ArmModel, FloatArray
from ..spatial import quaternion_matrix


def _array(value: ArrayLike | None, name: str, shape: tuple[int | str, ...]) -> FloatArray | None:
    """``value`` as a read-only float array of ``shape`` (a str entry: any size, named so in
    the error), or None; a ConfigurationError naming the field otherwise."""
    if value is None:
        return None
    try:
        a = np.array(value, dtype=float)
    except (TypeError, ValueError):
        raise ConfigurationError(f"ArmMotion.{name} must be numbers; got {str(value)[:60]!r}") from None
    if a.ndim != len(shape) or any(isinstance(s, int) and s != n for s, n in zip(shape, a.shape)):
        want = "(" + ", ".join(str(s) for s in shape) + ")"
        raise ConfigurationError(f"ArmMotion.{name} must have the shape {want}; got {a.shape}")
    if not np.all(np.isfinite(a)):
        raise ConfigurationError(f"ArmMotion.{name} must be finite (no NaN or inf)")
    a.setflags(write=False)
    return a


@dataclass(frozen=True, eq=False)  # arrays inside: compare to_dict() instead
class ArmMotion:
    """One motion of the full arm (every joint, locked ones at their angles).

    Attributes
    ----------
    label
        Shown in the legend (e.g. ``"halt, k = k*"``, ``"compensated"``).
    t
        (m,) increasing times [s].
    q
        (m, n) joint angles of the full arm [rad], joint numbers ascending.
    locks
        ``(joint number, time [s])`` of each lock; a time at or before ``t[0]`` means locked
        throughout.
    base_position, base_attitude
        (m, 3) origin [m] and (m, 4) attitude ``(w, x, y, z)`` of the root frame in the
        motion's first frame; None for a base that does not move.
    target
        (m, 3) the end effector's target (or nominal) position [m], first frame; or None.
    target_label
        Legend name of the target path.
    """

    label: str
    t: FloatArray
    q: FloatArray
    locks: tuple[tuple[int, float], ...] = ()
    base_position: FloatArray | None = None
    base_attitude: FloatArray | None = None
    target: FloatArray | None = None
    target_label: str = "target path"

    def __post_init__(self) -> None:
        t = _array(self.t, "t", ("m",))
        if t is None or t.size < 1 or np.any(np.diff(t) <= 0):
            raise ConfigurationError(
                f"ArmMotion.t must be one or more increasing times [s]; got {0 if t is None else t.size} values"
            )
        m = t.size
        object.__setattr__(self, "t", t)
        if self.q is None:
            raise ConfigurationError("ArmMotion.q is required: (m, n) joint angles [rad]")
        object.__setattr__(self, "q", _array(self.q, "q", (m, "n")))
        object.__setattr__(self, "base_position", _array(self.base_position, "base_position", (m, 3)))
        attitude = _array(self.base_attitude, "base_attitude", (m, 4))
        if attitude is not None and not np.all(np.linalg.norm(attitude, axis=-1) > 1e-9):
            raise ConfigurationError("ArmMotion.base_attitude must be unit quaternions (w, x, y, z); got a zero row")
        object.__setattr__(self, "base_attitude", attitude)
        object.__setattr__(self, "target", _array(self.target, "target", (m, 3)))
        if (self.base_position is None) != (self.base_attitude is None):
            raise ConfigurationError("ArmMotion: give base_position and base_attitude together, or neither")
        try:
            locks = tuple((int(j), float(s)) for j, s in self.locks)
        except (TypeError, ValueError):
            raise ConfigurationError(
                f"ArmMotion.locks must be (joint number, time [s]) pairs; got {str(self.locks)[:60]!r}"
            ) from None
        object.__setattr__(self, "locks", locks)

    @property
    def moving_base(self) -> bool:
        """True when the root frame moves (a free spacecraft)."""
        return self.base_position is not None

    def to_dict(self) -> dict[str, Any]:
        """Plain data for ``motion.json``: degrees, metres, seconds (names say the unit)."""
        d: dict[str, Any] = {
            "label": self.label,
            "t_s": self.t.tolist(),
            "q_deg": np.degrees(self.q).tolist(),
            "locks": [{"joint": j, "t_s": s} for j, s in self.locks],
        }
        if self.base_position is not None and self.base_attitude is not None:
            d["base_position_m"] = self.base_position.tolist()
            d["base_attitude_wxyz"] = self.base_attitude.tolist()
        if self.target is not None:
            d["target_m"] = self.target.tolist()
            d["target_label"] = self.target_label
        return d

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> ArmMotion:
        """The motion :meth:`to_dict` wrote."""
        try:
            return cls(
                label=str(data["label"]),
                t=data["t_s"],
                q=np.radians(np.asarray(data["q_deg"], dtype=float)),
                locks=tuple((lk["joint"], lk["t_s"]) for lk in data.get("locks", ())),
                base_position=data.get("base_position_m"),
                base_attitude=data.get("base_attitude_wxyz"),
                target=data.get("target_m"),
                target_label=str(data.get("target_label", "target path")),
            )
        except (KeyError, TypeError, ValueError) as exc:
            raise ConfigurationError(f"not a motion (ArmMotion.to_dict) : {exc}") from None


def drawn_arm(model: ArmModel) -> ArmModel:
    """The arm a motion is drawn on: the full arm of a locked model when it kept it."""
    return model.unlocked if model.locked and model.unlocked is not None else model


def frame_times(motions: list[ArmMotion], max_frames: int) -> FloatArray:
    """(F,) times of the animation's frames [s]: at most ``max_frames`` evenly spaced over the
    motions' span, with every lock's time added (the failure instant is always a frame)."""
    t0 = min(float(m.t[0]) for m in motions)
    t1 = max(float(m.t[-1]) for m in motions)
    count = min(max(max_frames, 2), max(m.t.size for m in motions))
    times = np.linspace(t0, t1, count) if t1 > t0 else np.array([t0])
    locks = [s for m in motions for _, s in m.locks if t0 < s <= t1]
    return np.unique(np.concatenate([times, locks]))


def _nearest(t: FloatArray, at: FloatArray) -> np.ndarray:
    i = np.clip(np.searchsorted(t, at), 1, max(t.size - 1, 1))
    if t.size == 1:
        return np.zeros(at.shape, dtype=int)
    return np.where(np.abs(at - t[i - 1]) <= np.abs(t[i] - at), i - 1, i)


def motion_points(model: ArmModel, motion: ArmMotion, times: FloatArray) -> dict[str, FloatArray]:
    """The points drawn for ``motion`` at ``times`` (F,) [s] (each frame shows the motion's
    nearest sample), in the motion's first frame [m]:

    ``joints`` (F, n, 3) joint origins, ``axes`` (F, n, 3) unit joint axes, ``ee`` (F, 3) end
    effector, ``coms`` (F, n, 3) link centres of mass, ``base`` (F, 3) root-frame origin,
    ``base_rotation`` (F, 3, 3) and ``sample`` (F,) the sample index shown.
    ``model`` is the full (unlocked) arm: ``motion.q`` has one angle per joint of it.
    """
    if motion.q.shape[1] != model.dof:
        raise ConfigurationError(
            f"motion {motion.label!r} has {motion.q.shape[1]} joint angles; the arm {model.name!r} has {model.dof}"
        )
    unknown = [j for j, _ in motion.locks if j not in model.joint_numbers]
    if unknown:
        raise ConfigurationError(
            f"motion {motion.label!r} locks joints {unknown}; the arm {model.name!r} has joints {list(model.joint_numbers)}"
        )
    k = _nearest(motion.t, np.asarray(times, dtype=float))
    q = motion.q[k]
    state = chain_state(model, q)
    coms = com_positions(model, q, state)
    if motion.base_position is None or motion.base_attitude is None:
        rot = np.broadcast_to(np.eye(3), (k.size, 3, 3))
        base = np.zeros((k.size, 3))
    else:
        rot = quaternion_matrix(motion.base_attitude[k])
        base = motion.base_position[k]

    def world(p: FloatArray) -> FloatArray:  # (F, ..., 3) root frame -> first frame
        return base.reshape((k.size,) + (1,) * (p.ndim - 2) + (3,)) + np.einsum(
            "fij,f...j->f...i", rot, p
        )

    return {
        "joints": world(state.positions),
        "axes": np.einsum("fij,fnj->fni", rot, state.axes),
        "ee": world(state.ee_position),
        "coms": world(coms),
        "base": base,
        "base_rotation": np.asarray(rot),
        "sample": k,
    }


def spacecraft_box(model: ArmModel) -> FloatArray | None:
    """(8, 3) corners of the spacecraft drawn as a box [m], root frame: the uniform box of the
    root body's mass and principal moments (half sides ``sqrt(3 (I_j + I_k - I_i) / (2 m))``),
    centred on its centre of mass along its principal axes; None when the root body has no mass
    (a bare mounting).  A body whose moments give no box (a point mass) is drawn as a cube of a
    tenth of the arm's reach."""
    body = model.root_body
    if body.mass <= 0:
        return None
    moments, axes = np.linalg.eigh(np.asarray(body.inertia, dtype=float))
    sq = 3.0 * (moments.sum() - 2.0 * moments) / (2.0 * body.mass)
    half = np.sqrt(np.clip(sq, 0.0, None))
    if not np.all(half > 0):
        reach = sum(float(np.linalg.norm(j.placement[:3, 3])) for j in model.joints)
        half = np.full(3, max(reach, 1.0) / 20.0)
    signs = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], dtype=float)
    return np.asarray(body.com, dtype=float) + (signs * half) @ axes.T
