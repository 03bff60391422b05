"""Headline figures of a scenario run (``summary`` in results.json) and the lines
``jointlock run`` prints."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..analysis.workspace import share_text, volume_text


def summarize(jobs: dict[str, dict]) -> dict[str, Any]:
    """Headline figures of each job (plain data)."""
    s: dict[str, Any] = {}
    if "halt_config" in jobs:
        r = jobs["halt_config"]["result"]
        s["halt_config"] = {
            "q_best_deg": r["best"]["q_deg"],
            "cp_best": r["best"]["cp"],
            "cp_best_sample": r["best_sample"]["cp"],
            "refinement_gain": r["refinement"]["gain"],
        }
        if (clear := r.get("clearance")) is not None:
            s["halt_config"].update(
                clearance_m=clear["best"]["min_clearance_m"],
                clearance_pair=clear["best"]["closest_pair"],
                clearance_required_m=clear["required_m"],
                colliding_samples=clear["colliding_samples"],
            )
    if "halt" in jobs:
        r = jobs["halt"]["result"]
        s["halt"] = {
            "feasible": r["feasible"],
            "k_deg_s6": r["k"],
            "global_torque_Nm": r["global_torque_Nm"],
            "global_torque_k0_Nm": r["global_torque_k0_Nm"],
            "reduction": r["reduction"],
            "minimum_T_s": r["minimum_T_s"],
            "violations": len(r["violations"]),
        }
        if (clear := r.get("clearance")) is not None:
            s["halt"]["clearance"] = {
                key: clear[key]
                for key in ("collides", "start_m", "motion_min_m", "motion_min_pair", "motion_min_time_s", "verdict")
            }
        if (wheels := r.get("attitude_control")) is not None:
            s["halt"]["attitude_control"] = {
                key: wheels[key] for key in ("peak_torque_Nm", "peak_momentum_Nms", "within", "verdict")
            }
        if r.get("state_source", "").startswith("task at"):
            s["halt"]["state_source"] = r["state_source"]
    if "jump" in jobs:
        r = jobs["jump"]["result"]
        s["jump"] = {
            "mode": r["mode"],
            "mean_reduction": r["mean_reduction"],
            "share_improved": r["share_improved"],
            "limits_ok": r["limits_ok"],
        }
        if "verification_fixed" in r:
            v = r["verification_fixed"]
            s["jump"]["fixed"] = {
                "fix": v["fix"],
                "mean_reduction": v["mean_reduction"],
                "share_improved": v["share_improved"],
                "limits_ok": v["limits_ok"],
            }
    if "tolerance_angle" in jobs:
        r = jobs["tolerance_angle"]["result"]
        s["tolerance_angle"] = {
            "absorbable_range_deg": r["absorbable_range_deg"],
            "gamma_deg": None if r["chosen"] is None else r["chosen"]["gamma_deg"],
        }
    if "replan" in jobs:
        r = jobs["replan"]["result"]
        s["replan"] = {
            "absorbed_waypoints": r["absorbed_waypoints"],
            "waypoints": r["waypoints"],
            "max_tracking_position_error_m": r["max_tracking_position_error_m"],
        }
    if "workspace" in jobs:
        r = jobs["workspace"]["result"]
        s["workspace"] = {
            k: r.get(k)
            for k in (
                "volume_full_m3",
                "volume_full_error_m3",
                "volume_locked_m3",
                "volume_locked_error_m3",
                "share_kept",
                "share_kept_error",
                "occupancy_full_m3",
                "occupancy_locked_m3",
                "share_kept_occupancy",
                "share_kept_half_samples",
                "warnings",
            )
        }
        if r.get("already_locked_deg"):
            s["workspace"]["already_locked_deg"] = r["already_locked_deg"]
    if "singular" in jobs:
        r = jobs["singular"]["result"]
        if "conditions" in r and isinstance(r["conditions"], dict) and "cond1" in r["conditions"]:
            s["singular"] = {
                k: {"sufficient": c["sufficient"], "fraction_singular": c["fraction_singular"]}
                for k, c in {**r["conditions"], **r.get("refined_conditions", {})}.items()
            }
        elif "families" in r:
            s["singular"] = {"families": len(r["families"]), "converged": r["converged"]}
        else:
            s["singular"] = {
                "sigma_min": r.get("sigma_min"),
                "rank": r.get("rank"),
                "singular": r.get("singular"),
            }
    return s


def _pct(x: Any) -> str:
    return "n/a" if x is None or not math.isfinite(float(x)) else f"{100 * float(x):.1f} %"


def _pct0(x: Any) -> str:
    """A Monte Carlo share, to the percent (its further digits move with the sample count)."""
    return "n/a" if x is None else f"{100 * float(x):.0f} %"


def summary_lines(results: dict[str, Any]) -> list[str]:
    """Human-readable summary of a run (a few lines per job)."""
    s = results["summary"]
    lines = [f"{results['title']}  ({results['scenario_file']}, seed {results['seed']})"]
    first = []
    verdict = ((s.get("halt") or {}).get("clearance") or {}).get("verdict")
    if verdict:  # a halt that comes too close says so first
        first.append(verdict)
    wheels = (s.get("halt") or {}).get("attitude_control") or {}
    if wheels.get("within") is False:  # ... then one that needs more than the wheels can give
        first.append(wheels["verdict"])
    lines[:0] = first
    if "halt_config" in s:
        h = s["halt_config"]
        q = ", ".join(f"{v:.2f}" for v in h["q_best_deg"])
        lines.append(f"  halt configuration: [{q}] deg, CP {h['cp_best']:.4f}")
        if h.get("clearance_m") is not None:
            excluded = h["colliding_samples"]
            lines.append(
                f"  clearance {h['clearance_m']:+.3f} m ({h['clearance_pair']})"
                + ("" if excluded is None else f"; {excluded} samples closer than {h['clearance_required_m']:g} m excluded")
            )
    if "halt" in s:
        h = s["halt"]
        if h["feasible"]:
            lines.append(
                f"  halt motion: feasible, k* = {np.ravel(h['k_deg_s6'])[0]:.4g} deg/s^6, base torque "
                f"{h['global_torque_k0_Nm']:.4g} -> {h['global_torque_Nm']:.4g} N m ({_pct(h['reduction'])} lower)"
            )
        else:
            t = h["minimum_T_s"]
            lines.append(
                f"  halt motion: INFEASIBLE, {h['violations']} limit(s) broken at the least-violating k; "
                f"smallest feasible halt time {'n/a' if t is None else f'{t:.3f} s'}"
            )
        if h.get("state_source"):
            lines.append(f"  state at failure: the {h['state_source']}")
        if (wheels := h.get("attitude_control")) is not None:
            lines.append(f"  {wheels['verdict']}")
    if "jump" in s:
        j = s["jump"]
        lines.append(
            f"  jump: mean reduction {_pct(j['mean_reduction'])}, improved at {_pct(j['share_improved'])} "
            f"of failure times, limits kept: {j['limits_ok']}"
        )
        if "fixed" in j:
            f = j["fixed"]
            lines.append(
                f"        with {f['fix']}: {_pct(f['mean_reduction'])}, {_pct(f['share_improved'])}, "
                f"limits kept: {f['limits_ok']}"
            )
    if "tolerance_angle" in s:
        t = s["tolerance_angle"]
        rng = "; ".join(f"{k}: {lo:.2f}..{hi:.2f} deg" for k, (lo, hi) in t["absorbable_range_deg"].items())
        g = t["gamma_deg"]
        lines.append(
            f"  tolerance angle: gamma = {'none' if g is None else f'{g:.4f} deg'}; absorbable {rng}"
        )
    if "replan" in s:
        r = s["replan"]
        lines.append(
            f"  replan: lock absorbed at {r['absorbed_waypoints']}/{r['waypoints']} waypoints, max tracking "
            f"error {1e3 * r['max_tracking_position_error_m']:.3f} mm"
        )
    if "workspace" in s:
        w = s["workspace"]
        lines.append(
            f"  workspace: {'before the failure' if w.get('already_locked_deg') else 'full'} "
            f"{volume_text(w.get('volume_full_m3'), w.get('volume_full_error_m3'))}"
            + (
                f", locked {volume_text(w.get('volume_locked_m3'), w.get('volume_locked_error_m3'))}, kept "
                f"{share_text(w.get('share_kept'), w.get('share_kept_error'))} (occupancy {_pct0(w['share_kept_occupancy'])}, "
                f"half the samples: {_pct0(w.get('share_kept_half_samples'))})"
                + ("; not converged" if w.get("warnings") else "")
                if w.get("share_kept_occupancy") is not None
                else ""
            )
        )
    if "singular" in s:
        g = s["singular"]
        if "cond1" in g:
            lines.append(
                "  singular: "
                + ", ".join(
                    f"{k} {'sufficient' if c['sufficient'] else 'NOT sufficient'}"
                    + (" (ours)" if k == "cond1f" else "")
                    for k, c in g.items()
                )
            )
        else:
            lines.append("  singular: " + ", ".join(f"{k} {v}" for k, v in g.items()))
    for job, check in (results.get("checks") or {}).items():
        lines.append(f"  checked in {check['simulator']} ({job}): " + check_text(check))
    return lines


def check_text(check: dict[str, Any]) -> str:
    """A replay's rows (:meth:`jointlock.sim.Replay.to_dict`) in one line: each figure's
    jointlock value and the simulator's difference from it."""
    return ", ".join(
        f"{r['short']} {r['jointlock']:.4g} {r['unit']} (MuJoCo {r['difference']:+.1e})" for r in check["rows"] if r.get("short")
    )
