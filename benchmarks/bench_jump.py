"""Benchmark: the full seed-001 pipeline on NOTES-001's default scenario.

40 failure times, kappa probe + grid + multi-start refinement, piecewise kappa(t) fit (with the
failure times added around its breaks), verification with the failure
injected at every 50 ms step (and the fixed kappa(t) when the fit breaks a limit).  Target:
under 10 s on one core.  Prints the wall time and the CPU time of the process (the CPU figure is
the one to compare on a shared machine).  Run with one BLAS thread for the one-core figure::

    OMP_NUMBER_THREADS=1 OPENBLAS_NUM_THREADS=1 python benchmarks/bench_jump.py [ROBOT]
"""

from __future__ import annotations

import sys
import time

from _info import machine_info

import jointlock as jl
from jointlock.planning.jump import JumpScenario, study_jump


def main(argv: list[str]) -> int:
    robot = argv[1] if len(argv) > 1 else "canadarm7"
    print(machine_info())
    model = jl.load_robot(robot)
    sc = JumpScenario()
    times, cpu = [], []
    for _ in range(3):
        t0, c0 = time.perf_counter(), time.process_time()
        st = study_jump(model, sc, n_samples=40)
        times.append(time.perf_counter() - t0)
        cpu.append(time.process_time() - c0)
    v = st.verification
    print(
        f"{robot}: full pipeline best of 3: {min(times):.2f} s wall, {min(cpu):.2f} s CPU "
        f"(runs {', '.join(f'{t:.2f}' for t in times)} s wall, {', '.join(f'{t:.2f}' for t in cpu)} s CPU)"
    )
    print("  stages [s]: " + ", ".join(f"{k} {val:.2f}" for k, val in st.elapsed.items()))
    print(
        f"  mean jump reduction {100 * v.mean_reduction:.1f} %, improved {100 * v.share_improved:.1f} % of "
        f"{v.t.size} steps, limits kept {v.limits_ok}; kappa(t) order {st.fit.order}, SSR {st.fit.ssr:.3g}, "
        f"segment points {st.fit.segment_points.tolist()}"
    )
    f = st.fit
    print(
        f"  breaks {f.breaks.tolist()}, segments {list(f.segments)}, {st.search.fail_times.size} failure times searched"
    )
    for pc in f.pieces or ():
        print(
            f"  piece {pc.start:.3g}..{pc.end:.3g} s: order {pc.order}, {pc.n_samples} samples, {pc.source}"
        )
    if st.verification_fixed is not None:
        f = st.verification_fixed
        print(
            f"  with fix {f.fix}: reduction {100 * f.mean_reduction:.1f} %, improved {100 * f.share_improved:.1f} %, "
            f"limits kept {f.limits_ok}"
        )
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
