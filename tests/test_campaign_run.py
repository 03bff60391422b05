"""Running campaigns: every engine gives the same ledger, a failing case is recorded and the
campaign goes on, an interrupted run (SIGINT, SIGTERM, SIGKILL of the coordinator) resumes
exactly the remainder, a worker that dies loses only its batch; status, export and report."""

from __future__ import annotations

import json
import os
import signal
import sqlite3
import time

import pytest
from campaign_helpers import descendants, ledger_count, records, start_cli, wait_for_cases, write_campaign

import jointlock as jl
from jointlock.campaign import (
    campaign_report,
    campaign_status,
    campaign_table,
    in_process,
    load_campaign,
    open_ledger,
    plan_campaign,
    run_campaign,
)

#: 40 halt cases (~0.1 s each), 4 of them failing at run time (speed limit below the state's
#: rates: "the state at failure already breaks a limit").
BODY = (
    '[grid]\n"failure.joint" = [1, 2, 3, 4, 5]\n"failure.angle_deg" = [-30.0, 30.0]\n'
    '"limits.vmax_deg_s" = [40.0, 45.0, 50.0, 30.0]\n'
    '[[exclude]]\n"limits.vmax_deg_s" = 30.0\n"failure.joint" = { gt = 2 }\n'
)
N_CASES, N_FAILING = 5 * 2 * 4 - 3 * 2, 2 * 2  # 34 cases, 4 failing


@pytest.fixture(scope="module")
def campaign_file(tmp_path_factory):
    return write_campaign(tmp_path_factory.mktemp("campaign"), BODY)


@pytest.fixture(scope="module")
def serial(campaign_file, tmp_path_factory):
    """The uninterrupted in-process run every other run is compared with."""
    out = tmp_path_factory.mktemp("serial") / "out"
    result = run_campaign(campaign_file, out, engine=in_process(), batch_seconds=0.5)
    return out, result


def test_in_process_run_records_every_case_and_the_failures(serial):
    out, result = serial
    assert (result.planned, result.ok, result.failed, result.remaining) == (N_CASES, N_CASES - N_FAILING, N_FAILING, 0)
    status = campaign_status(out)
    assert status.complete and status.failed == N_FAILING
    assert {f["error_type"] for f in status.failures} == {"InfeasibleError"}
    assert all("already breaks a limit" in f["error_message"] for f in status.failures)
    assert all(f["params"]["limits.vmax_deg_s"] == 30.0 for f in status.failures)
    lines = "\n".join(status.summary())
    # infeasible is an answer, counted apart from errors (issue 28)
    assert status.infeasible == 4 and status.to_dict()["errors"] == 0 and result.infeasible == 4
    assert "4 infeasible (an answer), 0 failed" in lines and "infeasible cases (nothing keeps the limits" in lines
    assert "failed cases" not in lines and "InfeasibleError" in lines
    assert "(0 ok, 4 infeasible, 0 failed)" in "\n".join(result.summary()) or "4 infeasible, 0 failed" in "\n".join(result.summary())


def test_the_ledger_holds_each_jobs_result_and_the_columns(serial):
    out, _ = serial
    with open_ledger(out) as ledger:
        row = next(r for r in ledger.rows() if r["status"] == "ok")
        result = ledger.result(row["key"])
    assert set(result) == {"halt_config", "halt"}
    assert row["record"]["halt.global_torque_Nm"] == result["halt"]["global_torque_Nm"]
    assert row["record"]["halt.peak_velocity_deg_s|max"] == max(result["halt"]["peak_velocity_deg_s"])
    assert row["record"]["halt.violations|len"] == len(result["halt"]["violations"])
    # the case's seed is the scenario's seed: the Monte Carlo search used it
    assert result["halt_config"]["seed"] == row["seed"]


def test_a_case_rerun_as_a_plain_scenario_gives_the_same_numbers(serial, tmp_path):
    out, _ = serial
    report = campaign_report(out, top=2)
    files = report.write(tmp_path / "report.html")
    scenario_file = files[1]
    assert scenario_file.suffix == ".toml" and "jointlock run" in scenario_file.read_text()
    # the mode the workers ran in (jointlock.compiled), so that the numbers are the same bit for bit
    mode = os.environ.get("JOINTLOCK_COMPILED", "").strip().lower() or "always"
    assert report.compiled == mode and jl.load_scenario(scenario_file).data["compiled"] == mode
    rerun = jl.run_scenario(jl.load_scenario(scenario_file))
    row = report.worst[0]
    assert rerun["halt"].to_dict()["global_torque_Nm"] == row["halt.global_torque_Nm"]
    assert rerun["halt"].to_dict()["k"] == row["halt.k"]


def test_process_pool_gives_the_same_ledger_as_in_process(campaign_file, serial, tmp_path):
    out = tmp_path / "pool"
    result = run_campaign(campaign_file, out, workers=2, batch_seconds=0.5)
    assert result.ok + result.failed == N_CASES and result.workers == 2
    assert records(out) == records(serial[0])


def test_running_again_runs_nothing_and_an_edit_runs_only_new_cases(campaign_file, serial, tmp_path):
    out = tmp_path / "copy"
    out.mkdir()
    with sqlite3.connect(str(serial[0] / "ledger.sqlite")) as src, sqlite3.connect(str(out / "ledger.sqlite")) as dst:
        src.backup(dst)
    again = run_campaign(campaign_file, out, engine=in_process())
    assert (again.done_before, again.to_run, again.ok + again.failed) == (N_CASES, 0, 0)
    # one more locked angle: 5 joints x 4 limits - 3 excluded = 17 new cases
    edited = write_campaign(tmp_path, BODY.replace("[-30.0, 30.0]", "[-30.0, 30.0, 60.0]"), name="edited.toml")
    plan = plan_campaign(edited, out, probe=0)
    assert (plan.cases, plan.ok + plan.failed, plan.to_run) == (N_CASES + 17, N_CASES, 17)
    more = run_campaign(edited, out, engine=in_process())
    assert (more.done_before, more.to_run) == (N_CASES, 17)
    # the failed cases are kept until asked for
    retried = run_campaign(edited, out, engine=in_process(), retry_failed=True)
    assert retried.to_run == N_FAILING + 2 and retried.failed == N_FAILING + 2
    # narrowing the file keeps the older cases in the ledger, out of the export
    narrow = write_campaign(tmp_path, BODY.replace("[1, 2, 3, 4, 5]", "[1, 2]"), name="narrow.toml")
    run_campaign(narrow, out, engine=in_process())
    status = campaign_status(out)
    assert status.planned == 16 and status.outside == N_CASES + 17 - 16
    assert len(campaign_table(out).rows) == 16 and len(campaign_table(out, include_outside=True).rows) == N_CASES + 17


def test_changing_the_columns_recomputes_records_without_running(campaign_file, serial, tmp_path):
    out = tmp_path / "cols"
    out.mkdir()
    with sqlite3.connect(str(serial[0] / "ledger.sqlite")) as src, sqlite3.connect(str(out / "ledger.sqlite")) as dst:
        src.backup(dst)
    text = campaign_file.read_text().replace("[grid]", 'columns = ["halt.q_final_deg.0", "halt.k_rad"]\n[grid]', 1)
    edited = campaign_file.parent / "columns.toml"
    edited.write_text(text)
    again = run_campaign(edited, out, engine=in_process())
    assert again.to_run == 0
    table = campaign_table(out)
    assert table.metrics == ("halt.q_final_deg.0", "halt.k_rad")
    ok = [r for r in table.rows if r["status"] == "ok"]
    with open_ledger(out) as ledger:
        res = ledger.result(ok[0]["key"])
    assert ok[0]["halt.q_final_deg.0"] == res["halt"]["q_final_deg"][0]


def test_export_csv_and_parquet(serial, tmp_path):
    pa = pytest.importorskip("pyarrow.parquet")
    out, _ = serial
    code, stdout, stderr = _cli("campaign", "export", str(out), "--csv", str(tmp_path / "c.csv"), "--parquet", str(tmp_path / "c.parquet"))
    assert code == 0, stderr
    assert f"wrote {N_CASES} cases" in stdout
    header = (tmp_path / "c.csv").read_text().splitlines()[0].split(",")
    assert header[:6] == ["key", "index", "status", "case_seed", "failure.joint", "failure.angle_deg"]
    assert "halt.feasible" in header and "error_message" in header
    table = pa.read_table(tmp_path / "c.parquet")
    assert table.num_rows == N_CASES
    assert table.column("failure.joint").to_pylist() == campaign_table(out).column("failure.joint")


def test_report_has_heatmaps_distributions_worst_cases_and_failures(serial, tmp_path):
    out, _ = serial
    code, stdout, stderr = _cli("campaign", "report", str(out), "--output", str(tmp_path / "r.html"))
    assert code == 0, stderr
    page = (tmp_path / "r.html").read_text()
    for text in ("Heatmaps", "Distributions", "Worst cases by halt.global_torque_Nm", "Failed cases", "InfeasibleError",
                 "failure.joint", "data:image/png;base64,", 'href="worst/case-'):
        assert text in page, text
    assert "<script" not in page
    rep = campaign_report(out, x="failure.angle_deg", y="failure.joint")
    assert (rep.x, rep.y) == ("failure.angle_deg", "failure.joint")
    with pytest.raises(jl.errors.CampaignError, match="not a varied field"):
        campaign_report(out, x="halt.T")


def _cli(*argv: str) -> tuple[int, str, str]:
    import contextlib
    import io

    from jointlock.cli import main

    o, e = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(o), contextlib.redirect_stderr(e):
        code = main(list(argv))
    return code, o.getvalue(), e.getvalue()


# -- interruptions: real `jointlock campaign run` processes -----------------------------------


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM])
def test_a_signal_stops_commits_and_the_same_command_resumes(campaign_file, serial, tmp_path, sig):
    out = tmp_path / "out"
    argv = ("campaign", "run", str(campaign_file), "--out", str(out), "--workers", "2", "--batch-seconds", "0.3")
    proc = start_cli(*argv)
    done = wait_for_cases(out, 6, proc)
    assert proc.poll() is None, proc.communicate()
    proc.send_signal(sig)
    _, stderr = proc.communicate(timeout=60)
    assert proc.returncode == (130 if sig == signal.SIGINT else 143), stderr
    assert f"stopped by {sig.name}" in stderr and "again to resume" in stderr and "Traceback" not in stderr
    stopped_at = ledger_count(out)
    assert done <= stopped_at < N_CASES
    status = campaign_status(out)
    assert status.runs[-1]["stopped_by"] == sig.name and status.remaining == N_CASES - stopped_at
    proc = start_cli(*argv, "--json")
    stdout, stderr = proc.communicate(timeout=120)
    assert proc.returncode == 0, stderr
    resumed = json.loads(stdout)
    assert resumed["done_before"] == stopped_at and resumed["to_run"] == N_CASES - stopped_at
    assert resumed["remaining"] == 0
    assert records(out) == records(serial[0])  # each case once, values equal to the serial run


def test_a_killed_coordinator_loses_only_uncommitted_batches(campaign_file, serial, tmp_path):
    out = tmp_path / "out"
    argv = ("campaign", "run", str(campaign_file), "--out", str(out), "--workers", "2", "--batch-seconds", "0.3")
    proc = start_cli(*argv)
    wait_for_cases(out, 6, proc)
    assert proc.poll() is None
    workers = descendants(proc.pid)
    proc.kill()
    proc.wait(timeout=30)  # reaped, as a shell does at once
    proc.communicate(timeout=30)  # the workers, which share its output pipes, are gone too
    killed_at = ledger_count(out)
    assert 0 < killed_at < N_CASES
    deadline = time.monotonic() + 15  # the pool's workers notice the coordinator is gone
    while time.monotonic() < deadline and any(_alive(pid) for pid in workers):
        time.sleep(0.2)
    assert not any(_alive(pid) for pid in workers), "orphaned worker processes"
    proc = start_cli(*argv, "--json")
    stdout, stderr = proc.communicate(timeout=120)
    assert proc.returncode == 0, stderr
    assert json.loads(stdout)["done_before"] == killed_at
    assert records(out) == records(serial[0])
    runs = campaign_status(out).runs
    assert runs[0]["finished_at"] is None and runs[1]["finished_at"] is not None  # the cut-off run shows


def _alive(pid: int) -> bool:
    try:
        with open(f"/proc/{pid}/stat") as fh:
            return fh.read().rsplit(")", 1)[1].split()[0] != "Z"
    except OSError:
        return False


def test_a_worker_that_dies_loses_only_its_batch(campaign_file, serial, tmp_path):
    out = tmp_path / "out"
    argv = ("campaign", "run", str(campaign_file), "--out", str(out), "--workers", "2", "--batch-seconds", "0.3", "--json")
    proc = start_cli(*argv)
    wait_for_cases(out, 4, proc)
    assert proc.poll() is None
    tree = descendants(proc.pid)
    servers = [pid for pid, (_, cmd) in tree.items() if "forkserver" in cmd]
    workers = [pid for pid, (ppid, _) in tree.items() if ppid in servers] if servers else []
    if not workers:  # spawn: the workers are the coordinator's children, except the tracker
        workers = [pid for pid, (ppid, cmd) in tree.items() if ppid == proc.pid and "resource_tracker" not in cmd]
    assert workers, tree
    import os

    os.kill(workers[0], signal.SIGKILL)
    stdout, stderr = proc.communicate(timeout=120)
    assert proc.returncode == 0, stderr
    result = json.loads(stdout)
    assert result["restarts"] >= 1 and result["lost_batches"] >= 1 and result["remaining"] == 0
    assert records(out) == records(serial[0])


def test_a_second_coordinator_on_the_same_folder_is_refused(campaign_file, tmp_path):
    import fcntl

    out = tmp_path / "out"
    out.mkdir()
    with open(out / ".campaign.lock", "w") as fh:  # as a running coordinator holds it
        fh.write("4242")
        fh.flush()
        fcntl.flock(fh, fcntl.LOCK_EX | fcntl.LOCK_NB)
        code, _, stderr = _cli("campaign", "run", str(campaign_file), "--out", str(out), "--in-process")
    assert code == 2 and "another `jointlock campaign run` (pid 4242)" in stderr
    assert not (out / "ledger.sqlite").exists()


def test_plan_estimates_from_timed_cases(campaign_file, tmp_path):
    plan = plan_campaign(load_campaign(campaign_file), tmp_path / "none", workers=2, probe=2)
    assert plan.cases == plan.to_run == N_CASES and len(plan.probe_seconds) == 2
    assert plan.estimate_s == pytest.approx(plan.seconds_per_case * N_CASES / 2)
    assert not (tmp_path / "none").exists()  # plan writes nothing
    assert plan.probe_errors == () and plan.unknown_columns == ()
    text = "\n".join(plan.summary())
    assert f"cases: {N_CASES} ({N_CASES + 6} described, 6 excluded by filters)" in text


def test_replicates_vary_the_seed_and_each_runs_with_its_own(tmp_path):
    path = write_campaign(tmp_path, '[grid]\nseed = [0, 1, 2]\n')
    out = tmp_path / "out"
    result = run_campaign(path, out, engine=in_process())
    assert (result.ok, result.failed) == (3, 0)
    table = campaign_table(out)
    assert table.column("seed") == [0, 1, 2]  # the varied field
    seeds = table.column("case_seed")
    assert len(set(seeds)) == 3 and not set(seeds) & {0, 1, 2}  # derived from each case's key
    cps = table.column("halt_config.best.cp")
    assert len(set(cps)) == 3  # three Monte Carlo searches
    with open_ledger(out) as ledger:
        assert [ledger.result(k)["halt_config"]["seed"] for k in table.column("key")] == seeds


def test_a_misspelt_column_is_reported_and_fixed_without_running_again(campaign_file, serial, tmp_path):
    text = campaign_file.read_text().replace("[grid]", 'columns = ["halt.feasable", "halt.k"]\n[grid]', 1)
    edited = tmp_path / "typo.toml"
    edited.write_text(text)
    plan = plan_campaign(edited, tmp_path / "none", probe=1)
    assert plan.unknown_columns == ("'halt.feasable' is not in the halt job's result (did you mean 'halt.feasible'?)",)
    with pytest.raises(jl.errors.CampaignError, match="reads the jump job, which no case runs"):
        bad = tmp_path / "job.toml"
        bad.write_text(campaign_file.read_text().replace("[grid]", 'columns = ["jump.kappa"]\n[grid]', 1))
        plan_campaign(bad, tmp_path / "none", probe=0)


def test_a_fault_in_every_batch_stops_the_run_with_one_line(campaign_file, tmp_path, monkeypatch):
    import jointlock.campaign._worker as worker

    monkeypatch.setattr(worker, "__version__", "0.0.0-elsewhere")
    with pytest.raises(jl.errors.CampaignError, match=r"not in one of its cases: RuntimeError: jointlock 0.0.0-elsewhere"):
        run_campaign(campaign_file, tmp_path / "out", engine=in_process())
    assert campaign_status(tmp_path / "out").ok == 0  # nothing recorded as a case's error


class _PoisonPool:
    """A stand-in for a local process pool that breaks whole when one batch holds the poison
    case: every batch not yet returned fails with BrokenProcessPool (as a real pool does when
    one worker dies); the others run for real, in a thread, after a short delay."""

    def __init__(self, poison: str) -> None:
        import concurrent.futures as cf
        import threading

        self.poison, self.cf = poison, cf
        self.pending: list = []
        self.lock = threading.Lock()
        self.thread = threading.Thread(target=self._loop, daemon=True)
        self.alive = True
        self.thread.start()

    def submit(self, fn, task):
        future = self.cf.Future()
        with self.lock:
            self.pending.append((future, fn, task))
        return future

    def _loop(self) -> None:
        from concurrent.futures.process import BrokenProcessPool

        while self.alive:
            time.sleep(0.05)
            with self.lock:
                batch, self.pending = self.pending, []
            if any(self.poison in [key for key, _, _ in task.cases] for _, _, task in batch):
                for future, _, _ in batch:
                    future.set_exception(BrokenProcessPool("a worker died"))
                continue
            for future, fn, task in batch:
                future.set_result(fn(task))

    def shutdown(self, wait=True, cancel_futures=False):
        self.alive = False


def test_a_case_that_kills_its_worker_is_found_and_only_it_is_lost(campaign_file, serial, tmp_path):
    from jointlock.campaign import Engine, plan_cases

    cases = plan_cases(load_campaign(campaign_file)).cases
    poison = cases[7].key
    pools = [_PoisonPool(poison)]

    def restart():
        pools.append(_PoisonPool(poison))
        return pools[-1]

    engine = Engine("poison pool", pools[0], 2, "poison pool", _restart=restart)
    out = tmp_path / "out"
    result = run_campaign(campaign_file, out, engine=engine, batch_seconds=0.3)
    engine.close()
    assert result.restarts >= 2 and result.remaining == 0
    rows = records(out)
    assert rows[poison][0] == "error" and rows[poison][2] == "WorkerLost"
    expected = {k: v for k, v in records(serial[0]).items() if k != poison}
    assert {k: v for k, v in rows.items() if k != poison} == expected  # every other case, as serially
    # the lost case runs again on the next run (and here is lost again)
    again = run_campaign(campaign_file, out, engine=Engine("poison pool", _PoisonPool(poison), 2, "p",
                                                           _restart=restart), batch_seconds=0.3)  # fmt: skip
    assert again.to_run == 1 and again.failed == 1


def test_export_to_stdout_and_to_a_folder(serial, tmp_path):
    out, _ = serial
    code, stdout, stderr = _cli("campaign", "export", str(out), "--csv", "-")
    assert code == 0 and stdout.splitlines()[0].startswith("key,index,status,case_seed,")
    assert len(stdout.splitlines()) == N_CASES + 1 and f"wrote {N_CASES} cases" in stderr
    code, _, stderr = _cli("campaign", "export", str(out), "--csv", str(tmp_path))
    assert code == 2 and stderr.count("\n") == 1 and "is a folder" in stderr and ".tmp" not in stderr


def test_status_while_a_run_writes_and_another_campaign_in_the_folder(campaign_file, serial, tmp_path):
    import fcntl

    out = tmp_path / "copy"
    out.mkdir()
    with sqlite3.connect(str(serial[0] / "ledger.sqlite")) as src, sqlite3.connect(str(out / "ledger.sqlite")) as dst:
        src.backup(dst)
    with open(out / ".campaign.lock", "w") as fh:
        fh.write("777")
        fh.flush()
        fcntl.flock(fh, fcntl.LOCK_EX | fcntl.LOCK_NB)
        status = campaign_status(out)
    assert status.running_pid == "777" and "a run is in progress (pid 777)" in "\n".join(status.summary())
    assert campaign_status(out).running_pid is None
    other = write_campaign(tmp_path, BODY.replace("[1, 2, 3, 4, 5]", "[6]"), name="other.toml")
    result = run_campaign(other, out, engine=in_process())
    assert result.other_campaign == str(campaign_file)
    assert any("held another campaign" in line for line in result.summary())
    lines = "\n".join(campaign_status(out).summary())
    assert "older case(s) no longer in the file" in lines and f"({campaign_file})" in lines


def test_a_worst_column_without_values_is_one_clear_error(serial):
    with pytest.raises(jl.errors.CampaignError, match="has no value in any finished case"):
        campaign_report(serial[0], worst="halt.minimum_T_s")
