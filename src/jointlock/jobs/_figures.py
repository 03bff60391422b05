"""Each job's main figure, the one a notebook shows beside the summary
(:meth:`JobResult._repr_html_ <jointlock.jobs._common.JobResult._repr_html_>`): the halt's
global torque vs k (000 Fig. 8), the jump's joint rates (001 Fig. 6), the re-plan's tracking
errors (002 Figs. 13/19), the workspace projections, the halt configuration's first section
(000 Fig. 7), the tolerance angle's locked joint vs gamma (002 Figs. 5-6) and the singularity
search's sigma_min.  Drawn outside pyplot (no backend touched)."""

from __future__ import annotations

from typing import Any

from ..plots._common import offscreen_figure


def _halt(r: Any) -> Any:
    from ..plots.halt import plot_global_torque_vs_k

    fig = offscreen_figure((7, 4))
    plot_global_torque_vs_k(r.motion, ax=fig.add_subplot())
    return fig


def _jump(r: Any) -> Any:
    from ..plots.jump import plot_joint_rates

    r0, r1, t_fail = r.runs()
    return plot_joint_rates(r.model, r.task.lock_joint, r0, r1, t_fail, fig=offscreen_figure((10, 3.6)))


def _replan(r: Any) -> Any:
    from ..plots.replan import plot_replan_errors

    return plot_replan_errors(r.plan, fig=offscreen_figure((11, 4)))


def _workspace(r: Any) -> Any:
    from ..plots.workspace import plot_workspace_projections

    return plot_workspace_projections(r.full_points, r.locked_points, fig=offscreen_figure((14, 4.5)))


def _halt_config(r: Any) -> Any:
    from ..plots.halt_config import section_figures

    return section_figures(r.configuration)[0]


def _tolerance_angle(r: Any) -> Any:
    from ..plots.tolerance_angle import plot_locked_joint_vs_gamma

    fig = offscreen_figure((6, 4))
    plot_locked_joint_vs_gamma(r.sweep, r.joint, r.angle, ax=fig.add_subplot())
    return fig


def _search(r: Any) -> Any:
    from ..plots.singular import plot_search_sigma_min

    fig = offscreen_figure((7, 4))
    plot_search_sigma_min(r.model, r.search, ax=fig.add_subplot())
    return fig


_MAIN = {
    "HaltPlan": _halt,
    "JumpJobResult": _jump,
    "ReplanJobResult": _replan,
    "WorkspaceStudy": _workspace,
    "HaltConfigurationStudy": _halt_config,
    "ToleranceAngleResult": _tolerance_angle,
    "SingularitySearchResult": _search,
}


def main_figure(result: Any) -> Any | None:
    """The main figure of a job's result (a matplotlib Figure outside pyplot), or None for a
    result without one (kinematics, ik, reproduce, the singularity study at one q)."""
    draw = _MAIN.get(type(result).__name__)
    return None if draw is None else draw(result)
