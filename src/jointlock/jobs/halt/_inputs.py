"""The inputs of :func:`~jointlock.jobs.halt.plan_halt`: the state at failure
(:class:`FailureState`), the joint limits (:class:`JointLimits`) and ``jointlock halt``'s rule
for them (:func:`halt_limits`), with 000's defaults."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import Any, cast

import numpy as np
from numpy.typing import ArrayLike

from ...errors import ScenarioError
from ...model import ArmModel
from ...papers import p000
from .._common import joint_vector_deg

#: 000's limits (§5.2), the fallback where neither the caller nor the model gives one
#: [deg/s, deg/s^2].
DEFAULT_VMAX_DEG = p000.VELOCITY_LIMIT_DEG_S
DEFAULT_AMAX_DEG = p000.ACCELERATION_LIMIT_DEG_S2


def is_000_failure(model: ArmModel) -> bool:
    """halt7 with joint 4 locked at 0 deg and no other lock: 000 §5's failure, the only one 000's
    state at failure, halt time and q_best belong to."""
    locked = {lj.number: math.degrees(lj.angle) for lj in model.locked}
    return (
        model.name == "halt7"
        and set(locked) == set(p000.SCENARIO["lock"])
        and all(math.isclose(locked[j], a, abs_tol=1e-9) for j, a in p000.SCENARIO["lock"].items())
    )


@dataclass(frozen=True)
class FailureState:
    """State of the healthy joints when the failure is detected.

    Attributes
    ----------
    q, dq, ddq
        (n,) angles [rad], rates [rad/s] and accelerations [rad/s^2] of the movable joints
        (the locked model's joint order, :attr:`ArmModel.joint_numbers`).
    """

    q: np.ndarray
    dq: np.ndarray
    ddq: np.ndarray

    def __post_init__(self) -> None:
        arrays = {}
        for name in ("q", "dq", "ddq"):
            arr = np.array(getattr(self, name), dtype=float)
            if arr.ndim != 1 or not np.all(np.isfinite(arr)):
                raise ScenarioError(
                    f"FailureState.{name} must be one finite value per movable joint; got {arr.tolist()}"
                )
            arr.setflags(write=False)
            arrays[name] = arr
        sizes = {name: arr.size for name, arr in arrays.items()}
        if len(set(sizes.values())) != 1:
            raise ScenarioError(
                f"FailureState: q, dq and ddq need one value per movable joint each; got sizes {sizes}"
            )
        for name, arr in arrays.items():
            object.__setattr__(self, name, arr)

    @classmethod
    def from_degrees(
        cls,
        model: ArmModel,
        q_deg: ArrayLike,
        dq_deg: ArrayLike | None = None,
        ddq_deg: ArrayLike | None = None,
        *,
        names: tuple[str, str, str] = ("q0_deg", "dq0_deg", "ddq0_deg"),
    ) -> FailureState:
        """From degrees, one value per movable joint or per joint of the full arm (a locked
        joint's angle must then equal its lock angle, its rate and acceleration 0); ``None``
        rates or accelerations are zeros.  ``names`` name the inputs in error messages."""
        return cls(
            joint_vector_deg(model, list(np.ravel(q_deg)), names[0]),
            joint_vector_deg(model, None if dq_deg is None else list(np.ravel(dq_deg)), names[1], rates=True),
            joint_vector_deg(
                model, None if ddq_deg is None else list(np.ravel(ddq_deg)), names[2], rates=True
            ),
        )


@dataclass(frozen=True)
class JointLimits:
    """Symmetric speed and acceleration limits of the healthy joints, and where each came from.

    Attributes
    ----------
    velocity, acceleration
        (n,) ``v_max`` [rad/s] and ``a_max`` [rad/s^2].
    velocity_source, acceleration_source
        (n,) plain-language origin of each joint's limit.
    torque, brake
        (n,) motor torque limits of the healthy joints and (n_locked,) brake torque limits of
        the locked joints (:attr:`ArmModel.locked` order) [N m], ``inf`` where there is none;
        None: no torque limit at all.
    torque_source, brake_source
        Their origins (empty when None).
    """

    velocity: np.ndarray
    acceleration: np.ndarray
    velocity_source: tuple[str, ...]
    acceleration_source: tuple[str, ...]
    torque: np.ndarray | None = None
    brake: np.ndarray | None = None
    torque_source: tuple[str, ...] = ()
    brake_source: tuple[str, ...] = ()

    def scaled(self, factor: float) -> JointLimits:
        """Every limit times ``factor`` (a margin kept free: ``1 - margin``), sources kept."""
        return replace(
            self,
            velocity=self.velocity * factor,
            acceleration=self.acceleration * factor,
            torque=None if self.torque is None else self.torque * factor,
            brake=None if self.brake is None else self.brake * factor,
        )


def _limit_values(values: Any, name: str, n: int, which: str = "") -> np.ndarray | None:
    """None, or (n,) from one value or n values (finite, > 0); ``which`` says whose (for the
    error)."""
    if values is None:
        return None
    arr = np.asarray(values, dtype=float).ravel()
    if arr.size == 1:
        arr = np.full(n, arr[0])
    if arr.shape != (n,) or not np.all(np.isfinite(arr) & (arr > 0)):
        count = f"one value or {n} values" if n > 1 else "one value"
        raise ScenarioError(f"{name} needs {count}, finite and > 0{which}; got {np.ravel(values).tolist()}")
    return arr


def _torque_limits(
    model: ArmModel, torque_max_Nm: Any, brake_max_Nm: Any, names: tuple[str, str]
) -> tuple[np.ndarray | None, np.ndarray | None, tuple[str, ...], tuple[str, ...]]:
    """Motor limits: ``torque_max_Nm`` capped by the model's own effort limits, else the
    model's where finite; brake limits: ``brake_max_Nm`` (a model has none)."""
    n = model.dof
    given = _limit_values(torque_max_Nm, names[0], n)
    effort = np.array([j.effort_limit for j in model.joints])
    torque, t_src = None, cast(tuple[str, ...], ())
    if given is not None or np.any(np.isfinite(effort)):
        g = np.full(n, np.inf) if given is None else given
        torque = np.minimum(g, effort)
        t_src = tuple(
            ("model's limit" if given is None else f"model's limit, below {names[0]} {g[i]:g}")
            if effort[i] < g[i]
            else (names[0] if given is not None else "none")
            for i in range(n)
        )
    brake, b_src = None, cast(tuple[str, ...], ())
    if brake_max_Nm is not None:
        if not model.locked:
            raise ScenarioError(
                f"{names[1]} is the locked joints' brake limit, but {model.name!r} has no locked joint"
            )
        locked = [lj.number for lj in model.locked]
        which = f" (the locked joints {locked}, in the order they were locked)"
        brake = _limit_values(brake_max_Nm, names[1], len(locked), which)
        b_src = (names[1],) * len(model.locked)
    return torque, brake, t_src, b_src


def halt_limits(
    model: ArmModel,
    vmax_deg: ArrayLike | None = None,
    amax_deg: ArrayLike | None = None,
    *,
    torque_max_Nm: ArrayLike | None = None,
    brake_max_Nm: ArrayLike | None = None,
    names: tuple[str, str] = ("vmax_deg", "amax_deg"),
    torque_names: tuple[str, str] = ("torque_max_Nm", "brake_max_Nm"),
) -> JointLimits:
    """Speed and acceleration limits of the healthy joints by ``jointlock halt``'s rule.

    A joint's speed limit is ``vmax_deg`` capped by the model's own ``velocity_limit`` (the
    smaller of the two); without ``vmax_deg``, the model's limit where finite, else 000's
    :data:`DEFAULT_VMAX_DEG`.  The acceleration limit is ``amax_deg``, else
    :data:`DEFAULT_AMAX_DEG` (a model has no acceleration limit).  A motor's torque limit is
    ``torque_max_Nm`` capped by the model's own effort limit, else the model's where finite,
    else none; a locked joint's brake limit is ``brake_max_Nm``, else none.

    Parameters
    ----------
    vmax_deg, amax_deg
        One value or one per healthy joint [deg/s, deg/s^2] (limits are typed by people, in
        degrees), or None.
    torque_max_Nm, brake_max_Nm
        One value or one per healthy joint [N m]; one value or one per locked joint
        (:attr:`ArmModel.locked` order) [N m]; or None.
    names, torque_names
        How the inputs are named in the sources and in error messages (the CLI's options).
    """
    n = model.dof
    v_opt = _limit_values(vmax_deg, names[0], n)
    a_opt = _limit_values(amax_deg, names[1], n)
    v_model = np.degrees([j.velocity_limit for j in model.joints])
    vmax, v_src = np.empty(n), []
    for i in range(n):
        finite = math.isfinite(v_model[i])
        if v_opt is not None and (not finite or v_opt[i] <= v_model[i]):
            vmax[i] = v_opt[i]
            v_src.append(names[0])
        elif v_opt is not None:
            vmax[i] = v_model[i]
            v_src.append(f"model's limit, below {names[0]} {v_opt[i]:g}")
        elif finite:
            vmax[i] = v_model[i]
            v_src.append("model's limit")
        else:
            vmax[i] = DEFAULT_VMAX_DEG
            v_src.append("000's default; the model gives none")
    if a_opt is not None:
        amax, a_src = a_opt, [names[1]] * n
    else:
        amax, a_src = np.full(n, DEFAULT_AMAX_DEG), ["000's default"] * n
    torque, brake, t_src, b_src = _torque_limits(model, torque_max_Nm, brake_max_Nm, torque_names)
    return JointLimits(
        np.radians(vmax), np.radians(amax), tuple(v_src), tuple(a_src), torque, brake, t_src, b_src
    )


#: How the two limits are named in the limit sources and errors, by caller.
CLI_LIMIT_NAMES = ("--vmax-deg", "--amax-deg")
SCENARIO_LIMIT_NAMES = ("limits.vmax_deg_s", "limits.amax_deg_s2")
CLI_TORQUE_NAMES = ("--torque-max-Nm", "--brake-max-Nm")
SCENARIO_TORQUE_NAMES = ("limits.torque_max_Nm", "limits.brake_max_Nm")


def resolve_limits(
    model: ArmModel, vmax_deg: Sequence[float] | None, amax_deg: Sequence[float] | None
) -> tuple[np.ndarray, np.ndarray, list[str], list[str]]:
    """:func:`halt_limits` as a tuple ``(vmax [rad/s], amax [rad/s^2], vmax_source,
    amax_source)`` (the CLI's form)."""
    lim = halt_limits(model, vmax_deg, amax_deg, names=CLI_LIMIT_NAMES)
    return lim.velocity, lim.acceleration, list(lim.velocity_source), list(lim.acceleration_source)


def limits_text(
    numbers: Sequence[int], values_rad: ArrayLike, sources: Sequence[str], unit: str, *, degrees: bool = True
) -> str:
    """``"40 deg/s (model's limit)"`` when every joint has the same limit from the same
    source, else the joints grouped: ``"joints 1, 2: 10 deg/s (model's limit); joint 4: ..."``."""
    groups: dict[tuple[str, str], list[int]] = {}
    values = np.degrees(values_rad) if degrees else np.asarray(values_rad, dtype=float)
    for num, v, src in zip(numbers, values, sources):
        groups.setdefault((f"{v:.6g}", src), []).append(num)
    if len(groups) == 1:
        (value, src), _ = next(iter(groups.items()))
        return f"{value} {unit} ({src})"
    parts = []
    for (value, src), nums in groups.items():
        label = "joint" if len(nums) == 1 else "joints"
        parts.append(f"{label} {', '.join(map(str, nums))}: {value} {unit} ({src})")
    return "; ".join(parts)
