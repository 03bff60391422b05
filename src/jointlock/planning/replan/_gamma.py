"""The fault-tolerance angle gamma (seed 002 steps 1-5, see :mod:`jointlock.planning.replan`):
the full-arm IK along the gamma sweep, the absorbable range of lock angles, and every gamma
that puts the locked joint at its angle."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..._search1d import bisect_root
from ...errors import ConfigurationError
from ...ik import Puma6Geometry, _as_poses, puma6_branches, puma6_geometry, wrap_angle
from ...model import ArmModel, FloatArray
from ...spatial import invert, rot_x

#: Bisection steps when refining a gamma root (bracket 0.1 deg -> 1e-17 rad).
ROOT_BISECTIONS = 56
#: Default gamma grid step for bracketing roots [rad].
DEFAULT_GAMMA_STEP = math.radians(0.1)


def tool_x_rotation(target: ArrayLike, gamma: ArrayLike) -> FloatArray:
    """002 eq. (18), corrected: ``T Rx(gamma)``.

    Parameters
    ----------
    target
        (..., 4, 4) poses [m].
    gamma
        (...) rotation about the tool x axis [rad]; broadcast against ``target``'s batch.

    Returns
    -------
    (..., 4, 4) poses.  The printed (1, 1) element of eq. (18) is 0; it must be 1 (a
    rotation), and only then does E4 -> E5 of 002 (roll + gamma) hold.
    """
    return np.asarray(target, dtype=float) @ rot_x(gamma)


def _full_geometry(model: ArmModel) -> Puma6Geometry:
    geom = puma6_geometry(model)
    return Puma6Geometry(geom.a2, geom.d4, geom.d6, geom.tool, None)


def _full_branches(geom: Puma6Geometry, poses: FloatArray) -> tuple[FloatArray, NDArray[np.bool_]]:
    return puma6_branches(geom, poses @ invert(geom.tool))


def _pick_branch(
    geom: Puma6Geometry, target: FloatArray, q_ref: FloatArray | None, branch: int | None
) -> int:
    if branch is not None:
        if not 0 <= branch < 8:
            raise ConfigurationError(f"branch must be 0..7; got {branch}")
        return int(branch)
    if q_ref is None:
        raise ConfigurationError("give q_ref (full-arm joint angles [rad]) or branch to choose the IK branch")
    q0, valid = _full_branches(geom, target)
    dist = np.where(valid, np.max(np.abs(wrap_angle(q0 - q_ref)), axis=-1), np.inf)
    if not np.any(np.isfinite(dist)):
        raise ConfigurationError("the target is out of reach of the full arm: no IK branch exists")
    return int(np.argmin(dist))


@dataclass(frozen=True)
class GammaSweep:
    """Full-arm IK along the gamma sweep.

    Attributes
    ----------
    gammas
        (G,) rotation about the tool x axis [rad].
    q
        (G, 6) joint angles on the followed branch [rad], unwrapped along ``gammas`` so that
        each curve is continuous (value at the gamma nearest 0 within [-pi, pi)).
    q_branches
        (G, 8, 6) every branch [rad] in [-pi, pi) (NaN where it does not exist).
    valid
        (G,) the followed branch exists.
    branch
        Index of the followed branch (:func:`jointlock.ik.puma6_branches` order).
    target
        (4, 4) pose at ``gamma = 0`` [m].
    """

    gammas: FloatArray
    q: FloatArray
    q_branches: FloatArray
    valid: np.ndarray
    branch: int
    target: FloatArray


def gamma_sweep(
    model: ArmModel,
    target: ArrayLike,
    gammas: ArrayLike | None = None,
    *,
    q_ref: ArrayLike | None = None,
    branch: int | None = None,
) -> GammaSweep:
    """Full-arm closed-form IK of ``T Rx(gamma)`` for every ``gamma`` (002 steps 1-4, Figs. 5-8).

    Parameters
    ----------
    model
        A ``puma6``-family arm (a locked one is accepted; its full arm is used).
    target
        (4, 4) desired pose [m] (002: FK of the desired joint angles).
    gammas
        (G,) [rad]; default ``[-pi, pi]`` in 0.1 deg steps.
    q_ref
        (6,) full-arm angles [rad] selecting the branch nearest to them at ``gamma = 0``
        (002 follows the branch of its desired configuration).
    branch
        Or the branch index directly.
    """
    geom = _full_geometry(model)
    t = _as_poses(target)
    g = np.linspace(-math.pi, math.pi, 3601) if gammas is None else np.asarray(gammas, dtype=float).ravel()
    b = _pick_branch(geom, t, None if q_ref is None else np.asarray(q_ref, dtype=float), branch)
    q_all, valid_all = _full_branches(geom, tool_x_rotation(t, g))
    q = q_all[:, b, :]
    valid = valid_all[:, b]
    q = _continuous(q, valid, g)
    return GammaSweep(g, q, q_all, valid, b, t)


def _continuous(q: FloatArray, valid: NDArray[np.bool_], gammas: FloatArray) -> FloatArray:
    out = np.full(q.shape, np.nan)
    if not np.any(valid):
        return out
    idx = np.flatnonzero(valid)
    seg = np.unwrap(q[idx], axis=0)
    anchor = int(np.argmin(np.abs(gammas[idx])))
    seg = seg - 2 * math.pi * np.round((seg[anchor] - wrap_angle(seg[anchor])) / (2 * math.pi))
    out[idx] = seg
    return out


@dataclass(frozen=True)
class LockRange:
    """Lock angles of ``joint`` absorbable by some ``|gamma| <= gamma_limit``.

    Attributes
    ----------
    joint
        Joint number (1-based).
    gamma_limit
        [rad].
    lower, upper
        [rad]: min and max of the joint's angle over the sweep on the followed branch
        (continuous curve, so every angle in between is hit).
    gamma_at_lower, gamma_at_upper
        [rad] where they are reached.
    """

    joint: int
    gamma_limit: float
    lower: float
    upper: float
    gamma_at_lower: float
    gamma_at_upper: float


def absorbable_range(sweep: GammaSweep, joint: int, gamma_limit: float = math.pi) -> LockRange:
    """Range of lock angles of ``joint`` that the sweep absorbs within ``|gamma| <= gamma_limit``.

    002: joint 2 of ``q = [5, 60, 35, 10, -120, 90] deg`` -> "48 deg to 123 deg" (+-180 deg)
    and "59.2 deg to 60.8 deg" (+-2 deg).
    """
    if not 1 <= joint <= 6:
        raise ConfigurationError(f"joint must be 1..6; got {joint}")
    sel = (np.abs(sweep.gammas) <= gamma_limit + 1e-12) & sweep.valid
    if not np.any(sel):
        raise ConfigurationError(f"no valid sweep point with |gamma| <= {math.degrees(gamma_limit):g} deg")
    vals = sweep.q[sel, joint - 1]
    g = sweep.gammas[sel]
    i_lo, i_hi = int(np.argmin(vals)), int(np.argmax(vals))
    return LockRange(
        joint, float(gamma_limit), float(vals[i_lo]), float(vals[i_hi]), float(g[i_lo]), float(g[i_hi])
    )


@dataclass(frozen=True)
class GammaRoot:
    """A gamma at which the full-arm IK puts the locked joint at its locked angle.

    Attributes
    ----------
    gamma
        [rad].
    q_full
        (6,) joint angles [rad]; entry ``joint - 1`` equals ``angle`` to bisection accuracy.
    joint, angle
        The locked joint (1-based) and its angle [rad].
    branch
        Full-arm IK branch followed.
    """

    gamma: float
    q_full: FloatArray
    joint: int
    angle: float
    branch: int


def _locked_value(
    geom: Puma6Geometry, poses: FloatArray, gammas: FloatArray, branch: int, joint: int
) -> FloatArray:
    q, valid = _full_branches(geom, tool_x_rotation(poses, gammas))
    return np.where(valid[..., branch], q[..., branch, joint - 1], np.nan)


def _bisect(geom, poses, lo, hi, f_lo, branch, joint, angle):
    """Vectorised bisection of ``wrap(theta_j(gamma) - angle)`` on brackets (K,)."""
    return bisect_root(
        lambda g: wrap_angle(_locked_value(geom, poses, g, branch, joint) - angle),
        lo,
        hi,
        f_lo=f_lo,
        iterations=ROOT_BISECTIONS,
    )


def _brackets(f: FloatArray) -> FloatArray:
    """(..., G-1) sign changes of ``f`` (..., G) that are not 2 pi wrap jumps."""
    a, b = f[..., :-1], f[..., 1:]
    ok = np.isfinite(a) & np.isfinite(b) & (np.abs(a) < math.pi / 2) & (np.abs(b) < math.pi / 2)
    return ok & ((a == 0) | (np.sign(a) != np.sign(b)))


#: A root where the locked joint's angle only touches the lock angle (no sign change: an
#: extremum of theta_j(gamma)) is kept when the extremum is this close [rad].
TANGENT_TOL = 1e-9


def _tangent_roots(geom: Any, t: FloatArray, grid: FloatArray, f: FloatArray, b: int, joint: int, angle: float) -> FloatArray:
    """Roots the sign-change brackets miss: ``theta_j(gamma)`` reaching the lock angle at an
    extremum (e.g. a target whose joint already sits at the lock angle, gamma = 0, at the
    bottom of the curve).  Each grid-local minimum of ``|f|`` without a sign change around it
    is refined (bounded scalar minimisation) and kept when ``|f|`` < :data:`TANGENT_TOL`."""
    from scipy.optimize import minimize_scalar

    a = np.abs(f)
    inner = np.arange(1, len(grid) - 1)
    cand = inner[
        np.isfinite(a[inner])
        & (a[inner] <= a[inner - 1])
        & (a[inner] <= a[inner + 1])
        & (a[inner] < math.pi / 2)
        & (np.sign(f[inner - 1]) == np.sign(f[inner + 1]))
        & (np.sign(f[inner]) == np.sign(f[inner + 1]))
    ]
    out = []
    for i in cand:  # few (one per extremum of the curve): a Python loop over candidates, not samples
        def err(g: float) -> float:
            return float(abs(wrap_angle(_locked_value(geom, t, np.array([g]), b, joint)[0] - angle)))

        res = minimize_scalar(err, bounds=(grid[i - 1], grid[i + 1]), method="bounded", options={"xatol": 1e-12})
        if res.fun < TANGENT_TOL:
            out.append(float(res.x))
    return np.array(out)


def gammas_for_lock(
    model: ArmModel,
    target: ArrayLike,
    joint: int,
    angle: float,
    *,
    q_ref: ArrayLike | None = None,
    branch: int | None = None,
    gamma_limit: float = math.pi,
    step: float = DEFAULT_GAMMA_STEP,
) -> tuple[GammaRoot, ...]:
    """Every ``gamma`` in ``[-gamma_limit, gamma_limit]`` at which the full-arm IK of
    ``T Rx(gamma)`` (on the chosen branch) puts ``joint`` exactly at ``angle`` (002 step 5).

    Parameters
    ----------
    model
        ``puma6``-family arm.
    target
        (4, 4) desired pose [m].
    joint, angle
        Locked joint (1-based) and its angle [rad].
    q_ref, branch
        Branch selection, as in :func:`gamma_sweep`.
    gamma_limit
        Fault tolerance [rad].
    step
        Grid step used to bracket the roots [rad]; each bracket is then bisected to
        machine precision.

    Returns
    -------
    tuple of GammaRoot, smallest ``|gamma|`` first (empty when the lock cannot be absorbed).
    """
    if not 1 <= joint <= 6:
        raise ConfigurationError(f"joint must be 1..6; got {joint}")
    geom = _full_geometry(model)
    t = _as_poses(target)
    b = _pick_branch(geom, t, None if q_ref is None else np.asarray(q_ref, dtype=float), branch)
    count = max(2, int(math.ceil(2 * gamma_limit / step)) + 1)
    grid = np.linspace(-gamma_limit, gamma_limit, count)
    f = wrap_angle(_locked_value(geom, t, grid, b, joint) - angle)
    br = np.flatnonzero(_brackets(f))
    gam = _bisect(geom, t, grid[br], grid[br + 1], f[br], b, joint, angle) if br.size else np.zeros(0)
    gam = np.where(f[br] == 0, grid[br], gam)
    gam = np.concatenate([gam, _tangent_roots(geom, t, grid, f, b, joint, angle)])
    if gam.size == 0:
        return ()
    q, _ = _full_branches(geom, tool_x_rotation(t, gam))
    roots = [GammaRoot(float(g), q[k, b].copy(), joint, float(angle), b) for k, g in enumerate(gam)]
    roots.sort(key=lambda r: abs(r.gamma))
    unique: list[GammaRoot] = []
    for r in roots:
        if all(abs(r.gamma - u.gamma) > 1e-9 for u in unique):
            unique.append(r)
    return tuple(unique)
