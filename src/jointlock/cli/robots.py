"""``jointlock robots``: table of the built-in arms."""

from __future__ import annotations

import argparse

from ._common import print_json


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("robots", help="list the built-in robots (name, DOF, masses, lengths, base)")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.set_defaults(func=run)


def describe(name: str) -> dict:
    """One built-in arm's row: DOF, link masses and lengths, reach, spacecraft mass, reading."""
    import numpy as np

    from ..robots import load_robot

    fixed = load_robot(name)
    floating = load_robot(name, base="floating")
    lengths = [float(np.linalg.norm(j.placement[:3, 3])) for j in fixed.joints[1:]] + [
        float(np.linalg.norm(fixed.tool[:3, 3]))
    ]
    return {
        "name": name,
        "dof": fixed.dof,
        "masses_kg": [b.mass for b in fixed.bodies],
        "link_lengths_m": lengths,
        "reach_m": float(sum(lengths)),
        "spacecraft_mass_kg": floating.root_body.mass,
        "description": fixed.description,
    }


def run(args: argparse.Namespace) -> int:
    from ..robots import BUILTIN_ROBOTS

    rows = [describe(name) for name in BUILTIN_ROBOTS]
    if args.json:
        print_json({"robots": rows})
        return 0
    print(f"{'name':<10} {'DOF':>3} {'link masses [kg]':<42} {'reach [m]':>9} {'spacecraft [kg]':>15}")
    for r in rows:
        masses = ", ".join(f"{m:g}" for m in r["masses_kg"])
        print(
            f"{r['name']:<10} {r['dof']:>3} {masses:<42} {r['reach_m']:>9.3f} {r['spacecraft_mass_kg']:>15g}"
        )
    print("\njoint-to-joint distances [m] (last: to the end effector):")
    for r in rows:
        print(f"  {r['name']:<10} " + ", ".join(f"{v:.3f}" for v in r["link_lengths_m"]))
    print("\nreadings:")
    for r in rows:
        print(f"  {r['name']:<10} {r['description']}")
    return 0
