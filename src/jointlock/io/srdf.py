"""SRDF (MoveIt's Semantic Robot Description Format): the link pairs it never checks for
collision (issue 27: "an SRDF's ``disable_collisions`` read when given").

An SRDF lists ``<disable_collisions link1="..." link2="..." reason="..."/>`` for pairs of a
URDF's links that are adjacent, always in contact, or can never meet.  jointlock names each
shape of a URDF robot after its link (:mod:`jointlock.io.urdf`), so these pairs are pairs of shape
names: :func:`jointlock.geometry.with_disabled_pairs` makes a model skip them in
:func:`jointlock.collision.clearance`, and ``load_robot(..., chain=UrdfChain(srdf=...))``
(``srdf`` in a scenario, ``--srdf`` on the command line) does so when it reads the URDF.  The rest
of an SRDF (groups, states, end effectors) is not used.  Pinocchio reads the same elements
(``removeCollisionPairs``; ``tests/test_srdf.py`` compares the pairs left and their distances).
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

from ..errors import ModelError
from .files import check_path_text, decode_text, read_input_bytes, shorten

__all__ = ["read_srdf"]


def read_srdf(path: str | Path) -> tuple[tuple[str, str], ...]:
    """The ``(link1, link2)`` pairs of ``path``'s ``<disable_collisions>`` elements, each sorted,
    without repeats.

    Raises
    ------
    ModelError
        The file is missing or not XML, its root is not ``<robot>``, or an element lacks a link
        name (one line, naming the element's number).
    """
    file = check_path_text(path, "SRDF file", ModelError)
    label = shorten(str(file))
    text = decode_text(read_input_bytes(file, "SRDF file", ModelError), f"SRDF {label}", ModelError)
    try:
        root = ET.fromstring(text)
    except (ET.ParseError, LookupError, ValueError) as exc:
        raise ModelError(f"SRDF {label}: malformed XML: {exc}") from None
    if root.tag != "robot":
        raise ModelError(f"SRDF {label}: the root element must be <robot>; got <{shorten(root.tag, 40)}>")
    pairs = []
    for k, element in enumerate(root.iter("disable_collisions")):
        first, second = element.get("link1"), element.get("link2")
        if not first or not second:
            raise ModelError(f"SRDF {label}: <disable_collisions> {k + 1} needs link1 and link2 (two link names)")
        pairs.append(tuple(sorted((first, second))))
    return tuple(sorted(set(pairs)))  # type: ignore[arg-type]
