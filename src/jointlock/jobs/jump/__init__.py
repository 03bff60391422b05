"""The velocity-jump study of seed 001 as one library call (``jointlock jump``).

Three modes, as the command has them:

* ``fail_at`` -- one failure time: the jump with and without compensation, the optimal kappa
  (or a given one) and its feasible interval, the limits kept (:func:`jump_at_time`);
* ``sweep`` -- sampled failure times: the optimal kappa per time, the fitted piecewise kappa(t)
  and its verification with the failure injected at every control step, plus a fix of kappa(t)
  when asked or needed (:func:`study_jump`);
* ``constant`` -- a constant kappa verified at every control step (:func:`verify_kappa`).

:func:`run_jump_study` runs one of them on an arm and a :class:`JumpScenario`; its
:class:`JumpJobResult` gives the command's JSON (:meth:`~JumpJobResult.to_dict`), text
(:meth:`~JumpJobResult.summary`) and files (:meth:`~JumpJobResult.write`).
:func:`jump_from_scenario` runs the ``[jump]`` job of a ``jointlock run`` scenario.

The package's modules:
``_run`` (:func:`run_jump_study`, its checks and defaults, :func:`jump_from_scenario`),
``_result`` (:class:`JumpJobResult`, the command's JSON and files), ``_text``
(:func:`summary_lines`).  Import from this package, not from them.
"""

from __future__ import annotations

from ...plots.jump import KAPPA_UNIT
from ._result import (
    FIG_DEVIATION,
    FIG_JOINT_RATES,
    FIG_JUMP,
    FIG_KAPPA_FIT,
    FIG_OBJECTIVE,
    JumpJobResult,
    Mode,
    limits_json,
    verification_csv,
)
from ._run import (
    DEFAULT_ORDER,
    DEFAULT_SWEEP,
    MAX_ORDER,
    Fix,
    jump_from_scenario,
    run_jump_study,
    task_as_the_command_reads_it,
)
from ._text import _interval_text, _less, _points_text, summary_lines

__all__ = [
    "KAPPA_UNIT",
    "MAX_ORDER",
    "JumpJobResult",
    "jump_from_scenario",
    "limits_json",
    "run_jump_study",
    "summary_lines",
    "task_as_the_command_reads_it",
    "verification_csv",
]

#: Names used from here besides ``__all__`` (``jointlock.cli.jump`` imports the defaults and
#: the text helpers).
_ALSO_EXPORTED = (
    DEFAULT_ORDER,
    DEFAULT_SWEEP,
    FIG_DEVIATION,
    FIG_JOINT_RATES,
    FIG_JUMP,
    FIG_KAPPA_FIT,
    FIG_OBJECTIVE,
    Fix,
    Mode,
    _interval_text,
    _less,
    _points_text,
)
