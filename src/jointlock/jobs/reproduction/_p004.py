"""004's rows: virtual lengths, eq. (15), Table 3 and the sufficiency of Cond1-Cond5."""

from __future__ import annotations

import numpy as np

from ...analysis import singularity as sg
from ...papers import p004
from ...robots import load_robot
from ._report import NOT_REPRODUCED, REPRODUCED, ReproductionRow, _list

#: 004: configurations sampled on each condition (``jointlock singular``'s default).
SUFFICIENCY_SAMPLES = 2000
#: 004: starts of the completeness search (no row reports it; 64 instead of 256 keeps it fast).
COMPLETENESS_STARTS = 64
#: 004: random configurations on which eq. (15) is compared with our Jacobian (seed 0).
EQ15_SAMPLES = 500
#: |det(J J^T)| below which a configuration is singular: 004's largest printed value is
#: 2.97e-12; random configurations give >= 2e-5 (tests/test_paper_004_singularity.py).
DET_SINGULAR = 1e-11


def solve_table3(name: str, lengths: sg.ArmLengths) -> np.ndarray:
    """004 Table 3's configuration of condition ``name`` [rad], (7,), with its length
    equation solved with unrounded lengths (004 prints the solved angles rounded to 0.1 deg;
    every other angle is kept as printed)."""
    from scipy.optimize import brentq, fsolve

    q = np.radians(np.array(p004.TABLE3_DEG[name], dtype=float))

    def eqs(qq: np.ndarray) -> np.ndarray:
        return sg.condition_equations(qq, lengths)[name]

    if name == "cond3":  # theta5 from d C3 + e C34 + h S345 = 0
        q[4] = brentq(lambda x: eqs(np.r_[q[:4], x, q[5:]])[1], q[4] - 0.05, q[4] + 0.05, xtol=1e-15)
    elif name == "cond4":  # theta3 from e C5 + d C45 - a S345 = 0
        q[2] = brentq(lambda x: eqs(np.r_[q[:2], x, q[3:]])[1], q[2] - 0.05, q[2] + 0.05, xtol=1e-15)
    elif name == "cond5":  # theta3, theta5 at theta4 = 180 deg
        q[2], q[4] = fsolve(lambda v: eqs(np.r_[q[:2], v[0], q[3], v[1], q[5:]]), q[[2, 4]], xtol=1e-13)
    return q


def rows_004() -> list[ReproductionRow]:
    """004: virtual lengths, eq. (15), Table 3 and the sufficiency of Cond1-Cond5."""
    arm = load_robot("canadarm7", base="floating")
    lengths = sg.arm_lengths(arm)
    dec = p004.VIRTUAL_LENGTH_DECIMALS
    rows = []
    for name, printed in p004.VIRTUAL_LENGTHS.items():
        v = getattr(lengths, name)
        rows.append(
            ReproductionRow(
                "004",
                f"virtual_{name}",
                f"virtual length {name}-hat [m] (004's formula (S_i/M) L_i)",
                f"{printed:g}",
                f"{v:.4f}",
                REPRODUCED if round(v, dec) == printed else NOT_REPRODUCED,
                f"to the printed {dec} decimals",
            )
        )
    q = np.random.default_rng(0).uniform(-np.pi, np.pi, (EQ15_SAMPLES, 7))
    diff = np.abs(sg.reference_jacobian(arm, q) - sg.eq15_jacobian(q, lengths)).max()
    rows.append(
        ReproductionRow(
            "004",
            "eq15",
            f"simplified Jacobian eq. (15) = ours in 004's frame and point ({EQ15_SAMPLES} random q)",
            "closed form",
            f"max abs difference {diff:.1e}",
            REPRODUCED if diff < 1e-12 else NOT_REPRODUCED,
            "equal to round-off",
        )
    )
    for name in sg.CONDITIONS:
        qs = solve_table3(name, lengths)
        printed_q = np.radians(np.array(p004.TABLE3_DEG[name], dtype=float))
        resolved = not np.allclose(qs, printed_q, rtol=0, atol=1e-12)
        det = float(sg.analyse_singularity(arm, qs, jacobian="virtual").det_jjt)
        det_printed = float(sg.analyse_singularity(arm, printed_q, jacobian="virtual").det_jjt)
        ok = abs(det) < DET_SINGULAR
        where = (
            f"at 004's angles re-solved unrounded ({_list(np.degrees(qs).round(4).tolist())} deg; printed "
            f"{_list(p004.TABLE3_DEG[name])})"
            if resolved
            else f"at {_list(p004.TABLE3_DEG[name])} deg"
        )
        rows.append(
            ReproductionRow(
                "004",
                f"table3_{name}",
                f"Table 3 {name.capitalize()}: det(J J^T) {where}",
                f"{p004.TABLE3_DET[name]:g}",
                f"{det:.3g}" + (f" (at the printed angles: {det_printed:.3g})" if resolved else ""),
                REPRODUCED if ok else NOT_REPRODUCED,
                (
                    "both round-off zero (random q: >= 2e-5); the printed angles, rounded to 0.1 deg, are only "
                    "near-singular"
                    if resolved
                    else "both round-off zero (random q: >= 2e-5)"
                )
                if ok
                else "not singular",
            )
        )
    ver = sg.verify_conditions(arm, samples=SUFFICIENCY_SAMPLES, search_samples=COMPLETENESS_STARTS, rng=0)
    for name in sg.CONDITIONS:
        c = ver.checks[name]
        rows.append(
            ReproductionRow(
                "004",
                f"sufficient_{name}",
                f"{name.capitalize()} is a sufficient singularity condition ({SUFFICIENCY_SAMPLES} samples on it)",
                "sufficient",
                f"{c.singular}/{c.samples} singular (median sigma_min {c.sigma_min_median:.2g})",
                REPRODUCED if c.sufficient else NOT_REPRODUCED,
                "every sample singular"
                if c.sufficient
                else "S4 = 0 is necessary only; singular iff also F = 0 (cond1f)",
            )
        )
    return rows
