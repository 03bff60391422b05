"""Replaying what the jobs produce: a halt (:func:`replay_halt`, free or held), the jump
study's two runs (:func:`replay_jump`), a re-plan (:func:`replay_replan`), every one of a run
(:func:`replay_jobs`), and the halt's attitude figure with the simulator's trace
(:func:`write_attitude_with_replay`)."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

from ..errors import ConfigurationError
from ..io.files import write_figure
from ..mjcf import TIMESTEP_S
from ._motions import TRACKING_RAD_S, replay_motion, replay_steps, replay_waypoints
from ._replay import Replay

#: The jobs whose motion :func:`replay_jobs` plays.
REPLAYED_JOBS = ("halt", "jump", "replan")


def replay_jobs(jobs: Mapping[str, Any], *, timestep: float = TIMESTEP_S) -> dict[str, Replay]:
    """Replay every motion among a run's typed job results (``{job: result}``) that MuJoCo can
    play (:data:`REPLAYED_JOBS`): ``{key: Replay}``.  A halt whose torques hold the spacecraft
    (000's reading) on a model with one is played twice: free (``"halt"``: the attitude, the
    drift) and held (``"halt_held"``: the brake torque 000's reading gives); the jump study's
    two runs are ``"jump_uncompensated"`` and ``"jump_compensated"``; the re-plan ``"replan"``."""
    out: dict[str, Replay] = {}
    if "halt" in jobs:
        plan = jobs["halt"]
        out["halt"] = replay_halt(plan, timestep=timestep)
        if plan.problem.model.floating and plan.problem.base == "fixed":  # 000's torques: the spacecraft held
            out["halt_held"] = replay_halt(plan, timestep=timestep, base="fixed")
    if "jump" in jobs:
        out.update(replay_jump(jobs["jump"], timestep=timestep))
    if "replan" in jobs and jobs["replan"].model is not None:
        out["replan"] = replay_replan(jobs["replan"], timestep=timestep)
    return out


def replay_jump(result: Any, *, timestep: float = TIMESTEP_S) -> dict[str, Replay]:
    """The jump study's two runs (:meth:`~jointlock.jobs.JumpJobResult.runs`: without and with
    the compensation, the joint locking at the failure instant) played with
    :func:`replay_steps`: ``{"jump_uncompensated": ..., "jump_compensated": ...}``."""
    r0, r1, _ = result.runs()
    return {
        f"jump_{key}": replay_steps(
            result.model,
            run.t,
            run.q,
            run.qd,
            [(int(j), float(t)) for j, t, _ in run.failures],
            label=f"jump, {label}",
            timestep=timestep,
        )
        for key, label, run in (("uncompensated", "kappa = 0", r0), ("compensated", "compensated", r1))
    }


def replay_replan(result: Any, *, timestep: float = TIMESTEP_S) -> Replay:
    """The re-planned waypoints (:class:`~jointlock.jobs.ReplanJobResult`'s ``plan.times`` and
    ``plan.q``) joined by a cubic spline and played with :func:`replay_waypoints`."""
    if result.model is None:
        raise ConfigurationError("this re-plan result has no model to replay (built without one)")
    return replay_waypoints(result.model, result.plan.times, result.plan.q, label="re-plan", timestep=timestep)


def replay_halt(
    plan: Any, *, timestep: float = TIMESTEP_S, tracking: float = TRACKING_RAD_S, base: str | None = None
) -> Replay:
    """Replay a :class:`~jointlock.jobs.HaltPlan`'s halt motion (its polynomial ``q(t)``, exact at
    every step) in MuJoCo.  ``base=None``: the spacecraft free when the plan's model floats,
    whatever base the plan's torques were computed with (000 holds it; the free replay shows what
    a free one does, as :meth:`~jointlock.jobs.HaltPlan.spacecraft_response` does); ``"fixed"``:
    held, the reading of 000's torques (its brake torque is
    :meth:`~jointlock.jobs.HaltPlan.actuator_loads`'s)."""
    problem = plan.problem
    held = base == "fixed" or not problem.model.floating
    return replay_motion(
        problem.model,
        plan.motion.trajectory,
        float(problem.T),
        label="halt, spacecraft held" if held else "halt, spacecraft free",
        timestep=timestep,
        tracking=tracking,
        base=base,
    )


def write_attitude_with_replay(plan: Any, replay: Replay, folder: str | Path) -> None:
    """Write a :class:`~jointlock.jobs.HaltPlan`'s ``spacecraft_attitude.png`` (and .svg) into
    ``folder`` again, with the replay's spacecraft (MuJoCo's) dashed on top (issue 30); nothing
    for a held spacecraft."""
    if replay.simulated_response() is None:
        return
    response = plan.spacecraft_response()
    if response is None:
        return
    from ..plots._common import offscreen_figure
    from ..plots.halt import plot_spacecraft_response

    fig = plot_spacecraft_response(response, fig=offscreen_figure((7, 4)), simulated=replay.simulated_response())
    write_figure(fig, Path(folder), "spacecraft_attitude.png")
