"""One control step of 001's resolved-rate integrator, fixed base, compiled: the chain's tool
point, joint axes and position Jacobian (:func:`fixed_frame`, the numbers of
:meth:`jointlock.planning.jump._frames._FixedChain.frame`) and the compensated rate law with
its closed-form gradient (:func:`rate_law`, the numbers of
:func:`jointlock.planning.jump._control.law` with ``axes``), for B runs, batch last as the
numpy reference keeps them.

The integrator calls them once per control step (about 1,400 steps per jump case) on a few
to a few hundred runs, where the numpy reference costs its ~120 calls' overhead per step.  The
same formulas, run by run, in the same order where it is cheap to keep (the running sums of
the gradient add joint by joint as ``np.cumsum`` does); products and sums inside a step
associate differently, so the results agree with numpy's to round-off (``tests/test_jump.py``).

A run whose Gram matrix ``J_h J_h^T`` is (nearly) singular gets ``singular[b] = True`` and no
rates: the caller computes those by the reference (an SVD), as the reference itself does.
"""

from __future__ import annotations

import math

import numpy as np

from ._common import _jit


@_jit
def fixed_frame(q, link_h, tool, x, jac, axes):
    """Tool point ``x`` (3, B) [m], joint axes ``axes`` (3, n, B) and position Jacobian ``jac``
    (3, n, B) [m/rad] at ``q`` (B, n) [rad]: link ``i``'s frame ``[R'_i | p_i]`` is
    ``[R'_{i-1} | p_{i-1}] H_i`` (``link_h`` (n, 4, 4); the first ``H_0``'s top rows) turned by
    ``Rz(q_i)`` in its first two columns; ``x = [R'_n | p_n] tool`` (``tool`` (4,))."""
    B, n = q.shape
    frame = np.empty((n, 3, 4))
    for b in range(B):
        for i in range(n):
            h = link_h[i]
            for r in range(3):
                for c in range(4):
                    if i == 0:
                        frame[0, r, c] = h[r, c]
                    else:
                        frame[i, r, c] = (
                            frame[i - 1, r, 0] * h[0, c]
                            + frame[i - 1, r, 1] * h[1, c]
                            + frame[i - 1, r, 2] * h[2, c]
                            + frame[i - 1, r, 3] * h[3, c]
                        )
            cq, sq = math.cos(q[b, i]), math.sin(q[b, i])
            for r in range(3):
                a0, a1 = frame[i, r, 0], frame[i, r, 1]
                frame[i, r, 0] = a0 * cq + a1 * sq
                frame[i, r, 1] = a1 * cq - a0 * sq
        for r in range(3):
            x[r, b] = (
                tool[0] * frame[n - 1, r, 0]
                + tool[1] * frame[n - 1, r, 1]
                + tool[2] * frame[n - 1, r, 2]
                + tool[3] * frame[n - 1, r, 3]
            )
        for i in range(n):
            z0, z1, z2 = frame[i, 0, 2], frame[i, 1, 2], frame[i, 2, 2]
            l0, l1, l2 = x[0, b] - frame[i, 0, 3], x[1, b] - frame[i, 1, 3], x[2, b] - frame[i, 2, 3]
            axes[0, i, b], axes[1, i, b], axes[2, i, b] = z0, z1, z2
            jac[0, i, b] = z1 * l2 - z2 * l1
            jac[1, i, b] = z2 * l0 - z0 * l2
            jac[2, i, b] = z0 * l1 - z1 * l0


@_jit
def rate_law(jac, axes, healthy, xdot, kappa, rtol, qdot, w, null, singular):
    """The compensated resolved-rate law for B runs (see :func:`jointlock.planning.jump._control.law`):
    ``qdot`` (n, B) [rad/s], ``w`` (B,) [m^3] and the null-space term ``null`` (n, B), from
    ``jac``, ``axes`` (3, n, B), ``healthy`` (n, B) bool, ``xdot`` (3, B) [m/s] and ``kappa``
    (B,); ``singular`` (B,) marks the runs whose Gram matrix is below ``rtol`` (left for the
    reference's SVD; their outputs are not written)."""
    n, B = jac.shape[1], jac.shape[2]
    jh = np.empty((3, n))
    m = np.empty((3, n))
    g = np.empty((3, 3))
    adj = np.empty((3, 3))
    suffix = np.empty((3, n))
    prefix = np.empty((3, n))
    grad = np.empty(n)
    for b in range(B):
        for k in range(n):
            keep = 1.0 if healthy[k, b] else 0.0
            for r in range(3):
                jh[r, k] = jac[r, k, b] * keep
        for r in range(3):
            for s in range(3):
                acc = 0.0
                for k in range(n):
                    acc += jh[r, k] * jh[s, k]
                g[r, s] = acc
        for r in range(3):  # adj[r, c] = cofactor of g[c, r]
            r1, r2 = (r + 1) % 3, (r + 2) % 3
            for c in range(3):
                c1, c2 = (c + 1) % 3, (c + 2) % 3
                adj[r, c] = g[c1, r1] * g[c2, r2] - g[c1, r2] * g[c2, r1]
        det = g[0, 0] * adj[0, 0] + g[0, 1] * adj[1, 0] + g[0, 2] * adj[2, 0]
        trace3 = (g[0, 0] + g[1, 1] + g[2, 2]) / 3.0
        if not det > rtol * (trace3 * trace3 * trace3):  # as the numpy reference
            singular[b] = True
            continue
        singular[b] = False
        inv_det = 1.0 / det
        for r in range(3):
            for k in range(n):
                m[r, k] = (adj[r, 0] * jh[0, k] + adj[r, 1] * jh[1, k] + adj[r, 2] * jh[2, k]) * inv_det
        wb = math.sqrt(max(det, 0.0))
        w[b] = wb
        # sum_{k >= i} J_k x M_k, and sum_{k < i} M_k x z_k, joint by joint as np.cumsum adds
        for k in range(n - 1, -1, -1):
            for r in range(3):
                r1, r2 = (r + 1) % 3, (r + 2) % 3
                term = jh[r1, k] * m[r2, k] - jh[r2, k] * m[r1, k]
                suffix[r, k] = term if k == n - 1 else suffix[r, k + 1] + term
        for r in range(3):
            prefix[r, 0] = 0.0
        for k in range(1, n):
            for r in range(3):
                r1, r2 = (r + 1) % 3, (r + 2) % 3
                term = m[r1, k - 1] * axes[r2, k - 1, b] - m[r2, k - 1] * axes[r1, k - 1, b]
                prefix[r, k] = term if k == 1 else prefix[r, k - 1] + term
        for i in range(n):
            dot = 0.0
            for r in range(3):
                dot += axes[r, i, b] * suffix[r, i]
            dot2 = 0.0
            for r in range(3):
                dot2 += jh[r, i] * prefix[r, i]
            grad[i] = wb * (dot + dot2) if healthy[i, b] else 0.0
        t0 = t1 = t2 = 0.0
        for k in range(n):
            t0 += jh[0, k] * grad[k]
            t1 += jh[1, k] * grad[k]
            t2 += jh[2, k] * grad[k]
        for i in range(n):
            nul = grad[i] - (m[0, i] * t0 + m[1, i] * t1 + m[2, i] * t2)
            null[i, b] = nul
            qdot[i, b] = (m[0, i] * xdot[0, b] + m[1, i] * xdot[1, b] + m[2, i] * xdot[2, b]) + kappa[b] * nul
