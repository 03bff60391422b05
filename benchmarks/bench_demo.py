"""CPU time of ``jointlock demo`` (issue 13): a fresh process writing the whole report (the
000 halt on halt7: 36,000-sample halt configuration, halt motion, 16 figures as PNG and SVG,
report.html), median of 3 runs, and its profile by cumulative CPU time with ``--profile``.

    .venv/bin/python benchmarks/bench_demo.py [--profile]
"""

from __future__ import annotations

import os
import resource
import statistics
import subprocess
import sys
import tempfile

from _info import machine_info

TOP = 10


def cpu_seconds(argv: list[str]) -> float:
    """User + system CPU time of one run of ``argv`` [s]."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run(argv, stdout=subprocess.DEVNULL, check=True, env={**os.environ, "MPLBACKEND": "Agg"})
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def profile(out: str) -> None:
    """The demo in this process, profiled by CPU time (not wall time: less sensitive to load)."""
    import cProfile
    import pstats
    import time

    os.environ.setdefault("MPLBACKEND", "Agg")
    from jointlock.cli import main

    prof = cProfile.Profile(time.process_time)
    prof.runcall(main, ["demo", "--quiet", "--out", out])
    pstats.Stats(prof).sort_stats("cumulative").print_stats(TOP + 12)  # the first lines are the call chain


def main() -> None:
    print(machine_info())
    with tempfile.TemporaryDirectory() as tmp:
        if "--profile" in sys.argv:
            profile(tmp)
            return
        runs = [cpu_seconds([sys.executable, "-m", "jointlock", "demo", "--quiet", "--out", tmp]) for _ in range(3)]
    print(f"jointlock demo: {statistics.median(runs):.2f} s CPU (median of 3; min {min(runs):.2f})")


if __name__ == "__main__":
    main()
