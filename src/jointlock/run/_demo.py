"""The main job on the built-in default: 000 §5 on halt7 plus an overview of the built-in arms.

:func:`run_demo` runs :data:`DEMO_SCENARIO` (the content of ``examples/halt_000.toml``: the
optimal halt configuration, then the optimal halt motion from 000's state at failure, with the
feasibility verdict) and a kinematic overview of every built-in arm: forward kinematics,
Jacobian conditioning fixed vs free-floating, the lock-equivalence check for every joint, the
virtual manipulator and a 3-D drawing.  :meth:`DemoResult.write` writes one ``report.html`` and
one ``results.json`` (``robots``: the overview; ``jobs``, ``summary``, ``scenario``: the main job).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..dynamics import mass_matrix
from ..io.files import atomic_write_bytes, figure_png
from ..kinematics import generalized_jacobian, jacobian, link_poses, virtual_link_vectors
from ..locking import lock
from ..papers import p000, p001
from ..plots._common import offscreen_figure
from ..plots.arm import arm_points, draw_arm, set_equal_3d
from ..report import Section
from ..robots import BUILTIN_ROBOTS, load_robot
from ..scenario import scenario_from_dict
from ._run import RunResult, run_scenario

#: The built-in default scenario: 000 §5 on halt7 (the content of examples/halt_000.toml).
DEMO_SCENARIO: dict[str, Any] = {
    "title": "000 §5: halt7 halts after joint 4 locks at 0 deg",
    "robot": "halt7",
    "base": "floating",
    "seed": 0,
    "failure": {"joint": 4, "angle_deg": 0.0},
    "state": {k: list(p000.SCENARIO[k]) for k in ("q0_deg", "dq0_deg", "ddq0_deg")},
    "limits": {"vmax_deg_s": p000.SCENARIO["vmax_deg"], "amax_deg_s2": p000.SCENARIO["amax_deg"]},
    "halt_config": {"samples": p000.SAMPLES, "jacobian": "generalized"},
    "halt": {"T": p000.SCENARIO["T"], "base": "fixed", "solver": "scan"},
}

def _with_locked(q_deg: Sequence[float], lock: Mapping[int, float]) -> list[float]:
    """All joints' angles [deg]: the healthy joints' ``q_deg`` with each locked joint's angle
    (``lock``: {joint number: angle [deg]}) inserted at its place."""
    q = list(q_deg)
    for joint, angle in sorted(lock.items()):
        q.insert(joint - 1, angle)
    return q


#: Reference configurations [deg]: 000 §5 start (joint 4 at its lock angle 0), NOTES-001's
#: start, 002's terminal example.
REFERENCE_Q_DEG = {
    "halt7": _with_locked(p000.SCENARIO["q0_deg"], p000.SCENARIO["lock"]),
    "canadarm7": list(p001.TASK["q0_deg"]),
    "puma6": [5.0, 60.0, 65.0, 10.0, -120.0, 90.0],
}

#: Title of the demo's report.
DEMO_TITLE = "jointlock demo: 000's halt on halt7, and the built-in arms"


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


def arm_overview(name: str) -> tuple[dict[str, Any], Section]:
    """The overview of one built-in arm at its reference configuration: the figures
    (results.json's ``robots[name]``) and its report section (with the 3-D drawing)."""
    fixed = load_robot(name)
    floating = load_robot(name, base="floating")
    q = np.radians(REFERENCE_Q_DEG[name])
    sv_fixed = np.linalg.svd(jacobian(fixed, q), compute_uv=False)
    sv_float = np.linalg.svd(generalized_jacobian(floating, q), compute_uv=False)
    equivalence = lock_equivalence(name, REFERENCE_Q_DEG[name])
    vm = np.linalg.norm(virtual_link_vectors(floating), axis=1)
    pts, _ = arm_points(fixed, q)
    figures = {
        "q_deg": REFERENCE_Q_DEG[name],
        "ee_position_m": pts[-1],
        "singular_values_fixed": sv_fixed,
        "singular_values_floating": sv_float,
        "lock_equivalence": equivalence,
        "virtual_link_lengths_m": vm,
        "description": fixed.description,
    }
    fig = offscreen_figure((5.5, 4.5))
    ax = fig.add_subplot(projection="3d")
    draw_arm(ax, fixed, q, label=f"{name} at the reference configuration")
    draw_arm(ax, fixed, np.zeros(fixed.dof), label="q = 0", color="0.6")
    set_equal_3d(ax, np.vstack([pts, arm_points(fixed, np.zeros(fixed.dof))[0]]))
    ax.legend(loc="upper left", fontsize=8)
    png = figure_png(fig)
    worst = max(max(r["pose_error_m"], r["jacobian_error"], r["mass_matrix_error"]) for r in equivalence)
    section = Section(
        level=3,
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
    return figures, section


@dataclass(frozen=True, eq=False)  # arrays inside: compare to_dict() instead
class DemoResult:
    """The demo's results: the main job's :class:`RunResult`, the arm overviews and their
    report sections and drawings (picklable)."""

    run: RunResult
    robots: dict[str, dict[str, Any]]
    sections: tuple[Section, ...]
    drawings: dict[str, bytes]

    def summary(self) -> list[str]:
        """The lines ``jointlock demo`` prints."""
        lines = self.run.summary()
        for name, r in self.robots.items():
            lines.append(
                f"{name:<10} ee {np.round(r['ee_position_m'], 3).tolist()} m, sigma_min fixed "
                f"{r['singular_values_fixed'][-1]:.4g}, floating {r['singular_values_floating'][-1]:.4g}"
            )
        return lines

    def write(self, out: str | Path) -> dict[str, Any]:
        """The main job's files, each arm's drawing, report.html and results.json; returns
        results.json's content."""
        from .._version import __version__

        out = Path(out)
        for name, png in self.drawings.items():
            atomic_write_bytes(out / f"{name}_arm.png", png)
        intro = Section(
            "The built-in arms",
            paragraphs=[
                "A kinematic overview of every built-in arm at a reference configuration: conditioning of "
                "the fixed-base and generalized Jacobians, the lock-equivalence check (each joint locked "
                "vs the full model frozen), the virtual manipulator."
            ],
        )
        return self.run.write(
            out,
            title=DEMO_TITLE,
            extra={"jointlock_version": __version__, "robots": self.robots},
            extra_sections=[intro, *self.sections],
        )


def run_demo(*, progress: bool = False) -> DemoResult:
    """Run the demo: :data:`DEMO_SCENARIO` and the overview of every built-in arm."""
    scenario = scenario_from_dict(DEMO_SCENARIO, source="built-in demo scenario (000 §5, halt7)")
    run = run_scenario(scenario, progress=progress)
    robots, sections, drawings = {}, [], {}
    for name in BUILTIN_ROBOTS:
        robots[name], section = arm_overview(name)
        sections.append(section)
        drawings[name] = section.images[0][1]
    return DemoResult(run, robots, tuple(sections), drawings)
