"""Batched rigid-body dynamics (zero gravity unless stated).

Mass matrices here are built from the centre-of-mass Jacobians (composite form).
:func:`rnea` is the recursive Newton-Euler algorithm of 000 eqs. 28-31, batched over any
leading shape (time samples and candidate trajectories at once), giving the joint torques
and the wrench the arm exerts on its base, with the base held fixed (000) or free-floating
(zero momentum, the spacecraft reacts).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike

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
    return hm - np.swapaxes(hbm, -1, -2) @ np.linalg.solve(hb, hbm)


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


def _cross(a: FloatArray, b: FloatArray) -> FloatArray:
    """Cross product of (3, N) component arrays (rows contiguous)."""
    return np.stack([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])


def _mv(r: FloatArray, v: FloatArray) -> FloatArray:
    """Per-sample matrix (3, 3, N) times vector (3, N)."""
    return r[:, 0] * v[0] + r[:, 1] * v[1] + r[:, 2] * v[2]


def _mtv(r: FloatArray, v: FloatArray) -> FloatArray:
    """Per-sample transposed matrix (3, 3, N) times vector (3, N)."""
    return r[0] * v[0] + r[1] * v[1] + r[2] * v[2]


def _mc(r: FloatArray, c: FloatArray) -> FloatArray:
    """Per-sample matrix (3, 3, N) times a constant matrix (3, 3) -> (3, 3, N); zero
    entries of the (usually sparse, DH-built) constant are skipped."""
    return np.stack([_mvc(r, c[:, col]) for col in range(3)], axis=1)


def _mvc(r: FloatArray, v: FloatArray) -> FloatArray:
    """Per-sample matrix (3, 3, N) times a constant vector (3,) -> (3, N), zeros skipped."""
    out = None
    for k in range(3):
        if v[k] != 0.0:
            term = r[:, k] if v[k] == 1.0 else r[:, k] * v[k]
            out = term if out is None else out + term
    return np.zeros(r.shape[::2]) if out is None else out


class _Kinematics:
    """Root-frame link kinematics in structure-of-arrays layout for N flattened samples."""

    def __init__(self, model: ArmModel, q: FloatArray) -> None:
        n_samples = q.shape[1]
        self.rot: list[FloatArray] = []  # (3, 3, N) link frame orientation
        self.pos: list[FloatArray] = []  # (3, N) link frame origin (on the joint axis)
        self.axis: list[FloatArray] = []  # (3, N) joint axis
        self.com: list[FloatArray] = []  # (3, N) centre of mass minus origin
        rot = np.broadcast_to(np.eye(3)[:, :, None], (3, 3, n_samples))
        pos = np.zeros((3, n_samples))
        for i, (joint, body) in enumerate(zip(model.joints, model.bodies)):
            pl = joint.placement
            pos = pos + _mvc(rot, pl[:3, 3])
            rp = _mc(rot, pl[:3, :3])
            a = joint.axis
            z = _mvc(rp, a)
            c, sn = np.cos(q[i]), np.sin(q[i])
            if np.array_equal(a, [0.0, 0.0, 1.0]):  # DH joints: rotate the first two columns
                x_col = c * rp[:, 0] + sn * rp[:, 1]
                y_col = c * rp[:, 1] - sn * rp[:, 0]
                rot = np.stack([x_col, y_col, rp[:, 2]], axis=1)
            else:  # Rodrigues: R(a, q) = c I + s [a]x + (1 - c) a a^T
                rot = c * rp + sn * _mc(rp, skew(a)) + (1.0 - c) * z[:, None, :] * a[None, :, None]
            self.rot.append(rot)
            self.pos.append(pos)
            self.axis.append(z)
            self.com.append(_mvc(rot, body.com))

    def inertia_times(self, i: int, inertia: FloatArray, v: FloatArray) -> FloatArray:
        """World inertia of link ``i`` times v: ``R I R^T v`` (3, N)."""
        return _mv(self.rot[i], inertia @ _mtv(self.rot[i], v))


def _forward(
    model: ArmModel,
    kin: _Kinematics,
    dq: FloatArray,
    ddq: FloatArray,
    omega0: FloatArray,
    acc0: FloatArray,
) -> tuple[list[FloatArray], list[FloatArray]]:
    """Forward Newton-Euler recursion (000 eq. 28): inertia force and moment of every link
    (3, N), root frame; the root frame turns at ``omega0`` with no angular acceleration and
    its origin accelerates at ``acc0``."""
    w, wd, acc = omega0, np.zeros_like(omega0), acc0
    prev = np.zeros((3, 1))
    forces, moments = [], []
    for i, body in enumerate(model.bodies):
        z, p, r = kin.axis[i], kin.pos[i], kin.com[i]
        d = p - prev
        acc = acc + _cross(wd, d) + _cross(w, _cross(w, d))  # origin i is fixed on body i-1
        wz = z * dq[i]
        wd = wd + z * ddq[i] + _cross(w, wz)
        w = w + wz
        acc_c = acc + _cross(wd, r) + _cross(w, _cross(w, r))
        forces.append(body.mass * acc_c)
        moments.append(
            kin.inertia_times(i, body.inertia, wd) + _cross(w, kin.inertia_times(i, body.inertia, w))
        )
        prev = p
    return forces, moments


def _backward(
    kin: _Kinematics, forces: list[FloatArray], moments: list[FloatArray]
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Backward recursion (000 eq. 29): joint torques (n, N), and the force ``f_1`` and the
    moment ``n_1`` about joint 1's origin (3, N) that the root body exerts on link 1."""
    n = len(forces)
    f = np.zeros_like(forces[0])
    nm = np.zeros_like(forces[0])
    p_next = kin.pos[-1]
    torques = np.empty((n,) + forces[0].shape[1:])
    for i in range(n - 1, -1, -1):
        p = kin.pos[i]
        nm = moments[i] + _cross(kin.com[i], forces[i]) + _cross(p_next - p, f) + nm
        f = forces[i] + f
        torques[i] = np.einsum("in,in->n", kin.axis[i], nm)
        p_next = p
    return torques, f, nm


def _floating_base(
    model: ArmModel, kin: _Kinematics, dq: FloatArray
) -> tuple[FloatArray, FloatArray, list[FloatArray]]:
    """Zero-momentum spacecraft twist (6, N) and base inertia ``H_b`` (N, 6, 6) about the
    spacecraft's centre of mass ``c_0``, plus every link's centre of mass minus ``c_0``."""
    n_samples = dq.shape[1]
    c0 = model.root_body.com[:, None]
    hb = np.zeros((n_samples, 6, 6))
    hb[:, :3, :3] = model.root_body.mass * np.eye(3)
    hb[:, 3:, 3:] = model.root_body.inertia
    lin = np.zeros((3, n_samples))
    ang = np.zeros((3, n_samples))
    w = np.zeros((3, n_samples))
    v = np.zeros((3, n_samples))
    prev = np.zeros((3, 1))
    rel = []
    for i, body in enumerate(model.bodies):
        m = body.mass
        p, r, z = kin.pos[i], kin.com[i], kin.axis[i]
        v = v + _cross(w, p - prev)
        w = w + z * dq[i]
        vc = v + _cross(w, r)
        rc = p + r - c0
        rel.append(rc)
        lin = lin + m * vc
        ang = ang + kin.inertia_times(i, body.inertia, w) + m * _cross(rc, vc)
        sk = skew(rc.T)  # (N, 3, 3)
        rot = np.moveaxis(kin.rot[i], -1, 0)
        hb[:, :3, :3] += m * np.eye(3)
        hb[:, :3, 3:] -= m * sk
        hb[:, 3:, :3] += m * sk
        hb[:, 3:, 3:] += rot @ body.inertia @ np.swapaxes(rot, -1, -2) - m * sk @ sk
        prev = p
    h_arm = np.concatenate([lin, ang]).T  # (N, 6) momentum of the arm, base still
    nu0 = -np.linalg.solve(hb, h_arm[..., None])[..., 0].T
    return nu0, hb, rel


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
    kin = _Kinematics(model, qf)
    p1 = kin.pos[0]
    pt = point[:, None]
    if base == "fixed":
        acc0 = np.broadcast_to(-g[:, None], (3, n_samples))  # gravity as an upward base acceleration
        forces, moments = _forward(model, kin, dqf, ddqf, np.zeros((3, n_samples)), acc0)
        tau, f1, n1 = _backward(kin, forces, moments)
        force = -f1
        moment = -(n1 + _cross(p1 - pt, f1))
        acc_base = np.zeros((6, n_samples))
        nu0 = np.zeros((6, n_samples))
    else:
        nu0, hb, rel = _floating_base(model, kin, dqf)
        w0 = nu0[3:]
        c0 = model.root_body.com[:, None]
        acc_origin = _cross(w0, _cross(w0, np.broadcast_to(-c0, (3, n_samples))))
        forces, moments = _forward(model, kin, dqf, ddqf, w0, acc_origin)
        f_tot = -sum(forces)
        n_tot = -sum(m + _cross(r, f) for m, r, f in zip(moments, rel, forces))
        rhs = np.concatenate([f_tot, n_tot - _cross(w0, model.root_body.inertia @ w0)]).T
        acc_base = np.linalg.solve(hb, rhs[..., None])[..., 0].T  # (6, N)
        a0, alpha0 = acc_base[:3], acc_base[3:]
        for i, body in enumerate(model.bodies):  # add the base acceleration (linear in it)
            forces[i] = forces[i] + body.mass * (a0 + _cross(alpha0, rel[i]))
            moments[i] = moments[i] + kin.inertia_times(i, body.inertia, alpha0)
        tau, f1, n1 = _backward(kin, forces, moments)
        force = -f1
        moment = -(n1 + _cross(p1 - pt, f1))

    def unflat(x: FloatArray) -> FloatArray:
        return np.ascontiguousarray(x.T).reshape(batch + (x.shape[0],))

    return InverseDynamics(unflat(tau), unflat(force), unflat(moment), unflat(acc_base), unflat(nu0), point)


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
