"""Polynomial pieces of kappa(t): least-squares pieces, breaks, segment points."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import cast

import numpy as np
from numpy.typing import ArrayLike

from ...model import FloatArray

# -- kappa(t) -------------------------------------------------------------------------------


@dataclass(frozen=True)
class KappaPiece:
    """One polynomial piece of a piecewise kappa(t).

    ``kappa(t) = p((t - center) / half_width)`` for ``start <= t < end`` (coefficients
    ascending; the local variable keeps high orders on short pieces well conditioned).

    Attributes
    ----------
    start, end
        Time span where the piece applies [s] (kappa = 0 in gaps between pieces).
    order
        Polynomial order (raised from the requested one until the criterion holds).
    coefficients
        (order + 1,) ascending powers of the local variable.
    center, half_width
        Normalisation of the local variable [s].
    ssr, threshold, accepted
        Residual over the samples used, its threshold and ``ssr <= threshold``.
    n_samples
        Samples the piece was fitted to.
    source
        ``"fit"`` (fitted to its own segment's samples) or ``"continued"`` (its polynomial
        was carried over the next segment(s), where it beat that segment's own fit).
    """

    start: float
    end: float
    order: int
    coefficients: FloatArray
    center: float
    half_width: float
    ssr: float
    threshold: float
    accepted: bool
    n_samples: int
    source: str = "fit"

    def polynomial(self, t: ArrayLike) -> FloatArray:
        """The piece's polynomial at ``t`` [s] (no span check)."""
        u = (np.asarray(t, dtype=float) - self.center) / self.half_width
        return cast(FloatArray, np.polynomial.polynomial.polyval(u, self.coefficients))



def _eval_pieces(pieces: Sequence[KappaPiece], t: FloatArray, duration: float) -> FloatArray:
    out = np.zeros_like(np.asarray(t, dtype=float))
    for pc in pieces:
        inside = (t >= pc.start) & ((t < pc.end) | ((pc.end >= duration) & (t <= pc.end)))
        out = np.where(inside, pc.polynomial(t), out)
    return out


def _polyfit(t: FloatArray, k: FloatArray, order: int, max_order: int, threshold: float | None, rtol: float):
    spread = float(np.sum((k - k.mean()) ** 2))
    thr = threshold if threshold is not None else rtol * max(spread, 1e-300)
    order = min(order, t.size - 1)
    while True:
        coef = np.polynomial.polynomial.polyfit(t, k, order)
        ssr = float(np.sum((np.polynomial.polynomial.polyval(t, coef) - k) ** 2))
        if ssr <= thr or order >= min(max_order, t.size - 1):
            return order, coef, ssr, thr, ssr <= thr
        order += 1


def _crossings(t: FloatArray, d: FloatArray, usable: np.ndarray, duration: float) -> FloatArray:
    """Segment points from d_i = obj(p(t_i)) - obj(0): first/last zero crossing into d < 0."""
    good = np.flatnonzero((d < 0) & usable)
    if good.size == 0:
        return np.array([np.nan, np.nan])
    i1, i2 = good[0], good[-1]
    if i1 == 0:
        t1 = 0.0
    else:
        a, b = d[i1 - 1], d[i1]
        t1 = t[i1 - 1] + (t[i1] - t[i1 - 1]) * (a / (a - b)) if np.isfinite(a) and a > 0 else t[i1]
    if i2 == t.size - 1:
        t2 = duration
    else:
        a, b = d[i2], d[i2 + 1]
        t2 = t[i2] + (t[i2 + 1] - t[i2]) * (a / (a - b)) if np.isfinite(b) and b > 0 else t[i2]
    return np.array([t1, t2])


def find_breaks(
    kappa: ArrayLike, width: float, *, jump_rtol: float = 0.1, jump_factor: float = 10.0
) -> np.ndarray:
    """Indices ``i`` such that samples ``i`` and ``i + 1`` lie on different branches.

    A jump between consecutive samples is a break when ``|kappa_{i+1} - kappa_i|`` exceeds
    both ``jump_rtol * width`` (``width``: the searched kappa range, e.g. the feasible band)
    and ``jump_factor`` times the median step between consecutive samples (what a smooth
    kappa(t) moves from one sample to the next).
    """
    k = np.asarray(kappa, dtype=float)
    if k.size < 2:
        return np.zeros(0, dtype=int)
    d = np.abs(np.diff(k))
    return np.flatnonzero((d > jump_rtol * width) & (d > jump_factor * np.median(d)))


def fit_pieces(
    t: ArrayLike,
    kappa: ArrayLike,
    cuts: ArrayLike = (),
    *,
    order: int = 5,
    max_order: int = 9,
    threshold: float | None = None,
    rtol: float = 0.1,
    span: tuple[float, float] | None = None,
) -> list[KappaPiece]:
    """Least-squares polynomial per segment of samples ``(t_i, kappa_i)`` (sorted by ``t``).

    ``cuts`` are sample indices ``i`` after which a new segment starts (e.g. from
    :func:`find_breaks`).  Each segment is fitted on its own (order raised from ``order`` up to
    ``max_order`` -- and at most samples - 1 -- until ``SSR <= threshold``, default
    ``rtol`` times the segment's spread ``sum (kappa_i - mean)^2``).  Adjacent pieces meet
    half-way between the last sample of one segment and the first of the next; the first
    starts at ``span[0]`` and the last ends at ``span[1]`` (default: the first / last sample).
    """
    t = np.asarray(t, dtype=float)
    k = np.asarray(kappa, dtype=float)
    if t.size == 0:
        return []
    lo, hi = (float(t[0]), float(t[-1])) if span is None else (float(span[0]), float(span[1]))
    bounds = [0] + [int(c) + 1 for c in np.unique(np.asarray(cuts, dtype=int))] + [t.size]
    pieces = []
    for s in range(len(bounds) - 1):
        ts, ks = t[bounds[s] : bounds[s + 1]], k[bounds[s] : bounds[s + 1]]
        start = lo if s == 0 else 0.5 * (t[bounds[s] - 1] + ts[0])
        end = hi if s == len(bounds) - 2 else 0.5 * (ts[-1] + t[bounds[s + 1]])
        center = 0.5 * (ts[0] + ts[-1])
        half = max(0.5 * (ts[-1] - ts[0]), 1e-9)
        ordr, coef, ssr, thr, acc = _polyfit((ts - center) / half, ks, order, max_order, threshold, rtol)
        pieces.append(
            KappaPiece(
                float(start), float(end), int(ordr), coef, center, half, ssr, float(thr), bool(acc), ts.size
            )
        )
    return pieces
