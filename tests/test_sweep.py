"""Clearance between the samples of a motion (issue 27: "a bound on how far any point can move
between samples so that nothing tunnels"): the reach matrix bounds how fast each pair closes
(finite differences), the certified bound never exceeds the distances of a motion sampled
100,000 times, a link that passes through a keep-out between two clear samples is caught, and the
halt reports the bound."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

import jointlock as jl
from jointlock.collision import clearance, collision_pairs
from jointlock.shapes import Capsule, Sphere
from jointlock.sweep import TUNNEL_TOLERANCE_M, pair_reach, swept_clearance


def _arms():
    halt7 = jl.load_robot("halt7", base="floating")
    return [
        halt7,
        jl.lock(halt7, 4, 0.0),
        jl.load_robot("canadarm7", base="fixed"),
        jl.lock(jl.load_robot("puma6"), 3, 0.4),
    ]


@pytest.mark.parametrize("index", range(4))
def test_reach_bounds_how_fast_each_pair_closes_per_joint(index):
    """Turning joint i by a small angle changes pair p's distance by at most reach[p, i] times
    the angle, and not at all where reach[p, i] is 0 (the joint moves both shapes together, or
    neither)."""
    model = _arms()[index]
    reach = pair_reach(model)
    rng = np.random.default_rng(index)
    step = 1e-6
    checked = 0
    for _ in range(20):
        q = rng.uniform(-math.pi, math.pi, model.dof)
        base = clearance(model, q).pair_distance
        for i in range(model.dof):
            moved = q.copy()
            moved[i] += step
            change = np.abs(clearance(model, moved).pair_distance - base)
            assert np.all(change <= reach[:, i] * step * (1 + 1e-6) + 1e-11)
            assert np.all(change[reach[:, i] == 0] <= 1e-11)
            checked += int(np.count_nonzero(change > 1e-9))
    assert checked > 0  # the finite differences did move pairs


def _halt7_halt():
    plan = jl.plan_halt(
        "halt7",
        search=jl.HaltSearch(samples=2000),
        motion=jl.HaltMotionSettings(n_samples=101),
    )
    p = plan.problem
    return plan, p, (lambda t: p.trajectory(float(plan.motion.k), t))


@pytest.mark.parametrize("depth", [0, 1, 4])
def test_the_bound_is_below_the_motion_sampled_100000_times(depth):
    """000's scenario's halt on a grid of 51 samples (0.2 s apart), refined 0, 1 or 4 times:
    every pair's certified bound is at most its smallest distance on 100,001 samples."""
    plan, p, motion = _halt7_halt()
    floor = np.full(len(collision_pairs(p.model).names), 0.05)
    swept = swept_clearance(p.model, motion, p.times(51), floor, max_depth=depth)
    dense = clearance(p.model, motion(p.times(100_001))[0]).pair_distance.min(axis=0)
    assert np.all(swept.lower_bound <= dense + 1e-12)
    assert np.all(swept.sampled_min >= dense - 1e-12)  # the refined samples lie on the motion
    if depth == 0:
        assert swept.refined_samples == 0
    else:
        assert swept.refined_samples > 0


def test_a_link_through_a_keep_out_between_two_clear_samples_is_caught():
    """A 1 m link swung from -60 to +60 deg about joint 1 in 1 s, a 0.1 m ball in its way at 0
    deg: both samples are 0.4 m clear, the bound is not, the refinement finds the overlap."""
    arm = jl.from_dh("swing", a=[0.0, 1.0, 1.0], alpha=[0.0, 0.0, 0.0], d=[0.0, 0.0, 0.0], convention="modified")
    rod = Capsule([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], 0.05, name="rod")
    bodies = (replace(arm.bodies[0], shapes=(rod,)),) + arm.bodies[1:]
    arm = replace(arm, bodies=bodies)
    ball = Sphere([0.6, 0.0, 0.0], 0.1, name="ball")
    speed = math.radians(120.0)

    def motion(t):
        t = np.asarray(t, dtype=float)
        q = np.zeros((t.size, 3))
        q[:, 0] = math.radians(-60.0) + speed * t
        dq = np.zeros_like(q)
        dq[:, 0] = speed
        return q, dq, np.zeros_like(q)

    ends = clearance(arm, motion(np.array([0.0, 1.0]))[0], keep_out=[ball])
    assert np.all(ends.distance > 0.3)
    swept = swept_clearance(arm, motion, [0.0, 1.0], [0.05], keep_out=[ball])
    assert not swept.certified and swept.shortfall > 0.1
    assert swept.sampled_min[0] < -0.14  # the refinement reached the ball: 0.15 m deep at 0 deg
    assert swept.lower_bound_time[0] == pytest.approx(0.5, abs=0.07)
    assert swept.to_dict()["lower_bound_pair"] == "rod - ball"


def test_the_halt_reports_its_clearance_between_samples():
    """000's scenario (the demo): the halt is certified between its samples, its bound within
    the tunnelling tolerance of the start's depth (the boom starts 0.051 m into the bus and comes
    no closer); the to_dict keys."""
    plan = jl.plan_halt(
        "halt7",
        search=jl.HaltSearch(samples=2000),
        motion=jl.HaltMotionSettings(n_samples=101),
    )
    data = plan.to_dict()["clearance"]
    assert plan.collision_free is True and data["between_samples_clear"] is True
    assert data["tunnelling_tolerance_m"] == TUNNEL_TOLERANCE_M
    assert data["start_m"] - TUNNEL_TOLERANCE_M <= data["between_samples_min_m"] <= data["motion_min_m"]
    assert data["collides_at_samples"] is False


def _jump(obstacle: bool = False):
    """001's jump study of canadarm7 at 6 s; ``obstacle``: a 0.15 m ball fixed to the bus where
    the end effector passes 9 s into the task (a payload left in the way)."""
    from jointlock.geometry import with_root_shapes
    from jointlock.jobs.jump import run_jump_study
    from jointlock.planning.jump import JumpScenario, simulate

    arm = jl.load_robot("canadarm7", base="fixed")
    if obstacle:
        at = jl.ee_pose(arm, simulate(arm, JumpScenario()).q[180])[:3, 3]
        arm = with_root_shapes(arm, [Sphere(at, 0.15, name="payload")])
    return run_jump_study(arm, JumpScenario(), fail_at=6.0)


def _dense(run, factor: int = 20):
    """The run's joint motion (rates held over each control step) at ``factor`` times its steps."""
    t = np.linspace(run.t[0], run.t[-1], factor * (run.t.size - 1) + 1)
    k = np.clip(np.searchsorted(run.t, t, side="right") - 1, 0, run.qd.shape[0] - 1)
    return run.q[k] + run.qd[k] * (t - run.t[k])[:, None]


def test_the_jump_studys_runs_report_their_clearance():
    """001's runs on canadarm7 keep clear of the bus (+0.27 m, link3 - bus), between the control
    steps too (20 times finer sampling agrees); with a ball on the end effector's path 9 s in,
    both runs hit it and say so first."""
    result = _jump()
    data = result.clearance()
    r0, r1, _ = result.runs()
    for label, run in (("uncompensated", r0), ("compensated", r1)):
        steps = clearance(result.model, run.q)
        assert data[label]["min_clearance_m"] == pytest.approx(float(steps.distance.min()), abs=1e-12)
        assert data[label]["collides"] is False
        pair = collision_pairs(result.model).names.index(data[label]["between_steps_pair"])
        dense = clearance(result.model, _dense(run)).pair_distance[:, pair].min()
        assert data[label]["between_steps_min_m"] <= dense + 1e-12  # that pair's bound, below its truth
        assert data[label]["between_steps_pair"] == "link3 - bus"  # not a mounted pair at its floor
    assert result.to_dict()["clearance"] == data
    assert not result.summary()[0].startswith("COLLIDES")

    hit = _jump(obstacle=True)
    data = hit.clearance()
    assert all(data[label]["collides"] for label in data)
    assert data["compensated"]["closest_pair"] == "payload - link7" and data["compensated"]["min_clearance_m"] < -0.1
    assert hit.summary()[0].startswith("COLLIDES: the uncompensated run")


def test_a_motion_with_nan_rates_is_refused_and_a_short_grid_works():
    from jointlock.errors import ConfigurationError
    from jointlock.planning.halt_motion._clearance_limits import keeps_clearance

    plan, p, motion = _halt7_halt()

    def broken(t):
        q, dq, ddq = motion(t)
        dq = dq.copy()
        dq[len(dq) // 2] = np.nan
        return q, dq, ddq

    with pytest.raises(ConfigurationError, match="not finite at t = "):
        swept_clearance(p.model, broken, p.times(51), np.zeros(len(collision_pairs(p.model).names)))
    short = replace(p, n_check=5)  # every check time on the screen: nothing left for the rest
    assert keeps_clearance(short, np.array([float(plan.motion.k)]), 0.05).shape == (1,)
