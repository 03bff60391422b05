"""Inverse kinematics: closed form for the puma6 family (seed 002) and the numerical fallback."""

from __future__ import annotations

import math

import numpy as np
import pytest

import jointlock as jl
from jointlock.errors import ConfigurationError, ModelError
from jointlock.ik import (
    EXACT_POSITION_TOL,
    ik_closed_form,
    ik_numeric,
    pose_from_zyx,
    puma6_geometry,
    solve_ik,
    wrap_angle,
    zyx_angles,
)
from jointlock.papers import p002
from jointlock.spatial import pose_error, rot_x, translation

#: Round trips away from singularities: round-off only [m], [rad].
ROUND_TRIP_TOL = 1e-9
#: Two joint vectors are the same solution [rad].
SAME_Q = 1e-6
#: 002 prints joint angles with 4 decimals [deg]: half a unit of the last digit plus round-off.
PRINT4_DEG = 0.5e-4 + 1e-9
#: Joint 4 locked at 0.7 rad etc.: one lock angle per joint for the round trips [rad].
LOCK_ANGLES = {1: 0.7, 2: 0.9, 3: -1.1, 4: 0.4, 5: -2.0, 6: 1.3}

# 002, §"The straight trajectory planning ... (fault-tolerant attitude error <= 10 deg)":
# the terminal configuration, eq. (22) and eq. (21) (rotation, position [mm]; 4 decimals).
Q_FINAL_DEG = p002.B_QF_DEG
EQ22_DEG = p002.EQ22_DEG
EQ21 = np.array(p002.EQ21_POSE)[:3]


@pytest.fixture(scope="module")
def puma() -> jl.ArmModel:
    return jl.load_robot("puma6")


def _eq21_target(model: jl.ArmModel) -> np.ndarray:
    """002's eq. (21) target: FK(q_f) rotated by gamma = -10 deg about the tool x axis."""
    return jl.ee_pose(model, np.radians(Q_FINAL_DEG)) @ rot_x(math.radians(p002.B_GAMMA_DEG))


def _contains(branches: np.ndarray, q: np.ndarray, mask: np.ndarray) -> np.ndarray:
    d = np.max(np.abs(wrap_angle(branches - q[..., None, :])), axis=-1)
    return np.any((d < SAME_Q) & mask, axis=-1)


# -- 002's worked examples -----------------------------------------------------------------


@pytest.mark.paper
def test_eq22_is_a_branch_of_the_full_ik_of_eq21(puma):
    res = ik_closed_form(puma, _eq21_target(puma))
    assert res.exact.all()
    d = np.abs(np.degrees(res.q_full) - EQ22_DEG).max(axis=-1)
    assert d.min() <= PRINT4_DEG


@pytest.mark.paper
def test_eq22_from_the_locked_arm_closed_form(puma):
    """002 step 6: the 5-DOF IK with theta2 = 52.0547 deg of the eq. (21) pose gives eq. (22)."""
    locked = jl.lock(puma, 2, math.radians(p002.B_LOCK_DEG))
    res = ik_closed_form(locked, _eq21_target(puma))
    d = np.abs(np.degrees(res.q_full) - EQ22_DEG).max(axis=-1)
    best = int(np.argmin(d))
    assert d[best] <= PRINT4_DEG
    # the printed lock angle is theta2(-10 deg) = 52.054712 truncated: a few micrometres off
    assert res.position_error[best] < 2e-5


@pytest.mark.paper
def test_eq21_pose_and_euler_convention(puma):
    t = jl.ee_pose(puma, np.radians(EQ22_DEG))
    assert np.abs(t[:3, :3] - EQ21[:, :3]).max() <= 0.5e-4 + 1e-6  # 4 printed decimals
    assert np.abs(t[:3, 3] * 1e3 - EQ21[:, 3]).max() <= 0.5e-4
    assert np.allclose(zyx_angles(t[:3, :3]), p002.EXAMPLES["E5"].euler_zyx, atol=0.5e-4)  # after eq. (22)
    back = pose_from_zyx(t[:3, 3], zyx_angles(t[:3, :3]))
    assert np.allclose(back, t, atol=1e-12)


@pytest.mark.paper
def test_printed_theta3_and_theta4_are_wrong(puma):
    """Eq. (6)/(16) without 1/d4 returns theta3 + 180 deg; eq. (17) without 1/s5 flips theta4."""
    g = puma6_geometry(puma)
    q = np.radians(EQ22_DEG)
    t = jl.ee_pose(puma, q)
    a, p = t[:3, 2], t[:3, 3]
    c1, s1 = math.cos(q[0]), math.sin(q[0])
    c2, s2 = math.cos(q[1]), math.sin(q[1])
    u = c1 * (p[0] - g.d6 * a[0]) + s1 * (p[1] - g.d6 * a[1])
    v = g.d6 * a[2] - p[2]
    printed = math.degrees(math.atan2(u * c2 + v * s2 - g.a2, u * s2 - v * c2))
    assert printed == pytest.approx(EQ22_DEG[2] - 180.0, abs=1e-3)
    c3, s3 = math.cos(q[2]), math.sin(q[2])
    x = c2 * (c1 * a[0] + s1 * a[1]) - s2 * a[2]
    y = s2 * (c1 * a[0] + s1 * a[1]) + c2 * a[2]
    s5 = math.sin(q[4])
    printed4 = math.degrees(math.atan2(-a[0] * s1 + a[1] * c1, c3 / s5 * x - s3 / s5 * y))
    eq11 = math.degrees(math.atan2((-a[0] * s1 + a[1] * c1) / s5, c3 / s5 * x - s3 / s5 * y))
    assert eq11 == pytest.approx(EQ22_DEG[3], abs=1e-3)
    assert abs(printed4 - EQ22_DEG[3]) > 10.0  # -7.1 deg instead of 8.561 deg


# -- round trips ---------------------------------------------------------------------------


def test_full_arm_round_trip_every_branch(puma, rng):
    q = rng.uniform(-np.pi, np.pi, (4000, 6))
    t = jl.ee_pose(puma, q)
    res = ik_closed_form(puma, t)
    assert res.q.shape == (4000, 8, 6)
    assert res.valid.all()
    # judge every branch with the model's own FK (not the IK's)
    dp, dr = pose_error(t[:, None], jl.ee_pose(puma, res.q))
    assert dp.max() < ROUND_TRIP_TOL and dr.max() < ROUND_TRIP_TOL
    assert _contains(res.q_full, q, res.valid).all()
    # 8 distinct branches
    pair = np.max(np.abs(wrap_angle(res.q[:, :, None] - res.q[:, None, :])), axis=-1)
    assert (pair + np.eye(8) * 10 > 1e-6).all()


@pytest.mark.parametrize("joint", [1, 2, 3, 4, 5, 6])
def test_locked_arm_round_trip(puma, rng, joint):
    angle = LOCK_ANGLES[joint]
    locked = jl.lock(puma, joint, angle)
    q_full = rng.uniform(-np.pi, np.pi, (3000, 6))
    q_full[:, joint - 1] = angle
    t = jl.ee_pose(puma, q_full)
    res = ik_closed_form(locked, t)
    assert res.q.shape == (3000, 4, 5)
    # the configuration that produced the pose is always found, exactly
    assert _contains(res.q_full, q_full, res.exact).all()
    # every branch flagged exact is exact by the full model's FK
    dp, dr = pose_error(t[:, None], jl.ee_pose(puma, np.where(res.valid[..., None], res.q_full, 0.0)))
    assert (dp[res.exact] < EXACT_POSITION_TOL).all() and (dr[res.exact] < EXACT_POSITION_TOL).all()
    assert dp[res.exact].max() < ROUND_TRIP_TOL * 100
    assert np.all(res.q_full[..., joint - 1][res.valid] == angle)


def test_batched_equals_loop(puma, rng):
    q = rng.uniform(-np.pi, np.pi, (5, 6))
    t = jl.ee_pose(puma, q)
    batch = ik_closed_form(puma, t)
    for k in range(5):
        one = ik_closed_form(puma, t[k])
        assert np.array_equal(one.q, batch.q[k])


def test_unreachable_locked_target_gives_nearest_pose(puma):
    locked = jl.lock(puma, 2, math.radians(40.0))
    target = _eq21_target(puma)
    res = solve_ik(locked, target)
    assert not res.reachable
    assert res.nearest is not None
    metric = res.nearest.position_error**2 + res.nearest.rotation_error**2
    best_candidate = min(c.position_error**2 + c.rotation_error**2 for c in res.candidates)
    assert metric <= best_candidate + 1e-12
    dp, dr = pose_error(res.nearest_pose, jl.ee_pose(locked, res.nearest.q))
    assert dp < 1e-12 and dr < 1e-12


def test_family_detection(puma):
    with pytest.raises(ModelError, match="puma6"):
        puma6_geometry(jl.load_robot("halt7"))
    tooled = jl.from_dh(
        "tooled",
        a=[0, 0.5, 0, 0, 0, 0],
        alpha=np.radians([-90, 0, 90, -90, 90, 0]),
        d=[0, 0, 0, 0.4, 0, 0.1],
        convention="standard",
        tool=translation([0.02, -0.01, 0.05]) @ rot_x(0.3),
    )
    g = puma6_geometry(tooled)
    assert (g.a2, g.d4, g.d6) == pytest.approx((0.5, 0.4, 0.15))
    q = np.random.default_rng(3).uniform(-np.pi, np.pi, (200, 6))
    res = ik_closed_form(tooled, jl.ee_pose(tooled, q))
    assert _contains(res.q_full, q, res.exact).all()


def test_bad_target_raises(puma):
    with pytest.raises(ConfigurationError, match="target"):
        ik_closed_form(puma, np.eye(3))


# -- numerical fallback --------------------------------------------------------------------


def test_numeric_ik_on_another_arm(rng):
    arm = jl.load_robot("halt7")
    q = rng.uniform(-np.pi, np.pi, (20, 7))
    t = jl.ee_pose(arm, q)
    res = ik_numeric(arm, t, starts=6, rng=1)
    assert res.q.shape == (20, 6, 7)
    assert res.exact.any(axis=-1).all()
    dp, dr = pose_error(t[:, None], jl.ee_pose(arm, res.q))
    assert dp[res.exact].max() < EXACT_POSITION_TOL


def test_numeric_ik_with_free_tool_rotation(puma, rng):
    """A locked arm cannot reach T Rx(0.3) in general; with gamma free it reaches it at gamma = -0.3."""
    locked = jl.lock(puma, 2, 0.9)
    q = rng.uniform(-np.pi, np.pi, (10, 5))
    t = jl.ee_pose(locked, q) @ rot_x(0.3)
    fixed = ik_numeric(locked, t, q0=q[:, None, :], starts=0)
    assert not fixed.exact.any()
    free = ik_numeric(locked, t, q0=q[:, None, :], starts=0, free_tool_x=True, gamma_bounds=(-1.0, 1.0))
    assert free.exact.all()
    assert np.allclose(free.gamma, -0.3, atol=1e-7)


def test_solve_ik_numeric_agrees_with_closed_form(puma, rng):
    q = rng.uniform(-np.pi, np.pi, 6)
    t = jl.ee_pose(puma, q)
    closed = solve_ik(puma, t)
    numeric = solve_ik(puma, t, method="numeric", starts=24, rng=2)
    assert len(closed.solutions) == 8
    for s in numeric.solutions:
        d = [np.max(np.abs(wrap_angle(s.q - c.q))) for c in closed.solutions]
        assert min(d) < 1e-5


# -- independent analytic IK (EAIK) --------------------------------------------------------


@pytest.mark.oracle
@pytest.mark.parametrize("joint", [None, 1, 2, 3, 4, 5, 6])
def test_every_exact_eaik_branch_is_ours(puma, joint):
    eaik_dh = pytest.importorskip("eaik.IK_DH")
    g = puma6_geometry(puma)
    alpha = np.radians([-90, 0, 90, -90, 90, 0])
    a = np.array([0, g.a2, 0, 0, 0, 0])
    d = np.array([0, 0, 0, g.d4, 0, g.d6])
    gen = np.random.default_rng(17)
    q = gen.uniform(-np.pi, np.pi, (60, 6))
    model = puma
    if joint is None:
        robot = eaik_dh.DhRobot(alpha, a, d)
    else:
        angle = LOCK_ANGLES[joint]
        q[:, joint - 1] = angle
        robot = eaik_dh.DhRobot(alpha, a, d, fixed_axes=[(joint - 1, angle)])
        model = jl.lock(puma, joint, angle)
    t = jl.ee_pose(puma, q)
    ours = ik_closed_form(model, t)
    checked = 0
    for k in range(q.shape[0]):
        sol = robot.IK(t[k])
        for qe in np.atleast_2d(sol.Q):
            dp, dr = pose_error(t[k], jl.ee_pose(puma, qe))
            if dp < EXACT_POSITION_TOL and dr < EXACT_POSITION_TOL:
                checked += 1
                assert _contains(ours.q_full[k], qe, ours.exact[k])
    assert checked >= q.shape[0]


def test_the_puma6_geometry_is_fitted_once_per_model():
    """Issue 13: the closed form's family fit is kept on the immutable model (a single-pose IK
    call does not fit it again); a changed model fits its own; a refusal is remembered."""
    import dataclasses

    from jointlock.ik import puma6_geometry

    arm = jl.load_robot("puma6")
    first = puma6_geometry(arm)
    assert puma6_geometry(arm) is first
    moved = dataclasses.replace(arm, tool=arm.tool @ jl.spatial.translation([0.0, 0.0, 0.1]))
    assert puma6_geometry(moved) is not first and puma6_geometry(moved).d6 == pytest.approx(first.d6 + 0.1)
    seven = jl.load_robot("halt7")
    for _ in range(2):
        with pytest.raises(jl.ModelError, match="6-joint arm"):
            puma6_geometry(seven)
