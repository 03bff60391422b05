"""Batched chain arithmetic shared by :mod:`jointlock.kinematics` and :mod:`jointlock.dynamics`.

Every link is described in its ``z``-joint frame (the joint frame turned by ``Q_i`` so that
the joint axis is ``z``); per-sample quantities are sparse rows (:mod:`jointlock._rows`) with
the batch as the last axis.  This module holds what both the kinematics and the dynamics
need, so that :mod:`jointlock.kinematics` never imports :mod:`jointlock.dynamics`:

* :func:`link_constants`: the per-link constants of a model (cached by the model's numbers,
  never by object identity);
* :func:`composite`: composite inertias of the outboard links, recursively in link frames
  (as in the composite-rigid-body algorithm), used by the momentum matrix and by the
  free-floating Newton-Euler algorithm;
* :func:`momentum_matrix_soa`: the momentum map ``H = [H_b | H_bm]`` of the free-floating
  system;
* :func:`ee_position_rows`: position-only forward kinematics of the tool point.

It imports only numpy, :mod:`jointlock._rows` and the model types.
"""

from __future__ import annotations

import struct
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from ._cache import cached_on
from ._rows import add, add3, cmv, cross_cv, lc, nz, rz
from .model import ArmModel, FloatArray

#: Entries of folded constant matrices and vectors below this (or this close to +-1) are the
#: exact zeros and ones of DH tables [-].
ZERO = 1e-15

#: Order of the six stored entries of a symmetric 3 x 3 matrix.
SYM = ((0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2))

#: Floats per link in the packed model data of :func:`link_constants`: placement (16),
#: axis (3), mass (1), centre of mass (3), inertia (9).
_PER_LINK = 32
#: Distinct (model numbers, origin) pairs whose link constants are kept.
_CACHE_SIZE = 64


def clean(arr: FloatArray) -> FloatArray:
    """``arr`` with entries within :data:`ZERO` of 0, 1 or -1 set to exactly that value."""
    out = np.where(np.abs(arr) < ZERO, 0.0, arr)
    out = np.where(np.abs(out - 1.0) < ZERO, 1.0, out)
    return np.where(np.abs(out + 1.0) < ZERO, -1.0, out)


def axis_frame(axis: FloatArray) -> FloatArray:
    """Rotation ``Q`` with ``Q e_z = axis`` (identity for ``+z``)."""
    a = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    if a[0] == 0.0 and a[1] == 0.0 and a[2] > 0:
        return np.eye(3)
    helper = np.array([1.0, 0.0, 0.0]) if abs(a[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    u = np.cross(helper, a)
    u /= np.linalg.norm(u)
    return np.column_stack([u, np.cross(a, u), a])


@dataclass(frozen=True)
class Link:
    """Constants of one link in its ``z``-joint frame: rotation ``E`` and translation ``p``
    from the parent's frame, mass, centre of mass, inertia about the centre of mass, the
    composite-inertia transform coefficients of :func:`composite`, and the turn ``Q`` from
    the joint frame to the ``z``-joint frame."""

    rot: FloatArray  # E (3, 3)
    pos: FloatArray  # p (3,)
    mass: float
    com: FloatArray
    inertia: FloatArray
    own_first: FloatArray  # m c (3,)
    own_inertia: FloatArray  # inertia about the frame origin (3, 3)
    sym_rot: FloatArray  # (6, 6), see sym_coefficients
    sym_shift: FloatArray  # (6, 3)
    frame: FloatArray  # Q (3, 3)
    turned: bool  # Q is not the identity


def sym_coefficients(e: FloatArray, p: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Coefficients of ``E K E^T`` on the six stored entries of ``K`` (6, 6), and of the
    parallel-axis cross terms ``2 (p.g) 1 - p g^T - g p^T`` with ``g = E h`` on ``h`` (6, 3)."""
    a = np.zeros((6, 6))
    g = np.zeros((6, 3))
    eye = np.eye(3)
    for r, (i, j) in enumerate(SYM):
        for col, (k, l) in enumerate(SYM):
            a[r, col] = e[i, k] * e[j, l] + (e[i, l] * e[j, k] if k != l else 0.0)
        for k in range(3):
            g[r, k] = 2.0 * p[k] * eye[i, j] - p[i] * eye[j, k] - p[j] * eye[i, k]
    a[np.abs(a) < ZERO] = 0.0
    b = g @ e
    b[np.abs(b) < ZERO] = 0.0
    return a, b


def link_constants(model: ArmModel, origin: FloatArray) -> tuple[Link, ...]:
    """Per-link constants of ``model``; the parent of link 1 is the root frame moved to
    ``origin`` (3,) [m].

    The result is a pure function of the model's numbers (placements, axes, masses, centres
    of mass, inertias) and ``origin``; it is cached under those numbers, so two models with
    the same numbers share an entry and no entry can be mistaken for another model's."""
    parts = [np.asarray(origin, dtype=float).reshape(3).tobytes()]
    for joint, body in zip(model.joints, model.bodies):
        parts += (
            joint.placement.tobytes(),
            joint.axis.tobytes(),
            struct.pack("d", body.mass),
            body.com.tobytes(),
            body.inertia.tobytes(),
        )
    return _link_constants(b"".join(parts))


@lru_cache(maxsize=_CACHE_SIZE)
def _link_constants(data: bytes) -> tuple[Link, ...]:
    packed = np.frombuffer(data, dtype=float)
    origin = packed[:3]
    links = []
    q_prev = np.eye(3)
    for i, row in enumerate(packed[3:].reshape(-1, _PER_LINK)):
        placement = row[:16].reshape(4, 4)
        axis, mass, com_j, inertia_j = row[16:19], float(row[19]), row[20:23], row[23:32].reshape(3, 3)
        qi = axis_frame(axis)
        pos = placement[:3, 3] - (origin if i == 0 else 0.0)
        e = clean(q_prev.T @ placement[:3, :3] @ qi)
        com = qi.T @ com_j
        inertia = qi.T @ inertia_j @ qi
        own = inertia + mass * (com @ com * np.eye(3) - np.outer(com, com))
        p = q_prev.T @ pos
        turned = not np.array_equal(qi, np.eye(3))
        link = Link(e, p, mass, com, inertia, mass * com, own, *sym_coefficients(e, p), qi, turned)
        for value in vars(link).values():
            if isinstance(value, np.ndarray):
                value.setflags(write=False)  # shared by every caller through the cache
        links.append(link)
        q_prev = qi
    return tuple(links)


# -- composite inertias (composite-rigid-body algorithm, batch last) -------------------------


def move_inertia(link, c, s, cos2, sin2, mass, first, inertia, own_inertia, own_first):
    """Move a composite body (mass, first moment and inertia about its frame origin, rows,
    in the frame of ``link``) into the parent frame of ``link``, about the parent origin,
    and add the parent's own constant inertia and first moment."""
    xx, yy, zz, xy, xz, yz = inertia
    tot, dif = xx + yy, xx - yy
    rxx = 0.5 * tot + (0.5 * cos2) * dif - sin2 * xy
    rot_k = (rxx, tot - rxx, zz, (0.5 * sin2) * dif + cos2 * xy, c * xz - s * yz, s * xz + c * yz)
    hz = rz(c, s, first)
    a, b, p = link.sym_rot, link.sym_shift, link.pos
    const = mass * (p @ p * np.eye(3) - np.outer(p, p)) + own_inertia
    new_inertia = [
        nz(lc([(a[r, k], rot_k[k]) for k in range(6)] + [(b[r, k], hz[k]) for k in range(3)], const[i, j]))
        for r, (i, j) in enumerate(SYM)
    ]
    new_first = [
        nz(lc([(link.rot[r, k], hz[k]) for k in range(3)], mass * p[r] + own_first[r])) for r in range(3)
    ]
    return new_first, new_inertia


def move_momentum(link, c, s, ang, lin):
    """Move a momentum (angular about the frame origin, linear) into the parent frame."""
    lin = cmv(link.rot, rz(c, s, lin))
    ang = add3(cmv(link.rot, rz(c, s, ang)), cross_cv(link.pos, lin), [None] * 3)
    return ang, lin


def composite(links, cos, sin, cos2, sin2, dq=None):
    """Composite inertia of the links outboard of every joint, recursively in link frames
    (as in the composite-rigid-body algorithm), and the momentum of the arm on a still base.

    Returns ``(mass, first, inertia, columns, momentum)``: the arm's mass, first moment (3
    rows) and inertia (6 rows, order :data:`SYM`) about the parent origin of link 1, in its
    frame; per link ``j`` the momentum (angular about origin ``j``, linear; frame ``j``) of
    the outboard composite turning at unit rate about joint ``j``, as 5 rows
    ``(K_xz, K_yz, K_zz, h_x, h_y)`` (angular ``K e_z``, linear ``e_z x h``); and, with
    ``dq``, the arm's momentum ``(L, P)`` (rows, parent frame of link 1, ``L`` about its
    origin), else ``None``."""
    n = len(links)
    columns = [None] * n
    last = links[-1]
    mass = last.mass
    inertia = [float(last.own_inertia[i, j]) for i, j in SYM]
    first = [float(x) for x in last.own_first]
    momentum = None
    for j in range(n - 1, -1, -1):
        if j < n - 1:
            nxt = links[j + 1]
            first, inertia = move_inertia(
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
                momentum = move_momentum(nxt, cos[j + 1], sin[j + 1], *momentum)
        col = (inertia[4], inertia[5], inertia[2], first[0], first[1])
        columns[j] = col
        if dq is not None:
            d = dq[j]
            own = ([col[0] * d, col[1] * d, col[2] * d], [-col[4] * d, col[3] * d, None])
            momentum = (
                own
                if momentum is None
                else tuple([add(x, y) for x, y in zip(u, v)] for u, v in zip(momentum, own))
            )
    zero3 = np.zeros(3)
    first, inertia = move_inertia(
        links[0], cos[0], sin[0], cos2[0], sin2[0], mass, first, inertia, np.zeros((3, 3)), zero3
    )
    if momentum is not None:
        momentum = move_momentum(links[0], cos[0], sin[0], *momentum)
    return mass, first, inertia, columns, momentum


def momentum_matrix_soa(
    model: ArmModel, qf: FloatArray, soa_rotations: FloatArray, soa_positions: FloatArray
) -> FloatArray:
    """:func:`jointlock.kinematics.momentum_matrix` as (6, 6 + n, N) for flattened joint
    angles ``qf`` (n, N) and the frames at them (``ChainState.soa_rotations`` (n, 3, 3, N),
    ``soa_positions`` (n, 3, N)): composite inertias recursively in link frames, each
    joint's column turned into the root frame once."""
    n = model.dof
    cos, sin = np.cos(qf), np.sin(qf)
    cos2, sin2 = cos * cos - sin * sin, 2.0 * sin * cos
    links = link_constants(model, np.zeros(3))
    mass, first, inertia, columns, _ = composite(links, cos, sin, cos2, sin2)
    out = np.zeros((6, 6 + n, qf.shape[1]))
    for j, link in enumerate(links):
        rot = soa_rotations[j]
        if link.turned:
            rot = np.matmul(link.frame.T, rot)  # frame j turned so that its z is the joint axis
        kxz, kyz, kzz, hx, hy = columns[j]
        lin = out[0:3, 6 + j]
        np.multiply(rot[:, 1], hx, out=lin)
        lin -= rot[:, 0] * hy
        ang = out[3:6, 6 + j]
        np.multiply(rot[:, 0], kxz, out=ang)
        ang += rot[:, 1] * kyz
        ang += rot[:, 2] * kzz
        p = soa_positions[j]
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
    for r, (i, j) in enumerate(SYM):
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


# -- position-only forward kinematics -------------------------------------------------------


def _constant_row(x: float):
    return None if x == 0.0 else float(x)


def position_program(model: ArmModel) -> tuple[list[tuple[FloatArray, list]], list]:
    """Constants of the tool point's chain: per joint ``(E_i, p_i)`` (``p_i`` as constant rows)
    with ``v_i = p_i + E_i Rz(q_i) v_{i+1}``, and the tool point ``v_n`` in the last
    ``z``-joint frame as constant rows (zeros as ``None``); ``v_1`` is the end effector in
    the root frame.  Entries within :data:`ZERO` of 0 or +-1 are snapped, as in the DH tables."""
    links = link_constants(model, np.zeros(3))
    steps = [(link.rot, [_constant_row(x) for x in clean(link.pos)]) for link in links]
    tool = clean(links[-1].frame.T @ model.tool[:3, 3])
    return steps, [_constant_row(x) for x in tool]


def ee_position_rows(program: tuple[list[tuple[FloatArray, list]], list], q: FloatArray) -> list:
    """Rows of the end-effector position for joint angles ``q`` (N, n) [rad], by the chain
    from the tool back to the root (:func:`position_program`).  A joint whose axis carries
    the point (e.g. the last joint of a spherical wrist) is skipped, its sine and cosine
    never computed; constant rows stay floats and zero rows ``None``."""
    steps, v = program
    for i in range(len(steps) - 1, -1, -1):
        mat, off = steps[i]
        if v[0] is not None or v[1] is not None:  # else the point is on this joint's axis
            v = rz(np.cos(q[:, i]), np.sin(q[:, i]), v)
        v = [lc(((mat[k, 0], v[0]), (mat[k, 1], v[1]), (mat[k, 2], v[2])), nz(off[k])) for k in range(3)]
        v = [None if isinstance(x, float) and x == 0.0 else x for x in v]
    return v


def kernel_program(model: ArmModel) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """The chain as the compiled kernels (:mod:`jointlock._kernels`) take it: ``E_i`` (n, 3, 3),
    ``p_i`` (n, 3) [m], the tool point in the last ``z``-joint frame (3,) [m] (the numbers of
    :func:`position_program`), and (n,) bool: joint ``i`` cannot move the tool point (the
    joints :func:`ee_position_rows` skips).  Computed once per model and shared: the kernels
    only read these arrays (writable, so that numba keeps one specialisation per kernel)."""
    return cached_on(model, "kernel_program", lambda: _kernel_program(model))


def _kernel_program(model: ArmModel) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    steps, tool_rows = position_program(model)
    rot = np.ascontiguousarray([mat for mat, _ in steps], dtype=float)
    pos = np.array([[0.0 if x is None else x for x in off] for _, off in steps], dtype=float)
    tool = np.array([0.0 if x is None else x for x in tool_rows], dtype=float)
    skip = np.zeros(len(steps), dtype=bool)
    zero = [x is None for x in tool_rows]  # which components are exactly zero for every q
    for i in range(len(steps) - 1, -1, -1):
        skip[i] = zero[0] and zero[1]
        if not skip[i]:
            zero[0] = zero[1] = False
        mat, off = steps[i]
        zero = [off[k] is None and all(mat[k, j] == 0.0 or zero[j] for j in range(3)) for k in range(3)]
    return rot, pos, tool, skip


def kernel_input(x: FloatArray) -> FloatArray:
    """``x`` as every compiled kernel takes its arrays: C-contiguous, writable float64 (a copy
    only where it is not), so that numba compiles one specialisation per kernel, not one per
    memory layout (read-only, broadcast, Fortran-ordered or integer input)."""
    if isinstance(x, np.ndarray) and x.dtype == np.float64 and x.flags.c_contiguous and x.flags.writeable:
        return x  # at once: the jump integrator passes its arrays once per control step
    return np.require(x, dtype=float, requirements=["C", "W"])


def kernel_mass_program(model: ArmModel) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """The masses for :func:`jointlock._kernels.generalized_jacobian`: per link mass (n,),
    centre of mass (n, 3) [m] and inertia about it (n, 3, 3) [kg m^2] in its ``z``-joint
    frame, and the spacecraft's mass, centre of mass and inertia (root frame) packed (13,).
    Computed once per model and shared, as :func:`kernel_program`."""

    def compute() -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
        _rot, _pos, mass, com, inertia = kernel_link_arrays(model, np.zeros(3))
        return mass, com, inertia, kernel_root(model)

    return cached_on(model, "kernel_mass_program", compute)


def kernel_link_arrays(model: ArmModel, origin: FloatArray) -> tuple[FloatArray, ...]:
    """The links of :func:`link_constants` (parent of link 1 moved to ``origin`` (3,) [m]) as
    the Newton-Euler kernels (:mod:`jointlock._kernels._dynamics`) take them: ``E`` (n, 3, 3),
    ``p`` (n, 3) [m], mass (n,) [kg], centre of mass (n, 3) [m], inertia (n, 3, 3) [kg m^2].
    Made once per model and origin and shared (a halt case asks for them ~10 times, 0.3 ms
    each): writable, as every kernel takes its arrays (:func:`kernel_input`), and never written."""
    at = np.asarray(origin, dtype=float).reshape(3)

    def compute() -> tuple[FloatArray, ...]:
        links = link_constants(model, at)
        return (
            np.ascontiguousarray([link.rot for link in links], dtype=float),
            np.ascontiguousarray([link.pos for link in links], dtype=float),
            np.array([link.mass for link in links], dtype=float),
            np.ascontiguousarray([link.com for link in links], dtype=float),
            np.ascontiguousarray([link.inertia for link in links], dtype=float),
        )

    return cached_on(model, "kernel_link_arrays_" + at.tobytes().hex(), compute)


def kernel_root(model: ArmModel) -> FloatArray:
    """(13,) the root body's (spacecraft's) mass [kg], centre of mass (3) [m] and inertia
    about it (9, row-major) [kg m^2], root frame, as the kernels take them."""
    root = model.root_body
    return np.concatenate([[float(root.mass)], root.com, np.asarray(root.inertia, dtype=float).reshape(9)])
