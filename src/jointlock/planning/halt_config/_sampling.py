"""Where the search samples (000 eqs. 21-22): the seed (:mod:`jointlock._random`), the box of
joint angles (limits, narrowed by the reachability constraint) and the message when nothing is
reachable."""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from ..._random import resolve_rng
from ...errors import ConfigurationError, InfeasibleError
from ...model import ArmModel, FloatArray
from ._bound import ReachabilityBound, _readonly
from ._reachability import HaltReachability

#: The package's one rng convention (:func:`jointlock._random.resolve_rng`), under the name the
#: halt-configuration modules imported before it was shared.
_resolve_rng = resolve_rng


def _sampling_box(
    model: ArmModel,
    lower: ArrayLike | None,
    upper: ArrayLike | None,
    reachability: ReachabilityBound | None,
) -> tuple[FloatArray, FloatArray]:
    n = model.dof
    box = model.angle_range()  # the limits as given, past +-pi too
    lo = box[0] if lower is None else np.asarray(lower, dtype=float)
    hi = box[1] if upper is None else np.asarray(upper, dtype=float)
    for name, arr in (("lower", lo), ("upper", hi)):
        if arr.shape != (n,) or not np.all(np.isfinite(arr)):
            raise ConfigurationError(
                f"{name} must be {n} finite angles [rad] (joints {list(model.joint_numbers)}); "
                f"got {np.asarray(arr).tolist()}"
            )
    if reachability is not None:
        if reachability.q0.shape != (n,):
            raise ConfigurationError(
                f"reachability.q0 must have {n} entries (joints {list(model.joint_numbers)}); "
                f"got {reachability.q0.shape}"
            )
        r_lo, r_hi = reachability.interval(model.joint_numbers)
        lo, hi = np.maximum(lo, r_lo), np.minimum(hi, r_hi)
    empty = hi < lo
    if np.any(empty):
        i = int(np.argmax(lo - hi))
        raise InfeasibleError(
            f"no admissible angle for joint {model.joint_numbers[i]}: the reachable range misses the "
            f"joint limits by {math.degrees(lo[i] - hi[i]):.4g} deg (lower {math.degrees(lo[i]):.4g} "
            f"deg > upper {math.degrees(hi[i]):.4g} deg)"
        )
    return _readonly(lo), _readonly(hi)


def _search_box(
    model: ArmModel,
    lower: ArrayLike | None,
    upper: ArrayLike | None,
    reachability: ReachabilityBound | HaltReachability | None,
) -> tuple[FloatArray, FloatArray, ReachabilityBound | HaltReachability | None, tuple[float, float] | None]:
    """The box to sample [rad], the reachability constraint as applied (a
    :class:`HaltReachability` bound to the model's angle limits) and the feasible shared ``k``
    range [rad/s^6] (exact reachability with a shared ``k`` only).

    Raises
    ------
    InfeasibleError
        The start breaks a limit, or no configuration in the box is reachable.
    """
    if not isinstance(reachability, HaltReachability):
        lo, hi = _sampling_box(model, lower, upper, reachability)
        return lo, hi, reachability, None
    reach = reachability.bind(model)
    reach.check_start(model.joint_numbers)  # impossible starts, up front
    lo, hi = _sampling_box(model, lower, upper, None)
    try:  # the bang-bang bound's own verdict (a joint cannot stop within T) is precise
        reach.bound().interval(model.joint_numbers)
    except InfeasibleError as exc:
        raise InfeasibleError(
            _unreachable_message(reach, lo, hi, model.joint_numbers, reason=str(exc))
        ) from None
    box = reach.search_box(lo, hi)
    if box is None:
        raise InfeasibleError(_unreachable_message(reach, lo, hi, model.joint_numbers))
    lo, hi, k_range, _ = box
    return _readonly(lo), _readonly(hi), reach, k_range


def _unreachable_message(
    reach: HaltReachability,
    lo: FloatArray,
    hi: FloatArray,
    joint_numbers: tuple[int, ...],
    *,
    reason: str | None = None,
) -> str:
    t_min = reach.minimum_halt_time(lo, hi)
    which = "one k per joint" if reach.per_joint else "a shared k (000)"
    msg = (
        f"no halt configuration is reachable by the halt polynomial with {which} within "
        f"T = {reach.halt_time:g} s from {reach.describe_state()} (healthy joints {list(joint_numbers)})"
    )
    if reason is not None:
        msg += f": {reason} (bang-bang bound, necessary only)"
    if t_min is None:
        return msg + "; no halt time up to the search limit makes one reachable"
    return msg + f"; the smallest halt time with a reachable configuration is T = {t_min:.3f} s"
