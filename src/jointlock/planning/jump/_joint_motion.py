"""001's Cartesian task as a planned joint motion (issue 28, item 1: "a Cartesian path followed
by resolved rates (001's task, which becomes one kind of ``[task]``)").

The healthy arm follows the task's straight line by resolved rates (:func:`~._simulate.simulate`
without a failure, ``kappa = 0``: the rates 001 commands before any lock); its joint angles at
every control step, joined by a cubic spline, are a sampled :class:`~jointlock.planning.task.Task`
like a CSV trajectory file's.  So every job can start from "the plan at t" of 001's task: the halt
from the arm moving along the line, the audit at every instant, and the jump study of the same
task at the same failure times.

``examples/audit_canadarm7_motion.csv`` was written from the same run: the task read from it and
the one computed here agree to its printed digits (5e-11 deg, ``tests/test_cartesian_task.py``).
"""

from __future__ import annotations

from ..._cache import cached_on
from ...model import ArmModel
from ..task import Task
from ._simulate import simulate
from ._task import JumpScenario

__all__ = ["cartesian_task"]


def cartesian_task(model: ArmModel, scenario: JumpScenario) -> Task:
    """The joint motion of 001's task ``scenario`` on ``model`` without a failure: the angles
    (N + 1, n) [rad] at the control steps ``0, dt, ..., T`` [s], joined by a cubic spline.

    ``model`` must have every joint (none locked) and the base ``scenario.base`` asks for (a
    free-floating model for ``"floating"``).  Computed once per model and task."""

    def run() -> Task:
        nominal = simulate(model, scenario)
        line = ", ".join(f"{v:g}" for v in scenario.dx)
        source = (
            f"001's Cartesian task (a straight line of [{line}] m in {scenario.duration:g} s by resolved rates at "
            f"{scenario.dt:g} s steps, {scenario.base} base)"
        )
        return Task(nominal.t, nominal.q, "samples", "spline", source)

    return cached_on(model, f"cartesian_task {scenario!r}", run)
