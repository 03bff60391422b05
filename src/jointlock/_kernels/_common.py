"""Shared by the kernels: block size, the ``@jit`` options, and branch-free sine and cosine
(see :mod:`jointlock._kernels`)."""


from __future__ import annotations

import math

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


@njit(inline="always", cache=True, error_model="numpy", nogil=True)
def _nan_max(a, b):
    """``np.maximum(a, b)`` on scalars: NaN when either is (``max`` would drop it).  Equal
    values give ``a``: a zero's sign may differ from numpy's (which SIMD lanes decide); the
    kernels' operands here are not signed zeros where it would show."""
    if a != a or b != b:
        return a + b
    return a if a >= b else b


@njit(inline="always", cache=True, error_model="numpy", nogil=True)
def _nan_min(a, b):
    """``np.minimum(a, b)`` on scalars: NaN when either is; equal values give ``a``
    (see :func:`_nan_max`)."""
    if a != a or b != b:
        return a + b
    return a if a <= b else b

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


@njit(inline="always", cache=True, error_model="numpy", nogil=True)
def _adjugate3(xx, yy, zz, xy, xz, yz):
    """Adjugate of the symmetric 3 x 3 matrix with entries ``xx yy zz xy xz yz``, as
    ``(a_xx, a_yy, a_zz, a_xy, a_xz, a_yz)``, and its determinant (inverse = adjugate / det)."""
    axx = yy * zz - yz * yz
    axy = xz * yz - xy * zz
    axz = xy * yz - xz * yy
    ayy = xx * zz - xz * xz
    ayz = xy * xz - xx * yz
    azz = xx * yy - xy * xy
    return axx, ayy, azz, axy, axz, ayz, xx * axx + xy * axy + xz * axz


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
