"""``jointlock demo``: the main job on the built-in arms, report written to a folder.

Until the halt pipeline lands this is a kinematic report of the built-in arms: forward
kinematics, Jacobian conditioning fixed vs free-floating, the lock-equivalence check for
every joint, the virtual manipulator, and a 3-D drawing of each arm.
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np

from .. import __version__
from ..dynamics import mass_matrix
from ..kinematics import generalized_jacobian, jacobian, link_poses, virtual_link_vectors
from ..locking import lock
from ..report import (
    Section,
    arm_points,
    atomic_write_bytes,
    atomic_write_json,
    atomic_write_text,
    draw_arm,
    figure_png,
    render_html,
    set_equal_3d,
)
from ..robots import BUILTIN_ROBOTS, load_robot

#: Reference configurations [deg]: 000 §5 start (joint 4 at its lock angle 0), NOTES-001's
#: start, 002's terminal example.
REFERENCE_Q_DEG = {
    "halt7": [-180.0, -180.0, -100.0, 0.0, -10.0, 20.0, 20.0],
    "canadarm7": [10.0, 40.0, -70.0, 100.0, -60.0, 30.0, 20.0],
    "puma6": [5.0, 60.0, 65.0, 10.0, -120.0, 90.0],
}


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("demo", help="run the main job on the built-in arms and write a report")
    p.add_argument("--out", default="jointlock-demo", help="output folder (default: jointlock-demo)")
    p.add_argument("--quiet", action="store_true", help="print nothing but errors")
    p.set_defaults(func=run)


def lock_equivalence(name: str, q_deg: list[float]) -> list[dict]:
    """For every joint: lock it at its reference angle, compare with the full model frozen."""
    full = load_robot(name)
    q = np.radians(q_deg)
    rows = []
    t_full = link_poses(full, q)
    j_full = jacobian(full, q)
    m_full = mass_matrix(full, q)
    for number in full.joint_numbers:
        i = number - 1
        locked = lock(full, number, q[i])
        qh = np.delete(q, i)
        keep = [k for k in range(full.dof) if k != i]
        rows.append(
            {
                "joint": number,
                "pose_error_m": float(np.abs(link_poses(locked, qh) - t_full[keep]).max()),
                "jacobian_error": float(np.abs(jacobian(locked, qh) - j_full[:, keep]).max()),
                "mass_matrix_error": float(
                    np.abs(mass_matrix(locked, qh) - m_full[np.ix_(keep, keep)]).max()
                ),
            }
        )
    return rows


def run(args: argparse.Namespace) -> int:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out = Path(args.out)
    results: dict = {"jointlock_version": __version__, "robots": {}}
    sections = []
    for name in BUILTIN_ROBOTS:
        fixed = load_robot(name)
        floating = load_robot(name, base="floating")
        q = np.radians(REFERENCE_Q_DEG[name])
        sv_fixed = np.linalg.svd(jacobian(fixed, q), compute_uv=False)
        sv_float = np.linalg.svd(generalized_jacobian(floating, q), compute_uv=False)
        equivalence = lock_equivalence(name, REFERENCE_Q_DEG[name])
        vm = np.linalg.norm(virtual_link_vectors(floating), axis=1)
        pts, _ = arm_points(fixed, q)
        results["robots"][name] = {
            "q_deg": REFERENCE_Q_DEG[name],
            "ee_position_m": pts[-1],
            "singular_values_fixed": sv_fixed,
            "singular_values_floating": sv_float,
            "lock_equivalence": equivalence,
            "virtual_link_lengths_m": vm,
            "description": fixed.description,
        }
        fig = plt.figure(figsize=(5.5, 4.5))
        ax = fig.add_subplot(projection="3d")
        draw_arm(ax, fixed, q, label=f"{name} at the reference configuration")
        draw_arm(ax, fixed, np.zeros(fixed.dof), label="q = 0", color="0.6")
        set_equal_3d(ax, np.vstack([pts, arm_points(fixed, np.zeros(fixed.dof))[0]]))
        ax.legend(loc="upper left", fontsize=8)
        png = figure_png(fig)
        plt.close(fig)
        atomic_write_bytes(out / f"{name}_arm.png", png)
        worst = max(max(r["pose_error_m"], r["jacobian_error"], r["mass_matrix_error"]) for r in equivalence)
        sections.append(
            Section(
                title=f"{name}: {fixed.dof} joints",
                paragraphs=[
                    fixed.description,
                    f"Reference configuration [deg]: {REFERENCE_Q_DEG[name]}. End effector at "
                    f"{np.round(pts[-1], 4).tolist()} m.",
                    f"Lock equivalence (each joint locked at its reference angle vs the full model "
                    f"with that joint frozen): worst difference {worst:.2e} "
                    f"({'<span class=ok>equal</span>' if worst < 1e-9 else '<span class=bad>DIFFERENT</span>'}).",
                ],
                tables=[
                    (
                        ["Jacobian", "sigma_min", "sigma_max", "condition number", "manipulability"],
                        [
                            [
                                "fixed base",
                                sv_fixed[-1],
                                sv_fixed[0],
                                sv_fixed[0] / sv_fixed[-1],
                                float(np.prod(sv_fixed)),
                            ],
                            [
                                "free-floating (generalized)",
                                sv_float[-1],
                                sv_float[0],
                                sv_float[0] / sv_float[-1],
                                float(np.prod(sv_float)),
                            ],
                        ],
                    ),
                    (
                        ["locked joint", "pose error [m]", "Jacobian error", "mass-matrix error"],
                        [
                            [r["joint"], r["pose_error_m"], r["jacobian_error"], r["mass_matrix_error"]]
                            for r in equivalence
                        ],
                    ),
                    (
                        ["virtual link"] + [str(k) for k in range(len(vm))],
                        [["length [m]"] + [float(v) for v in vm]],
                    ),
                ],
                images=[
                    (
                        f"{name}: reference configuration (colour) and q = 0 (grey); x = link centres of mass",
                        png,
                    )
                ],
            )
        )
    atomic_write_json(out / "results.json", results)
    atomic_write_text(
        out / "report.html",
        render_html("jointlock demo: the built-in arms", sections, intro=f"jointlock {__version__}."),
    )
    if not args.quiet:
        print(f"wrote {out / 'report.html'} and {out / 'results.json'}", file=sys.stderr)
        for name, r in results["robots"].items():
            print(
                f"{name:<10} ee {np.round(r['ee_position_m'], 3).tolist()} m, "
                f"sigma_min fixed {r['singular_values_fixed'][-1]:.4g}, floating {r['singular_values_floating'][-1]:.4g}"
            )
    return 0 if math.isfinite(0.0) else 1
