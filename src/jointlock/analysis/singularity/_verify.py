"""Verification of 004's Cond1-Cond5 on a Canadarm2-structure arm: exact samples of each
condition (sufficiency) and a singularity search (completeness)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np

from ..._deprecate import renamed_keyword
from ..._random import resolve_rng
from ...errors import ScenarioError
from ...kinematics import VMWeighting
from ...model import ArmModel, FloatArray
from ._canadarm2 import (
    CONDITION_TOL,
    CONDITIONS,
    REFINED_CONDITIONS,
    ArmLengths,
    _lengths,
    _trig,
    analytic_directions,
    arm_lengths,
    condition_residuals,
    conditions_hold,
    reference_jacobian,
    reorder_eq24,
)
from ._general import RANK_TOL, singularity_of_jacobian, task_jacobian
from ._search import find_singularities


def sample_condition(
    name: str,
    size: int,
    lengths: ArmLengths | ArmModel,
    *,
    rng: int | np.random.Generator | None = 0,
) -> FloatArray:
    """(size, 7) [rad] configurations that satisfy condition ``name`` exactly.

    The free angles are uniform in [-pi, pi); the condition's equations are solved in closed
    form for the others (batched; draws that have no solution are redrawn):

    * cond1: theta4 in {0, pi}.  cond2: theta2, theta6 in {0, pi}.
    * cond3: theta2 in {0, pi}; given theta3 and phi = theta3+theta4+theta5,
      ``cos(theta3+theta4) = -(d C3 + h sin phi) / e`` (both branches).
    * cond4: theta6 in {0, pi}; given theta5 and phi,
      ``cos(theta4+theta5) = (a sin phi - e C5) / d``.
    * cond5: given phi, a planar two-link problem
      ``d C3 + e C34 = -h sin phi``, ``d S3 + e S34 = a + h cos phi``.
    * cond1f: cond1 plus ``F = 0`` solved for theta6 (``F = A S6 + B C6``).

    ``rng``: seed (int >= 0, default 0), Generator or None (a fresh seed, not returned: pass a
    seed or a Generator to repeat the draw), see :mod:`jointlock._random`.
    """
    names = CONDITIONS + REFINED_CONDITIONS
    if name not in names:
        raise ScenarioError(f"condition must be one of {names}; got {name!r}")
    if size < 0:
        raise ScenarioError(f"size must be >= 0; got {size}")
    lg = _lengths(lengths)
    gen, _ = resolve_rng(rng)
    a, d, e, h = lg.a, lg.d, lg.e, lg.h
    out: list[FloatArray] = []
    have = 0
    while have < size:
        m = max(2 * (size - have), 16)
        q = gen.uniform(-np.pi, np.pi, (m, 7))
        ok = np.ones(m, dtype=bool)
        branch = gen.choice([-1.0, 1.0], m)
        if name in ("cond1", "cond1f"):
            q[:, 3] = gen.integers(0, 2, m) * np.pi
        if name == "cond2":
            q[:, 1], q[:, 5] = gen.integers(0, 2, m) * np.pi, gen.integers(0, 2, m) * np.pi
        elif name == "cond3":
            q[:, 1] = gen.integers(0, 2, m) * np.pi
            phi = q[:, 4]
            cc = -(d * np.cos(q[:, 2]) + h * np.sin(phi)) / e
            ok = np.abs(cc) <= 1.0
            t34 = branch * np.arccos(np.clip(cc, -1, 1))
            q[:, 3], q[:, 4] = t34 - q[:, 2], phi - t34
        elif name == "cond4":
            q[:, 5] = gen.integers(0, 2, m) * np.pi
            phi = q[:, 2]
            cc = (a * np.sin(phi) - e * np.cos(q[:, 4])) / d
            ok = np.abs(cc) <= 1.0
            t45 = branch * np.arccos(np.clip(cc, -1, 1))
            q[:, 3], q[:, 2] = t45 - q[:, 4], phi - t45
        elif name == "cond5":
            phi = q[:, 4]
            x, y = -h * np.sin(phi), a + h * np.cos(phi)
            c4 = (x * x + y * y - d * d - e * e) / (2 * d * e)
            ok = np.abs(c4) <= 1.0
            t4 = branch * np.arccos(np.clip(c4, -1, 1))
            t3 = np.arctan2(y, x) - np.arctan2(e * np.sin(t4), d + e * np.cos(t4))
            q[:, 2], q[:, 3], q[:, 4] = t3, t4, phi - t3 - t4
        elif name == "cond1f":
            t = _trig(q)
            s = np.cos(q[:, 3])
            big_d = d + s * e
            coef_s6 = t["S2"] * (lg.c + lg.f) * (a * t["C3"] + s * h * t["C5"]) - a * t["C2"] * t["C3"] * (
                big_d * t["C3"] + s * h * t["S35"]
            )
            coef_c6 = t["S2"] * h * t["C5"] * (big_d * t["C5"] - a * t["S35"])
            q[:, 5] = np.arctan2(-coef_c6, coef_s6) + gen.integers(0, 2, m) * np.pi
            ok = np.hypot(coef_s6, coef_c6) > 1e-6
        q = np.mod(q + np.pi, 2 * np.pi) - np.pi
        out.append(q[ok])
        have += int(ok.sum())
    return np.concatenate(out)[:size] if out else np.empty((0, 7))


@dataclass(frozen=True)
class ConditionCheck:
    """Sufficiency check of one condition: how many exact samples are singular.

    Attributes
    ----------
    name
        ``"cond1"`` .. ``"cond5"`` or ``"cond1f"``.
    samples, singular
        Number of samples and how many have sigma_min(J^_m) < ``tol``.
    fraction_singular
        ``singular / samples``.
    sigma_min_median, sigma_min_max
        Of the samples [raw Jacobian units].
    max_residual
        Largest condition residual over the samples (should be ~1e-15).
    direction_residual
        Median ``|J'^T u| / |J'|`` of 004's analytic direction over the singular samples
        (NaN if none).
    direction_alignment
        Median ``|u_analytic . u_numeric|`` over the singular samples (1 = same direction).
    """

    name: str
    samples: int
    singular: int
    fraction_singular: float
    sigma_min_median: float
    sigma_min_max: float
    max_residual: float
    direction_residual: float
    direction_alignment: float

    @property
    def sufficient(self) -> bool:
        """Every sample was singular."""
        return self.samples > 0 and self.singular == self.samples


@dataclass(frozen=True)
class Completeness:
    """Completeness check: of the singular configurations found by the search, how many
    satisfy some condition.

    Attributes
    ----------
    found
        Singular configurations found (search converged).
    explained
        How many satisfy at least one of Cond1-Cond5 (residual < ``tol``).
    explained_refined
        How many satisfy at least one of cond1f, Cond2-Cond5 (Cond1 with ``F = 0``).
    per_condition
        ``{name: count}`` over found configurations, Cond1-Cond5 and cond1f (a configuration
        may satisfy several).
    unexplained
        (u, 7) [rad] those satisfying none.
    starts
        Number of search starts.
    """

    found: int
    explained: int
    explained_refined: int
    per_condition: dict[str, int]
    unexplained: FloatArray
    starts: int

    @property
    def fraction_explained(self) -> float:
        return self.explained / self.found if self.found else math.nan


@dataclass(frozen=True)
class ConditionVerification:
    """Result of :func:`verify_conditions`: sufficiency per condition and completeness.

    ``seed`` is the seed the run started from (the fresh one drawn for ``rng=None``), or None
    when a ``Generator`` was passed."""

    checks: dict[str, ConditionCheck]
    completeness: Completeness
    lengths: ArmLengths
    base: str  # the Jacobian kind (``jacobian=``)
    weighting: str
    sigma_tol: float
    condition_tol: float
    seed: int | None


@renamed_keyword(old="base", new="jacobian")
def verify_conditions(
    model: ArmModel,
    *,
    samples: int = 2000,
    search_samples: int = 256,
    rng: int | np.random.Generator | None = 0,
    jacobian: Literal["fixed", "virtual"] = "virtual",
    weighting: VMWeighting = "segment",
    sigma_tol: float = RANK_TOL,
    condition_tol: float = CONDITION_TOL,
    progress: object | None = None,
) -> ConditionVerification:
    """Check 004's conditions against the numerical test on a Canadarm2-structure arm.

    Sufficiency: for each of Cond1-Cond5 (and our refined ``cond1f``) draw ``samples``
    configurations satisfying it exactly (:func:`sample_condition`) and count those with
    sigma_min(J^_m) < ``sigma_tol``.  Completeness: run :func:`find_singularities` from
    ``search_samples`` starts and count the singular configurations found that satisfy some
    condition (residual < ``condition_tol``).  One child generator per task (spawned from
    ``rng``), so results do not depend on order.

    ``jacobian="virtual"`` uses the virtual manipulator (needs a floating model, 004's case);
    ``"fixed"`` the real arm (formerly ``base=``, a deprecated alias).  ``rng``: seed (int >= 0, default 0), Generator or None (a fresh
    seed), recorded in ``seed`` (:mod:`jointlock._random`).
    """
    gen, seed = resolve_rng(rng)
    lengths = arm_lengths(model, jacobian=jacobian, weighting=weighting)
    children = gen.spawn(len(CONDITIONS + REFINED_CONDITIONS) + 1)
    checks: dict[str, ConditionCheck] = {}
    for child, name in zip(children, CONDITIONS + REFINED_CONDITIONS):
        q = sample_condition(name, samples, lengths, rng=child)
        res = singularity_of_jacobian(
            task_jacobian(model, q, jacobian=jacobian, weighting=weighting), tol=sigma_tol
        )
        max_res = float(condition_residuals(q, lengths, refined=True)[name].max()) if samples else math.nan
        dir_res, align = math.nan, math.nan
        sing = res.singular
        analytic_name = "cond1" if name == "cond1f" else name
        if sing.any():
            part = reorder_eq24(reference_jacobian(model, q[sing], jacobian=jacobian, weighting=weighting))
            ua = analytic_directions(q[sing], lengths)[analytic_name]
            jt_u = np.einsum("...ij,...i->...j", part.matrix, ua)
            dir_res = float(
                np.nanmedian(np.linalg.norm(jt_u, axis=-1) / np.linalg.norm(part.matrix, axis=(-2, -1)))
            )
            un = np.linalg.svd(part.matrix)[0][..., :, 5]
            align = float(np.nanmedian(np.abs(np.einsum("...i,...i->...", ua, un))))
        checks[name] = ConditionCheck(
            name=name,
            samples=int(samples),
            singular=int(sing.sum()),
            fraction_singular=float(sing.mean()) if samples else math.nan,
            sigma_min_median=float(np.median(res.sigma_min)) if samples else math.nan,
            sigma_min_max=float(res.sigma_min.max()) if samples else math.nan,
            max_residual=max_res,
            direction_residual=dir_res,
            direction_alignment=align,
        )
        if progress is not None:
            progress.update(1)  # type: ignore[attr-defined]
    search = find_singularities(
        model, samples=search_samples, rng=children[-1], jacobian=jacobian, weighting=weighting
    )
    held = conditions_hold(search.q, lengths, tol=condition_tol, refined=True)
    any_held = np.zeros(len(search.q), dtype=bool)
    for name in CONDITIONS:
        any_held |= held[name]
    any_refined = held["cond1f"].copy()
    for name in CONDITIONS[1:]:
        any_refined |= held[name]
    completeness = Completeness(
        found=len(search.q),
        explained=int(any_held.sum()),
        explained_refined=int(any_refined.sum()),
        per_condition={k: int(v.sum()) for k, v in held.items()},
        unexplained=search.q[~any_held],
        starts=search_samples,
    )
    if progress is not None:
        progress.update(1)  # type: ignore[attr-defined]
    return ConditionVerification(
        checks=checks,
        completeness=completeness,
        lengths=lengths,
        base=jacobian,
        weighting=weighting,
        sigma_tol=sigma_tol,
        condition_tol=condition_tol,
        seed=seed,
    )
