"""The ``[jump]`` table: the 001 task of a scenario and its checks."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from ..errors import JointlockError, ScenarioError
from ._task import CARTESIAN_FIELDS, cartesian_base, cartesian_fields, cartesian_given, in_table

#: JumpScenario fields a [jump] table may set.
JUMP_SCENARIO_FIELDS = (
    "q0_deg",
    "dx_m",
    "duration_s",
    "blend_s",
    "dt_s",
    "vmax_deg_s",
    "amax_deg_s2",
    "eps_m",
    "kp",
    "rest_transitions",
    "feedforward",
)


def jump_fields(out: Mapping[str, Any]) -> dict[str, Any]:
    """The 001 task of a resolved scenario in :func:`jointlock.planning.jump.scenario_from_mapping`
    form (limits fall back to ``[limits]``, the locking joint to ``failure.joint``; a Cartesian
    ``[task]`` gives the task itself and its base)."""
    j, lim = out["jump"], out["limits"]
    fields = {k: j[k] for k in JUMP_SCENARIO_FIELDS if j.get(k) is not None}
    if cartesian_given(out):
        fields = {k: v for k, v in fields.items() if k not in CARTESIAN_FIELDS}
        fields.update(cartesian_fields(out))
    for key, shared in (("vmax_deg_s", "vmax_deg"), ("amax_deg_s2", "amax_deg"), ("eps_m", "eps_m")):
        if key not in fields and lim.get(shared) is not None:
            fields[key] = lim[shared]
    if out["failure"]["joint"] is not None:
        fields["lock_joint"] = out["failure"]["joint"]
    fields["base"] = cartesian_base(out) if cartesian_given(out) else j["base"] or out["base"]
    return fields


def _check_jump(out: dict[str, Any], source: str, model: Any) -> None:
    from ..planning.jump import scenario_from_mapping

    j = out["jump"]
    if cartesian_given(out):
        twice = [k for k in CARTESIAN_FIELDS if j.get(k) is not None]
        if twice:
            raise ScenarioError(
                f"{source}: jump.{twice[0]} and the Cartesian [task] both give the task; give it once, in [task]"
            )
        time_s = out["failure"]["time_s"]
        if time_s is not None and (j["sweep"] is not None or (j["fail_at"] is not None and j["fail_at"] != time_s)):
            given = "jump.sweep" if j["sweep"] is not None else f"jump.fail_at = {j['fail_at']:g} s"
            raise ScenarioError(
                f"{source}: {given} with a Cartesian [task] and failure.time_s = {time_s:g} s: every job starts from "
                "the task at failure.time_s, the jump study too; leave it out (or leave out failure.time_s to sweep)"
            )
        task_base = (out.get("task") or {}).get("base")
        if j["base"] is not None and task_base is not None and j["base"] != task_base:
            raise ScenarioError(
                f"{source}: jump.base = {j['base']!r} but task.base = {task_base!r}: the jump study follows the "
                "task's resolved rates; give one base"
            )
    if j["fail_at"] is None and j["sweep"] is None and out["failure"]["time_s"] is not None:
        j["fail_at"] = out["failure"]["time_s"]
    if j["fail_at"] is not None and j["sweep"] is not None:
        raise ScenarioError(f"{source}: jump.fail_at (or failure.time_s) and jump.sweep exclude each other")
    if j["sweep"] is None and j["fail_at"] is None:
        j["sweep"] = 40
    try:
        sc = scenario_from_mapping(jump_fields(out), source=f"{source}: [jump]")
    except JointlockError as exc:
        raise in_table(exc, source, "jump") from None
    if len(sc.q0) != model.dof:
        raise ScenarioError(
            f"{source}: jump.q0_deg needs {model.dof} values (every joint of {model.name}); got {len(sc.q0)}"
        )
    if not 1 <= sc.lock_joint <= model.dof:
        raise ScenarioError(f"{source}: failure.joint must be 1..{model.dof}; got {sc.lock_joint}")
    if j["fail_at"] is not None and not j["fail_at"] < sc.duration:
        raise ScenarioError(
            f"{source}: jump.fail_at (failure.time_s) must lie in [0, {sc.duration:g}) s; got {j['fail_at']:g}"
        )
    cartesian = cartesian_given(out)
    for key, value in sc.to_fields().items():
        if key in JUMP_SCENARIO_FIELDS and j.get(key) is None and not (cartesian and key in CARTESIAN_FIELDS):
            j[key] = value  # the resolved scenario says every value it ran with (a Cartesian task's: in [task])
