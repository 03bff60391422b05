"""URDF writer: an :class:`~jointlock.model.ArmModel` -- a crippled arm with its locked joints
folded in and their bodies merged -- as a URDF file other tools load (Pinocchio, MuJoCo's
importer, Gazebo, Drake), so that the locked arm can be simulated elsewhere.

The chain is written as it is held: link ``base`` (the root body: the spacecraft of a
free-floating arm, whose URDF root link :func:`~jointlock.io.urdf.read_urdf` reads as the
spacecraft with ``base="floating"``), then one ``revolute`` (or ``continuous``, for a joint
without angle limits) joint per movable joint with its placement as ``<origin>`` (xyz, URDF
roll-pitch-yaw), its unit axis and its limits, each carrying its body's ``<inertial>`` (mass,
centre of mass and inertia about it, in the joint's frame), and a ``fixed`` joint to the link
``tool`` (the end effector).  Numbers are written with 17 significant digits, so that reading
the file back gives the same model to round-off.  Locked joints appear in an XML comment
(number, angle); they are no joints of the file.

Conventions a reader of the file needs:

- A joint without a speed or torque limit is written ``velocity="0"`` / ``effort="0"``, URDF's
  common "not given" (jointlock reads 0 as no limit; Pinocchio stores the 0 as it is).
- Read back, the movable joints are numbered 1..n in chain order (a locked joint is gone); the
  names keep the original numbers (``joint5`` is the arm's joint 5).
- URDF has no one-sided angle limit: a joint limited on one side only is written one turn from
  its finite side (:meth:`ArmModel.angle_range`), every angle it can take once.
- The base is whatever the reader is asked for (``read_urdf(..., base="floating")``,
  ``--base floating``): the root link's inertial is the spacecraft either way.
- Collision geometry (issue 27) as ``<collision>`` elements on the link that carries it: a
  sphere as ``<sphere>``, a box as ``<box>``, and a capsule, which URDF lacks, as a
  ``<cylinder>`` and a ``<sphere>`` at each end (their union is the capsule, so any reader's
  distances are the capsule's; :func:`~jointlock.io.urdf.read_urdf` reads the three back as the
  capsule), and a convex hull read from a mesh as the ``<mesh>`` it came from (its file and
  scale; a reader takes that mesh's convex hull, as jointlock does, or the mesh itself).  Each
  element is named after the shape (a capsule's end spheres ``NAME/end1``, ``NAME/end2``).
"""

from __future__ import annotations

import math
from pathlib import Path
from xml.sax.saxutils import quoteattr

import numpy as np

from ..errors import ModelError
from ..model import ArmModel, Body, FloatArray
from ..shapes import Box, Convex, Sphere
from ..spatial import pose
from .files import atomic_write_text

#: Name of the end-effector link and of the root link in the files written.
TOOL_LINK, BASE_LINK = "tool", "base"


def rpy_from_matrix(rotation: FloatArray) -> FloatArray:
    """URDF roll-pitch-yaw (3,) [rad] of a rotation matrix (3, 3), ``R = Rz(yaw) Ry(pitch)
    Rx(roll)`` (inverse of :func:`jointlock.spatial.rpy_matrix`; at pitch = +-90 deg, roll 0)."""
    r = np.asarray(rotation, dtype=float)
    pitch = math.atan2(-r[2, 0], math.hypot(r[0, 0], r[1, 0]))
    if math.hypot(r[0, 0], r[1, 0]) < 1e-12:  # gimbal lock: yaw takes the whole in-plane angle
        return np.array([0.0, pitch, math.atan2(-r[0, 1], r[1, 1])])
    return np.array([math.atan2(r[2, 1], r[2, 2]), pitch, math.atan2(r[1, 0], r[0, 0])])


def _num(value: float) -> str:
    return repr(float(value) + 0.0)  # + 0.0: no "-0.0"


def _vec(values: FloatArray) -> str:
    return " ".join(_num(v) for v in values)


def _origin(transform: FloatArray) -> str:
    t = np.asarray(transform, dtype=float)
    return f'<origin xyz="{_vec(t[:3, 3])}" rpy="{_vec(rpy_from_matrix(t[:3, :3]))}"/>'


def _inertial(body: Body) -> str:
    i = body.inertia
    return (
        f'<inertial><origin xyz="{_vec(body.com)}" rpy="0 0 0"/><mass value="{_num(body.mass)}"/>'
        f'<inertia ixx="{_num(i[0, 0])}" ixy="{_num(i[0, 1])}" ixz="{_num(i[0, 2])}" '
        f'iyy="{_num(i[1, 1])}" iyz="{_num(i[1, 2])}" izz="{_num(i[2, 2])}"/></inertial>'
    )


def _collisions(body: Body) -> str:
    out = []
    for shape in body.shapes:
        name = quoteattr(shape.name or body.name or "shape")
        if isinstance(shape, Convex):
            if not shape.source:
                raise ModelError(
                    f"convex shape {shape.name!r}: URDF has no inline mesh; a hull built in code has no file to "
                    "refer to (export to MJCF, which writes the vertices, or give the shape its mesh file as source)"
                )
            mesh = f'<mesh filename={quoteattr(shape.source)} scale="{_vec(shape.scale)}"/>'
            out.append(f"<collision name={name}>{_origin(shape.pose)}<geometry>{mesh}</geometry></collision>")
            continue
        if isinstance(shape, Box):
            parts = [(shape.pose, f'<box size="{_vec(2 * shape.half_extents)}"/>')]
        elif isinstance(shape, Sphere) or shape.length == 0:
            center = shape.center if isinstance(shape, Sphere) else shape.a
            parts = [(pose(np.eye(3), center), f'<sphere radius="{_num(shape.radius)}"/>')]
        else:
            parts = [(shape.frame, f'<cylinder radius="{_num(shape.radius)}" length="{_num(shape.length)}"/>')]
            parts += [(pose(np.eye(3), end), f'<sphere radius="{_num(shape.radius)}"/>') for end in (shape.a, shape.b)]
        names = [name] + [quoteattr(f"{shape.name or body.name or 'shape'}/end{k}") for k in (1, 2)]
        out += [
            f"<collision name={label}>{_origin(frame)}<geometry>{geometry}</geometry></collision>"
            for label, (frame, geometry) in zip(names, parts)
        ]
    return "".join(out)


def refuse_unread_meshes(model: ArmModel, what: str) -> None:
    """Refuse, in one line, to export a model whose URDF meshes could not be read: the file
    would lack them, and a model read back from it would look complete."""
    if model.unread_meshes:
        raise ModelError(
            f"{what} export of {model.name!r}: {len(model.unread_meshes)} <collision> mesh(es) could not be read "
            f"({model.unread_meshes[0]}), and the file would silently lack them; read them (the mesh extra, "
            "package_dirs) or leave them out on purpose (--meshes skip)"
        )


def urdf_text(model: ArmModel) -> str:
    """The URDF document of ``model`` (see the module docstring)."""
    refuse_unread_meshes(model, "URDF")
    locked = ", ".join(f"joint {lj.number} at {math.degrees(lj.angle):.12g} deg" for lj in model.locked)
    lines = [
        '<?xml version="1.0" encoding="utf-8"?>',
        f"<!-- written by jointlock; locked: {locked or 'none'} "
        f"(folded into the chain, bodies merged); base: {'floating' if model.floating else 'fixed'} -->",
        f"<robot name={quoteattr(model.name)}>",
        f"  <link name={quoteattr(BASE_LINK)}>{_inertial(model.root_body)}{_collisions(model.root_body)}</link>",
    ]
    parent = BASE_LINK
    lows, highs = model.angle_range()  # a one-sided limit: one turn from its finite side
    for joint, body, low, high in zip(model.joints, model.bodies, lows, highs):
        child = f"link{joint.number}"
        continuous = math.isinf(joint.lower) and math.isinf(joint.upper)
        limit = [f'effort="{_num(joint.effort_limit if math.isfinite(joint.effort_limit) else 0.0)}"',
                 f'velocity="{_num(joint.velocity_limit if math.isfinite(joint.velocity_limit) else 0.0)}"']  # fmt: skip
        if not continuous:
            limit = [f'lower="{_num(low)}"', f'upper="{_num(high)}"', *limit]
        lines += [
            f"  <link name={quoteattr(child)}>{_inertial(body)}{_collisions(body)}</link>",
            f"  <joint name={quoteattr(joint.name)} type=\"{'continuous' if continuous else 'revolute'}\">",
            f"    <parent link={quoteattr(parent)}/><child link={quoteattr(child)}/>",
            f"    {_origin(joint.placement)}<axis xyz=\"{_vec(joint.axis)}\"/>",
            f"    <limit {' '.join(limit)}/>",
            "  </joint>",
        ]
        parent = child
    lines += [
        f"  <link name={quoteattr(TOOL_LINK)}/>",
        f'  <joint name="tool_fixed" type="fixed"><parent link={quoteattr(parent)}/>'
        f"<child link={quoteattr(TOOL_LINK)}/>{_origin(model.tool)}</joint>",
        "</robot>",
    ]
    return "\n".join(lines) + "\n"


def write_urdf(model: ArmModel, path: str | Path) -> Path:
    """Write :func:`urdf_text` to ``path`` (atomically); returns the path."""
    path = Path(path)
    atomic_write_text(path, urdf_text(model))
    return path
