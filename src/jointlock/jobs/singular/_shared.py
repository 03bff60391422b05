"""What the modes of the singular job share: the defaults of ``jointlock singular``, the arm it
analyses (:func:`singular_model`), the checks of the inputs and the lengths of 004's
conditions."""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

from ..._deprecate import renamed_keyword
from ...analysis import singularity as sg
from ...errors import ModelError, ScenarioError
from ...locking import lock_joints
from ...model import ArmModel
from ...robots import UrdfChain, load_robot

#: Virtual link lengths: 004's formula, or the exact Vafa-Dubowsky virtual manipulator.
WEIGHTINGS: tuple[str, ...] = ("segment", "vafa-dubowsky")
#: Samples per condition of :func:`verify_singularity_conditions` (the CLI's default).
VERIFY_SAMPLES = 2000
#: Search starts of :func:`verify_singularity_conditions`' completeness check.
VERIFY_SEARCH_SAMPLES = 512
#: Starts of :func:`search_singularities` (the CLI's default).
SEARCH_SAMPLES = 512
#: Gauss-Newton iterations of a search.
SEARCH_MAX_ITER = 80

_DIRECTION_CONVENTION = "unit twists (vx, vy, vz, wx, wy, wz), base frame, sign arbitrary"
_EQ24_FRAME = "eq. (24) rows (wz, vx, vy, vz, wx, wy), Sigma_ref = link frame 5, point = axes 5 and 6"

Rng = int | np.random.Generator | None


@renamed_keyword(old="base", new="jacobian")
def singular_model(
    robot: str, locks: Mapping[int, float] | None = None, jacobian: str = "fixed", *, chain: UrdfChain | None = None
) -> ArmModel:
    """The arm ``jointlock singular`` analyses for the Jacobian ``jacobian``: ``robot`` (a
    built-in name or model file) loaded with a fixed base for ``jacobian="fixed"`` and
    free-floating otherwise (the generalized and the virtual-manipulator Jacobians need the
    spacecraft), with ``locks`` (``{joint number: angle [rad]}``) locked.  ``jacobian``:
    formerly ``base=`` (a deprecated alias).  ``chain``: the chain of a URDF tree
    (:class:`jointlock.robots.UrdfChain`)."""
    model = load_robot(robot, base="fixed" if jacobian == "fixed" else "floating", chain=chain)
    return lock_joints(model, dict(locks)) if locks else model


#: What the singular job's ``jacobian=`` accepts (:data:`jointlock.analysis.singularity.JACOBIAN_KINDS`
#: and ``"floating"``, the same as ``"generalized"``).
JACOBIANS: tuple[str, ...] = sg.JACOBIAN_KINDS + tuple(sg.JACOBIAN_SYNONYMS)


def _check_choice(name: str, value: str, choices: Sequence[str]) -> None:
    if value not in choices:
        raise ScenarioError(f"{name} must be one of {tuple(choices)}; got {value!r}")


def _check_samples(samples: int, name: str = "samples") -> None:
    if isinstance(samples, bool) or not isinstance(samples, (int, np.integer)) or samples < 1:
        raise ScenarioError(f"{name} must be an integer >= 1; got {samples!r}")


def _condition_lengths(model: ArmModel, jacobian: str, weighting: str) -> sg.ArmLengths | None:
    """Lengths of 004's conditions when ``model`` is a full Canadarm2-structure arm and the
    Jacobian is fixed or virtual; ``None`` otherwise."""
    if sg.jacobian_kind(jacobian) == "generalized" or model.dof != 7 or model.locked:
        return None
    try:
        return sg.arm_lengths(model, jacobian=jacobian, weighting=weighting)  # type: ignore[arg-type]
    except ModelError:
        return None
