"""``jointlock singular``: singularity analysis at one configuration, verification of seed
004's conditions Cond1-Cond5, and a search for the singular configurations of any arm."""

from __future__ import annotations

import argparse
import math
from pathlib import Path
from typing import Any

import numpy as np

from ..analysis import singularity as sg
from ..errors import ModelError, ScenarioError
from ..locking import lock_joints
from ..model import ArmModel
from ..progress import Progress
from ..robots import load_robot
from ._common import (
    add_robot_arguments,
    check_out_dir,
    format_matrix,
    joint_vector_deg,
    lock_map,
    locked_deg,
    locked_text,
    print_json,
    require_finite,
    seed_arg,
)

TWIST = ("vx", "vy", "vz", "wx", "wy", "wz")


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "singular",
        help="singular values, rank, lost directions; 004's Cond1-Cond5; singularity search",
        description=(
            "Singularity analysis. Jacobian: twist (v [m/s], omega [rad/s]) of the end-effector origin, "
            "base-frame components; --base fixed (geometric), floating (generalized, zero momentum) or "
            "virtual (004's virtual manipulator). For a Canadarm2-structure arm (canadarm7) the conditions "
            "Cond1-Cond5 of seed 004 are evaluated too."
        ),
    )
    add_robot_arguments(
        p,
        base_choices=sg.BASE_KINDS,
        base_default=None,
        base_help="fixed, floating (generalized Jacobian) or virtual (virtual manipulator); "
        "default: virtual with --verify-conditions, fixed otherwise",
    )
    p.add_argument(
        "--weighting",
        choices=("segment", "vafa-dubowsky"),
        default="segment",
        help="virtual link lengths: 004's formula (segment, default) or the exact Vafa-Dubowsky one",
    )
    p.add_argument(
        "--q-deg", type=float, nargs="+", metavar="DEG", help="joint angles [deg] (default: zeros)"
    )
    p.add_argument(
        "--tol",
        type=float,
        default=sg.RANK_TOL,
        help=f"rank tolerance on singular values (default {sg.RANK_TOL:g})",
    )
    p.add_argument(
        "--length",
        type=float,
        default=None,
        metavar="L",
        help="characteristic length [m] dividing the linear rows",
    )
    mode = p.add_mutually_exclusive_group()
    mode.add_argument(
        "--verify-conditions", action="store_true", help="check 004's Cond1-Cond5 by sampling and search"
    )
    mode.add_argument(
        "--search", action="store_true", help="search for singular configurations and cluster them"
    )
    p.add_argument(
        "--samples", type=int, default=None, help="samples per condition (2000) or search starts (512)"
    )
    p.add_argument("--seed", type=seed_arg, default=0, help="random seed, integer >= 0 (default 0)")
    p.add_argument(
        "--out", type=Path, default=None, metavar="DIR", help="--search: write search.json and plots here"
    )
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.set_defaults(func=run)


def _model(args: argparse.Namespace, base: str) -> ArmModel:
    model = load_robot(args.robot, base="fixed" if base == "fixed" else "floating")
    locks = lock_map(args.lock)
    return lock_joints(model, locks) if locks else model


def _lengths_or_none(model: ArmModel, base: str, weighting: str) -> sg.ArmLengths | None:
    if base == "floating" or model.dof != 7 or model.locked:
        return None
    try:
        return sg.arm_lengths(model, base=base, weighting=weighting)  # type: ignore[arg-type]
    except ModelError:
        return None


def run(args: argparse.Namespace) -> int:
    if args.samples is not None and args.samples < 1:
        raise ScenarioError(f"--samples must be >= 1; got {args.samples}")
    require_finite(args, "tol", "length")
    check_out_dir(args.out)
    if args.verify_conditions:
        return _verify(args)
    if args.search:
        return _search(args)
    return _single(args)


# -- one configuration -----------------------------------------------------------------------


def _single(args: argparse.Namespace) -> int:
    base = args.base or "fixed"
    model = _model(args, base)
    q = joint_vector_deg(model, args.q_deg, "--q-deg")
    res = sg.analyse_singularity(
        model, q, base=base, weighting=args.weighting, tol=args.tol, length=args.length
    )
    lost = res.lost_directions()
    out: dict[str, Any] = {
        "robot": model.name,
        "base": base,
        "weighting": args.weighting if base == "virtual" else None,
        "joint_numbers": list(model.joint_numbers),
        "locked": locked_deg(model),
        "q_deg": np.degrees(q),
        "singular_values": res.singular_values,
        "sigma_min": float(res.sigma_min),
        "rank": int(res.rank),
        "full_rank": int(res.singular_values.shape[-1]),
        "singular": bool(res.singular),
        "det_jjt": float(res.det_jjt),
        **_gram(res.singular_values, model.dof),
        "tol": res.tol,
        "lost_directions": lost.T,
        "direction_convention": "unit twists (vx, vy, vz, wx, wy, wz), base frame, sign arbitrary",
    }
    lengths = _lengths_or_none(model, base, args.weighting)
    if lengths is not None:
        out["conditions"] = _conditions_at(model, q, lengths, base, args.weighting, args.tol)
    if args.json:
        print_json(out)
        return 0
    locked = locked_text(out["locked"])
    print(
        f"{model.name}: {model.dof} movable joints {list(model.joint_numbers)}, locked: {locked}, Jacobian: {base}"
    )
    print("q [deg]: " + ", ".join(f"{v:.4f}" for v in out["q_deg"]))
    print("singular values: " + ", ".join(f"{v:.6g}" for v in res.singular_values))
    state = "SINGULAR" if res.singular else "regular"
    print(
        f"sigma_min = {res.sigma_min:.6g}   rank = {res.rank} of {out['full_rank']} (tol {res.tol:g})   "
        f"{out['gram_det_kind']} = {out['gram_det']:.6g}   -> {state}"
    )
    if model.dof < 6:
        print(
            f"  ({model.dof} movable joints < 6: J J^T (6 x 6) has rank <= {model.dof}, so det(J J^T) = 0 "
            f"always; det(J^T J) = product of the squared singular values tests the {model.dof} joints instead)"
        )
    if lost.shape[1]:
        print("lost directions (base frame, columns):")
        print(format_matrix(lost, "{:>9.4f}", [f"u{i + 1}" for i in range(lost.shape[1])]))
    if "conditions" in out:
        c = out["conditions"]
        print(
            f"\n004 conditions ({'virtual' if base == 'virtual' else 'real'} lengths; residual, holds at tol {c['tol']:g}):"
        )
        for name, item in c["residuals"].items():
            mark = "holds" if item["holds"] else "-"
            print(f"  {name:7s} {item['residual']:.3e}  {mark}")
        print("analytic vs numerical singular direction (eq. 24 order wz vx vy vz wx wy):")
        print(f"  numerical  {np.array2string(np.asarray(c['numerical_direction']), precision=4)}")
        for name, item in c["analytic_directions"].items():
            print(
                f"  {name:7s}    {np.array2string(np.asarray(item['direction']), precision=4)}  "
                f"|J'^T u|/|J'| = {item['residual']:.2e}  |u.u_num| = {item['alignment']:.4f}"
            )
    return 0


def _gram(singular_values: np.ndarray, dof: int) -> dict[str, Any]:
    """The Gram determinant that can vanish: ``det(J J^T)`` for 6 or more joints, ``det(J^T J)``
    (= product of the squared singular values) for fewer, where ``det(J J^T)`` is always 0."""
    kind = "det(J J^T)" if dof >= 6 else "det(J^T J)"
    return {"gram_det_kind": kind, "gram_det": float(np.prod(np.square(singular_values)))}


def _conditions_at(
    model: ArmModel, q: np.ndarray, lengths: sg.ArmLengths, base: str, weighting: str, tol: float
) -> dict[str, Any]:
    residuals = sg.condition_residuals(q, lengths, refined=True)
    part = sg.reorder_eq24(sg.reference_jacobian(model, q, base=base, weighting=weighting))  # type: ignore[arg-type]
    u_num = np.linalg.svd(part.matrix)[0][:, 5]
    norm = float(np.linalg.norm(part.matrix))
    held = {k: bool(v < sg.CONDITION_TOL) for k, v in residuals.items()}
    directions = {}
    for name, u in sg.analytic_directions(q, lengths).items():
        if not held[name] and not (name == "cond1" and held["cond1f"]):
            continue
        directions[name] = {
            "direction": u,
            "residual": float(np.linalg.norm(part.matrix.T @ u) / norm),
            "alignment": float(abs(u @ u_num)),
        }
    return {
        "tol": sg.CONDITION_TOL,
        "lengths": vars(lengths),
        "residuals": {k: {"residual": float(v), "holds": held[k]} for k, v in residuals.items()},
        "numerical_direction": u_num,
        "numerical_sigma_min": float(np.linalg.svd(part.matrix, compute_uv=False)[-1]),
        "analytic_directions": directions,
        "frame": "eq. (24) rows (wz, vx, vy, vz, wx, wy), Sigma_ref = link frame 5, point = axes 5 and 6",
    }


# -- verification of Cond1-Cond5 ---------------------------------------------------------------


def _verify(args: argparse.Namespace) -> int:
    base = args.base or "virtual"
    if base == "floating":
        raise ScenarioError("--verify-conditions needs --base virtual (004's case) or fixed; got floating")
    model = _model(args, base)
    samples = args.samples or 2000
    with Progress(len(sg.CONDITIONS) + 2, "verifying", enabled=False if args.quiet else None) as bar:
        ver = sg.verify_conditions(
            model,
            samples=samples,
            rng=args.seed,
            base=base,
            weighting=args.weighting,
            sigma_tol=args.tol,
            search_samples=512,
            progress=bar,
        )

    def item(c: sg.ConditionCheck) -> dict[str, Any]:
        return {
            "samples": c.samples,
            "singular": c.singular,
            "fraction_singular": c.fraction_singular,
            "sufficient": c.sufficient,
            "sigma_min_median": c.sigma_min_median,
            "sigma_min_max": c.sigma_min_max,
            "max_residual": c.max_residual,
            "direction_residual": c.direction_residual,
            "direction_alignment": c.direction_alignment,
        }

    comp = ver.completeness
    out = {
        "robot": model.name,
        "base": base,
        "weighting": args.weighting if base == "virtual" else None,
        "lengths": vars(ver.lengths),
        "seed": ver.seed,
        "sigma_tol": ver.sigma_tol,
        "condition_tol": ver.condition_tol,
        "conditions": {k: item(ver.checks[k]) for k in sg.CONDITIONS},
        "refined_conditions": {k: item(ver.checks[k]) for k in sg.REFINED_CONDITIONS},
        "completeness": {
            "starts": comp.starts,
            "found": comp.found,
            "explained": comp.explained,
            "explained_refined": comp.explained_refined,
            "fraction_explained": comp.fraction_explained,
            "per_condition": comp.per_condition,
            "unexplained_q_deg": np.degrees(comp.unexplained),
        },
    }
    if args.json:
        print_json(out)
        return 0
    print(f"{model.name}: 004's singularity conditions, Jacobian {base}, seed {ver.seed}")
    print("lengths [m]: " + ", ".join(f"{k}={v:.4f}" for k, v in vars(ver.lengths).items()))
    print(
        f"\nsufficiency: samples satisfying each condition exactly, singular if sigma_min < {ver.sigma_tol:g}"
    )
    print(
        f"  {'condition':10s} {'samples':>8s} {'singular':>9s} {'fraction':>9s} {'median sigma_min':>17s}  verdict"
    )
    for name, c in ver.checks.items():
        verdict = "sufficient" if c.sufficient else "NOT sufficient"
        if name == "cond1f":
            verdict += " (ours: S4 = 0 and F = 0)"
        print(
            f"  {name:10s} {c.samples:8d} {c.singular:9d} {c.fraction_singular:9.3f} {c.sigma_min_median:17.3e}  {verdict}"
        )
    bad = [k for k in sg.CONDITIONS if not ver.checks[k].sufficient]
    if bad:
        print(
            f"  -> 004 calls {', '.join(bad)} singularity conditions, but sampled configurations are not singular"
        )
    print(
        f"\ncompleteness: search from {comp.starts} starts found {comp.found} singular configurations; "
        f"{comp.explained} satisfy one of Cond1-Cond5 (residual < {ver.condition_tol:g}), "
        f"{comp.explained_refined} one of cond1f, Cond2-Cond5"
    )
    print("  per condition: " + ", ".join(f"{k}: {v}" for k, v in comp.per_condition.items()))
    return 0


# -- search ---------------------------------------------------------------------------------------


def _search(args: argparse.Namespace) -> int:
    base = args.base or "fixed"
    model = _model(args, base)
    samples = args.samples or 512
    max_iter = 80
    with Progress(max_iter, "searching", enabled=False if args.quiet else None) as bar:
        res = sg.find_singularities(
            model,
            samples=samples,
            rng=args.seed,
            base=base,
            weighting=args.weighting,
            length=args.length,
            progress=bar,
        )
    lengths = _lengths_or_none(model, base, args.weighting)
    families = []
    for fam in res.families:
        entry: dict[str, Any] = {
            "label": fam.label,
            "size": len(fam.members),
            "zero_sine_joints": list(fam.zero_sine_joints),
            "dependent_joints": list(fam.dependent_joints),
            "representative_q_deg": np.degrees(fam.representative),
            "sigma_min": fam.sigma_min,
            "lost_direction_base": fam.lost_direction,
            "lost_direction_ee": fam.lost_direction_ee,
        }
        if lengths is not None:
            held = sg.conditions_hold(res.q[fam.members], lengths, refined=True)
            entry["conditions"] = {k: int(v.sum()) for k, v in held.items()}
        families.append(entry)
    out = {
        "robot": model.name,
        "base": base,
        "joint_numbers": list(model.joint_numbers),
        "locked": locked_deg(model),
        "seed": res.seed,
        "starts": samples,
        "converged": int(res.converged.sum()),
        "iterations": res.iterations,
        "tol": res.tol,
        "families": families,
        "q_deg": np.degrees(res.q),
        "sigma_min": res.sigma_min,
    }
    files = []
    if args.out is not None:
        files = _write_search(args.out, model, res, out)
        out["files"] = [str(f) for f in files]
    if args.json:
        print_json({k: v for k, v in out.items() if k not in ("q_deg", "sigma_min")} | {"found": len(res.q)})
        return 0
    print(
        f"{model.name}: {model.dof} movable joints {list(model.joint_numbers)}, locked: "
        f"{locked_text(locked_deg(model))}, Jacobian {base}"
    )
    print(
        f"{samples} starts (seed {res.seed}): {out['converged']} converged to "
        f"sigma_min < {res.tol:g} in {res.iterations} iterations; {len(families)} families"
    )
    for i, fam in enumerate(families, 1):
        print(f"\n{i:2d}. {fam['label']}  ({fam['size']} configurations)")
        print(
            "    representative q [deg]: "
            + ", ".join(f"q{j}={v:.2f}" for j, v in zip(model.joint_numbers, fam["representative_q_deg"]))
        )
        print(
            "    lost direction (ee frame vx vy vz wx wy wz): "
            + np.array2string(np.asarray(fam["lost_direction_ee"]), precision=3, suppress_small=True)
        )
        if "conditions" in fam:
            print(
                "    004 conditions held: "
                + (", ".join(f"{k}: {v}" for k, v in fam["conditions"].items() if v) or "none")
            )
    for f in files:
        print(f"wrote {f}")
    return 0


def _write_search(
    out_dir: Path, model: ArmModel, res: sg.SingularitySearch, summary: dict[str, Any]
) -> list[Path]:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from ..report import atomic_write_bytes, atomic_write_json, draw_arm, figure_png

    out_dir.mkdir(parents=True, exist_ok=True)
    files = [out_dir / "search.json"]
    atomic_write_json(files[0], summary)

    fig, ax = plt.subplots(figsize=(6, 4))
    start = np.linalg.svd(
        sg.task_jacobian(model, res.q_start, base=res.base, weighting=res.weighting), compute_uv=False
    )
    bins = np.linspace(-17, 1, 55)
    ax.hist(np.log10(np.maximum(start[:, -1], 1e-17)), bins=bins, alpha=0.6, label="start")
    ax.hist(np.log10(np.maximum(res.sigma_final, 1e-17)), bins=bins, alpha=0.6, label="after search")
    ax.axvline(math.log10(res.tol), color="k", ls="--", lw=1, label="tolerance")
    ax.set_xlabel("log10 sigma_min")
    ax.set_ylabel("starts")
    ax.set_title(f"{model.name}: singularity search ({res.base} Jacobian)")
    ax.legend()
    files.append(out_dir / "sigma_min.png")
    atomic_write_bytes(files[-1], figure_png(fig))
    plt.close(fig)

    shown = res.families[:6]
    if shown:
        fig = plt.figure(figsize=(4.5 * min(len(shown), 3), 4.2 * math.ceil(len(shown) / 3)))
        for i, fam in enumerate(shown):
            ax = fig.add_subplot(math.ceil(len(shown) / 3), min(len(shown), 3), i + 1, projection="3d")
            draw_arm(ax, model, fam.representative, label=f"{len(fam.members)} found")
            ax.set_title(fam.label, fontsize=8)
        fig.tight_layout()
        files.append(out_dir / "families.png")
        atomic_write_bytes(files[-1], figure_png(fig))
        plt.close(fig)

        n = model.dof
        fig, axes = plt.subplots(1, n, figsize=(2.0 * n, 2.6), sharey=True)
        for j in range(n):
            for k, fam in enumerate(shown):
                axes[j].hist(
                    np.degrees(res.q[fam.members, j]),
                    bins=36,
                    range=(-180, 180),
                    histtype="step",
                    label=str(k + 1),
                )
            axes[j].set_xlabel(f"q{model.joint_numbers[j]} [deg]")
        axes[0].set_ylabel("configurations")
        axes[-1].legend(title="family", fontsize=6)
        fig.tight_layout()
        files.append(out_dir / "joint_angles.png")
        atomic_write_bytes(files[-1], figure_png(fig))
        plt.close(fig)
    return files
