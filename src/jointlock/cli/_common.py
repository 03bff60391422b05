"""Helpers shared by the subcommands: robot/lock options, degree conversion, JSON output."""

from __future__ import annotations

import argparse
import json
import math
import sys
from typing import Any

import numpy as np

from ..errors import ScenarioError
from ..locking import lock_joints
from ..model import ArmModel
from ..robots import BUILTIN_ROBOTS, load_robot


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


def single_lock(args: argparse.Namespace) -> tuple[int, float]:
    """The one ``--lock J=DEG`` of a subcommand that takes exactly one: (joint, angle [rad])."""
    if len(args.lock) != 1:
        raise ScenarioError(f"--lock must be given exactly once (J=DEG); got {len(args.lock)}")
    return args.lock[0]


def model_from_args(args: argparse.Namespace) -> ArmModel:
    model = load_robot(args.robot, base=args.base)
    locks = dict(getattr(args, "lock", []) or [])
    return lock_joints(model, locks) if locks else model


def locked_deg(model: ArmModel) -> dict[str, float]:
    """``{"J": angle [deg]}`` of the locked joints, for JSON output."""
    return {str(lj.number): math.degrees(lj.angle) for lj in model.locked}


def locked_text(locked: dict[str, float]) -> str:
    """``"joint J at DEG deg, ..."`` (or ``"none"``) from :func:`locked_deg`'s mapping."""
    return ", ".join(f"joint {k} at {v:g} deg" for k, v in locked.items()) or "none"


def joint_vector_deg(model: ArmModel, values: list[float] | None, option: str) -> np.ndarray:
    """Angles [rad] of the movable joints from a ``--*-deg`` option.

    Accepts either one value per movable joint, or one per joint of the full arm (the locked
    joints' entries must then equal their lock angles).
    """
    if values is None:
        return np.zeros(model.dof)
    arr = np.radians(np.asarray(values, dtype=float))
    if not np.all(np.isfinite(arr)):
        raise ScenarioError(f"{option} must be finite numbers [deg]; got {values}")
    if arr.size == model.dof:
        return arr
    if arr.size == model.full_dof and model.locked:
        full_locked = model.expand(model.healthy(arr))
        if not np.allclose(full_locked, arr, atol=1e-9):
            bad = [
                lj.number
                for lj in model.locked
                if not math.isclose(arr[lj.number - 1], lj.angle, abs_tol=1e-9)
            ]
            raise ScenarioError(
                f"{option}: the entries of locked joints {bad} must equal their lock angles "
                "(or give only the movable joints)"
            )
        return model.healthy(arr)
    raise ScenarioError(
        f"{option} needs {model.dof} values (movable joints {list(model.joint_numbers)}) "
        f"[deg]; got {arr.size}"
    )


def _plain(obj: Any) -> Any:
    if isinstance(obj, np.ndarray):
        return _plain(obj.tolist())
    if isinstance(obj, (np.floating, float)):
        value = float(obj)
        return value if math.isfinite(value) else None
    if isinstance(obj, np.integer):
        return int(obj)
    if isinstance(obj, dict):
        return {str(k): _plain(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_plain(v) for v in obj]
    return obj


def print_json(obj: Any) -> None:
    """Print one JSON object (non-finite floats become null)."""
    json.dump(_plain(obj), sys.stdout, indent=2, allow_nan=False)
    sys.stdout.write("\n")


def format_matrix(mat: np.ndarray, fmt: str = "{:>11.5f}", col_labels: list[str] | None = None) -> str:
    lines = []
    if col_labels is not None:
        lines.append(" ".join(f"{c:>11}" for c in col_labels))
    for row in np.atleast_2d(mat):
        lines.append(" ".join(fmt.format(v) for v in row))
    return "\n".join(lines)
