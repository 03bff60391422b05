"""Motor and brake torques of a crippled arm (issue 14, item 2): against Pinocchio's ``rnea``
on the full arm with the locked joint held, fixed and free-floating, and the invariant that
the healthy joints' torques equal the locked model's."""

from __future__ import annotations

import numpy as np
import pytest

import jointlock as jl
from jointlock.analysis.actuators import actuator_loads, actuator_torques


def _state(rng, n, batch=()):
    return (rng.uniform(-2, 2, batch + (n,)), rng.uniform(-0.5, 0.5, batch + (n,)), rng.uniform(-1, 1, batch + (n,)))


def _pinocchio_torques(full: jl.ArmModel, q, dq, ddq, floating: bool) -> np.ndarray:
    """Full-arm joint torques by Pinocchio; floating: the base twist from zero momentum and its
    acceleration from the base rows of the dynamics (no wrench on the spacecraft)."""
    from pin_oracle import pin, pin_q, to_pinocchio  # skips without Pinocchio

    pm, _ = to_pinocchio(full, free_flyer=floating)
    pm.gravity = pin.Motion.Zero()  # in orbit
    data = pm.createData()
    qq = pin_q(pm, q, floating)
    if not floating:
        return pin.rnea(pm, data, qq, dq, ddq).copy()
    mass = pin.crba(pm, data, qq).copy()
    mass = np.triu(mass) + np.triu(mass, 1).T
    nb = 6
    v = np.concatenate([-np.linalg.solve(mass[:nb, :nb], mass[:nb, nb:] @ dq), dq])
    nle = pin.nonLinearEffects(pm, data, qq, v).copy()
    a_base = -np.linalg.solve(mass[:nb, :nb], mass[:nb, nb:] @ ddq + nle[:nb])
    tau = pin.rnea(pm, data, qq, v, np.concatenate([a_base, ddq])).copy()
    assert np.allclose(tau[:nb], 0.0, atol=1e-9 * max(1.0, np.abs(tau).max()))  # the base is free
    return tau[nb:]


@pytest.mark.oracle
@pytest.mark.parametrize("floating", [False, True])
@pytest.mark.parametrize(("robot", "locks"), [("halt7", {4: 0.0}), ("halt7", {1: 0.3}), ("halt7", {3: -0.4, 7: 1.0}),
                                               ("canadarm7", {4: 0.5})])  # fmt: skip
def test_motor_and_brake_torques_match_pinocchio_with_the_joint_held(rng, robot, locks, floating):
    full = jl.load_robot(robot, base="floating")
    locked = jl.lock_joints(full, locks)
    base = "floating" if floating else "fixed"
    for _ in range(3):
        q, dq, ddq = _state(rng, locked.dof)
        motor, brake = actuator_torques(locked, q, dq, ddq, base=base)
        held = {"q": locked.expand(q), "dq": np.zeros(full.dof), "ddq": np.zeros(full.dof)}
        for name, x in (("dq", dq), ("ddq", ddq)):
            idx = [full.index_of(n) for n in locked.joint_numbers]
            held[name][idx] = x
        ref = _pinocchio_torques(full, held["q"], held["dq"], held["ddq"], floating)
        scale = max(1.0, np.abs(ref).max())
        np.testing.assert_allclose(motor, ref[[full.index_of(n) for n in locked.joint_numbers]], atol=1e-10 * scale)
        np.testing.assert_allclose(brake, ref[[full.index_of(lj.number) for lj in locked.locked]], atol=1e-10 * scale)
        assert np.abs(brake).max() > 1e-3  # the brake really holds something


@pytest.mark.parametrize("base", ["fixed", "floating"])
def test_the_motors_feel_what_the_locked_model_says(rng, base):
    locked = jl.lock(jl.load_robot("halt7", base="floating"), 4, 0.2)
    q, dq, ddq = _state(rng, locked.dof, (5, 4))
    motor, brake = actuator_torques(locked, q, dq, ddq, base=base)
    assert motor.shape == (5, 4, 6) and brake.shape == (5, 4, 1)
    np.testing.assert_allclose(motor, jl.rnea(locked, q, dq, ddq, base=base).torques, rtol=1e-12, atol=1e-9)


def test_an_arm_without_locks_has_no_brakes(rng):
    arm = jl.load_robot("halt7")
    q, dq, ddq = _state(rng, 7, (3,))
    loads = actuator_loads(arm, np.arange(3.0), q, dq, ddq)
    assert loads.brake.shape == (3, 0) and loads.peak_brake.size == 0
    assert loads.to_dict()["peak_brake_torque_Nm"] == {}


def test_a_locked_model_without_its_full_arm_is_refused_in_one_line(rng):
    from dataclasses import replace

    locked = replace(jl.lock(jl.load_robot("halt7"), 4, 0.0), unlocked=None)
    with pytest.raises(jl.ModelError, match="brake torques of 'halt7' need the arm before its locks"):
        actuator_torques(locked, *_state(rng, 6))


# -- torque limits as constraints of the halt (000's scenario, free-floating) ----------------------

from jointlock.jobs.halt import plan_halt  # noqa: E402
from jointlock.planning.halt_motion._actuator_limits import actuator_peaks  # noqa: E402

#: The clearance reported, not required (000's halt-configuration search).
OFF = jl.ClearanceSettings.off()


@pytest.fixture(scope="module")
def free_halt():
    # 000's q_best breaks a limit when free; the limits' behaviour is tested on 000's search
    # (the clearance reported, not required: a required one moves the halt configuration)
    return plan_halt("halt7", base="floating", clearance=OFF, search=jl.HaltSearch(samples=4000))


@pytest.fixture
def _halt(free_halt):
    return lambda **kw: plan_halt("halt7", qf=free_halt.problem.qf, base="floating", clearance=OFF, **kw)


def test_every_halt_reports_motor_and_brake_torques(free_halt):
    loads = free_halt.actuator_loads()
    p = free_halt.problem
    assert loads.locked_numbers == (4,) and loads.joint_numbers == p.model.joint_numbers
    q, dq, ddq = free_halt.motion.trajectory(loads.t)
    np.testing.assert_allclose(loads.motor, jl.rnea(p.model, q, dq, ddq, base="floating").torques, atol=1e-8)
    d = free_halt.to_dict()
    assert d["actuators"]["peak_brake_torque_Nm"]["4"] == pytest.approx(loads.peak_brake[0])
    assert d["torque_limit_Nm"] is None and d["brake_margin"] == [None]
    assert any("locked: brake holds peak" in line for line in free_halt.summary())


def test_a_brake_limit_moves_k_and_is_kept_on_every_sample(free_halt, _halt):
    peak = free_halt.actuator_loads().peak_brake[0]
    limit = 0.97 * peak
    plan = _halt(limits=jl.HaltLimits(brake_max_Nm=limit))
    assert plan.feasible and plan.motion.k != free_halt.motion.k
    fine = plan.problem.times(20001)
    q, dq, ddq = plan.motion.trajectory(fine)
    _, brake = actuator_torques(plan.problem.model, q, dq, ddq, base="floating")
    assert np.abs(brake).max() <= limit * (1 + 1e-6)
    name, margin = plan.binding_limit()
    assert "joint 4 brake torque (locked)" in name and margin == 0.0  # on the limit (round-off shown as 0)
    assert plan.to_dict()["binding_limit"] == name
    # the segment's ends are the boundary: just inside keeps the limit, just outside breaks it
    (a, b), = plan.motion.k_segments
    width = b - a
    ratio = actuator_peaks(plan.problem, np.array([a, b, a - 1e-4 * width, b + 1e-4 * width]))[2]
    inside_a, inside_b, out_a, out_b = ratio
    assert inside_a <= 1 + 1e-6 and inside_b <= 1 + 1e-6
    assert (out_a > 1 or a == plan.motion.k_interval[0]) and (out_b > 1 or b == plan.motion.k_interval[1])


def test_a_margin_keeps_a_share_of_the_torque_limits(free_halt):
    limit = 0.97 * free_halt.actuator_loads().peak_motor.max()
    s = free_halt.problem  # 000's state has joint 6 at its speed limit: a slower one leaves room for a margin
    state = jl.FailureState(s.q0, 0.9 * s.dq0, s.ddq0)
    plan = plan_halt(
        s.model,
        state,
        T=10.0,
        base="floating",
        clearance=OFF,
        search=jl.HaltSearch(samples=4000),
        limits=jl.HaltLimits(torque_max_Nm=limit, margin=0.02),
    )
    assert plan.feasible
    assert plan.actuator_loads().peak_motor.max() <= 0.98 * limit * (1 + 1e-6)
    assert np.nanmin(plan.margins()["torque"]) >= 0.02 - 1e-6


def test_a_torque_limit_no_k_keeps_is_reported_as_the_binding_one(free_halt, _halt):
    limit = 0.5 * free_halt.actuator_loads().peak_motor.max()
    plan = _halt(limits=jl.HaltLimits(torque_max_Nm=limit))
    assert not plan.feasible
    worst = plan.motion.violations[0]
    assert worst.kind == "torque" and worst.limit == pytest.approx(limit)
    text = "\n".join(plan.summary())
    assert "no k keeps the torque limits for a 10 s halt" in text
    assert "motor torque reaches" in text and "N m" in text
    assert plan.to_dict()["violations"][0]["limit_value_Nm"] == pytest.approx(limit)


def test_a_state_at_failure_beyond_a_torque_limit_is_refused_up_front():
    with pytest.raises(jl.InfeasibleError, match=r"already needs more torque than a limit allows.*joint 1 motor torque"):
        plan_halt("halt7", paper_qf=True, base="fixed", limits=jl.HaltLimits(torque_max_Nm=1000.0))


def test_torque_limits_need_the_scan_solver():
    with pytest.raises(jl.ScenarioError, match="torque limits need solver 'scan'"):
        plan_halt(
            "halt7",
            paper_qf=True,
            base="floating",
            limits=jl.HaltLimits(brake_max_Nm=1e6),
            motion=jl.HaltMotionSettings(solver="ga"),
        )


def test_a_model_effort_limit_is_the_default_motor_limit():
    arm = jl.from_dh("two", a=[1.0, 1.0], alpha=[0, 0], d=[0, 0], convention="standard",
                     bodies=[jl.Body(1.0, [0.5, 0, 0]), jl.Body(1.0, [0.5, 0, 0])], effort_limit=[50.0, np.inf])  # fmt: skip
    limits = jl.halt_limits(arm)
    assert limits.torque.tolist() == [50.0, np.inf] and limits.torque_source == ("model's limit", "none")
    capped = jl.halt_limits(arm, torque_max_Nm=[80.0, 20.0])
    assert capped.torque.tolist() == [50.0, 20.0]
    assert capped.torque_source == ("model's limit, below torque_max_Nm 80", "torque_max_Nm")


def test_brake_limits_without_a_locked_joint_are_refused():
    with pytest.raises(jl.ScenarioError, match="brake limit, but 'halt7' has no locked joint"):
        jl.halt_limits(jl.load_robot("halt7"), brake_max_Nm=100.0)


# -- robust choice of k among near-optimal ones (issue 14, item 3) --------------------------------


def test_prefer_margin_trades_a_little_objective_for_clear_limits(free_halt, _halt):
    from jointlock.planning.halt_motion._robust import limit_margins

    limit = 0.97 * free_halt.actuator_loads().peak_brake[0]
    tight = _halt(limits=jl.HaltLimits(brake_max_Nm=limit))
    robust = _halt(limits=jl.HaltLimits(brake_max_Nm=limit), motion=jl.HaltMotionSettings(prefer_margin=0.01))
    assert tight.motion.k_optimum is None and robust.motion.k_optimum == pytest.approx(tight.motion.k)
    assert robust.motion.global_torque <= tight.motion.global_torque * 1.01 + 1e-9
    assert robust.motion.global_torque > tight.motion.global_torque  # it did give something up
    p = robust.problem
    before = np.sort(limit_margins(p, np.array([tight.motion.k]))[0])
    after = np.sort(limit_margins(p, np.array([robust.motion.k]))[0])
    first = int(np.argmax(np.round(before, 6) != np.round(after, 6)))
    assert after[first] > before[first]  # leximin: the first margin that differs is larger
    assert robust.margins()["brake"][0] > tight.margins()["brake"][0] + 0.005  # off the brake's limit
    assert "costs" in "\n".join(robust.summary()) and robust.to_dict()["k_optimum"] is not None


def test_prefer_margin_is_bounded_and_named():
    with pytest.raises(jl.ScenarioError, match="prefer_margin"):
        plan_halt("halt7", paper_qf=True, motion=jl.HaltMotionSettings(prefer_margin=-0.1))


# -- review regressions ----------------------------------------------------------------------------

DATA = __import__("pathlib").Path(__file__).resolve().parent / "data"


def test_a_urdfs_own_effort_limits_are_reported_not_refused_by_the_ga():
    arm = jl.lock(jl.read_urdf(DATA / "arm5.urdf"), 2, 0.0)
    assert jl.halt_limits(arm).torque.tolist() == [100.0, np.inf, 10.0, 10.0]  # <limit effort> (none on one)
    state = jl.FailureState.from_degrees(arm, [0, 0, 0, 0], [5, 5, 5, 5], [0, 0, 0, 0])
    plan = plan_halt(
        arm,
        state,
        T=10.0,
        search=jl.HaltSearch(samples=50),
        motion=jl.HaltMotionSettings(solver="ga", ga=jl.jobs.halt._strategy.GASettings(n_pop=4, n_gen=2)),
    )
    assert not plan.problem.has_torque_limits and plan.limits.torque is not None
    assert any("the model's motor torque limits are reported, not kept: solver 'ga'" in line for line in plan.summary())
    assert np.isfinite(plan.margins()["torque"]).tolist() == [True, False, True, True]  # NaN: no limit
    with pytest.raises(jl.ScenarioError, match="torque limits need solver 'scan'"):
        plan_halt(
            arm,
            state,
            T=10.0,
            search=jl.HaltSearch(samples=50),
            motion=jl.HaltMotionSettings(solver="ga"),
            limits=jl.HaltLimits(torque_max_Nm=50.0),
        )


def test_a_kinematically_infeasible_halt_with_torque_limits_searches_t_with_them():
    res = plan_halt("halt7", paper_qf=True, limits=jl.HaltLimits(torque_max_Nm=1e5, brake_max_Nm=900.0))  # kinematics break at 10 s
    kinds = {v.kind for v in res.motion.violations}
    assert not res.feasible and "velocity" in kinds and "brake" in kinds
    t_min = res.motion.minimum_T
    assert t_min is None or plan_halt(
        "halt7",
        paper_qf=True,
        T=t_min + 0.01,
        limits=jl.HaltLimits(torque_max_Nm=1e5, brake_max_Nm=900.0),
    ).feasible


def test_fragile_looks_at_the_stretch_that_keeps_the_torques_too(free_halt, _halt):
    seg_plan = _halt(limits=jl.HaltLimits(brake_max_Nm=0.97 * free_halt.actuator_loads().peak_brake[0]))
    a, b = seg_plan.motion.feasible_stretch
    assert (a, b) in seg_plan.motion.k_segments
    assert seg_plan.fragile == bool(b - a < 0.01 * abs(seg_plan.motion.k))
    assert seg_plan.to_dict()["k_torque_stretches_deg"][0] == pytest.approx(np.array([a, b]) / (np.pi / 180))


def test_prefer_margin_with_one_k_per_joint_is_refused():
    with pytest.raises(jl.ScenarioError, match="prefer_margin needs one shared k"):
        plan_halt(
            "halt7",
            paper_qf=True,
            T=12.0,
            motion=jl.HaltMotionSettings(solver="vector", prefer_margin=0.05),
        )


def test_a_margin_the_start_state_leaves_no_room_for_is_said_so():
    with pytest.raises(jl.InfeasibleError, match="no limits.margin can be kept: the state starts at a limit"):
        plan_halt("halt7", limits=jl.HaltLimits(margin=0.001))
