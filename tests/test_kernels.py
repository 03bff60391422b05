"""The compiled kernels (jointlock._kernels) against their numpy references: LAPACK's SVD,
the chain-state Jacobian and the row-wise end-effector positions, on every built-in arm,
locked and unlocked, fixed and floating, at random and at (near-)singular configurations."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import minimize_scalar

import jointlock as jl
from jointlock import _kernels, forward
from jointlock._chain import ee_position_rows, kernel_mass_program, kernel_program, position_program
from jointlock.analysis.ability import configuration_indices, kinematic_indices, singular_values
from jointlock.kinematics import chain_state, ee_positions, generalized_jacobian, jacobian

ARMS = ("halt7", "canadarm7", "puma6")
#: sigma_i within this times sigma_max of LAPACK's
SV_TOL = 1e-12


def _models(name: str, base: str = "fixed") -> list[jl.ArmModel]:
    """The arm unlocked and with each joint locked in turn (at a non-special angle)."""
    arm = jl.load_robot(name, base=base)
    return [arm] + [jl.lock(arm, j, 0.4) for j in range(1, arm.dof + 1)]


def _lapack(jac: np.ndarray) -> np.ndarray:
    return np.linalg.svd(jac, compute_uv=False)


def _assert_sv(sv: np.ndarray, ref: np.ndarray) -> None:
    scale = ref[..., :1]
    assert sv.shape == ref.shape
    assert np.all(np.abs(sv - ref) <= SV_TOL * scale + 1e-300)


def _near_singular(model: jl.ArmModel, q0: np.ndarray, joint: int) -> np.ndarray:
    """``q0`` with ``joint`` moved to where the smallest singular value is least (LAPACK)."""

    def smin(x: float) -> float:
        q = q0.copy()
        q[joint] = x
        return float(_lapack(jacobian(model, q, state=chain_state(model, q)))[-1])

    res = minimize_scalar(smin, bounds=(-np.pi, np.pi), method="bounded", options={"xatol": 1e-12})
    q = q0.copy()
    q[joint] = res.x
    return q


def _singular_set(model: jl.ArmModel, name: str) -> np.ndarray:
    """Configurations at known singularities and 1e-8 off them, plus random ones."""
    rng = np.random.default_rng(7)
    n = model.dof
    qs = [np.zeros(n)]
    if name == "puma6" and n == 6:
        wrist = rng.uniform(-np.pi, np.pi, n)
        wrist[4] = 0.0  # q5 = 0: axes 4 and 6 aligned
        qs += [wrist, _near_singular(model, np.array([0.3, 0.4, 0.0, 0.5, 0.6, 0.7]), 2)]  # elbow
    else:
        qs.append(_near_singular(model, rng.uniform(-np.pi, np.pi, n), min(2, n - 1)))
    base = np.array(qs)
    off = base + 1e-8 * rng.standard_normal(base.shape)
    return np.vstack([base, off, rng.uniform(-np.pi, np.pi, (200, n))])


def test_sincos_within_an_ulp() -> None:
    rng = np.random.default_rng(0)
    special = np.pi / 2 * np.arange(-8, 9)
    x = np.concatenate([rng.uniform(-50, 50, 5000), special, special + 1e-8, [0.0, -0.0, 1e-300, 3e4, -7e4]])
    s, c = np.empty_like(x), np.empty_like(x)
    _kernels.sincos(x, s, c)
    for got, ref in ((s, np.sin(x)), (c, np.cos(x))):
        assert np.all(np.abs(got - ref) <= 2 * np.spacing(np.abs(ref)) + 1e-300)
    big = np.array([1e6, -3e7, 1e300])  # beyond TRIG_LIMIT: libm's
    s, c = np.empty_like(big), np.empty_like(big)
    _kernels.sincos(big, s, c)
    for got, ref in ((s, np.sin(big)), (c, np.cos(big))):  # within 1 ulp: numpy may use its own SIMD sin
        assert np.all(np.abs(got - ref) <= np.spacing(np.abs(ref)))


@pytest.mark.parametrize("name", ARMS)
def test_ee_positions_and_jacobian_match_numpy(name: str, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(forward, "COMPILED_MIN_POSITIONS", 1)  # the kernel, whatever the batch
    for base in ("fixed", "floating"):
        for model in _models(name, base):
            q = _singular_set(model, name)[:60] if base == "fixed" else np.random.default_rng(1).uniform(
                -np.pi, np.pi, (60, model.dof)
            )
            state = chain_state(model, q)
            pos = ee_positions(model, q, chunk=17)  # several kernel calls and a short tail block
            np.testing.assert_allclose(pos, state.ee_position, rtol=0, atol=1e-12)
            rows = ee_position_rows(position_program(model), q)
            ref = np.column_stack([np.zeros(len(q)) + (0.0 if r is None else r) for r in rows])
            np.testing.assert_allclose(pos, ref, rtol=0, atol=1e-12)
            jac = np.empty((len(q), 6, model.dof))
            _kernels.jacobian(np.ascontiguousarray(q), *kernel_program(model)[:3], jac)
            np.testing.assert_allclose(jac, jacobian(model, q, state=state), rtol=0, atol=1e-12)


@pytest.mark.parametrize("name", ARMS)
def test_singular_values_match_lapack_near_singularities(name: str) -> None:
    for model in _models(name):
        q = _singular_set(model, name)
        jac = jacobian(model, q, state=chain_state(model, q))  # the numpy reference Jacobian
        ref = _lapack(jac)
        _assert_sv(singular_values(jac, method="jacobi"), ref)
        ind = configuration_indices(model, q, jacobian="fixed", batch_size=97, method="jacobi")  # fused
        np.testing.assert_allclose(ind.sigma_min, ref[:, -1], rtol=0, atol=SV_TOL * ref[:, 0].max())
        # |dw| <= sum_i |d sigma_i| prod_{j != i} sigma_j
        bound = ref.shape[1] * SV_TOL * ref[:, 0] * np.prod(ref[:, :-1], axis=1)
        assert np.all(np.abs(ind.manipulability - np.prod(ref, axis=1)) <= bound)


def test_characteristic_length_matches_scaled_rows() -> None:
    model = jl.lock(jl.load_robot("halt7"), 4, 0.0)
    q = np.random.default_rng(3).uniform(-np.pi, np.pi, (300, model.dof))
    fused = configuration_indices(model, q, jacobian="fixed", characteristic_length=2.5, method="jacobi")
    ref = _lapack(jacobian(model, q, state=chain_state(model, q)) * np.array([[1 / 2.5] * 3 + [1.0] * 3]).T)
    np.testing.assert_allclose(fused.sigma_min, ref[:, -1], rtol=0, atol=SV_TOL * ref[:, 0].max())


@pytest.mark.parametrize("name", ARMS)
def test_generalized_indices_match_lapack(name: str) -> None:
    for model in _models(name, "floating"):
        q = np.ascontiguousarray(_singular_set(model, name)[:80])
        ref = _lapack(generalized_jacobian(model, q))
        _assert_sv(singular_values(generalized_jacobian(model, q), method="jacobi"), ref)
        jac = np.empty((len(q), 6, model.dof))
        _kernels.generalized_jacobian(q, *kernel_program(model)[:3], *kernel_mass_program(model), jac)
        np.testing.assert_allclose(jac, generalized_jacobian(model, q), rtol=0, atol=1e-12)
        ind = configuration_indices(model, q, jacobian="generalized", method="jacobi")  # fused
        lapack = kinematic_indices(generalized_jacobian(model, q), method="gram")  # independent route
        np.testing.assert_allclose(ind.sigma_min, ref[:, -1], rtol=0, atol=SV_TOL * ref[:, 0].max())
        np.testing.assert_allclose(ind.condition_number[ref[:, -1] > 1e-3], lapack.condition_number[ref[:, -1] > 1e-3], rtol=1e-7)


@pytest.mark.parametrize("shape", [(6, 7), (7, 6), (3, 5), (8, 8), (1, 4), (4, 1), (6, 6)])
def test_singular_values_any_shape_and_rank(shape: tuple[int, int]) -> None:
    rng = np.random.default_rng(sum(shape))
    m, k = shape
    mats = rng.standard_normal((300, m, k))
    r = min(m, k)
    # graded and rank-deficient matrices: U diag(s) V^T with s spanning 1 .. 1e-14 and exact zeros
    u = np.linalg.qr(rng.standard_normal((300, m, m)))[0][:, :, :r]
    v = np.linalg.qr(rng.standard_normal((300, k, k)))[0][:, :, :r]
    s = np.logspace(0, -14, r)[None] * rng.uniform(0.5, 2, (300, 1))
    s[::3, -1] = 0.0
    mats[150:] = ((u * s[:, None, :]) @ np.swapaxes(v, 1, 2))[150:]
    _assert_sv(singular_values(mats, method="jacobi"), _lapack(mats))
    assert singular_values(mats[:0], method="jacobi").shape == (0, r)
    _assert_sv(singular_values(mats[0], method="jacobi"), _lapack(mats[0]))


def test_out_of_range_matrices_go_to_lapack() -> None:
    mats = np.random.default_rng(5).standard_normal((4, 6, 6))
    for scale in (1e200, 1e-200):
        np.testing.assert_array_equal(singular_values(mats * scale, method="jacobi"), _lapack(mats * scale))


def test_large_batches_take_the_kernels_by_default(monkeypatch: pytest.MonkeyPatch) -> None:
    model = jl.lock(jl.load_robot("halt7"), 4, 0.0)
    q = np.random.default_rng(4).uniform(-np.pi, np.pi, (50, model.dof))
    calls: list[str] = []
    for name in ("fixed_singular_values", "ee_positions"):
        kernel = getattr(_kernels, name)
        monkeypatch.setattr(_kernels, name, lambda *a, k=kernel, n=name: (calls.append(n), k(*a))[1])
    small = configuration_indices(model, q, jacobian="fixed"), ee_positions(model, q)  # numpy + LAPACK
    assert calls == []
    monkeypatch.setattr(forward, "COMPILED_MIN_BATCH", 10)
    monkeypatch.setattr(forward, "COMPILED_MIN_POSITIONS", 10)
    large = configuration_indices(model, q, jacobian="fixed"), ee_positions(model, q)  # kernels
    assert calls == ["fixed_singular_values", "ee_positions"]
    ee_positions(model, q, compiled=False)
    assert len(calls) == 2
    ee_positions(model, q[:3], compiled=True)
    assert calls[-1] == "ee_positions"
    np.testing.assert_allclose(large[0].sigma_min, small[0].sigma_min, rtol=0, atol=SV_TOL)  # sigma_max ~ 1
    np.testing.assert_allclose(large[1], small[1], rtol=0, atol=1e-12)


@pytest.mark.parametrize("base", ["fixed", "floating"])
def test_public_jacobians_take_the_kernels(base: str, monkeypatch: pytest.MonkeyPatch) -> None:
    """jl.jacobian / jl.generalized_jacobian: the kernels (chunked, no chain state held) on
    request or from COMPILED_MIN_BATCH configurations, equal to the numpy path to round-off."""
    from jointlock import kinematics

    model = jl.lock(jl.load_robot("canadarm7", base=base), 3, 0.4)
    q = np.random.default_rng(9).uniform(-np.pi, np.pi, (3, 50, model.dof))
    calls: list[str] = []
    for name in ("jacobian", "generalized_jacobian"):
        kernel = getattr(_kernels, name)
        monkeypatch.setattr(_kernels, name, lambda *a, k=kernel, n=name: (calls.append(n), k(*a))[1])
    for fn in (jacobian, generalized_jacobian):
        ref = fn(model, q)  # 150 configurations: numpy
        assert calls == []
        ours = fn(model, q, compiled=True)
        kernel = "generalized_jacobian" if fn is generalized_jacobian and base == "floating" else "jacobian"
        assert calls == [kernel]
        assert ours.shape == ref.shape == (3, 50, 6, model.dof)
        np.testing.assert_allclose(ours, ref, rtol=0, atol=1e-12 * np.max(np.abs(ref)))
        calls.clear()
    monkeypatch.setattr(forward, "COMPILED_MIN_BATCH", 100)
    monkeypatch.setattr(kinematics, "DEFAULT_CHUNK", 64)  # three chunks
    np.testing.assert_allclose(jacobian(model, q), jacobian(model, q, compiled=False), rtol=0, atol=3e-11)
    ref = generalized_jacobian(model, q, compiled=False)
    np.testing.assert_allclose(generalized_jacobian(model, q), ref, rtol=0, atol=1e-12 * np.max(np.abs(ref)))
    assert calls == ["jacobian"] * 3 + ["generalized_jacobian" if base == "floating" else "jacobian"] * 3
    ref_ee = jacobian(model, q, frame="ee", compiled=False)
    np.testing.assert_allclose(jacobian(model, q, frame="ee"), ref_ee, rtol=0, atol=3e-11)  # kernel, turned
    assert len(calls) == 9
    jacobian(model, q[0, :3])  # three configurations: numpy
    jacobian(model, q, state=kinematics.chain_state(model, q))  # a state holds the frames: numpy
    assert len(calls) == 9
    with pytest.raises(jl.ConfigurationError, match="give q, and no state"):
        jacobian(model, q, state=kinematics.chain_state(model, q), compiled=True)
    with pytest.raises(jl.ConfigurationError, match="frame must be 'base' or 'ee'"):
        jacobian(model, q, frame="tool", compiled=True)
    with pytest.raises(jl.ConfigurationError, match="compiled must be True, False or None"):
        generalized_jacobian(model, q, compiled=1)
    with pytest.raises(jl.ConfigurationError, match="give q, and no state"):
        jacobian(model, None, compiled=True)
    with pytest.raises(jl.ConfigurationError, match="ragged"):
        jacobian(model, [[0.0] * model.dof, [0.0] * (model.dof - 1)])


def test_kernels_compile_once_for_any_input_layout() -> None:
    """Read-only, broadcast, Fortran-ordered and integer inputs reach the kernels as the same
    type (C-contiguous, writable float64): numba compiles one specialisation, not one each."""
    from jointlock.dynamics import rnea

    model = jl.load_robot("halt7")
    q = np.random.default_rng(2).uniform(-1, 1, (20, 7))
    frozen = q.copy()
    frozen.setflags(write=False)
    for x in (q, frozen, np.asfortranarray(q), np.broadcast_to(q[0], (20, 7)), np.ones((20, 7), dtype=int)):
        jacobian(model, x, compiled=True)
        ee_positions(model, x, compiled=True)
        configuration_indices(model, x, jacobian="fixed", method="jacobi")
        rnea(model, x, x, x, compiled=True)
        rnea(model, x, x, x, compiled=True, moment_point=np.arange(6.0)[::2])
    kernels = (_kernels.jacobian, _kernels.ee_positions, _kernels.fixed_singular_values, _kernels.rnea_fixed)
    for kernel in kernels:
        assert len(kernel.signatures) == 1, kernel.signatures
