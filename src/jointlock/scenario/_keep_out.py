"""``[[keep_out]]``: volumes the arm must keep clear of, in the root frame (issue 27): a docked
vehicle, a solar array, a payload.  Each entry is one shape::

    [[keep_out]]
    name = "docked vehicle"
    box_m = [2.0, 1.0, 1.0]          # full sizes along the box's axes [m]
    center_m = [3.0, 0.0, -1.0]      # its centre, root frame [m]
    rpy_deg = [0.0, 0.0, 30.0]       # optional: roll, pitch, yaw of its axes [deg]

    [[keep_out]]
    name = "antenna"
    sphere_m = 0.4                   # radius [m]
    center_m = [0.0, 2.5, 0.5]

    [[keep_out]]
    name = "boom of the other arm"
    capsule_m = 0.15                 # radius [m], about the segment from_m -> to_m
    from_m = [1.0, -1.0, 0.0]
    to_m = [1.0, -1.0, 3.0]

The jobs that keep a clearance (``halt_config``, ``halt``) keep ``[limits] clearance_min_m`` from
them too (:class:`jointlock.collision.ClearanceSettings`); every link is checked against them.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from ..bounds import MAX_LENGTH_M, shown
from ..errors import JointlockError, ScenarioError
from ..shapes import Box, Capsule, Shape, Sphere
from ..spatial import pose, rpy_matrix

#: The fields of one entry, by shape.
SHAPE_FIELDS = {
    "box_m": ("center_m", "rpy_deg"),
    "sphere_m": ("center_m",),
    "capsule_m": ("from_m", "to_m"),
}
ALL_FIELDS = ("name", *SHAPE_FIELDS, "center_m", "rpy_deg", "from_m", "to_m")


def check_keep_out(raw: Any, source: str) -> list[dict[str, Any]]:
    """The ``[[keep_out]]`` entries as plain data, each checked (one line naming the entry and
    the field on a bad one)."""
    if not isinstance(raw, list):
        raise ScenarioError(f"{source}: keep_out must be an array of tables ([[keep_out]] entries); got {type(raw).__name__}")
    out = []
    for k, entry in enumerate(raw):
        where = f"{source}: keep_out entry {k + 1}"
        if not isinstance(entry, Mapping):
            raise ScenarioError(f"{where} must be a table; got {shown(entry)}")
        unknown = [key for key in entry if key not in ALL_FIELDS]
        if unknown:
            raise ScenarioError(f"{where}: unknown field {shown(unknown[0])}; allowed: {', '.join(ALL_FIELDS)}")
        kinds = [key for key in SHAPE_FIELDS if key in entry]
        if len(kinds) != 1:
            raise ScenarioError(
                f"{where} needs exactly one of box_m (sizes), sphere_m (radius), capsule_m (radius); got "
                f"{', '.join(kinds) or 'none'}"
            )
        kind = kinds[0]
        allowed = {"name", kind, *SHAPE_FIELDS[kind]}
        extra = [key for key in entry if key not in allowed]
        if extra:
            raise ScenarioError(f"{where}: {extra[0]} does not belong to a {kind[:-2]} (its fields: {', '.join(sorted(allowed))})")
        clean: dict[str, Any] = {"name": _name(entry.get("name", f"keep-out {k + 1}"), where)}
        if kind == "box_m":
            clean["box_m"] = _vector(entry["box_m"], f"{where}: box_m", positive=True)
            clean["center_m"] = _vector(entry.get("center_m"), f"{where}: center_m")
            clean["rpy_deg"] = _vector(entry.get("rpy_deg", [0.0, 0.0, 0.0]), f"{where}: rpy_deg", limit=360.0)
        elif kind == "sphere_m":
            clean["sphere_m"] = _radius(entry["sphere_m"], f"{where}: sphere_m")
            clean["center_m"] = _vector(entry.get("center_m"), f"{where}: center_m")
        else:
            clean["capsule_m"] = _radius(entry["capsule_m"], f"{where}: capsule_m")
            clean["from_m"] = _vector(entry.get("from_m"), f"{where}: from_m")
            clean["to_m"] = _vector(entry.get("to_m"), f"{where}: to_m")
        try:
            shape_of(clean)
        except JointlockError as exc:
            raise ScenarioError(f"{where}: {exc}") from None
        out.append(clean)
    return out


def shape_of(entry: Mapping[str, Any]) -> Shape:
    """The :mod:`jointlock.shapes` shape of one checked entry (root frame, metres)."""
    name = entry["name"]
    if "box_m" in entry:
        frame = pose(rpy_matrix(np.radians(entry["rpy_deg"])), entry["center_m"])
        return Box(frame, 0.5 * np.asarray(entry["box_m"]), name=name)
    if "sphere_m" in entry:
        return Sphere(np.asarray(entry["center_m"]), float(entry["sphere_m"]), name=name)
    return Capsule(np.asarray(entry["from_m"]), np.asarray(entry["to_m"]), float(entry["capsule_m"]), name=name)


def keep_out_shapes(data: Mapping[str, Any]) -> tuple[Shape, ...]:
    """The keep-out shapes of a resolved scenario (none when it has no ``[[keep_out]]``)."""
    return tuple(shape_of(entry) for entry in data.get("keep_out") or ())


def _name(value: Any, where: str) -> str:
    if not isinstance(value, str) or not value.strip():
        raise ScenarioError(f"{where}: name must be a non-empty string; got {shown(value)}")
    return value


def _radius(value: Any, where: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not (
        math.isfinite(value) and 0 < value <= MAX_LENGTH_M
    ):
        raise ScenarioError(f"{where} must be a radius in (0, {MAX_LENGTH_M:g}] m; got {shown(value)}")
    return float(value)


def _vector(value: Any, where: str, *, positive: bool = False, limit: float = MAX_LENGTH_M) -> list[float]:
    ok = (
        isinstance(value, Sequence)
        and not isinstance(value, str)
        and len(value) == 3
        and all(not isinstance(v, bool) and isinstance(v, (int, float)) and math.isfinite(v) and abs(v) <= limit for v in value)
        and (not positive or all(v > 0 for v in value))
    )
    if not ok:
        what = "3 numbers > 0" if positive else "3 finite numbers"
        raise ScenarioError(f"{where} must be {what} within {limit:g}; got {shown(value)}")
    return [float(v) for v in value]
