"""``jointlock run``: every example scenario runs (reduced sample counts through --set, as the
CLI allows) and its results.json has the documented keys; CLI options override the file;
writes are atomic."""

from __future__ import annotations

import contextlib
import io
import json
import os
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
    assert res["scenario"]["failure"] == {"joint": 2, "angle_deg": pytest.approx(60.0), "time_s": None}
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
