"""``jointlock replan``: straight-line Cartesian re-planning of an arm with a locked joint (002)."""

from __future__ import annotations

import argparse
import math
from pathlib import Path

from ..bounds import MAX_LENGTH_M
from ..errors import ScenarioError
from ._common import (
    add_robot_arguments,
    chain_from_args,
    check_out_dir,
    deg_arg,
    field_arg,
    number_arg,
    print_json,
    single_lock,
)
from ._constants import DEFAULT_STEP_WEIGHT, MAX_ABS_DEG


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "replan",
        help="straight-line Cartesian plan through the locked-arm IK, with the tolerance angle gamma "
        "(puma6-family arms only)",
        description=(
            "Works on puma6-family arms only (6 joints with 002 Table 1's structure, any a2, d4, d6: "
            "002's closed-form IK). "
            "Start and goal are the poses of the full-arm joint vectors --from-deg and --to-deg; the "
            "line (002 eqs. 19-20) is followed by the arm with --lock, each waypoint rotated about the "
            "tool x axis by some |gamma| <= --tolerance-deg.  --method continuous (default) chooses "
            "gamma and the IK branch along the whole path (shortest path: tracking error plus "
            "--step-weight times the squared joint steps), so the joints do not jump; --method "
            "pointwise takes the smallest |gamma| that absorbs the lock at each waypoint on its own. "
            "The largest joint step, every jump and every step over a joint's speed limit are reported."
        ),
    )
    add_robot_arguments(p)
    p.add_argument(
        "--from-deg",
        type=deg_arg,
        nargs="+",
        required=True,
        metavar="DEG",
        help="start configuration, every joint of the arm [deg]",
    )
    p.add_argument(
        "--to-deg",
        type=deg_arg,
        nargs="+",
        required=True,
        metavar="DEG",
        help="goal configuration, every joint of the arm [deg]",
    )
    p.add_argument(
        "--steps",
        type=field_arg("replan", "steps"),
        default=40,
        help="interior points N of eq. (19), >= 1 (default 40)",
    )
    p.add_argument(
        "--cycle", type=field_arg("replan", "cycle"), default=0.25, help="time between points [s] (002: 0.25)"
    )
    p.add_argument(
        "--tolerance-deg",
        type=field_arg("replan", "tolerance_deg"),
        default=0.0,
        help="largest |gamma| accepted [deg] (default 0)",
    )
    p.add_argument(
        "--method",
        choices=("continuous", "pointwise"),
        default="continuous",
        help="choose gamma and branch along the path (default) or at each waypoint alone",
    )
    p.add_argument(
        "--step-weight",
        type=number_arg(0.0, MAX_LENGTH_M, unit="m/rad^2"),
        default=DEFAULT_STEP_WEIGHT,
        metavar="M_PER_RAD2",
        help=f"continuous: tracking error [m] traded per rad^2 of joint step (default {DEFAULT_STEP_WEIGHT:g})",
    )
    p.add_argument(
        "--jump-deg",
        type=number_arg(0.0, MAX_ABS_DEG, lo_open=True, unit="deg"),
        default=None,
        metavar="DEG",
        help="flag joint steps above this [deg] (default: 5x the median step, between 2 and 30 deg)",
    )
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.add_argument("--out", type=Path, metavar="DIR", help="write plots, trajectory.csv and plan.json here")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    import numpy as np

    from ..jobs.replan import plan_replan
    from ..robots import load_robot

    check_out_dir(args.out)
    joint, angle = single_lock(args)
    full = load_robot(args.robot, base=args.base, chain=chain_from_args(args))
    for opt, vals in (("--from-deg", args.from_deg), ("--to-deg", args.to_deg)):
        if len(vals) != full.dof:
            raise ScenarioError(f"{opt} needs {full.dof} values (all joints) [deg]; got {len(vals)}")
    result = plan_replan(
        full,
        joint,
        angle,
        np.radians(args.from_deg),
        np.radians(args.to_deg),
        steps=args.steps,
        cycle=args.cycle,
        tolerance_deg=args.tolerance_deg,
        method=args.method,
        step_weight=args.step_weight,
        jump_threshold=None if args.jump_deg is None else math.radians(args.jump_deg),
    )
    out = result.headline()
    if args.out is not None:
        out["files"] = [str(Path(args.out) / name) for name in result.write(args.out)]
    if args.json:
        print_json({**out, "trajectory": result.trajectory()})
        return 0
    for line in result.summary():
        print(line)
    for f in out.get("files", []):
        print(f"wrote {f}")
    return 0
