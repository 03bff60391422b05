"""Objective (entropy) weights of criteria over a sample set (000 eqs. 13-16; see
:mod:`jointlock.analysis.ability`)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from ...errors import ConfigurationError
from ...model import FloatArray


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
