"""Benchmark: batched Newton-Euler base wrench vs a Pinocchio ``rnea`` loop, and a whole GA
run of the halt motion (000 §4.2).  Run on one core:

    OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 python benchmarks/bench_dynamics.py
"""

from __future__ import annotations

import os
import sys
import time

import numpy as np
from _info import best_of, machine_info

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "tests"))

import jointlock as jl
from jointlock.dynamics import rnea  # noqa: E402
from jointlock.papers.p000 import SCENARIO as PAPER_SCENARIO  # noqa: E402
from jointlock.planning.ga import GASettings  # noqa: E402
from jointlock.planning.halt_motion import HaltProblem, optimal_halt_motion  # noqa: E402


def main() -> None:
    print(machine_info())
    model = jl.lock(jl.robots.halt7(base="floating"), 4, 0.0)
    d = np.radians
    sc = PAPER_SCENARIO  # 000 §5.2's state at failure and its printed q_best (T = 12 s: feasible)
    p = HaltProblem(
        model,
        d(sc["q0_deg"]),
        d(sc["dq0_deg"]),
        d(sc["ddq0_deg"]),
        d(sc["qf_deg"]),
        12.0,
        d(sc["vmax_deg"]),
        d(sc["amax_deg"]),
        n_samples=1001,
    )
    q, dq, ddq = p.trajectory(3e-4 * np.pi / 180, p.times(1001))
    t_ours = {}
    for base in ("fixed", "floating"):
        t_ours[base] = best_of(lambda b=base: rnea(model, q, dq, ddq, base=b), 20)
        print(f"ours  rnea+base wrench, 1001 samples, {base:8s}: {1e3 * t_ours[base]:8.2f} ms")
    try:
        from pin_oracle import pin, pin_q, to_pinocchio

        pm, _ = to_pinocchio(model)
        pm.gravity.linear[:] = 0.0
        data = pm.createData()
        qs = np.array([pin_q(pm, x, False) for x in q])

        def loop():
            out = np.empty((len(q), 6))
            for i in range(len(q)):
                pin.rnea(pm, data, qs[i], dq[i], ddq[i])
                pin.forwardKinematics(pm, data, qs[i])  # only rnea; placement of joint 1 below
                f = data.f[1]
                rot = data.oMi[1].rotation
                out[i, :3] = rot @ f.linear
                out[i, 3:] = rot @ f.angular
            return out

        t_pin = best_of(loop, 5)
        print(
            f"pinocchio rnea loop, 1001 samples (fixed):   {1e3 * t_pin:8.2f} ms  -> ratio "
            f"{t_pin / t_ours['fixed']:.1f}x (fixed), {t_pin / t_ours['floating']:.1f}x (floating)"
        )
    except ImportError:
        print("pinocchio not installed: no ratio")
    for base in ("fixed", "floating"):
        for n in (1, 10, 50):
            kk = np.linspace(0, 5e-4, n) * np.pi / 180
            qb, dqb, ddqb = p.trajectory(kk, p.times(1001))
            t = best_of(lambda a=qb, b=dqb, c=ddqb, m=base: rnea(model, a, b, c, base=m), 3)
            print(
                f"ours {base:8s}, {n:3d} trajectories x 1001 samples: {1e3 * t:8.1f} ms, "
                f"{n * 1001 / t / 1e6:.2f} M samples/s"
            )
    st = GASettings(n_pop=50, n_gen=100)
    for base in ("fixed", "floating"):
        pb = HaltProblem(**{**p.__dict__, "base": base})
        t = time.perf_counter()
        res = optimal_halt_motion(pb, solver="ga", rng=0, ga_settings=st)
        t = time.perf_counter() - t
        print(
            f"GA {st.n_pop} x {st.n_gen} generations, {base:8s} base, 1001 samples: {t:6.2f} s "
            f"({res.ga.n_evaluations} distinct trajectories scored), k* = {res.k * 180 / np.pi:.6g} deg/s^6"
        )


if __name__ == "__main__":
    main()
