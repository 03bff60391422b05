"""Clearance of a batch of configurations in one compiled pass (issue 27's speed): the chain's
frames, the shapes' placements and every pair's signed distance, block by block, without a
Python step per configuration or per pair (:func:`jointlock.collision.clearance` calls it).

Why a second kernel next to :func:`jointlock._kernels._distance.pair_distances`.  That kernel
takes every configuration's shapes already placed (a numpy forward-kinematics pass and a copy
per shape) and computes each pair's witness points on the way.  Here, for a block of
:data:`~jointlock._kernels._common.BLOCK` configurations:

1. the frames advance link by link (:func:`jointlock._kernels._arm._advance`, the chain
   convention of :mod:`jointlock._kernels`) and each link's shapes are placed as soon as its
   frame is known;
2. every pair's signed distance is a branch-free loop over the block (one SIMD lane per
   configuration): capsule-capsule as in ``_distance._capsule_capsule`` (the four end points
   against the other segment and the interior critical point, minus both radii);
   capsule-box from the derivative of the squared distance along the segment (below);
3. a capsule-box pair whose segment comes within :data:`NEAR_BOX_M` of the box (touching or
   overlapping: the penetration depth is a different computation) is computed again, those
   configurations side by side, by a branch-free copy of the scalar kernel's distance
   (:func:`_near_box_distance`: the same operations, the same bits as
   ``_distance._capsule_box``), and the closest pair of each configuration gets its witness
   points from the scalar kernels (when asked);
4. :func:`clearance_smallest`, the jobs' screens, computes only the pairs that bounds from the
   shapes' centres leave as possibly the closest.

Indexing.  Each shape's rows are taken as a view (``caps[6 * i : 6 * i + 6]``) and indexed by
the loop's own index: numba wraps an index that may be negative, and an offset plus the loop
index made every load of the SIMD loops a gather.

Capsule-box, away from the box.  In the box frame the squared distance from ``p + t d`` to the
box is ``f(t) = sum_k e_k(t)^2`` with ``e_k`` the excess of coordinate ``k`` over the half
extent: convex, and ``f'(t) / 2 = g(t) = sum_k e_k(t) d_k`` is piecewise linear and
non-decreasing, with breakpoints where a coordinate crosses a face plane.  ``g`` is evaluated
at ``0``, ``1`` and the (at most six) breakpoints in between; the largest of them with ``g <=
0`` and the smallest with ``g >= 0`` bracket the minimum with no breakpoint between them, so
the root of ``g`` there is a linear interpolation (``t = 0`` when ``g(0) >= 0``, ``t = 1``
when ``g(1) <= 0``): exact, with no sort and no branch.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ._arm import _advance, _identity_frames
from ._common import BLOCK, _jit, _trig_block
from ._distance import _capsule_box, _capsule_capsule

#: A capsule-box pair whose segment comes this close to the box [m] is computed by the scalar
#: kernel (touching or overlapping: its penetration depth and witness points).
NEAR_BOX_M = 1e-6
#: :func:`clearance_smallest` leaves a pair out only when its lower bound exceeds the least
#: upper bound by more than its slack: this [m], plus :data:`PARALLEL_SLACK` of the pair's
#: longer segment, plus :data:`ROUND_OFF_SLACK` of the coordinates' and the floor's size, so
#: that the pair a computed distance makes the closest is never left out.
BOUND_SLACK_M = 1e-9
#: A capsule pair's computed distance may exceed the true one by up to this share of the
#: longer segment [-]: :func:`_segments_sq` leaves out the interior critical point of nearly
#: parallel segments (``sin^2`` of their angle below 1e-14, so by at most 1e-7 of a length).
PARALLEL_SLACK = 1e-6
#: The bounds' and the distances' round-off, as a share of the size of the coordinates, the
#: floors and the offsets [-] (some 450 units in the last place).
ROUND_OFF_SLACK = 1e-13
#: Doubles in a SIMD register (AVX-512); :func:`clearance_smallest` computes its pairs in whole
#: registers.
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
def _place_block(q, s0, nb, rot, pos, cap_body, cap_points, box_body, box_frames, frames, sn, cs, caps, boxes):
    """The shapes of configurations ``s0 .. s0 + nb`` placed in the root frame: ``caps`` row
    ``6 c + k`` (capsule ``c``'s end points a, b), ``boxes`` row ``12 k + m`` (box ``k``'s
    rotation, row-major, then centre), each row a block of :data:`BLOCK` (see
    :func:`clearance_distances`); ``frames``, ``sn``, ``cs`` are scratch."""
    n = q.shape[1]
    n_caps, n_boxes = cap_points.shape[0], box_frames.shape[0]
    _identity_frames(frames, nb)
    for body in range(-1, n):
        if body >= 0:
            _trig_block(q, s0, nb, body, sn, cs)
            e = rot[body]
            p0, p1, p2 = pos[body, 0], pos[body, 1], pos[body, 2]
            for b in range(nb):
                _advance(frames, b, e, p0, p1, p2, cs[b], sn[b])
        for c in range(n_caps):
            if cap_body[c] != body:
                continue
            for end in range(2):
                x, y, z = cap_points[c, 3 * end], cap_points[c, 3 * end + 1], cap_points[c, 3 * end + 2]
                for r in range(3):
                    row = caps[6 * c + 3 * end + r]
                    for b in range(nb):
                        row[b] = (
                            frames[3 * r, b] * x + frames[3 * r + 1, b] * y + frames[3 * r + 2, b] * z
                            + frames[9 + r, b]
                        )
        for k in range(n_boxes):
            if box_body[k] != body:
                continue
            f = box_frames[k]
            for r in range(3):
                for col in range(3):  # (F R)[r, col]
                    row = boxes[12 * k + 3 * r + col]
                    for b in range(nb):
                        row[b] = (
                            frames[3 * r, b] * f[col] + frames[3 * r + 1, b] * f[3 + col]
                            + frames[3 * r + 2, b] * f[6 + col]
                        )
                row = boxes[12 * k + 9 + r]
                for b in range(nb):
                    row[b] = (
                        frames[3 * r, b] * f[9] + frames[3 * r + 1, b] * f[10] + frames[3 * r + 2, b] * f[11]
                        + frames[9 + r, b]
                    )


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


@_jit
def clearance_distances(
    q, rot, pos, cap_body, cap_points, radii, box_body, box_frames, halves, pairs, offsets,
    witness, out_distance, out_lowest, out_closest, out_witness,
):
    """Signed distances of every pair for every configuration, the closest pair and its
    witness points.

    Parameters
    ----------
    q
        (N, n) joint angles [rad].
    rot, pos
        (n, 3, 3), (n, 3) [m]: ``E_i`` and ``p_i`` of every link (:mod:`jointlock._kernels`),
        the root frame at the origin.
    cap_body, cap_points, radii
        (C,) int64 body of each capsule (-1 the root body and keep-outs, ``i`` link ``i``'s
        ``z``-joint frame); (C, 6) its end points a, b in that frame [m]; (C,) radii [m].
    box_body, box_frames, halves
        (B,) int64 body of each box; (B, 12) its rotation (row-major, box axes as columns) and
        centre in that frame [m]; (B, 3) half extents [m].
    pairs, offsets
        As :func:`jointlock._kernels._distance.pair_distances`; a pair of kind 2 (a convex
        hull) is left at +inf, for the caller.
    witness
        Whether to compute the closest pair's witness points (``out_witness`` is left as it is
        otherwise).
    out_distance, out_lowest, out_closest, out_witness
        Written in place: (P, N) every pair's signed distance [m] (pair-major: each pair's row
        is one contiguous store per block); (N,) the smallest, a mounted pair counting only when
        it is deeper than at the zero pose (+inf when none counts); (N,) its pair (0 when none);
        (N, 2, 3) its witness points [m], as :func:`jointlock._kernels._distance.pair_distances`.
    """
    count, n = q.shape
    n_caps, n_boxes, n_pairs = cap_points.shape[0], box_frames.shape[0], pairs.shape[0]
    frames = np.empty((12, BLOCK))
    sn = np.empty(BLOCK)
    cs = np.empty(BLOCK)
    caps = np.empty((max(n_caps, 1) * 6, BLOCK))  # row 6 c + k of capsule c, then the block
    boxes = np.empty((max(n_boxes, 1) * 12, BLOCK))
    dist = np.empty((max(n_pairs, 1), BLOCK))
    lowest = np.empty(BLOCK)
    nearest = np.zeros(BLOCK, dtype=np.int64)
    w = np.empty((2, 3))
    work = np.empty(14)
    cap_world = np.empty((2, 6))
    box_world = np.empty(12)
    near_lanes = np.empty(BLOCK, dtype=np.uint64)
    fixed = np.empty(BLOCK)
    cap_rows = np.empty((6, BLOCK))
    box_rows = np.empty((12, BLOCK))
    for s0 in range(0, count, BLOCK):
        nb = min(BLOCK, count - s0)
        _place_block(q, s0, nb, rot, pos, cap_body, cap_points, box_body, box_frames, frames, sn, cs, caps, boxes)
        for k in range(n_pairs):
            kind, i, j = pairs[k, 0], pairs[k, 1], pairs[k, 2]
            # each shape's rows as one view: an index b from a range is known not to be
            # negative, so the loops below load contiguously (an offset plus b would be wrapped
            # like a negative index, and gathered)
            ca = caps[6 * i : 6 * i + 6]
            out = dist[k]
            if kind == 0:
                cb = caps[6 * j : 6 * j + 6]
                gap = radii[i] + radii[j] + offsets[k]
                for b in range(nb):
                    out[b] = _capsule_lane(ca, cb, b, gap)
            elif kind == 2:  # a convex hull: coal, afterwards (jointlock.collision)
                for b in range(nb):
                    out[b] = np.inf
            else:
                bx = boxes[12 * j : 12 * j + 12]
                hx, hy, hz = halves[j, 0], halves[j, 1], halves[j, 2]
                gap = radii[i] + offsets[k]
                for b in range(nb):
                    out[b] = _box_lane(ca, bx, b, hx, hy, hz, gap)

        # pairs near or in a box: the scalar kernel's distance (penetration depth), in SIMD
        for k in range(n_pairs):
            if pairs[k, 0] != 1:
                continue
            i, j = pairs[k, 1], pairs[k, 2]
            _near_box_lanes(
                caps[6 * i : 6 * i + 6], boxes[12 * j : 12 * j + 12], dist[k], nb, near_lanes,
                halves[j, 0], halves[j, 1], halves[j, 2], radii[i], offsets[k], fixed, cap_rows, box_rows,
            )  # fmt: skip
        # the closest pair: a mounted one only when deeper than at the zero pose
        for b in range(nb):
            lowest[b] = np.inf
            nearest[b] = 0
        for k in range(n_pairs):
            mounted = offsets[k] < 0.0
            row = dist[k]
            for b in range(nb):
                value = row[b]
                out_distance[k, s0 + b] = value
                rank = np.inf if mounted and value >= 0.0 else value
                closer = rank < lowest[b]
                lowest[b] = rank if closer else lowest[b]
                nearest[b] = k if closer else nearest[b]
        for b in range(nb):
            out_lowest[s0 + b] = lowest[b]
            out_closest[s0 + b] = nearest[b]
        if witness:
            _witness_block(caps, boxes, radii, halves, pairs, s0, nb, lowest, nearest, cap_world, box_world, w, work, out_witness)


@_inline
def _gather(rows, lanes, m, out):
    """``out[:, t] = rows[:, lanes[t]]`` for ``t < m``: the configurations a pair is computed
    for, side by side (so that its loop runs on contiguous lanes)."""
    for r in range(rows.shape[0]):
        source, target = rows[r], out[r]
        for t in range(m):
            target[t] = source[lanes[t]]


@_jit
def _pair_slack(pos, cap_points, box_frames, halves, pairs, offsets, floor, half_length):
    """(P,) by how much a pair's lower bound must exceed the least upper bound to be left out
    [m] (:data:`BOUND_SLACK_M`)."""
    # every coordinate of a placed shape is at most this far from the origin: the chain's
    # offsets (its rotations keep lengths) plus the farthest point of any shape
    extent = 0.0
    for i in range(pos.shape[0]):
        extent += math.sqrt(pos[i, 0] ** 2 + pos[i, 1] ** 2 + pos[i, 2] ** 2)
    farthest = 0.0
    for c in range(cap_points.shape[0]):
        for end in range(2):
            x, y, z = cap_points[c, 3 * end], cap_points[c, 3 * end + 1], cap_points[c, 3 * end + 2]
            farthest = max(farthest, math.sqrt(x * x + y * y + z * z))
    for k in range(box_frames.shape[0]):
        centre = math.sqrt(box_frames[k, 9] ** 2 + box_frames[k, 10] ** 2 + box_frames[k, 11] ** 2)
        farthest = max(farthest, centre + math.sqrt(halves[k, 0] ** 2 + halves[k, 1] ** 2 + halves[k, 2] ** 2))
    extent += farthest
    out = np.empty(pairs.shape[0])
    for k in range(pairs.shape[0]):
        kind, i, j = pairs[k, 0], pairs[k, 1], pairs[k, 2]
        longest = 2.0 * max(half_length[i], half_length[j]) if kind == 0 else 0.0
        size = extent + abs(floor[k]) + abs(offsets[k])
        out[k] = BOUND_SLACK_M + PARALLEL_SLACK * longest + ROUND_OFF_SLACK * size
    return out


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


@_jit
def _witness_block(caps, boxes, radii, halves, pairs, s0, nb, lowest, nearest, cap_world, box_world, w, work, out_witness):
    """The witness points of each configuration's closest pair ``nearest[b]`` (none where
    ``lowest[b]`` is +inf) into ``out_witness[s0 + b]``, by the scalar kernels."""
    for b in range(nb):
        if lowest[b] == np.inf:
            continue
        k = nearest[b]
        kind, i, j = pairs[k, 0], pairs[k, 1], pairs[k, 2]
        _place(caps, boxes, i, j if kind == 1 else 0, b, cap_world, box_world)
        if kind == 0:
            for r in range(6):
                cap_world[1, r] = caps[6 * j + r, b]
            _capsule_capsule(cap_world[0], radii[i], cap_world[1], radii[j], w)
        else:
            _capsule_box(cap_world[0], radii[i], box_world, halves[j], w, work)
        for r in range(2):
            for col in range(3):
                out_witness[s0 + b, r, col] = w[r, col]


@_jit
def _place(caps, boxes, i, j, b, cap_world, box_world):
    """Capsule ``i`` and box ``j`` of configuration ``b`` of the block, as the scalar kernels
    take them: ``cap_world[0]`` (6,), ``box_world`` (12,)."""
    for r in range(6):
        cap_world[0, r] = caps[6 * i + r, b]
    if boxes.shape[0] >= 12 * (j + 1):
        for r in range(12):
            box_world[r] = boxes[12 * j + r, b]


@_jit
def clearance_smallest(
    q, rot, pos, cap_body, cap_points, radii, box_body, box_frames, halves, pairs, offsets, floor,
    out_smallest, out_closest,
):
    """The smallest excess of a pair's signed distance over its floor, and its pair, for every
    configuration, without every pair's distance (the jobs' screens).

    The excess of pair ``k`` is ``d_k - floor[k]``, ``d_k`` the signed distance
    :func:`clearance_distances` gives it (the same bits: the same lane functions).  Pairs of
    kind 2 are left out (the caller's).

    Most pairs of a configuration are nowhere near being its closest, and bounds from its
    shapes' centres say so at a fraction of the cost of its distance.  For a capsule of half
    length ``l`` and centre ``m``, every point of its segment lies within ``l`` of ``m``:

    * capsule-capsule: with ``e_i`` the distance from ``m_j`` to segment ``i`` and ``e_j`` the
      other way round, ``min(e_i, e_j) - r_i - r_j`` is at least the signed distance (the
      centres are points of the segments), and ``max(e_i - l_j, e_j - l_i) - r_i - r_j`` at
      most;
    * capsule-box: with ``e`` the distance from ``m`` to the box, ``e - r`` is at least the
      signed distance, and ``e - l - r`` at most when ``e > l`` (the segment does not reach the
      box; otherwise nothing is bounded).

    The least of the upper bounds over the pairs bounds the configuration's smallest excess; a
    pair whose lower bound exceeds it by more than its slack (:data:`BOUND_SLACK_M`: the
    computed distances' own errors, round-off and nearly parallel segments) cannot be the
    closest and is not computed.  The others are, exactly, in pair order, so that the smallest excess
    and its pair (the first of equal ones) are those of every pair computed.

    Parameters
    ----------
    q, rot, pos, cap_body, cap_points, radii, box_body, box_frames, halves, pairs, offsets
        As :func:`clearance_distances`.
    floor
        (P,) each pair's floor [m].
    out_smallest, out_closest
        Written in place: (N,) the smallest excess [m] (+inf when no pair counts); (N,) its
        pair (0 when none).
    """
    count = q.shape[0]
    n_caps, n_boxes, n_pairs = cap_points.shape[0], box_frames.shape[0], pairs.shape[0]
    frames = np.empty((12, BLOCK))
    sn = np.empty(BLOCK)
    cs = np.empty(BLOCK)
    caps = np.empty((max(n_caps, 1) * 6, BLOCK))
    boxes = np.empty((max(n_boxes, 1) * 12, BLOCK))
    centres = np.empty((max(n_caps, 1) * 3, BLOCK))
    half_length = np.empty(max(n_caps, 1))
    inv_length_sq = np.empty(max(n_caps, 1))
    for c in range(n_caps):
        dx = cap_points[c, 3] - cap_points[c, 0]
        dy = cap_points[c, 4] - cap_points[c, 1]
        dz = cap_points[c, 5] - cap_points[c, 2]
        half_length[c] = 0.5 * math.sqrt(dx * dx + dy * dy + dz * dz)
        inv_length_sq[c] = 1.0 / max(dx * dx + dy * dy + dz * dz, 1e-300)
    slack = _pair_slack(pos, cap_points, box_frames, halves, pairs, offsets, floor, half_length)
    lower = np.empty((max(n_pairs, 1), BLOCK))
    upper = np.empty(BLOCK)
    lowest = np.empty(BLOCK)
    nearest = np.zeros(BLOCK, dtype=np.int64)
    lanes = np.empty(BLOCK, dtype=np.uint64)
    values = np.empty(BLOCK)
    dense = np.empty(BLOCK)
    near_lanes = np.empty(BLOCK, dtype=np.uint64)
    fixed = np.empty(BLOCK)
    cap_rows = np.empty((6, BLOCK))
    box_rows = np.empty((12, BLOCK))
    near_a = np.empty((6, BLOCK))
    near_b = np.empty((6, BLOCK))
    near_box = np.empty((12, BLOCK))
    for s0 in range(0, count, BLOCK):
        nb = min(BLOCK, count - s0)
        _place_block(q, s0, nb, rot, pos, cap_body, cap_points, box_body, box_frames, frames, sn, cs, caps, boxes)
        for c in range(n_caps):
            for r in range(3):
                start, end, centre = caps[6 * c + r], caps[6 * c + 3 + r], centres[3 * c + r]
                for b in range(nb):
                    centre[b] = 0.5 * (start[b] + end[b])
        for b in range(nb):
            upper[b] = np.inf
            lowest[b] = np.inf
            nearest[b] = 0
        # the bounds of every pair, and the least upper bound of each configuration
        for k in range(n_pairs):
            kind, i, j = pairs[k, 0], pairs[k, 1], pairs[k, 2]
            low = lower[k]
            level = floor[k] + offsets[k]
            if kind == 2:
                for b in range(nb):
                    low[b] = np.inf
                continue
            xi, yi, zi = centres[3 * i], centres[3 * i + 1], centres[3 * i + 2]
            if kind == 0:
                xj, yj, zj = centres[3 * j], centres[3 * j + 1], centres[3 * j + 2]
                ca, cb = caps[6 * i : 6 * i + 6], caps[6 * j : 6 * j + 6]
                gap = radii[i] + radii[j] + level
                reach_i, reach_j = half_length[i], half_length[j]
                inv_i, inv_j = inv_length_sq[i], inv_length_sq[j]
                for b in range(nb):
                    # each centre against the other segment
                    to_i = math.sqrt(_point_segment_sq(
                        xj[b], yj[b], zj[b], ca[0, b], ca[1, b], ca[2, b],
                        ca[3, b] - ca[0, b], ca[4, b] - ca[1, b], ca[5, b] - ca[2, b], inv_i,
                    ))
                    to_j = math.sqrt(_point_segment_sq(
                        xi[b], yi[b], zi[b], cb[0, b], cb[1, b], cb[2, b],
                        cb[3, b] - cb[0, b], cb[4, b] - cb[1, b], cb[5, b] - cb[2, b], inv_j,
                    ))
                    above = min(to_i, to_j) - gap
                    low[b] = max(to_i - reach_j, to_j - reach_i) - gap
                    upper[b] = min(upper[b], above)
            else:
                bx = boxes[12 * j : 12 * j + 12]
                hx, hy, hz = halves[j, 0], halves[j, 1], halves[j, 2]
                gap = radii[i] + level
                reach = half_length[i]
                for b in range(nb):
                    x, y, z = xi[b] - bx[9, b], yi[b] - bx[10, b], zi[b] - bx[11, b]
                    ex = _excess(bx[0, b] * x + bx[3, b] * y + bx[6, b] * z, hx)
                    ey = _excess(bx[1, b] * x + bx[4, b] * y + bx[7, b] * z, hy)
                    ez = _excess(bx[2, b] * x + bx[5, b] * y + bx[8, b] * z, hz)
                    e = math.sqrt(ex * ex + ey * ey + ez * ez)
                    above = e - gap
                    low[b] = above - reach if e > reach else -np.inf
                    upper[b] = min(upper[b], above)
        # the pairs that may be the closest, exactly, in pair order
        for k in range(n_pairs):
            kind, i, j = pairs[k, 0], pairs[k, 1], pairs[k, 2]
            if kind == 2:
                continue
            low = lower[k]
            m = 0
            for b in range(nb):
                lanes[m] = b
                m += 0 if low[b] - slack[k] > upper[b] else 1
            if m == 0:
                continue
            # whole SIMD lanes (copies of the last configuration): a loop's scalar remainder
            # costs as much as a vector step per configuration
            padded = min(-(-m // LANES) * LANES, BLOCK)
            for t in range(m, padded):
                lanes[t] = lanes[m - 1]
            ca = caps[6 * i : 6 * i + 6]
            if kind == 0:
                cb = caps[6 * j : 6 * j + 6]
                gap = radii[i] + radii[j] + offsets[k]
                _capsule_lanes(ca, cb, lanes, padded, gap, near_a, near_b, values)
            else:
                bx = boxes[12 * j : 12 * j + 12]
                hx, hy, hz = halves[j, 0], halves[j, 1], halves[j, 2]
                gap = radii[i] + offsets[k]
                _box_lanes(ca, bx, lanes, padded, hx, hy, hz, gap, near_a, near_box, values)
                # near or in the box: the scalar kernel's distance, in SIMD
                _near_box_lanes(
                    near_a, near_box, values, m, near_lanes, hx, hy, hz, radii[i], offsets[k], fixed, cap_rows, box_rows
                )
            for b in range(nb):
                dense[b] = np.inf
            for t in range(m):
                dense[lanes[t]] = values[t] - floor[k]
            for b in range(nb):  # in SIMD registers: a pair left out is at +inf
                closer = dense[b] < lowest[b]
                lowest[b] = dense[b] if closer else lowest[b]
                nearest[b] = k if closer else nearest[b]
        for b in range(nb):
            out_smallest[s0 + b] = lowest[b]
            out_closest[s0 + b] = nearest[b]
