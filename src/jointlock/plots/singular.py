"""Figures of the singularity search (``jointlock singular --search``): sigma_min of the
starts before and after the search, the families' representative configurations, and the
joint angles of each family's members.

Each function takes the arm and the :class:`jointlock.analysis.singularity.SingularitySearch`
it was searched on, draws on ``ax`` / ``fig`` (a new pyplot one when ``None``) and returns it.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..analysis.singularity import SingularitySearch, task_jacobian
from ..model import ArmModel
from ._common import new_axes, new_figure
from .arm import draw_arm

#: Most families drawn (the largest ones; the search sorts them by size).
FAMILIES_SHOWN = 6
#: Size of the sigma_min histogram [inch].
SIGMA_MIN_FIGSIZE = (6.0, 4.0)


def families_figsize(search: SingularitySearch) -> tuple[float, float]:
    """Size [inch] of :func:`plot_singular_families`' figure: 4.5 x 4.2 per family drawn,
    at most 3 per row."""
    n = max(len(search.families[:FAMILIES_SHOWN]), 1)
    return (4.5 * min(n, 3), 4.2 * math.ceil(n / 3))


def joint_angles_figsize(model: ArmModel) -> tuple[float, float]:
    """Size [inch] of :func:`plot_family_joint_angles`' figure: 2.0 x 2.6 per joint."""
    return (2.0 * model.dof, 2.6)


def plot_search_sigma_min(model: ArmModel, search: SingularitySearch, *, ax: Any | None = None) -> Any:
    """Histogram of log10 sigma_min at the starts and where they ended, with the search's
    tolerance.  The starts' sigma_min is of the raw Jacobian (``base`` and ``weighting`` of
    the search, without its ``length``), as ``jointlock singular --search`` has always drawn it.
    Returns the axis."""
    ax = new_axes(ax, SIGMA_MIN_FIGSIZE)
    start = np.linalg.svd(
        task_jacobian(model, search.q_start, jacobian=search.base, weighting=search.weighting),  # type: ignore[arg-type, call-overload]
        compute_uv=False,
    )
    bins = np.linspace(-17, 1, 55)
    ax.hist(np.log10(np.maximum(start[:, -1], 1e-17)), bins=bins, alpha=0.6, label="start")
    ax.hist(np.log10(np.maximum(search.sigma_final, 1e-17)), bins=bins, alpha=0.6, label="after search")
    ax.axvline(math.log10(search.tol), color="k", ls="--", lw=1, label="tolerance")
    ax.set_xlabel("log10 sigma_min")
    ax.set_ylabel("starts")
    ax.set_title(f"{model.name}: singularity search ({search.base} Jacobian)")
    ax.legend()
    return ax


def plot_condition_checks(
    conditions: dict[str, dict[str, Any]], sigma_tol: float, *, ax: Any | None = None
) -> Any:
    """004's conditions checked: for each condition, the median and the largest sigma_min of
    the configurations sampled exactly on it (log scale) against the singularity tolerance,
    and the share found singular.  ``conditions``: ``{name: {"sigma_min_median",
    "sigma_min_max", "fraction_singular", ...}}`` as the verification's JSON gives them.
    A condition is sufficient when even its largest sigma_min is below the tolerance.
    Returns the axis."""
    ax = new_axes(ax, SIGMA_MIN_FIGSIZE)
    names = list(conditions)
    x = np.arange(len(names))
    floor = 1e-18  # an exact zero drawn at the bottom of the log scale
    median = np.maximum([float(conditions[k]["sigma_min_median"]) for k in names], floor)
    largest = np.maximum([float(conditions[k]["sigma_min_max"]) for k in names], floor)
    ax.vlines(x, median, largest, color="0.6", lw=2)
    ax.scatter(x, median, color="tab:blue", zorder=3, label="median sigma_min")
    ax.scatter(x, largest, color="tab:red", marker="^", zorder=3, label="largest sigma_min")
    ax.axhline(sigma_tol, color="k", ls="--", lw=1, label=f"singular below {sigma_tol:g}")
    ax.set_yscale("log")
    ax.set_xticks(x, [f"{k}\n{100 * float(conditions[k]['fraction_singular']):.0f} %" for k in names])
    ax.set_xlabel("condition (below: share of its sampled configurations that are singular)", fontsize=8)
    ax.set_ylabel("sigma_min on the condition")
    ax.set_title("004's conditions: are the configurations on them singular?", fontsize=10)
    ax.legend(fontsize=8)
    return ax


def plot_singular_families(model: ArmModel, search: SingularitySearch, *, fig: Any | None = None) -> Any:
    """The representative configuration of each of the (up to :data:`FAMILIES_SHOWN`) largest
    families, one 3-D axis each, titled with the family's label.  Returns the figure (no axes
    when the search found no family)."""
    fig = new_figure(fig, families_figsize(search))
    shown = search.families[:FAMILIES_SHOWN]
    if not shown:
        return fig
    rows, cols = math.ceil(len(shown) / 3), min(len(shown), 3)
    for i, fam in enumerate(shown):
        ax = fig.add_subplot(rows, cols, i + 1, projection="3d")
        draw_arm(ax, model, fam.representative, label=f"{len(fam.members)} found")
        ax.set_title(fam.label, fontsize=8)
    fig.tight_layout()
    return fig


def plot_family_joint_angles(model: ArmModel, search: SingularitySearch, *, fig: Any | None = None) -> Any:
    """Histograms of each joint's angle [deg] over the members of each of the (up to
    :data:`FAMILIES_SHOWN`) largest families, one axis per movable joint.  Returns the figure."""
    fig = new_figure(fig, joint_angles_figsize(model))
    shown = search.families[:FAMILIES_SHOWN]
    n = model.dof
    axes = fig.subplots(1, n, sharey=True, squeeze=False)[0]
    for j in range(n):
        for k, fam in enumerate(shown):
            axes[j].hist(
                np.degrees(search.q[fam.members, j]),
                bins=36,
                range=(-180, 180),
                histtype="step",
                label=str(k + 1),
            )
        axes[j].set_xlabel(f"q{model.joint_numbers[j]} [deg]")
    axes[0].set_ylabel("configurations")
    if shown:
        axes[-1].legend(title="family", fontsize=6)
    fig.tight_layout()
    return fig
