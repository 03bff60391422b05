"""Figures of the gamma sweep (002 Figs. 5-8): every joint and the locked joint against gamma."""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from ..planning.replan import GammaRoot, GammaSweep
from ._common import new_axes, new_figure


def plot_joints_vs_gamma(
    sweep: GammaSweep,
    joint: int,
    angle: float,
    roots: Sequence[GammaRoot] = (),
    *,
    window_deg: float | None = None,
    fig: Any | None = None,
) -> Any:
    """Six panels, one per joint: its angle [deg] against gamma [deg] along the sweep (002
    Fig. 7; with ``window_deg=2``, Fig. 8).

    Parameters
    ----------
    sweep
        The gamma sweep (:func:`jointlock.planning.replan.gamma_sweep`).
    joint, angle
        The locked joint (1-based) and its angle [rad]: its panel shows the locked angle
        (dashed) and the ``roots`` (dots).
    roots
        The gammas absorbing the lock (:func:`jointlock.planning.replan.gammas_for_lock`).
    window_deg
        Show only ``|gamma| <= window_deg`` [deg]; None: the whole sweep.
    fig
        Figure to draw on (2 x 3 axes are added); None: a new pyplot figure of 12 x 6 inch.

    Returns
    -------
    The figure.
    """
    fig = new_figure(fig, (12, 6))
    axes = fig.subplots(2, 3, sharex=True)
    g = np.degrees(sweep.gammas)
    q = np.degrees(sweep.q)
    sel = np.ones(g.shape, bool) if window_deg is None else np.abs(g) <= window_deg + 1e-9
    for k, ax in enumerate(axes.ravel()):
        ax.plot(g[sel], q[sel, k])
        if k == joint - 1:
            ax.axhline(math.degrees(angle), color="r", ls="--", lw=1, label="locked angle")
            for r in roots:
                if window_deg is None or abs(math.degrees(r.gamma)) <= window_deg:
                    ax.plot(math.degrees(r.gamma), math.degrees(angle), "ro")
            ax.legend(fontsize=8)
        ax.set_title(f"joint {k + 1}")
        ax.set_ylabel("angle [deg]")
        ax.grid(alpha=0.3)
    for ax in axes[1]:
        ax.set_xlabel("gamma (rotation about tool x) [deg]")
    fig.tight_layout()
    return fig


def plot_locked_joint_vs_gamma(sweep: GammaSweep, joint: int, angle: float, *, ax: Any | None = None) -> Any:
    """The locked joint's angle [deg] against gamma [deg] along the whole sweep, with the
    locked angle ``angle`` [rad] dashed (002 Figs. 5-6).  ``ax=None``: a new 6 x 4 inch
    figure.  Returns the axis."""
    ax = new_axes(ax, (6, 4))
    ax.plot(np.degrees(sweep.gammas), np.degrees(sweep.q[:, joint - 1]))
    ax.axhline(math.degrees(angle), color="r", ls="--", lw=1)
    ax.set_xlabel("gamma [deg]")
    ax.set_ylabel(f"joint {joint} [deg]")
    ax.grid(alpha=0.3)
    return ax
