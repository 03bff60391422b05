"""URDF reader into the internal chain form.

A URDF is a tree; a jointlock model is the serial chain from ``root_link`` (default: the tree's
root) to ``tip_link`` (default: the end of the one path of movable joints, when there is one).
On that chain, ``revolute`` and ``continuous`` joints move; everything else is frozen and its
bodies merged into the chain link it hangs from (as :func:`jointlock.lock` does): ``fixed``
joints, the joints named in ``freeze`` (at the value given), and every joint off the chain --
the other arm of a dual-arm robot, gripper fingers, sensors -- at its ``freeze`` value, else at
0 (a ``<mimic>`` joint at ``multiplier * value + offset`` of the joint it follows).  Links
above ``root_link`` are left out.  A prismatic joint on the chain must be frozen (the chain
model has revolute joints only), and so must a mimic joint on it (no coupled joints): each is
refused in one line naming it.  Planar and floating joints are left out above ``root_link``
(a ``world`` link joined to the robot's base for a simulator: start the chain at the base) and
refused below it.

Collision geometry (issue 27): each link's ``<collision>`` primitives become its shapes
(:mod:`jointlock.shapes`), merged with the link like its inertial: ``<sphere>`` and ``<box>`` as
they are, ``<cylinder>`` as its capsule envelope (the cylinder with a half-ball on each end:
conservative, a clearance is never overstated; a cylinder and the two spheres at its ends, as
:func:`~jointlock.io.urdf_export.urdf_text` writes a capsule, read back as the capsule exactly).
``<mesh>`` as its convex hull (:class:`~jointlock.shapes.Convex`, read by
:mod:`jointlock.io.mesh` with the ``mesh`` extra; distances by coal): a clearance against the
hull never exceeds the one against the mesh.  A mesh that cannot be read (the extra missing, a
file not found) does not stop the reading: the model's clearance refuses it, naming the mesh.
``meshes="skip"`` leaves meshes out on purpose (the model's description then says how many).
"""

from __future__ import annotations

import math
import re
import xml.etree.ElementTree as ET
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Literal

import numpy as np

from ..bounds import MAX_JOINT_VALUE, MAX_LENGTH_M, shown
from ..errors import ModelError
from ..model import ArmModel, Body, Joint
from ..shapes import Box, Capsule, Convex, Shape, Sphere
from ..spatial import pose, rpy_matrix
from ._urdf_chain import Chain, select_chain
from .files import check_path_text, decode_text, read_input_bytes, shorten
from .mesh import MESH_MODES


@dataclass
class _UrdfJoint:
    name: str
    kind: str
    parent: str
    child: str
    origin: np.ndarray
    axis: np.ndarray
    lower: float
    upper: float
    velocity: float
    effort: float
    mimic: tuple[str, float, float] | None = None  # (joint followed, multiplier, offset)


def _floats(text: str | None, count: int, where: str, default: list[float]) -> np.ndarray:
    if text is None:
        return np.array(default, dtype=float)
    try:
        values = [float(v) for v in text.split()]
    except ValueError:
        raise ModelError(f"{where}: expected {count} numbers; got {shown(text)}") from None
    if len(values) != count or not all(math.isfinite(v) for v in values):
        raise ModelError(f"{where}: expected {count} finite numbers; got {shown(text)}")
    return np.array(values)


#: An XML declaration naming its encoding (``<?xml version="1.0" encoding="ISO-8859-1"?>``).
_DECLARED_ENCODING = re.compile(rb"^\s*<\?xml[^>]*encoding\s*=", re.IGNORECASE)


def _urdf_text(path: Path, label: str) -> str | bytes:
    """The file's XML: its bytes when its declaration names an encoding (the XML parser
    decodes them), else its text read as UTF-8 (see :func:`decode_text`)."""
    data = read_input_bytes(path, "URDF file", ModelError)
    if _DECLARED_ENCODING.match(data):
        return data
    return decode_text(data, f"URDF file {shown(label)}", ModelError)


def _origin(elem: ET.Element | None, where: str) -> np.ndarray:
    if elem is None:
        return np.eye(4)
    xyz = _floats(elem.get("xyz"), 3, f"{where} <origin xyz>", [0, 0, 0])
    rpy = _floats(elem.get("rpy"), 3, f"{where} <origin rpy>", [0, 0, 0])
    if np.any(np.abs(xyz) > MAX_LENGTH_M):
        raise ModelError(f"{where} <origin xyz>: each coordinate must lie within +-{MAX_LENGTH_M:g} m; got {shown(elem.get('xyz'))}")
    if np.any(np.abs(rpy) > MAX_JOINT_VALUE):
        raise ModelError(f"{where} <origin rpy>: each angle must lie within +-{MAX_JOINT_VALUE:g} rad; got {shown(elem.get('rpy'))}")
    return pose(rpy_matrix(rpy), xyz)


def _number(elem: ET.Element, attr: str, where: str, default: float | None = None) -> float:
    text = elem.get(attr)
    if text is None:
        if default is None:
            raise ModelError(f"{where}: missing attribute {shown(attr)}")
        return default
    try:
        value = float(text)
    except ValueError:
        raise ModelError(f"{where}: attribute {shown(attr)} must be a number; got {shown(text)}") from None
    if math.isnan(value):
        raise ModelError(f"{where}: attribute {shown(attr)} must be a number; got {shown(text)}")
    return value


def _inertial(link: ET.Element, label: str) -> Body:
    name = link.get("name", "?")
    where = f"{label}: link {shorten(name, 40)!r} <inertial>"
    inertial = link.find("inertial")
    if inertial is None:
        return Body(0.0, name=name)
    mass_el = inertial.find("mass")
    mass = _number(mass_el, "value", f"{where} <mass>") if mass_el is not None else 0.0
    frame = _origin(inertial.find("origin"), where)
    inertia_el = inertial.find("inertia")
    if inertia_el is None:
        inertia = np.zeros((3, 3))
    else:
        vals = {
            k: _number(inertia_el, k, f"{where} <inertia>", 0.0)
            for k in ("ixx", "iyy", "izz", "ixy", "ixz", "iyz")
        }
        inertia = np.array(
            [
                [vals["ixx"], vals["ixy"], vals["ixz"]],
                [vals["ixy"], vals["iyy"], vals["iyz"]],
                [vals["ixz"], vals["iyz"], vals["izz"]],
            ]
        )
    try:
        body = Body(mass, np.zeros(3), inertia, name=name)
    except ModelError as exc:
        raise ModelError(f"{where}: {exc}") from None
    return body.transformed(frame)


@dataclass(frozen=True)
class _Meshes:
    """How a URDF's ``<mesh>`` elements are read (see the module)."""

    mode: str
    urdf_dir: Path | None
    package_dirs: tuple[str | Path, ...]
    unread: list[str] = field(default_factory=list)

    def shape(self, element: ET.Element, frame: np.ndarray, name: str, where: str) -> Convex | None:
        """The mesh's convex hull, or None when it cannot be read (the reason kept in
        ``unread``: the model's clearance refuses it, everything else works)."""
        from .mesh import hull_vertices, resolve_mesh

        filename = element.get("filename")
        if not filename:
            raise ModelError(f"{where} <mesh>: needs a filename")
        scale = _floats(element.get("scale"), 3, f"{where} <mesh scale>", [1.0, 1.0, 1.0])
        if not np.all(scale != 0) or np.any(np.abs(scale) > MAX_LENGTH_M):  # negative: a mirrored mesh
            raise ModelError(
                f"{where} <mesh scale>: must be 3 numbers, none 0, each within +-{MAX_LENGTH_M:g}; got {shown(scale.tolist())}"
            )
        try:
            path = resolve_mesh(filename, self.urdf_dir, self.package_dirs)
            vertices = hull_vertices(path, scale)
        except ModelError as exc:
            self.unread.append(f"link {shorten(name, 40)!r}: {exc}")
            return None
        return Convex(frame, vertices, name=name, source=str(path.resolve()), scale=scale)


def _collisions(link: ET.Element, label: str, meshes_as: _Meshes) -> tuple[tuple[Shape, ...], int]:
    """The link's ``<collision>`` elements as shapes in its frame, and how many meshes were
    left out (see the module)."""
    name = link.get("name", "?")
    shapes: list[Shape] = []
    meshes = 0
    for k, collision in enumerate(link.findall("collision")):
        where = f"{label}: link {shorten(name, 40)!r} <collision> {k + 1}"
        frame = _origin(collision.find("origin"), where)
        geometry = collision.find("geometry")
        element = None if geometry is None else next(iter(geometry), None)
        if element is None:
            raise ModelError(f"{where}: needs a <geometry> with a <box>, <cylinder>, <sphere> or <mesh>")
        label_name = name  # pairs are named after links (a merged link's shapes keep its name)
        try:
            if element.tag == "sphere":
                radius = _number(element, "radius", f"{where} <sphere>")
                shapes.append(Sphere(frame[:3, 3], radius, name=label_name))
            elif element.tag == "box":
                size = _floats(element.get("size"), 3, f"{where} <box size>", [])
                shapes.append(Box(frame, size / 2, name=label_name))
            elif element.tag == "cylinder":
                radius = _number(element, "radius", f"{where} <cylinder>")
                half = _number(element, "length", f"{where} <cylinder>") / 2
                ends = frame[:3, 3] + np.outer([-half, half], frame[:3, 2])
                shapes.append(Capsule(ends[0], ends[1], radius, name=label_name))
            elif element.tag == "mesh":
                if meshes_as.mode == "skip":
                    meshes += 1
                elif (hull := meshes_as.shape(element, frame, label_name, where)) is not None:
                    shapes.append(hull)
            else:
                raise ModelError(
                    f"{where}: <{shorten(element.tag, 40)}> is not a URDF geometry (box, cylinder, sphere, mesh)"
                )
        except ModelError as exc:
            raise ModelError(f"{where}: {exc}" if not str(exc).startswith(label) else str(exc)) from None
    return _without_contained_spheres(shapes), meshes


def _without_contained_spheres(shapes: list[Shape]) -> tuple[Shape, ...]:
    """``shapes`` without the spheres that lie inside a capsule of the same link (a capsule
    written as a cylinder and its two end spheres): they change no distance."""
    capsules = [s for s in shapes if isinstance(s, Capsule)]

    def inside(sphere: Sphere) -> bool:
        for c in capsules:
            d = c.b - c.a
            t = float(np.clip((sphere.center - c.a) @ d / max(float(d @ d), 1e-300), 0.0, 1.0))
            if np.linalg.norm(sphere.center - c.a - t * d) + sphere.radius <= c.radius * (1 + 1e-12):
                return True
        return False

    return tuple(s for s in shapes if not (isinstance(s, Sphere) and inside(s)))


# Over 100 lines: parse, walk the tree, merge fixed links and build share the link/joint maps.
def read_urdf(
    source: str | Path,
    *,
    base: Literal["fixed", "floating"] = "fixed",
    ee_link: str | None = None,
    name: str | None = None,
    root_link: str | None = None,
    tip_link: str | None = None,
    freeze: Mapping[str, float] | None = None,
    freeze_units: Mapping[str, str] | None = None,
    meshes: Literal["convex", "skip"] = "convex",
    package_dirs: Sequence[str | Path] = (),
) -> ArmModel:
    """Read a URDF file (or a string holding URDF XML) into an :class:`ArmModel`.

    Parameters
    ----------
    source
        Path to a ``.urdf`` file, or the XML text itself.
    base
        ``"fixed"``, or ``"floating"``: the root link's inertial becomes the spacecraft (it
        must have a positive mass).
    ee_link, tip_link
        Link whose frame is the end effector (the chain's end; one setting, two names);
        default: the end of the one path of movable joints from ``root_link`` (then fixed
        joints while the path is unique).  A tree that branches into several movable paths
        (two arms, two gripper fingers) needs it, or the other branches frozen.
    name
        Model name; default: the ``<robot name>``.
    root_link
        Link the chain starts from (its root body; the spacecraft with ``base="floating"``);
        default: the tree's root.  Links above it are left out.
    freeze
        ``{joint name: value}`` [rad, or m for a prismatic joint]: joints held at a value and
        merged, on the chain or off it.  Joints off the chain not named here are held at 0 (a
        ``<mimic>`` joint at ``multiplier * value + offset`` of the one it follows).
    freeze_units
        ``{joint name: "deg" | "m"}``: the unit each value was given in (a model file's
        ``freeze_deg`` / ``freeze_m``), refused for a joint of the other kind.
    meshes
        ``"convex"``: each ``<collision>`` ``<mesh>`` is read as its convex hull (needs the
        ``mesh`` extra: ``pip install 'jointlock[mesh]'``); a mesh that cannot be read (the extra
        missing, a file not found or unreadable) leaves the model usable for everything but its
        clearance, which refuses it in one line naming the mesh
        (:attr:`~jointlock.model.ArmModel.unread_meshes`).  ``"skip"``: meshes are left out on
        purpose, and the links that have only meshes have no collision geometry (the description
        says how many were left out).
    package_dirs
        Folders in which ``package://`` mesh files are looked for, before ``ROS_PACKAGE_PATH``
        and the folders above the URDF (:mod:`jointlock.io.mesh`).

    Notes
    -----
    The chain is described in the model's ``description`` (root, tip, frozen joints).
    """
    source_text = str(source)
    text: str | bytes = source_text
    label = "URDF"
    urdf_dir: Path | None = None
    if not isinstance(meshes, str) or meshes not in MESH_MODES:
        raise ModelError(f"meshes must be one of {', '.join(MESH_MODES)}; got {shown(meshes)}")
    if isinstance(package_dirs, (str, Path)):
        package_dirs = (package_dirs,)
    if not isinstance(package_dirs, (list, tuple)) or not all(isinstance(p, (str, Path)) for p in package_dirs):
        raise ModelError(f"package_dirs must be a folder or a list of folders (text or Path); got {shown(package_dirs)}")
    if not source_text.lstrip().startswith("<"):
        path = check_path_text(source_text, "URDF file", ModelError)
        label = shorten(str(path))
        text = _urdf_text(path, label)
        urdf_dir = Path(path).parent
    meshes_as = _Meshes(meshes, urdf_dir, tuple(package_dirs))
    try:
        root = ET.fromstring(text)
    except (ET.ParseError, LookupError, ValueError) as exc:  # LookupError: an unknown declared encoding
        raise ModelError(f"{label}: malformed XML: {exc}") from None
    if root.tag != "robot":
        raise ModelError(f"{label}: the root element must be <robot>; got <{shorten(root.tag, 40)}>")
    if base not in ("fixed", "floating"):
        raise ModelError(f"base must be 'fixed' or 'floating'; got {shown(base)}")

    links: dict[str, ET.Element] = {}
    for link in root.findall("link"):
        lname = link.get("name")
        if not lname:
            raise ModelError(f"{label}: a <link> has no name")
        if lname in links:
            raise ModelError(f"{label}: link {shown(lname)} is defined twice")
        links[lname] = link
    joints: list[_UrdfJoint] = []
    for jel in root.findall("joint"):
        jname = jel.get("name") or "?"
        where = f"{label}: joint {shown(jname)}"
        kind = jel.get("type")
        # planar / floating: read, and left out above root_link (a world -> base joint written
        # for a simulator); refused below it by select_chain
        if kind not in ("revolute", "continuous", "prismatic", "fixed", "planar", "floating"):
            raise ModelError(
                f"{where}: unknown type {shown(kind)} (allowed: revolute, continuous, prismatic, fixed; "
                "planar and floating above root_link)"
            )
        parent_el, child_el = jel.find("parent"), jel.find("child")
        parent = parent_el.get("link") if parent_el is not None else None
        child = child_el.get("link") if child_el is not None else None
        if not parent or not child:
            raise ModelError(f"{where}: needs <parent link=...> and <child link=...>")
        for role, lname in (("parent", parent), ("child", child)):
            if lname not in links:
                raise ModelError(f"{where}: {role} link {shown(lname)} is not defined")
        axis_el = jel.find("axis")
        axis = _floats(
            axis_el.get("xyz") if axis_el is not None else None,
            3,
            f"{where} <axis>",
            [1, 0, 0],
        )
        lower, upper, velocity, effort = -math.inf, math.inf, math.inf, math.inf
        limit = jel.find("limit")
        if kind in ("revolute", "prismatic"):
            if limit is None:
                raise ModelError(f"{where}: a {kind} joint needs <limit lower=... upper=...>")
            lower = _number(limit, "lower", f"{where} <limit>", 0.0)
            upper = _number(limit, "upper", f"{where} <limit>", 0.0)
        if limit is not None and limit.get("velocity") is not None:
            velocity = _number(limit, "velocity", f"{where} <limit>")
            if velocity <= 0:
                velocity = math.inf
        if limit is not None and limit.get("effort") is not None:
            effort = _number(limit, "effort", f"{where} <limit>")
            if effort <= 0:  # URDF's "no effort given" in many files: no limit
                effort = math.inf
        if kind != "fixed" and np.max(np.abs(axis)) < 1e-12:  # (a norm would overflow at 1e154)
            raise ModelError(f"{where}: <axis xyz> must be non-zero")
        mimic_el = jel.find("mimic")
        mimic = None
        if mimic_el is not None and kind != "fixed":
            mimic = (
                mimic_el.get("joint") or "?",
                _number(mimic_el, "multiplier", f"{where} <mimic>", 1.0),
                _number(mimic_el, "offset", f"{where} <mimic>", 0.0),
            )
        joints.append(
            _UrdfJoint(
                jname, kind, parent, child, _origin(jel.find("origin"), where), axis, lower, upper, velocity, effort,
                mimic,
            )
        )  # fmt: skip

    if not links:
        raise ModelError(f"{label}: no <link> found (a robot is links joined by joints)")
    if ee_link is not None and tip_link is not None and ee_link != tip_link:
        raise ModelError(f"{label}: ee_link {shown(ee_link)} and tip_link {shown(tip_link)} differ (they are one setting)")
    chain = select_chain(
        label, list(links), joints, root_link=root_link, tip_link=tip_link or ee_link, freeze=freeze,
        freeze_units=freeze_units,
    )  # fmt: skip
    owner, in_owner, movable = chain.owner, chain.in_owner, chain.movable

    bodies = [Body(0.0, name=j.child) for j, _ in movable]
    root_body = Body(0.0, name=chain.root)
    skipped_meshes = 0
    for lname, link in links.items():
        if lname not in owner:  # above root_link: not part of the model
            continue
        body = _inertial(link, label)
        shapes, skipped = _collisions(link, label, meshes_as)
        skipped_meshes += skipped
        if body.mass == 0 and not np.any(body.inertia) and not shapes:
            continue
        body = replace(body, shapes=shapes)
        o = owner[lname]
        if o < 0:
            root_body = root_body.merged(body, in_owner[lname], name=chain.root)
        else:
            bodies[o] = bodies[o].merged(body, in_owner[lname], name=bodies[o].name)
    tool = in_owner[chain.tip]

    try:
        model_joints = tuple(
            Joint(placement, j.axis, j.lower, j.upper, j.velocity, number=i + 1, name=j.name, effort_limit=j.effort)
            for i, (j, placement) in enumerate(movable)
        )
    except ModelError as exc:  # e.g. lower > upper: named with the file
        raise ModelError(f"{label}: {exc}") from None
    if base == "floating" and root_body.mass <= 0:
        raise ModelError(
            f"{label}: base='floating' needs an <inertial> with positive mass on the root link "
            f"{shown(chain.root)} (the spacecraft)"
        )
    return ArmModel(
        name=name or root.get("name") or "urdf-arm",
        joints=model_joints,
        bodies=tuple(bodies),
        tool=tool,
        root_body=root_body,
        floating=base == "floating",
        description=f"read from {label}" + _selection_text(chain)
        + (f"; {skipped_meshes} <collision> mesh(es) left out (meshes='skip')" if skipped_meshes else "")
        + (f"; {len(meshes_as.unread)} <collision> mesh(es) not read: no clearance until they are" if meshes_as.unread else ""),
        unread_meshes=tuple(meshes_as.unread),
    )


def _selection_text(chain: Chain) -> str:
    """``", chain 'a' -> 'b', frozen: j1 = 0.1, ..."`` for the model's description."""
    text = f", chain {chain.root!r} -> {chain.tip!r}"
    if chain.frozen:
        items = [f"{k} = {v:g}" for k, v in chain.frozen.items()]
        text += ", frozen: " + ", ".join(items[:6]) + (f", ... ({len(items)})" if len(items) > 6 else "")
    if chain.left_out:
        text += f", {len(chain.left_out)} links above the root left out"
    return text


def urdf_joint_types(source: str | Path) -> dict[str, str]:
    """``{joint name: type}`` of a URDF file (or XML text): which unit a value given per joint
    is in (degrees for a revolute joint, metres for a prismatic one).  Empty when the file
    cannot be read: :func:`read_urdf` then says why, in one line."""
    text = str(source)
    try:
        if not text.lstrip().startswith("<"):
            path = check_path_text(text, "URDF file", ModelError)
            root = ET.fromstring(_urdf_text(path, shorten(text)))
        else:
            root = ET.fromstring(text)
    except (ModelError, ET.ParseError, LookupError, ValueError):
        return {}
    return {j.get("name") or "?": j.get("type") or "?" for j in root.findall("joint")}
