"""Keep following the path through an unexpected lock: null-space "global compensation"
(seed 001, method as reconstructed in ``docs/reconstruction-001.md``).

Pipeline
--------
1. :func:`cartesian_trapezoid` -- straight line ``x0 -> x0 + dx`` timed by a trapezoidal
   velocity profile with parabolic blends (001 §4.3: 12 s task, 2 s blends, 50 ms step).
2. Resolved-rate following with the compensation term (NOTES-001, "The control law")::

       xdot_c = xdot_nom + K_p (x_nom - x)
       qdot   = J^+ xdot_c + kappa (I - J^+ J) grad w(q)          (healthy)
       qdot_r = J_r^+ xdot_c + kappa (I - J_r^+ J_r) grad w_r(q)   (after the lock; qdot_j = 0)

   ``w = sqrt(det(J J^T))`` of the 3 x n position Jacobian, gradient in closed form
   (:mod:`jointlock.derivatives`).  Joint states are integrated by explicit Euler over the
   control step (001 eq. 19, ``q_{k+1} = q_k + qdot_k dt``).  A failure at time ``t_f`` takes
   effect at the first control step ``k_f = ceil(t_f / dt)``; several joints may lock in
   sequence.  The locked Jacobian is the full one with the locked columns masked, which is
   exactly the reduced model's Jacobian (``docs/conventions.md``).
3. Jump metrics at ``t_f`` (same configuration, NOTES-001 "What is measured"): joint jump
   ``qdot(t_f+) - qdot(t_f-)`` with re-planning (padded reduced law) and without (only the
   locked joint stops), task jump ``-J_j qdot_j`` without re-planning and ``J dqdot`` (zero
   while ``J_r`` has full row rank) with it.
4. :func:`search_kappa` -- feasible kappa interval under ``|qdot| <= qdot_max``,
   ``|qddot| <= qddot_max`` (finite differences over the control step) and
   ``||x - x_nom|| <= eps`` for the healthy run *and* the run with the failure; grid search of
   ``||dqdot||`` then parabolic/golden-section refinement inside the brackets of the best
   feasible local grid minima (multi-start: a narrow valley between grid points is found).
5. :func:`fit_kappa` -- piecewise polynomial kappa(t): the sampled optimum is split where it
   jumps from one branch to another (:func:`find_breaks`), failure times are added around each
   break, one least-squares polynomial per segment (5th order by default; order raised until
   the residual criterion holds), and per segment, in time order and with the schedule's own
   history, the piece is kept, the previous piece continued, or kappa = 0 used -- whichever
   gives the smaller jumps at the segment's samples; a kept piece is trimmed to 001's segment
   points where compensated and uncompensated objectives are equal (kappa = 0 near start and
   end).  Without breaks: 001's single polynomial with two segment points.
6. :func:`verify_kappa` -- failure injected at **every** control step with kappa(t) in the
   law: jumps before/after, mean reduction, share improved, every limit checked (a fitted
   kappa(t) can break a limit that each sampled kappa kept: reported, and clipping to the
   feasible band is offered).

Batching (NOTES-001 property 4): the motion before a failure does not depend on when it
happens, so one healthy run per kappa gives the jump at *every* control step (both laws are
evaluated at each step of the healthy run).  The post-failure runs needed for the limits
branch off the healthy runs at their failure steps *in the same pass*: every kappa value and
failure time is a column of one batch (batch axis last in the law's kernel), the law is
evaluated once per control step for all of them, and the only Python loop is over the
integrator's time steps (and the joints inside the kinematics).  What stays sequential is
sequential by nature: the kappa scale (one run at kappa = 0) before the probe, the probe
before the grid, each refinement iteration after the last, the check of the refined values
after the refinement, the fit after the search, the verification after the fit.

Choices where the paper is silent (arguments / scenario fields):

* The step at which the lock happens is excluded from the acceleration check (the jump is
  the objective, not a constraint; otherwise no kappa is ever feasible).
* ``rest_transitions=False``: the start from rest and the stop at ``T`` are not checked
  against ``qddot_max`` (with a constant kappa the compensation term makes the arm start
  moving at ``t = 0``; 001 imposes kappa(0) = kappa(T) = 0 on its fitted function for that
  reason).  Set it True to check them.
* Free-floating base (``scenario.base="floating"``): the generalized Jacobian (zero
  momentum), its derivative by finite differences, the spacecraft attitude integrated from
  the base Jacobian, and the end-effector position taken in the inertial frame (system centre
  of mass fixed, inertial frame = root frame at ``t = 0``).

Modules (private; import from ``jointlock.planning.jump``): ``_task`` (scenario, task file),
``_path`` (Cartesian path), ``_control`` (the law, batched), ``_frames`` (its inputs per
step: fixed-base kinematics), ``_engine`` (batched integrator),
``_simulate`` (runs, jump tables, limit reports), ``_search`` (kappa search), ``_pieces`` and
``_fit`` (kappa(t)), ``_verify`` (verification), ``_study`` (one failure time, whole pipeline).
"""

from __future__ import annotations

# Leading-underscore names are re-exported (``x as x``) so that code written against the former
# single module ``jump.py`` keeps importing them from here; they are not part of the API.
from ._control import compensated_rates
from ._engine import LIMIT_RTOL, SINGULAR_W
from ._engine import _healthy_runs as _healthy_runs
from ._engine import _integrate as _integrate
from ._engine import _kappa_rows as _kappa_rows
from ._engine import _ok as _ok
from ._engine import _post_runs as _post_runs
from ._engine import _Problem as _Problem
from ._engine import _problem as _problem
from ._engine import _RunOut as _RunOut
from ._engine import _unsort as _unsort
from ._fit import KappaFit, fit_kappa
from ._fit import _feasible_samples as _feasible_samples
from ._fit import _fit_single as _fit_single
from ._joint_motion import cartesian_task
from ._path import CartesianPath, cartesian_trapezoid
from ._pieces import KappaPiece, find_breaks, fit_pieces
from ._pieces import _crossings as _crossings
from ._pieces import _eval_pieces as _eval_pieces
from ._pieces import _polyfit as _polyfit
from ._search import _GOLDEN as _GOLDEN
from ._search import KappaSearch, merge_searches, sample_failure_times, search_kappa
from ._search import _contiguous as _contiguous
from ._search import _probe as _probe
from ._search import _refine as _refine
from ._simulate import (
    NO_JUMP_RAD_S,
    JumpTable,
    LimitReport,
    Trajectory,
    improved_share,
    jump_reduction,
    jump_table,
    simulate,
)
from ._simulate import _limit_report as _limit_report
from ._simulate import _table as _table
from ._study import JumpAtTime, JumpStudy, jump_at_time, study_jump
from ._task import _RUN_SCENARIO_KEYS as _RUN_SCENARIO_KEYS
from ._task import SCENARIO_FIELDS, Base, JumpScenario, load_jump_task, scenario_from_mapping
from ._task import _is_number as _is_number
from ._task import _refuse_run_scenario as _refuse_run_scenario
from ._task import load_scenario as load_scenario  # deprecated alias of load_jump_task
from ._verify import Verification, feasible_band, ramp_schedule, verify_kappa
from ._verify import _step_limits as _step_limits

__all__ = [
    "Base",
    "CartesianPath",
    "JumpAtTime",
    "JumpScenario",
    "JumpStudy",
    "JumpTable",
    "KappaFit",
    "KappaPiece",
    "KappaSearch",
    "LIMIT_RTOL",
    "LimitReport",
    "SCENARIO_FIELDS",
    "SINGULAR_W",
    "Trajectory",
    "Verification",
    "cartesian_task",
    "cartesian_trapezoid",
    "compensated_rates",
    "feasible_band",
    "find_breaks",
    "fit_kappa",
    "fit_pieces",
    "jump_at_time",
    "jump_reduction",
    "improved_share",
    "NO_JUMP_RAD_S",
    "jump_table",
    "load_jump_task",
    "merge_searches",
    "ramp_schedule",
    "sample_failure_times",
    "scenario_from_mapping",
    "search_kappa",
    "simulate",
    "study_jump",
    "verify_kappa",
]
