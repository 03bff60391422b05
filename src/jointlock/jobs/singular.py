"""The ``singular`` job (seed 004): singularity analysis at one configuration, verification of
004's conditions Cond1-Cond5 by sampling, and a batched search for singular configurations.

One library call per mode of ``jointlock singular``:

* :func:`study_singularity` (``jointlock singular ROBOT --q-deg ...``): singular values,
  rank, ``det(J J^T)`` and lost directions at one configuration, and for a full
  Canadarm2-structure arm the residuals of Cond1-Cond5 and 004's analytic directions there;
* :func:`verify_singularity_conditions` (``--verify-conditions``): is each condition
  sufficient (exact samples all singular?) and is the list complete (does a search find
  singular configurations none of them explains?);
* :func:`search_singularities` (``--search``): seeded Gauss-Newton starts driven to
  ``sigma_min = 0``, clustered into families (with the figures of ``--out``).

Each returns a frozen, picklable result (:class:`SingularityResult`,
:class:`ConditionVerificationResult`, :class:`SingularitySearchResult`) whose ``to_dict()``
is the JSON of the command, ``summary()`` its printed lines and ``write(out)`` its files.
:func:`singular_from_scenario` runs the ``[singular]`` table of a scenario.

Jacobian: twist ``(v [m/s], omega [rad/s])`` of the end-effector origin, base-frame
components (see :func:`jointlock.analysis.singularity.task_jacobian`); angles in radians
inside, degrees only in names ending ``_deg``.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, ClassVar, Literal

import numpy as np
from numpy.typing import ArrayLike

from ..analysis import singularity as sg
from ..errors import ModelError, ScenarioError
from ..io.files import atomic_write_bytes, atomic_write_json, figure_png
from ..kinematics import VMWeighting
from ..locking import lock_joints
from ..model import ArmModel, FloatArray
from ..plots._common import offscreen_figure
from ..plots.singular import (
    SIGMA_MIN_FIGSIZE,
    families_figsize,
    joint_angles_figsize,
    plot_family_joint_angles,
    plot_search_sigma_min,
    plot_singular_families,
)
from ..progress import Progress
from ..robots import load_robot
from ._common import JobResult, joint_vector_deg, locked_deg, locked_text

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


# -- inputs --------------------------------------------------------------------------------------


def singular_model(robot: str, locks: Mapping[int, float] | None = None, base: str = "fixed") -> ArmModel:
    """The arm ``jointlock singular`` analyses: ``robot`` (a built-in name or model file)
    loaded with a fixed base for ``base="fixed"`` and free-floating otherwise (the generalized
    and the virtual-manipulator Jacobians need the spacecraft), with ``locks``
    (``{joint number: angle [rad]}``) locked."""
    model = load_robot(robot, base="fixed" if base == "fixed" else "floating")
    return lock_joints(model, dict(locks)) if locks else model


def _check_choice(name: str, value: str, choices: Sequence[str]) -> None:
    if value not in choices:
        raise ScenarioError(f"{name} must be one of {tuple(choices)}; got {value!r}")


def _check_samples(samples: int, name: str = "samples") -> None:
    if isinstance(samples, bool) or not isinstance(samples, (int, np.integer)) or samples < 1:
        raise ScenarioError(f"{name} must be an integer >= 1; got {samples!r}")


def _seeded(rng: Rng) -> int | np.random.Generator:
    """``rng`` itself, or for ``None`` a fresh seed (so the result records the seed used)."""
    if rng is None:
        return int(np.random.SeedSequence().generate_state(1)[0])
    return rng


def _condition_lengths(model: ArmModel, base: str, weighting: str) -> sg.ArmLengths | None:
    """Lengths of 004's conditions when ``model`` is a full Canadarm2-structure arm and the
    Jacobian is fixed or virtual; ``None`` otherwise."""
    if base == "floating" or model.dof != 7 or model.locked:
        return None
    try:
        return sg.arm_lengths(model, base=base, weighting=weighting)  # type: ignore[arg-type]
    except ModelError:
        return None


# -- one configuration ---------------------------------------------------------------------------


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


def conditions_at(
    model: ArmModel,
    q: ArrayLike,
    lengths: sg.ArmLengths,
    *,
    base: str = "virtual",
    weighting: str = "segment",
) -> ConditionsAtConfiguration:
    """Residuals of 004's Cond1-Cond5 (and cond1f) at ``q`` (7,) [rad] and 004's analytic
    directions of those that hold, compared with the numerical one of the eq.-(24) Jacobian
    (``base``: ``"fixed"`` or ``"virtual"``)."""
    q = np.asarray(q, dtype=float)
    residuals = sg.condition_residuals(q, lengths, refined=True)
    part = sg.reorder_eq24(sg.reference_jacobian(model, q, base=base, weighting=weighting))  # type: ignore[arg-type]
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


def _matrix_lines(mat: np.ndarray, fmt: str, col_labels: list[str]) -> list[str]:
    """Rows of ``mat`` under right-aligned column labels (the CLI's matrix layout)."""
    lines = [" ".join(f"{c:>11}" for c in col_labels)]
    lines += [" ".join(fmt.format(v) for v in row) for row in np.atleast_2d(mat)]
    return lines


@dataclass(frozen=True)
class SingularityResult(JobResult):
    """Result of :func:`study_singularity` (``jointlock singular ROBOT [--q-deg ...]``).

    Attributes
    ----------
    model
        The arm analysed.
    q
        (n,) [rad] the configuration (movable joints).
    base, weighting
        The Jacobian (``"fixed"``, ``"floating"`` or ``"virtual"``) and the virtual lengths.
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
            lines += _matrix_lines(lost, "{:>9.4f}", [f"u{i + 1}" for i in range(lost.shape[1])])
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


def study_singularity(
    model: ArmModel,
    q: ArrayLike,
    *,
    base: sg.BaseKind = "fixed",
    weighting: VMWeighting = "segment",
    tol: float = sg.RANK_TOL,
    length: float | None = None,
) -> SingularityResult:
    """Singularity analysis of ``model`` at one configuration (``jointlock singular``).

    Parameters
    ----------
    model
        Any arm (locked joints allowed); ``base="floating"``/``"virtual"`` need a free-floating
        one (:func:`singular_model` loads it so).
    q
        (n,) joint angles [rad] of the movable joints.
    base
        Jacobian: ``"fixed"`` (geometric), ``"floating"`` (generalized, zero momentum) or
        ``"virtual"`` (004's virtual manipulator).
    weighting
        Virtual link lengths: ``"segment"`` (004's formula) or ``"vafa-dubowsky"``.
    tol
        Rank tolerance on the singular values (units of the analysed matrix).
    length
        Characteristic length [m] dividing the linear rows (``None``: raw Jacobian).

    Returns
    -------
    SingularityResult
        With 004's conditions at ``q`` when ``model`` is a full Canadarm2-structure arm and
        ``base`` is fixed or virtual (evaluated on the raw eq.-(15) Jacobian).
    """
    _check_choice("base", base, sg.BASE_KINDS)
    _check_choice("weighting", weighting, WEIGHTINGS)
    q = np.asarray(q, dtype=float)
    if q.shape != (model.dof,):
        raise ScenarioError(
            f"q must hold {model.dof} angles [rad] (movable joints {list(model.joint_numbers)}); got shape {q.shape}"
        )
    analysis = sg.analyse_singularity(model, q, base=base, weighting=weighting, tol=tol, length=length)
    lengths = _condition_lengths(model, base, weighting)
    conditions = None if lengths is None else conditions_at(model, q, lengths, base=base, weighting=weighting)
    return SingularityResult(
        model=model, q=q, base=base, weighting=weighting, analysis=analysis, conditions=conditions
    )


# -- verification of Cond1-Cond5 -----------------------------------------------------------------


def _check_dict(c: sg.ConditionCheck) -> dict[str, Any]:
    return {
        "samples": c.samples,
        "singular": c.singular,
        "fraction_singular": c.fraction_singular,
        "sufficient": c.sufficient,
        "sigma_min_median": c.sigma_min_median,
        "sigma_min_max": c.sigma_min_max,
        "max_residual": c.max_residual,
        "direction_residual": c.direction_residual,
        "direction_alignment": c.direction_alignment,
    }


@dataclass(frozen=True)
class ConditionVerificationResult(JobResult):
    """Result of :func:`verify_singularity_conditions` (``jointlock singular ROBOT
    --verify-conditions``).

    Attributes
    ----------
    model
        The arm (full Canadarm2-structure arm).
    base, weighting
        The Jacobian (``"virtual"`` or ``"fixed"``) and the virtual lengths.
    verification
        Sufficiency per condition and completeness (seed, tolerances and lengths inside).
    """

    job: ClassVar[str] = "singular"

    model: ArmModel
    base: str
    weighting: str
    verification: sg.ConditionVerification

    def to_dict(self) -> dict[str, Any]:
        ver = self.verification
        comp = ver.completeness
        return {
            "robot": self.model.name,
            "base": self.base,
            "weighting": self.weighting if self.base == "virtual" else None,
            "lengths": dict(vars(ver.lengths)),
            "seed": ver.seed,
            "sigma_tol": ver.sigma_tol,
            "condition_tol": ver.condition_tol,
            "conditions": {k: _check_dict(ver.checks[k]) for k in sg.CONDITIONS},
            "refined_conditions": {k: _check_dict(ver.checks[k]) for k in sg.REFINED_CONDITIONS},
            "completeness": {
                "starts": comp.starts,
                "found": comp.found,
                "explained": comp.explained,
                "explained_refined": comp.explained_refined,
                "fraction_explained": comp.fraction_explained,
                "per_condition": dict(comp.per_condition),
                "unexplained_q_deg": np.degrees(comp.unexplained),
            },
        }

    def summary(self) -> list[str]:
        ver = self.verification
        comp = ver.completeness
        lines = [
            f"{self.model.name}: 004's singularity conditions, Jacobian {self.base}, seed {ver.seed}",
            "lengths [m]: " + ", ".join(f"{k}={v:.4f}" for k, v in vars(ver.lengths).items()),
            "",
            f"sufficiency: samples satisfying each condition exactly, singular if sigma_min < {ver.sigma_tol:g}",
            f"  {'condition':10s} {'samples':>8s} {'singular':>9s} {'fraction':>9s} {'median sigma_min':>17s}  verdict",
        ]
        for name, c in ver.checks.items():
            verdict = "sufficient" if c.sufficient else "NOT sufficient"
            if name == "cond1f":
                verdict += " (ours: S4 = 0 and F = 0)"
            lines.append(
                f"  {name:10s} {c.samples:8d} {c.singular:9d} {c.fraction_singular:9.3f} "
                f"{c.sigma_min_median:17.3e}  {verdict}"
            )
        bad = [k for k in sg.CONDITIONS if not ver.checks[k].sufficient]
        if bad:
            lines.append(
                f"  -> 004 calls {', '.join(bad)} singularity conditions, but sampled configurations are not singular"
            )
        lines += [
            "",
            f"completeness: search from {comp.starts} starts found {comp.found} singular configurations; "
            f"{comp.explained} satisfy one of Cond1-Cond5 (residual < {ver.condition_tol:g}), "
            f"{comp.explained_refined} one of cond1f, Cond2-Cond5",
            "  per condition: " + ", ".join(f"{k}: {v}" for k, v in comp.per_condition.items()),
        ]
        return lines

    def write(self, out: str | Path) -> list[str]:
        """``jointlock singular --verify-conditions`` writes no files (``--out`` is for
        ``--search``): nothing is written; returns ``[]``."""
        return []


def verify_singularity_conditions(
    model: ArmModel,
    *,
    samples: int = VERIFY_SAMPLES,
    rng: Rng = 0,
    base: Literal["fixed", "virtual"] = "virtual",
    weighting: VMWeighting = "segment",
    tol: float = sg.RANK_TOL,
    search_samples: int = VERIFY_SEARCH_SAMPLES,
    progress: bool = False,
) -> ConditionVerificationResult:
    """Check seed 004's Cond1-Cond5 on a Canadarm2-structure arm (``jointlock singular
    --verify-conditions``).

    Parameters
    ----------
    model
        The full 7-joint Canadarm2-structure arm (free-floating for ``base="virtual"``).
    samples
        Exact samples per condition (sufficiency: are they all singular?).
    rng
        Seed or Generator (``None``: a fresh seed, recorded in the result).
    base
        ``"virtual"`` (004's virtual manipulator) or ``"fixed"`` (the real arm).
    weighting
        Virtual link lengths: ``"segment"`` (004's formula) or ``"vafa-dubowsky"``.
    tol
        A sample is singular when sigma_min < ``tol`` (raw Jacobian units).
    search_samples
        Starts of the singularity search of the completeness check.
    progress
        Show a progress bar on stderr.

    Returns
    -------
    ConditionVerificationResult
    """
    if base not in ("fixed", "virtual"):
        raise ScenarioError(
            f"base must be 'virtual' (004's case) or 'fixed' to verify the conditions; got {base!r}"
        )
    _check_choice("weighting", weighting, WEIGHTINGS)
    _check_samples(samples)
    _check_samples(search_samples, "search_samples")
    with Progress(len(sg.CONDITIONS) + 2, "verifying", enabled=progress) as bar:
        ver = sg.verify_conditions(
            model,
            samples=samples,
            rng=_seeded(rng),
            base=base,
            weighting=weighting,
            sigma_tol=tol,
            search_samples=search_samples,
            progress=bar,
        )
    return ConditionVerificationResult(model=model, base=base, weighting=weighting, verification=ver)


# -- search --------------------------------------------------------------------------------------


@dataclass(frozen=True)
class SingularitySearchResult(JobResult):
    """Result of :func:`search_singularities` (``jointlock singular ROBOT --search``).

    Attributes
    ----------
    model
        The arm searched.
    search
        Starts, where they ended, the singular configurations found and their families
        (seed, tolerance and Jacobian settings inside).
    family_conditions
        For a full Canadarm2-structure arm (fixed or virtual Jacobian): per family,
        ``{condition: members satisfying it}`` over Cond1-Cond5 and cond1f; else ``None``.
    """

    job: ClassVar[str] = "singular"

    model: ArmModel
    search: sg.SingularitySearch
    family_conditions: tuple[dict[str, int], ...] | None

    def _families(self) -> list[dict[str, Any]]:
        families = []
        for i, fam in enumerate(self.search.families):
            entry: dict[str, Any] = {
                "label": fam.label,
                "size": len(fam.members),
                "zero_sine_joints": list(fam.zero_sine_joints),
                "dependent_joints": list(fam.dependent_joints),
                "representative_q_deg": np.degrees(fam.representative),
                "sigma_min": fam.sigma_min,
                "lost_direction_base": fam.lost_direction,
                "lost_direction_ee": fam.lost_direction_ee,
            }
            if self.family_conditions is not None:
                entry["conditions"] = dict(self.family_conditions[i])
            families.append(entry)
        return families

    def search_json(self) -> dict[str, Any]:
        """The content of ``search.json``: :meth:`to_dict` without ``found``, with every
        configuration found (``q_deg`` (m, n) [deg]) and its ``sigma_min`` (m,)."""
        res, model = self.search, self.model
        return {
            "robot": model.name,
            "base": res.base,
            "joint_numbers": list(model.joint_numbers),
            "locked": locked_deg(model),
            "seed": res.seed,
            "starts": len(res.q_start),
            "converged": int(res.converged.sum()),
            "iterations": res.iterations,
            "tol": res.tol,
            "families": self._families(),
            "q_deg": np.degrees(res.q),
            "sigma_min": res.sigma_min,
        }

    def to_dict(self, files: Sequence[str | Path] | None = None) -> dict[str, Any]:
        """The JSON of ``jointlock singular --search --json``.  ``files``: the paths
        :meth:`write` wrote, listed under ``"files"`` as the command does with ``--out``."""
        out = {k: v for k, v in self.search_json().items() if k not in ("q_deg", "sigma_min")}
        if files is not None:
            out["files"] = [str(f) for f in files]
        return out | {"found": len(self.search.q)}

    def summary(self) -> list[str]:
        res, model = self.search, self.model
        families = self._families()
        lines = [
            f"{model.name}: {model.dof} movable joints {list(model.joint_numbers)}, locked: "
            f"{locked_text(locked_deg(model))}, Jacobian {res.base}",
            f"{len(res.q_start)} starts (seed {res.seed}): {int(res.converged.sum())} converged to "
            f"sigma_min < {res.tol:g} in {res.iterations} iterations; {len(families)} families",
        ]
        for i, fam in enumerate(families, 1):
            lines += [
                "",
                f"{i:2d}. {fam['label']}  ({fam['size']} configurations)",
                "    representative q [deg]: "
                + ", ".join(
                    f"q{j}={v:.2f}" for j, v in zip(model.joint_numbers, fam["representative_q_deg"])
                ),
                "    lost direction (ee frame vx vy vz wx wy wz): "
                + np.array2string(np.asarray(fam["lost_direction_ee"]), precision=3, suppress_small=True),
            ]
            if "conditions" in fam:
                held = ", ".join(f"{k}: {v}" for k, v in fam["conditions"].items() if v) or "none"
                lines.append("    004 conditions held: " + held)
        return lines

    def file_names(self) -> list[str]:
        """The names :meth:`write` writes."""
        return ["search.json", "sigma_min.png"] + (["families.png", "joint_angles.png"] if self.search.families else [])

    def write(self, out: str | Path) -> list[str]:
        """``search.json`` (:meth:`search_json`), ``sigma_min.png`` and, when the search found
        families, ``families.png`` and ``joint_angles.png``; returns their names."""
        out = Path(out)
        out.mkdir(parents=True, exist_ok=True)
        atomic_write_json(out / "search.json", self.search_json())
        names = ["search.json"]
        fig = offscreen_figure(SIGMA_MIN_FIGSIZE)
        plot_search_sigma_min(self.model, self.search, ax=fig.add_subplot())
        atomic_write_bytes(out / "sigma_min.png", figure_png(fig))
        names.append("sigma_min.png")
        if self.search.families:
            fig = plot_singular_families(
                self.model, self.search, fig=offscreen_figure(families_figsize(self.search))
            )
            atomic_write_bytes(out / "families.png", figure_png(fig))
            fig = plot_family_joint_angles(
                self.model, self.search, fig=offscreen_figure(joint_angles_figsize(self.model))
            )
            atomic_write_bytes(out / "joint_angles.png", figure_png(fig))
            names += ["families.png", "joint_angles.png"]
        return names


def search_singularities(
    model: ArmModel,
    *,
    samples: int = SEARCH_SAMPLES,
    rng: Rng = 0,
    base: sg.BaseKind = "fixed",
    weighting: VMWeighting = "segment",
    length: float | None = None,
    tol: float = sg.SEARCH_TOL,
    max_iter: int = SEARCH_MAX_ITER,
    progress: bool = False,
) -> SingularitySearchResult:
    """Search ``model`` for singular configurations and cluster them into families
    (``jointlock singular --search``).

    Parameters
    ----------
    model
        Any arm (locked joints allowed); ``base="floating"``/``"virtual"`` need a free-floating one.
    samples
        Number of seeded starts, uniform within the joint limits (capped to +-pi).
    rng
        Seed or Generator (``None``: a fresh seed, recorded in the result).
    base, weighting, length
        The Jacobian (see :func:`study_singularity`).
    tol
        A start has converged when its sigma_min falls below this (the command uses the
        default, :data:`jointlock.analysis.singularity.SEARCH_TOL`, whatever ``--tol`` says).
    max_iter
        Gauss-Newton iterations.
    progress
        Show a progress bar on stderr.

    Returns
    -------
    SingularitySearchResult
        With the 004 conditions each family's members satisfy when ``model`` is a full
        Canadarm2-structure arm and ``base`` is fixed or virtual.
    """
    _check_choice("base", base, sg.BASE_KINDS)
    _check_choice("weighting", weighting, WEIGHTINGS)
    _check_samples(samples)
    with Progress(max_iter, "searching", enabled=progress) as bar:
        res = sg.find_singularities(
            model,
            samples=samples,
            rng=_seeded(rng),
            base=base,
            weighting=weighting,
            tol=tol,
            max_iter=max_iter,
            length=length,
            progress=bar,
        )
    lengths = _condition_lengths(model, base, weighting)
    family_conditions = None
    if lengths is not None:
        family_conditions = tuple(
            {
                k: int(v.sum())
                for k, v in sg.conditions_hold(res.q[fam.members], lengths, refined=True).items()
            }
            for fam in res.families
        )
    return SingularitySearchResult(model=model, search=res, family_conditions=family_conditions)


# -- scenario ------------------------------------------------------------------------------------

#: What :func:`singular_from_scenario` returns, by mode.
SingularJobResult = SingularityResult | ConditionVerificationResult | SingularitySearchResult


def singular_from_scenario(
    data: Mapping[str, Any], previous: Mapping[str, JobResult], *, progress: bool = False
) -> SingularJobResult:
    """The ``[singular]`` job of a resolved scenario (``Scenario.data``, file units).

    ``singular.verify_conditions`` -> :func:`verify_singularity_conditions`, else
    ``singular.search`` -> :func:`search_singularities`, else :func:`study_singularity` at
    ``singular.q_deg`` (zeros when not given).  The robot, the failure (locked joint) and
    ``seed`` come from the top level; ``singular.base`` (already inherited from the top-level
    ``base`` when the file gives one) defaults to virtual with ``verify_conditions`` and fixed
    otherwise; ``singular.samples`` to 2000 (verification) or 512 (search).  ``previous`` is
    not used.
    """
    t = data["singular"]
    fail = data.get("failure") or {}
    locks = {}
    if fail.get("joint") is not None and fail.get("angle_deg") is not None:
        locks = {int(fail["joint"]): math.radians(float(fail["angle_deg"]))}
    verify = bool(t["verify_conditions"])
    base = t["base"] or ("virtual" if verify else "fixed")
    model = singular_model(data["robot"], locks, base)
    weighting, seed, samples = t["weighting"], int(data["seed"]), t["samples"]
    length = None if t["length"] is None else float(t["length"])
    if verify:
        return verify_singularity_conditions(
            model,
            samples=int(samples or VERIFY_SAMPLES),
            rng=seed,
            base=base,
            weighting=weighting,
            tol=float(t["tol"]),
            progress=progress,
        )
    if t["search"]:
        return search_singularities(
            model,
            samples=int(samples or SEARCH_SAMPLES),
            rng=seed,
            base=base,
            weighting=weighting,
            length=length,
            progress=progress,
        )
    q = joint_vector_deg(model, t["q_deg"], "singular.q_deg")
    return study_singularity(model, q, base=base, weighting=weighting, tol=float(t["tol"]), length=length)
