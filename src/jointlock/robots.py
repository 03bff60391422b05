"""The seeds' robots, built in: ``halt7`` (000), ``canadarm7`` (004, also 001's arm) and
``puma6`` (002).  Each factory documents the readings of its paper that it chose.

Use :func:`load_robot` to get one by name (or to read a ``.urdf`` / ``.toml`` model file).
"""

from __future__ import annotations

import difflib
import functools
import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from stat import S_ISREG
from typing import Any, Literal, cast

import numpy as np

from .bounds import shown
from .dh import from_dh
from .errors import ModelError
from .geometry import bus_box, with_disabled_pairs, with_link_capsules, with_root_shapes
from .io.files import check_path_text
from .model import ArmModel, Body, FloatArray, Joint
from .shapes import Box
from .spatial import rot_x, translation

BaseMode = Literal["fixed", "floating"]


def _check_base(base: str) -> None:
    if base not in ("fixed", "floating"):
        raise ModelError(f"base must be 'fixed' or 'floating'; got {base!r}")


# -- halt7 (seed 000, Tables 6-7) ----------------------------------------------------------

#: Default spacecraft for ``halt7``.  000 gives no base: this one is ours, a 2000 kg body
#: shaped like a 2 m cube (I = m s^2 / 6), its centre of mass 1 m below the arm's mounting
#: point (the root frame origin).
HALT7_SPACECRAFT = Body(
    2000.0, np.array([0.0, 0.0, -1.0]), np.diag([2000.0 * 4 / 6] * 3), name="spacecraft"
)


#: Radius of ``halt7``'s link capsules [m] (ours, see :func:`halt7`).
HALT7_LINK_RADIUS = 0.1


def halt7(*, base: BaseMode = "fixed", theta_offsets: bool = False) -> ArmModel:
    """The 7-DOF space manipulator of seed 000 (Tables 6 and 7).

    Readings chosen (SPEC "Built-in robots"):

    * **Modified DH (Craig).**  Table 6 has a row 0 holding only ``a, alpha`` and a row 7
      holding only ``theta, d``: that is Craig's layout, row ``i`` listing
      ``(a_{i-1}, alpha_{i-1})`` next to ``(theta_i, d_i)``.  Table 7 then fits: the two 70 kg
      booms (links 3 and 4) have their centres of mass at ``[2.5, 0, 0]`` m, the middle of the
      5 m booms that run along ``x_3`` and ``x_4`` from joints 3 and 4 to joints 4 and 5.  In
      the standard reading the booms end at frames 3 and 4 and those centres of mass would
      lie outside them.  The tip pose is the same in both readings.
    * **theta column = the initial configuration, not an offset** (``theta_offsets=False``,
      default).  Adding it (+90 deg on joint 2, -90 deg on joint 6) puts 000's own optimal
      and sub-optimal halt configurations (§5.1: q_best has q2 = -90, q6 = 90; q_sub has
      q2 = 90, q6 = -90) at q2, q6 in {0, 180} deg, where the shoulder and wrist axes
      align: both become exactly singular (sigma_min ~ 1e-16), which a halt-configuration
      optimum cannot be.  So 000's printed joint angles are full DH angles.  Pass
      ``theta_offsets=True`` for the other reading.
    * Limits: [-180, 180] deg on every joint (000 §5.1); speed limit 40 deg/s (000 §5.2).
    * Masses, centres of mass and principal inertias from Table 7, as printed, in each link's
      DH frame.  The end effector is DH frame 7 (row 7's ``d_7 = 0.6`` m places it).
    * Base: 000 gives none; ``base="floating"`` attaches :data:`HALT7_SPACECRAFT` (ours).
    * Collision geometry (ours; 000 gives none): a capsule of radius :data:`HALT7_LINK_RADIUS`
      = 0.1 m along each link of the stick figure (root post, joint origins, end effector; the
      last link, of zero length, a sphere at the end effector), and the spacecraft bus as the
      2 m cube of :data:`HALT7_SPACECRAFT`'s mass and inertia, with either base (a held
      spacecraft is still there).  Table 7's axial moments imply solid cylinders of radius
      ``sqrt(2 I_axial / m)`` = 0.050 m (booms) and 0.049 m (short links); 0.1 m, twice that,
      is an envelope for the joint housings and the radius ``canadarm7`` uses, so a clearance
      found here is a lower bound for the thinner solid.
    """
    _check_base(base)
    deg = math.radians
    a = [0.0, 0.0, 0.0, 5.0, 5.0, 0.0, 0.0]
    alpha = [deg(v) for v in (0.0, 90.0, -90.0, 0.0, 0.0, 90.0, -90.0)]
    d = [0.6, 0.5, 0.5, 0.5, 0.5, 0.5, 0.6]
    theta = [deg(v) for v in (0.0, 90.0, 0.0, 0.0, 0.0, -90.0, 0.0)] if theta_offsets else None
    table7 = [
        (42.5, (0.89, 0.05, 0.89), (0.0, 0.25, 0.0)),
        (42.5, (0.05, 0.89, 0.89), (0.0, 0.25, 0.0)),
        (70.0, (0.088, 145.83, 145.83), (2.5, 0.0, 0.0)),
        (70.0, (0.088, 145.83, 145.83), (2.5, 0.0, 0.0)),
        (42.5, (0.89, 0.89, 0.05), (0.0, 0.0, -0.25)),
        (42.5, (0.89, 0.89, 0.05), (0.0, 0.0, -0.25)),
        (42.5, (1.28, 1.28, 0.05), (0.0, 0.0, -0.3)),
    ]
    bodies = [
        Body(m, np.array(com), np.array(inertia), name=f"link{i + 1}")
        for i, (m, inertia, com) in enumerate(table7)
    ]
    model = from_dh(
        "halt7",
        a=a,
        alpha=alpha,
        d=d,
        theta=theta,
        convention="modified",
        bodies=bodies,
        lower=[-math.pi] * 7,
        upper=[math.pi] * 7,
        velocity_limit=[deg(40.0)] * 7,
        spacecraft=HALT7_SPACECRAFT if base == "floating" else None,
        description=(
            "Seed 000 Tables 6-7 read as modified DH; theta column "
            + ("added as joint offsets" if theta_offsets else "taken as the initial configuration, not added")
            + f" (theta_offsets={theta_offsets}); spacecraft base: jointlock's default (000 gives none)."
        ),
    )
    return with_root_shapes(with_link_capsules(model, HALT7_LINK_RADIUS), [bus_box(HALT7_SPACECRAFT)])


# -- canadarm7 (seed 004, §5) -------------------------------------------------------------

#: 004 §5 lengths [m]: a = c = f = h = k = l = 0.5, d = e = 2.5.
CANADARM7_LENGTHS = {"l": 0.5, "a": 0.5, "c": 0.5, "d": 2.5, "e": 2.5, "f": 0.5, "h": 0.5, "k": 0.5}
#: 004 §5 masses [kg]: spacecraft m0 = 1000, m1 = m2 = m5 = m6 = m7 = 30, m3 = m4 = 100.
CANADARM7_MASSES = (1000.0, 30.0, 30.0, 100.0, 100.0, 30.0, 30.0, 30.0)


def canadarm7(*, base: BaseMode = "fixed") -> ArmModel:
    """The Canadarm2/SSRMS-structure 7-DOF arm of seed 004 with its §5 numbers (also the
    SSRMS-type arm of 001, whose own table was lost).

    004 prints no DH table.  The frames are inferred from its text and its simplified
    Jacobian eq. (15) (derivation in ``docs/readings/canadarm7-004.md``):

    * Modified DH (Craig), all theta offsets 0:
      ``alpha_{i-1} = [0, 90, -90, 0, 0, 90, -90] deg``, ``a_{i-1} = [0, 0, 0, d, e, 0, 0]``,
      ``d_i = [l, a, c, 0, f, h, 0]``, tool ``Tz(k)``.  The paper's frame Sigma_{i-1} is Craig
      frame {i}.  With these frames the geometric Jacobian, referred to the origin of Craig
      frame {5} (where axes 5 and 6 meet) and expressed in that frame, equals eq. (15)
      symbolically (tested numerically to 1e-12).
    * Eq. (15) leaves free: d_1 (taken = l, base centre of mass to joint 1 along z_1), the
      tool length k, the offsets of joints 1 and 7, and the split of c + f between d_3 and
      d_5; the choice gives every physical segment its §5 length.
    * Link frames sit at 004's joint points J_1..J_7 (frames 5 and 6 are slid along their
      own axes from the Craig origins, which changes nothing kinematically), so that the
      vector from frame k to frame k+1 is 004's physical segment of link k
      (a, c, d, e, f, h, then k to the tool).  Each link is a 0.1 m-radius solid cylinder
      along its segment, centre of mass at the midpoint (004 Table 1: a_i = b_i = L_i / 2;
      the cylinders are ours: 004 gives no inertias).  Spacecraft: 1000 kg, a 2 m cube
      (ours), centre of mass at the root-frame origin, joint 1 at l = 0.5 m along z.
    * Virtual manipulator: ``virtual_link_vectors(model, weighting="segment")`` is 004's
      formula (each segment of link i scaled by (m_0 + ... + m_i) / M) and reproduces its
      printed virtual lengths; the default ``"vafa-dubowsky"`` weighting is the exact one.
    * Collision geometry: each link's 0.1 m cylinder as a capsule along its segment (the
      root post, joint 1 at l = 0.5 m, likewise) and the bus as a 2 m cube, with either base.
      004 puts joint 1 only l = 0.5 m from the spacecraft's centre of mass, inside the 2 m cube
      of its inertia (which the 3-D view draws, centred there): the bus is that cube moved down
      by 0.5 m so that joint 1 stands on its top face (a spacecraft whose centre of mass is not
      its middle).  Pairs touching at the zero pose are mounted (:mod:`jointlock.collision`).
    """
    _check_base(base)
    L = CANADARM7_LENGTHS
    deg = math.radians
    placements = [
        translation([0.0, 0.0, L["l"]]),
        rot_x(deg(90.0)) @ translation([0.0, 0.0, L["a"]]),
        rot_x(deg(-90.0)) @ translation([0.0, 0.0, L["c"]]),
        translation([L["d"], 0.0, 0.0]),
        translation([L["e"], 0.0, 0.0]),
        translation([0.0, 0.0, L["f"]]) @ rot_x(deg(90.0)),
        translation([0.0, 0.0, L["h"]]) @ rot_x(deg(-90.0)),
    ]
    tool = translation([0.0, 0.0, L["k"]])
    radius = 0.1
    # (segment direction in the link frame, length) for links 1..7
    segments = [
        ((0, -1, 0), L["a"]),
        ((0, 1, 0), L["c"]),
        ((1, 0, 0), L["d"]),
        ((1, 0, 0), L["e"]),
        ((0, 0, 1), L["f"]),
        ((0, 0, 1), L["h"]),
        ((0, 0, 1), L["k"]),
    ]
    bodies = []
    for i, (direction, length) in enumerate(segments):
        mass = CANADARM7_MASSES[i + 1]
        u = np.array(direction, dtype=float)
        axial = mass * radius**2 / 2.0
        transverse = mass * (3.0 * radius**2 + length**2) / 12.0
        inertia = transverse * np.eye(3) + (axial - transverse) * np.outer(u, u)
        bodies.append(Body(mass, 0.5 * length * u, inertia, name=f"link{i + 1}"))
    joints = tuple(Joint(placements[i], number=i + 1, name=f"joint{i + 1}") for i in range(7))
    spacecraft = Body(
        CANADARM7_MASSES[0], np.zeros(3), np.diag([CANADARM7_MASSES[0] * 4.0 / 6.0] * 3), name="spacecraft"
    )
    model = ArmModel(
        name="canadarm7",
        joints=joints,
        bodies=tuple(bodies),
        tool=tool,
        root_body=spacecraft if base == "floating" else Body(0.0, name="root"),
        floating=base == "floating",
        description=(
            "Seed 004 Canadarm2 structure with its §5 lengths and masses; frames inferred from eq. (15) "
            "(modified DH, zero offsets, frames at 004's joint points); link inertias and spacecraft shape ours."
        ),
    )
    # the cube of the spacecraft's inertia, moved down so that joint 1 stands on its top face
    cube = bus_box(spacecraft)
    bus = Box(translation([0.0, 0.0, L["l"] - cube.half_extents[2]]) @ cube.pose, cube.half_extents, name="bus")
    return with_root_shapes(with_link_capsules(model, radius), [bus])


# -- puma6 (seed 002, Table 1) --------------------------------------------------------------

#: Lengths recovered from 002's worked examples [m] (see :func:`puma6`).
PUMA6_A2 = 0.985
PUMA6_D4 = -0.765
PUMA6_D6 = 0.382
#: Radius of ``puma6``'s link capsules [m] (illustrative, as its masses).
PUMA6_LINK_RADIUS = 0.06

#: Default spacecraft for ``puma6`` (002 has a fixed base; this one is ours): 500 kg, a
#: 1.2 m cube (I = m s^2 / 6), centre of mass 0.8 m below the root frame origin.
PUMA6_SPACECRAFT = Body(
    500.0, np.array([0.0, 0.0, -0.8]), np.diag([500.0 * 1.44 / 6] * 3), name="spacecraft"
)


def puma6(*, base: BaseMode = "fixed") -> ArmModel:
    """The non-redundant 6-DOF arm of seed 002 (Table 1), PUMA-like, spherical wrist.

    Readings chosen (each forced by 002's own numbers; derivation and residuals in
    ``docs/readings/puma6-002.md``):

    * **Standard DH**, although Table 1's header says ``a_{i-1}, alpha_{i-1}``: only the
      standard reading reproduces the printed end-effector positions (best max residual
      0.38 of the last printed digit; every modified-DH or offset-added reading misses by
      metres).  ``alpha = [-90, 0, 90, -90, 90, 0] deg``.
    * **The theta column [90, 0, 90, 0, 0, 0] is not added**: with it no length fits.
    * **a2 = 0.985 m, d4 = -0.765 m, d6 = 0.382 m**, fitted by least squares to every
      printed example (positions printed in mm to 4 decimals): raw fit 984.999942,
      -764.999962, 381.999945 mm, 1-sigma 8e-5 mm, so the round millimetre values are
      pinned.  d4 is negative because Table 1 keeps ``alpha_3 = +90 deg``.
    * 002's Euler angles are ZYX: ``R = Rz(yaw) Ry(pitch) Rx(roll)``, printed
      ``[yaw, pitch, roll]`` in radians; positions in mm.
    * 002 gives no joint limits (+-180 deg here) and no masses: the link masses below are
      illustrative (ours), each link a slender rod between consecutive DH origins.
    * Collision geometry (illustrative too): a capsule of radius :data:`PUMA6_LINK_RADIUS`
      along each of those rods and the bus as the 1.2 m cube of :data:`PUMA6_SPACECRAFT`'s
      mass and inertia, with either base.
    """
    _check_base(base)
    deg = math.radians
    a = [0.0, PUMA6_A2, 0.0, 0.0, 0.0, 0.0]
    alpha = [deg(v) for v in (-90.0, 0.0, 90.0, -90.0, 90.0, 0.0)]
    d = [0.0, 0.0, 0.0, PUMA6_D4, 0.0, PUMA6_D6]
    masses = [20.0, 25.0, 10.0, 6.0, 3.0, 2.0]
    bodies = []
    for i in range(6):
        fixed = translation([0.0, 0.0, d[i]]) @ translation([a[i], 0.0, 0.0]) @ rot_x(alpha[i])
        inverse = cast(FloatArray, np.linalg.inv(fixed))  # numpy stubs: floating[Any]
        previous_origin = inverse[:3, 3]  # previous DH origin, in DH frame i
        length = float(np.linalg.norm(previous_origin))
        rod = masses[i] * max(length, 0.1) ** 2 / 12.0
        bodies.append(Body(masses[i], 0.5 * previous_origin, np.diag([rod, rod, rod]), name=f"link{i + 1}"))
    model = from_dh(
        "puma6",
        a=a,
        alpha=alpha,
        d=d,
        convention="standard",
        bodies=bodies,
        spacecraft=PUMA6_SPACECRAFT if base == "floating" else None,
        description=(
            "Seed 002 Table 1 read as standard DH, theta column not added; a2, d4, d6 recovered "
            "from the worked examples; masses illustrative (002 gives none)."
        ),
    )
    return with_root_shapes(with_link_capsules(model, PUMA6_LINK_RADIUS), [bus_box(PUMA6_SPACECRAFT)])


# -- registry -------------------------------------------------------------------------------

# Models are immutable (frozen, read-only arrays), so one process builds each model once and
# shares it: a failure campaign loads the same arm for thousands of cases, in every worker.


@functools.lru_cache(maxsize=16)
def _builtin(name: str, base: BaseMode) -> ArmModel:
    return _builtin_factories()[name](base=base)


def _mentions_urdf(path: Path) -> bool:
    """A regular model file that may name a URDF (its first MB says "urdf"): read uncached."""
    with open(path, "rb") as fh:
        return b"urdf" in fh.read(1_000_000)


#: A scenario's fields naming the chain of a URDF tree (the command line's --root, --tip, --freeze).
CHAIN_FIELDS: tuple[str, ...] = ("root_link", "tip_link", "freeze_deg", "freeze_m", "srdf", "meshes")


@dataclass(frozen=True)
class UrdfChain:
    """Which chain of a URDF robot to read (:func:`jointlock.read_urdf`'s ``root_link``,
    ``tip_link`` and ``freeze``), as a scenario or the command line gives it.

    ``freeze_deg``: ``((revolute joint, value [deg]), ...)``; ``freeze_m``: ``((prismatic
    joint, value [m]), ...)``; ``srdf``: an SRDF file whose ``<disable_collisions>`` pairs the
    clearance never checks (:func:`jointlock.io.srdf.read_srdf`); ``meshes``: ``"skip"`` leaves
    the ``<collision>`` meshes out (default, None: each read as its convex hull,
    :func:`jointlock.read_urdf`).  Hashable: part of :func:`load_robot`'s cache key.
    """

    root_link: str | None = None
    tip_link: str | None = None
    freeze_deg: tuple[tuple[str, float], ...] = ()
    freeze_m: tuple[tuple[str, float], ...] = ()
    srdf: str | None = None
    meshes: str | None = None

    def __post_init__(self) -> None:
        if self.meshes is not None and self.meshes not in ("convex", "skip"):
            raise ModelError(f"meshes must be 'convex' or 'skip' (or None: convex); got {shown(self.meshes)}")

    @classmethod
    def from_fields(cls, data: Mapping[str, Any]) -> UrdfChain | None:
        """The chain named by :data:`CHAIN_FIELDS` of ``data`` (a validated scenario); None
        when it names none."""
        for key in ("root_link", "tip_link"):
            if data.get(key) is not None and not str(data[key]).strip():
                raise ModelError(f"{key} must name a link of the URDF; got an empty string (leave it out for the default)")
        chain = cls(
            data.get("root_link") or None,
            data.get("tip_link") or None,
            tuple((str(k), float(v)) for k, v in (data.get("freeze_deg") or {}).items()),
            tuple((str(k), float(v)) for k, v in (data.get("freeze_m") or {}).items()),
            data.get("srdf") or None,
            data.get("meshes") or None,
        )
        return chain if chain != cls() else None

    def fields(self) -> dict[str, Any]:
        """The given fields as a scenario writes them (``freeze_deg = {joint = value}``)."""
        out: dict[str, Any] = {"root_link": self.root_link, "tip_link": self.tip_link}
        out.update(freeze_deg=dict(self.freeze_deg), freeze_m=dict(self.freeze_m), srdf=self.srdf, meshes=self.meshes)
        return {k: v for k, v in out.items() if v}


def _read_urdf_chain(path: str, base: BaseMode, chain: UrdfChain | None) -> ArmModel:
    from .io.urdf import read_urdf

    if chain is None:
        return read_urdf(path, base=base)
    if chain.srdf is not None:
        from .io.srdf import read_srdf

        plain = UrdfChain(chain.root_link, chain.tip_link, chain.freeze_deg, chain.freeze_m, meshes=chain.meshes)
        return with_disabled_pairs(_read_urdf_chain(path, base, plain), read_srdf(chain.srdf))
    freeze = {k: math.radians(v) for k, v in chain.freeze_deg} | dict(chain.freeze_m)
    units = {k: "deg" for k, _ in chain.freeze_deg} | {k: "m" for k, _ in chain.freeze_m}
    if len(units) < len(chain.freeze_deg) + len(chain.freeze_m):
        twice = sorted({k for k, _ in chain.freeze_deg} & {k for k, _ in chain.freeze_m})
        raise ModelError(f"{path}: joint {shown(twice[0])} is frozen in both degrees and metres; give it once")
    return read_urdf(
        path, base=base, root_link=chain.root_link, tip_link=chain.tip_link, freeze=freeze, freeze_units=units,
        meshes="skip" if chain.meshes == "skip" else "convex",
    )  # fmt: skip


@functools.lru_cache(maxsize=32)
def _read_model_file(
    path: str, base: BaseMode, stamp: tuple[str, int, int] | None, chain: UrdfChain | None = None
) -> ArmModel:
    """A model file read once per (absolute path, base, modification time, size, chain): an
    edited file is read again."""
    del stamp  # part of the cache key only
    if Path(path).suffix.lower() == ".urdf":
        return _read_urdf_chain(path, base, chain)
    from .io.modelfile import read_model_toml

    model = read_model_toml(path)
    if base == "floating" and not model.floating:
        raise ModelError(f"{path}: base='floating' needs a [base] table with the spacecraft")
    return model if base == "floating" else model.fixed()


def _builtin_factories() -> dict[str, Callable[..., ArmModel]]:
    return {"halt7": halt7, "canadarm7": canadarm7, "puma6": puma6}


#: Names of the built-in robots.
BUILTIN_ROBOTS: tuple[str, ...] = ("halt7", "canadarm7", "puma6")


def load_robot(name_or_path: str | Path, *, base: BaseMode = "fixed", chain: UrdfChain | None = None) -> ArmModel:
    """A built-in robot by name, or a model read from a ``.urdf`` or ``.toml`` file.

    Parameters
    ----------
    name_or_path
        ``"halt7"``, ``"canadarm7"``, ``"puma6"``, or a path to a model file.
    base
        ``"fixed"`` or ``"floating"``.  For built-ins, ``"floating"`` attaches the robot's
        documented spacecraft; for a URDF, the root link's inertial; for a TOML file, its
        ``[base]`` table (``"fixed"`` drops it).
    chain
        For a ``.urdf`` file only: the chain to read from its tree (root link, tip link,
        frozen joints [deg or m]); refused, in one line, with a built-in robot or a ``.toml``
        file (whose ``urdf = ...`` form names its chain itself).

    Notes
    -----
    Each model is built once per process (a model file once per modification) and shared:
    models are immutable.
    """
    _check_base(base)
    text = str(name_or_path)
    factories = _builtin_factories()
    suffix = Path(text).suffix.lower()
    if chain is not None and (text in factories or suffix != ".urdf"):
        what = f"{shown(text)} is a built-in robot" if text in factories else f"{shown(text)} is not a .urdf file"
        raise ModelError(
            f"root_link, tip_link and freeze choose the chain of a URDF robot; {what} (a .toml model file names "
            "its chain itself: urdf, root_link, tip_link, freeze_deg, freeze_m)"
        )
    if text in factories:
        return _builtin(text, base)
    if suffix in (".urdf", ".toml"):
        check_path_text(text, "model file", ModelError)
        try:
            stat = Path(text).stat()
            refers = suffix == ".toml" and S_ISREG(stat.st_mode) and _mentions_urdf(Path(text))
        except OSError:  # the reader names the file and the reason
            return _read_model_file.__wrapped__(text, base, None, chain)
        if refers:  # a model file naming a URDF: the URDF may change on its own; read both afresh
            return _read_model_file.__wrapped__(text, base, None, chain)
        model = _read_model_file(text, base, (str(Path(text).resolve()), stat.st_mtime_ns, stat.st_size), chain)
        if model.unread_meshes:  # read afresh next time: the mesh extra installed, a file added since
            _read_model_file.cache_clear()
        return model
    close = difflib.get_close_matches(text, list(factories), n=1)
    hint = f" (did you mean {close[0]!r}?)" if close else ""
    raise ModelError(
        f"robot must be a built-in name ({', '.join(factories)}) or a .urdf/.toml file; got {shown(text)}{hint}"
    )
