"""Forward kinematics, batched: every frame of a chain (:func:`chain_state`), the end-effector
pose, and the end-effector position alone (:func:`ee_positions`).

Every function takes joint arrays of shape ``(..., n)`` (any leading batch shape) and loops
only over the ``n`` joints, never over samples; results are in the root (base) frame.  A
:class:`ChainState` remembers the joint angles it was computed at, and the functions taking
``q`` and ``state=`` (:mod:`jointlock.kinematics`, :mod:`jointlock.dynamics`,
:mod:`jointlock.derivatives`) use it only at those angles (:func:`state_at`).

Every name here is also importable from :mod:`jointlock.kinematics`.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import numpy as np
from numpy.typing import ArrayLike

from ._chain import ee_position_rows, kernel_input, kernel_program, position_program
from .compiled import use_compiled
from .errors import ConfigurationError
from .model import ArmModel, FloatArray, as_joint_array
from .spatial import pose, skew

#: Default samples per vectorised pass of :func:`ee_positions` (keeps the working set in cache).
DEFAULT_CHUNK = 65536
#: Batches from this many configurations on go to the compiled kernels (:mod:`jointlock._kernels`)
#: by default; smaller ones stay on numpy.  Importing numba and loading the cached kernels
#: costs a process 0.4-0.7 s on an idle core (about 2 s on a busy one; LLVM start-up), which the
#: kernels win back only on large batches (HCOM's K = 36,000 saves ~0.1 s); the first
#: compilation on a machine 5-25 s (README, "Speed").
COMPILED_MIN_BATCH = 200_000
#: ... and from this many for :func:`ee_positions`, whose numpy path is already ~0.4 us per
#: point: the kernel saves ~0.3 us per point, so it wins back numba's start-up (0.4-2 s) only
#: on millions of points (a 200,000-sample workspace stays on numpy).
COMPILED_MIN_POSITIONS = 4_000_000


@dataclass(frozen=True)
class ChainState:
    """Frames of a chain for a batch of configurations (all in the root frame).

    The frames are computed and stored with the batch as the *last* axis ("structure of
    arrays": every arithmetic step runs over one contiguous vector per matrix entry, which
    is several times faster than small-matrix products per sample).  The attributes below
    give them in the usual batch-first layout (computed once, on first access).

    A state belongs to the joint angles it was computed at, :attr:`q`.  Every function that
    takes ``q`` and ``state=`` uses the state only for those angles: it raises
    :class:`~jointlock.errors.ConfigurationError` unless ``q`` has the shape of ``state.q``
    and exactly its values (``np.array_equal``: no tolerance), and accepts ``q=None`` to
    mean ``state.q`` (see :func:`state_at`).

    Attributes
    ----------
    q
        (..., n) the joint angles [rad] the frames were computed at (a read-only copy).
    rotations
        (..., n, 3, 3) orientation of every link frame.
    positions
        (..., n, 3) origin of every link frame [m]; it lies on the joint axis.
    axes
        (..., n, 3) unit joint axes.
    ee_rotation, ee_position
        (..., 3, 3) and (..., 3) [m]: the end-effector frame.
    """

    batch_shape: tuple[int, ...]
    soa_rotations: FloatArray  # (n, 3, 3, N)
    soa_positions: FloatArray  # (n, 3, N)
    soa_axes: FloatArray  # (n, 3, N)
    soa_ee_rotation: FloatArray  # (3, 3, N)
    soa_ee_position: FloatArray  # (3, N)
    q: FloatArray  # (..., n), read-only
    model: ArmModel | None = field(default=None, repr=False, compare=False)  # the arm it belongs to

    def _batch_first(self, soa: FloatArray) -> FloatArray:
        return np.ascontiguousarray(np.moveaxis(soa, -1, 0)).reshape(self.batch_shape + soa.shape[:-1])

    @cached_property
    def rotations(self) -> FloatArray:
        return self._batch_first(self.soa_rotations)

    @cached_property
    def positions(self) -> FloatArray:
        return self._batch_first(self.soa_positions)

    @cached_property
    def axes(self) -> FloatArray:
        return self._batch_first(self.soa_axes)

    @cached_property
    def ee_rotation(self) -> FloatArray:
        return self._batch_first(self.soa_ee_rotation)

    @cached_property
    def ee_position(self) -> FloatArray:
        return self._batch_first(self.soa_ee_position)

    @staticmethod
    def select(mask: ArrayLike, a: ChainState, b: ChainState) -> ChainState:
        """Per-sample choice: ``a`` where ``mask`` (batch shape) is true, else ``b`` (the
        joint angles :attr:`q` chosen alike)."""
        m = np.asarray(mask, dtype=bool).reshape(-1)
        q = np.where(m.reshape(a.batch_shape)[..., None], a.q, b.q)
        q.setflags(write=False)
        rotations, positions, axes, ee_rotation, ee_position = (
            np.where(m, x, y)
            for x, y in zip(
                (a.soa_rotations, a.soa_positions, a.soa_axes, a.soa_ee_rotation, a.soa_ee_position),
                (b.soa_rotations, b.soa_positions, b.soa_axes, b.soa_ee_rotation, b.soa_ee_position),
            )
        )
        return ChainState(a.batch_shape, rotations, positions, axes, ee_rotation, ee_position, q, a.model)


def _kinematic_key(model: ArmModel) -> bytes:
    """What a chain state depends on: every joint's placement and axis, and the tool."""
    return b"".join(j.placement.tobytes() + j.axis.tobytes() for j in model.joints) + model.tool.tobytes()


def _rotate_soa(matrix: FloatArray, soa: FloatArray) -> FloatArray:
    """``soa[r, j, N] @ matrix[j, k]`` for every sample: (3, 3, N) -> (3, 3, N)."""
    return np.matmul(matrix.T, soa)


def chain_state(model: ArmModel, q: ArrayLike) -> ChainState:
    """Forward kinematics of every frame.

    Parameters
    ----------
    model
        The arm.
    q
        (..., n) joint angles [rad].

    Notes
    -----
    Frame ``i`` is ``R_{i-1} P_i Rot(axis_i, q_i)``.  For a joint about ``z`` the rotation
    only mixes the first two columns of ``A = R_{i-1} P_i``; for any other axis Rodrigues'
    formula ``A (I + sin q K + (1 - cos q) K^2)`` is used.  No loop over samples.
    """
    q = as_joint_array(model, q)
    n = model.dof
    batch = q.shape[:-1]
    flat = q.reshape(-1, n).T  # (n, N)
    count = flat.shape[1]
    cos, sin = np.cos(flat), np.sin(flat)
    rotations = np.empty((n, 3, 3, count))
    positions = np.empty((n, 3, count))
    axes = np.empty((n, 3, count))
    rot: FloatArray | None = None
    pos: FloatArray | None = None
    for i, joint in enumerate(model.joints):
        place_rot, place_pos = joint.placement[:3, :3], joint.placement[:3, 3]
        if rot is None:
            a = np.broadcast_to(place_rot[:, :, None], (3, 3, count))
            positions[i] = place_pos[:, None]
        else:
            a = _rotate_soa(place_rot, rot)
            positions[i] = pos + np.einsum("rjN,j->rN", rot, place_pos)
        out = rotations[i]
        axis = joint.axis
        if axis[0] == 0.0 and axis[1] == 0.0 and axis[2] > 0:  # about +z: the DH case
            np.multiply(a[:, 0], cos[i], out=out[:, 0])
            out[:, 0] += a[:, 1] * sin[i]
            np.multiply(a[:, 1], cos[i], out=out[:, 1])
            out[:, 1] -= a[:, 0] * sin[i]
            out[:, 2] = a[:, 2]
            axes[i] = a[:, 2]
        else:
            k = skew(axis)
            out[...] = a + sin[i] * _rotate_soa(k, a) + (1.0 - cos[i]) * _rotate_soa(k @ k, a)
            axes[i] = np.einsum("rjN,j->rN", out, axis)
        rot, pos = rotations[i], positions[i]
    assert rot is not None and pos is not None  # a chain has joints (q.reshape(-1, 0) refuses none)
    tool = model.tool
    ee_rot = _rotate_soa(tool[:3, :3], rot)
    ee_pos = pos + np.einsum("rjN,j->rN", rot, tool[:3, 3])
    q_at = q.copy()
    q_at.setflags(write=False)
    return ChainState(batch, rotations, positions, axes, ee_rot, ee_pos, q_at, model)


def state_at(model: ArmModel, q: ArrayLike | None, state: ChainState | None = None) -> ChainState:
    """The chain state at ``q``: ``state`` when given, else :func:`chain_state`.

    This is the rule of every function taking ``q`` and ``state=``: a state is used only
    for the joint angles it was computed at.

    Parameters
    ----------
    model
        The arm.
    q
        (..., n) joint angles [rad], or None to take ``state.q``.
    state
        A :func:`chain_state` of ``model`` (optional).

    Raises
    ------
    ConfigurationError
        When both are None, when ``state`` has another number of joints than ``model``, or
        when ``state`` was computed at other joint angles than ``q`` (``state.q`` and ``q``
        differ in shape or in any value: compared exactly, ``np.array_equal``).
    """
    if state is None:
        if q is None:
            raise ConfigurationError("give the joint angles q or a precomputed state (chain_state(model, q))")
        return chain_state(model, q)
    if not isinstance(state, ChainState):
        raise ConfigurationError(
            f"state must be a ChainState (chain_state(model, q)); got {type(state).__name__}"
        )
    if state.soa_axes.shape[0] != model.dof:
        raise ConfigurationError(
            f"state has {state.soa_axes.shape[0]} joints but model {model.name!r} has {model.dof}"
        )
    if state.model is not None and state.model is not model and _kinematic_key(state.model) != _kinematic_key(model):
        raise ConfigurationError(
            f"state was computed for another arm ({state.model.name!r}, locked "
            f"{[lj.number for lj in state.model.locked]}) than {model.name!r} (locked "
            f"{[lj.number for lj in model.locked]}): pass chain_state(model, q) of this model"
        )
    if q is None or q is state.q:
        return state
    try:
        arr = np.asarray(q, dtype=float)
    except (TypeError, ValueError):
        arr = as_joint_array(model, q)  # raises, naming q
    if arr.shape != state.q.shape or not (arr == state.q).all():  # np.array_equal, without its overhead
        detail = (
            f"shape {arr.shape} vs {state.q.shape}"
            if arr.shape != state.q.shape
            else f"largest difference {float(np.max(np.abs(arr - state.q))):.3g} rad"
        )
        raise ConfigurationError(
            f"state was computed at other joint angles than q ({detail}): pass the state of q "
            "(chain_state(model, q)), or q=None where the function allows it (state.q is used)"
        )
    return state


def ee_positions(
    model: ArmModel, q: ArrayLike, *, chunk: int = DEFAULT_CHUNK, compiled: bool | None = None
) -> FloatArray:
    """End-effector positions only, fast (compiled; several times faster than
    :func:`chain_state`).

    The chain is run from the tool back to the root, by the compiled kernel
    :func:`jointlock._kernels.ee_positions` for batches of :data:`COMPILED_MIN_POSITIONS`
    configurations or more (SIMD across configurations, branch-free sine and cosine within
    1 ulp of libm's), else by its numpy reference :func:`jointlock._chain.ee_position_rows`
    (constant entries of the placements folded once per model); a joint that cannot move
    the tool point (e.g. the last joint of a spherical wrist) is skipped.

    Parameters
    ----------
    model
        Any chain (locked joints included).
    q
        (..., n) joint angles [rad].
    chunk
        Samples per pass (>= 1); only the (N, 3) result grows with the batch.
    compiled
        True: the compiled kernel at any size; False: the numpy reference; None (default):
        the kernel from :data:`COMPILED_MIN_POSITIONS` configurations on.

    Returns
    -------
    (..., 3) end-effector positions in the root frame [m]; equal to
    ``ee_pose(model, q)[..., :3, 3]`` to round-off.
    """
    q = as_joint_array(model, q)
    if isinstance(chunk, bool) or not isinstance(chunk, (int, np.integer)) or chunk < 1:
        raise ConfigurationError(f"chunk must be an integer >= 1; got {chunk!r}")
    flat = kernel_input(q.reshape(-1, model.dof))
    out = np.empty((flat.shape[0], 3))
    if compiled is None:
        compiled = use_compiled(flat.shape[0], COMPILED_MIN_POSITIONS)
    elif not isinstance(compiled, (bool, np.bool_)):
        raise ConfigurationError(f"compiled must be True, False or None; got {compiled!r}")
    if compiled:
        from . import _kernels  # numba is imported on first use, not with the package

        rot, pos, tool, skip = kernel_program(model)
        for s0 in range(0, flat.shape[0], int(chunk)):
            _kernels.ee_positions(flat[s0 : s0 + chunk], rot, pos, tool, skip, out[s0 : s0 + chunk])
    else:  # the numpy reference of the kernel, row by row
        program = position_program(model)
        for s0 in range(0, flat.shape[0], int(chunk)):
            part = flat[s0 : s0 + chunk]
            for k, row in enumerate(ee_position_rows(program, part)):
                out[s0 : s0 + part.shape[0], k] = 0.0 if row is None else row
    return out.reshape(q.shape[:-1] + (3,))


def link_poses(model: ArmModel, q: ArrayLike) -> FloatArray:
    """(..., n, 4, 4) pose of every link frame in the root frame [m]."""
    s = chain_state(model, q)
    return pose(s.rotations, s.positions)


def ee_pose(model: ArmModel, q: ArrayLike) -> FloatArray:
    """(..., 4, 4) end-effector pose in the root frame [m].

    Batches larger than :data:`DEFAULT_CHUNK` configurations are computed a chunk at a time,
    so that memory holds the poses and one chunk's frames, not every frame of the batch
    (:func:`chain_state` of 10^7 configurations of a 7-joint arm would take 8 GB)."""
    arr = as_joint_array(model, q)
    flat = arr.reshape(-1, model.dof)
    if flat.shape[0] <= DEFAULT_CHUNK:
        s = chain_state(model, arr)
        return pose(s.ee_rotation, s.ee_position)
    out = np.empty((flat.shape[0], 4, 4))
    for s0 in range(0, flat.shape[0], DEFAULT_CHUNK):
        s = chain_state(model, flat[s0 : s0 + DEFAULT_CHUNK])
        out[s0 : s0 + DEFAULT_CHUNK] = pose(s.ee_rotation, s.ee_position)
    return out.reshape(arr.shape[:-1] + (4, 4))
