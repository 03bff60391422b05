"""Optimal halt motion (seed 000 §4): the 6th-order halt polynomial with one free
coefficient ``k``, the joint-limit check, the global base disturbance torque, and solvers.

Method (000 eqs. 25-38)
-----------------------
Every healthy joint moves from the state at failure ``(q0, dq0, ddq0)`` to the halt
configuration ``qf`` at rest (``dqf = ddqf = 0``) in the halt time ``T`` along

    q(t) = a0 + a1 t + ... + a6 t^6,   a6 = k                       (eqs. 25-27)

The ``k``-part of eq. 27 is ``k t^3 (t - T)^3``: a triple root at both ends, so it leaves
all six boundary conditions untouched and ``q(t; k) = q_quintic(t) + k t^3 (t - T)^3``.
Its extremum, at ``t = T/2``, is ``-k T^6 / 64`` (``t^3 (t - T)^3 <= 0`` on ``[0, T]``).

The objective is the time average of the 2-norm of the base disturbance torque (eq. 32),
``tau_bar(k) = 1/T int_0^T ||n_d(t; k)|| dt`` with ``n_d`` from :func:`jointlock.dynamics.rnea`
(000 eqs. 28-31; base held fixed as in 000, or free-floating), integrated by Simpson's
rule.  Constraints (eq. 33): angle, speed and acceleration limits per joint on a dense
time grid.  Each constraint is affine in ``k``, so the feasible set of a shared ``k`` is an
interval computed exactly on the grid (and a box for one ``k`` per joint).

Units of ``k``
--------------
Inside the library ``k`` is in rad/s^6 (SI).  000 works in degrees: its ``k = 0.0018``
reads as deg/s^6 (a 28 deg swing at mid-halt for ``T = 10`` s; in rad/s^6 it would be a
28 rad swing, far outside every limit), so the paper's reading is **deg/s^6**:
``k_si = k_paper * pi / 180`` (:data:`K_UNIT_SCALE`).  The CLI reports ``k`` in deg/s^6.

Infeasible scenarios are reported, never optimised silently: :class:`HaltMotion` then
has ``feasible=False``, the least-violating ``k``, the violations (joint, limit, excess)
and the smallest halt time ``T`` for which a feasible ``k`` exists.

The package's modules:
``_polynomial`` (eqs. 25-27), ``_problem`` (:class:`HaltProblem`), ``_objective`` (eq. 32),
``_feasibility`` (eq. 33 for one problem; smallest feasible ``T``), ``_batch_feasibility``
(feasible ``k`` of many halt configurations at once), ``_solve`` (:func:`optimal_halt_motion`,
:class:`HaltMotion`), ``_report`` (:func:`infeasibility_message`), ``_constants``.  Import
from this package, not from them.
"""

from __future__ import annotations

from ._batch_feasibility import (
    AffineKBounds,
    KIntervalBatch,
    _eval_envelope,
    _upper_envelope,
    feasible_k_interval_batch,
)
from ._clearance_limits import (
    clear_k_exists,
    clear_k_segments,
    clear_per_joint_k,
    clear_T_range,
    clearance_shortfall,
    halt_swept_clearance,
    minimum_clear_halt_time,
)
from ._constants import (
    CHUNK_SAMPLES,
    K_UNIT_SCALE,
    LIMIT_RTOL,
    MIN_SAMPLES,
    TORQUE_FLOOR,
    LimitKind,
    Solver,
)
from ._feasibility import (
    Violation,
    _limits,
    _slack,
    _start_breaks_limits,
    constraint_violations,
    feasible_k_intervals,
    least_violating_k,
    minimum_halt_time,
    relative_violation,
    shared_k_interval,
)
from ._objective import OBJECTIVES, _simpson_mean, base_torque_history, global_base_torque, halt_objective
from ._polynomial import halt_coefficients, k_shape, polynomial_profile
from ._problem import HALT_OBJECTIVES, MOMENT_POINTS, HaltProblem, MomentAbout, _angle_limit, _k_array, _vec
from ._report import infeasibility_message
from ._solve import HaltMotion, _check_k_bounds, _scan, log, optimal_halt_motion

__all__ = [
    "CHUNK_SAMPLES",
    "K_UNIT_SCALE",
    "LIMIT_RTOL",
    "MIN_SAMPLES",
    "TORQUE_FLOOR",
    "AffineKBounds",
    "HaltMotion",
    "HaltProblem",
    "HALT_OBJECTIVES",
    "OBJECTIVES",
    "halt_objective",
    "MOMENT_POINTS",
    "MomentAbout",
    "KIntervalBatch",
    "LimitKind",
    "Solver",
    "Violation",
    "base_torque_history",
    "clear_T_range",
    "clear_k_exists",
    "clear_k_segments",
    "clear_per_joint_k",
    "clearance_shortfall",
    "constraint_violations",
    "feasible_k_interval_batch",
    "feasible_k_intervals",
    "global_base_torque",
    "halt_swept_clearance",
    "halt_coefficients",
    "infeasibility_message",
    "k_shape",
    "least_violating_k",
    "minimum_clear_halt_time",
    "minimum_halt_time",
    "optimal_halt_motion",
    "polynomial_profile",
    "relative_violation",
    "shared_k_interval",
]

#: Private names of the former single module ``halt_motion.py``, still importable from here.
_FORMER_PRIVATE = (
    _angle_limit,
    _check_k_bounds,
    _eval_envelope,
    _k_array,
    _limits,
    _scan,
    _simpson_mean,
    _slack,
    _start_breaks_limits,
    _upper_envelope,
    _vec,
    log,
)
