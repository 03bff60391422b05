"""Benchmark W2 (issue 13): Newton-Euler joint torques and base wrench (000 eqs. 28-31) on
halt7 with joint 4 locked, fixed base and free-floating, against Pinocchio in the same run;
then a whole GA run of the halt motion (000 §4.2).

* one 1001-sample trajectory: ``jl.rnea`` (numpy, and the compiled kernels:
  ``compiled=True``) against a Pinocchio per-sample loop: fixed base ``rnea`` plus the
  placement of joint 1 (for the base wrench in the root frame); free-floating, two loops on
  the free-flyer model: the same work as ours (``crba`` for the spacecraft block ``H_b`` and
  the coupling ``H_bm``, the zero-momentum twist ``-H_b^-1 H_bm dq``, ``rnea`` with the
  spacecraft not accelerating, its acceleration ``-H_b^-1 tau_b`` and the torques
  ``tau_m + H_bm^T nu0_dot``), and ``rnea`` alone given the spacecraft twist and
  acceleration we solve for (a lower bound: Pinocchio is spared the solve; its base rows
  are then zero, checked);
* 50 trajectories x 1001 samples in one call against Pinocchio's batched
  ``rneaInParallel`` on one thread (joint torques only: it returns no base wrench);
* the compile time of the kernels in a fresh process (cold: empty numba cache; warm: cached).

    .venv/bin/python benchmarks/bench_dynamics.py [--no-ga]
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import numpy as np  # noqa: E402
from _info import best_of, machine_info  # noqa: E402

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "tests"))

import jointlock as jl  # noqa: E402
from jointlock.dynamics import rnea  # noqa: E402
from jointlock.papers.p000 import SCENARIO as PAPER_SCENARIO  # noqa: E402
from jointlock.planning.ga import GASettings  # noqa: E402
from jointlock.planning.halt_motion import HaltProblem, optimal_halt_motion  # noqa: E402

N_TRAJ = 50


def _problem(model: jl.ArmModel) -> HaltProblem:
    d = np.radians
    sc = PAPER_SCENARIO  # 000 §5.2's state at failure and its printed q_best (T = 12 s: feasible)
    return HaltProblem(
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


def _pin_inputs(model, pm, po, q, dq, ddq, floating):
    """Pinocchio's (q, v, a) per sample, (N, nq), (N, nv), (N, nv): for the free flyer, the
    spacecraft's twist and acceleration from our solution, at the root origin, body frame."""
    qs = np.array([po.pin_q(pm, x, floating) for x in q])
    if not floating:
        return qs, dq, ddq
    res = rnea(model, q, dq, ddq, base="floating")
    c0 = model.root_body.com
    v0, w0 = res.base_twist[:, :3], res.base_twist[:, 3:]
    a0, al0 = res.base_acceleration[:, :3], res.base_acceleration[:, 3:]
    v_o = v0 + np.cross(w0, -c0)
    a_o = a0 + np.cross(al0, -c0) + np.cross(w0, np.cross(w0, -c0))
    v = np.concatenate([v_o, w0, dq], axis=1)
    a = np.concatenate([a_o - np.cross(w0, v_o), al0, ddq], axis=1)
    return qs, v, a


def w2(model: jl.ArmModel, p: HaltProblem) -> None:
    q, dq, ddq = p.trajectory(3e-4 * np.pi / 180, p.times(1001))
    kk = np.linspace(0, 5e-4, N_TRAJ) * np.pi / 180
    qb, dqb, ddqb = p.trajectory(kk, p.times(1001))
    try:
        import pin_oracle as po
    except ImportError:
        po = None
    print("\nW2: halt7 joint 4 locked, joint torques + base wrench (best of 20 runs for one trajectory, 5 for 50)")
    print(
        f"  {'base':<9} {'samples':>14} {'numpy':>9} {'compiled':>9} {'Pinocchio':>10} "
        f"{'vs numpy':>9} {'vs Pinocchio':>13}"
    )
    for base in ("fixed", "floating"):
        floating = base == "floating"
        rnea(model, q[:2], dq[:2], ddq[:2], base=base, compiled=True)  # load the kernels outside the timing
        t_n = best_of(lambda b=base: rnea(model, q, dq, ddq, base=b, compiled=False), 20)
        t_c = best_of(lambda b=base: rnea(model, q, dq, ddq, base=b, compiled=True), 20)
        tb_n = best_of(lambda b=base: rnea(model, qb, dqb, ddqb, base=b, compiled=False), 5)
        tb_c = best_of(lambda b=base: rnea(model, qb, dqb, ddqb, base=b, compiled=True), 5)
        t_pin = t_pin_solve = tb_pin = float("nan")
        if po is not None:
            t_pin, t_pin_solve, tb_pin = _pinocchio_times(model, po, (q, dq, ddq), (qb, dqb, ddqb), floating)
        n1, nb = len(q), qb.shape[0] * qb.shape[1]
        if floating and po is not None:
            print(
                f"  {base:<9} {'1 x ' + str(n1):>14} {1e3 * t_n:7.2f}ms {1e3 * t_c:7.2f}ms {1e3 * t_pin_solve:8.2f}ms "
                f"{t_n / t_c:8.1f}x {t_pin_solve / t_c:12.1f}x   (Pinocchio: per-sample loop, the same work)"
            )
        print(
            f"  {base:<9} {'1 x ' + str(n1):>14} {1e3 * t_n:7.2f}ms {1e3 * t_c:7.2f}ms {1e3 * t_pin:8.2f}ms "
            f"{t_n / t_c:8.1f}x {t_pin / t_c:12.1f}x   (Pinocchio: per-sample loop"
            + (", rnea given the spacecraft's motion)" if floating else ")")
        )
        print(
            f"  {base:<9} {f'{N_TRAJ} x 1001':>14} {1e3 * tb_n:7.1f}ms {1e3 * tb_c:7.1f}ms {1e3 * tb_pin:8.1f}ms "
            f"{tb_n / tb_c:8.1f}x {tb_pin / tb_c:12.1f}x   (Pinocchio: rneaInParallel, 1 thread"
            + (", given the spacecraft's motion" if floating else ", torques only")
            + "; "
            f"ours {nb / tb_c / 1e6:.2f} M samples/s)"
        )
    with tempfile.TemporaryDirectory() as cache:
        cold, warm = (_child(cache) for _ in range(2))
    print(f"  compile (fresh process, both kernels): cold {cold:.2f} s (empty numba cache), warm {warm:.2f} s (cached)")


def _pinocchio_times(model, po, one, batch, floating):
    """Pinocchio's times [s] for one trajectory (per-sample loop; and for free-floating the
    same-work loop) and for the batch (``rneaInParallel``, one thread); each checked
    against ours."""
    pin = po.pin
    q, dq, ddq = one
    pm, _ = po.to_pinocchio(model, free_flyer=floating)
    pm.gravity.linear[:] = 0.0
    data = pm.createData()
    qs, vs, as_ = _pin_inputs(model, pm, po, q, dq, ddq, floating)

    def loop():
        out = np.empty((len(qs), 6))
        for i in range(len(qs)):
            tau = pin.rnea(pm, data, qs[i], vs[i], as_[i])
            if floating:
                out[i] = tau[:6]
            else:
                pin.forwardKinematics(pm, data, qs[i])  # placement of joint 1
                rot = data.oMi[1].rotation
                out[i, :3] = rot @ data.f[1].linear
                out[i, 3:] = rot @ data.f[1].angular
        return out

    t_pin = best_of(loop, 5)
    t_pin_solve = float("nan")
    if floating:
        assert np.max(np.abs(loop())) < 1e-6, "Pinocchio's free flyer needs a base wrench"
        solve_loop = _pin_zero_momentum_loop(pin, pm, data, qs, dq, ddq)
        t_pin_solve = best_of(solve_loop, 3)
        ref = rnea(model, q, dq, ddq, base="floating").torques
        assert np.allclose(solve_loop(), ref, atol=1e-6 * np.max(np.abs(ref))), "Pinocchio disagrees"
    qb, dqb, ddqb = (x.reshape(-1, model.dof) for x in batch)
    qsb, vsb, asb = _pin_inputs(model, pm, po, qb, dqb, ddqb, floating)
    pool = pin.ModelPool(pm, 1)
    qT, vT, aT = (np.asfortranarray(x.T) for x in (qsb, vsb, asb))
    tau = np.zeros((pm.nv, qT.shape[1]), order="F")
    tb_pin = best_of(lambda: pin.rneaInParallel(1, pool, qT, vT, aT, tau), 5)
    ours = rnea(model, qb, dqb, ddqb, base="floating" if floating else "fixed", compiled=True).torques
    assert np.allclose(tau[-model.dof :].T, ours, atol=1e-6), "rneaInParallel disagrees"
    return t_pin, t_pin_solve, tb_pin


def _pin_zero_momentum_loop(pin, pm, data, qs, dq, ddq):
    """Free-floating joint torques with zero momentum by Pinocchio, per sample, as a user
    would write it: ``crba`` for ``H_b`` and ``H_bm``, two 6 x 6 solves and one ``rnea``."""
    zero6 = np.zeros(6)

    def loop():
        out = np.empty((len(qs), dq.shape[1]))
        for i in range(len(qs)):
            m = pin.crba(pm, data, qs[i])  # upper triangle
            hb = np.triu(m[:6, :6]) + np.triu(m[:6, :6], 1).T
            hbm = m[:6, 6:]
            nu0 = -np.linalg.solve(hb, hbm @ dq[i])
            tau = pin.rnea(pm, data, qs[i], np.concatenate([nu0, dq[i]]), np.concatenate([zero6, ddq[i]]))
            out[i] = tau[6:] + hbm.T @ -np.linalg.solve(hb, tau[:6])
        return out

    return loop


_CHILD = """
import time
import numpy as np
import jointlock as jl
from jointlock.dynamics import rnea
model = jl.lock(jl.load_robot("halt7", base="floating"), 4, 0.0)
q = np.zeros((2, 6))
t = time.perf_counter()
rnea(model, q, q, q, compiled=True)
rnea(model, q, q, q, base="floating", compiled=True)
print(time.perf_counter() - t)
"""


def _child(cache_dir: str) -> float:
    env = dict(os.environ, NUMBA_CACHE_DIR=cache_dir)
    out = subprocess.run([sys.executable, "-c", _CHILD], env=env, capture_output=True, text=True, check=True)
    return float(out.stdout.split()[-1])


def ga(p: HaltProblem) -> None:
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


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--no-ga", action="store_true", help="skip the whole-GA timing")
    args = parser.parse_args()
    print(machine_info())
    model = jl.lock(jl.load_robot("halt7", base="floating"), 4, 0.0)
    p = _problem(model)
    w2(model, p)
    if not args.no_ga:
        print()
        ga(p)


if __name__ == "__main__":
    main()
