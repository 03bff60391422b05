"""Batched rigid-body dynamics (zero gravity unless stated).

Mass matrices here are built from the centre-of-mass Jacobians (composite form).
:func:`rnea` is the recursive Newton-Euler algorithm of 000 eqs. 28-31, batched over any
leading shape (time samples and candidate trajectories at once), giving the joint torques
and the wrench the arm exerts on its base, with the base held fixed (000) or free-floating
(zero momentum, the spacecraft reacts).

:func:`rnea` runs in numpy, or in compiled kernels (numba, :mod:`jointlock._kernels`) from
:data:`jointlock.forward.COMPILED_MIN_BATCH` samples on or with ``compiled=True``: 3-5x
faster than numpy, the same numbers to round-off (README, "Speed").
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike

from . import forward as _fk
from ._chain import SYM, composite, kernel_input, kernel_link_arrays, kernel_root, link_constants
from ._rows import add, add3, cmv, cross, cross_cv, cross_vc, lc, mul, nz, rz, sub
from .bounds import check_overflow
from .compiled import use_compiled
from .errors import ConfigurationError, ModelError
from .kinematics import ChainState, _world_inertias, com_jacobians, com_positions, state_at
from .model import ArmModel, FloatArray, as_joint_array
from .spatial import skew


def mass_matrix(model: ArmModel, q: ArrayLike | None, state: ChainState | None = None) -> FloatArray:
    """Joint-space mass matrix of the arm on a fixed base.

    ``M(q) = sum_i m_i Jv_i^T Jv_i + Jw_i^T I_i Jw_i`` over the links (root body excluded).

    Parameters
    ----------
    q
        (..., n) joint angles [rad].
    state
        Precomputed :func:`jointlock.kinematics.chain_state` at ``q`` (optional); it must
        have been computed at ``q`` (see :func:`jointlock.kinematics.state_at`), and with it
        ``q=None`` means ``state.q``.

    Returns
    -------
    (..., n, n) [kg m^2], symmetric positive definite when every link has mass and inertia.
    """
    s = state_at(model, q, state)
    jcom = com_jacobians(model, s.q, s)
    masses = np.array([b.mass for b in model.bodies])
    inertia_w = _world_inertias(model, s)
    jv, jw = jcom[..., :3, :], jcom[..., 3:, :]
    return np.einsum("n,...nij,...nik->...jk", masses, jv, jv) + np.einsum(
        "...nij,...nil,...nlk->...jk", jw, inertia_w, jw
    )


def system_mass_matrix(model: ArmModel, q: ArrayLike | None, state: ChainState | None = None) -> FloatArray:
    """Mass matrix of the free-floating system in the coordinates ``(v_0, omega_0, dq)``
    (spacecraft centre-of-mass velocity, its angular velocity, joint rates; root frame).
    ``state``: a :func:`jointlock.kinematics.chain_state` at ``q`` (optional; see
    :func:`jointlock.kinematics.state_at`).

    Returns
    -------
    (..., 6 + n, 6 + n) [kg, kg m, kg m^2 blocks]; the kinetic energy is
    ``0.5 x^T M x`` with ``x = [v_0; omega_0; dq]``.
    """
    s = state_at(model, q, state)
    n = model.dof
    batch = s.positions.shape[:-2]
    coms = com_positions(model, s.q, s)
    jcom = com_jacobians(model, s.q, s)
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
# Per-sample quantities are sparse rows (see :mod:`jointlock._rows`): one (N,) array per
# component, ``None`` for an exactly zero component; constant matrices are applied entry by
# entry.  Link frames are turned so that every joint turns about its own ``z``
# (:func:`jointlock._chain.link_constants`).


def _forward(links, cos, sin, dq, ddq, w, wd, a):
    """Forward Newton-Euler recursion (000 eq. 28) in link frames: inertia force and moment
    (rows) of every link.  ``w``, ``wd``, ``a``: angular velocity, angular acceleration and
    origin acceleration of the parent of link 1, in its frame."""
    out = []
    for i, link in enumerate(links):
        c, s = cos[i], sin[i]
        ap = add3(a, cross_vc(wd, link.pos), cross(w, cross_vc(w, link.pos)))
        et = link.rot.T
        wu = rz(c, s, cmv(et, w), True)
        wdu = rz(c, s, cmv(et, wd), True)
        a = rz(c, s, cmv(et, ap), True)
        w = [wu[0], wu[1], add(wu[2], dq[i])]
        wd = [add(wdu[0], mul(wu[1], dq[i])), sub(wdu[1], mul(wu[0], dq[i])), add(wdu[2], ddq[i])]
        acc = add3(a, cross_vc(wd, link.com), cross(w, cross_vc(w, link.com)))
        force = [lc(((link.mass, x),)) for x in acc]
        moment = [add(x, y) for x, y in zip(cmv(link.inertia, wd), cross(w, cmv(link.inertia, w)))]
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
        nm_own = add3(moment, cross_cv(links[i].com, force), [None] * 3)
        if f is None:
            f, nm = force, nm_own
        else:
            nxt = links[i + 1]
            fr = cmv(nxt.rot, rz(cos[i + 1], sin[i + 1], f))
            nr = cmv(nxt.rot, rz(cos[i + 1], sin[i + 1], nm))
            f = [add(x, y) for x, y in zip(force, fr)]
            nm = add3(nm_own, nr, cross_cv(nxt.pos, fr))
        tau[i] = nm[2]
    first = links[0]
    return tau, cmv(first.rot, rz(cos[0], sin[0], f)), cmv(first.rot, rz(cos[0], sin[0], nm))


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
        raise ModelError(_SINGULAR_SYSTEM)
    inv_det = 1.0 / det

    def solve(rf, rn):
        b = [nz(x) - im * nz(y) for x, y in zip(rn, cross(first, rf))]
        alpha = [
            (cxx * b[0] + cxy * b[1] + cxz * b[2]) * inv_det,
            (cxy * b[0] + cyy * b[1] + cyz * b[2]) * inv_det,
            (cxz * b[0] + cyz * b[1] + czz * b[2]) * inv_det,
        ]
        lin = [(nz(x) + nz(y)) * im for x, y in zip(rf, cross(first, alpha))]
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
        links = link_constants(model, np.zeros(3))
        acc0 = [None if x == 0.0 else -float(x) for x in g]  # gravity as an upward base acceleration
        wrenches = _forward(links, cos, sin, dq, ddq, none3, none3, acc0)
        tau, f1, n1 = _backward(links, cos, sin, wrenches)
        force = [lc(((-1.0, x),)) for x in f1]
        moment = [lc(((-1.0, x), (-1.0, y))) for x, y in zip(n1, cross_cv(links[0].pos - point, f1))]
        zero6 = [None] * 6
        return tau, force, moment, zero6, zero6
    root = model.root_body
    c0 = root.com
    links = link_constants(model, c0)
    cos2, sin2 = cos * cos - sin * sin, 2.0 * sin * cos
    mass, first, inertia, columns, (ang, lin) = composite(links, cos, sin, cos2, sin2, dq)
    inertia = [x + root.inertia[i, j] for x, (i, j) in zip(inertia, SYM)]
    solve = _base_solver(mass + root.mass, first, inertia)
    v0, w0 = solve([lc(((-1.0, x),)) for x in lin], [lc(((-1.0, x),)) for x in ang])
    wrenches = _forward(links, cos, sin, dq, ddq, w0, none3, none3)
    tau, f1, n1 = _backward(links, cos, sin, wrenches)
    spin = cross(w0, cmv(root.inertia, w0))
    rf = [lc(((-1.0, x),)) for x in f1]
    rn = [lc(((-1.0, x), (-1.0, y), (-1.0, z))) for x, y, z in zip(n1, cross_cv(links[0].pos, f1), spin)]
    a0, alpha0 = solve(rf, rn)
    # joint torques from the spacecraft's acceleration (linear in it): the rigid acceleration
    # carried out to every link, against each outboard composite's unit-rate momentum
    acc, alpha = a0, alpha0
    for j, link in enumerate(links):
        et = link.rot.T
        acc = rz(cos[j], sin[j], cmv(et, add3(acc, cross_vc(alpha, link.pos), none3)), True)
        alpha = rz(cos[j], sin[j], cmv(et, alpha), True)
        kxz, kyz, kzz, hx, hy = columns[j]
        tau[j] = nz(tau[j]) + kxz * alpha[0] + kyz * alpha[1] + kzz * alpha[2] + hx * acc[1] - hy * acc[0]
    force = [root.mass * x for x in a0]
    moment = add3(cmv(root.inertia, alpha0), spin, cross_cv(c0 - point, force))
    return tau, force, moment, a0 + alpha0, v0 + w0


#: Samples per pass of the compiled Newton-Euler kernels: inputs that are not C-contiguous
#: float64 (or not writable) are copied a chunk at a time (broadcast ones once, whole).
_COMPILED_CHUNK = 65536

#: What a free-floating system whose inertia about its centre of mass is singular gets.
_SINGULAR_SYSTEM = (
    "the free-floating system's rotational inertia about its centre of "
    "mass is singular (e.g. collinear point masses on a point-mass spacecraft); the base "
    "reaction is undefined"
)


def _rnea_compiled(model, q, dq, ddq, shape, base, g, point):
    """:func:`rnea` by the compiled kernels, in chunks of :data:`_COMPILED_CHUNK` samples:
    (torques, base wrench, base acceleration, base twist) as (N, .) arrays."""
    from . import _kernels  # numba is imported on first use, not with the package

    n = shape[-1]
    n_samples = int(np.prod(shape[:-1], dtype=np.int64))
    if n_samples <= _COMPILED_CHUNK:
        # one block for the four results: the allocator keeps it for the next call (four such
        # blocks went back to the OS, and the next call faulted fresh pages in: 5 of 14 ms at
        # 50 x 1001 samples); up to a chunk only, as one result kept keeps the whole block
        buf = np.empty(n_samples * (n + 18))
        tau = buf[: n_samples * n].reshape(n_samples, n)
        wrench, acc, twist = (buf[n_samples * (n + 6 * k) : n_samples * (n + 6 * k + 6)].reshape(-1, 6) for k in range(3))
        if base == "fixed":  # the kernel writes them free-floating only
            acc[:] = twist[:] = 0.0
    else:
        tau, wrench = np.empty((n_samples, n)), np.empty((n_samples, 6))
        acc, twist = np.zeros((n_samples, 6)), np.zeros((n_samples, 6))
    # a view of an input that has the full shape (writable: no copy below), else its broadcast
    bq, bdq, bddq = (
        (x if x.shape == shape else np.broadcast_to(x, shape)).reshape(-1, n) for x in (q, dq, ddq)
    )
    root = model.root_body
    point = np.array(point, dtype=float)  # writable, contiguous: one numba specialisation
    if base == "fixed":
        links = kernel_link_arrays(model, np.zeros(3))
        base_acc = -g  # gravity as an upward base acceleration
    else:
        links = kernel_link_arrays(model, root.com)
        packed = kernel_root(model)
    bad = 0
    for s0 in range(0, n_samples, _COMPILED_CHUNK):
        part = slice(s0, s0 + _COMPILED_CHUNK)
        cq, cdq, cddq = (kernel_input(x[part]) for x in (bq, bdq, bddq))
        if base == "fixed":
            _kernels.rnea_fixed(cq, cdq, cddq, *links, base_acc, point, tau[part], wrench[part])
        else:
            bad += _kernels.rnea_floating(
                cq, cdq, cddq, *links, packed, point, tau[part], wrench[part], acc[part], twist[part]
            )
    if bad:
        raise ModelError(_SINGULAR_SYSTEM)
    return tau, wrench, acc, twist


def _three_numbers(value: ArrayLike, name: str, unit: str) -> FloatArray:
    """``value`` as (3,) finite floats, or :class:`ModelError` naming ``name``."""
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        arr = np.full(1, np.nan)
    if arr.shape != (3,) or not np.all(np.isfinite(arr)):
        raise ModelError(f"{name} must be 3 finite numbers [{unit}]; got {str(value)[:80]}")
    return arr


def rnea(
    model: ArmModel,
    q: ArrayLike,
    dq: ArrayLike,
    ddq: ArrayLike,
    *,
    base: BaseMode = "fixed",
    gravity: ArrayLike | None = None,
    moment_point: ArrayLike | None = None,
    compiled: bool | None = None,
) -> InverseDynamics:
    """Recursive Newton-Euler inverse dynamics, batched, with the base reaction wrench.

    Implements 000 eqs. 28-31: inertia force and moment of every link (eq. 28), the
    backward force/moment recursion (eq. 29), and the force and moment at joint 1 moved to
    the spacecraft's centre of mass (eq. 30, ``n_d = n_1 + bP_1 x f_1``; eq. 31
    ``tau_b = n_d``).  Everything is computed in root-frame components with the spacecraft
    attitude taken as the root frame at each instant (the result does not depend on it).
    Samples are flattened and processed in structure-of-arrays layout; the numpy path
    loops in Python over the joints only, the compiled one over chunks of samples.

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
    compiled
        True: the compiled kernels (:mod:`jointlock._kernels`, numba; the same numbers to
        round-off); False: the numpy implementation (the reference the kernels are tested
        against); None (default): the kernels from :data:`jointlock.forward.COMPILED_MIN_BATCH`
        (200,000) samples on, where they win back numba's start-up (0.4-2 s per process).  Pass True
        when calling many times in one process (an optimiser scoring candidates).

    Returns
    -------
    InverseDynamics
        Joint torques (..., n) [N m], base force/moment (..., 3) [N, N m], spacecraft
        acceleration and twist (..., 6).
    """
    q = as_joint_array(model, q, "q")
    dq = as_joint_array(model, dq, "dq")
    ddq = as_joint_array(model, ddq, "ddq")
    try:
        shape = np.broadcast_shapes(q.shape, dq.shape, ddq.shape)
    except ValueError:
        raise ConfigurationError(
            f"q, dq and ddq must have broadcastable batch shapes; got {q.shape}, {dq.shape} and {ddq.shape}"
        ) from None
    batch = shape[:-1]
    if base not in ("fixed", "floating"):
        raise ModelError(f"base must be 'fixed' or 'floating'; got {base!r}")
    if base == "floating" and not model.floating:
        raise ModelError(
            f"base='floating' needs a free-floating model (a spacecraft body); model {model.name!r} "
            "has a fixed base: load it with base='floating'"
        )
    point = model.root_body.com if moment_point is None else _three_numbers(moment_point, "moment_point", "m")
    g = np.zeros(3) if gravity is None else _three_numbers(gravity, "gravity", "m/s^2")
    if base == "floating" and np.any(g != 0):
        raise ModelError("gravity must be zero with base='floating' (a free-falling system feels none)")

    n_samples = int(np.prod(batch, dtype=np.int64))
    if compiled is None:
        compiled = use_compiled(n_samples, _fk.COMPILED_MIN_BATCH)
    elif not isinstance(compiled, (bool, np.bool_)):
        raise ConfigurationError(f"compiled must be True, False or None; got {compiled!r}")
    if compiled:
        with np.errstate(over="ignore", invalid="ignore"):  # finite inputs that overflow: said below
            tau_c, wrench_c, acc_c, twist_c = _rnea_compiled(model, q, dq, ddq, shape, base, g, point)
        check_overflow((tau_c, wrench_c, acc_c, twist_c), "rnea", dq=dq, ddq=ddq)
        return InverseDynamics(
            tau_c.reshape(shape),
            wrench_c[:, :3].reshape(batch + (3,)),
            wrench_c[:, 3:].reshape(batch + (3,)),
            acc_c.reshape(batch + (6,)),
            twist_c.reshape(batch + (6,)),
            point,
        )

    def flat(x: FloatArray) -> FloatArray:
        return np.ascontiguousarray(np.broadcast_to(x, shape).reshape(-1, shape[-1]).T)

    qf, dqf, ddqf = flat(q), flat(dq), flat(ddq)
    with np.errstate(over="ignore", invalid="ignore"):  # finite inputs whose products overflow: said below
        rows = _rnea_rows(model, qf, dqf, ddqf, base, g, point)
    check_overflow(rows, "rnea", dq=dqf, ddq=ddqf)
    tau, force, moment, acc_base, nu0 = rows
    return InverseDynamics(
        _rows_out(tau, n_samples, batch),
        _rows_out(force, n_samples, batch),
        _rows_out(moment, n_samples, batch),
        _rows_out(acc_base, n_samples, batch),
        _rows_out(nu0, n_samples, batch),
        point,
    )


def joint_torques(
    model: ArmModel,
    q: ArrayLike,
    dq: ArrayLike,
    ddq: ArrayLike,
    *,
    base: BaseMode = "fixed",
    gravity: ArrayLike | None = None,
    compiled: bool | None = None,
) -> FloatArray:
    """(..., n) joint torques [N m] by :func:`rnea` (000 eqs. 28-29)."""
    return rnea(model, q, dq, ddq, base=base, gravity=gravity, compiled=compiled).torques


def base_wrench(
    model: ArmModel,
    q: ArrayLike,
    dq: ArrayLike,
    ddq: ArrayLike,
    *,
    base: BaseMode = "fixed",
    gravity: ArrayLike | None = None,
    moment_point: ArrayLike | None = None,
    compiled: bool | None = None,
) -> FloatArray:
    """(..., 6) wrench ``[f_d; n_d]`` [N, N m] the arm exerts on its base (000 eqs. 30-31),
    moment about the spacecraft's centre of mass, root frame.  See :func:`rnea`."""
    return rnea(
        model, q, dq, ddq, base=base, gravity=gravity, moment_point=moment_point, compiled=compiled
    ).base_wrench
