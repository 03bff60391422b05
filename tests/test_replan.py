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
from jointlock.papers import p002
from jointlock.planning.replan import (
    ReplanResult,
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
QD_A = np.radians(p002.A_QF_DEG)
PRINTED_QA = p002.A_Q_AT_GAMMA_DEG
# 002 §"... (fault-tolerant attitude error <= 10 deg)", eqs. (21)-(22)
QD_B = np.radians(p002.B_QF_DEG)
EQ22_DEG = p002.EQ22_DEG


@pytest.fixture(scope="module")
def puma() -> jl.ArmModel:
    return jl.load_robot("puma6")


@pytest.fixture(scope="module")
def sweep_a(puma):
    return gamma_sweep(puma, jl.ee_pose(puma, QD_A), q_ref=QD_A)


@pytest.mark.paper
def test_fig5_fig6_absorbable_ranges(sweep_a):
    """002: joint 2 compensates '48 deg to 123 deg' over +-180 deg, '59.2 to 60.8 deg' over +-2 deg."""
    wide = absorbable_range(sweep_a, 2, math.radians(p002.A_WIDE_GAMMA_DEG))
    narrow = absorbable_range(sweep_a, 2, math.radians(p002.A_NARROW_GAMMA_DEG))
    (lo, hi), (lo2, hi2) = p002.A_WIDE_RANGE_DEG, p002.A_NARROW_RANGE_DEG
    # ours 47.35 .. 123.23 deg; 002's "48" is read off Fig. 5 (1-deg digits, +-1 deg)
    assert abs(math.degrees(wide.lower) - lo) < 1.0
    assert round(math.degrees(wide.upper)) == hi
    assert round(math.degrees(narrow.lower), 1) == lo2
    assert round(math.degrees(narrow.upper), 1) == hi2


@pytest.mark.paper
def test_gamma_for_joint2_locked_at_59_4(puma):
    """002: gamma = -1.45 and q = [5.18, 59.40, 35.51, 9.89, -121.40, 89.76] deg.

    The exact root is gamma = -1.4694 deg; 002's vector is the IK at gamma = -1.45 deg
    exactly, truncated to 2 decimals (theta2 = 59.4079 there)."""
    target = jl.ee_pose(puma, QD_A)
    roots = gammas_for_lock(puma, target, 2, math.radians(p002.A_LOCK_DEG), q_ref=QD_A)
    best = roots[0]
    assert math.degrees(best.gamma) == pytest.approx(-1.4694, abs=1e-4)
    assert abs(math.degrees(best.gamma) - p002.A_GAMMA_DEG) < 0.02
    assert abs(best.q_full[1] - math.radians(p002.A_LOCK_DEG)) < ROOT_TOL
    res = ik_closed_form(puma, tool_x_rotation(target, math.radians(p002.A_GAMMA_DEG)))
    q = np.degrees(res.q_full[best.branch])
    assert np.array_equal(np.trunc(q * 100) / 100, PRINTED_QA)


@pytest.mark.paper
def test_gamma_minus_10_gives_eq21_eq22(puma):
    """002: joint 2 locked at 52.0547 deg, tolerance -10 deg -> eq. (21) pose and eq. (22)."""
    target = jl.ee_pose(puma, QD_B)
    roots = gammas_for_lock(puma, target, 2, math.radians(p002.B_LOCK_DEG), q_ref=QD_B)
    best = roots[0]
    assert round(math.degrees(best.gamma), 4) == p002.B_GAMMA_DEG
    # the printed lock angle is theta2(-10 deg) = 52.054712 deg rounded, so the exact root
    # sits 1.5e-5 deg away and moves the other joints by < 1e-4 deg ...
    assert np.abs(np.degrees(best.q_full) - EQ22_DEG).max() < 1e-4
    # ... while the IK at gamma = -10 deg exactly is eq. (22) to every printed digit
    exact = ik_closed_form(puma, tool_x_rotation(target, math.radians(p002.B_GAMMA_DEG)))
    assert np.abs(np.degrees(exact.q_full[best.branch]) - EQ22_DEG).max() <= PRINT4_DEG
    sweep = gamma_sweep(puma, target, np.radians(np.linspace(-10, 10, 201)), q_ref=QD_B)
    rng10 = absorbable_range(sweep, 2, math.radians(10.0))
    assert math.degrees(rng10.lower) == pytest.approx(p002.B_LOCK_DEG, abs=PRINT4_DEG)


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
    locked = jl.lock(puma, 2, math.radians(p002.B_LOCK_DEG))
    start = jl.ee_pose(puma, np.radians(p002.B_Q0_DEG))
    goal = jl.ee_pose(puma, QD_B)
    strict = replan_line(locked, start, goal, steps=30, q_ref=QD_B)
    loose = replan_line(locked, start, goal, steps=30, gamma_tolerance=math.radians(10.5), q_ref=QD_B)
    assert loose.absorbed.sum() > strict.absorbed.sum()
    assert np.all(np.abs(loose.gamma) <= math.radians(10.5) + 1e-12)
    assert loose.position_error[loose.absorbed].max() < 1e-9
    assert math.degrees(loose.gamma[-1]) == pytest.approx(p002.B_GAMMA_DEG, abs=1e-4)
    assert np.abs(np.degrees(wrap_angle(loose.q_full[-1])) - EQ22_DEG).max() < 1e-4


# 002 §"... (fault-tolerant attitude error <= 10 deg)": the line whose pointwise plan jumps
Q0_B = np.radians(p002.B_Q0_DEG)
LOCK_B = math.radians(p002.B_LOCK_DEG)


@pytest.fixture(scope="module")
def plans_b(puma):
    """002's second example (41 steps, 250 ms, gamma within 10 deg): pointwise vs continuous."""
    locked = jl.lock(puma, 2, LOCK_B)
    start, goal = jl.ee_pose(puma, Q0_B), jl.ee_pose(puma, QD_B)
    kw = dict(steps=40, cycle=0.25, gamma_tolerance=math.radians(10.0), q_ref=QD_B)
    return (
        locked,
        replan_line(locked, start, goal, method="pointwise", **kw),
        replan_line(locked, start, goal, **kw),
    )


def _path_length_inf(res: ReplanResult) -> float:
    """Joint-space path length in the max norm: sum over steps of the largest joint change [rad]."""
    return float(res.joint_step.max(axis=1).sum())


def test_pointwise_plan_of_002_second_example_jumps(plans_b):
    """The first implementation switches gamma from -10 to +10 deg at t = 5.75 s: joint 1 jumps 160 deg."""
    _, pointwise, _ = plans_b
    assert pointwise.method == "pointwise"
    assert math.degrees(pointwise.max_joint_step) == pytest.approx(160.29, abs=0.01)
    assert pointwise.max_joint_step_at == (23, 1)
    assert (
        math.degrees(pointwise.gamma[23]) == pytest.approx(-10.0)
        and math.degrees(pointwise.gamma[24]) == 10.0
    )
    flagged = {(f.index, f.joint) for f in pointwise.jumps}
    assert (23, 1) in flagged and (23, 6) in flagged
    assert all(f.step > pointwise.jump_threshold for f in pointwise.jumps)
    assert pointwise.max_joint_step > 0.5 * _path_length_inf(pointwise)  # one step is most of the path


def test_continuous_plan_of_002_second_example_has_no_jump(plans_b):
    locked, pointwise, res = plans_b
    assert res.method == "continuous"
    steps = res.joint_step.max(axis=1)
    # no step above a tenth of the path length (max norm) nor above 4x the mean step
    assert res.max_joint_step <= 0.1 * _path_length_inf(res)
    assert res.max_joint_step <= 4.0 * steps.mean()
    assert math.degrees(res.max_joint_step) < 20.0 < math.degrees(pointwise.max_joint_step) / 8
    assert res.jumps == ()
    assert np.array_equal(res.joint_step, np.abs(np.diff(res.q, axis=0)))
    assert np.all(np.abs(np.diff(res.q, axis=0)) < math.pi)  # q is continuous, no 2 pi wrap inside
    # gamma stays within the tolerance
    assert np.all(np.abs(res.gamma) <= math.radians(10.0) + 1e-12)
    # the goal is the pose of eq. (21) on eq. (22)'s branch (the exact root -10.000015 deg is
    # 1.5e-5 deg outside the tolerance, so gamma = -10 deg and the arm misses by < 1e-7 m)
    assert math.degrees(res.gamma[-1]) == pytest.approx(p002.B_GAMMA_DEG, abs=1e-9)
    assert np.abs(np.degrees(wrap_angle(res.q_full[-1])) - EQ22_DEG).max() < 1e-4
    assert res.absorbed[-1] and res.position_error[-1] < 1e-7


def test_continuous_plan_reports_tracking_error_honestly(plans_b):
    locked, pointwise, res = plans_b
    # the tracking error is the locked arm's FK against nominal Rx(gamma), recomputed here
    target = tool_x_rotation(res.nominal, res.gamma)
    dp, dr = pose_error(target, jl.ee_pose(locked, res.q))
    assert np.allclose(dp, res.position_error, atol=1e-12, rtol=0)
    assert np.allclose(dr, res.rotation_error, atol=1e-12, rtol=0)
    assert np.array_equal(res.absorbed, (dp <= 1e-7) & (dr <= 1e-7))
    # the lock is absorbed exactly at the start and end of the line (20 of 42 waypoints) ...
    assert res.absorbed.sum() >= 18
    assert res.position_error[res.absorbed].max() < 1e-7
    # ... and where it is not, the price of continuity is a larger (reported) tracking error
    # than the jumping plan's: up to ~109 mm instead of 72 mm, as the line passes near the
    # base axis (joint 1 has to turn 170 deg)
    assert 0.06 < pointwise.position_error.max() < 0.08
    assert 0.08 < res.position_error.max() < 0.13
    assert np.all(res.rotation_error < 1e-9)  # the joint-2-locked closed form keeps the orientation
    assert np.abs(np.degrees(res.q_full[-1, 0] - res.q_full[0, 0])) > 150


def test_continuous_plan_tolerances_and_weights(puma):
    locked = jl.lock(puma, 2, LOCK_B)
    start, goal = jl.ee_pose(puma, Q0_B), jl.ee_pose(puma, QD_B)
    for tol_deg in (0.0, 3.0, 10.5):
        res = replan_line(locked, start, goal, steps=15, gamma_tolerance=math.radians(tol_deg), q_ref=QD_B)
        assert np.all(np.abs(res.gamma) <= math.radians(tol_deg) + 1e-12)
        assert res.position_error[res.absorbed].max(initial=0.0) < 1e-7
    # a heavier step weight never gives a larger largest step here; a light one drifts to the jump
    kw = dict(steps=40, gamma_tolerance=math.radians(10.0), q_ref=QD_B)
    heavy = replan_line(locked, start, goal, step_weight=2.0, **kw)
    light = replan_line(locked, start, goal, step_weight=0.01, **kw)  # 78 deg on joint 1
    assert heavy.max_joint_step < math.radians(12.0)
    assert light.max_joint_step > math.radians(60.0) and light.jumps
    with pytest.raises(ConfigurationError, match="method"):
        replan_line(locked, start, goal, method="greedy")
    with pytest.raises(ConfigurationError, match="step_weight"):
        replan_line(locked, start, goal, step_weight=-1.0)


def test_continuous_equals_pointwise_when_lock_matches(puma):
    """002's first example (no tolerance): gamma = 0 everywhere, both choose the same branch."""
    locked = jl.lock(puma, 2, math.radians(60.0))
    start = jl.ee_pose(puma, np.radians([0, 60, 30, 10, -80, 30]))
    goal = jl.ee_pose(puma, QD_B)
    a = replan_line(locked, start, goal, steps=40, q_ref=QD_B, method="pointwise")
    b = replan_line(locked, start, goal, steps=40, q_ref=QD_B)
    assert np.allclose(a.q, b.q, atol=1e-12) and np.all(b.gamma == 0)
    assert math.degrees(b.max_joint_step) == pytest.approx(1.538, abs=1e-3) and b.jumps == ()


def test_velocity_limits_flagged(puma):
    """Steps needing more than a joint's speed limit at the cycle time are listed."""
    from dataclasses import replace

    limit = math.radians(30.0)
    slow = replace(puma, joints=tuple(replace(j, velocity_limit=limit) for j in puma.joints))
    locked = jl.lock(slow, 2, LOCK_B)
    start, goal = jl.ee_pose(puma, Q0_B), jl.ee_pose(puma, QD_B)
    res = replan_line(locked, start, goal, steps=40, gamma_tolerance=math.radians(10.0), q_ref=QD_B)
    assert np.all(res.velocity_limit == limit)
    over = res.joint_step / 0.25 > limit
    assert len(res.over_velocity) == over.sum() > 0
    assert {(f.index, f.joint) for f in res.over_velocity} == {
        (i, locked.joint_numbers[j]) for i, j in zip(*np.nonzero(over))
    }
    assert all(f.rate > f.limit == limit for f in res.over_velocity)
    fast = replace(puma, joints=tuple(replace(j, velocity_limit=math.radians(100.0)) for j in puma.joints))
    res = replan_line(
        jl.lock(fast, 2, LOCK_B), start, goal, steps=40, gamma_tolerance=math.radians(10), q_ref=QD_B
    )
    assert res.over_velocity == ()


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
    assert out["method"] == "continuous" and out["jumps"] == []
    assert out["max_joint_step_deg"] < 10 and out["max_joint_step_at"]["joint"] in (1, 3, 4, 5, 6)


def test_cli_replan_reports_the_jump(capsys):
    """002's second example: the pointwise plan's jump is reported, the continuous plan has none."""
    argv = ["replan", "puma6", "--from-deg", "0", "30", "30", "10", "-80", "30", "--to-deg", "5", "60"]
    argv += ["65", "10", "-120", "90", "--lock", "2=52.0547", "--tolerance-deg", "10", "--json"]
    old = _json(capsys, argv + ["--method", "pointwise"])
    new = _json(capsys, argv)
    assert old["max_joint_step_at"] == {"step": 23, "time_s": 5.75, "joint": 1}
    assert old["max_joint_step_deg"] == pytest.approx(160.29, abs=0.01)
    assert {"step": 23, "joint": 1} in [{"step": j["step"], "joint": j["joint"]} for j in old["jumps"]]
    assert new["jumps"] == [] and new["max_joint_step_deg"] < 20
    assert new["velocity_limit_deg_s"] == [None] * 5 and new["over_velocity"] == []
    assert -10 - 1e-9 <= new["gamma_deg_range"][0] and new["gamma_deg_range"][1] <= 10 + 1e-9
    assert new["max_tracking_position_error_m"] > old["max_tracking_position_error_m"]


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


# -- UX review: --steps, jump threshold, velocity legend --------------------------------------------


def test_cli_replan_refuses_zero_steps(capsys):
    argv = ["replan", "puma6", "--lock", "2=59.4", "--from-deg", "0", "60", "0", "0", "0", "0"]
    argv += ["--to-deg", "5", "60", "35", "10", "-120", "90", "--steps", "0"]
    with pytest.raises(SystemExit) as info:  # refused by the option's type, before anything runs
        main(argv)
    assert info.value.code == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "argument --steps: must be an integer >= 1 and <= 100000; got '0'" in err


def test_default_jump_threshold_is_capped():
    """A plan too coarse to follow the line (one interior point): the default threshold, 5x the
    median step, would exceed the steps themselves; capped at 30 deg, the big steps are flagged."""
    from jointlock.planning.replan import JUMP_MAX_STEP

    full = jl.load_robot("puma6")
    model = jl.lock(full, 2, math.radians(59.4))
    start = jl.ee_pose(full, np.radians([0, 60, 0, 0, 0, 0]))
    goal = jl.ee_pose(full, np.radians([5, 60, 35, 10, -120, 90]))
    res = replan_line(model, start, goal, steps=1, cycle=0.25, q_ref=np.radians([5, 60, 35, 10, -120, 90]))
    assert res.jump_threshold == pytest.approx(JUMP_MAX_STEP)
    assert res.max_joint_step > JUMP_MAX_STEP and res.jumps
    # a fine plan keeps its median-based threshold
    fine = replan_line(model, start, goal, steps=40, cycle=0.25, q_ref=np.radians([5, 60, 35, 10, -120, 90]))
    assert fine.jump_threshold < JUMP_MAX_STEP


def test_cli_replan_velocity_legend(tmp_path, monkeypatch):
    import matplotlib.axes

    labels: list[str] = []
    real = matplotlib.axes.Axes.plot

    def spy(self, *args, **kwargs):
        if "label" in kwargs:
            labels.append(kwargs["label"])
        return real(self, *args, **kwargs)

    monkeypatch.setattr(matplotlib.axes.Axes, "plot", spy)
    argv = ["replan", "puma6", "--lock", "2=60", "--from-deg", "0", "60", "0", "0", "0", "0"]
    argv += [
        "--to-deg",
        "5",
        "60",
        "35",
        "10",
        "-120",
        "90",
        "--steps",
        "4",
        "--json",
        "--out",
        str(tmp_path),
    ]
    assert main(argv) == 0
    assert {"vx", "vy", "vz", "wx", "wy", "wz"} <= set(labels)


@pytest.mark.parametrize("q5_deg", [30.0, 45.0])
def test_a_target_already_at_the_lock_angle_is_absorbed_at_gamma_zero(q5_deg):
    """theta_5(gamma) of puma6 at q = (0, 0, 0, 0, q5, 0) has its minimum, q5, at gamma = 0:
    the root touches the lock angle without crossing it, which a sign-change search misses
    (found by a first-user walkthrough: "no gamma within +-180 deg" for the target itself)."""
    from jointlock.planning.replan import gammas_for_lock

    arm = jl.load_robot("puma6")
    q = np.radians([0.0, 0.0, 0.0, 0.0, q5_deg, 0.0])
    roots = gammas_for_lock(arm, jl.ee_pose(arm, q), 5, math.radians(q5_deg), q_ref=q)
    assert roots and abs(roots[0].gamma) < 1e-6
