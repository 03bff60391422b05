"""Clearance benchmark (issue 27): signed distances of 36,000 halt7 configurations (joint 4
locked at 0) over every checked pair (links, post, bus), jointlock's compiled kernels against a
Pinocchio + coal ``computeDistances`` loop on the same shapes and pairs, in the same run: every
pair's distance with the closest pair's witness points (``clearance``), every pair's distance
alone (``witness=False``), and the smallest excess over a 0.05 m margin and its pair, every pair
decided but only those that can be the closest computed (``smallest_excess``, the jobs'
screens); then the halt-configuration search with and without the clearance required.

    .venv/bin/python benchmarks/bench_clearance.py [--samples 36000] [--pin-samples 3000]
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import numpy as np  # noqa: E402

sys.path.insert(0, str(Path(__file__).parent))
sys.path.insert(0, str(Path(__file__).parent.parent / "tests"))
from _info import best_of, machine_info  # noqa: E402

import jointlock as jl  # noqa: E402
from jointlock.collision import clearance, margin_floor, smallest_excess  # noqa: E402
from jointlock.planning.halt_config import optimal_halt_configuration  # noqa: E402


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=36000)
    parser.add_argument("--pin-samples", type=int, default=3000, help="configurations of the Pinocchio loop")
    args = parser.parse_args()
    print(machine_info())
    arm = jl.lock(jl.load_robot("halt7"), 4, 0.0)
    q = np.random.default_rng(0).uniform(-np.pi, np.pi, (args.samples, arm.dof))
    clearance(arm, q[:10])  # numba load and compilation out of the timing
    ours = best_of(lambda: clearance(arm, q), 5)
    distances = best_of(lambda: clearance(arm, q, witness=False), 5)
    floor = margin_floor(arm, 0.05)
    screen = best_of(lambda: smallest_excess(arm, q, floor), 5)
    result = clearance(arm, q)
    print(f"pairs checked: {len(result.names)}; colliding: {100 * float(np.mean(result.distance < 0)):.1f} %")
    print(f"jointlock.collision   {args.samples} configurations: {ours * 1e3:8.1f} ms  ({args.samples / ours / 1e3:7.0f} k/s)")
    print(f"  every pair's distance only (witness=False): {distances * 1e3:.1f} ms ({args.samples / distances / 1e3:.0f} k/s)")
    print(f"  smallest excess over 0.05 m and its pair (smallest_excess, the jobs' screens): {screen * 1e3:.1f} ms "
          f"({args.samples / screen / 1e3:.0f} k/s)")

    from pin_oracle import pin, pin_q, to_pinocchio, to_pinocchio_geometry

    pm, _ = to_pinocchio(arm)
    geom, _ = to_pinocchio_geometry(arm, pm)
    data, gdata = pm.createData(), pin.GeometryData(geom)
    qs = [pin_q(pm, row, False) for row in q[: args.pin_samples]]

    def loop() -> None:
        for qq in qs:
            pin.computeDistances(pm, data, geom, gdata, qq)

    theirs = best_of(loop, 3) / len(qs)
    print(f"Pinocchio + coal loop {len(qs)} configurations: {theirs * len(qs) * 1e3:8.1f} ms  ({1 / theirs / 1e3:7.0f} k/s)")
    print(f"ratio: {theirs * args.samples / ours:.1f}x Pinocchio + coal (issue 27 target: >= 20x); "
          f"distances only {theirs * args.samples / distances:.1f}x; smallest excess {theirs * args.samples / screen:.1f}x")

    floating = jl.lock(jl.load_robot("halt7", base="floating"), 4, 0.0)
    for label, minimum in (("without clearance", None), ("with 0.05 m", 0.05)):
        t0 = time.process_time()
        optimal_halt_configuration(floating, samples=args.samples, rng=0, clearance_min_m=minimum)
        print(f"halt-configuration search {label:18s}: {time.process_time() - t0:6.2f} s CPU")


if __name__ == "__main__":
    main()
