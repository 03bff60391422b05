"""Helpers shared by the subcommands: robot/lock options, degree conversion, option checks,
output folders, JSON output and atomic figure files."""

from __future__ import annotations

import argparse
import math
import sys
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

from .._lazy import lazy_attributes
from ..bounds import MAX_OPTION_DEG, shorten
from ..errors import ScenarioError
from ._constants import BUILTIN_ROBOTS

if TYPE_CHECKING:
    from ..model import ArmModel
    from ..robots import UrdfChain
    from ..scenario import Field

# The library (numpy behind it) is imported on first use, never to build a parser: these names
# are re-exported for the subcommands' run functions and older callers.
__getattr__, __dir__ = lazy_attributes(
    __name__,
    {
        "json_text": "jointlock.io.files",
        "write_png": "jointlock.io.files",
        "format_matrix": "jointlock.jobs._common",
        "joint_vector_deg": "jointlock.jobs._common",
        "locked_deg": "jointlock.jobs._common",
        "locked_text": "jointlock.jobs._common",
        "load_robot": "jointlock.robots",
        "lock_joints": "jointlock.locking",
    },
    namespace=globals(),
)


def _plain(obj: Any) -> Any:
    """Former name of :func:`jointlock.io.files.to_plain`."""
    from ..io.files import to_plain

    return to_plain(obj)


def parse_lock(text: str) -> tuple[int, float]:
    """``"J=DEG"`` -> (joint number, angle [rad])."""
    try:
        joint_text, angle_text = text.split("=", 1)
        joint, angle = int(joint_text), float(angle_text)
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"--lock must look like J=DEG (joint number from 1, angle in degrees), e.g. 4=0; got {text!r}"
        ) from None
    if not math.isfinite(angle):
        raise argparse.ArgumentTypeError(f"--lock angle must be finite; got {text!r}")
    return joint, math.radians(angle)


def int_at_least(minimum: int) -> Callable[[str], int]:
    """An argparse type: an integer >= ``minimum``."""

    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"must be an integer >= {minimum}; got {text!r}") from None
        if value < minimum:
            raise argparse.ArgumentTypeError(f"must be an integer >= {minimum}; got {text!r}")
        return value

    return parse




def field_arg(table: str, name: str) -> Callable[[str], Any]:
    """An argparse type checking an option against its scenario field ``[table] name``: the
    same kind, bounds and unit as in a scenario file (so ``--samples``, ``--T``, ``--voxel``
    ... refuse what ``jointlock run`` refuses).  A list field is checked value by value.  The
    field is looked up when a value is parsed (the schema is not needed to print ``--help``)."""

    def spec() -> Field:
        import dataclasses

        from ..scenario import ALL_TABLES, TOP_FIELDS

        field = ALL_TABLES[table][name] if table else TOP_FIELDS[name]
        return dataclasses.replace(field, kind="number", length=None) if field.kind == "numbers" else field

    return _SpecArg(spec)


def number_arg(
    lo: float | None = None,
    hi: float | None = None,
    *,
    lo_open: bool = False,
    unit: str = "",
    integer: bool = False,
) -> Callable[[str], Any]:
    """An argparse type: a finite number (an integer with ``integer=True``) within the bounds."""
    kind = "int" if integer else "number"

    def spec() -> Field:
        from ..scenario import Field

        return Field(kind, lo=lo, hi=hi, lo_open=lo_open, unit=unit)

    return _SpecArg(spec, kind)


class _SpecArg:
    """An argparse type checking a value against a scenario :class:`~jointlock.scenario.Field`
    made on first use by ``spec``; named by the field's kind once known (argparse names the
    type in its own messages)."""

    def __init__(self, spec: Callable[[], Field], kind: str | None = None) -> None:
        self._make = spec
        self._spec: Field | None = None
        self._kind = kind

    @property
    def spec(self) -> Field:
        if self._spec is None:
            self._spec = self._make()
        return self._spec

    @property
    def __name__(self) -> str:
        # argparse asks for it when it expands any help text, before a value is parsed: the
        # field is not looked up for that (its kind names the type once it has been)
        if self._kind is None and self._spec is not None:
            self._kind = self._spec.kind
        return self._kind or "value"

    def __call__(self, text: str) -> Any:
        from ..scenario import check_value

        spec = self.spec
        try:
            value: Any = int(text) if spec.kind == "int" else float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"must be {spec.allowed()}; got {shorten(text)!r}") from None
        try:
            return check_value(value, spec, "value")
        except ScenarioError:  # said with the text as typed (not as converted: 1e400 -> inf)
            raise argparse.ArgumentTypeError(f"must be {spec.allowed()}; got {shorten(text)!r}") from None


#: argparse type of every joint-space vector option in degrees (``--q-deg``, ``--from-deg`` ...):
#: multi-turn joints of a URDF allowed (a scenario's ``*_deg`` fields keep one turn).
deg_arg = number_arg(-MAX_OPTION_DEG, MAX_OPTION_DEG, unit="deg")
#: argparse type of every ``--seed``: the scenario's seed field (an integer 0 .. 2**63 - 1).
seed_arg = field_arg("", "seed")


def check_out_dir(path: str | Path | None, option: str = "--out") -> Path | None:
    """Check, before any work, that ``path`` can be the output folder: it is a folder or does
    not exist yet, and its nearest existing ancestor is a folder.  Returns it as a Path."""
    if path is None:
        return None
    out = Path(path)
    if out.exists() and not out.is_dir():
        raise ScenarioError(f"{option} {str(out)!r} exists and is not a folder")
    for parent in out.parents:
        if parent.exists():
            if not parent.is_dir():
                raise ScenarioError(f"{option} {str(out)!r}: {str(parent)!r} is not a folder")
            break
    return out


def add_robot_arguments(
    parser: argparse.ArgumentParser,
    *,
    lock: bool = True,
    base_choices: tuple[str, ...] = ("fixed", "floating"),
    base_default: str | None = "fixed",
    base_help: str = "fixed base, or free-floating spacecraft (generalized Jacobian); default fixed",
) -> None:
    """Add ROBOT, ``--lock J=DEG`` (unless ``lock=False``) and ``--base`` to ``parser``.

    ``base_choices``, ``base_default`` and ``base_help`` let a subcommand offer other bases
    (e.g. ``singular``'s "virtual") or leave the default to be decided later (``None``).
    """
    parser.add_argument(
        "robot",
        metavar="ROBOT",
        help=f"built-in name ({', '.join(BUILTIN_ROBOTS)}) or a model file (.urdf, .toml)",
    )
    if lock:
        parser.add_argument(
            "--lock",
            metavar="J=DEG",
            type=parse_lock,
            action="append",
            default=[],
            help="lock joint J (numbered from 1) at DEG degrees; repeat for several",
        )
    parser.add_argument(
        "--base",
        choices=base_choices,
        default=base_default,
        help=base_help,
    )
    chain = parser.add_argument_group("the chain of a URDF robot (a tree: two arms, a gripper)")
    chain.add_argument("--root", metavar="LINK", help="link the chain starts from (default: the tree's root)")
    chain.add_argument("--tip", metavar="LINK", help="link the chain ends at (needed when the tree branches)")
    chain.add_argument(
        "--freeze",
        metavar="JOINT=VALUE",
        type=parse_freeze,
        action="append",
        default=[],
        help="hold JOINT at VALUE (degrees for a revolute joint, metres for a prismatic one) and merge its "
        "links; repeat for several (joints off the chain are held at 0, a <mimic> joint follows its leader)",
    )
    chain.add_argument(
        "--srdf", metavar="FILE", help="an SRDF file: its <disable_collisions> link pairs are never checked for clearance"
    )
    chain.add_argument(
        "--meshes", choices=("convex", "skip"), default=None,
        help="the URDF's <collision> meshes: read as their convex hulls (default; needs jointlock[mesh]) or left out",
    )  # fmt: skip


def single_lock(args: argparse.Namespace) -> tuple[int, float]:
    """The one ``--lock J=DEG`` of a subcommand that takes exactly one: (joint, angle [rad])."""
    if len(args.lock) != 1:
        raise ScenarioError(f"--lock must be given exactly once (J=DEG); got {len(args.lock)}")
    return args.lock[0]


def lock_map(locks: list[tuple[int, float]] | None) -> dict[int, float]:
    """``{joint: angle [rad]}`` from the repeated ``--lock J=DEG`` options; a joint given
    twice is refused (rather than keeping the last angle)."""
    out: dict[int, float] = {}
    for joint, angle in locks or []:
        if joint in out:
            raise ScenarioError(
                f"--lock: joint {joint} given twice ({math.degrees(out[joint]):g} and "
                f"{math.degrees(angle):g} deg); give each locked joint once"
            )
        out[joint] = angle
    return out


def parse_freeze(text: str) -> tuple[str, float]:
    """``"JOINT=VALUE"`` -> (joint name, value [deg or m, by the joint's type])."""
    name, _, value_text = text.rpartition("=")
    try:
        value = float(value_text)
    except ValueError:
        value = math.nan
    if not name.strip() or not math.isfinite(value) or abs(value) > MAX_OPTION_DEG:
        raise argparse.ArgumentTypeError(
            "--freeze must look like JOINT=VALUE (a URDF joint's name; a finite number within "
            f"+-{MAX_OPTION_DEG:g}: degrees for a revolute joint, metres for a prismatic one), e.g. "
            f"panda_finger_joint1=0.02; got {shorten(text)!r}"
        )
    return name.strip(), value


def chain_from_args(args: argparse.Namespace) -> UrdfChain | None:
    """The chain ``--root``, ``--tip`` and ``--freeze`` name (None without them); refused in one
    line for a ROBOT that is not a ``.urdf`` file.  Each ``--freeze`` value is in the unit of its
    joint's type, read from the file."""
    root, tip, freeze = getattr(args, "root", None), getattr(args, "tip", None), getattr(args, "freeze", None) or []
    srdf, meshes = getattr(args, "srdf", None), getattr(args, "meshes", None)
    if root is None and tip is None and not freeze and srdf is None and meshes is None:
        return None
    robot = str(args.robot)
    if robot in BUILTIN_ROBOTS or Path(robot).suffix.lower() != ".urdf":
        what = "a built-in robot" if robot in BUILTIN_ROBOTS else "not a .urdf file (a .toml model file names its chain itself)"
        raise ScenarioError(
            f"--root, --tip and --freeze choose the chain of a URDF robot (--srdf its pairs not checked for "
            f"clearance, --meshes how its meshes are read); ROBOT {shorten(robot)!r} is {what}"
        )
    from ..io.urdf import urdf_joint_types
    from ..robots import UrdfChain

    types = urdf_joint_types(robot)
    seen: dict[str, float] = {}
    for name, value in freeze:
        if name in seen:
            raise ScenarioError(f"--freeze: joint {shorten(name)!r} given twice ({seen[name]:g} and {value:g}); give it once")
        seen[name] = value
    prismatic = {k: v for k, v in seen.items() if types.get(k) == "prismatic"}
    degrees = {k: v for k, v in seen.items() if k not in prismatic}
    return UrdfChain(root, tip, tuple(degrees.items()), tuple(prismatic.items()), srdf, meshes)


def model_from_args(args: argparse.Namespace) -> ArmModel:
    """The robot of ``args`` (ROBOT, ``--base``, ``--root``/``--tip``/``--freeze``), with its
    ``--lock`` joints locked."""
    from ..locking import lock_joints
    from ..robots import load_robot

    model = load_robot(args.robot, base=args.base, chain=chain_from_args(args))
    locks = lock_map(getattr(args, "lock", []))
    return lock_joints(model, locks) if locks else model


def print_json(obj: Any) -> None:
    """Print one JSON object (non-finite floats become null)."""
    from ..io.files import json_text

    sys.stdout.write(json_text(obj))


def add_clearance_options(p: argparse.ArgumentParser) -> None:
    """``--clearance-min-m`` and ``--no-clearance`` (scenario ``[limits] clearance_min_m`` and
    ``check_clearance``)."""
    p.add_argument(
        "--clearance-min-m",
        type=field_arg("limits", "clearance_min_m"),
        metavar="M",
        help="clearance kept between the links, the spacecraft bus and keep-outs [m] (default 0.05): closer "
        "halt configurations are excluded, a closer --qf-deg is refused, a closer halt motion is reported",
    )
    p.add_argument(
        "--no-clearance",
        action="store_true",
        help="do not require the clearance (the papers' way); it is still reported",
    )
    p.add_argument(
        "--keep-out",
        metavar="FILE",
        help="a TOML file of [[keep_out]] volumes (boxes, spheres, capsules in the root frame: a docked vehicle, "
        "a solar array) kept clear like the bus (format: docs/scenarios.md)",
    )


def clearance_from_args(args: argparse.Namespace) -> Any:
    """The :class:`~jointlock.collision.ClearanceSettings` of ``--clearance-min-m`` / ``--no-clearance``
    and ``--keep-out FILE``."""
    import dataclasses

    from ..io.files import read_toml_file
    from ..jobs._common import clearance_settings
    from ..scenario._keep_out import check_keep_out, shape_of

    settings = clearance_settings(args.clearance_min_m, not args.no_clearance)
    if args.keep_out is None:
        return settings
    data = read_toml_file(args.keep_out, "--keep-out file", ScenarioError)
    if "keep_out" not in data:
        raise ScenarioError(f"--keep-out {args.keep_out}: no [[keep_out]] entries in the file")
    shapes = tuple(shape_of(e) for e in check_keep_out(data["keep_out"], f"--keep-out {args.keep_out}"))
    return dataclasses.replace(settings, keep_out=shapes)


def export_facts(model: Any, path: Any) -> dict[str, Any]:
    """What ``export-urdf`` and ``export-mjcf`` print about the file written: the file, the arm,
    its base, its healthy joints and its locks [deg]."""
    import math

    return {
        "file": str(path),
        "robot": model.name,
        "base": "floating" if model.floating else "fixed",
        "joint_numbers": list(model.joint_numbers),
        "locked": {str(lj.number): math.degrees(lj.angle) for lj in model.locked},
    }


def export_line(facts: dict[str, Any]) -> str:
    """The one line an export prints: ``wrote FILE: ROBOT, BASE base, healthy joints [...], locked: ...``."""
    locked = ", ".join(f"joint {k} at {v:g} deg" for k, v in facts["locked"].items()) or "none"
    return (
        f"wrote {facts['file']}: {facts['robot']}, {facts['base']} base, healthy joints {facts['joint_numbers']}, "
        f"locked: {locked}"
    )
