"""``jointlock kinematics``: end-effector pose, Jacobian and singular values at one configuration."""

from __future__ import annotations

import argparse
import math

import numpy as np

from ..kinematics import chain_state, generalized_jacobian, jacobian
from ..spatial import pose
from ._common import (
    add_robot_arguments,
    format_matrix,
    joint_vector_deg,
    locked_deg,
    locked_text,
    model_from_args,
    print_json,
)


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
        "--q-deg", type=float, nargs="+", metavar="DEG", help="joint angles [deg] (default: zeros)"
    )
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    model = model_from_args(args)
    q = joint_vector_deg(model, args.q_deg, "--q-deg")
    state = chain_state(model, q)
    jac = generalized_jacobian(model, q, state=state) if model.floating else jacobian(model, q, state=state)
    sv = np.linalg.svd(jac, compute_uv=False)
    ee = pose(state.ee_rotation, state.ee_position)
    result = {
        "robot": model.name,
        "base": "floating" if model.floating else "fixed",
        "joint_numbers": list(model.joint_numbers),
        "locked": locked_deg(model),
        "q_deg": np.degrees(q),
        "pose": ee,
        "jacobian": jac,
        "jacobian_kind": "generalized" if model.floating else "geometric",
        "jacobian_convention": "twist (v, omega) of the end-effector origin, base-frame components",
        "singular_values": sv,
        "condition_number": float(sv[0] / sv[-1]) if sv[-1] > 0 else math.inf,
        "manipulability": float(np.prod(sv)),
    }
    if args.json:
        print_json(result)
        return 0
    locked = locked_text(result["locked"])
    print(
        f"{model.name}: {model.dof} movable joints {list(model.joint_numbers)}, locked: {locked}, base: {result['base']}"
    )
    print("q [deg]: " + ", ".join(f"{v:.4f}" for v in result["q_deg"]))
    print("\nend-effector pose T_base_ee [m]:")
    print(format_matrix(ee, "{:>11.6f}"))
    print(f"\n{result['jacobian_kind']} Jacobian (rows vx vy vz [m/s], wx wy wz [rad/s]):")
    print(format_matrix(jac, "{:>11.5f}", [f"joint {n}" for n in model.joint_numbers]))
    print("\nsingular values: " + ", ".join(f"{v:.6g}" for v in sv))
    print(
        f"condition number: {result['condition_number']:.6g}   manipulability: {result['manipulability']:.6g}"
    )
    return 0
