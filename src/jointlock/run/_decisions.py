"""The Decisions section of a scenario run's report: what each job decided (halt
configuration, k, kappa(t), gamma, volumes, 004's conditions)."""

from __future__ import annotations

from typing import Any

import numpy as np

from ..analysis.workspace import share_text, volume_text
from ..jobs.jump import KAPPA_UNIT, _points_text
from ..papers import p004
from ..report import Section
from ..scenario import Scenario
from ._summary import _pct, _pct0


def _condition_verdict(name: str, sufficient: bool) -> str:
    """Verdict of one singularity condition: 004's Cond1-Cond5 are reproduced or not;
    ``cond1f`` is jointlock's own condition, so it is only sufficient or not."""
    if name == "cond1f":
        return "sufficient (ours)" if sufficient else "not sufficient (ours)"
    return "reproduced" if sufficient else "not reproduced: not sufficient"


def _decide_halt_config(scenario: Scenario, jobs: dict[str, Any]) -> tuple[list[tuple[str, Any]], list[Any]]:
    """Facts and tables of the ``halt_config`` job for the Decisions section."""
    decisions: list[tuple[str, Any]] = []
    dtables: list[Any] = []
    r = jobs["halt_config"]["result"]
    decisions.append(("halt configuration [deg]", [round(v, 3) for v in r["best"]["q_deg"]]))
    decisions.append(
        (
            "CP at it (best sample, refinement gain)",
            f"{r['best']['cp']:.5f} ({r['best_sample']['cp']:.5f}, {r['refinement']['gain']:+.5f})",
        )
    )
    w = r["weights"]
    dtables.append(
        (
            ["weights", *w["combined"].keys()],
            [[k, *v.values()] for k, v in w.items()],
            "index weights (AHP + entropy)",
        )
    )
    return decisions, dtables


def _decide_halt(scenario: Scenario, jobs: dict[str, Any]) -> tuple[list[tuple[str, Any]], list[Any]]:
    """Facts and tables of the ``halt`` job for the Decisions section."""
    d = scenario.data
    decisions: list[tuple[str, Any]] = []
    dtables: list[Any] = []
    r = jobs["halt"]["result"]
    source = r.get("qf_source", "")
    if "halt_config" in jobs and d["halt"]["qf_deg"] is None and not d["halt"]["paper_qf"]:
        source = "the optimal halt configuration above (halt_config job)"
    decisions.append(("halt configuration source", source))
    decisions.append(("halt time T [s]", r["T_s"]))
    verdict = "feasible" if r["feasible"] else "INFEASIBLE: no k keeps every limit"
    decisions.append(("verdict", verdict))
    decisions.append(("k* [deg/s^6]" if r["feasible"] else "least-violating k [deg/s^6]", r["k"]))
    decisions.append(
        (
            "global base torque k = 0 -> " + ("k*" if r["feasible"] else "least-violating k") + " [N m]",
            f"{r['global_torque_k0_Nm']:.5g} -> {r['global_torque_Nm']:.5g} ({_pct(r['reduction'])} lower)",
        )
    )
    if r["minimum_T_s"] is not None:
        decisions.append(("smallest feasible halt time [s]", r["minimum_T_s"]))
    return decisions, dtables


def _decide_jump(scenario: Scenario, jobs: dict[str, Any]) -> tuple[list[tuple[str, Any]], list[Any]]:
    """Facts and tables of the ``jump`` job for the Decisions section."""
    decisions: list[tuple[str, Any]] = []
    dtables: list[Any] = []
    r = jobs["jump"]["result"]
    if "kappa_fit" in r:
        f = r["kappa_fit"]
        decisions.append(
            (
                f"kappa(t) [{KAPPA_UNIT}]",
                f"polynomial of order {f['order']} in tau = t/T, segment points "
                f"{_points_text(f['segment_points_s'])}",
            )
        )
        decisions.append(
            (
                f"kappa(t) coefficients (tau^0 first) [{KAPPA_UNIT}]",
                [float(f"{c:.4g}") for c in f["coefficients_tau"]],
            )
        )
    elif r["mode"] == "fail_at":
        decisions.append((f"optimal kappa at the failure [{KAPPA_UNIT}]", r["kappa"]))
    elif np.ndim(r["kappa"]) == 0:
        decisions.append((f"constant kappa [{KAPPA_UNIT}]", r["kappa"]))
    decisions.append(
        (
            "mean jump reduction / share improved",
            f"{_pct(r['mean_reduction'])} / {_pct(r['share_improved'])}",
        )
    )
    return decisions, dtables


def _decide_tolerance_angle(scenario: Scenario, jobs: dict[str, Any]) -> tuple[list[tuple[str, Any]], list[Any]]:
    """Facts and tables of the ``tolerance_angle`` job for the Decisions section."""
    decisions: list[tuple[str, Any]] = []
    dtables: list[Any] = []
    r = jobs["tolerance_angle"]["result"]
    ch = r["chosen"]
    decisions.append(("tolerance angle gamma [deg]", None if ch is None else ch["gamma_deg"]))
    if ch is not None:
        decisions.append(("q at gamma [deg]", [round(v, 4) for v in ch["q_deg"]]))
    return decisions, dtables


def _decide_replan(scenario: Scenario, jobs: dict[str, Any]) -> tuple[list[tuple[str, Any]], list[Any]]:
    """Facts and tables of the ``replan`` job for the Decisions section."""
    decisions: list[tuple[str, Any]] = []
    dtables: list[Any] = []
    r = jobs["replan"]["result"]
    decisions.append(
        (
            "re-plan",
            f"{r['absorbed_waypoints']}/{r['waypoints']} waypoints absorb the lock; gamma {r['gamma_deg_range'][0]:.3f}..{r['gamma_deg_range'][1]:.3f} deg; max tracking error {1e3 * r['max_tracking_position_error_m']:.3f} mm",
        )
    )
    return decisions, dtables


def _decide_workspace(scenario: Scenario, jobs: dict[str, Any]) -> tuple[list[tuple[str, Any]], list[Any]]:
    """Facts and tables of the ``workspace`` job for the Decisions section."""
    decisions: list[tuple[str, Any]] = []
    dtables: list[Any] = []
    r = jobs["workspace"]["result"]
    full = volume_text(r.get("volume_full_m3"), r.get("volume_full_error_m3"))
    if r.get("share_kept_occupancy") is None:  # no lock
        decisions.append(("workspace volume", full))
    else:
        decisions.append(
            (
                "workspace volume before / after the failure"
                if r.get("already_locked_deg")
                else "workspace volume full / locked",
                f"{full} / {volume_text(r.get('volume_locked_m3'), r.get('volume_locked_error_m3'))} "
                f"(kept {share_text(r.get('share_kept'), r.get('share_kept_error'))}; occupancy "
                f"{_pct0(r.get('share_kept_occupancy'))}, from half the samples "
                f"{_pct0(r.get('share_kept_half_samples'))})",
            )
        )
        for w in r.get("warnings", []):
            decisions.append(("workspace: warning", w))
    return decisions, dtables


def _decide_singular(scenario: Scenario, jobs: dict[str, Any]) -> tuple[list[tuple[str, Any]], list[Any]]:
    """Facts and tables of the ``singular`` job for the Decisions section."""
    decisions: list[tuple[str, Any]] = []
    dtables: list[Any] = []
    r = jobs["singular"]["result"]
    if isinstance(r.get("conditions"), dict) and "cond1" in r["conditions"]:
        conds = {**r["conditions"], **r.get("refined_conditions", {})}
        dtables.append(
            (
                ["condition", "equations (004 eq. 30)", "samples", "singular", "fraction", "median sigma_min", "verdict"],
                [
                    [
                        k,
                        p004.CONDITION_TEXT.get(k, ""),
                        c["samples"],
                        c["singular"],
                        c["fraction_singular"],
                        c["sigma_min_median"],
                        _condition_verdict(k, c["sufficient"]),
                    ]
                    for k, c in conds.items()
                ],
                "004's conditions: is every sampled configuration singular? Si = sin(theta_i), Cij = "
                "cos(theta_i + theta_j), ..., lengths virtual (hatted in 004); cond1f is ours",
            )
        )
    elif "families" in r:
        decisions.append(("singular families found", len(r["families"])))
    else:
        decisions.append(("sigma_min / rank", f"{r['sigma_min']:.4g} / {r['rank']}"))
    return decisions, dtables


#: The Decisions section's part of each job, in the order the report lists them.
_DECIDE = {
    "halt_config": _decide_halt_config,
    "halt": _decide_halt,
    "jump": _decide_jump,
    "tolerance_angle": _decide_tolerance_angle,
    "replan": _decide_replan,
    "workspace": _decide_workspace,
    "singular": _decide_singular,
}


def _decisions_section(scenario: Scenario, jobs: dict[str, Any], full: Any, locked: Any) -> list[Section]:
    """What was decided: halt configuration, k, kappa(t), gamma, volumes, conditions."""
    decisions: list[tuple[str, Any]] = []
    tables: list[Any] = []
    for job, decide in _DECIDE.items():
        if job in jobs:
            facts, more = decide(scenario, jobs)
            decisions += facts
            tables += more
    return [Section("Decisions", facts=decisions, tables=tables)]
