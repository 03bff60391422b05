"""The jobs' clearance screen in one compiled pass: for each configuration the smallest excess of
a pair's signed distance over its floor, and its pair, computing only the pairs that bounds
from the shapes' centres leave as possibly the closest (:func:`jointlock.collision.
smallest_excess` calls it; :func:`clearance_smallest` says how).
"""

from __future__ import annotations

import math

import numpy as np

from ._clearance import _place_block
from ._common import BLOCK, _jit
from ._lanes import LANES, _box_lanes, _capsule_lanes, _excess, _point_segment_sq
from ._near_box import _near_box_lanes

#: :func:`clearance_smallest` leaves a pair out only when its lower bound exceeds the least
#: upper bound by more than its slack: this [m], plus :data:`PARALLEL_SLACK` of the pair's
#: longer segment, plus :data:`ROUND_OFF_SLACK` of the coordinates' and the floor's size, so
#: that the pair a computed distance makes the closest is never left out.
BOUND_SLACK_M = 1e-9
#: A capsule pair's computed distance may exceed the true one by up to this share of the
#: longer segment [-]: ``_lanes._segments_sq`` leaves out the interior critical point of
#: nearly parallel segments (``sin^2`` of their angle below 1e-14, so by at most 1e-7 of a
#: length).
PARALLEL_SLACK = 1e-6
#: The bounds' and the distances' round-off, as a share of the size of the coordinates, the
#: floors and the offsets [-] (some 450 units in the last place).
ROUND_OFF_SLACK = 1e-13


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
