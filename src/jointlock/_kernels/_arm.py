"""Chain kernels: end-effector positions, the fixed-base and the generalized Jacobian, and
both fused with the singular values (see :mod:`jointlock._kernels`)."""

from __future__ import annotations

import numpy as np
from numba import njit

from ._common import BLOCK, _adjugate3, _jit, _trig_block
from ._svd import _jacobi6_block, _jacobi_block, _work


@njit(inline="always", cache=True, error_model="numpy", nogil=True)
def _identity_frames(frames, nb):
    """The root frame (identity rotation, zero origin) in ``frames[:, :nb]`` (12, BLOCK)."""
    for b in range(nb):
        for k in range(12):
            frames[k, b] = 0.0
        frames[0, b] = 1.0
        frames[4, b] = 1.0
        frames[8, b] = 1.0


@njit(inline="always", cache=True, error_model="numpy", nogil=True)
def _advance(frames, b, e, p0, p1, p2, c, s):
    """Frame ``i`` of configuration ``b`` from frame ``i - 1`` (in place): ``F_i = F_{i-1}
    [E_i, p_i] Rot(z, q_i)`` with ``c, s = cos q_i, sin q_i``; the rows of the rotation are
    ``frames[3 r : 3 r + 3, b]``, the origin ``frames[9:12, b]``."""
    for r in range(3):
        r0, r1, r2 = frames[3 * r, b], frames[3 * r + 1, b], frames[3 * r + 2, b]
        frames[9 + r, b] += r0 * p0 + r1 * p1 + r2 * p2
        a0 = r0 * e[0, 0] + r1 * e[1, 0] + r2 * e[2, 0]
        a1 = r0 * e[0, 1] + r1 * e[1, 1] + r2 * e[2, 1]
        a2 = r0 * e[0, 2] + r1 * e[1, 2] + r2 * e[2, 2]
        frames[3 * r, b] = a0 * c + a1 * s
        frames[3 * r + 1, b] = a1 * c - a0 * s
        frames[3 * r + 2, b] = a2


@_jit
def ee_positions(q, rot, pos, tool, skip, out):
    """End-effector positions of a chain.

    Parameters
    ----------
    q : (N, n) joint angles [rad].
    rot, pos : (n, 3, 3), (n, 3) [m]: ``E_i`` and ``p_i`` of every link (module docstring).
    tool : (3,) [m] tool point in the last link's frame.
    skip : (n,) bool: joint ``i`` cannot move the point (it lies on the axis): its rotation
        is not applied (as :func:`jointlock._chain.ee_position_rows`).
    out : (N, 3) [m] written: ``v_1`` of ``v_i = p_i + E_i Rot(z, q_i) v_{i+1}``, ``v_{n+1} = t``.
    """
    n = q.shape[1]
    sn = np.empty(BLOCK)
    cs = np.empty(BLOCK)
    vx = np.empty(BLOCK)
    vy = np.empty(BLOCK)
    vz = np.empty(BLOCK)
    for s0 in range(0, q.shape[0], BLOCK):
        nb = min(BLOCK, q.shape[0] - s0)
        for b in range(nb):
            vx[b] = tool[0]
            vy[b] = tool[1]
            vz[b] = tool[2]
        for i in range(n - 1, -1, -1):
            if not skip[i]:
                _trig_block(q, s0, nb, i, sn, cs)
                for b in range(nb):
                    x, y = vx[b], vy[b]
                    vx[b] = cs[b] * x - sn[b] * y
                    vy[b] = sn[b] * x + cs[b] * y
            e = rot[i]
            p0, p1, p2 = pos[i, 0], pos[i, 1], pos[i, 2]
            for b in range(nb):
                x, y, z = vx[b], vy[b], vz[b]
                vx[b] = e[0, 0] * x + e[0, 1] * y + e[0, 2] * z + p0
                vy[b] = e[1, 0] * x + e[1, 1] * y + e[1, 2] * z + p1
                vz[b] = e[2, 0] * x + e[2, 1] * y + e[2, 2] * z + p2
        for b in range(nb):
            out[s0 + b, 0] = vx[b]
            out[s0 + b, 1] = vy[b]
            out[s0 + b, 2] = vz[b]


#: Rows (each ``BLOCK`` long) of the fixed-base Jacobian's work vectors (:func:`jacobian_work`):
#: ``fw``, the running frame (rotation rows 9, origin 3), the sine and cosine of the current
#: joint and the end effector (3); ``fj``, per joint its axis (3), origin (3) and Jacobian
#: column (6).  Flat vectors with the rows at constant offsets: each loop over the block
#: touches two arrays, which LLVM vectorises (rows of 2-D work arrays, whose strides are
#: run-time values, defeated its alias checks and the loops ran scalar).
_FSN, _FCS, _FPE, _FW_LEN = 12 * BLOCK, 13 * BLOCK, 14 * BLOCK, 17 * BLOCK
_FJ = 12 * BLOCK  # entries per joint in fj


@_jit
def jacobian_work(n):
    """The work vectors of :func:`_jacobian_block` for ``n`` joints, and a (6, n, BLOCK) array
    for the Jacobian."""
    return np.zeros(_FW_LEN), np.zeros(n * _FJ), np.zeros((6, n, BLOCK))


@njit(inline="always", cache=True, error_model="numpy", nogil=True)
def _advance_row(fw, b, r, e0, e1, e2, p0, p1, p2, c, s):
    """Row ``r`` of frame ``i`` of configuration ``b`` from frame ``i - 1`` (in place):
    ``F_i = F_{i-1} [E_i, p_i] Rot(z, q_i)`` with ``e0, e1, e2`` the columns of ``E_i``
    (three entries each) and ``c, s = cos q_i, sin q_i``."""
    r0, r1, r2 = fw[(3 * r) * BLOCK + b], fw[(3 * r + 1) * BLOCK + b], fw[(3 * r + 2) * BLOCK + b]
    fw[(9 + r) * BLOCK + b] += r0 * p0 + r1 * p1 + r2 * p2
    a0 = r0 * e0[0] + r1 * e0[1] + r2 * e0[2]
    a1 = r0 * e1[0] + r1 * e1[1] + r2 * e1[2]
    a2 = r0 * e2[0] + r1 * e2[1] + r2 * e2[2]
    fw[(3 * r) * BLOCK + b] = a0 * c + a1 * s
    fw[(3 * r + 1) * BLOCK + b] = a1 * c - a0 * s
    fw[(3 * r + 2) * BLOCK + b] = a2


@_jit
def _jacobian_block(q, s0, nb, rot, pos, tool, length, fw, fj, jac):
    """Geometric Jacobian (6, n, :nb) of ``q[s0:s0 + nb]`` into ``jac``, the linear rows
    divided by ``length`` [m]; ``fw``, ``fj``: the work vectors of :func:`jacobian_work`."""
    n = q.shape[1]
    for b in range(nb):  # the root frame: identity rotation, zero origin
        for k in range(12):
            fw[k * BLOCK + b] = 0.0
        fw[b] = 1.0
        fw[4 * BLOCK + b] = 1.0
        fw[8 * BLOCK + b] = 1.0
    for i in range(n):
        _trig_block(q, s0, nb, i, fw[_FSN : _FSN + BLOCK], fw[_FCS : _FCS + BLOCK])
        e = rot[i]
        e0 = (e[0, 0], e[1, 0], e[2, 0])
        e1 = (e[0, 1], e[1, 1], e[2, 1])
        e2 = (e[0, 2], e[1, 2], e[2, 2])
        p0, p1, p2 = pos[i, 0], pos[i, 1], pos[i, 2]
        o = i * _FJ
        for b in range(nb):
            c, s = fw[_FCS + b], fw[_FSN + b]
            _advance_row(fw, b, 0, e0, e1, e2, p0, p1, p2, c, s)
            _advance_row(fw, b, 1, e0, e1, e2, p0, p1, p2, c, s)
            _advance_row(fw, b, 2, e0, e1, e2, p0, p1, p2, c, s)
            for r in range(3):
                fj[o + r * BLOCK + b] = fw[(3 * r + 2) * BLOCK + b]
                fj[o + (3 + r) * BLOCK + b] = fw[(9 + r) * BLOCK + b]
    t0, t1, t2 = tool[0], tool[1], tool[2]
    for b in range(nb):
        for r in range(3):
            fw[_FPE + r * BLOCK + b] = (
                fw[(9 + r) * BLOCK + b]
                + fw[(3 * r) * BLOCK + b] * t0 + fw[(3 * r + 1) * BLOCK + b] * t1 + fw[(3 * r + 2) * BLOCK + b] * t2
            )
    for i in range(n):
        o = i * _FJ
        for b in range(nb):
            z0, z1, z2 = fj[o + b], fj[o + BLOCK + b], fj[o + 2 * BLOCK + b]
            d0 = fw[_FPE + b] - fj[o + 3 * BLOCK + b]
            d1 = fw[_FPE + BLOCK + b] - fj[o + 4 * BLOCK + b]
            d2 = fw[_FPE + 2 * BLOCK + b] - fj[o + 5 * BLOCK + b]
            fj[o + 6 * BLOCK + b] = (z1 * d2 - z2 * d1) / length
            fj[o + 7 * BLOCK + b] = (z2 * d0 - z0 * d2) / length
            fj[o + 8 * BLOCK + b] = (z0 * d1 - z1 * d0) / length
            fj[o + 9 * BLOCK + b] = z0
            fj[o + 10 * BLOCK + b] = z1
            fj[o + 11 * BLOCK + b] = z2
        for r in range(6):
            col = jac[r, i]
            for b in range(nb):
                col[b] = fj[o + (6 + r) * BLOCK + b]


@_jit
def jacobian(q, rot, pos, tool, out):
    """Fixed-base geometric Jacobian, root frame: ``out`` (N, 6, n) written, column ``i``
    ``(z_i x (p_e - p_i), z_i)`` (as :func:`jointlock.kinematics.jacobian`)."""
    n = q.shape[1]
    fw, fj, jac = jacobian_work(n)
    for s0 in range(0, q.shape[0], BLOCK):
        nb = min(BLOCK, q.shape[0] - s0)
        _jacobian_block(q, s0, nb, rot, pos, tool, 1.0, fw, fj, jac)
        for b in range(nb):
            for r in range(6):
                for i in range(n):
                    out[s0 + b, r, i] = jac[r, i, b]


@_jit
def fixed_singular_values(q, rot, pos, tool, length, out):
    """Singular values of the fixed-base geometric Jacobian (linear rows divided by ``length`` [m], as
    :func:`jointlock.analysis.ability.scale_linear_rows`)
    at ``q`` (N, n) into ``out`` (N, min(6, n)), descending: :func:`jacobian` and
    :func:`singular_values` fused per block (the Jacobian never leaves the cache)."""
    n = q.shape[1]
    fw, fj, jac = jacobian_work(n)
    tall = n <= 6
    m, k = (6, n) if tall else (n, 6)
    a = jac if tall else np.empty((n, 6, BLOCK))
    norms, gam, cosv, sinv, tanv = _work(m, k)
    for s0 in range(0, q.shape[0], BLOCK):
        nb = min(BLOCK, q.shape[0] - s0)
        _jacobian_block(q, s0, nb, rot, pos, tool, length, fw, fj, jac)
        if not tall:
            for i in range(n):
                for r in range(6):
                    for b in range(nb):
                        a[i, r, b] = jac[r, i, b]
        if m == 6:
            _jacobi6_block(a, nb, norms, out, s0)
        else:
            _jacobi_block(a, nb, norms, gam, cosv, sinv, tanv, out, s0)


@_jit
def _generalized_block(q, s0, nb, rot, pos, tool, length, mass, com, inertia, root, frames, sn, cs, w, jac):
    """Generalized Jacobian (6, n, :nb) of a free-floating arm with zero momentum into ``jac``
    (linear rows divided by ``length``).

    With ``r_g`` the system's centre of mass, ``M`` its mass and, per joint ``j``, the
    composite of the links outboard of it (mass ``M_j``, first moment ``S_j`` and inertia
    ``K_j`` about the joint origin ``o_j``): the arm's momentum at unit rate of joint ``j``
    on a still base is ``P_j = z_j x (S_j - M_j o_j)`` and, about ``r_g``,
    ``L_j = K_j z_j + (o_j - r_g) x P_j``; zero total momentum turns the base at
    ``omega_j = -I_g^-1 L_j`` (``I_g``: system inertia about ``r_g``) and column ``j`` is
    ``(z_j x (p_e - o_j) + omega_j x (p_e - r_g) - P_j / M, z_j + omega_j)``: the
    Umetani-Yoshida Jacobian of :func:`jointlock.kinematics.generalized_jacobian`.

    ``mass`` (n,), ``com`` (n, 3) [m], ``inertia`` (n, 3, 3) [kg m^2]: each link's in its
    ``z``-joint frame; ``root`` (13,): the spacecraft's mass, centre of mass (3) and inertia
    (9, row-major), root frame.  ``w`` (n, 15, BLOCK) work: per link axis (3), origin (3),
    centre of mass (3), world inertia (6: xx yy zz xy xz yz)."""
    n = q.shape[1]
    _identity_frames(frames, nb)
    for i in range(n):
        _trig_block(q, s0, nb, i, sn, cs)
        e = rot[i]
        p0, p1, p2 = pos[i, 0], pos[i, 1], pos[i, 2]
        c0, c1, c2 = com[i, 0], com[i, 1], com[i, 2]
        ii = inertia[i]
        for b in range(nb):
            _advance(frames, b, e, p0, p1, p2, cs[b], sn[b])
            for r in range(3):
                w[i, r, b] = frames[3 * r + 2, b]
                w[i, 3 + r, b] = frames[9 + r, b]
            # centre of mass and inertia in the root frame: R c + o, R I R^T
            for r in range(3):
                w[i, 6 + r, b] = (
                    frames[9 + r, b] + frames[3 * r, b] * c0 + frames[3 * r + 1, b] * c1 + frames[3 * r + 2, b] * c2
                )
            for slot, (ra, rc) in enumerate(((0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2))):
                acc = 0.0
                for k in range(3):
                    t = frames[3 * ra, b] * ii[0, k] + frames[3 * ra + 1, b] * ii[1, k] + frames[3 * ra + 2, b] * ii[2, k]
                    acc += t * frames[3 * rc + k, b]
                w[i, 9 + slot, b] = acc
    m0 = root[0]
    t0, t1, t2 = tool[0], tool[1], tool[2]
    total = m0
    for i in range(n):
        total += mass[i]
    for b in range(nb):
        pe0 = frames[9, b] + frames[0, b] * t0 + frames[1, b] * t1 + frames[2, b] * t2
        pe1 = frames[10, b] + frames[3, b] * t0 + frames[4, b] * t1 + frames[5, b] * t2
        pe2 = frames[11, b] + frames[6, b] * t0 + frames[7, b] * t1 + frames[8, b] * t2
        # composites about the root origin, suffix sums from the last link: first moment S,
        # inertia C = sum I_k + m_k (|c|^2 1 - c c^T) (6 entries)
        sx = sy = sz = 0.0
        cxx = cyy = czz = cxy = cxz = cyz = 0.0
        mj = 0.0
        for j in range(n - 1, -1, -1):
            m = mass[j]
            x, y, z = w[j, 6, b], w[j, 7, b], w[j, 8, b]
            mj += m
            sx += m * x
            sy += m * y
            sz += m * z
            cxx += w[j, 9, b] + m * (y * y + z * z)
            cyy += w[j, 10, b] + m * (x * x + z * z)
            czz += w[j, 11, b] + m * (x * x + y * y)
            cxy += w[j, 12, b] - m * x * y
            cxz += w[j, 13, b] - m * x * z
            cyz += w[j, 14, b] - m * y * z
            # column j: composite inertia about o_j, K = C - (2 (o.S) 1 - o S^T - S o^T) + M_j (|o|^2 1 - o o^T)
            z0, z1, z2 = w[j, 0, b], w[j, 1, b], w[j, 2, b]
            o0, o1, o2 = w[j, 3, b], w[j, 4, b], w[j, 5, b]
            os_ = o0 * sx + o1 * sy + o2 * sz
            oo = o0 * o0 + o1 * o1 + o2 * o2
            kxx = cxx - 2.0 * os_ + 2.0 * o0 * sx + mj * (oo - o0 * o0)
            kyy = cyy - 2.0 * os_ + 2.0 * o1 * sy + mj * (oo - o1 * o1)
            kzz = czz - 2.0 * os_ + 2.0 * o2 * sz + mj * (oo - o2 * o2)
            kxy = cxy + o0 * sy + sx * o1 - mj * o0 * o1
            kxz = cxz + o0 * sz + sx * o2 - mj * o0 * o2
            kyz = cyz + o1 * sz + sy * o2 - mj * o1 * o2
            h0, h1, h2 = sx - mj * o0, sy - mj * o1, sz - mj * o2
            jac[0, j, b] = z1 * h2 - z2 * h1  # P_j for now
            jac[1, j, b] = z2 * h0 - z0 * h2
            jac[2, j, b] = z0 * h1 - z1 * h0
            jac[3, j, b] = kxx * z0 + kxy * z1 + kxz * z2  # K_j z_j for now
            jac[4, j, b] = kxy * z0 + kyy * z1 + kyz * z2
            jac[5, j, b] = kxz * z0 + kyz * z1 + kzz * z2
        # the whole system: centre of mass and inertia about it
        gx = (sx + m0 * root[1]) / total
        gy = (sy + m0 * root[2]) / total
        gz = (sz + m0 * root[3]) / total
        r0x, r0y, r0z = root[1], root[2], root[3]
        ixx = cxx + root[4] + m0 * (r0y * r0y + r0z * r0z) - total * (gy * gy + gz * gz)
        iyy = cyy + root[8] + m0 * (r0x * r0x + r0z * r0z) - total * (gx * gx + gz * gz)
        izz = czz + root[12] + m0 * (r0x * r0x + r0y * r0y) - total * (gx * gx + gy * gy)
        ixy = cxy + root[5] - m0 * r0x * r0y + total * gx * gy
        ixz = cxz + root[6] - m0 * r0x * r0z + total * gx * gz
        iyz = cyz + root[9] - m0 * r0y * r0z + total * gy * gz
        # I_g^-1 by the adjugate (symmetric positive definite 3 x 3)
        a00, a11, a22, a01, a02, a12, det = _adjugate3(ixx, iyy, izz, ixy, ixz, iyz)
        inv_det = 1.0 / det
        eg0, eg1, eg2 = pe0 - gx, pe1 - gy, pe2 - gz
        for j in range(n):
            z0, z1, z2 = w[j, 0, b], w[j, 1, b], w[j, 2, b]
            o0, o1, o2 = w[j, 3, b], w[j, 4, b], w[j, 5, b]
            p_0, p_1, p_2 = jac[0, j, b], jac[1, j, b], jac[2, j, b]
            d0, d1, d2 = o0 - gx, o1 - gy, o2 - gz
            l0 = jac[3, j, b] + d1 * p_2 - d2 * p_1
            l1 = jac[4, j, b] + d2 * p_0 - d0 * p_2
            l2 = jac[5, j, b] + d0 * p_1 - d1 * p_0
            w0 = -(a00 * l0 + a01 * l1 + a02 * l2) * inv_det
            w1 = -(a01 * l0 + a11 * l1 + a12 * l2) * inv_det
            w2 = -(a02 * l0 + a12 * l1 + a22 * l2) * inv_det
            f0, f1, f2 = pe0 - o0, pe1 - o1, pe2 - o2
            jac[0, j, b] = (z1 * f2 - z2 * f1 + w1 * eg2 - w2 * eg1 - p_0 / total) / length
            jac[1, j, b] = (z2 * f0 - z0 * f2 + w2 * eg0 - w0 * eg2 - p_1 / total) / length
            jac[2, j, b] = (z0 * f1 - z1 * f0 + w0 * eg1 - w1 * eg0 - p_2 / total) / length
            jac[3, j, b] = z0 + w0
            jac[4, j, b] = z1 + w1
            jac[5, j, b] = z2 + w2


@_jit
def generalized_jacobian(q, rot, pos, tool, mass, com, inertia, root, out):
    """Generalized Jacobian of a free-floating arm, root frame: ``out`` (N, 6, n) written
    (see :func:`_generalized_block`)."""
    n = q.shape[1]
    frames = np.empty((12, BLOCK))
    sn = np.empty(BLOCK)
    cs = np.empty(BLOCK)
    w = np.empty((n, 15, BLOCK))
    jac = np.empty((6, n, BLOCK))
    for s0 in range(0, q.shape[0], BLOCK):
        nb = min(BLOCK, q.shape[0] - s0)
        _generalized_block(q, s0, nb, rot, pos, tool, 1.0, mass, com, inertia, root, frames, sn, cs, w, jac)
        for b in range(nb):
            for r in range(6):
                for i in range(n):
                    out[s0 + b, r, i] = jac[r, i, b]


@_jit
def generalized_singular_values(q, rot, pos, tool, mass, com, inertia, root, length, out):
    """Singular values of the generalized Jacobian (linear rows divided by ``length``) into
    ``out`` (N, min(6, n)), descending: :func:`_generalized_block` and the Jacobi method
    fused per block."""
    n = q.shape[1]
    frames = np.empty((12, BLOCK))
    sn = np.empty(BLOCK)
    cs = np.empty(BLOCK)
    w = np.empty((n, 15, BLOCK))
    jac = np.empty((6, n, BLOCK))
    tall = n <= 6
    m, k = (6, n) if tall else (n, 6)
    a = jac if tall else np.empty((n, 6, BLOCK))
    norms, gam, cosv, sinv, tanv = _work(m, k)
    for s0 in range(0, q.shape[0], BLOCK):
        nb = min(BLOCK, q.shape[0] - s0)
        _generalized_block(q, s0, nb, rot, pos, tool, length, mass, com, inertia, root, frames, sn, cs, w, jac)
        if not tall:
            for i in range(n):
                for r in range(6):
                    for b in range(nb):
                        a[i, r, b] = jac[r, i, b]
        if m == 6:
            _jacobi6_block(a, nb, norms, out, s0)
        else:
            _jacobi_block(a, nb, norms, gam, cosv, sinv, tanv, out, s0)
