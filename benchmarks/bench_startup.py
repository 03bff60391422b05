"""Start-up cost of the command line (issue 13): CPU time of a fresh process, median of 7 runs.

``jointlock --help`` lists the commands without importing any; a command imports its own
module only, and the library (numpy behind it) only once its options are parsed, so a
command's ``--help`` imports no numpy; the floor of any command that computes is the
interpreter plus numpy.

Then two commands that compute, process included (issue 13's "through the CLI" rows): W1,
``jointlock halt-config halt7 --lock 4=0 --samples 36000`` with the fixed-base Jacobian,
against a Pinocchio loop over the same 36,000 configurations in this process (Jacobian +
SVD; no process start counted for Pinocchio); and the 001 pipeline, ``jointlock jump
canadarm7 --sweep 40``.

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


#: Commands that compute (median of 3 runs each).
WORKLOADS = {
    "W1: jointlock halt-config halt7 --lock 4=0 --samples 36000 --jacobian fixed": [
        sys.executable, "-m", "jointlock", "halt-config", "halt7", "--lock", "4=0", "--samples", "36000",
        "--jacobian", "fixed", "--quiet",
    ],
    "jointlock jump canadarm7 --sweep 40": [sys.executable, "-m", "jointlock", "jump", "canadarm7", "--sweep", "40"],
}  # fmt: skip


def main() -> None:
    print(machine_info())
    for label, argv in CASES.items():
        runs = [cpu_seconds(argv) for _ in range(7)]
        print(f"{label:58s} {statistics.median(runs):6.3f} s CPU (min {min(runs):.3f})")
    print()
    for label, argv in WORKLOADS.items():
        runs = [cpu_seconds(argv) for _ in range(3)]
        line = f"{label:76s} {statistics.median(runs):6.3f} s CPU (min {min(runs):.3f})"
        if label.startswith("W1"):
            line += _pinocchio_w1(statistics.median(runs))
        print(line)


def _pinocchio_w1(cli_seconds: float) -> str:
    """The ratio of a Pinocchio loop over W1's 36,000 configurations (Jacobian + SVD, in this
    process) to the command's CPU time."""
    import time
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
    try:
        import numpy as np
        from bench_halt_config import pinocchio_loop

        import jointlock as jl

        model = jl.lock(jl.load_robot("halt7", base="fixed"), 4, 0.0)
        run = pinocchio_loop(model, np.random.default_rng(0).uniform(-np.pi, np.pi, (36000, 6)), False)
    except ImportError:
        return "; Pinocchio not installed"
    t0 = time.process_time()
    run()
    t_pin = time.process_time() - t0
    return f"; Pinocchio loop {t_pin:.3f} s CPU -> ratio {t_pin / cli_seconds:.2f}x"


if __name__ == "__main__":
    main()
