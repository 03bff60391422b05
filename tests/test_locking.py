"""A locked model equals the full model with that joint frozen (SPEC piece 2)."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import EXACT_ATOL, ROBOT_NAMES, random_q

import jointlock as jl


def _frozen_comparison(full: jl.ArmModel, locks: dict[int, float], q_healthy: np.ndarray):
    locked = jl.lock_joints(full, locks)
    q_full = locked.expand(q_healthy)
    keep = [i for i, n in enumerate(full.joint_numbers) if n not in locks]
    return locked, q_full, keep


@pytest.mark.parametrize("name", ROBOT_NAMES)
@pytest.mark.parametrize("base", ["fixed", "floating"])
def test_lock_every_joint_equals_frozen_full_model(name, base, rng):
    full = jl.load_robot(name, base=base)
    for number in full.joint_numbers:
        angle = rng.uniform(-np.pi, np.pi)
        locked = jl.lock(full, number, angle)
        assert locked.dof == full.dof - 1
        assert locked.joint_numbers == tuple(n for n in full.joint_numbers if n != number)
        q = random_q(locked, rng, (4,))
        q_full = locked.expand(q)
        assert np.allclose(q_full[:, number - 1], angle)
        keep = [i for i in range(full.dof) if i != number - 1]
        np.testing.assert_allclose(
            jl.link_poses(locked, q), jl.link_poses(full, q_full)[:, keep], atol=EXACT_ATOL
        )
        np.testing.assert_allclose(jl.ee_pose(locked, q), jl.ee_pose(full, q_full), atol=EXACT_ATOL)
        np.testing.assert_allclose(
            jl.jacobian(locked, q), jl.jacobian(full, q_full)[..., keep], atol=EXACT_ATOL
        )
        m_full = jl.mass_matrix(full, q_full)
        np.testing.assert_allclose(jl.mass_matrix(locked, q), m_full[:, keep][:, :, keep], atol=1e-9)
        assert locked.total_mass == pytest.approx(full.total_mass, rel=1e-14)
        np.testing.assert_allclose(jl.system_com(locked, q), jl.system_com(full, q_full), atol=EXACT_ATOL)
        if base == "floating":
            np.testing.assert_allclose(
                jl.generalized_jacobian(locked, q),
                jl.generalized_jacobian(full, q_full)[..., keep],
                atol=1e-9,
            )
            h_full = jl.generalized_inertia(full, q_full)
            np.testing.assert_allclose(
                jl.generalized_inertia(locked, q), h_full[:, keep][:, :, keep], atol=1e-8
            )
            if number != 1:
                # Locking joint 1 merges link 1 into the spacecraft and moves the centre of
                # mass whose velocity is the base coordinate: compare the coordinate-free H*
                # above only.
                sys_full = jl.system_mass_matrix(full, q_full)
                idx = list(range(6)) + [6 + k for k in keep]
                np.testing.assert_allclose(
                    jl.system_mass_matrix(locked, q), sys_full[:, idx][:, :, idx], atol=1e-8
                )


@pytest.mark.parametrize("locks", [{1: 0.4, 7: -1.0}, {4: 0.0, 2: 0.7, 6: -0.3}, {7: 0.1, 6: 0.2, 5: 0.3}])
def test_several_locks_in_any_order(locks, rng):
    full = jl.load_robot("halt7", base="floating")
    locked = jl.lock_joints(full, locks)
    assert sorted(lj.number for lj in locked.locked) == sorted(locks)
    q = random_q(locked, rng, (3,))
    q_full = locked.expand(q)
    keep = [i for i, n in enumerate(full.joint_numbers) if n not in locks]
    np.testing.assert_allclose(jl.jacobian(locked, q), jl.jacobian(full, q_full)[..., keep], atol=EXACT_ATOL)
    m_full = jl.mass_matrix(full, q_full)
    np.testing.assert_allclose(jl.mass_matrix(locked, q), m_full[:, keep][:, :, keep], atol=1e-9)
    np.testing.assert_allclose(locked.healthy(q_full), q)


def test_lock_does_not_change_the_original_model():
    full = jl.load_robot("halt7")
    before = [j.placement.copy() for j in full.joints]
    jl.lock(full, 3, 0.5)
    assert full.dof == 7
    for j, p in zip(full.joints, before):
        np.testing.assert_array_equal(j.placement, p)
    with pytest.raises(ValueError):
        full.joints[0].placement[0, 0] = 2.0  # read-only


def test_merged_body_matches_hand_computation():
    """Two point-like rods merged: mass, centre of mass and parallel-axis inertia by hand."""
    a = jl.Body(2.0, [0, 0, 0], [1.0, 1.0, 1.0])
    b = jl.Body(2.0, [0, 0, 0], [1.0, 1.0, 1.0])
    pose = np.eye(4)
    pose[:3, 3] = [2.0, 0.0, 0.0]
    merged = a.merged(b, pose)
    assert merged.mass == 4.0
    np.testing.assert_allclose(merged.com, [1.0, 0.0, 0.0])
    # each body 1 m from the common COM along x: +2*1^2 about y and z
    np.testing.assert_allclose(np.diag(merged.inertia), [2.0, 6.0, 6.0])


def test_lock_errors_name_the_joint_and_allowed_values():
    model = jl.load_robot("halt7")
    with pytest.raises(jl.ModelError, match=r"one of the movable joints \[1, 2, 3, 4, 5, 6, 7\].*got 8"):
        jl.lock(model, 8, 0.0)
    with pytest.raises(jl.ModelError, match="got 0"):
        jl.lock(model, 0, 0.0)
    locked = jl.lock(model, 4, 0.0)
    with pytest.raises(jl.ModelError, match="joint 4 is locked"):
        jl.lock(locked, 4, 0.0)
    with pytest.raises(jl.ModelError, match="within its limits"):
        jl.lock(model, 2, 4.0)
    with pytest.raises(jl.ModelError, match="finite"):
        jl.lock(model, 2, float("nan"))


def test_massless_bodies_keep_their_rotational_inertia_when_merged(rng):
    """Issue 15, item 3: a body of mass 0 with inertia (a rotor, a URDF link with mass 0) keeps
    it when merged, whichever order the two bodies come in, and locking stays exact."""
    rotor = jl.Body(0.0, [0.3, 0.0, 0.0], [0.05, 0.06, 0.03])
    merged = jl.Body(0.0).merged(rotor)
    np.testing.assert_allclose(merged.inertia, np.diag([0.05, 0.06, 0.03]))
    np.testing.assert_allclose(rotor.merged(jl.Body(0.0)).inertia, merged.inertia)
    # an arm whose joint-2 link is massless but has inertia: locking joint 2 (or 3) is exact
    bodies = [jl.Body(2.0, [0.4, 0, 0], [0.01, 0.2, 0.2]), jl.Body(0.0, [0.2, 0, 0], [0.05, 0.06, 0.03]),
              jl.Body(0.0, [0.1, 0, 0], [0.02, 0.02, 0.04]), jl.Body(1.0, [0.2, 0, 0], [0.01, 0.1, 0.1])]  # fmt: skip
    arm = jl.from_dh("rotors", a=[0.8, 0.4, 0.3, 0.4], alpha=[np.pi / 2, 0, -np.pi / 2, 0], d=[0.1, 0, 0.2, 0],
                     convention="standard", bodies=bodies)  # fmt: skip
    for locks in ({2: 0.4}, {3: -0.7}, {2: 0.4, 3: -0.7}):
        locked, q_full, keep = _frozen_comparison(arm, locks, random_q(arm, rng, (5,))[:, : arm.dof - len(locks)])
        m_full = jl.mass_matrix(arm, q_full)
        np.testing.assert_allclose(jl.mass_matrix(locked, locked.healthy(q_full)), m_full[:, keep][:, :, keep], atol=1e-12)


def test_check_lock_refuses_what_lock_refuses():
    """A scenario's validation checks each lock without building the locked arm (issue 29: one
    validation per campaign case): the same errors as lock itself."""
    from jointlock.errors import ModelError
    from jointlock.locking import check_lock

    arm = jl.load_robot("puma6")
    one = jl.lock_joints(arm, {1: 0.0, 2: 0.0, 3: 0.0, 4: 0.0, 5: 0.0})
    for model, joint, angle in ((arm, 0, 0.0), (arm, 7, 0.0), (arm, True, 0.0), (arm, 2, float("nan")),
                                (arm, 2, 10.0), (one, 6, 0.0), (one, 3, 0.0)):  # fmt: skip
        with pytest.raises(ModelError) as built:
            jl.lock(model, joint, angle)
        with pytest.raises(ModelError) as checked:
            check_lock(model, joint, angle)
        assert str(checked.value) == str(built.value)
    assert check_lock(arm, 3, 0.5) == (2, 0.5)
