"""Kinematic-ability indices, standardisation, AHP and entropy weights, CP (seed 000 §3.1)."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
from conftest import EXACT_ATOL, random_q

import jointlock as jl
from jointlock.analysis.ability import (
    CR_LIMIT,
    PAPER_JUDGMENT,
    PAPER_RI,
    KinematicIndices,
    Normalization,
    ahp_weights,
    combine_weights,
    combined_index,
    configuration_indices,
    entropy_weights,
    fit_ability_model,
    kinematic_indices,
    standardize,
)
from jointlock.errors import ConfigurationError, ScenarioError
from jointlock.papers import p000

#: Agreement of the Gram-eigenvalue path with the SVD for well-conditioned random matrices
#: (error ~ eps * sigma_max^2 / sigma_min with sigma ~ 1).
GRAM_RTOL = 1e-9


# -- AHP ----------------------------------------------------------------------------------------


@pytest.mark.paper
def test_paper_judgment_matrix_eq39():
    # 000 §5.1: lambda = 3, eigenvector (1/4, 1/2, 1/4), CR = 0 < 0.10.
    np.testing.assert_array_equal(PAPER_JUDGMENT, p000.JUDGMENT)  # eq. (39)
    assert dict(PAPER_RI) == dict(p000.RANDOM_INDEX) and CR_LIMIT == p000.CR_LIMIT  # Table 5, §3.1.3
    res = ahp_weights(PAPER_JUDGMENT)
    np.testing.assert_allclose(res.weights, p000.AHP_WEIGHTS, atol=1e-12)
    assert res.lambda_max == pytest.approx(3.0, abs=1e-12)
    assert res.ci == pytest.approx(0.0, abs=1e-12)
    assert res.cr == pytest.approx(0.0, abs=1e-12)
    assert res.ri == p000.RANDOM_INDEX[3]  # 000 Table 5


def test_consistent_matrix_recovers_its_weights():
    w = np.array([0.1, 0.2, 0.3, 0.4])
    res = ahp_weights(np.outer(w, 1 / w))
    np.testing.assert_allclose(res.weights, w, atol=1e-12)
    assert res.lambda_max == pytest.approx(4.0, abs=1e-10)
    assert res.cr == pytest.approx(0.0, abs=1e-10)


def test_inconsistent_matrix_is_refused_with_the_matrix_shown():
    bad = [[1, 9, 1 / 9], [1 / 9, 1, 9], [9, 1 / 9, 1]]  # a > b > c > a
    with pytest.raises(ScenarioError, match=r"CR = .* >= 0.1.*\[1 9 0.1111"):
        ahp_weights(bad)


def test_mildly_inconsistent_matrix_ri_tables():
    m = np.array([[1, 2, 4], [1 / 2, 1, 3], [1 / 4, 1 / 3, 1]])
    paper = ahp_weights(m)
    saaty = ahp_weights(m, ri="saaty")
    assert paper.lambda_max > 3
    assert paper.ci == pytest.approx((paper.lambda_max - 3) / 2)
    assert paper.cr == pytest.approx(paper.ci / p000.RANDOM_INDEX[3])
    assert saaty.cr == pytest.approx(paper.ci / 0.58)
    np.testing.assert_allclose(paper.weights.sum(), 1.0)
    assert ahp_weights(m, ri={3: 1.0}).cr == pytest.approx(paper.ci)


@pytest.mark.parametrize(
    "matrix, message",
    [
        ([[1, 2], [2, 1]], "reciprocal"),
        ([[1, -1], [-1, 1]], "> 0"),
        ([[1, 2, 3]], "square"),
        (np.ones((7, 7)), r"N = 7.*\[1, 2, 3, 4, 5, 6\]"),
    ],
)
def test_ahp_input_errors(matrix, message):
    with pytest.raises(ScenarioError, match=message):
        ahp_weights(matrix)


def test_saaty_table_covers_order_seven():
    assert ahp_weights(np.ones((7, 7)), ri="saaty").cr == pytest.approx(0.0, abs=1e-12)


# -- entropy ------------------------------------------------------------------------------------


def test_entropy_hand_computed():
    # column 0 constant: P = (1/2, 1/2), e = 1; column 1: P = (1/4, 3/4),
    # e = -(1/4 ln 1/4 + 3/4 ln 3/4) / ln 2; column 2: P = (0, 1), e = 0.
    res = entropy_weights([[1.0, 1.0, 0.0], [1.0, 3.0, 2.0]])
    e1 = -(0.25 * math.log(0.25) + 0.75 * math.log(0.75)) / math.log(2)
    np.testing.assert_allclose(res.entropy, [1.0, e1, 0.0], atol=1e-15)
    g = np.array([0.0, 1 - e1, 1.0])
    np.testing.assert_allclose(res.divergence, g, atol=1e-15)
    np.testing.assert_allclose(res.weights, g / g.sum(), atol=1e-15)
    assert res.samples == 2


def test_entropy_scale_invariant_and_uniform_when_uninformative():
    rng = np.random.default_rng(0)
    x = rng.random((50, 3))
    np.testing.assert_allclose(entropy_weights(x * [1, 10, 1e3]).weights, entropy_weights(x).weights)
    np.testing.assert_allclose(entropy_weights(np.ones((4, 3))).weights, [1 / 3] * 3)


def test_entropy_errors():
    with pytest.raises(ConfigurationError, match="K >= 2"):
        entropy_weights([[1.0, 2.0]])
    with pytest.raises(ConfigurationError, match=">= 0"):
        entropy_weights([[1.0, -2.0], [1.0, 1.0]])


# -- indices ------------------------------------------------------------------------------------


@pytest.mark.parametrize("shape", [(6, 6), (6, 5), (3, 6)])
def test_indices_match_numpy_svd_loop(shape):
    rng = np.random.default_rng(1)
    jac = rng.normal(size=(4, 5) + shape)
    ind = kinematic_indices(jac)
    for idx in np.ndindex(4, 5):
        sv = np.linalg.svd(jac[idx], compute_uv=False)
        assert ind.sigma_min[idx] == pytest.approx(sv[-1], rel=1e-12)
        assert ind.condition_number[idx] == pytest.approx(sv[0] / sv[-1], rel=1e-12)
        assert ind.manipulability[idx] == pytest.approx(np.prod(sv), rel=1e-12)
        assert ind.inverse_condition[idx] == pytest.approx(sv[-1] / sv[0], rel=1e-12)
    gram = kinematic_indices(jac, method="gram")
    np.testing.assert_allclose(gram.sigma_min, ind.sigma_min, rtol=GRAM_RTOL)
    np.testing.assert_allclose(gram.manipulability, ind.manipulability, rtol=GRAM_RTOL)


def test_manipulability_is_sqrt_det_for_square_and_wide():
    rng = np.random.default_rng(2)
    jac = rng.normal(size=(10, 6, 7))
    np.testing.assert_allclose(
        kinematic_indices(jac).manipulability, np.sqrt(np.linalg.det(jac @ jac.swapaxes(-1, -2))), rtol=1e-10
    )


def test_characteristic_length_scales_linear_rows():
    rng = np.random.default_rng(3)
    jac = rng.normal(size=(8, 6, 6))
    length = 2.5
    scaled = np.diag([1 / length] * 3 + [1.0] * 3) @ jac
    np.testing.assert_allclose(
        kinematic_indices(jac, characteristic_length=length).sigma_min,
        np.linalg.svd(scaled, compute_uv=False)[..., -1],
        rtol=1e-12,
    )
    with pytest.raises(ConfigurationError, match="characteristic_length"):
        kinematic_indices(jac, characteristic_length=0.0)


def test_singular_jacobian_gives_inf_condition_without_warnings():
    jac = np.zeros((2, 6, 6))
    jac[0] = np.eye(6)
    jac[1, 0, 0] = 1.0
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        ind = kinematic_indices(jac)
    assert ind.condition_number[0] == 1.0 and np.isinf(ind.condition_number[1])
    assert ind.inverse_condition[1] == 0.0 and ind.manipulability[1] == 0.0


# -- standardisation, weights, CP ---------------------------------------------------------------


def _indices(s, kappa, w):
    s, kappa, w = (np.asarray(v, dtype=float) for v in (s, kappa, w))
    return KinematicIndices(s, kappa, w, 1 / kappa)


def test_standardize_minmax_and_inverse_condition():
    ind = _indices([0.1, 0.3, 0.2], [2.0, 4.0, 5.0], [1.0, 3.0, 5.0])
    std = standardize(ind)
    np.testing.assert_allclose(std.s_hat, [0.0, 1.0, 0.5])
    np.testing.assert_allclose(std.w_hat, [0.0, 0.5, 1.0])
    np.testing.assert_allclose(std.kappa_hat, [0.5, 0.25, 0.2])
    frozen = standardize(_indices([0.5], [1.0], [7.0]), Normalization.from_samples(ind))
    assert frozen.s_hat[0] == pytest.approx(2.0) and frozen.w_hat[0] == pytest.approx(1.5)


def test_combine_weights_readings():
    ahp = [0.25, 0.5, 0.25]  # eq. (39) vector
    ent = np.array([0.2, 0.3, 0.5])  # canonical order (s, kappa, w)
    np.testing.assert_allclose(combine_weights(ahp, ent, assignment="equation"), [0.45, 0.8, 0.75])
    np.testing.assert_allclose(combine_weights(ahp, ent, assignment="text"), [0.45, 0.55, 1.0])
    np.testing.assert_allclose(
        combine_weights(ahp, ent, assignment="text", renormalize=True), [0.225, 0.275, 0.5]
    )
    with pytest.raises(ScenarioError, match="assignment"):
        combine_weights(ahp, ent, assignment="eq")  # type: ignore[arg-type]


def test_cp_eq19_by_hand():
    ind = _indices([0.1, 0.3, 0.2], [2.0, 4.0, 5.0], [1.0, 3.0, 5.0])
    model = fit_ability_model(ind)
    std = standardize(ind)
    w = model.weights
    expected = w[0] * std.s_hat + w[1] * std.kappa_hat + w[2] * std.w_hat
    np.testing.assert_allclose(model(ind), expected)
    np.testing.assert_allclose(combined_index(std, w), expected)
    ent = entropy_weights(std.stacked()).weights
    np.testing.assert_allclose(w, [0.25, 0.5, 0.25] + ent)  # equation reading, not renormalised
    assert set(model.weights_dict()) == {"ahp", "entropy", "combined"}


@pytest.mark.parametrize("jacobian", ["generalized", "fixed"])
def test_configuration_indices_batched_equals_looped(jacobian, rng):
    model = jl.lock(jl.load_robot("halt7", base="floating"), 4, 0.0)
    q = random_q(model, rng, (3, 4))
    batched = configuration_indices(model, q, jacobian=jacobian, batch_size=5)
    fn = jl.generalized_jacobian if jacobian == "generalized" else jl.jacobian
    for idx in np.ndindex(3, 4):
        one = kinematic_indices(fn(model, q[idx]))
        assert abs(batched.sigma_min[idx] - one.sigma_min) < EXACT_ATOL
        assert abs(batched.manipulability[idx] - one.manipulability) < EXACT_ATOL


def test_singular_values_auto_matches_svd_even_near_singularities():
    from jointlock.analysis.ability import singular_values

    model = jl.load_robot("puma6")
    rng = np.random.default_rng(5)
    q = rng.uniform(-np.pi, np.pi, (2000, model.dof))
    q[:200, 4] = 1e-5 * rng.normal(size=200)  # joint 5 near 0: wrist singularity
    jac = jl.jacobian(model, q)
    exact = np.linalg.svd(jac, compute_uv=False)
    auto = singular_values(jac, method="auto")
    np.testing.assert_allclose(auto, exact, rtol=2e-8, atol=1e-13)
    # the plain Gram route is not that accurate near the singularity (the test can fail)
    gram = singular_values(jac, method="gram")
    assert np.max(np.abs(gram[:200, -1] - exact[:200, -1]) / exact[:200, -1]) > 1e-6
