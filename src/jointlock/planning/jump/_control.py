"""The resolved-rate law with global compensation (NOTES-001, "The control law").

:func:`compensated_rates` is the public, batch-first form; :func:`law` is the kernel the
integrator calls once per control step for every run at once.  The kernel keeps the batch as
the *last* axis ("structure of arrays", as :class:`jointlock.kinematics.ChainState` stores its
frames): each arithmetic step is then one ufunc call over a contiguous vector per matrix entry,
so a step of one run and a step of a thousand runs cost nearly the same number of numpy calls.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from ..._chain import kernel_input
from ...compiled import use_compiled
from ...forward import COMPILED_MIN_BATCH
from ...model import FloatArray

#: Gram matrices ``J_h J_h^T`` whose determinant is below this fraction of ``(tr/3)^3`` are
#: treated as singular: ``J_h^+`` comes from an SVD (``np.linalg.pinv``) instead of the
#: adjugate, whose entries would be round-off divided by round-off there [-].
SINGULAR_GRAM_RTOL = 1e-13


#: Cyclic component indices: ``(a x b)_i = a_{i+1} b_{i+2} - a_{i+2} b_{i+1}``.
_NEXT, _AFTER = np.array([1, 2, 0]), np.array([2, 0, 1])
#: A vector's components twice over, ``(a_0, a_1, a_2, a_0, a_1)``: with it ``a_{i+1}`` and
#: ``a_{i+2}`` are the slices ``[1:4]`` and ``[2:5]``, one gather per operand instead of two.
CYCLIC = np.array([0, 1, 2, 0, 1])
#: Flat indices (into a 3 x 3 matrix's 9 entries) of the two products of each cofactor,
#: ``adj[r, c] = g[NEXT c, NEXT r] g[AFTER c, AFTER r] - g[NEXT c, AFTER r] g[AFTER c, NEXT r]``:
#: the first factors of both products, then the second factors (one gather each).
_COF_FIRST, _COF_SECOND = (
    np.concatenate(
        [np.array([3 * i[c] + j[r] for r in range(3) for c in range(3)]) for i, j in pairs]
    )
    for pairs in (((_NEXT, _NEXT), (_NEXT, _AFTER)), ((_AFTER, _AFTER), (_AFTER, _NEXT)))
)


def cross_cyclic(a5: FloatArray, b5: FloatArray) -> FloatArray:
    """Cross product ``a x b`` over the *first* axis, (3, ...) from ``a5 = a[CYCLIC]`` and
    ``b5 = b[CYCLIC]`` (5, ...) (broadcast): an operand used in several products is gathered
    once (the integrator's step is about 120 numpy calls on small batches; each counts)."""
    return a5[1:4] * b5[2:5] - a5[2:5] * b5[1:4]


def _pinv_rows(jac_h: FloatArray, gram: FloatArray) -> tuple[FloatArray, FloatArray]:
    """``(J J^T)^-1 J`` (3, n, B) for well-conditioned Gram matrices by the adjugate of the
    ``gram`` (3, 3, B), with an SVD fallback for the (near-)singular ones; returns it with
    ``det(J J^T)`` (B,)."""
    g = gram.reshape(9, -1)
    products = g[_COF_FIRST] * g[_COF_SECOND]
    adj = products[:9] - products[9:]  # (9, B), row-major adj[r, c]
    det = np.einsum("cb,cb->b", g[:3], adj[::3])  # along the first row of g
    trace3 = g[::4].sum(axis=0) / 3.0
    singular = ~(det > SINGULAR_GRAM_RTOL * (trace3 * trace3 * trace3))  # as the compiled kernel
    inv_det = 1.0 / np.where(singular, 1.0, det)
    m = np.einsum("rsb,skb->rkb", adj.reshape(gram.shape), jac_h) * inv_det
    if singular.any():
        # pinv(J^T) = (J^+)^T = (J J^T)^-1 J wherever the latter exists (rank 3)
        jt = np.moveaxis(jac_h[..., singular], -1, 0).swapaxes(-1, -2)  # (S, n, 3)
        # a locked (zero) column of J has a zero column here: exactly, as the adjugate gives
        # it (the SVD's rotations leave ~1e-17, and NOTES-001 property 3 wants the locked
        # joint's rate exactly 0)
        moving = np.any(jac_h[..., singular] != 0.0, axis=0)  # (n, S)
        m[..., singular] = np.moveaxis(np.linalg.pinv(jt), 0, -1) * moving
    return m, det


#: From this many runs on, :func:`_running_sum` adds joint by joint: numpy's ``cumsum`` along
#: a middle axis is not vectorised (~5 ns per entry), an ``add`` per joint is (~2 us per call).
RUNNING_SUM_LOOP_FROM = 128


def _running_sum(terms: FloatArray, *, reverse: bool = False) -> FloatArray:
    """Running sums of ``terms`` (3, n, B) over the joints (axis 1), from the first joint or
    (``reverse``) from the last: the additions of ``np.cumsum``, in its order, so the same
    values to the bit.  ``terms`` may be overwritten."""
    n, B = terms.shape[1], terms.shape[2]
    if B < RUNNING_SUM_LOOP_FROM:
        if reverse:
            return np.cumsum(terms[:, ::-1], axis=1)[:, ::-1]
        return np.cumsum(terms, axis=1)
    for i in range(n - 2, -1, -1) if reverse else range(1, n):
        j = i + 1 if reverse else i - 1
        np.add(terms[:, j], terms[:, i], out=terms[:, i])
    return terms


def law(
    jac: FloatArray,
    healthy: np.ndarray,
    xdot: FloatArray,
    kappa: FloatArray,
    *,
    axes: FloatArray | None = None,
    djac: FloatArray | None = None,
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """The compensated resolved-rate law for B runs, batch last (the integrator's kernel).

    ``qdot = J_h^+ xdot + kappa (I - J_h^+ J_h) grad w_h`` with ``J_h`` the position Jacobian
    with the locked columns zeroed (``healthy``) and ``w_h = sqrt(det(J_h J_h^T))``.  The
    gradient ``dw/dq_i = w tr((J J^T)^-1 J (dJ/dq_i)^T)`` (NOTES-001; 001 eq. 25) comes from

    * ``axes`` (fixed base, closed form): with ``M = (J J^T)^-1 J`` and the columns' triple
      products, ``dw/dq_i / w = z_i . sum_{k >= i} (J_k x M_k) + J_i . sum_{k < i} (M_k x z_k)``
      (``dJ_k/dq_i = z_i x J_k`` for ``i <= k``, ``z_k x J_i`` for ``i > k``): O(n) per run
      instead of the O(n^2) array of derivatives;
    * ``djac`` (any Jacobian, e.g. the free-floating one by finite differences) otherwise.

    Parameters
    ----------
    jac
        (3, n, B) position Jacobian [m/rad], *all* columns.
    healthy
        (n, B) boolean mask of the joints that can move.
    xdot
        (3, B) commanded end-effector velocity [m/s].
    kappa
        (B,) compensation coefficient [rad^2/(s m^3)].
    axes
        (3, n, B) unit joint axes, root frame (fixed-base closed-form gradient).
    djac
        (n, 3, n, B) ``djac[i, :, k] = dJ[:, k]/dq_i`` [m/rad^2] (when ``axes`` is None).

    Returns
    -------
    qdot
        (n, B) joint rates [rad/s]; exactly 0 at the locked joints (NOTES-001 property 3).
    w
        (B,) manipulability of the healthy columns [m^3].
    null
        (n, B) the null-space term ``(I - J_h^+ J_h) grad w_h`` [m^3/rad] (``qdot`` at
        ``xdot = 0``, ``kappa = 1``).
    """
    if axes is not None and use_compiled(jac.shape[-1], COMPILED_MIN_BATCH):
        return _compiled_law(jac, healthy, xdot, kappa, axes)
    return _reference_law(jac, healthy, xdot, kappa, axes=axes, djac=djac)


def _reference_law(
    jac: FloatArray,
    healthy: np.ndarray,
    xdot: FloatArray,
    kappa: FloatArray,
    *,
    axes: FloatArray | None = None,
    djac: FloatArray | None = None,
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """:func:`law` in numpy, batch last (the reference of the compiled kernel)."""
    jac_h = jac * healthy
    gram = np.einsum("rkb,skb->rsb", jac_h, jac_h)
    m, det = _pinv_rows(jac_h, gram)  # m[:, k] = 0 where column k is locked
    w = np.sqrt(np.maximum(det, 0.0))
    if axes is not None:
        m5 = m[CYCLIC]
        suffix = _running_sum(cross_cyclic(jac_h[CYCLIC], m5), reverse=True)  # sum_{k >= i} J_k x M_k
        prefix = np.zeros_like(m)
        prefix[:, 1:] = _running_sum(cross_cyclic(m5, axes[CYCLIC])[:, :-1])  # sum_{k < i} M_k x z_k
        grad = w * (np.einsum("rib,rib->ib", axes, suffix) + np.einsum("rib,rib->ib", jac_h, prefix))
    elif djac is not None:
        grad = w * np.einsum("rcb,ircb->ib", m, djac)  # M's locked columns are 0: no need to mask djac
    else:
        raise TypeError("law() needs the joint axes or the Jacobian's derivatives")
    grad = grad * healthy
    null = grad - np.einsum("rib,rb->ib", m, np.einsum("rkb,kb->rb", jac_h, grad))
    qdot = np.einsum("rib,rb->ib", m, xdot) + kappa * null
    return qdot, w, null


def _compiled_law(
    jac: FloatArray, healthy: np.ndarray, xdot: FloatArray, kappa: FloatArray, axes: FloatArray
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """:func:`law` with ``axes`` by the compiled kernel (:func:`jointlock._kernels.rate_law`);
    runs with a (nearly) singular Gram matrix by the reference, whose SVD handles them."""
    from ... import _kernels

    n, B = jac.shape[1], jac.shape[2]
    qdot, w, null = np.empty((n, B)), np.empty(B), np.empty((n, B))
    singular = np.zeros(B, dtype=np.bool_)
    # broadcast as numpy would (the kernel indexes every run's column; numba checks no bounds)
    healthy_c = np.ascontiguousarray(healthy if healthy.shape == (n, B) else np.broadcast_to(healthy, (n, B)),
                                     dtype=np.bool_)  # fmt: skip
    jac_c = kernel_input(jac)
    axes_c = kernel_input(axes if axes.shape == jac.shape else np.broadcast_to(axes, jac.shape))
    xdot_c = kernel_input(xdot if xdot.shape == (3, B) else np.broadcast_to(xdot, (3, B)))
    kappa_c = np.array(np.broadcast_to(kappa, (B,)), dtype=float)  # a column of the schedules: strided
    _kernels.rate_law(jac_c, axes_c, healthy_c, xdot_c, kappa_c, SINGULAR_GRAM_RTOL, qdot, w, null, singular)
    if singular.any():
        q_s, w_s, n_s = _reference_law(jac_c[..., singular], healthy_c[:, singular], xdot_c[:, singular],
                                       kappa_c[singular], axes=axes_c[..., singular])  # fmt: skip
        qdot[:, singular], w[singular], null[:, singular] = q_s, w_s, n_s
    return qdot, w, null


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
    manipulability; locked entries of ``qdot`` are exactly 0 (NOTES-001 property 3).  The
    same law as the integrator's kernel (:func:`law`, fed the derivatives here).

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
    jac_a = np.asarray(jac, dtype=float)
    djac_a = np.asarray(djac, dtype=float)
    xdot_a = np.asarray(xdot, dtype=float)
    kappa_a = np.asarray(kappa, dtype=float)
    n = jac_a.shape[-1]
    mask = np.ones(n, dtype=bool) if healthy is None else np.asarray(healthy, dtype=bool)
    batch = np.broadcast_shapes(
        jac_a.shape[:-2], djac_a.shape[:-3], xdot_a.shape[:-1], kappa_a.shape, mask.shape[:-1]
    )
    size = int(np.prod(batch))

    def last(a: np.ndarray, core: tuple[int, ...]) -> np.ndarray:  # (..., *core) -> (*core, size)
        return np.moveaxis(np.broadcast_to(a, batch + core).reshape((size,) + core), 0, -1)

    qdot, w, _ = law(
        last(jac_a, (3, n)),
        last(mask, (n,)),
        last(xdot_a, (3,)),
        np.broadcast_to(kappa_a, batch).reshape(size),
        djac=last(djac_a, (n, 3, n)),
    )
    return np.moveaxis(qdot, -1, 0).reshape(batch + (n,)), w.reshape(batch)
