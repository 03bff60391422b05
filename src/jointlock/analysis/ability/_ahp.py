"""Subjective (AHP) weights of a judgment matrix with its consistency test (000 §3.1.3,
eqs. 10-12, Tables 4-5), and 000's judgment matrix and RI table (from
:mod:`jointlock.papers.p000`)."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike

from ...errors import ScenarioError
from ...model import FloatArray
from ...papers import p000

#: 000 eq. (39): the judgment matrix of §5.1 (:data:`jointlock.papers.p000.JUDGMENT`).
#: Rows/columns are ``(s, w, kappa)`` under the ``"text"`` reading and ``(s, kappa, w)`` under
#: the ``"equation"`` reading.
PAPER_JUDGMENT: FloatArray = np.array(p000.JUDGMENT, dtype=float)
PAPER_JUDGMENT.setflags(write=False)

#: Random consistency index RI by matrix order N, as printed in 000 Table 5
#: (:data:`jointlock.papers.p000.RANDOM_INDEX`).
PAPER_RI: Mapping[int, float] = dict(p000.RANDOM_INDEX)
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
#: Consistency ratio at and above which a judgment matrix is refused (000 §3.1.3 step 3,
#: :data:`jointlock.papers.p000.CR_LIMIT`).
CR_LIMIT = p000.CR_LIMIT
#: Relative tolerance on the reciprocity ``r_ji = 1 / r_ij`` of a judgment matrix [-].
RECIPROCITY_RTOL = 1e-6

RITable = Literal["paper", "saaty"]


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
