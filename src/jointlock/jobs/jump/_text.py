"""The text of ``jointlock jump``: :func:`summary_lines` from the command's JSON object, and
its phrases."""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np

from ...plots.jump import KAPPA_UNIT


def _share(share: float | None) -> str:
    """``"97.5 %"``; ``"n/a (no jump)"`` when no failure time has a jump to improve."""
    return "n/a (no jump)" if share is None or not math.isfinite(share) else f"{100 * share:.1f} %"


def _less(reduction: float | None) -> str:
    """``"12.3 % less"``; ``"34x larger"`` (or ``"5.0 % larger"``) when the compensation makes
    the jump larger; ``"reduction n/a"`` when it is undefined (no jump before)."""
    if reduction is None or not math.isfinite(reduction):
        return "reduction n/a: no jump without compensation"
    if reduction >= 0:
        return f"{100 * reduction:.1f} % less"
    ratio = 1.0 - reduction  # after / before
    return f"{ratio:.3g}x larger" if ratio >= 2 else f"{-100 * reduction:.1f} % larger"


def _deg(rad_s: float) -> float:
    return math.degrees(rad_s)


def _kappa(value: float | None) -> str:
    return "none" if value is None else f"{value:.6g} {KAPPA_UNIT}"


def _interval_text(r: dict, given: bool) -> str:
    lo, hi = (np.nan, np.nan) if r["kappa_interval"] is None else r["kappa_interval"]
    lo = np.nan if lo is None else lo
    hi = np.nan if hi is None else hi
    if np.isfinite(lo) and np.isfinite(hi):
        return f"feasible [{lo:.4g}, {hi:.4g}]"
    return "given, feasible interval not searched" if given else "no feasible kappa"


def _points_text(points: list) -> str:
    """001's segment points [s]; NaN (kappa falls back to 0 over the whole task) -> none."""
    vals = [np.nan if p is None else float(p) for p in points]
    if not any(np.isfinite(vals)):
        return "none (kappa = 0 everywhere)"
    return ", ".join(f"{v:.3g} s" if np.isfinite(v) else "none" for v in vals)


def summary_lines(r: Mapping[str, Any], *, kappa_given: bool = False) -> list[str]:
    """The text of ``jointlock jump`` from its JSON object ``r`` (:meth:`JumpJobResult.to_dict`)."""
    sc = r["scenario"]
    lines = [
        f"{r['robot']}: joint {r['lock_joint']} locks; task {sc['duration_s']:g} s, dt {sc['dt_s']:g} s, "
        f"limits {sc['vmax_deg_s']:g} deg/s, {sc['amax_deg_s2']:g} deg/s^2, {1e3 * sc['eps_m']:g} mm, "
        f"base {sc['base']}"
    ]
    if r["mode"] == "fail_at":
        la = r["limits_after"]
        lines += [
            f"failure at {r['fail_time_s']:g} s, kappa = {_kappa(r['kappa'])} "
            f"({_interval_text(dict(r), kappa_given)})",
            f"joint jump ||dq||: {_deg(r['jump_before']):.5g} -> {_deg(r['jump_after']):.5g} deg/s "
            f"({'not compensated' if r.get('infeasible') else _less(r['mean_reduction'])})",
            f"without re-planning: locked joint stops from {_deg(r['joint_jump_noreplan_before']):.5g} / "
            f"{_deg(r['joint_jump_noreplan_after']):.5g} deg/s; task jump {r['task_jump_noreplan_before_m_s']:.4g} / "
            f"{r['task_jump_noreplan_after_m_s']:.4g} m/s (re-planned: {r['task_jump_replan_after_m_s']:.2g} m/s)",
            f"limits kept: {la['ok']} (max {la['max_velocity_deg_s']:.3f} deg/s, "
            f"{la['max_acceleration_deg_s2']:.3f} deg/s^2, {la['max_deviation_mm']:.3f} mm)",
        ]
        if r.get("infeasible"):
            lines.insert(0, f"INFEASIBLE: {r['infeasible']} (the jump below is the uncompensated one, kappa = 0)")
        return lines
    if "kappa_fit" in r:
        f = r["kappa_fit"]
        k = np.asarray([np.nan if v is None else v for v in r["kappa"]], dtype=float)
        feasible = int(np.sum(np.isfinite(k)))
        if feasible:
            lines.append(
                f"optimal kappa at {len(k)} failure times: {np.nanmin(k):.4g} .. {np.nanmax(k):.4g} "
                f"{KAPPA_UNIT} ({feasible} feasible)"
            )
        else:
            lines.append(f"no feasible kappa at any of the {len(k)} failure times")
        lines.append(
            f"kappa(t): order {f['order']}, SSR {f['ssr']:.3g} (threshold {f['threshold']:.3g}, "
            f"accepted {f['accepted']}), segment points {_points_text(f['segment_points_s'])}"
        )
        if len(f.get("breaks_s", [])):
            lines.append(
                f"  optimal kappa jumps at {', '.join(f'{b:.3g}' for b in f['breaks_s'])} s (piecewise fit)"
            )
        for seg in f.get("segments", []):
            lines.append(f"  segment {seg['start_s']:.3g}..{seg['end_s']:.3g} s: {seg['decision']}")
        for pc in f.get("pieces", []):
            lines.append(
                f"  piece {pc['start_s']:.3g}..{pc['end_s']:.3g} s: order {pc['order']}, {pc['n_samples']} samples, "
                f"SSR {pc['ssr']:.3g} (threshold {pc['threshold']:.3g}), {pc['source']}"
            )
    elif r["kappa"] is not None and np.ndim(r["kappa"]) == 0:
        lines.append(f"constant kappa = {_kappa(r['kappa'])}")
    for key in ("verification", "verification_fixed"):
        if key not in r:
            continue
        v = r[key]
        label = "kappa(t)" if v["fix"] is None else f"kappa(t) with fix {v['fix']}"
        lines.append(
            f"{label}, failure at every step: mean jump {_deg(v['mean_jump_before']):.5g} -> "
            f"{_deg(v['mean_jump_after']):.5g} deg/s ({_less(v['mean_reduction'])}), improved at "
            f"{_share(v['share_improved'])} of steps, limits kept: {v['limits_ok']}"
        )
        if not v["limits_ok"]:
            times = v["broken_failure_times_s"]
            lines.append(
                f"  broken: {'; '.join(v['limits']['broken'])}"
                + (
                    f" (failure times {times[0]:g}..{times[-1]:g} s)"
                    if len(times)
                    else " (run without failure)"
                )
            )
    return lines
