"""Scenario files (TOML): one description of a locked-joint case and the jobs to run on it.

A scenario names the robot, its base, the failure (which joint, at what angle, at what time),
the state at failure, the limits, and which jobs to run with their settings and seed.  It is
validated here, in one place, before anything runs; every error is a
:class:`~jointlock.errors.ScenarioError` naming the file, the field, the value received and
what is allowed (with a did-you-mean for unknown keys).  The resolved scenario (defaults
filled in, file paths absolute) is plain data: :attr:`Scenario.data`.

Field names are those of the command-line options (``--q0-deg`` is ``q0_deg``, ``--T`` is
``T``); degrees only in fields ending in ``_deg`` (``_deg_s``, ``_deg_s2`` for rates).  The
format reference is ``docs/scenarios.md``::

    title = "000 §5: halt after joint 4 locks"
    robot = "halt7"            # built-in name, or a .toml / .urdf model file (relative to this file)
    base = "floating"          # fixed | floating
    seed = 0

    [failure]
    joint = 4                  # numbered from 1
    angle_deg = 0.0

    [state]                    # at failure: healthy joints (or the full arm)
    q0_deg = [-180, -180, -100, -10, 20, 20]

    [limits]
    vmax_deg_s = 40.0          # [deg/s]
    amax_deg_s2 = 20.0         # [deg/s^2]

    [halt_config]
    samples = 36000

    [halt]
    T = 10.0

Jobs run in the order of :data:`JOB_ORDER`: those whose table is present, or those listed in
``jobs = [...]``.

One name per quantity: a former field name (:data:`DEPRECATED_FIELDS`: ``[limits] vmax_deg``,
``amax_deg``) still works, in a file and in an override, and warns once (``FutureWarning``)
naming the new one.  The resolved ``data["limits"]`` keeps the keys ``vmax_deg`` [deg/s] and
``amax_deg`` [deg/s^2] (:data:`RESOLVED_KEYS`).

Modules (private; import from ``jointlock.scenario``): ``_fields`` (the schema: jobs, fields,
tables), ``_scenario`` (:class:`Scenario`), ``_read`` (file, overrides, values), ``_checks``
(cross-field checks), ``_jump`` (the ``[jump]`` table's 001 task), ``_defaults`` (000's
defaults).
"""

from __future__ import annotations

# Leading-underscore names are re-exported (``x as x``) so that code written against the former
# single module ``scenario.py`` keeps importing them from here; they are not part of the API.
from ._checks import _check_semantics as _check_semantics
from ._checks import _inherit_singular_base as _inherit_singular_base
from ._checks import _load as _load
from ._checks import _resolve_robot as _resolve_robot
from ._defaults import _defaults_000 as _defaults_000
from ._fields import _BASE2 as _BASE2
from ._fields import (
    ALL_TABLES,
    DEPRECATED_FIELDS,
    JOB_ORDER,
    JOB_PAPER,
    JOB_TABLES,
    MAX_ABS_DEG,
    NEEDS_LOCK,
    RESOLVED_KEYS,
    SHARED_TABLES,
    TOP_FIELDS,
    WORKSPACE_MIN_SAMPLES,
    Field,
)
from ._fields import _deg as _deg
from ._fields import _hint as _hint
from ._fields import _pos as _pos
from ._fields import _spellings as _spellings
from ._jump import JUMP_SCENARIO_FIELDS, jump_fields
from ._jump import _check_jump as _check_jump
from ._read import _table as _table
from ._read import apply_overrides, check_value, load_scenario, parse_set, scenario_from_dict
from ._read import check_value as _check  # noqa: F401  (former private name)
from ._scenario import Scenario, job_lock_args

__all__ = [
    "ALL_TABLES",
    "DEPRECATED_FIELDS",
    "JOB_ORDER",
    "JOB_PAPER",
    "JOB_TABLES",
    "JUMP_SCENARIO_FIELDS",
    "MAX_ABS_DEG",
    "NEEDS_LOCK",
    "RESOLVED_KEYS",
    "SHARED_TABLES",
    "TOP_FIELDS",
    "WORKSPACE_MIN_SAMPLES",
    "Field",
    "Scenario",
    "apply_overrides",
    "check_value",
    "job_lock_args",
    "jump_fields",
    "load_scenario",
    "parse_set",
    "scenario_from_dict",
]
