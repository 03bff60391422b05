"""Jacobian derivatives and the manipulability gradient (NOTES-001, "Gradient of w").

For a chain of revolute joints the derivative of the geometric Jacobian is closed form.  With
``z_i`` the joint axes and ``J_k = (J_k^v, J_k^w)`` the columns of :func:`jointlock.jacobian`
(reference point = end-effector origin, root-frame components):

* linear part:  ``dJ_k^v/dq_i = z_i x J_k^v`` for ``i <= k``, ``z_k x J_i^v`` for ``i > k``;
* angular part: ``dJ_k^w/dq_i = z_i x z_k`` for ``i < k``, ``0`` for ``i >= k``.

The manipulability of a row block (the position rows by default, as in seed 001) is
``w = sqrt(det(J_s J_s^T))`` and its gradient (NOTES-001; 001 eqs. 21-25)

    dw/dq_i = w * tr((J_s J_s^T)^-1 J_s (dJ_s/dq_i)^T).

*Locked / healthy-only variants.*  A locked model's Jacobian equals the full model's with the
locked columns removed (``docs/conventions.md``), and so do its derivatives with respect to the
healthy joints.  :func:`manipulability_and_gradient` therefore takes a ``columns`` mask: the
reduced manipulability ``w_r`` and its gradient over the healthy joints come from the full
arrays without building a reduced model (entries of locked joints are returned as 0).

*Free-floating base.*  The generalized Jacobian ``J* = J_m + J_b J_btheta`` involves the
inverse of the momentum matrix; its derivative is not written in closed form here.
:func:`generalized_jacobian_derivatives` uses central finite differences instead (truncation
error ``O(h^2)``), batched over all ``2 n`` perturbations in one call.
"""

from __future__ import annotations

from typing import Literal

import numpy as np
from numpy.typing import ArrayLike

from .errors import ConfigurationError
from .kinematics import ChainState, chain_state, generalized_jacobian, jacobian, state_at
from .model import ArmModel, FloatArray, as_joint_array

#: Rows of the 6 x n Jacobian that hold the linear velocity (seed 001's position-only task).
POSITION_ROWS = slice(0, 3)
#: Rows of the 6 x n Jacobian that hold the angular velocity.
ORIENTATION_ROWS = slice(3, 6)
#: Central finite-difference step for the generalized Jacobian derivative [rad].
GENERALIZED_FD_STEP = 1e-6

RowBlock = Literal["position", "orientation", "full"]


def _rows(rows: RowBlock | slice) -> slice:
    if isinstance(rows, slice):
        return rows
    table = {"position": POSITION_ROWS, "orientation": ORIENTATION_ROWS, "full": slice(0, 6)}
    if rows not in table:
        raise ConfigurationError(f"rows must be one of {sorted(table)} or a slice; got {rows!r}")
    return table[rows]


def cross3(a: FloatArray, b: FloatArray) -> FloatArray:
    """Broadcast cross product over the last axis (faster than ``np.cross`` for small batches)."""
    a0, a1, a2 = a[..., 0], a[..., 1], a[..., 2]
    b0, b1, b2 = b[..., 0], b[..., 1], b[..., 2]
    return np.stack([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0], axis=-1)


def linear_jacobian_derivatives(axes: FloatArray, jac_lin: FloatArray) -> FloatArray:
    """Linear rows only: (..., n, 3, n) from joint axes (..., n, 3) and ``J^v`` (..., 3, n).

    ``out[..., i, :, k] = z_i x J_k^v`` for ``i <= k`` and ``z_k x J_i^v`` for ``i > k``
    (NOTES-001).
    """
    n = axes.shape[-2]
    lin = np.swapaxes(jac_lin, -1, -2)  # (..., n, 3)
    upper = np.triu(np.ones((n, n), dtype=bool))[:, :, None]
    dlin = np.where(
        upper,
        cross3(axes[..., :, None, :], lin[..., None, :, :]),
        cross3(axes[..., None, :, :], lin[..., :, None, :]),
    )
    return np.swapaxes(dlin, -1, -2)


def jacobian_derivatives(
    model: ArmModel, q: ArrayLike | None, *, state: ChainState | None = None
) -> FloatArray:
    """Closed-form derivative of the geometric Jacobian with respect to every joint angle.

    Parameters
    ----------
    model
        A chain of revolute joints (fixed-base Jacobian; a locked model is a chain too).
    q
        (..., n) joint angles [rad].
    state
        Precomputed :func:`jointlock.kinematics.chain_state` at ``q`` (optional); it must
        have been computed at ``q`` (see :func:`jointlock.kinematics.state_at`), and with it
        ``q=None`` means ``state.q``.

    Returns
    -------
    (..., n, 6, n) array ``D`` with ``D[..., i, :, k] = dJ[:, k]/dq_i``: linear rows in
    [m/(s rad)] per [rad/s], angular rows dimensionless, root-frame components, reference point
    the end-effector origin (same convention as :func:`jointlock.jacobian`).  NOTES-001:
    ``dJ_k/dq_i = z_i x J_k`` (i <= k), ``z_k x J_i`` (i > k) for the linear part.
    """
    s = state_at(model, q, state)
    jac = jacobian(model, s.q, state=s)
    n = model.dof
    z = s.axes  # (..., n, 3)
    dlin = linear_jacobian_derivatives(z, jac[..., :3, :])  # (..., i, 3, k)
    strict = np.triu(np.ones((n, n), dtype=bool), 1)  # i < k
    dang = np.where(strict[:, :, None], cross3(z[..., :, None, :], z[..., None, :, :]), 0.0)
    return np.concatenate([dlin, np.swapaxes(dang, -1, -2)], axis=-2)


def generalized_jacobian_derivatives(
    model: ArmModel, q: ArrayLike, *, step: float = GENERALIZED_FD_STEP
) -> FloatArray:
    """Derivative of the free-floating generalized Jacobian by central finite differences.

    Not closed form (the generalized Jacobian contains ``H_b^-1``); error ``O(step^2)``.

    Parameters
    ----------
    model
        The arm; a fixed-base model gives the finite-difference derivative of its ordinary
        Jacobian.
    q
        (..., n) joint angles [rad].
    step
        Finite-difference step [rad].

    Returns
    -------
    (..., n, 6, n) with ``[..., i, :, k] = dJ*[:, k]/dq_i`` (root/spacecraft-frame components).
    """
    q = as_joint_array(model, q)
    n = model.dof
    eye = np.eye(n) * step
    pert = np.concatenate([q[..., None, :] + eye, q[..., None, :] - eye], axis=-2)  # (..., 2n, n)
    jac = generalized_jacobian(model, pert)
    return (jac[..., :n, :, :] - jac[..., n:, :, :]) / (2.0 * step)


def manipulability(
    jac: ArrayLike, *, rows: RowBlock | slice = "position", columns: ArrayLike | None = None
) -> FloatArray:
    """Manipulability ``w = sqrt(det(J_s J_s^T))`` of a row block and a column subset.

    Parameters
    ----------
    jac
        (..., 6, n) Jacobian (fixed-base or generalized).
    rows
        Row block: ``"position"`` (default, 3 x n, 001's choice), ``"orientation"``, ``"full"``
        or a slice.  The raw Jacobian is used (no characteristic length).
    columns
        (..., n) boolean mask of the healthy (movable) joints; ``None`` = all.  Masked columns
        are removed, giving the reduced manipulability ``w_r`` of NOTES-001.

    Returns
    -------
    (...) manipulability [m^3 for the position block].
    """
    js = np.asarray(jac, dtype=float)[..., _rows(rows), :]
    if columns is not None:
        js = js * np.asarray(columns, dtype=bool)[..., None, :]
    det = np.linalg.det(js @ np.swapaxes(js, -1, -2))
    return np.sqrt(np.maximum(det, 0.0))


def manipulability_and_gradient(
    jac: ArrayLike,
    djac: ArrayLike,
    *,
    rows: RowBlock | slice = "position",
    columns: ArrayLike | None = None,
) -> tuple[FloatArray, FloatArray]:
    """Manipulability and its closed-form gradient from a Jacobian and its derivatives.

    ``dw/dq_i = w tr((J_s J_s^T)^-1 J_s (dJ_s/dq_i)^T)`` (NOTES-001; 001 eq. 25).

    Parameters
    ----------
    jac
        (..., 6, n) Jacobian.
    djac
        (..., n, 6, n) its derivatives, ``djac[..., i, :, k] = dJ[:, k]/dq_i``
        (:func:`jacobian_derivatives` or :func:`generalized_jacobian_derivatives`).
    rows
        Row block (see :func:`manipulability`).
    columns
        (..., n) boolean mask of healthy joints; ``None`` = all.  Locked columns are removed
        from ``J_s`` and the gradient is taken over the healthy joints only (locked entries 0).

    Returns
    -------
    w
        (...) manipulability of the selected block.
    grad
        (..., n) ``dw/dq`` [w per rad].  Requires ``J_s`` of full row rank; at a singular
        configuration the result is not finite.
    """
    r = _rows(rows)
    js = np.asarray(jac, dtype=float)[..., r, :]
    dj = np.asarray(djac, dtype=float)[..., r, :]
    if columns is not None:
        mask = np.asarray(columns, dtype=bool)
        js = js * mask[..., None, :]
        dj = dj * mask[..., None, None, :]
    # w = prod(sigma_r); dw/dq_i = sum_r (prod_{s != r} sigma_s) u_r^T dJ_i v_r, equal to
    # w tr((J J^T)^-1 J dJ_i^T) where J has full row rank and finite where it has not.
    u, s, vh = np.linalg.svd(js, full_matrices=False)
    k = s.shape[-1]
    w = np.prod(s, axis=-1) if k == js.shape[-2] else np.zeros(s.shape[:-1])
    others = np.prod(np.where(np.eye(k, dtype=bool), 1.0, s[..., None, :]), axis=-1)
    if k < js.shape[-2]:
        others = np.zeros_like(others)
    grad = np.einsum("...r,...ar,...iab,...rb->...i", others, u, dj, vh)
    if columns is not None:
        grad = grad * mask
    return w, grad


def manipulability_gradient(
    model: ArmModel,
    q: ArrayLike,
    *,
    rows: RowBlock | slice = "position",
    locked: ArrayLike | None = None,
    base: Literal["fixed", "floating"] = "fixed",
) -> tuple[FloatArray, FloatArray]:
    """Manipulability ``w`` and gradient ``dw/dq`` of an arm at ``q`` (batched).

    Parameters
    ----------
    model
        The arm.
    q
        (..., n) joint angles [rad].
    rows
        Row block of the Jacobian (``"position"`` by default, seed 001).
    locked
        Joint numbers (1-based) treated as locked at their current angle: the reduced
        manipulability ``w_r`` and its gradient over the healthy joints (locked entries 0).
    base
        ``"fixed"``: closed-form derivative of the geometric Jacobian.  ``"floating"``: the
        generalized Jacobian (``model.floating`` required) with its derivative by central
        finite differences (:func:`generalized_jacobian_derivatives`).

    Returns
    -------
    w
        (...) manipulability.
    grad
        (..., n) gradient [per rad].
    """
    q = as_joint_array(model, q)
    columns = None
    if locked is not None:
        columns = np.ones(model.dof, dtype=bool)
        for number in np.atleast_1d(np.asarray(locked, dtype=int)):
            columns[model.index_of(int(number))] = False
    if base == "fixed":
        state = chain_state(model.fixed(), q)
        jac = jacobian(model, q, state=state)
        djac = jacobian_derivatives(model, q, state=state)
    elif base == "floating":
        from .errors import ModelError

        if not model.floating:
            raise ModelError(
                f"base='floating' needs a free-floating model (load_robot(..., base='floating')); "
                f"model {model.name!r} has a fixed base"
            )
        jac = generalized_jacobian(model, q)
        djac = generalized_jacobian_derivatives(model, q)
    else:
        raise ConfigurationError(f"base must be 'fixed' or 'floating'; got {base!r}")
    return manipulability_and_gradient(jac, djac, rows=rows, columns=columns)
