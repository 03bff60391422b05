"""Section plots of the halt-configuration search (seed 000 Fig. 7): for one healthy joint,
its angle [deg] against CP over the sample set, with the upper envelope, the best
configuration and the runner-up."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..errors import ConfigurationError
from ._common import new_axes, offscreen_figure

#: Size of one section plot [inch].
SECTION_FIGSIZE = (5.0, 3.4)
#: Angle bins of the upper envelope (max CP per bin).
SECTION_BINS = 72


def _configuration(result: Any) -> Any:
    """The :class:`~jointlock.planning.halt_config.HaltConfiguration` of ``result`` (a job
    result holding it as ``configuration``, or the search result itself)."""
    return getattr(result, "configuration", result)


def plot_section(result: Any, joint: int, *, ax: Any | None = None, bins: int = SECTION_BINS) -> Any:
    """Joint angle [deg] vs CP over the sample set for healthy joint ``joint`` (its number,
    1-based, full arm), with the upper envelope (max CP per angle bin), the best and the
    runner-up (000 Fig. 7).  Under exact reachability unreachable samples are grey crosses
    (their own legend entry) and the envelope is over the reachable ones; with a clearance
    required, samples too close to the bus or the arm itself are greyed out with them.

    Parameters
    ----------
    result
        A :class:`~jointlock.planning.halt_config.HaltConfiguration`, or a job result holding
        one as ``configuration`` (:class:`jointlock.jobs.halt_config.HaltConfigurationStudy`).
    joint
        Number of a healthy joint (``result.joint_numbers``).
    ax
        Axes to draw on; None: a new pyplot figure of :data:`SECTION_FIGSIZE` (laid out tight).
    bins
        Angle bins of the envelope.

    Returns
    -------
    The ``matplotlib.axes.Axes`` drawn on.
    """
    res = _configuration(result)
    if joint not in res.joint_numbers:
        raise ConfigurationError(
            f"joint {joint} is not a healthy joint of this search; give one of {list(res.joint_numbers)}"
        )
    j = res.joint_numbers.index(joint)
    own = ax is None
    ax = new_axes(ax, SECTION_FIGSIZE)
    q_deg = np.degrees(res.q_samples)
    edges = np.linspace(math.degrees(float(res.lower.min())), math.degrees(float(res.upper.max())), bins + 1)
    ok = np.ones(res.samples, bool) if res.reachable is None else res.reachable
    # with a clearance required the mask is "reachable and clear" (HaltConfiguration.reachable)
    kept, excluded = ("admissible", "unreachable or too close") if res.colliding_samples is not None else ("reachable", "unreachable")
    if not ok.all():
        ax.scatter(
            q_deg[~ok, j],
            res.cp_samples[~ok],
            s=8.0,
            alpha=0.6,
            color="0.3",
            marker="x",
            linewidths=0.7,
            zorder=2.5,  # above the reachable cloud: a thin set must stay visible
            rasterized=True,
            label=f"{excluded} samples ({int((~ok).sum())})",
        )
    ax.scatter(
        q_deg[ok, j],
        res.cp_samples[ok],
        s=1.5,
        alpha=0.25,
        color="tab:blue",
        rasterized=True,
        label="samples" if res.reachable is None else f"{kept} samples ({int(ok.sum())})",
    )
    which = np.clip(np.digitize(q_deg[ok, j], edges) - 1, 0, bins - 1)
    envelope = np.full(bins, np.nan)
    np.fmax.at(envelope, which, res.cp_samples[ok])
    centres = 0.5 * (edges[1:] + edges[:-1])
    ax.plot(centres, envelope, color="tab:blue", lw=1.2, label="max CP per bin")
    ax.plot(math.degrees(res.best.q[j]), res.best.cp, "r*", ms=12, label="best")
    if res.runner_up is not None:
        ax.plot(math.degrees(res.runner_up.q[j]), res.runner_up.cp, "ks", ms=6, label="runner-up")
    ax.set_xlabel(f"angle of joint {joint} [deg]")
    ax.set_ylabel("CP")
    ax.set_title(f"joint {joint} - CP ({res.samples} samples)", fontsize=10)
    legend = ax.legend(fontsize=7, loc="lower right", markerscale=1.0)
    # the sample clouds are drawn faint and tiny: their legend keys opaque and readable
    for handle in getattr(legend, "legend_handles", getattr(legend, "legendHandles", [])):
        if hasattr(handle, "set_sizes"):
            handle.set_sizes([25.0])
            handle.set_alpha(1.0)
    ax.grid(alpha=0.3)
    if own:
        ax.figure.tight_layout()
    return ax


def section_figures(result: Any, *, bins: int = SECTION_BINS) -> list[Any]:
    """:func:`plot_section` of every healthy joint, each on a figure of its own outside pyplot
    (:func:`~jointlock.plots._common.offscreen_figure`, for writing files), laid out tight.

    Returns
    -------
    list of ``matplotlib.figure.Figure``, chain order (``result.joint_numbers``).
    """
    figures: list[Any] = []
    for number in _configuration(result).joint_numbers:
        fig = offscreen_figure(SECTION_FIGSIZE)
        plot_section(result, number, ax=fig.add_subplot(), bins=bins)
        if not figures:
            fig.tight_layout()
        else:  # the same title, labels and CP axis on the same size: the first layout fits them all
            pars = figures[0].subplotpars
            fig.subplots_adjust(left=pars.left, right=pars.right, bottom=pars.bottom, top=pars.top)
        figures.append(fig)
    return figures
