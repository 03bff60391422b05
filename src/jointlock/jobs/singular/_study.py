"""One configuration (``jointlock singular ROBOT --q-deg ...``): :func:`study_singularity` and
its :class:`SingularityResult`, with 004's conditions and analytic directions there
(:func:`conditions_at`)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any, ClassVar

import numpy as np
from numpy.typing import ArrayLike

from ..._deprecate import renamed_keyword
from ...analysis import singularity as sg
from ...errors import ScenarioError
from ...kinematics import VMWeighting
from ...model import ArmModel, FloatArray
from .._common import JobResult, format_matrix, locked_deg, locked_text
from ._shared import (
    _DIRECTION_CONVENTION,
    _EQ24_FRAME,
    JACOBIANS,
    WEIGHTINGS,
    _check_choice,
    _condition_lengths,
)


@dataclass(frozen=True)
class AnalyticDirection:
    """004's analytic singular direction of one condition, checked against the Jacobian.

    Attributes
    ----------
    direction
        (6,) unit vector, eq.-(24) row order (wz, vx, vy, vz, wx, wy), Sigma_ref components.
    residual
        ``|J'^T u| / |J'|`` (0 when ``u`` is a lost direction of the eq.-(24) Jacobian ``J'``).
    alignment
        ``|u . u_num|`` with the numerical direction of the smallest singular value (1 = same).
    """

    direction: FloatArray
    residual: float
    alignment: float


@dataclass(frozen=True)
class ConditionsAtConfiguration:
    """Seed 004's conditions at one configuration of a Canadarm2-structure arm.

    Attributes
    ----------
    lengths
        The lengths the conditions use (virtual for the virtual Jacobian, else real) [m].
    residuals
        ``{name: residual}`` (dimensionless, :func:`jointlock.analysis.singularity.condition_residuals`),
        Cond1-Cond5 and cond1f.
    holds
        ``{name: residual < tol}``.
    numerical_direction
        (6,) left singular vector of the smallest singular value of the eq.-(24) Jacobian.
    numerical_sigma_min
        Smallest singular value of the eq.-(24) Jacobian [mixed units].
    analytic_directions
        004's direction of each condition that holds (Cond1's also when cond1f holds).
    tol
        Tolerance on the residuals.
    """

    lengths: sg.ArmLengths
    residuals: dict[str, float]
    holds: dict[str, bool]
    numerical_direction: FloatArray
    numerical_sigma_min: float
    analytic_directions: dict[str, AnalyticDirection]
    tol: float

    def to_dict(self) -> dict[str, Any]:
        return {
            "tol": self.tol,
            "lengths": dict(vars(self.lengths)),
            "residuals": {k: {"residual": v, "holds": self.holds[k]} for k, v in self.residuals.items()},
            "numerical_direction": self.numerical_direction,
            "numerical_sigma_min": self.numerical_sigma_min,
            "analytic_directions": {
                k: {"direction": d.direction, "residual": d.residual, "alignment": d.alignment}
                for k, d in self.analytic_directions.items()
            },
            "frame": _EQ24_FRAME,
        }


@renamed_keyword(old="base", new="jacobian")
def conditions_at(
    model: ArmModel,
    q: ArrayLike,
    lengths: sg.ArmLengths,
    *,
    jacobian: str = "virtual",
    weighting: str = "segment",
) -> ConditionsAtConfiguration:
    """Residuals of 004's Cond1-Cond5 (and cond1f) at ``q`` (7,) [rad] and 004's analytic
    directions of those that hold, compared with the numerical one of the eq.-(24) Jacobian
    (``jacobian``: ``"fixed"`` or ``"virtual"``; formerly ``base=``, a deprecated alias)."""
    q = np.asarray(q, dtype=float)
    residuals = sg.condition_residuals(q, lengths, refined=True)
    part = sg.reorder_eq24(sg.reference_jacobian(model, q, jacobian=jacobian, weighting=weighting))  # type: ignore[arg-type]
    u_num = np.linalg.svd(part.matrix)[0][:, 5]
    norm = float(np.linalg.norm(part.matrix))
    held = {k: bool(v < sg.CONDITION_TOL) for k, v in residuals.items()}
    directions = {}
    for name, u in sg.analytic_directions(q, lengths).items():
        if not held[name] and not (name == "cond1" and held["cond1f"]):
            continue
        directions[name] = AnalyticDirection(
            direction=u,
            residual=float(np.linalg.norm(part.matrix.T @ u) / norm),
            alignment=float(abs(u @ u_num)),
        )
    return ConditionsAtConfiguration(
        lengths=lengths,
        residuals={k: float(v) for k, v in residuals.items()},
        holds=held,
        numerical_direction=u_num,
        numerical_sigma_min=float(np.linalg.svd(part.matrix, compute_uv=False)[-1]),
        analytic_directions=directions,
        tol=sg.CONDITION_TOL,
    )


def _gram(singular_values: np.ndarray, dof: int) -> dict[str, Any]:
    """The Gram determinant that can vanish: ``det(J J^T)`` for 6 or more joints, ``det(J^T J)``
    (= product of the squared singular values) for fewer, where ``det(J J^T)`` is always 0."""
    kind = "det(J J^T)" if dof >= 6 else "det(J^T J)"
    return {"gram_det_kind": kind, "gram_det": float(np.prod(np.square(singular_values)))}


@dataclass(frozen=True, eq=False)  # arrays inside: compare to_dict() instead
class SingularityResult(JobResult):
    """Result of :func:`study_singularity` (``jointlock singular ROBOT [--q-deg ...]``).

    Attributes
    ----------
    model
        The arm analysed.
    q
        (n,) [rad] the configuration (movable joints).
    base, weighting
        The Jacobian as given (``jacobian=``: ``"fixed"``, ``"generalized"``/``"floating"`` or
        ``"virtual"``) and the virtual lengths.
    analysis
        Singular values, rank, ``det(J J^T)`` and lost directions at ``q``.
    conditions
        004's conditions at ``q`` (full Canadarm2-structure arm, fixed or virtual Jacobian),
        else ``None``.
    """

    job: ClassVar[str] = "singular"

    model: ArmModel
    q: FloatArray
    base: str
    weighting: str
    analysis: sg.SingularityAnalysis
    conditions: ConditionsAtConfiguration | None

    @property
    def lost_directions(self) -> FloatArray:
        """(6, r) the lost directions (unit twists, base frame, sign arbitrary)."""
        return self.analysis.lost_directions()

    def to_dict(self) -> dict[str, Any]:
        model, res = self.model, self.analysis
        out: dict[str, Any] = {
            "robot": model.name,
            "base": self.base,
            "weighting": self.weighting if self.base == "virtual" else None,
            "joint_numbers": list(model.joint_numbers),
            "locked": locked_deg(model),
            "q_deg": np.degrees(self.q),
            "singular_values": res.singular_values,
            "sigma_min": float(res.sigma_min),
            "rank": int(res.rank),
            "full_rank": int(res.singular_values.shape[-1]),
            "singular": bool(res.singular),
            "det_jjt": float(res.det_jjt),
            **_gram(res.singular_values, model.dof),
            "tol": res.tol,
            "lost_directions": self.lost_directions.T,
            "direction_convention": _DIRECTION_CONVENTION,
        }
        if self.conditions is not None:
            out["conditions"] = self.conditions.to_dict()
        return out

    def summary(self) -> list[str]:
        model, res, base = self.model, self.analysis, self.base
        lost = self.lost_directions
        gram = _gram(res.singular_values, model.dof)
        full_rank = int(res.singular_values.shape[-1])
        lines = [
            f"{model.name}: {model.dof} movable joints {list(model.joint_numbers)}, locked: "
            f"{locked_text(locked_deg(model))}, Jacobian: {base}",
            "q [deg]: " + ", ".join(f"{v:.4f}" for v in np.degrees(self.q)),
            "singular values: " + ", ".join(f"{v:.6g}" for v in res.singular_values),
            f"sigma_min = {res.sigma_min:.6g}   rank = {res.rank} of {full_rank} (tol {res.tol:g})   "
            f"{gram['gram_det_kind']} = {gram['gram_det']:.6g}   -> {'SINGULAR' if res.singular else 'regular'}",
        ]
        if model.dof < 6:
            lines.append(
                f"  ({model.dof} movable joints < 6: J J^T (6 x 6) has rank <= {model.dof}, so det(J J^T) = 0 "
                f"always; det(J^T J) = product of the squared singular values tests the {model.dof} joints instead)"
            )
        if lost.shape[1]:
            lines.append("lost directions (base frame, columns):")
            lines += format_matrix(lost, "{:>9.4f}", [f"u{i + 1}" for i in range(lost.shape[1])]).split("\n")
        c = self.conditions
        if c is not None:
            lengths = "virtual" if base == "virtual" else "real"
            lines += ["", f"004 conditions ({lengths} lengths; residual, holds at tol {c.tol:g}):"]
            for name, residual in c.residuals.items():
                lines.append(f"  {name:7s} {residual:.3e}  {'holds' if c.holds[name] else '-'}")
            lines.append("analytic vs numerical singular direction (eq. 24 order wz vx vy vz wx wy):")
            lines.append(f"  numerical  {np.array2string(np.asarray(c.numerical_direction), precision=4)}")
            for name, d in c.analytic_directions.items():
                lines.append(
                    f"  {name:7s}    {np.array2string(np.asarray(d.direction), precision=4)}  "
                    f"|J'^T u|/|J'| = {d.residual:.2e}  |u.u_num| = {d.alignment:.4f}"
                )
        return lines

    def write(self, out: str | Path) -> list[str]:
        """``jointlock singular`` writes no files for one configuration (``--out`` is for
        ``--search``): nothing is written; returns ``[]``."""
        return []


@renamed_keyword(old="base", new="jacobian")
@renamed_keyword(old="length", new="characteristic_length")
def study_singularity(
    model: ArmModel,
    q: ArrayLike,
    *,
    jacobian: sg.TaskJacobianKind = "fixed",
    weighting: VMWeighting = "segment",
    tol: float = sg.RANK_TOL,
    characteristic_length: float | None = None,
) -> SingularityResult:
    """Singularity analysis of ``model`` at one configuration (``jointlock singular``).

    Parameters
    ----------
    model
        Any arm (locked joints allowed); ``jacobian="generalized"``/``"virtual"`` need a
        free-floating one (:func:`singular_model` loads it so).
    q
        (n,) joint angles [rad] of the movable joints.
    jacobian
        ``"fixed"`` (geometric), ``"generalized"`` (zero momentum; ``"floating"`` is the same)
        or ``"virtual"`` (004's virtual manipulator).  Formerly ``base=`` (a deprecated alias).
    weighting
        Virtual link lengths: ``"segment"`` (004's formula) or ``"vafa-dubowsky"``.
    tol
        Rank tolerance on the singular values (units of the analysed matrix).
    characteristic_length
        ``L`` [m] dividing the linear rows (``None``: raw Jacobian).  Formerly ``length=`` (a
        deprecated alias).

    Returns
    -------
    SingularityResult
        With 004's conditions at ``q`` when ``model`` is a full Canadarm2-structure arm and
        ``jacobian`` is fixed or virtual (evaluated on the raw eq.-(15) Jacobian).
    """
    _check_choice("jacobian", jacobian, JACOBIANS)
    _check_choice("weighting", weighting, WEIGHTINGS)
    q = np.asarray(q, dtype=float)
    if q.shape != (model.dof,):
        raise ScenarioError(
            f"q must hold {model.dof} angles [rad] (movable joints {list(model.joint_numbers)}); got shape {q.shape}"
        )
    analysis = sg.analyse_singularity(
        model, q, jacobian=jacobian, weighting=weighting, tol=tol, characteristic_length=characteristic_length
    )
    lengths = _condition_lengths(model, jacobian, weighting)
    conditions = (
        None if lengths is None else conditions_at(model, q, lengths, jacobian=jacobian, weighting=weighting)
    )
    return SingularityResult(
        model=model, q=q, base=jacobian, weighting=weighting, analysis=analysis, conditions=conditions
    )
