"""The jump task (:class:`JumpScenario`) and the task-file reader (flat TOML table):
:func:`load_jump_task` (formerly ``load_scenario``, a name it shared with
:func:`jointlock.scenario.load_scenario`, the reader of ``jointlock run`` scenario files)."""

from __future__ import annotations

import difflib
import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal, cast

import numpy as np
from numpy.typing import ArrayLike

from ..._deprecate import warn_once
from ...bounds import (
    MAX_GAIN,
    MAX_JOINT_VALUE,
    MAX_LENGTH_M,
    MAX_TIME_S,
    MAX_TIME_STEPS,
    MIN_STEP_S,
    MIN_TIME_S,
    as_real,
    shown,
)
from ...errors import ScenarioError
from ...io.files import read_toml_file
from ...model import FloatArray

Base = Literal["fixed", "floating"]


# -- scenario -------------------------------------------------------------------------------


@dataclass(frozen=True)
class JumpScenario:
    """A path-following task with a joint that may lock (SI units and radians).

    Attributes
    ----------
    q0
        Start configuration, one angle per joint [rad].
    dx
        Straight-line displacement of the end effector (3,) [m], root/inertial frame.
    duration, blend, dt
        Task time ``T``, blend time ``t_b`` of the parabolic segments and control step [s].
        ``T`` must be a whole number of steps and ``2 t_b <= T``.
    lock_joint
        Number (1-based) of the joint that locks.
    vmax, amax
        Joint speed [rad/s] and acceleration [rad/s^2] limits (all joints).
    eps
        Position-deviation threshold ``||x - x_nom||`` [m].
    kp
        Feedback gain ``K_p`` [1/s]; 0 = open loop.
    base
        ``"fixed"`` or ``"floating"`` (generalized Jacobian; needs a free-floating model).
    rest_transitions
        Check the start from rest and the stop at ``T`` against ``amax`` (see module notes).
    feedforward
        Discrete feed-forward over a control step: ``"step"`` (default) uses the nominal
        displacement over the step divided by ``dt``, exact for rates held over the step;
        ``"instant"`` uses ``xdot_nom(t_k)``, which lags by ``xddot dt / 2`` in the blends
        (with the default scenario that alone puts ``||x - x_nom||`` at 1.3 mm > 1 mm).
    """

    q0: tuple[float, ...] = tuple(math.radians(v) for v in (10.0, 40.0, -70.0, 100.0, -60.0, 30.0, 20.0))
    dx: tuple[float, float, float] = (1.2, -1.5, 0.8)
    duration: float = 12.0
    blend: float = 2.0
    dt: float = 0.05
    lock_joint: int = 2
    vmax: float = math.radians(10.0)
    amax: float = math.radians(5.0)
    eps: float = 1e-3
    kp: float = 2.0
    base: Base = "fixed"
    rest_transitions: bool = False
    feedforward: Literal["step", "instant"] = "step"

    def __post_init__(self) -> None:
        q0 = tuple(float(v) for v in np.atleast_1d(np.asarray(self.q0, dtype=float)))
        dx = tuple(float(v) for v in np.asarray(self.dx, dtype=float).ravel())
        if not all(math.isfinite(v) for v in q0):
            raise ScenarioError(f"q0 must be finite angles [rad]; got {q0}")
        if len(dx) != 3 or not all(math.isfinite(v) for v in dx):
            raise ScenarioError(f"dx must be 3 finite numbers [m]; got {self.dx!r}")
        if any(abs(v) > MAX_JOINT_VALUE for v in q0):
            raise ScenarioError(f"q0 must lie within +-{MAX_JOINT_VALUE:g} rad; got {shown(q0)}")
        if any(abs(v) > MAX_LENGTH_M for v in dx):
            raise ScenarioError(f"dx must lie within +-{MAX_LENGTH_M:g} m; got {shown(dx)}")
        for name, (lo, hi, unit) in _BOUNDS.items():
            value = as_real(getattr(self, name), name, hi=hi, unit=unit, error=ScenarioError)
            if not value >= lo or (lo == 0 and value == 0):
                raise ScenarioError(
                    f"{name} must be a finite number {'> 0' if lo == 0 else f'>= {lo:g}'} and <= {hi:g} "
                    f"[{unit}]; got {shown(getattr(self, name))}"
                )
            object.__setattr__(self, name, value)
        as_real(self.kp, "kp", lo=0.0, hi=MAX_GAIN, unit="1/s", error=ScenarioError)
        if 2.0 * self.blend > self.duration + 1e-12:
            raise ScenarioError(
                f"blend must be at most duration/2 = {self.duration / 2:g} s; got {self.blend:g} s"
            )
        steps = self.duration / self.dt
        if steps > MAX_TIME_STEPS:
            raise ScenarioError(
                f"duration / dt = {steps:.3g} control steps; at most {MAX_TIME_STEPS:g} (a longer step dt, "
                "or a shorter task)"
            )
        if abs(steps - round(steps)) > 1e-6 or round(steps) < 2:
            raise ScenarioError(
                f"duration ({self.duration:g} s) must be a whole number (>= 2) of control steps "
                f"dt = {self.dt:g} s; got {steps:g} steps"
            )
        if isinstance(self.lock_joint, bool) or not isinstance(self.lock_joint, (int, np.integer)):
            raise ScenarioError(
                f"lock_joint must be an integer joint number (1-based); got {self.lock_joint!r}"
            )
        if self.base not in ("fixed", "floating"):
            raise ScenarioError(f"base must be 'fixed' or 'floating'; got {self.base!r}")
        if self.feedforward not in ("step", "instant"):
            raise ScenarioError(f"feedforward must be 'step' or 'instant'; got {self.feedforward!r}")
        object.__setattr__(self, "q0", q0)
        object.__setattr__(self, "dx", dx)
        object.__setattr__(self, "kp", float(self.kp))
        object.__setattr__(self, "lock_joint", int(self.lock_joint))

    @property
    def n_steps(self) -> int:
        """Number of control steps ``N = T / dt``."""
        return int(round(self.duration / self.dt))

    @property
    def times(self) -> FloatArray:
        """(N + 1,) sample times ``k dt`` [s], k = 0..N."""
        return cast(FloatArray, np.arange(self.n_steps + 1) * self.dt)

    def step_of(self, t: ArrayLike) -> np.ndarray:
        """Control step at which a failure at time(s) ``t`` [s] takes effect: ``ceil(t/dt)``."""
        t = np.asarray(t, dtype=float)
        if np.any(~np.isfinite(t)) or np.any(t < 0) or np.any(t >= self.duration):
            raise ScenarioError(
                f"failure time must lie in [0, {self.duration:g}) s; got {np.atleast_1d(t).tolist()}"
            )
        return np.ceil(t / self.dt - 1e-9).astype(int)

    def to_fields(self) -> dict[str, Any]:
        """The scenario in file units (degrees for angles), keys as in :data:`SCENARIO_FIELDS`."""
        return {
            "q0_deg": [math.degrees(v) for v in self.q0],
            "dx_m": list(self.dx),
            "duration_s": self.duration,
            "blend_s": self.blend,
            "dt_s": self.dt,
            "lock_joint": self.lock_joint,
            "vmax_deg_s": math.degrees(self.vmax),
            "amax_deg_s2": math.degrees(self.amax),
            "eps_m": self.eps,
            "kp": self.kp,
            "base": self.base,
            "rest_transitions": self.rest_transitions,
            "feedforward": self.feedforward,
        }


#: Bounds of the task's positive quantities: attribute -> (lowest, highest, unit); a lowest
#: of 0 means "> 0" (see :mod:`jointlock.bounds`).
_BOUNDS: dict[str, tuple[float, float, str]] = {
    "duration": (MIN_TIME_S, MAX_TIME_S, "s"),
    "blend": (0.0, MAX_TIME_S, "s"),
    "dt": (MIN_STEP_S, MAX_TIME_S, "s"),
    "vmax": (0.0, MAX_JOINT_VALUE, "rad/s"),
    "amax": (0.0, MAX_JOINT_VALUE, "rad/s^2"),
    "eps": (0.0, MAX_LENGTH_M, "m"),
}


#: Scenario-file fields: name -> (JumpScenario attribute, kind, conversion to SI).
SCENARIO_FIELDS: dict[str, tuple[str, str, Callable[[Any], Any]]] = {
    "q0_deg": ("q0", "list", lambda v: tuple(math.radians(x) for x in v)),
    "dx_m": ("dx", "list3", lambda v: tuple(float(x) for x in v)),
    "duration_s": ("duration", "number", float),
    "blend_s": ("blend", "number", float),
    "dt_s": ("dt", "number", float),
    "lock_joint": ("lock_joint", "int", int),
    "vmax_deg_s": ("vmax", "number", math.radians),
    "amax_deg_s2": ("amax", "number", math.radians),
    "eps_m": ("eps", "number", float),
    "kp": ("kp", "number", float),
    "base": ("base", "str", str),
    "rest_transitions": ("rest_transitions", "bool", bool),
    "feedforward": ("feedforward", "str", str),
}


def _is_number(v: Any) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool)


def scenario_from_mapping(data: Mapping[str, Any], *, source: str = "scenario") -> JumpScenario:
    """Build a :class:`JumpScenario` from file-style fields (degrees; see :data:`SCENARIO_FIELDS`).

    Missing fields take NOTES-001's defaults.  Unknown keys and wrong types raise
    :class:`~jointlock.errors.ScenarioError` naming the field (with a did-you-mean hint).
    """
    kwargs: dict[str, Any] = {}
    for key, value in data.items():
        if key not in SCENARIO_FIELDS:
            close = difflib.get_close_matches(key, list(SCENARIO_FIELDS), n=1)
            hint = f" (did you mean {close[0]!r}?)" if close else ""
            raise ScenarioError(
                f"{source}: unknown field {key!r}{hint}; allowed: {', '.join(SCENARIO_FIELDS)}"
            )
        attr, kind, convert = SCENARIO_FIELDS[key]
        ok = {
            "number": _is_number(value),
            "int": isinstance(value, int) and not isinstance(value, bool),
            "bool": isinstance(value, bool),
            "str": isinstance(value, str),
            "list": isinstance(value, list) and len(value) > 0 and all(_is_number(v) for v in value),
            "list3": isinstance(value, list) and len(value) == 3 and all(_is_number(v) for v in value),
        }[kind]
        if not ok:
            want = {
                "number": "a number",
                "int": "an integer",
                "bool": "true or false",
                "str": "a string",
                "list": "a list of numbers",
                "list3": "a list of 3 numbers",
            }[kind]
            raise ScenarioError(
                f"{source}: field {key!r} must be {want}; got {shown(value)} ({type(value).__name__})"
            )
        try:
            kwargs[attr] = convert(value)
        except OverflowError:
            raise ScenarioError(f"{source}: field {key!r} is too large for a number; got {shown(value)}") from None
    try:
        return JumpScenario(**kwargs)
    except ScenarioError as exc:
        raise ScenarioError(f"{source}: {exc}") from None


def load_jump_task(path: str | Path) -> JumpScenario:
    """Read a jump task file: a flat TOML table, the fields of :data:`SCENARIO_FIELDS`.

    Not a ``jointlock run`` scenario file (tables such as ``[jump]``): those are read by
    :func:`jointlock.scenario.load_scenario`, and refused here with a message saying so.  The
    same task can be a scenario's ``[task]`` table (issue 28: ``q0_deg``, ``dx_m``, ...), which
    every job then follows (:func:`jointlock.planning.jump.cartesian_task`).
    """
    data = read_toml_file(path, "scenario file", ScenarioError)
    _refuse_run_scenario(data, str(path))
    return scenario_from_mapping(data, source=str(path))


def load_scenario(path: str | Path) -> JumpScenario:
    """Deprecated alias of :func:`load_jump_task` (warns once per process, ``FutureWarning``)."""
    warn_once(
        "function jointlock.planning.jump.load_scenario",
        "jointlock.planning.jump.load_scenario is deprecated: use jointlock.planning.jump."
        "load_jump_task (the same jump task-file reader; jointlock.load_scenario reads "
        "`jointlock run` scenario files)",
    )
    return load_jump_task(path)


#: Top-level keys of a ``jointlock run`` scenario file that a jump task file never has.
_RUN_SCENARIO_KEYS = ("title", "description", "robot", "seed", "jobs", "out")


def _refuse_run_scenario(data: Mapping[str, Any], source: str) -> None:
    """A ``jointlock run`` scenario file (tables such as ``[jump]``, ``[failure]``, or keys such
    as ``title``, ``robot``) given where a flat task file is expected: say which command runs it."""
    tables = [k for k, v in data.items() if isinstance(v, Mapping)]
    keys = [k for k in _RUN_SCENARIO_KEYS if k in data]
    if not tables and not keys:
        return
    what = ", ".join([f"[{t}]" for t in tables] + keys)
    raise ScenarioError(
        f"{source} is a `jointlock run` scenario file ({what}), not a jump task file: run it with "
        f"`jointlock run {source}` (add --jobs jump to run only its [jump] table), or give "
        "--scenario a flat task file: the task fields of a [jump] table (q0_deg, dx_m, duration_s, ...) at the "
        "top level, no tables (docs/jump.md)"
    )
