"""The one internal form of an arm: an immutable serial chain of revolute joints and rigid bodies.

Conventions (see ``docs/conventions.md``):

* Frame ``i`` is attached to the body carried by joint ``i``.  Its pose in the parent frame
  (frame ``i-1``, or the root frame for the first joint) is ``placement_i @ Rot(axis_i, q_i)``:
  a fixed 4x4 placement followed by the joint rotation about a unit ``axis`` expressed in the
  joint frame (``z`` for every DH-built model).
* The root frame is the chain's base frame.  With a fixed base it is the inertial frame.  With
  a free-floating base it is attached to the spacecraft body (``root_body``), whose centre of
  mass and inertia are expressed in it.
* Joints keep the number they had in the full arm (1-based, as in the papers) even after other
  joints are locked; ``ArmModel.joint_numbers`` lists them.
* SI units and radians everywhere.

Models never change: :func:`jointlock.locking.lock` and :meth:`ArmModel.with_base` return new
models.  Arrays stored in models are read-only.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from typing import cast

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .bounds import MAX_INERTIA_KGM2, MAX_MASS_KG, MAX_MODEL_LENGTH_M, shown
from .errors import ConfigurationError, ModelError
from .shapes import Shape, check_shapes, with_link

FloatArray = NDArray[np.float64]

#: Relative tolerance on the symmetry of an inertia tensor [-].
INERTIA_SYMMETRY_RTOL = 1e-9
#: Smallest eigenvalue accepted for a non-zero inertia tensor, relative to its largest [-]:
#: positive semi-definite up to round-off (a merged pair of point masses has a zero moment).
INERTIA_EIGEN_RTOL = -1e-12


def _readonly(array: ArrayLike) -> FloatArray:
    out = np.array(array, dtype=float)
    out.setflags(write=False)
    return out


def _vector3(value: ArrayLike, name: str) -> FloatArray:
    arr = np.asarray(value, dtype=float)
    if arr.shape != (3,) or not np.all(np.isfinite(arr)):
        raise ModelError(f"{name} must be 3 finite numbers [m]; got {shown(np.asarray(value).tolist())}")
    if np.any(np.abs(arr) > MAX_MODEL_LENGTH_M):
        raise ModelError(f"{name} must lie within +-{MAX_MODEL_LENGTH_M:g} m; got {shown(arr.tolist())}")
    return arr


def _transform(value: ArrayLike, name: str) -> FloatArray:
    arr = np.asarray(value, dtype=float)
    if arr.shape != (4, 4) or not np.all(np.isfinite(arr)):
        raise ModelError(f"{name} must be a finite 4x4 homogeneous transform; got shape {arr.shape}")
    if np.any(np.abs(arr[:3, 3]) > MAX_MODEL_LENGTH_M):
        raise ModelError(
            f"{name}: the translation must lie within +-{MAX_MODEL_LENGTH_M:g} m; got {shown(arr[:3, 3].tolist())}"
        )
    rot = arr[:3, :3]
    if not np.allclose(rot @ rot.T, np.eye(3), atol=1e-9) or np.linalg.det(rot) < 0:
        raise ModelError(f"{name}: the upper-left 3x3 block is not a rotation matrix")
    if not np.allclose(arr[3], [0.0, 0.0, 0.0, 1.0]):
        raise ModelError(f"{name}: the last row of a homogeneous transform must be [0, 0, 0, 1]")
    return arr


def inertia_matrix(value: ArrayLike, name: str = "inertia") -> FloatArray:
    """Return a 3x3 inertia tensor from 3 principal moments, 6 values or a 3x3 matrix.

    Parameters
    ----------
    value
        ``[Ixx, Iyy, Izz]``, ``[Ixx, Iyy, Izz, Ixy, Ixz, Iyz]`` or a 3x3 matrix [kg m^2].
    name
        Name used in error messages.
    """
    arr = np.asarray(value, dtype=float)
    if arr.shape == (3,):
        mat = np.diag(arr)
    elif arr.shape == (6,):
        ixx, iyy, izz, ixy, ixz, iyz = arr
        mat = np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])
    elif arr.shape == (3, 3):
        mat = arr.copy()
    else:
        raise ModelError(
            f"{name} must be [Ixx, Iyy, Izz], [Ixx, Iyy, Izz, Ixy, Ixz, Iyz] or a 3x3 matrix "
            f"[kg m^2]; got shape {arr.shape}"
        )
    return mat


@dataclass(frozen=True)
class Body:
    """A rigid body: mass [kg], centre of mass ``com`` (3,) [m] and inertia (3, 3) [kg m^2]
    about the centre of mass, both expressed in the body's own frame, and its collision
    ``shapes`` (:mod:`jointlock.shapes`, in the same frame; none by default)."""

    mass: float
    com: FloatArray = field(default_factory=lambda: _readonly(np.zeros(3)))
    inertia: FloatArray = field(default_factory=lambda: _readonly(np.zeros((3, 3))))
    name: str = ""
    shapes: tuple[Shape, ...] = field(default=(), compare=False)

    def __post_init__(self) -> None:
        label = f"body {shown(self.name)}" if self.name else "body"
        mass = float(self.mass)
        if not math.isfinite(mass) or not 0 <= mass <= MAX_MASS_KG:
            raise ModelError(f"{label}: mass must be a number in [0, {MAX_MASS_KG:g}] kg; got {shown(self.mass)}")
        com = _vector3(self.com, f"{label}: com")
        inertia = inertia_matrix(self.inertia, f"{label}: inertia")
        if not np.all(np.isfinite(inertia)) or np.any(np.abs(inertia) > MAX_INERTIA_KGM2):
            raise ModelError(
                f"{label}: inertia must be finite, each entry within +-{MAX_INERTIA_KGM2:g} kg m^2; "
                f"got {shown(inertia.tolist())}"
            )
        scale = max(float(np.max(np.abs(inertia))), 1e-300)
        if not np.allclose(inertia, inertia.T, rtol=0, atol=INERTIA_SYMMETRY_RTOL * scale):
            raise ModelError(f"{label}: inertia must be symmetric; got {inertia.tolist()}")
        if np.any(inertia != 0):
            eig = np.linalg.eigvalsh(inertia)
            if eig[0] < INERTIA_EIGEN_RTOL * eig[-1]:
                raise ModelError(
                    f"{label}: inertia must be positive semi-definite (all zero for a point mass); "
                    f"got eigenvalues {np.round(eig, 12).tolist()} [kg m^2]"
                )
        object.__setattr__(self, "mass", mass)
        object.__setattr__(self, "shapes", check_shapes(self.shapes, label))
        object.__setattr__(self, "com", _readonly(com))
        object.__setattr__(self, "inertia", _readonly(0.5 * (inertia + inertia.T)))

    def transformed(self, pose: ArrayLike) -> Body:
        """The same body expressed in another frame; ``pose`` (4, 4) is T_new_old."""
        pose = np.asarray(pose, dtype=float)
        rot = pose[:3, :3]
        shapes = tuple(s.transformed(pose) for s in self.shapes)
        return Body(self.mass, rot @ self.com + pose[:3, 3], rot @ self.inertia @ rot.T, self.name, shapes)

    def merged(self, other: Body, pose_other: ArrayLike | None = None, name: str = "") -> Body:
        """Merge ``other`` (expressed in a frame whose pose in this body's frame is
        ``pose_other``, (4, 4)) into this body: total mass, mass-weighted centre of mass,
        inertias moved to the common centre of mass by the parallel-axis theorem after
        rotating ``other`` into this frame (000 §3.1.1, items 1-3, with the rotation made
        explicit).  The merged body carries both bodies' shapes, ``other``'s moved into this
        frame."""
        if pose_other is not None:
            other = other.transformed(pose_other)
        total = self.mass + other.mass
        # two massless bodies may still carry rotational inertia (a rotor, a URDF link with
        # mass 0): it adds as it is, about any point (the parallel-axis terms vanish)
        com = self.com if total == 0 else (self.mass * self.com + other.mass * other.com) / total
        inertia = (
            self.inertia
            + _parallel_axis(self.mass, self.com - com)
            + other.inertia
            + _parallel_axis(other.mass, other.com - com)
        )
        return Body(total, com, inertia, name or self.name, self.shapes + other.shapes)


def _parallel_axis(mass: float, offset: FloatArray) -> FloatArray:
    return mass * (float(offset @ offset) * np.eye(3) - np.outer(offset, offset))


@dataclass(frozen=True)
class Joint:
    """A revolute joint.

    Attributes
    ----------
    placement
        (4, 4) pose of the joint frame in the parent frame at ``q = 0`` [m].
    axis
        (3,) unit rotation axis in the joint frame.
    lower, upper
        Position limits [rad].
    velocity_limit
        Speed limit [rad/s] (``inf`` when unknown).
    number
        The joint's number in the full arm, 1-based as in the papers.
    name
        Free text (URDF joint name, ``"joint3"``, ...).
    effort_limit
        The motor's torque limit [N m] (``inf`` when unknown; URDF ``<limit effort>``).
    """

    placement: FloatArray
    axis: FloatArray = field(default_factory=lambda: _readonly([0.0, 0.0, 1.0]))
    lower: float = -math.pi
    upper: float = math.pi
    velocity_limit: float = math.inf
    number: int = 0
    name: str = ""
    effort_limit: float = math.inf

    def __post_init__(self) -> None:
        label = self.name or f"joint {self.number}"
        placement = _transform(self.placement, f"{label}: placement")
        axis = np.asarray(self.axis, dtype=float)
        if axis.shape != (3,) or not np.all(np.isfinite(axis)) or np.max(np.abs(axis)) < 1e-12:
            raise ModelError(f"{label}: axis must be a non-zero 3-vector; got {shown(axis.tolist())}")
        if not 1e-100 < np.max(np.abs(axis)) < 1e100:  # a direction: rescaled, so that its norm cannot overflow
            axis = axis / np.max(np.abs(axis))
        lower, upper = float(self.lower), float(self.upper)
        if math.isnan(lower) or math.isnan(upper) or lower > upper or lower == math.inf or upper == -math.inf:
            raise ModelError(
                f"{label}: limits must satisfy lower <= upper [rad], lower < inf, upper > -inf; got [{lower}, {upper}]"
            )
        if not (self.velocity_limit > 0):
            raise ModelError(f"{label}: velocity_limit must be > 0 [rad/s]; got {self.velocity_limit}")
        object.__setattr__(self, "placement", _readonly(placement))
        object.__setattr__(self, "axis", _readonly(axis / np.linalg.norm(axis)))
        object.__setattr__(self, "lower", lower)
        object.__setattr__(self, "upper", upper)
        if not (self.effort_limit > 0):
            raise ModelError(f"{label}: effort_limit must be > 0 [N m]; got {self.effort_limit}")
        object.__setattr__(self, "velocity_limit", float(self.velocity_limit))
        object.__setattr__(self, "effort_limit", float(self.effort_limit))
        object.__setattr__(self, "name", self.name or f"joint{self.number}")


@dataclass(frozen=True)
class LockedJoint:
    """Record of a joint folded into the chain: its number (1-based) and angle [rad]."""

    number: int
    angle: float


@dataclass(frozen=True)
class ArmModel:
    """An immutable serial chain of revolute joints.

    Attributes
    ----------
    name
        Model name.
    joints
        The movable joints, from the base outwards.
    bodies
        ``bodies[i]`` is carried by ``joints[i]`` and expressed in frame ``i``.
    tool
        (4, 4) pose of the end-effector frame in the last joint's frame [m].
    root_body
        The body rigidly attached to the root frame.  For a free-floating arm it is the
        spacecraft (its mass must be positive); for a fixed arm it is the mounting (often
        massless) and plays no part in dynamics.
    floating
        True for a free-floating spacecraft base, False for a fixed base.
    locked
        The joints that were folded into this chain, in the order they were locked.
    description
        Free text: where the numbers come from and the readings chosen.
    unlocked
        The arm before any lock (same base), kept by :func:`jointlock.locking.lock` so that
        the locked joints' brake torques can be computed (None for an arm without locks, or
        when unknown).  Not compared.
    disabled_pairs
        Pairs of shape names (URDF link names) whose clearance is never checked: an SRDF's
        ``<disable_collisions>`` (:func:`jointlock.io.srdf.read_srdf`,
        :func:`jointlock.geometry.with_disabled_pairs`), each pair sorted.  Not compared.
    unread_meshes
        The URDF ``<collision>`` meshes that could not be read (each ``"link: why"``: the
        ``mesh`` extra missing, a file not found or not readable).  The model is usable for
        everything but its clearance, which it refuses in one line naming them
        (:func:`jointlock.collision.collision_pairs`) until they are read or left out on purpose
        (``meshes="skip"``).  Not compared.
    """

    name: str
    joints: tuple[Joint, ...]
    bodies: tuple[Body, ...]
    tool: FloatArray = field(default_factory=lambda: _readonly(np.eye(4)))
    root_body: Body = field(default_factory=lambda: Body(0.0, name="root"))
    floating: bool = False
    locked: tuple[LockedJoint, ...] = ()
    description: str = ""
    unlocked: ArmModel | None = field(default=None, compare=False, repr=False)
    disabled_pairs: tuple[tuple[str, str], ...] = field(default=(), compare=False, repr=False)
    unread_meshes: tuple[str, ...] = field(default=(), compare=False, repr=False)

    def __post_init__(self) -> None:
        joints = tuple(self.joints)
        bodies = tuple(self.bodies)
        for what, text in [("model name", self.name)] + [("joint name", j.name) for j in joints] + [
            ("body name", b.name) for b in bodies
        ]:
            if not isinstance(text, str) or any(ord(c) < 32 or 127 <= ord(c) < 160 for c in text):
                raise ModelError(
                    f"{what} {shown(text)} must be text without control characters (they would "
                    "reach the terminal and the reports)"
                )
        if len(joints) != len(bodies):
            raise ModelError(
                f"model {shown(self.name)}: {len(joints)} joints but {len(bodies)} bodies; "
                "each joint carries exactly one body"
            )
        numbers = [j.number for j in joints]
        if len(set(numbers)) != len(numbers):
            raise ModelError(f"model {shown(self.name)}: joint numbers must be unique; got {numbers}")
        if self.floating and self.root_body.mass <= 0:
            raise ModelError(
                f"model {shown(self.name)}: a free-floating base needs a spacecraft body with mass > 0 "
                f"[kg]; got {self.root_body.mass}"
            )
        # each shape remembers the link it was made for (0: the root body), whatever is
        # merged later: it decides the pairs checked and names them (jointlock.collision)
        bodies = tuple(
            b if all(s.link is not None for s in b.shapes) else replace(b, shapes=with_link(b.shapes, j.number))
            for j, b in zip(joints, bodies)
        )
        if any(s.link is None for s in self.root_body.shapes):
            object.__setattr__(self, "root_body", replace(self.root_body, shapes=with_link(self.root_body.shapes, 0)))
        object.__setattr__(self, "joints", joints)
        object.__setattr__(self, "bodies", bodies)
        object.__setattr__(self, "tool", _readonly(_transform(self.tool, f"model {shown(self.name)}: tool")))
        object.__setattr__(self, "locked", tuple(self.locked))
        pairs = []
        for pair in self.disabled_pairs:
            if not (isinstance(pair, (tuple, list)) and len(pair) == 2 and all(isinstance(n, str) for n in pair)):
                raise ModelError(f"model {shown(self.name)}: disabled_pairs must be pairs of shape names; got {shown(pair)}")
            pairs.append(tuple(sorted(pair)))
        object.__setattr__(self, "disabled_pairs", tuple(sorted(set(pairs))))

    def __repr__(self) -> str:
        """One line (the arrays stay in the fields): name, joints, locks, base and mass."""
        locked = ", ".join(f"{lj.number}: {math.degrees(lj.angle):.6g} deg" for lj in self.locked)
        base = f"floating on a {self.root_body.mass:.6g} kg spacecraft" if self.floating else "fixed base"
        locks = f", locked {{{locked}}}" if locked else ""
        return f"ArmModel({self.name!r}, {self.dof} movable joints {list(self.joint_numbers)}{locks}, {base}, links {float(self.masses.sum()):.6g} kg)"

    # -- sizes and limits -------------------------------------------------------------
    @property
    def dof(self) -> int:
        """Number of movable joints."""
        return len(self.joints)

    @property
    def joint_numbers(self) -> tuple[int, ...]:
        """1-based numbers (full-arm numbering) of the movable joints, in chain order."""
        return tuple(j.number for j in self.joints)

    @property
    def lower(self) -> FloatArray:
        """(n,) lower position limits [rad]."""
        return _readonly([j.lower for j in self.joints])

    @property
    def upper(self) -> FloatArray:
        """(n,) upper position limits [rad]."""
        return _readonly([j.upper for j in self.joints])

    def angle_range(self) -> tuple[FloatArray, FloatArray]:
        """(n,) lower and upper angles [rad] that cover every angle each joint can take once:
        its limits as given (past +-pi too: a multi-turn joint is sampled over all its turns); a
        side without a limit one turn from the other; a joint without limits (continuous) one
        turn, [-pi, pi].  What sampling and search starts draw from."""
        lo, hi = np.array(self.lower), np.array(self.upper)
        free = ~np.isfinite(lo) & ~np.isfinite(hi)
        lo[free], hi[free] = -math.pi, math.pi
        lo = np.where(np.isfinite(lo), lo, hi - 2.0 * math.pi)
        hi = np.where(np.isfinite(hi), hi, lo + 2.0 * math.pi)
        return _readonly(lo), _readonly(hi)

    @property
    def masses(self) -> FloatArray:
        """(n,) link masses [kg] (root body excluded)."""
        return _readonly([b.mass for b in self.bodies])

    @property
    def total_mass(self) -> float:
        """Mass of the links plus the root body [kg]."""
        return float(sum(b.mass for b in self.bodies) + self.root_body.mass)

    @property
    def full_dof(self) -> int:
        """Number of joints of the arm before any lock."""
        return self.dof + len(self.locked)

    def index_of(self, number: int) -> int:
        """0-based position in this chain of the joint numbered ``number`` (1-based)."""
        for i, joint in enumerate(self.joints):
            if joint.number == number:
                return i
        locked = [lj.number for lj in self.locked]
        extra = f" (joint {number} is locked)" if number in locked else ""
        raise ModelError(
            f"joint must be one of the movable joints {list(self.joint_numbers)} of model "
            f"{shown(self.name)}; got {shown(number)}{extra}"
        )

    # -- variants ---------------------------------------------------------------------
    def with_base(self, spacecraft: Body | None) -> ArmModel:
        """A free-floating copy with ``spacecraft`` as the root body, or a fixed-base copy
        when ``spacecraft`` is None.  The spacecraft's centre of mass and inertia are given
        in the root frame."""
        if spacecraft is None:
            return self.fixed()
        # joint 1 locked: link 1 was merged into the old root body, which is replaced here
        keeps_links = all(lj.number != 1 for lj in self.locked)
        full = self.unlocked.with_base(spacecraft) if self.unlocked is not None and keeps_links else None
        return replace(self, root_body=spacecraft, floating=True, unlocked=full)

    def fixed(self) -> ArmModel:
        """Fixed-base copy (the root body is kept but plays no part in dynamics)."""
        return replace(self, floating=False, unlocked=None if self.unlocked is None else self.unlocked.fixed())

    def expand(self, q: ArrayLike) -> FloatArray:
        """Insert the locked joints' angles into a healthy-joint vector.

        Parameters
        ----------
        q
            (..., n) angles of this model's movable joints [rad].

        Returns
        -------
        (..., n + n_locked) angles in full-arm order (joint numbers ascending) [rad].
        """
        q = as_joint_array(self, q)
        numbers = list(self.joint_numbers) + [lj.number for lj in self.locked]
        order = np.argsort(numbers)
        locked_vals = np.broadcast_to(
            np.array([lj.angle for lj in self.locked], dtype=float), q.shape[:-1] + (len(self.locked),)
        )
        return np.concatenate([q, locked_vals], axis=-1)[..., order]

    def healthy(self, q_full: ArrayLike) -> FloatArray:
        """The movable joints' entries of a full-arm vector (..., n_full) -> (..., n)."""
        q_full = np.asarray(q_full, dtype=float)
        numbers = sorted(list(self.joint_numbers) + [lj.number for lj in self.locked])
        if q_full.shape[-1] != len(numbers):
            raise ConfigurationError(
                f"q_full must have {len(numbers)} entries (joints {numbers}); got {q_full.shape[-1]}"
            )
        return q_full[..., [numbers.index(n) for n in self.joint_numbers]]

    def summary(self) -> dict:
        """Plain-data summary: name, dof, joints, masses [kg], base."""
        return {
            "name": self.name,
            "dof": self.dof,
            "joint_numbers": list(self.joint_numbers),
            "locked": {str(lj.number): math.degrees(lj.angle) for lj in self.locked},
            "masses_kg": [b.mass for b in self.bodies],
            "total_link_mass_kg": float(sum(b.mass for b in self.bodies)),
            "base": {"type": "floating", "mass_kg": self.root_body.mass} if self.floating else {"type": "fixed"},
        }


def as_joint_array(model: ArmModel, q: ArrayLike, name: str = "q") -> FloatArray:
    """Validate a joint-space array: real numbers (not bool or complex), shape
    (..., model.dof), all finite.  (No magnitude bound here: the maths calls this on its own
    intermediate arrays too; a computation whose result overflows says so, e.g. :func:`rnea`.)

    Raises
    ------
    ConfigurationError
        Naming ``name``, the shape received and the shape allowed, or where the first
        non-finite value is.
    """
    try:
        raw, kind = np.asarray(q), ""
    except ValueError:  # a ragged nesting of lists
        raw, kind = np.empty(0, dtype=object), "a ragged nesting of sequences"
    if raw.dtype.kind not in "iuf":  # bool, complex, text, objects: no silent conversion
        if raw.dtype.kind == "O":
            try:
                raw = np.asarray(q, dtype=float)
            except (TypeError, ValueError, OverflowError):
                pass
        if raw.dtype.kind not in "iuf":
            raise ConfigurationError(
                f"{name} must be an array of real numbers with shape (..., {model.dof}); got "
                f"{kind or f'dtype {raw.dtype}'} ({shown(q)})"
            )
    arr = np.asarray(raw, dtype=float)
    if arr.ndim == 0 or arr.shape[-1] != model.dof:
        raise ConfigurationError(
            f"{name} must have shape (..., {model.dof}) for model {shown(model.name)} "
            f"(movable joints {list(model.joint_numbers)}); got shape {arr.shape}"
        )
    if not np.all(np.isfinite(arr)):
        bad = tuple(int(i) for i in np.argwhere(~np.isfinite(arr))[0])
        raise ConfigurationError(f"{name} must be finite; got {arr[bad]} at index {bad}")
    return arr


def chain_from_placements(
    name: str,
    placements: Sequence[ArrayLike],
    bodies: Sequence[Body],
    *,
    tool: ArrayLike | None = None,
    axes: Sequence[ArrayLike] | None = None,
    lower: Sequence[float] | None = None,
    upper: Sequence[float] | None = None,
    names: Sequence[str] | None = None,
    root_body: Body | None = None,
    floating: bool = False,
    description: str = "",
) -> ArmModel:
    """Build an :class:`ArmModel` from per-joint placements (the general constructor)."""
    n = len(placements)
    joints = tuple(
        Joint(
            placement=cast(FloatArray, placements[i]),  # Joint converts and checks
            axis=cast(FloatArray, axes[i] if axes is not None else (0.0, 0.0, 1.0)),
            lower=(lower[i] if lower is not None else -math.pi),
            upper=(upper[i] if upper is not None else math.pi),
            number=i + 1,
            name=(names[i] if names is not None else f"joint{i + 1}"),
        )
        for i in range(n)
    )
    return ArmModel(
        name=name,
        joints=joints,
        bodies=tuple(bodies),
        tool=np.eye(4) if tool is None else cast(FloatArray, tool),  # ArmModel converts and checks
        root_body=root_body if root_body is not None else Body(0.0, name="root"),
        floating=floating,
        description=description,
    )
