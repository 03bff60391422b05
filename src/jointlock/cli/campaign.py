"""``jointlock campaign plan|run|status|export|report``: failure campaigns (docs/campaigns.md).

A thin shell over :mod:`jointlock.campaign` (imported when a subcommand runs, so that the
command line starts fast): parse, call, print, write.
"""

from __future__ import annotations

import argparse
import importlib.util
import shlex
import sys
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

from ..errors import CampaignError
from ._common import check_out_dir, int_at_least, print_json

if TYPE_CHECKING:
    from ..campaign import CampaignSpec, Engine

DESCRIPTION = (
    "Sweep failure cases: a campaign file (TOML) names a base scenario and what to vary with the names "
    "of `jointlock run --set` ([grid], [zip], [sample]); each case is keyed by its resolved inputs and "
    "its result goes to one SQLite ledger (DIR/ledger.sqlite), so running again resumes exactly what is "
    "left. Format: docs/campaigns.md."
)


def _seconds(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be a number of seconds > 0; got {text!r}") from None
    if not 0 < value < 86400:
        raise argparse.ArgumentTypeError(f"must be a number of seconds in (0, 86400); got {text!r}")
    return value


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "campaign", help="sweep thousands of failure cases (process pool or Dask), resumable", description=DESCRIPTION
    )
    cmds = p.add_subparsers(dest="campaign_command", metavar="SUBCOMMAND")
    cmds.required = True

    plan = cmds.add_parser("plan", help="count the cases, those done, and estimate the time", description=(
        "Validate CAMPAIGN.toml, count its cases and those already finished in the output folder, and "
        "time a few cases (in this process) to estimate the run. Nothing is written."))  # fmt: skip
    plan.add_argument("campaign", metavar="CAMPAIGN.toml")
    plan.add_argument(
        "--out", metavar="DIR", help="output folder (default: the file's out, else <name>-campaign beside the file)"
    )
    plan.add_argument("--workers", type=int_at_least(1), help="workers the estimate assumes (default: cores)")
    plan.add_argument("--probe", type=int_at_least(0), default=3, help="cases to time for the estimate (0: none; default 3)")
    plan.add_argument("--json", action="store_true", help="print one JSON object")
    plan.set_defaults(func=_plan)

    run = cmds.add_parser("run", help="run the cases not yet in the ledger", description=(
        "Run every case of CAMPAIGN.toml not yet finished in DIR: a local process pool by default "
        "(one worker per core), or a Dask cluster. Ctrl-C (SIGINT) or SIGTERM stops it with everything "
        "finished committed; the same command resumes. A case that raises is recorded with its error."))  # fmt: skip
    run.add_argument("campaign", metavar="CAMPAIGN.toml")
    run.add_argument(
        "--out", metavar="DIR", help="output folder (default: the file's out, else <name>-campaign beside the file)"
    )
    engine = run.add_mutually_exclusive_group()
    engine.add_argument("--workers", type=int_at_least(1), help="local worker processes (default: one per core)")
    engine.add_argument("--in-process", action="store_true", help="run every case in this process (no pool)")
    engine.add_argument(
        "--dask", metavar="ADDRESS",
        help="run on Dask: 'local' (a LocalCluster of --dask-workers processes) or a scheduler's address "
        "tcp://HOST:8786 (needs the 'dask' extra)",
    )  # fmt: skip
    engine.add_argument("--dask-scheduler-file", metavar="FILE", help="run on the Dask cluster of this scheduler file (HPC)")
    run.add_argument("--dask-workers", type=int_at_least(1), help="workers of --dask local (default: cores)")
    run.add_argument("--retry-failed", action="store_true", help="run again the cases recorded as failed")
    run.add_argument(
        "--batch-seconds", type=_seconds, default=None,
        help="work per batch sent to a worker [s] (default 10; 5-30 keeps the engine's overhead small)",
    )  # fmt: skip
    run.add_argument("--yes", action="store_true", help="confirm a campaign of more than 100,000 cases")
    run.add_argument("--report", action="store_true", help="write report.html when the run ends")
    run.add_argument("--json", action="store_true", help="print one JSON object (no progress bar)")
    run.add_argument("--quiet", action="store_true", help="no progress bar, no summary")
    run.set_defaults(func=_run)

    status = cmds.add_parser("status", help="cases done, failed, left; the failures", description=(
        "What the ledger in DIR holds: cases planned, finished, failed (with their errors) and left, and "
        "each run."))  # fmt: skip
    status.add_argument("out", metavar="DIR")
    status.add_argument("--json", action="store_true", help="print one JSON object")
    status.set_defaults(func=_status)

    export = cmds.add_parser("export", help="one row per case as CSV or Parquet", description=(
        "Write the finished cases of DIR, one row each (key, varied fields, recorded results, error), "
        "as CSV and/or Parquet (Parquet needs pyarrow: the 'parquet' extra)."))  # fmt: skip
    export.add_argument("out", metavar="DIR")
    export.add_argument("--csv", metavar="FILE", help="write CSV ('-': to stdout)")
    export.add_argument("--parquet", metavar="FILE", help="write Parquet")
    export.add_argument("--all", action="store_true", help="also the cases no longer in the campaign file")
    export.set_defaults(func=_export)

    report = cmds.add_parser("report", help="self-contained HTML report: heatmaps, distributions, worst cases",
                             description=(
        "Write DIR/report.html: what varied, headline numbers, heatmaps of each result over two varied "
        "fields, distributions, the worst cases (each as a scenario file that `jointlock run` re-runs) and "
        "the failed cases."))  # fmt: skip
    report.add_argument("out", metavar="DIR")
    report.add_argument("--output", metavar="FILE", help="where to write the page (default DIR/report.html)")
    report.add_argument("--x", metavar="FIELD", help="varied field across the heatmaps (default: chosen)")
    report.add_argument("--y", metavar="FIELD", help="varied field down the heatmaps (default: chosen)")
    report.add_argument("--worst", metavar="COLUMN", help="result ranking the worst cases")
    report.add_argument("--worse", choices=("higher", "lower"), help="which way is worse for --worst")
    report.add_argument("--top", type=int_at_least(1), default=10, help="worst cases listed (default 10)")
    report.add_argument("--json", action="store_true", help="print one JSON object")
    report.set_defaults(func=_report)


def _out(args: argparse.Namespace, spec: CampaignSpec) -> Path:
    out = check_out_dir(args.out) if args.out else spec.default_out()
    assert out is not None  # check_out_dir returns None for no path only
    return Path(out)


def _plan(args: argparse.Namespace) -> int:
    from ..campaign import load_campaign, plan_campaign

    spec = load_campaign(args.campaign)
    plan = plan_campaign(
        spec, _out(args, spec), workers=args.workers, probe=args.probe, progress=sys.stderr.isatty() and not args.json
    )
    if args.json:
        print_json(plan.to_dict())
    else:
        print("\n".join(plan.summary()))
    return 0


def _engine(args: argparse.Namespace, quiet: bool) -> Callable[[], Engine] | None:
    """The engine the options ask for, as a function that starts it (called by the run once
    the campaign is checked and there is work: nothing starts for a bad file)."""
    from ..campaign import dask_cluster, in_process

    if args.dask_workers is not None and args.dask != "local":
        raise CampaignError("--dask-workers sizes a --dask local cluster; give --dask local (or use --workers)")
    if args.in_process:
        return in_process
    if not (args.dask or args.dask_scheduler_file):
        return None

    def start() -> Engine:
        if args.dask_scheduler_file:
            engine = dask_cluster(None, scheduler_file=args.dask_scheduler_file)
        else:
            engine = dask_cluster(args.dask, workers=args.dask_workers)
        if not quiet:
            print(f"engine: {engine.description}; dashboard: {engine.dashboard}", file=sys.stderr)
        return engine

    return start


def resume_command(args: argparse.Namespace) -> str:
    """The command that resumes this run (the same options)."""
    argv = ["jointlock", "campaign", "run", args.campaign]
    for option, value in (
        ("--out", args.out),
        ("--workers", args.workers),
        ("--dask", args.dask),
        ("--dask-scheduler-file", args.dask_scheduler_file),
        ("--dask-workers", args.dask_workers),
        ("--batch-seconds", args.batch_seconds),
    ):
        if value is not None:
            argv += [option, str(value)]
    flags = (("--in-process", args.in_process), ("--yes", args.yes), ("--retry-failed", args.retry_failed),
             ("--report", args.report), ("--quiet", args.quiet), ("--json", args.json))  # fmt: skip
    for flag, on in flags:
        if on:
            argv.append(flag)
    return shlex.join(argv)


def _run(args: argparse.Namespace) -> int:
    from ..campaign import BATCH_SECONDS, CONFIRM_CASES, load_campaign, run_campaign, write_campaign_report

    spec = load_campaign(args.campaign)
    out = _out(args, spec)
    quiet = args.quiet or args.json
    result = run_campaign(
        spec,
        out,
        engine=_engine(args, quiet),
        workers=args.workers,
        retry_failed=args.retry_failed,
        max_cases=None if args.yes else CONFIRM_CASES,
        batch_seconds=args.batch_seconds or BATCH_SECONDS,
        progress=not quiet,
    )
    if not quiet:  # before the report: what ran is said even if the report's settings are wrong
        print("\n".join(result.summary()))
    written = write_campaign_report(out) if args.report and not result.interrupted else []
    if args.json:
        print_json(result.to_dict() | {"files": [str(p) for p in written]})
    elif written and not args.quiet:
        print(f"  report: {written[0]}")
    if result.interrupted:
        print(
            f"jointlock campaign: stopped by {result.stopped_by}; {result.planned - result.remaining} of "
            f"{result.planned} cases are in the ledger. Run the same command again to resume the remaining "
            f"{result.remaining}: {resume_command(args)}",
            file=sys.stderr,
        )
        return 130 if result.stopped_by == "SIGINT" else 143
    return 0


def _status(args: argparse.Namespace) -> int:
    from ..campaign import campaign_status

    status = campaign_status(args.out)
    if args.json:
        print_json(status.to_dict())
    else:
        print("\n".join(status.summary()))
    return 0


def _export(args: argparse.Namespace) -> int:
    from ..campaign import campaign_table

    if not args.csv and not args.parquet:
        raise CampaignError("export needs --csv FILE and/or --parquet FILE")
    if args.parquet and importlib.util.find_spec("pyarrow") is None:  # before writing anything
        raise CampaignError("--parquet needs pyarrow: pip install 'jointlock[parquet]' (or export --csv only)")
    table = campaign_table(args.out, include_outside=args.all)
    written: list[str] = []
    if args.parquet:
        written.append(str(table.write_parquet(args.parquet)))
    if args.csv == "-":
        sys.stdout.write(table.csv_text())
        written.append("stdout")
    elif args.csv:
        written.append(str(table.write_csv(args.csv)))
    print(
        f"wrote {len(table.rows)} cases x {len(table.names)} columns to {', '.join(written)}",
        file=sys.stderr if args.csv == "-" else sys.stdout,
    )
    return 0


def _report(args: argparse.Namespace) -> int:
    from ..campaign import campaign_report

    rep = campaign_report(args.out, x=args.x, y=args.y, worst=args.worst, worse=args.worse, top=args.top)
    written = rep.write(args.output)
    if args.json:
        print_json(rep.to_dict() | {"files": [str(p) for p in written]})
    else:
        print("\n".join(rep.summary()))
        print(f"wrote {written[0]}" + (f" and {len(written) - 1} worst-case scenario file(s)" if len(written) > 1 else ""))
    return 0
