"""Seed 002 from Python: puma6 keeps working with joint 2 locked at 59.4 deg.

The fault-tolerance angle gamma (rotate the target about the tool x axis until the full arm's
IK puts joint 2 at its locked angle; 002: -1.45 deg), the straight-line re-plan of 002's first
example within |gamma| <= 2 deg, and the workspace before and after the lock.

    python examples/replan_002.py [OUT_DIR]
"""

import math
import sys
from pathlib import Path

import numpy as np

import jointlock as jl
from jointlock.jobs.replan import plan_replan
from jointlock.jobs.tolerance_angle import find_tolerance_angle
from jointlock.jobs.workspace import study_workspace

out = Path(sys.argv[1] if len(sys.argv) > 1 else "out/replan_002_py")

arm = jl.load_robot("puma6")
joint, angle = 2, math.radians(59.4)
target_deg = [5.0, 60.0, 35.0, 10.0, -120.0, 90.0]

gamma = find_tolerance_angle(arm, joint, angle, target_deg)  # 002 Figs. 5-8
plan = plan_replan(arm, joint, angle, np.radians([0, 60, 0, 0, 0, 0]), np.radians(target_deg), tolerance_deg=2.0)
space = study_workspace(arm, (joint, angle), samples=200_000, rng=0)  # 002 Figs. 2-3 (volumes with errors)

for result, folder in ((gamma, "tolerance_angle"), (plan, "replan"), (space, "workspace")):
    for line in result.summary():
        print(line)
    result.write(out / folder)

# checked quantities: 002's tolerance angle; the re-plan keeps |gamma| within its tolerance
chosen = gamma.to_dict()["chosen"]
print(f"gamma = {chosen['gamma_deg']:.4f} deg (002 prints -1.45)")
assert abs(chosen["gamma_deg"] - (-1.45)) < 0.05, "002's gamma is a grid value near the exact root"
assert max(abs(g) for g in plan.to_dict()["gamma_deg_range"]) <= 2.0 + 1e-9
kept = space.to_dict()
assert 0 < kept["share_kept"] < 1 and kept["share_kept_error"] < 0.1, "200k samples give the share kept to +-10 %"
