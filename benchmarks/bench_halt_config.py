"""Benchmark: HCOM (000 §3.2) with K = 36,000 on halt7, joint 4 locked at 0.

Times jointlock's batched search (sampling + Jacobians + indices + CP, without and with the
refinement) against a Pinocchio per-configuration loop (Jacobian + SVD, the part HCOM
spends its time on) in the same run, for the fixed-base and the generalized Jacobian, and
prints the machine, numpy/BLAS and thread information.

Run: ``python benchmarks/bench_halt_config.py [--samples 36000] [--repeat 3]``.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np
from _info import best_of, machine_info

import jointlock as jl
from jointlock.analysis.ability import configuration_indices
from jointlock.planning.halt_config import optimal_halt_configuration

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))


def pinocchio_loop(model: jl.ArmModel, q: np.ndarray, floating: bool) -> np.ndarray:
    from pin_oracle import pin, pin_q, to_pinocchio

    pm, fid = to_pinocchio(model, free_flyer=floating)
    data = pm.createData()
    qs = [pin_q(pm, qi, floating) for qi in q]  # conversion outside the timed loop
    frame = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED

    def run() -> np.ndarray:
        out = np.empty((len(qs), model.dof))
        for i, qq in enumerate(qs):
            jac = pin.computeFrameJacobian(pm, data, qq, fid, frame)
            if floating:
                mass = pin.crba(pm, data, qq)
                mass = np.triu(mass) + np.triu(mass, 1).T
                jac = jac[:, 6:] - jac[:, :6] @ np.linalg.solve(mass[:6, :6], mass[:6, 6:])
            out[i] = np.linalg.svd(jac, compute_uv=False)
        return out

    return run


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=36000)
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    k = args.samples
    print(machine_info())
    print(f"HCOM on halt7, joint 4 locked at 0 deg, K = {k}; best of {args.repeat}\n")
    header = f"{'Jacobian':<12} {'stage':<34} {'time [s]':>9} {'configs/s':>11} {'vs Pinocchio':>13}"
    print(header)
    print("-" * len(header))
    for base, kind in (("fixed", "fixed"), ("floating", "generalized")):
        model = jl.lock(jl.load_robot("halt7", base=base), 4, 0.0)
        q = np.random.default_rng(0).uniform(-np.pi, np.pi, (k, model.dof))
        pin_run = pinocchio_loop(model, q, base == "floating")
        t_pin = best_of(pin_run, 1)
        sv_pin = pin_run()
        ind = configuration_indices(model, q, jacobian=kind, method="gram")
        err_s = np.max(np.abs(ind.sigma_min - sv_pin[:, -1]))
        err_w = np.max(np.abs(ind.manipulability - np.prod(sv_pin, axis=1)))
        t_ind = best_of(
            lambda model=model, q=q, kind=kind: configuration_indices(model, q, jacobian=kind, method="gram"),
            args.repeat,
        )
        t_mc = best_of(
            lambda model=model, kind=kind: optimal_halt_configuration(
                model, samples=k, rng=0, jacobian=kind, refine=False
            ),
            args.repeat,
        )
        t_full = best_of(
            lambda model=model, kind=kind: optimal_halt_configuration(model, samples=k, rng=0, jacobian=kind),
            args.repeat,
        )
        rows = [
            ("Pinocchio loop (Jacobian + SVD)", t_pin, 1.0),
            ("jointlock indices (Jacobian+eig)", t_ind, t_pin / t_ind),
            ("jointlock HCOM Monte Carlo", t_mc, t_pin / t_mc),
            ("jointlock HCOM + refinement", t_full, None),
        ]
        for label, t, ratio in rows:
            r = f"{ratio:12.2f}x" if ratio is not None else f"{'':>13}"
            print(f"{kind:<12} {label:<34} {t:9.3f} {k / t:11.0f} {r}")
        print(f"{kind:<12} agreement with Pinocchio: max |d sigma_min| {err_s:.1e}, max |d w| {err_w:.1e}")
    print("\n'vs Pinocchio' = Pinocchio loop time / jointlock time, same configurations, same run.")


if __name__ == "__main__":
    main()
