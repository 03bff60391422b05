"""Every row of issue 13's speed table in one command: each benchmark script in turn, in a
fresh process, one BLAS thread, with the machine printed once at the top.

    .venv/bin/python benchmarks/bench_all.py [--quick]

Rows and where they come from (each script prints its reference libraries' times from the
same run, and the ratio):

* W1, σ_min/κ/w of 36,000 configurations, fixed and generalized Jacobian, compiled kernels
  vs numpy + LAPACK vs a Pinocchio loop; the kernels' cold and warm compile times; the peak
  memory of 10^7 configurations (``bench_kinematics.py --w1-only``);
* W2, joint torques and base wrench of one 1001-sample trajectory and of 50 at once, vs a
  Pinocchio loop, a same-work free-flyer loop and ``rneaInParallel`` (``bench_dynamics.py``);
* W3, 10^6 end-effector positions vs a Pinocchio FK loop, 10^7 in bounded memory; closed-form
  IK of puma6 vs EAIK (``bench_workspace.py``);
* start-up of the command line, and W1 and the 001 pipeline through it, process included,
  against the interpreter + numpy floor (``bench_startup.py``);
* the 001 pipeline in-process (``bench_jump.py``) and ``jointlock demo`` (``bench_demo.py``).

``--quick`` skips the 10^7-configuration memory runs and the whole-GA timing.
roboticstoolbox-python is not a dependency of the tests; where it is installed the scripts
that know it print its rows too.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
from pathlib import Path

# one BLAS thread here too (the machine line reports this process's thread pools)
for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

from _info import machine_info  # noqa: E402

HERE = Path(__file__).resolve().parent


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="skip the 1e7 memory runs and the whole GA")
    args = parser.parse_args()
    env = {**os.environ, "OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1"}
    print(machine_info())
    runs = [
        ["bench_kinematics.py", "--w1-only"] + (["--mem-samples", "0"] if args.quick else []),
        ["bench_dynamics.py"] + (["--no-ga"] if args.quick else []),
        ["bench_workspace.py"] + (["--mem-samples", "0"] if args.quick else []),
        ["bench_startup.py"],
        ["bench_jump.py"],
        ["bench_demo.py"],
    ]
    failed = []
    for argv in runs:
        print(f"\n===== {' '.join(argv)} =====", flush=True)
        proc = subprocess.run([sys.executable, str(HERE / argv[0]), *argv[1:]], env=env, capture_output=True, text=True)
        # the machine lines are printed once, above
        lines = [ln for ln in proc.stdout.splitlines() if not _machine_line(ln)]
        print("\n".join(lines), flush=True)
        if proc.returncode:
            failed.append(argv[0])
            print(proc.stderr[-2000:], flush=True)
    if failed:
        print(f"\nfailed: {', '.join(failed)}")
    return 1 if failed else 0


def _machine_line(line: str) -> bool:
    return line.startswith(("CPU:", "python ", "thread env:", "  openblas", "  openmp", "  mkl"))


if __name__ == "__main__":
    sys.exit(main())
