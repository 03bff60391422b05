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

Speed.  These loops run scalar: LLVM's loop vectoriser does not vectorise loop bodies that
touch this many arrays (it gives up on the run-time alias checks), so the gain over numpy is
the removal of per-operation overhead and temporaries, not SIMD (README, "Speed").
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


@_jit
def _work(n):
    """The work arrays of one block for ``n`` joints: sines, cosines, rates, accelerations
    (n, BLOCK); the recursion's state ``(w, wd, a)`` (9, BLOCK); a force and moment (6, BLOCK);
    every link's inertia force and moment (n, 3, BLOCK) each."""
    return (
        np.empty((n, BLOCK)),
        np.empty((n, BLOCK)),
        np.empty((n, BLOCK)),
        np.empty((n, BLOCK)),
        np.empty((9, BLOCK)),
        np.empty((6, BLOCK)),
        np.empty((n, 3, BLOCK)),
        np.empty((n, 3, BLOCK)),
    )


@_jit
def _load_block(q, dq, ddq, s0, nb, sn, cs, qd, qdd):
    """Sines, cosines, rates and accelerations of samples ``s0 : s0 + nb`` into the (n, BLOCK)
    work arrays (contiguous along the block)."""
    n = q.shape[1]
    for i in range(n):
        _trig_block(q, s0, nb, i, sn[i], cs[i])
        for b in range(nb):
            qd[i, b] = dq[s0 + b, i]
            qdd[i, b] = ddq[s0 + b, i]


@_jit
def _forward(nb, sn, cs, qd, qdd, rot, pos, mass, com, inertia, state, force, moment):
    """Forward recursion (000 eq. 28) from the parent of link 1, whose ``(w, wd, a)`` are
    ``state[0:9, :nb]`` (its frame); every link's inertia force and moment (link frame) into
    ``force``, ``moment`` (n, 3, BLOCK).  ``state`` ends as the last link's."""
    n = rot.shape[0]
    for i in range(n):
        e = _entries(rot[i])
        i00, i01, i02, i10, i11, i12, i20, i21, i22 = _entries(inertia[i])
        p0, p1, p2 = pos[i, 0], pos[i, 1], pos[i, 2]
        m = mass[i]
        c0, c1, c2 = com[i, 0], com[i, 1], com[i, 2]
        for b in range(nb):
            w0, w1, w2 = state[0, b], state[1, b], state[2, b]
            d0, d1, d2 = state[3, b], state[4, b], state[5, b]
            # origin acceleration: a + wd x p + w x (w x p), parent frame
            x0 = w1 * p2 - w2 * p1
            x1 = w2 * p0 - w0 * p2
            x2 = w0 * p1 - w1 * p0
            a0 = state[6, b] + d1 * p2 - d2 * p1 + w1 * x2 - w2 * x1
            a1 = state[7, b] + d2 * p0 - d0 * p2 + w2 * x0 - w0 * x2
            a2 = state[8, b] + d0 * p1 - d1 * p0 + w0 * x1 - w1 * x0
            c, s = cs[i, b], sn[i, b]
            wu0, wu1, u2 = _into_link(e, c, s, w0, w1, w2)
            wdu0, wdu1, v2 = _into_link(e, c, s, d0, d1, d2)
            la0, la1, g2 = _into_link(e, c, s, a0, a1, a2)
            rate, accel = qd[i, b], qdd[i, b]
            nw0, nw1, nw2 = wu0, wu1, u2 + rate
            nd0, nd1, nd2 = wdu0 + wu1 * rate, wdu1 - wu0 * rate, v2 + accel
            # centre-of-mass acceleration and the inertia wrench
            y0 = nw1 * c2 - nw2 * c1
            y1 = nw2 * c0 - nw0 * c2
            y2 = nw0 * c1 - nw1 * c0
            ac0 = la0 + nd1 * c2 - nd2 * c1 + nw1 * y2 - nw2 * y1
            ac1 = la1 + nd2 * c0 - nd0 * c2 + nw2 * y0 - nw0 * y2
            ac2 = g2 + nd0 * c1 - nd1 * c0 + nw0 * y1 - nw1 * y0
            force[i, 0, b] = m * ac0
            force[i, 1, b] = m * ac1
            force[i, 2, b] = m * ac2
            h0 = i00 * nw0 + i01 * nw1 + i02 * nw2
            h1 = i10 * nw0 + i11 * nw1 + i12 * nw2
            h2 = i20 * nw0 + i21 * nw1 + i22 * nw2
            moment[i, 0, b] = i00 * nd0 + i01 * nd1 + i02 * nd2 + nw1 * h2 - nw2 * h1
            moment[i, 1, b] = i10 * nd0 + i11 * nd1 + i12 * nd2 + nw2 * h0 - nw0 * h2
            moment[i, 2, b] = i20 * nd0 + i21 * nd1 + i22 * nd2 + nw0 * h1 - nw1 * h0
            state[0, b], state[1, b], state[2, b] = nw0, nw1, nw2
            state[3, b], state[4, b], state[5, b] = nd0, nd1, nd2
            state[6, b], state[7, b], state[8, b] = la0, la1, g2


@_jit
def _backward(nb, sn, cs, rot, pos, com, force, moment, tau, s0, fn):
    """Backward recursion (000 eq. 29): joint torques into ``tau[s0 : s0 + nb]``, and into
    ``fn[0:6, :nb]`` the force and the moment about the origin of link 1 that link 1 receives
    from its parent, in the parent's frame."""
    n = rot.shape[0]
    for i in range(n - 1, -1, -1):
        c0, c1, c2 = com[i, 0], com[i, 1], com[i, 2]
        last = i == n - 1
        j = i if last else i + 1
        e = _entries(rot[j])
        p0, p1, p2 = pos[j, 0], pos[j, 1], pos[j, 2]
        for b in range(nb):
            f0, f1, f2 = force[i, 0, b], force[i, 1, b], force[i, 2, b]
            n0 = moment[i, 0, b] + c1 * f2 - c2 * f1
            n1 = moment[i, 1, b] + c2 * f0 - c0 * f2
            n2 = moment[i, 2, b] + c0 * f1 - c1 * f0
            if not last:
                c, s = cs[i + 1, b], sn[i + 1, b]
                g0, g1, g2 = _out_of_link(e, c, s, fn[0, b], fn[1, b], fn[2, b])
                h0, h1, h2 = _out_of_link(e, c, s, fn[3, b], fn[4, b], fn[5, b])
                n0 += h0 + p1 * g2 - p2 * g1
                n1 += h1 + p2 * g0 - p0 * g2
                n2 += h2 + p0 * g1 - p1 * g0
                f0 += g0
                f1 += g1
                f2 += g2
            fn[0, b], fn[1, b], fn[2, b] = f0, f1, f2
            fn[3, b], fn[4, b], fn[5, b] = n0, n1, n2
            tau[s0 + b, i] = n2


@_jit
def _to_parent(nb, sn, cs, rot, fn):
    """``fn[0:6, :nb]`` (force, moment in the frame of link 1) turned into its parent's frame."""
    e = _entries(rot[0])
    for b in range(nb):
        c, s = cs[0, b], sn[0, b]
        for k in (0, 3):
            fn[k, b], fn[k + 1, b], fn[k + 2, b] = _out_of_link(e, c, s, fn[k, b], fn[k + 1, b], fn[k + 2, b])


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
    sn, cs, qd, qdd, state, fn, force, moment = _work(n)
    l0, l1, l2 = pos[0, 0] - point[0], pos[0, 1] - point[1], pos[0, 2] - point[2]
    g0, g1, g2 = base_acc[0], base_acc[1], base_acc[2]
    for s0 in range(0, nsamp, BLOCK):
        nb = min(BLOCK, nsamp - s0)
        _load_block(q, dq, ddq, s0, nb, sn, cs, qd, qdd)
        for b in range(nb):
            for k in range(6):
                state[k, b] = 0.0
            state[6, b], state[7, b], state[8, b] = g0, g1, g2
        _forward(nb, sn, cs, qd, qdd, rot, pos, mass, com, inertia, state, force, moment)
        _backward(nb, sn, cs, rot, pos, com, force, moment, tau, s0, fn)
        _to_parent(nb, sn, cs, rot, fn)
        for b in range(nb):
            f0, f1, f2 = fn[0, b], fn[1, b], fn[2, b]
            wrench[s0 + b, 0] = -f0
            wrench[s0 + b, 1] = -f1
            wrench[s0 + b, 2] = -f2
            wrench[s0 + b, 3] = -(fn[3, b] + l1 * f2 - l2 * f1)
            wrench[s0 + b, 4] = -(fn[4, b] + l2 * f0 - l0 * f2)
            wrench[s0 + b, 5] = -(fn[5, b] + l0 * f1 - l1 * f0)


@_jit
def _composite_block(nb, sn, cs, qd, rot, pos, mass, com, inertia, sums, columns):
    """Composite inertias of the links outboard of every joint, from the last link back, in
    link frames (as :func:`jointlock._chain.composite`), and the arm's momentum on a still
    spacecraft.

    Writes ``columns[j, 0:5, :nb]`` = ``(K_xz, K_yz, K_zz, S_x, S_y)`` of the composite
    outboard of joint ``j`` (inertia ``K`` about origin ``j``, first moment ``S``, frame
    ``j``: its momentum at unit rate of joint ``j`` is ``(K e_z, e_z x S)``), and
    ``sums[0:15, :nb]`` = the whole arm's first moment (3), inertia (6: xx yy zz xy xz yz)
    about the parent origin of link 1, linear momentum (3) and angular momentum about that
    origin (3), in its frame."""
    n = rot.shape[0]
    outboard = 0.0  # mass of the links after j
    for j in range(n - 1, -1, -1):
        m = mass[j]
        c0, c1, c2 = com[j, 0], com[j, 1], com[j, 2]
        i00, i01, i02, i10, i11, i12, i20, i21, i22 = _entries(inertia[j])
        cc = c0 * c0 + c1 * c1 + c2 * c2
        # the link's own inertia about its origin and first moment
        oxx, oyy, ozz = i00 + m * (cc - c0 * c0), i11 + m * (cc - c1 * c1), i22 + m * (cc - c2 * c2)
        oxy, oxz, oyz = i01 - m * c0 * c1, i02 - m * c0 * c2, i12 - m * c1 * c2
        if j == n - 1:
            for b in range(nb):
                sums[0, b], sums[1, b], sums[2, b] = m * c0, m * c1, m * c2
                sums[3, b], sums[4, b], sums[5, b] = oxx, oyy, ozz
                sums[6, b], sums[7, b], sums[8, b] = oxy, oxz, oyz
                for k in range(9, 15):
                    sums[k, b] = 0.0
        else:
            _move_composite(nb, sn, cs, rot, pos, j + 1, outboard, sums)
            for b in range(nb):
                sums[0, b] += m * c0
                sums[1, b] += m * c1
                sums[2, b] += m * c2
                sums[3, b] += oxx
                sums[4, b] += oyy
                sums[5, b] += ozz
                sums[6, b] += oxy
                sums[7, b] += oxz
                sums[8, b] += oyz
        outboard += m
        for b in range(nb):
            kxz, kyz, kzz, sx, sy = sums[7, b], sums[8, b], sums[5, b], sums[0, b], sums[1, b]
            columns[j, 0, b], columns[j, 1, b], columns[j, 2, b] = kxz, kyz, kzz
            columns[j, 3, b], columns[j, 4, b] = sx, sy
            rate = qd[j, b]
            sums[9, b] -= sy * rate
            sums[10, b] += sx * rate
            sums[12, b] += kxz * rate
            sums[13, b] += kyz * rate
            sums[14, b] += kzz * rate
    _move_composite(nb, sn, cs, rot, pos, 0, outboard, sums)


@_jit
def _move_composite(nb, sn, cs, rot, pos, j, mc, sums):
    """The composite and momentum in ``sums[0:15]`` (frame ``j``, about origin ``j``; mass
    ``mc``) moved into the parent frame of link ``j``, about its origin: turned by
    ``R = E_j Rot(z, q_j)``, then shifted by ``p_j`` (parallel axes:
    ``K' = R K R^T + mc (|p|^2 1 - p p^T) + 2 (p.g) 1 - p g^T - g p^T`` with ``g = R S``)."""
    e = _entries(rot[j])
    e00, e01, e02, e10, e11, e12, e20, e21, e22 = e
    p0, p1, p2 = pos[j, 0], pos[j, 1], pos[j, 2]
    pp = p0 * p0 + p1 * p1 + p2 * p2
    mxx, myy, mzz = mc * (pp - p0 * p0), mc * (pp - p1 * p1), mc * (pp - p2 * p2)
    mxy, mxz, myz = -mc * p0 * p1, -mc * p0 * p2, -mc * p1 * p2
    for b in range(nb):
        c, s = cs[j, b], sn[j, b]
        # Rot(z, q) K Rot(z, q)^T
        xx, yy, zz, xy, xz, yz = sums[3, b], sums[4, b], sums[5, b], sums[6, b], sums[7, b], sums[8, b]
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
        g0, g1, g2 = _out_of_link(e, c, s, sums[0, b], sums[1, b], sums[2, b])
        l0, l1, l2 = _out_of_link(e, c, s, sums[9, b], sums[10, b], sums[11, b])
        h0, h1, h2 = _out_of_link(e, c, s, sums[12, b], sums[13, b], sums[14, b])
        sums[12, b] = h0 + p1 * l2 - p2 * l1
        sums[13, b] = h1 + p2 * l0 - p0 * l2
        sums[14, b] = h2 + p0 * l1 - p1 * l0
        sums[9, b], sums[10, b], sums[11, b] = l0, l1, l2
        pg = p0 * g0 + p1 * g1 + p2 * g2
        sums[3, b] = t00 * e00 + t01 * e01 + t02 * e02 + mxx + 2.0 * (pg - p0 * g0)
        sums[4, b] = t10 * e10 + t11 * e11 + t12 * e12 + myy + 2.0 * (pg - p1 * g1)
        sums[5, b] = t20 * e20 + t21 * e21 + t22 * e22 + mzz + 2.0 * (pg - p2 * g2)
        sums[6, b] = t00 * e10 + t01 * e11 + t02 * e12 + mxy - p0 * g1 - g0 * p1
        sums[7, b] = t00 * e20 + t01 * e21 + t02 * e22 + mxz - p0 * g2 - g0 * p2
        sums[8, b] = t10 * e20 + t11 * e21 + t12 * e22 + myz - p1 * g2 - g1 * p2
        sums[0, b], sums[1, b], sums[2, b] = g0 + mc * p0, g1 + mc * p1, g2 + mc * p2


@_jit
def _accel_torques(nb, sn, cs, rot, pos, columns, state, tau, s0):
    """Joint torques of the spacecraft's acceleration ``(alpha_0, a_0)`` =
    ``state[3:9, :nb]`` (root frame, at the parent origin of link 1) added to
    ``tau[s0 : s0 + nb]``: the rigid acceleration carried out to every link against each
    outboard composite's unit-rate momentum (``H_bm^T nu0_dot``; ``columns`` of
    :func:`_composite_block`)."""
    n = rot.shape[0]
    for i in range(n):
        e = _entries(rot[i])
        p0, p1, p2 = pos[i, 0], pos[i, 1], pos[i, 2]
        for b in range(nb):
            d0, d1, d2 = state[3, b], state[4, b], state[5, b]
            a0 = state[6, b] + d1 * p2 - d2 * p1
            a1 = state[7, b] + d2 * p0 - d0 * p2
            a2 = state[8, b] + d0 * p1 - d1 * p0
            c, s = cs[i, b], sn[i, b]
            nd0, nd1, v2 = _into_link(e, c, s, d0, d1, d2)
            la0, la1, g2 = _into_link(e, c, s, a0, a1, a2)
            state[3, b], state[4, b], state[5, b] = nd0, nd1, v2
            state[6, b], state[7, b], state[8, b] = la0, la1, g2
            tau[s0 + b, i] += (
                columns[i, 0, b] * nd0 + columns[i, 1, b] * nd1 + columns[i, 2, b] * v2
                + columns[i, 3, b] * la1 - columns[i, 4, b] * la0
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
    sn, cs, qd, qdd, state, fn, force, moment = _work(n)
    columns = np.empty((n, 5, BLOCK))
    sums = np.empty((15, BLOCK))
    solver = np.empty((6, BLOCK))  # the inverse Schur complement, entries xx yy zz xy xz yz
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
        _load_block(q, dq, ddq, s0, nb, sn, cs, qd, qdd)
        _composite_block(nb, sn, cs, qd, rot, pos, mass, com, inertia, sums, columns)
        for b in range(nb):
            hx, hy, hz = sums[0, b], sums[1, b], sums[2, b]
            # Schur complement K + [h]x [h]x / M and its adjugate
            kxx = sums[3, b] + z00 - (hy * hy + hz * hz) * inv_total
            kyy = sums[4, b] + z11 - (hx * hx + hz * hz) * inv_total
            kzz = sums[5, b] + z22 - (hx * hx + hy * hy) * inv_total
            kxy = sums[6, b] + z01 + hx * hy * inv_total
            kxz = sums[7, b] + z02 + hx * hz * inv_total
            kyz = sums[8, b] + z12 + hy * hz * inv_total
            cxx, cyy, czz, cxy, cxz, cyz, det = _adjugate3(kxx, kyy, kzz, kxy, kxz, kyz)
            if not det > 0.0:
                bad += 1
            inv_det = 1.0 / det
            solver[0, b], solver[1, b], solver[2, b] = cxx * inv_det, cyy * inv_det, czz * inv_det
            solver[3, b], solver[4, b], solver[5, b] = cxy * inv_det, cxz * inv_det, cyz * inv_det
            # nu_0 = H_b^-1 (-P, -L)
            rf0, rf1, rf2 = -sums[9, b], -sums[10, b], -sums[11, b]
            b0 = -sums[12, b] - inv_total * (hy * rf2 - hz * rf1)
            b1 = -sums[13, b] - inv_total * (hz * rf0 - hx * rf2)
            b2 = -sums[14, b] - inv_total * (hx * rf1 - hy * rf0)
            om0 = solver[0, b] * b0 + solver[3, b] * b1 + solver[4, b] * b2
            om1 = solver[3, b] * b0 + solver[1, b] * b1 + solver[5, b] * b2
            om2 = solver[4, b] * b0 + solver[5, b] * b1 + solver[2, b] * b2
            base_twist[s0 + b, 0] = (rf0 + hy * om2 - hz * om1) * inv_total
            base_twist[s0 + b, 1] = (rf1 + hz * om0 - hx * om2) * inv_total
            base_twist[s0 + b, 2] = (rf2 + hx * om1 - hy * om0) * inv_total
            base_twist[s0 + b, 3] = om0
            base_twist[s0 + b, 4] = om1
            base_twist[s0 + b, 5] = om2
            for k in range(3, 9):
                state[k, b] = 0.0
            state[0, b], state[1, b], state[2, b] = om0, om1, om2
        _forward(nb, sn, cs, qd, qdd, rot, pos, mass, com, inertia, state, force, moment)
        _backward(nb, sn, cs, rot, pos, com, force, moment, tau, s0, fn)
        _to_parent(nb, sn, cs, rot, fn)
        for b in range(nb):
            hx, hy, hz = sums[0, b], sums[1, b], sums[2, b]
            om0, om1, om2 = base_twist[s0 + b, 3], base_twist[s0 + b, 4], base_twist[s0 + b, 5]
            j0 = z00 * om0 + z01 * om1 + z02 * om2
            j1 = z10 * om0 + z11 * om1 + z12 * om2
            j2 = z20 * om0 + z21 * om1 + z22 * om2
            sp0, sp1, sp2 = om1 * j2 - om2 * j1, om2 * j0 - om0 * j2, om0 * j1 - om1 * j0
            f0, f1, f2 = fn[0, b], fn[1, b], fn[2, b]
            rf0, rf1, rf2 = -f0, -f1, -f2
            rn0 = -(fn[3, b] + l1 * f2 - l2 * f1 + sp0)
            rn1 = -(fn[4, b] + l2 * f0 - l0 * f2 + sp1)
            rn2 = -(fn[5, b] + l0 * f1 - l1 * f0 + sp2)
            b0 = rn0 - inv_total * (hy * rf2 - hz * rf1)
            b1 = rn1 - inv_total * (hz * rf0 - hx * rf2)
            b2 = rn2 - inv_total * (hx * rf1 - hy * rf0)
            al0 = solver[0, b] * b0 + solver[3, b] * b1 + solver[4, b] * b2
            al1 = solver[3, b] * b0 + solver[1, b] * b1 + solver[5, b] * b2
            al2 = solver[4, b] * b0 + solver[5, b] * b1 + solver[2, b] * b2
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
            state[3, b], state[4, b], state[5, b] = al0, al1, al2
            state[6, b], state[7, b], state[8, b] = a0, a1, a2
        _accel_torques(nb, sn, cs, rot, pos, columns, state, tau, s0)
    return bad
