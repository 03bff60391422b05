"""001's Cartesian task as a kind of [task] (issue 28, item 1): the healthy arm's resolved-rate
joint motion equals the trajectory file written from the same run; every job starts from it (the
halt from the arm moving along the line, the jump study at the same failure time); an audit's jump
cells equal `jointlock jump` at their failure times; a jump cell without a kappa that keeps the
limits is an answer (the uncompensated jump and why), and the cell keeps its halt; bad tables are
one line each."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import jointlock as jl
from jointlock.campaign import in_process, open_ledger, run_audit
from jointlock.cli import main
from jointlock.errors import InfeasibleError, ScenarioError
from jointlock.planning.jump import JumpScenario, cartesian_task
from jointlock.planning.task import load_task_file

#: 001's task on canadarm7 (NOTES-001's, `jointlock jump canadarm7`'s), with the attitude held.
CARTESIAN = """
title = "canadarm7 follows 001's line"
robot = "canadarm7"
base = "floating"
seed = 0
[failure]
joint = 2
time_s = 6.0
[task]
q0_deg = [10.0, 40.0, -70.0, 100.0, -60.0, 30.0, 20.0]
dx_m = [1.2, -1.5, 0.8]
base = "fixed"
[limits]
vmax_deg_s = 10.0
amax_deg_s2 = 5.0
[halt_config]
samples = 400
[halt]
T = 10.0
base = "fixed"
[jump]
"""


def _scenario(tmp_path, text: str = CARTESIAN, **overrides):
    path = tmp_path / "line.toml"
    path.write_text(text)
    return jl.load_scenario(path, overrides or None)


def test_the_joint_motion_equals_the_trajectory_file_of_the_same_run():
    task = cartesian_task(jl.load_robot("canadarm7", base="fixed"), JumpScenario())
    written = load_task_file("examples/audit_canadarm7_motion.csv")
    assert task.t == pytest.approx(written.t, abs=1e-12)
    assert np.degrees(task.q) == pytest.approx(np.degrees(written.q), abs=1e-9)  # the file's printed digits
    assert task.kind == "samples" and "001's Cartesian task" in task.source
    # rates and accelerations of the spline against finite differences of its angles
    t, h = np.array([0.3, 5.0, 11.2]), 1e-5
    q, dq, ddq = task.state(t)
    assert dq == pytest.approx((task.state(t + h)[0] - task.state(t - h)[0]) / (2 * h), abs=1e-7)
    assert ddq == pytest.approx((task.state(t + h)[1] - task.state(t - h)[1]) / (2 * h), abs=1e-5)


def test_every_job_starts_from_the_task_and_the_jump_is_jointlock_jumps(tmp_path):
    scenario = _scenario(tmp_path)
    run = jl.run_scenario(scenario)
    halt, jump = run["halt"], run["jump"]
    task = cartesian_task(jl.load_robot("canadarm7", base="fixed"), JumpScenario())
    q, dq, _ = (np.degrees(v) for v in task.state(6.0))
    healthy = [0, 2, 3, 4, 5, 6]
    assert np.degrees(halt.problem.q0) == pytest.approx(q[healthy], abs=1e-8)
    assert np.degrees(halt.problem.dq0) == pytest.approx(dq[healthy], abs=1e-8)
    assert halt.state_source == "task at t = 6 s"
    assert scenario.data["failure"]["angle_deg"] == pytest.approx(q[1], abs=1e-8)  # locked where the task has it
    # the jump study of the same task at the same failure time: `jointlock jump canadarm7 --fail-at 6`
    alone = jl.jobs.jump.run_jump_study(jl.load_robot("canadarm7", base="fixed"), JumpScenario(), fail_at=6.0)
    mine, theirs = jump.to_dict(), alone.to_dict()
    for key in ("kappa", "jump_before", "jump_after", "mean_reduction", "limits_ok"):
        assert mine[key] == pytest.approx(theirs[key], rel=1e-12, abs=1e-15), key


def test_the_audits_jump_cells_equal_jointlock_jump_and_infeasible_keeps_the_halt(tmp_path, capsys):
    path = tmp_path / "line.toml"
    path.write_text(CARTESIAN)
    result = run_audit(path, tmp_path / "out", joints=[2, 5], times=3, engine=in_process())
    # the task's end (12 s) leaves nothing for the jump study to follow: 0 and 6 s only
    assert result.windows is not None and result.windows.times == (0.0, 6.0)
    with open_ledger(tmp_path / "out") as ledger:
        rows = {(r["params"]["failure.joint"], r["params"]["failure.time_s"]): r for r in ledger.rows()}
        assert all(r["status"] == "ok" for r in rows.values())
        recorded = ledger.result(rows[2, 6.0]["key"])["jump"]
    assert main(["jump", "canadarm7", "--lock", "2", "--fail-at", "6", "--json", "--quiet"]) == 0
    command = json.loads(capsys.readouterr().out)
    for key in ("kappa", "jump_before", "jump_after", "mean_reduction", "limits_ok"):
        assert recorded[key] == pytest.approx(command[key], rel=1e-12, abs=1e-15), key
    # joint 5: no kappa keeps the limits (001's task breaks them after any lock of joint 5)
    cell = rows[5, 6.0]["record"]
    assert cell["jump.limits_ok"] is False and cell["jump.kappa"] is None and cell["jump.mean_reduction"] is None
    assert cell["jump.infeasible"].startswith("no kappa")
    assert cell["halt.feasible"] is not None  # the cell keeps its halt
    with pytest.raises(InfeasibleError, match="no kappa"):
        jl.jobs.jump.run_jump_study(jl.load_robot("canadarm7", base="fixed"), JumpScenario(lock_joint=5), fail_at=6.0)
    reported = jl.jobs.jump.run_jump_study(
        jl.load_robot("canadarm7", base="fixed"), JumpScenario(lock_joint=5), fail_at=6.0, on_infeasible="report"
    )
    assert reported.to_dict()["infeasible"].startswith("no kappa") and reported.summary()[0].startswith("INFEASIBLE")


Q0 = "q0_deg = [10.0, 40.0, -70.0, 100.0, -60.0, 30.0, 20.0]\n"
LINE = "dx_m = [1.2, -1.5, 0.8]\n"


@pytest.mark.parametrize(
    "text, words",
    [
        (CARTESIAN.replace(LINE, LINE + 'file = "plan.csv"\n'), "task.dx_m (a Cartesian task) and task.file exclude each other"),
        (CARTESIAN.replace(Q0, ""), "task.dx_m needs task.q0_deg"),
        (CARTESIAN.replace(Q0, "q0_deg = [10.0, 40.0]\n"), "task.q0_deg needs 7 values"),
        (CARTESIAN.replace(LINE, ""), "task.q0_deg belongs to a Cartesian task"),
        (CARTESIAN.replace("[jump]\n", "[jump]\nduration_s = 10.0\n"), "jump.duration_s and the Cartesian [task] both give the task"),
        (CARTESIAN.replace("[jump]\n", '[jump]\nbase = "floating"\n'), "jump.base = 'floating' but task.base = 'fixed'"),
        (CARTESIAN.replace(LINE, LINE + "dt_s = 0.07\n"), "whole number"),
        (CARTESIAN.replace("[jump]\n", "[jump]\nfail_at = 3.0\n"), "jump.fail_at = 3 s with a Cartesian [task]"),
        (CARTESIAN.replace("[jump]\n", "[jump]\nsweep = 5\n"), "jump.sweep with a Cartesian [task]"),
    ],
)
def test_bad_cartesian_tasks_are_one_line(tmp_path, text, words):
    (tmp_path / "plan.csv").write_text("t_s,q1,q2,q3,q4,q5,q6,q7\n0,0,0,0,0,0,0,0\n1,1,1,1,1,1,1,1\n")
    with pytest.raises(ScenarioError) as err:
        jl.run_scenario(_scenario(tmp_path, text))
    assert words in str(err.value) and "\n" not in str(err.value)


def test_the_jump_study_alone_sweeps_the_cartesian_task(tmp_path):
    text = CARTESIAN.replace("time_s = 6.0\n", "").replace("[halt_config]\nsamples = 400\n[halt]\nT = 10.0\nbase = \"fixed\"\n", "")
    text = text.replace("[jump]\n", "[jump]\nsweep = 4\n")
    run = jl.run_scenario(_scenario(tmp_path, text))
    assert list(run.jobs) == ["jump"] and run["jump"].mode == "sweep"
    assert math.isclose(run["jump"].task.duration, 12.0)
