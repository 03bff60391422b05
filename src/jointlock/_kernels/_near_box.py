"""The scalar kernel's capsule-box distance (``_distance._capsule_box``) for the configurations
whose segment comes within :data:`~jointlock._kernels._lanes.NEAR_BOX_M` of the box, branch-free
and side by side in SIMD registers: the same operations, the same bits.

``_capsule_box`` minimises the squared distance over the pieces of the segment between its
breakpoints (where a coordinate crosses a face plane, insertion-sorted), and where that is 0
takes the penetration depth over the box's axes and their cross products with the segment.
The copy sorts the six breakpoints by a sorting network, a missing one replaced by 0 (which
only adds the piece [0, 0]), and puts a candidate normal the scalar kernel skips at +inf.  A
third of halt7's random configurations put a link into the bus: 30 ns a configuration here
against 90 ns one at a time.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ._common import BLOCK, _jit
from ._lanes import LANES, _gather

_inline = njit(inline="always", cache=True, error_model="numpy", nogil=True)


@_inline
def _sorted2(a, b):
    return min(a, b), max(a, b)


@_inline
def _cut_scalar(p, d, h, sign):
    """A breakpoint of ``_distance._capsule_box`` (the same operations), or 0 where that
    kernel has none (``d == 0`` or outside (0, 1)): a repeated 0 only adds the piece [0, 0]."""
    t = (sign * h - p) / d
    return t if (d != 0.0 and 0.0 < t < 1.0) else 0.0


@_inline
def _piece_sq(px, py, pz, dx, dy, dz, hx, hy, hz, t0, t1):
    """The smallest squared distance ``_distance._capsule_box`` finds on the piece [t0, t1] of
    the segment (its four candidates, the same operations)."""
    tm = 0.5 * (t0 + t1)
    qa = 0.0
    qb = 0.0
    # a coordinate outside its slab at tm adds its term (adding 0.0 changes no sum here: qa
    # and qb start at +0.0, and no sum of such terms is -0.0)
    x = px + tm * dx
    out = x > hx or x < -hx
    qa += dx * dx if out else 0.0
    qb += ((px - hx) if x > hx else (px + hx)) * dx if out else 0.0
    x = py + tm * dy
    out = x > hy or x < -hy
    qa += dy * dy if out else 0.0
    qb += ((py - hy) if x > hy else (py + hy)) * dy if out else 0.0
    x = pz + tm * dz
    out = x > hz or x < -hz
    qa += dz * dz if out else 0.0
    qb += ((pz - hz) if x > hz else (pz + hz)) * dz if out else 0.0
    t = min(max(-qb / qa, t0), t1) if qa > 0.0 else t0
    best = _box_sq_at(px, py, pz, dx, dy, dz, hx, hy, hz, t0)
    best = min(best, _box_sq_at(px, py, pz, dx, dy, dz, hx, hy, hz, t))
    best = min(best, _box_sq_at(px, py, pz, dx, dy, dz, hx, hy, hz, tm))
    return min(best, _box_sq_at(px, py, pz, dx, dy, dz, hx, hy, hz, t1))


@_inline
def _excess_as_scalar(x, h):
    """``_distance._excess`` as selects (0 for NaN, as there: a candidate whose ``t`` is NaN
    after an overflow counts as inside)."""
    return (x - h) if x > h else ((x + h) if x < -h else 0.0)


@_inline
def _box_sq_at(px, py, pz, dx, dy, dz, hx, hy, hz, t):
    ex = _excess_as_scalar(px + t * dx, hx)
    ey = _excess_as_scalar(py + t * dy, hy)
    ez = _excess_as_scalar(pz + t * dz, hz)
    return 0.0 + ex * ex + ey * ey + ez * ez


@_inline
def _facet_depth(ux, uy, uz, hx, hy, hz, dx, dy, dz, mx, my, mz):
    """How far the segment must move along +-u to leave the box, the smaller of the two
    (``_distance._capsule_box``'s candidate, the same operations)."""
    spread = hx * abs(ux) + hy * abs(uy) + hz * abs(uz)
    spread += 0.5 * abs(ux * dx + uy * dy + uz * dz)
    along = ux * mx + uy * my + uz * mz
    return min(spread - 1.0 * along, spread - -1.0 * along)


@_inline
def _cross_depth(ux, uy, uz, dn, hx, hy, hz, dx, dy, dz, mx, my, mz):
    """:func:`_facet_depth` along the unit ``u / |u|``, +inf where ``_distance._capsule_box``
    leaves the candidate out (a zero segment, or ``u`` nearly parallel to it)."""
    un = math.sqrt(ux * ux + uy * uy + uz * uz)
    depth = _facet_depth(ux / un, uy / un, uz / un, hx, hy, hz, dx, dy, dz, mx, my, mz)
    return depth if (dn > 0.0 and not un <= 1e-12 * dn) else np.inf


@_inline
def _near_box_distance(ca, bx, t, hx, hy, hz, radius):
    """The signed distance of ``_distance._capsule_box`` (capsule ``ca``, box ``bx`` of half
    extents h, configuration ``t`` of the rows) branch-free, bit for bit, for the
    configurations whose segment comes within :data:`NEAR_BOX_M` of the box: its squared
    distance over the pieces between the sorted breakpoints (a sorting network instead of an
    insertion sort: the same pieces, and repeated zeros for missing breakpoints), and where
    that is 0, the penetration depth over the box's axes and their cross products with the
    segment.  Bit for bit while the squares of the coordinates are finite (below 1e154 m: a
    model's lengths are at most 1e12 m); beyond, the two kernels' overflows differ."""
    ox, oy, oz = ca[0, t] - bx[9, t], ca[1, t] - bx[10, t], ca[2, t] - bx[11, t]
    vx, vy, vz = ca[3, t] - ca[0, t], ca[4, t] - ca[1, t], ca[5, t] - ca[2, t]
    px = bx[0, t] * ox + bx[3, t] * oy + bx[6, t] * oz
    py = bx[1, t] * ox + bx[4, t] * oy + bx[7, t] * oz
    pz = bx[2, t] * ox + bx[5, t] * oy + bx[8, t] * oz
    dx = bx[0, t] * vx + bx[3, t] * vy + bx[6, t] * vz
    dy = bx[1, t] * vx + bx[4, t] * vy + bx[7, t] * vz
    dz = bx[2, t] * vx + bx[5, t] * vy + bx[8, t] * vz
    c0, c1 = _cut_scalar(px, dx, hx, -1.0), _cut_scalar(px, dx, hx, 1.0)
    c2, c3 = _cut_scalar(py, dy, hy, -1.0), _cut_scalar(py, dy, hy, 1.0)
    c4, c5 = _cut_scalar(pz, dz, hz, -1.0), _cut_scalar(pz, dz, hz, 1.0)
    for _ in range(1):  # a sorting network of the six breakpoints
        c1, c2 = _sorted2(c1, c2)
        c4, c5 = _sorted2(c4, c5)
        c0, c2 = _sorted2(c0, c2)
        c3, c5 = _sorted2(c3, c5)
        c0, c1 = _sorted2(c0, c1)
        c3, c4 = _sorted2(c3, c4)
        c1, c4 = _sorted2(c1, c4)
        c0, c3 = _sorted2(c0, c3)
        c2, c5 = _sorted2(c2, c5)
        c1, c3 = _sorted2(c1, c3)
        c2, c4 = _sorted2(c2, c4)
        c2, c3 = _sorted2(c2, c3)
    best = _piece_sq(px, py, pz, dx, dy, dz, hx, hy, hz, 0.0, c0)
    best = min(best, _piece_sq(px, py, pz, dx, dy, dz, hx, hy, hz, c0, c1))
    best = min(best, _piece_sq(px, py, pz, dx, dy, dz, hx, hy, hz, c1, c2))
    best = min(best, _piece_sq(px, py, pz, dx, dy, dz, hx, hy, hz, c2, c3))
    best = min(best, _piece_sq(px, py, pz, dx, dy, dz, hx, hy, hz, c3, c4))
    best = min(best, _piece_sq(px, py, pz, dx, dy, dz, hx, hy, hz, c4, c5))
    best = min(best, _piece_sq(px, py, pz, dx, dy, dz, hx, hy, hz, c5, 1.0))
    dn = math.sqrt(dx * dx + dy * dy + dz * dz)
    mx, my, mz = px + 0.5 * dx, py + 0.5 * dy, pz + 0.5 * dz
    depth = _facet_depth(1.0, 0.0, 0.0, hx, hy, hz, dx, dy, dz, mx, my, mz)
    depth = min(depth, _facet_depth(0.0, 1.0, 0.0, hx, hy, hz, dx, dy, dz, mx, my, mz))
    depth = min(depth, _facet_depth(0.0, 0.0, 1.0, hx, hy, hz, dx, dy, dz, mx, my, mz))
    depth = min(depth, _cross_depth(0.0, -dz, dy, dn, hx, hy, hz, dx, dy, dz, mx, my, mz))
    depth = min(depth, _cross_depth(dz, 0.0, -dx, dn, hx, hy, hz, dx, dy, dz, mx, my, mz))
    depth = min(depth, _cross_depth(-dy, dx, 0.0, dn, hx, hy, hz, dx, dy, dz, mx, my, mz))
    return math.sqrt(best) - radius if best > 0.0 else -(depth + radius)


@_jit
def _near_box_lanes(near_a, near_box, values, m, lanes, hx, hy, hz, radius, offset, fixed, cap_rows, box_rows):
    """The lanes ``t < m`` whose ``values[t]`` :func:`_box_lane` left NaN (near or in the box)
    get :func:`_near_box_distance` minus ``offset``: those of ``_distance._capsule_box`` bit
    for bit, side by side in whole SIMD registers (``lanes``, ``fixed``, ``cap_rows`` (6,
    BLOCK), ``box_rows`` (12, BLOCK): scratch)."""
    count = 0
    for t in range(m):
        lanes[count] = t
        count += 1 if values[t] != values[t] else 0
    if count == 0:
        return
    padded = min(-(-count // LANES) * LANES, BLOCK)
    for u in range(count, padded):
        lanes[u] = lanes[count - 1]
    _gather(near_a, lanes, padded, cap_rows)
    _gather(near_box, lanes, padded, box_rows)
    for u in range(padded):
        fixed[u] = _near_box_distance(cap_rows, box_rows, u, hx, hy, hz, radius) - offset
    for u in range(count):
        values[lanes[u]] = fixed[u]
