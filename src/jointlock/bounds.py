"""Bounds that make physical sense, and the small checks every public boundary shares.

float64 holds numbers up to ~1.8e308, but the products inside the maths overflow long before
that: a mass times a squared joint rate times a length (``rnea``), ``1/T**6`` of a halt
polynomial, ``duration / dt`` time steps.  So every input is held to a range that covers any
real space manipulator with orders of magnitude to spare, and a value outside it is refused
with one line naming the field (or option), the value (shortened) and the range -- never
returned as inf or NaN.  The ranges:

==========================  =====================  ==========================================
quantity                    range                  why
==========================  =====================  ==========================================
length (link, offset, pose) ``|x| <= 1e6`` m       1000 km: longer than anything in orbit
length that divides         ``>= 1e-6`` m          (characteristic length, voxel side)
mass                        ``<= 1e9`` kg          a billion kg: ~2000 space stations
inertia                     ``<= 1e15`` kg m^2     1e9 kg at 1000 m
joint angle / rate / accel  ``|x| <= 1e6``         rad, rad/s, rad/s^2 (any arm: < 1e2)
time (halt T, task)         ``1e-3 .. 1e6`` s      a millisecond to 11 days
time step (control cycle)   ``1e-6 .. 1e6`` s
time steps of one motion    ``<= 1e5``             every step is a failure time to verify
==========================  =====================  ==========================================
"""

from __future__ import annotations

import math
import os
from typing import Any

from .errors import JointlockError

#: Largest |length| of a model dimension, a pose or a displacement [m].
MAX_LENGTH_M = 1e6
#: Largest |length| an ArmModel holds [m]: a safety net above MAX_LENGTH_M, as the placements
#: of a locked arm compose several lengths of the model files (each within MAX_LENGTH_M).
MAX_MODEL_LENGTH_M = 1e12
#: Smallest length that a computation divides by (characteristic length, voxel side) [m].
MIN_LENGTH_M = 1e-6
#: Largest mass of a link or a spacecraft [kg].
MAX_MASS_KG = 1e9
#: Largest entry of an inertia tensor [kg m^2].
MAX_INERTIA_KGM2 = 1e15
#: Largest |value| of a joint-space array: angles [rad], rates [rad/s], accelerations [rad/s^2].
MAX_JOINT_VALUE = 1e6
#: Shortest and longest duration of a motion (halt time, task time) [s].
MIN_TIME_S, MAX_TIME_S = 1e-3, 1e6
#: Shortest control step or cycle [s].
MIN_STEP_S = 1e-6
#: Most control steps of one jump task: the verification injects the failure at every step,
#: so the work grows with the square of the steps (12,000 steps already take many minutes).
MAX_TIME_STEPS = 100_000

#: Largest |kappa| of 001's compensation [rad^2/(s m^3)]: beyond it the compensation term alone
#: drives any arm's joints at thousands of rad/s (the searched range is +-2 vmax / |grad w|).
MAX_KAPPA = 1e6
#: Largest feedback gain [1/s] (a gain above 1/dt is unstable anyway).
MAX_GAIN = 1e6

#: Largest joint speed and acceleration limits [deg/s, deg/s^2]: far above any arm (the ISS arm
#: moves at a few deg/s), low enough that rates and accelerations derived from them stay finite.
MAX_RATE_DEG = 1e6

#: Largest torque limit [N m]: a billion newton-metres is no limit for any arm.
MAX_TORQUE_NM = 1e9
#: Largest |angle| of a command-line angle option [deg] (a scenario's *_deg fields keep +-360).
MAX_OPTION_DEG = 1e6
#: Largest seed (numpy takes any integer >= 0; seeds are stored as 64-bit integers).
MAX_SEED = 2**63 - 1

#: Longest text of a value echoed in an error message [characters].
SHOWN_CHARS = 80


def shown(value: Any, limit: int = SHOWN_CHARS) -> str:
    """``repr(value)`` on one line, shortened to ``limit`` characters (a 5000-character name
    is not echoed back whole; an array's repr loses its line breaks)."""
    return shorten(" ".join(repr(value).split()), limit)


def shorten(text: str, limit: int = SHOWN_CHARS) -> str:
    """``text`` cut to ``limit`` characters (with "..."); see :func:`shown` for a repr."""
    return text if len(text) <= limit else text[: limit - 3] + "..."


def as_real(
    value: Any,
    where: str,
    *,
    lo: float | None = None,
    hi: float | None = None,
    unit: str = "",
    error: type[JointlockError] = JointlockError,
) -> float:
    """``value`` as a finite float within ``[lo, hi]``, else ``error`` naming ``where``.

    Refuses booleans, complex numbers, strings and integers too large for a float (TOML
    allows integers of any length)."""
    unit_text = f" [{unit}]" if unit else ""
    rng = []
    if lo is not None:
        rng.append(f">= {lo:g}")
    if hi is not None:
        rng.append(f"<= {hi:g}")
    allowed = "a finite real number" + (" " + " and ".join(rng) if rng else "") + unit_text
    if isinstance(value, bool) or not isinstance(value, (int, float)) and not _is_numpy_real(value):
        raise error(f"{where} must be {allowed}; got {shown(value)} ({type(value).__name__})")
    try:
        x = float(value)
    except OverflowError:
        raise error(
            f"{where} must be {allowed}; got an integer of {len(str(abs(int(value))))} digits"
        ) from None
    if not math.isfinite(x) or (lo is not None and x < lo) or (hi is not None and x > hi):
        raise error(f"{where} must be {allowed}; got {shown(value)}")
    return x


def _is_numpy_real(value: Any) -> bool:
    import numpy as np

    return isinstance(value, (np.integer, np.floating)) and not isinstance(value, np.bool_)


def check_overflow(results: Any, what: str, **inputs: Any) -> None:
    """Raise :class:`~jointlock.errors.ConfigurationError` when a computation from finite
    inputs returned inf or NaN (its products overflowed float64): one line naming ``what``
    and the largest magnitude of each input (``dq=...``), instead of returning the overflow.

    ``results``: arrays, possibly nested in lists or tuples (``None`` entries skipped); call it after computing under
    ``np.errstate(over="ignore", invalid="ignore")``."""
    import numpy as np

    from .errors import ConfigurationError

    def finite(obj: Any) -> bool:
        if obj is None:
            return True
        if isinstance(obj, (list, tuple)):
            return all(finite(x) for x in obj)
        # one pass, no temporary: a sum is finite iff every entry is (or the sum itself
        # overflows, i.e. entries near 1e308 -- an overflow too, for what it says)
        return math.isfinite(float(np.sum(obj)))

    with np.errstate(over="ignore", invalid="ignore"):
        ok = finite(results)
    if ok:
        return
    sizes = ", ".join(f"|{k}| up to {float(np.max(np.abs(v), initial=0.0)):.3g}" for k, v in inputs.items())
    raise ConfigurationError(
        f"{what}: the result overflows float64 for these inputs ({sizes}): rates and accelerations "
        f"this large are far beyond any arm (|x| <= {MAX_JOINT_VALUE:g} computes)"
    )


def physical_memory_bytes() -> int | None:
    """Physical memory of this machine [bytes], or None where the OS does not say."""
    try:
        return int(os.sysconf("SC_PAGE_SIZE")) * int(os.sysconf("SC_PHYS_PAGES"))
    except (AttributeError, ValueError, OSError):
        return None


def check_memory(nbytes: float, what: str, error: type[JointlockError] = JointlockError) -> None:
    """Refuse, before allocating, a computation whose arrays need more than this machine's
    physical memory: ``nbytes`` is an estimate of what it holds at once; ``what`` names the
    option or field that sets the size (e.g. ``"--samples 4294967297"``)."""
    total = physical_memory_bytes()
    if total is not None and nbytes > total:
        raise error(
            f"{what} needs about {_size(nbytes)} of memory; this machine has {_size(total)}: ask for fewer"
        )


def _size(nbytes: float) -> str:
    for unit in ("B", "KB", "MB", "GB", "TB", "PB"):
        if nbytes < 1024 or unit == "PB":
            return f"{nbytes:.3g} {unit}"
        nbytes /= 1024
    return f"{nbytes:.3g} PB"  # pragma: no cover
