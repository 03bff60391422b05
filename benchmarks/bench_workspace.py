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
import sys
from pathlib import Path

import numpy as np
from _info import best_of, machine_info

import jointlock as jl
from jointlock.analysis.workspace import sample_configurations
from jointlock.ik import ik_closed_form
from jointlock.kinematics import ee_positions


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=1_000_000)
    parser.add_argument("--pin-subset", type=int, default=100_000)
    args = parser.parse_args()

    print(machine_info())

    arm = jl.load_robot("puma6")
    locked = jl.lock(arm, 2, np.radians(60.0))
    q = sample_configurations(arm, args.samples, rng=0)
    ql = sample_configurations(locked, args.samples, rng=1)

    t_fast = best_of(lambda: ee_positions(arm, q))
    t_fast_l = best_of(lambda: ee_positions(locked, ql))
    sub = q[: min(args.samples, 200_000)]
    t_chain = best_of(lambda: jl.chain_state(arm, sub), 1) * (args.samples / sub.shape[0])
    rate = args.samples / t_fast
    print(f"\nworkspace sampling, {args.samples:.0e} configurations:")
    print(f"  ee_positions (full arm)      : {rate:12,.0f} points/s  ({t_fast:.3f} s)")
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
        print(f"  ratio ee_positions / pinocchio: {rate / pin_rate:.2f}x (target >= 3x)")

    print("\nclosed-form IK (every branch), puma6:")
    for batch in (1, 100, 10_000, 100_000):
        t = jl.ee_pose(arm, q[:batch])
        tt = best_of(lambda t=t: ik_closed_form(arm, t))
        print(f"  batch {batch:>7}: {batch / tt:12,.0f} poses/s (8 branches, errors checked by FK)")
    t = jl.ee_pose(arm, ql[:100_000, [0, 0, 1, 2, 3, 4]])
    tt = best_of(lambda: ik_closed_form(locked, t))
    print(f"  joint 2 locked, batch 100000: {1e5 / tt:12,.0f} poses/s (4 branches)")


if __name__ == "__main__":
    main()
