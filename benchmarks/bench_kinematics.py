"""Foundation benchmark: Jacobian + singular values for many configurations.

halt7 with joint 4 locked, random configurations -> geometric Jacobian (6x6) and its
singular values.  jointlock evaluates the whole batch at once; the reference is a Pinocchio
per-configuration loop (computeFrameJacobian + numpy SVD) in the same run.  Then W1 of issue
13: the three indices (sigma_min, kappa, w) by the compiled kernels
(``configuration_indices(method="jacobi")``) next to the numpy path (``method="svd"``: numpy
Jacobian + LAPACK) and Pinocchio, fixed base and generalized (floating) Jacobian; the
kernels' compile time (cold: empty numba cache, warm: cached) and the peak memory of the
indices of 10^7 configurations, each in a fresh process.

    .venv/bin/python benchmarks/bench_kinematics.py [--samples 36000] [--mem-samples 10000000]
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
from pathlib import Path

# One core: OpenBLAS threads fight over a busy machine and make small-matrix products erratic.
for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import numpy as np  # noqa: E402

sys.path.insert(0, str(Path(__file__).parent))
sys.path.insert(0, str(Path(__file__).parent.parent / "tests"))
from _info import best_of, machine_info  # noqa: E402

import jointlock as jl  # noqa: E402


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=36000)
    parser.add_argument("--pin-samples", type=int, default=5000, help="configurations for the Pinocchio loop")
    parser.add_argument("--mem-samples", type=int, default=10_000_000, help="configurations of the memory run (0: skip)")
    parser.add_argument("--w1-only", action="store_true", help="only the compiled-vs-numpy-vs-Pinocchio W1 table")
    args = parser.parse_args()
    print(machine_info())
    model = jl.lock(jl.load_robot("halt7"), 4, 0.0)
    rng = np.random.default_rng(0)

    from jointlock.analysis.ability import singular_values

    w1_compiled(args)
    if args.w1_only:
        return
    rates = {}
    for method in ("svd", "auto"):
        label = (
            "exact SVD"
            if method == "svd"
            else "auto: Gram eigenvalues, SVD where cond > 1e4 (rel. error < 1.2e-8)"
        )
        print(f"\njointlock batched (halt7, joint 4 locked): Jacobian + singular values [{label}]")
        for k in sorted({100, 1000, 10000, args.samples}):
            q = rng.uniform(-np.pi, np.pi, (k, model.dof))
            t = best_of(lambda q=q, method=method: singular_values(jl.jacobian(model, q), method=method))
            rates[method, k] = k / t
            print(f"  {k:>7} configs: {t * 1e3:9.2f} ms  {k / t:>12,.0f} configs/s")

    try:
        import pinocchio as pin
        from pin_oracle import to_pinocchio
    except ImportError:
        print("\nPinocchio absent: no reference loop (pip install '.[test]', which holds Pinocchio)")
        return
    pm, fid = to_pinocchio(model)
    data = pm.createData()
    q = rng.uniform(-np.pi, np.pi, (args.pin_samples, model.dof))

    def pin_loop():
        for qi in q:
            jac = pin.computeFrameJacobian(pm, data, qi, fid, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
            np.linalg.svd(jac, compute_uv=False)

    t_pin = best_of(pin_loop)
    pin_rate = args.pin_samples / t_pin
    print(f"\nPinocchio per-config loop ({args.pin_samples} configs): {pin_rate:>12,.0f} configs/s")
    for method in ("svd", "auto"):
        ratio = rates[method, args.samples] / pin_rate
        print(f"ratio jointlock ({method}) / Pinocchio loop at {args.samples} configs: {ratio:.1f}x")
    # the same comparison without the SVD, which both sides pay in numpy
    qb = rng.uniform(-np.pi, np.pi, (args.samples, model.dof))
    t_j = best_of(lambda: jl.jacobian(model, qb))

    def pin_jac_only():
        for qi in q:
            pin.computeFrameJacobian(pm, data, qi, fid, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)

    t_pj = best_of(pin_jac_only)
    print(
        f"Jacobian only: jointlock {args.samples / t_j:,.0f} configs/s, Pinocchio {args.pin_samples / t_pj:,.0f} "
        f"configs/s, ratio {(args.samples / t_j) / (args.pin_samples / t_pj):.2f}x"
    )


# -- W1 (issue 13): compiled kernels vs numpy vs Pinocchio ----------------------------------

_CHILD = """
import resource, sys, time, tracemalloc
t0 = time.perf_counter()
import numpy as np
import jointlock as jl
from jointlock.analysis.ability import configuration_indices
base, n = sys.argv[1], int(sys.argv[2])
model = jl.lock(jl.load_robot("halt7", base=base), 4, 0.0)
kind = "fixed" if base == "fixed" else "generalized"
t1 = time.perf_counter()
configuration_indices(model, np.zeros((100, model.dof)), jacobian=kind, method="jacobi")
t2 = time.perf_counter()
if n:
    rss0 = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    tracemalloc.start()
    q = np.random.default_rng(0).uniform(-np.pi, np.pi, (n, model.dof))
    t3 = time.perf_counter()
    ind = configuration_indices(model, q, jacobian=kind, batch_size=65536)
    t4 = time.perf_counter()
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    heap = tracemalloc.get_traced_memory()[1]
    print(f"{t1 - t0:.3f} {t2 - t1:.3f} {rss0 / 1024:.0f} {rss / 1024:.0f} {t4 - t3:.3f} {heap / 2**20:.0f}")
else:
    print(f"{t1 - t0:.3f} {t2 - t1:.3f}")
"""


_JAC_CHILD = """
import resource, sys, time
import numpy as np
import jointlock as jl
model = jl.lock(jl.load_robot("halt7"), 4, 0.0)
compiled = sys.argv[2] == "1"
jl.jacobian(model, np.zeros((10, 6)), compiled=compiled)
q = np.random.default_rng(0).uniform(-np.pi, np.pi, (int(sys.argv[1]), 6))
t = time.perf_counter()
jac = jl.jacobian(model, q, compiled=compiled)
t = time.perf_counter() - t
print(f"{t:.3f} {resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024:.0f} {jac.nbytes / 2**20:.0f}")
"""


def jacobian_memory(n: int) -> None:
    """``jl.jacobian`` of ``n`` configurations of halt7 (joint 4 locked), compiled (chunked)
    and numpy (whole-batch chain state), each in a fresh process: time and peak RSS."""
    rows = []
    for compiled in ("1", "0"):
        out = subprocess.run([sys.executable, "-c", _JAC_CHILD, str(n), compiled], capture_output=True, text=True,
                             check=True, env=dict(os.environ))  # fmt: skip
        rows.append([float(x) for x in out.stdout.split()])
    (tc, rc, size), (tn, rn, _) = rows
    print(
        f"  jl.jacobian, {n:.0e} configurations (halt7, joint 4 locked; the result {size:.0f} MB): compiled "
        f"{tc:.2f} s, peak RSS {rc:,.0f} MB; numpy {tn:.2f} s, peak RSS {rn:,.0f} MB ({tn / tc:.0f}x)"
    )


def _child(base: str, n: int, cache_dir: str) -> list[float]:
    env = dict(os.environ, NUMBA_CACHE_DIR=cache_dir)
    out = subprocess.run(
        [sys.executable, "-c", _CHILD, base, str(n)], env=env, capture_output=True, text=True, check=True
    )
    return [float(x) for x in out.stdout.split()]


def w1_compiled(args: argparse.Namespace) -> None:
    """The W1 table: configs/s of the compiled kernels, the numpy path and Pinocchio."""
    from bench_halt_config import pinocchio_loop

    from jointlock.analysis.ability import configuration_indices

    k = args.samples
    print(f"\nW1: halt7 joint 4 locked, {k} configurations -> sigma_min, kappa, w (configs/s; best of 3)")
    print(f"  {'Jacobian':<12} {'compiled':>11} {'numpy+LAPACK':>13} {'Pinocchio':>11} {'vs numpy':>9} {'vs Pinocchio':>13}")
    for base, kind in (("fixed", "fixed"), ("floating", "generalized")):
        model = jl.lock(jl.load_robot("halt7", base=base), 4, 0.0)
        q = np.random.default_rng(0).uniform(-np.pi, np.pi, (k, model.dof))
        configuration_indices(model, q[:10], jacobian=kind)  # compile (or load) outside the timing
        t_c = best_of(lambda m=model, kd=kind, q=q: configuration_indices(m, q, jacobian=kd, method="jacobi"))
        t_n = best_of(lambda m=model, kd=kind, q=q: configuration_indices(m, q, jacobian=kd, method="svd"))
        try:
            pin_run = pinocchio_loop(model, q[: args.pin_samples], base == "floating")
        except ImportError:
            pin_rate = float("nan")
        else:
            pin_rate = args.pin_samples / best_of(pin_run)
        rc, rn = k / t_c, k / t_n
        print(f"  {kind:<12} {rc:11,.0f} {rn:13,.0f} {pin_rate:11,.0f} {rc / rn:8.1f}x {rc / pin_rate:12.1f}x")
    with tempfile.TemporaryDirectory() as cache:
        cold = _child("fixed", 0, cache)
        warm = _child("fixed", 0, cache)
        print(
            f"  compile (fresh process, fixed-base kernels): cold {cold[1]:.2f} s (empty numba cache), "
            f"warm {warm[1]:.2f} s (cached); import jointlock {warm[0]:.2f} s"
        )
        if args.mem_samples:
            jacobian_memory(min(args.mem_samples, 1_000_000))
            for base in ("fixed", "floating"):
                _child(base, 0, cache)
                r = _child(base, args.mem_samples, cache)
                print(
                    f"  {args.mem_samples:.0e} configs ({base}): {r[4]:.1f} s, {args.mem_samples / r[4]:,.0f} configs/s; "
                    f"peak arrays {r[5]:,.0f} MB (tracemalloc, q and results included: q "
                    f"{args.mem_samples * 6 * 8 / 2**20:,.0f} MB, the four results {args.mem_samples * 4 * 8 / 2**20:,.0f} MB); "
                    f"peak RSS {r[3]:,.0f} MB (imports and compilation: {r[2]:,.0f} MB)"
                )


if __name__ == "__main__":
    main()
