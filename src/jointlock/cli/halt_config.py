"""``jointlock halt-config``: the optimal halt configuration of an arm with a locked joint
(seed 000 HCOM), its index values and weights, section plots and the sample set."""

from __future__ import annotations

import argparse
import io
import math
import sys
from pathlib import Path

import numpy as np

from ..analysis.ability import INDEX_NAMES
from ..errors import ScenarioError
from ..planning.halt_config import (
    HaltReachability,
    ReachabilityBound,
    optimal_halt_configuration,
    write_section_plots,
)
from ..progress import Progress
from ..report import atomic_write_bytes, atomic_write_json
from ._common import add_robot_arguments, joint_vector_deg, model_from_args, print_json, seed_arg
from .halt import DEFAULT_AMAX_DEG, DEFAULT_VMAX_DEG, LIMITS_HELP, limits_text, resolve_limits

#: Below this many samples no progress bar is shown (the run takes well under a second).
PROGRESS_MIN_SAMPLES = 20000


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "halt-config",
        help="optimal halt configuration after a lock (000 HCOM: Monte Carlo + refinement)",
        description=(
            "Sample the healthy joints within their limits, score each configuration by the "
            "combined kinematic-ability index CP (min singular value, condition number, "
            "manipulability; AHP + entropy weights, seed 000 eqs. 8-19), refine the best "
            "samples, print the best configuration [deg], and with --out write the section "
            "plots (joint angle vs CP) and the samples (NPZ, CSV)."
        ),
    )
    add_robot_arguments(p)
    p.add_argument("--samples", type=int, default=36000, help="Monte Carlo samples K (default 36000, as 000)")
    p.add_argument("--seed", type=seed_arg, default=None, help="random seed (default: fresh, printed)")
    p.add_argument(
        "--jacobian",
        choices=("generalized", "fixed"),
        default="generalized",
        help="generalized (free-floating, 000's J_F; needs --base floating to differ) or fixed-base "
        "Jacobian (default generalized)",
    )
    p.add_argument(
        "--assignment",
        choices=("equation", "text"),
        default="equation",
        help="which index gets AHP weight 1/2: condition number as in 000 eq. 19 (equation, "
        "default) or manipulability as in 000 §5.1 (text)",
    )
    p.add_argument(
        "--renormalize",
        action="store_true",
        help="divide the combined weights by their sum (000 eq. 18 does not)",
    )
    p.add_argument(
        "--length",
        type=float,
        default=None,
        metavar="L",
        help="characteristic length [m]: divide the Jacobian's linear rows by L (default: raw, as 000)",
    )
    p.add_argument("--no-refine", action="store_true", help="plain Monte Carlo, as 000 (no local refinement)")
    reach = p.add_argument_group(
        "reachability",
        "require the halt configuration to be reachable from a state within a halt time: by default "
        "exactly, by 000's halt polynomial (eq. 27) under the limits for some k",
    )
    reach.add_argument("--from-q-deg", type=float, nargs="+", metavar="DEG", help="start angles [deg]")
    reach.add_argument("--from-dq-deg", type=float, nargs="+", metavar="DEG", help="start rates [deg/s]")
    reach.add_argument(
        "--from-ddq-deg",
        type=float,
        nargs="+",
        metavar="DEG",
        help="start accelerations [deg/s^2] (default 0)",
    )
    reach.add_argument("--halt-time", type=float, metavar="S", help="halt time T [s]")
    reach.add_argument(
        "--vmax-deg",
        type=float,
        nargs="+",
        metavar="DEG",
        help="speed limit(s) [deg/s], one or one per healthy joint, capped by the model's own limit "
        f"(default: the model's, else {DEFAULT_VMAX_DEG:g} as 000). " + LIMITS_HELP,
    )
    reach.add_argument(
        "--amax-deg",
        type=float,
        nargs="+",
        metavar="DEG",
        help=f"acceleration limit(s) [deg/s^2] (default {DEFAULT_AMAX_DEG:g}, as 000)",
    )
    reach.add_argument(
        "--reachability",
        choices=("exact", "bound"),
        default="exact",
        help="exact: the halt polynomial must have a feasible k (default); bound: only the bang-bang "
        "box of rest angles (necessary, not sufficient)",
    )
    reach.add_argument(
        "--per-joint-k",
        action="store_true",
        help="exact reachability with one k per joint instead of a shared k",
    )
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.add_argument("--out", metavar="DIR", help="write result.json, section plots and samples here")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(func=run)


def _reachability(args: argparse.Namespace, model) -> ReachabilityBound | HaltReachability | None:
    given = [args.from_q_deg is not None, args.halt_time is not None]
    if not any(given):
        if args.from_dq_deg is not None or getattr(args, "from_ddq_deg", None) is not None:
            raise ScenarioError("--from-dq-deg/--from-ddq-deg need --from-q-deg and --halt-time")
        return None
    if not all(given):
        raise ScenarioError(
            "reachability needs both --from-q-deg and --halt-time (and optionally --from-dq-deg)"
        )
    q0 = joint_vector_deg(model, args.from_q_deg, "--from-q-deg")
    dq0 = (
        joint_vector_deg(model, args.from_dq_deg, "--from-dq-deg", rates=True)
        if args.from_dq_deg
        else np.zeros(model.dof)
    )
    if not (math.isfinite(args.halt_time) and args.halt_time > 0):
        raise ScenarioError(f"--halt-time must be a finite number > 0 [s]; got {args.halt_time}")
    ddq0 = (
        joint_vector_deg(model, args.from_ddq_deg, "--from-ddq-deg", rates=True)
        if getattr(args, "from_ddq_deg", None)
        else np.zeros(model.dof)
    )
    vmax, amax, v_src, a_src = resolve_limits(model, args.vmax_deg, args.amax_deg)
    args.limit_sources = (v_src, a_src)  # for the text and JSON output
    if getattr(args, "reachability", "exact") == "bound":
        return ReachabilityBound(q0, dq0, args.halt_time, vmax, amax, ddq0)
    return HaltReachability(
        q0, dq0, ddq0, args.halt_time, vmax, amax, per_joint=getattr(args, "per_joint_k", False)
    )


def _samples_csv(result) -> bytes:
    ind = result.indices_samples
    table = np.column_stack(
        [
            np.degrees(result.q_samples),
            ind.sigma_min,
            ind.condition_number,
            ind.manipulability,
            result.cp_samples,
        ]
    )
    header = ",".join([f"q{n}_deg" for n in result.joint_numbers] + list(INDEX_NAMES) + ["cp"])
    buf = io.StringIO()
    np.savetxt(buf, table, delimiter=",", header=header, comments="", fmt="%.10g")
    return buf.getvalue().encode("utf-8")


def _samples_npz(result) -> bytes:
    ind = result.indices_samples
    buf = io.BytesIO()
    np.savez_compressed(
        buf,
        q_rad=result.q_samples,
        joint_numbers=np.array(result.joint_numbers),
        sigma_min=ind.sigma_min,
        condition_number=ind.condition_number,
        manipulability=ind.manipulability,
        cp=result.cp_samples,
    )
    return buf.getvalue()


def run(args: argparse.Namespace) -> int:
    if args.samples < 2:
        raise ScenarioError(f"--samples must be an integer >= 2; got {args.samples}")
    if args.length is not None and not (math.isfinite(args.length) and args.length > 0):
        raise ScenarioError(f"--length must be a finite length > 0 [m]; got {args.length}")
    model = model_from_args(args)
    if not model.locked:
        raise ScenarioError("halt-config needs a locked joint: add --lock J=DEG (e.g. --lock 4=0)")
    reach = _reachability(args, model)
    show = not args.quiet and args.samples >= PROGRESS_MIN_SAMPLES
    with Progress(args.samples, "sampling", enabled=None if show else False) as bar:
        result = optimal_halt_configuration(
            model,
            samples=args.samples,
            rng=args.seed,
            jacobian=args.jacobian,
            refine=not args.no_refine,
            assignment=args.assignment,
            renormalize=args.renormalize,
            characteristic_length=args.length,
            reachability=reach,
            progress=bar,
        )
    data = {"robot": model.name, **result.to_dict()}
    if reach is not None and data.get("reachability") is not None:
        v_src, a_src = args.limit_sources
        data["reachability"]["velocity_limit_source"] = v_src
        data["reachability"]["acceleration_limit_source"] = a_src
    files = []
    if args.out:
        out = Path(args.out)
        atomic_write_json(out / "result.json", data)
        atomic_write_bytes(out / "samples.npz", _samples_npz(result))
        atomic_write_bytes(out / "samples.csv", _samples_csv(result))
        files = [out / "result.json", out / "samples.npz", out / "samples.csv"]
        files += write_section_plots(result, out)
        data["files"] = [str(f) for f in files]
    if args.json:
        print_json(data)
        return 0
    _print_text(model, result, reach, getattr(args, "limit_sources", None))
    if files:
        print(f"\nwrote {len(files)} files to {args.out}: " + ", ".join(f.name for f in files))
    return 0


def _fmt_q(q: np.ndarray) -> str:
    return "[" + ", ".join(f"{v:8.3f}" for v in np.degrees(q)) + "]"


def _print_text(model, result, reach, sources=None) -> None:
    locked = ", ".join(f"joint {k} at {math.degrees(v):g} deg" for k, v in result.locked.items())
    print(
        f"{model.name}: healthy joints {list(result.joint_numbers)}, locked: {locked}, base: {result.base}, "
        f"Jacobian: {result.jacobian}"
    )
    if result.jacobian == "generalized" and result.base == "fixed":
        print("  (fixed base: the generalized Jacobian is the fixed-base one; --base floating for 000's J_F)")
    print(f"samples: {result.samples}, seed: {result.seed}")
    if isinstance(reach, HaltReachability):
        k_txt = ""
        if result.k_range is not None:
            lo, hi = np.degrees(result.k_range)
            k_txt = f", shared k in [{lo:.4g}, {hi:.4g}] deg/s^6"
        print(
            f"reachability (exact, halt polynomial, {'one k per joint' if reach.per_joint else 'shared k'}, "
            f"T = {reach.halt_time:g} s): {result.reachable_samples} of {result.samples} samples reachable"
            f"{k_txt}; box {_fmt_q(result.lower)} .. {_fmt_q(result.upper)} deg"
        )
    elif reach is not None:
        print(f"reachability: bang-bang bound, box {_fmt_q(result.lower)} .. {_fmt_q(result.upper)} deg")
    if reach is not None and sources is not None:
        nums = result.joint_numbers
        print(f"  speed limits: {limits_text(nums, reach.velocity_limit, sources[0], 'deg/s')}")
        print(f"  acceleration limits: {limits_text(nums, reach.acceleration_limit, sources[1], 'deg/s^2')}")
    print(f"\n{'':<14}{'q [deg]':<62}{'CP':>9}{'sigma_min':>11}{'kappa':>11}{'w':>11}")
    rows = [("best", result.best), ("best sample", result.best_sample), ("runner-up", result.runner_up)]
    for label, c in rows:
        if c is None:
            continue
        print(
            f"{label:<14}{_fmt_q(c.q):<62}{c.cp:9.5f}{c.sigma_min:11.5g}{c.condition_number:11.5g}"
            f"{c.manipulability:11.5g}"
        )
    gain = result.refinement_gain
    rel = gain / abs(result.best_sample.cp) if result.best_sample.cp else float("nan")
    print(f"refinement gain: {gain:+.5f} CP ({100 * rel:+.2f} %), {result.refine_evaluations} evaluations")
    w = result.weights
    ahp = result.ability.ahp
    print(
        f"\nweights ({result.ability.assignment} reading, "
        f"{'renormalised' if result.ability.renormalize else 'not renormalised'}):"
    )
    print(f"  {'':<10}" + "".join(f"{name:>18}" for name in INDEX_NAMES))
    for key in ("ahp", "entropy", "combined"):
        print(f"  {key:<10}" + "".join(f"{w[key][name]:18.5f}" for name in INDEX_NAMES))
    print(f"  AHP: lambda_max = {ahp.lambda_max:.6g}, CI = {ahp.ci:.3g}, CR = {ahp.cr:.3g} (RI = {ahp.ri:g})")
    sys.stdout.flush()
