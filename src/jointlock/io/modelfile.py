"""jointlock's TOML model format: a DH table users can write by hand.

Units are in the field names (``_m``, ``_deg``, ``_kg``, ``_kgm2``, ``_deg_s``)::

    name = "my-arm"
    convention = "dh_modified"          # or "dh_standard"
    description = "where the numbers come from"

    [[joint]]                           # one table per joint, base outwards
    a_m = 0.0                           # modified: a_{i-1};  standard: a_i
    alpha_deg = 0.0                     # modified: alpha_{i-1};  standard: alpha_i
    d_m = 0.6
    theta_deg = 0.0                     # offset added to the joint angle (optional)
    lower_deg = -180.0                  # optional, default -180
    upper_deg = 180.0                   # optional, default 180
    velocity_limit_deg_s = 4.0          # optional, default unlimited
    effort_limit_Nm = 300.0             # optional: the motor's torque limit, default unlimited
    mass_kg = 42.5                      # optional body of the link, in its DH frame
    com_m = [0.0, 0.25, 0.0]
    inertia_kgm2 = [0.89, 0.05, 0.89]   # [Ixx, Iyy, Izz], 6 values or 3x3
    flip = false                        # optional: true = turns about -z (theta - q)
    prismatic = false                   # optional: true = slides along z, held at d_m
    radius_m = 0.1                      # optional: a collision capsule along the link (0: none)

    [tool]                              # optional: end effector in the last DH frame
    xyz_m = [0.0, 0.0, 0.1]
    rpy_deg = [0.0, 0.0, 0.0]           # URDF roll-pitch-yaw

    [mount]                             # optional: DH frame 0 in the root frame
    xyz_m = [0.0, 0.0, 0.5]
    rpy_deg = [0.0, 0.0, 90.0]

    [base]                              # optional: a free-floating spacecraft
    mass_kg = 1000.0
    com_m = [0.0, 0.0, -1.0]            # in the root frame (DH frame 0)
    inertia_kgm2 = [667.0, 667.0, 667.0]
    box_m = [2.0, 2.0, 2.0]             # optional: the bus, a box of these sides centred on
                                        # com_m (root-frame axes); kept with a fixed base too

Or the chain of a URDF tree (:func:`jointlock.read_urdf`), which every command then takes as
``ROBOT``::

    name = "panda-arm"
    urdf = "panda.urdf"                 # relative to this file
    root_link = "panda_link0"           # optional: default the tree's root
    tip_link = "panda_hand_tcp"         # optional when the tree has one movable path
    freeze_deg = { panda_joint7 = 45.0 }            # revolute joints held [deg]
    freeze_m = { panda_finger_joint1 = 0.02 }       # prismatic joints held [m]
    meshes = "skip"                     # optional: <collision> meshes left out (default "convex":
                                        # each read as its convex hull, the mesh extra)

Every joint off the chain is held at 0 unless frozen here (a ``<mimic>`` joint follows the
joint it mimics).  The root link's inertial is the spacecraft: with a mass, the model can be
loaded with ``base="floating"``.
"""

from __future__ import annotations

import difflib
import math
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from ..bounds import MAX_LENGTH_M, MAX_OPTION_DEG, as_real, shown
from ..dh import from_dh
from ..errors import ModelError
from ..geometry import with_root_shapes
from ..model import ArmModel, Body
from ..shapes import Box
from ..spatial import pose, rpy_matrix, translation
from .files import read_toml_file, shorten

_TOP_KEYS = {"name", "convention", "description", "joint", "tool", "base", "mount"}
_JOINT_KEYS = {
    "a_m",
    "alpha_deg",
    "d_m",
    "theta_deg",
    "lower_deg",
    "upper_deg",
    "velocity_limit_deg_s",
    "effort_limit_Nm",
    "mass_kg",
    "com_m",
    "inertia_kgm2",
    "name",
    "flip",
    "prismatic",
    "radius_m",
}
_TOOL_KEYS = {"xyz_m", "rpy_deg"}
_BASE_KEYS = {"mass_kg", "com_m", "inertia_kgm2", "box_m"}
_CONVENTIONS = {"dh_modified": "modified", "dh_standard": "standard"}


def _check_keys(table: dict[str, Any], allowed: set[str], where: str) -> None:
    for key in table:
        if key not in allowed:
            close = difflib.get_close_matches(key, sorted(allowed), n=1)
            hint = f" (did you mean {shown(close[0])}?)" if close else ""
            raise ModelError(f"{where}: unknown field {shown(key)}{hint}; allowed: {', '.join(sorted(allowed))}")


def _num(table: dict[str, Any], key: str, where: str, default: float | None = None) -> float:
    """A number field; a length (``_m``) within +-:data:`~jointlock.bounds.MAX_LENGTH_M`, an
    angle (``_deg``) within +-1e6 deg."""
    if key not in table:
        if default is None:
            raise ModelError(f"{where}: missing field {shown(key)}")
        return default
    bound = _BOUND.get(key.rsplit("_", 1)[-1])
    unit = {"m": "m", "deg": "deg"}.get(key.rsplit("_", 1)[-1], "")
    lo = None if bound is None else -bound
    return as_real(table[key], f"{where}: field {shown(key)}", lo=lo, hi=bound, unit=unit, error=ModelError)


#: Bounds of a model file's fields by unit suffix (lengths as the readers allow them).
_BOUND = {"m": MAX_LENGTH_M, "deg": MAX_OPTION_DEG}


def _array(table: dict[str, Any], key: str, where: str, default: Any) -> np.ndarray:
    value = table.get(key, default)
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError, OverflowError):
        raise ModelError(f"{where}: field {shown(key)} must be finite numbers; got {shown(value)}") from None
    if not np.all(np.isfinite(arr)):
        raise ModelError(f"{where}: field {shown(key)} must be finite; got {shown(value)}")
    bound = _BOUND.get(key.rsplit("_", 1)[-1])
    if bound is not None and np.any(np.abs(arr) > bound):
        raise ModelError(f"{where}: field {shown(key)} must lie within +-{bound:g}; got {shown(value)}")
    return arr


def _body(table: dict[str, Any], where: str, name: str) -> Body:
    mass = _num(table, "mass_kg", where, 0.0)
    com = _array(table, "com_m", where, [0.0, 0.0, 0.0])
    inertia = _array(table, "inertia_kgm2", where, [0.0, 0.0, 0.0])
    try:
        return Body(mass, com, inertia, name=name)
    except ModelError as exc:
        raise ModelError(f"{where}: {exc}") from None


def _pose_table(data: dict[str, Any], key: str, where: str) -> np.ndarray:
    """The pose of table ``[key]`` (``xyz_m``, ``rpy_deg``); identity without the table."""
    if key not in data:
        return np.eye(4)
    tw = f"{where}: [{key}]"
    if not isinstance(data[key], dict):
        raise ModelError(f"{tw}: must be a table")
    _check_keys(data[key], _TOOL_KEYS, tw)
    xyz = _array(data[key], "xyz_m", tw, [0.0, 0.0, 0.0])
    rpy = np.radians(_array(data[key], "rpy_deg", tw, [0.0, 0.0, 0.0]))
    if xyz.shape != (3,) or rpy.shape != (3,):
        raise ModelError(f"{tw}: xyz_m and rpy_deg must hold 3 numbers each")
    return pose(rpy_matrix(rpy), xyz)


def model_from_dict(data: dict[str, Any], where: str = "model", folder: str | Path = ".") -> ArmModel:
    """Build a model from the parsed TOML structure (see the module docstring); ``folder``:
    where a ``urdf`` path is relative to."""
    if "urdf" in data:
        return _urdf_model(data, where, Path(folder))
    _check_keys(data, _TOP_KEYS, where)
    convention = data.get("convention")
    if not isinstance(convention, str) or convention not in _CONVENTIONS:
        raise ModelError(
            f"{where}: field 'convention' must be one of {sorted(_CONVENTIONS)}; got {shown(convention)}"
        )
    rows = data.get("joint")
    if not isinstance(rows, list) or not rows:
        raise ModelError(f"{where}: needs at least one [[joint]] table")
    cols: dict[str, list[float]] = {k: [] for k in ("a", "alpha", "d", "theta", "lower", "upper", "vmax", "effort")}
    bodies = []
    flips: list[bool] = []
    slides: list[bool] = []
    radii: list[float] = []
    for i, row in enumerate(rows, start=1):
        jw = f"{where}: joint {i}"
        if not isinstance(row, dict):
            raise ModelError(f"{jw}: must be a table")
        _check_keys(row, _JOINT_KEYS, jw)
        cols["a"].append(_num(row, "a_m", jw, 0.0))
        cols["alpha"].append(math.radians(_num(row, "alpha_deg", jw, 0.0)))
        cols["d"].append(_num(row, "d_m", jw, 0.0))
        cols["theta"].append(math.radians(_num(row, "theta_deg", jw, 0.0)))
        cols["lower"].append(math.radians(_num(row, "lower_deg", jw, -180.0)))
        cols["upper"].append(math.radians(_num(row, "upper_deg", jw, 180.0)))
        vmax = _num(row, "velocity_limit_deg_s", jw, math.inf)
        if vmax <= 0:
            raise ModelError(f"{jw}: field 'velocity_limit_deg_s' must be > 0; got {vmax}")
        cols["vmax"].append(math.radians(vmax))
        effort = _num(row, "effort_limit_Nm", jw, math.inf)
        if effort <= 0:
            raise ModelError(f"{jw}: field 'effort_limit_Nm' must be > 0 [N m]; got {effort}")
        cols["effort"].append(effort)
        if cols["lower"][-1] > cols["upper"][-1]:
            raise ModelError(
                f"{jw}: lower_deg must be <= upper_deg; got {row.get('lower_deg')} > {row.get('upper_deg')}"
            )
        bodies.append(_body(row, jw, str(row.get("name", f"link{i}"))))
        flip = row.get("flip", False)
        if not isinstance(flip, bool):
            raise ModelError(f"{jw}: field 'flip' must be true or false; got {shown(flip)}")
        flips.append(flip)
        slide = row.get("prismatic", False)
        if not isinstance(slide, bool):
            raise ModelError(f"{jw}: field 'prismatic' must be true or false; got {shown(slide)}")
        slides.append(slide)
        radii.append(_num(row, "radius_m", jw, 0.0))
        if radii[-1] < 0:
            raise ModelError(f"{jw}: field 'radius_m' must be >= 0 [m] (0: no collision shape); got {radii[-1]}")
    tool, mount = _pose_table(data, "tool", where), _pose_table(data, "mount", where)
    spacecraft = None
    bus: Box | None = None
    if "base" in data:
        bw = f"{where}: [base]"
        if not isinstance(data["base"], dict):
            raise ModelError(f"{bw}: must be a table")
        _check_keys(data["base"], _BASE_KEYS, bw)
        spacecraft = _body(data["base"], bw, "spacecraft")
        if spacecraft.mass <= 0:
            raise ModelError(
                f"{bw}: field 'mass_kg' must be > 0 for a free-floating base; got {spacecraft.mass}"
            )
        if "box_m" in data["base"]:
            sides = _array(data["base"], "box_m", bw, None)
            if sides.shape != (3,) or np.any(sides <= 0):
                raise ModelError(f"{bw}: field 'box_m' must be 3 side lengths > 0 [m]; got {shown(data['base']['box_m'])}")
            bus = Box(translation(spacecraft.com), sides / 2, name="bus")
    name = data.get("name", "toml-arm")
    if not isinstance(name, str):
        raise ModelError(f"{where}: field 'name' must be a string; got {shown(name)}")
    try:
        model = from_dh(
            name,
            a=cols["a"],
            alpha=cols["alpha"],
            d=cols["d"],
            theta=cols["theta"],
            convention=_CONVENTIONS[convention],  # type: ignore[arg-type]
            bodies=bodies,
            tool=tool,
            lower=cols["lower"],
            upper=cols["upper"],
            velocity_limit=cols["vmax"],
            effort_limit=cols["effort"],
            spacecraft=spacecraft,
            description=str(data.get("description", f"read from {where}")),
            base=mount,
            flip=flips,
            prismatic=slides,
            radius=radii if any(radii) else None,
        )
    except ModelError as exc:  # e.g. a joint's limits: named with the file
        raise ModelError(f"{where}: {exc}") from None
    return model if bus is None else with_root_shapes(model, [bus])


def read_model_toml(path: str | Path) -> ArmModel:
    """Read a TOML model file (format in the module docstring)."""
    data = read_toml_file(path, "model file", ModelError)
    return model_from_dict(data, shorten(str(path)), Path(path).parent)


_URDF_KEYS = {"name", "description", "urdf", "root_link", "tip_link", "freeze_deg", "freeze_m", "meshes"}


def _urdf_model(data: dict[str, Any], where: str, folder: Path) -> ArmModel:
    """The ``urdf = ...`` form: the chain of a URDF tree, floating when its root link has mass."""
    from .urdf import read_urdf

    _check_keys(data, _URDF_KEYS, where)
    texts = {k: data.get(k) for k in ("urdf", "root_link", "tip_link", "name", "description", "meshes")}
    for key, value in texts.items():
        if value is not None and (not isinstance(value, str) or not value):
            raise ModelError(f"{where}: field {shown(key)} must be a non-empty string; got {shown(value)}")
    freeze: dict[str, float] = {}
    units: dict[str, str] = {}
    for key, scale in (("freeze_deg", math.pi / 180.0), ("freeze_m", 1.0)):
        table = data.get(key, {})
        if not isinstance(table, dict):
            raise ModelError(f"{where}: field {shown(key)} must be a table {{joint = value}}; got {shown(table)}")
        for joint, value in table.items():
            if joint in freeze:
                raise ModelError(f"{where}: joint {shown(joint)} is in both freeze_deg and freeze_m")
            limit = MAX_OPTION_DEG if scale != 1.0 else MAX_LENGTH_M
            units[joint] = "m" if key == "freeze_m" else "deg"
            freeze[joint] = scale * as_real(value, f"{where}: {key}.{joint}", lo=-limit, hi=limit, error=ModelError)
    try:
        model = _read_urdf_of(read_urdf, folder, texts, freeze, units)
    except ModelError as exc:  # named with the model file that refers to it
        raise ModelError(f"{where}: {exc}") from None
    if texts["description"]:
        model = replace(model, description=f"{texts['description']} ({model.description})")
    return model.with_base(model.root_body) if model.root_body.mass > 0 else model


def _read_urdf_of(read_urdf: Any, folder: Path, texts: dict[str, Any], freeze: dict[str, float], units: dict[str, str]) -> ArmModel:
    return read_urdf(
        folder / str(texts["urdf"]),
        name=texts["name"],
        root_link=texts["root_link"],
        tip_link=texts["tip_link"],
        freeze=freeze,
        freeze_units=units,
        meshes=texts["meshes"] or "convex",
    )
