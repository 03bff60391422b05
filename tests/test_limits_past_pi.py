"""Joint limits past +-pi are kept as given (issue 15, item 2): sampling, search starts, the
numeric IK's projection and the closed form's branches use them; nothing is cut to +-pi."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

import jointlock as jl
from jointlock.analysis.workspace import sample_configurations
from jointlock.spatial import turns_into_limits

TURN = 2 * np.pi


def _two_link():
    return jl.from_dh("two", a=[1.0, 0.8], alpha=[0, 0], d=[0, 0], convention="standard",
                      lower=[-np.pi, 0.5], upper=[np.pi, 5.5])  # fmt: skip


def test_a_target_made_past_pi_is_solved_exactly():
    arm = _two_link()
    result = jl.solve_ik(arm, jl.ee_pose(arm, [0.3, 4.0]))
    assert result.reachable
    np.testing.assert_allclose(result.solutions[0].q, [0.3, 4.0], atol=1e-9)


def test_sampling_covers_the_limits_as_given():
    arm = _two_link()
    q = sample_configurations(arm, 20000, rng=0)
    assert q[:, 1].min() < 0.6 and q[:, 1].max() > 5.4 and np.mean(q[:, 1] > np.pi) > 0.4
    lo, hi = replace(arm, joints=(replace(arm.joints[0], lower=-np.inf, upper=np.inf), arm.joints[1])).angle_range()
    assert lo.tolist() == [-np.pi, 0.5] and hi.tolist() == [np.pi, 5.5]  # continuous: one turn
    half = replace(arm, joints=(replace(arm.joints[0], lower=1.0, upper=np.inf), arm.joints[1]))
    assert half.angle_range()[1][0] == pytest.approx(1.0 + TURN)
    from jointlock.planning.halt_config._sampling import _sampling_box

    box = _sampling_box(arm, None, None, None)  # the halt configuration's Monte Carlo
    assert box[0].tolist() == [-np.pi, 0.5] and box[1].tolist() == [np.pi, 5.5]


def test_turns_into_limits_moves_by_whole_turns_only(rng):
    q = rng.uniform(-20, 20, 5000)
    lo = rng.uniform(-8, 4, 5000)
    hi = lo + rng.uniform(0.1, 9, 5000)
    out = turns_into_limits(q, lo, hi)
    turns = (out - q) / TURN
    np.testing.assert_allclose(turns, np.round(turns), atol=1e-9)  # the same pose
    reachable = np.ceil((lo - q) / TURN) * TURN + q <= hi  # some turn lands inside
    assert np.all((out[reachable] >= lo[reachable] - 1e-12) & (out[reachable] <= hi[reachable] + 1e-12))
    already = (q >= lo) & (q <= hi)
    np.testing.assert_array_equal(out[already], q[already])  # an angle inside is left alone


def test_the_closed_form_keeps_branches_within_limits_past_pi():
    arm = jl.load_robot("puma6")
    shifted = replace(arm, joints=tuple(replace(j, lower=0.0, upper=TURN) if j.number == 6 else j for j in arm.joints))
    q_true = np.radians([5.0, 60.0, 35.0, 10.0, -120.0, -90.0])
    q_true[5] += TURN  # -90 deg is 270 deg within [0, 360]
    target = jl.ee_pose(shifted, q_true)
    br = jl.ik_closed_form(shifted, target)
    q6 = br.q[br.exact][:, 5]
    assert np.all((q6 >= 0) & (q6 <= TURN)) and np.any(np.isclose(q6, q_true[5]))
    np.testing.assert_allclose(jl.ee_pose(shifted, br.q[br.exact]), np.broadcast_to(target, (int(br.exact.sum()), 4, 4)), atol=1e-9)


def test_from_dh_takes_a_continuous_joint():
    arm = jl.from_dh("two", a=[1.0, 0.8], alpha=[0, 0], d=[0, 0], convention="standard",
                     lower=[-np.inf, 0.5], upper=[np.inf, 5.5])  # fmt: skip
    assert arm.angle_range()[0].tolist() == [-np.pi, 0.5]
    result = jl.solve_ik(arm, jl.ee_pose(arm, [3.0 + TURN, 4.0]))
    np.testing.assert_allclose(result.solutions[0].q, [3.0, 4.0], atol=1e-9)  # one turn is one pose
    with pytest.raises(jl.ModelError, match=r"lower must hold 2 finite numbers \(or -inf for no limit\)"):
        jl.from_dh("two", a=[1.0, 0.8], alpha=[0, 0], d=[0, 0], convention="standard", lower=[np.nan, 0.5])


def test_the_singularity_search_projects_into_limits_past_pi():
    from jointlock.analysis.singularity._search import _project

    arm = jl.from_dh("a", a=[0.3, 0.2, 0.1], alpha=[0, 0, 0], d=[0, 0, 0], convention="standard",
                     lower=[-np.pi, 0.5, -np.pi], upper=[np.pi, 0.5 + TURN, np.pi])  # fmt: skip
    out = _project(arm, np.array([[0.0, 4.0, 0.0], [0.0, 6.5, 0.0], [4.0, 0.2, 0.0]]))
    np.testing.assert_allclose(out[:, 1], [4.0, 6.5, 0.2 + TURN])  # q2 stays in [0.5, 0.5 + 2 pi]
    assert out[2, 0] == pytest.approx(4.0 - TURN)  # a [-pi, pi] joint still wraps
    with pytest.raises(jl.ModelError, match="lower < inf, upper > -inf"):
        jl.Joint(np.eye(4), lower=np.inf, upper=np.inf)
