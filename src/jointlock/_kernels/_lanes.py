"""One pair's signed distance in one configuration, branch-free, so that a loop over a block of
configurations runs in SIMD registers (:mod:`jointlock._kernels._clearance` and
:mod:`jointlock._kernels._screen` call them): segment-segment as ``_distance._capsule_capsule``
(the four end points against the other segment and the interior critical point), and
segment-box away from the box (below); and the gathering of the configurations a pair is
computed for side by side.

Capsule-box, away from the box.  In the box frame the squared distance from ``p + t d`` to the
box is ``f(t) = sum_k e_k(t)^2`` with ``e_k`` the excess of coordinate ``k`` over the half
extent: convex, and ``f'(t) / 2 = g(t) = sum_k e_k(t) d_k`` is piecewise linear and
non-decreasing, with breakpoints where a coordinate crosses a face plane.  ``g`` is evaluated
at ``0``, ``1`` and the (at most six) breakpoints in between; the largest of them with ``g <=
0`` and the smallest with ``g >= 0`` bracket the minimum with no breakpoint between them, so
the root of ``g`` there is a linear interpolation (``t = 0`` when ``g(0) >= 0``, ``t = 1``
when ``g(1) <= 0``): exact, with no sort and no branch.

A shape's rows (``caps[6 * i : 6 * i + 6]``, ``boxes[12 * j : 12 * j + 12]``: a block of
configurations each) are passed as a view and indexed by the loop's own index: numba wraps an
index that may be negative, and an offset plus the loop index made every load a gather.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ._common import _jit

#: A capsule-box pair whose segment comes this close to the box [m] is computed again by
#: :mod:`jointlock._kernels._near_box` (touching or overlapping: its penetration depth).
NEAR_BOX_M = 1e-6
#: Doubles in a SIMD register (AVX-512): gathered lanes are computed in whole registers.
LANES = 8

_inline = njit(inline="always", cache=True, error_model="numpy", nogil=True)


@_inline
def _point_segment_sq(px, py, pz, ax, ay, az, dx, dy, dz, inv_dd):
    """Squared distance from point p to the segment a + t d, ``inv_dd = 1 / max(|d|^2, tiny)``,
    branch-free (a zero-length segment gives t = 0: its dot product is 0)."""
    t = ((px - ax) * dx + (py - ay) * dy + (pz - az) * dz) * inv_dd
    t = min(max(t, 0.0), 1.0)
    ex = ax + t * dx - px
    ey = ay + t * dy - py
    ez = az + t * dz - pz
    return ex * ex + ey * ey + ez * ez


@_inline
def _segments_sq(ax, ay, az, dx, dy, dz, bx, by, bz, ex, ey, ez):
    """Squared distance between the segments a + s d and b + t e (s, t in [0, 1]), branch-free:
    the four end points against the other segment, and the interior critical point when it is
    one (as ``_distance._capsule_capsule``)."""
    aa = dx * dx + dy * dy + dz * dz
    ee = ex * ex + ey * ey + ez * ez
    inv_aa = 1.0 / max(aa, 1e-300)
    inv_ee = 1.0 / max(ee, 1e-300)
    best = _point_segment_sq(ax, ay, az, bx, by, bz, ex, ey, ez, inv_ee)
    best = min(best, _point_segment_sq(ax + dx, ay + dy, az + dz, bx, by, bz, ex, ey, ez, inv_ee))
    best = min(best, _point_segment_sq(bx, by, bz, ax, ay, az, dx, dy, dz, inv_aa))
    best = min(best, _point_segment_sq(bx + ex, by + ey, bz + ez, ax, ay, az, dx, dy, dz, inv_aa))
    de = dx * ex + dy * ey + dz * ez
    denom = aa * ee - de * de
    fx, fy, fz = ax - bx, ay - by, az - bz
    df = dx * fx + dy * fy + dz * fz
    ef = ex * fx + ey * fy + ez * fz
    inv = 1.0 / max(denom, 1e-300)
    s = (de * ef - df * ee) * inv
    t = (aa * ef - de * df) * inv
    gx = ax + s * dx - bx - t * ex
    gy = ay + s * dy - by - t * ey
    gz = az + s * dz - bz - t * ez
    d2 = gx * gx + gy * gy + gz * gz
    inside = (denom > 1e-14 * aa * ee) and (aa > 0.0) and (ee > 0.0) and (0.0 < s < 1.0) and (0.0 < t < 1.0)
    return min(best, d2) if inside else best


@_inline
def _excess(x, h):
    return max(x - h, 0.0) + min(x + h, 0.0)


@_inline
def _slope(px, py, pz, dx, dy, dz, hx, hy, hz, t):
    """``g(t) = sum_k e_k(p_k + t d_k) d_k``: half the derivative of the squared distance."""
    return (
        _excess(px + t * dx, hx) * dx + _excess(py + t * dy, hy) * dy + _excess(pz + t * dz, hz) * dz
    )


@_inline
def _cut(p, d, h):
    """The two parameters where ``p + t d`` crosses ``-h`` and ``h``, or 0 outside (0, 1)."""
    inv = 1.0 / d if d != 0.0 else 0.0
    lo = (-h - p) * inv
    hi = (h - p) * inv
    return (lo if 0.0 < lo < 1.0 else 0.0), (hi if 0.0 < hi < 1.0 else 0.0)


@_inline
def _bracket(t, g, lo, glo, hi, ghi):
    """Narrow the bracket [lo, hi] of the root of g with the candidate (t, g)."""
    if g <= 0.0 and t > lo:
        lo, glo = t, g
    if g >= 0.0 and t < hi:
        hi, ghi = t, g
    return lo, glo, hi, ghi


@_inline
def _segment_box_sq(px, py, pz, dx, dy, dz, hx, hy, hz):
    """Squared distance from the segment p + t d (t in [0, 1], box frame) to the box of half
    extents h centred at the origin (see the module)."""
    lo, glo = 0.0, _slope(px, py, pz, dx, dy, dz, hx, hy, hz, 0.0)
    hi, ghi = 1.0, _slope(px, py, pz, dx, dy, dz, hx, hy, hz, 1.0)
    g0, g1 = glo, ghi
    c0, c1 = _cut(px, dx, hx)
    c2, c3 = _cut(py, dy, hy)
    c4, c5 = _cut(pz, dz, hz)
    lo, glo, hi, ghi = _bracket(c0, _slope(px, py, pz, dx, dy, dz, hx, hy, hz, c0), lo, glo, hi, ghi)
    lo, glo, hi, ghi = _bracket(c1, _slope(px, py, pz, dx, dy, dz, hx, hy, hz, c1), lo, glo, hi, ghi)
    lo, glo, hi, ghi = _bracket(c2, _slope(px, py, pz, dx, dy, dz, hx, hy, hz, c2), lo, glo, hi, ghi)
    lo, glo, hi, ghi = _bracket(c3, _slope(px, py, pz, dx, dy, dz, hx, hy, hz, c3), lo, glo, hi, ghi)
    lo, glo, hi, ghi = _bracket(c4, _slope(px, py, pz, dx, dy, dz, hx, hy, hz, c4), lo, glo, hi, ghi)
    lo, glo, hi, ghi = _bracket(c5, _slope(px, py, pz, dx, dy, dz, hx, hy, hz, c5), lo, glo, hi, ghi)
    span = ghi - glo
    t = lo + (hi - lo) * (-glo / span) if span > 0.0 else lo
    t = min(max(t, min(lo, hi)), max(lo, hi))
    t = 0.0 if g0 >= 0.0 else (1.0 if g1 <= 0.0 else t)
    ex = _excess(px + t * dx, hx)
    ey = _excess(py + t * dy, hy)
    ez = _excess(pz + t * dz, hz)
    return ex * ex + ey * ey + ez * ez


@_inline
def _capsule_lane(ca, cb, b, gap):
    """Signed distance of the capsules ``ca`` and ``cb`` (each its six rows of ``caps``,
    :func:`_place_block`), configuration ``b`` of the block; ``gap``: both radii plus the
    pair's offset [m]."""
    ax, ay, az = ca[0, b], ca[1, b], ca[2, b]
    bx, by, bz = cb[0, b], cb[1, b], cb[2, b]
    d2 = _segments_sq(
        ax, ay, az, ca[3, b] - ax, ca[4, b] - ay, ca[5, b] - az,
        bx, by, bz, cb[3, b] - bx, cb[4, b] - by, cb[5, b] - bz,
    )
    return math.sqrt(d2) - gap


@_inline
def _box_lane(ca, bx, b, hx, hy, hz, gap):
    """Signed distance of the capsule ``ca`` (its six rows of ``caps``) and the box ``bx`` (its
    twelve rows of ``boxes``, :func:`_place_block`) of half extents h, configuration ``b`` of
    the block; ``gap``: the radius plus the pair's offset [m].  NaN when the segment comes
    within :data:`NEAR_BOX_M` of the box: the scalar kernel's (penetration depth)."""
    # the segment in the box frame (box axes are the rotation's columns)
    ox = ca[0, b] - bx[9, b]
    oy = ca[1, b] - bx[10, b]
    oz = ca[2, b] - bx[11, b]
    vx = ca[3, b] - ca[0, b]
    vy = ca[4, b] - ca[1, b]
    vz = ca[5, b] - ca[2, b]
    r00, r01, r02 = bx[0, b], bx[1, b], bx[2, b]
    r10, r11, r12 = bx[3, b], bx[4, b], bx[5, b]
    r20, r21, r22 = bx[6, b], bx[7, b], bx[8, b]
    d2 = _segment_box_sq(
        r00 * ox + r10 * oy + r20 * oz,
        r01 * ox + r11 * oy + r21 * oz,
        r02 * ox + r12 * oy + r22 * oz,
        r00 * vx + r10 * vy + r20 * vz,
        r01 * vx + r11 * vy + r21 * vz,
        r02 * vx + r12 * vy + r22 * vz,
        hx, hy, hz,
    )
    # near or in the box: NaN marks it for the scalar kernel below (q is finite)
    return math.sqrt(d2) - gap if d2 > NEAR_BOX_M * NEAR_BOX_M else np.nan


@_inline
def _gather(rows, lanes, m, out):
    """``out[:, t] = rows[:, lanes[t]]`` for ``t < m``: the configurations a pair is computed
    for, side by side (so that its loop runs on contiguous lanes)."""
    for r in range(rows.shape[0]):
        source, target = rows[r], out[r]
        for t in range(m):
            target[t] = source[lanes[t]]


@_jit
def _capsule_lanes(ca, cb, lanes, m, gap, near_a, near_b, values):
    """``values[t]``: :func:`_capsule_lane` of configuration ``lanes[t]``, ``t < m``."""
    _gather(ca, lanes, m, near_a)
    _gather(cb, lanes, m, near_b)
    for t in range(m):
        values[t] = _capsule_lane(near_a, near_b, t, gap)


@_jit
def _box_lanes(ca, bx, lanes, m, hx, hy, hz, gap, near_a, near_box, values):
    """``values[t]``: :func:`_box_lane` of configuration ``lanes[t]``, ``t < m``."""
    _gather(ca, lanes, m, near_a)
    _gather(bx, lanes, m, near_box)
    for t in range(m):
        values[t] = _box_lane(near_a, near_box, t, hx, hy, hz, gap)
