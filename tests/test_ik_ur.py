"""Closed-form IK of the three-parallel-axes family (issue 15, item 4, part): UR3, UR5, UR10
by their published DH tables.  Round trips, the family decided from the model's own
kinematics and reported, locked joints, and EAIK (an independent analytic solver) as oracle:
every exact EAIK branch is among ours."""

from __future__ import annotations

import numpy as np
import pytest

import jointlock as jl
from jointlock.ik import (
    EXACT_POSITION_TOL,
    closed_form_family,
    ik_closed_form,
    solve_ik,
    ur_geometry,
    wrap_angle,
)
from jointlock.spatial import pose_error

ALPHA = [np.pi / 2, 0.0, 0.0, np.pi / 2, -np.pi / 2, 0.0]
#: Universal Robots' published DH parameters [m]: (d1, a2, a3, d4, d5, d6).
UR = {
    "ur3": (0.1519, -0.24365, -0.21325, 0.11235, 0.08535, 0.0819),
    "ur5": (0.089159, -0.425, -0.39225, 0.10915, 0.09465, 0.0823),
    "ur10": (0.1273, -0.612, -0.5723, 0.163941, 0.1157, 0.0922),
}


def _arm(name: str, tool=None) -> jl.ArmModel:
    d1, a2, a3, d4, d5, d6 = UR[name]
    return jl.from_dh(name, a=[0, a2, a3, 0, 0, 0], alpha=ALPHA, d=[d1, 0, 0, d4, d5, d6], convention="standard",
                      lower=[-2 * np.pi] * 6, upper=[2 * np.pi] * 6, tool=tool)  # fmt: skip


def _found(branches_q: np.ndarray, q: np.ndarray, tol: float = 1e-7) -> bool:
    return bool(np.any(np.all(np.abs(wrap_angle(branches_q - q)) < tol, axis=-1)))


@pytest.mark.parametrize("name", sorted(UR))
def test_every_branch_round_trips_and_the_pose_is_found(name):
    tool = jl.spatial.translation([0.01, -0.02, 0.05]) @ jl.spatial.rot_z(0.3)
    arm = _arm(name, tool)
    assert closed_form_family(arm) == "ur"
    g = ur_geometry(arm)
    np.testing.assert_allclose(g.lengths, np.add(UR[name], [0, 0, 0, 0, 0, 0.05]), atol=1e-9)  # tool z into d6
    q = np.random.default_rng(3).uniform(-np.pi, np.pi, (300, 6))
    br = ik_closed_form(arm, jl.ee_pose(arm, q))
    assert br.family == "ur" and br.q.shape == (300, 8, 6)
    assert np.all(br.exact == br.valid)  # every branch with a real solution reaches the pose
    assert all(_found(br.q_full[k][br.valid[k]], wrap_angle(q[k])) for k in range(300))
    assert br.valid.sum(axis=-1).min() >= 2


@pytest.mark.parametrize("joint", [1, 2, 3, 4, 5, 6])
def test_a_locked_ur_arm_is_solved_in_closed_form(joint):
    """With joint ``joint`` locked, a pose the locked arm reaches is solved exactly by the
    closed form (the branches whose locked angle is the lock's), and the method says so."""
    full = _arm("ur5")
    lock = 0.7 if joint != 5 else -1.1
    arm = jl.lock(full, joint, lock)
    rng = np.random.default_rng(joint)
    for q in rng.uniform(-np.pi, np.pi, (20, 5)):
        res = solve_ik(arm, jl.ee_pose(arm, q), rng=0)
        assert res.method == "closed-form" and res.family == "ur" and res.reachable
        assert _found(np.array([s.q for s in res.solutions]), wrap_angle(q), 1e-6)


@pytest.mark.oracle
@pytest.mark.parametrize("name", sorted(UR))
def test_every_exact_eaik_branch_is_ours(name):
    eaik_dh = pytest.importorskip("eaik.IK_DH")
    d1, a2, a3, d4, d5, d6 = UR[name]
    robot = eaik_dh.DhRobot(np.array(ALPHA), np.array([0, a2, a3, 0, 0, 0]), np.array([d1, 0, 0, d4, d5, d6]))
    arm = _arm(name)
    q = np.random.default_rng(11).uniform(-np.pi, np.pi, (60, 6))
    t = jl.ee_pose(arm, q)
    ours = ik_closed_form(arm, t)
    checked = 0
    for k in range(q.shape[0]):
        for qe in np.atleast_2d(robot.IK(t[k]).Q):
            dp, dr = pose_error(t[k], jl.ee_pose(arm, qe))
            if dp < EXACT_POSITION_TOL and dr < EXACT_POSITION_TOL:
                checked += 1
                assert _found(ours.q_full[k][ours.exact[k]], wrap_angle(qe), 1e-6), (k, qe)
    assert checked >= 4 * q.shape[0]  # EAIK finds several branches per pose; all are ours


def test_other_arms_keep_their_method():
    assert closed_form_family(jl.load_robot("puma6")) == "puma6"
    with pytest.raises(jl.ModelError, match="no closed form for 'halt7'"):
        closed_form_family(jl.load_robot("halt7"))
    res = solve_ik(jl.load_robot("halt7"), jl.ee_pose(jl.load_robot("halt7"), np.zeros(7)), rng=0)
    assert res.method == "numeric" and res.family is None


@pytest.mark.parametrize("name", ["ur5", "puma6"])
def test_the_numeric_fallback_finds_every_analytic_branch(name):
    """Issue 15, item 4: Levenberg-Marquardt from random starts, then from the symmetric images
    of what it found (a joint turned by pi, the wrist flipped), finds >= 99 % of the closed
    form's branches; every solution it reports reaches the pose."""
    arm = jl.load_robot("puma6") if name == "puma6" else _arm("ur5")
    q = np.random.default_rng(21).uniform(-np.pi, np.pi, (20, 6))
    t = jl.ee_pose(arm, q)
    analytic = ik_closed_form(arm, t)
    found = total = 0
    for k in range(len(q)):
        res = solve_ik(arm, t[k], method="numeric", rng=k)
        sols = np.array([s.q for s in res.solutions])
        for s in res.solutions:
            dp, dr = pose_error(t[k], jl.ee_pose(arm, s.q))
            assert dp < EXACT_POSITION_TOL and dr < EXACT_POSITION_TOL  # never a wrong pose
        for b in np.flatnonzero(analytic.exact[k]):
            total += 1
            found += _found(sols, analytic.q[k, b], 1e-5)
    assert found >= 0.99 * total, (found, total)


@pytest.mark.oracle
def test_the_numeric_fallback_finds_every_eaik_branch_of_puma560():
    """Puma560 as roboticstoolbox tabulates it (shoulder offset d3, forearm offset a3), solved
    numerically on purpose (its closed form is tested in test_ik_spherical.py): every exact EAIK
    branch is among the numerical method's solutions."""
    eaik_dh = pytest.importorskip("eaik.IK_DH")
    a, d = [0, 0.4318, 0.0203, 0, 0, 0], [0, 0, 0.15005, 0.4318, 0, 0]
    alpha = [np.pi / 2, 0, -np.pi / 2, np.pi / 2, -np.pi / 2, 0]
    arm = jl.from_dh("puma560", a=a, alpha=alpha, d=d, convention="standard")
    robot = eaik_dh.DhRobot(np.array(alpha), np.array(a), np.array(d))
    q = np.random.default_rng(2).uniform(-np.pi, np.pi, (15, 6))
    t = jl.ee_pose(arm, q)
    checked = 0
    for k in range(len(q)):
        res = solve_ik(arm, t[k], method="numeric", rng=k)
        assert res.method == "numeric"
        sols = np.array([s.q for s in res.solutions])
        for qe in np.atleast_2d(robot.IK(t[k]).Q):
            dp, dr = pose_error(t[k], jl.ee_pose(arm, qe))
            if dp < EXACT_POSITION_TOL and dr < EXACT_POSITION_TOL:
                checked += 1
                assert _found(sols, wrap_angle(qe), 1e-5), (k, qe)
    assert checked >= 4 * len(q)


def test_a_redundant_arm_gets_no_symmetric_rounds():
    """halt7 (seven joints): a pose has a continuum of solutions, not branches; the numerical
    method reports its starts' solutions only (the symmetric rounds would multiply them)."""
    arm = jl.load_robot("halt7")
    res = solve_ik(arm, jl.ee_pose(arm, np.full(7, 0.3)), rng=0, starts=8)
    assert res.reachable and len(res.candidates) <= 16


def test_the_upright_pose_is_solved_exactly_at_its_three_singularities():
    """UR5 upright (shoulder, elbow and wrist singular at once): every branch exact, theta5
    computed from the tool axis, not an arccos of positions; locks that make two lengths
    indistinguishable still solve (the fit is the full arm's)."""
    arm = _arm("ur5")
    br = ik_closed_form(arm, jl.ee_pose(arm, np.array([0.0, -np.pi / 2, 0.0, -np.pi / 2, 0.0, 0.0])))
    assert br.valid.all() and br.exact.all()
    locked = jl.lock(arm, 3, np.pi)
    q = np.random.default_rng(4).uniform(-np.pi, np.pi, (10, 5))
    assert ik_closed_form(locked, jl.ee_pose(locked, q)).exact.any(axis=-1).all()
