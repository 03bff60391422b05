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
