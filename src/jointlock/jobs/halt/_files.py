"""The files of a halt (``HaltPlan.write``): 000 Figs. 8-9 (the global torque over k, the joint
profiles), the base torque over time, the actuators' and the spacecraft's figures and tables, the
clearance over time, the time series (CSV, NPZ), the motion to animate and ``result.json``."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any, cast

import numpy as np

from ...io.files import (
    atomic_write_bytes,
    atomic_write_json,
    atomic_write_text,
    csv_text,
    npz_bytes,
    write_figure,
)
from ...plots._common import offscreen_figure
from ...plots.halt import (
    global_torque_curve,
    plot_actuator_loads,
    plot_base_torque_vs_time,
    plot_clearance,
    plot_global_torque_vs_k,
    plot_joint_profiles,
    plot_spacecraft_response,
)

if TYPE_CHECKING:
    from ._result import HaltPlan


def write_halt_files(plan: HaltPlan, out: Path) -> list[str]:
    """Write the halt ``plan``'s figures (PNG), tables (CSV, NPZ) and ``result.json`` into the
    folder ``out`` (made when missing); returns the file names."""
    out.mkdir(parents=True, exist_ok=True)
    res, p = plan.motion, plan.problem
    grid, tau = global_torque_curve(res)
    ts = plan.time_series()
    figures: tuple[Any, ...] = (
        (
            "global_torque_vs_k.png",
            (7, 4),
            # laid out: the x label's superscript reaches past the edge (a costlier crop)
            lambda fig: plot_global_torque_vs_k(res, ax=fig.add_subplot()).figure.tight_layout(),
        ),
        ("joint_profiles.png", (3 * p.dof, 7), lambda fig: plot_joint_profiles(res, fig=fig)),
        (
            "base_torque_vs_time.png",
            (7, 4),
            lambda fig: plot_base_torque_vs_time(res, ax=fig.add_subplot()),
        ),
    )
    loads = plan.actuator_loads()
    if loads is not None:
        figures += (
            ("actuator_torques.png", (7, 6), lambda fig: plot_actuator_loads(
                loads, motor_limits=plan.limits.torque, brake_limits=plan.limits.brake, fig=fig)),
        )  # fmt: skip
    sc = plan.spacecraft_response()
    if sc is not None:
        figures += (
            ("spacecraft_attitude.png", (7, 4), lambda fig: plot_spacecraft_response(sc, fig=fig)),
        )
    clear = plan.clearance()
    if clear is not None:
        figures += (
            ("clearance.png", (7, 4), lambda fig: plot_clearance(
                clear, p.times(p.n_check), margin=plan.clearance_settings.margin, ax=fig.add_subplot())),
        )  # fmt: skip
    written = []
    for name, size, draw in figures:
        fig = offscreen_figure(size)
        draw(fig)
        written += write_figure(fig, out, name)
    cols = {"t_s": ts["t"]}
    for j, num in enumerate(p.model.joint_numbers):
        cols[f"q{num}_deg"] = np.degrees(ts["q"][:, j])
        cols[f"dq{num}_deg_s"] = np.degrees(ts["dq"][:, j])
        cols[f"ddq{num}_deg_s2"] = np.degrees(ts["ddq"][:, j])
    for i, ax_name in enumerate("xyz"):
        cols[f"tau_b_{ax_name}_Nm"] = ts["tau_b"][:, i]
    for i, ax_name in enumerate("xyz"):
        cols[f"tau_b0_{ax_name}_Nm"] = ts["tau_b_k0"][:, i]
    atomic_write_text(out / "halt_motion.csv", csv_text(cols))
    atomic_write_bytes(out / "halt_motion.npz", npz_bytes(**cast(dict[str, Any], ts), k_grid=grid, global_torque_grid=tau))
    atomic_write_json(out / "result.json", plan.to_dict())
    files = written + ["halt_motion.csv", "halt_motion.npz", "result.json", *plan._write_motions(out)]
    if loads is not None:
        atomic_write_text(out / "actuators.csv", csv_text({"t_s": loads.t, **loads.columns()}))
        files.append("actuators.csv")
    if clear is not None:
        columns = {"t_s": p.times(p.n_check), "clearance_m": clear.distance}
        columns.update({f"{name}_m": clear.pair_distance[:, i] for i, name in enumerate(clear.names)})
        atomic_write_text(out / "clearance.csv", csv_text(columns))
        files.append("clearance.csv")
    if sc is not None:
        cols = {"t_s": sc.t, "attitude_change_deg": sc.attitude_change_deg}
        cols.update({f"q_{c}": sc.attitude[:, i] for i, c in enumerate("wxyz")})
        cols.update(
            {f"omega_{c}_deg_s": np.degrees(sc.angular_velocity[:, i]) for i, c in enumerate("xyz")}
        )
        cols.update({f"com_{c}_m": sc.com_displacement[:, i] for i, c in enumerate("xyz")})
        atomic_write_text(out / "spacecraft.csv", csv_text(cols))
        files.append("spacecraft.csv")
    return files
