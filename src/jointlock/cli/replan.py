"""``jointlock replan``: straight-line Cartesian re-planning of an arm with a locked joint (002)."""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import numpy as np

from ..errors import ScenarioError
from ..ik import zyx_angles
from ..kinematics import ee_pose
from ..locking import lock
from ..planning.replan import DEFAULT_STEP_WEIGHT, replan_line
from ..robots import load_robot
from ._common import add_robot_arguments, check_out_dir, print_json, require_finite, single_lock, write_png


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "replan",
        help="straight-line Cartesian plan through the locked-arm IK, with the tolerance angle gamma "
        "(puma6-family arms only)",
        description=(
            "Works on puma6-family arms only (6 joints with 002 Table 1's structure, any a2, d4, d6: "
            "002's closed-form IK). "
            "Start and goal are the poses of the full-arm joint vectors --from-deg and --to-deg; the "
            "line (002 eqs. 19-20) is followed by the arm with --lock, each waypoint rotated about the "
            "tool x axis by some |gamma| <= --tolerance-deg.  --method continuous (default) chooses "
            "gamma and the IK branch along the whole path (shortest path: tracking error plus "
            "--step-weight times the squared joint steps), so the joints do not jump; --method "
            "pointwise takes the smallest |gamma| that absorbs the lock at each waypoint on its own. "
            "The largest joint step, every jump and every step over a joint's speed limit are reported."
        ),
    )
    add_robot_arguments(p)
    p.add_argument(
        "--from-deg",
        type=float,
        nargs="+",
        required=True,
        metavar="DEG",
        help="start configuration, every joint of the arm [deg]",
    )
    p.add_argument(
        "--to-deg",
        type=float,
        nargs="+",
        required=True,
        metavar="DEG",
        help="goal configuration, every joint of the arm [deg]",
    )
    p.add_argument("--steps", type=int, default=40, help="interior points N of eq. (19), >= 1 (default 40)")
    p.add_argument("--cycle", type=float, default=0.25, help="time between points [s] (002: 0.25)")
    p.add_argument(
        "--tolerance-deg", type=float, default=0.0, help="largest |gamma| accepted [deg] (default 0)"
    )
    p.add_argument(
        "--method",
        choices=("continuous", "pointwise"),
        default="continuous",
        help="choose gamma and branch along the path (default) or at each waypoint alone",
    )
    p.add_argument(
        "--step-weight",
        type=float,
        default=DEFAULT_STEP_WEIGHT,
        metavar="M_PER_RAD2",
        help=f"continuous: tracking error [m] traded per rad^2 of joint step (default {DEFAULT_STEP_WEIGHT:g})",
    )
    p.add_argument(
        "--jump-deg",
        type=float,
        default=None,
        metavar="DEG",
        help="flag joint steps above this [deg] (default: 5x the median step, between 2 and 30 deg)",
    )
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.add_argument("--out", type=Path, metavar="DIR", help="write plots, trajectory.csv and plan.json here")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    require_finite(args, "cycle", "tolerance_deg", "step_weight", "jump_deg")
    check_out_dir(args.out)
    joint, angle = single_lock(args)
    full = load_robot(args.robot, base=args.base)
    for opt, vals in (("--from-deg", args.from_deg), ("--to-deg", args.to_deg)):
        if len(vals) != full.dof or not np.all(np.isfinite(vals)):
            raise ScenarioError(f"{opt} needs {full.dof} finite values (all joints) [deg]; got {vals}")
    if args.steps < 1:
        raise ScenarioError(
            f"--steps must be >= 1 (interior points between start and goal); got {args.steps}"
        )
    if not (args.cycle > 0):
        raise ScenarioError(f"--cycle must be > 0 [s]; got {args.cycle}")
    if not (0 <= args.tolerance_deg <= 180):
        raise ScenarioError(f"--tolerance-deg must be in [0, 180]; got {args.tolerance_deg}")
    if not (args.step_weight >= 0):
        raise ScenarioError(f"--step-weight must be >= 0; got {args.step_weight}")
    if args.jump_deg is not None and not (args.jump_deg > 0):
        raise ScenarioError(f"--jump-deg must be > 0; got {args.jump_deg}")
    model = lock(full, joint, angle)
    q_to = np.radians(args.to_deg)
    start, goal = ee_pose(full, np.radians(args.from_deg)), ee_pose(full, q_to)
    res = replan_line(
        model,
        start,
        goal,
        steps=args.steps,
        cycle=args.cycle,
        gamma_tolerance=math.radians(args.tolerance_deg),
        q_ref=q_to,
        method=args.method,
        step_weight=args.step_weight,
        jump_threshold=None if args.jump_deg is None else math.radians(args.jump_deg),
    )
    step_at, step_joint = res.max_joint_step_at
    summary = {
        "robot": full.name,
        "lock": {"joint": joint, "angle_deg": math.degrees(angle)},
        "waypoints": int(res.times.size),
        "duration_s": float(res.times[-1]),
        "branch": res.branch,
        "tolerance_deg": args.tolerance_deg,
        "absorbed_waypoints": int(res.absorbed.sum()),
        "gamma_deg_range": [float(np.degrees(res.gamma.min())), float(np.degrees(res.gamma.max()))],
        "max_tracking_position_error_m": float(res.position_error.max()),
        "max_tracking_rotation_error_deg": float(np.degrees(res.rotation_error.max())),
        "max_deviation_from_line_m": float(res.position_deviation.max()),
        "max_rotation_deviation_deg": float(np.degrees(res.rotation_deviation.max())),
        "max_joint_rate_deg_s": np.degrees(np.abs(res.dq).max(axis=0)),
        "q_start_deg": np.degrees(res.q_full[0]),
        "q_goal_deg": np.degrees(res.q_full[-1]),
        "gamma_goal_deg": float(np.degrees(res.gamma[-1])),
        "method": res.method,
        "step_weight": args.step_weight,
        "mean_tracking_position_error_m": float(res.position_error.mean()),
        "max_joint_step_deg": math.degrees(res.max_joint_step),
        "max_joint_step_at": {"step": step_at, "time_s": float(res.times[step_at]), "joint": step_joint},
        "max_joint_step_per_joint_deg": np.degrees(res.joint_step.max(axis=0)) if res.joint_step.size else [],
        "max_step_rate_deg_s": np.degrees(res.step_rate.max(axis=0)) if res.joint_step.size else [],
        "velocity_limit_deg_s": [v if math.isfinite(v) else None for v in np.degrees(res.velocity_limit)],
        "jump_threshold_deg": math.degrees(res.jump_threshold),
        "jumps": [_flag(f, "deg") for f in res.jumps],
        "over_velocity": [_flag(f, "deg_s") for f in res.over_velocity],
    }
    trajectory = {
        "time_s": res.times,
        "q_deg": np.degrees(res.q_full),
        "gamma_deg": np.degrees(res.gamma),
        "absorbed": res.absorbed,
        "position_error_m": res.position_error,
        "rotation_error_deg": np.degrees(res.rotation_error),
    }
    if args.out is not None:
        summary["files"] = _write(args.out, res, summary, trajectory)
    if args.json:
        print_json({**summary, "trajectory": trajectory})
        return 0
    print(
        f"{full.name}, joint {joint} locked at {math.degrees(angle):g} deg: {res.times.size} waypoints over "
        f"{res.times[-1]:g} s, gamma tolerance {args.tolerance_deg:g} deg"
    )
    print(f"  waypoints where the lock is absorbed exactly: {summary['absorbed_waypoints']}/{res.times.size}")
    print(f"  gamma used: {summary['gamma_deg_range'][0]:.4f} .. {summary['gamma_deg_range'][1]:.4f} deg")
    print(
        f"  max tracking error: {summary['max_tracking_position_error_m'] * 1e3:.4f} mm, "
        f"{summary['max_tracking_rotation_error_deg']:.4g} deg"
    )
    print(
        f"  largest joint step: {summary['max_joint_step_deg']:.4g} deg (joint {step_joint}, waypoint "
        f"{step_at} -> {step_at + 1}, t = {res.times[step_at]:g} s); jump threshold "
        f"{summary['jump_threshold_deg']:.4g} deg"
    )
    for f in res.jumps:
        print(
            f"  JUMP: joint {f.joint} moves {math.degrees(f.step):.4g} deg between t = {f.time:g} s and "
            f"{f.time + res.cycle:g} s ({math.degrees(f.rate):.4g} deg/s)"
        )
    if res.over_velocity:
        worst = max(res.over_velocity, key=lambda f: f.rate / f.limit)
        print(
            f"  {len(res.over_velocity)} joint steps exceed the speed limit; worst: joint {worst.joint} at "
            f"t = {worst.time:g} s needs {math.degrees(worst.rate):.4g} deg/s (limit {math.degrees(worst.limit):.4g})"
        )
    elif np.all(np.isfinite(res.velocity_limit)):
        print("  every joint step is within the speed limits at this cycle")
    print("  goal q [deg]: " + " ".join(f"{v:.4f}" for v in summary["q_goal_deg"]))
    for f in summary.get("files", []):
        print(f"wrote {f}")
    return 0


def _flag(f, unit: str) -> dict:
    lim = math.degrees(f.limit)
    return {
        "step": f.index,
        "time_s": f.time,
        "joint": f.joint,
        "step_deg": math.degrees(f.step),
        "rate_deg_s": math.degrees(f.rate),
        f"limit_{unit}": lim,
    }


def _write(out_dir: Path, res, summary, trajectory) -> list[str]:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from ..report import atomic_write_json, atomic_write_text

    out_dir.mkdir(parents=True, exist_ok=True)
    t = res.times
    files = []

    def save(fig, name):
        # every panel plots against time, with a legend and a light grid
        for ax in fig.axes:
            ax.set_xlabel("time [s]")
            ax.legend(fontsize=8)
            ax.grid(alpha=0.3)
        fig.tight_layout()
        write_png(fig, out_dir / name, dpi=110)
        plt.close(fig)
        files.append(str(out_dir / name))

    fig, ax = plt.subplots(figsize=(7, 4))
    for k in range(res.q_full.shape[1]):
        ax.plot(t, np.degrees(res.q_full[:, k]), label=f"joint {k + 1}")
    ax.set_ylabel("angle [deg]")
    save(fig, "joints.png")

    fig, (a1, a2) = plt.subplots(1, 2, figsize=(11, 4))
    for k, lab in enumerate("xyz"):
        a1.plot(t, res.actual[:, k, 3] * 1e3, label=f"{lab} actual")
        a1.plot(t, res.nominal[:, k, 3] * 1e3, "--", lw=1, label=f"{lab} line")
    eul = np.degrees(zyx_angles(res.actual[:, :3, :3]))
    for k, lab in enumerate(("yaw", "pitch", "roll")):
        a2.plot(t, eul[:, k], label=lab)
    a1.set_ylabel("position [mm]")
    a2.set_ylabel("ZYX Euler [deg]")
    save(fig, "pose.png")

    fig, (a1, a2) = plt.subplots(1, 2, figsize=(11, 4))
    a1.plot(t, res.position_error * 1e3, label="tracking (vs line rotated by gamma)")
    a1.plot(t, res.position_deviation * 1e3, "--", label="vs line")
    a2.plot(t, np.degrees(res.rotation_error), label="tracking")
    a2.plot(t, np.degrees(res.rotation_deviation), "--", label="vs line (includes gamma)")
    a2.plot(t, np.degrees(res.gamma), ":", label="gamma")
    a1.set_ylabel("position error [mm]")
    a2.set_ylabel("rotation [deg]")
    save(fig, "error.png")

    fig, (a1, a2) = plt.subplots(1, 2, figsize=(11, 4))
    for k in range(3):
        a1.plot(t, res.ee_velocity[:, k] * 1e3, label=f"v{'xyz'[k]}")
        a2.plot(t, np.degrees(res.ee_velocity[:, 3 + k]), label=f"w{'xyz'[k]}")
    a1.set_ylabel("linear velocity [mm/s]")
    a2.set_ylabel("angular velocity [deg/s]")
    save(fig, "velocity.png")

    header = "time_s," + ",".join(f"q{k + 1}_deg" for k in range(res.q_full.shape[1]))
    header += ",gamma_deg,position_error_m,rotation_error_deg"
    rows = np.column_stack(
        [t, np.degrees(res.q_full), np.degrees(res.gamma), res.position_error, np.degrees(res.rotation_error)]
    )
    lines = [header] + [",".join(f"{v:.9g}" for v in row) for row in rows]
    atomic_write_text(out_dir / "trajectory.csv", "\n".join(lines) + "\n")
    files.append(str(out_dir / "trajectory.csv"))
    atomic_write_json(out_dir / "plan.json", {**summary, "trajectory": trajectory})
    files.append(str(out_dir / "plan.json"))
    return files
