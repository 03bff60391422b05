"""Regression tests for defects found in review (each failed before its fix)."""

from __future__ import annotations

import numpy as np
import pytest

import jointlock as jl
from jointlock.derivatives import manipulability_gradient
from jointlock.spatial import axis_angle_rotation, rotation_log


def _planar_floating() -> jl.ArmModel:
    bodies = [jl.Body(3.0, [-0.5, 0, 0], [0.01, 0.3, 0.3]), jl.Body(2.0, [-0.5, 0, 0], [0.01, 0.2, 0.2])]
    return jl.from_dh(
        "planar",
        a=[1.0, 1.0],
        alpha=[0.0, 0.0],
        d=[0.0, 0.0],
        convention="standard",
        bodies=bodies,
        spacecraft=jl.Body(10.0, [0, 0, 0], [1, 1, 1]),
    )


def test_floating_rnea_on_a_planar_arm_matches_the_generalized_inertia():
    model = _planar_floating()
    q, ddq = np.array([0.3, 0.2]), np.array([1.0, -0.5])
    res = jl.rnea(model, q, np.zeros(2), ddq, base="floating")
    np.testing.assert_allclose(res.torques, jl.generalized_inertia(model, q) @ ddq, atol=1e-12)


def test_locking_point_masses_keeps_a_semidefinite_merged_inertia():
    model = jl.from_dh(
        "points",
        a=[1, 1, 1],
        alpha=[0, 0, 0],
        d=[0, 0, 0],
        convention="standard",
        bodies=[jl.Body(2.0, [-0.5, 0, 0])] * 3,
    )
    locked = jl.lock(model, 2, 0.3)  # merged inertia has a zero moment along the link
    q = np.array([0.1, -0.4])
    full = jl.mass_matrix(model, locked.expand(q))
    np.testing.assert_allclose(jl.mass_matrix(locked, q), full[np.ix_([0, 2], [0, 2])], atol=1e-12)


@pytest.mark.parametrize("name", jl.BUILTIN_ROBOTS)
def test_virtual_manipulator_of_a_fixed_base_reaches_the_real_tip(name):
    model = jl.load_robot(name)
    q = np.random.default_rng(3).uniform(-1, 1, (4, model.dof))
    np.testing.assert_allclose(
        jl.virtual_manipulator(model, q).ee_position, jl.ee_pose(model, q)[..., :3, 3], atol=1e-12
    )


def test_massless_model_has_no_centre_of_mass():
    model = jl.from_dh("x", a=[1, 1], alpha=[0, 0], d=[0, 0], convention="standard")
    with pytest.raises(jl.ModelError, match="no mass"):
        jl.system_com(model, np.zeros(2))


def test_expand_checks_the_length():
    locked = jl.lock(jl.load_robot("halt7"), 4, 0.5)
    with pytest.raises(jl.ConfigurationError, match=r"shape \(\.\.\., 6\)"):
        locked.expand(np.arange(7.0))


@pytest.mark.parametrize("gap", [1e-3, 1e-5, 1e-7, 0.0])
def test_rotation_log_is_accurate_near_pi(gap):
    axis = np.array([0.3, -0.5, 0.8]) / np.linalg.norm([0.3, -0.5, 0.8])
    angle = np.pi - gap
    log = rotation_log(axis_angle_rotation(axis, angle))
    np.testing.assert_allclose(np.linalg.norm(log), angle, atol=1e-12)
    assert abs(abs(log @ axis) - angle) < 1e-12


def test_manipulability_gradient_is_finite_at_a_singularity():
    model = jl.load_robot("puma6")
    w, grad = manipulability_gradient(model, np.zeros((2, 6)), rows="full")
    assert np.all(w < 1e-12) and np.all(np.isfinite(grad))


def test_factories_refuse_a_misspelt_base():
    from jointlock.robots import canadarm7, halt7, puma6

    for factory in (halt7, canadarm7, puma6):
        with pytest.raises(jl.ModelError, match="base must be 'fixed' or 'floating'"):
            factory(base="flaoting")


def test_wrong_frame_is_a_jointlock_error():
    with pytest.raises(jl.ConfigurationError, match="frame must be"):
        jl.jacobian(jl.load_robot("puma6"), np.zeros(6), frame="world")
