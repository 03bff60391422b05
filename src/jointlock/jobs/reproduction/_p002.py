"""002's rows: the worked examples, eqs. (21)-(22), example A's ranges, gamma and q at gamma."""

from __future__ import annotations

import math

import numpy as np

from ...ik import zyx_angles
from ...kinematics import ee_pose
from ...papers import p002
from ...planning.replan import absorbable_range, gamma_sweep, gammas_for_lock
from ...robots import load_robot
from ._report import NOT_REPRODUCED, REPRODUCED, ReproductionRow, _list, within_printed


def _printed(x: np.ndarray, decimals: int) -> np.ndarray:
    """What 002 would print: truncated to 2 decimals, rounded to 4."""
    scale = 10.0**decimals
    return np.trunc(x * scale) / scale if decimals == 2 else np.round(x, decimals)


# Over 100 lines: one block per printed figure of 002, in the paper's order; each is a few lines.
def rows_002() -> list[ReproductionRow]:
    """002: the worked examples, eqs. (21)-(22), example A's ranges, gamma and q at gamma."""
    arm = load_robot("puma6")
    j = p002.LOCKED_JOINT
    rows = []
    for label, (q, pos, eul, dec) in p002.EXAMPLES.items():
        pose = ee_pose(arm, np.radians(q))
        ours_p, ours_e = pose[:3, 3] * 1e3, zyx_angles(pose[:3, :3])
        same = np.array_equal(_printed(ours_p, dec), pos) and np.array_equal(_printed(ours_e, dec), eul)
        how = "truncated" if dec == 2 else "rounded"
        rows.append(
            ReproductionRow(
                "002",
                f"example_{label}",
                f"worked example {label}: tip position [mm] (and ZYX Euler) at q = {_list(q)}",
                _list(pos),
                "[" + ", ".join(f"{v:.{dec}f}" for v in _printed(ours_p, dec)) + "]",
                REPRODUCED if same else NOT_REPRODUCED,
                f"every printed digit ({how} to {dec} decimals)" if same else "digits differ",
            )
        )
    pose = ee_pose(arm, np.radians(p002.EQ22_DEG))
    diff = np.abs(np.c_[pose[:3, :3], pose[:3, 3:] * 1e3] - np.array(p002.EQ21_POSE)[:3]).max()
    rows.append(
        ReproductionRow(
            "002",
            "eq21",
            "eq. (21) pose = FK of eq. (22)",
            "4-decimal matrix",
            f"max abs difference {diff:.1e}",
            REPRODUCED if diff < 5e-5 + 1e-9 else NOT_REPRODUCED,
            "within the 4th decimal",
        )
    )
    qd = np.radians(p002.A_QF_DEG)
    target = ee_pose(arm, qd)
    wide_deg, narrow_deg = p002.A_WIDE_GAMMA_DEG, p002.A_NARROW_GAMMA_DEG
    sweep = gamma_sweep(arm, target, np.radians(np.linspace(-wide_deg, wide_deg, 3601)), q_ref=qd)
    wide = absorbable_range(sweep, j, math.radians(wide_deg))
    narrow = absorbable_range(sweep, j, math.radians(narrow_deg))
    lo, hi = math.degrees(wide.lower), math.degrees(wide.upper)
    lo2, hi2 = math.degrees(narrow.lower), math.degrees(narrow.upper)
    (p_lo, p_hi), (p_lo2, p_hi2) = p002.A_WIDE_RANGE_DEG, p002.A_NARROW_RANGE_DEG
    rows += [
        ReproductionRow(
            "002",
            "range_180",
            f"joint-{j} lock angles absorbable with gamma in [{-wide_deg:g}, {wide_deg:g}] deg [deg]",
            f"{p_lo:g} to {p_hi:g}",
            f"{lo:.2f} to {hi:.2f}",
            REPRODUCED if within_printed(lo, p_lo, 0) and within_printed(hi, p_hi, 0) else NOT_REPRODUCED,
            "to the printed degree"
            if within_printed(lo, p_lo, 0) and within_printed(hi, p_hi, 0)
            else f"the ends round to {lo:.0f} and {hi:.0f} deg (002 read its ends off Fig. 5)",
        ),
        ReproductionRow(
            "002",
            "range_2",
            f"same with gamma in [{-narrow_deg:g}, {narrow_deg:g}] deg [deg]",
            f"{p_lo2:g} to {p_hi2:g}",
            f"{lo2:.2f} to {hi2:.2f}",
            REPRODUCED if within_printed(lo2, p_lo2, 1) and within_printed(hi2, p_hi2, 1) else NOT_REPRODUCED,
            "to the printed decimal",
        ),
    ]
    gamma_deg = p002.A_GAMMA_DEG
    roots = gammas_for_lock(arm, target, j, math.radians(p002.A_LOCK_DEG), branch=sweep.branch)
    g = min((math.degrees(r.gamma) for r in roots), key=abs)
    rows.append(
        ReproductionRow(
            "002",
            "gamma",
            f"tolerance angle gamma for joint {j} locked at {p002.A_LOCK_DEG:g} deg [deg]",
            f"{gamma_deg:g}",
            f"{g:.4f} (exact root)",
            REPRODUCED if within_printed(g, gamma_deg, 2) else NOT_REPRODUCED,
            "to the printed digits"
            if within_printed(g, gamma_deg, 2)
            else f"the exact root is {abs(g - gamma_deg):.2g} deg from 002's {gamma_deg:g}, more than half its last "
            "digit: 002's value is a grid point, not the root",
        )
    )
    at = gamma_sweep(arm, target, np.radians([gamma_deg]), branch=sweep.branch)
    q_at = np.degrees(at.q[0])
    same = np.array_equal(np.trunc(q_at * 100) / 100, p002.A_Q_AT_GAMMA_DEG)
    rows.append(
        ReproductionRow(
            "002",
            "q_at_gamma",
            f"q at gamma = {gamma_deg:g} deg [deg]",
            _list(p002.A_Q_AT_GAMMA_DEG),
            "[" + ", ".join(f"{v:.4f}" for v in q_at) + "]",
            REPRODUCED if same else NOT_REPRODUCED,
            "truncated to 2 decimals it is 002's vector" if same else "differs after truncation",
        )
    )
    qd2 = np.radians(p002.B_QF_DEG)
    s2 = gamma_sweep(arm, ee_pose(arm, qd2), np.radians([p002.B_GAMMA_DEG]), q_ref=qd2)
    q22 = np.degrees(s2.q[0])
    same = np.array_equal(np.round(q22, 4), p002.EQ22_DEG)
    rows.append(
        ReproductionRow(
            "002",
            "eq22",
            f"eq. (22): q for joint {j} locked at {p002.B_LOCK_DEG:g} deg (gamma = {p002.B_GAMMA_DEG:g} deg) [deg]",
            _list(p002.EQ22_DEG),
            "[" + ", ".join(f"{v:.4f}" for v in q22) + "]",
            REPRODUCED if same else NOT_REPRODUCED,
            "every printed digit" if same else "digits differ",
        )
    )
    return rows
