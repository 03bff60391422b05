"""Figures of a failure campaign: a heatmap of one result over two varied fields (e.g. failure
joint x failure time -> feasibility) and the distribution of one result over every case."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from ._common import new_axes

#: Cells annotated with their value when the grid has at most this many.
ANNOTATE_CELLS = 150


def plot_heatmap(
    values: ArrayLike,
    x_labels: Sequence[str],
    y_labels: Sequence[str],
    *,
    x_name: str = "",
    y_name: str = "",
    label: str = "",
    title: str = "",
    share: bool = False,
    ax: Any | None = None,
) -> Any:
    """One result over a grid of two varied fields.

    Parameters
    ----------
    values
        (ny, nx) cell values (the mean over the cases in each cell; NaN: no case finished
        there, drawn blank).
    x_labels, y_labels
        Tick labels of the columns and rows.
    x_name, y_name, label, title
        Axis names, colour-bar label and title.
    share
        The values are shares in [0, 1] (e.g. of feasible halts): a fixed 0..1 red-to-green
        scale, annotated in percent.
    ax
        Axis to draw on; None: a new figure sized to the grid.

    Returns
    -------
    The axis.
    """
    z = np.asarray(values, dtype=float)
    ny, nx = z.shape
    ax = new_axes(ax, (min(2.0 + 0.6 * nx, 12.0), min(1.6 + 0.45 * ny, 9.0)))
    masked = np.ma.masked_invalid(z)
    kw = {"cmap": "RdYlGn", "vmin": 0.0, "vmax": 1.0} if share else {"cmap": "viridis"}
    image = ax.imshow(masked, aspect="auto", origin="lower", interpolation="nearest", **kw)
    ax.figure.colorbar(image, ax=ax, label=label)
    ax.set_xticks(range(nx), list(x_labels), rotation=45 if nx > 8 else 0, ha="right" if nx > 8 else "center")
    ax.set_yticks(range(ny), list(y_labels))
    ax.set_xlabel(x_name)
    ax.set_ylabel(y_name)
    ax.set_title(title)
    if z.size <= ANNOTATE_CELLS:
        finite = z[np.isfinite(z)]
        mid = 0.5 if share else (float(finite.min() + finite.max()) / 2 if finite.size else 0.0)
        for i in range(ny):
            for j in range(nx):
                if np.isfinite(z[i, j]):
                    text = f"{100 * z[i, j]:.0f}%" if share else f"{z[i, j]:.3g}"
                    dark = z[i, j] < mid if not share else abs(z[i, j] - 0.5) > 0.3
                    ax.text(j, i, text, ha="center", va="center", fontsize=7, color="white" if dark else "black")
    return ax


def plot_distribution(
    values: ArrayLike, *, name: str = "", bins: int = 30, ax: Any | None = None
) -> Any:
    """Histogram of one result over the campaign's cases (non-finite values left out; their
    count is given in the title).

    Parameters
    ----------
    values
        (N,) values, NaN where a case has none.
    name
        The result's name (x label).
    bins
        Histogram bins (fewer when there are few distinct values).
    ax
        Axis to draw on; None: a new 5 x 3.5 inch figure.

    Returns
    -------
    The axis.
    """
    v = np.asarray(values, dtype=float)
    finite = v[np.isfinite(v)]
    ax = new_axes(ax, (5.0, 3.5))
    distinct = np.unique(finite).size
    ax.hist(finite, bins=max(1, min(bins, distinct)), color="tab:blue", edgecolor="white")
    ax.set_xlabel(name)
    ax.set_ylabel("cases")
    missing = v.size - finite.size
    ax.set_title(f"{name}: {finite.size} cases" + (f" ({missing} without a value)" if missing else ""), fontsize=9)
    return ax
