"""What a free spacecraft does while the arm moves (jointlock.analysis.spacecraft): angular and
linear velocity from zero momentum against Pinocchio's free-flyer model (an independent
momentum matrix), momentum conservation along a halt, the attitude integration against the
closed form of a constant rate, its convergence in the time step, and the halt's report."""

from __future__ import annotations

import numpy as np
import pytest

import jointlock as jl
from jointlock.analysis.spacecraft import _prefix_products, _rotvec_quaternions, spacecraft_response


@pytest.fixture(scope="module")
def paper_halt():
    return jl.plan_halt("halt7", paper_qf=True, motion=jl.HaltMotionSettings(n_samples=201))


def test_the_spacecraft_keeps_zero_momentum_along_a_halt(paper_halt):
    p = paper_halt.problem
    t = p.times(101)
    q, dq, ddq = paper_halt.motion.trajectory(t)
    twist = jl.rnea(p.model, q, dq, ddq, base="floating").base_twist
    h = jl.momentum(p.model, q, dq, base_twist=twist)  # an independent function of the model
    assert np.abs(h).max() < 1e-9 * np.abs(jl.momentum(p.model, q, dq)).max()


@pytest.mark.oracle
def test_base_velocity_from_zero_momentum_matches_pinocchio(rng):
    from pin_oracle import pin, pin_q, to_pinocchio

    arm = jl.lock(jl.load_robot("canadarm7", base="floating"), 3, 0.4)
    pm, _ = to_pinocchio(arm, free_flyer=True)
    data = pm.createData()
    q = rng.uniform(-2.5, 2.5, (5, arm.dof))
    dq = rng.uniform(-0.3, 0.3, (5, arm.dof))
    twist = jl.rnea(arm, q, dq, np.zeros_like(q), base="floating").base_twist
    for i in range(5):
        qq = pin_q(pm, q[i], True)
        ag = pin.computeCentroidalMap(pm, data, qq).copy()  # centroidal momentum = Ag v
        v_base = np.linalg.solve(ag[:, :6], -ag[:, 6:] @ dq[i])  # base frame origin: (v, omega), local
        omega = v_base[3:]
        v_com = v_base[:3] + np.cross(omega, arm.root_body.com)
        np.testing.assert_allclose(twist[i, 3:], omega, atol=1e-12)
        np.testing.assert_allclose(twist[i, :3], v_com, atol=1e-12)


def test_a_constant_rate_turns_by_rate_times_time():
    w, T, n = np.array([0.1, -0.2, 0.3]), 7.0, 1001
    steps = _rotvec_quaternions(np.tile(w * T / (n - 1), (n - 1, 1)))
    final = _prefix_products(steps)[-1]
    assert np.degrees(2 * np.arccos(final[0])) == pytest.approx(np.degrees(np.linalg.norm(w) * T), rel=1e-12)
    np.testing.assert_allclose(final[1:] / np.linalg.norm(final[1:]), w / np.linalg.norm(w), atol=1e-12)


def test_the_ordered_product_matches_a_loop(rng):
    steps = _rotvec_quaternions(rng.normal(scale=0.3, size=(37, 3)))
    from jointlock.analysis.spacecraft import _quaternion_product

    acc = [steps[0]]
    for s in steps[1:]:  # the sequential definition the scan must equal
        acc.append(_quaternion_product(acc[-1], s))
    np.testing.assert_allclose(_prefix_products(steps), np.array(acc), atol=1e-12)


def test_the_attitude_converges_in_the_time_step(paper_halt):
    coarse = paper_halt.spacecraft_response(501)
    fine = paper_halt.spacecraft_response(4001)
    assert coarse.final_attitude_change_deg == pytest.approx(fine.final_attitude_change_deg, abs=1e-3)
    assert coarse.com_drift_m == pytest.approx(fine.com_drift_m, abs=1e-5)


def test_the_halt_reports_what_the_spacecraft_feels(paper_halt, tmp_path):
    """000's scenario on the default 2000 kg spacecraft: the 70 kg, 5 m booms swinging through
    the halt would turn a free spacecraft by ~124 deg (its torque is 000's, with it held)."""
    sc = paper_halt.to_dict()["spacecraft"]
    assert sc["attitude_change_deg"] == pytest.approx(123.9, abs=0.1)
    assert sc["peak_rate_deg_s"] == pytest.approx(27.6, abs=0.1)
    assert any(line.startswith("spacecraft if it were free") for line in paper_halt.summary())
    assert "spacecraft_attitude.png" in paper_halt.write(tmp_path)


def test_a_fixed_model_has_no_spacecraft_response():
    arm = jl.load_robot("puma6")
    with pytest.raises(jl.ModelError, match="free-floating model"):
        spacecraft_response(arm, [0.0, 1.0], np.zeros((2, 6)), np.zeros((2, 6)))


@pytest.mark.parametrize(("n", "tol_m"), [(501, 1e-4), (4001, 2e-6)])
def test_the_whole_systems_centre_of_mass_stays_put(paper_halt, n, tol_m):
    """Zero momentum: the system's centre of mass does not move.  In the first frame it is the
    spacecraft's drift plus its attitude applied to (system CoM - spacecraft CoM) in its own
    frame: this checks the order of the rotations (the other order moves it by ~0.16 m) and the
    drift, independently of how they were computed."""
    from jointlock.analysis.spacecraft import _rotate
    from jointlock.kinematics import system_com

    p = paper_halt.problem
    sc = paper_halt.spacecraft_response(n)
    q, _, _ = paper_halt.motion.trajectory(sc.t)
    inertial = sc.com_displacement + _rotate(sc.attitude, system_com(p.model, q) - p.model.root_body.com)
    assert np.abs(inertial - inertial[0]).max() < tol_m


def test_the_attitude_needs_no_fine_objective_grid():
    """The halt's objective may use few samples; the attitude keeps its own 0.02 s step."""
    coarse = jl.plan_halt("halt7", paper_qf=True, motion=jl.HaltMotionSettings(n_samples=11)).spacecraft_response()
    assert coarse.final_attitude_change_deg == pytest.approx(123.89, abs=0.01)
    assert coarse.rotation_path_deg >= coarse.final_attitude_change_deg


# -- the jump study and the re-plan (issue 14, item 1: every free-floating motion) ---------------


def test_held_rates_turn_the_spacecraft_as_the_jump_integrator_does(rng):
    """``rates="hold"``: R_{k+1} = R_k exp([omega(q_k, dq_k)] dt), omega from the base Jacobian
    (kinematics, not the Newton-Euler base twist), composed here as rotation matrices."""
    from jointlock.kinematics import base_jacobian
    from jointlock.spatial import axis_angle_rotation

    model = jl.load_robot("canadarm7", base="floating")
    t = np.linspace(0.0, 2.0, 41)
    q = np.cumsum(rng.uniform(-0.05, 0.05, (41, 7)), axis=0)
    dq = rng.uniform(-0.3, 0.3, (41, 7))
    sc = spacecraft_response(model, t, q, dq, rates="hold")
    R = np.eye(3)
    for k in range(40):
        omega = base_jacobian(model, q[k])[3:] @ dq[k] * (t[k + 1] - t[k])
        angle = np.linalg.norm(omega)
        R = R @ axis_angle_rotation(omega / angle, angle)
    w, x, y, z = sc.attitude[-1]
    from_quaternion = np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )
    np.testing.assert_allclose(from_quaternion, R, atol=1e-12)


def test_a_free_floating_jump_reports_the_spacecraft_of_both_runs():
    from jointlock.jobs.jump import run_jump_study
    from jointlock.planning.jump import JumpScenario

    model = jl.load_robot("canadarm7", base="floating")
    task = JumpScenario(base="floating", duration=4.0, dt=0.02)
    res = run_jump_study(model, task, fail_at=2.0, kappa=0.0)
    d = res.to_dict()["spacecraft"]
    assert d["fail_time_s"] == 2.0 and set(d) == {"fail_time_s", "uncompensated", "compensated"}
    assert d["compensated"]["attitude_change_deg"] > 0.1
    assert any(line.startswith("spacecraft, failure at 2 s, compensated") for line in res.summary())
    fixed = run_jump_study(jl.load_robot("canadarm7"), JumpScenario(duration=4.0, dt=0.02), fail_at=2.0, kappa=0.0)
    assert "spacecraft" not in fixed.to_dict() and fixed.spacecraft_responses() is None


def test_a_free_floating_replan_reports_the_spacecraft_and_keeps_the_system_still():
    from jointlock.jobs.replan import plan_replan
    from jointlock.kinematics import system_com

    model = jl.load_robot("puma6", base="floating")
    res = plan_replan(model, 2, np.radians(59.4), np.radians([0, 60, 0, 0, 0, 0]), np.radians([5, 60, 35, 10, -120, 90]),
                      tolerance_deg=2.0, steps=80)  # fmt: skip
    sc = res.spacecraft_response()
    assert res.to_dict()["spacecraft"] == sc.to_dict() and sc.final_attitude_change_deg > 0.05
    # zero momentum: the whole system's centre of mass does not move (to the rates' differencing error)
    locked = res.model
    com_arm = system_com(locked, res.plan.q)  # in the spacecraft frame
    R = np.array([[[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                   [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                   [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]] for w, x, y, z in sc.attitude])  # fmt: skip
    com0 = locked.root_body.com
    world = sc.com_displacement + np.einsum("kij,kj->ki", R, com_arm - com0) - (com_arm[0] - com0)
    assert np.abs(world).max() < 0.02 * np.abs(sc.com_displacement).max() + 1e-6
    assert plan_replan(jl.load_robot("puma6"), 2, np.radians(59.4), np.zeros(6) + np.radians([0, 60, 0, 0, 0, 0]),
                       np.radians([5, 60, 35, 10, -120, 90]), tolerance_deg=2.0).spacecraft_response() is None  # fmt: skip


# -- halt objectives beyond 000's (issue 14, item 1) ---------------------------------------------


@pytest.fixture(scope="module")
def free_problem():
    plan = jl.plan_halt(
        "halt7",
        base="floating",
        search=jl.HaltSearch(samples=4000),
        motion=jl.HaltMotionSettings(n_samples=201),
    )
    return plan.problem


def test_the_attitude_objective_is_the_spacecraft_response_at_the_end(free_problem):
    from dataclasses import replace

    from jointlock.planning.halt_motion import halt_objective

    p = replace(free_problem, objective="attitude_change")
    ks = np.linspace(*jl.planning.halt_motion.shared_k_interval(p), 5)
    values = halt_objective(p, ks)
    t = p.times()
    for k, value in zip(ks, values):
        q, dq, _ = p.trajectory(k, t)
        assert value == pytest.approx(spacecraft_response(p.model, t, q, dq).final_attitude_change_deg, rel=1e-12)
    peak = halt_objective(replace(p, objective="peak_torque"), ks)
    hist = jl.planning.halt_motion.base_torque_history(p, ks, t)
    np.testing.assert_allclose(peak, np.linalg.norm(hist, axis=-1).max(axis=-1), rtol=1e-12)


@pytest.mark.parametrize("objective", ["peak_torque", "attitude_change"])
def test_each_objective_is_minimised_over_the_feasible_k(free_problem, objective):
    from dataclasses import replace

    from jointlock.planning.halt_motion import halt_objective, optimal_halt_motion

    p = replace(free_problem, objective=objective)
    res = optimal_halt_motion(p)
    lo, hi = res.k_interval
    grid = np.linspace(lo, hi, 301)
    assert res.feasible and lo <= res.k <= hi
    assert res.objective_value <= halt_objective(p, grid).min() * (1 + 1e-9)
    assert res.objective_value == pytest.approx(float(halt_objective(p, res.k)))
    mean = optimal_halt_motion(free_problem)
    assert res.k != pytest.approx(mean.k, rel=1e-3)  # another objective, another k
    assert res.global_torque >= mean.global_torque * (1 - 1e-9)  # 000's objective is best at its own k


def test_the_attitude_objective_needs_a_spacecraft():
    model = jl.lock(jl.load_robot("halt7"), 4, 0.0)
    state = jl.FailureState.from_degrees(model, [0.0] * 6)
    with pytest.raises(jl.ScenarioError, match="objective 'attitude_change' needs a model with a spacecraft"):
        jl.plan_halt(
            model,
            state,
            T=10.0,
            qf=np.full(6, 0.1),
            motion=jl.HaltMotionSettings(objective="attitude_change"),
        )
