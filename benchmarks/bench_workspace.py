"""Benchmark: Monte Carlo workspace sampling and closed-form IK throughput (issue 6).

Run: ``python benchmarks/bench_workspace.py [--samples 1000000] [--pin-subset 100000]``.

Prints end-effector positions per second of :func:`jointlock.kinematics.ee_positions`
(10^6 configurations of ``puma6``, full and with joint 2 locked, plus the general
:func:`jointlock.chain_state`) against a Python loop of Pinocchio ``forwardKinematics`` +
``updateFramePlacement`` on a subset, in the same run; and closed-form IK poses per second
(8 branches each) at several batch sizes.  Records CPU, numpy/BLAS and thread settings.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
from _info import best_of, machine_info

import jointlock as jl
from jointlock.analysis.workspace import sample_configurations
from jointlock.ik import ik_closed_form
from jointlock.kinematics import ee_positions

_MEM_CHILD = """
import resource, sys, time, tracemalloc
import numpy as np
import jointlock as jl
from jointlock.kinematics import ee_positions
arm = jl.load_robot("puma6")
ee_positions(arm, np.zeros((10, 6)), compiled=True)  # loads numba and the cached kernel
tracemalloc.start()
q = np.random.default_rng(0).uniform(-np.pi, np.pi, (int(sys.argv[1]), 6))
t0 = time.perf_counter()
ee_positions(arm, q)
t = time.perf_counter() - t0
print(t, tracemalloc.get_traced_memory()[1] / 2**20, resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024)
"""


def numpy_ee_positions(model: jl.ArmModel, q: np.ndarray, chunk: int = 65536) -> np.ndarray:
    """The numpy reference of the kernel (the rows of :func:`jointlock._chain.ee_position_rows`)."""
    from jointlock._chain import ee_position_rows, position_program

    program = position_program(model)
    out = np.empty((q.shape[0], 3))
    for s0 in range(0, q.shape[0], chunk):
        part = q[s0 : s0 + chunk]
        for k, row in enumerate(ee_position_rows(program, part)):
            out[s0 : s0 + part.shape[0], k] = 0.0 if row is None else row
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=1_000_000)
    parser.add_argument("--pin-subset", type=int, default=100_000)
    parser.add_argument("--mem-samples", type=int, default=10_000_000, help="configurations of the memory run (0: skip)")
    args = parser.parse_args()

    print(machine_info())

    arm = jl.load_robot("puma6")
    locked = jl.lock(arm, 2, np.radians(60.0))
    q = sample_configurations(arm, args.samples, rng=0)
    ql = sample_configurations(locked, args.samples, rng=1)

    ee_positions(arm, q[:10], compiled=True)  # compile (or load) the kernel outside the timing
    t_fast = best_of(lambda: ee_positions(arm, q, compiled=True))
    t_numpy = best_of(lambda: numpy_ee_positions(arm, q))
    t_fast_l = best_of(lambda: ee_positions(locked, ql, compiled=True))
    sub = q[: min(args.samples, 200_000)]
    t_chain = best_of(lambda: jl.chain_state(arm, sub), 1) * (args.samples / sub.shape[0])
    rate = args.samples / t_fast
    print(f"\nworkspace sampling, {args.samples:.0e} configurations:")
    print(f"  ee_positions (full arm)      : {rate:12,.0f} points/s  ({t_fast:.3f} s, compiled kernel)")
    print(f"  numpy reference (rows)       : {args.samples / t_numpy:12,.0f} points/s  (compiled / numpy {t_numpy / t_fast:.1f}x)")
    print(f"  ee_positions (joint 2 locked): {args.samples / t_fast_l:12,.0f} points/s")
    print(f"  chain_state (all frames)     : {args.samples / t_chain:12,.0f} points/s")

    try:
        sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
        import pinocchio as pin
        from pin_oracle import pin_q, to_pinocchio
    except ImportError:
        print("  pinocchio: not installed, no ratio")
    else:
        pm, fid = to_pinocchio(arm)
        data = pm.createData()
        n = args.pin_subset
        qs = [pin_q(pm, qq, False) for qq in q[:n]]
        out = np.empty((n, 3))

        def loop() -> None:
            for k, qq in enumerate(qs):
                pin.forwardKinematics(pm, data, qq)
                out[k] = pin.updateFramePlacement(pm, data, fid).translation

        t_pin = best_of(loop)
        assert np.abs(out - ee_positions(arm, q[:n])).max() < 1e-12
        pin_rate = n / t_pin
        print(f"  pinocchio FK loop ({n:.0e})   : {pin_rate:12,.0f} points/s")
        print(f"  ratio ee_positions / pinocchio: {rate / pin_rate:.2f}x (issue 13 target >= 20x)")
    if args.mem_samples:
        out = subprocess.run([sys.executable, "-c", _MEM_CHILD, str(args.mem_samples)], capture_output=True,
                             text=True, check=True, env=dict(os.environ))
        t, heap, rss = (float(x) for x in out.stdout.split())
        print(f"  {args.mem_samples:.0e} configurations, fresh process: {t:.2f} s ({args.mem_samples / t:,.0f} points/s); "
              f"peak arrays {heap:,.0f} MB (tracemalloc; q {args.mem_samples * 6 * 8 / 2**20:,.0f} MB and the "
              f"result {args.mem_samples * 3 * 8 / 2**20:,.0f} MB included), peak RSS {rss:,.0f} MB")

    ik_speed(arm, locked, q, ql)


def ik_speed(arm: jl.ArmModel, locked: jl.ArmModel, q: np.ndarray, ql: np.ndarray) -> None:
    """Closed-form IK of puma6, every branch: with each branch's FK check (``ik_closed_form``)
    and the branches alone (``puma6_branches``), against EAIK (C++, Ostermeier et al.) on the
    same poses in the same run."""
    from jointlock.ik import puma6_branches, puma6_geometry
    from jointlock.spatial import invert

    geom = puma6_geometry(arm)
    print("\nclosed-form IK (every branch), puma6:")
    for batch in (1, 100, 10_000, 100_000):
        t = jl.ee_pose(arm, q[:batch])
        tt = best_of(lambda t=t: ik_closed_form(arm, t))
        print(f"  batch {batch:>7}: {batch / tt:12,.0f} poses/s (8 branches, errors checked by FK)")
    t = jl.ee_pose(arm, q[:10_000])
    t06 = t @ invert(geom.tool)
    t_checked = best_of(lambda: ik_closed_form(arm, t))
    t_branches = best_of(lambda: puma6_branches(geom, t06))
    print(f"  batch   10000: {1e4 / t_branches:12,.0f} poses/s (8 branches alone: puma6_branches)")
    try:
        import eaik.IK_DH as eaik_dh
    except ImportError:
        print("  EAIK not installed: no ratio")
    else:
        alpha = np.radians([-90, 0, 90, -90, 90, 0])
        robot = eaik_dh.DhRobot(alpha, np.array([0, geom.a2, 0, 0, 0, 0]), np.array([0, 0, 0, geom.d4, 0, geom.d6]))
        poses = list(t06)
        t_eaik = best_of(lambda: robot.IK_batched(poses, 1))
        sol = robot.IK(t06[0])
        assert any(np.allclose(np.asarray(x), np.asarray(y), atol=1e-9)
                   for x in np.atleast_2d(sol.Q) for y in puma6_branches(geom, t06[0])[0])
        print(
            f"  EAIK IK_batched, 1 thread, batch 10000: {1e4 / t_eaik:12,.0f} poses/s -> ratio branches alone "
            f"{t_eaik / t_branches:.2f}x, with the FK check ({1e4 / t_checked:,.0f} poses/s) {t_eaik / t_checked:.2f}x"
        )
    t = jl.ee_pose(arm, ql[:100_000, [0, 0, 1, 2, 3, 4]])
    tt = best_of(lambda: ik_closed_form(locked, t))
    print(f"  joint 2 locked, batch 100000: {1e5 / tt:12,.0f} poses/s (4 branches)")


if __name__ == "__main__":
    main()
