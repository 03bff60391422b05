"""Clearance: batched signed distances between an arm's links, its spacecraft bus and keep-out
volumes (SPEC piece 16, issue 27).

:func:`clearance` takes any batch of configurations (..., n) and returns, for each, the smallest
signed distance over the checked pairs (negative: the two shapes overlap by that much), which
pair it is, its witness points, and every pair's distance.

Which pairs are checked.  The shapes are those of the model's bodies (:mod:`jointlock.shapes`;
the built-in arms have capsules along their links and the bus box) and the keep-out volumes
given in the root frame.  Each shape remembers the link it was made for (its joint number in
the full arm, 0 for the root body), so the pairs are the same before and after a lock:

* two shapes of one rigid body (a locked joint's two links included) are never checked;
* adjacent links (``|i - j| = 1``, the root body being link 0) are never checked: a joint
  keeps them in contact by design;
* pairs that overlap at the full arm's zero pose (every joint at 0) are *mounted*: parts in
  contact by design (canadarm7's root lies inside the box of its spacecraft's mass and
  inertia; puma6's zero-length elbow joins its upper arm and forearm).  Each is measured from
  its depth there (its distance is how much less deep it is than at the zero pose: 0 as
  mounted, negative when it goes deeper) and is exempt from a clearance margin, so that a boom
  mounted on the bus's face is flagged when it swings into the bus, never for touching it;
  :attr:`Clearance.mounted` lists them;
* a keep-out volume is checked against every link but not the root body (both are fixed);
* pairs of shape names the model disables (:attr:`~jointlock.model.ArmModel.disabled_pairs`: an
  SRDF's ``<disable_collisions>``, read by :func:`jointlock.io.srdf.read_srdf`) are never checked.

Distances are exact for capsule-capsule (spheres included) and capsule-box pairs and are
computed by compiled kernels (:mod:`jointlock._kernels._clearance`, one pass over a batch),
tested against coal (hpp-fcl) to 1e-12 m, penetration included.  A pair with a convex hull (a
URDF mesh, :class:`~jointlock.shapes.Convex`) or of two boxes is computed by coal itself (GJK
and EPA to 1e-12, :mod:`jointlock._hull_distance`; the ``mesh`` extra), about 5 us per pair and
configuration.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from ._cache import cached_on
from ._chain import link_constants
from .bounds import MAX_LENGTH_M, as_real
from .errors import ConfigurationError, ModelError
from .forward import DEFAULT_CHUNK, chain_state
from .model import ArmModel, FloatArray, as_joint_array
from .shapes import Box, Capsule, Convex, Shape, Sphere, check_shapes

#: The link number keep-out volumes are given (checked against every link, not the root body).
KEEP_OUT_LINK = -1


@dataclass(frozen=True, eq=False)
class CollisionPairs:
    """The shapes of a model (and keep-outs) and the pairs checked between them.

    Attributes
    ----------
    capsule_body, box_body
        (C,), (B,) body of each capsule (spheres included) and box: -1 for the root body and
        keep-outs, ``i`` for the model's ``bodies[i]``.
    capsule_points, capsule_radii
        (C, 6) end points a, b in the body frame [m]; (C,) radii [m].
    box_poses, box_halves
        (B, 4, 4) box frames in the body frame; (B, 3) half extents [m].
    pairs
        (P, 3) int64: kind (0 capsule-capsule, 1 capsule-box, 2 a pair with a convex hull:
        indices into ``shapes``), index 1, index 2.
    names
        (P,) ``"link3 - bus"``: the two shapes' names.
    links
        (P, 2) the two shapes' links (full-arm joint numbers, 0 the root body, -1 a keep-out).
    offsets
        (P,) a mounted pair's signed distance at the full arm's zero pose [m] (< 0), from which
        it is measured; 0 for the others.
    keys
        (P,) each pair's shapes as ``(link, name, link, name)``.
    shape_body, shapes
        Every shape with its body (-1: the root body and keep-outs): capsules and spheres, then
        boxes, then convex hulls, so that index ``i`` of a capsule or box is its index here too
        plus ``C`` for a box (kind-2 pairs index them).
    """

    capsule_body: np.ndarray
    capsule_points: FloatArray
    capsule_radii: FloatArray
    box_body: np.ndarray
    box_poses: FloatArray
    box_halves: FloatArray
    pairs: np.ndarray
    names: tuple[str, ...]
    links: np.ndarray
    offsets: FloatArray = field(default_factory=lambda: np.zeros(0))
    keys: tuple[tuple[int, str, int, str], ...] = ()
    shape_body: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    shapes: tuple[Shape, ...] = ()

    @property
    def mounted(self) -> tuple[str, ...]:
        """The mounted pairs (in contact at the full arm's zero pose)."""
        return tuple(name for name, offset in zip(self.names, self.offsets) if offset < 0)


def _shape_name(shape: Shape) -> str:
    if shape.name:
        return shape.name
    return "root" if shape.link == 0 else f"link{shape.link}"


def _collect(model: ArmModel, keep_out: Sequence[Shape]) -> list[tuple[int, Shape]]:
    shapes: list[tuple[int, Shape]] = [(-1, s) for s in model.root_body.shapes]
    for i, body in enumerate(model.bodies):
        shapes += [(i, s) for s in body.shapes]
    for k, s in enumerate(keep_out):
        named = s if s.name else replace(s, name=f"keep_out{k + 1}")
        shapes.append((-1, replace(named, link=KEEP_OUT_LINK)))
    return shapes


def _checked(link_a: int, link_b: int, body_a: int, body_b: int) -> bool:
    if link_a == KEEP_OUT_LINK or link_b == KEEP_OUT_LINK:
        other = link_b if link_a == KEEP_OUT_LINK else link_a
        return other > 0
    if body_a == body_b:
        return False
    return abs(link_a - link_b) > 1


def _build(model: ArmModel, keep_out: Sequence[Shape], mounted: dict[tuple[int, str, int, str], float]) -> CollisionPairs:
    shapes = _collect(model, keep_out)
    capsules = [(b, s) for b, s in shapes if isinstance(s, (Capsule, Sphere))]
    boxes = [(b, s) for b, s in shapes if isinstance(s, Box)]
    hulls = [(b, s) for b, s in shapes if isinstance(s, Convex)]
    every = capsules + boxes + hulls
    pairs: list[tuple[int, int, int]] = []
    names: list[str] = []
    links: list[tuple[int, int]] = []
    keys: list[tuple[int, str, int, str]] = []
    offsets: list[float] = []
    seen: dict[tuple[int, str, int, str], int] = {}

    disabled = set(model.disabled_pairs)

    def add(kind: int, i: int, j: int, a: tuple[int, Shape], b: tuple[int, Shape]) -> None:
        la, lb = int(a[1].link), int(b[1].link)  # type: ignore[arg-type]
        if not _checked(la, lb, a[0], b[0]):
            return
        if tuple(sorted((_shape_name(a[1]), _shape_name(b[1])))) in disabled:
            return
        key = (la, _shape_name(a[1]), lb, _shape_name(b[1]))
        seen[key] = seen.get(key, 0) + 1
        if seen[key] > 1:  # two shapes of one name on a link: every pair keeps its own name
            key = (la, key[1], lb, f"{key[3]} #{seen[key]}")
        pairs.append((kind, i, j))
        names.append(f"{key[1]} - {key[3]}")
        links.append((la, lb))
        keys.append(key)
        offsets.append(mounted.get(key, 0.0))

    for i in range(len(capsules)):
        for j in range(i + 1, len(capsules)):
            add(0, i, j, capsules[i], capsules[j])
        for j in range(len(boxes)):
            add(1, i, j, capsules[i], boxes[j])
    # a pair with a convex hull (coal): indices into ``every``
    first_hull = len(capsules) + len(boxes)
    for h in range(len(hulls)):
        for other in range(first_hull + h):
            add(2, other, first_hull + h, every[other], every[first_hull + h])
    # two boxes of which one moves: coal as well (both fixed: never checked)
    for i in range(len(boxes)):
        for j in range(i + 1, len(boxes)):
            if boxes[i][0] >= 0 or boxes[j][0] >= 0:
                add(2, len(capsules) + i, len(capsules) + j, boxes[i], boxes[j])

    def points(s: Shape) -> list[float]:
        if isinstance(s, Sphere):
            return list(s.center) * 2
        return list(s.a) + list(s.b)  # type: ignore[union-attr]

    return CollisionPairs(
        capsule_body=np.array([b for b, _ in capsules], dtype=np.int64),
        capsule_points=np.array([points(s) for _, s in capsules], dtype=float).reshape(-1, 6),
        capsule_radii=np.array([s.radius for _, s in capsules], dtype=float),
        box_body=np.array([b for b, _ in boxes], dtype=np.int64),
        box_poses=np.array([s.pose for _, s in boxes], dtype=float).reshape(-1, 4, 4),
        box_halves=np.array([s.half_extents for _, s in boxes], dtype=float).reshape(-1, 3),
        pairs=np.array(pairs, dtype=np.int64).reshape(-1, 3),
        names=tuple(names),
        links=np.array(links, dtype=np.int64).reshape(-1, 2),
        offsets=np.array(offsets, dtype=float),
        keys=tuple(keys),
        shape_body=np.array([b for b, _ in every], dtype=np.int64),
        shapes=tuple(s for _, s in every),
    )


def _zero_pose_contacts(model: ArmModel) -> dict[tuple[int, str, int, str], float]:
    """The model's own pairs (no keep-outs) that overlap at the full arm's zero pose, with their
    signed distance there [m] (a pair touching at exactly 0 is mounted at -1e-12 m)."""
    full = model.unlocked if model.locked and model.unlocked is not None else model
    pairs = _build(full, (), {})
    if not len(pairs.names):
        return {}
    distance, _, _, _ = _distances(full, pairs, np.zeros((1, full.dof)), witness=False)
    return {key: min(float(d), -1e-12) for key, d in zip(pairs.keys, distance[0]) if d <= 0.0}


def collision_pairs(model: ArmModel, keep_out: Sequence[Shape] = ()) -> CollisionPairs:
    """The shapes and the pairs :func:`clearance` checks on ``model`` with ``keep_out`` volumes
    (shapes in the root frame); see the module for the rules."""
    keep = check_shapes(keep_out, "keep_out")
    if model.unread_meshes:
        more = f" (and {len(model.unread_meshes) - 1} more)" if len(model.unread_meshes) > 1 else ""
        raise ModelError(
            f"model {model.name!r}: its clearance needs the <collision> meshes its URDF names, and "
            f"{len(model.unread_meshes)} could not be read: {model.unread_meshes[0]}{more}; read them (the mesh extra, "
            "package_dirs), or leave them out on purpose (meshes='skip', --meshes skip: those links are then "
            "geometry-blind)"
        )
    mounted = cached_on(model, "zero_pose_contacts", lambda: _zero_pose_contacts(model))
    if not keep:
        return cached_on(model, "collision_pairs", lambda: _build(model, (), mounted))
    return _build(model, keep, mounted)


@dataclass(frozen=True, eq=False)
class _KernelShapes:
    """The chain and the shapes as :func:`jointlock._kernels._clearance.clearance_distances`
    takes them: link constants in ``z``-joint frames, shapes in those frames."""

    rot: FloatArray  # (n, 3, 3)
    pos: FloatArray  # (n, 3)
    capsule_points: FloatArray  # (C, 6)
    box_frames: FloatArray  # (B, 12)


def _kernel_shapes(model: ArmModel, pairs: CollisionPairs) -> _KernelShapes:
    # a link's z-joint frame is its body frame turned by Q (jointlock._chain.link_constants):
    # a point x of the body is Q^T x there
    links = link_constants(model, np.zeros(3))
    turn = [link.frame.T for link in links]
    points = pairs.capsule_points.copy()
    for c, body in enumerate(pairs.capsule_body):
        if body >= 0:
            points[c] = (turn[body] @ points[c].reshape(2, 3).T).T.ravel()
    frames = np.empty((pairs.box_halves.shape[0], 12))
    for k, body in enumerate(pairs.box_body):
        pose = pairs.box_poses[k]
        rot, centre = (pose[:3, :3], pose[:3, 3]) if body < 0 else (turn[body] @ pose[:3, :3], turn[body] @ pose[:3, 3])
        frames[k, :9], frames[k, 9:] = rot.ravel(), centre
    return _KernelShapes(
        rot=np.ascontiguousarray(np.array([link.rot for link in links], dtype=float).reshape(-1, 3, 3)),
        pos=np.ascontiguousarray(np.array([link.pos for link in links], dtype=float).reshape(-1, 3)),
        capsule_points=np.ascontiguousarray(points),
        box_frames=np.ascontiguousarray(frames),
    )


def unread_meshes_line(model: ArmModel) -> list[str]:
    """A summary's first line when the model's clearance could not be reported because meshes
    were not read (none otherwise)."""
    if not model.unread_meshes:
        return []
    return [
        f"CLEARANCE NOT CHECKED: {len(model.unread_meshes)} <collision> mesh(es) of the URDF could not be read "
        f"({model.unread_meshes[0]}); read them (the mesh extra, package_dirs) or leave them out on purpose "
        "(--meshes skip)"
    ]


def reports_clearance(model: ArmModel, keep_out: Sequence[Shape] = ()) -> bool:
    """Whether a result that only *reports* the clearance (an IK branch's, a re-plan's, a jump
    run's, a halt's with the clearance off) has one to report: the model has pairs to check and
    its meshes were read.  A model whose meshes could not be read reports none (the results say
    so); where the clearance is *required*, :func:`collision_pairs` refuses it naming them."""
    return not model.unread_meshes and bool(collision_pairs(model, keep_out).names)


def _kernel_inputs(model: ArmModel, pairs: CollisionPairs, q: FloatArray) -> tuple[np.ndarray, ...]:
    """The configurations, the chain and the shapes, as both clearance kernels take them first
    (:func:`jointlock._kernels._clearance.clearance_distances`)."""
    shapes = cached_on(pairs, "kernel_shapes", lambda: _kernel_shapes(model, pairs))
    return (
        np.ascontiguousarray(q, dtype=float),
        shapes.rot,
        shapes.pos,
        np.ascontiguousarray(pairs.capsule_body),
        shapes.capsule_points,
        np.ascontiguousarray(pairs.capsule_radii),
        np.ascontiguousarray(pairs.box_body),
        shapes.box_frames,
        np.ascontiguousarray(pairs.box_halves),
        np.ascontiguousarray(pairs.pairs),
        np.ascontiguousarray(pairs.offsets),
    )


def _distances(
    model: ArmModel, pairs: CollisionPairs, q: FloatArray, witness: bool = True
) -> tuple[FloatArray, FloatArray, np.ndarray, FloatArray]:
    """(N, P) signed distances (a mounted pair's from its zero-pose depth), (N,) the smallest
    (a mounted pair counting only when deeper than at the zero pose; +inf when none counts),
    (N,) its pair and (N, 2, 3) its witness points (NaN unless ``witness``) of configurations
    q (N, n), in one compiled pass (:mod:`jointlock._kernels._clearance`)."""
    from ._kernels._clearance import clearance_distances

    count = q.shape[0]
    n_pairs = pairs.pairs.shape[0]
    by_pair = np.empty((n_pairs, count))
    lowest = np.full(count, np.inf)
    closest = np.zeros(count, dtype=np.int64)
    points = np.zeros((count, 2, 3)) if witness else np.full((count, 2, 3), np.nan)
    if n_pairs and count:
        kernel: Callable[..., None] = clearance_distances  # numba's stubs type no *args
        kernel(
            *_kernel_inputs(model, pairs, q),
            witness,
            by_pair,
            lowest,
            closest,
            points,
        )
    hulls = np.flatnonzero(pairs.pairs[:, 0] == 2)
    if hulls.size and count:
        _hull_rows(model, pairs, q, hulls, witness, by_pair, lowest, closest, points)
    return by_pair.T, lowest, closest, points


def _smallest(model: ArmModel, pairs: CollisionPairs, q: FloatArray, floor: FloatArray) -> tuple[FloatArray, np.ndarray]:
    """(N,) the smallest ``d_p - floor[p]`` over the pairs of configurations q (N, n), and (N,)
    its pair (the first of equal ones; 0 when there is no pair): that of :func:`_distances`'
    distances, bit for bit, without computing every pair (:func:`jointlock._kernels._screen.
    clearance_smallest`; with a convex hull, from every pair's distance)."""
    from ._kernels._screen import clearance_smallest

    count = q.shape[0]
    if (pairs.pairs[:, 0] == 2).any():  # a convex hull: coal's distance, every pair
        excess = _distances(model, pairs, q, witness=False)[0] - floor
        return excess.min(axis=1), excess.argmin(axis=1)
    smallest = np.full(count, np.inf)
    closest = np.zeros(count, dtype=np.int64)
    if pairs.pairs.shape[0] and count:
        kernel: Callable[..., None] = clearance_smallest  # numba's stubs type no *args
        kernel(
            *_kernel_inputs(model, pairs, q),
            np.ascontiguousarray(floor, dtype=float),
            smallest,
            closest,
        )
    return smallest, closest


def _hull_rows(
    model: ArmModel,
    pairs: CollisionPairs,
    q: FloatArray,
    rows: np.ndarray,
    witness: bool,
    by_pair: FloatArray,
    lowest: FloatArray,
    closest: np.ndarray,
    points: FloatArray,
) -> None:
    """The pairs with a convex hull (``rows``, computed by coal), written into the kernel's
    results in place: their distances, and the closest pair and its witness points where one
    of them is closer."""
    from ._hull_distance import hull_pair_distances

    count = q.shape[0]
    distance = np.empty((len(rows), count))
    hull_witness = np.empty((len(rows), count, 2, 3))
    for start in range(0, count, DEFAULT_CHUNK):  # bounded memory: frames of a chunk at a time
        stop = min(start + DEFAULT_CHUNK, count)
        state = chain_state(model, q[start:stop]) if model.dof else None
        part, points_part = hull_pair_distances(
            pairs.shapes,
            pairs.shape_body,
            pairs.pairs[rows, 1:],
            None if state is None else state.rotations,
            None if state is None else state.positions,
            with_witness=witness,
        )
        distance[:, start:stop] = part
        hull_witness[:, start:stop] = points_part
    offsets = pairs.offsets[rows]
    distance = distance - offsets[:, None]
    by_pair[rows] = distance
    rank = np.where((offsets[:, None] < 0) & (distance >= 0.0), np.inf, distance)
    best = np.argmin(rank, axis=0)
    nearer = rank[best, np.arange(q.shape[0])] < lowest
    lowest[nearer] = rank[best[nearer], np.flatnonzero(nearer)]
    closest[nearer] = rows[best[nearer]]
    if witness:
        points[nearer] = hull_witness[best[nearer], np.flatnonzero(nearer)]


@dataclass(frozen=True, eq=False)
class Clearance:
    """Signed distances of a batch of configurations (:func:`clearance`).

    Attributes
    ----------
    distance
        (...,) smallest signed distance over the checked pairs [m]; negative: overlap.  A mounted
        pair counts only when it is deeper than at the zero pose (then by how much deeper).
        +inf when no pair counts.
    closest
        (...,) index into ``names`` of the pair that gives it.
    witness
        (..., 2, 3) points on its two shapes, root frame [m]: the closest points of separate
        shapes, the deepest point of the first and where it would have to go for overlapping
        ones (``|w[1] - w[0]|`` is the raw distance, a mounted pair's too); NaN when
        :func:`clearance` was asked for the distances only (``witness=False``).
    pair_distance
        (..., P) every checked pair's signed distance [m] (a mounted pair's from its depth at the
        zero pose).
    names
        (P,) the checked pairs, ``"link3 - bus"``.
    mounted_pairs
        (P,) True for the mounted pairs (in contact at the full arm's zero pose): exempt from
        the margin, they must not go deeper than there.
    margin
        The clearance required of the other pairs [m] (:meth:`colliding`).
    """

    distance: FloatArray
    closest: np.ndarray
    witness: FloatArray
    pair_distance: FloatArray
    names: tuple[str, ...]
    mounted_pairs: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=bool))
    margin: float = 0.0

    @property
    def mounted(self) -> tuple[str, ...]:
        """The names of the mounted pairs."""
        return tuple(n for n, m in zip(self.names, self.mounted_pairs) if m)

    def pair_at(self, index: tuple[int, ...] = ()) -> str:
        """The name of the closest pair of the configuration at ``index``."""
        return self.names[int(self.closest[index])] if self.names else ""

    def shortfall(self, margin: float | None = None) -> FloatArray:
        """(..., P) by how much [m] each pair comes closer than allowed: ``margin`` (default the
        result's) for most pairs, 0 for a mounted one (no deeper than at the zero pose); <= 0:
        allowed."""
        margin = self.margin if margin is None else check_clearance_m(margin, "margin")
        return np.where(self.mounted_pairs, 0.0, margin) - self.pair_distance

    def colliding(self, margin: float | None = None) -> np.ndarray:
        """(...,) True where a pair comes closer than allowed (:meth:`shortfall`)."""
        if not self.names:
            return np.zeros(self.distance.shape, dtype=bool)
        return np.asarray(np.any(self.shortfall(margin) > 0, axis=-1))

    def worst(self) -> tuple[int, ...]:
        """Index of the configuration with the smallest clearance (``()`` for one configuration
        or none)."""
        if self.distance.size == 0 or self.distance.ndim == 0:
            return ()
        return tuple(int(i) for i in np.unravel_index(int(np.argmin(self.distance)), self.distance.shape))

    def summary(self) -> str:
        """One line: the smallest clearance, the pair and, for a batch, how many come closer than
        allowed."""
        if not self.names:
            return "clearance: no pair checked (the model has no collision shapes)"
        if self.distance.size == 0:
            return f"clearance: no configuration ({len(self.names)} pairs checked)"
        at = self.worst()
        d = float(self.distance[at])
        verdict = "COLLIDES" if d < 0 else ("below the margin" if bool(self.colliding()[at]) else "clear")
        text = f"clearance {d:+.4f} m ({self.pair_at(at)}): {verdict}"
        if self.margin:
            text += f" (margin {self.margin:g} m)"
        if self.distance.size > 1:
            below = int(np.count_nonzero(self.colliding()))
            text = f"smallest {text}; {below} of {self.distance.size} configurations closer than allowed"
        return text

    def to_dict(self) -> dict[str, Any]:
        """Plain data: the smallest clearance [m], its pair and witness points, each pair's
        smallest distance, the margin and how many configurations come closer than allowed."""
        base = {"checked_pairs": list(self.names), "mounted_pairs": list(self.mounted), "margin_m": self.margin}
        if not self.names or not self.distance.size:
            return {**base, "min_clearance_m": None, "configurations": int(self.distance.size)}
        at = self.worst()
        flat = self.pair_distance.reshape(-1, len(self.names))
        return {
            **base,
            "min_clearance_m": float(self.distance[at]),
            "closest_pair": self.pair_at(at),
            "witness_points_m": self.witness[at].tolist() if np.all(np.isfinite(self.witness[at])) else None,
            "configurations": int(self.distance.size),
            "closer_than_allowed": int(np.count_nonzero(self.colliding())),
            "pair_min_clearance_m": {name: float(v) for name, v in zip(self.names, flat.min(axis=0))},
        }


def check_clearance_m(value: object, name: str) -> float:
    """``value`` as a clearance [m]: a real number (numpy's too), finite, >= 0, at most
    :data:`~jointlock.bounds.MAX_LENGTH_M`; a :class:`~jointlock.errors.ConfigurationError`
    naming ``name`` otherwise."""
    return as_real(value, name, lo=0.0, hi=MAX_LENGTH_M, unit="m", error=ConfigurationError)


def clearance(
    model: ArmModel, q: ArrayLike, *, keep_out: Sequence[Shape] = (), margin: float = 0.0, witness: bool = True
) -> Clearance:
    """Signed distances of configurations ``q`` (..., n) [rad] between the arm's links, its
    spacecraft bus and the ``keep_out`` volumes (shapes in the root frame).

    Parameters
    ----------
    model
        The arm (locked or not) with collision shapes on its bodies.
    q
        (..., n) joint angles of its movable joints [rad].
    keep_out
        Shapes in the root frame (a docked vehicle, a solar array, a payload).
    margin
        The clearance required [m] (``clearance_min_m``), kept on the result for
        :meth:`Clearance.colliding` and the summary.
    witness
        Whether to compute the closest pair's witness points; False leaves them NaN (a batch
        screened for its distances only: about a quarter less time).

    Returns
    -------
    Clearance
        Negative distances are penetration depths; see the module for the pairs checked.
    """
    q = as_joint_array(model, q)
    margin = check_clearance_m(margin, "margin")
    if not isinstance(witness, (bool, np.bool_)):
        raise ConfigurationError(f"witness must be True or False; got {witness!r}")
    pairs = collision_pairs(model, keep_out)
    batch = q.shape[:-1]
    distance, smallest, closest, points = _distances(model, pairs, q.reshape(-1, model.dof), witness)
    return Clearance(
        distance=smallest.reshape(batch),
        closest=closest.reshape(batch),
        witness=points.reshape(batch + (2, 3)),
        pair_distance=distance.reshape(batch + (distance.shape[1],)),
        names=pairs.names,
        mounted_pairs=pairs.offsets < 0,
        margin=margin,
    )


#: Default clearance a job requires [m]: 5 cm between the collision shapes (which are envelopes
#: already: the built-in arms' capsules are twice the radius their inertias imply), so that a
#: recommended halt configuration does not graze the bus; a scenario sets it with
#: ``limits.clearance_min_m`` (``limits.check_clearance = false``: reported only).
DEFAULT_CLEARANCE_MIN_M = 0.05


def smallest_excess(
    model: ArmModel, q: ArrayLike, floor: ArrayLike, *, keep_out: Sequence[Shape] = ()
) -> tuple[FloatArray, np.ndarray]:
    """How far each configuration keeps its pairs above their floors, without every pair's
    distance: the jobs' screens.

    Parameters
    ----------
    model
        The arm.
    q
        (..., n) joint angles [rad].
    floor
        (P,) the distance each checked pair must keep [m] (:func:`margin_floor` for a margin;
        the pairs are those of :attr:`Clearance.names`).
    keep_out
        Keep-out volumes in the root frame.

    Returns
    -------
    excess, pair
        (...,) the smallest ``pair_distance - floor`` over the pairs [m] (negative: a pair comes
        closer than its floor; +inf without pairs) and (...,) its pair: those of
        :func:`clearance`'s ``pair_distance``, bit for bit.  Pairs that cannot be the closest
        (bounded from their shapes' centres) are not computed: a fraction of the time.
    """
    q = as_joint_array(model, q)
    pairs = collision_pairs(model, keep_out)
    floor = np.asarray(floor, dtype=float)
    if floor.shape != (len(pairs.names),):
        raise ConfigurationError(
            f"floor must be one distance [m] per checked pair, shape ({len(pairs.names)},); got shape {floor.shape}"
        )
    if not np.all(np.isfinite(floor)):
        raise ConfigurationError(f"floor must be finite [m]; got {floor[~np.isfinite(floor)][0]} (pair {pairs.names[int(np.argmin(np.isfinite(floor)))]})")
    smallest, closest = _smallest(model, pairs, q.reshape(-1, model.dof), floor)
    return smallest.reshape(q.shape[:-1]), closest.reshape(q.shape[:-1])


def margin_floor(model: ArmModel, margin: float, keep_out: Sequence[Shape] = ()) -> FloatArray:
    """(P,) the floor of each checked pair under a clearance ``margin`` [m]: the margin, 0 for a
    mounted pair (as :meth:`Clearance.shortfall`)."""
    margin = check_clearance_m(margin, "margin")
    return np.where(collision_pairs(model, keep_out).offsets < 0, 0.0, margin)


@dataclass(frozen=True, eq=False)
class ClearanceSettings:
    """What a job requires of clearance (one typed setting, like the limits).

    Attributes
    ----------
    min_m
        The clearance required [m] between the arm's links, its spacecraft bus and the keep-out
        volumes; None: not checked as a constraint (a paper's own way; results still report
        the clearance).
    keep_out
        Keep-out volumes, shapes in the root frame (:mod:`jointlock.shapes`).
    """

    min_m: float | None = DEFAULT_CLEARANCE_MIN_M
    keep_out: tuple[Shape, ...] = ()

    def __post_init__(self) -> None:
        if self.min_m is not None:
            object.__setattr__(self, "min_m", check_clearance_m(self.min_m, "clearance min_m"))
        object.__setattr__(self, "keep_out", check_shapes(self.keep_out, "keep_out"))

    @classmethod
    def off(cls, keep_out: Sequence[Shape] = ()) -> ClearanceSettings:
        """Clearance reported, not required (the papers' way)."""
        return cls(min_m=None, keep_out=keep_out)  # type: ignore[arg-type]

    @property
    def required(self) -> bool:
        """Whether the clearance is a constraint."""
        return self.min_m is not None

    @property
    def margin(self) -> float:
        """The clearance a result is judged against [m] (0 when not required)."""
        return 0.0 if self.min_m is None else self.min_m

    def to_dict(self) -> dict[str, Any]:
        """Plain data: the clearance required [m] (None: reported only) and the keep-outs."""
        return {"min_m": self.min_m, "keep_out": [s.to_dict() for s in self.keep_out]}
