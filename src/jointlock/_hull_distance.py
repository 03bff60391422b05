"""Signed distances of pairs with a convex hull (a mesh's envelope, :class:`jointlock.shapes.
Convex`) and of two boxes, computed with coal (hpp-fcl: GJK, and EPA for the penetration depth), one pair and
one configuration at a time (:func:`jointlock.collision.clearance` calls it for its kind-2
pairs; the primitives' pairs go through the compiled kernels).

coal comes with the ``mesh`` extra (``pip install 'jointlock[mesh]'``); without it such a pair
is refused in one line when a distance is asked of it.

Tolerances: GJK and EPA to 1e-12 (coal's defaults, 1e-6 relative, would put a clearance's
sixth digit in doubt).  Cost: a few microseconds per pair and configuration (a Python call each).
"""

from __future__ import annotations

import weakref
from collections.abc import Sequence
from typing import Any

import numpy as np

from .errors import ModelError
from .shapes import Box, Capsule, Convex, FloatArray, Shape, Sphere

#: GJK's and EPA's stopping tolerance [m].
HULL_TOLERANCE = 1e-12

# coal's geometry of each shape, built once (a hull's Qhull and its triangles) and dropped with
# the shape; not stored on the shape itself, which pickles (coal's objects do not)
_GEOMETRY: weakref.WeakKeyDictionary[Any, tuple[Any, FloatArray]] = weakref.WeakKeyDictionary()


def import_coal(what: str) -> Any:
    """coal, or a :class:`~jointlock.errors.ModelError` naming ``what`` needs it."""
    try:
        import coal
    except ImportError:
        raise ModelError(
            f"{what} needs coal for its distances (convex hulls of meshes): pip install 'jointlock[mesh]'"
        ) from None
    return coal


def _geometry(coal: Any, shape: Shape) -> tuple[Any, FloatArray]:
    """coal's geometry of ``shape`` and its frame (4, 4) in the body frame."""
    if isinstance(shape, Sphere):
        frame = np.eye(4)
        frame[:3, 3] = shape.center
        return coal.Sphere(shape.radius), frame
    if isinstance(shape, Capsule):
        if shape.length == 0:
            frame = np.eye(4)
            frame[:3, 3] = shape.a
            return coal.Sphere(shape.radius), frame
        return coal.Capsule(shape.radius, shape.length), shape.frame
    if isinstance(shape, Box):
        return coal.Box(*(2.0 * shape.half_extents)), np.array(shape.pose)
    assert isinstance(shape, Convex)
    from scipy.spatial import ConvexHull

    hull = ConvexHull(shape.vertices)
    index = {int(v): k for k, v in enumerate(hull.vertices)}
    points = coal.StdVec_Vec3s()
    for v in hull.vertices:
        points.append(np.array(shape.vertices[v], dtype=float))
    triangles = coal.StdVec_Triangle()
    for a, b, c in hull.simplices:
        triangles.append(coal.Triangle(index[int(a)], index[int(b)], index[int(c)]))
    return coal.Convex(points, triangles), np.array(shape.pose)


def hull_pair_distances(
    shapes: Sequence[Shape],
    shape_body: np.ndarray,
    pairs: np.ndarray,
    rotations: FloatArray | None,
    positions: FloatArray | None,
    with_witness: bool = True,
) -> tuple[FloatArray, FloatArray]:
    """Signed distances and witness points of shape pairs over a batch of configurations.

    Parameters
    ----------
    shapes, shape_body
        (G,) the shapes (in their body's frame) and their bodies (-1: the root frame).
    pairs
        (K, 2) int: the two shapes of each pair.
    rotations, positions
        (N, n, 3, 3), (N, n, 3) every body's frame in the root frame [m] (None: no movable body).
    with_witness
        Whether to return the witness points (NaN otherwise).

    Returns
    -------
    distance, witness
        (K, N) signed distances [m] (negative: penetration depth) and (K, N, 2, 3) the points on
        the two shapes, root frame [m] (``|w[1] - w[0]| = |distance|``).
    """
    first = shapes[int(pairs[0][1])] if len(pairs) else None
    coal = import_coal(f"{type(first).__name__.lower()} {getattr(first, 'name', '')!r} (a mesh's hull, or a box facing a box)")
    count = 1 if rotations is None else rotations.shape[0]
    geometry = []
    for shape in shapes:
        if shape not in _GEOMETRY:
            _GEOMETRY[shape] = _geometry(coal, shape)
        geometry.append(_GEOMETRY[shape])
    request = coal.DistanceRequest()
    request.enable_signed_distance = True
    request.gjk_tolerance = HULL_TOLERANCE
    request.epa_tolerance = HULL_TOLERANCE
    result = coal.DistanceResult()
    distance = np.empty((len(pairs), count))
    witness = np.empty((len(pairs), count, 2, 3)) if with_witness else np.full((len(pairs), count, 2, 3), np.nan)
    # every shape's frame in the root frame, for every configuration, in one numpy pass each
    world: dict[int, tuple[FloatArray, FloatArray]] = {}
    for g in {int(x) for x in np.asarray(pairs).ravel()}:
        frame, body = geometry[g][1], int(shape_body[g])
        if body < 0 or rotations is None or positions is None:
            world[g] = (np.broadcast_to(frame[:3, :3], (count, 3, 3)), np.broadcast_to(frame[:3, 3], (count, 3)))
        else:
            world[g] = (rotations[:, body] @ frame[:3, :3], rotations[:, body] @ frame[:3, 3] + positions[:, body])
    first, second = coal.Transform3s(), coal.Transform3s()
    for k, (i, j) in enumerate(pairs):
        compute = coal.ComputeDistance(geometry[i][0], geometry[j][0])
        (rot_i, pos_i), (rot_j, pos_j) = world[int(i)], world[int(j)]
        for n in range(count):
            first.setRotation(rot_i[n])
            first.setTranslation(pos_i[n])
            second.setRotation(rot_j[n])
            second.setTranslation(pos_j[n])
            result.clear()
            compute(first, second, request, result)
            distance[k, n] = result.min_distance
            if with_witness:
                witness[k, n, 0] = result.getNearestPoint1()
                witness[k, n, 1] = result.getNearestPoint2()
    return distance, witness
