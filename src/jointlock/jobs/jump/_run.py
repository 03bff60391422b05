"""The velocity-jump study as one call: :func:`run_jump_study` (one of the three modes of
``jointlock jump``), its input checks and defaults, and the ``[jump]`` job of a scenario
(:func:`jump_from_scenario`)."""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any, Literal

import numpy as np

from ...errors import ScenarioError
from ...model import ArmModel
from ...planning.jump import JumpScenario, jump_at_time, scenario_from_mapping, study_jump, verify_kappa
from ...plots.jump import KAPPA_UNIT
from ...progress import Progress
from .._common import JobResult
from ._result import JumpJobResult

#: Largest polynomial order of kappa(t) (the scenario schema's ``jump.order`` cap).
MAX_ORDER = 9

#: Default number of sampled failure times of the sweep (001: 40).
DEFAULT_SWEEP = 40
#: Default polynomial order of kappa(t) (001: 5).
DEFAULT_ORDER = 5

Fix = Literal["auto", "clip", "ramp", "clip+ramp"]


def run_jump_study(
    model: ArmModel,
    task: JumpScenario | None = None,
    *,
    fail_at: float | None = None,
    sweep: int = DEFAULT_SWEEP,
    kappa: float | None = None,
    order: int = DEFAULT_ORDER,
    fix: Fix | None = "auto",
    single: bool = False,
    progress: bool = False,
    on_infeasible: Literal["raise", "report"] = "raise",
) -> JumpJobResult:
    """The velocity jump of seed 001 when ``task.lock_joint`` locks (``jointlock jump``).

    Parameters
    ----------
    model
        The arm, ``model.dof`` movable joints (free-floating when ``task.base == "floating"``).
    task
        Start, straight line, timing, the joint that locks, limits, gain
        (:class:`~jointlock.planning.jump.JumpScenario`; NOTES-001's task when omitted).
    fail_at
        One failure time [s] in ``[0, task.duration)`` (mode ``fail_at``); ``None``: the sweep,
        or the constant kappa verified at every step when ``kappa`` is given.
    sweep
        Number of sampled failure times of the sweep (>= 1; used without ``fail_at`` and
        ``kappa``).
    kappa
        A constant kappa [rad^2/(s m^3)] instead of the search (with ``fail_at``: the jump at
        that time with it; without: mode ``constant``).
    order
        Polynomial order of kappa(t), 1..:data:`MAX_ORDER` (sweep with the search only).
    fix
        Fix of kappa(t) verified as well: ``"auto"`` (``"clip+ramp"`` only when kappa(t) breaks a
        limit), ``"clip"``, ``"ramp"``, ``"clip+ramp"`` or ``None`` (sweep with the search only).
    single
        One polynomial for kappa(t) (001's form) instead of one piece per branch of the optimum
        (sweep with the search only).
    progress
        Show progress bars on stderr (when it is a terminal).
    on_infeasible
        ``fail_at`` with the search: when no kappa keeps every limit, ``"raise"``
        (:class:`~jointlock.errors.InfeasibleError`) or ``"report"`` (the uncompensated jump,
        the reason in :attr:`~jointlock.planning.jump.JumpAtTime.infeasible`; an audit's cells).

    Returns
    -------
    JumpJobResult
        Its ``mode`` says which of the three ran.
    """
    sc = JumpScenario() if task is None else task
    _check_inputs(model, sc, fail_at=fail_at, sweep=sweep, kappa=kappa, order=order, fix=fix)

    def bar(total: int, desc: str) -> Progress:
        return Progress(total, desc, enabled=None if progress else False)

    given = None if kappa is None else float(kappa)
    if fail_at is not None:
        p = bar(sc.n_steps, "kappa search")  # the grid pass updates once per control step
        res = jump_at_time(model, sc, fail_at, kappa=given, progress=p, on_infeasible=on_infeasible)
        p.close()
        return JumpJobResult("fail_at", model, sc, at_time=res, kappa=given)
    if given is not None:
        ver = verify_kappa(model, sc, given)
        return JumpJobResult("constant", model, sc, verification=ver, kappa=given)
    study = study_jump(
        model,
        sc,
        n_samples=sweep,
        order=order,
        fix=fix,
        fit_options={"piecewise": not single},
        progress_factory=bar if progress else None,
    )
    return JumpJobResult("sweep", model, sc, study=study, verification=study.verification)


def _check_inputs(
    model: ArmModel,
    sc: JumpScenario,
    *,
    fail_at: float | None,
    sweep: int,
    kappa: float | None,
    order: int,
    fix: str | None,
) -> None:
    if len(sc.q0) != model.dof:
        raise ScenarioError(
            f"task.q0 has {len(sc.q0)} angles but model {model.name!r} has {model.dof} movable joints "
            f"{list(model.joint_numbers)}"
        )
    if kappa is not None and not math.isfinite(kappa):
        raise ScenarioError(f"kappa must be a finite number [{KAPPA_UNIT}]; got {kappa!r}")
    if fail_at is not None and not math.isfinite(fail_at):
        raise ScenarioError(f"fail_at must be a finite failure time [s]; got {fail_at!r}")
    if isinstance(sweep, bool) or not isinstance(sweep, (int, np.integer)) or sweep < 1:
        raise ScenarioError(f"sweep must be an integer >= 1; got {sweep!r}")
    if isinstance(order, bool) or not isinstance(order, (int, np.integer)) or not 1 <= order <= MAX_ORDER:
        raise ScenarioError(f"order must be an integer 1..{MAX_ORDER}; got {order!r}")
    if fix not in (None, "auto", "clip", "ramp", "clip+ramp"):
        raise ScenarioError(f"fix must be None, 'auto', 'clip', 'ramp' or 'clip+ramp'; got {fix!r}")


def jump_from_scenario(
    data: Mapping[str, Any], previous: Mapping[str, JobResult], *, progress: bool = False
) -> JumpJobResult:
    """Run the ``[jump]`` job of a resolved ``jointlock run`` scenario (``Scenario.data``).

    The task is :func:`jointlock.scenario.jump_fields` of ``data`` (limits from ``[limits]``, the
    locking joint from ``failure.joint``, the base from ``jump.base`` else the top level); the
    mode from ``jump.fail_at`` / ``jump.kappa`` / ``jump.sweep`` (with ``jump.order`` and
    ``jump.fix`` for the sweep), as ``jointlock run`` has always run ``jointlock jump``.
    ``previous`` is not used (the job needs no earlier result).
    """
    from ...robots import UrdfChain, load_robot
    from ...scenario import jump_fields

    del previous
    t = data["jump"]
    sc = task_as_the_command_reads_it(scenario_from_mapping(jump_fields(data), source="[jump]"))
    model = load_robot(data["robot"], base=sc.base, chain=UrdfChain.from_fields(data))
    if t["fail_at"] is not None:
        return run_jump_study(
            model, sc, fail_at=t["fail_at"], kappa=t["kappa"], progress=progress, on_infeasible=t["on_infeasible"] or "raise"
        )
    if t["kappa"] is not None:
        return run_jump_study(model, sc, kappa=t["kappa"], progress=progress)
    fix = None if t["fix"] == "none" else t["fix"]
    return run_jump_study(model, sc, sweep=t["sweep"], order=t["order"], fix=fix, progress=progress)


def task_as_the_command_reads_it(task: JumpScenario) -> JumpScenario:
    """``task`` passed once through its file form (:meth:`JumpScenario.to_fields`, degrees) and
    back, as ``jointlock jump`` reads every task; converting radians -> degrees -> radians can
    move an angle or a limit by one unit in the last place, and once through it is stable."""
    return scenario_from_mapping(task.to_fields(), source="task")
