"""Jacobian derivatives and manipulability gradient vs central finite differences (NOTES-001)."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import FD_STEP, random_q

import jointlock as jl
from jointlock.derivatives import (
    generalized_jacobian_derivatives,
    jacobian_derivatives,
    manipulability,
    manipulability_and_gradient,
    manipulability_gradient,
)

#: FD agreement for the manipulability gradient: w ~ 1e2 m^3 on 10 m arms, rounding
#: ~ eps * w / h ~ 1e-8, truncation ~ h^2 * w''' ~ 1e-9.
GRAD_ATOL = 1e-6
#: The generalized-Jacobian derivative is itself a finite difference (error O(h^2) + round-off).
FLOAT_ATOL = 1e-5


def _fd(fun, q, h=FD_STEP):
    n = q.shape[-1]
    return np.stack([(fun(q + h * e) - fun(q - h * e)) / (2 * h) for e in np.eye(n)], axis=-1)


@pytest.mark.parametrize("name", ["canadarm7", "halt7", "puma6"])
def test_jacobian_derivative_matches_fd(name, rng):
    model = jl.load_robot(name)
    q = random_q(model, rng, (6,))
    d = jacobian_derivatives(model, q)  # (..., i, 6, k)
    fd = np.moveaxis(_fd(lambda x: jl.jacobian(model, x), q), -1, -3)
    np.testing.assert_allclose(d, fd, atol=1e-7)


@pytest.mark.parametrize("name", ["canadarm7", "halt7"])
def test_manipulability_gradient_matches_fd(name, rng):
    model = jl.load_robot(name)
    q = random_q(model, rng, (5,))
    w, g = manipulability_gradient(model, q)
    np.testing.assert_allclose(w, manipulability(jl.jacobian(model, q)), rtol=1e-12)
    fd = _fd(lambda x: manipulability(jl.jacobian(model, x)), q)
    np.testing.assert_allclose(g, fd, atol=GRAD_ATOL * max(1.0, np.abs(fd).max()))


def test_reduced_gradient_equals_locked_model(rng):
    """Masking a column == the gradient of the locked model's manipulability."""
    model = jl.load_robot("canadarm7")
    q = random_q(model, rng)
    w_r, g_r = manipulability_gradient(model, q, locked=[3])
    locked = jl.lock(model, 3, q[2], check_limits=False)
    qh = np.delete(q, 2)
    w_l, g_l = manipulability_gradient(locked, qh)
    np.testing.assert_allclose(w_r, w_l, rtol=1e-12)
    np.testing.assert_allclose(np.delete(g_r, 2), g_l, atol=1e-9)
    assert g_r[2] == 0.0


def test_full_block_and_batched_equals_loop(rng):
    model = jl.load_robot("halt7")
    q = random_q(model, rng, (3, 2))
    jac, djac = jl.jacobian(model, q), jacobian_derivatives(model, q)
    w, g = manipulability_and_gradient(jac, djac, rows="full")
    for idx in np.ndindex(3, 2):
        wi, gi = manipulability_and_gradient(jac[idx], djac[idx], rows="full")
        np.testing.assert_allclose(w[idx], wi, rtol=1e-12)
        np.testing.assert_allclose(g[idx], gi, rtol=1e-10, atol=1e-12)
    fd = _fd(lambda x: manipulability(jl.jacobian(model, x), rows="full"), q)
    np.testing.assert_allclose(g, fd, atol=GRAD_ATOL * max(1.0, np.abs(fd).max()))


def test_floating_gradient_matches_fd(rng):
    model = jl.load_robot("canadarm7", base="floating")
    q = random_q(model, rng, (2,))
    d = generalized_jacobian_derivatives(model, q)
    fd = np.moveaxis(_fd(lambda x: jl.generalized_jacobian(model, x), q, h=1e-5), -1, -3)
    np.testing.assert_allclose(d, fd, atol=FLOAT_ATOL)
    w, g = manipulability_gradient(model, q, base="floating")
    fdw = _fd(lambda x: manipulability(jl.generalized_jacobian(model, x)), q, h=1e-5)
    np.testing.assert_allclose(g, fdw, atol=FLOAT_ATOL * max(1.0, np.abs(fdw).max()))


def test_floating_needs_floating_model():
    with pytest.raises(jl.ModelError, match="free-floating"):
        manipulability_gradient(jl.load_robot("canadarm7"), np.zeros(7), base="floating")
