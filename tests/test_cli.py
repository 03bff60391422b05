"""The installed ``jointlock`` command (the console script, not just the module)."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import jointlock as jl

SCRIPT = Path(sys.executable).parent / "jointlock"


def run(*args: str, check: bool = True) -> subprocess.CompletedProcess:
    proc = subprocess.run(
        [str(SCRIPT), *args],
        capture_output=True,
        text=True,
        timeout=300,
        env={"MPLBACKEND": "Agg", "PATH": "/usr/bin:/bin"},
    )
    if check and proc.returncode != 0:
        raise AssertionError(f"exit {proc.returncode}: {proc.stderr}")
    return proc


def test_console_script_is_installed():
    assert SCRIPT.exists(), f"{SCRIPT} missing: is jointlock installed in this environment?"
    assert run("--version").stdout.startswith("jointlock ")


def test_robots_json_lists_every_builtin():
    data = json.loads(run("robots", "--json").stdout)
    names = [r["name"] for r in data["robots"]]
    assert names == list(jl.BUILTIN_ROBOTS)
    halt7 = data["robots"][0]
    assert halt7["dof"] == 7 and halt7["masses_kg"][2] == 70.0


def test_kinematics_json_matches_the_library():
    q_deg = [-180, -180, -100, -10, 20, 20]
    out = json.loads(
        run("kinematics", "halt7", "--lock", "4=0", "--q-deg", *map(str, q_deg), "--json").stdout
    )
    model = jl.lock(jl.load_robot("halt7"), 4, 0.0)
    q = np.radians(q_deg)
    np.testing.assert_allclose(out["pose"], jl.ee_pose(model, q), atol=1e-12)
    np.testing.assert_allclose(out["jacobian"], jl.jacobian(model, q), atol=1e-12)
    np.testing.assert_allclose(out["singular_values"], np.linalg.svd(jl.jacobian(model, q), compute_uv=False))
    assert out["joint_numbers"] == [1, 2, 3, 5, 6, 7]


def test_kinematics_floating_gives_the_generalized_jacobian():
    out = json.loads(run("kinematics", "canadarm7", "--base", "floating", "--json").stdout)
    model = jl.load_robot("canadarm7", base="floating")
    np.testing.assert_allclose(out["jacobian"], jl.generalized_jacobian(model, np.zeros(7)), atol=1e-12)
    assert out["jacobian_kind"] == "generalized"


def test_kinematics_reads_a_urdf_file():
    urdf = Path(__file__).parent / "data" / "arm5.urdf"
    out = json.loads(run("kinematics", str(urdf), "--q-deg", "10", "20", "30", "40", "50", "--json").stdout)
    assert np.asarray(out["jacobian"]).shape == (6, 5)


@pytest.mark.parametrize(
    "args, message",
    [
        (["kinematics", "halt8"], "did you mean 'halt7'"),
        (["kinematics", "halt7", "--lock", "9=0"], "one of the movable joints"),
        (["kinematics", "halt7", "--q-deg", "1", "2"], "--q-deg needs 7 values"),
        (["kinematics", "halt7", "--lock", "4=zero"], "--lock must look like J=DEG"),
        (["kinematics", "puma6", "--q-deg", "nan", "0", "0", "0", "0", "0"], "must be a finite number"),
        (["kinematics", "/nonexistent.urdf"], "URDF file '/nonexistent.urdf' does not exist"),
    ],
)
def test_errors_are_one_line_without_traceback(args, message):
    proc = run(*args, check=False)
    assert proc.returncode == 2
    assert message in proc.stderr
    assert "Traceback" not in proc.stderr
    assert proc.stdout == ""


def test_demo_writes_its_report(tmp_path):
    run("demo", "--out", str(tmp_path / "demo"), "--quiet")
    results = json.loads((tmp_path / "demo" / "results.json").read_text())
    assert set(results["robots"]) == set(jl.BUILTIN_ROBOTS)
    for r in results["robots"].values():
        assert max(max(row["pose_error_m"], row["jacobian_error"]) for row in r["lock_equivalence"]) < 1e-9
    html = (tmp_path / "demo" / "report.html").read_text()
    assert html.startswith("<!DOCTYPE html>") and "data:image/png;base64," in html
