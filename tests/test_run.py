"""``jointlock run``: every example scenario runs (reduced sample counts through --set, as the
CLI allows) and its results.json has the documented keys; CLI options override the file;
writes are atomic."""

from __future__ import annotations

import contextlib
import io
import json
import os
from html import unescape
from pathlib import Path

import pytest

from jointlock.cli import main
from jointlock.report import atomic_write_text

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"

#: Reduced settings per example (the numbers checked here do not depend on them).
FAST = {
    "halt_000": ["--set", "halt_config.samples=3000", "--set", "halt.n_samples=201"],
    "jump_001": ["--set", "jump.sweep=6"],
    "replan_002": ["--set", "workspace.samples=4000", "--set", "replan.steps=10"],
    "singular_004": ["--set", "singular.samples=50"],
}
#: Keys of results.json (docs/scenarios.md).
TOP_KEYS = {"title", "scenario_file", "scenario", "seed", "versions", "jobs", "summary", "files"}
JOB_KEYS = {"paper", "command", "exit_code", "result"}
SUMMARY_KEYS = {
    "halt_config": {"q_best_deg", "cp_best"},
    "halt": {"feasible", "k_deg_s6", "global_torque_Nm", "global_torque_k0_Nm", "minimum_T_s"},
    "jump": {"mean_reduction", "share_improved", "limits_ok"},
    "tolerance_angle": {"absorbable_range_deg", "gamma_deg"},
    "replan": {"absorbed_waypoints", "max_tracking_position_error_m"},
    "workspace": {"volume_full_m3", "share_kept"},
    "singular": {"cond1", "cond2", "cond3", "cond4", "cond5"},
}


def cli(*argv: str) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(list(argv))
    return code, out.getvalue(), err.getvalue()


@pytest.mark.parametrize("name", sorted(FAST))
def test_example_runs_and_writes_documented_keys(tmp_path, name):
    out = tmp_path / name
    code, stdout, _ = cli("run", str(EXAMPLES / f"{name}.toml"), "--out", str(out), "--quiet", *FAST[name])
    assert code == 0 and stdout == ""
    res = json.loads((out / "results.json").read_text())
    assert TOP_KEYS <= set(res)
    assert set(res["versions"]) >= {"jointlock", "python", "numpy", "scipy", "matplotlib"}
    assert res["seed"] == res["scenario"]["seed"] == 0
    for job in res["scenario"]["jobs"]:
        assert JOB_KEYS <= set(res["jobs"][job]) and res["jobs"][job]["exit_code"] == 0
        assert res["jobs"][job]["command"].startswith("jointlock ")
        assert SUMMARY_KEYS[job] <= set(res["summary"][job])
    for f in res["files"]:
        assert (out / f).is_file(), f
    files = set(res["files"])
    assert {"report.html", "results.json", "figures/arm.png", "figures/arm.svg"} <= files
    assert not [p for p in out.rglob("*.tmp")]  # atomic writes leave no temporaries
    text = (out / "results.json").read_text()
    assert "NaN" not in text and "Infinity" not in text
    if name == "halt_000":
        # the halt configuration is searched among those the halt polynomial can reach
        assert "halt/halt_motion.csv" in files and res["summary"]["halt"]["feasible"] is True
        assert res["scenario"]["halt_config"]["reachable"] is True
        assert "limits applied by the halt" in (out / "report.html").read_text()
    if name == "jump_001":
        assert "jump/verification.csv" in files and 0 < res["summary"]["jump"]["mean_reduction"] < 1
    if name == "replan_002":
        assert "replan/trajectory.csv" in files
        assert res["summary"]["tolerance_angle"]["gamma_deg"] == pytest.approx(-1.4694, abs=1e-3)
    if name == "singular_004":
        s = res["summary"]["singular"]
        assert not s["cond1"]["sufficient"] and all(
            s[c]["sufficient"] for c in ("cond2", "cond3", "cond4", "cond5")
        )


def test_cli_options_override_the_file_and_json_is_clean(tmp_path):
    path = tmp_path / "ws.toml"
    path.write_text('robot = "puma6"\nseed = 3\nout = "ignored"\n[workspace]\nsamples = 100000\n')
    code, stdout, _ = cli(
        "run",
        str(path),
        "--out",
        str(tmp_path / "o"),
        "--seed",
        "5",
        "--lock",
        "2=60",
        "--set",
        "workspace.samples=2000",
        "--json",
    )
    assert code == 0
    res = json.loads(stdout)  # --json: one JSON object, nothing else on stdout
    assert res["seed"] == 5 and res["scenario"]["workspace"]["samples"] == 2000
    assert res["scenario"]["failure"] == {"joint": 2, "angle_deg": pytest.approx(60.0), "also_locked_deg": None, "time_s": None}
    assert "--lock 2=" in res["jobs"]["workspace"]["command"]
    assert (tmp_path / "o" / "report.html").is_file() and not (tmp_path / "ignored").exists()


def test_bad_scenario_exits_2_with_one_line(tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text('robot = "halt7"\n[halt_config]\nsampels = 10\n[failure]\njoint = 4\nangle_deg = 0\n')
    code, stdout, err = cli("run", str(path))
    assert code == 2 and stdout == ""
    assert err.count("\n") == 1 and "did you mean 'samples'" in err and str(path) in err


def test_interrupted_write_leaves_the_old_file(tmp_path, monkeypatch):
    target = tmp_path / "results.json"
    atomic_write_text(target, "old")

    def boom(*args):
        raise KeyboardInterrupt

    monkeypatch.setattr(os, "replace", boom)
    with pytest.raises(KeyboardInterrupt):
        atomic_write_text(target, "new, half written")
    assert target.read_text() == "old"
    assert [p.name for p in tmp_path.iterdir()] == ["results.json"]


# -- UX review ------------------------------------------------------------------------------------


def test_overridden_failure_is_marked_in_title_summary_and_report(tmp_path):
    out = tmp_path / "o"
    argv = ["run", str(EXAMPLES / "replan_002.toml"), "--lock", "2=52.0547", "--jobs", "tolerance_angle"]
    code, stdout, _ = cli(*argv, "--out", str(out))
    assert code == 0
    mark = "[failure overridden: joint 2 locked at 52.0547 deg]"
    assert mark in stdout.splitlines()[0]
    res = json.loads((out / "results.json").read_text())
    assert res["title"].endswith(mark)
    assert res["overrides"]["failure.angle_deg"] == {"file": 59.4, "value": pytest.approx(52.0547)}
    html = (out / "report.html").read_text()
    assert mark in html and "the file gives angle_deg = 59.4" in html
    # without the override the file's title stands
    code, stdout, _ = cli(
        "run", str(EXAMPLES / "replan_002.toml"), "--jobs", "tolerance_angle", "--out", str(out)
    )
    assert "overridden" not in stdout.splitlines()[0]


def test_halt_report_labels_limits_and_the_000_note(tmp_path):
    out = tmp_path / "h"
    code, _, _ = cli("run", str(EXAMPLES / "halt_000.toml"), "--out", str(out), "--quiet", *FAST["halt_000"])
    assert code == 0
    html = unescape((out / "report.html").read_text())
    assert "speed limit [deg/s]" in html and "acceleration limit [deg/s^2]" in html
    failure = html.split(">The failure</h2>")[1].split("</h2>")[0]
    # the limits table's rows are in words; where a limit came from names the scenario's field
    assert "limits.vmax_deg_s" in failure and "--vmax-deg" not in failure
    assert "000's headline numbers are not reproduced" in html  # halt7, joint 4 at 0: 000's case


def test_000_note_only_for_000s_scenario(tmp_path):
    from jointlock.robots import load_robot
    from jointlock.run._report import assumptions, is_000_case
    from jointlock.scenario import load_scenario

    def _model(sc):
        return load_robot(sc.data["robot"]), None

    for angle, expected in ((0.0, True), (10.0, False)):
        path = tmp_path / f"s{angle:g}.toml"
        own = "" if expected else "T = 10.0\n[state]\nq0_deg = [0, 0, 0, 0, 0, 0]\ndq0_deg = [0, 0, 0, 0, 0, 0]\nddq0_deg = [0, 0, 0, 0, 0, 0]\n"
        path.write_text(f'robot = "halt7"\n[failure]\njoint = 4\nangle_deg = {angle}\n[halt]\n{own}')
        sc = load_scenario(path)
        full, _ = _model(sc)
        assert is_000_case(sc, full) is expected
        assert any("not reproduced" in n for n in assumptions(sc, full)) is expected
    path = tmp_path / "puma.toml"
    path.write_text('robot = "puma6"\n[failure]\njoint = 4\nangle_deg = 0\n[workspace]\n')
    sc = load_scenario(path)
    assert not is_000_case(sc, _model(sc)[0])


def test_halt_k_label_by_feasibility():
    from jointlock.run._report import halt_k_label

    assert halt_k_label({"k": 0.00105573, "feasible": True}) == "k* = 0.00106 deg/s^6 (feasible)"
    label = halt_k_label({"k": [0.02], "feasible": False})
    assert label.startswith("least-violating k = 0.02 deg/s^6") and "k*" not in label


def test_singular_report_verdicts_and_no_failure(tmp_path):
    from jointlock.run._report import _condition_verdict

    assert _condition_verdict("cond1f", True) == "sufficient (ours)"
    assert _condition_verdict("cond2", True) == "reproduced"
    assert _condition_verdict("cond1", False) == "not reproduced: not sufficient"
    out = tmp_path / "s"
    code, stdout, _ = cli(
        "run", str(EXAMPLES / "singular_004.toml"), "--out", str(out), *FAST["singular_004"]
    )
    assert code == 0 and "cond1f sufficient (ours)" in stdout
    html = unescape((out / "report.html").read_text())
    assert "sufficient (ours)" in html
    failure = html.split(">The failure</h2>")[1].split("</h2>")[0]
    assert "no locked joint" in failure


def test_a_singular_study_of_canadarm7_writes_its_report(tmp_path):
    """A [singular] study (no verification) of a Canadarm2-structure arm: its conditions are the
    study's, not the verification's figure (the report once asked them for its sigma_tol)."""
    path = tmp_path / "s.toml"
    path.write_text('robot = "canadarm7"\n[singular]\nq_deg = [0, 30, 0, 45, 0, 20, 0]\n')
    code, stdout, _ = cli("run", str(path), "--out", str(tmp_path / "out"))
    assert code == 0 and "singular: sigma_min" in stdout
    assert (tmp_path / "out" / "report.html").is_file()


def test_singular_job_inherits_the_scenarios_base(tmp_path):
    path = tmp_path / "s.toml"
    path.write_text(
        'robot = "canadarm7"\nbase = "floating"\n[singular]\nq_deg = [0, 10, 20, 30, 40, 50, 60]\n'
    )
    out = tmp_path / "o"
    code, _, _ = cli("run", str(path), "--out", str(out), "--quiet")
    assert code == 0
    res = json.loads((out / "results.json").read_text())
    assert "--base floating" in res["jobs"]["singular"]["command"]
    assert res["jobs"]["singular"]["result"]["base"] == "floating"


def test_workspace_summary_prints_few_digits_and_the_half_sample_estimate(tmp_path):
    out = tmp_path / "w"
    code, stdout, _ = cli(
        "run",
        str(EXAMPLES / "replan_002.toml"),
        "--jobs",
        "workspace",
        "--out",
        str(out),
        *FAST["replan_002"],
    )
    assert code == 0
    line = next(x for x in stdout.splitlines() if x.strip().startswith("workspace:"))
    assert "half the samples" in line
    import re

    # a Monte Carlo share, to the percent (no estimate from these few samples), and its occupancy
    assert re.search(r"kept (\d+ ± \d+ %|no estimate) \(occupancy \d+ %", line)
