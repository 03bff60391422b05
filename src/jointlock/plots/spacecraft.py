"""What a free spacecraft does during one or several motions of its arm
(:class:`~jointlock.analysis.spacecraft.SpacecraftResponse`): attitude change and angular
rate over time, one colour per motion."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from ._common import new_figure


def plot_spacecraft_responses(responses: Mapping[str, Any], *, fig: Any | None = None, title: str = "") -> Any:
    """Attitude change [deg] (top) and angular rate [deg/s] (bottom) of each labelled response,
    with its final change, peak rate and drift in the legend.  Returns the figure."""
    fig = new_figure(fig, (7, 5))
    top, bottom = fig.subplots(2, 1, sharex=True)
    for label, r in responses.items():
        line = top.plot(
            r.t,
            r.attitude_change_deg,
            label=f"{label}: {r.final_attitude_change_deg:.3g} deg at the end, peak {r.peak_rate_deg_s:.3g} deg/s, "
            f"drift {r.com_drift_m:.3g} m",
        )[0]
        bottom.plot(r.t, np.degrees(np.linalg.norm(r.angular_velocity, axis=-1)), color=line.get_color())
    top.set_ylabel("attitude change [deg]")
    bottom.set_ylabel("angular rate [deg/s]")
    bottom.set_xlabel("t [s]")
    top.legend(fontsize=7)
    top.set_title(title or "spacecraft (free, zero momentum)", fontsize=9)
    return fig
