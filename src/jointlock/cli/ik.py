"""``jointlock ik``: every inverse-kinematics branch of an arm, full or with a locked joint
(a thin shell over :func:`jointlock.jobs.ik.inverse_kinematics`)."""

from __future__ import annotations

import argparse
from typing import Any

from ..bounds import MAX_LENGTH_M, MIN_LENGTH_M
from ..errors import ScenarioError
from ._common import add_robot_arguments, model_from_args, number_arg, print_json, seed_arg


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "ik",
        help="inverse kinematics: every branch, full arm or with a locked joint",
        description=(
            "Closed form for 002's puma6 family (its printed theta3/theta4 equations corrected), "
            "the UR family (three parallel axes) and spherical-wrist arms (Pieper: PUMA with "
            "offsets, KUKA KR, ABB IRB, Staeubli), decided from the arm's own kinematics; "
            "Levenberg-Marquardt from several starts otherwise. When the locked arm "
            "cannot reach the target, the nearest reachable pose is reported."
        ),
    )
    add_robot_arguments(p)
    target = p.add_mutually_exclusive_group(required=True)
    target.add_argument(
        "--pose",
        type=number_arg(-MAX_LENGTH_M, MAX_LENGTH_M),
        nargs=6,
        metavar=("X", "Y", "Z", "YAW", "PITCH", "ROLL"),
        help="position [m] and ZYX Euler angles [deg] (R = Rz(yaw) Ry(pitch) Rx(roll), as 002 prints)",
    )
    target.add_argument(
        "--matrix",
        type=number_arg(-MAX_LENGTH_M, MAX_LENGTH_M),
        nargs=16,
        metavar="M",
        help="4x4 pose, row-major [m]",
    )
    p.add_argument(
        "--method",
        choices=("auto", "closed-form", "numeric"),
        default="auto",
        help="closed-form: analytic IK, every branch (6-joint arms of the puma6, UR or "
        "spherical-wrist family, at most one locked; the family used is printed); numeric: "
        "Levenberg-Marquardt from several random starts (any arm; --seed); auto (default): "
        "closed-form when the arm is of a family, numeric otherwise",
    )
    p.add_argument(
        "--length-scale",
        type=number_arg(MIN_LENGTH_M, MAX_LENGTH_M, unit="m"),
        default=1.0,
        metavar="M",
        help="L [m] of the nearest-pose metric (> 0)",
    )
    p.add_argument(
        "--tol-mm",
        type=number_arg(0.0, MAX_LENGTH_M * 1e3, unit="mm"),
        default=None,
        metavar="MM",
        help="accept a target reached within this distance [mm] when no exact solution exists (a pose "
        "typed with rounded numbers); default: exact only (1e-4 mm)",
    )
    p.add_argument(
        "--tol-deg",
        type=number_arg(0.0, 180.0, unit="deg"),
        default=None,
        metavar="DEG",
        help="the same for the orientation [deg]; default: exact only (5.7e-6 deg)",
    )
    p.add_argument("--seed", type=seed_arg, default=0, help="seed of the numerical starts (integer >= 0)")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.set_defaults(func=run)


def _target(args: argparse.Namespace) -> Any:
    """The target pose (4x4) of ``--pose`` or ``--matrix`` (checked, re-orthonormalised)."""
    import numpy as np

    from ..ik import pose_from_zyx

    if args.pose is not None:
        vals = np.asarray(args.pose, dtype=float)
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


def run(args: argparse.Namespace) -> int:
    import numpy as np

    from ..ik import EXACT_POSITION_TOL, EXACT_ROTATION_TOL
    from ..jobs.ik import inverse_kinematics

    model = model_from_args(args)
    tolerance = None
    if args.tol_mm is not None or args.tol_deg is not None:  # the one not given: exact
        tolerance = (
            max(1e-3 * (args.tol_mm or 0.0), EXACT_POSITION_TOL),
            max(np.radians(args.tol_deg or 0.0), EXACT_ROTATION_TOL),
        )
    report = inverse_kinematics(
        model, _target(args), method=args.method, rng=args.seed, length_scale=args.length_scale, tolerance=tolerance
    )
    if args.json:
        print_json(report.to_dict())
        return 0
    for line in report.summary():
        print(line)
    return 0
