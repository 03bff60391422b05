"""Clearance between the samples of a motion: a certified lower bound, so that nothing tunnels
(issue 27, item 3: "a bound on how far any point can move between samples").

:func:`jointlock.collision.clearance` measures a motion at its samples only; a thin link moving
fast could pass through another, or through the bus, between two of them.  This module bounds
how far the shapes of a pair can move relative to each other between two samples and turns the
two sampled distances into a lower bound of the distance over the whole interval:

* **How far a shape moves.**  A point ``p`` of link ``b`` moves, relative to link ``a < b``, only
  by the joints between them; joint ``i`` turns it about an axis through its frame's origin
  ``o_i``, at a speed of at most ``|dq_i| |p - o_i|``.  For a serial chain of revolute joints
  (:class:`jointlock.model.ArmModel`) ``|p - o_i| <= R_ib``: the lengths of the joint placements
  from ``i`` to ``b`` plus the farthest point of the shape in its body's frame (a capsule's far
  end plus its radius, a box's centre plus its half diagonal).  ``R_ib`` does not depend on the
  configuration, so the (P, n) matrix of these reaches [m/rad] (:func:`pair_reach`) is computed
  once per model.  The bus and the keep-out volumes are fixed in the root frame, which is where
  distances are taken, so a free-floating base changes nothing.
* **How far a joint turns.**  Between samples ``t0 < t1`` (``h = t1 - t0``) joint ``i`` turns by
  at most ``h max(|dq_i(t0)|, |dq_i(t1)|) + A_i h^2 / 4`` [rad] (:func:`joint_travel`), with
  ``A_i`` the largest sampled ``|ddq_i|`` of the motion.  (The sampled acceleration stands for
  the largest one: for the halt's polynomials on 2,001 samples the difference is of the third
  order in ``h``.)
* **The bound.**  The signed distance of two convex shapes changes by at most how far one moves
  relative to the other (it is a difference of support functions), so over the interval it is at
  least ``(d(t0) + d(t1) - D) / 2``, ``D`` the pair's relative travel (the smaller of the two
  straight lines from the ends meeting at the lowest point).

The acceleration bound grows with the refined samples' accelerations as they come.  An interval
whose bound falls more than ``tolerance`` below the distance a pair must keep (``floor``) is cut
into :data:`SUBDIVISIONS` pieces, the motion evaluated at the new samples, and
so on, at most :data:`MAX_DEPTH` times; what is left then is reported as it stands (a bound,
not proven clear).  Most intervals of a halt are far from their floor and never refined.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from ._cache import cached_on
from .collision import CollisionPairs, clearance, collision_pairs
from .errors import ConfigurationError
from .model import ArmModel, FloatArray
from .shapes import Convex, Shape

#: How far below the distance a pair must keep its certified bound between samples may fall
#: [m] before the interval is refined, and the most by which an accepted motion can come closer
#: than its samples show: 1 mm, small against the 5 cm clearance jobs require by default.
TUNNEL_TOLERANCE_M = 1e-3
#: Pieces an interval is cut into when it is refined.
SUBDIVISIONS = 8
#: Times an interval is refined at most (8^4 = 4,096 times finer than the grid).
MAX_DEPTH = 4
#: Most new samples one motion may ask for; beyond, the bound is reported as it stands.
MAX_REFINED_SAMPLES = 200_000
#: Round-off allowed to a sample against its pair's floor [m]: a pair in contact at the start
#: (its floor its own distance then) is not "closer" for a nanometre of floating point.
ROUND_OFF_M = 1e-9

#: A motion: (n_t,) times [s] -> q, dq, ddq, each (n_t, n) [rad, rad/s, rad/s^2].
Motion = Callable[[FloatArray], tuple[FloatArray, FloatArray, FloatArray]]


def _extent(points: FloatArray, radius: float) -> float:
    return float(max(np.linalg.norm(points[:3]), np.linalg.norm(points[3:]))) + radius


def pair_reach(model: ArmModel, pairs: CollisionPairs | None = None) -> FloatArray:
    """(P, n) how fast [m/rad] each checked pair's shapes can approach each other per radian
    of each movable joint: ``R_ib`` of the module for the joints between the pair's two bodies,
    0 for the others.  ``pairs`` default: the model's own (:func:`~jointlock.collision.
    collision_pairs`, no keep-outs)."""
    pairs = collision_pairs(model) if pairs is None else pairs
    lengths = np.array([float(np.linalg.norm(j.placement[:3, 3])) for j in model.joints])
    cap_extent = [_extent(p, float(r)) for p, r in zip(pairs.capsule_points, pairs.capsule_radii)]
    box_extent = [
        float(np.linalg.norm(pose[:3, 3]) + np.linalg.norm(half)) for pose, half in zip(pairs.box_poses, pairs.box_halves)
    ]
    # in the order of pairs.shapes: capsules, boxes, then convex hulls (a kind-2 pair's indices;
    # a capsule-box pair's box is its index after the capsules)
    extents = cap_extent + box_extent + [s.extent for s in pairs.shapes if isinstance(s, Convex)]
    reach = np.zeros((len(pairs.pairs), model.dof))
    for p, (kind, first, second) in enumerate(pairs.pairs):
        shapes = (first, second + len(cap_extent) if kind == 1 else second)
        ends = [(int(pairs.shape_body[g]), extents[g]) for g in shapes]
        (low, _), (body, extent) = sorted(ends)
        for i in range(low + 1, body + 1):
            # joint i turns the outer shape about an axis through o_i, at most this far from it
            reach[p, i] = float(lengths[i + 1 : body + 1].sum()) + extent
    return reach


def joint_travel(dq_start: FloatArray, dq_end: FloatArray, accel_max: FloatArray, h: FloatArray) -> FloatArray:
    """(m, n) the most each joint can turn [rad] over intervals of length ``h`` (m,) [s] with
    the speeds ``dq_start``, ``dq_end`` (m, n) [rad/s] at their ends and accelerations of at most
    ``accel_max`` (n,) [rad/s^2] (see the module)."""
    h = np.asarray(h, dtype=float)[:, None]
    return h * np.maximum(np.abs(dq_start), np.abs(dq_end)) + accel_max * h**2 / 4.0


@dataclass(frozen=True)
class SweptClearance:
    """The clearance of a motion between its samples (:func:`swept_clearance`).

    Attributes
    ----------
    lower_bound
        (P,) a lower bound of each pair's signed distance over the whole motion [m] (for a
        mounted pair, as :class:`~jointlock.collision.Clearance` measures it).
    lower_bound_time
        (P,) the middle of the interval that gives it [s].
    sampled_min
        (P,) each pair's smallest distance on the samples, the refined ones included [m].
    grid_min
        (P,) the same on the samples given (``t``) only [m].
    floor
        (P,) the distance each pair must keep [m].
    names
        (P,) the pairs.
    tolerance
        [m] how far below ``floor`` a bound may fall between samples (:data:`TUNNEL_TOLERANCE_M`).
    samples, refined_samples
        Samples of the motion given, and added by the refinement.
    """

    lower_bound: FloatArray
    lower_bound_time: FloatArray
    sampled_min: FloatArray
    grid_min: FloatArray
    floor: FloatArray
    names: tuple[str, ...]
    tolerance: float
    samples: int
    refined_samples: int

    @property
    def sampled_shortfall(self) -> float:
        """The most by which a sample comes closer than its pair's floor [m]: a sample given
        exactly, a refined one beyond :data:`ROUND_OFF_M` (<= 0: none)."""
        if not self.names:
            return -np.inf
        return float(max((self.floor - self.grid_min).max(), (self.floor - ROUND_OFF_M - self.sampled_min).max()))

    @property
    def shortfall(self) -> float:
        """The most by which the motion may come closer than allowed [m]: on a sample, or between
        samples by more than ``tolerance``; <= 0: the whole motion keeps the clearance."""
        if not self.names:
            return -np.inf
        between = float((self.floor - self.tolerance - self.lower_bound).max())
        return max(self.sampled_shortfall, between)

    @property
    def certified(self) -> bool:
        """Whether the whole motion, between samples too, keeps the clearance (``shortfall <= 0``)."""
        return self.shortfall <= 0.0

    def worst(self) -> int:
        """The pair whose bound falls furthest below its floor."""
        return int(np.argmax(self.floor - self.lower_bound))

    def to_dict(self) -> dict[str, Any]:
        """Plain data: the smallest bound [m], its pair and time, whether the motion is certified
        clear between its samples, the tolerance and the samples."""
        if not self.names:
            return {"lower_bound_m": None, "certified": True, "tolerance_m": self.tolerance}
        p = self.worst()
        return {
            "lower_bound_m": float(self.lower_bound[p]),
            "lower_bound_pair": self.names[p],
            "lower_bound_time_s": float(self.lower_bound_time[p]),
            "certified": self.certified,
            "tolerance_m": self.tolerance,
            "samples": self.samples,
            "refined_samples": self.refined_samples,
        }


def swept_clearance(
    model: ArmModel,
    motion: Motion,
    t: ArrayLike,
    floor: ArrayLike,
    *,
    keep_out: Sequence[Shape] = (),
    tolerance: float = TUNNEL_TOLERANCE_M,
    max_depth: int = MAX_DEPTH,
    sampled: tuple[FloatArray, FloatArray, FloatArray, FloatArray] | None = None,
) -> SweptClearance:
    """A certified lower bound of every pair's clearance over a continuous motion (see the module).

    Parameters
    ----------
    model
        The arm, with collision shapes (:mod:`jointlock.shapes`).
    motion
        (n_t,) times [s] -> q, dq, ddq (n_t, n) [rad, rad/s, rad/s^2], at any time of ``t``'s span.
    t
        (n_t,) increasing sample times [s], at least 2.
    floor
        (P,) the distance each pair must keep [m] (e.g. the clearance required, 0 for a mounted
        pair, or the pair's distance at the start when it starts closer); decides where to refine.
    keep_out
        Keep-out volumes (shapes in the root frame).
    tolerance, max_depth
        See :data:`TUNNEL_TOLERANCE_M` and :data:`MAX_DEPTH`.
    sampled
        ``(q, dq, ddq, distances)`` already computed at ``t`` (distances (n_t, P) [m]), to save
        computing them again.

    Returns
    -------
    SweptClearance
    """
    t = np.asarray(t, dtype=float)
    pairs = collision_pairs(model, keep_out)
    floor = np.broadcast_to(np.asarray(floor, dtype=float), (len(pairs.names),))
    if sampled is None:
        q, dq, ddq = motion(t)
        distance = clearance(model, q, keep_out=keep_out, witness=False).pair_distance
    else:
        q, dq, ddq, distance = sampled
    _check_finite(t, dq, ddq, distance)
    reach = pair_reach(model, pairs) if keep_out else cached_on(model, "pair_reach", lambda: pair_reach(model, pairs))
    accel = np.abs(ddq).max(axis=0)
    lower = distance.min(axis=0)
    lower_time = t[np.argmin(distance, axis=0)]
    sampled_min = lower.copy()
    start_t, end_t = t[:-1], t[1:]
    start_v, end_v = dq[:-1], dq[1:]
    start_d, end_d = distance[:-1], distance[1:]
    refined = 0
    for depth in range(max_depth + 1):
        h = end_t - start_t
        bound = 0.5 * (start_d + end_d - joint_travel(start_v, end_v, accel, h) @ reach.T)  # (m, P)
        # refine where the bound may hide a shortfall, unless a sample already shows one
        ends_clear = np.all(np.minimum(start_d, end_d) >= floor - ROUND_OFF_M, axis=1)
        refine = np.any(bound < floor - tolerance, axis=1) & ends_clear
        if depth == max_depth or refined + refine.sum() * (SUBDIVISIONS - 1) > MAX_REFINED_SAMPLES:
            refine[:] = False
        kept = bound[~refine]
        if kept.size:
            where = np.argmin(kept, axis=0)
            better = kept[where, np.arange(kept.shape[1])] < lower
            mid = 0.5 * (start_t + end_t)[~refine][where]
            lower = np.where(better, kept[where, np.arange(kept.shape[1])], lower)
            lower_time = np.where(better, mid, lower_time)
        if not refine.any():
            break
        fractions = np.arange(1, SUBDIVISIONS) / SUBDIVISIONS
        inner = start_t[refine, None] + h[refine, None] * fractions  # (r, S - 1)
        q_in, dq_in, ddq_in = motion(inner.ravel())
        d_in = clearance(model, q_in, keep_out=keep_out, witness=False).pair_distance
        _check_finite(inner.ravel(), dq_in, ddq_in, d_in)
        accel = np.maximum(accel, np.abs(ddq_in).max(axis=0))  # the refined samples' too
        refined += inner.size
        sampled_min = np.minimum(sampled_min, d_in.min(axis=0))
        r, n_p = int(refine.sum()), distance.shape[1]
        times = np.concatenate([start_t[refine, None], inner, end_t[refine, None]], axis=1)  # (r, S + 1)
        speeds = np.concatenate([start_v[refine, None], dq_in.reshape(r, -1, model.dof), end_v[refine, None]], axis=1)
        dists = np.concatenate([start_d[refine, None], d_in.reshape(r, -1, n_p), end_d[refine, None]], axis=1)
        start_t, end_t = times[:, :-1].ravel(), times[:, 1:].ravel()
        start_v, end_v = speeds[:, :-1].reshape(-1, model.dof), speeds[:, 1:].reshape(-1, model.dof)
        start_d, end_d = dists[:, :-1].reshape(-1, n_p), dists[:, 1:].reshape(-1, n_p)
    return SweptClearance(
        lower_bound=lower,
        lower_bound_time=lower_time,
        sampled_min=sampled_min,
        grid_min=distance.min(axis=0),
        floor=np.array(floor),
        names=pairs.names,
        tolerance=float(tolerance),
        samples=int(t.size),
        refined_samples=refined,
    )


def _check_finite(t: FloatArray, dq: FloatArray, ddq: FloatArray, distance: FloatArray) -> None:
    """A motion with a NaN or infinite rate, acceleration or distance has no bound: one line."""
    bad = ~(np.isfinite(dq).all(axis=-1) & np.isfinite(ddq).all(axis=-1) & np.isfinite(distance).all(axis=-1))
    if bad.any():
        raise ConfigurationError(
            f"the motion's rates, accelerations or clearances are not finite at t = {float(np.ravel(t)[np.argmax(bad)]):g} s: "
            "no bound between its samples"
        )
