"""MJCF writer: an :class:`~jointlock.model.ArmModel` -- a crippled arm with its locked joints
folded in and their bodies merged -- as a MuJoCo model file (issue 30), so that the locked arm
and its spacecraft can be simulated, watched and checked in MuJoCo.

What the file holds:

- the root body ``base``: the spacecraft of a free-floating arm, a free body (``<freejoint>``)
  with the spacecraft's mass, centre of mass and inertia; welded to the world for a fixed base
  (held is not absent: its collision geometry is kept either way);
- one body ``link<j>`` per healthy joint ``j`` (the arm's own numbering), placed by the joint's
  placement (position and unit quaternion), with a ``hinge`` joint named as the model names it
  (``joint<j>`` when the name is empty or taken), its unit axis and its angle limits (none for a
  joint without limits), and its body's mass, centre of mass and full inertia tensor
  (``fullinertia``, which MuJoCo diagonalises to round-off);
- gravity: jointlock's arms are in orbit, so ``0 0 0`` unless ``gravity`` is given
  (jointlock's own dynamics take gravity per call: :func:`jointlock.dynamics.rnea`);
- one ``motor`` per healthy joint (gear 1: the control is the joint torque [N m]), its control
  range the joint's effort limit when the model has one;
- the collision geometry (issue 27) as geoms: capsules (``fromto``), spheres, boxes and convex
  hulls (a ``<mesh>`` asset of the hull's vertices), in the body that carries them; every body and its parent (adjacent links, never checked by jointlock;
  MuJoCo would filter them itself except under a body welded to the world) and the pairs jointlock
  measures from their zero-pose contact ("mounted": :mod:`jointlock.collision`) are excluded
  from MuJoCo's contacts.  Geoms carry no mass (``inertiafromgeom="false"``: the inertia is the
  model's); a massless body or a point mass gets MuJoCo's floors :data:`BOUND_MASS_KG`,
  :data:`BOUND_INERTIA_KGM2` (MuJoCo refuses zero);
- a site ``tool`` at the end effector;
- with ``brakes=True`` and a locked model, the *unlocked* chain instead, each locked joint a
  hinge held at its lock angle by a joint equality (``brake<j>``) and given no motor: the
  constraint's force on that joint is the brake torque (what :mod:`jointlock.sim` replays).

Numbers are written in full precision (``repr`` of the float: 17 significant digits at most),
angles in radians.  Reading the file with ``mujoco.MjModel.from_xml_path`` gives jointlock's
inverse dynamics to round-off (``tests/test_mjcf.py``: ``mj_inverse`` against
:func:`jointlock.rnea`, 1e-10 relative).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from xml.sax.saxutils import quoteattr

import numpy as np
from numpy.typing import ArrayLike

from .collision import collision_pairs
from .errors import ModelError
from .io.files import atomic_write_text
from .io.urdf_export import BASE_LINK, TOOL_LINK, refuse_unread_meshes
from .model import ArmModel, Body, FloatArray
from .shapes import Box, Capsule, Convex, Shape, Sphere

__all__ = ["mjcf_text", "quaternion_from_matrix", "write_mjcf"]

#: MuJoCo refuses a moving body without mass or with a zero principal inertia (a point mass, a
#: massless tool link): its compiler raises them to these floors [kg, kg m^2], which change the
#: dynamics by as much (``boundmass``, ``boundinertia``).
BOUND_MASS_KG = 1e-9
BOUND_INERTIA_KGM2 = 1e-12
#: Default simulation step written in ``<option>`` [s] and its integrator (fourth-order
#: Runge-Kutta: the replay's attitude agrees with jointlock's to the step's fourth power).
TIMESTEP_S = 0.001
INTEGRATOR = "RK4"
#: How stiffly a brake holds its joint: MuJoCo's ``solref`` (time constant [s], damping ratio)
#: and ``solimp`` of the joint equalities (stiffer than MuJoCo's default, which lets a held
#: joint creep by ~1e-3 rad under the halt's loads).
BRAKE_SOLREF = (0.004, 1.0)
BRAKE_SOLIMP = (0.9999, 0.9999, 0.001, 0.5, 2.0)


def quaternion_from_matrix(rotation: ArrayLike) -> FloatArray:
    """Unit quaternion ``(w, x, y, z)`` (MuJoCo's order, ``w >= 0``) of a rotation matrix
    (3, 3) (Shepperd's method: the largest of the four squares first, no loss near 180 deg)."""
    r = np.asarray(rotation, dtype=float)
    trace = np.trace(r)
    squares = np.array([trace, r[0, 0], r[1, 1], r[2, 2]])
    k = int(np.argmax(squares))
    if k == 0:
        s = 2.0 * math.sqrt(1.0 + trace)
        q = [0.25 * s, (r[2, 1] - r[1, 2]) / s, (r[0, 2] - r[2, 0]) / s, (r[1, 0] - r[0, 1]) / s]
    elif k == 1:
        s = 2.0 * math.sqrt(1.0 + r[0, 0] - r[1, 1] - r[2, 2])
        q = [(r[2, 1] - r[1, 2]) / s, 0.25 * s, (r[0, 1] + r[1, 0]) / s, (r[0, 2] + r[2, 0]) / s]
    elif k == 2:
        s = 2.0 * math.sqrt(1.0 + r[1, 1] - r[0, 0] - r[2, 2])
        q = [(r[0, 2] - r[2, 0]) / s, (r[0, 1] + r[1, 0]) / s, 0.25 * s, (r[1, 2] + r[2, 1]) / s]
    else:
        s = 2.0 * math.sqrt(1.0 + r[2, 2] - r[0, 0] - r[1, 1])
        q = [(r[1, 0] - r[0, 1]) / s, (r[0, 2] + r[2, 0]) / s, (r[1, 2] + r[2, 1]) / s, 0.25 * s]
    out = np.array(q)
    out /= np.linalg.norm(out)
    return -out if out[0] < 0 else out


def _num(value: float) -> str:
    return repr(float(value) + 0.0)  # + 0.0: no "-0.0"


def _vec(values: ArrayLike) -> str:
    return " ".join(_num(v) for v in np.asarray(values, dtype=float).ravel())


def _frame(transform: FloatArray) -> str:
    t = np.asarray(transform, dtype=float)
    return f'pos="{_vec(t[:3, 3])}" quat="{_vec(quaternion_from_matrix(t[:3, :3]))}"'


def _inertial(body: Body) -> str:
    i = body.inertia
    full = [i[0, 0], i[1, 1], i[2, 2], i[0, 1], i[0, 2], i[1, 2]]
    return f'<inertial pos="{_vec(body.com)}" mass="{_num(body.mass)}" fullinertia="{_vec(full)}"/>'


class _Names:
    """Unique MuJoCo names (MuJoCo refuses two elements of one kind with the same name)."""

    def __init__(self) -> None:
        self.taken: set[str] = set()

    def __call__(self, wanted: str, fallback: str) -> str:
        name = wanted or fallback
        base, k = name, 2
        while name in self.taken:
            name, k = f"{base} #{k}", k + 1
        self.taken.add(name)
        return name


def _geoms(shapes: Sequence[Shape], body_name: str, names: _Names, assets: list[str]) -> list[str]:
    """The geoms of ``shapes``; a convex hull's vertices go to ``assets`` as a ``<mesh>``
    (MuJoCo collides a mesh by its convex hull)."""
    out = []
    for k, shape in enumerate(shapes):
        name = quoteattr(names(shape.name, f"{body_name}/shape{k + 1}"))
        if isinstance(shape, Convex):
            mesh = quoteattr(f"{body_name}/mesh{len(assets) + 1}")
            assets.append(f"<mesh name={mesh} vertex=\"{_vec(shape.vertices.ravel())}\"/>")
            out.append(f'<geom name={name} type="mesh" mesh={mesh} {_frame(shape.pose)}/>')
        elif isinstance(shape, Box):
            out.append(f'<geom name={name} type="box" {_frame(shape.pose)} size="{_vec(shape.half_extents)}"/>')
        elif isinstance(shape, Sphere) or (isinstance(shape, Capsule) and shape.length == 0):
            center = shape.center if isinstance(shape, Sphere) else shape.a
            out.append(f'<geom name={name} type="sphere" pos="{_vec(center)}" size="{_num(shape.radius)}"/>')
        else:
            out.append(
                f'<geom name={name} type="capsule" fromto="{_vec(np.concatenate([shape.a, shape.b]))}" '
                f'size="{_num(shape.radius)}"/>'
            )
    return out


def mjcf_text(
    model: ArmModel,
    *,
    gravity: ArrayLike = (0.0, 0.0, 0.0),
    brakes: bool = False,
    timestep: float = TIMESTEP_S,
    base: str | None = None,
    brakes_engaged: bool = True,
) -> str:
    """The MJCF document of ``model`` (see the module docstring).

    Parameters
    ----------
    model
        The (locked) arm; ``model.floating`` decides a free or a welded spacecraft.
    gravity
        (3,) gravity in the world frame [m/s^2] (the spacecraft's frame at the start); 0 in orbit.
    brakes
        Write the unlocked chain with each locked joint held by a joint equality at its lock
        angle (``brake<j>``), for a replay that measures the brake torque.  Needs the model's
        unlocked arm (:attr:`ArmModel.unlocked`).
    timestep
        ``<option timestep>`` [s].
    base
        ``"floating"`` (a free spacecraft) or ``"fixed"`` (welded); default the model's.
    brakes_engaged
        With ``brakes``: False writes each brake inactive (``active="false"``) and gives its
        joint a motor too, for a replay in which the joint moves until it locks (the replay turns
        the brake on: ``MjData.eq_active``).
    """
    g = np.asarray(gravity, dtype=float)
    if g.shape != (3,) or not np.all(np.isfinite(g)):
        raise ModelError(f"gravity must be 3 finite numbers [m/s^2]; got {np.asarray(gravity).tolist()}")
    if not (isinstance(timestep, (int, float)) and 0 < timestep <= 1):
        raise ModelError(f"timestep must be a number in (0, 1] [s]; got {timestep!r}")
    if base not in (None, "fixed", "floating"):
        raise ModelError(f"base must be 'fixed' or 'floating'; got {base!r}")
    floating = model.floating if base is None else base == "floating"
    refuse_unread_meshes(model, "MJCF")
    if floating and not model.root_body.mass > 0:
        raise ModelError(
            f"{model.name!r} is free-floating but its spacecraft has no mass: MuJoCo cannot float a massless body "
            "(give the root body a mass, or export with a fixed base)"
        )
    held = {lj.number: lj.angle for lj in model.locked} if brakes else {}
    chain = model
    if held:
        if model.unlocked is None:
            raise ModelError(f"brakes=True needs the unlocked arm of {model.name!r} (model.unlocked is None)")
        chain = model.unlocked
    locked_text = ", ".join(f"joint {lj.number} at {math.degrees(lj.angle):.12g} deg" for lj in model.locked)
    how = "held by brakes (joint equalities)" if held else "folded into the chain, bodies merged"
    names, joint_names = _Names(), _Names()
    assets: list[str] = []
    body_of_link: dict[int, str] = {}
    lines = [
        f"<mujoco model={quoteattr(model.name)}>",
        f"  <!-- written by jointlock; locked: {locked_text or 'none'} ({how}); "
        f"base: {'floating' if floating else 'fixed'} -->",
        f'  <compiler angle="radian" autolimits="true" inertiafromgeom="false" boundmass="{_num(BOUND_MASS_KG)}" '
        f'boundinertia="{_num(BOUND_INERTIA_KGM2)}"/>',
        f'  <option gravity="{_vec(g)}" timestep="{_num(timestep)}" integrator="{INTEGRATOR}"/>',
        "  <worldbody>",
        f"    <body name={quoteattr(BASE_LINK)}>",
    ]
    if floating:
        lines.append(f"      <freejoint name={quoteattr(BASE_LINK)}/>")
    root = chain.root_body
    if root.mass > 0:
        lines.append(f"      {_inertial(root)}")
    lines += [f"      {g_}" for g_ in _geoms(root.shapes, BASE_LINK, names, assets)]
    for shape in root.shapes:
        body_of_link.setdefault(shape.link if shape.link is not None else 0, BASE_LINK)
    actuators, equalities = [], []
    indent = "      "
    lows, highs = chain.angle_range()
    for joint, body, low, high in zip(chain.joints, chain.bodies, lows, highs):
        body_name = f"link{joint.number}"
        joint_name = quoteattr(joint_names(joint.name, f"joint{joint.number}"))
        limited = math.isfinite(joint.lower) or math.isfinite(joint.upper)
        limits = f' range="{_num(low)} {_num(high)}"' if limited else ""
        lines += [
            f"{indent}<body name={quoteattr(body_name)} {_frame(joint.placement)}>",
            f'{indent}  <joint name={joint_name} type="hinge" axis="{_vec(joint.axis)}"{limits}/>',
        ]
        if body.mass > 0:
            lines.append(f"{indent}  {_inertial(body)}")
        lines += [f"{indent}  {g_}" for g_ in _geoms(body.shapes, body_name, names, assets)]
        for shape in body.shapes:
            body_of_link.setdefault(shape.link if shape.link is not None else joint.number, body_name)
        if joint.number in held:
            active = "" if brakes_engaged else ' active="false"'
            equalities.append(
                f'    <joint name="brake{joint.number}" joint1={joint_name} '
                f'polycoef="{_num(held[joint.number])} 0 0 0 0" solref="{_vec(BRAKE_SOLREF)}" '
                f'solimp="{_vec(BRAKE_SOLIMP)}"{active}/>'
            )
        if joint.number not in held or not brakes_engaged:
            effort = f' ctrlrange="{_num(-joint.effort_limit)} {_num(joint.effort_limit)}"' if math.isfinite(joint.effort_limit) else ""
            actuators.append(f"    <motor name={joint_name} joint={joint_name} gear=\"1\"{effort}/>")
        indent += "  "
    lines.append(f'{indent}<site name={quoteattr(TOOL_LINK)} {_frame(chain.tool)} size="0.02"/>')
    for k in range(len(chain.joints), -1, -1):
        lines.append(f"{'      ' + '  ' * (k - 1) if k else '    '}</body>")
    lines.append("  </worldbody>")
    if assets:
        at = lines.index("  <worldbody>")
        lines[at:at] = ["  <asset>", *[f"    {a_}" for a_ in assets], "  </asset>"]
    # a body and its parent never touch in jointlock (adjacent links); MuJoCo filters that pair
    # itself except under a body welded to the world (a fixed base), so it is written out
    chain_bodies = [BASE_LINK] + [f"link{joint.number}" for joint in chain.joints]
    excluded = list(zip(chain_bodies[:-1], chain_bodies[1:]))
    excluded += [pair for pair in _mounted_body_pairs(model, body_of_link) if pair not in excluded and pair[::-1] not in excluded]
    if excluded:
        lines += ["  <contact>"] + [
            f"    <exclude body1={quoteattr(a)} body2={quoteattr(b)}/>" for a, b in excluded
        ] + ["  </contact>"]
    if equalities:
        lines += ["  <equality>", *equalities, "  </equality>"]
    if actuators:
        lines += ["  <actuator>", *actuators, "  </actuator>"]
    lines.append("</mujoco>")
    return "\n".join(lines) + "\n"


def _mounted_body_pairs(model: ArmModel, body_of_link: dict[int, str]) -> list[tuple[str, str]]:
    """The body pairs holding a pair that jointlock measures from its zero-pose contact."""
    pairs = collision_pairs(model)
    out: list[tuple[str, str]] = []
    for (link_a, _, link_b, _), offset in zip(pairs.keys, pairs.offsets):
        a, b = body_of_link.get(link_a), body_of_link.get(link_b)
        if offset < 0 and a is not None and b is not None and a != b and (a, b) not in out and (b, a) not in out:
            out.append((a, b))
    return out


def write_mjcf(
    model: ArmModel,
    path: str | Path,
    *,
    gravity: ArrayLike = (0.0, 0.0, 0.0),
    brakes: bool = False,
    timestep: float = TIMESTEP_S,
    base: str | None = None,
) -> Path:
    """Write :func:`mjcf_text` to ``path`` (atomically); returns the path."""
    path = Path(path)
    atomic_write_text(path, mjcf_text(model, gravity=gravity, brakes=brakes, timestep=timestep, base=base))
    return path
