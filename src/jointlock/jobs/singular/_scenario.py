"""The ``[singular]`` job of a scenario: :func:`singular_from_scenario` runs one of the three
modes."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from ...collision import ClearanceSettings
from ...errors import ScenarioError
from ...robots import UrdfChain
from .._common import JobResult, joint_vector_deg, scenario_clearance, scenario_locks
from ._search import SingularitySearchResult, search_singularities
from ._shared import SEARCH_SAMPLES, VERIFY_SAMPLES, singular_model
from ._study import SingularityResult, study_singularity
from ._verify import ConditionVerificationResult, verify_singularity_conditions

#: What :func:`singular_from_scenario` returns, by mode.
SingularJobResult = SingularityResult | ConditionVerificationResult | SingularitySearchResult


def _search_clearance(data: Mapping[str, Any]) -> ClearanceSettings | None:
    """``[singular] skip_colliding``: true -> the scenario's clearance (``[limits]
    clearance_min_m``, ``[[keep_out]]``) screens the singular configurations found; false ->
    they are counted only; unset -> not checked."""
    skip = data["singular"].get("skip_colliding")
    if skip is None:
        return None
    settings = scenario_clearance(data)
    return settings if skip else ClearanceSettings.off(settings.keep_out)


def singular_from_scenario(
    data: Mapping[str, Any], previous: Mapping[str, JobResult], *, progress: bool = False
) -> SingularJobResult:
    """The ``[singular]`` job of a resolved scenario (``Scenario.data``, file units).

    ``singular.verify_conditions`` -> :func:`verify_singularity_conditions`, else
    ``singular.search`` -> :func:`search_singularities`, else :func:`study_singularity` at
    ``singular.q_deg`` (zeros when not given).  The robot, the failure (locked joint) and
    ``seed`` come from the top level; ``singular.base`` (the Jacobian, ``jacobian=``; already
    inherited from the top-level ``base`` when the file gives one) defaults to virtual with
    ``verify_conditions`` and fixed otherwise; ``singular.length`` is the
    ``characteristic_length``; ``singular.samples`` to 2000 (verification) or 512 (search).  ``previous`` is
    not used.
    """
    t = data["singular"]
    if t.get("skip_colliding") is not None and not t["search"]:
        raise ScenarioError("singular.skip_colliding: with singular.search = true only (it screens the singular "
                            "configurations the search finds)")  # fmt: skip
    locks = scenario_locks(data)
    verify = bool(t["verify_conditions"])
    base: Any = t["base"] or ("virtual" if verify else "fixed")  # checked by the scenario reader
    model = singular_model(data["robot"], locks, base, chain=UrdfChain.from_fields(data))
    weighting, seed, samples = t["weighting"], int(data["seed"]), t["samples"]
    length = None if t["length"] is None else float(t["length"])  # the scenario's name for it
    if verify:
        return verify_singularity_conditions(
            model,
            samples=int(samples or VERIFY_SAMPLES),
            rng=seed,
            jacobian=base,
            weighting=weighting,
            tol=float(t["tol"]),
            progress=progress,
        )
    if t["search"]:
        return search_singularities(
            model,
            samples=int(samples or SEARCH_SAMPLES),
            rng=seed,
            jacobian=base,
            weighting=weighting,
            characteristic_length=length,
            clearance=_search_clearance(data),
            progress=progress,
        )
    q = joint_vector_deg(model, t["q_deg"], "singular.q_deg")
    return study_singularity(
        model, q, jacobian=base, weighting=weighting, tol=float(t["tol"]), characteristic_length=length
    )
