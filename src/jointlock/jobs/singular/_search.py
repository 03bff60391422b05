"""The search for singular configurations (``jointlock singular --search``):
:func:`search_singularities` and its :class:`SingularitySearchResult` (with the figures of
``--out``)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any, ClassVar

import numpy as np

from ..._deprecate import renamed_keyword
from ..._random import resolve_seed
from ...analysis import singularity as sg
from ...collision import ClearanceSettings, collision_pairs
from ...collision import clearance as clearance_of
from ...errors import ScenarioError
from ...io.files import atomic_write_json, with_svg, write_figure
from ...kinematics import VMWeighting
from ...model import ArmModel
from ...plots._common import offscreen_figure
from ...plots.singular import (
    SIGMA_MIN_FIGSIZE,
    families_figsize,
    joint_angles_figsize,
    plot_family_joint_angles,
    plot_search_sigma_min,
    plot_singular_families,
)
from ...progress import Progress
from .._common import JobResult, locked_deg, locked_text
from ._shared import (
    JACOBIANS,
    SEARCH_MAX_ITER,
    SEARCH_SAMPLES,
    WEIGHTINGS,
    Rng,
    _check_choice,
    _check_samples,
    _condition_lengths,
)


@dataclass(frozen=True, eq=False)  # arrays inside: compare to_dict() instead
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
    clearance
        The clearance check of the singular configurations found, when one was asked
        (:func:`search_singularities`'s ``clearance``): ``required_m`` (None: reported only),
        ``checked`` configurations, ``closer_than_allowed`` among them, ``left_out`` (those
        dropped before clustering: all of them when required, else 0), ``closest_m`` and its
        ``closest_pair``, and per family ``family_colliding`` (members closer than allowed, of
        the families kept); None when not asked.
    """

    job: ClassVar[str] = "singular"

    model: ArmModel
    search: sg.SingularitySearch
    family_conditions: tuple[dict[str, int], ...] | None
    clearance: dict[str, Any] | None = None

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
            if self.clearance is not None:
                entry["closer_than_allowed"] = self.clearance["family_colliding"][i]
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
        } | ({} if self.clearance is None else {"clearance": self.clearance})

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
        if self.clearance is not None:
            lines.insert(0, _clearance_line(self.clearance))
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
        return with_svg(["search.json", "sigma_min.png"] + (["families.png", "joint_angles.png"] if self.search.families else []))

    def write(self, out: str | Path) -> list[str]:
        """``search.json`` (:meth:`search_json`), ``sigma_min.png`` and, when the search found
        families, ``families.png`` and ``joint_angles.png``; returns their names."""
        out = Path(out)
        out.mkdir(parents=True, exist_ok=True)
        atomic_write_json(out / "search.json", self.search_json())
        fig = offscreen_figure(SIGMA_MIN_FIGSIZE)
        plot_search_sigma_min(self.model, self.search, ax=fig.add_subplot())
        write_figure(fig, out, "sigma_min.png")
        if self.search.families:
            fig = plot_singular_families(
                self.model, self.search, fig=offscreen_figure(families_figsize(self.search))
            )
            write_figure(fig, out, "families.png")
            fig = plot_family_joint_angles(
                self.model, self.search, fig=offscreen_figure(joint_angles_figsize(self.model))
            )
            write_figure(fig, out, "joint_angles.png")
        return self.file_names()


def _clearance_line(report: Mapping[str, Any]) -> str:
    """The summary's first line about the clearance of the singular configurations found."""
    required = report["required_m"]
    closer, checked = report["closer_than_allowed"], report["checked"]
    if not checked:
        return "clearance: no singular configuration found to check"
    what = f"closer than {required:g} m" if required is not None else "overlapping"
    head = f"clearance: {closer} of {checked} singular configurations found are {what} (links, spacecraft bus, keep-outs)"
    if required is not None:
        return head + (": left out before clustering" if closer else ": none left out")
    return head + f"; closest {report['closest_m']:+.3f} m ({report['closest_pair']}): reported, none left out"


def _screen(
    model: ArmModel, res: sg.SingularitySearch, settings: ClearanceSettings, cluster: Any
) -> tuple[sg.SingularitySearch, dict[str, Any]]:
    """``res`` without the configurations closer than the clearance required (re-clustered by
    ``cluster``), or as it is when the clearance is reported only; and the report."""
    if not collision_pairs(model, settings.keep_out).names:
        raise ScenarioError(
            f"clearance: {model.name!r} has no collision shapes to check (give it link radii or collision "
            "geometry, or leave the clearance out)"
        )
    report: dict[str, Any] = {"required_m": settings.min_m, "checked": len(res.q), "closer_than_allowed": 0,
                              "left_out": 0, "closest_m": None, "closest_pair": None}  # fmt: skip
    if not len(res.q):
        return res, report | {"family_colliding": []}
    measured = clearance_of(model, res.q, keep_out=settings.keep_out, margin=settings.margin, witness=False)
    colliding = measured.colliding()
    at = measured.worst()
    report.update(
        closer_than_allowed=int(colliding.sum()), closest_m=float(measured.distance[at]), closest_pair=measured.pair_at(at)
    )
    if settings.required and colliding.any():
        keep = ~colliding
        res = replace(res, q=res.q[keep], sigma_min=res.sigma_min[keep], families=cluster(res.q[keep]))
        report["left_out"] = int(colliding.sum())
        colliding = colliding[keep]
    report["family_colliding"] = [int(colliding[list(f.members)].sum()) for f in res.families]
    return res, report


@renamed_keyword(old="base", new="jacobian")
@renamed_keyword(old="length", new="characteristic_length")
def search_singularities(
    model: ArmModel,
    *,
    samples: int = SEARCH_SAMPLES,
    rng: Rng = 0,
    jacobian: sg.TaskJacobianKind = "fixed",
    weighting: VMWeighting = "segment",
    characteristic_length: float | None = None,
    tol: float = sg.SEARCH_TOL,
    max_iter: int = SEARCH_MAX_ITER,
    clearance: ClearanceSettings | None = None,
    progress: bool = False,
) -> SingularitySearchResult:
    """Search ``model`` for singular configurations and cluster them into families
    (``jointlock singular --search``).

    Parameters
    ----------
    model
        Any arm (locked joints allowed); ``jacobian="generalized"``/``"virtual"`` need a
        free-floating one.
    samples
        Number of seeded starts, uniform within the joint limits (capped to +-pi).
    rng
        Seed or Generator (``None``: a fresh seed, recorded in the result).
    jacobian, weighting, characteristic_length
        The Jacobian (see :func:`study_singularity`; formerly ``base=`` and ``length=``,
        deprecated aliases).
    tol
        A start has converged when its sigma_min falls below this (the command uses the
        default, :data:`jointlock.analysis.singularity.SEARCH_TOL`, whatever ``--tol`` says).
    max_iter
        Gauss-Newton iterations.
    clearance
        Beyond 004 (issue 27): check the singular configurations found against the arm's
        collision shapes and ``keep_out`` volumes.  With the clearance required
        (``ClearanceSettings(min_m=...)``), those closer than ``min_m`` are left out before
        clustering (a singularity the arm cannot reach without a collision is not one to plan
        around), and counted; with ``ClearanceSettings.off()``, the overlapping ones are counted
        per family, none left out.  Default None: not checked (004's way).
    progress
        Show a progress bar on stderr.

    Returns
    -------
    SingularitySearchResult
        With the 004 conditions each family's members satisfy when ``model`` is a full
        Canadarm2-structure arm and ``jacobian`` is fixed or virtual.
    """
    _check_choice("jacobian", jacobian, JACOBIANS)
    _check_choice("weighting", weighting, WEIGHTINGS)
    _check_samples(samples)
    seed = resolve_seed(rng)  # None: a fresh seed, recorded in the result
    with Progress(max_iter, "searching", enabled=None if progress else False) as bar:
        res = sg.find_singularities(
            model,
            samples=samples,
            rng=seed,
            jacobian=jacobian,
            weighting=weighting,
            tol=tol,
            max_iter=max_iter,
            characteristic_length=characteristic_length,
            progress=bar,
        )
    report = None
    if clearance is not None:
        if not isinstance(clearance, ClearanceSettings):
            raise ScenarioError(f"clearance must be a ClearanceSettings; got {type(clearance).__name__}")

        def cluster(q: np.ndarray) -> tuple[sg.SingularFamily, ...]:
            return sg.cluster_singularities(
                model, q, jacobian=jacobian, weighting=weighting, characteristic_length=characteristic_length
            )

        res, report = _screen(model, res, clearance, cluster)
    lengths = _condition_lengths(model, jacobian, weighting)
    family_conditions = None
    if lengths is not None:
        family_conditions = tuple(
            {
                k: int(v.sum())
                for k, v in sg.conditions_hold(res.q[fam.members], lengths, refined=True).items()
            }
            for fam in res.families
        )
    return SingularitySearchResult(model=model, search=res, family_conditions=family_conditions, clearance=report)
