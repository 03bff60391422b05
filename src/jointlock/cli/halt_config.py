"""``jointlock halt-config``: the optimal halt configuration of an arm with a locked joint
(seed 000 HCOM), its index values and weights, section plots and the sample set."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ..errors import ScenarioError
from ..papers import p000
from ._common import (
    add_clearance_options,
    add_robot_arguments,
    clearance_from_args,
    deg_arg,
    field_arg,
    model_from_args,
    print_json,
    seed_arg,
)
from .halt import DEFAULT_AMAX_DEG, DEFAULT_VMAX_DEG, LIMITS_HELP

if TYPE_CHECKING:
    from ..jobs.halt_config import ReachabilitySettings


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
    p.add_argument(
        "--samples",
        type=field_arg("halt_config", "samples"),
        default=p000.SAMPLES,
        help=f"Monte Carlo samples K (default {p000.SAMPLES}, as 000)",
    )
    p.add_argument("--seed", type=seed_arg, default=0, help="random seed, integer >= 0 (default 0, as every command)")
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
        type=field_arg("halt_config", "length"),
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
    reach.add_argument("--from-q-deg", type=deg_arg, nargs="+", metavar="DEG", help="start angles [deg]")
    reach.add_argument(
        "--from-dq-deg",
        type=field_arg("state", "dq0_deg"),
        nargs="+",
        metavar="DEG",
        help="start rates [deg/s]",
    )
    reach.add_argument(
        "--from-ddq-deg",
        type=field_arg("state", "ddq0_deg"),
        nargs="+",
        metavar="DEG",
        help="start accelerations [deg/s^2] (default 0)",
    )
    reach.add_argument(
        "--halt-time", type=field_arg("halt_config", "halt_time"), metavar="S", help="halt time T [s]"
    )
    reach.add_argument(
        "--vmax-deg",
        type=field_arg("limits", "vmax_deg_s"),
        nargs="+",
        metavar="DEG",
        help="speed limit(s) [deg/s], one or one per healthy joint, capped by the model's own limit "
        f"(default: the model's, else {DEFAULT_VMAX_DEG:g} as 000). " + LIMITS_HELP,
    )
    reach.add_argument(
        "--amax-deg",
        type=field_arg("limits", "amax_deg_s2"),
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
    add_clearance_options(p)
    p.set_defaults(func=run)


def _reachability(args: argparse.Namespace, model: Any) -> ReachabilitySettings | None:
    """The reachability options as typed settings (checked and named as options), or None."""
    from ..jobs._common import joint_vector_deg
    from ..jobs.halt import FailureState
    from ..jobs.halt_config import ReachabilitySettings

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
    dq0 = joint_vector_deg(model, args.from_dq_deg or None, "--from-dq-deg", rates=True)
    ddq0 = joint_vector_deg(model, getattr(args, "from_ddq_deg", None) or None, "--from-ddq-deg", rates=True)
    return ReachabilitySettings(
        FailureState(q0, dq0, ddq0),
        args.halt_time,
        method=getattr(args, "reachability", "exact"),
        per_joint_k=getattr(args, "per_joint_k", False),
    )


def run(args: argparse.Namespace) -> int:
    from ..jobs.halt import CLI_LIMIT_NAMES
    from ..jobs.halt_config import PROGRESS_MIN_SAMPLES, study_halt_configuration

    model = model_from_args(args)
    if not model.locked:
        raise ScenarioError("halt-config needs a locked joint: add --lock J=DEG (e.g. --lock 4=0)")
    result = study_halt_configuration(
        model,
        samples=args.samples,
        rng=args.seed,
        jacobian=args.jacobian,
        assignment=args.assignment,
        renormalize=args.renormalize,
        refine=not args.no_refine,
        characteristic_length=args.length,
        reachability=_reachability(args, model),
        vmax_deg=args.vmax_deg,
        amax_deg=args.amax_deg,
        limit_names=CLI_LIMIT_NAMES,
        progress=not args.quiet and args.samples >= PROGRESS_MIN_SAMPLES,
        clearance=clearance_from_args(args),
    )
    data = result.to_dict()
    files = []
    if args.out:
        files = [Path(args.out) / name for name in result.write(args.out)]
        data["files"] = [str(f) for f in files]
    if args.json:
        print_json(data)
        return 0
    for line in result.summary():
        print(line)
    if files:
        print(f"\nwrote {len(files)} files to {args.out}: " + ", ".join(f.name for f in files))
    return 0
