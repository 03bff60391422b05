"""Figures of jointlock's results: one function per figure.

Each function takes ``ax=None`` (``fig=None`` for a figure of several axes), draws on it
(making a new pyplot figure when none is given) and returns what it drew.  Nothing here
chooses a plotting backend.
"""

from ._common import new_axes, new_figure, offscreen_figure
from .arm import arm_figure, draw_arm, plot_arm, set_equal_3d

__all__ = ["arm_figure", "draw_arm", "new_axes", "new_figure", "offscreen_figure", "plot_arm", "set_equal_3d"]
