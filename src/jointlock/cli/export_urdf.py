"""``jointlock export-urdf``: the (locked) arm as a URDF file, its locked joints folded in and
their bodies merged, for simulating the crippled arm elsewhere (a thin shell over
:func:`jointlock.io.urdf_export.write_urdf`)."""

from __future__ import annotations

import argparse
from pathlib import Path

from ._common import add_robot_arguments, export_facts, export_line, model_from_args, print_json


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "export-urdf",
        help="write the (locked) arm as URDF, locked joints folded in and bodies merged",
        description=(
            "Write the arm, with every --lock folded into the chain and the bodies it joins merged, "
            "as a URDF file that Pinocchio, MuJoCo, Gazebo or Drake load: link 'base' (the spacecraft "
            "with --base floating), one revolute joint per healthy joint, link 'tool' at the end "
            "effector. Reading it back (jointlock, Pinocchio) gives the locked model's kinematics and "
            "dynamics to round-off. Read back, the healthy joints are numbered 1..n in chain order (their "
            "names keep the arm's numbers), the base is the one asked for (--base floating: the root "
            "link is the spacecraft), and velocity=\"0\" / effort=\"0\" mean no limit."
        ),
    )
    add_robot_arguments(p)
    p.add_argument("--out", type=Path, metavar="FILE", required=True, help="the URDF file to write")
    p.add_argument("--json", action="store_true", help="print one JSON object (the file, joints, locks)")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from ..io.urdf_export import write_urdf

    model = model_from_args(args)
    facts = export_facts(model, write_urdf(model, args.out))
    if args.json:
        print_json(facts)
        return 0
    print(export_line(facts))
    return 0
