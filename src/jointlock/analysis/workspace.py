"""Monte Carlo workspace of an arm before and after a joint locks (002 Figs. 2-3).

Joint angles are drawn uniformly within the limits as given (:meth:`ArmModel.angle_range`), the end-effector
positions computed in one batched pass.  The volume, ``volume`` [m^3] with its error
``volume_error``, is the voxel occupancy at several voxel sides extrapolated to a zero side
(:func:`jointlock.analysis._volume.estimate_volume`; NaN, with a warning, when the samples are
too few).  The plain occupancy at the voxel ``voxel`` (cubes of that side holding at least
one sample, times ``voxel^3``: biased high by the cubes overhanging the surface) stays
available as ``occupancy``.

The locked arm's configurations are the full arm's with one joint fixed, so its positions
are full-arm positions: the full arm's volume is estimated from both clouds together, and the
locked workspace is a subset of the full one by construction (share kept <= 1).  ``outside``
still reports how many locked voxels the full arm's own samples missed: a sampling
diagnostic, not a contradiction.

The end-effector positions come from :func:`jointlock.kinematics.ee_positions`, the
position-only forward kinematics (re-exported here with :data:`DEFAULT_CHUNK`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .._random import resolve_rng
from ..bounds import MAX_LENGTH_M, MIN_LENGTH_M, as_real
from ..errors import ConfigurationError
from ..io.files import to_plain
from ..kinematics import DEFAULT_CHUNK, ee_positions
from ..locking import lock
from ..model import ArmModel, FloatArray
from ._volume import VolumeEstimate, estimate_volume

__all__ = [
    "DEFAULT_CHUNK",
    "MIN_SAMPLES",
    "MIN_SAMPLES_PER_VOXEL",
    "OUTSIDE_TOL",
    "SAMPLES_PER_VOXEL",
    "SHARE_HALF_TOL",
    "VolumeEstimate",
    "Workspace",
    "WorkspaceComparison",
    "compare_workspaces",
    "ee_positions",
    "estimate_volume",
    "projection_extent",
    "sample_configurations",
    "sample_workspace",
    "share_text",
    "volume_text",
    "voxel_keys",
]

#: What the text forms say for a NaN or missing volume, and for a share without one.
NO_VOLUME = "no estimate (too few samples)"
NO_SHARE = "no estimate"

#: Mean full-arm samples per voxel of the bounding box when the voxel side is chosen [-].
SAMPLES_PER_VOXEL = 16.0

#: Fewest samples per arm the command line and scenario files accept: below, the voxel
#: estimate says little (a handful of voxels, or a volume of ~0 with a tiny voxel).
MIN_SAMPLES = 1000
#: Fewest mean samples per occupied voxel of the full arm for a volume estimate: with fewer,
#: nearly every sample has its own voxel and the "volume" is ``samples x voxel^3``.
MIN_SAMPLES_PER_VOXEL = 2.0
#: :meth:`WorkspaceComparison.warnings`: largest difference between the share kept from all
#: the samples and from half of them [-] ...
SHARE_HALF_TOL = 0.03
#: ... and largest share of the locked arm's voxels outside the full cloud [-].
OUTSIDE_TOL = 0.03


def sample_configurations(
    model: ArmModel, samples: int, rng: int | np.random.Generator | None = None
) -> FloatArray:
    """(samples, n) joint angles uniform within the limits as given [rad]
    (:meth:`ArmModel.angle_range`: past +-pi too; one turn for a joint without limits).

    ``rng``: seed (int >= 0) or ``numpy.random.Generator`` (:mod:`jointlock._random`); ``None``
    draws a fresh seed, which is not returned (pass a seed or a Generator to repeat the draw;
    :func:`sample_workspace` and :func:`compare_workspaces` record theirs).
    """
    if isinstance(samples, bool) or not isinstance(samples, (int, np.integer)) or samples < 1:
        raise ConfigurationError(f"samples must be an integer >= 1; got {samples!r}")
    gen, _ = resolve_rng(rng)
    lo, hi = model.angle_range()
    return gen.uniform(lo, hi, (int(samples), model.dof))


def voxel_keys(points: ArrayLike, voxel: float, origin: ArrayLike | None = None) -> FloatArray:
    """(k, 3) integer indices of the occupied voxels of side ``voxel`` [m], unique, sorted."""
    if not (voxel > 0):
        raise ConfigurationError(f"voxel must be > 0 [m]; got {voxel}")
    pts = np.asarray(points, dtype=float).reshape(-1, 3)
    o = np.zeros(3) if origin is None else np.asarray(origin, dtype=float)
    idx = np.floor((pts - o) / voxel).astype(np.int64)
    if idx.shape[0] == 0:
        return idx
    lo = idx.min(axis=0)
    span = idx.max(axis=0) - lo + 1
    code = ((idx[:, 0] - lo[0]) * span[1] + (idx[:, 1] - lo[1])) * span[2] + (idx[:, 2] - lo[2])
    code = np.unique(code)  # 1-D unique: much faster than unique rows
    z = code % span[2]
    y = (code // span[2]) % span[1]
    x = code // (span[1] * span[2])
    return np.stack([x, y, z], axis=1) + lo


def _auto_voxel(points: FloatArray) -> float:
    box = float(np.prod(np.ptp(points, axis=0) + 1e-9))
    return (box * SAMPLES_PER_VOXEL / points.shape[0]) ** (1.0 / 3.0)


def volume_text(volume: float | None, error: float | None) -> str:
    """``"V ± err m^3"`` (the error to 2 significant digits, the volume to the same decimal
    place: ``"13.9 ± 1.0 m^3"``, ``"14.10 ± 0.63 m^3"``), or ``"no estimate (too few samples)"``
    for a NaN or missing volume (``None``: the JSON form)."""
    if volume is None or error is None or not (math.isfinite(volume) and math.isfinite(error)):
        return NO_VOLUME
    if error <= 0:
        return f"{volume:.3g} ± 0 m^3"
    places = max(0, 1 - math.floor(math.log10(error)))
    return f"{volume:.{places}f} ± {error:.{places}f} m^3"


def share_text(share: float | None, error: float | None) -> str:
    """``"S ± err %"`` (whole percent), or ``"no estimate"`` for a NaN or missing share."""
    if share is None or error is None or not (math.isfinite(share) and math.isfinite(error)):
        return NO_SHARE
    return f"{100 * share:.0f} ± {100 * error:.0f} %"

@dataclass(frozen=True)
class Workspace:
    """Monte Carlo workspace of one arm.

    Attributes
    ----------
    points
        (N, 3) end-effector positions [m], root frame.
    voxel
        Voxel side [m] of ``occupancy``.
    occupancy
        Occupied volume at that voxel [m^3] (voxel count x voxel^3; biased high).
    seed
        The seed the samples were drawn with (the fresh one drawn for ``rng=None``), or None
        when a ``Generator`` was passed.
    estimate
        The volume extrapolated to a zero voxel side, with its error and ladder.
    """

    points: FloatArray
    voxel: float
    occupancy: float
    seed: int | None
    estimate: VolumeEstimate

    @property
    def volume(self) -> float:
        """Estimated volume [m^3] (NaN when the samples are too few; :meth:`warnings`)."""
        return self.estimate.volume

    @property
    def volume_error(self) -> float:
        """Stated error of :attr:`volume` [m^3]."""
        return self.estimate.error

    @property
    def samples_per_voxel(self) -> float:
        """Mean samples per occupied voxel [-] (see :data:`MIN_SAMPLES_PER_VOXEL`)."""
        occupied = self.occupancy / self.voxel**3
        return float(self.points.shape[0] / occupied) if occupied > 0 else math.nan

    def warnings(self) -> list[str]:
        """Why there is no volume estimate (empty when there is one)."""
        return [self.estimate.warning] if self.estimate.warning else []

    def to_dict(self) -> dict[str, Any]:
        """Plain JSON values: the volume, its error and the samples per voxel as numbers, ``None``
        where there is no estimate, and ``volume_text`` saying so in words ("no estimate (too
        few samples)")."""
        return to_plain({
            "voxel_m": self.voxel,
            "volume_full_m3": self.volume,
            "volume_full_error_m3": self.volume_error,
            "occupancy_full_m3": self.occupancy,
            "extent_full_m": projection_extent(self.points),
            "samples_per_voxel": self.samples_per_voxel,
            "volume_full_text": volume_text(self.volume, self.volume_error),
            "warnings": self.warnings(),
        })

    def summary(self, name: str = "full arm") -> list[str]:
        """The volume line, indented (``name``: how the arm is called)."""
        return [
            f"  {name + ' volume':<18}: {volume_text(self.volume, self.volume_error)} "
            f"(occupancy at the voxel: {self.occupancy:.3g} m^3)"
        ]


def sample_workspace(
    model: ArmModel,
    *,
    samples: int = 200_000,
    voxel: float | None = None,
    rng: int | np.random.Generator | None = None,
) -> Workspace:
    """Monte Carlo workspace of one arm (002 Fig. 2): uniform joint samples, batched FK, the
    volume extrapolated to a zero voxel side with its error, and the plain occupancy at
    ``voxel`` [m] (``voxel=None``: about :data:`SAMPLES_PER_VOXEL` samples per voxel of the
    bounding box).  ``rng``: seed, Generator or None (a fresh seed), recorded in
    ``seed`` (:mod:`jointlock._random`)."""
    gen, seed = resolve_rng(rng)
    pts = ee_positions(model, sample_configurations(model, samples, gen))
    side = _auto_voxel(pts) if voxel is None else float(voxel)
    vol = voxel_keys(pts, side).shape[0] * side**3
    return Workspace(pts, side, float(vol), seed, estimate_volume(pts))


@dataclass(frozen=True)
class WorkspaceComparison:
    """Monte Carlo workspace of an arm and of the same arm with one joint locked.

    Attributes
    ----------
    full, locked
        (N, 3), (M, 3) end-effector positions [m], root frame.
    voxel
        Voxel side [m] of the occupancies.
    occupancy_full, occupancy_locked
        Occupied volume at that voxel [m^3] (voxel count x voxel^3 of each cloud alone;
        biased high).
    share_kept_occupancy
        ``occupancy_locked / occupancy_full`` [-].
    outside
        Share of the locked arm's voxels not occupied by the full arm's own samples [-]
        (0 in the limit; a sampling diagnostic: the volumes count the locked samples as
        full-arm samples, so the locked workspace is inside the full one by construction).
    joint, angle
        The locked joint (1-based) and its angle [rad].
    seed
        The seed the samples were drawn with (the fresh one drawn for ``rng=None``), or None
        when a ``Generator`` was passed.
    share_kept_half
        ``share_kept_occupancy`` from the first half of each cloud (same voxel rule: the given
        ``voxel``, or the automatic side for half the samples) [-]; its distance to
        ``share_kept`` shows how far the estimate has converged.
    voxel_half
        The voxel side of that estimate [m].
    estimate_full, estimate_locked
        The volumes extrapolated to a zero voxel side with their errors: the full arm's from
        both clouds (the locked arm's positions are full-arm positions), the locked arm's
        from its own.
    """

    full: FloatArray
    locked: FloatArray
    voxel: float
    occupancy_full: float
    occupancy_locked: float
    share_kept_occupancy: float
    outside: float
    joint: int
    angle: float
    seed: int | None
    share_kept_half: float
    voxel_half: float
    estimate_full: VolumeEstimate
    estimate_locked: VolumeEstimate

    @property
    def volume_full(self) -> float:
        """Estimated volume of the full arm's workspace [m^3] (NaN: too few samples)."""
        return self.estimate_full.volume

    @property
    def volume_full_error(self) -> float:
        """Stated error of :attr:`volume_full` [m^3]."""
        return self.estimate_full.error

    @property
    def volume_locked(self) -> float:
        """Estimated volume of the locked arm's workspace [m^3] (NaN: too few samples)."""
        return self.estimate_locked.volume

    @property
    def volume_locked_error(self) -> float:
        """Stated error of :attr:`volume_locked` [m^3]."""
        return self.estimate_locked.error

    @property
    def share_kept(self) -> float:
        """``volume_locked / volume_full`` [-], at most 1 (the locked workspace is a subset); NaN
        without both volumes, or with a full volume of 0 (a one-joint arm's curve)."""
        ratio = _ratio(self.volume_locked, self.volume_full)
        return min(1.0, ratio) if math.isfinite(ratio) else math.nan

    @property
    def share_kept_error(self) -> float:
        """Stated error of :attr:`share_kept` [-]: ``(e_locked + share e_full) / V_full``, the
        relative errors of both volumes added (finite for a locked volume of 0; NaN with
        :attr:`share_kept`)."""
        ratio = _ratio(self.volume_locked, self.volume_full)
        return _ratio(self.volume_locked_error + abs(ratio) * self.volume_full_error, abs(self.volume_full))

    @property
    def samples_per_voxel(self) -> float:
        """Mean full-arm samples per occupied voxel [-] (below :data:`MIN_SAMPLES_PER_VOXEL`
        the voxel is too small for the samples)."""
        occupied = self.occupancy_full / self.voxel**3
        return float(self.full.shape[0] / occupied) if occupied > 0 else math.nan

    def warnings(self) -> list[str]:
        """Why the numbers should not be trusted to their digits (empty when they look converged):
        a volume without an estimate (too few samples), the occupancy share kept moves by more
        than :data:`SHARE_HALF_TOL` between half and all the samples, more than
        :data:`OUTSIDE_TOL` of the locked voxels lie outside the full cloud (samples missed),
        or the voxel holds fewer than :data:`MIN_SAMPLES_PER_VOXEL` samples on average."""
        out = [
            f"{which} arm volume: {est.warning}"
            for which, est in (
                ("full (counting both arms' positions)", self.estimate_full),
                ("locked", self.estimate_locked),
            )
            if est.warning
        ]
        if (
            math.isfinite(self.share_kept_half)
            and abs(self.share_kept_occupancy - self.share_kept_half) > SHARE_HALF_TOL
        ):
            out.append(
                f"share kept moves from {100 * self.share_kept_half:.0f} % (half the samples) to "
                f"{100 * self.share_kept_occupancy:.0f} % (all) at voxel {self.voxel:.3g} m: not converged; "
                "use more samples"
            )
        if self.outside > OUTSIDE_TOL:
            out.append(
                f"{100 * self.outside:.0f} % of the locked arm's voxels lie outside the full arm's cloud "
                f"(> {100 * OUTSIDE_TOL:.0f} %): the full cloud is under-sampled at this voxel"
            )
        if self.samples_per_voxel < MIN_SAMPLES_PER_VOXEL:
            out.append(
                f"{self.samples_per_voxel:.2g} samples per occupied voxel: the voxel "
                f"({self.voxel:.3g} m) is too small for the samples, the volumes are meaningless"
            )
        return out

    def to_dict(self) -> dict[str, Any]:
        """Plain JSON values: every figure as a number, ``None`` where there is no estimate
        (too few samples, or a full volume of 0), and the ``*_text`` entries saying so in words
        ("no estimate (too few samples)", "no estimate") next to the numbers."""
        return to_plain({
            "lock": {"joint": self.joint, "angle_deg": math.degrees(self.angle)},
            "voxel_m": self.voxel,
            "volume_full_m3": self.volume_full,
            "volume_full_error_m3": self.volume_full_error,
            "volume_locked_m3": self.volume_locked,
            "volume_locked_error_m3": self.volume_locked_error,
            "share_kept": self.share_kept,
            "share_kept_error": self.share_kept_error,
            "occupancy_full_m3": self.occupancy_full,
            "occupancy_locked_m3": self.occupancy_locked,
            "share_kept_occupancy": self.share_kept_occupancy,
            "share_kept_half_samples": self.share_kept_half,
            "voxel_half_samples_m": self.voxel_half,
            "locked_voxels_outside_full": self.outside,
            "extent_full_m": projection_extent(self.full),
            "extent_locked_m": projection_extent(self.locked),
            "samples_per_voxel": self.samples_per_voxel,
            "volume_full_text": volume_text(self.volume_full, self.volume_full_error),
            "volume_locked_text": volume_text(self.volume_locked, self.volume_locked_error),
            "share_kept_text": share_text(self.share_kept, self.share_kept_error),
            "warnings": self.warnings(),
        })

    def summary(self, before: str = "full arm") -> list[str]:
        """The volume, share-kept and sampling lines, indented (``before``: how the arm before
        the failure is called); "no estimate" where a figure has none."""
        converged = "; not converged, see the warnings" if self.warnings() else ""
        return [
            f"  {before + ' volume':<18}: {volume_text(self.volume_full, self.volume_full_error)} "
            f"(occupancy at the voxel: {self.occupancy_full:.3g} m^3)",
            f"  locked arm volume : {volume_text(self.volume_locked, self.volume_locked_error)} (joint "
            f"{self.joint} at {math.degrees(self.angle):g} deg; occupancy {self.occupancy_locked:.3g} m^3)",
            f"  share kept        : {share_text(self.share_kept, self.share_kept_error)} (occupancy: "
            f"{_percent(self.share_kept_occupancy)}, from half the samples: {_percent(self.share_kept_half)})"
            + converged,
            f"  locked voxels outside the full cloud (sampling): {_percent(self.outside, 1)}",
        ]


def _ratio(num: float, den: float) -> float:
    """``num / den``, NaN for a zero or non-finite denominator (no ZeroDivisionError)."""
    return num / den if math.isfinite(den) and den != 0 else math.nan


def _percent(share: float, places: int = 0) -> str:
    """``"75 %"``, or ``"no estimate"`` for NaN."""
    return f"{100 * share:.{places}f} %" if math.isfinite(share) else NO_SHARE


def compare_workspaces(
    model: ArmModel,
    joint: int,
    angle: float,
    *,
    samples: int = 200_000,
    locked_samples: int | None = None,
    voxel: float | None = None,
    rng: int | np.random.Generator | None = None,
) -> WorkspaceComparison:
    """Workspace of ``model`` and of ``lock(model, joint, angle)`` (002 Figs. 2 and 3).

    Parameters
    ----------
    model
        The healthy arm.
    joint, angle
        Joint to lock (1-based) and its angle [rad].
    samples, locked_samples
        Monte Carlo sizes (the locked arm defaults to the same number).
    voxel
        Voxel side [m] of the plain occupancies; default: the side giving about
        :data:`SAMPLES_PER_VOXEL` full-arm samples per voxel of the full cloud's bounding box.
    rng
        Seed (int >= 0), ``numpy.random.Generator`` or None (a fresh seed), recorded in
        ``seed`` (:mod:`jointlock._random`); the full arm's samples come first, then the
        locked arm's.
    """
    if voxel is not None:
        voxel = as_real(voxel, "voxel", lo=MIN_LENGTH_M, hi=MAX_LENGTH_M, unit="m", error=ConfigurationError)
    gen, seed = resolve_rng(rng)
    locked_model = lock(model, joint, angle)
    full = ee_positions(model, sample_configurations(model, samples, gen))
    locked = ee_positions(locked_model, sample_configurations(locked_model, locked_samples or samples, gen))
    auto = voxel is None
    if voxel is None:
        voxel = _auto_voxel(full)
    keys_full = voxel_keys(full, voxel)
    keys_locked = voxel_keys(locked, voxel)
    inside = _rows_in(keys_locked, keys_full)
    vol_full = keys_full.shape[0] * voxel**3
    vol_locked = keys_locked.shape[0] * voxel**3
    # the same estimate from half of each cloud: how far it has converged
    share_half, voxel_half = math.nan, math.nan
    nf, nl = full.shape[0] // 2, locked.shape[0] // 2
    if nf >= 1 and nl >= 1:
        voxel_half = _auto_voxel(full[:nf]) if auto else float(voxel)
        share_half = voxel_keys(locked[:nl], voxel_half).shape[0] / voxel_keys(full[:nf], voxel_half).shape[0]
    # the locked arm's positions are full-arm positions: the full volume counts both clouds
    # (the half estimate: the first half of each)
    both = np.concatenate([full, locked])
    first_half = np.concatenate([np.arange(full.shape[0]) < nf, np.arange(locked.shape[0]) < nl])
    return WorkspaceComparison(
        full,
        locked,
        float(voxel),
        float(vol_full),
        float(vol_locked),
        float(vol_locked / vol_full),
        float(1.0 - inside.mean()) if inside.size else 0.0,
        int(joint),
        float(angle),
        seed,
        float(share_half),
        float(voxel_half),
        estimate_volume(both, first_half),
        estimate_volume(locked),
    )


def _rows_in(a: FloatArray, b: FloatArray) -> NDArray[np.bool_]:
    """(len(a),) bool: row of ``a`` present in ``b`` (integer rows)."""
    if a.size == 0:
        return np.zeros(0, dtype=bool)
    lo = np.minimum(a.min(0), b.min(0))
    span = np.maximum(a.max(0), b.max(0)) - lo + 1

    def code(x):
        y = x - lo
        return (y[:, 0] * span[1] + y[:, 1]) * span[2] + y[:, 2]

    return np.isin(code(a), code(b))


def projection_extent(points: ArrayLike) -> dict[str, list[float]]:
    """Axis-aligned bounds ``{"x": [min, max], ...}`` [m] of a point cloud (N, 3)."""
    p = np.asarray(points, dtype=float)
    return {ax: [float(p[:, k].min()), float(p[:, k].max())] for k, ax in enumerate("xyz")}
