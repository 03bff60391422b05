"""The continuous re-plan (``method="continuous"`` of :func:`~jointlock.planning.replan.replan_line`):
one shortest path over waypoints x gamma grid x locked-arm branch, then gamma refined to an
exact root within one cell."""

from __future__ import annotations

import math

import numpy as np

from ..._search1d import golden_section_minimize
from ...errors import ConfigurationError
from ...ik import EXACT_POSITION_TOL, EXACT_ROTATION_TOL, ik_closed_form, puma6_branches, wrap_angle
from ...kinematics import ee_pose
from ...model import FloatArray
from ...spatial import invert, pose_error
from ._gamma import _full_branches, tool_x_rotation

#: Gamma grid step of the continuous plan's path search [rad]; absorbed waypoints are then
#: refined to the exact root within one cell either side.
PATH_GAMMA_STEP = math.radians(0.25)
#: Most gamma values per waypoint in the path search (the grid coarsens beyond).
PATH_MAX_GAMMAS = 161
#: Golden-section steps of that refinement (a cell shrinks by 0.618**64 ~ 4e-14).
REFINE_STEPS = 64
#: Default weight of the squared joint step against the tracking error [m / rad^2].
DEFAULT_STEP_WEIGHT = 0.5
#: The goal's tracking error counts this many times (the task is to reach it).
GOAL_WEIGHT = 100.0


def _continuous_plan(
    model, geom_locked, geom, nominal, b, gamma_tolerance, grid_step, step_weight, length_scale
):
    """Shortest path over (waypoint x gamma x locked branch); see :func:`replan_line`."""
    k = nominal.shape[0]
    if gamma_tolerance > 0:
        count = min(2 * int(math.ceil(gamma_tolerance / grid_step)) + 1, PATH_MAX_GAMMAS)
        grid = np.linspace(-gamma_tolerance, gamma_tolerance, max(count, 3))
    else:
        grid = np.zeros(1)
    g = grid.size
    sol = ik_closed_form(model, tool_x_rotation(nominal[:, None], grid[None, :]))  # (K, G, B)
    nb = sol.valid.shape[-1]
    err = np.where(sol.valid, sol.position_error + length_scale * sol.rotation_error, np.inf)
    # the goal stays on the followed full-arm branch: its nearest locked branch at each gamma
    full_q, full_valid = _full_branches(geom, tool_x_rotation(nominal[-1], grid))  # (G, 8, 6)
    ref = full_q[:, b, :]
    dist = np.max(np.abs(wrap_angle(sol.q_full[-1] - ref[:, None, :])), axis=-1)  # (G, B)
    near = np.argmin(np.where(sol.valid[-1], dist, np.inf), axis=1)
    keep = (np.arange(nb)[None, :] == near[:, None]) | ~full_valid[:, b, None]
    if np.any(keep & sol.valid[-1]):
        err[-1] = np.where(keep, err[-1], np.inf)
    err[-1] *= GOAL_WEIGHT
    node = _shortest_path(sol.q.reshape(k, g * nb, -1), err.reshape(k, g * nb), step_weight)
    gi, bi = np.divmod(node, nb)
    rows = np.arange(k)
    gamma = grid[gi]
    q = sol.q[rows, gi, bi]
    if g > 1:  # refine to an exact root within one cell either side, where there is one
        lo = grid[np.maximum(gi - 1, 0)]
        hi = grid[np.minimum(gi + 1, g - 1)]
        gam_r = _golden(lambda x: _branch_error(model, geom_locked, nominal, x, bi, length_scale)[0], lo, hi)
        pe, re, q_r = _branch_error(model, geom_locked, nominal, gam_r, bi, 0.0)
        exact = (pe <= EXACT_POSITION_TOL) & (re <= EXACT_ROTATION_TOL)
        gamma = np.where(exact, gam_r, gamma)
        q = np.where(exact[:, None], q_r, q)
    return gamma, q


def _branch_error(model, geom_locked, nominal, gammas, branches, length_scale):
    """Tracking error (position + length_scale * rotation), rotation error and joints of one
    locked branch per waypoint, each at its own gamma (closed form without the geometry fit)."""
    rows = np.arange(nominal.shape[0])
    target = tool_x_rotation(nominal, gammas)
    q_full, valid = puma6_branches(geom_locked, target @ invert(geom_locked.tool))
    q = model.healthy(q_full[rows, branches])
    ok = valid[rows, branches]
    pe, re = pose_error(target, ee_pose(model, np.where(ok[:, None], q, 0.0)))
    pe, re = np.where(ok, pe, np.inf), np.where(ok, re, np.inf)
    return pe + length_scale * re, re, q


def _golden(fun, lo: FloatArray, hi: FloatArray) -> FloatArray:
    """Vectorised golden-section minimisation of ``fun`` (K,) -> (K,) on ``[lo, hi]``."""
    return golden_section_minimize(fun, lo, hi, iterations=REFINE_STEPS).x


def _shortest_path(q: FloatArray, cost: FloatArray, weight: float) -> np.ndarray:
    """Viterbi over waypoints: nodes ``q`` (K, N, n) [rad] (NaN where invalid) with node
    costs ``cost`` (K, N) (``inf`` where invalid); edge cost ``weight * |wrap(dq)|^2``.
    Returns the (K,) node of the cheapest path."""
    k, n_nodes, n = q.shape
    ok = np.isfinite(cost)
    bad = np.flatnonzero(~np.any(ok, axis=1))
    if bad.size:
        raise ConfigurationError(f"waypoint {int(bad[0])} has no locked-arm IK solution")
    qz = np.where(ok[..., None], q, 0.0)
    acc = cost[0].copy()
    back = np.zeros((k, n_nodes), dtype=np.intp)
    cols = np.arange(n_nodes)
    two_pi = 2.0 * math.pi
    for i in range(1, k):
        d = np.abs(qz[i][None, :, :] - qz[i - 1][:, None, :])  # (prev, next, n), in [0, 2 pi)
        d = np.minimum(d, two_pi - d)  # wrapped |dq|
        trans = acc[:, None] + weight * np.einsum("ijk,ijk->ij", d, d)
        back[i] = np.argmin(trans, axis=0)
        acc = trans[back[i], cols] + cost[i]
    path = np.empty(k, dtype=np.intp)
    path[-1] = int(np.argmin(acc))
    for i in range(k - 1, 0, -1):
        path[i - 1] = back[i, path[i]]
    return path
