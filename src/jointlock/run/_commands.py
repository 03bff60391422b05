"""The equivalent command line of each job of a scenario, for people to reproduce one job on
its own (recorded in results.json and shown in the report).

Nothing runs through these: :func:`jointlock.run.run_scenario` calls the library directly.
They are formed from the resolved scenario the way ``jointlock COMMAND`` reads its options, so
that running the printed command gives the same result.
"""

from __future__ import annotations

import shlex
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from ..io.files import toml_document
from ..robots import UrdfChain, load_robot
from ..scenario import JOB_ORDER, Scenario, job_lock_args, jump_fields

#: Subcommand name of each job.
JOB_COMMAND = {job: job.replace("_", "-") for job in JOB_ORDER}


def _num(v: float) -> str:
    return repr(float(v))


def _nums(values: list[float]) -> list[str]:
    return [_num(v) for v in values]


def _healthy_rates(scenario: Scenario, values: list[float]) -> list[float]:
    """A rate or acceleration vector of the state for the command line: the healthy joints'
    entries (a full-arm vector's locked entry is 0, checked when the scenario was loaded)."""
    locked = set(scenario.locks)
    if not locked:
        return values
    full = load_robot(scenario.data["robot"], base="fixed", chain=UrdfChain.from_fields(scenario.data))
    if len(values) != full.dof:
        return values
    return [v for i, v in enumerate(values) if i + 1 not in locked]


def _chain_args(data: Mapping[str, Any]) -> list[str]:
    """``--root``, ``--tip`` and ``--freeze`` for a scenario naming the chain of a URDF robot
    (every command taking ROBOT has them; ``--freeze`` values in the joint's unit, as given)."""
    chain = UrdfChain.from_fields(data)
    if chain is None:
        return []
    argv = ["--root", chain.root_link] if chain.root_link else []
    argv += ["--tip", chain.tip_link] if chain.tip_link else []
    for name, value in (*chain.freeze_deg, *chain.freeze_m):
        argv += ["--freeze", f"{name}={_num(value)}"]
    argv += ["--srdf", chain.srdf] if chain.srdf else []
    argv += ["--meshes", chain.meshes] if chain.meshes else []
    return argv


def _clearance_args(lim: Mapping[str, Any], keep_out: Any = None, out: Path | None = None) -> list[str]:
    """``--clearance-min-m`` / ``--no-clearance`` of ``[limits]`` (none when at the defaults), and
    ``--keep-out OUT/keep_out.toml`` when the scenario has ``[[keep_out]]`` (written with the run:
    :func:`keep_out_toml`)."""
    argv = ["--clearance-min-m", _num(lim["clearance_min_m"])] if lim.get("clearance_min_m") is not None else []
    argv += ["--keep-out", str(out / KEEP_OUT_FILE)] if keep_out and out is not None else []
    return argv + (["--no-clearance"] if lim.get("check_clearance") is False else [])


#: The file of a run's keep-out volumes, for its equivalent commands.
KEEP_OUT_FILE = "keep_out.toml"


def keep_out_toml(scenario: Scenario) -> str:
    """The scenario's ``[[keep_out]]`` entries as a TOML file ``--keep-out`` reads."""
    return toml_document({"keep_out": list(scenario.data.get("keep_out") or [])})


def job_argv(
    job: str, scenario: Scenario, out: Path, previous: Mapping[str, dict], *, quiet: bool
) -> list[str]:  # one branch per job: the options of seven subcommands
    """The command line (argv, without ``jointlock``) of ``job`` formed from the resolved
    scenario; ``previous`` holds the result dictionaries of the jobs run before it.  The jump
    job's task file is ``out/jump/task.toml`` (:func:`jump_task_toml`, written with the run)."""
    d = scenario.data
    t = d[job]
    robot, seed = d["robot"], d["seed"]
    st, lim = d["state"], d["limits"]
    job_out = str(out / job)
    argv = [JOB_COMMAND[job], robot, *_chain_args(d)]
    if job == "halt_config":
        argv += job_lock_args(scenario) + ["--base", t["base"] or d["base"]]
        argv += ["--samples", str(t["samples"]), "--seed", str(seed), "--jacobian", t["jacobian"]]
        argv += ["--assignment", t["assignment"]]
        argv += ["--renormalize"] if t["renormalize"] else []
        argv += ["--no-refine"] if t["no_refine"] else []
        argv += ["--length", _num(t["length"])] if t["length"] is not None else []
        if t["reachable"]:
            argv += ["--from-q-deg", *_nums(st["q0_deg"])]
            argv += ["--from-dq-deg", *_nums(_healthy_rates(scenario, st["dq0_deg"]))] if st["dq0_deg"] else []
            argv += ["--from-ddq-deg", *_nums(_healthy_rates(scenario, st["ddq0_deg"]))] if st["ddq0_deg"] else []
            halt_time = t["halt_time"] if t["halt_time"] is not None else d["halt"]["T"]
            argv += ["--halt-time", _num(halt_time)]
        for key in ("vmax_deg", "amax_deg"):
            if lim[key] is not None:
                argv += [f"--{key.replace('_', '-')}", _num(lim[key])]
        argv += _clearance_args(lim, d.get("keep_out"), out)
        argv += ["--json", "--out", job_out] + (["--quiet"] if quiet else [])
    elif job == "halt":
        argv += job_lock_args(scenario) + ["--base", t["base"] or d["base"]]
        for key in ("q0_deg", "dq0_deg", "ddq0_deg"):
            values = st[key] if key == "q0_deg" else _healthy_rates(scenario, st[key])
            argv += [f"--{key.replace('_', '-')}", *_nums(values)]
        argv += ["--T", _num(t["T"])]
        if t["qf_deg"] is not None:
            argv += ["--qf-deg", *_nums(t["qf_deg"])]
        elif t["paper_qf"]:
            argv += ["--paper-qf"]
        elif "halt_config" in previous:
            argv += ["--qf-deg", *_nums(previous["halt_config"]["best"]["q_deg"])]
        for key in ("vmax_deg", "amax_deg"):
            if lim[key] is not None:
                argv += [f"--{key.replace('_', '-')}", _num(lim[key])]
        for key, option in (("torque_max_Nm", "--torque-max-Nm"), ("brake_max_Nm", "--brake-max-Nm")):
            argv += [option, _num(lim[key])] if lim.get(key) is not None else []
        argv += _clearance_args(lim, d.get("keep_out"), out)
        for key, option in (("wheel_torque_max_Nm", "--wheel-torque-max-Nm"), ("wheel_momentum_max_Nms", "--wheel-momentum-max-Nms")):
            argv += [option, _num(d["spacecraft"][key])] if d["spacecraft"].get(key) is not None else []
        argv += ["--solver", t["solver"], "--seed", str(seed), "--samples", str(t["samples"])]
        argv += ["--n-samples", str(t["n_samples"]), "--generations", str(t["generations"])]
        argv += ["--population", str(t["population"])] + (["--minimum-T"] if t["minimum_T"] else [])
        argv += ["--moment-about", t["moment_about"]] if t["moment_about"] != "spacecraft_com" else []
        argv += ["--margin", _num(t["margin"])] if t["margin"] else []
        argv += ["--objective", t["objective"]] if t["objective"] != "mean_torque" else []
        argv += ["--prefer-margin", _num(t["prefer_margin"])] if t["prefer_margin"] else []
        argv += ["--json", "--out", job_out] + (["--quiet"] if quiet else [])
    elif job == "jump":
        fields = jump_fields(d)
        task = out / "jump" / "task.toml"
        argv += ["--base", fields["base"], "--scenario", str(task)]
        if "lock_joint" in fields:
            argv += ["--lock", str(fields["lock_joint"])]
        # only the options the mode uses (the command warns about the others)
        if t["fail_at"] is not None:
            argv += ["--fail-at", _num(t["fail_at"])]
            argv += ["--on-infeasible", t["on_infeasible"]] if t["on_infeasible"] == "report" else []
        elif t["kappa"] is None:
            argv += ["--sweep", str(t["sweep"])]
        if t["kappa"] is not None:
            argv += ["--kappa", _num(t["kappa"])]
        elif t["fail_at"] is None:
            argv += ["--order", str(t["order"]), "--fix", t["fix"]]
        argv += ["--json", "--out", job_out]
        argv += ["--quiet"] if quiet else []
    elif job == "tolerance_angle":
        argv += job_lock_args(scenario) + ["--base", d["base"], "--q-target-deg", *_nums(t["q_target_deg"])]
        argv += ["--gamma-limit-deg", _num(t["gamma_limit_deg"]), "--zoom-deg", _num(t["zoom_deg"])]
        argv += ["--step-deg", _num(t["step_deg"]), "--json", "--out", job_out]
    elif job == "replan":
        argv += job_lock_args(scenario) + ["--base", d["base"]]
        argv += ["--from-deg", *_nums(t["from_deg"]), "--to-deg", *_nums(t["to_deg"])]
        argv += ["--steps", str(t["steps"]), "--cycle", _num(t["cycle"])]
        argv += ["--tolerance-deg", _num(t["tolerance_deg"]), "--json", "--out", job_out]
    elif job == "workspace":
        argv += job_lock_args(scenario) + ["--base", d["base"], "--samples", str(t["samples"])]
        argv += ["--voxel", _num(t["voxel"])] if t["voxel"] is not None else []
        argv += ["--seed", str(seed), "--json", "--out", job_out]
    elif job == "singular":
        argv += job_lock_args(scenario)
        argv += ["--base", t["base"]] if t["base"] else []  # inherited from the top level when given
        argv += ["--weighting", t["weighting"], "--tol", _num(t["tol"]), "--seed", str(seed)]
        argv += ["--q-deg", *_nums(t["q_deg"])] if t["q_deg"] is not None else []
        argv += ["--length", _num(t["length"])] if t["length"] is not None else []
        argv += ["--samples", str(t["samples"])] if t["samples"] is not None else []
        if t["verify_conditions"]:
            argv += ["--verify-conditions"]
        elif t["search"]:
            argv += ["--search", "--out", job_out]
        argv += ["--json"] + (["--quiet"] if quiet else [])
    return argv


def toml_table(fields: dict[str, Any]) -> str:
    """A flat TOML table (numbers, strings, booleans, lists of numbers)."""
    return toml_document(fields)


def jump_task_toml(scenario: Scenario) -> str:
    """The task file the jump job's equivalent command reads (``out/jump/task.toml``)."""
    return toml_table({k: v for k, v in jump_fields(scenario.data).items() if k != "base"})


def job_command(job: str, scenario: Scenario, out: Path, previous: Mapping[str, dict]) -> str:
    """``"jointlock COMMAND ..."``: :func:`job_argv` as one shell-quoted line."""
    return "jointlock " + shlex.join(job_argv(job, scenario, out, previous, quiet=True))
