"""A motion replayed in a simulator next to jointlock's own figures of it
(:class:`jointlock.sim.Replay`, issue 30): the spacecraft's attitude change and each brake's
torque over time, jointlock's as solid lines and the simulator's dashed on top."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from ._common import new_figure

if TYPE_CHECKING:  # annotations only: jointlock.sim sits above the plots
    from ..sim import Replay


def plot_replay(replay: Replay, *, fig: Any | None = None) -> Any:
    """Attitude change [deg] (top; a welded spacecraft has none) and brake torques [N m]
    (bottom) of ``replay``: jointlock solid, MuJoCo dashed.  Returns the figure."""
    panels = int(replay.reference is not None) + int(bool(replay.locked_numbers))
    fig = new_figure(fig, (7, 2.6 * max(panels, 1) + 0.4))
    axes = np.atleast_1d(fig.subplots(max(panels, 1), 1, sharex=True))
    k = 0
    if replay.reference is not None:
        ax = axes[k]
        k += 1
        series = replay.time_series()
        ax.plot(replay.reference.t, replay.reference.attitude_change_deg, color="C0", lw=2.5, alpha=0.6,
                label="jointlock")  # fmt: skip
        ax.plot(replay.t, series["attitude_change_deg"], color="k", ls="--", lw=1, label="MuJoCo")
        ax.set_ylabel("spacecraft attitude\nchange [deg]")
        ax.legend(fontsize=7)
    for i, j in enumerate(replay.locked_numbers):
        ax = axes[k]
        ax.plot(replay.t, replay.brake_ref[:, i], color=f"C{i + 1}", lw=2.5, alpha=0.6, label=f"joint {j}: jointlock")
        ax.plot(replay.t, replay.brake[:, i], color="k", ls="--", lw=1, label=f"joint {j}: MuJoCo")
        ax.set_ylabel("brake torque [N m]")
        ax.legend(fontsize=7)
    axes[-1].set_xlabel("t [s]")
    difference = replay.attitude_difference_deg
    extra = f"; final attitudes {difference:.2g} deg apart" if difference is not None else ""
    axes[0].set_title(f"{replay.label} replayed in MuJoCo {replay.mujoco_version}{extra}", fontsize=9)
    return fig
