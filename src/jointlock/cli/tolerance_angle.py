"""``jointlock tolerance-angle``: the fault-tolerance angle gamma of seed 002 (Figs. 5-8)."""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import numpy as np

from ..errors import ScenarioError
from ..kinematics import ee_pose
from ..planning.replan import absorbable_range, gamma_sweep, gammas_for_lock
from ..robots import load_robot
from ._common import add_robot_arguments, check_out_dir, print_json, single_lock, write_png

#: Most gamma samples of one sweep (steps of about 0.0018 deg over +-180 deg; some 1.5 GB and
#: 15 s): each is an IK solution, and a tiny --step-deg would otherwise try to allocate many GiB.
MAX_GAMMA_SAMPLES = 200_000


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "tolerance-angle",
        help="gamma sweep (rotate the target about the tool x axis) and the gamma absorbing a lock "
        "(puma6-family arms only)",
        description=(
            "Works on puma6-family arms only (6 joints with 002 Table 1's structure, any a2, d4, d6: "
            "002's closed-form IK). Rotate the pose of --q-target-deg about the tool x axis by gamma in [-limit, limit], solve "
            "the full-arm IK on the branch of the target configuration, and find where the locked "
            "joint equals its locked angle (seed 002, eq. 18 and Figs. 5-8)."
        ),
    )
    add_robot_arguments(p)
    p.add_argument(
        "--q-target-deg",
        type=float,
        nargs="+",
        required=True,
        metavar="DEG",
        help="desired configuration, every joint of the arm [deg]",
    )
    p.add_argument(
        "--gamma-limit-deg",
        type=float,
        default=180.0,
        metavar="DEG",
        help="sweep |gamma| <= this [deg], in (0, 180] (default 180)",
    )
    p.add_argument(
        "--zoom-deg",
        type=float,
        default=2.0,
        metavar="DEG",
        help="half-width of the second, narrow gamma range [deg] (002 Fig. 6: 2)",
    )
    p.add_argument(
        "--step-deg", type=float, default=0.1, metavar="DEG", help="gamma sweep step [deg] (default 0.1)"
    )
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.add_argument("--out", type=Path, metavar="DIR", help="write plots and sweep.json here")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    check_out_dir(args.out)
    joint, angle = single_lock(args)
    model = load_robot(args.robot, base=args.base)
    if not 1 <= joint <= model.dof:
        raise ScenarioError(f"--lock joint must be 1..{model.dof}; got {joint}")
    if len(args.q_target_deg) != model.dof:
        raise ScenarioError(f"--q-target-deg needs {model.dof} values [deg]; got {len(args.q_target_deg)}")
    for name in ("gamma_limit_deg", "zoom_deg", "step_deg"):
        val = getattr(args, name)
        if not (0 < val <= 180):
            raise ScenarioError(f"--{name.replace('_', '-')} must be in (0, 180]; got {val}")
    q_target = np.radians(args.q_target_deg)
    target = ee_pose(model, q_target)
    limit, zoom, step = (math.radians(v) for v in (args.gamma_limit_deg, args.zoom_deg, args.step_deg))
    count = int(round(2 * limit / step)) + 1
    if count > MAX_GAMMA_SAMPLES:
        raise ScenarioError(
            f"--step-deg {args.step_deg:g} gives {count} gamma samples over +-{args.gamma_limit_deg:g} deg; "
            f"at most {MAX_GAMMA_SAMPLES} are allowed: use --step-deg >= "
            f"{2 * args.gamma_limit_deg / (MAX_GAMMA_SAMPLES - 1):.2g} or a smaller --gamma-limit-deg"
        )
    sweep = gamma_sweep(model, target, np.linspace(-limit, limit, count), q_ref=q_target)
    wide = absorbable_range(sweep, joint, limit)
    narrow = absorbable_range(sweep, joint, min(zoom, limit))
    roots = gammas_for_lock(model, target, joint, angle, branch=sweep.branch, gamma_limit=limit, step=step)
    out = {
        "robot": model.name,
        "q_target_deg": args.q_target_deg,
        "lock": {"joint": joint, "angle_deg": math.degrees(angle)},
        "branch": sweep.branch,
        "absorbable_range_deg": {
            f"gamma_within_{args.gamma_limit_deg:g}_deg": [
                math.degrees(wide.lower),
                math.degrees(wide.upper),
            ],
            f"gamma_within_{args.zoom_deg:g}_deg": [math.degrees(narrow.lower), math.degrees(narrow.upper)],
        },
        "roots": [{"gamma_deg": math.degrees(r.gamma), "q_deg": np.degrees(r.q_full)} for r in roots],
        "chosen": (
            {"gamma_deg": math.degrees(roots[0].gamma), "q_deg": np.degrees(roots[0].q_full)}
            if roots
            else None
        ),
    }
    if args.out is not None:
        out["files"] = _write(args.out, sweep, joint, angle, roots, zoom, out)
    if args.json:
        print_json(out)
        return 0
    print(
        f"{model.name}: gamma sweep on IK branch {sweep.branch}, joint {joint} locked at {math.degrees(angle):g} deg"
    )
    for key, (lo, hi) in out["absorbable_range_deg"].items():
        print(
            f"  lock angles of joint {joint} absorbable with {key.replace('_', ' ')}: {lo:.4f} .. {hi:.4f} deg"
        )
    if not roots:
        print(
            f"  no gamma within +-{args.gamma_limit_deg:g} deg puts joint {joint} at {math.degrees(angle):g} deg"
        )
    for r in roots:
        q = " ".join(f"{v:9.4f}" for v in np.degrees(r.q_full))
        print(f"  gamma = {math.degrees(r.gamma):10.5f} deg   q [deg] = {q}")
    for f in out.get("files", []):
        print(f"wrote {f}")
    return 0


def _write(out_dir: Path, sweep, joint, angle, roots, zoom, summary) -> list[str]:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from ..report import atomic_write_json

    out_dir.mkdir(parents=True, exist_ok=True)
    g = np.degrees(sweep.gammas)
    q = np.degrees(sweep.q)
    files = []
    for name, lim in (("joints_vs_gamma.png", None), ("joints_vs_gamma_zoom.png", math.degrees(zoom))):
        fig, axes = plt.subplots(2, 3, figsize=(12, 6), sharex=True)
        sel = np.ones(g.shape, bool) if lim is None else np.abs(g) <= lim + 1e-9
        for k, ax in enumerate(axes.ravel()):
            ax.plot(g[sel], q[sel, k])
            if k == joint - 1:
                ax.axhline(math.degrees(angle), color="r", ls="--", lw=1, label="locked angle")
                for r in roots:
                    if lim is None or abs(math.degrees(r.gamma)) <= lim:
                        ax.plot(math.degrees(r.gamma), math.degrees(angle), "ro")
                ax.legend(fontsize=8)
            ax.set_title(f"joint {k + 1}")
            ax.set_ylabel("angle [deg]")
            ax.grid(alpha=0.3)
        for ax in axes[1]:
            ax.set_xlabel("gamma (rotation about tool x) [deg]")
        fig.tight_layout()
        write_png(fig, out_dir / name, dpi=110)
        plt.close(fig)
        files.append(str(out_dir / name))
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.plot(g, q[:, joint - 1])
    ax.axhline(math.degrees(angle), color="r", ls="--", lw=1)
    ax.set_xlabel("gamma [deg]")
    ax.set_ylabel(f"joint {joint} [deg]")
    ax.grid(alpha=0.3)
    fig.tight_layout()
    write_png(fig, out_dir / "locked_joint_vs_gamma.png", dpi=110)
    plt.close(fig)
    files.append(str(out_dir / "locked_joint_vs_gamma.png"))
    atomic_write_json(out_dir / "sweep.json", {**summary, "gamma_deg": g, "q_deg": q})
    files.append(str(out_dir / "sweep.json"))
    return files
