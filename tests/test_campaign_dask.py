"""A real Dask cluster on this machine: a scheduler and two workers started as `dask scheduler`
and `dask worker` processes (one killed midway), and a LocalCluster; the ledger equals the
process pool's for the same campaign file."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from campaign_helpers import cli_env, records, start_cli, wait_for_cases, write_campaign

from jointlock.campaign import run_campaign

pytest.importorskip("distributed")

#: 24 halt cases, ~0.1 s each.
BODY = '[grid]\n"failure.joint" = [1, 2, 3, 5, 6, 7]\n"failure.angle_deg" = [-40.0, 40.0]\n"halt.T" = [9.0, 11.0]\n'
N_CASES = 24


def _dask(*argv: str) -> subprocess.Popen:
    exe = Path(sys.executable).with_name("dask")
    return subprocess.Popen(
        [str(exe), *argv], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=cli_env(), start_new_session=True
    )


@pytest.fixture(scope="module")
def campaign_file(tmp_path_factory):
    return write_campaign(tmp_path_factory.mktemp("dask"), BODY)


@pytest.fixture(scope="module")
def pool_ledger(campaign_file, tmp_path_factory):
    out = tmp_path_factory.mktemp("pool") / "out"
    run_campaign(campaign_file, out, workers=2, batch_seconds=0.5)
    return out


@pytest.fixture
def cluster(tmp_path):
    """``dask scheduler`` and two ``dask worker`` processes (no nanny: killing one kills the
    worker); yields (scheduler address, worker processes)."""
    from distributed import Client

    sched_file = tmp_path / "scheduler.json"
    procs = [_dask("scheduler", "--scheduler-file", str(sched_file), "--port", "0", "--no-dashboard")]
    try:
        deadline = time.monotonic() + 60
        while not sched_file.exists() and time.monotonic() < deadline:
            time.sleep(0.1)
        assert sched_file.exists(), "the scheduler did not start"
        workers = [
            _dask("worker", "--scheduler-file", str(sched_file), "--nthreads", "1", "--no-nanny", "--no-dashboard",
                  "--death-timeout", "60")  # fmt: skip
            for _ in range(2)
        ]
        procs += workers
        address = json.loads(sched_file.read_text())["address"]
        with Client(address, timeout=60) as client:
            client.wait_for_workers(2, timeout=60)
        yield address, workers, sched_file
    finally:
        for p in reversed(procs):
            if p.poll() is None:
                os.killpg(p.pid, signal.SIGTERM)
        for p in procs:
            try:
                p.wait(timeout=20)
            except subprocess.TimeoutExpired:
                os.killpg(p.pid, signal.SIGKILL)


def test_a_dask_cluster_with_a_worker_killed_midway(campaign_file, pool_ledger, cluster, tmp_path):
    address, workers, _ = cluster
    out = tmp_path / "out"
    proc = start_cli("campaign", "run", str(campaign_file), "--out", str(out), "--dask", address,
                     "--batch-seconds", "0.3", "--json")  # fmt: skip
    wait_for_cases(out, 4, proc)
    assert proc.poll() is None, proc.communicate()
    os.killpg(workers[0].pid, signal.SIGKILL)  # Dask re-runs its tasks on the other worker
    stdout, stderr = proc.communicate(timeout=180)
    assert proc.returncode == 0, stderr
    result = json.loads(stdout)
    assert result["engine"].startswith(f"dask ({address})")
    assert result["remaining"] == 0 and result["ok"] + result["failed"] == N_CASES
    assert records(out) == records(pool_ledger)  # every case once, the same values


def test_a_scheduler_file(campaign_file, pool_ledger, cluster, tmp_path):
    _, _, sched_file = cluster
    out = tmp_path / "out"
    proc = start_cli("campaign", "run", str(campaign_file), "--out", str(out), "--dask-scheduler-file", str(sched_file),
                     "--quiet")  # fmt: skip
    _, stderr = proc.communicate(timeout=180)
    assert proc.returncode == 0, stderr
    assert records(out) == records(pool_ledger)


def test_a_local_cluster(campaign_file, pool_ledger, tmp_path):
    out = tmp_path / "out"
    proc = start_cli("campaign", "run", str(campaign_file), "--out", str(out), "--dask", "local", "--dask-workers", "2")
    stdout, stderr = proc.communicate(timeout=180)
    assert proc.returncode == 0, stderr
    assert "engine: dask (LocalCluster), 2 worker(s); dashboard: http://" in stderr
    assert records(out) == records(pool_ledger)


def test_an_unreachable_scheduler_is_one_clear_error():
    from jointlock.campaign import dask_cluster
    from jointlock.errors import CampaignError

    with pytest.raises(CampaignError, match=r"cannot reach the Dask cluster \(tcp://127.0.0.1:9\)"):
        dask_cluster("tcp://127.0.0.1:9", timeout_s=1.0)


def test_a_misspelt_address_and_a_missing_scheduler_file_are_one_line(tmp_path):
    from jointlock.campaign import dask_cluster
    from jointlock.errors import CampaignError

    with pytest.raises(CampaignError, match="did you mean 'local'"):
        dask_cluster("lcoal")
    with pytest.raises(CampaignError, match="does not exist: start the scheduler first"):
        dask_cluster(None, scheduler_file=str(tmp_path / "nosuch.json"))
