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
   configuration, :mod:`jointlock._kernels._lanes`): capsule-capsule as in
   ``_distance._capsule_capsule``, capsule-box from the derivative of the squared distance
   along the segment;
3. a capsule-box pair whose segment comes within
   :data:`~jointlock._kernels._lanes.NEAR_BOX_M` of the box (touching or overlapping: the
   penetration depth is a different computation) is computed again, those configurations side
   by side, by a branch-free copy of the scalar kernel's distance
   (:mod:`jointlock._kernels._near_box`: the same bits as ``_distance._capsule_box``), and the
   closest pair of each configuration gets its witness points from the scalar kernels (when
   asked).

The jobs' screens, which need only the closest pair's excess over its floor, place the shapes
as here (:func:`_place_block`) and compute only the pairs that may be the closest
(:mod:`jointlock._kernels._screen`).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ._arm import _advance, _identity_frames
from ._common import BLOCK, _jit, _trig_block
from ._distance import _capsule_box, _capsule_capsule
from ._lanes import _box_lane, _capsule_lane
from ._near_box import _near_box_lanes

_inline = njit(inline="always", cache=True, error_model="numpy", nogil=True)


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
