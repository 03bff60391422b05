"""Foundation benchmark: Jacobian + singular values for many configurations.

halt7 with joint 4 locked, random configurations -> geometric Jacobian (6x6) and its
singular values.  jointlock evaluates the whole batch at once; the reference is a Pinocchio
per-configuration loop (computeFrameJacobian + numpy SVD) in the same run.

    .venv/bin/python benchmarks/bench_kinematics.py [--samples 36000]
"""

from __future__ import annotations

import argparse
import os
import sys
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
    args = parser.parse_args()
    print(machine_info())
    model = jl.lock(jl.load_robot("halt7"), 4, 0.0)
    rng = np.random.default_rng(0)

    from jointlock.analysis.ability import singular_values

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


if __name__ == "__main__":
    main()
