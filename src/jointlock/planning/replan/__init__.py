"""Fault-tolerant re-planning of a non-redundant arm with one locked joint (seed 002).

* :func:`gamma_sweep` -- 002 §"Fault-tolerant planning based on the inverse solution of
  6-DOF manipulator", steps 1-4: rotate the target about the **tool x axis** by ``gamma``
  (eq. 18, ``T' = T Rx(gamma)``; the printed (1, 1) element 0 is a typo for 1), solve the
  full-arm closed-form IK for every ``gamma`` at once and follow one branch (Figs. 5-8).
* :func:`absorbable_range` -- the range of lock angles of a joint that some ``gamma`` within
  a tolerance can absorb (002: joint 2 "48 deg to 123 deg" over +-180 deg, "59.2 to 60.8 deg"
  over +-2 deg).
* :func:`gammas_for_lock` -- step 5: every ``gamma`` at which the full-arm IK puts the
  locked joint exactly at its locked angle (bracketing on a grid, then vectorised
  bisection), with the joint solution at each.
* :func:`replan_line` -- step 6 and eqs. (19)-(20): a straight Cartesian line solved with
  the locked-arm closed form, ``gamma`` (within the tolerance) and the branch chosen along
  the whole path (shortest path over waypoint x gamma x branch, tracking error against the
  squared joint steps) so that the joints do not jump; joint trajectories, poses, tracking
  errors, the largest joint step, jumps and speed-limit excesses.

Everything is batched over ``gamma`` and over waypoints; SI units and radians.

Modules (private; every name, private ones included, is re-exported here): ``_gamma`` (the
sweep, the absorbable range and the gamma roots), ``_line`` (:func:`replan_line` and the
straight line of eqs. 19-20), ``_path`` (the continuous plan: shortest path over waypoints x
gamma x branch), ``_pointwise`` (the first, waypoint-by-waypoint plan) and ``_result`` (the
result types).
"""

from __future__ import annotations

# Private names (marked F401) are re-exported too: code written before the split imports them
# from here.
from ._gamma import (  # noqa: F401
    DEFAULT_GAMMA_STEP,
    ROOT_BISECTIONS,
    GammaRoot,
    GammaSweep,
    LockRange,
    _bisect,
    _brackets,
    _continuous,
    _full_branches,
    _full_geometry,
    _locked_value,
    _pick_branch,
    absorbable_range,
    gamma_sweep,
    gammas_for_lock,
    tool_x_rotation,
)
from ._line import (  # noqa: F401
    JUMP_MAX_STEP,
    JUMP_MEDIAN_FACTOR,
    JUMP_MIN_STEP,
    _flags,
    line_waypoints,
    replan_line,
)
from ._path import (  # noqa: F401
    DEFAULT_STEP_WEIGHT,
    GOAL_WEIGHT,
    PATH_GAMMA_STEP,
    PATH_MAX_GAMMAS,
    REFINE_STEPS,
    _branch_error,
    _continuous_plan,
    _golden,
    _shortest_path,
)
from ._pointwise import _pointwise_absorbed, _pointwise_grid, _pointwise_plan  # noqa: F401
from ._result import ReplanResult, StepFlag

__all__ = [
    "DEFAULT_GAMMA_STEP",
    "DEFAULT_STEP_WEIGHT",
    "GOAL_WEIGHT",
    "JUMP_MAX_STEP",
    "JUMP_MEDIAN_FACTOR",
    "JUMP_MIN_STEP",
    "PATH_GAMMA_STEP",
    "PATH_MAX_GAMMAS",
    "REFINE_STEPS",
    "ROOT_BISECTIONS",
    "GammaRoot",
    "GammaSweep",
    "LockRange",
    "ReplanResult",
    "StepFlag",
    "absorbable_range",
    "gamma_sweep",
    "gammas_for_lock",
    "line_waypoints",
    "replan_line",
    "tool_x_rotation",
]
