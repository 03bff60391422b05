"""Seed 000 from Python: halt7 halts after joint 4 locks at 0 deg.

Load the arm with its spacecraft, lock joint 4, give 000 §5.2's state at failure, and plan
the halt: the optimal halt configuration among those the halt polynomial can reach in
T = 10 s under the limits, then the optimal halt motion (k minimising the base torque).
Plots 000's Figs. 8-9 and writes the time series and figures.

    python examples/halt_000.py [OUT_DIR]
"""

import sys
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

import jointlock as jl
from jointlock.papers import p000
from jointlock.plots.halt import plot_global_torque_vs_k

out = sys.argv[1] if len(sys.argv) > 1 else "out/halt_000_py"

arm = jl.lock(jl.load_robot("halt7", base="floating"), joint=4, angle=0.0)  # torque about the spacecraft COM
state = jl.FailureState.from_degrees(
    arm, p000.SCENARIO["q0_deg"], p000.SCENARIO["dq0_deg"], p000.SCENARIO["ddq0_deg"]
)
plan = jl.plan_halt(arm, state, T=10.0, base="fixed", rng=0)  # limits: halt7's 40 deg/s, 000's 20 deg/s^2

for line in plan.summary():
    print(line)
print("halt configuration [deg]:", np.round(np.degrees(plan.problem.qf), 2))

files = plan.write(out)  # 000 Figs. 8-9, base torque vs time, CSV, NPZ, result.json
print(f"wrote {', '.join(files)} to {out}")

fig, ax = plt.subplots(figsize=(7, 4))  # any figure of your own: the plot functions take ax=
plot_global_torque_vs_k(plan.motion, ax=ax)
fig.savefig(Path(out) / "my_fig8.png", dpi=110)

# checked quantities: the halt keeps every limit and lowers the base torque
assert plan.feasible, "000's scenario with the reachable halt configuration must be feasible"
assert plan.motion.global_torque < plan.motion.global_torque_k0
result = plan.to_dict()  # plain JSON data, as `jointlock halt --json` prints it
assert np.all(np.asarray(result["peak_velocity_deg_s"]) <= np.asarray(result["velocity_limit_deg_s"]) + 1e-9)
