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
    return jl.plan_halt("halt7", paper_qf=True, n_samples=201)


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
    coarse = jl.plan_halt("halt7", paper_qf=True, n_samples=11).spacecraft_response()
    assert coarse.final_attitude_change_deg == pytest.approx(123.89, abs=0.01)
    assert coarse.rotation_path_deg >= coarse.final_attitude_change_deg
