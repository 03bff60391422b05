"""Verification of 004's Cond1-Cond5 (``jointlock singular --verify-conditions``):
:func:`verify_singularity_conditions` and its :class:`ConditionVerificationResult`."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any, ClassVar, Literal

import numpy as np

from ..._deprecate import renamed_keyword
from ..._random import resolve_seed
from ...analysis import singularity as sg
from ...errors import ScenarioError
from ...kinematics import VMWeighting
from ...model import ArmModel
from ...progress import Progress
from .._common import JobResult
from ._shared import VERIFY_SAMPLES, VERIFY_SEARCH_SAMPLES, WEIGHTINGS, Rng, _check_choice, _check_samples


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


@dataclass(frozen=True, eq=False)  # arrays inside: compare to_dict() instead
class ConditionVerificationResult(JobResult):
    """Result of :func:`verify_singularity_conditions` (``jointlock singular ROBOT
    --verify-conditions``).

    Attributes
    ----------
    model
        The arm (full Canadarm2-structure arm).
    base, weighting
        The Jacobian (``jacobian=``: ``"virtual"`` or ``"fixed"``) and the virtual lengths.
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


@renamed_keyword(old="base", new="jacobian")
def verify_singularity_conditions(
    model: ArmModel,
    *,
    samples: int = VERIFY_SAMPLES,
    rng: Rng = 0,
    jacobian: Literal["fixed", "virtual"] = "virtual",
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
        The full 7-joint Canadarm2-structure arm (free-floating for ``jacobian="virtual"``).
    samples
        Exact samples per condition (sufficiency: are they all singular?).
    rng
        Seed or Generator (``None``: a fresh seed, recorded in the result).
    jacobian
        ``"virtual"`` (004's virtual manipulator) or ``"fixed"`` (the real arm).  Formerly
        ``base=`` (a deprecated alias).
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
    if jacobian not in ("fixed", "virtual"):
        raise ScenarioError(
            f"jacobian must be 'virtual' (004's case) or 'fixed' to verify the conditions; got {jacobian!r}"
        )
    _check_choice("weighting", weighting, WEIGHTINGS)
    _check_samples(samples)
    _check_samples(search_samples, "search_samples")
    seed = resolve_seed(rng)  # None: a fresh seed, recorded in the result
    with Progress(len(sg.CONDITIONS) + 2, "verifying", enabled=None if progress else False) as bar:
        ver = sg.verify_conditions(
            model,
            samples=samples,
            rng=seed,
            jacobian=jacobian,
            weighting=weighting,
            sigma_tol=tol,
            search_samples=search_samples,
            progress=bar,
        )
    return ConditionVerificationResult(model=model, base=jacobian, weighting=weighting, verification=ver)
