"""Helpers shared by the subcommands: robot/lock options, degree conversion, option checks,
output folders, JSON output and atomic figure files."""

from __future__ import annotations

import argparse
import io
import json
import math
import sys
from pathlib import Path
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


def seed_arg(text: str) -> int:
    """argparse type of every ``--seed``: an integer >= 0 (numpy refuses negative seeds)."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be an integer >= 0; got {text!r}") from None
    if value < 0:
        raise argparse.ArgumentTypeError(f"must be an integer >= 0; got {text!r}")
    return value


def require_finite(args: argparse.Namespace, *names: str) -> None:
    """Raise :class:`ScenarioError` naming the option when one of ``args.<name>`` (if given)
    is NaN or infinite; ``names`` are attribute names (``"length_scale"`` -> ``--length-scale``)."""
    for name in names:
        value = getattr(args, name, None)
        if value is None:
            continue
        values = value if isinstance(value, (list, tuple)) else [value]
        if not all(math.isfinite(float(v)) for v in values):
            option = "--" + name.replace("_", "-")
            raise ScenarioError(f"{option} must be a finite number; got {value}")


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


def write_png(fig: Any, path: str | Path, *, dpi: int = 110) -> None:
    """``fig.savefig(path, dpi=dpi)`` as PNG, written atomically (in-memory buffer, then
    :func:`jointlock.report.atomic_write_bytes`).  The figure is left open."""
    from ..report import atomic_write_bytes

    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi)
    atomic_write_bytes(path, buf.getvalue())


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


def model_from_args(args: argparse.Namespace) -> ArmModel:
    model = load_robot(args.robot, base=args.base)
    locks = lock_map(getattr(args, "lock", []))
    return lock_joints(model, locks) if locks else model


def locked_deg(model: ArmModel) -> dict[str, float]:
    """``{"J": angle [deg]}`` of the locked joints, for JSON output."""
    return {str(lj.number): math.degrees(lj.angle) for lj in model.locked}


def locked_text(locked: dict[str, float]) -> str:
    """``"joint J at DEG deg, ..."`` (or ``"none"``) from :func:`locked_deg`'s mapping."""
    return ", ".join(f"joint {k} at {v:g} deg" for k, v in locked.items()) or "none"


def joint_vector_deg(
    model: ArmModel, values: list[float] | None, option: str, *, rates: bool = False
) -> np.ndarray:
    """Angles [rad] of the movable joints from a ``--*-deg`` option (or, with ``rates=True``,
    rates [rad/s] or accelerations [rad/s^2] from a ``--*dq*-deg`` option).

    Accepts either one value per movable joint, or one per joint of the full arm: the locked
    joints' entries must then equal their lock angles (angles) or be 0 (``rates=True``: a
    locked joint does not move).
    """
    if values is None:
        return np.zeros(model.dof)
    arr = np.radians(np.asarray(values, dtype=float))
    if not np.all(np.isfinite(arr)):
        raise ScenarioError(f"{option} must be finite numbers [deg]; got {values}")
    if arr.size == model.dof:
        return arr
    if arr.size == model.full_dof and model.locked and rates:
        bad = [lj.number for lj in model.locked if not abs(arr[lj.number - 1]) <= 1e-9]
        if bad:
            raise ScenarioError(
                f"{option}: the entries of locked joints {bad} must be 0 (a locked joint does not "
                "move; or give only the movable joints)"
            )
        return model.healthy(arr)
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
