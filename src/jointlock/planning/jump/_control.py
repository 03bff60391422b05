"""The resolved-rate law with global compensation (NOTES-001, "The control law")."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from ...model import FloatArray

# -- the control law ------------------------------------------------------------------------


def compensated_rates(
    jac: ArrayLike,
    djac: ArrayLike,
    xdot: ArrayLike,
    kappa: ArrayLike,
    healthy: ArrayLike | None = None,
) -> tuple[FloatArray, FloatArray]:
    """Resolved rate with global compensation (NOTES-001, "The control law"), batched.

    ``qdot = J_h^+ xdot + kappa (I - J_h^+ J_h) grad w_h`` where ``J_h`` is the position
    Jacobian with the locked columns removed (``healthy`` mask) and ``w_h`` its
    manipulability; locked entries of ``qdot`` are exactly 0 (NOTES-001 property 3).

    Parameters
    ----------
    jac
        (..., 3, n) position Jacobian [m/rad].
    djac
        (..., n, 3, n) its derivatives, ``djac[..., i, :, k] = dJ[:, k]/dq_i``.
    xdot
        (..., 3) commanded end-effector velocity [m/s].
    kappa
        (...) compensation coefficient [rad^2/(s m^3)] (``w`` in m^3 for the position block).
    healthy
        (..., n) boolean mask of joints that can move; ``None`` = all.

    Returns
    -------
    qdot
        (..., n) joint rates [rad/s].
    w
        (...) manipulability of the healthy columns [m^3].
    """
    jac_h: FloatArray = np.asarray(jac, dtype=float)
    djac_h: FloatArray = np.asarray(djac, dtype=float)
    if healthy is not None:
        mask = np.asarray(healthy, dtype=bool)
        jac_h = jac_h * mask[..., None, :]
        djac_h = djac_h * mask[..., None, None, :]
    gram = jac_h @ np.swapaxes(jac_h, -1, -2)
    det = np.linalg.det(gram)
    w = np.sqrt(np.maximum(det, 0.0))
    try:
        m = np.linalg.solve(gram, jac_h)  # (J J^T)^-1 J, rows of J^+ transposed
    except np.linalg.LinAlgError:
        m = np.swapaxes(np.linalg.pinv(np.swapaxes(jac_h, -1, -2)), -1, -2)
    # grad w = w tr((J J^T)^-1 J dJ_i^T), the formula of derivatives.manipulability_and_gradient,
    # written again here on purpose: it reuses the solve above (needed for J^+ anyway), while
    # derivatives uses an SVD.  Both agree to ~1e-13 relative away from singularities
    # (tests/test_jump_gradient.py) but not bit for bit, and every recorded jump output used this one.
    grad = w[..., None] * np.einsum("...rc,...irc->...i", m, djac_h)
    if healthy is not None:
        grad = grad * mask
    pinv = np.swapaxes(m, -1, -2)  # (..., n, 3)
    null = grad - np.einsum("...ir,...r->...i", pinv, np.einsum("...rc,...c->...r", jac_h, grad))
    qdot = np.einsum("...ir,...r->...i", pinv, np.asarray(xdot, dtype=float))
    qdot = qdot + np.asarray(kappa, dtype=float)[..., None] * null
    return qdot, w
