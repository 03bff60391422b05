"""``jointlock reproduce``: each seed paper's published experiment, re-run with the documented
readings, as one table -- quantity, the paper's value, ours, and whether it is reproduced.

A thin shell over :func:`jointlock.jobs.reproduction.reproduce` (the comparisons) and
:mod:`jointlock.papers` (the printed numbers): parse, call, print.
"""

from __future__ import annotations

import argparse

from ._common import print_json
from ._constants import PAPERS


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "reproduce",
        help="re-run each seed paper's published experiment and compare with its printed numbers",
        description=(
            "Runs the experiments of seeds 000 (halt configuration and halt motion), 001 (velocity-jump "
            "compensation; no published numbers survived), 002 (worked examples, tolerance angle) and 004 "
            "(virtual lengths, eq. 15, Table 3, Cond1-Cond5) with the documented readings and prints one "
            "table: quantity, paper's value, ours, agreement. About 5 s for all four."
        ),
    )
    p.add_argument("--paper", choices=PAPERS, action="append", help="only this paper (repeatable)")
    p.add_argument("--json", action="store_true", help="print one JSON object: rows, timings, notes")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from ..jobs.reproduction import reproduce

    result = reproduce(args.paper or PAPERS)
    if args.json:
        print_json(result.to_dict())
        return 0
    for line in result.summary():
        print(line)
    return 0
