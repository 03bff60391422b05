"""Giving a model collision geometry (SPEC piece 16, issue 27): capsules along its links, a box
for its spacecraft bus.

The shapes themselves are :mod:`jointlock.shapes`; a model carries them on its bodies
(``Body.shapes``), so that locking merges them like the inertia.  Distances are
:mod:`jointlock.collision`.
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from dataclasses import replace
from typing import cast

from .errors import ModelError
from .model import ArmModel, Body
from .shapes import Box, Shape, box_from_inertia, chain_capsules


def with_link_capsules(model: ArmModel, radius: float | Sequence[float]) -> ArmModel:
    """``model`` with a capsule along each link of its stick figure (the polyline through the
    root, every joint origin and the end effector that the 3-D view draws), replacing the
    links' shapes; the root post (root origin to joint 1) goes to the root body, next to its
    other shapes.

    Parameters
    ----------
    radius
        One radius [m] for every capsule, or (n + 1,) radii: the root post's, then link
        1..n's; 0 leaves that body without a shape.  A zero-length link (an end effector at
        the last joint's origin) gets a sphere.
    """
    if model.locked:
        raise ModelError("give the full arm its capsules, then lock it (locking merges them)")
    root, links = chain_capsules([j.placement for j in model.joints], model.tool, radius)  # type: ignore[arg-type]
    bodies = tuple(replace(b, shapes=s) for b, s in zip(model.bodies, links))
    root_shapes = tuple(s for s in model.root_body.shapes if s.name != "post") + root
    return replace(model, bodies=bodies, root_body=replace(model.root_body, shapes=root_shapes))


def with_root_shapes(model: ArmModel, shapes: Sequence[Shape]) -> ArmModel:
    """``model`` with ``shapes`` added to its root body (the spacecraft bus, a mounting), in
    the root frame.  The root body keeps them with a fixed base too: a held spacecraft is
    still there."""
    return replace(model, root_body=replace(model.root_body, shapes=model.root_body.shapes + tuple(shapes)))


def bus_box(spacecraft: Body, name: str = "bus") -> Box:
    """The spacecraft bus as the uniform box of ``spacecraft``'s mass and inertia, in the root
    frame (:func:`jointlock.shapes.box_from_inertia`): the box the 3-D view draws."""
    return box_from_inertia(spacecraft.mass, spacecraft.com, spacecraft.inertia, name=name)


def with_disabled_pairs(model: ArmModel, pairs: Sequence[tuple[str, str]]) -> ArmModel:
    """``model`` whose clearance never checks ``pairs`` of shape names (URDF link names; an SRDF's
    ``<disable_collisions>``, :func:`jointlock.io.srdf.read_srdf`), added to those it disables
    already; the arm before its locks (``unlocked``) disables them too.  Pairs that name no shape
    of the model are kept (an SRDF covers the whole robot, a chain only part of it); when none of
    ``pairs`` names one, a ``UserWarning`` says so (another robot's SRDF?)."""
    for pair in pairs:
        if isinstance(pair, str) or len(pair) != 2 or not all(isinstance(n, str) for n in pair):
            raise ModelError(f"disabled pairs must be pairs of shape names (two strings each); got {pair!r}")
    names = {s.name for body in (model.root_body, *model.bodies) for s in body.shapes}
    if pairs and not any(a in names or b in names for a, b in pairs):
        warnings.warn(
            f"none of the {len(pairs)} disabled pairs names a link of {model.name}'s collision shapes: is it "
            "this robot's SRDF?",
            UserWarning,
            stacklevel=2,
        )
    # checked by ArmModel (each a pair of names)
    both = cast(tuple[tuple[str, str], ...], tuple(model.disabled_pairs) + tuple(tuple(p) for p in pairs))
    unlocked = None if model.unlocked is None else replace(model.unlocked, disabled_pairs=both)
    return replace(model, disabled_pairs=both, unlocked=unlocked)
