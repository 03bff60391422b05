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

The package's modules:
``_shared`` (defaults, :func:`singular_model`, input checks), ``_study`` (one configuration),
``_verify`` (Cond1-Cond5), ``_search`` (the search), ``_scenario``
(:func:`singular_from_scenario`).  Import from this package, not from them.
"""

from __future__ import annotations

from ._scenario import SingularJobResult, singular_from_scenario
from ._search import SingularitySearchResult, search_singularities
from ._shared import (
    SEARCH_MAX_ITER,
    SEARCH_SAMPLES,
    VERIFY_SAMPLES,
    VERIFY_SEARCH_SAMPLES,
    WEIGHTINGS,
    Rng,
    singular_model,
)
from ._study import (
    AnalyticDirection,
    ConditionsAtConfiguration,
    SingularityResult,
    conditions_at,
    study_singularity,
)
from ._verify import ConditionVerificationResult, verify_singularity_conditions

__all__ = [
    "SEARCH_MAX_ITER",
    "SEARCH_SAMPLES",
    "VERIFY_SAMPLES",
    "VERIFY_SEARCH_SAMPLES",
    "WEIGHTINGS",
    "AnalyticDirection",
    "ConditionVerificationResult",
    "ConditionsAtConfiguration",
    "Rng",
    "SingularJobResult",
    "SingularityResult",
    "SingularitySearchResult",
    "conditions_at",
    "search_singularities",
    "singular_from_scenario",
    "singular_model",
    "study_singularity",
    "verify_singularity_conditions",
]
