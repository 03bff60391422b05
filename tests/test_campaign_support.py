"""What campaigns rely on elsewhere in the library: models built once per process (a model file
read again when it changes), the halt's smallest feasible time on request, the progress bar's
rate and time left."""

from __future__ import annotations

import io
import os
import shutil
from pathlib import Path

import pytest

import jointlock as jl
from jointlock.progress import Progress

DATA = Path(__file__).resolve().parent / "data"


def test_built_in_models_are_built_once_per_process():
    assert jl.load_robot("halt7") is jl.load_robot("halt7")
    assert jl.load_robot("halt7", base="floating") is not jl.load_robot("halt7")


def test_a_model_file_is_read_again_when_it_changes(tmp_path):
    path = tmp_path / "arm.urdf"
    shutil.copy(DATA / "arm5.urdf", path)
    first = jl.load_robot(str(path))
    assert jl.load_robot(str(path)) is first
    text = path.read_text()
    assert 'mass value="' in text
    path.write_text(text.replace('mass value="', 'mass value="1', 1))
    os.utime(path, ns=(path.stat().st_atime_ns, path.stat().st_mtime_ns + 10**9))
    second = jl.load_robot(str(path))
    assert second is not first and second.total_mass != first.total_mass


def test_the_halt_finds_its_smallest_time_on_request():
    plan = jl.plan_halt(
        "halt7",
        search=jl.HaltSearch(samples=2000),
        motion=jl.HaltMotionSettings(minimum_T=True),
    )
    assert plan.feasible
    t_min = plan.motion.minimum_T
    assert t_min is not None and t_min < 10.0
    from jointlock.planning.halt_motion import shared_k_interval

    lo, hi = shared_k_interval(plan.problem.with_time(t_min + 0.01))
    assert lo <= hi  # feasible just above
    lo, hi = shared_k_interval(plan.problem.with_time(t_min - 0.01))
    assert lo > hi  # infeasible just below
    assert plan.to_dict()["minimum_T_s"] == t_min
    assert any("smallest halt time with a feasible k" in line for line in plan.summary())
    assert jl.plan_halt("halt7", search=jl.HaltSearch(samples=2000)).motion.minimum_T is None  # the default: not searched


def test_the_minimum_T_field_reaches_the_halt_and_its_equivalent_command(tmp_path):
    examples = Path(__file__).resolve().parents[1] / "examples"
    sc = jl.load_scenario(
        examples / "halt_000.toml",
        {"halt.minimum_T": True, "halt_config.samples": 1000, "halt_config.no_refine": True, "halt.n_samples": 101},
    )
    run = jl.run_scenario(sc)
    assert run["halt"].to_dict()["minimum_T_s"] is not None
    assert "--minimum-T" in run.to_dict()["jobs"]["halt"]["command"]
    assert "--minimum-T" not in jl.run_scenario(
        jl.load_scenario(examples / "halt_000.toml", {"halt_config.samples": 1000, "halt.n_samples": 101})
    ).to_dict()["jobs"]["halt"]["command"]


@pytest.mark.parametrize("note", ["", "2 failed"])
def test_progress_shows_count_rate_and_time_left(note):
    stream = io.StringIO()
    bar = Progress(10, "cases", enabled=True, stream=stream, unit="cases", initial=4)
    bar.update(6, note=note)
    bar.close()
    text = stream.getvalue()
    assert "10/10" in text and "cases/s" in text and "100%" in text and "<00:00" in text  # done, rate, time left
    assert (note in text) if note else "failed" not in text


def test_atomic_writes_go_through_links_and_refuse_folders(tmp_path):
    from jointlock.io.files import atomic_write_text

    real = tmp_path / "real.csv"
    real.write_text("old")
    link = tmp_path / "link.csv"
    link.symlink_to(real)
    atomic_write_text(link, "new")
    assert link.is_symlink() and real.read_text() == "new"
    with pytest.raises(IsADirectoryError, match="is a folder"):
        atomic_write_text(tmp_path, "x")
    assert not list(tmp_path.glob(".*.tmp"))


def test_progress_off_a_terminal_logs_a_line_now_and_then():
    stream = io.StringIO()  # not a terminal: no bar
    bar = Progress(5, "cases", stream=stream, unit="cases", log_every_s=3600.0)
    for _ in range(5):
        bar.update(1)
    bar.close()
    lines = stream.getvalue().splitlines()
    assert len(lines) == 2 and "\r" not in stream.getvalue()  # the first and the last
    assert lines[-1].startswith("cases [") and "5/5 cases" in lines[-1]
    quiet = io.StringIO()
    Progress(5, "cases", stream=quiet, unit="cases").update(5)  # no log_every_s: silent
    assert quiet.getvalue() == ""


def test_a_workers_cases_do_not_import_matplotlib():
    """A campaign worker's halt and jump cases draw nothing, so they leave matplotlib (0.1 s of
    every worker's start) unimported: a fresh interpreter runs one case of each example
    campaign as a worker does."""
    import subprocess
    import sys

    script = """
import sys
from jointlock import campaign
from jointlock.campaign._cases import plan_cases
from jointlock.campaign._columns import check_columns
for name in sys.argv[1:]:
    spec = campaign.load_campaign(name)
    plan = plan_cases(spec)
    (outcome,) = campaign.run_batch(campaign.make_task(spec, list(plan.cases[:1]), check_columns(spec, plan)))
    assert outcome.ok, outcome
print("matplotlib" in sys.modules)
"""
    examples = Path(__file__).resolve().parents[1] / "examples" / "campaigns"
    out = subprocess.run(
        [sys.executable, "-c", script, str(examples / "halt7.toml"), str(examples / "jump_canadarm7.toml")],
        capture_output=True, text=True, check=True,
    )  # fmt: skip
    assert out.stdout.split()[-1] == "False"
