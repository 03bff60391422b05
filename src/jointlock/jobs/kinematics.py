"""The kinematics of one configuration as one call (``jointlock kinematics``): the
end-effector pose, the Jacobian (generalized for a free-floating arm) and its singular values."""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any, ClassVar

import numpy as np
from numpy.typing import ArrayLike

from ..io.files import atomic_write_json
from ..kinematics import chain_state, generalized_jacobian, jacobian
from ..model import ArmModel, as_joint_array
from ..spatial import pose
from ._common import JobResult, format_matrix, locked_deg, locked_text

#: How the Jacobian's rows and reference point are defined (printed in the JSON).
JACOBIAN_CONVENTION = "twist (v, omega) of the end-effector origin, base-frame components"


@dataclass(frozen=True, eq=False)  # arrays inside: compare to_dict() instead
class KinematicsReport(JobResult):
    """Pose, Jacobian and singular values of ``model`` at ``q``.

    Attributes
    ----------
    model
        The arm (locked joints allowed; free-floating: the generalized Jacobian).
    q
        (n,) joint angles of the movable joints [rad].
    pose
        (4, 4) end-effector pose ``T_base_ee`` [m].
    jacobian
        (6, n) geometric Jacobian (fixed base) or generalized Jacobian (free-floating, zero
        momentum): twist (v [m/s], omega [rad/s]) of the end-effector origin, base frame.
    singular_values
        (min(6, n),) singular values of ``jacobian``, largest first.
    """

    job: ClassVar[str] = "kinematics"

    model: ArmModel
    q: np.ndarray
    pose: np.ndarray
    jacobian: np.ndarray
    singular_values: np.ndarray

    @property
    def jacobian_kind(self) -> str:
        return "generalized" if self.model.floating else "geometric"

    @property
    def condition_number(self) -> float:
        sv = self.singular_values
        return float(sv[0] / sv[-1]) if sv[-1] > 0 else math.inf

    @property
    def manipulability(self) -> float:
        return float(np.prod(self.singular_values))

    def to_dict(self) -> dict[str, Any]:
        """What ``jointlock kinematics --json`` prints."""
        m = self.model
        return {
            "robot": m.name,
            "base": "floating" if m.floating else "fixed",
            "joint_numbers": list(m.joint_numbers),
            "locked": locked_deg(m),
            "q_deg": np.degrees(self.q),
            "pose": self.pose,
            "jacobian": self.jacobian,
            "jacobian_kind": self.jacobian_kind,
            "jacobian_convention": JACOBIAN_CONVENTION,
            "singular_values": self.singular_values,
            "condition_number": self.condition_number,
            "manipulability": self.manipulability,
        }

    def summary(self) -> list[str]:
        """The lines ``jointlock kinematics`` prints."""
        m = self.model
        base = "floating" if m.floating else "fixed"
        # a URDF chain or a DH table with held rows numbers its joints 1..n: say which is which
        named = [j.name for j in m.joints]
        names = "" if named == [f"joint{n}" for n in m.joint_numbers] else f" ({', '.join(named)})"
        text = [
            f"{m.name}: {m.dof} movable joints {list(m.joint_numbers)}{names}, locked: "
            f"{locked_text(locked_deg(m))}, base: {base}",
            "q [deg]: " + ", ".join(f"{v:.4f}" for v in np.degrees(self.q)),
            "",
            "end-effector pose T_base_ee [m]:",
            format_matrix(self.pose, "{:>11.6f}"),
            "",
            f"{self.jacobian_kind} Jacobian (rows vx vy vz [m/s], wx wy wz [rad/s]):",
            format_matrix(self.jacobian, "{:>11.5f}", [f"joint {n}" for n in m.joint_numbers]),
            "",
            "singular values: " + ", ".join(f"{v:.6g}" for v in self.singular_values),
            f"condition number: {self.condition_number:.6g}   manipulability: {self.manipulability:.6g}",
        ]
        return "\n".join(text).split("\n")

    def write(self, out: str | Path) -> list[str]:
        """``result.json`` (:meth:`to_dict`) in ``out``; returns its name."""
        atomic_write_json(Path(out) / "result.json", self.to_dict())
        return ["result.json"]


def describe_configuration(model: ArmModel, q: ArrayLike | None = None) -> KinematicsReport:
    """End-effector pose, Jacobian and singular values of ``model`` at ``q`` (n,) [rad]
    (default: zeros); the Jacobian is the generalized one (zero momentum) when the arm is
    free-floating."""
    q = np.zeros(model.dof) if q is None else as_joint_array(model, q)
    state = chain_state(model, q)
    jac = generalized_jacobian(model, q, state=state) if model.floating else jacobian(model, q, state=state)
    return KinematicsReport(
        model, q, pose(state.ee_rotation, state.ee_position), jac, np.linalg.svd(jac, compute_uv=False)
    )
