"""Collision shapes carried by a model's bodies (SPEC piece 16, issue 27).

A shape is an immutable solid expressed in the frame of the body that carries it (a link, or the
root body: the spacecraft bus, or a bare mounting):

* :class:`Capsule`: the segment ``a``-``b`` (3,) [m] swept by a ball of ``radius`` [m] -- the
  links of the built-in arms;
* :class:`Sphere`: a ball (a capsule of zero length);
* :class:`Box`: a rectangular box of ``half_extents`` (3,) [m] at ``pose`` (4, 4) -- the
  spacecraft bus, keep-out volumes;
* :class:`Convex`: the convex hull of ``vertices`` (V, 3) [m] at ``pose`` (4, 4) -- a URDF
  ``<mesh>``, read as its convex hull (:mod:`jointlock.io.urdf`).

Shapes move with their body: :meth:`jointlock.model.Body.transformed` turns them and
:meth:`jointlock.model.Body.merged` keeps both bodies' shapes, so that :func:`jointlock.lock`
merges a locked link's shapes into its parent exactly as it merges the inertia.  Each shape
remembers the link it was made for (``link``: the link's joint number in the full arm, 0 for the
root body), which decides the pairs that are checked (adjacent links never are) and names the
closest pair in :func:`jointlock.collision.clearance`, whatever was locked since.

Distances between shapes are computed by :mod:`jointlock.collision`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import cast

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .bounds import MAX_MODEL_LENGTH_M, shown
from .errors import ModelError

FloatArray = NDArray[np.float64]


def _readonly(array: ArrayLike) -> FloatArray:
    out = np.array(array, dtype=float)
    out.setflags(write=False)
    return out


def _floats(value: object, what: str) -> FloatArray:
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError, OverflowError):
        raise ModelError(f"{what} must be numbers; got {shown(value)}") from None
    if np.asarray(value).dtype.kind == "b":
        raise ModelError(f"{what} must be numbers, not booleans; got {shown(value)}")
    return arr


def _point(value: ArrayLike, what: str) -> FloatArray:
    arr = _floats(value, what)
    if arr.shape != (3,) or not np.all(np.isfinite(arr)) or np.any(np.abs(arr) > MAX_MODEL_LENGTH_M):
        raise ModelError(
            f"{what} must be 3 finite numbers within +-{MAX_MODEL_LENGTH_M:g} m; got {shown(np.asarray(value).tolist())}"
        )
    return _readonly(arr)


def _length(value: float, what: str, *, positive: bool) -> float:
    try:
        if isinstance(value, (bool, np.bool_, str, bytes)):
            raise TypeError
        out = float(value)
    except (TypeError, ValueError, OverflowError):
        raise ModelError(f"{what} must be a number [m]; got {shown(value)}") from None
    if not math.isfinite(out) or out < 0 or (positive and out == 0) or out > MAX_MODEL_LENGTH_M:
        bound = "> 0" if positive else ">= 0"
        raise ModelError(f"{what} must be finite, {bound} and at most {MAX_MODEL_LENGTH_M:g} m; got {shown(value)}")
    return out


def _pose(value: ArrayLike, what: str) -> FloatArray:
    arr = _floats(value, what)
    if arr.shape != (4, 4) or not np.all(np.isfinite(arr)):
        raise ModelError(f"{what} must be a finite 4x4 homogeneous transform; got shape {arr.shape}")
    rot = arr[:3, :3]
    if not np.allclose(rot @ rot.T, np.eye(3), atol=1e-9) or np.linalg.det(rot) < 0:
        raise ModelError(f"{what}: the upper-left 3x3 block is not a rotation matrix")
    if not np.allclose(arr[3], [0.0, 0.0, 0.0, 1.0]):
        raise ModelError(f"{what}: the last row of a homogeneous transform must be [0, 0, 0, 1]")
    _point(arr[:3, 3], f"{what}: the translation")
    return _readonly(arr)


def _label(name: str, kind: str) -> str:
    return f"{kind} {shown(name)}" if name else kind


def _check_identity(shape: Capsule | Sphere | Box | Convex, kind: str) -> None:
    """``name`` text, ``link`` None or an integer joint number (0: the root body, -1 a keep-out)."""
    if not isinstance(shape.name, str):
        raise ModelError(f"{kind}: name must be text; got {shown(shape.name)}")
    link = shape.link
    if link is not None and (isinstance(link, (bool, np.bool_)) or not isinstance(link, (int, np.integer)) or link < -1):
        raise ModelError(
            f"{_label(shape.name, kind)}: link must be None or the joint number of its link (0: the root body); "
            f"got {shown(link)}"
        )
    if link is not None:
        object.__setattr__(shape, "link", int(link))


@dataclass(frozen=True, eq=False)
class Capsule:
    """The segment from ``a`` to ``b`` (3,) [m] swept by a ball of ``radius`` [m], in the frame
    of the body that carries it.  ``a == b`` is a sphere.

    ``link``: the full-arm joint number of the link the capsule was made for (0: the root
    body); None until the model that carries it sets it (:class:`jointlock.model.ArmModel`)."""

    a: FloatArray
    b: FloatArray
    radius: float
    name: str = ""
    link: int | None = None

    def __post_init__(self) -> None:
        _check_identity(self, "capsule")
        label = _label(self.name, "capsule")
        object.__setattr__(self, "a", _point(self.a, f"{label}: a"))
        object.__setattr__(self, "b", _point(self.b, f"{label}: b"))
        object.__setattr__(self, "radius", _length(self.radius, f"{label}: radius", positive=False))

    @property
    def length(self) -> float:
        """Length of the segment [m]."""
        return float(np.linalg.norm(self.b - self.a))

    @property
    def frame(self) -> FloatArray:
        """(4, 4) a frame at the segment's middle with its ``z`` axis along ``b - a`` (any
        orientation for a sphere): where tools that centre a capsule or cylinder on its ``z``
        axis (URDF, coal) place it."""
        frame = np.eye(4)
        frame[:3, 3] = (self.a + self.b) / 2
        if self.length > 0:
            z = (self.b - self.a) / self.length
            helper = np.array([1.0, 0.0, 0.0]) if abs(z[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
            x = np.cross(helper, z)
            x /= np.linalg.norm(x)
            frame[:3, :3] = np.column_stack([x, np.cross(z, x), z])
        return frame

    def transformed(self, pose: ArrayLike) -> Capsule:
        """The same capsule in another frame; ``pose`` (4, 4) is T_new_old."""
        pose = np.asarray(pose, dtype=float)
        rot, p = pose[:3, :3], pose[:3, 3]
        return replace(self, a=rot @ self.a + p, b=rot @ self.b + p)

    def to_dict(self) -> dict:
        """Plain data: type, end points [m], radius [m], name, link."""
        return {
            "type": "capsule",
            "a_m": self.a.tolist(),
            "b_m": self.b.tolist(),
            "radius_m": self.radius,
            "name": self.name,
            "link": self.link,
        }


@dataclass(frozen=True, eq=False)
class Sphere:
    """A ball of ``radius`` [m] centred at ``center`` (3,) [m] in its body's frame (``link``
    as for :class:`Capsule`)."""

    center: FloatArray
    radius: float
    name: str = ""
    link: int | None = None

    def __post_init__(self) -> None:
        _check_identity(self, "sphere")
        label = _label(self.name, "sphere")
        object.__setattr__(self, "center", _point(self.center, f"{label}: center"))
        object.__setattr__(self, "radius", _length(self.radius, f"{label}: radius", positive=True))

    def transformed(self, pose: ArrayLike) -> Sphere:
        """The same sphere in another frame; ``pose`` (4, 4) is T_new_old."""
        pose = np.asarray(pose, dtype=float)
        return replace(self, center=pose[:3, :3] @ self.center + pose[:3, 3])

    def to_dict(self) -> dict:
        """Plain data: type, centre [m], radius [m], name, link."""
        return {"type": "sphere", "center_m": self.center.tolist(), "radius_m": self.radius, "name": self.name, "link": self.link}


@dataclass(frozen=True, eq=False)
class Box:
    """A rectangular box of ``half_extents`` (3,) [m] along the axes of ``pose`` (4, 4), the
    box frame (centre and orientation) in its body's frame (``link`` as for :class:`Capsule`)."""

    pose: FloatArray
    half_extents: FloatArray
    name: str = ""
    link: int | None = None

    def __post_init__(self) -> None:
        _check_identity(self, "box")
        label = _label(self.name, "box")
        object.__setattr__(self, "pose", _pose(self.pose, f"{label}: pose"))
        half = _point(self.half_extents, f"{label}: half_extents")
        if np.any(half <= 0):
            raise ModelError(f"{label}: half_extents must all be > 0 [m]; got {shown(half.tolist())}")
        object.__setattr__(self, "half_extents", half)

    def transformed(self, pose: ArrayLike) -> Box:
        """The same box in another frame; ``pose`` (4, 4) is T_new_old."""
        return replace(self, pose=np.asarray(pose, dtype=float) @ self.pose)

    def to_dict(self) -> dict:
        """Plain data: type, centre [m], rotation (3 x 3), half extents [m], name, link."""
        return {
            "type": "box",
            "center_m": self.pose[:3, 3].tolist(),
            "rotation": self.pose[:3, :3].tolist(),
            "half_extents_m": self.half_extents.tolist(),
            "name": self.name,
            "link": self.link,
        }


@dataclass(frozen=True, eq=False)
class Convex:
    """The convex hull of ``vertices`` (V, 3) [m] given in the frame ``pose`` (4, 4), itself in
    its body's frame (``link`` as for :class:`Capsule`): a mesh's envelope.

    ``source`` is the mesh file it was read from (empty when built in code) and ``scale`` (3,)
    the scale the file's coordinates were multiplied by to give ``vertices``: what an export
    writes back.  Distances to a convex hull are computed with coal (the ``mesh`` extra,
    :mod:`jointlock.collision`)."""

    pose: FloatArray
    vertices: FloatArray
    name: str = ""
    link: int | None = None
    source: str = ""
    scale: FloatArray = field(default_factory=lambda: np.ones(3))

    def __post_init__(self) -> None:
        _check_identity(self, "convex")
        label = _label(self.name, "convex")
        object.__setattr__(self, "pose", _pose(self.pose, f"{label}: pose"))
        vertices = _floats(self.vertices, f"{label}: vertices")
        if vertices.ndim != 2 or vertices.shape[1] != 3 or vertices.shape[0] < 4:
            raise ModelError(f"{label}: vertices must be (V, 3) with V >= 4 (a solid); got shape {vertices.shape}")
        if not np.all(np.isfinite(vertices)) or np.any(np.abs(vertices) > MAX_MODEL_LENGTH_M):
            raise ModelError(f"{label}: vertices must be finite and within +-{MAX_MODEL_LENGTH_M:g} m")
        spread = vertices - vertices.mean(axis=0)
        if np.linalg.matrix_rank(spread, tol=1e-9 * max(float(np.abs(spread).max()), 1e-300)) < 3:
            raise ModelError(f"{label}: vertices are flat (all in one plane): a convex hull needs volume")
        object.__setattr__(self, "vertices", _readonly(vertices))
        if not isinstance(self.source, str):
            raise ModelError(f"{label}: source must be text (a file name); got {shown(self.source)}")
        object.__setattr__(self, "scale", _point(self.scale, f"{label}: scale"))

    @property
    def extent(self) -> float:
        """The largest distance [m] of a vertex from the body frame's origin."""
        placed = self.vertices @ self.pose[:3, :3].T + self.pose[:3, 3]
        return float(np.linalg.norm(placed, axis=1).max())

    def transformed(self, pose: ArrayLike) -> Convex:
        """The same hull in another frame; ``pose`` (4, 4) is T_new_old."""
        return replace(self, pose=np.asarray(pose, dtype=float) @ self.pose)

    def to_dict(self) -> dict:
        """Plain data: type, frame centre [m] and rotation, vertices [m], source file, scale,
        name, link."""
        return {
            "type": "convex",
            "center_m": self.pose[:3, 3].tolist(),
            "rotation": self.pose[:3, :3].tolist(),
            "vertices_m": self.vertices.tolist(),
            "source": self.source,
            "scale": self.scale.tolist(),
            "name": self.name,
            "link": self.link,
        }


#: A collision shape.
Shape = Capsule | Sphere | Box | Convex
SHAPE_TYPES = (Capsule, Sphere, Box, Convex)


def check_shapes(shapes: object, what: str) -> tuple[Shape, ...]:
    """``shapes`` as a tuple of shapes, or a :class:`~jointlock.errors.ModelError` naming
    ``what`` and the first entry that is not one."""
    if isinstance(shapes, SHAPE_TYPES):
        return (shapes,)
    try:
        items: tuple[object, ...] = tuple(shapes)  # type: ignore[arg-type]
    except TypeError:
        raise ModelError(f"{what}: shapes must be a sequence of Capsule, Sphere, Box or Convex; got {shown(shapes)}") from None
    for i, item in enumerate(items):
        if not isinstance(item, SHAPE_TYPES):
            raise ModelError(
                f"{what}: shapes[{i}] must be a Capsule, Sphere, Box or Convex; got {type(item).__name__} ({shown(item)})"
            )
    return cast(tuple[Shape, ...], items)


def with_link(shapes: tuple[Shape, ...], link: int) -> tuple[Shape, ...]:
    """``shapes`` with ``link`` set on each that has none yet."""
    return tuple(s if s.link is not None else replace(s, link=link) for s in shapes)


def box_from_inertia(mass: float, com: ArrayLike, inertia: ArrayLike, name: str = "bus") -> Box:
    """The uniform box of a body's ``mass`` [kg] and inertia (3, 3) [kg m^2] about its centre
    of mass ``com`` (3,) [m]: half sides ``sqrt(3 (I_j + I_k - I_i) / (2 m))`` along the
    principal axes (the box the 3-D view draws for a spacecraft)."""
    inertia = np.asarray(inertia, dtype=float)
    if not mass > 0:
        raise ModelError(f"box {shown(name)}: a box from a body's inertia needs mass > 0 [kg]; got {shown(mass)}")
    moments, axes = np.linalg.eigh(inertia)
    half = np.sqrt(np.clip(3.0 * (moments.sum() - 2.0 * moments) / (2.0 * mass), 0.0, None))
    if np.linalg.det(axes) < 0:
        axes[:, 0] = -axes[:, 0]
    pose = np.eye(4)
    pose[:3, :3] = axes
    pose[:3, 3] = np.asarray(com, dtype=float)
    return Box(pose, half, name=name)


def chain_capsules(
    placements: list[FloatArray] | tuple[FloatArray, ...], tool: FloatArray, radius: float | list[float]
) -> tuple[tuple[Capsule | Sphere, ...], list[tuple[Capsule | Sphere, ...]]]:
    """Capsules along a chain's stick figure (the polyline the 3-D view draws): the root body's
    from the root origin to joint 1's origin, link ``i``'s from its frame's origin to the next
    joint's origin (the last link's to the tool point); a zero-length segment is a sphere.

    Parameters
    ----------
    placements
        (n,) joint placements (4, 4) [m] (``Joint.placement``).
    tool
        (4, 4) tool pose in the last link's frame [m].
    radius
        One radius [m] for every capsule, or (n + 1,) radii: the root post's, then link 1..n's;
        a radius of 0 leaves that body without a shape.

    Returns
    -------
    root, links
        The root body's shapes and, for each link, its shapes (in its own frame).
    """
    n = len(placements)
    radii = [float(radius)] * (n + 1) if isinstance(radius, (int, float)) else [float(r) for r in radius]
    if len(radii) != n + 1:
        raise ModelError(f"radius must be one number or {n + 1} numbers (the root post, then links 1..{n}); got {len(radii)}")
    ends = [np.asarray(p, dtype=float)[:3, 3] for p in placements[1:]] + [np.asarray(tool, dtype=float)[:3, 3]]

    def shape(start: FloatArray, end: FloatArray, r: float, name: str) -> tuple[Capsule | Sphere, ...]:
        if r == 0:
            return ()
        if np.linalg.norm(end - start) < 1e-12:
            return (Sphere(start, r, name=name),)
        return (Capsule(start, end, r, name=name),)

    root = shape(np.zeros(3), np.asarray(placements[0], dtype=float)[:3, 3], radii[0], "post") if n else ()
    links = [shape(np.zeros(3), ends[i], radii[i + 1], f"link{i + 1}") for i in range(n)]
    return root, links
