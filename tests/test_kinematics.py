"""Batched kinematics: Jacobians against finite differences of forward kinematics, batched
results against loops of single calls."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import EXACT_ATOL, FD_ATOL, FD_STEP, ROBOT_NAMES, random_q

import jointlock as jl
from jointlock.spatial import rotation_log


def fd_jacobian(model: jl.ArmModel, q: np.ndarray) -> np.ndarray:
    """Central differences of FK; the rotation part through the log map of R(q+h) R(q-h)^T."""
    n = model.dof
    steps = np.eye(n) * FD_STEP
    plus = jl.ee_pose(model, q + steps)  # (n, 4, 4): batched over the perturbations
    minus = jl.ee_pose(model, q - steps)
    lin = (plus[:, :3, 3] - minus[:, :3, 3]) / (2 * FD_STEP)
    ang = rotation_log(plus[:, :3, :3] @ np.swapaxes(minus[:, :3, :3], -1, -2)) / (2 * FD_STEP)
    return np.concatenate([lin.T, ang.T], axis=0)


@pytest.mark.parametrize("name", ROBOT_NAMES)
@pytest.mark.parametrize("base", ["fixed", "floating"])
def test_jacobian_matches_finite_differences(name, base, rng):
    model = jl.load_robot(name, base=base)
    for q in random_q(model, rng, (5,)):
        np.testing.assert_allclose(jl.jacobian(model, q), fd_jacobian(model, q), atol=FD_ATOL)


@pytest.mark.parametrize("name", ROBOT_NAMES)
def test_locked_jacobian_matches_finite_differences(name, rng):
    model = jl.lock(jl.load_robot(name), 2, 0.3)
    q = random_q(model, rng)
    np.testing.assert_allclose(jl.jacobian(model, q), fd_jacobian(model, q), atol=FD_ATOL)


def test_ee_frame_jacobian_is_the_rotated_base_jacobian(rng):
    model = jl.load_robot("halt7")
    q = random_q(model, rng)
    rot = jl.ee_pose(model, q)[:3, :3]
    jb, je = jl.jacobian(model, q), jl.jacobian(model, q, frame="ee")
    np.testing.assert_allclose(je[:3], rot.T @ jb[:3], atol=EXACT_ATOL)
    np.testing.assert_allclose(je[3:], rot.T @ jb[3:], atol=EXACT_ATOL)


def test_com_jacobians_match_finite_differences(rng):
    model = jl.load_robot("halt7")
    q = random_q(model, rng)
    steps = np.eye(model.dof) * FD_STEP
    dcom = (jl.com_positions(model, q + steps) - jl.com_positions(model, q - steps)) / (2 * FD_STEP)
    np.testing.assert_allclose(jl.com_jacobians(model, q)[:, :3, :], np.moveaxis(dcom, 0, -1), atol=FD_ATOL)


BATCHED = {
    "link_poses": lambda m, q: jl.link_poses(m, q),
    "ee_pose": lambda m, q: jl.ee_pose(m, q),
    "com_positions": lambda m, q: jl.com_positions(m, q),
    "jacobian": lambda m, q: jl.jacobian(m, q),
    "jacobian_ee": lambda m, q: jl.jacobian(m, q, frame="ee"),
    "com_jacobians": lambda m, q: jl.com_jacobians(m, q),
    "momentum_matrix": lambda m, q: jl.momentum_matrix(m, q),
    "base_jacobian": lambda m, q: jl.base_jacobian(m, q),
    "generalized_jacobian": lambda m, q: jl.generalized_jacobian(m, q),
    "system_com": lambda m, q: jl.system_com(m, q),
    "mass_matrix": lambda m, q: jl.mass_matrix(m, q),
    "system_mass_matrix": lambda m, q: jl.system_mass_matrix(m, q),
    "generalized_inertia": lambda m, q: jl.generalized_inertia(m, q),
    "virtual_jacobian": lambda m, q: jl.virtual_manipulator(m, q).jacobian,
    "virtual_joints": lambda m, q: jl.virtual_manipulator(m, q).joint_positions,
    "momentum": lambda m, q: jl.momentum(m, q, np.cos(q)),
}


@pytest.mark.parametrize("fn", sorted(BATCHED))
def test_batched_equals_loop_of_single_calls(fn, rng):
    model = jl.lock(jl.load_robot("canadarm7", base="floating"), 3, -0.2)
    q = random_q(model, rng, (3, 4))
    batched = BATCHED[fn](model, q)
    looped = np.array([[BATCHED[fn](model, q[i, j]) for j in range(4)] for i in range(3)])
    np.testing.assert_allclose(batched, looped, atol=EXACT_ATOL, rtol=0)


def test_poses_are_rigid_transforms(rng):
    model = jl.load_robot("puma6")
    poses = jl.link_poses(model, random_q(model, rng, (50,)))
    rot = poses[..., :3, :3]
    np.testing.assert_allclose(
        rot @ np.swapaxes(rot, -1, -2), np.broadcast_to(np.eye(3), rot.shape), atol=1e-12
    )
    np.testing.assert_allclose(np.linalg.det(rot), 1.0, atol=1e-12)


def test_standard_and_modified_dh_describe_the_same_arm(rng):
    """puma6 rewritten by hand as a modified-DH table (frames moved to the proximal joint)
    gives the same end-effector pose."""
    std = jl.load_robot("puma6")
    deg = np.radians
    a2, d4, d6 = 0.985, -0.765, 0.382
    mod = jl.from_dh(
        "puma6-modified",
        a=[0, 0, a2, 0, 0, 0],
        alpha=deg([0, -90, 0, 90, -90, 90]),
        d=[0, 0, 0, d4, 0, d6],
        convention="modified",
    )
    q = random_q(std, rng, (20,))
    np.testing.assert_allclose(jl.ee_pose(mod, q), jl.ee_pose(std, q), atol=1e-12)
