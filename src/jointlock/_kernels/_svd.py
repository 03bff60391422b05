"""Singular values by the one-sided (Hestenes) Jacobi method, SIMD across a block of matrices
(see :mod:`jointlock._kernels`)."""

from __future__ import annotations

import math

import numpy as np

from ._common import _EPS, BLOCK, MAX_SWEEPS, _jit


@_jit
def _jacobi_block(a, nb, norms, gam, cosv, sinv, tanv, out, s0):
    """Singular values of the ``nb`` matrices ``a[:, :, :nb]`` (m, k, BLOCK), ``k <= m``, into
    ``out[s0:s0 + nb, :k]``, descending; ``a`` is overwritten (its columns orthogonalised).

    ``norms`` (k, BLOCK) and ``gam``, ``cosv``, ``sinv``, ``tanv`` (BLOCK,) are work arrays."""
    m, k = a.shape[0], a.shape[1]
    tol = m * _EPS
    for _sweep in range(MAX_SWEEPS):
        for j in range(k):  # squared column norms, recomputed each sweep (no drift)
            for b in range(nb):
                norms[j, b] = 0.0
            for r in range(m):
                for b in range(nb):
                    norms[j, b] += a[r, j, b] * a[r, j, b]
        rotated = 0
        for p in range(k - 1):
            for qc in range(p + 1, k):
                for b in range(nb):
                    gam[b] = 0.0
                for r in range(m):
                    for b in range(nb):
                        gam[b] += a[r, p, b] * a[r, qc, b]
                count = 0
                for b in range(nb):
                    g = gam[b]
                    alpha, beta = norms[p, b], norms[qc, b]
                    big = abs(g) > tol * math.sqrt(alpha * beta)
                    # t: the smaller root of t^2 + 2 zeta t - 1 = 0 (Rutishauser's formula)
                    zeta = (beta - alpha) / (2.0 * g)
                    t = math.copysign(1.0, zeta) / (abs(zeta) + math.sqrt(1.0 + zeta * zeta))
                    t = t if big else 0.0
                    c = 1.0 / math.sqrt(1.0 + t * t)
                    cosv[b] = c
                    sinv[b] = c * t
                    tanv[b] = t
                    norms[p, b] = alpha - t * g
                    norms[qc, b] = beta + t * g
                    count += 1 if big else 0
                if count == 0:
                    continue
                rotated += count
                for r in range(m):
                    for b in range(nb):
                        x, y = a[r, p, b], a[r, qc, b]
                        a[r, p, b] = cosv[b] * x - sinv[b] * y
                        a[r, qc, b] = sinv[b] * x + cosv[b] * y
        if rotated == 0:
            break
    for j in range(k):
        for b in range(nb):
            norms[j, b] = 0.0
        for r in range(m):
            for b in range(nb):
                norms[j, b] += a[r, j, b] * a[r, j, b]
    _sorted_roots(norms, nb, out, s0)


@_jit
def _jacobi6_block(a, nb, norms, out, s0):
    """:func:`_jacobi_block` for ``m = 6`` rows (every Jacobian with at most six columns): one
    pass per column pair computes the inner product, the rotation and the rotated columns
    with the twelve entries in registers, SIMD across the block."""
    k = a.shape[1]
    tol2 = (6 * _EPS) ** 2
    for j in range(k):
        for b in range(nb):
            norms[j, b] = (
                a[0, j, b] * a[0, j, b] + a[1, j, b] * a[1, j, b] + a[2, j, b] * a[2, j, b]
                + a[3, j, b] * a[3, j, b] + a[4, j, b] * a[4, j, b] + a[5, j, b] * a[5, j, b]
            )
    for _sweep in range(MAX_SWEEPS):
        rotated = 0
        for p in range(k - 1):
            for qc in range(p + 1, k):
                count = 0
                for b in range(nb):
                    x0, x1, x2 = a[0, p, b], a[1, p, b], a[2, p, b]
                    x3, x4, x5 = a[3, p, b], a[4, p, b], a[5, p, b]
                    y0, y1, y2 = a[0, qc, b], a[1, qc, b], a[2, qc, b]
                    y3, y4, y5 = a[3, qc, b], a[4, qc, b], a[5, qc, b]
                    g = x0 * y0 + x1 * y1 + x2 * y2 + x3 * y3 + x4 * y4 + x5 * y5
                    alpha, beta = norms[p, b], norms[qc, b]
                    big = g * g > tol2 * (alpha * beta)
                    # t = sgn(zeta) / (|zeta| + sqrt(1 + zeta^2)), zeta = d / 2g, without dividing by g
                    d = beta - alpha
                    t = math.copysign(1.0, d) * (2.0 * g) / (abs(d) + math.sqrt(d * d + 4.0 * g * g))
                    t = t if big else 0.0
                    c = 1.0 / math.sqrt(1.0 + t * t)
                    s = c * t
                    u0, u1, u2 = c * x0 - s * y0, c * x1 - s * y1, c * x2 - s * y2
                    u3, u4, u5 = c * x3 - s * y3, c * x4 - s * y4, c * x5 - s * y5
                    v0, v1, v2 = s * x0 + c * y0, s * x1 + c * y1, s * x2 + c * y2
                    v3, v4, v5 = s * x3 + c * y3, s * x4 + c * y4, s * x5 + c * y5
                    a[0, p, b], a[1, p, b], a[2, p, b] = u0, u1, u2
                    a[3, p, b], a[4, p, b], a[5, p, b] = u3, u4, u5
                    a[0, qc, b], a[1, qc, b], a[2, qc, b] = v0, v1, v2
                    a[3, qc, b], a[4, qc, b], a[5, qc, b] = v3, v4, v5
                    # explicit norms, not alpha - t g: that update loses a small column's accuracy
                    norms[p, b] = u0 * u0 + u1 * u1 + u2 * u2 + u3 * u3 + u4 * u4 + u5 * u5
                    norms[qc, b] = v0 * v0 + v1 * v1 + v2 * v2 + v3 * v3 + v4 * v4 + v5 * v5
                    count += 1 if big else 0
                rotated += count
        if rotated == 0:
            break
    _sorted_roots(norms, nb, out, s0)


@_jit
def _sorted_roots(norms, nb, out, s0):
    """``out[s0 + b]`` = square roots of ``norms[:, b]``, descending (insertion sort)."""
    k = norms.shape[0]
    for b in range(nb):
        row = out[s0 + b]
        for j in range(k):
            v = math.sqrt(norms[j, b])
            i = j
            while i > 0 and row[i - 1] < v:
                row[i] = row[i - 1]
                i -= 1
            row[i] = v


@_jit
def _work(m, k):
    """Work arrays of :func:`_jacobi_block` for ``k`` columns."""
    return (
        np.empty((k, BLOCK)),
        np.empty(BLOCK),
        np.empty(BLOCK),
        np.empty(BLOCK),
        np.empty(BLOCK),
    )


@_jit
def singular_values(mats, out):
    """Singular values of ``mats`` (N, m, k) into ``out`` (N, min(m, k)), descending, by
    one-sided Jacobi on the columns (on the rows when ``k > m``)."""
    m0, k0 = mats.shape[1], mats.shape[2]
    tall = k0 <= m0
    m, k = (m0, k0) if tall else (k0, m0)
    a = np.empty((m, k, BLOCK))
    norms, gam, cosv, sinv, tanv = _work(m, k)
    for s0 in range(0, mats.shape[0], BLOCK):
        nb = min(BLOCK, mats.shape[0] - s0)
        for r in range(m):
            for j in range(k):
                for b in range(nb):
                    a[r, j, b] = mats[s0 + b, r, j] if tall else mats[s0 + b, j, r]
        if m == 6:
            _jacobi6_block(a, nb, norms, out, s0)
        else:
            _jacobi_block(a, nb, norms, gam, cosv, sinv, tanv, out, s0)
