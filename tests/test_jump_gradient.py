"""The compensation law's manipulability gradient equals :mod:`jointlock.derivatives`' one.

``compensated_rates`` computes ``grad w`` from ``(J J^T)^-1 J`` (the adjugate of the Gram
matrix), which it needs for ``J^+`` anyway; ``manipulability_and_gradient`` uses an SVD.  Same
formula (NOTES-001; 001 eq. 25), different round-off: they agree to 1e-12 relative away from
singularities but not bit for bit.  (The integrator's kernel takes the fixed-base gradient in
closed form from the joint axes instead: tests/test_jump_batched.py.)
"""

from __future__ import annotations

import numpy as np
import pytest

import jointlock as jl
from jointlock.derivatives import jacobian_derivatives, manipulability_and_gradient
from jointlock.kinematics import jacobian
from jointlock.planning.jump import JumpScenario, compensated_rates

#: Agreement of the two gradient forms, relative to the largest entry (round-off only).
RTOL = 1e-12


@pytest.mark.parametrize("locked", [(), (2,), (2, 5)])
def test_null_space_term_uses_the_derivatives_gradient(locked):
    arm = jl.load_robot("canadarm7")
    rng = np.random.default_rng(1)
    q = np.asarray(JumpScenario().q0) + rng.uniform(-0.3, 0.3, (50, arm.dof))
    jac = jacobian(arm, q)[..., :3, :]
    djac = jacobian_derivatives(arm, q)[..., :3, :]
    healthy = np.ones(arm.dof, dtype=bool)
    for number in locked:
        healthy[arm.index_of(number)] = False
    # kappa = 1 and no task velocity: qdot is the null-space term (I - J_h^+ J_h) grad w_h
    null, w = compensated_rates(jac, djac, np.zeros(3), np.ones(len(q)), healthy)
    w_ref, grad = manipulability_and_gradient(jac, djac, rows="position", columns=healthy)
    jh = jac * healthy
    proj = np.eye(arm.dof) - np.linalg.pinv(jh) @ jh
    null_ref = np.einsum("bij,bj->bi", proj, grad) * healthy
    assert np.all(w_ref > 1.0)  # well away from singular configurations [m^3]
    np.testing.assert_allclose(w, w_ref, rtol=RTOL, atol=0)
    scale = np.abs(null_ref).max(axis=-1, keepdims=True)
    assert np.all(np.abs(null - null_ref) <= RTOL * scale)
    assert np.all(null[:, ~healthy] == 0.0)
