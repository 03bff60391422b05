"""The sections of a scenario run's ``report.html``: the scenario, the failure, the decisions,
the limits kept or broken, the arm in 3-D, the summary and paper-style figures, the
assumptions and readings.  Built from a :class:`~jointlock.run.RunResult` (its results.json
content and typed job results); summary figures are written to ``out/figures``."""

from __future__ import annotations

import html
import math
from pathlib import Path
from typing import Any

import numpy as np

from ..io.files import save_figure
from ..jobs._common import scenario_locks
from ..jobs.halt._text import MOMENT_TEXT
from ..locking import lock_joints
from ..papers import REFERENCES
from ..plots._common import offscreen_figure
from ..plots.arm import plot_arm
from ..plots.singular import plot_condition_checks
from ..plots.summary import plot_halt_base_torque, plot_jump_before_after, plot_replan_error
from ..report import LIMITS_HEADER, Section, limit_status, limits_rows
from ..robots import UrdfChain, load_robot
from ..scenario import JOB_PAPER, Scenario
from ..scenario._scenario import FAILURE_KEYS
from ._decisions import _condition_verdict, _decisions_section  # noqa: F401  (re-exported)

#: Row labels of the report's limits table (``[limits]`` field -> words and unit).
LIMIT_LABELS = {
    "vmax_deg": "speed limit [deg/s]",
    "amax_deg": "acceleration limit [deg/s^2]",
    "eps_m": "position-deviation threshold [m]",
    "torque_max_Nm": "motor torque limit [N m]",
    "brake_max_Nm": "brake torque limit [N m]",
}


def halt_k_label(r: dict[str, Any]) -> str:
    """Legend of the halt's chosen k, by feasibility: ``k*`` only when it keeps every limit."""
    k_text = f"{float(np.ravel(r['k'])[0]):.3g} deg/s^6"
    if r["feasible"]:
        return f"k* = {k_text} (feasible)"
    return f"least-violating k = {k_text} (INFEASIBLE: breaks a limit)"


def is_000_case(scenario: Scenario, model: Any) -> bool:
    """halt7 with joint 4 locked at 0 deg: 000 §5's scenario, whose headline numbers the halt
    report compares against."""
    lk = scenario.lock
    if scenario.data.get("failure", {}).get("also_locked_deg"):
        return False  # another joint locked too: not 000's failure
    return model.name == "halt7" and lk is not None and lk[0] == 4 and math.isclose(lk[1], 0.0, abs_tol=1e-9)


def _job_images(folder: Path, limit: int = 8) -> list[tuple[str, bytes]]:
    if not folder.is_dir():
        return []
    return [(f"{folder.name}/{p.name}", p.read_bytes()) for p in sorted(folder.glob("*.png"))[:limit]]


def report_sections(
    scenario: Scenario, results: dict[str, Any], typed: dict[str, Any], out: Path
) -> list[Section]:
    """The report's sections: scenario, failure, decisions, limits, 3-D drawing, figures,
    assumptions, from results.json's content (``results``) and the typed job results
    (``typed``).  Summary figures are written to ``out/figures`` as PNG and SVG; each job's own
    figures are read from ``out/<job>`` (written before the report)."""
    jobs = results["jobs"]
    full = load_robot(scenario.data["robot"], base="fixed", chain=UrdfChain.from_fields(scenario.data))
    locks = scenario_locks(scenario.data)
    locked = lock_joints(full, locks) if locks else None
    return [
        *_safety_section(jobs),
        *_scenario_section(scenario, jobs, full, locked, results["versions"]),
        *_failure_section(scenario, jobs, full, locked),
        *_decisions_section(scenario, jobs, full, locked),
        *_limits_section(scenario, jobs, full, locked),
        *_figure_sections(scenario, jobs, full, locked, typed, out),
        *_checks_section(results.get("checks") or {}, out),
        Section("Assumptions and readings", notes=assumptions(scenario, full)),
        _references_section(scenario),
    ]


def _safety_section(jobs: dict[str, Any]) -> list[Section]:
    """First, when a job's answer comes closer than allowed to the spacecraft bus or the arm
    itself (issue 27), or needs more than the attitude control can give (issue 28): the verdict
    each such job gives as its first line."""
    lines = []
    halt = (jobs.get("halt") or {}).get("result") or {}
    verdict = (halt.get("clearance") or {}).get("verdict")
    if verdict:
        lines.append(("halt", verdict))
    wheels = halt.get("attitude_control") or {}
    if wheels.get("within") is False:
        lines.append(("halt", wheels["verdict"]))
    replan = ((jobs.get("replan") or {}).get("result") or {}).get("clearance") or {}
    if replan.get("colliding_waypoints"):
        lines.append(
            ("replan", f"COLLIDES: {replan['colliding_waypoints']} waypoints overlap; deepest {-replan['min_m']:.3f} m "
                       f"into {replan['pair']} at t = {replan['time_s']:g} s")
        )  # fmt: skip
    if not lines:
        return []
    clearance = any(not text.startswith("ATTITUDE CONTROL") for _, text in lines)
    return [
        Section(
            "Clearance: read this first" if clearance else "Attitude control: read this first",
            paragraphs=[f"<b>{html.escape(job)}</b>: {html.escape(text)}" for job, text in lines],
            notes=["Collision geometry, the pairs checked and the mounted pairs: docs/clearance.md."]
            if clearance
            else ["The attitude control's load with the spacecraft held: jointlock.analysis.attitude_control."],
        )
    ]


def _checks_section(checks: dict[str, Any], out: Path) -> list[Section]:
    """"Checked in MuJoCo": per replayed job, the table quantity / jointlock / MuJoCo /
    difference and the figure with both traces (:mod:`jointlock.sim`)."""
    if not checks:
        return []
    tables, images = [], []
    for job, check in checks.items():
        rows = [[r["quantity"], r["unit"], f"{r['jointlock']:.6g}", f"{r['mujoco']:.6g}", f"{r['difference']:+.3g}"]
                for r in check["rows"]]  # fmt: skip
        caption = (
            f"{job}: {check['steps']} steps of {check['timestep_s']:g} s (RK4), the spacecraft {check['spacecraft']}"
        )
        tables.append((["quantity", "unit", "jointlock", check["simulator"], "difference"], rows, caption))
        png = out / "checks" / f"mujoco_{job}.png"
        if png.is_file():
            images.append((f"checks/mujoco_{job}.png", png.read_bytes()))
    return [
        Section(
            f"Checked in {next(iter(checks.values()))['simulator']}",
            paragraphs=[
                "Each motion below was played in MuJoCo: the healthy joints driven by jointlock's inverse-dynamics "
                "torques plus a stiff tracking correction (a control loop's rates, as the jump study's: set at "
                "each control step, the spacecraft taking the momentum-keeping impulse from MuJoCo's own mass "
                "matrix), the locked joints held by joint equalities (their constraint torque is the brake's), "
                "the spacecraft a free body starting with zero momentum, contacts off. The difference is MuJoCo "
                "minus jointlock (for the attitude: the angle between the two final attitudes)."
            ],
            tables=tables,
            images=images,
            notes=["How the replay is set up, and what it checks: docs/simulators.md."],
        )
    ]


def _references_section(scenario: Scenario) -> Section:
    """The seed papers behind the jobs run (docs/references.md)."""
    seeds = sorted({JOB_PAPER[job][:3] for job in scenario.jobs})
    return Section("References", notes=[f"{seed}: {REFERENCES[seed]}" for seed in seeds])


def _scenario_section(scenario: Scenario, jobs: dict[str, Any], full: Any, locked: Any, versions: dict[str, str]) -> list[Section]:
    """The scenario: robot, model, base, seed, jobs, versions and the equivalent commands."""
    d = scenario.data
    sections: list[Section] = []
    facts: list[tuple[str, Any]] = [
        ("robot", f"{full.name}: {full.dof} joints"),
        ("model", full.description),
        ("base", d["base"]),
        ("seed", d["seed"]),
        ("jobs", ", ".join(f"{j} ({JOB_PAPER[j]})" for j in scenario.jobs)),
        ("versions", ", ".join(f"{k} {v}" for k, v in versions.items() if k != "platform")),
    ]
    sections.append(
        Section(
            "Scenario",
            paragraphs=[html.escape(d["description"])] if d.get("description") else [],
            facts=facts,
            code=[jobs[j]["command"] for j in scenario.jobs],
            notes=["The command lines above reproduce each job on its own (same options, same seed)."],
        )
    )
    return sections


def _failure_section(scenario: Scenario, jobs: dict[str, Any], full: Any, locked: Any) -> list[Section]:
    """The failure: which joint, when, the state at failure and the limits given and applied."""
    d = scenario.data
    sections: list[Section] = []
    # the failure
    fail = d["failure"]
    ffacts: list[tuple[str, Any]] = []
    if fail["joint"] is None:
        ffacts.append(("locked joint", "none: no locked joint in this scenario (no [failure] table)"))
    if fail["joint"] is not None:
        ffacts.append(("joint that locks", fail["joint"]))
    if fail["angle_deg"] is not None:
        ffacts.append(("locked angle [deg]", fail["angle_deg"]))
    if fail.get("also_locked_deg"):
        ffacts.append(
            ("locked before it", ", ".join(f"joint {j} at {a:g} deg" for j, a in fail["also_locked_deg"].items()))
        )
    if scenario.failure_overridden():
        changed = {
            k.split(".", 1)[1]: v["file"]
            for k, v in scenario.overrides.items()
            if k in FAILURE_KEYS and v["file"] != v["value"]
        }
        ffacts.append(
            (
                "overridden on the command line",
                "the file gives " + ", ".join(f"{k} = {v}" for k, v in changed.items()),
            )
        )
    if "jump" in jobs:
        r = jobs["jump"]["result"]
        ffacts.append(
            (
                "failure time [s]",
                r["fail_time_s"] if r["mode"] == "fail_at" else "unknown: every control step",
            )
        )
    tables = []
    st = d["state"]
    if locked is not None and st["q0_deg"] is not None:
        n_h = locked.dof

        def healthy(v: list[float] | None) -> list[Any]:
            if v is None:
                return [None] * n_h
            return list(v) if len(v) == n_h else [x for i, x in enumerate(v) if i + 1 in locked.joint_numbers]

        rows = [
            [num, a, b, c]
            for num, a, b, c in zip(
                locked.joint_numbers, healthy(st["q0_deg"]), healthy(st["dq0_deg"]), healthy(st["ddq0_deg"])
            )
        ]
        tables.append((["joint", "q [deg]", "dq [deg/s]", "ddq [deg/s^2]"], rows, "state at failure"))
    lim_rows = [[LIMIT_LABELS.get(k, k), v] for k, v in d["limits"].items() if v is not None]
    if lim_rows:
        tables.append((["limit", "value"], lim_rows, "limits given in the scenario"))
    if "halt" in jobs and "velocity_limit_deg_s" in jobs["halt"]["result"]:
        # what the halt actually applied: the scenario's limits capped by the model's
        r = jobs["halt"]["result"]

        def per_joint(value: Any, j: int) -> Any:
            return value[j] if isinstance(value, (list, tuple)) else value

        rows = [
            [
                num,
                round(r["velocity_limit_deg_s"][j], 6),
                per_joint(r.get("velocity_limit_source", ""), j),
                round(r["acceleration_limit_deg_s2"][j], 6),
                per_joint(r.get("acceleration_limit_source", ""), j),
            ]
            for j, num in enumerate(r["joint_numbers"])
        ]
        tables.append(
            (
                ["joint", "speed limit [deg/s]", "from", "acceleration limit [deg/s^2]", "from"],
                rows,
                "limits applied by the halt",
            )
        )
    sections.append(Section("The failure", facts=ffacts, tables=tables))
    return sections


def _torque_rows(r: dict[str, Any]) -> list[list[Any]]:
    """The halt's motor and brake torque rows of the limits table (a joint without a limit:
    its peak, "none", "no limit")."""
    loads = r.get("actuators")
    if not loads:
        return []
    rows: list[list[Any]] = []
    for key, peaks, limits in (
        ("motor torque", loads["peak_motor_torque_Nm"], r.get("torque_limit_Nm")),
        ("brake torque (locked)", loads["peak_brake_torque_Nm"], r.get("brake_limit_Nm")),
    ):
        for i, (joint, peak) in enumerate(peaks.items()):
            limit = None if limits is None else limits[i]
            if limit is None:
                rows.append([int(joint), f"{key} [N m]", peak, "none", "", "no limit"])
            else:
                rows += limits_rows([int(joint)], [peak], [limit], key, "N m")
    return rows


def _limits_section(scenario: Scenario, jobs: dict[str, Any], full: Any, locked: Any) -> list[Section]:
    """The limits kept or broken by the halt and the jump."""
    sections: list[Section] = []
    # limits kept or broken
    ltables = []
    if "halt" in jobs:
        r = jobs["halt"]["result"]
        nums = r["joint_numbers"]
        rows = limits_rows(nums, r["peak_velocity_deg_s"], r["velocity_limit_deg_s"], "velocity", "deg/s")
        rows += limits_rows(
            nums, r["peak_acceleration_deg_s2"], r["acceleration_limit_deg_s2"], "acceleration", "deg/s^2"
        )
        rows += _torque_rows(r)
        caption = "halt motion at k*" if r["feasible"] else "halt motion at the least-violating k"
        if r["feasible"] and r.get("binding_limit"):
            caption += f"; binding limit: {r['binding_limit']}"
        if r.get("fragile"):
            caption += "; FRAGILE: the feasible stretch of k is under 1 % of k* wide"
        ltables.append((LIMITS_HEADER, rows, caption))
        if r["violations"]:
            ltables.append(
                (
                    ["joint", "limit", "limit value", "worst value", "excess", "at t [s]"],
                    [
                        [
                            v["joint"],
                            v["limit"],
                            v.get("limit_value_deg", v.get("limit_value_Nm")),
                            v.get("value_deg", v.get("value_Nm")),
                            v.get("excess_deg", v.get("excess_Nm")),
                            v["time_s"],
                        ]
                        for v in r["violations"]
                    ],
                    "limits broken (deg, deg/s, deg/s^2; N m for motor and brake torques)",
                )
            )
    if "jump" in jobs:
        r = jobs["jump"]["result"]
        for key in ("verification", "verification_fixed", "limits_after"):
            if key not in r:
                continue
            v = r[key]
            lim = v["limits"] if "limits" in v else v
            sc = r["scenario"]
            label = key if key != "verification_fixed" else f"verification with {v['fix']}"
            ltables.append(
                (
                    ["quantity", "worst value", "limit", "status"],
                    [
                        [quantity, worst, limit, limit_status(worst, limit)]
                        for quantity, worst, limit in (
                            ("joint speed [deg/s]", lim["max_velocity_deg_s"], sc["vmax_deg_s"]),
                            (
                                "joint acceleration [deg/s^2]",
                                lim["max_acceleration_deg_s2"],
                                sc["amax_deg_s2"],
                            ),
                            ("position deviation [mm]", lim["max_deviation_mm"], 1e3 * sc["eps_m"]),
                        )
                    ],
                    f"jump: {label}",
                )
            )
    sections.append(
        Section(
            "Limits kept or broken",
            tables=ltables,
            paragraphs=[] if ltables else ["No job of this scenario checks joint limits."],
        )
    )
    return sections


def _figure_sections(scenario: Scenario, jobs: dict[str, Any], full: Any, locked: Any, typed: dict[str, Any], out: Path) -> list[Section]:
    """The arm in 3-D, the summary figures (PNG and SVG in ``out/figures``) and each job's own figures."""
    d = scenario.data
    sections: list[Section] = []
    figdir = out / "figures"
    # 3-D drawing
    images = []
    configs: dict[str, np.ndarray] = {}
    draw_model = locked
    if "halt" in jobs:
        r = jobs["halt"]["result"]
        configs = {
            "at failure": np.radians(r["q_initial_deg"]),
            "halt configuration": np.radians(r["q_final_deg"]),
        }
    elif "halt_config" in jobs:
        configs = {"halt configuration": np.radians(jobs["halt_config"]["result"]["best"]["q_deg"])}
    elif "replan" in jobs:
        r = jobs["replan"]["result"]
        draw_model = full
        configs = {"start": np.radians(r["q_start_deg"]), "goal (re-planned)": np.radians(r["q_goal_deg"])}
    elif "jump" in jobs:
        draw_model = full
        configs = {"task start": np.radians(jobs["jump"]["result"]["scenario"]["q0_deg"])}
    else:
        draw_model = full
        q = d.get("singular", {}).get("q_deg")
        configs = {
            "q = 0" if q is None else "analysed configuration": np.radians(q) if q else np.zeros(full.dof)
        }
    if draw_model is not None and configs:
        fig = offscreen_figure((6.0, 5.0))
        plot_arm(
            draw_model, configs, title=f"{full.name}: " + " / ".join(configs), ax=fig.add_subplot(projection="3d")
        )
        images.append(
            (
                "arm: " + ", ".join(configs) + " (x = link centres of mass, * = end effector)",
                save_figure(fig, figdir, "arm"),
            )
        )
    # summary figures
    if (
        "jump" in jobs
        and "jump_before" in jobs["jump"]["result"]
        and np.ndim(jobs["jump"]["result"]["jump_before"])
    ):
        r = jobs["jump"]["result"]
        fig = offscreen_figure((7, 3.6))
        plot_jump_before_after(
            r["verification_t_s"], _floats(r["jump_before"]), _floats(r["jump_after"]), ax=fig.add_subplot()
        )
        images.append(("velocity jump vs failure time", save_figure(fig, figdir, "jump_vs_failure_time")))
    if "halt" in jobs:
        ts = typed["halt"].time_series()
        fig = offscreen_figure((7, 3.6))
        plot_halt_base_torque(
            ts["t"], ts["tau_b"], ts["tau_b_k0"], label=halt_k_label(jobs["halt"]["result"]), ax=fig.add_subplot()
        )
        fig.tight_layout()  # else the x label reaches past the edge (a costlier crop)
        images.append(("base disturbance torque during the halt", save_figure(fig, figdir, "base_torque")))
    if "singular" in jobs and isinstance(jobs["singular"]["result"].get("conditions"), dict) and (
        "sigma_tol" in jobs["singular"]["result"]  # the verification's (a study's conditions are others)
    ):
        r = jobs["singular"]["result"]
        fig = offscreen_figure((7, 4))
        plot_condition_checks({**r["conditions"], **r.get("refined_conditions", {})}, r["sigma_tol"], ax=fig.add_subplot())
        images.append(("singular: sigma_min on each of 004's conditions", save_figure(fig, figdir, "singular_conditions")))
    if "replan" in jobs:
        tr = jobs["replan"]["result"].get("trajectory", {})
        if tr:
            fig = offscreen_figure((7, 3.6))
            plot_replan_error(tr["time_s"], tr["position_error_m"], tr["gamma_deg"], ax=fig.add_subplot())
            images.append(("re-plan: tracking error and gamma", save_figure(fig, figdir, "replan_error")))
    sections.append(Section("The arm and summary figures", images=images))
    animations = [
        (caption, figure)
        for job, caption in _ANIMATED.items()
        if job in typed and (figure := typed[job].animation(title=f"{full.name}: {job}")) is not None
    ]
    if animations:
        sections.append(
            Section(
                "The arm in motion (interactive 3-D)",
                paragraphs=[
                    "Drag to orbit, scroll to zoom; Play / Pause and the slider step through time. The "
                    "locked joint is the red diamond from the instant it locks; with a free base the "
                    "spacecraft (box of its mass and inertia) turns and drifts as the arm moves. Every "
                    "motion is also in the job's motion.json."
                ],
                animations=animations,
            )
        )
    # paper-style figures of each job
    for job in scenario.jobs:
        imgs = _job_images(out / job)
        if imgs:
            sections.append(Section(f"Figures: {job} ({JOB_PAPER[job]})", images=imgs, level=3))
    return sections


#: Jobs whose motion the report animates, with the caption.
_ANIMATED = {
    "halt": "halt: from the failure state to rest at the halt configuration",
    "jump": "jump: the task without (kappa = 0) and with compensation, the joint locking at the failure instant",
    "replan": "re-plan: the locked arm along the re-planned path, the target path dashed",
}


def _floats(values: Any) -> np.ndarray:
    """A JSON list of numbers (null = NaN) as a float array."""
    return np.array([np.nan if v is None else v for v in values], dtype=float)


def assumptions(scenario: Scenario, model: Any) -> list[str]:
    """The readings of the seed papers and the assumptions behind this run."""
    d = scenario.data
    notes = [f"{model.name}: {model.description}"]
    if model.name == "halt7":
        notes.append(
            "halt7 (000 Tables 6-7): modified DH; the theta column is the initial configuration, not an "
            "offset (adding it makes 000's own q_best and q_sub singular); 000 gives no spacecraft: ours is "
            "a 2000 kg, 2 m cube 1 m below the mount."
        )
    if model.name == "canadarm7":
        notes.append(
            "canadarm7 (004 §5): frames inferred from 004's eq. (15); inertias are assumed (004 gives none); "
            "it stands in for 001's SSRMS-type arm, whose table was lost."
        )
    if model.name == "puma6":
        notes.append(
            "puma6 (002 Table 1): standard DH despite the header, theta column not added; a2 = 0.985 m, "
            "d4 = -0.765 m, d6 = 0.382 m recovered from 002's worked examples; masses illustrative."
        )
    jobs = scenario.jobs
    if "halt_config" in jobs:
        hc = d["halt_config"]
        notes.append(
            f"Halt configuration: {hc['samples']} Monte Carlo samples, {hc['jacobian']} Jacobian, AHP reading "
            f"'{hc['assignment']}', weights {'renormalised' if hc['renormalize'] else 'summed as eq. (18)'}; "
            f"{'no refinement' if hc['no_refine'] else 'best samples refined by L-BFGS-B'} (docs/halt-config.md)."
        )
    if "halt" in jobs:
        notes.append(
            "Halt motion: 000 eq. (27) with one shared k, k read in deg/s^6 (000's reading); objective = "
            f"time average of the base torque about {MOMENT_TEXT[d['halt']['moment_about']]} (Simpson's rule); "
            "limits checked on a 2001-point grid (docs/halt-motion.md)."
            + (" 000's headline numbers are not reproduced." if is_000_case(scenario, model) else "")
        )
    if "jump" in jobs:
        notes.append(
            "Jump compensation: 001 lost its equations; NOTES-001's reconstruction is implemented "
            "(docs/jump.md): position-only task, w = sqrt(det(J J^T)), feed-forward per step."
        )
    if {"tolerance_angle", "replan", "workspace"} & set(jobs):
        notes.append(
            "002: gamma rotates the target about the tool x axis (T Rx(gamma)); closed-form IK with two "
            "printed equations corrected (docs/replan.md); 002 prints truncated, not rounded, numbers."
        )
    if "singular" in jobs:
        notes.append(
            "004: virtual link lengths by 004's formula (S_i/M) L_i unless weighting = 'vafa-dubowsky'; "
            "Cond1 (S4 = 0) is necessary, not sufficient (docs/readings/canadarm7-004.md)."
        )
    notes.append(f"Seed {d['seed']} drives every stochastic step (Monte Carlo, GA, sampling).")
    return notes
