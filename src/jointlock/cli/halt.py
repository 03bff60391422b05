"""``jointlock halt``: the halt strategy of seed 000 -- optimal halt configuration (unless
``--qf-deg``/``--paper-qf``), then the optimal halt motion (§4), with plots and time series.

With no options beyond the robot, ``halt7`` runs 000 §5's scenario: joint 4 locked at 0,
q0/dq0/ddq0, the 40 deg/s and 20 deg/s^2 limits and T = 10 s of §5.2.
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import ModelError, ScenarioError
from ..locking import lock_joints
from ..planning.ga import GASettings
from ..planning.halt_motion import (
    K_UNIT_SCALE,
    HaltMotion,
    HaltProblem,
    base_torque_history,
    global_base_torque,
    infeasibility_message,
    optimal_halt_motion,
)
from ..progress import Progress
from ..robots import load_robot
from ._common import (
    add_robot_arguments,
    check_out_dir,
    joint_vector_deg,
    lock_map,
    locked_deg,
    locked_text,
    print_json,
    seed_arg,
)

#: 000 §5.1-5.2 scenario on halt7 (healthy joints 1, 2, 3, 5, 6, 7) [deg, deg/s, deg/s^2, s].
PAPER_SCENARIO: dict[str, Any] = {
    "lock": {4: 0.0},
    "q0_deg": [-180.0, -180.0, -100.0, -10.0, 20.0, 20.0],
    "dq0_deg": [20.0, 30.0, 15.0, 25.0, 40.0, 35.0],
    "ddq0_deg": [8.0, 10.0, 12.0, 10.0, -8.0, 6.0],
    "T": 10.0,
    "vmax_deg": 40.0,
    "amax_deg": 20.0,
    "qf_deg": [-167.0, -90.0, 40.0, -158.0, 90.0, -62.0],  # 000's printed q_best
}
#: 000's printed results (§5.2): k [deg/s^6], global torque at k = 0 and at k* [N m].
PAPER_RESULTS = {"k": 0.0018, "global_torque_k0_Nm": 22.25, "global_torque_Nm": 15.55, "reduction": 0.301}


#: Jacobian of the halt-configuration search (CP): 000 §3.1.2's generalized Jacobian J_F of
#: the free-floating arm, whatever --base (which sets the base of the disturbance torque only).
HCOM_JACOBIAN = "generalized"
BASE_HELP = (
    "base of the disturbance torque: fixed (000, default) or free-floating spacecraft; the halt "
    "configuration is searched with the free-floating arm's generalized Jacobian J_F either way "
    "(000 §3.1.2)"
)


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "halt",
        help="optimal halt configuration and optimal halt motion after a lock (seed 000)",
        description=(
            "Halt a crippled arm: optimal halt configuration (Monte Carlo + refinement) unless --qf-deg "
            "or --paper-qf is given, then the 6th-order halt polynomial with the free coefficient k "
            "(000 eq. 27) minimising the global base disturbance torque (eq. 32) under angle/velocity/"
            "acceleration limits. k is reported in deg/s^6 (000's reading). Without options, halt7 runs "
            "000 §5's scenario."
        ),
    )
    add_robot_arguments(p, base_help=BASE_HELP)
    p.add_argument("--q0-deg", type=float, nargs="+", metavar="DEG", help="angles at failure [deg]")
    p.add_argument("--dq0-deg", type=float, nargs="+", metavar="DEG", help="rates at failure [deg/s]")
    p.add_argument(
        "--ddq0-deg", type=float, nargs="+", metavar="DEG", help="accelerations at failure [deg/s^2]"
    )
    p.add_argument("--T", type=float, help="halt time [s] (000: 10)")
    qf = p.add_mutually_exclusive_group()
    qf.add_argument("--qf-deg", type=float, nargs="+", metavar="DEG", help="halt configuration [deg]")
    qf.add_argument("--paper-qf", action="store_true", help="use 000's printed q_best (halt7 only)")
    p.add_argument(
        "--vmax-deg", type=float, nargs="+", metavar="DEG", help="speed limit(s) [deg/s] (000: 40)"
    )
    p.add_argument(
        "--amax-deg", type=float, nargs="+", metavar="DEG", help="acceleration limit(s) [deg/s^2] (000: 20)"
    )
    p.add_argument("--solver", choices=("scan", "ga", "vector"), default="scan", help="default scan (exact)")
    p.add_argument(
        "--seed", type=seed_arg, default=0, help="seed of the GA and the Monte Carlo search (default 0)"
    )
    p.add_argument(
        "--samples", type=int, default=36000, help="Monte Carlo samples for the halt configuration"
    )
    p.add_argument(
        "--no-reachability",
        action="store_true",
        help="search the halt configuration over the whole joint ranges (000's way) instead of only "
        "among configurations the halt polynomial reaches from the state within T under the limits "
        "(exact constraint, the default)",
    )
    p.add_argument("--n-samples", type=int, default=501, help="time samples of the objective (odd)")
    p.add_argument("--generations", type=int, default=100, help="GA generations (default 100)")
    p.add_argument("--population", type=int, default=50, help="GA population (default 50)")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.add_argument("--out", metavar="DIR", help="write plots (PNG), time series (CSV, NPZ) and result.json")
    p.add_argument("--quiet", action="store_true", help="no progress bars")
    p.set_defaults(func=run)


def _deg_vec(model, values, default, option) -> np.ndarray:
    if values is None:
        if default is None:
            raise ScenarioError(f"{option} is required for this robot (000's defaults apply to halt7 only)")
        values = default
    return joint_vector_deg(model, list(values), option, rates=option != "--q0-deg")


def _limit(values, default, option, n) -> np.ndarray:
    if values is None:
        values = [default]
    arr = np.radians(np.asarray(values, dtype=float))
    if arr.size == 1:
        arr = np.full(n, arr[0])
    if arr.shape != (n,) or not np.all(arr > 0):
        raise ScenarioError(f"{option} needs one value or {n} values > 0; got {values}")
    return arr


def build_problem(args: argparse.Namespace, progress_enabled: bool) -> tuple[HaltProblem, dict]:
    """Parse the options into a :class:`HaltProblem` (+ notes on where ``qf`` came from)."""
    paper = args.robot == "halt7"
    defaults = PAPER_SCENARIO if paper else {}
    locks = (
        lock_map(args.lock)
        if args.lock
        else {j: math.radians(a) for j, a in defaults.get("lock", {}).items()}
    )
    # moment point of the base torque: the spacecraft's centre of mass (000 eq. 30), so the
    # model carries the spacecraft even when the base is held fixed.
    try:
        model = load_robot(args.robot, base="floating")
    except ModelError:
        if args.base == "floating":
            raise
        model = load_robot(args.robot, base="fixed")
    model = lock_joints(model, locks) if locks else model
    q0 = _deg_vec(model, args.q0_deg, defaults.get("q0_deg"), "--q0-deg")
    dq0 = _deg_vec(model, args.dq0_deg, defaults.get("dq0_deg"), "--dq0-deg")
    ddq0 = _deg_vec(model, args.ddq0_deg, defaults.get("ddq0_deg"), "--ddq0-deg")
    T = args.T if args.T is not None else defaults.get("T")
    if T is None:
        raise ScenarioError("--T (halt time [s]) is required for this robot")
    vmax = _limit(args.vmax_deg, defaults.get("vmax_deg", None) or 40.0, "--vmax-deg", model.dof)
    amax = _limit(args.amax_deg, defaults.get("amax_deg", None) or 20.0, "--amax-deg", model.dof)
    notes: dict[str, Any] = {}
    if args.qf_deg is not None:
        qf = joint_vector_deg(model, args.qf_deg, "--qf-deg")
        notes["qf_source"] = "--qf-deg"
    elif args.paper_qf:
        if not paper:
            raise ScenarioError("--paper-qf is 000's q_best for halt7 only; give --qf-deg")
        qf = joint_vector_deg(model, PAPER_SCENARIO["qf_deg"], "--paper-qf")
        notes["qf_source"] = "000's printed q_best"
    else:
        from ..errors import InfeasibleError
        from ..planning.halt_config import HaltReachability, optimal_halt_configuration

        reach = None
        if not getattr(args, "no_reachability", False):
            # Only configurations the halt polynomial reaches from the state within T under
            # the limits (exact, same grid as the halt motion): 000 samples the whole ranges,
            # and its optimum can then have no feasible halt motion at all.
            reach = HaltReachability(
                q0, dq0, ddq0, float(T), vmax, amax, per_joint=getattr(args, "solver", "scan") == "vector"
            )
        bar = Progress(args.samples, "halt configuration", enabled=progress_enabled)
        try:
            hc = optimal_halt_configuration(
                model,
                samples=args.samples,
                rng=args.seed,
                jacobian=HCOM_JACOBIAN,
                progress=bar,
                reachability=reach,
            )
        except InfeasibleError as exc:
            if reach is None:
                raise
            notes["reachability"] = f"not met, searched the whole ranges instead (000's way): {exc}"
            bar.close()
            bar = Progress(args.samples, "halt configuration", enabled=progress_enabled)
            hc = optimal_halt_configuration(
                model, samples=args.samples, rng=args.seed, jacobian=HCOM_JACOBIAN, progress=bar
            )
        bar.close()
        if reach is not None and hc.reachability is not None:
            notes["reachability"] = (
                f"exact: {hc.reachable_samples} of {args.samples} samples reachable by the halt polynomial "
                f"within T = {float(T):g} s under the limits"
            )
            notes["reachable_samples"] = hc.reachable_samples
        qf = np.asarray(hc.q_best, dtype=float)
        notes["qf_source"] = (
            f"optimal halt configuration (Monte Carlo, {args.samples} samples, seed {args.seed})"
        )
        notes["cp_best"] = float(getattr(hc, "cp_best", float("nan")))
        notes["hcom_jacobian"] = hc.jacobian
        notes["hcom_base"] = hc.base
    problem = HaltProblem(
        model, q0, dq0, ddq0, qf, float(T), vmax, amax, base=args.base, n_samples=args.n_samples
    )
    return problem, notes


def _jacobian_text(notes: dict) -> str:
    if notes.get("hcom_base") == "fixed":  # a robot without a spacecraft: J_F is the fixed-base one
        return "generalized Jacobian, which for this fixed-base model is the fixed-base Jacobian"
    return "free-floating arm's generalized Jacobian J_F (000 §3.1.2)"


def result_dict(res: HaltMotion, notes: dict) -> dict:
    p = res.problem
    scale = K_UNIT_SCALE["deg/s^6"]
    q, dq, ddq = res.trajectory(p.times(p.n_check))
    return {
        "robot": p.model.name,
        "base": p.base,
        "joint_numbers": list(p.model.joint_numbers),
        "locked": locked_deg(p.model),
        "T_s": p.T,
        "k": np.asarray(res.k) / scale,
        "k_unit": "deg/s^6",
        "k_rad": res.k,
        "global_torque_Nm": res.global_torque,
        "global_torque_k0_Nm": res.global_torque_k0,
        "reduction": None if math.isnan(res.reduction) else res.reduction,
        "feasible": res.feasible,
        "violations": [_violation(v) for v in res.violations],
        "violations_k0": [_violation(v) for v in res.violations_k0],
        "k_interval_deg": res.k_interval / scale,
        **({"joint_k_intervals_deg": res.joint_intervals / scale} if res.per_joint else {}),
        "minimum_T_s": res.minimum_T,
        "q_initial_deg": np.degrees(p.q0),
        "q_final_deg": np.degrees(p.qf),
        "peak_velocity_deg_s": np.degrees(np.abs(dq).max(axis=0)),
        "peak_acceleration_deg_s2": np.degrees(np.abs(ddq).max(axis=0)),
        "velocity_limit_deg_s": np.degrees(p.dq_max),
        "acceleration_limit_deg_s2": np.degrees(p.ddq_max),
        "solver": res.solver,
        "seed": res.seed,
        "paper": PAPER_RESULTS,
        **notes,
    }


def _violation(v) -> dict:
    return {
        "joint": v.joint,
        "limit": v.kind,
        "limit_value_deg": math.degrees(v.limit),
        "value_deg": math.degrees(v.value),
        "excess_deg": math.degrees(v.excess),
        "time_s": v.time,
    }


def write_outputs(res: HaltMotion, out: Path, data: dict) -> list[str]:
    """Plots like 000 Figs. 8-9, base torque vs time, time series (CSV, NPZ), result.json."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from ..report import atomic_write_bytes, atomic_write_json, atomic_write_text, figure_png

    p = res.problem
    scale = K_UNIT_SCALE["deg/s^6"]
    out.mkdir(parents=True, exist_ok=True)
    written = []
    # Fig. 8: global torque vs k
    k_star = float(np.mean(res.k)) if res.per_joint else float(res.k)
    lo, hi = res.k_interval
    span = [0.0, max(0.01 * scale, 1.5 * abs(k_star))]
    if lo <= hi:
        span = [min(span[0], lo - 0.2 * (hi - lo)), max(span[1], hi + 0.2 * (hi - lo))]
    grid = np.linspace(span[0], span[1], 201)
    tau = global_base_torque(p, grid)
    fig, ax = plt.subplots(figsize=(7, 4))
    ax.plot(grid / scale, tau, label=r"$\bar\tau_b(k)$")
    if lo <= hi:
        ax.axvspan(lo / scale, hi / scale, color="g", alpha=0.15, label="feasible k")
    ax.plot([k_star / scale], [res.global_torque], "r*", ms=12, label=f"k* = {k_star / scale:.5g}")
    ax.set_xlabel("k [deg/s$^6$]")
    ax.set_ylabel("global base torque [N m]")
    ax.set_title(f"global base disturbance torque vs k ({p.base} base)")
    ax.legend()
    atomic_write_bytes(out / "global_torque_vs_k.png", figure_png(fig))
    plt.close(fig)
    written.append("global_torque_vs_k.png")
    # Fig. 9: angle / velocity / acceleration per joint
    t = p.times()
    q, dq, ddq = res.trajectory(t)
    q0_, dq0_, ddq0_ = p.trajectory(0.0, t)
    n = p.dof
    fig, axes = plt.subplots(3, n, figsize=(3 * n, 7), sharex=True)
    for j in range(n):
        for row, (a, b, lim, label) in enumerate(
            (
                (q, q0_, None, "angle [deg]"),
                (dq, dq0_, p.dq_max[j], "velocity [deg/s]"),
                (ddq, ddq0_, p.ddq_max[j], "acc. [deg/s$^2$]"),
            )
        ):
            ax = axes[row, j]
            ax.plot(t, np.degrees(a[:, j]), label="k*")
            ax.plot(t, np.degrees(b[:, j]), "--", lw=0.8, label="k = 0")
            if lim is not None:
                for s in (-1, 1):
                    ax.axhline(s * math.degrees(lim), color="r", lw=0.6)
            if j == 0:
                ax.set_ylabel(label)
        axes[0, j].set_title(f"joint {p.model.joint_numbers[j]}")
        axes[2, j].set_xlabel("t [s]")
    axes[0, 0].legend(fontsize=7)
    atomic_write_bytes(out / "joint_profiles.png", figure_png(fig))
    plt.close(fig)
    written.append("joint_profiles.png")
    # base torque vs time
    tb = base_torque_history(p, res.k, t, per_joint=res.per_joint)
    tb0 = base_torque_history(p, 0.0, t)
    fig, ax = plt.subplots(figsize=(7, 4))
    ax.plot(t, np.linalg.norm(tb0, axis=-1), label=f"k = 0 (mean {res.global_torque_k0:.4g} N m)")
    ax.plot(t, np.linalg.norm(tb, axis=-1), label=f"k* (mean {res.global_torque:.4g} N m)")
    ax.set_xlabel("t [s]")
    ax.set_ylabel(r"$\|\tau_b\|$ [N m]")
    ax.legend()
    atomic_write_bytes(out / "base_torque_vs_time.png", figure_png(fig))
    plt.close(fig)
    written.append("base_torque_vs_time.png")
    # time series
    cols = {"t_s": t}
    for j, num in enumerate(p.model.joint_numbers):
        cols[f"q{num}_deg"] = np.degrees(q[:, j])
        cols[f"dq{num}_deg_s"] = np.degrees(dq[:, j])
        cols[f"ddq{num}_deg_s2"] = np.degrees(ddq[:, j])
    for i, ax_name in enumerate("xyz"):
        cols[f"tau_b_{ax_name}_Nm"] = tb[:, i]
    for i, ax_name in enumerate("xyz"):
        cols[f"tau_b0_{ax_name}_Nm"] = tb0[:, i]
    header = ",".join(cols)
    body = "\n".join(",".join(f"{v:.9g}" for v in row) for row in np.column_stack(list(cols.values())))
    atomic_write_text(out / "halt_motion.csv", header + "\n" + body + "\n")
    import io

    buf = io.BytesIO()
    np.savez(buf, t=t, q=q, dq=dq, ddq=ddq, tau_b=tb, tau_b_k0=tb0, k_grid=grid, global_torque_grid=tau)
    atomic_write_bytes(out / "halt_motion.npz", buf.getvalue())
    atomic_write_json(out / "result.json", data)
    written += ["halt_motion.csv", "halt_motion.npz", "result.json"]
    return written


def run(args: argparse.Namespace) -> int:
    check_out_dir(args.out)
    show = not args.quiet and sys.stderr.isatty()
    problem, notes = build_problem(args, show)
    bar = Progress(args.generations, "GA generations", enabled=show) if args.solver == "ga" else None
    res = optimal_halt_motion(
        problem,
        solver=args.solver,
        rng=args.seed,
        ga_settings=GASettings(n_pop=args.population, n_gen=args.generations),
        progress=bar,
    )
    if bar is not None:
        bar.close()
    data = result_dict(res, notes)
    written = write_outputs(res, Path(args.out), data) if args.out else []
    if args.json:
        print_json(data)
        return 0
    p = problem
    nums = list(p.model.joint_numbers)
    locked = locked_text(locked_deg(p.model))
    print(f"{p.model.name}: healthy joints {nums}, locked: {locked}, base torque with {p.base} base")
    print(
        f"halt configuration ({notes['qf_source']}): "
        + ", ".join(f"{v:.2f}" for v in data["q_final_deg"])
        + " deg"
    )
    if "hcom_jacobian" in notes:
        print(f"  (CP with the {_jacobian_text(notes)}; --base sets the base of the disturbance torque only)")
    if "reachability" in notes:
        print(f"reachability: {notes['reachability']}")
    print(
        f"halt time T = {p.T:g} s; limits {np.degrees(p.dq_max[0]):g} deg/s, {np.degrees(p.ddq_max[0]):g} deg/s^2"
    )
    if not res.feasible:
        print("\nINFEASIBLE: " + infeasibility_message(res))
    else:
        kd = np.asarray(res.k) / K_UNIT_SCALE["deg/s^6"]
        if res.per_joint:  # one k per joint: each within its own joint's interval
            print(f"\nfeasible k per joint [deg/s^6]; solver {res.solver}")
            for num, (lo, hi), kj in zip(nums, res.joint_intervals / K_UNIT_SCALE["deg/s^6"], kd):
                print(f"  joint {num}: [{lo:.6g}, {hi:.6g}], k* = {kj:.6g}")
        else:
            lo, hi = res.k_interval / K_UNIT_SCALE["deg/s^6"]
            print(f"\nfeasible k: [{lo:.6g}, {hi:.6g}] deg/s^6; solver {res.solver}")
            print(f"k* = {np.array2string(kd, precision=6)} deg/s^6")
    at = "k*" if res.feasible else "least-violating k (infeasible)"
    change = (
        "reduction n/a: no torque at k = 0"
        if math.isnan(res.reduction)
        else f"{100 * res.reduction:.1f} % lower"
    )
    print(
        f"global base torque: k = 0: {res.global_torque_k0:.4f} N m; {at}: {res.global_torque:.4f} N m "
        f"({change})"
    )
    print("000 printed: k = 0.0018, 22.25 -> 15.55 N m (30.1 %) -- not reproduced, see docs/halt-motion.md")
    print("\njoint   peak |dq| [deg/s] (limit)   peak |ddq| [deg/s^2] (limit)")
    for j, num in enumerate(nums):
        print(
            f"{num:>5}   {data['peak_velocity_deg_s'][j]:10.3f} ({data['velocity_limit_deg_s'][j]:g})"
            f"          {data['peak_acceleration_deg_s2'][j]:10.3f} ({data['acceleration_limit_deg_s2'][j]:g})"
        )
    if written:
        print(f"\nwrote {', '.join(written)} to {args.out}")
    return 0
