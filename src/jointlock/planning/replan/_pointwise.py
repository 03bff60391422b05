"""The pointwise re-plan (``method="pointwise"`` of :func:`~jointlock.planning.replan.replan_line`,
the first implementation): gamma and branch chosen at each waypoint on its own."""

from __future__ import annotations

import math

import numpy as np

from ...ik import ik_closed_form, wrap_angle
from ...model import FloatArray
from ._gamma import _bisect, _brackets, _full_branches, _locked_value, tool_x_rotation


def _pointwise_grid(gamma_tolerance: float, gamma_step: float) -> FloatArray:
    count = max(1, 2 * int(math.ceil(gamma_tolerance / gamma_step)) + 1) if gamma_tolerance > 0 else 1
    return np.linspace(-gamma_tolerance, gamma_tolerance, count)


def _pointwise_plan(model, geom, nominal, b, joint, angle, gamma_tolerance, gamma_step):
    """The first implementation: gamma and branch chosen at each waypoint on its own."""
    k = nominal.shape[0]
    grid = _pointwise_grid(gamma_tolerance, gamma_step)
    f = wrap_angle(_locked_value(geom, nominal[:, None], grid[None, :], b, joint) - angle)  # (K, G)
    gamma = grid[np.argmin(np.where(np.isfinite(f), np.abs(f), np.inf), axis=1)]
    if grid.size > 1:
        brk = _brackets(f)  # (K, G-1)
        mid = 0.5 * (grid[:-1] + grid[1:])
        score = np.where(brk, np.abs(mid), np.inf)
        j = np.argmin(score, axis=1)
        has = np.isfinite(score[np.arange(k), j])
        if np.any(has):
            rows = np.flatnonzero(has)
            gamma[rows] = _bisect(
                geom, nominal[rows], grid[j[rows]], grid[j[rows] + 1], f[rows, j[rows]], b, joint, angle
            )
    target = tool_x_rotation(nominal, gamma)
    full_q, full_valid = _full_branches(geom, target)
    ref = full_q[:, b, :]
    locked = ik_closed_form(model, target)  # (K, 4)
    dist = np.max(np.abs(wrap_angle(locked.q_full - ref[:, None, :])), axis=-1)
    cost = np.where(locked.valid, locked.position_error + locked.rotation_error, np.inf)
    # prefer the branch on the followed full-arm solution; else the most accurate one
    choice = np.where(
        full_valid[:, b], np.argmin(np.where(locked.valid, dist, np.inf), axis=1), np.argmin(cost, 1)
    )
    return gamma, locked.q[np.arange(k), choice]


def _pointwise_absorbed(geom, nominal, gamma, b, joint, angle, gamma_tolerance, gamma_step):
    k = nominal.shape[0]
    grid = _pointwise_grid(gamma_tolerance, gamma_step)
    out = np.zeros(k, dtype=bool)
    if grid.size > 1:
        f = wrap_angle(_locked_value(geom, nominal[:, None], grid[None, :], b, joint) - angle)
        out = np.any(_brackets(f), axis=1)
    return out | (np.abs(wrap_angle(_locked_value(geom, nominal, gamma, b, joint) - angle)) < 1e-9)
