"""``jointlock run SCENARIO.toml``: every job of a scenario file, one output folder, one report.

Each job is run through its own subcommand (``halt-config``, ``halt``, ``jump``,
``tolerance-angle``, ``replan``, ``workspace``, ``singular``) with the command line formed from
the resolved scenario -- same library calls, same writers, same result dictionaries as
``jointlock COMMAND --json --out DIR`` -- so a scenario and the equivalent commands (recorded in
``results.json`` and the report) always agree.  The output folder holds:

``results.json``
    ``scenario`` (resolved, defaults filled in), ``seed``, ``versions`` (jointlock, Python,
    numpy, scipy, matplotlib), ``jobs`` (each job's result dictionary, its command line and
    files), ``summary`` (the headline figures), ``files``.
``report.html``
    Self-contained report (see :mod:`jointlock.report`).
``figures/``
    Summary plots, PNG and SVG.
``<job>/``
    Each job's own outputs: plots (PNG), time series (CSV, NPZ), its result JSON.

Every file is written atomically; ``results.json`` and ``report.html`` last.
"""

from __future__ import annotations

import argparse
import contextlib
import importlib
import io
import json
import math
import platform
import shlex
from pathlib import Path
from typing import Any

import numpy as np

from .. import __version__
from ..errors import JointlockError, ScenarioError
from ..scenario import JOB_ORDER, JOB_PAPER, Scenario, job_lock_args, jump_fields, load_scenario, parse_set
from ._common import check_out_dir, parse_lock, print_json, seed_arg

#: Subcommand module of each job.
JOB_MODULE = {
    "halt_config": "halt_config",
    "halt": "halt",
    "jump": "jump",
    "tolerance_angle": "tolerance_angle",
    "replan": "replan",
    "workspace": "workspace",
    "singular": "singular",
}
#: Subcommand name of each job.
JOB_COMMAND = {job: job.replace("_", "-") for job in JOB_ORDER}


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "run",
        help="run every job of a scenario file; results.json, CSV, plots and report.html in one folder",
        description=(
            "Validate SCENARIO.toml (format: docs/scenarios.md), run its jobs (halt_config, halt, jump, "
            "tolerance_angle, replan, workspace, singular) and write results.json, time series (CSV), "
            "plots (PNG, SVG) and a self-contained report.html to the output folder. Options given here "
            "override the file."
        ),
    )
    p.add_argument("scenario", metavar="SCENARIO.toml", help="scenario file (TOML)")
    p.add_argument(
        "--out", metavar="DIR", help="output folder (default: the file's out, else <name>-results)"
    )
    p.add_argument("--robot", help="override robot (built-in name or .toml/.urdf model file)")
    p.add_argument("--base", choices=("fixed", "floating"), help="override base")
    p.add_argument("--seed", type=seed_arg, help="override seed (integer >= 0)")
    p.add_argument(
        "--lock", metavar="J=DEG", type=parse_lock, help="override the failure: joint J locked at DEG degrees"
    )
    p.add_argument("--jobs", nargs="+", choices=JOB_ORDER, metavar="JOB", help="run only these jobs")
    p.add_argument(
        "--set",
        action="append",
        default=[],
        metavar="TABLE.FIELD=VALUE",
        help="override any field, value in TOML syntax (e.g. --set halt.T=12 --set workspace.samples=5000)",
    )
    p.add_argument("--json", action="store_true", help="print results.json on stdout")
    p.add_argument("--quiet", action="store_true", help="no progress bars, no summary")
    p.set_defaults(func=run)


def overrides_from_args(args: argparse.Namespace) -> dict[str, Any]:
    """Command-line options as ``{"table.field": value}`` overrides of the file."""
    out: dict[str, Any] = dict(parse_set(s) for s in args.set)
    if args.robot is not None:
        out["robot"] = args.robot
    if args.base is not None:
        out["base"] = args.base
    if args.seed is not None:
        out["seed"] = args.seed
    if args.lock is not None:
        out["failure.joint"] = args.lock[0]
        out["failure.angle_deg"] = math.degrees(args.lock[1])
    if args.jobs:
        out["jobs"] = list(args.jobs)
    if args.out is not None:
        out["out"] = args.out
    return out


def default_out(scenario: Scenario) -> Path:
    if scenario.data.get("out"):
        return Path(scenario.data["out"])
    return Path(f"{Path(scenario.source).stem}-results")


def run(args: argparse.Namespace) -> int:
    scenario = load_scenario(args.scenario, overrides_from_args(args))
    out = default_out(scenario)
    check_out_dir(out, "--out" if args.out is not None else "output folder (out)")
    results = run_scenario(scenario, out, quiet=args.quiet or args.json)
    if args.json:
        print_json(results)
        return 0
    if not args.quiet:
        for line in summary_lines(results):
            print(line)
        print(f"\nwrote {out / 'results.json'}, {out / 'report.html'} and {len(results['files'])} files")
    return 0


# -- running the jobs ----------------------------------------------------------------------------


def _num(v: float) -> str:
    return repr(float(v))


def _nums(values: list[float]) -> list[str]:
    return [_num(v) for v in values]


def versions() -> dict[str, str]:
    """Versions of jointlock, Python and the core dependencies."""
    import matplotlib
    import scipy

    return {
        "jointlock": __version__,
        "python": platform.python_version(),
        "numpy": np.__version__,
        "scipy": scipy.__version__,
        "matplotlib": matplotlib.__version__,
        "platform": platform.platform(),
    }


def call_subcommand(module: str, argv: list[str]) -> tuple[dict, int]:
    """Run ``jointlock <argv>`` in-process through the subcommand ``module`` and return the
    JSON object it prints (``--json`` must be in ``argv``) and its exit code."""
    mod = importlib.import_module(f"jointlock.cli.{module}")
    parser = argparse.ArgumentParser(prog="jointlock")
    mod.register(parser.add_subparsers(dest="command"))
    err = io.StringIO()
    try:
        with contextlib.redirect_stderr(err):
            args = parser.parse_args(argv)
    except SystemExit:
        msg = err.getvalue().strip().splitlines()
        raise ScenarioError(
            f"cannot form the command line `jointlock {shlex.join(argv)}`: {msg[-1] if msg else '?'}"
        ) from None
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        code = int(args.func(args) or 0)
    text = buf.getvalue()
    return (json.loads(text) if text.strip() else {}), code


def _rates(scenario: Scenario, values: list[float]) -> list[float]:
    """A rate or acceleration vector of the state for the command line: the healthy joints'
    entries (a full-arm vector's locked entry is 0, checked when the scenario was loaded)."""
    lk = scenario.lock
    if lk is None:
        return values
    full, _ = _model(scenario)
    if len(values) != full.dof:
        return values
    return [v for i, v in enumerate(values) if i + 1 != lk[0]]


def job_argv(job: str, scenario: Scenario, out: Path, previous: dict[str, dict], *, quiet: bool) -> list[str]:
    """The command line of ``job`` formed from the resolved scenario."""
    d = scenario.data
    t = d[job]
    robot, seed = d["robot"], d["seed"]
    st, lim = d["state"], d["limits"]
    job_out = str(out / job)
    argv = [JOB_COMMAND[job], robot]
    if job == "halt_config":
        argv += job_lock_args(scenario) + ["--base", t["base"] or d["base"]]
        argv += ["--samples", str(t["samples"]), "--seed", str(seed), "--jacobian", t["jacobian"]]
        argv += ["--assignment", t["assignment"]]
        argv += ["--renormalize"] if t["renormalize"] else []
        argv += ["--no-refine"] if t["no_refine"] else []
        argv += ["--length", _num(t["length"])] if t["length"] is not None else []
        if t["reachable"]:
            argv += ["--from-q-deg", *_nums(st["q0_deg"])]
            argv += ["--from-dq-deg", *_nums(_rates(scenario, st["dq0_deg"]))] if st["dq0_deg"] else []
            argv += ["--from-ddq-deg", *_nums(_rates(scenario, st["ddq0_deg"]))] if st["ddq0_deg"] else []
            halt_time = t["halt_time"] if t["halt_time"] is not None else d["halt"]["T"]
            argv += ["--halt-time", _num(halt_time)]
        for key in ("vmax_deg", "amax_deg"):
            if lim[key] is not None:
                argv += [f"--{key.replace('_', '-')}", _num(lim[key])]
        argv += ["--json", "--out", job_out] + (["--quiet"] if quiet else [])
    elif job == "halt":
        argv += job_lock_args(scenario) + ["--base", t["base"] or d["base"]]
        for key in ("q0_deg", "dq0_deg", "ddq0_deg"):
            values = st[key] if key == "q0_deg" else _rates(scenario, st[key])
            argv += [f"--{key.replace('_', '-')}", *_nums(values)]
        argv += ["--T", _num(t["T"])]
        if t["qf_deg"] is not None:
            argv += ["--qf-deg", *_nums(t["qf_deg"])]
        elif t["paper_qf"]:
            argv += ["--paper-qf"]
        elif "halt_config" in previous:
            argv += ["--qf-deg", *_nums(previous["halt_config"]["best"]["q_deg"])]
        for key in ("vmax_deg", "amax_deg"):
            if lim[key] is not None:
                argv += [f"--{key.replace('_', '-')}", _num(lim[key])]
        argv += ["--solver", t["solver"], "--seed", str(seed), "--samples", str(t["samples"])]
        argv += ["--n-samples", str(t["n_samples"]), "--generations", str(t["generations"])]
        argv += ["--population", str(t["population"]), "--json", "--out", job_out]
        argv += ["--quiet"] if quiet else []
    elif job == "jump":
        fields = jump_fields(d)
        task = out / "jump" / "task.toml"
        from ..report import atomic_write_text

        atomic_write_text(task, toml_table({k: v for k, v in fields.items() if k not in ("base",)}))
        argv += ["--base", fields["base"], "--scenario", str(task)]
        if "lock_joint" in fields:
            argv += ["--lock-joint", str(fields["lock_joint"])]
        # only the options the mode uses (the command warns about the others)
        if t["fail_at"] is not None:
            argv += ["--fail-at", _num(t["fail_at"])]
        elif t["kappa"] is None:
            argv += ["--sweep", str(t["sweep"])]
        if t["kappa"] is not None:
            argv += ["--kappa", _num(t["kappa"])]
        elif t["fail_at"] is None:
            argv += ["--order", str(t["order"]), "--fix", t["fix"]]
        argv += ["--json", "--out", job_out]
        argv += ["--quiet"] if quiet else []
    elif job == "tolerance_angle":
        argv += job_lock_args(scenario) + ["--base", d["base"], "--q-target-deg", *_nums(t["q_target_deg"])]
        argv += ["--gamma-limit-deg", _num(t["gamma_limit_deg"]), "--zoom-deg", _num(t["zoom_deg"])]
        argv += ["--step-deg", _num(t["step_deg"]), "--json", "--out", job_out]
    elif job == "replan":
        argv += job_lock_args(scenario) + ["--base", d["base"]]
        argv += ["--from-deg", *_nums(t["from_deg"]), "--to-deg", *_nums(t["to_deg"])]
        argv += ["--steps", str(t["steps"]), "--cycle", _num(t["cycle"])]
        argv += ["--tolerance-deg", _num(t["tolerance_deg"]), "--json", "--out", job_out]
    elif job == "workspace":
        argv += job_lock_args(scenario) + ["--base", d["base"], "--samples", str(t["samples"])]
        argv += ["--voxel", _num(t["voxel"])] if t["voxel"] is not None else []
        argv += ["--seed", str(seed), "--json", "--out", job_out]
    elif job == "singular":
        argv += job_lock_args(scenario)
        argv += ["--base", t["base"]] if t["base"] else []  # inherited from the top level when given
        argv += ["--weighting", t["weighting"], "--tol", _num(t["tol"]), "--seed", str(seed)]
        argv += ["--q-deg", *_nums(t["q_deg"])] if t["q_deg"] is not None else []
        argv += ["--length", _num(t["length"])] if t["length"] is not None else []
        argv += ["--samples", str(t["samples"])] if t["samples"] is not None else []
        if t["verify_conditions"]:
            argv += ["--verify-conditions"]
        elif t["search"]:
            argv += ["--search", "--out", job_out]
        argv += ["--json"] + (["--quiet"] if quiet else [])
    return argv


def toml_table(fields: dict[str, Any]) -> str:
    """A flat TOML table (numbers, strings, booleans, lists of numbers)."""

    def value(v: Any) -> str:
        if isinstance(v, bool):
            return "true" if v else "false"
        if isinstance(v, str):
            return json.dumps(v)
        if isinstance(v, (list, tuple)):
            return "[" + ", ".join(value(x) for x in v) + "]"
        if isinstance(v, int):
            return str(v)
        return repr(float(v))

    return "".join(f"{k} = {value(v)}\n" for k, v in fields.items())


def run_jobs(scenario: Scenario, out: str | Path, *, quiet: bool = False) -> dict[str, Any]:
    """Run every job of ``scenario`` (each writes its files under ``out/<job>``); returns the
    content of results.json without ``files`` (see :func:`write_results`)."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    jobs: dict[str, dict] = {}
    for job in scenario.jobs:
        argv = job_argv(job, scenario, out, {k: v["result"] for k, v in jobs.items()}, quiet=quiet)
        try:
            result, code = call_subcommand(JOB_MODULE[job], argv)
        except JointlockError as exc:
            raise type(exc)(f"{scenario.source}: job [{job}]: {exc}") from exc
        if job == "singular" and "--out" not in argv:
            from ..report import atomic_write_json

            atomic_write_json(out / job / "result.json", result)
        jobs[job] = {
            "paper": JOB_PAPER[job],
            "command": "jointlock " + shlex.join(argv),
            "exit_code": code,
            "result": result,
        }
    return {
        "title": run_title(scenario),
        "scenario_file": scenario.source,
        "overrides": dict(scenario.overrides),
        "scenario": scenario.to_dict(),
        "seed": scenario.data["seed"],
        "versions": versions(),
        "jobs": jobs,
        "summary": summarize(jobs),
    }


def run_title(scenario: Scenario) -> str:
    """The file's title (else its name); when a command-line override changed the failure, the
    file's title no longer describes the run: it is marked, with the failure actually run."""
    title = scenario.data.get("title") or Path(scenario.source).stem
    if not scenario.failure_overridden():
        return title
    lk = scenario.lock
    fail = scenario.data["failure"]
    what = (
        f"joint {lk[0]} locked at {lk[1]:g} deg"
        if lk is not None
        else (f"joint {fail['joint']} locks" if fail["joint"] is not None else "no locked joint")
    )
    return f"{title} [failure overridden: {what}]"


def write_results(
    scenario: Scenario,
    results: dict[str, Any],
    out: str | Path,
    *,
    title: str | None = None,
    extra_sections: list | None = None,
) -> dict[str, Any]:
    """Write the summary figures, ``report.html`` and ``results.json`` (last, atomically);
    returns ``results`` with ``files`` added."""
    from .. import report as rp

    out = Path(out)
    sections = report_sections(scenario, results, out) + list(extra_sections or [])
    files = {str(p.relative_to(out)) for p in out.rglob("*") if p.is_file() and not p.name.startswith(".")}
    results["files"] = sorted(files | {"results.json", "report.html"})
    html = rp.render_html(
        title or f"jointlock run: {results['title']}",
        sections,
        intro=(
            f"Scenario <code>{rp.html.escape(scenario.source)}</code>, jointlock {__version__}, seed "
            f"{scenario.data['seed']}. Jobs: {', '.join(scenario.jobs)}."
        ),
        toc=True,
        footer="Generated by <code>jointlock</code>; every number is also in results.json.",
    )
    rp.atomic_write_text(out / "report.html", html)
    rp.atomic_write_json(out / "results.json", results)
    return results


def run_scenario(scenario: Scenario, out: str | Path, *, quiet: bool = False) -> dict[str, Any]:
    """Run every job of ``scenario`` and write all outputs to ``out``; returns results.json's content."""
    return write_results(scenario, run_jobs(scenario, out, quiet=quiet), out)


# -- summaries -----------------------------------------------------------------------------------


def summarize(jobs: dict[str, dict]) -> dict[str, Any]:
    """Headline figures of each job (plain data)."""
    s: dict[str, Any] = {}
    if "halt_config" in jobs:
        r = jobs["halt_config"]["result"]
        s["halt_config"] = {
            "q_best_deg": r["best"]["q_deg"],
            "cp_best": r["best"]["cp"],
            "cp_best_sample": r["best_sample"]["cp"],
            "refinement_gain": r["refinement"]["gain"],
        }
    if "halt" in jobs:
        r = jobs["halt"]["result"]
        s["halt"] = {
            "feasible": r["feasible"],
            "k_deg_s6": r["k"],
            "global_torque_Nm": r["global_torque_Nm"],
            "global_torque_k0_Nm": r["global_torque_k0_Nm"],
            "reduction": r["reduction"],
            "minimum_T_s": r["minimum_T_s"],
            "violations": len(r["violations"]),
        }
    if "jump" in jobs:
        r = jobs["jump"]["result"]
        s["jump"] = {
            "mode": r["mode"],
            "mean_reduction": r["mean_reduction"],
            "share_improved": r["share_improved"],
            "limits_ok": r["limits_ok"],
        }
        if "verification_fixed" in r:
            v = r["verification_fixed"]
            s["jump"]["fixed"] = {
                "fix": v["fix"],
                "mean_reduction": v["mean_reduction"],
                "share_improved": v["share_improved"],
                "limits_ok": v["limits_ok"],
            }
    if "tolerance_angle" in jobs:
        r = jobs["tolerance_angle"]["result"]
        s["tolerance_angle"] = {
            "absorbable_range_deg": r["absorbable_range_deg"],
            "gamma_deg": None if r["chosen"] is None else r["chosen"]["gamma_deg"],
        }
    if "replan" in jobs:
        r = jobs["replan"]["result"]
        s["replan"] = {
            "absorbed_waypoints": r["absorbed_waypoints"],
            "waypoints": r["waypoints"],
            "max_tracking_position_error_m": r["max_tracking_position_error_m"],
        }
    if "workspace" in jobs:
        r = jobs["workspace"]["result"]
        s["workspace"] = {
            k: r.get(k)
            for k in (
                "volume_full_m3",
                "volume_locked_m3",
                "share_kept",
                "share_kept_half_samples",
                "warnings",
            )
        }
    if "singular" in jobs:
        r = jobs["singular"]["result"]
        if "conditions" in r and isinstance(r["conditions"], dict) and "cond1" in r["conditions"]:
            s["singular"] = {
                k: {"sufficient": c["sufficient"], "fraction_singular": c["fraction_singular"]}
                for k, c in {**r["conditions"], **r.get("refined_conditions", {})}.items()
            }
        elif "families" in r:
            s["singular"] = {"families": len(r["families"]), "converged": r["converged"]}
        else:
            s["singular"] = {
                "sigma_min": r.get("sigma_min"),
                "rank": r.get("rank"),
                "singular": r.get("singular"),
            }
    return s


def _pct(x: Any) -> str:
    return "n/a" if x is None else f"{100 * float(x):.1f} %"


def _pct0(x: Any) -> str:
    """A Monte Carlo share, to the percent (its further digits move with the sample count)."""
    return "n/a" if x is None else f"{100 * float(x):.0f} %"


#: Row labels of the report's limits table (``[limits]`` field -> words and unit).
LIMIT_LABELS = {
    "vmax_deg": "speed limit [deg/s]",
    "amax_deg": "acceleration limit [deg/s^2]",
    "eps_m": "position-deviation threshold [m]",
}


def _condition_verdict(name: str, sufficient: bool) -> str:
    """Verdict of one singularity condition: 004's Cond1-Cond5 are reproduced or not;
    ``cond1f`` is jointlock's own condition, so it is only sufficient or not."""
    if name == "cond1f":
        return "sufficient (ours)" if sufficient else "not sufficient (ours)"
    return "reproduced" if sufficient else "not reproduced: not sufficient"


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
    return model.name == "halt7" and lk is not None and lk[0] == 4 and math.isclose(lk[1], 0.0, abs_tol=1e-9)


def summary_lines(results: dict[str, Any]) -> list[str]:
    """Human-readable summary of a run (a few lines per job)."""
    s = results["summary"]
    lines = [f"{results['title']}  ({results['scenario_file']}, seed {results['seed']})"]
    if "halt_config" in s:
        h = s["halt_config"]
        q = ", ".join(f"{v:.2f}" for v in h["q_best_deg"])
        lines.append(f"  halt configuration: [{q}] deg, CP {h['cp_best']:.4f}")
    if "halt" in s:
        h = s["halt"]
        if h["feasible"]:
            lines.append(
                f"  halt motion: feasible, k* = {np.ravel(h['k_deg_s6'])[0]:.4g} deg/s^6, base torque "
                f"{h['global_torque_k0_Nm']:.4g} -> {h['global_torque_Nm']:.4g} N m ({_pct(h['reduction'])} lower)"
            )
        else:
            t = h["minimum_T_s"]
            lines.append(
                f"  halt motion: INFEASIBLE, {h['violations']} limit(s) broken at the least-violating k; "
                f"smallest feasible halt time {'n/a' if t is None else f'{t:.3f} s'}"
            )
    if "jump" in s:
        j = s["jump"]
        lines.append(
            f"  jump: mean reduction {_pct(j['mean_reduction'])}, improved at {_pct(j['share_improved'])} "
            f"of failure times, limits kept: {j['limits_ok']}"
        )
        if "fixed" in j:
            f = j["fixed"]
            lines.append(
                f"        with {f['fix']}: {_pct(f['mean_reduction'])}, {_pct(f['share_improved'])}, "
                f"limits kept: {f['limits_ok']}"
            )
    if "tolerance_angle" in s:
        t = s["tolerance_angle"]
        rng = "; ".join(f"{k}: {lo:.2f}..{hi:.2f} deg" for k, (lo, hi) in t["absorbable_range_deg"].items())
        g = t["gamma_deg"]
        lines.append(
            f"  tolerance angle: gamma = {'none' if g is None else f'{g:.4f} deg'}; absorbable {rng}"
        )
    if "replan" in s:
        r = s["replan"]
        lines.append(
            f"  replan: lock absorbed at {r['absorbed_waypoints']}/{r['waypoints']} waypoints, max tracking "
            f"error {1e3 * r['max_tracking_position_error_m']:.3f} mm"
        )
    if "workspace" in s:
        w = s["workspace"]
        lines.append(
            f"  workspace: full {w['volume_full_m3']:.3g} m^3"
            + (
                f", locked {w['volume_locked_m3']:.3g} m^3, kept {_pct0(w['share_kept'])} "
                f"(half the samples: {_pct0(w.get('share_kept_half_samples'))})"
                + ("; not converged" if w.get("warnings") else "")
                if w.get("volume_locked_m3") is not None
                else ""
            )
        )
    if "singular" in s:
        g = s["singular"]
        if "cond1" in g:
            lines.append(
                "  singular: "
                + ", ".join(
                    f"{k} {'sufficient' if c['sufficient'] else 'NOT sufficient'}"
                    + (" (ours)" if k == "cond1f" else "")
                    for k, c in g.items()
                )
            )
        else:
            lines.append("  singular: " + ", ".join(f"{k} {v}" for k, v in g.items()))
    return lines


# -- report --------------------------------------------------------------------------------------


def _model(scenario: Scenario, base: str = "fixed"):
    from ..locking import lock
    from ..robots import load_robot

    model = load_robot(scenario.data["robot"], base=base)  # type: ignore[arg-type]
    lk = scenario.lock
    return model, (None if lk is None else lock(model, lk[0], math.radians(lk[1])))


def _job_images(folder: Path, limit: int = 8) -> list[tuple[str, bytes]]:
    if not folder.is_dir():
        return []
    return [(f"{folder.name}/{p.name}", p.read_bytes()) for p in sorted(folder.glob("*.png"))[:limit]]


def report_sections(scenario: Scenario, results: dict[str, Any], out: Path) -> list:
    """The report's sections: scenario, failure, decisions, limits, 3-D drawing, figures,
    assumptions.  Summary figures are written to ``out/figures`` as PNG and SVG."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from ..report import LIMITS_HEADER, Section, arm_figure, limit_status, limits_rows, save_figure
    from .jump import KAPPA_UNIT, _points_text

    d = scenario.data
    jobs = results["jobs"]
    figdir = out / "figures"
    full, locked = _model(scenario)
    sections = []
    facts: list[tuple[str, Any]] = [
        ("robot", f"{full.name}: {full.dof} joints"),
        ("model", full.description),
        ("base", d["base"]),
        ("seed", d["seed"]),
        ("jobs", ", ".join(f"{j} ({JOB_PAPER[j]})" for j in scenario.jobs)),
        ("versions", ", ".join(f"{k} {v}" for k, v in results["versions"].items() if k != "platform")),
    ]
    sections.append(
        Section(
            "Scenario",
            paragraphs=[rp_escape(d["description"])] if d.get("description") else [],
            facts=facts,
            code=[jobs[j]["command"] for j in scenario.jobs],
            notes=["The command lines above reproduce each job on its own (same options, same seed)."],
        )
    )
    # the failure
    fail = d["failure"]
    ffacts: list[tuple[str, Any]] = []
    if fail["joint"] is None:
        ffacts.append(("locked joint", "none: no locked joint in this scenario (no [failure] table)"))
    if fail["joint"] is not None:
        ffacts.append(("joint that locks", fail["joint"]))
    if fail["angle_deg"] is not None:
        ffacts.append(("locked angle [deg]", fail["angle_deg"]))
    if scenario.failure_overridden():
        changed = {
            k.split(".", 1)[1]: v["file"]
            for k, v in scenario.overrides.items()
            if k in ("failure.joint", "failure.angle_deg") and v["file"] != v["value"]
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
            return list(v) if len(v) == n_h else [x for i, x in enumerate(v) if i + 1 != fail["joint"]]

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
    # decisions
    decisions: list[tuple[str, Any]] = []
    dtables = []
    if "halt_config" in jobs:
        r = jobs["halt_config"]["result"]
        decisions.append(("halt configuration [deg]", [round(v, 3) for v in r["best"]["q_deg"]]))
        decisions.append(
            (
                "CP at it (best sample, refinement gain)",
                f"{r['best']['cp']:.5f} ({r['best_sample']['cp']:.5f}, {r['refinement']['gain']:+.5f})",
            )
        )
        w = r["weights"]
        dtables.append(
            (
                ["weights", *w["combined"].keys()],
                [[k, *v.values()] for k, v in w.items()],
                "index weights (AHP + entropy)",
            )
        )
    if "halt" in jobs:
        r = jobs["halt"]["result"]
        source = r.get("qf_source", "")
        if "halt_config" in jobs and d["halt"]["qf_deg"] is None and not d["halt"]["paper_qf"]:
            source = "the optimal halt configuration above (halt_config job)"
        decisions.append(("halt configuration source", source))
        decisions.append(("halt time T [s]", r["T_s"]))
        verdict = "feasible" if r["feasible"] else "INFEASIBLE: no k keeps every limit"
        decisions.append(("verdict", verdict))
        decisions.append(("k* [deg/s^6]" if r["feasible"] else "least-violating k [deg/s^6]", r["k"]))
        decisions.append(
            (
                "global base torque k = 0 -> " + ("k*" if r["feasible"] else "least-violating k") + " [N m]",
                f"{r['global_torque_k0_Nm']:.5g} -> {r['global_torque_Nm']:.5g} ({_pct(r['reduction'])} lower)",
            )
        )
        if r["minimum_T_s"] is not None:
            decisions.append(("smallest feasible halt time [s]", r["minimum_T_s"]))
    if "jump" in jobs:
        r = jobs["jump"]["result"]
        if "kappa_fit" in r:
            f = r["kappa_fit"]
            decisions.append(
                (
                    f"kappa(t) [{KAPPA_UNIT}]",
                    f"polynomial of order {f['order']} in tau = t/T, segment points "
                    f"{_points_text(f['segment_points_s'])}",
                )
            )
            decisions.append(
                (
                    f"kappa(t) coefficients (tau^0 first) [{KAPPA_UNIT}]",
                    [float(f"{c:.4g}") for c in f["coefficients_tau"]],
                )
            )
        elif r["mode"] == "fail_at":
            decisions.append((f"optimal kappa at the failure [{KAPPA_UNIT}]", r["kappa"]))
        elif np.ndim(r["kappa"]) == 0:
            decisions.append((f"constant kappa [{KAPPA_UNIT}]", r["kappa"]))
        decisions.append(
            (
                "mean jump reduction / share improved",
                f"{_pct(r['mean_reduction'])} / {_pct(r['share_improved'])}",
            )
        )
    if "tolerance_angle" in jobs:
        r = jobs["tolerance_angle"]["result"]
        ch = r["chosen"]
        decisions.append(("tolerance angle gamma [deg]", None if ch is None else ch["gamma_deg"]))
        if ch is not None:
            decisions.append(("q at gamma [deg]", [round(v, 4) for v in ch["q_deg"]]))
    if "replan" in jobs:
        r = jobs["replan"]["result"]
        decisions.append(
            (
                "re-plan",
                f"{r['absorbed_waypoints']}/{r['waypoints']} waypoints absorb the lock; gamma {r['gamma_deg_range'][0]:.3f}..{r['gamma_deg_range'][1]:.3f} deg; max tracking error {1e3 * r['max_tracking_position_error_m']:.3f} mm",
            )
        )
    if "workspace" in jobs:
        r = jobs["workspace"]["result"]
        if r.get("volume_locked_m3") is None:
            decisions.append(("workspace volume [m^3]", f"{r['volume_full_m3']:.3g}"))
        else:
            decisions.append(
                (
                    "workspace volume full / locked [m^3]",
                    f"{r['volume_full_m3']:.3g} / {r['volume_locked_m3']:.3g} (kept {_pct0(r.get('share_kept'))}; "
                    f"from half the samples {_pct0(r.get('share_kept_half_samples'))})",
                )
            )
            for w in r.get("warnings", []):
                decisions.append(("workspace: warning", w))
    if "singular" in jobs:
        r = jobs["singular"]["result"]
        if isinstance(r.get("conditions"), dict) and "cond1" in r["conditions"]:
            conds = {**r["conditions"], **r.get("refined_conditions", {})}
            dtables.append(
                (
                    ["condition", "samples", "singular", "fraction", "median sigma_min", "verdict"],
                    [
                        [
                            k,
                            c["samples"],
                            c["singular"],
                            c["fraction_singular"],
                            c["sigma_min_median"],
                            _condition_verdict(k, c["sufficient"]),
                        ]
                        for k, c in conds.items()
                    ],
                    "004's conditions: is every sampled configuration singular? (cond1f = S4 = 0 and F = 0, ours)",
                )
            )
        elif "families" in r:
            decisions.append(("singular families found", len(r["families"])))
        else:
            decisions.append(("sigma_min / rank", f"{r['sigma_min']:.4g} / {r['rank']}"))
    sections.append(Section("Decisions", facts=decisions, tables=dtables))
    # limits kept or broken
    ltables = []
    if "halt" in jobs:
        r = jobs["halt"]["result"]
        nums = r["joint_numbers"]
        rows = limits_rows(nums, r["peak_velocity_deg_s"], r["velocity_limit_deg_s"], "velocity", "deg/s")
        rows += limits_rows(
            nums, r["peak_acceleration_deg_s2"], r["acceleration_limit_deg_s2"], "acceleration", "deg/s^2"
        )
        ltables.append(
            (
                LIMITS_HEADER,
                rows,
                "halt motion at k*" if r["feasible"] else "halt motion at the least-violating k",
            )
        )
        if r["violations"]:
            ltables.append(
                (
                    ["joint", "limit", "limit value", "worst value", "excess", "at t [s]"],
                    [
                        [
                            v["joint"],
                            v["limit"],
                            v["limit_value_deg"],
                            v["value_deg"],
                            v["excess_deg"],
                            v["time_s"],
                        ]
                        for v in r["violations"]
                    ],
                    "limits broken (deg, deg/s, deg/s^2)",
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
        fig = arm_figure(draw_model, configs, title=f"{full.name}: " + " / ".join(configs))
        images.append(
            (
                "arm at " + ", ".join(configs) + " (x = link centres of mass, * = end effector)",
                save_figure(fig, figdir, "arm"),
            )
        )
        plt.close(fig)
    # summary figures
    if (
        "jump" in jobs
        and "jump_before" in jobs["jump"]["result"]
        and np.ndim(jobs["jump"]["result"]["jump_before"])
    ):
        r = jobs["jump"]["result"]
        fig, ax = plt.subplots(figsize=(7, 3.6))
        ax.plot(r["verification_t_s"], np.degrees(_floats(r["jump_before"])), label="kappa = 0")
        ax.plot(r["verification_t_s"], np.degrees(_floats(r["jump_after"])), label="kappa(t)")
        ax.set_xlabel("failure time [s]")
        ax.set_ylabel("||joint-rate jump|| [deg/s]")
        ax.legend()
        images.append(("velocity jump vs failure time", save_figure(fig, figdir, "jump_vs_failure_time")))
        plt.close(fig)
    if "halt" in jobs:
        r = jobs["halt"]["result"]
        npz = out / "halt" / "halt_motion.npz"
        if npz.is_file():
            with np.load(npz) as z:
                t, tb, tb0 = z["t"], z["tau_b"], z["tau_b_k0"]
            fig, ax = plt.subplots(figsize=(7, 3.6))
            ax.plot(t, np.linalg.norm(tb0, axis=-1), label="k = 0")
            ax.plot(t, np.linalg.norm(tb, axis=-1), label=halt_k_label(r))
            ax.set_xlabel("t [s]")
            ax.set_ylabel("||base torque|| [N m]")
            ax.legend()
            images.append(
                ("base disturbance torque during the halt", save_figure(fig, figdir, "base_torque"))
            )
            plt.close(fig)
    if "replan" in jobs:
        tr = jobs["replan"]["result"].get("trajectory", {})
        if tr:
            fig, ax = plt.subplots(figsize=(7, 3.6))
            ax.plot(
                tr["time_s"], 1e3 * np.asarray(tr["position_error_m"], dtype=float), label="position [mm]"
            )
            ax.plot(tr["time_s"], tr["gamma_deg"], label="gamma [deg]")
            ax.set_xlabel("t [s]")
            ax.legend()
            images.append(("re-plan: tracking error and gamma", save_figure(fig, figdir, "replan_error")))
            plt.close(fig)
    sections.append(Section("The arm and summary figures", images=images))
    # paper-style figures of each job
    for job in scenario.jobs:
        imgs = _job_images(out / job)
        if imgs:
            sections.append(Section(f"Figures: {job} ({JOB_PAPER[job]})", images=imgs, level=3))
    sections.append(Section("Assumptions and readings", notes=assumptions(scenario, full)))
    return sections


def _floats(values: Any) -> np.ndarray:
    """A JSON list of numbers (null = NaN) as a float array."""
    return np.array([np.nan if v is None else v for v in values], dtype=float)


def rp_escape(text: str) -> str:
    import html

    return html.escape(text)


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
            "time average of the base torque about the spacecraft's centre of mass (Simpson's rule); limits "
            "checked on a 2001-point grid (docs/halt-motion.md)."
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
