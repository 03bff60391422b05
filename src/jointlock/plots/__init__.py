"""Figures of jointlock's results: one function per figure.

Each function takes ``ax=None`` (``fig=None`` for a figure of several axes), draws on it
(making a new pyplot figure when none is given) and returns what it drew.  Nothing here
chooses a plotting backend.  One module per job (``jl.plots.halt``, ``.halt_config``,
``.jump``, ``.tolerance_angle``, ``.replan``, ``.workspace``, ``.singular``), the arm in 3-D
(``.arm``) and a run report's summary figures (``.summary``); the functions are also reachable
from here (``jl.plots.plot_global_torque_vs_k``).  Modules are imported on first use.
"""

from __future__ import annotations

import importlib
from typing import Any

from ._common import new_axes, new_figure, offscreen_figure
from .arm import arm_figure, draw_arm, plot_arm, set_equal_3d

#: Figure functions of each job's module (imported on first use).
_FUNCTIONS: dict[str, tuple[str, ...]] = {
    "halt": ("global_torque_curve", "plot_global_torque_vs_k", "plot_joint_profiles", "plot_base_torque_vs_time"),
    "halt_config": ("plot_section", "section_figures"),
    "jump": (
        "plot_objective_vs_kappa",
        "plot_joint_rates",
        "plot_position_deviation",
        "plot_kappa_fit",
        "plot_jump_vs_failure_time",
    ),
    "tolerance_angle": ("plot_joints_vs_gamma", "plot_locked_joint_vs_gamma"),
    "replan": ("plot_replan_joints", "plot_replan_pose", "plot_replan_errors", "plot_replan_velocity"),
    "workspace": (
        "plot_workspace_projection",
        "plot_workspace_projections",
        "plot_workspace_cloud",
        "plot_workspace_clouds",
    ),
    "singular": ("plot_search_sigma_min", "plot_singular_families", "plot_family_joint_angles"),
    "summary": ("plot_jump_before_after", "plot_halt_base_torque", "plot_replan_error"),
}
_WHERE = {name: module for module, names in _FUNCTIONS.items() for name in names}
_MODULES = (*_FUNCTIONS, "arm")


def __getattr__(name: str) -> Any:
    if name in _MODULES:
        return importlib.import_module(f"{__name__}.{name}")
    if name in _WHERE:
        return getattr(importlib.import_module(f"{__name__}.{_WHERE[name]}"), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_MODULES) | set(_WHERE))


__all__ = ["arm_figure", "draw_arm", "new_axes", "new_figure", "offscreen_figure", "plot_arm", "set_equal_3d", *_WHERE]
