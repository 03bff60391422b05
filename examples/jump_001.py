"""Seed 001 from Python: keep following the line when joint 2 locks at an unknown time.

NOTES-001's task on canadarm7 (001's own arm table was lost; 004's Canadarm2-type arm stands
in): a 12 s straight line with parabolic blends, resolved-rate control every 50 ms with the
null-space compensation kappa (I - J+J) grad w.  The optimal kappa at sampled failure times,
the fitted kappa(t), and its verification with the failure injected at every control step.

    python examples/jump_001.py [OUT_DIR]
"""

import sys

import numpy as np

import jointlock as jl
from jointlock.jobs.jump import run_jump_study
from jointlock.planning.jump import JumpScenario

out = sys.argv[1] if len(sys.argv) > 1 else "out/jump_001_py"

arm = jl.load_robot("canadarm7")
task = JumpScenario()  # NOTES-001's task: joint 2 locks, 10 deg/s, 5 deg/s^2, 1 mm
study = run_jump_study(arm, task, sweep=12, order=5)  # 12 sampled failure times (001: 40)

for line in study.summary():
    print(line)
files = study.write(out)  # 001 Figs. 5-9 and the verification time series
print(f"wrote {len(files)} files to {out}")

# checked quantities: the fitted kappa(t) lowers the mean joint-rate jump
result = study.to_dict()
before = np.asarray(result["jump_before"], dtype=float)
after = np.asarray(result["jump_after"], dtype=float)
print(f"mean jump: {np.degrees(np.nanmean(before)):.3f} -> {np.degrees(np.nanmean(after)):.3f} deg/s")
assert result["mean_reduction"] > 0, "the compensation must lower the mean velocity jump"
assert np.nanmean(after) < np.nanmean(before)
