"""Signed distances between capsules (a sphere is a capsule of zero length) and boxes, for a batch
of configurations (issue 27; :func:`jointlock.collision.clearance` is the public call).

Signed distance: the distance between two separate shapes, minus the penetration depth (the
length of the smallest translation that separates them) of two that overlap.  Both are exact:

* capsule-capsule: the distance ``delta`` between the segments (the smaller of the interior
  critical point, when it is one, and the four end-point-to-segment distances: robust for
  parallel segments) minus both radii; overlapping capsules have depth ``r1 + r2 - delta``,
  since the Minkowski difference of two segments is flat.
* capsule-box: in the box frame, the squared distance from the segment ``p + t d`` to the box is
  a convex piecewise quadratic in ``t`` with breakpoints where a coordinate crosses a face
  plane; each piece is minimised in closed form.  If the segment meets the box, the depth is
  that of the origin in the zonotope ``box (+) -segment`` (whose facet normals are among the
  box axes and their cross products with the segment, each tried with both signs) plus the
  radius.

Witness points (root frame): on shape 1 and on shape 2, with ``|w2 - w1| = |distance|``;
separate shapes give their closest points, overlapping ones the deepest point of shape 1 and
where it would have to go.
"""

from __future__ import annotations

import math

import numpy as np

from ._common import _jit

_TINY = 1e-300


@_jit
def _point_segment(px, py, pz, ax, ay, az, dx, dy, dz, dd):
    """Squared distance from point p to the segment a + t d (|d|^2 = dd), and t."""
    t = 0.0
    if dd > 0.0:
        t = ((px - ax) * dx + (py - ay) * dy + (pz - az) * dz) / dd
        t = min(max(t, 0.0), 1.0)
    ex = ax + t * dx - px
    ey = ay + t * dy - py
    ez = az + t * dz - pz
    return ex * ex + ey * ey + ez * ez, t


@_jit
def _capsule_capsule(c1, r1, c2, r2, w):
    """Signed distance of capsules c1 = (a, b) and c2 (6,) with radii r1, r2; witness points
    into w (2, 3)."""
    ax, ay, az = c1[0], c1[1], c1[2]
    dx, dy, dz = c1[3] - ax, c1[4] - ay, c1[5] - az
    bx, by, bz = c2[0], c2[1], c2[2]
    ex, ey, ez = c2[3] - bx, c2[4] - by, c2[5] - bz
    aa = dx * dx + dy * dy + dz * dz
    ee = ex * ex + ey * ey + ez * ez
    # the four end points against the other segment
    best, t2 = _point_segment(ax, ay, az, bx, by, bz, ex, ey, ez, ee)
    s1 = 0.0
    d2, t = _point_segment(ax + dx, ay + dy, az + dz, bx, by, bz, ex, ey, ez, ee)
    if d2 < best:
        best, s1, t2 = d2, 1.0, t
    d2, t = _point_segment(bx, by, bz, ax, ay, az, dx, dy, dz, aa)
    if d2 < best:
        best, s1, t2 = d2, t, 0.0
    d2, t = _point_segment(bx + ex, by + ey, bz + ez, ax, ay, az, dx, dy, dz, aa)
    if d2 < best:
        best, s1, t2 = d2, t, 1.0
    # the interior critical point, when both parameters are inside
    de = dx * ex + dy * ey + dz * ez
    denom = aa * ee - de * de
    if denom > 1e-14 * aa * ee and aa > 0.0 and ee > 0.0:
        fx, fy, fz = ax - bx, ay - by, az - bz
        df = dx * fx + dy * fy + dz * fz
        ef = ex * fx + ey * fy + ez * fz
        s = (de * ef - df * ee) / denom
        t = (aa * ef - de * df) / denom
        if 0.0 < s < 1.0 and 0.0 < t < 1.0:
            gx = ax + s * dx - bx - t * ex
            gy = ay + s * dy - by - t * ey
            gz = az + s * dz - bz - t * ez
            d2 = gx * gx + gy * gy + gz * gz
            if d2 < best:
                best, s1, t2 = d2, s, t
    px, py, pz = ax + s1 * dx, ay + s1 * dy, az + s1 * dz
    qx, qy, qz = bx + t2 * ex, by + t2 * ey, bz + t2 * ez
    delta = math.sqrt(best)
    gx, gy, gz = qx - px, qy - py, qz - pz
    gap = math.sqrt(gx * gx + gy * gy + gz * gz)
    scale = math.sqrt(max(aa, ee)) + abs(ax) + abs(ay) + abs(az)
    if gap > 1e-12 * scale:  # the witness points' own difference: above round-off
        nx, ny, nz = gx / gap, gy / gap, gz / gap
    else:  # the segments meet: any normal to both separates them
        nx, ny, nz = dy * ez - dz * ey, dz * ex - dx * ez, dx * ey - dy * ex
        norm = math.sqrt(nx * nx + ny * ny + nz * nz)
        if norm <= _TINY:
            nx, ny, nz = _any_normal(dx + ex, dy + ey, dz + ez)
        else:
            nx, ny, nz = nx / norm, ny / norm, nz / norm
    w[0, 0], w[0, 1], w[0, 2] = px + r1 * nx, py + r1 * ny, pz + r1 * nz
    w[1, 0], w[1, 1], w[1, 2] = qx - r2 * nx, qy - r2 * ny, qz - r2 * nz
    return delta - r1 - r2


@_jit
def _any_normal(x, y, z):
    """A unit vector normal to (x, y, z) (the x axis for a zero vector)."""
    norm = math.sqrt(x * x + y * y + z * z)
    if norm <= _TINY:
        return 1.0, 0.0, 0.0
    x, y, z = x / norm, y / norm, z / norm
    if abs(x) < 0.9:
        nx, ny, nz = 0.0, -z, y  # (1, 0, 0) x v
    else:
        nx, ny, nz = z, 0.0, -x  # (0, 1, 0) x v
    norm = math.sqrt(nx * nx + ny * ny + nz * nz)
    return nx / norm, ny / norm, nz / norm


@_jit
def _excess(x, h):
    if x > h:
        return x - h
    if x < -h:
        return x + h
    return 0.0


@_jit
def _capsule_box(c, r, box, half, w, work):
    """Signed distance of capsule c = (a, b) (6,) of radius r and the box (12,) = rotation
    (row-major 3 x 3: box axes as columns) then centre, with half extents half (3,); witness
    points (capsule, box) into w (2, 3); ``work`` (14,) scratch."""
    # segment in the box frame: p + t d
    ox, oy, oz = c[0] - box[9], c[1] - box[10], c[2] - box[11]
    vx, vy, vz = c[3] - c[0], c[4] - c[1], c[5] - c[2]
    p = work[0:3]
    d = work[3:6]
    for k in range(3):
        p[k] = box[k] * ox + box[3 + k] * oy + box[6 + k] * oz
        d[k] = box[k] * vx + box[3 + k] * vy + box[6 + k] * vz
    # breakpoints in (0, 1) where a coordinate crosses a face plane
    cuts = work[6:14]
    m = 0
    cuts[m] = 0.0
    m += 1
    for k in range(3):
        if d[k] != 0.0:
            for sign in (-1.0, 1.0):
                t = (sign * half[k] - p[k]) / d[k]
                if 0.0 < t < 1.0:
                    cuts[m] = t
                    m += 1
    cuts[m] = 1.0
    m += 1
    for i in range(1, m):  # insertion sort (at most 8)
        v = cuts[i]
        j = i - 1
        while j >= 0 and cuts[j] > v:
            cuts[j + 1] = cuts[j]
            j -= 1
        cuts[j + 1] = v
    best = np.inf
    t_best = 0.0
    for i in range(m - 1):
        t0, t1 = cuts[i], cuts[i + 1]
        tm = 0.5 * (t0 + t1)
        qa = 0.0
        qb = 0.0
        for k in range(3):
            x = p[k] + tm * d[k]
            if x > half[k] or x < -half[k]:
                off = p[k] - half[k] if x > half[k] else p[k] + half[k]
                qa += d[k] * d[k]
                qb += off * d[k]
        t = t0
        if qa > 0.0:
            t = min(max(-qb / qa, t0), t1)
        for tt in (t0, t, tm, t1):  # tm: exactly 0 on a piece inside the box (the ends are on faces up to round-off)
            f = 0.0
            for k in range(3):
                e = _excess(p[k] + tt * d[k], half[k])
                f += e * e
            if f < best:
                best, t_best = f, tt
    # closest points, box frame
    sx, sy, sz = p[0] + t_best * d[0], p[1] + t_best * d[1], p[2] + t_best * d[2]
    if best > 0.0:
        bx = min(max(sx, -half[0]), half[0])
        by = min(max(sy, -half[1]), half[1])
        bz = min(max(sz, -half[2]), half[2])
        delta = math.sqrt(best)
        nx, ny, nz = (bx - sx) / delta, (by - sy) / delta, (bz - sz) / delta
        cx, cy, cz = sx + r * nx, sy + r * ny, sz + r * nz
        signed = delta - r
    else:
        # the segment meets the box: depth of the origin in box (+) -segment, over the
        # candidate facet normals (box axes, their cross products with the segment)
        dn = math.sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2])
        mx, my, mz = p[0] + 0.5 * d[0], p[1] + 0.5 * d[1], p[2] + 0.5 * d[2]
        depth = np.inf
        nx, ny, nz = 1.0, 0.0, 0.0
        for cand in range(6):
            if cand < 3:
                ux, uy, uz = 0.0, 0.0, 0.0
                if cand == 0:
                    ux = 1.0
                elif cand == 1:
                    uy = 1.0
                else:
                    uz = 1.0
            else:
                if dn <= 0.0:
                    continue
                k = cand - 3  # e_k x d
                if k == 0:
                    ux, uy, uz = 0.0, -d[2], d[1]
                elif k == 1:
                    ux, uy, uz = d[2], 0.0, -d[0]
                else:
                    ux, uy, uz = -d[1], d[0], 0.0
                un = math.sqrt(ux * ux + uy * uy + uz * uz)
                if un <= 1e-12 * dn:
                    continue
                ux, uy, uz = ux / un, uy / un, uz / un
            spread = half[0] * abs(ux) + half[1] * abs(uy) + half[2] * abs(uz)
            spread += 0.5 * abs(ux * d[0] + uy * d[1] + uz * d[2])
            along = ux * mx + uy * my + uz * mz
            for sign in (1.0, -1.0):
                # translating the segment by (spread - sign * along) along sign * u separates it
                h = spread - sign * along
                if h < depth:
                    depth = h
                    nx, ny, nz = sign * ux, sign * uy, sign * uz
        # the segment's point deepest against n, the capsule's point behind it, and where that
        # point would have to go
        lead = nx * d[0] + ny * d[1] + nz * d[2]
        t_deep = 1.0 if lead < 0.0 else (0.0 if lead > 0.0 else 0.5)
        sx, sy, sz = p[0] + t_deep * d[0], p[1] + t_deep * d[1], p[2] + t_deep * d[2]
        cx, cy, cz = sx - r * nx, sy - r * ny, sz - r * nz
        signed = -(depth + r)
        bx, by, bz = cx - signed * nx, cy - signed * ny, cz - signed * nz
    # back to the root frame
    _to_root(box, cx, cy, cz, w, 0)
    _to_root(box, bx, by, bz, w, 1)
    return signed


@_jit
def _to_root(box, x, y, z, w, row):
    w[row, 0] = box[0] * x + box[1] * y + box[2] * z + box[9]
    w[row, 1] = box[3] * x + box[4] * y + box[5] * z + box[10]
    w[row, 2] = box[6] * x + box[7] * y + box[8] * z + box[11]


@_jit
def pair_distances(capsules, radii, boxes, halves, pairs, offsets, out_distance, out_closest, out_witness):
    """Signed distances of every pair for every configuration.

    Parameters
    ----------
    capsules
        (N, C, 6) capsule end points a, b per configuration [m].
    radii
        (C,) capsule radii [m].
    boxes
        (N, B, 12) box rotation (row-major) and centre per configuration [m].
    halves
        (B, 3) box half extents [m].
    pairs
        (P, 3) int64: kind (0 capsule-capsule, 1 capsule-box), index 1, index 2.
    offsets
        (P,) subtracted from each pair's signed distance [m] (a mounted pair's depth at the zero
        pose, :mod:`jointlock.collision`; 0 for the others).
    out_distance, out_closest, out_witness
        (N, P) signed distances [m], (N,) index of the closest pair (a mounted pair only when
        it is deeper than at the zero pose; 0 when no pair counts), (N, 2, 3) its witness points
        [m], written in place.
    """
    count = capsules.shape[0]
    w = np.empty((2, 3))
    work = np.empty(14)
    for n in range(count):
        lowest = np.inf
        closest = 0
        for k in range(pairs.shape[0]):
            kind, i, j = pairs[k, 0], pairs[k, 1], pairs[k, 2]
            if kind == 0:
                value = _capsule_capsule(capsules[n, i], radii[i], capsules[n, j], radii[j], w)
            else:
                value = _capsule_box(capsules[n, i], radii[i], boxes[n, j], halves[j], w, work)
            value -= offsets[k]
            out_distance[n, k] = value
            # a mounted pair (offset < 0) counts for the closest only when deeper than mounted
            rank = np.inf if offsets[k] < 0.0 and value >= 0.0 else value
            if rank < lowest:
                lowest = rank
                closest = k
                for a in range(2):
                    for b in range(3):
                        out_witness[n, a, b] = w[a, b]
        out_closest[n] = closest
