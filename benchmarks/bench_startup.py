"""Start-up cost of the command line (issue 13): CPU time of a fresh process, median of 7 runs.

``jointlock --help`` lists the commands without importing any; a command imports its own
module only, and the library (numpy behind it) only once its options are parsed, so a
command's ``--help`` imports no numpy; the floor of any command that computes is the
interpreter plus numpy.

    .venv/bin/python benchmarks/bench_startup.py
"""

from __future__ import annotations

import os
import resource
import statistics
import subprocess
import sys

from _info import machine_info

CASES = {
    "python -c pass (interpreter)": [sys.executable, "-c", "pass"],
    "python -c 'import numpy' (floor of a computing command)": [sys.executable, "-c", "import numpy"],
    "jointlock --help": [sys.executable, "-m", "jointlock", "--help"],
    "jointlock halt --help": [sys.executable, "-m", "jointlock", "halt", "--help"],
    "jointlock jump --help": [sys.executable, "-m", "jointlock", "jump", "--help"],
    "jointlock robots": [sys.executable, "-m", "jointlock", "robots"],
    "jointlock kinematics halt7": [sys.executable, "-m", "jointlock", "kinematics", "halt7"],
}


def cpu_seconds(argv: list[str]) -> float:
    """User + system CPU time of one run of ``argv`` [s]."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run(argv, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=True,
                   env={**os.environ, "MPLBACKEND": "Agg"})  # fmt: skip
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def main() -> None:
    print(machine_info())
    for label, argv in CASES.items():
        runs = [cpu_seconds(argv) for _ in range(7)]
        print(f"{label:58s} {statistics.median(runs):6.3f} s CPU (min {min(runs):.3f})")


if __name__ == "__main__":
    main()
