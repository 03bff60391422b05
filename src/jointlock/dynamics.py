"""Batched rigid-body dynamics (zero gravity unless stated).

Mass matrices here are built from the centre-of-mass Jacobians (composite form).
:func:`rnea` is the recursive Newton-Euler algorithm of 000 eqs. 28-31, batched over any
leading shape (time samples and candidate trajectories at once), giving the joint torques
and the wrench the arm exerts on its base, with the base held fixed (000) or free-floating
(zero momentum, the spacecraft reacts).
"""

from __future__ import annotations

import weakref
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike

from .errors import ModelError
from .kinematics import ChainState, _world_inertias, chain_state, com_jacobians, com_positions
from .model import ArmModel, FloatArray, as_joint_array
from .spatial import skew


def mass_matrix(model: ArmModel, q: ArrayLike, state: ChainState | None = None) -> FloatArray:
    """Joint-space mass matrix of the arm on a fixed base.

    ``M(q) = sum_i m_i Jv_i^T Jv_i + Jw_i^T I_i Jw_i`` over the links (root body excluded).

    Parameters
    ----------
    q
        (..., n) joint angles [rad].

    Returns
    -------
    (..., n, n) [kg m^2], symmetric positive definite when every link has mass and inertia.
    """
    s = chain_state(model, q) if state is None else state
    jcom = com_jacobians(model, q, s)
    masses = np.array([b.mass for b in model.bodies])
    inertia_w = _world_inertias(model, s)
    jv, jw = jcom[..., :3, :], jcom[..., 3:, :]
    return np.einsum("n,...nij,...nik->...jk", masses, jv, jv) + np.einsum(
        "...nij,...nil,...nlk->...jk", jw, inertia_w, jw
    )


def system_mass_matrix(model: ArmModel, q: ArrayLike, state: ChainState | None = None) -> FloatArray:
    """Mass matrix of the free-floating system in the coordinates ``(v_0, omega_0, dq)``
    (spacecraft centre-of-mass velocity, its angular velocity, joint rates; root frame).

    Returns
    -------
    (..., 6 + n, 6 + n) [kg, kg m, kg m^2 blocks]; the kinetic energy is
    ``0.5 x^T M x`` with ``x = [v_0; omega_0; dq]``.
    """
    s = chain_state(model, q) if state is None else state
    n = model.dof
    batch = s.positions.shape[:-2]
    coms = com_positions(model, q, s)
    jcom = com_jacobians(model, q, s)
    r0 = model.root_body.com
    a_lin = np.zeros(batch + (n, 3, 6 + n))
    a_lin[..., :, :, 0:3] = np.eye(3)
    a_lin[..., :, :, 3:6] = -skew(coms - r0)
    a_lin[..., :, :, 6:] = jcom[..., :3, :]
    a_ang = np.zeros(batch + (n, 3, 6 + n))
    a_ang[..., :, :, 3:6] = np.eye(3)
    a_ang[..., :, :, 6:] = jcom[..., 3:, :]
    masses = np.array([b.mass for b in model.bodies])
    inertia_w = _world_inertias(model, s)
    out = np.einsum("n,...nij,...nik->...jk", masses, a_lin, a_lin) + np.einsum(
        "...nij,...nil,...nlk->...jk", a_ang, inertia_w, a_ang
    )
    out[..., 0:3, 0:3] += model.root_body.mass * np.eye(3)
    out[..., 3:6, 3:6] += model.root_body.inertia
    return out


def generalized_inertia(model: ArmModel, q: ArrayLike) -> FloatArray:
    """Generalized inertia matrix of the free-floating arm with zero momentum,
    ``H* = H_m - H_bm^T H_b^{-1} H_bm`` (..., n, n) [kg m^2]."""
    m = system_mass_matrix(model, q)
    hb, hbm, hm = m[..., :6, :6], m[..., :6, 6:], m[..., 6:, 6:]
    try:
        return hm - np.swapaxes(hbm, -1, -2) @ np.linalg.solve(hb, hbm)
    except np.linalg.LinAlgError:
        raise ModelError(
            f"model {model.name!r}: the free-floating system's inertia is singular; H* is undefined"
        ) from None


# -- recursive Newton-Euler and the base reaction wrench (000 eqs. 28-31) ------------------

BaseMode = Literal["fixed", "floating"]


@dataclass(frozen=True)
class InverseDynamics:
    """Result of :func:`rnea` for a batch of states (leading shape ``...``).

    Attributes
    ----------
    torques
        (..., n) joint torques [N m] about each movable joint's axis.
    base_force
        (..., 3) force the arm exerts on its base at joint 1 [N], root frame (000 eq. 30,
        ``f_d``, with the sign of ``docs/conventions.md``: positive = acting on the
        spacecraft, i.e. ``-f_1`` in 000's notation).
    base_moment
        (..., 3) moment the arm exerts on its base about ``moment_point`` (the spacecraft's
        centre of mass by default) [N m], root frame (000 eqs. 30-31, ``n_d = tau_b``).
    base_acceleration
        (..., 6) spacecraft acceleration ``(a_0, alpha_0)``: acceleration of its centre of
        mass [m/s^2] and angular acceleration [rad/s^2], root-frame components of inertial
        derivatives; zero for ``base="fixed"``.
    base_twist
        (..., 6) spacecraft twist ``(v_0, omega_0)`` [m/s, rad/s] implied by zero momentum;
        zero for ``base="fixed"``.
    moment_point
        (3,) point about which ``base_moment`` is taken, root frame [m].
    """

    torques: FloatArray
    base_force: FloatArray
    base_moment: FloatArray
    base_acceleration: FloatArray
    base_twist: FloatArray
    moment_point: FloatArray

    @property
    def base_wrench(self) -> FloatArray:
        """(..., 6) ``[f_d; n_d]`` [N, N m]."""
        return np.concatenate([self.base_force, self.base_moment], axis=-1)


# -- batch-last Newton-Euler in link frames --------------------------------------------------
#
# Every per-sample quantity below is a list of scalar rows, one (N,) array per component
# (``None`` for an exactly zero component).  Constant matrices (placements, inertias, centres
# of mass) are applied entry by entry with zero entries skipped and unit entries not
# multiplied, so a signed-permutation placement (every DH model) costs nothing; the joint
# rotation about ``z`` is four products and two sums per vector.  Links frames are rotated
# so that every joint turns about its own ``z`` (see :func:`_link_constants`).


def _lc(terms, const: float = 0.0):
    """Sum of ``coef * row`` over ``terms`` plus ``const``; zero coefficients and ``None``
    rows skipped, unit coefficients not multiplied; ``None`` when everything is zero."""
    out = None
    owned = False
    for coef, row in terms:
        if row is None or coef == 0.0:
            continue
        if out is None:
            if coef == 1.0:
                out = row
            else:
                out = row * coef
                owned = True
        elif coef == 1.0:
            if owned:
                out += row
            else:
                out = out + row
                owned = True
        elif coef == -1.0:
            if owned:
                out -= row
            else:
                out = out - row
                owned = True
        else:
            if owned:
                out += coef * row
            else:
                out = out + coef * row
                owned = True
    if const != 0.0:
        out = const if out is None else out + const
    return out


def _add(a, b):
    if a is None:
        return b
    if b is None:
        return a
    return a + b


def _sub(a, b):
    if b is None:
        return a
    if a is None:
        return -b
    return a - b


def _mul(a, b):
    if a is None or b is None:
        return None
    return a * b


def _add3(a, b, c):
    return [_add(_add(x, y), z) for x, y, z in zip(a, b, c)]


def _cmv(c: FloatArray, v):
    """Constant (3, 3) times a row vector."""
    return [_lc(((c[r, 0], v[0]), (c[r, 1], v[1]), (c[r, 2], v[2]))) for r in range(3)]


def _cross(a, b):
    """Cross product of two row vectors."""
    return [
        _sub(_mul(a[1], b[2]), _mul(a[2], b[1])),
        _sub(_mul(a[2], b[0]), _mul(a[0], b[2])),
        _sub(_mul(a[0], b[1]), _mul(a[1], b[0])),
    ]


def _cross_vc(v, p: FloatArray):
    """Row vector ``v`` cross a constant vector ``p``."""
    return [
        _lc(((p[2], v[1]), (-p[1], v[2]))),
        _lc(((p[0], v[2]), (-p[2], v[0]))),
        _lc(((p[1], v[0]), (-p[0], v[1]))),
    ]


def _rz(c, s, v, transpose: bool = False):
    """``Rot(z, q) v`` (or its transpose) for rows ``c = cos q``, ``s = sin q``."""
    x, y = v[0], v[1]
    if x is None and y is None:
        return [None, None, v[2]]
    if transpose:
        return [_add(_mul(c, x), _mul(s, y)), _sub(_mul(c, y), _mul(s, x)), v[2]]
    return [_sub(_mul(c, x), _mul(s, y)), _add(_mul(s, x), _mul(c, y)), v[2]]


@dataclass(frozen=True)
class _Link:
    """Constants of one link in its ``z``-joint frame (the joint frame turned by ``Q`` so that
    the joint axis is ``z``): rotation ``E`` and translation ``p`` from the parent's frame,
    mass, centre of mass, inertia about the centre of mass, and the composite-inertia
    transform coefficients of :func:`_composite`."""

    rot: FloatArray  # E (3, 3)
    pos: FloatArray  # p (3,)
    mass: float
    com: FloatArray
    inertia: FloatArray
    own_first: FloatArray  # m c (3,)
    own_inertia: FloatArray  # inertia about the frame origin (3, 3)
    sym_rot: FloatArray  # (6, 6), see _sym_coefficients
    sym_shift: FloatArray  # (6, 3)


_SYM = ((0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2))


def _axis_frame(axis: FloatArray) -> FloatArray:
    """Rotation ``Q`` with ``Q e_z = axis`` (identity for ``+z``)."""
    a = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    if a[0] == 0.0 and a[1] == 0.0 and a[2] > 0:
        return np.eye(3)
    helper = np.array([1.0, 0.0, 0.0]) if abs(a[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    u = np.cross(helper, a)
    u /= np.linalg.norm(u)
    return np.column_stack([u, np.cross(a, u), a])


#: Link constants of recently used models, by ``id`` (models are immutable); each entry keeps
#: a weak reference to its model so that a recycled ``id`` is never mistaken for it.
_LINK_CACHE: dict[tuple[int, bytes], tuple[weakref.ref, list[_Link]]] = {}
_LINK_CACHE_SIZE = 64


def _link_constants(model: ArmModel, origin: FloatArray) -> list[_Link]:
    """Per-link constants (cached per model); the parent of link 1 is the root frame moved
    to ``origin``."""
    key = (id(model), np.asarray(origin, dtype=float).tobytes())
    hit = _LINK_CACHE.get(key)
    if hit is not None and hit[0]() is model:
        return hit[1]
    links = _compute_link_constants(model, origin)
    if len(_LINK_CACHE) >= _LINK_CACHE_SIZE:
        _LINK_CACHE.clear()
    _LINK_CACHE[key] = (weakref.ref(model), links)
    return links


def _compute_link_constants(model: ArmModel, origin: FloatArray) -> list[_Link]:
    links = []
    q_prev = np.eye(3)
    for i, (joint, body) in enumerate(zip(model.joints, model.bodies)):
        qi = _axis_frame(joint.axis)
        pos = joint.placement[:3, 3] - (origin if i == 0 else 0.0)
        e = q_prev.T @ joint.placement[:3, :3] @ qi
        e[np.abs(e) < 1e-15] = 0.0
        e[np.abs(np.abs(e) - 1.0) < 1e-15] = np.sign(e[np.abs(np.abs(e) - 1.0) < 1e-15])
        com = qi.T @ body.com
        inertia = qi.T @ body.inertia @ qi
        m = body.mass
        own = inertia + m * (com @ com * np.eye(3) - np.outer(com, com))
        p = q_prev.T @ pos
        links.append(_Link(e, p, m, com, inertia, m * com, own, *_sym_coefficients(e, p)))
        q_prev = qi
    return links


def _cross_cv(p: FloatArray, v):
    """Constant vector ``p`` cross a row vector ``v``."""
    return [
        _lc(((p[1], v[2]), (-p[2], v[1]))),
        _lc(((p[2], v[0]), (-p[0], v[2]))),
        _lc(((p[0], v[1]), (-p[1], v[0]))),
    ]


def _forward(links, cos, sin, dq, ddq, w, wd, a):
    """Forward Newton-Euler recursion (000 eq. 28) in link frames: inertia force and moment
    (rows) of every link.  ``w``, ``wd``, ``a``: angular velocity, angular acceleration and
    origin acceleration of the parent of link 1, in its frame."""
    out = []
    for i, link in enumerate(links):
        c, s = cos[i], sin[i]
        ap = _add3(a, _cross_vc(wd, link.pos), _cross(w, _cross_vc(w, link.pos)))
        et = link.rot.T
        wu = _rz(c, s, _cmv(et, w), True)
        wdu = _rz(c, s, _cmv(et, wd), True)
        a = _rz(c, s, _cmv(et, ap), True)
        w = [wu[0], wu[1], _add(wu[2], dq[i])]
        wd = [_add(wdu[0], _mul(wu[1], dq[i])), _sub(wdu[1], _mul(wu[0], dq[i])), _add(wdu[2], ddq[i])]
        acc = _add3(a, _cross_vc(wd, link.com), _cross(w, _cross_vc(w, link.com)))
        force = [_lc(((link.mass, x),)) for x in acc]
        moment = [_add(x, y) for x, y in zip(_cmv(link.inertia, wd), _cross(w, _cmv(link.inertia, w)))]
        out.append((force, moment))
    return out


def _backward(links, cos, sin, wrenches):
    """Backward recursion (000 eq. 29): joint torques (rows), and the force and the moment
    about joint 1's origin that the root body exerts on link 1, in the parent frame of link 1."""
    n = len(links)
    tau = [None] * n
    f = nm = None
    for i in range(n - 1, -1, -1):
        force, moment = wrenches[i]
        nm_own = _add3(moment, _cross_cv(links[i].com, force), [None] * 3)
        if f is None:
            f, nm = force, nm_own
        else:
            nxt = links[i + 1]
            fr = _cmv(nxt.rot, _rz(cos[i + 1], sin[i + 1], f))
            nr = _cmv(nxt.rot, _rz(cos[i + 1], sin[i + 1], nm))
            f = [_add(x, y) for x, y in zip(force, fr)]
            nm = _add3(nm_own, nr, _cross_cv(nxt.pos, fr))
        tau[i] = nm[2]
    first = links[0]
    return tau, _cmv(first.rot, _rz(cos[0], sin[0], f)), _cmv(first.rot, _rz(cos[0], sin[0], nm))


def _sym_coefficients(e: FloatArray, p: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Coefficients of ``E K E^T`` on the six stored entries of ``K`` (6, 6), and of the
    parallel-axis cross terms ``2 (p.g) 1 - p g^T - g p^T`` with ``g = E h`` on ``h`` (6, 3)."""
    a = np.zeros((6, 6))
    g = np.zeros((6, 3))
    eye = np.eye(3)
    for r, (i, j) in enumerate(_SYM):
        for col, (k, l) in enumerate(_SYM):
            a[r, col] = e[i, k] * e[j, l] + (e[i, l] * e[j, k] if k != l else 0.0)
        for k in range(3):
            g[r, k] = 2.0 * p[k] * eye[i, j] - p[i] * eye[j, k] - p[j] * eye[i, k]
    a[np.abs(a) < 1e-15] = 0.0
    b = g @ e
    b[np.abs(b) < 1e-15] = 0.0
    return a, b


def _nz(x):
    return 0.0 if x is None else x


def _move_inertia(link, c, s, cos2, sin2, mass, first, inertia, own_inertia, own_first):
    """Move a composite body (mass, first moment and inertia about its frame origin, rows,
    in the frame of ``link``) into the parent frame of ``link``, about the parent origin,
    and add the parent's own constant inertia and first moment."""
    xx, yy, zz, xy, xz, yz = inertia
    tot, dif = xx + yy, xx - yy
    rxx = 0.5 * tot + (0.5 * cos2) * dif - sin2 * xy
    rot_k = (rxx, tot - rxx, zz, (0.5 * sin2) * dif + cos2 * xy, c * xz - s * yz, s * xz + c * yz)
    hz = _rz(c, s, first)
    a, b, p = link.sym_rot, link.sym_shift, link.pos
    const = mass * (p @ p * np.eye(3) - np.outer(p, p)) + own_inertia
    new_inertia = [
        _nz(_lc([(a[r, k], rot_k[k]) for k in range(6)] + [(b[r, k], hz[k]) for k in range(3)], const[i, j]))
        for r, (i, j) in enumerate(_SYM)
    ]
    new_first = [
        _nz(_lc([(link.rot[r, k], hz[k]) for k in range(3)], mass * p[r] + own_first[r])) for r in range(3)
    ]
    return new_first, new_inertia


def _move_momentum(link, c, s, ang, lin):
    """Move a momentum (angular about the frame origin, linear) into the parent frame."""
    lin = _cmv(link.rot, _rz(c, s, lin))
    ang = _add3(_cmv(link.rot, _rz(c, s, ang)), _cross_cv(link.pos, lin), [None] * 3)
    return ang, lin


def _composite(links, cos, sin, cos2, sin2, dq=None):
    """Composite inertia of the links outboard of every joint, recursively in link frames
    (as in the composite-rigid-body algorithm), and the momentum of the arm on a still base.

    Returns ``(mass, first, inertia, columns, momentum)``: the arm's mass, first moment (3
    rows) and inertia (6 rows, order ``_SYM``) about the parent origin of link 1, in its
    frame; per link ``j`` the momentum (angular about origin ``j``, linear; frame ``j``) of
    the outboard composite turning at unit rate about joint ``j``, as 5 rows
    ``(K_xz, K_yz, K_zz, h_x, h_y)`` (angular ``K e_z``, linear ``e_z x h``); and, with
    ``dq``, the arm's momentum ``(L, P)`` (rows, parent frame of link 1, ``L`` about its
    origin), else ``None``."""
    n = len(links)
    columns = [None] * n
    last = links[-1]
    mass = last.mass
    inertia = [float(last.own_inertia[i, j]) for i, j in _SYM]
    first = [float(x) for x in last.own_first]
    momentum = None
    for j in range(n - 1, -1, -1):
        if j < n - 1:
            nxt = links[j + 1]
            first, inertia = _move_inertia(
                nxt,
                cos[j + 1],
                sin[j + 1],
                cos2[j + 1],
                sin2[j + 1],
                mass,
                first,
                inertia,
                links[j].own_inertia,
                links[j].own_first,
            )
            mass += links[j].mass
            if momentum is not None:
                momentum = _move_momentum(nxt, cos[j + 1], sin[j + 1], *momentum)
        col = (inertia[4], inertia[5], inertia[2], first[0], first[1])
        columns[j] = col
        if dq is not None:
            d = dq[j]
            own = ([col[0] * d, col[1] * d, col[2] * d], [-col[4] * d, col[3] * d, None])
            momentum = (
                own
                if momentum is None
                else tuple([_add(x, y) for x, y in zip(u, v)] for u, v in zip(momentum, own))
            )
    zero3 = np.zeros(3)
    first, inertia = _move_inertia(
        links[0], cos[0], sin[0], cos2[0], sin2[0], mass, first, inertia, np.zeros((3, 3)), zero3
    )
    if momentum is not None:
        momentum = _move_momentum(links[0], cos[0], sin[0], *momentum)
    return mass, first, inertia, columns, momentum


def _base_solver(mass: float, first, inertia):
    """Solver of ``H_b x = [r_f; r_n]`` for the spacecraft-plus-arm inertia about the
    spacecraft's centre of mass, ``H_b = [[M 1, -[h]x], [[h]x, K]]`` (rows): the Schur
    complement ``K + [h]x [h]x / M`` (the inertia about the system's centre of mass) is
    inverted by its adjugate."""
    hx, hy, hz = first
    xx, yy, zz, xy, xz, yz = inertia
    im = 1.0 / mass
    kxx = xx - (hy * hy + hz * hz) * im
    kyy = yy - (hx * hx + hz * hz) * im
    kzz = zz - (hx * hx + hy * hy) * im
    kxy = xy + hx * hy * im
    kxz = xz + hx * hz * im
    kyz = yz + hy * hz * im
    cxx = kyy * kzz - kyz * kyz
    cxy = kxz * kyz - kxy * kzz
    cxz = kxy * kyz - kxz * kyy
    cyy = kxx * kzz - kxz * kxz
    cyz = kxy * kxz - kxx * kyz
    czz = kxx * kyy - kxy * kxy
    det = kxx * cxx + kxy * cxy + kxz * cxz
    if np.any(np.asarray(det) <= 0):
        raise ModelError(
            "the free-floating system's rotational inertia about its centre of "
            "mass is singular (e.g. collinear point masses on a point-mass spacecraft); the base "
            "reaction is undefined"
        )
    inv_det = 1.0 / det

    def solve(rf, rn):
        b = [_nz(x) - im * _nz(y) for x, y in zip(rn, _cross(first, rf))]
        alpha = [
            (cxx * b[0] + cxy * b[1] + cxz * b[2]) * inv_det,
            (cxy * b[0] + cyy * b[1] + cyz * b[2]) * inv_det,
            (cxz * b[0] + cyz * b[1] + czz * b[2]) * inv_det,
        ]
        lin = [(_nz(x) + _nz(y)) * im for x, y in zip(rf, _cross(first, alpha))]
        return lin, alpha

    return solve


def _rows_out(rows, n_samples: int, batch: tuple[int, ...]) -> FloatArray:
    out = np.empty((n_samples, len(rows)))
    for k, row in enumerate(rows):
        out[:, k] = 0.0 if row is None else row
    return out.reshape(batch + (len(rows),))


def _rnea_rows(model, qf, dqf, ddqf, base, g, point):
    """Rows of torques, base force, base moment, base acceleration and twist."""
    cos, sin = np.cos(qf), np.sin(qf)
    dq, ddq = list(dqf), list(ddqf)
    none3 = [None] * 3
    if base == "fixed":
        links = _link_constants(model, np.zeros(3))
        acc0 = [None if x == 0.0 else -float(x) for x in g]  # gravity as an upward base acceleration
        wrenches = _forward(links, cos, sin, dq, ddq, none3, none3, acc0)
        tau, f1, n1 = _backward(links, cos, sin, wrenches)
        force = [_lc(((-1.0, x),)) for x in f1]
        moment = [_lc(((-1.0, x), (-1.0, y))) for x, y in zip(n1, _cross_cv(links[0].pos - point, f1))]
        zero6 = [None] * 6
        return tau, force, moment, zero6, zero6
    root = model.root_body
    c0 = root.com
    links = _link_constants(model, c0)
    cos2, sin2 = cos * cos - sin * sin, 2.0 * sin * cos
    mass, first, inertia, columns, (ang, lin) = _composite(links, cos, sin, cos2, sin2, dq)
    inertia = [x + root.inertia[i, j] for x, (i, j) in zip(inertia, _SYM)]
    solve = _base_solver(mass + root.mass, first, inertia)
    v0, w0 = solve([_lc(((-1.0, x),)) for x in lin], [_lc(((-1.0, x),)) for x in ang])
    wrenches = _forward(links, cos, sin, dq, ddq, w0, none3, none3)
    tau, f1, n1 = _backward(links, cos, sin, wrenches)
    spin = _cross(w0, _cmv(root.inertia, w0))
    rf = [_lc(((-1.0, x),)) for x in f1]
    rn = [_lc(((-1.0, x), (-1.0, y), (-1.0, z))) for x, y, z in zip(n1, _cross_cv(links[0].pos, f1), spin)]
    a0, alpha0 = solve(rf, rn)
    # joint torques from the spacecraft's acceleration (linear in it): the rigid acceleration
    # carried out to every link, against each outboard composite's unit-rate momentum
    acc, alpha = a0, alpha0
    for j, link in enumerate(links):
        et = link.rot.T
        acc = _rz(cos[j], sin[j], _cmv(et, _add3(acc, _cross_vc(alpha, link.pos), none3)), True)
        alpha = _rz(cos[j], sin[j], _cmv(et, alpha), True)
        kxz, kyz, kzz, hx, hy = columns[j]
        tau[j] = _nz(tau[j]) + kxz * alpha[0] + kyz * alpha[1] + kzz * alpha[2] + hx * acc[1] - hy * acc[0]
    force = [root.mass * x for x in a0]
    moment = _add3(_cmv(root.inertia, alpha0), spin, _cross_cv(c0 - point, force))
    return tau, force, moment, a0 + alpha0, v0 + w0


def rnea(
    model: ArmModel,
    q: ArrayLike,
    dq: ArrayLike,
    ddq: ArrayLike,
    *,
    base: BaseMode = "fixed",
    gravity: ArrayLike | None = None,
    moment_point: ArrayLike | None = None,
) -> InverseDynamics:
    """Recursive Newton-Euler inverse dynamics, batched, with the base reaction wrench.

    Implements 000 eqs. 28-31: inertia force and moment of every link (eq. 28), the
    backward force/moment recursion (eq. 29), and the force and moment at joint 1 moved to
    the spacecraft's centre of mass (eq. 30, ``n_d = n_1 + bP_1 x f_1``; eq. 31
    ``tau_b = n_d``).  Everything is computed in root-frame components with the spacecraft
    attitude taken as the root frame at each instant (the result does not depend on it).
    Samples are flattened and processed in structure-of-arrays layout; the only Python
    loop is over the joints.

    Parameters
    ----------
    model
        The arm; a locked model is handled exactly (it is the full arm with the joint frozen).
    q, dq, ddq
        (..., n) joint angles [rad], rates [rad/s] and accelerations [rad/s^2]; broadcast to
        a common leading batch shape, e.g. (n_candidates, n_time, n).
    base
        ``"fixed"``: the spacecraft is held still (what 000 computes).  ``"floating"``: the
        spacecraft reacts freely and the total momentum stays zero.  Its twist is
        ``nu_0 = -H_b^{-1} h_arm`` (``h_arm``: the arm's momentum with the base still) and its
        acceleration solves the base rows of the system dynamics,
        ``H_b nu0_dot = w_arm(nu0_dot = 0) - [0; omega_0 x I_0 omega_0]``, with ``H_b`` the
        base block of :func:`system_mass_matrix`.  Needs ``model.floating``.
    gravity
        (3,) gravity acceleration in the root frame [m/s^2]; zero (orbit) by default.  Only
        with ``base="fixed"`` (in free fall a uniform field changes no internal wrench).
    moment_point
        (3,) point of the root frame about which the base moment is taken [m]; default the
        root body's centre of mass (the spacecraft's for a free-floating model; the root
        origin for a fixed model without a base body).

    Returns
    -------
    InverseDynamics
        Joint torques (..., n) [N m], base force/moment (..., 3) [N, N m], spacecraft
        acceleration and twist (..., 6).
    """
    from .errors import ModelError

    q = as_joint_array(model, q, "q")
    dq = as_joint_array(model, dq, "dq")
    ddq = as_joint_array(model, ddq, "ddq")
    shape = np.broadcast_shapes(q.shape, dq.shape, ddq.shape)
    batch = shape[:-1]
    if base not in ("fixed", "floating"):
        raise ModelError(f"base must be 'fixed' or 'floating'; got {base!r}")
    if base == "floating" and not model.floating:
        raise ModelError(
            f"base='floating' needs a free-floating model (a spacecraft body); model {model.name!r} "
            "has a fixed base: load it with base='floating'"
        )
    point = model.root_body.com if moment_point is None else np.asarray(moment_point, dtype=float)
    if point.shape != (3,) or not np.all(np.isfinite(point)):
        raise ModelError(
            f"moment_point must be 3 finite numbers [m]; got {np.asarray(moment_point).tolist()}"
        )
    g = np.zeros(3) if gravity is None else np.asarray(gravity, dtype=float)
    if g.shape != (3,) or not np.all(np.isfinite(g)):
        raise ModelError(f"gravity must be 3 finite numbers [m/s^2]; got {np.asarray(gravity).tolist()}")
    if base == "floating" and np.any(g != 0):
        raise ModelError("gravity must be zero with base='floating' (a free-falling system feels none)")

    def flat(x: FloatArray) -> FloatArray:
        return np.ascontiguousarray(np.broadcast_to(x, shape).reshape(-1, shape[-1]).T)

    qf, dqf, ddqf = flat(q), flat(dq), flat(ddq)
    n_samples = qf.shape[1]
    tau, force, moment, acc_base, nu0 = _rnea_rows(model, qf, dqf, ddqf, base, g, point)
    return InverseDynamics(
        *(_rows_out(rows, n_samples, batch) for rows in (tau, force, moment, acc_base, nu0)), point
    )


def joint_torques(
    model: ArmModel,
    q: ArrayLike,
    dq: ArrayLike,
    ddq: ArrayLike,
    *,
    base: BaseMode = "fixed",
    gravity: ArrayLike | None = None,
) -> FloatArray:
    """(..., n) joint torques [N m] by :func:`rnea` (000 eqs. 28-29)."""
    return rnea(model, q, dq, ddq, base=base, gravity=gravity).torques


def base_wrench(
    model: ArmModel,
    q: ArrayLike,
    dq: ArrayLike,
    ddq: ArrayLike,
    *,
    base: BaseMode = "fixed",
    gravity: ArrayLike | None = None,
    moment_point: ArrayLike | None = None,
) -> FloatArray:
    """(..., 6) wrench ``[f_d; n_d]`` [N, N m] the arm exerts on its base (000 eqs. 30-31),
    moment about the spacecraft's centre of mass, root frame.  See :func:`rnea`."""
    return rnea(model, q, dq, ddq, base=base, gravity=gravity, moment_point=moment_point).base_wrench


def _momentum_matrix_soa(model: ArmModel, qf: FloatArray, state: ChainState) -> FloatArray:
    """:func:`jointlock.kinematics.momentum_matrix` as (6, 6 + n, N) for flattened joint
    angles ``qf`` (n, N): composite inertias recursively in link frames, each joint's column
    turned into the root frame once."""
    n = model.dof
    cos, sin = np.cos(qf), np.sin(qf)
    cos2, sin2 = cos * cos - sin * sin, 2.0 * sin * cos
    links = _link_constants(model, np.zeros(3))
    mass, first, inertia, columns, _ = _composite(links, cos, sin, cos2, sin2)
    out = np.zeros((6, 6 + n, qf.shape[1]))
    for j, joint in enumerate(model.joints):
        rot = state.soa_rotations[j]
        qa = _axis_frame(joint.axis)
        if not np.array_equal(qa, np.eye(3)):
            rot = np.matmul(qa.T, rot)  # frame j turned so that its z is the joint axis
        kxz, kyz, kzz, hx, hy = columns[j]
        lin = out[0:3, 6 + j]
        np.multiply(rot[:, 1], hx, out=lin)
        lin -= rot[:, 0] * hy
        ang = out[3:6, 6 + j]
        np.multiply(rot[:, 0], kxz, out=ang)
        ang += rot[:, 1] * kyz
        ang += rot[:, 2] * kzz
        p = state.soa_positions[j]
        ang[0] += p[1] * lin[2] - p[2] * lin[1]
        ang[1] += p[2] * lin[0] - p[0] * lin[2]
        ang[2] += p[0] * lin[1] - p[1] * lin[0]
    root = model.root_body
    m0, r0 = root.mass, root.com
    h = first
    for k in range(3):
        out[k, k] = m0 + mass
        for col in range(3):
            out[3 + k, 3 + col] = root.inertia[k, col]
    for r, (i, j) in enumerate(_SYM):
        out[3 + i, 3 + j] += inertia[r]
        if i != j:
            out[3 + j, 3 + i] += inertia[r]
    # -skew(h - M r0) (linear from omega_0), skew(h + m0 r0) (angular from v_0), skew(h) skew(r0)
    for a, b, c in ((0, 1, 2), (1, 2, 0), (2, 0, 1)):
        lin_w = h[c] - mass * r0[c]
        out[a, 3 + b] += lin_w
        out[b, 3 + a] -= lin_w
        ang_v = h[c] + m0 * r0[c]
        out[3 + a, b] -= ang_v
        out[3 + b, a] += ang_v
    dot = h[0] * r0[0] + h[1] * r0[1] + h[2] * r0[2]
    for a in range(3):  # skew(h) @ skew(r0) = r0 h^T - (h . r0) 1
        for b in range(3):
            out[3 + a, 3 + b] += h[b] * r0[a] - (dot if a == b else 0.0)
    return out
