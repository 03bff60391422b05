"""000 §5's rows: CP at the printed q_sub and q_best, the halt motion at the printed k."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from ...locking import lock
from ...papers import p000
from ...planning.halt_config import evaluate_cp, optimal_halt_configuration
from ...planning.halt_motion import (
    K_UNIT_SCALE,
    HaltProblem,
    constraint_violations,
    global_base_torque,
    optimal_halt_motion,
)
from ...robots import load_robot
from ._report import NOT_REPRODUCED, REPRODUCED, ReproductionRow, _g, _pct, within_printed


# Over 100 lines: one block per printed figure of 000, in the paper's order; each is a few lines.
def rows_000() -> list[ReproductionRow]:
    """000 §5: CP at its printed q_sub and q_best, the halt motion at its k and limits."""
    sc, printed = p000.SCENARIO, p000.HALT_RESULTS
    ((joint, angle),) = sc["lock"].items()
    k_deg = printed["k"]
    model = lock(load_robot("halt7", base="floating"), joint, angle)
    hc = optimal_halt_configuration(model, samples=p000.SAMPLES, rng=0, refine=False)
    cp_best, cp_sub = evaluate_cp(hc, model, np.radians([p000.Q_BEST_DEG, p000.Q_SUB_DEG]))
    gain = (cp_best - cp_sub) / cp_sub
    share_above = float(np.mean(hc.cp_samples > cp_best))
    rows = [
        ReproductionRow(
            "000",
            "cp_q_sub",
            f"CP(q_sub), 000 §5.1 (halt7, joint {joint} at {angle:g}, K = {p000.SAMPLES}, J_F)",
            f"{p000.CP_Q_SUB:g}",
            f"{cp_sub:.4f}",
            NOT_REPRODUCED,
            "no reading of 000 gives it (docs/halt-config.md lists nine)",
        ),
        ReproductionRow(
            "000",
            "cp_gain",
            "CP(q_best) vs CP(q_sub)",
            _pct(p000.CP_GAIN),
            f"{_pct(gain)} (CP(q_best) = {cp_best:.4f})",
            NOT_REPRODUCED,
            f"{100 * share_above:.0f} % of our samples beat 000's q_best; our best sample CP {hc.cp_best:.4f}",
        ),
    ]
    deg = np.radians
    problem = HaltProblem(
        model,
        deg(sc["q0_deg"]),
        deg(sc["dq0_deg"]),
        deg(sc["ddq0_deg"]),
        deg(sc["qf_deg"]),
        sc["T"],
        np.full(model.dof, deg(sc["vmax_deg"])),
        np.full(model.dof, deg(sc["amax_deg"])),
        base="fixed",
    )
    k_paper = k_deg * K_UNIT_SCALE["deg/s^6"]
    tau0, tauk = global_base_torque(problem, np.array([0.0, k_paper]))
    res = optimal_halt_motion(problem, solver="scan", find_minimum_T=True)
    viol = constraint_violations(problem, k_paper)
    # the same halt with the spacecraft free, about its centre of mass: how far off the fixed base is
    floating = replace(problem, base="floating") if model.floating else None
    ratio = global_base_torque(floating, np.array([0.0, k_paper])) if floating is not None else None

    def mag(i: int, key: str) -> str:
        free = "" if ratio is None else f"; free-floating {ratio[i] / printed[key]:.1f}x"
        return f"two orders above 000 with a fixed base, about either point (70 kg, 5 m booms){free}"

    close = within_printed(100 * (1 - tauk / tau0), 100 * printed["reduction"], 1)  # 000 prints 30.1 %
    rows += [
        ReproductionRow(
            "000",
            "torque_k0",
            f"global base torque at k = 0 [N m] (000's q_best, T = {sc['T']:g} s, fixed base)",
            f"{printed['global_torque_k0_Nm']:g}",
            _g(tau0),
            NOT_REPRODUCED,
            mag(0, "global_torque_k0_Nm"),
        ),
        ReproductionRow(
            "000",
            "torque_k",
            f"global base torque at k = {k_deg:g} deg/s^6 [N m]",
            f"{printed['global_torque_Nm']:g}",
            _g(tauk),
            NOT_REPRODUCED,
            mag(1, "global_torque_Nm"),
        ),
        ReproductionRow(
            "000",
            "torque_reduction",
            f"torque reduction at k = {k_deg:g}",
            _pct(-printed["reduction"]),
            _pct(tauk / tau0 - 1),
            REPRODUCED if close else NOT_REPRODUCED,
            "relative drop only; the magnitudes differ"
            if close
            else f"a third of 000's drop, and k = {k_deg:g} breaks the limits",
        ),
        ReproductionRow(
            "000",
            "k_opt",
            "optimal k [deg/s^6]",
            f"{k_deg:g}",
            f"none feasible (least-violating k = {float(res.k) / K_UNIT_SCALE['deg/s^6']:.3g})",
            NOT_REPRODUCED,
            f"no k keeps 000's limits with T = {sc['T']:g} s",
        ),
        ReproductionRow(
            "000",
            "feasible",
            f"000's halt keeps joint speeds <= {sc['vmax_deg']:g} deg/s and accelerations <= "
            f"{sc['amax_deg']:g} deg/s^2",
            f"yes (k = {k_deg:g})",
            "INFEASIBLE: "
            + "; ".join(
                f"joint {v.joint} {v.kind} +{math.degrees(v.excess):.2f}"
                for v in (res.violations or viol)[:2]
            )
            + (f"; smallest feasible T = {res.minimum_T:.2f} s" if res.minimum_T is not None else ""),
            NOT_REPRODUCED,
            f"k = {k_deg:g} breaks {len(viol)} limit(s) (joint {viol[0].joint} {viol[0].kind})"
            if viol
            else "",
        ),
    ]
    return rows
