"""000's whole halt strategy as one call: :func:`plan_halt`.

After a joint locks, the arm must stop.  000 chooses *where* (the optimal halt configuration,
HCOM, §3: Monte Carlo over the healthy joints maximising the combined kinematic-ability index
on the free-floating arm's generalized Jacobian J_F) and *how* (the optimal halt motion, HMOM,
§4: the 6th-order polynomial of eq. 27 with one free coefficient k minimising the time-averaged
base disturbance torque of eq. 32 under angle, speed and acceleration limits).

:func:`plan_halt` chains both with the defaults of ``jointlock halt``:

- the halt configuration is searched only among configurations the halt polynomial can reach
  from the state at failure within T under the limits (exact; 000 searches the whole ranges,
  and its own optimum then has no feasible halt motion).  When no sampled configuration is
  reachable the search falls back to the whole ranges (000's way) and says so;
- the limit rules of :func:`halt_limits`;
- on ``halt7`` with nothing else given, 000 §5's scenario (:mod:`jointlock.papers.p000`).

The result, :class:`HaltPlan`, is what ``jointlock halt --json`` prints (``to_dict()``), the
lines it prints (``summary()``) and the files of ``--out`` (``write()``).

The package's modules:
``_inputs`` (:class:`FailureState`, :class:`JointLimits`, :func:`halt_limits`, 000's default
limits), ``_checks`` (the checks before any work, the settings' names), ``_strategy``
(:func:`plan_halt`, its search, :func:`halt_model`, :func:`halt_from_scenario`), ``_result``
(:class:`HaltPlan`), ``_text`` (its words).  Import from this package, not
from them.
"""

from __future__ import annotations

from ._checks import CLI_NAMES, LIBRARY_NAMES, MIN_N_SAMPLES, check_halt_settings
from ._inputs import (
    CLI_LIMIT_NAMES,
    DEFAULT_AMAX_DEG,
    DEFAULT_VMAX_DEG,
    SCENARIO_LIMIT_NAMES,
    FailureState,
    JointLimits,
    halt_limits,
    is_000_failure,
    limits_text,
    resolve_limits,
)
from ._result import HaltPlan
from ._settings import FORMER_KEYWORDS, HaltLimits, HaltMotionSettings, HaltSearch
from ._strategy import (
    HCOM_JACOBIAN,
    Solver,
    halt_from_scenario,
    halt_model,
    plan_halt,
)

__all__ = [
    "CLI_LIMIT_NAMES",
    "SCENARIO_LIMIT_NAMES",
    "CLI_NAMES",
    "LIBRARY_NAMES",
    "DEFAULT_AMAX_DEG",
    "DEFAULT_VMAX_DEG",
    "HCOM_JACOBIAN",
    "MIN_N_SAMPLES",
    "FORMER_KEYWORDS",
    "FailureState",
    "HaltLimits",
    "HaltMotionSettings",
    "HaltPlan",
    "HaltSearch",
    "JointLimits",
    "Solver",
    "check_halt_settings",
    "halt_from_scenario",
    "halt_limits",
    "halt_model",
    "is_000_failure",
    "limits_text",
    "plan_halt",
    "resolve_limits",
]
