"""Kinematic ability of an arm (seed 000 §3.1.2-3.1.3): the three unilateral indices, their
standardisation, AHP and entropy weights, and the combined index CP.

The three indices (000 Table 3), computed from the singular values ``sigma_1 >= ... >= sigma_m``
of a Jacobian (the locked joint's column already removed, i.e. the Jacobian of the locked
model):

* minimum singular value ``s = sigma_m``  (bigger is better),
* condition number ``kappa = sigma_1 / sigma_m``  (smaller is better, ``kappa >= 1``),
* manipulability ``w = sigma_1 sigma_2 ... sigma_m``  (bigger is better).

**Units.**  A 6 x k Jacobian mixes m/s (rows 0-2) and rad/s (rows 3-5), so its singular values
mix units.  000 uses the raw matrix and so do we by default; pass a characteristic length
``L`` [m] to divide the linear rows by ``L`` (all rows then in rad/s per rad/s) — see
``docs/conventions.md``.

**Index order.**  Everywhere in this module index vectors are in the *canonical order*
:data:`INDEX_NAMES` = ``(sigma_min, condition_number, manipulability)``, the order of eq. (19)
(``s_hat, kappa_hat, w_hat``).

**The paper's two ambiguities** (SPEC, "Known problems in the seeds"):

1. *Which index receives which AHP weight.*  Eq. (12) and §5.1 say the AHP vector of the
   judgment matrix eq. (39), ``(1/4, 1/2, 1/4)``, holds the weights of ``(s_hat, w_hat,
   kappa_hat)`` — manipulability gets 1/2.  Eq. (19) multiplies ``omega_C2 = omega_CR2 +
   omega_CP2`` with ``kappa_hat`` — the condition number gets 1/2.  ``assignment="text"``
   reads the AHP vector in the order ``(s, w, kappa)``; ``assignment="equation"`` in the order
   ``(s, kappa, w)``.  Entropy weights always belong to their own index.
2. *Whether the combined weights are renormalised.*  Eq. (18) adds the AHP and the entropy
   weights, so they sum to 2 and CP lies in ``[0, 2]``; ``renormalize=True`` halves them
   (sum 1, CP in ``[0, 1]``).  The ranking of configurations is the same either way; only the
   CP values differ by the factor 2.

Defaults: ``assignment="equation"`` and ``renormalize=False`` — the combination exactly as
eqs. (18)-(19) print it, the formula that defines CP.  No reading reproduces the paper's
figures (``docs/halt-config.md``), so the tie-break is the one published value they imply:
the paper's arithmetic ``(1 - 0.2969) / 0.2969`` takes ``CP(q_best) = 1``.  That is out of
reach with renormalised weights (CP = 1 would need ``kappa = 1`` together with the
sample-set maxima of ``s`` and ``w``; the best of 36000 samples on ``halt7`` scores 0.59-0.77),
and of the two un-renormalised readings, ``"equation"`` puts the best sample nearest to 1
(1.18 fixed base, 1.33 free-floating, against 1.42 and 1.52 for ``"text"``).  The ``"text"``
reading (eq. 12 and the sentence of §5.1, "the subjective weights of s_hat, w_hat and
kappa_hat are 1/4, 1/2 and 1/4") is one argument away.

Other choices the paper leaves open, fixed here and documented where they are made: the
entropy of eq. (13)-(14) is taken over the *standardised* indices (the values that enter
eq. 19), with ``ln K`` as the normaliser of eq. (14) (printed as ``ln sum(h)``).

Modules (private; every name, private ones included, is re-exported here): ``_indices`` (the
three indices of a batch of Jacobians or of an arm's configurations, and their
standardisation), ``_ahp`` (AHP weights of a judgment matrix, 000's judgment matrix and RI
table), ``_entropy`` (entropy weights) and ``_combined`` (the combined weights, CP and the
fitted :class:`AbilityModel`).
"""

from __future__ import annotations

# Private names (marked F401) are re-exported too: code written before the split imports them
# from here.
from ._ahp import (  # noqa: F401
    CR_LIMIT,
    PAPER_JUDGMENT,
    PAPER_RI,
    RECIPROCITY_RTOL,
    SAATY_RI,
    AHPResult,
    RITable,
    _format_matrix,
    ahp_weights,
)
from ._combined import (  # noqa: F401
    AbilityModel,
    Assignment,
    _flatten,
    ahp_to_canonical,
    combine_weights,
    combined_index,
    fit_ability_model,
)
from ._entropy import EntropyResult, entropy_weights
from ._indices import (  # noqa: F401
    DEFAULT_BATCH,
    GRAM_CONDITION_LIMIT,
    INDEX_NAMES,
    JacobianKind,
    KinematicIndices,
    Normalization,
    StandardizedIndices,
    _minmax,
    configuration_indices,
    kinematic_indices,
    scale_linear_rows,
    singular_values,
    standardize,
)

__all__ = [
    "CR_LIMIT",
    "DEFAULT_BATCH",
    "GRAM_CONDITION_LIMIT",
    "INDEX_NAMES",
    "PAPER_JUDGMENT",
    "PAPER_RI",
    "RECIPROCITY_RTOL",
    "SAATY_RI",
    "AHPResult",
    "AbilityModel",
    "Assignment",
    "EntropyResult",
    "JacobianKind",
    "KinematicIndices",
    "Normalization",
    "RITable",
    "StandardizedIndices",
    "ahp_to_canonical",
    "ahp_weights",
    "combine_weights",
    "combined_index",
    "configuration_indices",
    "entropy_weights",
    "fit_ability_model",
    "kinematic_indices",
    "scale_linear_rows",
    "singular_values",
    "standardize",
]
