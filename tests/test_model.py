"""Model construction and the errors a user gets for bad input."""

from __future__ import annotations

import numpy as np
import pytest

import jointlock as jl


def test_wrong_shaped_q_names_the_argument_and_allowed_shape():
    model = jl.load_robot("halt7")
    with pytest.raises(jl.ConfigurationError, match=r"q must have shape \(\.\.\., 7\).*got shape \(6,\)"):
        jl.jacobian(model, np.zeros(6))
    with pytest.raises(jl.ConfigurationError, match=r"got shape \(\)"):
        jl.ee_pose(model, 0.0)


def test_nan_in_q_is_refused_with_its_position():
    model = jl.load_robot("puma6")
    q = np.zeros((3, 6))
    q[1, 4] = np.nan
    with pytest.raises(jl.ConfigurationError, match=r"q must be finite; got nan at index \(1, 4\)"):
        jl.link_poses(model, q)
    with pytest.raises(jl.ConfigurationError, match="dq must be finite"):
        jl.momentum(model, np.zeros(6), np.full(6, np.inf))


def test_unknown_robot_suggests_the_closest_name():
    with pytest.raises(jl.ModelError, match=r"did you mean 'halt7'\?"):
        jl.load_robot("halt8")
    with pytest.raises(jl.ModelError, match="built-in name"):
        jl.load_robot("nothing-like-it")
    with pytest.raises(jl.ModelError, match="base must be 'fixed' or 'floating'"):
        jl.load_robot("halt7", base="flying")


def test_negative_mass_and_bad_inertia_are_refused():
    with pytest.raises(jl.ModelError, match=r"mass must be a number in \[0, 1e\+09\] kg; got -1"):
        jl.Body(-1.0)
    with pytest.raises(jl.ModelError, match="positive semi-definite"):
        jl.Body(1.0, [0, 0, 0], [1.0, -1.0, 1.0])
    with pytest.raises(jl.ModelError, match="symmetric"):
        jl.Body(1.0, [0, 0, 0], [[1, 0.5, 0], [0, 1, 0], [0, 0, 1]])
    with pytest.raises(jl.ModelError, match=r"\[Ixx, Iyy, Izz\]"):
        jl.Body(1.0, [0, 0, 0], [1.0, 2.0])
    with pytest.raises(jl.ModelError, match="com must be 3 finite numbers"):
        jl.Body(1.0, [0, np.nan, 0])
    jl.Body(1.0)  # a point mass (zero inertia) is fine


def test_floating_base_needs_a_massive_spacecraft():
    model = jl.load_robot("halt7")
    with pytest.raises(jl.ModelError, match="spacecraft body with mass > 0"):
        model.with_base(jl.Body(0.0))


def test_dh_table_errors_name_the_column():
    with pytest.raises(jl.ModelError, match="DH column d must hold 2 finite numbers"):
        jl.from_dh("x", a=[0, 1], alpha=[0, 0], d=[0], convention="standard")
    with pytest.raises(jl.ModelError, match="convention must be 'standard' or 'modified'"):
        jl.from_dh("x", a=[0], alpha=[0], d=[0], convention="craig")


def test_expand_and_healthy_are_inverse():
    model = jl.lock_joints(jl.load_robot("halt7"), {4: 0.25, 1: -0.5})
    q = np.arange(10.0).reshape(2, 5)
    full = model.expand(q)
    assert full.shape == (2, 7)
    np.testing.assert_allclose(full[:, 0], -0.5)
    np.testing.assert_allclose(full[:, 3], 0.25)
    np.testing.assert_allclose(model.healthy(full), q)
    assert model.index_of(5) == 2


def test_models_are_immutable():
    model = jl.load_robot("puma6")
    with pytest.raises(AttributeError):
        model.name = "other"  # type: ignore[misc]
    with pytest.raises(ValueError):
        model.tool[0, 3] = 1.0
    with pytest.raises(ValueError):
        model.bodies[0].inertia[0, 0] = 1.0


def test_every_public_name_resolves():
    for name in jl.__all__ + sorted(jl._LAZY):
        assert getattr(jl, name) is not None, name
    with pytest.raises(AttributeError):
        jl.no_such_function  # noqa: B018


def test_a_model_prints_in_one_short_line():
    """Issue 16, item 3: a model's repr is one line, not its nested arrays."""
    for name in ("halt7", "canadarm7", "puma6"):
        for model in (jl.load_robot(name), jl.lock_joints(jl.load_robot(name, base="floating"), {2: 0.3, 4: 0.0})):
            text = repr(model)
            assert "\n" not in text and len(text) < 200 and text.startswith(f"ArmModel({name!r}")
    assert "locked {2: 17.1887 deg, 4: 0 deg}" in repr(jl.lock_joints(jl.load_robot("halt7"), {2: 0.3, 4: 0.0}))


def _three_link(**kwargs):
    return jl.from_dh(
        "three", a=[0.0, 0.5, 0.4], alpha=[np.pi / 2, 0.0, 0.0], d=[0.3, 0.0, 0.1], convention="standard",
        bodies=[jl.Body(2.0, [0.0, 0.1, 0.0], [0.1, 0.2, 0.3])] * 3, **kwargs,
    )  # fmt: skip


@pytest.mark.parametrize("convention", ["standard", "modified"])
def test_from_dh_mounts_the_table_on_a_base_pose(convention):
    """Issue 15, item 1: ``base`` = DH frame 0 in the root frame: every pose moves by it, the
    Jacobian turns with it, the mass matrix does not change."""
    from jointlock.spatial import pose, rpy_matrix

    mount = pose(rpy_matrix([0.3, -0.2, 1.1]), [0.1, -0.4, 0.7])
    plain = jl.from_dh("a", a=[0.0, 0.5, 0.4], alpha=[np.pi / 2, 0.0, 0.0], d=[0.3, 0.0, 0.1], convention=convention)
    moved = jl.from_dh(
        "a", a=[0.0, 0.5, 0.4], alpha=[np.pi / 2, 0.0, 0.0], d=[0.3, 0.0, 0.1], convention=convention, base=mount
    )
    q = np.random.default_rng(2).uniform(-2, 2, (6, 3))
    np.testing.assert_allclose(jl.ee_pose(moved, q), mount @ jl.ee_pose(plain, q), atol=1e-12)
    rot = np.kron(np.eye(2), mount[:3, :3])
    np.testing.assert_allclose(jl.jacobian(moved, q), rot @ jl.jacobian(plain, q), atol=1e-12)


def test_a_flipped_joint_turns_the_other_way():
    """``flip``: the joint turns about -z, i.e. the table with ``theta - q``."""
    plain, flipped = _three_link(), _three_link(flip=[False, True, False])
    q = np.random.default_rng(4).uniform(-2, 2, (6, 3))
    mirrored = q * [1.0, -1.0, 1.0]
    np.testing.assert_allclose(jl.ee_pose(flipped, q), jl.ee_pose(plain, mirrored), atol=1e-12)
    np.testing.assert_allclose(jl.jacobian(flipped, q), jl.jacobian(plain, mirrored) * [1.0, -1.0, 1.0], atol=1e-12)
    sign = np.diag([1.0, -1.0, 1.0])
    np.testing.assert_allclose(jl.mass_matrix(flipped, q), sign @ jl.mass_matrix(plain, mirrored) @ sign, atol=1e-12)
    with pytest.raises(jl.ModelError, match="flip must hold 3 booleans"):
        _three_link(flip=[1, 0, 0])
    with pytest.raises(jl.ModelError, match=r"base must be a \(4, 4\) pose"):
        _three_link(base=np.eye(3))


def test_a_model_file_mounts_and_flips(tmp_path):
    from jointlock.spatial import pose, rpy_matrix

    path = tmp_path / "m.toml"
    path.write_text(
        'name = "m"\nconvention = "dh_standard"\n[[joint]]\nalpha_deg = 90.0\nd_m = 0.3\n'
        "[[joint]]\na_m = 0.5\nflip = true\n[mount]\nxyz_m = [0.0, 0.0, 0.5]\nrpy_deg = [0.0, 0.0, 90.0]\n"
    )
    model = jl.read_model_toml(path)
    plain = jl.from_dh("p", a=[0.0, 0.5], alpha=[np.pi / 2, 0.0], d=[0.3, 0.0], convention="standard")
    mount = pose(rpy_matrix(np.radians([0.0, 0.0, 90.0])), [0.0, 0.0, 0.5])
    q = np.array([0.4, 0.7])
    np.testing.assert_allclose(jl.ee_pose(model, q), mount @ jl.ee_pose(plain, q * [1, -1]), atol=1e-12)
    path.write_text('convention = "dh_standard"\n[[joint]]\nd_m = 0.3\nflip = "yes"\n')
    with pytest.raises(jl.ModelError, match="field 'flip' must be true or false"):
        jl.read_model_toml(path)


@pytest.mark.parametrize("convention", ["standard", "modified"])
@pytest.mark.parametrize("row", [0, 2, 3])
@pytest.mark.parametrize("floating", [False, True])
def test_a_prismatic_row_is_held_at_its_d_like_a_joint_locked_at_zero(convention, row, floating):
    """``prismatic``: a row whose joint slides is held at the table's d (issue 15, item 1: the
    chain model turns joints; a prismatic one is frozen and its link merged).  Oracle: the same
    table with that row revolute, locked at 0 (kinematics, mass matrix, momentum, total mass)."""
    from jointlock.model import Body

    rng = np.random.default_rng(row)
    bodies = [Body(1.0 + i, rng.uniform(-0.1, 0.1, 3), np.diag(rng.uniform(0.05, 0.3, 3))) for i in range(4)]
    table = dict(a=[0.1, 0.4, 0.3, 0.05], alpha=[np.pi / 2, 0.0, -np.pi / 2, np.pi / 2], d=[0.3, 0.05, 0.2, 0.1],
                 theta=[0.0, 0.2, -0.3, 0.4], convention=convention, bodies=bodies,
                 tool=jl.spatial.translation([0.0, 0.0, 0.12]),
                 spacecraft=Body(500.0, [0.0, 0.0, -0.5], np.diag([80.0, 90.0, 70.0])) if floating else None)  # fmt: skip
    slides = [i == row for i in range(4)]
    held = jl.from_dh("held", prismatic=slides, **table)
    locked = jl.lock(jl.from_dh("held", **table), row + 1, 0.0)
    assert held.dof == 3 and held.joint_numbers == (1, 2, 3)
    assert [j.name for j in held.joints] == [f"joint{i + 1}" for i in range(4) if i != row]
    q = rng.uniform(-2, 2, (5, 3))
    np.testing.assert_allclose(jl.ee_pose(held, q), jl.ee_pose(locked, q), atol=1e-12)
    np.testing.assert_allclose(jl.jacobian(held, q), jl.jacobian(locked, q), atol=1e-12)
    np.testing.assert_allclose(jl.mass_matrix(held, q), jl.mass_matrix(locked, q), atol=1e-11)
    assert held.total_mass == pytest.approx(locked.total_mass)
    if floating:
        np.testing.assert_allclose(jl.momentum_matrix(held, q), jl.momentum_matrix(locked, q), atol=1e-11)
    with pytest.raises(jl.ModelError, match="prismatic must hold 4 booleans"):
        jl.from_dh("x", prismatic=[1, 0, 0, 0], **table)
    with pytest.raises(jl.ModelError, match="at least one DH row must be a revolute joint"):
        jl.from_dh("x", prismatic=[True] * 4, **table)


def test_a_model_file_holds_a_prismatic_row(tmp_path):
    path = tmp_path / "m.toml"
    path.write_text(
        'name = "m"\nconvention = "dh_standard"\n[[joint]]\nalpha_deg = 90.0\nd_m = 0.3\n'
        "[[joint]]\nd_m = 0.25\nprismatic = true\n[[joint]]\na_m = 0.5\n"
    )
    model = jl.read_model_toml(path)
    plain = jl.from_dh("p", a=[0.0, 0.0, 0.5], alpha=[np.pi / 2, 0.0, 0.0], d=[0.3, 0.25, 0.0], convention="standard")
    q = np.array([0.4, 0.7])
    np.testing.assert_allclose(jl.ee_pose(model, q), jl.ee_pose(plain, [0.4, 0.0, 0.7]), atol=1e-12)
    path.write_text('convention = "dh_standard"\n[[joint]]\nd_m = 0.3\nprismatic = 1\n')
    with pytest.raises(jl.ModelError, match="field 'prismatic' must be true or false"):
        jl.read_model_toml(path)
