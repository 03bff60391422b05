"""``jointlock workspace``: Monte Carlo workspace of the full and the locked arm (002 Figs. 2-3)."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from ..errors import ScenarioError
from ._common import (
    add_robot_arguments,
    chain_from_args,
    check_out_dir,
    field_arg,
    lock_map,
    print_json,
    seed_arg,
)
from ._constants import WORKSPACE_MIN_SAMPLES as MIN_SAMPLES


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "workspace",
        help="Monte Carlo workspace, full arm vs locked arm: clouds, projections, volume, share kept",
        description=(
            "Sample joint angles uniformly within the limits as given (a joint without limits: one "
            "turn), compute the "
            "end-effector positions of the full arm and, with --lock, of the arm with that joint "
            "locked (002 Figs. 2-3), and estimate each volume with its error: voxel occupancy at "
            "several voxel sides, all and half the samples, extrapolated to a zero side (the full "
            "arm's counting the locked arm's samples too, so the locked workspace is a subset). Too "
            "few samples give no estimate and say so. The plain voxel occupancy on one common grid "
            "(cubes of side --voxel holding at least one sample) and the share kept from it are "
            "printed too, next to the same share from half the samples, and a warning says when "
            "the two differ or when many locked voxels fall outside the full cloud. With "
            "--lock repeated, the last is the failure and the others were locked before it: the "
            "comparison is then before vs after the failure."
        ),
    )
    add_robot_arguments(p)
    p.add_argument(
        "--samples",
        type=field_arg("workspace", "samples"),
        default=200_000,
        help=f"configurations per arm, >= {MIN_SAMPLES} (default 200000)",
    )
    p.add_argument(
        "--voxel",
        type=field_arg("workspace", "voxel"),
        default=None,
        metavar="M",
        help="voxel side of the plain occupancy and the figures [m] (default: automatic); the volume "
        "estimates use their own ladder of sides",
    )
    p.add_argument("--seed", type=seed_arg, default=0, help="random seed, integer >= 0 (default 0)")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.add_argument("--out", type=Path, metavar="DIR", help="write projections, clouds (NPZ) and summary here")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from ..jobs.workspace import VoxelTooSmallError, study_workspace
    from ..locking import lock_joints
    from ..robots import load_robot

    check_out_dir(args.out)
    model = load_robot(args.robot, base=args.base, chain=chain_from_args(args))
    lock_map(args.lock)  # each joint once
    if len(args.lock) > 1:  # the last --lock is the failure; the others were locked before it
        model = lock_joints(model, lock_map(args.lock[:-1]))
    try:
        result = study_workspace(
            model,
            args.lock[-1] if args.lock else None,
            samples=args.samples,
            voxel=args.voxel,
            rng=args.seed,
            progress=not args.json,
        )
    except VoxelTooSmallError as exc:
        raise ScenarioError(exc.message("--voxel")) from None
    out = result.to_dict()
    if args.out is not None:
        out["files"] = [str(Path(args.out) / name) for name in result.write(args.out)]
    lines = result.summary()
    # the warnings only once every figure is computed and written: a failure is the last line
    for w in result.warnings():
        print(f"jointlock workspace: warning: {w}", file=sys.stderr)
    if args.json:
        print_json(out)
        return 0
    for line in lines:
        print(line)
    for f in out.get("files", []):
        print(f"wrote {f}")
    return 0
