"""Fault-tolerance angle gamma and straight-line re-planning (seed 002)."""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import jointlock as jl
from jointlock.cli import main
from jointlock.errors import ConfigurationError, ModelError
from jointlock.ik import ik_closed_form, wrap_angle
from jointlock.planning.replan import (
    absorbable_range,
    gamma_sweep,
    gammas_for_lock,
    line_waypoints,
    replan_line,
    tool_x_rotation,
)
from jointlock.spatial import pose_error

#: 002 prints joint angles with 4 decimals [deg].
PRINT4_DEG = 0.5e-4 + 1e-9
#: Bisected roots put the locked joint on its angle to round-off [rad].
ROOT_TOL = 1e-10

# 002 §"The analysis of fault tolerance under a single joint failure" (Figs. 5-8)
QD_A = np.radians([5, 60, 35, 10, -120, 90])
PRINTED_QA = [5.18, 59.40, 35.51, 9.89, -121.40, 89.76]
# 002 §"... (fault-tolerant attitude error <= 10 deg)", eqs. (21)-(22)
QD_B = np.radians([5, 60, 65, 10, -120, 90])
EQ22_DEG = [10.5789, 52.0547, 66.1915, 8.5610, -124.0978, 82.7611]


@pytest.fixture(scope="module")
def puma() -> jl.ArmModel:
    return jl.load_robot("puma6")


@pytest.fixture(scope="module")
def sweep_a(puma):
    return gamma_sweep(puma, jl.ee_pose(puma, QD_A), q_ref=QD_A)


@pytest.mark.paper
def test_fig5_fig6_absorbable_ranges(sweep_a):
    """002: joint 2 compensates '48 deg to 123 deg' over +-180 deg, '59.2 to 60.8 deg' over +-2 deg."""
    wide = absorbable_range(sweep_a, 2, math.pi)
    narrow = absorbable_range(sweep_a, 2, math.radians(2.0))
    # ours 47.35 .. 123.23 deg; 002's "48" is read off Fig. 5 (1-deg digits, +-1 deg)
    assert abs(math.degrees(wide.lower) - 48.0) < 1.0
    assert round(math.degrees(wide.upper)) == 123
    assert round(math.degrees(narrow.lower), 1) == 59.2
    assert round(math.degrees(narrow.upper), 1) == 60.8


@pytest.mark.paper
def test_gamma_for_joint2_locked_at_59_4(puma):
    """002: gamma = -1.45 and q = [5.18, 59.40, 35.51, 9.89, -121.40, 89.76] deg.

    The exact root is gamma = -1.4694 deg; 002's vector is the IK at gamma = -1.45 deg
    exactly, truncated to 2 decimals (theta2 = 59.4079 there)."""
    target = jl.ee_pose(puma, QD_A)
    roots = gammas_for_lock(puma, target, 2, math.radians(59.4), q_ref=QD_A)
    best = roots[0]
    assert math.degrees(best.gamma) == pytest.approx(-1.4694, abs=1e-4)
    assert abs(math.degrees(best.gamma) - (-1.45)) < 0.02
    assert abs(best.q_full[1] - math.radians(59.4)) < ROOT_TOL
    res = ik_closed_form(puma, tool_x_rotation(target, math.radians(-1.45)))
    q = np.degrees(res.q_full[best.branch])
    assert np.array_equal(np.trunc(q * 100) / 100, PRINTED_QA)


@pytest.mark.paper
def test_gamma_minus_10_gives_eq21_eq22(puma):
    """002: joint 2 locked at 52.0547 deg, tolerance -10 deg -> eq. (21) pose and eq. (22)."""
    target = jl.ee_pose(puma, QD_B)
    roots = gammas_for_lock(puma, target, 2, math.radians(52.0547), q_ref=QD_B)
    best = roots[0]
    assert round(math.degrees(best.gamma), 4) == -10.0
    # the printed lock angle is theta2(-10 deg) = 52.054712 deg rounded, so the exact root
    # sits 1.5e-5 deg away and moves the other joints by < 1e-4 deg ...
    assert np.abs(np.degrees(best.q_full) - EQ22_DEG).max() < 1e-4
    # ... while the IK at gamma = -10 deg exactly is eq. (22) to every printed digit
    exact = ik_closed_form(puma, tool_x_rotation(target, math.radians(-10.0)))
    assert np.abs(np.degrees(exact.q_full[best.branch]) - EQ22_DEG).max() <= PRINT4_DEG
    sweep = gamma_sweep(puma, target, np.radians(np.linspace(-10, 10, 201)), q_ref=QD_B)
    rng10 = absorbable_range(sweep, 2, math.radians(10.0))
    assert math.degrees(rng10.lower) == pytest.approx(52.0547, abs=PRINT4_DEG)


def test_sweep_batched_equals_single_calls(puma, sweep_a):
    target = jl.ee_pose(puma, QD_A)
    idx = [0, 900, 1800, 2500, 3600]
    for k in idx:
        one = ik_closed_form(puma, tool_x_rotation(target, sweep_a.gammas[k]))
        assert np.allclose(wrap_angle(one.q_full[sweep_a.branch] - sweep_a.q[k]), 0.0, atol=1e-12)
    assert np.all(np.abs(np.diff(sweep_a.q[:, 1])) < 0.05)  # followed branch is continuous


def test_roots_put_locked_joint_on_its_angle(puma, rng):
    for _ in range(5):
        q = rng.uniform(-2.5, 2.5, 6)
        target = jl.ee_pose(puma, q)
        angle = q[2] + 0.05
        for r in gammas_for_lock(puma, target, 3, angle, q_ref=q):
            assert abs(wrap_angle(r.q_full[2] - angle)) < ROOT_TOL
            dp, dr = pose_error(tool_x_rotation(target, r.gamma), jl.ee_pose(puma, r.q_full))
            assert dp < 1e-9 and dr < 1e-9


def test_replan_line_exact_when_lock_matches(puma):
    """002 'without fault-tolerant attitude error': both ends have theta2 = the lock angle."""
    lock = math.radians(60.0)
    locked = jl.lock(puma, 2, lock)
    q0 = np.radians([0, 60, 30, 10, -80, 30])
    start, goal = jl.ee_pose(puma, q0), jl.ee_pose(puma, QD_B)
    res = replan_line(locked, start, goal, steps=20, cycle=0.25, q_ref=QD_B)
    assert res.q.shape == (22, 5) and res.times[-1] == pytest.approx(21 * 0.25)
    assert np.all(res.q_full[:, 1] == lock)
    assert res.absorbed[0] and res.absorbed[-1]
    assert res.position_error[[0, -1]].max() < 1e-9
    assert np.allclose(wrap_angle(res.q_full[-1] - QD_B), 0, atol=1e-9)
    dp, dr = pose_error(res.actual, jl.ee_pose(locked, res.q))
    assert dp.max() < 1e-12
    # the line itself (eqs. 19-20)
    assert np.allclose(res.nominal[:, :3, 3], np.linspace(start[:3, 3], goal[:3, 3], 22))
    assert np.all(res.rotation_error < 1e-9)  # the locked closed form keeps the orientation


def test_replan_tolerance_absorbs_more(puma):
    locked = jl.lock(puma, 2, math.radians(52.0547))
    start = jl.ee_pose(puma, np.radians([0, 30, 30, 10, -80, 30]))
    goal = jl.ee_pose(puma, QD_B)
    strict = replan_line(locked, start, goal, steps=30, q_ref=QD_B)
    loose = replan_line(locked, start, goal, steps=30, gamma_tolerance=math.radians(10.5), q_ref=QD_B)
    assert loose.absorbed.sum() > strict.absorbed.sum()
    assert np.all(np.abs(loose.gamma) <= math.radians(10.5) + 1e-12)
    assert loose.position_error[loose.absorbed].max() < 1e-9
    assert math.degrees(loose.gamma[-1]) == pytest.approx(-10.0, abs=1e-4)
    assert np.abs(np.degrees(wrap_angle(loose.q_full[-1])) - EQ22_DEG).max() < 1e-4


def test_replan_errors(puma):
    with pytest.raises(ModelError, match="locked"):
        replan_line(puma, np.eye(4), np.eye(4))
    with pytest.raises(ConfigurationError, match="cycle"):
        replan_line(jl.lock(puma, 2, 1.0), np.eye(4), np.eye(4), cycle=0.0)
    with pytest.raises(ConfigurationError, match="steps"):
        line_waypoints(np.eye(4), np.eye(4), -1)


# -- command line --------------------------------------------------------------------------


def _json(capsys, argv):
    assert main(argv) == 0
    return json.loads(capsys.readouterr().out)


@pytest.mark.paper
def test_cli_tolerance_angle(capsys, tmp_path):
    out = _json(
        capsys,
        [
            "tolerance-angle",
            "puma6",
            "--q-target-deg",
            "5",
            "60",
            "35",
            "10",
            "-120",
            "90",
            "--lock",
            "2=59.4",
            "--json",
            "--out",
            str(tmp_path),
        ],
    )
    assert out["chosen"]["gamma_deg"] == pytest.approx(-1.4694, abs=1e-4)
    assert out["chosen"]["q_deg"][1] == pytest.approx(59.4, abs=1e-9)
    assert (tmp_path / "joints_vs_gamma.png").stat().st_size > 1000


def test_cli_replan(capsys, tmp_path):
    out = _json(
        capsys,
        [
            "replan",
            "puma6",
            "--from-deg",
            "0",
            "60",
            "30",
            "10",
            "-80",
            "30",
            "--to-deg",
            "5",
            "60",
            "65",
            "10",
            "-120",
            "90",
            "--lock",
            "2=60",
            "--steps",
            "10",
            "--json",
            "--out",
            str(tmp_path),
        ],
    )
    assert out["waypoints"] == 12
    assert len(out["trajectory"]["q_deg"]) == 12
    assert out["q_goal_deg"] == pytest.approx([5, 60, 65, 10, -120, 90], abs=1e-7)
    for name in ("joints.png", "pose.png", "error.png", "velocity.png", "trajectory.csv"):
        assert (tmp_path / name).exists()


def test_cli_ik_installed_entry_point():
    """The console script runs and prints only JSON with --json."""
    exe = [str(Path(sys.executable).with_name("jointlock"))]
    args = [
        "ik",
        "puma6",
        "--pose",
        "-0.0983390",
        "-0.0662696",
        "-0.0378197",
        "89.227",
        "-8.176",
        "-4.5890",
        "--lock",
        "2=52.0547",
        "--json",
    ]
    proc = subprocess.run(exe + args, capture_output=True, text=True, check=True)
    out = json.loads(proc.stdout)
    assert out["reachable"] is False
    assert out["nearest"]["distance_position_m"] < 1e-3
    assert "q_deg" in out["candidates"][0]


def test_cli_ik_full_arm(capsys):
    out = _json(capsys, ["ik", "puma6", "--pose", "0.5", "0.2", "-0.4", "10", "20", "30", "--json"])
    assert out["reachable"] and len(out["solutions"]) == 8
    assert all(s["position_error_m"] < 1e-9 for s in out["solutions"])


def test_cli_bad_lock_is_an_error(capsys):
    code = main(["tolerance-angle", "puma6", "--q-target-deg", "5", "60", "35", "10", "-120", "90"])
    assert code == 2
    assert "--lock" in capsys.readouterr().err
