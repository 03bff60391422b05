"""``jointlock run SCENARIO.toml``: every job of a scenario file, one output folder, one report.

A thin shell over :func:`jointlock.load_scenario` and :func:`jointlock.run_scenario`: the
options become overrides of the file, the jobs run in-process, and
:meth:`jointlock.run.RunResult.write` writes ``results.json``, each job's files, the figures and
``report.html`` (format: docs/scenarios.md).
"""

from __future__ import annotations

import argparse
import math
import sys
from typing import Any

from ..errors import ScenarioError
from ._common import check_out_dir, parse_lock, print_json, seed_arg
from ._constants import JOB_ORDER


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
        "--lock",
        metavar="J=DEG",
        type=parse_lock,
        action="append",
        help="override the failure: joint J locked at DEG degrees; repeat it to lock several (the last is "
        "the failure, the others [failure] also_locked_deg, locked before it)",
    )
    p.add_argument("--jobs", nargs="+", choices=JOB_ORDER, metavar="JOB", help="run only these jobs")
    p.add_argument(
        "--set",
        action="append",
        default=[],
        metavar="TABLE.FIELD=VALUE",
        help="override any field, value in TOML syntax (e.g. --set halt.T=12 --set workspace.samples=5000)",
    )
    p.add_argument(
        "--check-in",
        choices=("none", "mujoco"),
        help="replay the halt, the jump runs and the re-plan in this simulator and compare (overrides check_in; "
        "mujoco: the optional extra jointlock[mujoco])",
    )
    p.add_argument("--json", action="store_true", help="print results.json on stdout")
    p.add_argument("--quiet", action="store_true", help="no progress bars, no summary")
    p.set_defaults(func=run)


def overrides_from_args(args: argparse.Namespace) -> dict[str, Any]:
    """Command-line options as ``{"table.field": value}`` overrides of the file."""
    from ..scenario import parse_set

    out: dict[str, Any] = dict(parse_set(s) for s in args.set)
    if args.robot is not None:
        out["robot"] = args.robot
    if args.base is not None:
        out["base"] = args.base
    if args.seed is not None:
        out["seed"] = args.seed
    if args.lock is not None:
        numbers = [j for j, _ in args.lock]
        if len(set(numbers)) != len(numbers):
            raise ScenarioError(f"--lock: each joint once; got joints {numbers}")
        *earlier, (joint, angle) = args.lock  # the last --lock is the failure, the others locked before it
        out["failure.joint"] = joint
        out["failure.angle_deg"] = math.degrees(angle)
        out["failure.also_locked_deg"] = {str(j): math.degrees(a) for j, a in earlier} or None
    if args.jobs:
        out["jobs"] = list(args.jobs)
    if args.out is not None:
        out["out"] = args.out
    if args.check_in is not None:
        out["check_in"] = args.check_in
    return out


def run(args: argparse.Namespace) -> int:
    from ..run import default_out_dir, run_scenario
    from ..run._summary import summary_lines
    from ..scenario import load_scenario

    scenario = load_scenario(args.scenario, overrides_from_args(args))
    out = default_out_dir(scenario)
    check_out_dir(out, "--out" if args.out is not None else "output folder (out)")
    quiet = args.quiet or args.json
    result = run_scenario(scenario, progress=not quiet and sys.stderr.isatty())
    results = result.write(out)
    if args.json:
        print_json(results)
        return 0
    if not args.quiet:
        for line in summary_lines(results):
            print(line)
        print(f"\nwrote {out / 'results.json'}, {out / 'report.html'} and {len(results['files'])} files")
    return 0
