"""Volume of a sampled workspace with its error: voxel occupancy at several resolutions,
extrapolated to a zero voxel side.

The occupied-voxel volume ``V(h)`` (cubes of side ``h`` holding at least one sample, times
``h^3``) of a well-sampled body is its volume plus a boundary layer about linear in ``h``
(the cubes that overhang the surface), less the cubes that touch the body so little that no
sample fell in them.  This second part barely depends on ``h`` (corner-clipped cubes) and
shrinks slowly with the sample count; it shows as a difference between the occupancy of all
the samples and of half of them.  Under-sampling of whole cubes (``h`` too small) shows the
same way, but large.

:func:`estimate_volume` therefore

1. counts ``V(h)`` on a geometric ladder of sides ``h_k = extent / 8 * 2**(-k/4)``, each
   averaged over :data:`GRID_OFFSETS` shifted grids, for all the samples and for the first
   half, and stops at the first side where the two differ by more than :data:`STOP_GAP`;
2. keeps the sides where all and half agree within :data:`SATURATED_GAP` (saturated);
3. adds to ``V(h)`` the missed volume ``d / (2**p - 1)`` (``d``: all minus half, averaged over
   the window; ``p = 1/2``), fits ``V0 + b h`` by least squares on the :data:`WINDOW` finest
   consecutive saturated sides, and takes ``V0``;
4. states an error that sums the distance to the same fit on the next coarser window, twice
   the intercept's standard error, and the missed-volume correction's spread for ``p``
   between 1/3 (corner-clipped cubes) and 1 (face-clipped cubes).

Without two such windows there is no estimate: the volume is NaN and a warning says why (use
more samples).  Checked against arms whose workspace is known in closed form (a spherical
shell and a sector of one, ``tests/test_workspace_volume.py``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

#: Grid shifts [voxel sides] over which each occupancy is averaged (aliasing of the grid).
GRID_OFFSETS = np.array([[0.0, 0.0, 0.0], [0.5, 0.5, 0.5]])
#: Largest voxel side of the ladder, as a share of the cloud's largest extent [-] ...
LADDER_TOP = 1.0 / 8.0
#: ... the ratio of two successive sides [-] ...
LADDER_RATIO = 2.0 ** -0.25
#: ... and the most sides tried.
LADDER_STEPS = 20
#: Largest relative difference between the occupancy of all and of half the samples for a
#: side to count as saturated [-] ...
SATURATED_GAP = 0.04
#: ... and the one past which the ladder stops (the cubes are under-sampled) [-].
STOP_GAP = 0.08
#: Consecutive saturated sides per linear fit (a factor 2 in side).
WINDOW = 5
#: Exponent of the missed volume's decay with the sample count: assumed, and bounds [-].
MISSED_EXPONENT = 0.5
MISSED_EXPONENT_RANGE = (1.0 / 3.0, 1.0)


@dataclass(frozen=True)
class VolumeEstimate:
    """A workspace volume extrapolated to a zero voxel side, with its error.

    Attributes
    ----------
    volume
        Estimated volume [m^3]; NaN without saturated sides (see ``warning``).
    error
        Its stated error [m^3] (a bound on the bias and the sampling, not a standard
        deviation); NaN with ``volume``.
    sides
        (K,) voxel sides of the ladder [m], largest first.
    occupancy, occupancy_half
        (K,) occupied-voxel volume of all the samples and of the first half [m^3].
    window
        Indices into ``sides`` of the fit that gives ``volume`` (empty without one).
    warning
        Why there is no estimate; empty when there is one.
    """

    volume: float
    error: float
    sides: NDArray[np.float64]
    occupancy: NDArray[np.float64]
    occupancy_half: NDArray[np.float64]
    window: tuple[int, ...]
    warning: str = ""


def _occupancy(points: NDArray[np.float64], half: NDArray[np.bool_], side: float) -> tuple[float, float]:
    """Occupied-voxel volume of all ``points`` and of those flagged ``half`` [m^3], averaged
    over :data:`GRID_OFFSETS`."""
    total = np.zeros(2)
    for shift in GRID_OFFSETS:
        idx = np.floor(points / side + shift).astype(np.int64)
        lo = idx.min(axis=0)
        span = idx.max(axis=0) - lo + 1
        code = ((idx[:, 0] - lo[0]) * span[1] + (idx[:, 1] - lo[1])) * span[2] + (idx[:, 2] - lo[2])
        total += (np.unique(code).size, np.unique(code[half]).size)
    return float(total[0] * side**3 / len(GRID_OFFSETS)), float(total[1] * side**3 / len(GRID_OFFSETS))


def _intercept(sides: NDArray[np.float64], values: NDArray[np.float64]) -> tuple[float, float]:
    """Least-squares ``values = v0 + b sides``: ``v0`` and its standard error [m^3]."""
    a = np.stack([np.ones_like(sides), sides], axis=1)
    coef, *_ = np.linalg.lstsq(a, values, rcond=None)
    resid = values - a @ coef
    cov = np.linalg.inv(a.T @ a) * float(resid @ resid) / max(len(sides) - 2, 1)
    return float(coef[0]), math.sqrt(max(float(cov[0, 0]), 0.0))


def estimate_volume(points: ArrayLike, half: ArrayLike | None = None) -> VolumeEstimate:
    """Volume of the body the ``points`` sample, extrapolated to a zero voxel side, with its error.

    Parameters
    ----------
    points
        (N, 3) sample positions [m].
    half
        (N,) bool: the samples of the half-size estimate (the first half of each cloud drawn);
        default: the first ``N // 2``.

    Returns
    -------
    VolumeEstimate
        NaN volume and error, with a warning, when fewer than two windows of
        :data:`WINDOW` saturated sides exist (too few samples).
    """
    pts = np.asarray(points, dtype=float).reshape(-1, 3)
    n = pts.shape[0]
    mask = np.arange(n) < n // 2 if half is None else np.asarray(half, dtype=bool)
    extent = float(np.ptp(pts, axis=0).max()) if n else 0.0
    sides: list[float] = []
    occ: list[tuple[float, float]] = []
    if n >= 2 and extent > 0 and mask.any():
        for k in range(LADDER_STEPS):
            side = extent * LADDER_TOP * LADDER_RATIO**k
            v_all, v_half = _occupancy(pts, mask, side)
            sides.append(side)
            occ.append((v_all, v_half))
            if v_all - v_half > STOP_GAP * v_all:
                break
    h = np.array(sides)
    v = np.array([o[0] for o in occ])
    vh = np.array([o[1] for o in occ])
    gap = v - vh
    saturated = gap <= SATURATED_GAP * v
    # the finest windows of consecutive saturated sides, finest first
    windows = [
        tuple(range(s, s + WINDOW)) for s in range(len(h) - WINDOW, -1, -1) if saturated[s : s + WINDOW].all()
    ]
    if len(windows) < 2:
        return VolumeEstimate(
            math.nan,
            math.nan,
            h,
            v,
            vh,
            (),
            f"too few samples ({n}) for a volume with a bounded error: fewer than two windows of {WINDOW} "
            f"successive voxel sides where all and half the samples agree within {100 * SATURATED_GAP:g} %; "
            "use more samples (200,000 per arm, the default, give the built-in arms a volume)",
        )
    fits = []
    for w in windows[:2]:
        idx = np.array(w)
        d = float(gap[idx].mean())
        missed = d / (2.0**MISSED_EXPONENT - 1.0)
        v0, se = _intercept(h[idx], v[idx] + missed)
        fits.append((v0, se, d))
    v0, se, d = fits[0]
    lo_p, hi_p = MISSED_EXPONENT_RANGE
    central = 1.0 / (2.0**MISSED_EXPONENT - 1.0)
    spread = d * max(1.0 / (2.0**lo_p - 1.0) - central, central - 1.0 / (2.0**hi_p - 1.0))
    error = abs(v0 - fits[1][0]) + 2.0 * se + spread
    # a workspace without volume (a surface: a 2-DOF arm) extrapolates to about 0, possibly
    # just below it: a volume is never negative, the error says how far from 0 it may be
    return VolumeEstimate(max(v0, 0.0), error, h, v, vh, windows[0])
