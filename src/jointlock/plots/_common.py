"""How plot functions get their axes: the caller's, or new ones.

Every plot function of :mod:`jointlock.plots` takes ``ax=None`` (or ``fig=None`` for a figure
of several axes), draws on what it is given and returns it, the way pytransform3d's plotting
functions do.  Without one it makes a new figure through pyplot, so a notebook or a script
shows it with the user's own backend; nothing here ever calls ``matplotlib.use``.  Code that
only writes files (jobs, reports) passes an :func:`offscreen_figure`, which pyplot never sees
(no backend, no global figure list to close).
"""

from __future__ import annotations

from typing import Any


def offscreen_figure(figsize: tuple[float, float] = (7.0, 4.0)) -> Any:
    """A :class:`matplotlib.figure.Figure` outside pyplot, for writing files."""
    from matplotlib.figure import Figure

    return Figure(figsize=figsize)


def new_figure(fig: Any | None, figsize: tuple[float, float]) -> Any:
    """``fig`` if given, else a new pyplot figure of ``figsize`` [inch]."""
    if fig is not None:
        return fig
    import matplotlib.pyplot as plt

    return plt.figure(figsize=figsize)


def new_axes(ax: Any | None, figsize: tuple[float, float] = (7.0, 4.0), *, projection: str | None = None) -> Any:
    """``ax`` if given, else one axis on a new pyplot figure (``projection="3d"`` for 3-D)."""
    if ax is not None:
        return ax
    return new_figure(None, figsize).add_subplot(projection=projection)
