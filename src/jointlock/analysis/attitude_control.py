"""What the spacecraft's attitude control must absorb while the arm moves with the spacecraft
held (issue 28, item 4).

With the attitude held (000's fixed-base reading), the arm's motion exerts the base moment
``tau_b(t)`` on the spacecraft (:func:`jointlock.dynamics.rnea`'s ``base_moment``, about the
spacecraft's centre of mass, 000 eq. 31).  Reaction wheels holding the attitude supply
``-tau_b``, so they must deliver a torque of ``|tau_b(t)|`` and store the angular momentum the
arm gives up:

``h_w(t) = int_0^t tau_b dt = L_arm(0) - L_arm(t)``

(the arm's angular momentum about the fixed centre of mass; at the end of a halt, the arm at
rest, all of ``L_arm(0)`` has gone to the wheels).  The check compares the peak torque and the
peak stored momentum (Euclidean norms: a wheel assembly that can give that much about any
axis) with the capacities ``wheel_torque_max_Nm`` and ``wheel_momentum_max_Nms`` of the
scenario's ``[spacecraft]`` table.

Assumption: the spacecraft is held in translation too (000's fixed-base reading).  Wheels hold
the attitude only; the base force the arm exerts (``rnea``'s ``base_force``) would move a
spacecraft held by wheels alone, or needs thrusters, and is not judged here.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from ..bounds import MAX_TORQUE_NM, as_real
from ..dynamics import rnea
from ..errors import ConfigurationError
from ..model import ArmModel, FloatArray

__all__ = ["AttitudeControlCheck", "WheelCapacity", "attitude_control_check"]


@dataclass(frozen=True)
class WheelCapacity:
    """What the attitude control can give: torque [N m] and stored momentum [N m s]; None: not
    given (the figure is reported, not judged)."""

    torque_max_Nm: float | None = None
    momentum_max_Nms: float | None = None

    def __post_init__(self) -> None:
        for name, unit in (("torque_max_Nm", "N m"), ("momentum_max_Nms", "N m s")):
            value = getattr(self, name)
            if value is not None:
                checked = as_real(value, f"wheel {name}", lo=0.0, hi=MAX_TORQUE_NM, unit=unit, error=ConfigurationError)
                if checked <= 0:
                    raise ConfigurationError(f"wheel {name} must be > 0 [{unit}]; got {value!r}")
                object.__setattr__(self, name, checked)

    @property
    def given(self) -> bool:
        return self.torque_max_Nm is not None or self.momentum_max_Nms is not None


@dataclass(frozen=True, eq=False)  # arrays inside
class AttitudeControlCheck:
    """The torque and momentum the attitude control must absorb to hold the spacecraft.

    Attributes
    ----------
    t
        (m,) times [s].
    torque
        (m, 3) base moment the arm exerts on the held spacecraft [N m], root frame, about the
        spacecraft's centre of mass.
    momentum
        (m, 3) angular momentum handed to the wheels so far, ``int_0^t torque dt`` [N m s]
        (trapezoidal rule).
    capacity
        The wheels' capacities (:class:`WheelCapacity`).
    """

    t: FloatArray
    torque: FloatArray
    momentum: FloatArray
    capacity: WheelCapacity

    @property
    def peak_torque_Nm(self) -> float:
        return float(np.linalg.norm(self.torque, axis=-1).max())

    @property
    def peak_momentum_Nms(self) -> float:
        return float(np.linalg.norm(self.momentum, axis=-1).max())

    @property
    def final_momentum_Nms(self) -> float:
        """Momentum left in the wheels at the end [N m s] (the arm's momentum at the start, for a
        motion that ends at rest)."""
        return float(np.linalg.norm(self.momentum[-1]))

    def margins(self) -> dict[str, float | None]:
        """``1 - peak / capacity`` per capacity given (negative: exceeded), None where not given."""
        cap = self.capacity
        return {
            "torque": None if cap.torque_max_Nm is None else 1.0 - self.peak_torque_Nm / cap.torque_max_Nm,
            "momentum": None if cap.momentum_max_Nms is None else 1.0 - self.peak_momentum_Nms / cap.momentum_max_Nms,
        }

    @property
    def within(self) -> bool | None:
        """True: within every capacity given; False: one is exceeded; None: none given."""
        given = [m for m in self.margins().values() if m is not None]
        return None if not given else all(m >= 0 for m in given)

    def verdict(self) -> str:
        """One line: within or EXCEEDS, with the peaks and the capacities."""
        cap = self.capacity
        parts = [
            f"peak torque {self.peak_torque_Nm:.4g} N m"
            + ("" if cap.torque_max_Nm is None else f" of {cap.torque_max_Nm:.4g}"),
            f"peak momentum {self.peak_momentum_Nms:.4g} N m s"
            + ("" if cap.momentum_max_Nms is None else f" of {cap.momentum_max_Nms:.4g}"),
        ]
        if self.within is None:
            return "attitude control (spacecraft held): " + ", ".join(parts) + " (no wheel capacity given)"
        exceeded = [k for k, m in self.margins().items() if m is not None and m < 0]
        head = "ATTITUDE CONTROL EXCEEDED" if exceeded else "attitude control: within the wheels' capacity"
        tail = f" ({' and '.join(exceeded)} over)" if exceeded else ""
        return f"{head}: " + ", ".join(parts) + tail

    def to_dict(self) -> dict[str, Any]:
        return {
            "peak_torque_Nm": self.peak_torque_Nm,
            "peak_momentum_Nms": self.peak_momentum_Nms,
            "final_momentum_Nms": self.final_momentum_Nms,
            "wheel_torque_max_Nm": self.capacity.torque_max_Nm,
            "wheel_momentum_max_Nms": self.capacity.momentum_max_Nms,
            "torque_margin": self.margins()["torque"],
            "momentum_margin": self.margins()["momentum"],
            "within": self.within,
            "verdict": self.verdict(),
        }


def attitude_control_check(
    model: ArmModel,
    t: ArrayLike,
    q: ArrayLike,
    dq: ArrayLike,
    ddq: ArrayLike,
    capacity: WheelCapacity | None = None,
    *,
    moment_point: ArrayLike | None = None,
) -> AttitudeControlCheck:
    """The attitude control's load for the motion ``q, dq, ddq`` (m, n) on the times ``t`` (m,)
    [s] with the spacecraft held (see the module docstring); ``moment_point`` as
    :func:`jointlock.dynamics.rnea` (default the spacecraft's centre of mass)."""
    times = np.asarray(t, dtype=float)
    if times.ndim != 1 or times.size < 2 or np.any(np.diff(times) <= 0):
        raise ConfigurationError(f"t must be (m,) increasing times, m >= 2 [s]; got shape {times.shape}")
    torque = rnea(model, q, dq, ddq, base="fixed", moment_point=moment_point).base_moment
    if torque.shape != (times.size, 3):
        raise ConfigurationError(f"q, dq, ddq must have one row per time: {times.size}; got {torque.shape[:-1]}")
    steps = 0.5 * (torque[1:] + torque[:-1]) * np.diff(times)[:, None]
    momentum = np.concatenate([np.zeros((1, 3)), np.cumsum(steps, axis=0)])
    return AttitudeControlCheck(times, torque, momentum, capacity or WheelCapacity())
