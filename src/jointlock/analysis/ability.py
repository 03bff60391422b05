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
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike

from ..errors import ConfigurationError, ScenarioError
from ..model import ArmModel, FloatArray
from ..progress import Progress

#: Names of the three unilateral indices, in the canonical order used by every vector here.
INDEX_NAMES: tuple[str, str, str] = ("sigma_min", "condition_number", "manipulability")

#: 000 eq. (39): the judgment matrix of §5.1.  Rows/columns are ``(s, w, kappa)`` under the
#: ``"text"`` reading and ``(s, kappa, w)`` under the ``"equation"`` reading.
PAPER_JUDGMENT: FloatArray = np.array([[1.0, 0.5, 1.0], [2.0, 1.0, 2.0], [1.0, 0.5, 1.0]])
PAPER_JUDGMENT.setflags(write=False)

#: Random consistency index RI by matrix order N, as printed in 000 Table 5.
PAPER_RI: Mapping[int, float] = {1: 0.0, 2: 0.0, 3: 0.52, 4: 0.89, 5: 1.12, 6: 1.24}
#: Saaty's random consistency index (The Analytic Hierarchy Process, 1980).
SAATY_RI: Mapping[int, float] = {
    1: 0.0,
    2: 0.0,
    3: 0.58,
    4: 0.90,
    5: 1.12,
    6: 1.24,
    7: 1.32,
    8: 1.41,
    9: 1.45,
    10: 1.49,
}
#: Consistency ratio at and above which a judgment matrix is refused (000 §3.1.3 step 3).
CR_LIMIT = 0.10
#: Relative tolerance on the reciprocity ``r_ji = 1 / r_ij`` of a judgment matrix [-].
RECIPROCITY_RTOL = 1e-6

Assignment = Literal["text", "equation"]
RITable = Literal["paper", "saaty"]


# -- the three indices ----------------------------------------------------------------------


@dataclass(frozen=True)
class KinematicIndices:
    """The unilateral kinematic-ability indices of 000 Table 3 for a batch of Jacobians.

    Attributes
    ----------
    sigma_min
        (...) minimum singular value ``s`` [units of the Jacobian].
    condition_number
        (...) ``kappa = sigma_max / sigma_min`` [-]; ``inf`` where ``sigma_min = 0``.
    manipulability
        (...) ``w`` = product of all singular values.
    inverse_condition
        (...) ``1 / kappa = sigma_min / sigma_max`` in ``[0, 1]`` (0 at a singularity), the
        standardised condition number of 000 eq. (9).
    """

    sigma_min: FloatArray
    condition_number: FloatArray
    manipulability: FloatArray
    inverse_condition: FloatArray

    def __getitem__(self, key) -> KinematicIndices:
        return KinematicIndices(
            self.sigma_min[key],
            self.condition_number[key],
            self.manipulability[key],
            self.inverse_condition[key],
        )

    def as_dict(self) -> dict[str, FloatArray]:
        """``{index name: values}`` in :data:`INDEX_NAMES` order."""
        return {
            "sigma_min": self.sigma_min,
            "condition_number": self.condition_number,
            "manipulability": self.manipulability,
        }


def scale_linear_rows(jac: ArrayLike, characteristic_length: float) -> FloatArray:
    """Divide the linear-velocity rows (0-2) of a (..., 6, k) Jacobian by a length ``L`` [m].

    The result maps joint rates [rad/s] to ``(v / L, omega)``, all in [1/s], so that singular
    values no longer mix m/s and rad/s.
    """
    jac = np.asarray(jac, dtype=float)
    length = float(characteristic_length)
    if not (math.isfinite(length) and length > 0):
        raise ConfigurationError(f"characteristic_length must be a finite length > 0 [m]; got {length}")
    if jac.ndim < 2 or jac.shape[-2] != 6:
        raise ConfigurationError(
            f"jacobian must have shape (..., 6, k) to scale its linear rows; got {jac.shape}"
        )
    out = jac.copy()
    out[..., :3, :] /= length
    return out


#: Above this condition number :func:`singular_values` with ``method="auto"`` falls back to
#: the SVD: the Gram route's relative error on ``sigma_i`` is ~ eps * kappa_i^2 / 2, i.e.
#: below 1.2e-8 up to here.
GRAM_CONDITION_LIMIT = 1e4


def singular_values(jac: ArrayLike, *, method: Literal["svd", "gram", "auto"] = "svd") -> FloatArray:
    """Singular values of a batch of matrices, descending.

    Parameters
    ----------
    jac
        (..., m, k) matrices.
    method
        ``"svd"``: LAPACK's batched SVD, exact to round-off.  ``"gram"``: square roots of the
        eigenvalues of the smaller Gram matrix (about twice as fast on 6 x 6 batches; relative
        error ~ eps * kappa_i^2 / 2 on ``sigma_i``).  ``"auto"``: ``"gram"`` with the SVD redone
        for the matrices whose condition number exceeds :data:`GRAM_CONDITION_LIMIT`, so the
        relative error stays below ~1.2e-8 for every matrix.

    Returns
    -------
    (..., min(m, k)) singular values.
    """
    arr = np.asarray(jac, dtype=float)
    if method == "svd":
        return np.linalg.svd(arr, compute_uv=False)
    if method not in ("gram", "auto"):
        raise ConfigurationError(f"method must be 'svd', 'gram' or 'auto'; got {method!r}")
    jt = np.swapaxes(arr, -1, -2)
    gram = jt @ arr if arr.shape[-1] <= arr.shape[-2] else arr @ jt
    sv = np.sqrt(np.clip(np.linalg.eigvalsh(gram), 0.0, None))[..., ::-1]
    if method == "auto":
        bad = sv[..., -1] * GRAM_CONDITION_LIMIT < sv[..., 0]
        if np.any(bad):
            sv[bad] = np.linalg.svd(arr[bad], compute_uv=False)
    return sv


def kinematic_indices(
    jac: ArrayLike,
    *,
    characteristic_length: float | None = None,
    method: Literal["svd", "gram", "auto"] = "svd",
) -> KinematicIndices:
    """Minimum singular value, condition number and manipulability (000 Table 3, eqs. 6-7).

    Parameters
    ----------
    jac
        (..., m, k) Jacobians, any leading batch shape; for an arm with a locked joint, the
        Jacobian of the locked model (000's ``J~_F``, or the fixed-base ``J~``), twist order
        ``(v [m/s], omega [rad/s])`` when ``m = 6``.
    characteristic_length
        ``L`` [m]: divide the linear rows by ``L`` first (``m`` must be 6).  ``None`` (default,
        as 000): the raw matrix.
    method
        ``"svd"`` (default): batched singular value decomposition, exact to round-off.
        ``"gram"``: square roots of the eigenvalues of the smaller Gram matrix (``J^T J`` or
        ``J J^T``), about 1.5x faster on 6 x 6 batches; absolute error of ``sigma_min`` about
        ``eps sigma_max^2 / sigma_min`` (1e-8 at ``sigma_min = 1e-6``, ``sigma_max = 10``),
        harmless for ranking samples.  Negative round-off eigenvalues are clipped to 0.
        ``"auto"``: ``"gram"``, with the SVD redone where the condition number exceeds
        :data:`GRAM_CONDITION_LIMIT` (see :func:`singular_values`).

    Returns
    -------
    KinematicIndices
        Arrays of shape (...).  The singular values are the ``min(m, k)`` values of the
        batched SVD; ``w`` is their product (``sqrt(det(J J^T))`` when ``k >= m``).
    """
    arr = np.asarray(jac, dtype=float)
    if arr.ndim < 2 or 0 in arr.shape[-2:]:
        raise ConfigurationError(f"jacobian must have shape (..., m, k) with m, k >= 1; got {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ConfigurationError("jacobian must be finite; got NaN or inf entries")
    if characteristic_length is not None:
        arr = scale_linear_rows(arr, characteristic_length)
    sv = singular_values(arr, method=method)
    smax = sv[..., 0]
    smin = sv[..., -1]
    positive = smin > 0
    kappa = np.divide(smax, smin, out=np.full(smin.shape, np.inf), where=positive)
    inv_kappa = np.divide(smin, smax, out=np.zeros(smin.shape), where=smax > 0)
    return KinematicIndices(smin, kappa, np.prod(sv, axis=-1), inv_kappa)


# -- standardisation (000 eqs. 8-9) -----------------------------------------------------------


@dataclass(frozen=True)
class Normalization:
    """Min-max bounds of 000 eq. (8), frozen from a sample set.

    Attributes
    ----------
    sigma_min_range
        ``(a, b)``: min and max of ``s`` over the sample set.
    manipulability_range
        ``(a, b)``: min and max of ``w`` over the sample set.
    """

    sigma_min_range: tuple[float, float]
    manipulability_range: tuple[float, float]

    @classmethod
    def from_samples(cls, indices: KinematicIndices) -> Normalization:
        """Bounds over every sample of ``indices`` (any shape, at least one sample)."""
        s = np.asarray(indices.sigma_min).ravel()
        w = np.asarray(indices.manipulability).ravel()
        if s.size == 0:
            raise ConfigurationError("the sample set for min-max standardisation is empty")
        return cls((float(s.min()), float(s.max())), (float(w.min()), float(w.max())))


@dataclass(frozen=True)
class StandardizedIndices:
    """Standardised indices (000 eqs. 8-9), each (...), bigger is better.

    Attributes
    ----------
    s_hat
        ``(s - a) / (b - a)``: in ``[0, 1]`` over the sample set that fixed the bounds.
    kappa_hat
        ``1 / kappa`` in ``[0, 1]`` (eq. 9; not min-max standardised, as 000 writes it).
    w_hat
        ``(w - a) / (b - a)``.
    """

    s_hat: FloatArray
    kappa_hat: FloatArray
    w_hat: FloatArray

    def stacked(self) -> FloatArray:
        """(..., 3) in canonical order ``(s_hat, kappa_hat, w_hat)``."""
        return np.stack([self.s_hat, self.kappa_hat, self.w_hat], axis=-1)


def _minmax(x: FloatArray, bounds: tuple[float, float]) -> FloatArray:
    a, b = bounds
    span = b - a
    if span <= 0:  # constant over the sample set: carries no information
        return np.zeros(np.shape(x))
    return (x - a) / span


def standardize(indices: KinematicIndices, normalization: Normalization | None = None) -> StandardizedIndices:
    """Standardise the indices as 000 eqs. (8)-(9) write them.

    Parameters
    ----------
    indices
        Indices of shape (...).
    normalization
        Min-max bounds; ``None`` takes them from ``indices`` itself (the sample set).  Values
        outside the frozen bounds map outside ``[0, 1]`` (used by the refinement).
    """
    norm = Normalization.from_samples(indices) if normalization is None else normalization
    return StandardizedIndices(
        _minmax(np.asarray(indices.sigma_min), norm.sigma_min_range),
        np.asarray(indices.inverse_condition),
        _minmax(np.asarray(indices.manipulability), norm.manipulability_range),
    )


# -- AHP (000 eqs. 10-12, Tables 4-5) ---------------------------------------------------------


@dataclass(frozen=True)
class AHPResult:
    """Subjective (AHP) weights of a judgment matrix.

    Attributes
    ----------
    weights
        (N,) principal eigenvector normalised to sum 1, in the matrix's row order.
    lambda_max
        Principal eigenvalue.
    ci
        Consistency index ``(lambda_max - N) / (N - 1)`` (eq. 10); 0 for ``N = 1``.
    cr
        Consistency ratio ``CI / RI`` (eq. 11); 0 where ``RI = 0`` (``N <= 2``).
    ri
        The random index used.
    matrix
        (N, N) the judgment matrix.
    """

    weights: FloatArray
    lambda_max: float
    ci: float
    cr: float
    ri: float
    matrix: FloatArray


def _format_matrix(m: FloatArray) -> str:
    return "[" + "; ".join(" ".join(f"{v:.4g}" for v in row) for row in m) + "]"


def ahp_weights(
    matrix: ArrayLike,
    *,
    ri: RITable | Mapping[int, float] = "paper",
    cr_limit: float = CR_LIMIT,
) -> AHPResult:
    """AHP weights of a pairwise-comparison (judgment) matrix (000 §3.1.3 steps 2-4).

    Parameters
    ----------
    matrix
        (N, N) positive reciprocal matrix: ``r_ii = 1``, ``r_ji = 1 / r_ij`` (000 Table 4).
    ri
        Random consistency index table: ``"paper"`` (000 Table 5, N <= 6, default),
        ``"saaty"`` (Saaty 1980, N <= 10), or a mapping ``{N: RI}``.
    cr_limit
        The matrix is refused when ``CR >= cr_limit`` (000: 0.10).

    Returns
    -------
    AHPResult
        Principal eigenvector (summing to 1), ``lambda_max``, CI, CR.

    Raises
    ------
    ScenarioError
        Not square, not positive and finite, not reciprocal, N missing from the RI table, or
        ``CR >= cr_limit``; the message shows the matrix.
    """
    m = np.asarray(matrix, dtype=float)
    if m.ndim != 2 or m.shape[0] != m.shape[1] or m.shape[0] == 0:
        raise ScenarioError(f"judgment matrix must be square (N, N) with N >= 1; got shape {m.shape}")
    if not np.all(np.isfinite(m)) or np.any(m <= 0):
        raise ScenarioError(f"judgment matrix entries must be finite and > 0; got {_format_matrix(m)}")
    if not np.allclose(m * m.T, 1.0, rtol=RECIPROCITY_RTOL, atol=0):
        raise ScenarioError(
            "judgment matrix must be reciprocal (r_ii = 1, r_ji = 1/r_ij, 000 Table 4); "
            f"got {_format_matrix(m)}"
        )
    n = m.shape[0]
    if isinstance(ri, str):
        tables = {"paper": PAPER_RI, "saaty": SAATY_RI}
        if ri not in tables:
            raise ScenarioError(f"ri must be 'paper', 'saaty' or a mapping {{N: RI}}; got {ri!r}")
        table = tables[ri]
    else:
        table = ri
    if n not in table:
        raise ScenarioError(
            f"the RI table has no entry for a judgment matrix of order N = {n}; "
            f"it covers N in {sorted(table)} (use ri='saaty' for N <= 10 or pass a mapping)"
        )
    ri_value = float(table[n])
    eigval, eigvec = np.linalg.eig(m)
    k = int(np.argmax(eigval.real))
    lam = float(eigval[k].real)
    vec = np.abs(eigvec[:, k].real)  # Perron vector: one sign, positive
    weights = vec / vec.sum()
    ci = (lam - n) / (n - 1) if n > 1 else 0.0
    ci = max(ci, 0.0) if abs(ci) < 1e-12 else ci  # round-off on consistent matrices
    cr = ci / ri_value if ri_value > 0 else 0.0
    if cr >= cr_limit:
        raise ScenarioError(
            f"judgment matrix is not consistent enough: CR = {cr:.4f} >= {cr_limit} "
            f"(lambda_max = {lam:.4f}, CI = {ci:.4f}, RI = {ri_value}); revise r_ij in "
            f"{_format_matrix(m)}"
        )
    weights.setflags(write=False)
    m = m.copy()
    m.setflags(write=False)
    return AHPResult(weights, lam, float(ci), float(cr), ri_value, m)


# -- entropy weights (000 eqs. 13-17) ---------------------------------------------------------


@dataclass(frozen=True)
class EntropyResult:
    """Objective (entropy) weights over a sample set.

    Attributes
    ----------
    weights
        (m,) ``g_h / sum g`` (eq. 16); equal weights when every ``g_h = 0``.
    entropy
        (m,) ``e_h`` in ``[0, 1]`` (eq. 14).
    divergence
        (m,) ``g_h = 1 - e_h`` (eq. 15).
    samples
        ``K``, the number of samples.
    """

    weights: FloatArray
    entropy: FloatArray
    divergence: FloatArray
    samples: int


def entropy_weights(values: ArrayLike) -> EntropyResult:
    """Entropy weights of m criteria over K samples (000 eqs. 13-16).

    ``P_kh = X_kh / sum_k X_kh``;  ``e_h = -sum_k P_kh ln P_kh / ln K`` (``0 ln 0 = 0``; 000
    prints the normaliser as ``ln sum(h)``, read as ``ln K`` so that ``0 <= e_h <= 1``);
    ``g_h = 1 - e_h``;  ``w_h = g_h / sum g``.

    Parameters
    ----------
    values
        (K, m) non-negative criterion values, K >= 2 (for HCOM: the standardised indices of
        the sample set, canonical order).  A criterion that is zero on every sample carries no
        information: ``e_h = 1``.

    Returns
    -------
    EntropyResult
    """
    x = np.asarray(values, dtype=float)
    if x.ndim != 2 or x.shape[0] < 2 or x.shape[1] < 1:
        raise ConfigurationError(f"values must have shape (K, m) with K >= 2 samples; got {x.shape}")
    if not np.all(np.isfinite(x)):
        raise ConfigurationError("values must be finite")
    if np.any(x < 0):
        bad = tuple(int(i) for i in np.argwhere(x < 0)[0])
        raise ConfigurationError(
            f"values must be >= 0 for the entropy method (eq. 13); got {x[bad]} at index {bad}"
        )
    k = x.shape[0]
    total = x.sum(axis=0)
    p = np.divide(x, total, out=np.zeros_like(x), where=total > 0)
    plogp = np.where(p > 0, p * np.log(np.where(p > 0, p, 1.0)), 0.0)
    e = np.where(total > 0, -plogp.sum(axis=0) / math.log(k), 1.0)
    e = np.clip(e, 0.0, 1.0)
    g = 1.0 - e
    gsum = g.sum()
    w = g / gsum if gsum > 0 else np.full(g.shape, 1.0 / g.size)
    return EntropyResult(w, e, g, k)


# -- combination and CP (000 eqs. 18-19) ------------------------------------------------------


def ahp_to_canonical(weights: ArrayLike, assignment: Assignment) -> FloatArray:
    """Reorder a 3-vector of AHP weights into the canonical order ``(s, kappa, w)``.

    ``"text"``: the AHP vector is ``(s, w, kappa)`` (000 eq. 12 and §5.1).  ``"equation"``:
    it is ``(s, kappa, w)`` (the index order of 000 eq. 19).
    """
    w = np.asarray(weights, dtype=float)
    if w.shape != (3,):
        raise ConfigurationError(f"AHP weights must be 3 numbers (one per index); got shape {w.shape}")
    if assignment == "text":
        return w[[0, 2, 1]]
    if assignment == "equation":
        return w.copy()
    raise ScenarioError(f"assignment must be 'text' or 'equation'; got {assignment!r}")


def combine_weights(
    ahp: ArrayLike,
    entropy: ArrayLike,
    *,
    assignment: Assignment = "equation",
    renormalize: bool = False,
) -> FloatArray:
    """Combined weights ``omega_C = omega_CR + omega_CP`` (000 eq. 18), canonical order.

    Parameters
    ----------
    ahp
        (3,) AHP weights in the judgment matrix's row order (see :func:`ahp_to_canonical`).
    entropy
        (3,) entropy weights in canonical order.
    assignment
        ``"equation"`` (default) or ``"text"``; see the module docstring.
    renormalize
        Divide by the sum (2) so the weights sum to 1.  Default False, as eq. (18) is printed.

    Returns
    -------
    (3,) weights of ``(s_hat, kappa_hat, w_hat)``.
    """
    ent = np.asarray(entropy, dtype=float)
    if ent.shape != (3,):
        raise ConfigurationError(f"entropy weights must be 3 numbers; got shape {ent.shape}")
    combined = ahp_to_canonical(ahp, assignment) + ent
    if renormalize:
        combined = combined / combined.sum()
    return combined


def combined_index(standardized: StandardizedIndices, weights: ArrayLike) -> FloatArray:
    """CP of 000 eq. (19): ``w_1 s_hat + w_2 kappa_hat + w_3 w_hat``, shape (...).

    ``weights`` is (3,) in canonical order (from :func:`combine_weights`).
    """
    w = np.asarray(weights, dtype=float)
    if w.shape != (3,):
        raise ConfigurationError(f"weights must be 3 numbers (s_hat, kappa_hat, w_hat); got shape {w.shape}")
    return w[0] * standardized.s_hat + w[1] * standardized.kappa_hat + w[2] * standardized.w_hat


@dataclass(frozen=True)
class AbilityModel:
    """CP with its normalisation and weights frozen from a sample set: a function of indices.

    Build it with :func:`fit_ability_model`; call it on any :class:`KinematicIndices` to get
    CP (...).

    Attributes
    ----------
    normalization
        Min-max bounds of ``s`` and ``w`` over the sample set.
    weights
        (3,) combined weights, canonical order.
    ahp
        The AHP result (weights in the judgment matrix's row order).
    entropy
        The entropy result (canonical order) over the sample set.
    assignment, renormalize
        The readings used (see the module docstring).
    """

    normalization: Normalization
    weights: FloatArray
    ahp: AHPResult
    entropy: EntropyResult
    assignment: Assignment = "equation"
    renormalize: bool = False
    ahp_canonical: FloatArray = field(default_factory=lambda: np.zeros(3))

    def standardize(self, indices: KinematicIndices) -> StandardizedIndices:
        """Standardise with the frozen bounds."""
        return standardize(indices, self.normalization)

    def __call__(self, indices: KinematicIndices) -> FloatArray:
        """CP (...) of ``indices`` with the frozen normalisation and weights."""
        return combined_index(self.standardize(indices), self.weights)

    def weights_dict(self) -> dict[str, dict[str, float]]:
        """``{"ahp" | "entropy" | "combined": {index name: weight}}``."""
        return {
            "ahp": dict(zip(INDEX_NAMES, map(float, self.ahp_canonical))),
            "entropy": dict(zip(INDEX_NAMES, map(float, self.entropy.weights))),
            "combined": dict(zip(INDEX_NAMES, map(float, self.weights))),
        }


def fit_ability_model(
    indices: KinematicIndices,
    *,
    judgment: ArrayLike = PAPER_JUDGMENT,
    assignment: Assignment = "equation",
    renormalize: bool = False,
    ri: RITable | Mapping[int, float] = "paper",
) -> AbilityModel:
    """Fix the normalisation and the weights of CP from a sample set (000 §3.1.2-3.1.3).

    Parameters
    ----------
    indices
        Indices of the K sample configurations (any shape, flattened; K >= 2).
    judgment
        (3, 3) AHP judgment matrix; default 000 eq. (39).  Its row order is ``(s, w, kappa)``
        under ``assignment="text"`` and ``(s, kappa, w)`` under ``"equation"``.
    assignment, renormalize
        The readings of 000's ambiguities (module docstring); defaults ``"equation"``, False.
    ri
        RI table for the consistency test (:func:`ahp_weights`).

    Returns
    -------
    AbilityModel
    """
    ahp = ahp_weights(judgment, ri=ri)
    if ahp.weights.shape != (3,):
        raise ScenarioError(
            f"judgment matrix must be 3 x 3 (one row per index); got {ahp.matrix.shape[0]} x "
            f"{ahp.matrix.shape[0]}"
        )
    flat = indices[...] if np.ndim(indices.sigma_min) == 1 else _flatten(indices)
    norm = Normalization.from_samples(flat)
    std = standardize(flat, norm)
    ent = entropy_weights(std.stacked())
    weights = combine_weights(ahp.weights, ent.weights, assignment=assignment, renormalize=renormalize)
    for arr in (weights,):
        arr.setflags(write=False)
    return AbilityModel(
        normalization=norm,
        weights=weights,
        ahp=ahp,
        entropy=ent,
        assignment=assignment,
        renormalize=bool(renormalize),
        ahp_canonical=ahp_to_canonical(ahp.weights, assignment),
    )


def _flatten(indices: KinematicIndices) -> KinematicIndices:
    return KinematicIndices(
        np.ravel(indices.sigma_min),
        np.ravel(indices.condition_number),
        np.ravel(indices.manipulability),
        np.ravel(indices.inverse_condition),
    )


# -- indices of an arm over configurations ----------------------------------------------------

JacobianKind = Literal["generalized", "fixed"]

#: Configurations evaluated per batched call (keeps the temporaries in cache; ~4 MB each).
DEFAULT_BATCH = 4096


def configuration_indices(
    model: ArmModel,
    q: ArrayLike,
    *,
    jacobian: JacobianKind = "generalized",
    characteristic_length: float | None = None,
    method: Literal["svd", "gram"] = "svd",
    batch_size: int = DEFAULT_BATCH,
    progress: Progress | None = None,
) -> KinematicIndices:
    """Kinematic-ability indices of an arm at a batch of configurations.

    Parameters
    ----------
    model
        The arm (for 000: the locked model, so the locked joint's column is already gone).
    q
        (..., n) angles of the model's movable joints [rad].
    jacobian
        ``"generalized"``: the free-floating generalized Jacobian ``J_F`` with zero momentum
        (000 eq. 5, what 000 §3.1.2 analyses); for a fixed-base model it *is* the fixed-base
        Jacobian (infinite base mass).  ``"fixed"``: the geometric Jacobian with the base held.
        Both: end-effector origin, root-frame components, twist order ``(v, omega)``.
    characteristic_length, method
        See :func:`kinematic_indices`.
    batch_size
        Configurations per batched call (memory/cache only; results do not depend on it).
    progress
        Optional :class:`~jointlock.progress.Progress`, advanced by the number of
        configurations done.

    Returns
    -------
    KinematicIndices
        Arrays of shape (...).
    """
    from ..kinematics import generalized_jacobian
    from ..kinematics import jacobian as fixed_jacobian
    from ..model import as_joint_array

    if jacobian not in ("generalized", "fixed"):
        raise ConfigurationError(f"jacobian must be 'generalized' or 'fixed'; got {jacobian!r}")
    if int(batch_size) < 1:
        raise ConfigurationError(f"batch_size must be >= 1; got {batch_size!r}")
    arr = as_joint_array(model, q)
    batch = arr.shape[:-1]
    flat = arr.reshape(-1, model.dof)
    jac_fn = generalized_jacobian if jacobian == "generalized" else fixed_jacobian
    parts = []
    step = int(batch_size)
    for start in range(0, flat.shape[0], step):  # chunks of the batch, not single samples
        chunk = flat[start : start + step]
        parts.append(
            kinematic_indices(
                jac_fn(model, chunk), characteristic_length=characteristic_length, method=method
            )
        )
        if progress is not None:
            progress.update(chunk.shape[0])
    if not parts:
        empty = np.zeros(batch)
        return KinematicIndices(empty, empty.copy(), empty.copy(), empty.copy())

    def join(name: str) -> FloatArray:
        return np.concatenate([getattr(p, name) for p in parts]).reshape(batch)

    return KinematicIndices(
        join("sigma_min"), join("condition_number"), join("manipulability"), join("inverse_condition")
    )
