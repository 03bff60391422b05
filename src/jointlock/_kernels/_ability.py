"""000's combined index CP (eqs. 8-9, 19) of a batch of configurations, compiled: the singular
values of the Jacobian (:func:`jointlock._kernels._arm.generalized_singular_values` or
:func:`~jointlock._kernels._arm.fixed_singular_values`), the three indices, their frozen
standardisation and the weighted sum, in one call (:func:`combined_index`).

Why.  The halt configuration's refinement (L-BFGS-B, 8 starts) asks CP of 13 configurations
about 340 times a case; the numpy route around the kernel (``configuration_indices``, then
``AbilityModel``: a dozen small arrays) cost about as much as the kernel itself.  The same
operations in the same order (the product of the singular values left to right, as
``np.prod`` multiplies them; ``(x - a) / span``; ``w_0 s + w_1 / kappa + w_2 w``), so the same
numbers to the bit (``tests/test_halt_config.py``).
"""

from __future__ import annotations

import numpy as np

from ._arm import fixed_singular_values, generalized_singular_values
from ._common import _jit


@_jit
def combined_index(
    q, rot, pos, tool, mass, com, inertia, root, floating, length, bounds, weights, out,
):  # fmt: skip
    """CP ``out`` (N,) of the configurations ``q`` (N, n) [rad].

    ``rot, pos, tool``: the chain (:func:`jointlock._chain.kernel_program`); ``mass, com,
    inertia, root``: its masses (:func:`jointlock._chain.kernel_mass_program`), used when
    ``floating`` (the generalized Jacobian), else the fixed-base Jacobian; ``length``: the
    characteristic length dividing the linear rows [m]; ``bounds`` (4,): ``(a_s, span_s, a_w,
    span_w)``, the frozen min-max bounds of ``sigma_min`` and ``w`` (a span <= 0 standardises
    to 0); ``weights`` (3,): the combined weights of ``(s, 1/kappa, w)``.
    """
    N = q.shape[0]
    r = min(6, q.shape[1])
    sv = np.empty((N, r))
    if floating:
        generalized_singular_values(q, rot, pos, tool, mass, com, inertia, root, length, sv)
    else:
        fixed_singular_values(q, rot, pos, tool, length, sv)
    a_s, span_s, a_w, span_w = bounds[0], bounds[1], bounds[2], bounds[3]
    for b in range(N):
        smax, smin = sv[b, 0], sv[b, r - 1]
        inverse_condition = smin / smax if smax > 0 else 0.0
        w = 1.0
        for i in range(r):
            w = w * sv[b, i]
        s_hat = 0.0 if span_s <= 0 else (smin - a_s) / span_s  # as _minmax: NaN stays NaN
        w_hat = 0.0 if span_w <= 0 else (w - a_w) / span_w
        out[b] = weights[0] * s_hat + weights[1] * inverse_condition + weights[2] * w_hat
