"""Auditing a planned motion (issue 28): every chosen joint locking at every chosen instant of a
scenario's [task], on the campaign engine.  A cell is exactly the standalone run with the cell's
seed; the halt7 example's cell of joint 4 at t = 0 is 000's halt; infeasible cells are answers,
counted apart from errors; the safe windows are read back."""

from __future__ import annotations

import json
import os

import numpy as np
import pytest

import jointlock as jl
from jointlock.campaign import (
    audit_campaign,
    audit_windows,
    campaign_status,
    in_process,
    open_ledger,
    run_audit,
)
from jointlock.cli import main
from jointlock.errors import CampaignError

PUMA = """
title = "puma6 moves a payload"
robot = "puma6"
seed = 0
[failure]
joint = 2
time_s = 0.0
[task]
waypoints_deg = [[0, 30, 0, 0, 0, 0], [20, 40, 20, 10, -40, 30], [30, 50, 30, 20, -80, 60]]
durations_s = [3.0, 3.0]
[limits]
vmax_deg_s = 40.0
amax_deg_s2 = 40.0
[halt_config]
samples = 600
[halt]
T = 4.0
samples = 600
minimum_T = true
"""


@pytest.fixture(scope="module")
def audited(tmp_path_factory):
    folder = tmp_path_factory.mktemp("audit")
    scenario = folder / "plan.toml"
    scenario.write_text(PUMA)
    result = jl.audit(scenario, folder / "out", joints=[2, 3], times=3, engine=in_process())  # = run_audit
    return scenario, folder / "out", result


def test_every_cell_runs_once_and_the_windows_are_read_back(audited):
    scenario, out, result = audited
    assert result.run.planned == 6 and result.run.remaining == 0 and result.windows is not None
    assert result.windows.times == (0.0, 3.0, 6.0) and result.windows.joints == (2, 3)
    assert json.loads((out / "audit.json").read_text()) == result.windows.to_dict()
    page = (out / "report.html").read_text()
    assert "Audit: safe windows" in page and "risk timeline" in page
    # the grid again, interactive: each cell's numbers on hover (plotly, inline: no network)
    assert "every cell, interactive" in page and "Plotly.newPlot" in page
    assert "joint 3 locks at t = 0 s" in page and "task could be finished instead" in page
    worst = sorted((out / "worst").glob("*.toml"))
    assert worst and jl.load_scenario(worst[0]).data["task"]["waypoints_deg"] is not None  # re-runs as it is
    again = run_audit(scenario, out, joints=[2, 3], times=3, engine=in_process())  # resumes: nothing left
    assert again.run.to_run == 0 and again.run.done_before == 6


def test_a_cell_is_the_standalone_run_with_its_seed(audited):
    scenario, out, _ = audited
    with open_ledger(out) as ledger:
        rows = [r for r in ledger.rows() if r["status"] == "ok"]
        row = rows[-1]
        recorded = ledger.result(row["key"])
        mode = ledger.meta("compiled")
    # a campaign's workers run every batch compiled (jointlock.compiled), unless told otherwise
    assert mode == (os.environ.get("JOINTLOCK_COMPILED", "").strip().lower() or "always")
    overrides = {f"failure.{k.split('.')[1]}": v for k, v in row["params"].items()} | {"seed": row["seed"]}
    overrides["compiled"] = mode  # the run in the campaign's mode: the same numbers, bit for bit
    alone = jl.run_scenario(jl.load_scenario(scenario, overrides))
    mine = json.loads(json.dumps(alone["halt"].to_dict(), default=lambda a: np.asarray(a).tolist()))
    for key in ("k", "global_torque_Nm", "minimum_T_s", "q_final_deg", "dq_initial_deg_s"):
        assert recorded["halt"][key] == pytest.approx(mine[key], rel=1e-12, abs=1e-12), key
    assert recorded["halt"]["state_source"] == f"task at t = {row['params']['failure.time_s']:g} s"
    assert recorded["halt"]["task_completion"] == mine["task_completion"] is not None


def test_a_cell_says_whether_the_task_could_be_finished_instead(audited):
    """Each cell records jl.task_completion of the scenario's task with the cell's joint locked
    at its instant: whether every remaining waypoint is reachable, and the first that is not."""
    from jointlock.scenario._task import scenario_task

    scenario, out, _ = audited
    sc = jl.load_scenario(scenario)
    task, arm = scenario_task(sc.data), jl.load_robot("puma6")
    with open_ledger(out) as ledger:
        rows = [r for r in ledger.rows() if r["status"] == "ok"]
    assert rows
    for row in rows:
        joint, t = row["params"]["failure.joint"], row["params"]["failure.time_s"]
        expected = jl.task_completion(arm, task, joint, t)
        assert row["record"]["halt.task_completion.completable"] == expected.completable
        assert row["record"]["halt.task_completion.first_unreachable_s"] == expected.first_unreachable_s
    # joint 3 locked at t = 0 misses the next waypoint; at the last one nothing is left to miss
    cells = {(r["params"]["failure.joint"], r["params"]["failure.time_s"]): r["record"] for r in rows}
    assert cells[3, 0.0]["halt.task_completion.first_unreachable_s"] == 3.0
    assert cells[3, 6.0]["halt.task_completion.completable"] is True


def test_audit_windows_on_hand_made_cells():
    def cell(j, t, feasible=True, clear=True, wheels=True, status="ok"):
        return {"failure.joint": j, "failure.time_s": t, "status": status, "halt.feasible": feasible,
                "halt.collision_free": clear, "halt.attitude_control.within": wheels, "halt.minimum_T_s": 5.0 + j}  # fmt: skip

    rows = [cell(1, 0.0), cell(2, 0.0), cell(1, 1.0), cell(2, 1.0, wheels=False), cell(1, 2.0), cell(2, 2.0),
            cell(1, 3.0, status="error"), cell(2, 3.0), cell(1, 4.0), cell(2, 4.0)]  # fmt: skip
    w = audit_windows(rows)
    assert w.windows == ((0.0, 0.0), (2.0, 2.0), (4.0, 4.0))
    assert w.unsafe_joints[1] == (2,) and w.unsafe_joints[3] == (1,) and w.worst_joint[0] == 2
    assert audit_windows([cell(1, 0.0, feasible=False)]).summary()[0].startswith("NO SAFE WINDOW")


def test_the_interactive_grid_colours_and_labels_each_cell():
    from jointlock.campaign._report import audit_cell_figure

    def cell(j, t, **extra):
        return {"key": f"k{j}{t}", "status": "ok", "failure.joint": j, "failure.time_s": t, "halt.feasible": True,
                "halt.collision_free": True, "halt.minimum_T_s": 7.25, **extra}  # fmt: skip

    rows = [cell(1, 0.0), cell(2, 0.0, **{"halt.collision_free": False}),
            {"key": "bad", "status": "error", "failure.joint": 3, "failure.time_s": 0.0}]  # fmt: skip
    fig = audit_cell_figure(rows, {"bad": "InfeasibleError: the state at failure already breaks a limit"})
    by_name = {trace["name"]: trace for trace in fig["data"]}
    assert by_name["safe"]["y"] == [1] and by_name["no safe halt"]["y"] == [2] and by_name["no halt"]["y"] == [3]
    assert "smallest feasible halt time [s]: 7.250" in by_name["safe"]["text"][0]
    assert "clear of the bus and the arm: NO" in by_name["no safe halt"]["text"][0]
    assert "already breaks a limit" in by_name["no halt"]["text"][0]
    assert fig["frames"] == [] and fig["layout"]["yaxis"]["tickvals"] == [1, 2, 3]


def test_bad_audits_are_one_line(tmp_path):
    plain = tmp_path / "plain.toml"
    plain.write_text('robot = "puma6"\n[failure]\njoint = 2\nangle_deg = 10.0\n[state]\nq0_deg = [0, 0, 0, 0, 0]\n'
                     'dq0_deg = [0, 0, 0, 0, 0]\nddq0_deg = [0, 0, 0, 0, 0]\n[halt]\nT = 3.0\n')  # fmt: skip
    with pytest.raises(CampaignError, match="has no \\[task\\]"):
        audit_campaign(plain)
    planned = tmp_path / "plan.toml"
    planned.write_text(PUMA)
    with pytest.raises(CampaignError, match="joints must be distinct joint numbers 1..6"):
        audit_campaign(planned, joints=[2, 9])
    with pytest.raises(CampaignError, match="give --times or --dt, not both"):
        audit_campaign(planned, times=3, dt=1.0)
    spec = audit_campaign(planned, dt=1.5)
    assert list(spec.grid["failure.time_s"]) == [0.0, 1.5, 3.0, 4.5, 6.0]


def test_cli_audit_and_infeasible_cells_counted_apart(tmp_path, capsys):
    """With a 10 deg/s speed limit the task's own rates are over it at 3 s: those cells are
    infeasible (an answer), counted apart from errors in the run and the status."""
    scenario = tmp_path / "plan.toml"
    scenario.write_text(PUMA.replace("vmax_deg_s = 40.0", "vmax_deg_s = 10.0"))
    out = tmp_path / "out"
    assert main(["audit", str(scenario), "--joints", "2", "--times", "2", "--in-process", "--out", str(out), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["planned"] == 2 and data["infeasible"] >= 1 and data["errors"] == 0
    status = campaign_status(out)
    assert status.infeasible == data["infeasible"] and "infeasible (an answer)" in "\n".join(status.summary())


@pytest.mark.paper
def test_the_halt7_example_at_000s_instant_is_000s_halt(tmp_path, capsys):
    """examples/audit_halt7.toml starts its task at 000 §5.2's state: the scenario as it is (joint 4
    at t = 0, seed 0) gives `jointlock halt halt7`'s k* and base torque."""
    run = jl.run_scenario(jl.load_scenario("examples/audit_halt7.toml"))
    plan = run["halt"]
    assert plan.state_source == "task at t = 0 s"
    assert main(["halt", "halt7", "--json", "--quiet"]) == 0
    reference = json.loads(capsys.readouterr().out)
    assert float(np.ravel(plan.to_dict()["k"])[0]) == pytest.approx(float(np.ravel(reference["k"])[0]), rel=1e-9)
    assert plan.motion.global_torque == pytest.approx(reference["global_torque_Nm"], rel=1e-9)
    np.testing.assert_allclose(np.degrees(plan.problem.dq0), [20, 30, 15, 25, 40, 35], atol=1e-9)


def test_a_worst_cell_with_a_task_file_runs_from_its_own_folder(tmp_path):
    """The worst cells are written under DIR/worst/: a task file relative to the audited scenario
    is written as an absolute path there, so that `jointlock run` finds it."""
    (tmp_path / "motion.csv").write_text(
        "t_s, q1, q2, q3, q4, q5, q6\n0, 0, 30, 0, 0, 0, 0\n3, 20, 40, 20, 10, -40, 30\n6, 30, 50, 30, 20, -80, 60\n"
    )
    text = PUMA.replace(
        "waypoints_deg = [[0, 30, 0, 0, 0, 0], [20, 40, 20, 10, -40, 30], [30, 50, 30, 20, -80, 60]]\ndurations_s = [3.0, 3.0]",
        'file = "motion.csv"',
    )
    scenario = tmp_path / "plan.toml"
    scenario.write_text(text)
    result = run_audit(scenario, tmp_path / "out", joints=[3], times=2, engine=in_process())
    worst = sorted((tmp_path / "out" / "worst").glob("*.toml"))
    assert result.windows is not None and worst
    assert jl.load_scenario(worst[0]).data["task"]["file"] == str((tmp_path / "motion.csv").resolve())


def test_an_audited_scenario_needs_no_joint_nor_instant_and_a_damaged_audit_json_is_said(tmp_path):
    """The audit sets each cell's joint and instant: the file need not name them (it must not
    name an angle: the task's is used); a damaged audit.json is a note in the report, not a
    traceback."""
    text = PUMA.replace("joint = 2\ntime_s = 0.0\n", "")
    scenario = tmp_path / "plan.toml"
    scenario.write_text(text)
    spec = audit_campaign(scenario, joints=[3], times=2)
    assert list(spec.grid["failure.joint"]) == [3]
    scenario.write_text(PUMA.replace("time_s = 0.0", "time_s = 0.0\nangle_deg = 30.0"))
    with pytest.raises(CampaignError, match="failure.angle_deg is the task's"):
        audit_campaign(scenario)
    scenario.write_text(PUMA)
    out = tmp_path / "out"
    run_audit(scenario, out, joints=[3], times=2, engine=in_process())
    (out / "audit.json").write_text("{not json")
    from jointlock.campaign import write_campaign_report

    page = write_campaign_report(out)[0].read_text()
    assert "audit.json could not be read" in page


def test_a_per_joint_table_reduces_to_one_column():
    """The audit records the locked joints' peak brake torque: a table per joint reduced by |max."""
    from jointlock.campaign import AUDIT_COLUMNS, column_value

    assert "halt.actuators.peak_brake_torque_Nm|max" in AUDIT_COLUMNS
    results = {"halt": {"actuators": {"peak_brake_torque_Nm": {"4": 2220.5, "2": 10.0}}}}
    assert column_value(results, "halt.actuators.peak_brake_torque_Nm|max") == 2220.5
    assert column_value(results, "halt.actuators.peak_brake_torque_Nm|len") == 2


def test_sigma_min_at_failure_is_recorded():
    """Issue 28's cell content: how close to a singularity the arm is when the joint locks (the
    locked arm's generalized Jacobian at the state at failure for a free-floating model)."""
    from jointlock.campaign import AUDIT_COLUMNS

    plan = jl.plan_halt("halt7", progress=False)
    p = plan.problem
    expected = np.linalg.svd(jl.generalized_jacobian(p.model, p.q0), compute_uv=False).min()
    assert plan.sigma_min_at_failure() == pytest.approx(expected, rel=1e-12)
    assert plan.to_dict()["sigma_min_at_failure"] == pytest.approx(expected, rel=1e-12)
    assert "halt.sigma_min_at_failure" in AUDIT_COLUMNS


@pytest.mark.parametrize("how", ["SIGKILL", "SIGINT"])
def test_an_interrupted_audit_resumes_with_every_cell_once(how, tmp_path):
    """`jointlock audit` stopped mid-way (the coordinator killed, or Ctrl-C) and run again runs
    only the cells not finished: every cell exactly once, the same numbers as an audit never
    interrupted."""
    import signal

    from campaign_helpers import ledger_count, records, start_cli, wait_for_cases

    scenario = tmp_path / "plan.toml"
    scenario.write_text(PUMA)
    whole = tmp_path / "whole"
    run_audit(scenario, whole, joints=[2, 3, 4, 5], times=6, engine=in_process())
    out = tmp_path / "out"
    argv = ("audit", str(scenario), "--joints", "2", "3", "4", "5", "--times", "6", "--out", str(out), "--workers", "2")
    proc = start_cli(*argv, "--quiet")
    wait_for_cases(out, 2, proc)
    assert proc.poll() is None, proc.communicate()
    proc.send_signal(signal.SIGKILL if how == "SIGKILL" else signal.SIGINT)
    proc.communicate(timeout=60)
    stopped_at = ledger_count(out)
    assert 0 < stopped_at < 24
    again = start_cli(*argv, "--json")
    stdout, stderr = again.communicate(timeout=180)
    assert again.returncode == 0, stderr
    assert json.loads(stdout)["done_before"] == stopped_at
    assert records(out) == records(whole)  # 24 cells, each once, each as never interrupted
