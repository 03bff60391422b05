"""``jointlock jump``: keep following the path through an unexpected lock (seed 001).

At one failure time (``--fail-at S``): the velocity jump with and without compensation, the
optimal kappa and its feasible interval, the limits kept.  Over sampled failure times
(``--sweep N``, the default with N = 40): optimal kappa per time, the fitted piecewise
kappa(t), and its verification with the failure injected at every control step.  The optimal
kappa is searched by default (``--optimize`` says so explicitly); ``--kappa K`` uses a
constant instead.  Options that the chosen mode does not use (``--order``, ``--single``,
``--fix`` with ``--fail-at`` or ``--kappa``; ``--sweep`` with ``--kappa``) are reported on
stderr as ignored.
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import ScenarioError
from ..planning.jump import (
    JumpAtTime,
    JumpScenario,
    JumpStudy,
    Verification,
    jump_at_time,
    load_scenario,
    simulate,
    study_jump,
    verify_kappa,
)
from ..progress import Progress
from ..report import atomic_write_bytes, atomic_write_json, atomic_write_text, figure_png
from ..robots import load_robot
from ._common import add_robot_arguments, check_out_dir, print_json, require_finite

#: Largest polynomial order of kappa(t) (the scenario schema's ``jump.order`` cap).
MAX_ORDER = 9

#: Unit of kappa: qdot [rad/s] = kappa * grad w, w = sqrt(det(J J^T)) of the 3 x n position
#: Jacobian [m^3], grad w [m^3/rad] (docs/jump.md).
KAPPA_UNIT = "rad^2/(s m^3)"

#: A start of the example task shown when a robot needs its own q0_deg (NOTES-001's start,
#: cut or padded with zeros to the robot's joints).
_EXAMPLE_Q0 = (10.0, 40.0, -70.0, 100.0, -60.0, 30.0, 20.0)


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "jump",
        help="velocity jump at an unexpected lock: optimal kappa, fitted kappa(t), verification (001)",
        description=(
            "Resolved-rate path following with the null-space compensation kappa (I - J+J) grad w "
            "(seed 001, NOTES-001). Default: NOTES-001's scenario, joint 2 locking, --sweep 40. "
            "Jumps are 2-norms of joint-rate changes, printed and plotted in deg/s (rad/s in the JSON "
            f"output, as its key names say); kappa is in {KAPPA_UNIT}. The task (start q0_deg, line "
            "dx_m, ...) is NOTES-001's for canadarm7; any other robot needs a task file: --scenario "
            "FILE with q0_deg (one angle per joint) -- a flat TOML table, the fields of a run "
            "scenario's [jump] table (docs/jump.md)."
        ),
    )
    add_robot_arguments(
        p,
        lock=False,
        base_default=None,
        base_help="fixed base, or free-floating spacecraft (generalized Jacobian); "
        "default: the scenario file's base, else fixed",
    )
    p.add_argument(
        "--scenario",
        metavar="FILE",
        help="task file, a flat TOML table: q0_deg (one angle per joint [deg]), dx_m, duration_s, ... "
        "(needed for any robot but canadarm7; a `jointlock run` scenario file is run with `jointlock run`)",
    )
    p.add_argument("--lock-joint", type=int, metavar="J", help="joint that locks (from 1; default 2)")
    when = p.add_mutually_exclusive_group()
    when.add_argument("--fail-at", type=float, metavar="S", help="one failure time [s]")
    when.add_argument("--sweep", type=int, metavar="N", help="N sampled failure times (default 40)")
    how = p.add_mutually_exclusive_group()
    how.add_argument(
        "--kappa",
        type=float,
        metavar="K",
        help=f"use this constant kappa [{KAPPA_UNIT}] (no search)",
    )
    how.add_argument(
        "--optimize",
        action="store_true",
        help="search the optimal kappa: the default mode, this flag only makes it explicit",
    )
    p.add_argument(
        "--order",
        type=int,
        default=None,
        help=f"polynomial order of kappa(t), 1..{MAX_ORDER} (default 5; sweep with the search only)",
    )
    p.add_argument(
        "--single",
        action="store_true",
        help="one polynomial for kappa(t) (001's form) instead of a piece per branch of the optimum",
    )
    p.add_argument(
        "--fix",
        choices=("auto", "clip", "ramp", "clip+ramp", "none"),
        default=None,
        help="fix of kappa(t) verified as well (default auto: clip+ramp only when a limit breaks; "
        "sweep with the search only)",
    )
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.add_argument("--out", metavar="DIR", help="write results.json, CSV and figures (PNG) here")
    p.add_argument("--quiet", action="store_true", help="no progress bars")
    p.set_defaults(func=run)


def _scenario(args: argparse.Namespace) -> JumpScenario:
    sc = load_scenario(args.scenario) if args.scenario else JumpScenario()
    fields = sc.to_fields()
    if args.lock_joint is not None:
        fields["lock_joint"] = args.lock_joint
    if args.base is not None:  # the file's base (else the default, fixed) unless --base is given
        fields["base"] = args.base
    from ..planning.jump import scenario_from_mapping

    return scenario_from_mapping(fields, source="command line")


def _check_q0(args: argparse.Namespace, sc: JumpScenario, model: Any) -> None:
    """A start that does not fit the robot: say where it came from and what to give."""
    if len(sc.q0) == model.dof:
        return
    n = model.dof
    example_q0 = ", ".join(f"{v:g}" for v in (list(_EXAMPLE_Q0) + [0.0] * n)[:n])
    example = (
        f"e.g. a file task.toml with the lines `q0_deg = [{example_q0}]` and `dx_m = [0.2, -0.2, 0.1]`, "
        f"then `jointlock jump {args.robot} --scenario task.toml`"
    )
    joints = f"model {model.name!r} has {n} movable joints {list(model.joint_numbers)}"
    if args.scenario is None:
        raise ScenarioError(
            f"the default task is NOTES-001's for canadarm7 (q0_deg: 7 angles); {joints}: a robot other "
            f"than canadarm7 needs --scenario FILE with q0_deg ({n} values [deg]); {example}"
        )
    given = "q0_deg" in _file_fields(args.scenario)
    if not given:
        raise ScenarioError(
            f"{args.scenario} gives no q0_deg, and the default start is canadarm7's 7 angles; {joints}: "
            f"add q0_deg ({n} values [deg]); {example}"
        )
    raise ScenarioError(
        f"{args.scenario}: q0_deg has {len(sc.q0)} angles but {joints}; give {n} values [deg]"
    )


def _file_fields(path: str) -> set[str]:
    import tomllib

    try:
        return set(tomllib.loads(Path(path).read_text(encoding="utf-8")))
    except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError):  # read before, by load_scenario
        return set()


def _limits(rep: Any) -> dict:
    return {
        "ok": rep.ok,
        "max_velocity_deg_s": math.degrees(rep.max_velocity),
        "max_acceleration_deg_s2": math.degrees(rep.max_acceleration),
        "max_deviation_mm": 1e3 * rep.max_deviation,
        "broken": rep.broken(),
    }


def _ver_json(v: Verification) -> dict:
    return {
        "fix": v.fix,
        "mean_jump_before": float(v.jump_before.mean()),
        "mean_jump_after": float(v.jump_after.mean()),
        "mean_reduction": v.mean_reduction,
        "share_improved": v.share_improved,
        "limits_ok": v.limits_ok,
        "healthy_run_ok": v.healthy_ok,
        "limits": _limits(v.limits),
        "broken_failure_times_s": v.broken_steps,
        "sampled_kappas_kept_limits": v.sampled_limits_ok,
        "task_jump_replan_max_m_s": v.task_jump_replan_max,
    }


def _ver_series_json(v: Verification) -> dict:
    """The verification's jumps per failure time, its headline figures and :func:`_ver_json`."""
    return {
        "verification_t_s": v.t,
        "jump_before": v.jump_before,
        "jump_after": v.jump_after,
        "mean_reduction": v.mean_reduction,
        "share_improved": v.share_improved,
        "limits_ok": v.limits_ok,
        "verification": _ver_json(v),
    }


def _warn_ignored(args: argparse.Namespace) -> None:
    """Say on stderr which given options the chosen mode does not use."""
    if args.fail_at is not None or args.kappa is not None:
        mode = "--fail-at" if args.fail_at is not None else "--kappa"
        ignored = [
            opt
            for opt, given in (
                ("--order", args.order is not None),
                ("--single", args.single),
                ("--fix", args.fix is not None),
                ("--sweep", mode == "--kappa" and args.sweep is not None),
            )
            if given
        ]
        if ignored:
            what = (
                "one failure time, no kappa(t) fit"
                if mode == "--fail-at"
                else "a constant kappa verified at every step, no sampling or fit"
            )
            print(
                f"jointlock jump: warning: {', '.join(ignored)} ignored with {mode} ({what})",
                file=sys.stderr,
            )


def run(args: argparse.Namespace) -> int:
    require_finite(args, "kappa", "fail_at")
    if args.sweep is not None and args.sweep < 1:
        raise ScenarioError(f"--sweep must be >= 1; got {args.sweep}")
    if args.order is not None and not 1 <= args.order <= MAX_ORDER:
        raise ScenarioError(f"--order must be 1..{MAX_ORDER}; got {args.order}")
    out_dir = check_out_dir(args.out)
    sc = _scenario(args)
    model = load_robot(args.robot, base=sc.base)
    _check_q0(args, sc, model)
    _warn_ignored(args)
    order = 5 if args.order is None else args.order
    show = not args.quiet

    def bar(total: int, desc: str) -> Progress:
        return Progress(total, desc, enabled=None if show else False)

    if args.fail_at is not None:
        p = bar(2 * sc.n_steps, "kappa search")
        res = jump_at_time(model, sc, args.fail_at, kappa=args.kappa, progress=p)
        p.close()
        result = _single_json(model.name, sc, res)
        if out_dir is not None:
            _single_files(out_dir, model, sc, res, result)
    else:
        n = 40 if args.sweep is None else args.sweep
        fix = {None: "auto", "none": None}.get(args.fix, args.fix)
        if args.kappa is not None:
            study = None
            ver = verify_kappa(model, sc, args.kappa)
            result = _constant_json(model.name, sc, args.kappa, ver)
        else:
            study = study_jump(
                model,
                sc,
                n_samples=n,
                order=order,
                fix=fix,
                fit_options={"piecewise": not args.single},
                progress_factory=bar if show else None,
            )
            result = _study_json(model.name, sc, study)
            ver = study.verification
        if out_dir is not None:
            _sweep_files(out_dir, model, sc, study, ver, result)
    if args.json:
        print_json(result)
        return 0
    _print_text(result, kappa_given=args.kappa is not None)
    if out_dir is not None:
        print(f"\nwrote {out_dir}/results.json and figures")
    return 0


def _single_json(robot: str, sc: JumpScenario, r: JumpAtTime) -> dict:
    return {
        "robot": robot,
        "mode": "fail_at",
        "scenario": sc.to_fields(),
        "lock_joint": sc.lock_joint,
        "fail_time_s": r.fail_time,
        "kappa": r.kappa,
        "kappa_unit": KAPPA_UNIT,
        "kappa_interval": r.interval,
        "jump_before": r.jump_before,
        "jump_after": r.jump_after,
        "mean_reduction": r.reduction,
        "share_improved": float(r.jump_after < r.jump_before),
        "limits_ok": r.limits_after.ok,
        "joint_jump_before_rad_s": r.joint_jump_before,
        "joint_jump_after_rad_s": r.joint_jump_after,
        "joint_jump_noreplan_before": r.joint_jump_noreplan_before,
        "joint_jump_noreplan_after": r.joint_jump_noreplan_after,
        "task_jump_noreplan_before_m_s": r.task_jump_noreplan_before,
        "task_jump_noreplan_after_m_s": r.task_jump_noreplan_after,
        "task_jump_replan_before_m_s": r.task_jump_replan_before,
        "task_jump_replan_after_m_s": r.task_jump_replan_after,
        "limits_before": _limits(r.limits_before),
        "limits_after": _limits(r.limits_after),
    }


def _study_json(robot: str, sc: JumpScenario, st: JumpStudy) -> dict:
    s, f, v = st.search, st.fit, st.verification
    out = {
        "robot": robot,
        "mode": "sweep",
        "scenario": sc.to_fields(),
        "lock_joint": sc.lock_joint,
        "fail_times_s": s.fail_times,
        "kappa": s.kappa_opt,
        "kappa_unit": KAPPA_UNIT,
        "kappa_interval": s.interval,
        "objective_opt": s.objective_opt,
        "objective_zero": s.objective_zero,
        "kappa_fit": {
            "order": f.order,
            "coefficients_tau": f.coefficients,
            "tau": "t / duration_s",
            "ssr": f.ssr,
            "threshold": f.threshold,
            "accepted": f.accepted,
            "segment_points_s": f.segment_points,
            "breaks_s": f.breaks,
            "segments": [{"start_s": a, "end_s": b, "decision": d} for a, b, d in f.segments],
            "pieces": [
                {
                    "start_s": pc.start,
                    "end_s": pc.end,
                    "order": pc.order,
                    "coefficients_u": pc.coefficients,
                    "u": f"(t - {pc.center:.6g}) / {pc.half_width:.6g}",
                    "ssr": pc.ssr,
                    "threshold": pc.threshold,
                    "accepted": pc.accepted,
                    "n_samples": pc.n_samples,
                    "source": pc.source,
                }
                for pc in (f.pieces or ())
            ],
        },
        **_ver_series_json(v),
        "elapsed_s": st.elapsed,
    }
    if st.verification_fixed is not None:
        out["verification_fixed"] = _ver_json(st.verification_fixed)
    return out


def _constant_json(robot: str, sc: JumpScenario, kappa: float, v: Verification) -> dict:
    return {
        "robot": robot,
        "mode": "sweep",
        "scenario": sc.to_fields(),
        "lock_joint": sc.lock_joint,
        "kappa": kappa,
        "kappa_unit": KAPPA_UNIT,
        **_ver_series_json(v),
    }


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


def _kappa(value: float) -> str:
    return f"{value:.6g} {KAPPA_UNIT}"


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


def _print_text(r: dict, *, kappa_given: bool = False) -> None:
    sc = r["scenario"]
    print(
        f"{r['robot']}: joint {r['lock_joint']} locks; task {sc['duration_s']:g} s, dt {sc['dt_s']:g} s, "
        f"limits {sc['vmax_deg_s']:g} deg/s, {sc['amax_deg_s2']:g} deg/s^2, {1e3 * sc['eps_m']:g} mm, "
        f"base {sc['base']}"
    )
    if r["mode"] == "fail_at":
        print(
            f"failure at {r['fail_time_s']:g} s, kappa = {_kappa(r['kappa'])} "
            f"({_interval_text(r, kappa_given)})"
        )
        print(
            f"joint jump ||dq||: {_deg(r['jump_before']):.5g} -> {_deg(r['jump_after']):.5g} deg/s "
            f"({_less(r['mean_reduction'])})"
        )
        print(
            f"without re-planning: locked joint stops from {_deg(r['joint_jump_noreplan_before']):.5g} / "
            f"{_deg(r['joint_jump_noreplan_after']):.5g} deg/s; task jump {r['task_jump_noreplan_before_m_s']:.4g} / "
            f"{r['task_jump_noreplan_after_m_s']:.4g} m/s (re-planned: {r['task_jump_replan_after_m_s']:.2g} m/s)"
        )
        la = r["limits_after"]
        print(
            f"limits kept: {la['ok']} (max {la['max_velocity_deg_s']:.3f} deg/s, "
            f"{la['max_acceleration_deg_s2']:.3f} deg/s^2, {la['max_deviation_mm']:.3f} mm)"
        )
        return
    if "kappa_fit" in r:
        f = r["kappa_fit"]
        k = np.asarray([np.nan if v is None else v for v in r["kappa"]], dtype=float)
        feasible = int(np.sum(np.isfinite(k)))
        if feasible:
            print(
                f"optimal kappa at {len(k)} failure times: {np.nanmin(k):.4g} .. {np.nanmax(k):.4g} "
                f"{KAPPA_UNIT} ({feasible} feasible)"
            )
        else:
            print(f"no feasible kappa at any of the {len(k)} failure times")
        print(
            f"kappa(t): order {f['order']}, SSR {f['ssr']:.3g} (threshold {f['threshold']:.3g}, "
            f"accepted {f['accepted']}), segment points {_points_text(f['segment_points_s'])}"
        )
        if len(f.get("breaks_s", [])):
            print(
                f"  optimal kappa jumps at {', '.join(f'{b:.3g}' for b in f['breaks_s'])} s (piecewise fit)"
            )
        for seg in f.get("segments", []):
            print(f"  segment {seg['start_s']:.3g}..{seg['end_s']:.3g} s: {seg['decision']}")
        for pc in f.get("pieces", []):
            print(
                f"  piece {pc['start_s']:.3g}..{pc['end_s']:.3g} s: order {pc['order']}, {pc['n_samples']} samples, "
                f"SSR {pc['ssr']:.3g} (threshold {pc['threshold']:.3g}), {pc['source']}"
            )
    elif r["kappa"] is not None and np.ndim(r["kappa"]) == 0:
        print(f"constant kappa = {_kappa(r['kappa'])}")
    for key in ("verification", "verification_fixed"):
        if key not in r:
            continue
        v = r[key]
        label = "kappa(t)" if v["fix"] is None else f"kappa(t) with fix {v['fix']}"
        print(
            f"{label}, failure at every step: mean jump {_deg(v['mean_jump_before']):.5g} -> "
            f"{_deg(v['mean_jump_after']):.5g} deg/s ({_less(v['mean_reduction'])}), improved at "
            f"{100 * v['share_improved']:.1f} % of steps, limits kept: {v['limits_ok']}"
        )
        if not v["limits_ok"]:
            times = v["broken_failure_times_s"]
            print(
                f"  broken: {'; '.join(v['limits']['broken'])}"
                + (
                    f" (failure times {times[0]:g}..{times[-1]:g} s)"
                    if len(times)
                    else " (run without failure)"
                )
            )


# -- files and figures ------------------------------------------------------------------------


def _plt():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _save(out_dir: Path, name: str, fig: Any) -> None:
    atomic_write_bytes(out_dir / name, figure_png(fig))
    _plt().close(fig)


def _fig_objective(out_dir: Path, search: Any, f: int, title: str) -> None:
    plt = _plt()
    fig, ax = plt.subplots(figsize=(6, 3.6))
    g, obj, feas = search.kappa_grid, np.degrees(search.objective[:, f]), search.feasible[:, f]
    ax.plot(g, obj, "-", color="0.6")
    ax.plot(g[feas], obj[feas], "o", label="feasible")
    ax.plot(g[~feas], obj[~feas], "x", color="r", label="breaks a limit")
    if np.isfinite(search.kappa_opt[f]):
        ax.plot(search.kappa_opt[f], np.degrees(search.objective_opt[f]), "*", ms=12, label="optimum")
    ax.set_xlabel(f"kappa [{KAPPA_UNIT}]")
    ax.set_ylabel("||dq jump|| [deg/s]")
    ax.set_title(title)
    ax.legend()
    _save(out_dir, "fig5_objective_vs_kappa.png", fig)


def _fig_runs(out_dir: Path, model: Any, sc: JumpScenario, kappa: Any, t_fail: float) -> None:
    plt = _plt()
    r0 = simulate(model, sc, 0.0, failures=[(sc.lock_joint, t_fail)])
    r1 = simulate(model, sc, kappa, failures=[(sc.lock_joint, t_fail)])
    t = r0.t[:-1]
    fig, axes = plt.subplots(1, 2, figsize=(10, 3.6))
    j = model.index_of(sc.lock_joint)
    other = (j + 1) % model.dof
    for ax, col in zip(axes, (j, other)):
        ax.step(t, np.degrees(r0.qd[:, col]), where="post", label="kappa = 0")
        ax.step(t, np.degrees(r1.qd[:, col]), where="post", label="compensated")
        ax.axvline(t_fail, color="k", lw=0.6, ls=":")
        ax.set_title(f"joint {model.joint_numbers[col]}" + (" (locked)" if col == j else ""))
        ax.set_xlabel("t [s]")
        ax.set_ylabel("joint rate [deg/s]")
        ax.legend()
    _save(out_dir, "fig6_joint_velocities.png", fig)
    fig, ax = plt.subplots(figsize=(6, 3.6))
    ax.plot(r0.t, 1e3 * r0.deviation, label="kappa = 0")
    ax.plot(r1.t, 1e3 * r1.deviation, label="compensated")
    ax.axhline(1e3 * sc.eps, color="r", ls="--", label="threshold")
    ax.axvline(t_fail, color="k", lw=0.6, ls=":")
    ax.set_xlabel("t [s]")
    ax.set_ylabel("||x - x_nom|| [mm]")
    ax.legend()
    _save(out_dir, "fig7_position_deviation.png", fig)


def _single_files(out_dir: Path, model: Any, sc: JumpScenario, res: JumpAtTime, result: dict) -> None:
    atomic_write_json(out_dir / "results.json", result)
    if res.search is not None:
        _fig_objective(out_dir, res.search, 0, f"failure at {res.fail_time:g} s")
    _fig_runs(out_dir, model, sc, res.kappa, res.fail_time)


def _sweep_files(
    out_dir: Path, model: Any, sc: JumpScenario, st: JumpStudy | None, ver: Verification, result: dict
) -> None:
    plt = _plt()
    atomic_write_json(out_dir / "results.json", result)
    rows = ["t_fail_s,kappa,jump_before_rad_s,jump_after_rad_s,limits_ok"]
    rows += [
        f"{t:.6g},{k:.9g},{b:.9g},{a:.9g},{int(ok)}"
        for t, k, b, a, ok in zip(ver.t, ver.kappa, ver.jump_before, ver.jump_after, ver.limits_ok_per_step)
    ]
    atomic_write_text(out_dir / "verification.csv", "\n".join(rows) + "\n")
    mid_t = sc.duration / 2
    if st is not None:
        s, f = st.search, st.fit
        mid = int(np.argmin(np.abs(s.fail_times - mid_t)))
        _fig_objective(out_dir, s, mid, f"failure at {s.fail_times[mid]:g} s")
        fig, ax = plt.subplots(figsize=(6, 3.6))
        ax.plot(s.fail_times, s.kappa_opt, "o", label="optimal kappa (samples)")
        tt = np.linspace(0, sc.duration, 400)
        ax.plot(tt, f.polynomial(tt), "--", color="0.5", label=f"polynomial, order {f.order}")
        ax.plot(tt, f(tt), "-", label="kappa(t), piecewise")
        for tp in f.segment_points:
            if np.isfinite(tp):
                ax.axvline(tp, color="k", lw=0.6, ls=":")
        for tb in f.breaks:
            ax.axvline(tb, color="r", lw=0.6, ls="--")
        ax.set_xlabel("failure time [s]")
        ax.set_ylabel(f"kappa [{KAPPA_UNIT}]")
        ax.legend()
        _save(out_dir, "fig8_kappa_fit.png", fig)
    k_mid = ver.kappa
    _fig_runs(out_dir, model, sc, k_mid, float(np.round(mid_t / sc.dt) * sc.dt))
    fig, ax = plt.subplots(figsize=(7, 3.6))
    ax.plot(ver.t, np.degrees(ver.jump_before), label="kappa = 0")
    ax.plot(ver.t, np.degrees(ver.jump_after), label="kappa(t)")
    if st is not None and st.verification_fixed is not None:
        ax.plot(
            st.verification_fixed.t,
            np.degrees(st.verification_fixed.jump_after),
            ":",
            label=f"kappa(t), {st.verification_fixed.fix}",
        )
    ax.set_xlabel("failure time [s]")
    ax.set_ylabel("||dq jump|| [deg/s]")
    ax.legend()
    _save(out_dir, "fig9_jump_vs_failure_time.png", fig)
