"""Closed-form IK of 6R arms with a spherical wrist and parallel shoulder-elbow axes (issue 15,
item 4): Puma560 with its shoulder and forearm offsets, a KUKA KR and an ABB IRB, by the DH
tables roboticstoolbox publishes.  Round trips, every joint locked in turn, the free joint at
singularities, and EAIK (an independent analytic solver) as oracle: every exact EAIK branch
is among ours, locked arms included."""

from __future__ import annotations

import numpy as np
import pytest

import jointlock as jl
from jointlock.ik import EXACT_POSITION_TOL, closed_form_family, ik_closed_form, solve_ik, wrap_angle
from jointlock.ik._spherical import spherical_wrist_geometry
from jointlock.spatial import pose_error, rot_x, rot_z, translation

HALF_PI = np.pi / 2
#: roboticstoolbox-python's DH tables (standard DH) [m, rad].
ARMS = {
    # Puma560: shoulder offset d3, forearm offset a3
    "puma560": dict(a=[0, 0.4318, 0.0203, 0, 0, 0], d=[0, 0, 0.15005, 0.4318, 0, 0],
                    alpha=[HALF_PI, 0, -HALF_PI, HALF_PI, -HALF_PI, 0]),
    # KUKA KR5: shoulder offset a1, elbow offset a3, flipped axes (alpha = pi)
    "kr5": dict(a=[0.18, 0.6, 0.12, 0, 0, 0], d=[0.4, 0.135, 0.135, 0.62, 0, 0.115],
                alpha=[HALF_PI, np.pi, -HALF_PI, HALF_PI, HALF_PI, np.pi]),
    # ABB IRB140: shoulder offset a1
    "irb140": dict(a=[0.07, 0.36, 0, 0, 0, 0], d=[0.352, 0, 0, 0.38, 0, 0.065],
                   alpha=[-HALF_PI, 0, HALF_PI, -HALF_PI, HALF_PI, 0]),
}  # fmt: skip
UR5 = dict(a=[0, -0.425, -0.39225, 0, 0, 0], d=[0.089159, 0, 0, 0.10915, 0.09465, 0.0823],
           alpha=[HALF_PI, 0, 0, HALF_PI, -HALF_PI, 0])  # fmt: skip


def _arm(name: str, **extra) -> jl.ArmModel:
    table = UR5 if name == "ur5" else ARMS[name]
    return jl.from_dh(name, convention="standard", **table, **extra)


def _found(branches_q: np.ndarray, q: np.ndarray, tol: float = 1e-6) -> bool:
    return bool(np.any(np.all(np.abs(wrap_angle(np.asarray(branches_q) - q)) < tol, axis=-1)))


@pytest.mark.parametrize("name", sorted(ARMS))
def test_every_branch_round_trips_with_a_base_and_a_tool(name):
    base = translation([0.3, -0.2, 1.0]) @ rot_x(0.4) @ rot_z(-1.2)
    tool = translation([0.01, -0.02, 0.15]) @ rot_x(0.5)
    arm = _arm(name, base=base, tool=tool)
    assert closed_form_family(arm) == "spherical-wrist"
    q = np.random.default_rng(5).uniform(-np.pi, np.pi, (300, 6))
    br = ik_closed_form(arm, jl.ee_pose(arm, q))
    assert br.family == "spherical-wrist" and br.q.shape == (300, 8, 6)
    assert np.all(br.exact == br.valid)  # every branch with a real solution reaches the pose
    assert all(_found(br.q_full[k][br.valid[k]], wrap_angle(q[k]), 1e-7) for k in range(300))
    assert br.valid.sum(axis=-1).min() >= 2
    assert np.max(br.position_error[br.valid]) < 1e-12


@pytest.mark.parametrize("name", sorted(ARMS))
@pytest.mark.parametrize("joint", [1, 2, 3, 4, 5, 6])
def test_every_joint_locked_in_turn_is_solved_in_closed_form(name, joint):
    """A pose the locked arm reaches is solved exactly (the branches whose locked angle is the
    lock's), the configuration it came from among them, and the method says so."""
    arm = jl.lock(_arm(name), joint, 0.7 if joint != 5 else -1.1)
    q = np.random.default_rng(joint).uniform(-np.pi, np.pi, (25, 5))
    for qk in q:
        res = solve_ik(arm, jl.ee_pose(arm, qk), rng=0)
        assert res.method == "closed-form" and res.family == "spherical-wrist" and res.reachable
        assert _found([s.q for s in res.solutions], wrap_angle(qk))


@pytest.mark.parametrize("name", sorted(ARMS))
@pytest.mark.parametrize("joint", [4, 6])
def test_a_locked_wrist_joint_is_solved_at_the_wrist_singularity(name, joint):
    """q5 = 0 puts axes 4 and 6 in line: joints 4 and 6 are free together, and the free one
    takes the lock's angle (else the locked arm would get no exact branch)."""
    arm = jl.lock(_arm(name), joint, 0.9)
    rng = np.random.default_rng(joint)
    for _ in range(10):
        q_full = rng.uniform(-np.pi, np.pi, 6)
        q_full[4] = 0.0
        q_full[joint - 1] = 0.9
        qk = arm.healthy(q_full)
        br = ik_closed_form(arm, jl.ee_pose(arm, qk))
        assert br.exact.any()
    full = _arm(name)
    q_full = rng.uniform(-np.pi, np.pi, (20, 6))
    q_full[:, 4] = 0.0
    br = ik_closed_form(full, jl.ee_pose(full, q_full))
    assert br.exact.any(axis=-1).all()


def test_a_locked_shoulder_is_solved_with_the_wrist_centre_on_axis_1():
    """IRB140 (no lateral offset) can put its wrist centre on axis 1: joint 1 is then free and
    takes the lock's angle."""
    full = _arm("irb140")
    g = spherical_wrist_geometry(full)
    # the wrist centre over the base: found by turning joint 2 until it crosses axis 1
    q2 = np.linspace(-np.pi, np.pi, 200001)
    q = np.zeros((q2.size, 6))
    q[:, 1], q[:, 2] = q2, 0.3
    centres = jl.ee_pose(full, q) @ np.linalg.solve(g.home, np.append(g.wrist_centre, 1.0))
    k = int(np.argmin(np.hypot(centres[:, 0], centres[:, 1])))
    assert np.hypot(*centres[k, :2]) < 1e-5
    arm = jl.lock(full, 1, 1.3)
    qk = arm.healthy(np.array([1.3, q2[k], 0.3, 0.4, 0.5, 0.6]))
    res = solve_ik(arm, jl.ee_pose(arm, qk), rng=0)
    assert res.method == "closed-form" and res.reachable


def test_arms_outside_the_family_are_refused_with_the_reason():
    offset_wrist = jl.from_dh("bent", convention="standard", a=ARMS["puma560"]["a"],
                              d=[0, 0, 0.15005, 0.4318, 0.05, 0], alpha=ARMS["puma560"]["alpha"])  # fmt: skip
    with pytest.raises(jl.ModelError, match="axes 4-6 miss a common point by 0.025 m"):
        spherical_wrist_geometry(offset_wrist)
    with pytest.raises(jl.ModelError, match="no closed form for 'bent'"):
        closed_form_family(offset_wrist)
    assert solve_ik(offset_wrist, jl.ee_pose(offset_wrist, np.full(6, 0.3)), rng=0).method == "numeric"
    assert closed_form_family(_arm("ur5")) == "ur"  # three parallel axes: the UR form
    assert closed_form_family(jl.load_robot("puma6")) == "puma6"  # 002's own equations first


@pytest.mark.oracle
@pytest.mark.parametrize("name", [*sorted(ARMS), "ur5"])
@pytest.mark.parametrize("joint", [None, 1, 2, 3, 4, 5, 6])
def test_every_exact_eaik_branch_is_ours(name, joint):
    """EAIK solves the full arm; with a joint locked, its branches at the lock's angle are the
    locked arm's, and each must be among ours."""
    eaik_dh = pytest.importorskip("eaik.IK_DH")
    table = UR5 if name == "ur5" else ARMS[name]
    robot = eaik_dh.DhRobot(np.array(table["alpha"], float), np.array(table["a"], float), np.array(table["d"], float))
    full = _arm(name)
    arm = full if joint is None else jl.lock(full, joint, 0.7)
    q = np.random.default_rng(11 + (joint or 0)).uniform(-np.pi, np.pi, (20, arm.dof))
    t = jl.ee_pose(arm, q)
    ours = ik_closed_form(arm, t)
    checked = 0
    for k in range(len(q)):
        for qe in np.atleast_2d(robot.IK(t[k]).Q):
            if joint is not None and abs(wrap_angle(qe[joint - 1] - 0.7)) > 1e-9:
                continue  # a branch of the full arm the locked one cannot take
            dp, dr = pose_error(t[k], jl.ee_pose(full, qe))
            if dp < EXACT_POSITION_TOL and dr < EXACT_POSITION_TOL:
                checked += 1
                assert _found(ours.q_full[k][ours.exact[k]], wrap_angle(qe)), (k, qe)
    assert checked >= (4 if joint is None else 1) * len(q)


@pytest.mark.parametrize("q5", [1e-9, 1e-8, 1e-7, 3e-7, 1e-6, 1e-5])
def test_near_the_wrist_singularity_every_branch_stays_exact(q5):
    """q5 a hair off 0: subproblem 2's square root loses half the digits of z, yet joint 4 is
    still solved (not taken as free) once q5 is past 1e-9, so every branch reaches the pose
    and the configuration it came from is among them from q5 = 1e-7 on (below, every angle of
    joint 4 reaches the pose within the 1e-7 tolerance)."""
    arm = _arm("puma560")
    q = np.random.default_rng(8).uniform(-np.pi, np.pi, (40, 6))
    q[:, 4] = q5
    br = ik_closed_form(arm, jl.ee_pose(arm, q))
    assert br.exact.all()
    if q5 >= 1e-7:
        assert all(_found(br.q_full[k][br.exact[k]], wrap_angle(q[k])) for k in range(len(q)))
