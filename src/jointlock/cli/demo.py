"""``jointlock demo``: the main job on the built-in default scenario, report written to a folder.

A thin shell over :func:`jointlock.run.run_demo` (000 §5 on ``halt7`` -- the same run as
``jointlock run examples/halt_000.toml`` -- and an overview of the built-in arms).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from .._lazy import lazy_attributes

# re-exported, imported on first use (the parser is built without the library)
__getattr__, __dir__ = lazy_attributes(
    __name__,
    {name: "jointlock.run._demo" for name in ("DEMO_SCENARIO", "REFERENCE_Q_DEG", "lock_equivalence", "run_demo")},
    namespace=globals(),
)


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("demo", help="run the main job on the built-in arms and write a report")
    p.add_argument("--out", default="jointlock-demo", help="output folder (default: jointlock-demo)")
    p.add_argument("--quiet", action="store_true", help="print nothing but errors")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from ..run._demo import run_demo

    out = Path(args.out)
    demo = run_demo(progress=not args.quiet and sys.stderr.isatty())
    demo.write(out)
    if not args.quiet:
        for line in demo.summary():
            print(line)
        print(f"wrote {out / 'report.html'} and {out / 'results.json'}")
    return 0
