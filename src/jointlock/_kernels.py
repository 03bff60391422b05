"""Compiled batch kernels (numba): chain forward kinematics, the fixed-base geometric Jacobian,
singular values by one-sided Jacobi, and end-effector positions.

The numpy implementations (:mod:`jointlock.forward`, :mod:`jointlock.kinematics`,
``np.linalg.svd``) are the reference these kernels are tested against
(``tests/test_kernels.py``); the public functions call the kernels.

Layout.  Configurations are processed in blocks of :data:`BLOCK` with the block as the
innermost (contiguous) axis of every work array ("structure of arrays"), so that each step
is a plain loop over the block that LLVM turns into SIMD code.  Nothing here calls LAPACK
or allocates per configuration.

Chain convention (the one of :func:`jointlock._chain.link_constants` and
:func:`jointlock._chain.position_program`): every link in its ``z``-joint frame; link ``i``
has the constant turn ``E_i`` (3, 3) and offset ``p_i`` (3,) from its parent, then turns by
``Rot(z, q_i)``; the tool point ``t`` (3,) is given in the last link's frame.  Locked
joints are already folded into the constants.

Sines and cosines.  libm's scalar ``sin``/``cos`` cost ~25 ns each and block SIMD, so
:func:`_sincos` evaluates them branch-free: Cody-Waite reduction by ``pi/2`` in three parts
(musl's ``__rem_pio2`` constants; exact for ``|q| <`` :data:`TRIG_LIMIT`) and musl's
``__sin``/``__cos`` minimax polynomials on ``[-pi/4, pi/4]`` (error below 1 ulp).  Angles
beyond :data:`TRIG_LIMIT` (never joint angles in practice) take ``math.sin``/``math.cos``.

Singular values.  :func:`_jacobi_block` is the one-sided (Hestenes) Jacobi method:
columns of ``A`` are rotated pairwise, cyclically, until every pair is orthogonal to
``m * eps`` relative (the stopping rule of LAPACK's ``dgesvj``); the singular values are
then the column norms.  It computes every singular value to high relative accuracy
(Demmel & Veselic, "Jacobi's method is more accurate than QR", SIAM J. Matrix Anal. Appl.
13 (1992) 1204-1245), so in particular to ``~1e-15 * sigma_max`` absolute, as LAPACK's SVD.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

#: Configurations per block: the work arrays of one block stay in L1/L2.
BLOCK = 128
#: Largest |angle| [rad] for the branch-free sine and cosine; beyond, libm's (exact) ones.
TRIG_LIMIT = 1.0e5
#: Cyclic sweeps of the Jacobi method before giving up (LAPACK dgesvj: 30); 6 x 6
#: Jacobians converge in 5-9.
MAX_SWEEPS = 30
_EPS = 2.220446049250313e-16

# cache=True: compiled once per machine (numba cache next to this file or NUMBA_CACHE_DIR);
# error_model="numpy": x / 0 gives inf/nan (masked afterwards) instead of raising
_jit = njit(cache=True, error_model="numpy", nogil=True)

# musl __rem_pio2: 2/pi, and pi/2 split in parts whose products with small integers are exact
_TOINT = 6755399441055744.0  # 1.5 / eps: adding it rounds to an integer
_INVPIO2 = 6.36619772367581382433e-01
_PIO2_1 = 1.57079632673412561417e00
_PIO2_2 = 6.07710050630396597660e-11
_PIO2_2T = 2.02226624879595063154e-21
# musl __sin / __cos minimax coefficients on [-pi/4, pi/4]
_S1 = -1.66666666666666324348e-01
_S2 = 8.33333333332248946124e-03
_S3 = -1.98412698298579493134e-04
_S4 = 2.75573137070700676789e-06
_S5 = -2.50507602534068634195e-08
_S6 = 1.58969099521155010221e-10
_C1 = 4.16666666666666019037e-02
_C2 = -1.38888888888741095749e-03
_C3 = 2.48015872894767294178e-05
_C4 = -2.75573143513906633035e-07
_C5 = 2.08757232129817482790e-09
_C6 = -1.13596475577881948265e-11


@njit(inline="always", cache=True, error_model="numpy", nogil=True)
def _sincos(x):
    """``(sin x, cos x)`` for ``|x| <`` :data:`TRIG_LIMIT`, branch-free (see the module)."""
    fn = (x * _INVPIO2 + _TOINT) - _TOINT
    quadrant = fn - 4.0 * math.floor(0.25 * fn)  # fn mod 4 as a float (AVX2 has no float->int64)
    r = x - fn * _PIO2_1  # exact: fn has few bits, _PIO2_1 has 33
    w = fn * _PIO2_2
    y0 = r - w
    w = fn * _PIO2_2T - ((r - y0) - w)
    y = y0 - w
    tail = (y0 - y) - w  # y + tail = x - fn * pi/2 to ~1e-34
    z = y * y
    zz = z * z
    # __sin(y, tail)
    rs = _S2 + z * (_S3 + z * _S4) + z * zz * (_S5 + z * _S6)
    v = z * y
    s = y - ((z * (0.5 * tail - v * rs) - tail) - v * _S1)
    # __cos(y, tail)
    rc = z * (_C1 + z * (_C2 + z * _C3)) + zz * zz * (_C4 + z * (_C5 + z * _C6))
    hz = 0.5 * z
    one_m = 1.0 - hz
    c = one_m + (((1.0 - one_m) - hz) + (z * rc - y * tail))
    odd = quadrant == 1.0 or quadrant == 3.0
    sin_x = c if odd else s
    cos_x = s if odd else c
    sin_x = -sin_x if quadrant >= 2.0 else sin_x
    cos_x = -cos_x if quadrant == 1.0 or quadrant == 2.0 else cos_x
    return sin_x, cos_x


@_jit
def _trig_block(q, s0, nb, joint, sin_out, cos_out):
    """``sin``/``cos`` of ``q[s0:s0 + nb, joint]`` into ``sin_out[:nb]``, ``cos_out[:nb]``."""
    safe = True
    for b in range(nb):
        if not abs(q[s0 + b, joint]) < TRIG_LIMIT:  # also NaN
            safe = False
    if safe:
        for b in range(nb):  # a contiguous copy first: the SIMD loop below then has unit stride
            cos_out[b] = q[s0 + b, joint]
        for b in range(nb):
            sin_out[b], cos_out[b] = _sincos(cos_out[b])
    else:
        for b in range(nb):
            sin_out[b] = math.sin(q[s0 + b, joint])
            cos_out[b] = math.cos(q[s0 + b, joint])


@_jit
def sincos(x, sin_out, cos_out):
    """``sin`` and ``cos`` of ``x`` (N,) into ``sin_out``, ``cos_out`` (N,) (tests' entry)."""
    q = x.reshape(-1, 1)
    for s0 in range(0, x.shape[0], BLOCK):
        nb = min(BLOCK, x.shape[0] - s0)
        _trig_block(q, s0, nb, 0, sin_out[s0:], cos_out[s0:])


# -- end-effector positions -------------------------------------------------------------------


@_jit
def ee_positions(q, rot, pos, tool, skip, out):
    """End-effector positions of a chain.

    Parameters
    ----------
    q : (N, n) joint angles [rad].
    rot, pos : (n, 3, 3), (n, 3) [m]: ``E_i`` and ``p_i`` of every link (module docstring).
    tool : (3,) [m] tool point in the last link's frame.
    skip : (n,) bool: joint ``i`` cannot move the point (it lies on the axis): its rotation
        is not applied (as :func:`jointlock._chain.ee_position_rows`).
    out : (N, 3) [m] written: ``v_1`` of ``v_i = p_i + E_i Rot(z, q_i) v_{i+1}``, ``v_{n+1} = t``.
    """
    n = q.shape[1]
    sn = np.empty(BLOCK)
    cs = np.empty(BLOCK)
    vx = np.empty(BLOCK)
    vy = np.empty(BLOCK)
    vz = np.empty(BLOCK)
    for s0 in range(0, q.shape[0], BLOCK):
        nb = min(BLOCK, q.shape[0] - s0)
        for b in range(nb):
            vx[b] = tool[0]
            vy[b] = tool[1]
            vz[b] = tool[2]
        for i in range(n - 1, -1, -1):
            if not skip[i]:
                _trig_block(q, s0, nb, i, sn, cs)
                for b in range(nb):
                    x, y = vx[b], vy[b]
                    vx[b] = cs[b] * x - sn[b] * y
                    vy[b] = sn[b] * x + cs[b] * y
            e = rot[i]
            p0, p1, p2 = pos[i, 0], pos[i, 1], pos[i, 2]
            for b in range(nb):
                x, y, z = vx[b], vy[b], vz[b]
                vx[b] = e[0, 0] * x + e[0, 1] * y + e[0, 2] * z + p0
                vy[b] = e[1, 0] * x + e[1, 1] * y + e[1, 2] * z + p1
                vz[b] = e[2, 0] * x + e[2, 1] * y + e[2, 2] * z + p2
        for b in range(nb):
            out[s0 + b, 0] = vx[b]
            out[s0 + b, 1] = vy[b]
            out[s0 + b, 2] = vz[b]


# -- fixed-base geometric Jacobian ----------------------------------------------------------


@_jit
def _jacobian_block(q, s0, nb, rot, pos, tool, length, frames, sn, cs, axes, origins, jac):
    """Geometric Jacobian (6, n, :nb) of ``q[s0:s0 + nb]`` into ``jac``, the linear rows
    divided by ``length`` [m]; ``frames`` (12, BLOCK), ``axes``/``origins`` (n, 3, BLOCK) work."""
    n = q.shape[1]
    for b in range(nb):
        for k in range(12):
            frames[k, b] = 0.0
        frames[0, b] = 1.0
        frames[4, b] = 1.0
        frames[8, b] = 1.0
    for i in range(n):
        _trig_block(q, s0, nb, i, sn, cs)
        e = rot[i]
        p0, p1, p2 = pos[i, 0], pos[i, 1], pos[i, 2]
        for b in range(nb):
            # frame i = frame (i-1) [E_i, p_i] Rot(z, q_i); rows of R are frames[3r:3r+3]
            c, s = cs[b], sn[b]
            for r in range(3):
                r0, r1, r2 = frames[3 * r, b], frames[3 * r + 1, b], frames[3 * r + 2, b]
                frames[9 + r, b] += r0 * p0 + r1 * p1 + r2 * p2
                a0 = r0 * e[0, 0] + r1 * e[1, 0] + r2 * e[2, 0]
                a1 = r0 * e[0, 1] + r1 * e[1, 1] + r2 * e[2, 1]
                a2 = r0 * e[0, 2] + r1 * e[1, 2] + r2 * e[2, 2]
                frames[3 * r, b] = a0 * c + a1 * s
                frames[3 * r + 1, b] = a1 * c - a0 * s
                frames[3 * r + 2, b] = a2
                axes[i, r, b] = a2
                origins[i, r, b] = frames[9 + r, b]
    t0, t1, t2 = tool[0], tool[1], tool[2]
    for b in range(nb):
        pe0 = frames[9, b] + frames[0, b] * t0 + frames[1, b] * t1 + frames[2, b] * t2
        pe1 = frames[10, b] + frames[3, b] * t0 + frames[4, b] * t1 + frames[5, b] * t2
        pe2 = frames[11, b] + frames[6, b] * t0 + frames[7, b] * t1 + frames[8, b] * t2
        for i in range(n):
            z0, z1, z2 = axes[i, 0, b], axes[i, 1, b], axes[i, 2, b]
            d0, d1, d2 = pe0 - origins[i, 0, b], pe1 - origins[i, 1, b], pe2 - origins[i, 2, b]
            jac[0, i, b] = (z1 * d2 - z2 * d1) / length
            jac[1, i, b] = (z2 * d0 - z0 * d2) / length
            jac[2, i, b] = (z0 * d1 - z1 * d0) / length
            jac[3, i, b] = z0
            jac[4, i, b] = z1
            jac[5, i, b] = z2


@_jit
def jacobian(q, rot, pos, tool, out):
    """Fixed-base geometric Jacobian, root frame: ``out`` (N, 6, n) written, column ``i``
    ``(z_i x (p_e - p_i), z_i)`` (as :func:`jointlock.kinematics.jacobian`)."""
    n = q.shape[1]
    frames = np.empty((12, BLOCK))
    sn = np.empty(BLOCK)
    cs = np.empty(BLOCK)
    axes = np.empty((n, 3, BLOCK))
    origins = np.empty((n, 3, BLOCK))
    jac = np.empty((6, n, BLOCK))
    for s0 in range(0, q.shape[0], BLOCK):
        nb = min(BLOCK, q.shape[0] - s0)
        _jacobian_block(q, s0, nb, rot, pos, tool, 1.0, frames, sn, cs, axes, origins, jac)
        for b in range(nb):
            for r in range(6):
                for i in range(n):
                    out[s0 + b, r, i] = jac[r, i, b]


# -- singular values: one-sided (Hestenes) Jacobi --------------------------------------------


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
    for b in range(nb):
        row = out[s0 + b]
        for j in range(k):  # insertion sort, descending
            v = math.sqrt(norms[j, b])
            i = j
            while i > 0 and row[i - 1] < v:
                row[i] = row[i - 1]
                i -= 1
            row[i] = v


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


@_jit
def fixed_singular_values(q, rot, pos, tool, length, out):
    """Singular values of the fixed-base geometric Jacobian (linear rows divided by ``length`` [m], as
    :func:`jointlock.analysis.ability.scale_linear_rows`)
    at ``q`` (N, n) into ``out`` (N, min(6, n)), descending: :func:`jacobian` and
    :func:`singular_values` fused per block (the Jacobian never leaves the cache)."""
    n = q.shape[1]
    frames = np.empty((12, BLOCK))
    sn = np.empty(BLOCK)
    cs = np.empty(BLOCK)
    axes = np.empty((n, 3, BLOCK))
    origins = np.empty((n, 3, BLOCK))
    jac = np.empty((6, n, BLOCK))
    tall = n <= 6
    m, k = (6, n) if tall else (n, 6)
    a = jac if tall else np.empty((n, 6, BLOCK))
    norms, gam, cosv, sinv, tanv = _work(m, k)
    for s0 in range(0, q.shape[0], BLOCK):
        nb = min(BLOCK, q.shape[0] - s0)
        _jacobian_block(q, s0, nb, rot, pos, tool, length, frames, sn, cs, axes, origins, jac)
        if not tall:
            for i in range(n):
                for r in range(6):
                    for b in range(nb):
                        a[i, r, b] = jac[r, i, b]
        if m == 6:
            _jacobi6_block(a, nb, norms, out, s0)
        else:
            _jacobi_block(a, nb, norms, gam, cosv, sinv, tanv, out, s0)
