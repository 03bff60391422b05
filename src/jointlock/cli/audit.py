"""``jointlock audit SCENARIO.toml``: every chosen joint locking at every chosen instant of the
scenario's planned motion (``[task]``), on the campaign engine (a thin shell over
:func:`jointlock.campaign.run_audit`)."""

from __future__ import annotations

import argparse
import math
import shlex
import sys
from pathlib import Path

from ._common import check_out_dir, int_at_least, print_json


def _positive(text: str) -> float:
    """A step in seconds: a finite number > 0."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be a number of seconds > 0; got {text[:40]!r}") from None
    if not (math.isfinite(value) and value > 0):
        raise argparse.ArgumentTypeError(f"must be a number of seconds > 0; got {text[:40]!r}")
    return value


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "audit",
        help="audit a planned motion: every joint locking at every instant of the scenario's [task]",
        description=(
            "For every chosen joint and every chosen instant of the scenario's planned motion ([task]), lock "
            "that joint there and run the scenario's jobs from the task's state at that instant (the halt: "
            "feasible within the limits? clear of the spacecraft? within the attitude control's capacity? "
            "smallest feasible halt time). Each cell is exactly 'jointlock run SCENARIO --set failure.joint=J "
            "--set failure.time_s=T --seed <the cell's case seed>'. The folder is a campaign folder: 'jointlock "
            "campaign status/export/report DIR' work on it, and the same command resumes after Ctrl-C. Writes "
            "report.html (heatmaps joint x time, the worst cells as scenario files) and audit.json (the safe "
            "windows: the stretches where every lock leaves a safe halt)."
        ),
    )
    p.add_argument("scenario", metavar="SCENARIO.toml", help="a scenario with [task] and a [halt] job")
    p.add_argument("--joints", type=int_at_least(1), nargs="+", metavar="J", help="joints to lock (default: every joint)")
    when = p.add_mutually_exclusive_group()
    when.add_argument(
        "--times", type=int_at_least(1), metavar="N", help="instants evenly spaced over the task, both ends (default 11)"
    )
    when.add_argument("--dt", type=_positive, metavar="S", help="an instant every S seconds from 0")
    p.add_argument("--out", metavar="DIR", help="output folder (default <scenario name>-audit)")
    engine = p.add_mutually_exclusive_group()
    engine.add_argument("--workers", type=int_at_least(1), help="local worker processes (default: one per core)")
    engine.add_argument("--in-process", action="store_true", help="run every cell in this process (no pool)")
    engine.add_argument("--dask", metavar="local|tcp://HOST:PORT", help="run on a Dask cluster")
    engine.add_argument("--dask-scheduler-file", metavar="FILE", help="run on the Dask cluster of this scheduler file")
    p.add_argument("--dask-workers", type=int_at_least(1), help="workers of --dask local (default: cores)")
    p.add_argument("--json", action="store_true", help="print one JSON object (no progress bar)")
    p.add_argument("--quiet", action="store_true", help="no progress bar, no summary")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from ..campaign import run_audit
    from .campaign import _engine

    out = check_out_dir(args.out) if args.out else Path(f"{Path(args.scenario).stem}-audit")
    quiet = args.quiet or args.json
    start = _engine(args, quiet)
    result = run_audit(
        args.scenario,
        out,
        joints=args.joints,
        times=args.times,
        dt=args.dt,
        engine=start,
        workers=args.workers,
        progress=not quiet and sys.stderr.isatty(),
    )
    if args.json:
        print_json(result.to_dict())
    elif not args.quiet:
        print("\n".join(result.summary()))
    if result.run.interrupted:
        argv = ["jointlock", "audit", *sys.argv[2:]] if len(sys.argv) > 2 else ["jointlock", "audit", args.scenario]
        print(
            f"jointlock audit: stopped by {result.run.stopped_by}; run the same command again to resume: {shlex.join(argv)}",
            file=sys.stderr,
        )
        return 130 if result.run.stopped_by == "SIGINT" else 143
    return 0
