"""001's resolved-rate integrator, fixed base, compiled: the chain's tool point, joint axes
and position Jacobian (:func:`fixed_frame`, the numbers of
:meth:`jointlock.planning.jump._frames._FixedChain.frame`), the compensated rate law with its
closed-form gradient (:func:`rate_law`, the numbers of
:func:`jointlock.planning.jump._control.law` with ``axes``), for B runs, batch last as the
numpy reference keeps them, and the integrator's whole loop over the control steps around
them (:func:`integrate_steps`, the numbers of ``_engine._integrate``'s Python step).

A jump case takes about 1,400 control steps on a few to a few hundred runs; a Python step
costs ~90 us of calls (its bookkeeping, the two kernels, the records) against ~10 us of
arithmetic, so in a campaign's worker (compiled mode ``"always"``) the loop itself runs
compiled, and a Python step is taken only where the loop leaves one (a singular Gram matrix,
a diverging run).  The same formulas, run by run, in the same order where it is cheap to keep
(the running sums of the gradient add joint by joint as ``np.cumsum`` does); products and sums
inside a step associate differently, so the results agree with numpy's to round-off
(``tests/test_jump.py``).  The compiled loop and the Python loop over the same kernels agree
to the bit where a step holds two runs or more (``tests/test_jump_batched.py``); with a single
run numpy's ``einsum`` adds the deviation's three squares in another order (an ulp).

A run whose Gram matrix ``J_h J_h^T`` is (nearly) singular gets ``singular[b] = True`` and no
rates: the caller computes those by the reference (an SVD), as the reference itself does.
"""

from __future__ import annotations

import math

import numpy as np

from ._common import _jit, _nan_max, _nan_min


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


@_jit
def integrate_steps(
    k_begin, k_end, link_h, tool, x_nom, xd_nom, kp, dt, kappa, first_run, parent, locks_at, fail_steps,
    rest_transitions, jump_col, null_norm, diverged_rate, rtol,
    q, qd_prev, max_vel, max_acc, max_dev, min_w, max_null,
    rec_q, rec_qd, rec_dev, rec_x, rec_qd_plus, rec_task_plus, rec_task_noreplan,
):  # fmt: skip
    """Control steps ``k_begin .. k_end - 1`` of the fixed-base integrator
    (:func:`jointlock.planning.jump._engine._integrate`'s loop body, the same numbers to
    round-off): for the runs started by step ``k``, :func:`fixed_frame`, the tracking error and
    commanded rate, :func:`rate_law` (with the first ``R`` runs again with column ``jump_col``
    locked as well, when ``jump_col >= 0``), the running maxima, the records of the first ``R``
    runs (``R = rec_q.shape[0]``) and the explicit-Euler step of ``q`` (B, n).

    A run whose rate passes ``diverged_rate`` [rad/s] has its maxima and records of the step
    written, then its rates zeroed (it stays where it is), as the reference does.  Returns the
    first step not taken: ``k_end``, or the step at which a run's Gram matrix is (nearly)
    singular, every run diverges, or a rate is NaN -- nothing of that step is written, and the
    caller takes it by the reference (an SVD; refusing the task) before calling again from the
    next step.

    ``first_run`` (N + 1,): the number of runs started before each step; ``parent`` (B,): the
    run whose angles a run takes at its first step (-1: none); ``locks_at`` (B, n): the step
    from which each joint is locked; ``fail_steps`` (B, L): the failure steps (a step at which
    a joint locks is not an acceleration sample).  Histories: ``rec_q`` (R, N + 1, n),
    ``rec_qd`` (R, N, n), ``rec_dev`` (R, N + 1), ``rec_x`` (R, N + 1, 3); with ``jump_col``:
    ``rec_qd_plus`` (R, N, n), ``rec_task_plus`` and ``rec_task_noreplan`` (R, N, 3).
    """
    n = q.shape[1]
    R = rec_q.shape[0]
    n_fail = fail_steps.shape[1]
    for k in range(k_begin, k_end):
        m = first_run[k + 1]  # the runs started by now
        new = first_run[k]  # runs new .. m - 1 start at this step
        extra = R if jump_col >= 0 else 0
        cols = m + extra
        qs = np.empty((m, n))
        for b in range(m):
            src = parent[b] if b >= new and parent[b] >= 0 else b
            for i in range(n):
                qs[b, i] = q[src, i]
        x = np.empty((3, m))
        jac = np.empty((3, n, cols))
        axes = np.empty((3, n, cols))
        fixed_frame(qs, link_h, tool, x, jac, axes)
        healthy = np.empty((n, cols), dtype=np.bool_)
        xdot = np.empty((3, cols))
        kap = np.empty(cols)
        err = np.empty((3, m))
        for b in range(m):
            for i in range(n):
                healthy[i, b] = locks_at[b, i] > k
            for r in range(3):
                err[r, b] = x_nom[k, r] - x[r, b]
                xdot[r, b] = xd_nom[k, r] + kp * err[r, b]
            kap[b] = kappa[b, k]
        for j in range(extra):  # the first R runs again, column jump_col locked as well
            for i in range(n):
                healthy[i, m + j] = healthy[i, j] and i != jump_col
                for r in range(3):
                    jac[r, i, m + j] = jac[r, i, j]
                    axes[r, i, m + j] = axes[r, i, j]
            for r in range(3):
                xdot[r, m + j] = xdot[r, j]
            kap[m + j] = kap[j]
        qdot, w, null = np.empty((n, cols)), np.empty(cols), np.empty((n, cols))
        singular = np.zeros(cols, dtype=np.bool_)
        rate_law(jac, axes, healthy, xdot, kap, rtol, qdot, w, null, singular)
        for b in range(cols):
            if singular[b]:
                return k
        peaks = np.empty(m)
        every_run_diverges = m > 0
        for b in range(m):
            peak = 0.0
            for i in range(n):
                peak = _nan_max(peak, abs(qdot[i, b]))
            if peak != peak:
                return k  # NaN rates: the reference's rules (no run is stopped then)
            peaks[b] = peak
            every_run_diverges = every_run_diverges and peak > diverged_rate
        if every_run_diverges:
            return k  # the reference refuses the task in one line
        for b in range(m):
            dev = math.sqrt(err[0, b] * err[0, b] + err[1, b] * err[1, b] + err[2, b] * err[2, b])
            max_dev[b] = _nan_max(max_dev[b], dev)
            peak = peaks[b]
            acc = 0.0
            big_null = 0.0
            for i in range(n):
                acc = _nan_max(acc, abs(qdot[i, b] - qd_prev[b, i]))
                big_null = _nan_max(big_null, abs(null[i, b]))
            max_vel[b] = _nan_max(max_vel[b], peak)
            min_w[b] = _nan_min(min_w[b], w[b])
            if null_norm:
                max_null[b] = _nan_max(max_null[b], big_null)
            if b >= new:  # a run's first step: a jump, or the start from rest
                check = rest_transitions and k == 0
            else:
                check = True
                for col in range(n_fail):
                    if fail_steps[b, col] == k:
                        check = False
            if check:
                max_acc[b] = _nan_max(max_acc[b], acc / dt)
            if b < R:
                for i in range(n):
                    rec_qd[b, k, i] = qdot[i, b]
                rec_dev[b, k] = dev
                for r in range(3):
                    rec_x[b, k, r] = x[r, b]
                if jump_col >= 0:
                    for i in range(n):
                        rec_qd_plus[b, k, i] = qdot[i, m + b]
                    for r in range(3):
                        acc_r = 0.0
                        for c in range(n):
                            acc_r += jac[r, c, b] * (qdot[c, m + b] - qdot[c, b])
                        rec_task_plus[b, k, r] = acc_r
                        rec_task_noreplan[b, k, r] = -(jac[r, jump_col, b] * qdot[jump_col, b])
            if peak > diverged_rate:  # stopped, as the reference's _stop_diverged: recorded, then held
                for i in range(n):
                    qdot[i, b] = 0.0
            for i in range(n):
                qd_prev[b, i] = qdot[i, b]
                q[b, i] = qs[b, i] + dt * qdot[i, b]
            if b < R:
                for i in range(n):
                    rec_q[b, k + 1, i] = q[b, i]
    return k_end
