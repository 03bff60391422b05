"""``jointlock workspace``: Monte Carlo workspace of the full and the locked arm (002 Figs. 2-3)."""

from __future__ import annotations

import argparse
import io
import math
import sys
from pathlib import Path

import numpy as np

from ..analysis.workspace import (
    MIN_SAMPLES,
    MIN_SAMPLES_PER_VOXEL,
    _auto_voxel,
    compare_workspaces,
    projection_extent,
    sample_workspace,
)
from ..errors import ScenarioError
from ..progress import Progress
from ..robots import load_robot
from ._common import add_robot_arguments, check_out_dir, print_json, require_finite, seed_arg, write_png


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "workspace",
        help="Monte Carlo workspace, full arm vs locked arm: clouds, projections, volume, share kept",
        description=(
            "Sample joint angles uniformly within the limits (capped to +-180 deg), compute the "
            "end-effector positions of the full arm and, with --lock, of the arm with that joint "
            "locked (002 Figs. 2-3), and estimate each volume by voxel occupancy on one common grid "
            "(cubes of side --voxel holding at least one sample). The share of the full workspace "
            "that the locked arm keeps is a Monte Carlo estimate that moves with --samples and "
            "--voxel: it is printed next to the same estimate from half the samples, and a warning "
            "says when the two differ or when many locked voxels fall outside the full cloud."
        ),
    )
    add_robot_arguments(p)
    p.add_argument(
        "--samples",
        type=int,
        default=200_000,
        help=f"configurations per arm, >= {MIN_SAMPLES} (default 200000)",
    )
    p.add_argument(
        "--voxel", type=float, default=None, metavar="M", help="voxel side [m] (default: automatic)"
    )
    p.add_argument("--seed", type=seed_arg, default=0, help="random seed, integer >= 0 (default 0)")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.add_argument("--out", type=Path, metavar="DIR", help="write projections, clouds (NPZ) and summary here")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    if args.samples < MIN_SAMPLES:
        raise ScenarioError(
            f"--samples must be >= {MIN_SAMPLES} (a voxel-occupancy volume from fewer samples says "
            f"little); got {args.samples}"
        )
    require_finite(args, "voxel")
    check_out_dir(args.out)
    if args.voxel is not None and not (args.voxel > 0):
        raise ScenarioError(f"--voxel must be > 0 [m]; got {args.voxel}")
    if len(args.lock) > 1:
        raise ScenarioError(f"--lock may be given at most once; got {len(args.lock)}")
    model = load_robot(args.robot, base=args.base)
    with Progress(1, "workspace", enabled=None if not args.json else False) as bar:
        if args.lock:
            joint, angle = args.lock[0]
            cmp = compare_workspaces(
                model, joint, angle, samples=args.samples, voxel=args.voxel, rng=args.seed
            )
            full, locked, voxel = cmp.full, cmp.locked, cmp.voxel
            density, warnings = cmp.samples_per_voxel, cmp.warnings()
            summary = {
                "robot": model.name,
                "samples": args.samples,
                "seed": args.seed,
                "lock": {"joint": joint, "angle_deg": math.degrees(angle)},
                "voxel_m": voxel,
                "volume_full_m3": cmp.volume_full,
                "volume_locked_m3": cmp.volume_locked,
                "share_kept": cmp.share_kept,
                "share_kept_half_samples": cmp.share_kept_half,
                "voxel_half_samples_m": cmp.voxel_half,
                "locked_voxels_outside_full": cmp.outside,
                "extent_full_m": projection_extent(full),
                "extent_locked_m": projection_extent(locked),
            }
        else:
            ws = sample_workspace(model, samples=args.samples, voxel=args.voxel, rng=args.seed)
            full, locked, voxel = ws.points, None, ws.voxel
            density, warnings = ws.samples_per_voxel, []
            summary = {
                "robot": model.name,
                "samples": args.samples,
                "seed": args.seed,
                "lock": None,
                "voxel_m": voxel,
                "volume_full_m3": ws.volume,
                "extent_full_m": projection_extent(full),
            }
        bar.update()
    if args.voxel is not None and not density >= MIN_SAMPLES_PER_VOXEL:
        raise ScenarioError(
            f"--voxel {args.voxel:g} m is too small for {args.samples} samples: only {density:.2g} samples per "
            f"occupied voxel on average, so the volume is about samples x voxel^3, not the workspace's; use a "
            f"larger --voxel (automatic for these samples: {_auto_voxel(full):.3g} m) or more samples"
        )
    summary["samples_per_voxel"] = density
    if locked is not None:
        summary["warnings"] = warnings
    for w in warnings:
        print(f"jointlock workspace: warning: {w}", file=sys.stderr)
    if args.out is not None:
        summary["files"] = _write(args.out, full, locked, summary)
    if args.json:
        print_json(summary)
        return 0
    print(
        f"{model.name}: {args.samples} samples per arm (seed {args.seed}), voxel {voxel:.3g} m "
        f"({density:.3g} samples per occupied voxel)"
    )
    print(f"  full arm volume   : {summary['volume_full_m3']:.3g} m^3")
    if locked is not None:
        lk = summary["lock"]
        print(
            f"  locked arm volume : {summary['volume_locked_m3']:.3g} m^3 (joint {lk['joint']} at {lk['angle_deg']:g} deg)"
        )
        print(
            f"  share kept        : {100 * summary['share_kept']:.0f} % (from half the samples: "
            f"{100 * summary['share_kept_half_samples']:.0f} %)"
            + ("; not converged, see the warnings" if warnings else "")
        )
        print(
            f"  locked voxels outside the full cloud (sampling): {100 * summary['locked_voxels_outside_full']:.1f} %"
        )
    for f in summary.get("files", []):
        print(f"wrote {f}")
    return 0


def _write(out_dir: Path, full: np.ndarray, locked: np.ndarray | None, summary: dict) -> list[str]:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from ..report import atomic_write_bytes, atomic_write_json

    out_dir.mkdir(parents=True, exist_ok=True)
    files = []
    show = 20000
    f_pts = full[:show]
    l_pts = None if locked is None else locked[:show]
    fig, axes = plt.subplots(1, 3, figsize=(14, 4.5))
    for ax, (i, j, name) in zip(axes, ((0, 1, "xy"), (0, 2, "xz"), (1, 2, "yz"))):
        ax.scatter(f_pts[:, i], f_pts[:, j], s=0.3, alpha=0.3, label="full arm", color="tab:blue")
        if l_pts is not None:
            ax.scatter(l_pts[:, i], l_pts[:, j], s=0.3, alpha=0.3, label="locked arm", color="tab:red")
        ax.set_xlabel(f"{name[0]} [m]")
        ax.set_ylabel(f"{name[1]} [m]")
        ax.set_aspect("equal")
        ax.set_title(f"{name} projection")
    axes[0].legend(markerscale=20)
    fig.tight_layout()
    write_png(fig, out_dir / "projections.png", dpi=110)
    plt.close(fig)
    files.append(str(out_dir / "projections.png"))
    fig = plt.figure(figsize=(11, 5))
    clouds = [("full arm", f_pts, "tab:blue")] + (
        [("locked arm", l_pts, "tab:red")] if l_pts is not None else []
    )
    for k, (title, pts, color) in enumerate(clouds):
        ax = fig.add_subplot(1, len(clouds), k + 1, projection="3d")
        ax.scatter(pts[:5000, 0], pts[:5000, 1], pts[:5000, 2], s=0.5, alpha=0.4, color=color)
        ax.set_title(title)
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
        ax.set_zlabel("z [m]")
    fig.tight_layout()
    write_png(fig, out_dir / "clouds.png", dpi=110)
    plt.close(fig)
    files.append(str(out_dir / "clouds.png"))
    arrays = {"full": full} if locked is None else {"full": full, "locked": locked}
    buf = io.BytesIO()
    np.savez_compressed(buf, **arrays)
    atomic_write_bytes(out_dir / "points.npz", buf.getvalue())
    files.append(str(out_dir / "points.npz"))
    atomic_write_json(out_dir / "workspace.json", summary)
    files.append(str(out_dir / "workspace.json"))
    return files
