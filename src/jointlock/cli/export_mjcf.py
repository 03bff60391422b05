"""``jointlock export-mjcf``: the (locked) arm and its spacecraft as a MuJoCo model file (MJCF),
its locked joints folded in and their bodies merged, or held by brakes (a thin shell over
:func:`jointlock.mjcf.write_mjcf`)."""

from __future__ import annotations

import argparse
from pathlib import Path

from ._common import add_robot_arguments, export_facts, export_line, model_from_args, print_json


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "export-mjcf",
        help="write the (locked) arm and its spacecraft as a MuJoCo model (MJCF)",
        description=(
            "Write the arm as a MuJoCo model: with every --lock folded into the chain and the bodies it "
            "joins merged (or, with --brakes, kept as hinges held at their angles by joint equalities, "
            "whose constraint torque is the brake's), the spacecraft a free body with its mass and "
            "inertia (--base floating) or welded to the world (--base fixed), no gravity (in orbit), the "
            "joint limits, one motor per healthy joint with the effort limit as its control range, the "
            "collision geometry as geoms, and a site 'tool' at the end effector. Numbers are written in "
            "full precision: MuJoCo's inverse dynamics of the file equal jointlock's to round-off."
        ),
    )
    add_robot_arguments(p)
    p.add_argument("--out", type=Path, metavar="FILE", required=True, help="the MJCF file to write (.xml)")
    p.add_argument(
        "--brakes",
        action="store_true",
        help="keep each locked joint as a hinge held by a joint equality at its angle (its constraint "
        "torque is the brake torque) instead of folding it into the chain",
    )
    p.add_argument("--json", action="store_true", help="print one JSON object (the file, joints, locks)")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from ..mjcf import write_mjcf

    model = model_from_args(args)
    facts = export_facts(model, write_mjcf(model, args.out, brakes=args.brakes))
    facts["brakes"] = bool(args.brakes and model.locked)
    if args.json:
        print_json(facts)
        return 0
    print(export_line(facts) + (" (held by brakes)" if facts["brakes"] else ""))
    return 0
