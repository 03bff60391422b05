"""``jointlock tolerance-angle``: the fault-tolerance angle gamma of seed 002 (Figs. 5-8)."""

from __future__ import annotations

import argparse
from pathlib import Path

from ..errors import ScenarioError
from ._common import (
    add_robot_arguments,
    chain_from_args,
    check_out_dir,
    deg_arg,
    field_arg,
    print_json,
    single_lock,
)
from ._constants import MAX_GAMMA_SAMPLES


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "tolerance-angle",
        help="gamma sweep (rotate the target about the tool x axis) and the gamma absorbing a lock "
        "(puma6-family arms only)",
        description=(
            "Works on puma6-family arms only (6 joints with 002 Table 1's structure, any a2, d4, d6: "
            "002's closed-form IK). Rotate the pose of --q-target-deg about the tool x axis by gamma in [-limit, limit], solve "
            "the full-arm IK on the branch of the target configuration, and find where the locked "
            "joint equals its locked angle (seed 002, eq. 18 and Figs. 5-8)."
        ),
    )
    add_robot_arguments(p)
    p.add_argument(
        "--q-target-deg",
        type=deg_arg,
        nargs="+",
        required=True,
        metavar="DEG",
        help="desired configuration, every joint of the arm [deg]",
    )
    p.add_argument(
        "--gamma-limit-deg",
        type=field_arg("tolerance_angle", "gamma_limit_deg"),
        default=180.0,
        metavar="DEG",
        help="sweep |gamma| <= this [deg], in (0, 180] (default 180)",
    )
    p.add_argument(
        "--zoom-deg",
        type=field_arg("tolerance_angle", "zoom_deg"),
        default=2.0,
        metavar="DEG",
        help="half-width of the second, narrow gamma range [deg] (002 Fig. 6: 2)",
    )
    p.add_argument(
        "--step-deg",
        type=field_arg("tolerance_angle", "step_deg"),
        default=0.1,
        metavar="DEG",
        help="gamma sweep step [deg] (default 0.1)",
    )
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.add_argument("--out", type=Path, metavar="DIR", help="write plots and sweep.json here")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from ..jobs.tolerance_angle import find_tolerance_angle, gamma_sample_count
    from ..robots import load_robot

    check_out_dir(args.out)
    joint, angle = single_lock(args)
    model = load_robot(args.robot, base=args.base, chain=chain_from_args(args))
    if not 1 <= joint <= model.dof:
        raise ScenarioError(f"--lock joint must be 1..{model.dof}; got {joint}")
    if len(args.q_target_deg) != model.dof:
        raise ScenarioError(f"--q-target-deg needs {model.dof} values [deg]; got {len(args.q_target_deg)}")
    for name in ("gamma_limit_deg", "zoom_deg", "step_deg"):
        val = getattr(args, name)
        if not (0 < val <= 180):
            raise ScenarioError(f"--{name.replace('_', '-')} must be in (0, 180]; got {val}")
    count = gamma_sample_count(args.gamma_limit_deg, args.step_deg)
    if count > MAX_GAMMA_SAMPLES:
        raise ScenarioError(
            f"--step-deg {args.step_deg:g} gives {count} gamma samples over +-{args.gamma_limit_deg:g} deg; "
            f"at most {MAX_GAMMA_SAMPLES} are allowed: use --step-deg >= "
            f"{2 * args.gamma_limit_deg / (MAX_GAMMA_SAMPLES - 1):.2g} or a smaller --gamma-limit-deg"
        )
    result = find_tolerance_angle(
        model,
        joint,
        angle,
        args.q_target_deg,
        gamma_limit_deg=args.gamma_limit_deg,
        zoom_deg=args.zoom_deg,
        step_deg=args.step_deg,
    )
    out = result.to_dict()
    if args.out is not None:
        out["files"] = [str(Path(args.out) / name) for name in result.write(args.out)]
    if args.json:
        print_json(out)
        return 0
    for line in result.summary():
        print(line)
    for f in out.get("files", []):
        print(f"wrote {f}")
    return 0
