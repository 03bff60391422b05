"""The compiled Newton-Euler kernels (jointlock._kernels.rnea_fixed / rnea_floating) against
the numpy reference (jointlock.dynamics.rnea, compiled=False) on every built-in arm and the
URDF test arm, unlocked and with each joint locked, fixed base (with gravity and a moment
point) and free-floating; and the dispatch between the two."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import jointlock as jl
from jointlock import _kernels, forward
from jointlock.dynamics import base_wrench, joint_torques, rnea

ARMS = ("halt7", "canadarm7", "puma6", "arm5")
FIELDS = ("torques", "base_force", "base_moment", "base_acceleration", "base_twist")
#: Both are exact computations in a different order: round-off, relative to each output's
#: largest entry (torques of these arms reach 1e5 N m at the rates drawn below).
RTOL = 1e-12
URDF_ARM = Path(__file__).parent / "data" / "arm5.urdf"


def _models(name: str, base: str) -> list[jl.ArmModel]:
    arm = jl.read_urdf(URDF_ARM, base=base) if name == "arm5" else jl.load_robot(name, base=base)
    return [arm] + [jl.lock(arm, j, 0.4) for j in range(1, arm.dof + 1)]


def _states(model: jl.ArmModel, n: int, seed: int = 0) -> tuple[np.ndarray, ...]:
    rng = np.random.default_rng(seed)
    shape = (n, model.dof)
    # more samples than one block of the kernels (128), and not a multiple of it
    return rng.uniform(-4.0, 4.0, shape), rng.uniform(-2.0, 2.0, shape), rng.uniform(-3.0, 3.0, shape)


def _assert_same(ours: jl.InverseDynamics, ref: jl.InverseDynamics) -> None:
    for field in FIELDS:
        a, b = getattr(ours, field), getattr(ref, field)
        assert a.shape == b.shape, field
        scale = max(float(np.max(np.abs(b), initial=0.0)), 1e-300)
        err = float(np.max(np.abs(a - b), initial=0.0))
        assert err <= RTOL * scale, f"{field}: {err:.3g} off (scale {scale:.3g})"


@pytest.mark.parametrize("name", ARMS)
def test_fixed_base_kernel_matches_numpy(name: str) -> None:
    for model in _models(name, "fixed"):
        q, dq, ddq = _states(model, 300)
        kw = {"gravity": [0.3, -0.2, -9.81], "moment_point": [0.1, -0.4, 0.25]}
        _assert_same(
            rnea(model, q, dq, ddq, compiled=True, **kw), rnea(model, q, dq, ddq, compiled=False, **kw)
        )


@pytest.mark.parametrize("name", ARMS)
def test_floating_kernel_matches_numpy(name: str) -> None:
    for model in _models(name, "floating"):
        q, dq, ddq = _states(model, 300, seed=1)
        for point in (None, [0.5, 0.0, -0.3]):
            kw = {"base": "floating", "moment_point": point}
            ours, ref = (
                rnea(model, q, dq, ddq, compiled=True, **kw),
                rnea(model, q, dq, ddq, compiled=False, **kw),
            )
            _assert_same(ours, ref)
            assert np.max(np.abs(ref.base_twist)) > 0.1  # the spacecraft does move


def test_kernels_keep_batch_shapes_and_broadcast() -> None:
    model = jl.load_robot("halt7", base="floating")
    rng = np.random.default_rng(3)
    q = rng.uniform(-3, 3, (4, 1, 7))
    dq = rng.uniform(-1, 1, (1, 5, 7))
    ddq = rng.uniform(-1, 1, (7,))
    for base in ("fixed", "floating"):
        ours = rnea(model, q, dq, ddq, base=base, compiled=True)
        _assert_same(ours, rnea(model, q, dq, ddq, base=base, compiled=False))
        assert ours.torques.shape == (4, 5, 7) and ours.base_acceleration.shape == (4, 5, 6)
    single = rnea(model, q[0, 0], dq[0, 0], ddq, compiled=True)
    assert single.torques.shape == (7,) and single.base_force.shape == (3,)
    np.testing.assert_array_equal(
        joint_torques(model, q, dq, ddq, compiled=True), rnea(model, q, dq, ddq, compiled=True).torques
    )
    np.testing.assert_array_equal(
        base_wrench(model, q, dq, ddq, compiled=True), rnea(model, q, dq, ddq, compiled=True).base_wrench
    )


def test_kernels_on_one_joint_and_on_no_samples() -> None:
    arm = jl.load_robot("halt7", base="floating")
    one = jl.lock_joints(arm, {j: 0.3 for j in arm.joint_numbers[1:]})  # joint 1 alone moves
    assert one.dof == 1
    q, dq, ddq = _states(one, 130, seed=6)
    for base in ("fixed", "floating"):
        _assert_same(rnea(one, q, dq, ddq, base=base, compiled=True), rnea(one, q, dq, ddq, base=base, compiled=False))
        empty = rnea(arm, np.zeros((0, arm.dof)), np.zeros((0, arm.dof)), np.zeros((0, arm.dof)), base=base, compiled=True)
        assert empty.torques.shape == (0, arm.dof) and empty.base_twist.shape == (0, 6)


def test_kernels_over_several_chunks(monkeypatch: pytest.MonkeyPatch) -> None:
    from jointlock import dynamics

    monkeypatch.setattr(dynamics, "_COMPILED_CHUNK", 200)  # 3 chunks, the last one short
    model = jl.load_robot("canadarm7", base="floating")
    q, dq, ddq = _states(model, 555, seed=5)
    for base in ("fixed", "floating"):
        _assert_same(
            rnea(model, q, dq, ddq, base=base, compiled=True),
            rnea(model, q, dq, ddq, base=base, compiled=False),
        )


def test_dispatch_by_batch_size(monkeypatch: pytest.MonkeyPatch) -> None:
    model = jl.load_robot("puma6", base="floating")
    q, dq, ddq = _states(model, 50)
    calls: list[str] = []
    for name in ("rnea_fixed", "rnea_floating"):
        kernel = getattr(_kernels, name)
        monkeypatch.setattr(_kernels, name, lambda *a, k=kernel, n=name: (calls.append(n), k(*a))[1])
    rnea(model, q, dq, ddq)
    rnea(model, q, dq, ddq, base="floating")
    assert calls == []  # 50 samples: numpy
    monkeypatch.setattr(forward, "COMPILED_MIN_BATCH", 10)
    rnea(model, q, dq, ddq)
    rnea(model, q, dq, ddq, base="floating")
    assert calls == ["rnea_fixed", "rnea_floating"]
    rnea(model, q, dq, ddq, compiled=False)
    rnea(model, q[:2], dq[:2], ddq[:2], compiled=True)
    assert calls == ["rnea_fixed", "rnea_floating", "rnea_fixed"]
    with pytest.raises(jl.ConfigurationError, match="compiled must be True, False or None"):
        rnea(model, q, dq, ddq, compiled="yes")


def test_kernel_says_when_results_overflow() -> None:
    model = jl.load_robot("halt7", base="floating")
    q = np.zeros((3, 7))
    dq = np.full((3, 7), 1e160)  # finite, but squared beyond float64
    for base in ("fixed", "floating"):
        with pytest.raises(jl.ConfigurationError, match="overflows float64"):
            rnea(model, q, dq, q, base=base, compiled=True)


def test_kernel_refuses_a_singular_system_inertia() -> None:
    """Point masses on one line and a point-mass spacecraft: the rotational inertia about the
    system's centre of mass is singular about that line, as in the numpy path."""
    point = jl.Body(mass=1.0)
    model = jl.from_dh(
        "line",
        a=[1.0, 1.0],
        alpha=[0.0, 0.0],
        d=[0.0, 0.0],
        convention="standard",
        bodies=[point, point],
        spacecraft=point,
    )
    q = np.zeros((2, 2))  # every mass on the x axis
    for compiled in (False, True):
        with pytest.raises(jl.ModelError, match="rotational inertia about its centre of mass is singular"):
            rnea(model, q, q + 0.1, q, base="floating", compiled=compiled)


@pytest.mark.parametrize("compiled", [False, True])
def test_bad_gravity_and_moment_point_are_named(compiled: bool) -> None:
    model = jl.load_robot("halt7")
    q = np.zeros((2, 7))
    cases = (
        ({"gravity": "down"}, "gravity"),
        ({"moment_point": [1.0, "a", 2.0]}, "moment_point"),
        ({"gravity": [0.0, 0.0]}, "gravity"),
        ({"moment_point": [0.0, np.inf, 0.0]}, "moment_point"),
    )
    for kw, name in cases:
        with pytest.raises(jl.ModelError, match=f"^{name} must be 3 finite numbers"):
            rnea(model, q, q, q, compiled=compiled, **kw)
    with pytest.raises(jl.ConfigurationError, match="dq must be .* ragged"):
        rnea(model, q, [[0.0] * 7, [0.0] * 6], q, compiled=compiled)
