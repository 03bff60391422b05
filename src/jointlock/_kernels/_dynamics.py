"""Newton-Euler kernels: joint torques and the base reaction wrench of a chain, fixed base
and free-floating, batched over samples (see :mod:`jointlock._kernels` for the layout).

The numpy reference is :func:`jointlock.dynamics.rnea` (000 eqs. 28-31); these kernels
compute the same quantities in the same frames:

* every link in its ``z``-joint frame (:func:`jointlock._chain.link_constants`): constant
  turn ``E_i`` and offset ``p_i`` from the parent, then ``Rot(z, q_i)``; mass ``m_i``,
  centre of mass ``c_i`` and inertia ``I_i`` about it in that frame;
* forward recursion (000 eq. 28): angular velocity ``w``, angular acceleration ``wd`` and
  origin acceleration ``a`` of each link, its inertia force ``F = m (a + wd x c + w x (w x c))``
  and moment ``N = I wd + w x I w``;
* backward recursion (000 eq. 29): ``f_i = F_i + R_{i+1} f_{i+1}``,
  ``n_i = N_i + c_i x F_i + R_{i+1} n_{i+1} + p_{i+1} x R_{i+1} f_{i+1}``, ``tau_i = n_i . z``.

Free-floating (zero momentum), as the numpy reference:

1. composite inertias of the links outboard of every joint, from the last link back in link
   frames (the composite-rigid-body recursion), with the arm's momentum ``h_arm`` on a still
   spacecraft; at the root they give the base block ``H_b`` of the system inertia about the
   spacecraft's centre of mass, and the spacecraft's twist is ``nu_0 = -H_b^-1 h_arm``;
2. a Newton-Euler pass with the spacecraft turning at ``omega_0`` but not accelerating: its
   wrench on the spacecraft gives the acceleration,
   ``H_b nu0_dot = -[f_1; n_1 + p_1 x f_1 + omega_0 x I_0 omega_0]``;
3. the torques are that pass's plus ``H_bm^T nu0_dot`` (Newton-Euler is affine in the
   accelerations at fixed velocities): the spacecraft's acceleration carried out to every
   link against each outboard composite's unit-rate momentum.

``H_b = [[M 1, -[h]x], [[h]x, K]]`` is solved by the Schur complement ``K + [h]x [h]x / M``
(the inertia about the system's centre of mass) and its adjugate, as
:func:`jointlock.dynamics._base_solver`.

Layout, for SIMD (:mod:`jointlock._kernels`): one flat vector ``g`` of the rows the links share
and one ``lk[i]`` per link, rows ``BLOCK`` long at constant offsets, so that LLVM vectorises
each loop (with 2-D work arrays it gave up on its run-time alias checks: 1.8-2.3x slower).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ._common import BLOCK, _adjugate3, _jit, _trig_block


@njit(inline="always", cache=True, error_model="numpy", nogil=True)
def _entries(m):
    """The nine entries of a 3 x 3 matrix, row by row, as scalars: loaded once per link, out
    of the loops over the block (the work arrays those loops write could alias ``m``, so
    the compiler would not hoist the loads itself)."""
    return m[0, 0], m[0, 1], m[0, 2], m[1, 0], m[1, 1], m[1, 2], m[2, 0], m[2, 1], m[2, 2]


@njit(inline="always", cache=True, error_model="numpy", nogil=True)
def _into_link(e, c, s, x0, x1, x2):
    """``Rot(z, q)^T E^T x``: a parent-frame vector in the link frame (``e``: the nine entries
    of ``E`` row by row, ``c, s = cos q, sin q``)."""
    e00, e01, e02, e10, e11, e12, e20, e21, e22 = e
    u0 = e00 * x0 + e10 * x1 + e20 * x2
    u1 = e01 * x0 + e11 * x1 + e21 * x2
    u2 = e02 * x0 + e12 * x1 + e22 * x2
    return c * u0 + s * u1, c * u1 - s * u0, u2


@njit(inline="always", cache=True, error_model="numpy", nogil=True)
def _out_of_link(e, c, s, x0, x1, x2):
    """``E Rot(z, q) x``: a link-frame vector in the parent frame (see :func:`_into_link`)."""
    e00, e01, e02, e10, e11, e12, e20, e21, e22 = e
    r0, r1 = c * x0 - s * x1, s * x0 + c * x1
    return (
        e00 * r0 + e01 * r1 + e02 * x2,
        e10 * r0 + e11 * r1 + e12 * x2,
        e20 * r0 + e21 * r1 + e22 * x2,
    )


#: Entries per row of the work vectors: one block of samples.
_R = BLOCK
# rows of the shared vector g: the recursion's state (w, wd, a), the force and moment carried
# back (fn), the composite sums (15, see _composite_block) and the spacecraft solver (6)
_W0, _W1, _W2, _D0, _D1, _D2, _A0, _A1, _A2 = (k * _R for k in range(9))
_F0, _F1, _F2, _N0, _N1, _N2 = ((9 + k) * _R for k in range(6))
_S = 15 * _R
_V = 30 * _R
_SHARED = 36 * _R
# rows of a link's vector lk[i]: sine, cosine, rate, acceleration of its joint; inertia force
# and moment (link frame); composite columns (5, see _composite_block); joint torque
_SN, _CS, _QD, _QDD = 0, _R, 2 * _R, 3 * _R
_FO, _MO, _CO, _TA = 4 * _R, 7 * _R, 10 * _R, 15 * _R
_LINK = 16 * _R


@_jit
def _load_block(q, dq, ddq, s0, nb, lk):
    """Sines, cosines, rates and accelerations of samples ``s0 : s0 + nb`` into ``lk``."""
    n = q.shape[1]
    for i in range(n):
        li = lk[i]
        _trig_block(q, s0, nb, i, li[_SN : _SN + _R], li[_CS : _CS + _R])
        for b in range(nb):
            li[_QD + b] = dq[s0 + b, i]
            li[_QDD + b] = ddq[s0 + b, i]


@_jit
def _forward(nb, lk, rot, pos, mass, com, inertia, g):
    """Forward recursion (000 eq. 28) from the parent of link 1, whose ``(w, wd, a)`` are the
    state rows of ``g`` (its frame); every link's inertia force and moment (link frame) into
    its vector.  The state ends as the last link's."""
    n = rot.shape[0]
    for i in range(n):
        li = lk[i]
        e = _entries(rot[i])
        i00, i01, i02, i10, i11, i12, i20, i21, i22 = _entries(inertia[i])
        p0, p1, p2 = pos[i, 0], pos[i, 1], pos[i, 2]
        m = mass[i]
        c0, c1, c2 = com[i, 0], com[i, 1], com[i, 2]
        for b in range(nb):
            w0, w1, w2 = g[_W0 + b], g[_W1 + b], g[_W2 + b]
            d0, d1, d2 = g[_D0 + b], g[_D1 + b], g[_D2 + b]
            # origin acceleration: a + wd x p + w x (w x p), parent frame
            x0 = w1 * p2 - w2 * p1
            x1 = w2 * p0 - w0 * p2
            x2 = w0 * p1 - w1 * p0
            a0 = g[_A0 + b] + d1 * p2 - d2 * p1 + w1 * x2 - w2 * x1
            a1 = g[_A1 + b] + d2 * p0 - d0 * p2 + w2 * x0 - w0 * x2
            a2 = g[_A2 + b] + d0 * p1 - d1 * p0 + w0 * x1 - w1 * x0
            c, s = li[_CS + b], li[_SN + b]
            wu0, wu1, u2 = _into_link(e, c, s, w0, w1, w2)
            wdu0, wdu1, v2 = _into_link(e, c, s, d0, d1, d2)
            la0, la1, g2 = _into_link(e, c, s, a0, a1, a2)
            rate, accel = li[_QD + b], li[_QDD + b]
            nw0, nw1, nw2 = wu0, wu1, u2 + rate
            nd0, nd1, nd2 = wdu0 + wu1 * rate, wdu1 - wu0 * rate, v2 + accel
            # centre-of-mass acceleration and the inertia wrench
            y0 = nw1 * c2 - nw2 * c1
            y1 = nw2 * c0 - nw0 * c2
            y2 = nw0 * c1 - nw1 * c0
            ac0 = la0 + nd1 * c2 - nd2 * c1 + nw1 * y2 - nw2 * y1
            ac1 = la1 + nd2 * c0 - nd0 * c2 + nw2 * y0 - nw0 * y2
            ac2 = g2 + nd0 * c1 - nd1 * c0 + nw0 * y1 - nw1 * y0
            li[_FO + b] = m * ac0
            li[_FO + _R + b] = m * ac1
            li[_FO + 2 * _R + b] = m * ac2
            h0 = i00 * nw0 + i01 * nw1 + i02 * nw2
            h1 = i10 * nw0 + i11 * nw1 + i12 * nw2
            h2 = i20 * nw0 + i21 * nw1 + i22 * nw2
            li[_MO + b] = i00 * nd0 + i01 * nd1 + i02 * nd2 + nw1 * h2 - nw2 * h1
            li[_MO + _R + b] = i10 * nd0 + i11 * nd1 + i12 * nd2 + nw2 * h0 - nw0 * h2
            li[_MO + 2 * _R + b] = i20 * nd0 + i21 * nd1 + i22 * nd2 + nw0 * h1 - nw1 * h0
            g[_W0 + b], g[_W1 + b], g[_W2 + b] = nw0, nw1, nw2
            g[_D0 + b], g[_D1 + b], g[_D2 + b] = nd0, nd1, nd2
            g[_A0 + b], g[_A1 + b], g[_A2 + b] = la0, la1, g2


@_jit
def _backward(nb, lk, rot, pos, com, g):
    """Backward recursion (000 eq. 29): joint torques into the links' vectors, and into the
    fn rows of ``g`` the force and the moment about the origin of link 1 that link 1 receives
    from its parent, in the parent's frame."""
    n = rot.shape[0]
    for i in range(n - 1, -1, -1):
        li = lk[i]
        c0, c1, c2 = com[i, 0], com[i, 1], com[i, 2]
        last = i == n - 1
        j = i if last else i + 1
        lj = lk[j]  # the child's sine and cosine turn what it passes back
        e = _entries(rot[j])
        p0, p1, p2 = pos[j, 0], pos[j, 1], pos[j, 2]
        for b in range(nb):
            f0, f1, f2 = li[_FO + b], li[_FO + _R + b], li[_FO + 2 * _R + b]
            n0 = li[_MO + b] + c1 * f2 - c2 * f1
            n1 = li[_MO + _R + b] + c2 * f0 - c0 * f2
            n2 = li[_MO + 2 * _R + b] + c0 * f1 - c1 * f0
            if not last:
                c, s = lj[_CS + b], lj[_SN + b]
                g0, g1, g2 = _out_of_link(e, c, s, g[_F0 + b], g[_F1 + b], g[_F2 + b])
                h0, h1, h2 = _out_of_link(e, c, s, g[_N0 + b], g[_N1 + b], g[_N2 + b])
                n0 += h0 + p1 * g2 - p2 * g1
                n1 += h1 + p2 * g0 - p0 * g2
                n2 += h2 + p0 * g1 - p1 * g0
                f0 += g0
                f1 += g1
                f2 += g2
            g[_F0 + b], g[_F1 + b], g[_F2 + b] = f0, f1, f2
            g[_N0 + b], g[_N1 + b], g[_N2 + b] = n0, n1, n2
            li[_TA + b] = n2


@_jit
def _to_parent(nb, lk, rot, g):
    """The fn rows of ``g`` (force, moment; frame of link 1) turned into its parent's frame."""
    e = _entries(rot[0])
    l0 = lk[0]
    for b in range(nb):
        c, s = l0[_CS + b], l0[_SN + b]
        g[_F0 + b], g[_F1 + b], g[_F2 + b] = _out_of_link(e, c, s, g[_F0 + b], g[_F1 + b], g[_F2 + b])
        g[_N0 + b], g[_N1 + b], g[_N2 + b] = _out_of_link(e, c, s, g[_N0 + b], g[_N1 + b], g[_N2 + b])


@_jit
def _newton_euler(nb, lk, rot, pos, mass, com, inertia, g):
    """Both recursions from the state rows of ``g``: each link's torque into its vector, the
    force and moment link 1 receives into the fn rows of ``g`` (its parent's frame)."""
    _forward(nb, lk, rot, pos, mass, com, inertia, g)
    _backward(nb, lk, rot, pos, com, g)
    _to_parent(nb, lk, rot, g)


@_jit
def _store_torques(nb, lk, tau, s0):
    """The links' torques into ``tau[s0 : s0 + nb]`` (samples by joints)."""
    for i in range(lk.shape[0]):
        li = lk[i]
        for b in range(nb):
            tau[s0 + b, i] = li[_TA + b]


@_jit
def rnea_fixed(q, dq, ddq, rot, pos, mass, com, inertia, base_acc, point, tau, wrench):
    """Newton-Euler on a fixed base.

    Parameters
    ----------
    q, dq, ddq : (N, n) joint angles [rad], rates [rad/s], accelerations [rad/s^2].
    rot, pos, mass, com, inertia : (n, 3, 3), (n, 3) [m], (n,) [kg], (n, 3) [m],
        (n, 3, 3) [kg m^2]: the links of :func:`jointlock._chain.link_constants` with the
        root origin as origin.
    base_acc : (3,) [m/s^2] acceleration of the root frame (minus gravity).
    point : (3,) [m] point of the root frame the base moment is taken about.
    tau : (N, n) [N m] written: joint torques.
    wrench : (N, 6) [N, N m] written: the force and moment the arm exerts on its base,
        root frame (``-f_1``, ``-(n_1 + (p_1 - point) x f_1)``).
    """
    nsamp, n = q.shape
    g, lk = np.zeros(_SHARED), np.zeros((n, _LINK))  # the block's work (module docstring)
    l0, l1, l2 = pos[0, 0] - point[0], pos[0, 1] - point[1], pos[0, 2] - point[2]
    a0, a1, a2 = base_acc[0], base_acc[1], base_acc[2]
    for s0 in range(0, nsamp, BLOCK):
        nb = min(BLOCK, nsamp - s0)
        _load_block(q, dq, ddq, s0, nb, lk)
        for b in range(nb):
            g[_W0 + b], g[_W1 + b], g[_W2 + b] = 0.0, 0.0, 0.0
            g[_D0 + b], g[_D1 + b], g[_D2 + b] = 0.0, 0.0, 0.0
            g[_A0 + b], g[_A1 + b], g[_A2 + b] = a0, a1, a2
        _newton_euler(nb, lk, rot, pos, mass, com, inertia, g)
        _store_torques(nb, lk, tau, s0)
        for b in range(nb):
            f0, f1, f2 = g[_F0 + b], g[_F1 + b], g[_F2 + b]
            wrench[s0 + b, 0] = -f0
            wrench[s0 + b, 1] = -f1
            wrench[s0 + b, 2] = -f2
            wrench[s0 + b, 3] = -(g[_N0 + b] + l1 * f2 - l2 * f1)
            wrench[s0 + b, 4] = -(g[_N1 + b] + l2 * f0 - l0 * f2)
            wrench[s0 + b, 5] = -(g[_N2 + b] + l0 * f1 - l1 * f0)


@_jit
def _composite_block(nb, lk, rot, pos, mass, com, inertia, g):
    """Composite inertias of the links outboard of every joint, from the last link back, in
    link frames (as :func:`jointlock._chain.composite`), and the arm's momentum on a still
    spacecraft.

    Writes into the columns rows of ``lk[j]`` ``(K_xz, K_yz, K_zz, S_x, S_y)`` of the
    composite outboard of joint ``j`` (inertia ``K`` about origin ``j``, first moment ``S``,
    frame ``j``: its momentum at unit rate of joint ``j`` is ``(K e_z, e_z x S)``), and into
    the 15 sums rows of ``g`` the whole arm's first moment (3), inertia (6: xx yy zz xy xz
    yz) about the parent origin of link 1, linear momentum (3) and angular momentum about
    that origin (3), in its frame."""
    n = rot.shape[0]
    outboard = 0.0  # mass of the links after j
    for j in range(n - 1, -1, -1):
        lj = lk[j]
        m = mass[j]
        c0, c1, c2 = com[j, 0], com[j, 1], com[j, 2]
        i00, i01, i02, i10, i11, i12, i20, i21, i22 = _entries(inertia[j])
        cc = c0 * c0 + c1 * c1 + c2 * c2
        # the link's own inertia about its origin and first moment
        oxx, oyy, ozz = i00 + m * (cc - c0 * c0), i11 + m * (cc - c1 * c1), i22 + m * (cc - c2 * c2)
        oxy, oxz, oyz = i01 - m * c0 * c1, i02 - m * c0 * c2, i12 - m * c1 * c2
        if j == n - 1:
            for b in range(nb):
                g[_S + b], g[_S + _R + b], g[_S + 2 * _R + b] = m * c0, m * c1, m * c2
                g[_S + 3 * _R + b], g[_S + 4 * _R + b], g[_S + 5 * _R + b] = oxx, oyy, ozz
                g[_S + 6 * _R + b], g[_S + 7 * _R + b], g[_S + 8 * _R + b] = oxy, oxz, oyz
                for k in range(9, 15):
                    g[_S + k * _R + b] = 0.0
        else:
            _move_composite(nb, lk, rot, pos, j + 1, outboard, g)
            for b in range(nb):
                g[_S + b] += m * c0
                g[_S + _R + b] += m * c1
                g[_S + 2 * _R + b] += m * c2
                g[_S + 3 * _R + b] += oxx
                g[_S + 4 * _R + b] += oyy
                g[_S + 5 * _R + b] += ozz
                g[_S + 6 * _R + b] += oxy
                g[_S + 7 * _R + b] += oxz
                g[_S + 8 * _R + b] += oyz
        outboard += m
        for b in range(nb):
            kxz, kyz, kzz = g[_S + 7 * _R + b], g[_S + 8 * _R + b], g[_S + 5 * _R + b]
            sx, sy = g[_S + b], g[_S + _R + b]
            lj[_CO + b], lj[_CO + _R + b], lj[_CO + 2 * _R + b] = kxz, kyz, kzz
            lj[_CO + 3 * _R + b], lj[_CO + 4 * _R + b] = sx, sy
            rate = lj[_QD + b]
            g[_S + 9 * _R + b] -= sy * rate
            g[_S + 10 * _R + b] += sx * rate
            g[_S + 12 * _R + b] += kxz * rate
            g[_S + 13 * _R + b] += kyz * rate
            g[_S + 14 * _R + b] += kzz * rate
    _move_composite(nb, lk, rot, pos, 0, outboard, g)


@_jit
def _move_composite(nb, lk, rot, pos, j, mc, g):
    """The composite and momentum in the sums rows of ``g`` (frame ``j``, about origin ``j``;
    mass ``mc``) moved into the parent frame of link ``j``, about its origin: turned by
    ``R = E_j Rot(z, q_j)``, then shifted by ``p_j`` (parallel axes:
    ``K' = R K R^T + mc (|p|^2 1 - p p^T) + 2 (p.g) 1 - p g^T - g p^T`` with ``g = R S``)."""
    lj = lk[j]
    e = _entries(rot[j])
    e00, e01, e02, e10, e11, e12, e20, e21, e22 = e
    p0, p1, p2 = pos[j, 0], pos[j, 1], pos[j, 2]
    pp = p0 * p0 + p1 * p1 + p2 * p2
    mxx, myy, mzz = mc * (pp - p0 * p0), mc * (pp - p1 * p1), mc * (pp - p2 * p2)
    mxy, mxz, myz = -mc * p0 * p1, -mc * p0 * p2, -mc * p1 * p2
    for b in range(nb):
        c, s = lj[_CS + b], lj[_SN + b]
        # Rot(z, q) K Rot(z, q)^T
        xx, yy, zz = g[_S + 3 * _R + b], g[_S + 4 * _R + b], g[_S + 5 * _R + b]
        xy, xz, yz = g[_S + 6 * _R + b], g[_S + 7 * _R + b], g[_S + 8 * _R + b]
        cos2, sin2 = c * c - s * s, 2.0 * s * c
        tot, dif = xx + yy, xx - yy
        rxx = 0.5 * tot + (0.5 * cos2) * dif - sin2 * xy
        ryy = tot - rxx
        rxy = (0.5 * sin2) * dif + cos2 * xy
        rxz = c * xz - s * yz
        ryz = s * xz + c * yz
        # E (.) E^T: T = E K, then the six entries of T E^T
        t00 = e00 * rxx + e01 * rxy + e02 * rxz
        t01 = e00 * rxy + e01 * ryy + e02 * ryz
        t02 = e00 * rxz + e01 * ryz + e02 * zz
        t10 = e10 * rxx + e11 * rxy + e12 * rxz
        t11 = e10 * rxy + e11 * ryy + e12 * ryz
        t12 = e10 * rxz + e11 * ryz + e12 * zz
        t20 = e20 * rxx + e21 * rxy + e22 * rxz
        t21 = e20 * rxy + e21 * ryy + e22 * ryz
        t22 = e20 * rxz + e21 * ryz + e22 * zz
        # vectors: first moment, linear and angular momentum, turned by R
        g0, g1, g2 = _out_of_link(e, c, s, g[_S + b], g[_S + _R + b], g[_S + 2 * _R + b])
        l0, l1, l2 = _out_of_link(e, c, s, g[_S + 9 * _R + b], g[_S + 10 * _R + b], g[_S + 11 * _R + b])
        h0, h1, h2 = _out_of_link(e, c, s, g[_S + 12 * _R + b], g[_S + 13 * _R + b], g[_S + 14 * _R + b])
        g[_S + 12 * _R + b] = h0 + p1 * l2 - p2 * l1
        g[_S + 13 * _R + b] = h1 + p2 * l0 - p0 * l2
        g[_S + 14 * _R + b] = h2 + p0 * l1 - p1 * l0
        g[_S + 9 * _R + b], g[_S + 10 * _R + b], g[_S + 11 * _R + b] = l0, l1, l2
        pg = p0 * g0 + p1 * g1 + p2 * g2
        g[_S + 3 * _R + b] = t00 * e00 + t01 * e01 + t02 * e02 + mxx + 2.0 * (pg - p0 * g0)
        g[_S + 4 * _R + b] = t10 * e10 + t11 * e11 + t12 * e12 + myy + 2.0 * (pg - p1 * g1)
        g[_S + 5 * _R + b] = t20 * e20 + t21 * e21 + t22 * e22 + mzz + 2.0 * (pg - p2 * g2)
        g[_S + 6 * _R + b] = t00 * e10 + t01 * e11 + t02 * e12 + mxy - p0 * g1 - g0 * p1
        g[_S + 7 * _R + b] = t00 * e20 + t01 * e21 + t02 * e22 + mxz - p0 * g2 - g0 * p2
        g[_S + 8 * _R + b] = t10 * e20 + t11 * e21 + t12 * e22 + myz - p1 * g2 - g1 * p2
        g[_S + b], g[_S + _R + b], g[_S + 2 * _R + b] = g0 + mc * p0, g1 + mc * p1, g2 + mc * p2


@_jit
def _accel_torques(nb, lk, rot, pos, g):
    """Joint torques of the spacecraft's acceleration ``(alpha_0, a_0)`` (the ``wd`` and ``a``
    state rows of ``g``; root frame, parent origin of link 1) added to the links' torques:
    it is carried out to every link against each outboard composite's unit-rate momentum
    (``H_bm^T nu0_dot``; the columns of :func:`_composite_block`)."""
    n = rot.shape[0]
    for i in range(n):
        li = lk[i]
        e = _entries(rot[i])
        p0, p1, p2 = pos[i, 0], pos[i, 1], pos[i, 2]
        for b in range(nb):
            d0, d1, d2 = g[_D0 + b], g[_D1 + b], g[_D2 + b]
            a0 = g[_A0 + b] + d1 * p2 - d2 * p1
            a1 = g[_A1 + b] + d2 * p0 - d0 * p2
            a2 = g[_A2 + b] + d0 * p1 - d1 * p0
            c, s = li[_CS + b], li[_SN + b]
            nd0, nd1, v2 = _into_link(e, c, s, d0, d1, d2)
            la0, la1, g2 = _into_link(e, c, s, a0, a1, a2)
            g[_D0 + b], g[_D1 + b], g[_D2 + b] = nd0, nd1, v2
            g[_A0 + b], g[_A1 + b], g[_A2 + b] = la0, la1, g2
            li[_TA + b] += (
                li[_CO + b] * nd0 + li[_CO + _R + b] * nd1 + li[_CO + 2 * _R + b] * v2
                + li[_CO + 3 * _R + b] * la1 - li[_CO + 4 * _R + b] * la0
            )


@_jit
def rnea_floating(q, dq, ddq, rot, pos, mass, com, inertia, root, point, tau, wrench, base_acc, base_twist):
    """Newton-Euler on a free-floating spacecraft with zero momentum (module docstring).

    Parameters
    ----------
    q, dq, ddq : (N, n) joint angles [rad], rates [rad/s], accelerations [rad/s^2].
    rot, pos, mass, com, inertia : the links of :func:`jointlock._chain.link_constants` with
        the spacecraft's centre of mass as origin (see :func:`rnea_fixed`).
    root : (13,) the spacecraft's mass [kg], centre of mass (3) [m] and inertia about it
        (9, row-major) [kg m^2], root frame.
    point : (3,) [m] point of the root frame the base moment is taken about.
    tau : (N, n) [N m] written: joint torques.
    wrench : (N, 6) [N, N m] written: the force and moment the arm exerts on the spacecraft
        (``m_0 a_0``, ``I_0 alpha_0 + omega_0 x I_0 omega_0 + (c_0 - point) x m_0 a_0``).
    base_acc, base_twist : (N, 6) written: ``(a_0, alpha_0)`` [m/s^2, rad/s^2] and
        ``(v_0, omega_0)`` [m/s, rad/s] of the spacecraft (centre of mass, root frame).

    Returns
    -------
    Number of samples whose system inertia about its centre of mass is not positive
    definite (their outputs are meaningless).
    """
    nsamp, n = q.shape
    g, lk = np.zeros(_SHARED), np.zeros((n, _LINK))  # solver rows of g: H_b's Schur complement, inverted
    m0 = root[0]
    z00, z01, z02, z10, z11, z12, z20, z21, z22 = _entries(root[4:13].reshape(3, 3))
    arm_mass = 0.0
    for i in range(n):
        arm_mass += mass[i]
    total = m0 + arm_mass
    inv_total = 1.0 / total
    l0, l1, l2 = pos[0, 0], pos[0, 1], pos[0, 2]
    k0, k1, k2 = root[1] - point[0], root[2] - point[1], root[3] - point[2]
    bad = 0
    for s0 in range(0, nsamp, BLOCK):
        nb = min(BLOCK, nsamp - s0)
        _load_block(q, dq, ddq, s0, nb, lk)
        _composite_block(nb, lk, rot, pos, mass, com, inertia, g)
        for b in range(nb):
            hx, hy, hz = g[_S + b], g[_S + _R + b], g[_S + 2 * _R + b]
            # Schur complement K + [h]x [h]x / M and its adjugate
            kxx = g[_S + 3 * _R + b] + z00 - (hy * hy + hz * hz) * inv_total
            kyy = g[_S + 4 * _R + b] + z11 - (hx * hx + hz * hz) * inv_total
            kzz = g[_S + 5 * _R + b] + z22 - (hx * hx + hy * hy) * inv_total
            kxy = g[_S + 6 * _R + b] + z01 + hx * hy * inv_total
            kxz = g[_S + 7 * _R + b] + z02 + hx * hz * inv_total
            kyz = g[_S + 8 * _R + b] + z12 + hy * hz * inv_total
            cxx, cyy, czz, cxy, cxz, cyz, det = _adjugate3(kxx, kyy, kzz, kxy, kxz, kyz)
            if not det > 0.0:
                bad += 1
            inv_det = 1.0 / det
            g[_V + b], g[_V + _R + b], g[_V + 2 * _R + b] = cxx * inv_det, cyy * inv_det, czz * inv_det
            g[_V + 3 * _R + b], g[_V + 4 * _R + b], g[_V + 5 * _R + b] = cxy * inv_det, cxz * inv_det, cyz * inv_det
            # nu_0 = H_b^-1 (-P, -L)
            rf0, rf1, rf2 = -g[_S + 9 * _R + b], -g[_S + 10 * _R + b], -g[_S + 11 * _R + b]
            b0 = -g[_S + 12 * _R + b] - inv_total * (hy * rf2 - hz * rf1)
            b1 = -g[_S + 13 * _R + b] - inv_total * (hz * rf0 - hx * rf2)
            b2 = -g[_S + 14 * _R + b] - inv_total * (hx * rf1 - hy * rf0)
            om0 = g[_V + b] * b0 + g[_V + 3 * _R + b] * b1 + g[_V + 4 * _R + b] * b2
            om1 = g[_V + 3 * _R + b] * b0 + g[_V + _R + b] * b1 + g[_V + 5 * _R + b] * b2
            om2 = g[_V + 4 * _R + b] * b0 + g[_V + 5 * _R + b] * b1 + g[_V + 2 * _R + b] * b2
            base_twist[s0 + b, 0] = (rf0 + hy * om2 - hz * om1) * inv_total
            base_twist[s0 + b, 1] = (rf1 + hz * om0 - hx * om2) * inv_total
            base_twist[s0 + b, 2] = (rf2 + hx * om1 - hy * om0) * inv_total
            base_twist[s0 + b, 3] = om0
            base_twist[s0 + b, 4] = om1
            base_twist[s0 + b, 5] = om2
            g[_D0 + b], g[_D1 + b], g[_D2 + b] = 0.0, 0.0, 0.0
            g[_A0 + b], g[_A1 + b], g[_A2 + b] = 0.0, 0.0, 0.0
            g[_W0 + b], g[_W1 + b], g[_W2 + b] = om0, om1, om2
        _newton_euler(nb, lk, rot, pos, mass, com, inertia, g)
        for b in range(nb):
            hx, hy, hz = g[_S + b], g[_S + _R + b], g[_S + 2 * _R + b]
            om0, om1, om2 = base_twist[s0 + b, 3], base_twist[s0 + b, 4], base_twist[s0 + b, 5]
            j0 = z00 * om0 + z01 * om1 + z02 * om2
            j1 = z10 * om0 + z11 * om1 + z12 * om2
            j2 = z20 * om0 + z21 * om1 + z22 * om2
            sp0, sp1, sp2 = om1 * j2 - om2 * j1, om2 * j0 - om0 * j2, om0 * j1 - om1 * j0
            f0, f1, f2 = g[_F0 + b], g[_F1 + b], g[_F2 + b]
            rf0, rf1, rf2 = -f0, -f1, -f2
            rn0 = -(g[_N0 + b] + l1 * f2 - l2 * f1 + sp0)
            rn1 = -(g[_N1 + b] + l2 * f0 - l0 * f2 + sp1)
            rn2 = -(g[_N2 + b] + l0 * f1 - l1 * f0 + sp2)
            b0 = rn0 - inv_total * (hy * rf2 - hz * rf1)
            b1 = rn1 - inv_total * (hz * rf0 - hx * rf2)
            b2 = rn2 - inv_total * (hx * rf1 - hy * rf0)
            al0 = g[_V + b] * b0 + g[_V + 3 * _R + b] * b1 + g[_V + 4 * _R + b] * b2
            al1 = g[_V + 3 * _R + b] * b0 + g[_V + _R + b] * b1 + g[_V + 5 * _R + b] * b2
            al2 = g[_V + 4 * _R + b] * b0 + g[_V + 5 * _R + b] * b1 + g[_V + 2 * _R + b] * b2
            a0 = (rf0 + hy * al2 - hz * al1) * inv_total
            a1 = (rf1 + hz * al0 - hx * al2) * inv_total
            a2 = (rf2 + hx * al1 - hy * al0) * inv_total
            base_acc[s0 + b, 0], base_acc[s0 + b, 1], base_acc[s0 + b, 2] = a0, a1, a2
            base_acc[s0 + b, 3], base_acc[s0 + b, 4], base_acc[s0 + b, 5] = al0, al1, al2
            g0, g1, g2 = m0 * a0, m0 * a1, m0 * a2
            wrench[s0 + b, 0], wrench[s0 + b, 1], wrench[s0 + b, 2] = g0, g1, g2
            wrench[s0 + b, 3] = z00 * al0 + z01 * al1 + z02 * al2 + sp0 + k1 * g2 - k2 * g1
            wrench[s0 + b, 4] = z10 * al0 + z11 * al1 + z12 * al2 + sp1 + k2 * g0 - k0 * g2
            wrench[s0 + b, 5] = z20 * al0 + z21 * al1 + z22 * al2 + sp2 + k0 * g1 - k1 * g0
            # the acceleration-only pass starts from the spacecraft's acceleration
            g[_D0 + b], g[_D1 + b], g[_D2 + b] = al0, al1, al2
            g[_A0 + b], g[_A1 + b], g[_A2 + b] = a0, a1, a2
        _accel_torques(nb, lk, rot, pos, g)
        _store_torques(nb, lk, tau, s0)
    return bad
