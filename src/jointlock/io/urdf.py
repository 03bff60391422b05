"""URDF reader into the internal chain form.

Supported: ``revolute``, ``continuous`` and ``fixed`` joints, ``<inertial>`` blocks.  Fixed
joints are merged into their parent body (the frames behind them are kept for the end
effector).  The movable joints must form a single serial path from the root link; branches
of fixed links are fine.  Prismatic, planar and floating joints are rejected with a message
naming the joint.
"""

from __future__ import annotations

import math
import re
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path
from typing import Literal

import numpy as np

from ..bounds import MAX_JOINT_VALUE, MAX_LENGTH_M, shown
from ..errors import ModelError
from ..model import ArmModel, Body, Joint
from ..spatial import pose, rpy_matrix
from .files import check_path_text, decode_text, read_input_bytes, shorten


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


def _some_names(names: list[str]) -> str:
    """The first five link names, each shortened, for an error line."""
    return ", ".join(repr(shorten(k, 40)) for k in names[:5]) + (", ..." if len(names) > 5 else "")


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


# Over 100 lines: parse, walk the tree, merge fixed links and build share the link/joint maps.
def read_urdf(
    source: str | Path,
    *,
    base: Literal["fixed", "floating"] = "fixed",
    ee_link: str | None = None,
    name: str | None = None,
) -> ArmModel:
    """Read a URDF file (or a string holding URDF XML) into an :class:`ArmModel`.

    Parameters
    ----------
    source
        Path to a ``.urdf`` file, or the XML text itself.
    base
        ``"fixed"``, or ``"floating"``: the root link's inertial becomes the spacecraft (it
        must have a positive mass).
    ee_link
        Link whose frame is the end effector; default: the last link of the chain (following
        fixed joints after the last movable joint while the path is unique).
    name
        Model name; default: the ``<robot name>``.
    """
    source_text = str(source)
    text: str | bytes = source_text
    label = "URDF"
    if not source_text.lstrip().startswith("<"):
        path = check_path_text(source_text, "URDF file", ModelError)
        label = shorten(str(path))
        text = _urdf_text(path, label)
    try:
        root = ET.fromstring(text)
    except (ET.ParseError, LookupError, ValueError) as exc:  # LookupError: an unknown declared encoding
        raise ModelError(f"{label}: malformed XML: {exc}") from None
    if root.tag != "robot":
        raise ModelError(f"{label}: the root element must be <robot>; got <{root.tag}>")
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
        if kind in ("prismatic", "planar", "floating"):
            raise ModelError(
                f"{where}: type {shown(kind)} is not supported (allowed: revolute, continuous, fixed)"
            )
        if kind not in ("revolute", "continuous", "fixed"):
            raise ModelError(f"{where}: unknown type {shown(kind)} (allowed: revolute, continuous, fixed)")
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
        if kind == "revolute":
            if limit is None:
                raise ModelError(f"{where}: a revolute joint needs <limit lower=... upper=...>")
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
        joints.append(
            _UrdfJoint(
                jname, kind, parent, child, _origin(jel.find("origin"), where), axis, lower, upper, velocity, effort
            )
        )

    children: dict[str, list[_UrdfJoint]] = {k: [] for k in links}
    parent_of: dict[str, str] = {}
    for j in joints:
        if j.child in parent_of:
            raise ModelError(f"{label}: link {shown(j.child)} has two parent joints")
        parent_of[j.child] = j.name
        children[j.parent].append(j)
    if not links:
        raise ModelError(f"{label}: no <link> found (a robot is links joined by joints)")
    roots = [k for k in links if k not in parent_of]
    if len(roots) != 1:
        names = _some_names(roots)
        why = " (every link has a parent: the joints form a cycle)" if not roots else ""
        raise ModelError(f"{label}: expected exactly one root link; found {len(roots)}: [{names}]{why}")
    root_link = roots[0]

    # Walk the tree: every link belongs to an owner body (root = -1 or a movable joint index).
    owner: dict[str, int] = {root_link: -1}
    in_owner: dict[str, np.ndarray] = {root_link: np.eye(4)}
    movable: list[tuple[_UrdfJoint, np.ndarray, int]] = []  # joint, placement in parent owner, parent owner
    stack = [root_link]
    while stack:
        lname = stack.pop()
        for j in children[lname]:
            if j.kind == "fixed":
                owner[j.child] = owner[lname]
                in_owner[j.child] = in_owner[lname] @ j.origin
            else:
                movable.append((j, in_owner[lname] @ j.origin, owner[lname]))
                owner[j.child] = len(movable) - 1
                in_owner[j.child] = np.eye(4)
            stack.append(j.child)
    unreached = [k for k in links if k not in owner]
    if unreached:  # beside the tree from the root: links whose joints form a closed loop
        names = _some_names(unreached)
        raise ModelError(
            f"{label}: links {names} are not connected to the root link {shown(root_link)} (their joints "
            "form a closed loop); a model is one tree from its root"
        )
    if not movable:
        raise ModelError(f"{label}: no revolute or continuous joint found")
    for i, (j, _, parent_owner) in enumerate(movable):
        if parent_owner != i - 1:
            prev = movable[parent_owner][0].name if parent_owner >= 0 else f"root link {shown(root_link)}"
            raise ModelError(
                f"{label}: joint {shown(j.name)} branches from {prev}; only serial chains of movable "
                "joints are supported"
            )

    bodies = [Body(0.0, name=movable[i][0].child) for i in range(len(movable))]
    root_body = Body(0.0, name=root_link)
    for lname, link in links.items():
        body = _inertial(link, label)
        if body.mass == 0 and not np.any(body.inertia):
            continue
        o = owner[lname]
        if o < 0:
            root_body = root_body.merged(body, in_owner[lname], name=root_link)
        else:
            bodies[o] = bodies[o].merged(body, in_owner[lname], name=bodies[o].name)

    last = len(movable) - 1
    if ee_link is None:
        ee_link = movable[-1][0].child
        while len(children[ee_link]) == 1 and children[ee_link][0].kind == "fixed":
            ee_link = children[ee_link][0].child
    elif ee_link not in links:
        raise ModelError(f"{label}: ee_link {shown(ee_link)} is not a link of the robot")
    elif owner[ee_link] != last:
        raise ModelError(
            f"{label}: ee_link {shown(ee_link)} must be rigidly attached to the last movable joint "
            f"{movable[-1][0].name!r}"
        )
    tool = in_owner[ee_link]

    try:
        model_joints = tuple(
            Joint(placement, j.axis, j.lower, j.upper, j.velocity, number=i + 1, name=j.name, effort_limit=j.effort)
            for i, (j, placement, _) in enumerate(movable)
        )
    except ModelError as exc:  # e.g. lower > upper: named with the file
        raise ModelError(f"{label}: {exc}") from None
    if base == "floating" and root_body.mass <= 0:
        raise ModelError(
            f"{label}: base='floating' needs an <inertial> with positive mass on the root link "
            f"{shown(root_link)} (the spacecraft)"
        )
    return ArmModel(
        name=name or root.get("name") or "urdf-arm",
        joints=model_joints,
        bodies=tuple(bodies),
        tool=tool,
        root_body=root_body,
        floating=base == "floating",
        description=f"read from {label}",
    )
