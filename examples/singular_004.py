"""Seed 004 from Python: where is the free-floating Canadarm2-type arm singular?

The virtual manipulator with 004's own weighting, σ_min at one configuration, 004's closed-form
conditions Cond1-Cond5 checked by sampling configurations that satisfy each (are they all
singular?), and a batched search for singular configurations.

    python examples/singular_004.py [OUT_DIR]
"""

import sys
from pathlib import Path

import numpy as np

import jointlock as jl
from jointlock.jobs.singular import search_singularities, study_singularity, verify_singularity_conditions

out = Path(sys.argv[1] if len(sys.argv) > 1 else "out/singular_004_py")

arm = jl.load_robot("canadarm7", base="floating")

at_q = study_singularity(arm, np.radians([10, 40, -70, 100, -60, 30, 20]), jacobian="virtual")
conditions = verify_singularity_conditions(arm, samples=200, rng=0)
search = search_singularities(arm, samples=64, rng=0, jacobian="generalized")

for result in (at_q, conditions, search):
    for line in result.summary():
        print(line)
search.write(out)  # sigma_min histogram, families, joint angles

# checked quantities: Cond2-Cond5 are sufficient, Cond1 (S4 = 0) only necessary (docs/singularity.md)
verdict = {name: c["sufficient"] for name, c in conditions.to_dict()["conditions"].items()}
print("sufficient:", verdict)
assert not verdict["cond1"] and all(verdict[f"cond{i}"] for i in range(2, 6))
