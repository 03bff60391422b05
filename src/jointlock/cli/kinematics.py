"""``jointlock kinematics``: end-effector pose, Jacobian and singular values at one configuration
(a thin shell over :func:`jointlock.jobs.kinematics.describe_configuration`)."""

from __future__ import annotations

import argparse

from ._common import add_robot_arguments, deg_arg, model_from_args, print_json


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "kinematics",
        help="end-effector pose, Jacobian and its singular values at one configuration",
        description=(
            "Jacobian: twist order (v [m/s], omega [rad/s]), reference point = end-effector origin, "
            "components in the base frame. With --base floating it is the generalized Jacobian "
            "(zero momentum)."
        ),
    )
    add_robot_arguments(p)
    p.add_argument(
        "--q-deg", type=deg_arg, nargs="+", metavar="DEG", help="joint angles [deg] (default: zeros)"
    )
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from ..jobs._common import joint_vector_deg
    from ..jobs.kinematics import describe_configuration

    model = model_from_args(args)
    report = describe_configuration(model, joint_vector_deg(model, args.q_deg, "--q-deg"))
    if args.json:
        print_json(report.to_dict())
        return 0
    for line in report.summary():
        print(line)
    return 0
