"""Motor and brake torque limits of a halt (issue 14): the healthy joints' motor torques and the
locked joints' brake torques (:func:`jointlock.analysis.actuators.actuator_torques`) must stay
within :attr:`HaltProblem.tau_max` and :attr:`HaltProblem.brake_max` on every sample of the
constraint grid (``n_check`` samples over ``[0, T]``).

Unlike the kinematic limits (affine in ``k``: an exact interval), the torques are not affine
in ``k`` (the Coriolis terms are quadratic in the rates, the inertia depends on the angles),
so the set of ``k`` that keeps them may be several intervals.  It is found on the candidate
set: a dense scan of ``k`` over the kinematically feasible interval, then every boundary
between a feasible and an infeasible scan point refined by bisection to ``1e-9`` of the
interval's width.  A feasible stretch narrower than the scan's step can be missed; the
scan's size is the solver's ``n_scan``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike

from ..._search1d import bisect_boundary, true_segments
from ...analysis.actuators import actuator_torques
from ...model import FloatArray
from ._constants import CHUNK_SAMPLES, LIMIT_RTOL, LimitKind
from ._feasibility import Violation, feasible_k_intervals, minimum_halt_time
from ._problem import HaltProblem

#: Relative width of the refined boundaries of the torque-feasible set of ``k`` [-].
BOUNDARY_RTOL = 1e-9


def actuator_peaks(problem: HaltProblem, k: ArrayLike) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Largest |motor| and |brake| torque over the halt for a batch of shared ``k`` [rad/s^6].

    Returns
    -------
    motor, brake, ratio
        (..., n) and (..., n_locked) [N m]; (...) the largest ``peak / limit`` over every
        limited motor and brake (0 when none is limited).
    """
    k = np.asarray(k, dtype=float)
    flat = k.reshape(-1)
    n_locked = len(problem.model.locked)
    motor = np.empty((flat.size, problem.dof))
    brake = np.empty((flat.size, n_locked))
    step = max(1, CHUNK_SAMPLES // problem.n_check)
    for start in range(0, flat.size, step):  # chunks of candidates, not of time samples
        q, dq, ddq = problem.on_grid(flat[start : start + step], problem.n_check)
        m, b = actuator_torques(problem.model, q, dq, ddq, base=problem.base)
        motor[start : start + step] = np.abs(m).max(axis=-2)
        brake[start : start + step] = np.abs(b).max(axis=-2) if n_locked else b[..., 0, :]
    ratio = np.zeros(flat.size)
    tau_max, brake_max = problem.torque_limits()
    if np.any(np.isfinite(tau_max)):
        ratio = np.maximum(ratio, (motor / tau_max).max(axis=-1))
    if n_locked and np.any(np.isfinite(brake_max)):
        ratio = np.maximum(ratio, (brake / brake_max).max(axis=-1))
    return motor.reshape(k.shape + (-1,)), brake.reshape(k.shape + (n_locked,)), ratio.reshape(k.shape)


def _within(problem: HaltProblem, k: ArrayLike) -> np.ndarray:
    return actuator_peaks(problem, k)[2] <= 1.0 + LIMIT_RTOL


def torque_feasible_segments(
    problem: HaltProblem, lo: float, hi: float, n_scan: int
) -> list[tuple[float, float]]:
    """The stretches of ``[lo, hi]`` [rad/s^6] whose halts keep every torque limit: a scan of
    ``n_scan`` points, each feasible/infeasible boundary bisected (batched) to
    :data:`BOUNDARY_RTOL` of the width, the refined end kept on the feasible side."""
    return true_segments(lambda x: _within(problem, x), lo, hi, n_scan, BOUNDARY_RTOL)


def torque_violations(problem: HaltProblem, k: float) -> tuple[Violation, ...]:
    """Every motor or brake torque limit the halt at ``k`` breaks (SI: N m), worst first."""
    t = problem.times(problem.n_check)
    q, dq, ddq = problem.on_grid(np.asarray(k, dtype=float), problem.n_check)
    motor, brake = actuator_torques(problem.model, q, dq, ddq, base=problem.base)
    tau_max, brake_max = problem.torque_limits()
    out = []
    groups: tuple[tuple[LimitKind, FloatArray, FloatArray, Sequence[int]], ...] = (
        ("torque", motor, tau_max, problem.model.joint_numbers),
        ("brake", brake, brake_max, [lj.number for lj in problem.model.locked]),
    )
    for kind, values, limits, numbers in groups:
        for j, number in enumerate(numbers):
            if not math.isfinite(limits[j]):
                continue
            i_t = int(np.argmax(np.abs(values[:, j])))
            excess = float(abs(values[i_t, j]) - limits[j])
            if excess > LIMIT_RTOL * limits[j]:
                out.append(
                    Violation(number, kind, float(limits[j]), float(values[i_t, j]), excess, float(t[i_t]))
                )
    return tuple(sorted(out, key=lambda v: -v.excess / v.limit))


def least_torque_violating_k(problem: HaltProblem, lo: float, hi: float, n_scan: int) -> float:
    """The ``k`` in ``[lo, hi]`` [rad/s^6] (the kinematically feasible interval) with the smallest
    largest torque-to-limit ratio, on the scan grid (ratios are not convex in ``k``)."""
    grid = np.linspace(lo, hi, max(n_scan, 2)) if hi > lo else np.array([lo])
    return float(grid[int(np.argmin(actuator_peaks(problem, grid)[2]))])


def _feasible_with_torques(problem: HaltProblem, n_scan: int) -> bool:
    per = feasible_k_intervals(problem)
    lo, hi = float(per[:, 0].max()), float(per[:, 1].min())
    return lo <= hi and bool(torque_feasible_segments(problem, lo, hi, n_scan))


def minimum_halt_time_with_torques(
    problem: HaltProblem, *, n_scan: int = 101, growth: float = 1.1, tol: float = 1e-2
) -> float | None:
    """Smallest halt time [s] with a ``k`` that keeps every kinematic and torque limit: from the
    kinematic one (:func:`minimum_halt_time`), ``T`` grows by ``growth`` per step up to
    ``max(10 T, 120 s)``, then the first infeasible-to-feasible bracket is bisected to
    ``tol`` [s].  None when no halt time in that range has one (the torques at the start do not
    shrink with ``T``)."""
    t = minimum_halt_time(problem)
    if t is None:
        return None
    t_max = max(10 * problem.T, 120.0)
    prev = None
    while t <= t_max:
        if _feasible_with_torques(problem.with_time(t), n_scan):
            if prev is None:
                return float(t)
            ok = bisect_boundary(
                lambda x: np.array([_feasible_with_torques(problem.with_time(float(v)), n_scan) for v in np.ravel(x)]).reshape(np.shape(x)),
                prev, t, xtol=tol,
            )  # fmt: skip
            return float(ok.true_end)
        prev, t = t, t * growth
    return None
