"""Free-floating base: generalized Jacobian against a simulated zero-momentum motion,
momentum measured independently (finite differences of body motion), virtual manipulator."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import EXACT_ATOL, FD_ATOL, FD_STEP, random_q

import jointlock as jl
from jointlock.spatial import rotation_log, skew


def _simulate(model: jl.ArmModel, q0: np.ndarray, dq: np.ndarray, duration: float, steps: int):
    """RK4 of the spacecraft pose while the joints move at constant rate ``dq``, the base
    twist coming from the zero-momentum base Jacobian.  Also integrates J* dq (rotated to
    the inertial frame) for the end-effector displacement it predicts."""
    r0 = model.root_body.com

    def deriv(state, t):
        rot = state[:9].reshape(3, 3)
        q = q0 + dq * t
        nu = jl.base_jacobian(model, q) @ dq  # (v_com, w) in base-frame components
        w_inertial = rot @ nu[3:]
        v_origin = rot @ nu[:3] - np.cross(w_inertial, rot @ r0)
        ee_rate = rot @ (jl.generalized_jacobian(model, q)[:3] @ dq)
        return np.concatenate([(skew(w_inertial) @ rot).ravel(), v_origin, ee_rate])

    state = np.concatenate([np.eye(3).ravel(), np.zeros(3), np.zeros(3)])
    h = duration / steps
    history = [state]
    for k in range(steps):
        t = k * h
        k1 = deriv(state, t)
        k2 = deriv(state + h / 2 * k1, t + h / 2)
        k3 = deriv(state + h / 2 * k2, t + h / 2)
        k4 = deriv(state + h * k3, t + h)
        state = state + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        history.append(state)
    return np.array(history)


def _inertial_bodies(model, q, rot_b, p_b):
    """Inertial COM positions and orientations of spacecraft + links (independent of the
    momentum code: forward kinematics only)."""
    state = jl.chain_state(model, q)
    coms = jl.com_positions(model, q, state)
    pos = np.vstack([model.root_body.com, coms]) @ rot_b.T + p_b
    rots = np.concatenate([np.eye(3)[None], state.rotations])
    return pos, rot_b @ rots


@pytest.mark.parametrize("name", ["halt7", "canadarm7"])
def test_generalized_jacobian_predicts_the_free_floating_motion(name, rng):
    model = jl.load_robot(name, base="floating")
    q0 = random_q(model, rng)
    dq = rng.uniform(-0.3, 0.3, model.dof)
    duration, steps = 1.0, 200
    hist = _simulate(model, q0, dq, duration, steps)
    masses = np.concatenate([[model.root_body.mass], [b.mass for b in model.bodies]])
    inertias = np.concatenate([model.root_body.inertia[None], [b.inertia for b in model.bodies]])

    # 1) momentum stays zero, measured by central differences of the simulated body motion
    h = duration / steps
    for k in (1, steps // 2, steps - 1):
        frames = []
        for kk in (k - 1, k + 1):
            rot_b = hist[kk, :9].reshape(3, 3)
            frames.append(_inertial_bodies(model, q0 + dq * kk * h, rot_b, hist[kk, 9:12]))
        rot_b = hist[k, :9].reshape(3, 3)
        pos, rots = _inertial_bodies(model, q0 + dq * k * h, rot_b, hist[k, 9:12])
        vel = (frames[1][0] - frames[0][0]) / (2 * h)
        # angular velocity of each body: body-frame log of R(t-h)^T R(t+h), rotated to inertial
        omega = np.array(
            [
                rots[i] @ rotation_log(frames[0][1][i].T @ frames[1][1][i]) / (2 * h)
                for i in range(len(masses))
            ]
        )
        lin = masses @ vel
        ang = sum(
            rots[i] @ inertias[i] @ rots[i].T @ omega[i] + masses[i] * np.cross(pos[i], vel[i])
            for i in range(len(masses))
        )
        scale = float(np.sum(masses * np.linalg.norm(vel, axis=1))) + 1.0
        assert np.linalg.norm(lin) < 1e-5 * scale
        assert np.linalg.norm(ang) < 1e-4 * scale

    # 2) the system centre of mass does not move (inertial frame)
    coms0 = _inertial_bodies(model, q0, np.eye(3), np.zeros(3))[0]
    rot_f, p_f = hist[-1, :9].reshape(3, 3), hist[-1, 9:12]
    coms1 = _inertial_bodies(model, q0 + dq * duration, rot_f, p_f)[0]
    np.testing.assert_allclose(masses @ coms1 / masses.sum(), masses @ coms0 / masses.sum(), atol=1e-9)

    # 3) the end-effector displacement from forward kinematics equals the J* prediction
    ee0 = jl.ee_pose(model, q0)[:3, 3]
    ee1 = rot_f @ jl.ee_pose(model, q0 + dq * duration)[:3, 3] + p_f
    np.testing.assert_allclose(ee1 - ee0, hist[-1, 12:15], atol=1e-8)
    # ...and differs from what the fixed-base Jacobian predicts (the test can fail)
    fixed_prediction = jl.ee_pose(model.fixed(), q0 + dq * duration)[:3, 3] - ee0
    assert np.linalg.norm(fixed_prediction - (ee1 - ee0)) > 1e-3


def test_momentum_is_zero_with_the_base_jacobian_motion(rng):
    model = jl.lock(jl.load_robot("halt7", base="floating"), 4, 0.0)
    q = random_q(model, rng, (10,))
    dq = rng.normal(size=(10, model.dof))
    nu = np.einsum("...ij,...j->...i", jl.base_jacobian(model, q), dq)
    np.testing.assert_allclose(jl.momentum(model, q, dq, nu), 0.0, atol=1e-9)
    assert np.abs(jl.momentum(model, q, dq)).max() > 1.0  # without the base reaction it is not zero


def test_system_mass_matrix_is_symmetric_positive_definite(rng):
    model = jl.load_robot("canadarm7", base="floating")
    m = jl.system_mass_matrix(model, random_q(model, rng, (20,)))
    np.testing.assert_allclose(m, np.swapaxes(m, -1, -2), atol=1e-9)
    assert np.all(np.linalg.eigvalsh(m) > 0)


def test_fixed_base_generalized_jacobian_is_the_ordinary_one(rng):
    model = jl.load_robot("halt7")
    q = random_q(model, rng, (5,))
    np.testing.assert_allclose(jl.generalized_jacobian(model, q), jl.jacobian(model, q), atol=EXACT_ATOL)


@pytest.mark.parametrize("name", ["halt7", "canadarm7", "puma6"])
def test_virtual_manipulator_reaches_the_real_end_effector(name, rng):
    model = jl.load_robot(name, base="floating")
    q = random_q(model, rng, (8,))
    vm = jl.virtual_manipulator(model, q)
    np.testing.assert_allclose(vm.ee_position, jl.ee_pose(model, q)[..., :3, 3], atol=EXACT_ATOL)
    np.testing.assert_allclose(vm.ground, jl.system_com(model, q), atol=EXACT_ATOL)


def test_virtual_jacobian_matches_finite_differences(rng):
    model = jl.load_robot("canadarm7", base="floating")
    q = random_q(model, rng)
    steps = np.eye(model.dof) * FD_STEP

    def tip_from_ground(qq):
        vm = jl.virtual_manipulator(model, qq)
        return vm.ee_position - vm.ground

    d = (tip_from_ground(q + steps) - tip_from_ground(q - steps)) / (2 * FD_STEP)
    np.testing.assert_allclose(jl.virtual_manipulator(model, q).jacobian[:3], d.T, atol=FD_ATOL)


def test_virtual_manipulator_of_a_fixed_base_is_the_real_arm(rng):
    model = jl.load_robot("halt7")
    q = random_q(model, rng)
    vm = jl.virtual_manipulator(model, q)
    np.testing.assert_allclose(vm.jacobian, jl.jacobian(model, q), atol=EXACT_ATOL)
