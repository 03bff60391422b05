"""The serial chain of a URDF tree: from ``root_link`` to ``tip_link``, every other joint frozen.

:func:`select_chain` works on the parsed joints of :mod:`jointlock.io.urdf` and says, for every
link below ``root_link``, which body of the chain it belongs to (``owner``: -1 the root body,
``i`` the link moved by the chain's i-th movable joint) and where it sits in that body's frame.
Frozen joints -- fixed ones, those named in ``freeze``, and every joint off the chain -- are
folded into those placements at their values, so that the bodies behind them merge as
:func:`jointlock.lock` merges a locked joint's.
"""

from __future__ import annotations

import difflib
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..bounds import shown
from ..errors import ModelError
from ..spatial import axis_angle_rotation, pose
from .files import shorten

#: A frozen value may pass a limit by this much (round-off of a value read back from a file).
LIMIT_SLACK = 1e-9


@dataclass
class Chain:
    """What :func:`select_chain` found (see the module docstring)."""

    root: str
    tip: str
    movable: list[tuple[Any, np.ndarray]]  # (joint, placement in the previous body's frame)
    owner: dict[str, int]
    in_owner: dict[str, np.ndarray]
    frozen: dict[str, float] = field(default_factory=dict)  # movable-type joints frozen: value used
    left_out: list[str] = field(default_factory=list)  # links above root_link


def _close(name: str, known: Mapping[str, Any]) -> str:
    """`` (did you mean 'x'?)`` for the known name closest to a misspelt one, else ``""``."""
    match = difflib.get_close_matches(str(name), [str(k) for k in known], n=1)
    return f" (did you mean {shown(match[0])}?)" if match else ""


def _some(names: Sequence[str], limit: int = 5) -> str:
    """The first ``limit`` names, each shortened, for an error line."""
    head = ", ".join(repr(shorten(str(k), 40)) for k in list(names)[:limit])
    return head + (f", ... ({len(names)} in all)" if len(names) > limit else "")


def _motion(joint: Any, value: float) -> np.ndarray:
    """The joint's own motion at ``value`` [rad or m] (after its origin)."""
    if joint.kind == "fixed" or value == 0.0:
        return np.eye(4)
    axis = joint.axis / np.linalg.norm(joint.axis)
    if joint.kind == "prismatic":
        return pose(np.eye(3), axis * value)
    return pose(axis_angle_rotation(axis, value), np.zeros(3))


def _tree(label: str, links: Sequence[str], joints: Sequence[Any]) -> tuple[dict[str, list[Any]], dict[str, Any], str]:
    """Children of each link, the joint above each link, the tree's root (checked: one)."""
    children: dict[str, list[Any]] = {k: [] for k in links}
    above: dict[str, Any] = {}
    for j in joints:
        if j.child in above:
            raise ModelError(f"{label}: link {shown(j.child)} has two parent joints")
        above[j.child] = j
        children[j.parent].append(j)
    roots = [k for k in links if k not in above]
    if len(roots) != 1:
        why = " (every link has a parent: the joints form a cycle)" if not roots else ""
        raise ModelError(f"{label}: expected exactly one root link; found {len(roots)}: [{_some(roots)}]{why}")
    return children, above, roots[0]


def _below(children: Mapping[str, list[Any]], start: str) -> list[str]:
    """``start`` and every link below it, depth first."""
    out, stack = [], [start]
    while stack:
        link = stack.pop()
        out.append(link)
        stack.extend(j.child for j in children[link])
    return out


def select_chain(
    label: str,
    links: Sequence[str],
    joints: Sequence[Any],
    *,
    root_link: str | None = None,
    tip_link: str | None = None,
    freeze: Mapping[str, float] | None = None,
    freeze_units: Mapping[str, str] | None = None,
) -> Chain:
    """The chain from ``root_link`` to ``tip_link`` with every other joint frozen (module
    docstring); refuses, in one line naming what, a link or joint that does not exist, a tip not
    below the root, a branching tree without ``tip_link``, a prismatic or mimic joint left
    movable on the chain, and a frozen value outside its joint's limits.  ``freeze_units``
    (``{joint: "deg" | "m"}``, a model file's ``freeze_deg`` / ``freeze_m``) are checked against
    each joint's type."""
    children, above, tree_root = _tree(label, links, joints)
    reachable = set(_below(children, tree_root))
    unreached = [k for k in links if k not in reachable]
    if unreached:  # beside the tree from the root: links whose joints form a closed loop
        raise ModelError(
            f"{label}: links {_some(unreached)} are not connected to the root link {shown(tree_root)} (their "
            "joints form a closed loop); a model is one tree from its root"
        )
    by_name = {j.name: j for j in joints}
    root = tree_root if root_link is None else root_link
    if root not in children:
        raise ModelError(
            f"{label}: root_link {shown(root)} is not a link of the robot{_close(root, children)} (links: {_some(list(links))})"
        )
    freeze = dict(freeze or {})
    for name, given in freeze.items():
        j = by_name.get(name)
        if j is None:
            raise ModelError(f"{label}: freeze names joint {shown(name)}, which is not in the robot{_close(name, by_name)}")
        if j.kind == "fixed":
            raise ModelError(f"{label}: freeze names joint {shown(name)}, which is fixed already")
        if isinstance(given, bool) or not isinstance(given, (int, float)) or not math.isfinite(given):
            raise ModelError(f"{label}: freeze {shown(name)} must be a finite number; got {shown(given)}")
        unit = (freeze_units or {}).get(name)
        if unit is not None and (unit == "m") != (j.kind == "prismatic"):
            want = "freeze_m [m]" if j.kind == "prismatic" else "freeze_deg [deg]"
            raise ModelError(f"{label}: joint {shown(name)} is {j.kind}: give it in {want}")
    below = _below(children, root)
    free = next((j for link in below for j in children[link] if j.kind in ("planar", "floating")), None)
    if free is not None:
        raise ModelError(
            f"{label}: joint {shown(free.name)}: type {shown(free.kind)} is not supported below root_link {shown(root)} "
            f"(allowed: revolute, continuous, prismatic, fixed); start the chain below it (root_link = "
            f"{shown(free.child)}; base='floating' makes that link a free-floating spacecraft)"
        )
    above_root = [n for n in freeze if by_name[n].child not in below]
    if above_root:
        raise ModelError(f"{label}: freeze names joints [{_some(above_root)}], which are not below root_link {shown(root)}")
    active_below: dict[str, bool] = {}
    for link in reversed(below):  # children before parents
        active_below[link] = any(_active(j, freeze) or active_below[j.child] for j in children[link])
    tip = _tip(label, root, tip_link, children, above, active_below, freeze)
    if not any(j.kind in ("revolute", "continuous") for link in below for j in children[link]):
        raise ModelError(f"{label}: no revolute or continuous joint found" + (f" below {shown(root)}" if root_link else ""))
    path: list[Any] = []
    link = tip
    while link != root:
        path.append(above[link])
        link = above[link].parent
    path.reverse()
    movable = [j for j in path if j.kind != "fixed" and j.name not in freeze]
    for j in movable:
        if j.mimic is not None:
            raise ModelError(
                f"{label}: joint {shown(j.name)} on the chain mimics {shown(j.mimic[0])} (a coupled joint); "
                f"jointlock's joints move independently: freeze it (--freeze {j.name}=VALUE; freeze_deg or "
                "freeze_m in a scenario or model file)"
            )
        if j.kind == "prismatic":
            raise ModelError(
                f"{label}: joint {shown(j.name)} on the chain is prismatic; jointlock's chain has revolute joints "
                f"only: freeze it (--freeze {j.name}=METRES; freeze_m in a scenario or model file) or end the "
                "chain before it (--tip / tip_link)"
            )
    if not movable:
        raise ModelError(f"{label}: no movable joint between root_link {shown(root)} and tip_link {shown(tip)}")
    index = {j.name: i for i, j in enumerate(movable)}
    values: dict[str, float] = {}

    def value(j: Any, seen: tuple[str, ...] = ()) -> float:
        if j.name in values:
            return values[j.name]
        if j.name in freeze:
            v = float(freeze[j.name])
        elif j.mimic is not None:
            master = by_name.get(j.mimic[0])
            if master is None:
                raise ModelError(f"{label}: joint {shown(j.name)} mimics {shown(j.mimic[0])}, which is not a joint")
            if master.name in seen or master.name == j.name:
                raise ModelError(f"{label}: joints [{_some([*seen, j.name])}] mimic each other in a cycle")
            if master.name in index:
                raise ModelError(
                    f"{label}: joint {shown(j.name)} off the chain mimics chain joint {shown(master.name)}: its links "
                    f"would move with it; freeze one of them"
                )
            v = j.mimic[1] * value(master, (*seen, j.name)) + j.mimic[2]
        else:
            v = 0.0
        if not math.isfinite(v) or abs(v) > 1e6:
            raise ModelError(f"{label}: joint {shown(j.name)} would be frozen at {v:g}: give it a value with freeze")
        if j.kind in ("revolute", "prismatic") and not j.lower - LIMIT_SLACK <= v <= j.upper + LIMIT_SLACK:
            # in the unit it was given in (a model file's freeze_deg, the command line's degrees)
            deg = (freeze_units or {}).get(j.name) == "deg"
            scale, unit = (180.0 / math.pi, " deg") if deg else (1.0, " m" if j.kind == "prismatic" else " rad")
            raise ModelError(
                f"{label}: joint {shown(j.name)} is frozen at {v * scale:g}{unit} (off the chain, or named in freeze), "
                f"outside its limits [{j.lower * scale:g}, {j.upper * scale:g}]{unit}: give it a value within "
                f"them (--freeze {j.name}=VALUE, or freeze_deg / freeze_m in a scenario or model file)"
            )
        values[j.name] = v
        return v

    owner: dict[str, int] = {root: -1}
    in_owner: dict[str, np.ndarray] = {root: np.eye(4)}
    placed: list[tuple[Any, np.ndarray]] = []
    for link in below:  # depth first: a parent before its children
        for j in children[link]:
            if j.name in index:
                placed.append((j, in_owner[link] @ j.origin))
                owner[j.child], in_owner[j.child] = index[j.name], np.eye(4)
            else:
                owner[j.child] = owner[link]
                in_owner[j.child] = in_owner[link] @ j.origin @ _motion(j, value(j) if j.kind != "fixed" else 0.0)
    placed.sort(key=lambda jp: index[jp[0].name])
    if owner[tip] != len(movable) - 1:  # pragma: no cover - the path ends after its last movable joint
        raise ModelError(f"{label}: tip_link {shown(tip)} does not follow the chain's last movable joint")
    left_out = [k for k in links if k not in owner]
    return Chain(root, tip, placed, owner, in_owner, values, left_out)


def _tip(
    label: str,
    root: str,
    tip_link: str | None,
    children: Mapping[str, list[Any]],
    above: Mapping[str, Any],
    active_below: Mapping[str, bool],
    freeze: Mapping[str, float],
) -> str:
    """``tip_link`` checked to hang below ``root``, or the end of the one path of movable joints
    from ``root`` (then the unique run of fixed links after it)."""
    if tip_link is not None:
        if tip_link not in children:
            raise ModelError(f"{label}: tip_link {shown(tip_link)} is not a link of the robot{_close(tip_link, children)}")
        link = tip_link
        while link != root:
            if link not in above:
                raise ModelError(f"{label}: tip_link {shown(tip_link)} is not below root_link {shown(root)}")
            link = above[link].parent
        return tip_link
    link = root
    while True:
        branches = [j for j in children[link] if _active(j, freeze) or active_below[j.child]]
        if len(branches) > 1:
            raise ModelError(
                f"{label}: the tree branches at link {shown(link)} into joints [{_some([j.name for j in branches])}]; "
                "name the chain's end with tip_link (a model file's tip_link), or freeze the branches you do not use"
            )
        if not branches:
            break
        link = branches[0].child
    while len(fixed := [j for j in children[link] if j.kind == "fixed"]) == 1:  # frozen fingers beside it
        link = fixed[0].child
    return link


def _active(joint: Any, freeze: Mapping[str, float]) -> bool:
    """A joint that would move on a chain: not fixed, not frozen, not a mimic follower (which
    follows its joint: it never moves on its own)."""
    return joint.kind != "fixed" and joint.name not in freeze and joint.mimic is None
