"""Singularity analysis (seed 004, Chen et al. 2014): singular values, rank and singular
directions of any arm, a batched search for singular configurations, and the closed-form
conditions Cond1-Cond5 of Canadarm2-structure arms checked against the numerical test.

**General part** (any model, any batch of configurations):

* :func:`task_jacobian` picks the Jacobian whose singularities are studied (``jacobian=``):
  ``"fixed"`` (geometric Jacobian, :func:`jointlock.jacobian`), ``"generalized"`` (or
  ``"floating"``, the same: generalized Jacobian with zero momentum,
  :func:`jointlock.generalized_jacobian`) or ``"virtual"`` (the Jacobian ``J^_m`` of the
  virtual manipulator, 004 eqs. 10-14, :func:`jointlock.virtual_manipulator`).
* :func:`analyse_singularity` gives sigma_min, the numerical rank (tolerance by argument),
  ``det(J J^T)`` (004's test, Whitney) and the lost task directions: the left singular vectors
  ``u`` whose singular values fell below the tolerance, so that ``J^T u ~ 0``.
* :func:`find_singularities` drives many seeded starts to ``sigma_min = 0`` at once (batched
  Gauss-Newton on the smallest singular value, see its Notes) and
  :func:`cluster_singularities` groups what it finds into families.

**Structure-specific part** (Canadarm2 / SSRMS structure: 7 revolute joints, axes 3, 4, 5
parallel, frames of ``jointlock.robots.canadarm7``):

* :func:`reference_jacobian` is our Jacobian referred to 004's reference point (the point
  where axes 5 and 6 meet, origin of link frame 6, index 5) and expressed in its reference
  frame Sigma_4 (orientation of link frame 5, index 4); :func:`eq15_jacobian` is eq. (15) as
  printed.  They are equal (tested).
* :func:`reorder_eq24` permutes it into eq. (24) ``[[J11, J12], [J21, O3]]``.
* :func:`condition_equations` / :func:`condition_residuals` evaluate Cond1-Cond5 (eq. 30),
  :func:`analytic_directions` the singular directions of eqs. (28) and (32),
  :func:`sample_condition` draws configurations that satisfy a condition exactly, and
  :func:`verify_conditions` checks each condition by sampling (is it sufficient?) and the list
  by searching (is it complete?).

**What the verification finds** (``docs/singularity.md``): Cond2-Cond5 are sufficient — every
sample is singular.  Cond1 (``S4 = 0``, the determinant ``d^ e^ S4`` of J12) is *not*: no
sample with ``S4 = 0`` alone is singular.  With ``S4 = 0`` the rank drops only if in addition
``F = 0`` (:func:`cond1_extra`, a closed form found with sympy; 004 does not state it), and
that refined condition ``"cond1f"`` is sufficient.  Every singular configuration the search
finds satisfies one of Cond1-Cond5 (the list is complete).

**Units.**  A 6 x n Jacobian mixes m/s and rad/s rows.  As in 004 the raw matrix is used;
``characteristic_length=L`` [m] divides the linear rows by ``L`` (``docs/conventions.md``).
Tolerances on sigma_min are therefore in the raw matrix's mixed units.

**Names** (``docs/conventions.md``, "Names").  The keywords were ``base=`` (which Jacobian)
and ``length=`` before; both still work as deprecated aliases of ``jacobian=`` and
``characteristic_length=`` (a ``FutureWarning`` once per process and function).  Result
fields keep their names (``base``, ``length``).

**Which virtual lengths.**  ``weighting="segment"`` (default here) is 004's formula and
reproduces its printed virtual lengths and Table 3; ``"vafa-dubowsky"`` is the exact virtual
manipulator (:func:`jointlock.virtual_link_vectors`).  The conditions hold for any lengths.

**Modules.**  ``_general`` (task Jacobian, SVD, rank, lost directions of any arm),
``_search`` (batched search and families), ``_canadarm2`` (lengths, eqs. 15 and 24,
Cond1-Cond5, analytic directions) and ``_verify`` (exact samples of each condition, and the
verification); everything is imported from here.
"""

from __future__ import annotations

# Private names (marked F401) are re-exported too: tests and older callers reach them here.
from ._canadarm2 import (
    _STRUCTURE_TOL,  # noqa: F401
    CONDITION_TOL,
    CONDITIONS,
    EQ24_COLS,
    EQ24_ROW_NAMES,
    EQ24_ROWS,
    REFINED_CONDITIONS,
    ArmLengths,
    Eq24Partition,
    _check_canadarm,  # noqa: F401
    _lengths,  # noqa: F401
    _real_segments,  # noqa: F401
    _trig,  # noqa: F401
    analytic_directions,
    arm_lengths,
    cond1_extra,
    condition_equations,
    condition_residuals,
    conditions_hold,
    eq15_jacobian,
    reference_jacobian,
    reorder_eq24,
)
from ._general import (
    BASE_KINDS,
    JACOBIAN_KINDS,
    JACOBIAN_SYNONYMS,
    RANK_TOL,
    BaseKind,
    SingularityAnalysis,
    TaskJacobianKind,
    _check_base,  # noqa: F401
    _rng,  # noqa: F401
    analyse_singularity,
    jacobian_kind,
    singularity_of_jacobian,
    task_jacobian,
)
from ._search import (
    _FD_STEP,  # noqa: F401
    SEARCH_TOL,
    SingularFamily,
    SingularitySearch,
    _project,  # noqa: F401
    _sigma_min,  # noqa: F401
    _sigma_min_and_gradient,  # noqa: F401
    cluster_singularities,
    find_singularities,
)
from ._verify import (
    Completeness,
    ConditionCheck,
    ConditionVerification,
    sample_condition,
    verify_conditions,
)

__all__ = [
    "BASE_KINDS",
    "CONDITIONS",
    "CONDITION_TOL",
    "EQ24_COLS",
    "EQ24_ROWS",
    "EQ24_ROW_NAMES",
    "JACOBIAN_KINDS",
    "JACOBIAN_SYNONYMS",
    "RANK_TOL",
    "REFINED_CONDITIONS",
    "SEARCH_TOL",
    "ArmLengths",
    "BaseKind",
    "Completeness",
    "ConditionCheck",
    "ConditionVerification",
    "Eq24Partition",
    "SingularFamily",
    "SingularityAnalysis",
    "SingularitySearch",
    "TaskJacobianKind",
    "analyse_singularity",
    "analytic_directions",
    "arm_lengths",
    "cluster_singularities",
    "cond1_extra",
    "condition_equations",
    "condition_residuals",
    "conditions_hold",
    "eq15_jacobian",
    "find_singularities",
    "jacobian_kind",
    "reference_jacobian",
    "reorder_eq24",
    "sample_condition",
    "singularity_of_jacobian",
    "task_jacobian",
    "verify_conditions",
]
