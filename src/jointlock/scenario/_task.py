"""The ``[task]`` table (issue 28): a planned motion, and the state at failure taken from it at
``[failure] time_s`` (the joint locks at the angle the task has it then).

Three kinds: a joint trajectory file (``file``), waypoints with durations (``waypoints_deg``,
``durations_s``), or 001's Cartesian task (``dx_m`` from ``q0_deg``, with ``duration_s``,
``blend_s``, ``dt_s``, ``kp``, ``feedforward``, ``base``: the fields of a ``[jump]`` table), which
the healthy arm follows by resolved rates (:func:`jointlock.planning.jump.cartesian_task`).  With a
Cartesian task the jump study follows that task (its ``[jump]`` table then gives no task fields).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from ..bounds import shown
from ..errors import JointlockError, ScenarioError
from ..io.files import check_path_text
from ..planning.task import Task, load_task_file

#: Decimal places [deg, deg/s, deg/s^2] the state taken from a task is rounded to.
ROUND_DEG = 9


#: The fields of a Cartesian ``[task]`` (001's task: :class:`~jointlock.planning.jump.JumpScenario`'s).
CARTESIAN_FIELDS = ("q0_deg", "dx_m", "duration_s", "blend_s", "dt_s", "kp", "feedforward")


def task_given(out: Mapping[str, Any]) -> bool:
    """Whether the scenario has a planned motion."""
    t = out.get("task") or {}
    return t.get("file") is not None or t.get("waypoints_deg") is not None or t.get("dx_m") is not None


def cartesian_given(out: Mapping[str, Any]) -> bool:
    """Whether the scenario's task is 001's Cartesian task (``task.dx_m``)."""
    return (out.get("task") or {}).get("dx_m") is not None


def cartesian_base(out: Mapping[str, Any]) -> str:
    """The base of a Cartesian task's resolved rates: ``task.base``, else ``jump.base``, else the
    top-level base."""
    return str((out.get("task") or {}).get("base") or (out.get("jump") or {}).get("base") or out["base"])


def cartesian_fields(out: Mapping[str, Any]) -> dict[str, Any]:
    """A Cartesian task's fields in :func:`jointlock.planning.jump.scenario_from_mapping` form."""
    t = out["task"]
    return {**{k: t[k] for k in CARTESIAN_FIELDS if t.get(k) is not None}, "base": cartesian_base(out)}


def resolve_task_file(out: dict[str, Any], source: str, base_dir: Path) -> None:
    """``task.file`` as an absolute path (relative to the scenario's folder), checked to exist."""
    name = (out.get("task") or {}).get("file")
    if name is None:
        return
    check_path_text(name, f"{source}: task.file", ScenarioError)
    path = Path(name)
    if not path.is_absolute():
        path = (base_dir / path).resolve()
    if not path.is_file():
        raise ScenarioError(f"{source}: task.file {shown(name)} not found (looked for {path})")
    out["task"]["file"] = str(path)


def scenario_task(out: dict[str, Any], source: str = "scenario") -> Task | None:
    """The :class:`~jointlock.planning.task.Task` of a resolved scenario, or None."""
    t = out.get("task") or {}
    if t.get("dx_m") is not None:
        return _cartesian_task(out, source)
    cartesian_only = [k for k in (*CARTESIAN_FIELDS, "base") if t.get(k) is not None]
    if cartesian_only:
        raise ScenarioError(
            f"{source}: task.{cartesian_only[0]} belongs to a Cartesian task: give task.dx_m (the straight line) "
            "too, or leave it out"
        )
    if t.get("file") is not None:
        if t.get("waypoints_deg") is not None or t.get("durations_s") is not None:
            raise ScenarioError(f"{source}: task.file and task.waypoints_deg exclude each other; give one")
        return load_task_file(t["file"])
    if t.get("waypoints_deg") is None:
        if t.get("durations_s") is not None:
            raise ScenarioError(f"{source}: task.durations_s needs task.waypoints_deg")
        return None
    if t.get("durations_s") is None:
        raise ScenarioError(f"{source}: task.waypoints_deg needs task.durations_s (one per segment)")
    return Task.from_waypoints(t["waypoints_deg"], t["durations_s"], t["scaling"], source=f"{source}: [task]")


def in_table(exc: JointlockError, source: str, table: str) -> JointlockError:
    """``exc`` raised while reading the scenario's ``[table]``: as it is when it names ``source``
    already, else a :class:`~jointlock.errors.ScenarioError` saying where (one line)."""
    return exc if str(exc).startswith(source) else ScenarioError(f"{source}: [{table}]: {exc}")


def _cartesian_task(out: dict[str, Any], source: str) -> Task:
    """001's Cartesian task of the scenario as a joint motion (the arm loaded with the task's base)."""
    from ..planning.jump import cartesian_task, scenario_from_mapping
    from ..robots import UrdfChain, load_robot

    t = out["task"]
    others = [k for k in ("file", "waypoints_deg", "durations_s") if t.get(k) is not None]
    if others:
        raise ScenarioError(f"{source}: task.dx_m (a Cartesian task) and task.{others[0]} exclude each other; give one")
    if t.get("q0_deg") is None:
        raise ScenarioError(f"{source}: task.dx_m needs task.q0_deg (where the task starts, every joint of the arm)")
    try:
        task = scenario_from_mapping(cartesian_fields(out), source=f"{source}: [task]")
        model = load_robot(out["robot"], base=task.base, chain=UrdfChain.from_fields(out))
    except JointlockError as exc:
        raise in_table(exc, source, "task") from None
    if len(task.q0) != model.dof:
        raise ScenarioError(
            f"{source}: task.q0_deg needs {model.dof} values (every joint of {model.name}); got {len(task.q0)}"
        )
    return cartesian_task(model, task)


def state_from_task(out: dict[str, Any], jobs: tuple[str, ...], source: str, model: Any) -> None:
    """With a ``[task]``: check it against the arm, and with ``failure.time_s`` fill the state at
    failure (the healthy joints' angles, rates and accelerations of the task then) and the locked
    angle (the task's), in place.  A ``[state]`` given too, an angle that disagrees with the
    task's, a time past the task's end: one line each."""
    task = scenario_task(out, source)
    if task is None:
        return
    task.check(model)
    fail = out["failure"]
    time_s = fail["time_s"]
    if "jump" in jobs and not cartesian_given(out):
        raise ScenarioError(
            f"{source}: [task] is a planned joint motion; the jump study follows a Cartesian task (task.dx_m, or its own "
            "[jump]): run them in separate scenarios"
        )
    if time_s is None:
        if cartesian_given(out) and set(jobs) <= {"jump"}:
            return  # the jump study alone: it sweeps the failure times itself
        raise ScenarioError(
            f"{source}: [task] needs failure.time_s (the instant the joint locks, in [{task.start:g}, {task.end:g}] s)"
        )
    if not task.start <= time_s <= task.end:
        raise ScenarioError(
            f"{source}: failure.time_s = {time_s:g} s is outside the task, [{task.start:g}, {task.end:g}] s"
        )
    given = [k for k in ("q0_deg", "dq0_deg", "ddq0_deg") if out["state"][k] is not None]
    if given:
        raise ScenarioError(
            f"{source}: state.{given[0]} and [task] with failure.time_s both give the state at failure; give one "
            "(the task's state at that instant, or [state] without a task)"
        )
    # to 1e-9 deg: the spline reproduces its samples to round-off (a rate sampled at exactly a
    # limit, 000's 40 deg/s, must not come back 1e-13 above it)
    q, dq, ddq = (np.round(np.degrees(v), ROUND_DEG) for v in task.state(float(time_s)))
    locks = {int(j): float(a) for j, a in (fail.get("also_locked_deg") or {}).items()}
    if fail["joint"] is not None:
        j = int(fail["joint"])
        if not 1 <= j <= model.dof:
            return  # the joint number's own check names it
        if fail["angle_deg"] is None:
            fail["angle_deg"] = float(q[j - 1])
        elif not math.isclose(fail["angle_deg"], q[j - 1], abs_tol=1e-6):
            raise ScenarioError(
                f"{source}: failure.angle_deg = {fail['angle_deg']:g} but the task has joint {j} at {q[j - 1]:.6g} deg "
                f"at t = {time_s:g} s; drop failure.angle_deg (the joint locks where the task has it)"
            )
        locks[j] = float(fail["angle_deg"])
    for j, angle in locks.items():
        if 1 <= j <= model.dof and not math.isclose(q[j - 1], angle, abs_tol=1e-6):
            raise ScenarioError(
                f"{source}: failure.also_locked_deg.{j} = {angle:g} but the task has joint {j} at {q[j - 1]:.6g} deg at "
                f"t = {time_s:g} s: a joint locked before the failure cannot move in the task"
            )
    healthy = [k for k in range(model.dof) if k + 1 not in locks]
    out["state"]["q0_deg"] = [float(q[k]) for k in healthy]
    out["state"]["dq0_deg"] = [float(dq[k]) for k in healthy]
    out["state"]["ddq0_deg"] = [float(ddq[k]) for k in healthy]
    if "replan" in jobs and out["replan"]["from_deg"] is None:
        out["replan"]["from_deg"] = [float(v) for v in q]
