"""``jointlock halt``: the halt strategy of seed 000 -- optimal halt configuration (unless
``--qf-deg``/``--paper-qf``), then the optimal halt motion (§4), with plots and time series.

With no options beyond the robot, ``halt7`` runs 000 §5's scenario: joint 4 locked at 0,
q0/dq0/ddq0, the 40 deg/s and 20 deg/s^2 limits and T = 10 s of §5.2.

Limits (:func:`resolve_limits`): the speed limit of a joint is ``--vmax-deg`` capped by the
model's own ``velocity_limit`` (the smaller of the two); without the option, the model's limit
where it is finite, else 000's 40 deg/s.  The acceleration limit is ``--amax-deg``, else 000's
20 deg/s^2 (models carry no acceleration limit).  The text output and the JSON
(``velocity_limit_source``, ``acceleration_limit_source``) say where each came from.
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
from ..model import ArmModel
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
    "vmax_deg": 40.0,  # = halt7's own velocity_limit
    "amax_deg": 20.0,
    "qf_deg": [-167.0, -90.0, 40.0, -158.0, 90.0, -62.0],  # 000's printed q_best
}
#: 000's printed results (§5.2): k [deg/s^6], global torque at k = 0 and at k* [N m].
PAPER_RESULTS = {"k": 0.0018, "global_torque_k0_Nm": 22.25, "global_torque_Nm": 15.55, "reduction": 0.301}


#: 000's limits (§5.2), the fallback where neither an option nor the model gives one
#: [deg/s, deg/s^2].
DEFAULT_VMAX_DEG = 40.0
DEFAULT_AMAX_DEG = 20.0
LIMITS_HELP = (
    "Limits: a joint's speed limit is --vmax-deg capped by the model's own velocity limit (the "
    "smaller of the two); without --vmax-deg the model's limit where it gives one, else 000's "
    f"{DEFAULT_VMAX_DEG:g} deg/s. The acceleration limit is --amax-deg, else 000's "
    f"{DEFAULT_AMAX_DEG:g} deg/s^2 (models give none). The output says where each limit came from."
)
#: Smallest number of time samples of the objective (Simpson's rule, odd).
MIN_N_SAMPLES = 11

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
            "000 §5's scenario; other robots need --q0-deg, --dq0-deg, --ddq0-deg and --T. "
            + LIMITS_HELP
            + " A joint without angle limits (continuous) has no angle constraint; its halt "
            "configuration is searched within [-180, 180] deg."
        ),
    )
    add_robot_arguments(p, base_help=BASE_HELP)
    p.add_argument("--q0-deg", type=float, nargs="+", metavar="DEG", help="angles at failure [deg]")
    p.add_argument("--dq0-deg", type=float, nargs="+", metavar="DEG", help="rates at failure [deg/s]")
    p.add_argument(
        "--ddq0-deg", type=float, nargs="+", metavar="DEG", help="accelerations at failure [deg/s^2]"
    )
    p.add_argument("--T", type=float, help="halt time [s], > 0 (000: 10)")
    qf = p.add_mutually_exclusive_group()
    qf.add_argument("--qf-deg", type=float, nargs="+", metavar="DEG", help="halt configuration [deg]")
    qf.add_argument("--paper-qf", action="store_true", help="use 000's printed q_best (halt7 only)")
    p.add_argument(
        "--vmax-deg",
        type=float,
        nargs="+",
        metavar="DEG",
        help="speed limit(s) [deg/s], one or one per healthy joint, capped by the model's own limit "
        f"(default: the model's, else {DEFAULT_VMAX_DEG:g} as 000)",
    )
    p.add_argument(
        "--amax-deg",
        type=float,
        nargs="+",
        metavar="DEG",
        help=f"acceleration limit(s) [deg/s^2], one or one per healthy joint (default {DEFAULT_AMAX_DEG:g}, as 000)",
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
    p.add_argument(
        "--n-samples",
        type=int,
        default=501,
        help=f"time samples of the objective (odd, >= {MIN_N_SAMPLES}; default 501)",
    )
    p.add_argument("--generations", type=int, default=100, help="GA generations, >= 0 (default 100)")
    p.add_argument("--population", type=int, default=50, help="GA population, >= 2 (default 50)")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.add_argument("--out", metavar="DIR", help="write plots (PNG), time series (CSV, NPZ) and result.json")
    p.add_argument("--quiet", action="store_true", help="no progress bars")
    p.set_defaults(func=run)


def _option_limit(values: list[float] | None, option: str, n: int) -> np.ndarray | None:
    """``--vmax-deg``/``--amax-deg``: None, or (n,) [deg/s or deg/s^2] from one value or n."""
    if values is None:
        return None
    arr = np.asarray(values, dtype=float)
    if arr.size == 1:
        arr = np.full(n, arr[0])
    if arr.shape != (n,) or not np.all(np.isfinite(arr) & (arr > 0)):
        raise ScenarioError(f"{option} needs one value or {n} values, finite and > 0; got {values}")
    return arr


def resolve_limits(
    model: ArmModel, vmax_deg: list[float] | None, amax_deg: list[float] | None
) -> tuple[np.ndarray, np.ndarray, list[str], list[str]]:
    """Speed and acceleration limits of the healthy joints and where each came from.

    Rule: a joint's speed limit is ``vmax_deg`` (``--vmax-deg``) capped by the model's own
    ``velocity_limit`` (the smaller of the two); without the option, the model's limit where
    finite, else 000's :data:`DEFAULT_VMAX_DEG`.  The acceleration limit is ``amax_deg``
    (``--amax-deg``), else :data:`DEFAULT_AMAX_DEG` (a model has no acceleration limit).

    Returns
    -------
    vmax, amax
        (n,) [rad/s, rad/s^2].
    vmax_source, amax_source
        (n,) plain-language origin of each joint's limit.
    """
    n = model.dof
    v_opt = _option_limit(vmax_deg, "--vmax-deg", n)
    a_opt = _option_limit(amax_deg, "--amax-deg", n)
    v_model = np.degrees([j.velocity_limit for j in model.joints])
    vmax, v_src = np.empty(n), []
    for i in range(n):
        finite = math.isfinite(v_model[i])
        if v_opt is not None and (not finite or v_opt[i] <= v_model[i]):
            vmax[i] = v_opt[i]
            v_src.append("--vmax-deg")
        elif v_opt is not None:
            vmax[i] = v_model[i]
            v_src.append(f"model's limit, below --vmax-deg {v_opt[i]:g}")
        elif finite:
            vmax[i] = v_model[i]
            v_src.append("model's limit")
        else:
            vmax[i] = DEFAULT_VMAX_DEG
            v_src.append("000's default; the model gives none")
    if a_opt is not None:
        amax, a_src = a_opt, ["--amax-deg"] * n
    else:
        amax, a_src = np.full(n, DEFAULT_AMAX_DEG), ["000's default"] * n
    return np.radians(vmax), np.radians(amax), v_src, a_src


def limits_text(numbers, values_rad, sources, unit: str) -> str:
    """``"40 deg/s (model's limit)"`` when every joint has the same limit from the same
    source, else the joints grouped: ``"joints 1, 2: 10 deg/s (model's limit); joint 4: ..."``."""
    groups: dict[tuple[str, str], list[int]] = {}
    for num, v, src in zip(numbers, np.degrees(values_rad), sources):
        groups.setdefault((f"{v:.6g}", src), []).append(num)
    if len(groups) == 1:
        (value, src), _ = next(iter(groups.items()))
        return f"{value} {unit} ({src})"
    parts = []
    for (value, src), nums in groups.items():
        label = "joint" if len(nums) == 1 else "joints"
        parts.append(f"{label} {', '.join(map(str, nums))}: {value} {unit} ({src})")
    return "; ".join(parts)


def _check_options(args: argparse.Namespace) -> None:
    """Numbers the options must satisfy, named as options (before any work)."""
    if args.T is not None and not (math.isfinite(args.T) and args.T > 0):
        raise ScenarioError(f"--T must be a finite halt time > 0 [s]; got {args.T:g}")
    n = args.n_samples
    if n < MIN_N_SAMPLES or n % 2 == 0:
        raise ScenarioError(
            f"--n-samples must be an odd integer >= {MIN_N_SAMPLES} (time samples of the objective, "
            f"Simpson's rule); got {n}"
        )
    if args.samples < 2:
        raise ScenarioError(f"--samples must be an integer >= 2 (Monte Carlo samples); got {args.samples}")
    if args.solver == "ga":
        bad = []
        if args.population < 2:
            bad.append(f"--population must be >= 2 (GA population); got {args.population}")
        if args.generations < 0:
            bad.append(f"--generations must be >= 0 (GA generations); got {args.generations}")
        if bad:
            raise ScenarioError("; ".join(bad))


def _paper_state(model: ArmModel, q0, dq0, ddq0, T: float, vmax, amax) -> bool:
    """True for 000 §5's scenario on halt7: joint 4 locked at 0, §5.2's state, T and limits."""
    ps = PAPER_SCENARIO
    if model.name != "halt7" or {lj.number: lj.angle for lj in model.locked} != ps["lock"]:
        return False
    same = all(
        np.allclose(np.degrees(v), ps[key], atol=1e-9)
        for v, key in ((q0, "q0_deg"), (dq0, "dq0_deg"), (ddq0, "ddq0_deg"))
    )
    return (
        same
        and T == ps["T"]
        and np.allclose(np.degrees(vmax), ps["vmax_deg"])
        and np.allclose(np.degrees(amax), ps["amax_deg"])
    )


def _check_start(model: ArmModel, q0, dq0, ddq0, T: float, vmax, amax, v_src, a_src) -> None:
    """Refuse a state at failure that itself breaks a limit before any search: every halt
    starts from it (the k-part vanishes at t = 0 with two derivatives), so no halt
    configuration, halt time or k helps, and a Monte Carlo search would be pointless."""
    from ..errors import InfeasibleError
    from ..planning.halt_config import HaltReachability

    bad = HaltReachability(q0, dq0, ddq0, T, vmax, amax).bind(model).start_violations(model.joint_numbers)
    if bad:
        nums = model.joint_numbers
        raise InfeasibleError(
            "the state at failure (--q0-deg, --dq0-deg, --ddq0-deg) already breaks a limit, and every "
            "halt starts from it, so no halt configuration, halt time or k helps: "
            + "; ".join(bad)
            + f" (speed limits: {limits_text(nums, vmax, v_src, 'deg/s')}; acceleration limits: "
            f"{limits_text(nums, amax, a_src, 'deg/s^2')}); no halt configuration searched"
        )


def build_problem(args: argparse.Namespace, progress_enabled: bool) -> tuple[HaltProblem, dict]:
    """Parse the options into a :class:`HaltProblem` (+ notes on where ``qf`` and the limits
    came from)."""
    _check_options(args)
    paper = args.robot == "halt7"
    defaults = PAPER_SCENARIO if paper else {}
    missing = [
        option
        for option, value, key in (
            ("--q0-deg", args.q0_deg, "q0_deg"),
            ("--dq0-deg", args.dq0_deg, "dq0_deg"),
            ("--ddq0-deg", args.ddq0_deg, "ddq0_deg"),
            ("--T", args.T, "T"),
        )
        if value is None and key not in defaults
    ]
    if missing:
        raise ScenarioError(
            f"this robot needs {', '.join(missing)} (the state at failure [deg, deg/s, deg/s^2] and "
            "the halt time [s]; 000's scenario is the default for halt7 only)"
        )
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
    q0 = joint_vector_deg(model, list(args.q0_deg or defaults["q0_deg"]), "--q0-deg")
    dq0 = joint_vector_deg(model, list(args.dq0_deg or defaults["dq0_deg"]), "--dq0-deg", rates=True)
    ddq0 = joint_vector_deg(model, list(args.ddq0_deg or defaults["ddq0_deg"]), "--ddq0-deg", rates=True)
    T = float(args.T if args.T is not None else defaults["T"])
    vmax, amax, v_src, a_src = resolve_limits(model, args.vmax_deg, args.amax_deg)
    notes: dict[str, Any] = {
        "velocity_limit_source": v_src,
        "acceleration_limit_source": a_src,
        "paper_scenario": _paper_state(model, q0, dq0, ddq0, T, vmax, amax),
    }
    if args.qf_deg is None and not args.paper_qf:
        _check_start(model, q0, dq0, ddq0, T, vmax, amax, v_src, a_src)
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
        # 000's printed numbers, for 000 §5's scenario on halt7 only (None otherwise)
        "paper": PAPER_RESULTS if notes.get("paper_scenario") else None,
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


def k_label(res: HaltMotion) -> str:
    """What the reported k is: the optimum, or the least-violating k of an infeasible halt."""
    if not res.feasible:
        return "least-violating k (infeasible)"
    return "optimal k per joint" if res.per_joint else "optimal k*"


def k_text(res: HaltMotion, digits: int = 6) -> str:
    """The reported k in deg/s^6, ``digits`` significant digits, with the unit."""
    kd = np.atleast_1d(np.asarray(res.k, dtype=float) / K_UNIT_SCALE["deg/s^6"])
    body = ", ".join(f"{v:.{digits}g}" for v in kd)
    return (f"[{body}]" if res.per_joint else body) + " deg/s^6"


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
    label = k_label(res)
    k_star = float(np.mean(res.k)) if res.per_joint else float(res.k)
    lo, hi = res.k_interval
    span = [0.0, max(0.01 * scale, 1.5 * abs(k_star))]
    if lo <= hi:
        span = [min(span[0], lo - 0.2 * (hi - lo)), max(span[1], hi + 0.2 * (hi - lo))]
    span = [min(span[0], 1.5 * k_star), span[1]]  # a negative k* is on the plot too
    grid = np.linspace(span[0], span[1], 201)
    tau = global_base_torque(p, grid)
    fig, ax = plt.subplots(figsize=(7, 4))
    ax.plot(grid / scale, tau, label=r"$\bar\tau_b(k)$, shared k")
    if lo <= hi:
        ax.axvspan(
            lo / scale,
            hi / scale,
            color="g",
            alpha=0.15,
            label=f"feasible k: [{lo / scale:.4g}, {hi / scale:.4g}] deg/s$^6$",
        )
    else:  # a legend line saying so (no band to shade)
        ax.plot([], [], " ", label=f"no feasible k: every k breaks a limit (T = {p.T:g} s)")
    i_min = int(np.argmin(tau))
    star_text = f"{label} = {k_star / scale:.4g} deg/s$^6$"
    if res.per_joint:
        star_text = f"{label} (at their mean {k_star / scale:.4g} deg/s$^6$)"
    ax.plot([k_star / scale], [res.global_torque], "r*", ms=12, label=star_text)
    if abs(grid[i_min] - k_star) > 1.5 * (grid[1] - grid[0]):  # the curve's own minimum elsewhere
        where = "feasible" if lo <= grid[i_min] <= hi else "breaks a limit"
        ax.plot(
            [grid[i_min] / scale],
            [tau[i_min]],
            "o",
            mfc="none",
            mec="k",
            ms=8,
            label=f"minimum on this range: k = {grid[i_min] / scale:.4g} deg/s$^6$ ({where})",
        )
    ax.set_xlabel("k [deg/s$^6$]")
    ax.set_ylabel("global base torque [N m]")
    verdict = "" if res.feasible else ", INFEASIBLE"
    ax.set_title(f"global base disturbance torque vs k ({p.base} base{verdict})")
    ax.legend(fontsize=8)
    atomic_write_bytes(out / "global_torque_vs_k.png", figure_png(fig))
    plt.close(fig)
    written.append("global_torque_vs_k.png")
    # Fig. 9: angle / velocity / acceleration per joint
    t = p.times()
    q, dq, ddq = res.trajectory(t)
    q0_, dq0_, ddq0_ = p.trajectory(0.0, t)
    n = p.dof
    fig, axes = plt.subplots(3, n, figsize=(3 * n, 7), sharex=True, squeeze=False)
    for j in range(n):
        for row, (a, b, lim, ylabel) in enumerate(
            (
                (q, q0_, None, "angle [deg]"),
                (dq, dq0_, p.dq_max[j], "velocity [deg/s]"),
                (ddq, ddq0_, p.ddq_max[j], "acc. [deg/s$^2$]"),
            )
        ):
            ax = axes[row, j]
            ax.plot(t, np.degrees(a[:, j]), label=label)
            ax.plot(t, np.degrees(b[:, j]), "--", lw=0.8, label="k = 0")
            if lim is not None:
                for sgn in (-1, 1):
                    ax.axhline(sgn * math.degrees(lim), color="r", lw=0.6, label="limit" if sgn > 0 else None)
            if j == 0:
                ax.set_ylabel(ylabel)
        axes[0, j].set_title(f"joint {p.model.joint_numbers[j]}")
        axes[2, j].set_xlabel("t [s]")
    axes[1, 0].legend(fontsize=7)
    if not res.feasible:
        fig.suptitle(f"INFEASIBLE halt: {label} = {k_text(res, 4)}, limits broken", color="r")
    atomic_write_bytes(out / "joint_profiles.png", figure_png(fig))
    plt.close(fig)
    written.append("joint_profiles.png")
    # base torque vs time
    tb = base_torque_history(p, res.k, t, per_joint=res.per_joint)
    tb0 = base_torque_history(p, 0.0, t)
    fig, ax = plt.subplots(figsize=(7, 4))
    ax.plot(t, np.linalg.norm(tb0, axis=-1), label=f"k = 0 (mean {res.global_torque_k0:.4g} N m)")
    ax.plot(
        t,
        np.linalg.norm(tb, axis=-1),
        label=f"{label} = {k_text(res, 4).replace('^6', '$^6$')} (mean {res.global_torque:.4g} N m)",
    )
    ax.set_xlabel("t [s]")
    ax.set_ylabel(r"$\|\tau_b\|$ [N m]")
    if not res.feasible:
        ax.set_title("INFEASIBLE halt: every k breaks a limit", color="r")
    ax.legend(fontsize=8)
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
    print(f"halt time T = {p.T:g} s")
    print(f"speed limits: {limits_text(nums, p.dq_max, notes['velocity_limit_source'], 'deg/s')}")
    print(
        f"acceleration limits: {limits_text(nums, p.ddq_max, notes['acceleration_limit_source'], 'deg/s^2')}"
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
            print(f"k* = {k_text(res)}")
    at = "k*" if res.feasible else "least-violating k (infeasible)"
    change = (
        "reduction n/a: no torque at k = 0"
        if math.isnan(res.reduction)
        else f"{100 * res.reduction:.1f} % lower"
        if res.reduction >= 0
        else f"{-100 * res.reduction:.1f} % higher: k = 0 breaks a limit"
        if res.violations_k0
        else f"{-100 * res.reduction:.1f} % higher"
    )
    print(
        f"global base torque: k = 0: {res.global_torque_k0:.4f} N m; {at}: {res.global_torque:.4f} N m "
        f"({change})"
    )
    if notes.get("paper_scenario"):  # 000's numbers belong to 000 §5's scenario on halt7 only
        print(
            "000 printed: k = 0.0018, 22.25 -> 15.55 N m (30.1 %) -- not reproduced, see docs/halt-motion.md"
        )
    print("\njoint   peak |dq| [deg/s] (limit)   peak |ddq| [deg/s^2] (limit)")
    for j, num in enumerate(nums):
        v_lim = f"({data['velocity_limit_deg_s'][j]:.6g})"
        print(
            f"{num:>5}   {data['peak_velocity_deg_s'][j]:10.3f} {v_lim:<14}"
            f"  {data['peak_acceleration_deg_s2'][j]:10.3f} ({data['acceleration_limit_deg_s2'][j]:.6g})"
        )
    if written:
        print(f"\nwrote {', '.join(written)} to {args.out}")
    return 0
