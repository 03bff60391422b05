"""Optimal halt configuration (seed 000 §3.2 and §5.1): HCOM by Monte Carlo, then a bounded
local refinement, with an optional reachability bound and the section plots of 000 Fig. 7.

The search (000 eqs. 20-24): sample ``K`` configurations of the healthy joints uniformly within
their limits (eq. 21), evaluate the combined kinematic-ability index CP of every sample in
batched calls (eq. 19, :mod:`jointlock.analysis.ability`), keep the best.  The normalisation of
CP (min-max bounds of ``s`` and ``w``) and its weights (AHP + entropy) depend on the sample
set; they are fitted once and then *frozen*, so that the refinement and any later evaluation
score configurations on the same scale.

Beyond the paper: the best ``refine_starts`` samples are polished by a bounded quasi-Newton
search (``scipy.optimize.minimize``, L-BFGS-B, central-difference gradients evaluated in one
batched call).  The result is never worse than the best sample, and the gain is reported.

The section plots (000 Fig. 7) are drawn by :mod:`jointlock.plots.halt_config` and written by
:mod:`jointlock.jobs.halt_config` (``section_figures`` and ``write_section_plots`` here are
deprecated aliases of theirs).

Modules (private; every name is re-exported here): ``_bound`` (the bang-bang reachability
bound), ``_reachability`` (exact reachability by the halt polynomial), ``_result`` (the result
types), ``_sampling`` (seed and sampling box), ``_refine`` (the local refinement), ``_search``
(the search itself and :func:`evaluate_cp`).
"""

from __future__ import annotations

import importlib
import warnings
from typing import Any

# Private names are re-exported too: code written before the split imports them from here.
# AffineKBounds is looked up here by HaltReachability (one name to patch, as before the split).
from ..halt_motion import LIMIT_RTOL, AffineKBounds, KIntervalBatch  # noqa: F401
from ._bound import ReachabilityBound, _max_rest_displacement, _readonly  # noqa: F401
from ._reachability import HaltReachability
from ._refine import REFINE_FD_STEP, _pull_back, _refine  # noqa: F401
from ._result import HaltCandidate, HaltConfiguration
from ._sampling import _resolve_rng, _sampling_box, _search_box, _unreachable_message  # noqa: F401
from ._search import (  # noqa: F401
    EQUIVALENT_CP_RTOL,
    RUNNER_UP_SEPARATION,
    _candidate,
    _runner_up,
    evaluate_cp,
    logger,
    optimal_halt_configuration,
)

__all__ = [
    "EQUIVALENT_CP_RTOL",
    "REFINE_FD_STEP",
    "RUNNER_UP_SEPARATION",
    "HaltCandidate",
    "HaltConfiguration",
    "HaltReachability",
    "ReachabilityBound",
    "evaluate_cp",
    "optimal_halt_configuration",
]


#: Names that moved out of this layer (figures and files are drawn and written above it):
#: still found here, with a DeprecationWarning, resolved on first use (PEP 562).
_MOVED = {
    "section_figures": "jointlock.plots.halt_config",
    "write_section_plots": "jointlock.jobs.halt_config",
}


def __getattr__(name: str) -> Any:
    if name in _MOVED:
        warnings.warn(
            f"jointlock.planning.halt_config.{name} is deprecated: use {_MOVED[name]}.{name}",
            DeprecationWarning,
            stacklevel=2,
        )
        return getattr(importlib.import_module(_MOVED[name]), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
