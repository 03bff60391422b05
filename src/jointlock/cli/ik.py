"""``jointlock ik``: every inverse-kinematics branch of an arm, full or with a locked joint."""

from __future__ import annotations

import argparse
import math

import numpy as np

from ..errors import ScenarioError
from ..ik import pose_from_zyx, solve_ik, zyx_angles
from ._common import (
    add_robot_arguments,
    format_matrix,
    locked_deg,
    locked_text,
    model_from_args,
    print_json,
    require_finite,
    seed_arg,
)


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "ik",
        help="inverse kinematics: every branch, full arm or with a locked joint",
        description=(
            "Closed form for the puma6 family (002, with its printed theta3/theta4 equations "
            "corrected), Levenberg-Marquardt from several starts otherwise. When the locked arm "
            "cannot reach the target, the nearest reachable pose is reported."
        ),
    )
    add_robot_arguments(p)
    target = p.add_mutually_exclusive_group(required=True)
    target.add_argument(
        "--pose",
        type=float,
        nargs=6,
        metavar=("X", "Y", "Z", "YAW", "PITCH", "ROLL"),
        help="position [m] and ZYX Euler angles [deg] (R = Rz(yaw) Ry(pitch) Rx(roll), as 002 prints)",
    )
    target.add_argument("--matrix", type=float, nargs=16, metavar="M", help="4x4 pose, row-major [m]")
    p.add_argument(
        "--method",
        choices=("auto", "closed-form", "numeric"),
        default="auto",
        help="closed-form: 002's analytic IK, every branch (puma6-family arms only: 6 joints with "
        "002 Table 1's structure, at most one locked); numeric: Levenberg-Marquardt from several "
        "random starts (any arm; --seed); auto (default): closed-form when the arm is of the puma6 "
        "family, numeric otherwise",
    )
    p.add_argument(
        "--length-scale", type=float, default=1.0, metavar="M", help="L [m] of the nearest-pose metric (> 0)"
    )
    p.add_argument("--seed", type=seed_arg, default=0, help="seed of the numerical starts (integer >= 0)")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.set_defaults(func=run)


def _target(args: argparse.Namespace) -> np.ndarray:
    if args.pose is not None:
        vals = np.asarray(args.pose, dtype=float)
        if not np.all(np.isfinite(vals)):
            raise ScenarioError(f"--pose must be 6 finite numbers; got {args.pose}")
        return pose_from_zyx(vals[:3], np.radians(vals[3:]))
    mat = np.asarray(args.matrix, dtype=float).reshape(4, 4)
    rot = mat[:3, :3]
    if (
        not np.all(np.isfinite(mat))
        or not np.allclose(rot @ rot.T, np.eye(3), atol=1e-4)
        or np.linalg.det(rot) < 0
    ):
        raise ScenarioError("--matrix: the upper-left 3x3 block must be a rotation matrix (tolerance 1e-4)")
    if not np.allclose(mat[3], [0, 0, 0, 1]):
        raise ScenarioError(f"--matrix: the last row must be 0 0 0 1; got {mat[3].tolist()}")
    # re-orthonormalise a matrix typed with 4 decimals
    u, _, vt = np.linalg.svd(rot)
    mat[:3, :3] = u @ vt
    return mat


def _solution(sol) -> dict:
    return {
        "branch": sol.branch,
        "q_deg": np.degrees(sol.q_full),
        "position_error_m": sol.position_error,
        "rotation_error_deg": math.degrees(sol.rotation_error),
        "exact": sol.exact,
    }


def run(args: argparse.Namespace) -> int:
    require_finite(args, "length_scale")
    if not args.length_scale > 0:
        raise ScenarioError(f"--length-scale must be > 0 [m]; got {args.length_scale}")
    model = model_from_args(args)
    target = _target(args)
    res = solve_ik(model, target, method=args.method, rng=args.seed, length_scale=args.length_scale)
    out = {
        "robot": model.name,
        "locked": locked_deg(model),
        "method": res.method,
        "target": target,
        "target_position_m": target[:3, 3],
        "target_zyx_deg": np.degrees(zyx_angles(target[:3, :3])),
        "reachable": res.reachable,
        "solutions": [_solution(s) for s in res.solutions],
        "candidates": [_solution(s) for s in res.candidates],
        "nearest": None,
    }
    if res.nearest is not None:
        near = res.nearest_pose
        out["nearest"] = {
            **_solution(res.nearest),
            "pose": near,
            "position_m": near[:3, 3],
            "zyx_deg": np.degrees(zyx_angles(near[:3, :3])),
            "distance_position_m": res.nearest.position_error,
            "distance_rotation_deg": math.degrees(res.nearest.rotation_error),
            "length_scale_m": res.length_scale,
        }
    if args.json:
        print_json(out)
        return 0
    locked = locked_text(out["locked"])
    print(f"{model.name}: {res.method} IK, locked: {locked}")
    print("target T_base_ee [m]:")
    print(format_matrix(target, "{:>11.6f}"))
    if res.reachable:
        print(
            f"\n{len(res.solutions)} solution(s), q [deg] (all joints), position error [m], rotation error [deg]:"
        )
        for s in res.solutions:
            q = " ".join(f"{v:9.4f}" for v in np.degrees(s.q_full))
            print(f"  branch {s.branch}: {q}   {s.position_error:.2e}  {math.degrees(s.rotation_error):.2e}")
    else:
        n = out["nearest"]
        print("\nnot reachable by this arm" + (" with the locked joint" if model.locked else ""))
        if n is not None:
            print("nearest reachable pose [m]:")
            print(format_matrix(n["pose"], "{:>11.6f}"))
            print(
                f"distance: {n['distance_position_m']:.6g} m, {n['distance_rotation_deg']:.6g} deg; "
                "q [deg]: " + " ".join(f"{v:.4f}" for v in n["q_deg"])
            )
    return 0
