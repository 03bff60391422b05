"""Figures of jointlock's results: one function per figure.

Each function takes ``ax=None`` (``fig=None`` for a figure of several axes), draws on it
(making a new pyplot figure when none is given) and returns what it drew.  Nothing here
chooses a plotting backend.  One module per job (``jl.plots.halt``, ``.halt_config``,
``.jump``, ``.tolerance_angle``, ``.replan``, ``.workspace``, ``.singular``), the arm in 3-D
(``.arm``), the interactive animated 3-D view (``.animation``, plotly.js, of
``.motion.ArmMotion``), a run report's summary figures (``.summary``) and a failure campaign's
heatmaps and distributions (``.campaign``); the functions are also reachable
from here (``jl.plots.plot_global_torque_vs_k``).  Modules are imported on first use.
"""

from __future__ import annotations

from .._lazy import lazy_attributes
from ._common import new_axes, new_figure, offscreen_figure
from .arm import arm_figure, draw_arm, plot_arm, set_equal_3d

#: Figure functions of each job's module (imported on first use).
_FUNCTIONS: dict[str, tuple[str, ...]] = {
    "halt": (
        "global_torque_curve",
        "plot_global_torque_vs_k",
        "plot_joint_profiles",
        "plot_base_torque_vs_time",
        "plot_clearance",
    ),
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
    "singular": ("plot_search_sigma_min", "plot_singular_families", "plot_family_joint_angles", "plot_condition_checks"),
    "summary": ("plot_jump_before_after", "plot_halt_base_torque", "plot_replan_error"),
    "campaign": ("plot_heatmap", "plot_distribution"),
    "animation": ("animation_figure", "animation_html", "standalone_html", "write_animation_html"),
    "motion": ("ArmMotion", "motion_points"),
}
_WHERE = {name: module for module, names in _FUNCTIONS.items() for name in names}
_MODULES = (*_FUNCTIONS, "arm")


__getattr__, __dir__ = lazy_attributes(
    __name__, {name: f"{__name__}.{module}" for name, module in _WHERE.items()}, _MODULES, globals()
)


__all__ = ["arm_figure", "draw_arm", "new_axes", "new_figure", "offscreen_figure", "plot_arm", "set_equal_3d", *_WHERE]
