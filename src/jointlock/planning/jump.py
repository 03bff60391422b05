"""Keep following the path through an unexpected lock: null-space "global compensation"
(seed 001, method as reconstructed in ``NOTES-001.md``).

Pipeline
--------
1. :func:`cartesian_trapezoid` -- straight line ``x0 -> x0 + dx`` timed by a trapezoidal
   velocity profile with parabolic blends (001 §4.3: 12 s task, 2 s blends, 50 ms step).
2. Resolved-rate following with the compensation term (NOTES-001, "The control law")::

       xdot_c = xdot_nom + K_p (x_nom - x)
       qdot   = J^+ xdot_c + kappa (I - J^+ J) grad w(q)          (healthy)
       qdot_r = J_r^+ xdot_c + kappa (I - J_r^+ J_r) grad w_r(q)   (after the lock; qdot_j = 0)

   ``w = sqrt(det(J J^T))`` of the 3 x n position Jacobian, gradient in closed form
   (:mod:`jointlock.derivatives`).  Joint states are integrated by explicit Euler over the
   control step (001 eq. 19, ``q_{k+1} = q_k + qdot_k dt``).  A failure at time ``t_f`` takes
   effect at the first control step ``k_f = ceil(t_f / dt)``; several joints may lock in
   sequence.  The locked Jacobian is the full one with the locked columns masked, which is
   exactly the reduced model's Jacobian (``docs/conventions.md``).
3. Jump metrics at ``t_f`` (same configuration, NOTES-001 "What is measured"): joint jump
   ``qdot(t_f+) - qdot(t_f-)`` with re-planning (padded reduced law) and without (only the
   locked joint stops), task jump ``-J_j qdot_j`` without re-planning and ``J dqdot`` (zero
   while ``J_r`` has full row rank) with it.
4. :func:`search_kappa` -- feasible kappa interval under ``|qdot| <= qdot_max``,
   ``|qddot| <= qddot_max`` (finite differences over the control step) and
   ``||x - x_nom|| <= eps`` for the healthy run *and* the run with the failure; grid search of
   ``||dqdot||`` then parabolic/golden-section refinement inside the brackets of the best
   feasible local grid minima (multi-start: a narrow valley between grid points is found).
5. :func:`fit_kappa` -- piecewise polynomial kappa(t): the sampled optimum is split where it
   jumps from one branch to another (:func:`find_breaks`), failure times are added around each
   break, one least-squares polynomial per segment (5th order by default; order raised until
   the residual criterion holds), and per segment, in time order and with the schedule's own
   history, the piece is kept, the previous piece continued, or kappa = 0 used -- whichever
   gives the smaller jumps at the segment's samples; a kept piece is trimmed to 001's segment
   points where compensated and uncompensated objectives are equal (kappa = 0 near start and
   end).  Without breaks: 001's single polynomial with two segment points.
6. :func:`verify_kappa` -- failure injected at **every** control step with kappa(t) in the
   law: jumps before/after, mean reduction, share improved, every limit checked (a fitted
   kappa(t) can break a limit that each sampled kappa kept: reported, and clipping to the
   feasible band is offered).

Batching (NOTES-001 property 4): the motion before a failure does not depend on when it
happens, so one healthy run per kappa gives the jump at *every* control step (both laws are
evaluated at each step of the healthy run).  The post-failure runs needed for the limits
start from the healthy history and are integrated together: all kappa values and failure
times are array dimensions; the only Python loop is over the integrator's time steps.

Choices where the paper is silent (arguments / scenario fields):

* The step at which the lock happens is excluded from the acceleration check (the jump is
  the objective, not a constraint; otherwise no kappa is ever feasible).
* ``rest_transitions=False``: the start from rest and the stop at ``T`` are not checked
  against ``qddot_max`` (with a constant kappa the compensation term makes the arm start
  moving at ``t = 0``; 001 imposes kappa(0) = kappa(T) = 0 on its fitted function for that
  reason).  Set it True to check them.
* Free-floating base (``scenario.base="floating"``): the generalized Jacobian (zero
  momentum), its derivative by finite differences, the spacecraft attitude integrated from
  the base Jacobian, and the end-effector position taken in the inertial frame (system centre
  of mass fixed, inertial frame = root frame at ``t = 0``).
"""

from __future__ import annotations

import dataclasses
import difflib
import logging
import math
import time
import warnings
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field, fields
from pathlib import Path
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike

from ..derivatives import cross3, generalized_jacobian_derivatives, linear_jacobian_derivatives
from ..errors import InfeasibleError, ModelError, ScenarioError, SingularityWarning
from ..kinematics import base_jacobian, chain_state, generalized_jacobian, system_com
from ..model import ArmModel, FloatArray
from ..spatial import axis_angle_rotation

log = logging.getLogger(__name__)

#: Relative slack on the velocity/acceleration/deviation limits (round-off only) [-].
LIMIT_RTOL = 1e-9
#: Manipulability below which a run counts as singular (masked out of searches) [m^3].
SINGULAR_W = 1e-6
#: Golden ratio conjugate used by the bounded refinement.
_GOLDEN = (math.sqrt(5.0) - 1.0) / 2.0

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
        for name in ("duration", "blend", "dt", "vmax", "amax", "eps"):
            value = float(getattr(self, name))
            if not (math.isfinite(value) and value > 0):
                raise ScenarioError(f"{name} must be a finite number > 0; got {getattr(self, name)!r}")
            object.__setattr__(self, name, value)
        if not (math.isfinite(float(self.kp)) and float(self.kp) >= 0):
            raise ScenarioError(f"kp must be a finite number >= 0 [1/s]; got {self.kp!r}")
        if 2.0 * self.blend > self.duration + 1e-12:
            raise ScenarioError(
                f"blend must be at most duration/2 = {self.duration / 2:g} s; got {self.blend:g} s"
            )
        steps = self.duration / self.dt
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
        return np.arange(self.n_steps + 1) * self.dt

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
                f"{source}: field {key!r} must be {want}; got {value!r} ({type(value).__name__})"
            )
        kwargs[attr] = convert(value)
    return JumpScenario(**kwargs)


def load_scenario(path: str | Path) -> JumpScenario:
    """Read a scenario TOML file (flat table, fields of :data:`SCENARIO_FIELDS`)."""
    try:
        import tomllib
    except ModuleNotFoundError:  # pragma: no cover - Python < 3.11
        import tomli as tomllib  # type: ignore[no-redef]
    path = Path(path)
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise ScenarioError(f"scenario file {str(path)!r} does not exist") from None
    except UnicodeDecodeError as exc:
        raise ScenarioError(f"scenario file {str(path)!r} is not UTF-8 text: {exc}") from None
    except OSError as exc:  # a folder, no permission, ...
        reason = exc.strerror or type(exc).__name__
        raise ScenarioError(f"cannot read scenario file {str(path)!r}: {reason}") from None
    except tomllib.TOMLDecodeError as exc:
        raise ScenarioError(f"scenario file {str(path)!r} is not valid TOML: {exc}") from None
    _refuse_run_scenario(data, str(path))
    return scenario_from_mapping(data, source=str(path))


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


# -- Cartesian path -------------------------------------------------------------------------


@dataclass(frozen=True)
class CartesianPath:
    """Samples of the nominal straight-line path.

    Attributes
    ----------
    t
        (...) times [s].
    s, sd, sdd
        (...) path parameter in [0, 1] and its first two time derivatives [1/s, 1/s^2].
    x, xd, xdd
        (..., 3) position [m], velocity [m/s], acceleration [m/s^2].
    """

    t: FloatArray
    s: FloatArray
    sd: FloatArray
    sdd: FloatArray
    x: FloatArray
    xd: FloatArray
    xdd: FloatArray


def cartesian_trapezoid(
    x0: ArrayLike, dx: ArrayLike, t: ArrayLike, *, duration: float = 12.0, blend: float = 2.0
) -> CartesianPath:
    """Straight line with a trapezoidal velocity profile and parabolic blends (001 §4.3).

    ``s(t)``: constant acceleration ``a = v / t_b`` for ``t < t_b``, cruise at
    ``v = 1 / (T - t_b)`` and constant deceleration for ``t > T - t_b``; ``s(0) = 0``,
    ``s(T) = 1``, velocity zero at both ends, ``s`` and ``sd`` continuous.  Outside ``[0, T]``
    the path is held at its end points.

    Parameters
    ----------
    x0
        (3,) start position [m].
    dx
        (3,) displacement [m].
    t
        (...) times [s].
    duration, blend
        ``T`` and ``t_b`` [s], ``0 < 2 t_b <= T``.
    """
    if not (duration > 0 and 0 < blend <= duration / 2):
        raise ScenarioError(f"need 0 < blend <= duration/2; got blend={blend!r}, duration={duration!r}")
    t = np.clip(np.asarray(t, dtype=float), 0.0, duration)
    v = 1.0 / (duration - blend)
    a = v / blend
    rise = t < blend
    fall = t > duration - blend
    tau = duration - t
    s = np.where(rise, 0.5 * a * t**2, np.where(fall, 1.0 - 0.5 * a * tau**2, v * (t - 0.5 * blend)))
    sd = np.where(rise, a * t, np.where(fall, a * tau, v))
    sdd = np.where(rise, a, np.where(fall, -a, 0.0))
    x0 = np.asarray(x0, dtype=float)
    dx = np.asarray(dx, dtype=float)
    return CartesianPath(t, s, sd, sdd, x0 + s[..., None] * dx, sd[..., None] * dx, sdd[..., None] * dx)


# -- the control law ------------------------------------------------------------------------


def compensated_rates(
    jac: ArrayLike,
    djac: ArrayLike,
    xdot: ArrayLike,
    kappa: ArrayLike,
    healthy: ArrayLike | None = None,
) -> tuple[FloatArray, FloatArray]:
    """Resolved rate with global compensation (NOTES-001, "The control law"), batched.

    ``qdot = J_h^+ xdot + kappa (I - J_h^+ J_h) grad w_h`` where ``J_h`` is the position
    Jacobian with the locked columns removed (``healthy`` mask) and ``w_h`` its
    manipulability; locked entries of ``qdot`` are exactly 0 (NOTES-001 property 3).

    Parameters
    ----------
    jac
        (..., 3, n) position Jacobian [m/rad].
    djac
        (..., n, 3, n) its derivatives, ``djac[..., i, :, k] = dJ[:, k]/dq_i``.
    xdot
        (..., 3) commanded end-effector velocity [m/s].
    kappa
        (...) compensation coefficient [rad^2/(s m^3)] (``w`` in m^3 for the position block).
    healthy
        (..., n) boolean mask of joints that can move; ``None`` = all.

    Returns
    -------
    qdot
        (..., n) joint rates [rad/s].
    w
        (...) manipulability of the healthy columns [m^3].
    """
    jac = np.asarray(jac, dtype=float)
    djac = np.asarray(djac, dtype=float)
    if healthy is not None:
        mask = np.asarray(healthy, dtype=bool)
        jac = jac * mask[..., None, :]
        djac = djac * mask[..., None, None, :]
    gram = jac @ np.swapaxes(jac, -1, -2)
    det = np.linalg.det(gram)
    w = np.sqrt(np.maximum(det, 0.0))
    try:
        m = np.linalg.solve(gram, jac)  # (J J^T)^-1 J, rows of J^+ transposed
    except np.linalg.LinAlgError:
        m = np.swapaxes(np.linalg.pinv(np.swapaxes(jac, -1, -2)), -1, -2)
    grad = w[..., None] * np.einsum("...rc,...irc->...i", m, djac)
    if healthy is not None:
        grad = grad * mask
    pinv = np.swapaxes(m, -1, -2)  # (..., n, 3)
    null = grad - np.einsum("...ir,...r->...i", pinv, np.einsum("...rc,...c->...r", jac, grad))
    qdot = np.einsum("...ir,...r->...i", pinv, np.asarray(xdot, dtype=float))
    qdot = qdot + np.asarray(kappa, dtype=float)[..., None] * null
    return qdot, w


# -- simulation engine ----------------------------------------------------------------------


@dataclass
class _Problem:
    model: ArmModel
    scenario: JumpScenario
    floating: bool
    n: int
    N: int
    t: FloatArray
    x_nom: FloatArray  # (N+1, 3)
    xd_nom: FloatArray  # (N, 3) feed-forward per control step
    q0: FloatArray
    com0: FloatArray  # floating: system centre of mass at t=0 (inertial origin offset)
    lock_col: int

    def evaluate(self, q: FloatArray, rb: FloatArray | None) -> tuple[FloatArray, ...]:
        """x (B,3), J (B,3,n), dJ (B,n,3,n), base angular Jacobian (B,3,n) or None."""
        model = self.model
        if not self.floating:
            state = chain_state(model, q)
            lin = cross3(state.axes, state.ee_position[..., None, :] - state.positions)  # (B, n, 3)
            jac = np.swapaxes(lin, -1, -2)
            djac = linear_jacobian_derivatives(state.axes, jac)
            return state.ee_position, jac, djac, None
        state = chain_state(model, q)
        jg = generalized_jacobian(model, q, state=state)[..., :3, :]
        djg = generalized_jacobian_derivatives(model, q)[..., :3, :]
        jb = base_jacobian(model, q, state)[..., 3:, :]
        rel = state.ee_position - system_com(model, q, state)
        x = self.com0 + np.einsum("...ij,...j->...i", rb, rel)
        jac = rb @ jg
        djac = np.einsum("...ab,...ibk->...iak", rb, djg)
        return x, jac, djac, jb

    def position(self, q: FloatArray, rb: FloatArray | None) -> FloatArray:
        state = chain_state(self.model, q)
        if not self.floating:
            return state.ee_position
        rel = state.ee_position - system_com(self.model, q, state)
        return self.com0 + np.einsum("...ij,...j->...i", rb, rel)


def _problem(model: ArmModel, scenario: JumpScenario) -> _Problem:
    if not isinstance(scenario, JumpScenario):
        raise ScenarioError(f"scenario must be a JumpScenario; got {type(scenario).__name__}")
    if len(scenario.q0) != model.dof:
        default = scenario.q0 == JumpScenario().q0
        raise ScenarioError(
            f"q0 has {len(scenario.q0)} angles but model {model.name!r} has {model.dof} movable joints "
            f"{list(model.joint_numbers)}"
            + (
                " (q0 is the default task's, NOTES-001's start for canadarm7: give a JumpScenario with "
                f"q0 = {model.dof} angles [rad], or in a task file q0_deg [deg])"
                if default
                else ""
            )
        )
    floating = scenario.base == "floating"
    if floating and not model.floating:
        raise ModelError(
            f"base='floating' needs a free-floating model (load_robot(..., base='floating')); "
            f"model {model.name!r} has a fixed base"
        )
    if not floating:
        model = model.fixed()
    lock_col = model.index_of(scenario.lock_joint)
    q0 = np.asarray(scenario.q0, dtype=float)
    state = chain_state(model, q0)
    com0 = system_com(model, q0, state) if floating else np.zeros(3)
    x0 = state.ee_position
    t = scenario.times
    path = cartesian_trapezoid(x0, scenario.dx, t, duration=scenario.duration, blend=scenario.blend)
    if scenario.feedforward == "step":
        xd_ff = np.diff(path.x, axis=0) / scenario.dt
    else:
        xd_ff = path.xd[:-1]
    return _Problem(
        model, scenario, floating, model.dof, scenario.n_steps, t, path.x, xd_ff, q0, com0, lock_col
    )


@dataclass
class _RunOut:
    max_vel: FloatArray  # (B,) max |qdot| [rad/s]
    max_acc: FloatArray  # (B,) max |qddot| [rad/s^2] (failure steps excluded)
    max_dev: FloatArray  # (B,) max ||x - x_nom|| [m]
    min_w: FloatArray  # (B,)
    max_null: FloatArray  # (B,) max |(I - J+J) grad w|_inf at kappa = 1
    q: FloatArray | None = None  # (B, N+1, n)
    rb: FloatArray | None = None  # (B, N+1, 3, 3)
    qd: FloatArray | None = None  # (B, N, n)
    dev: FloatArray | None = None  # (B, N+1)
    x: FloatArray | None = None  # (B, N+1, 3)
    qd_plus: FloatArray | None = None  # (B, N, n) reduced law at the same state
    task_plus: FloatArray | None = None  # (B, N, 3) J (qd_plus - qd)
    task_noreplan: FloatArray | None = None  # (B, N, 3) -J_j qd_j


def _integrate(
    prob: _Problem,
    kappa: FloatArray,
    q_init: FloatArray,
    rb_init: FloatArray | None,
    k_start: np.ndarray,
    fail_steps: np.ndarray,
    fail_cols: Sequence[int],
    *,
    record: bool = False,
    jump_col: int | None = None,
    k_stop: int | None = None,
    null_norm: bool = False,
    progress: Any = None,
) -> _RunOut:
    """Integrate B runs together.  Runs must be sorted by ``k_start`` (ascending); run ``b``
    is idle before ``k_start[b]`` and then follows the law with the columns ``fail_cols[l]``
    locked from step ``fail_steps[b, l]`` on.  ``kappa`` is (B, N)."""
    sc = prob.scenario
    n, N, dt = prob.n, prob.N, sc.dt
    B = q_init.shape[0]
    k_stop = N if k_stop is None else min(int(k_stop), N)
    q = q_init.copy()
    rb = (
        None
        if not prob.floating
        else (np.broadcast_to(np.eye(3), (B, 3, 3)).copy() if rb_init is None else rb_init.copy())
    )
    qd_prev = np.zeros((B, n))
    max_vel = np.zeros(B)
    max_acc = np.zeros(B)
    max_dev = np.zeros(B)
    min_w = np.full(B, np.inf)
    max_null = np.zeros(B)
    fail_steps = np.asarray(fail_steps, dtype=int).reshape(B, -1)
    onehot = np.zeros((len(fail_cols), n), dtype=bool)
    for l, c in enumerate(fail_cols):
        onehot[l, c] = True
    out = _RunOut(max_vel, max_acc, max_dev, min_w, max_null)
    if record:
        out.q = np.repeat(q_init[:, None, :], N + 1, axis=1)
        out.qd = np.zeros((B, N, n))
        out.dev = np.zeros((B, N + 1))
        out.x = np.zeros((B, N + 1, 3))
        if prob.floating:
            out.rb = np.repeat(rb[:, None], N + 1, axis=1)
        if jump_col is not None:
            out.qd_plus = np.zeros((B, N, n))
            out.task_plus = np.zeros((B, N, 3))
            out.task_noreplan = np.zeros((B, N, 3))
    k0 = int(k_start.min()) if B else k_stop
    for k in range(k0, k_stop):
        m = int(np.searchsorted(k_start, k, side="right"))
        sl = slice(0, m)
        failed = fail_steps[sl] <= k  # (m, L)
        mask = ~np.any(failed[:, :, None] & onehot[None], axis=1)  # (m, n)
        changed = np.any(fail_steps[sl] == k, axis=1)
        rbm = None if rb is None else rb[sl]
        x, jac, djac, jb = prob.evaluate(q[sl], rbm)
        err = prob.x_nom[k] - x
        xdc = prob.xd_nom[k] + sc.kp * err
        qd, w = compensated_rates(jac, djac, xdc, kappa[sl, k], mask)
        dev = np.linalg.norm(err, axis=-1)
        max_dev[sl] = np.maximum(max_dev[sl], dev)
        max_vel[sl] = np.maximum(max_vel[sl], np.abs(qd).max(-1))
        min_w[sl] = np.minimum(min_w[sl], w)
        if null_norm:
            null, _ = compensated_rates(jac, djac, np.zeros(3), np.ones(m), mask)
            max_null[sl] = np.maximum(max_null[sl], np.abs(null).max(-1))
        acc = np.abs(qd - qd_prev[sl]).max(-1) / dt
        first = k_start[sl] == k
        check = ~first & ~changed
        if sc.rest_transitions:
            check |= first & (k == 0)
        max_acc[sl] = np.where(check, np.maximum(max_acc[sl], acc), max_acc[sl])
        if record:
            out.qd[sl, k] = qd
            out.dev[sl, k] = dev
            out.x[sl, k] = x
            if jump_col is not None:
                mask2 = mask.copy()
                mask2[:, jump_col] = False
                qd2, _ = compensated_rates(jac, djac, xdc, kappa[sl, k], mask2)
                out.qd_plus[sl, k] = qd2
                out.task_plus[sl, k] = np.einsum("...rc,...c->...r", jac, qd2 - qd)
                out.task_noreplan[sl, k] = -jac[..., jump_col] * qd[:, jump_col, None]
        qd_prev[sl] = qd
        q[sl] = q[sl] + dt * qd
        if rb is not None:
            omega = np.einsum("...ij,...j->...i", jb, qd) * dt
            angle = np.linalg.norm(omega, axis=-1)
            axis = omega / np.where(angle > 0, angle, 1.0)[:, None]
            rb[sl] = rb[sl] @ axis_angle_rotation(axis, angle)
        if record:
            out.q[sl, k + 1] = q[sl]
            if rb is not None:
                out.rb[sl, k + 1] = rb[sl]
        if progress is not None:
            progress.update()
    if k_stop == N and B:
        x_end = prob.position(q, rb)
        dev_end = np.linalg.norm(prob.x_nom[N] - x_end, axis=-1)
        max_dev[:] = np.maximum(max_dev, dev_end)
        if record:
            out.dev[:, N] = dev_end
            out.x[:, N] = x_end
        if sc.rest_transitions:
            max_acc[:] = np.maximum(max_acc, np.abs(qd_prev).max(-1) / dt)
    if np.any(min_w < SINGULAR_W):
        warnings.warn(
            f"{int(np.sum(min_w < SINGULAR_W))} of {B} runs passed within w < {SINGULAR_W:g} of a "
            "singular configuration; they are marked infeasible",
            SingularityWarning,
            stacklevel=3,
        )
    return out


def _kappa_rows(prob: _Problem, kappa: ArrayLike) -> FloatArray:
    """Constant kappa (K,) or schedules (K, N) -> (K, N)."""
    arr = np.asarray(kappa, dtype=float)
    if arr.ndim == 0:
        arr = arr[None]
    if arr.ndim == 1:
        return np.repeat(arr[:, None], prob.N, axis=1)
    if arr.ndim == 2 and arr.shape[1] == prob.N:
        return arr
    raise ScenarioError(
        f"kappa must be a number, (K,) values or (K, {prob.N}) schedules; got shape {arr.shape}"
    )


def _ok(prob: _Problem, out: _RunOut) -> np.ndarray:
    sc = prob.scenario
    slack = 1.0 + LIMIT_RTOL
    return (
        (out.max_vel <= sc.vmax * slack)
        & (out.max_acc <= sc.amax * slack)
        & (out.max_dev <= sc.eps * slack)
        & (out.min_w >= SINGULAR_W)
    )


# -- results --------------------------------------------------------------------------------


@dataclass(frozen=True)
class LimitReport:
    """Largest values reached against the scenario's limits (one run or a set of runs).

    Attributes
    ----------
    max_velocity, max_acceleration, max_deviation
        [rad/s], [rad/s^2] (failure steps excluded), [m].
    vmax, amax, eps
        The limits.
    ok
        All three kept (and no singular configuration met).
    """

    max_velocity: float
    max_acceleration: float
    max_deviation: float
    vmax: float
    amax: float
    eps: float
    ok: bool

    def broken(self) -> list[str]:
        """Human-readable list of the limits broken (degrees, millimetres)."""
        msgs = []
        slack = 1.0 + LIMIT_RTOL
        if self.max_velocity > self.vmax * slack:
            msgs.append(
                f"joint speed {math.degrees(self.max_velocity):.4g} deg/s > {math.degrees(self.vmax):.4g} deg/s"
            )
        if self.max_acceleration > self.amax * slack:
            msgs.append(
                f"joint acceleration {math.degrees(self.max_acceleration):.4g} deg/s^2 > "
                f"{math.degrees(self.amax):.4g} deg/s^2"
            )
        if self.max_deviation > self.eps * slack:
            msgs.append(f"position deviation {1e3 * self.max_deviation:.4g} mm > {1e3 * self.eps:.4g} mm")
        return msgs


def _limit_report(
    prob: _Problem, outs: Sequence[_RunOut], select: Sequence[np.ndarray | None]
) -> LimitReport:
    sc = prob.scenario
    vel = acc = dev = 0.0
    ok = True
    for o, sel in zip(outs, select):
        s = slice(None) if sel is None else sel
        vel = max(vel, float(np.max(o.max_vel[s], initial=0.0)))
        acc = max(acc, float(np.max(o.max_acc[s], initial=0.0)))
        dev = max(dev, float(np.max(o.max_dev[s], initial=0.0)))
        ok = ok and bool(np.all(_ok(prob, o)[s]))
    return LimitReport(vel, acc, dev, sc.vmax, sc.amax, sc.eps, ok)


@dataclass(frozen=True)
class Trajectory:
    """One simulated run (:func:`simulate`).

    Attributes
    ----------
    t
        (N + 1,) times [s].
    q
        (N + 1, n) joint angles [rad].
    qd
        (N, n) joint rates applied over ``[t_k, t_k + dt)`` [rad/s].
    x, x_nom
        (N + 1, 3) actual and nominal end-effector positions [m] (inertial frame).
    deviation
        (N + 1,) ``||x - x_nom||`` [m].
    healthy
        (N, n) boolean: joints movable at each step.
    kappa
        (N,) compensation coefficient used at each step.
    failures
        ``(joint number, time [s], step)`` of each lock.
    limits
        :class:`LimitReport` of the run.
    scenario
        The settings.
    """

    t: FloatArray
    q: FloatArray
    qd: FloatArray
    x: FloatArray
    x_nom: FloatArray
    deviation: FloatArray
    healthy: np.ndarray
    kappa: FloatArray
    failures: tuple[tuple[int, float, int], ...]
    limits: LimitReport
    scenario: JumpScenario


def simulate(
    model: ArmModel,
    scenario: JumpScenario | None = None,
    kappa: ArrayLike = 0.0,
    *,
    failures: Sequence[tuple[int, float]] = (),
) -> Trajectory:
    """Simulate the task with global compensation and locks injected at given times.

    Parameters
    ----------
    model
        The arm (full, all joints healthy at the start).
    scenario
        Task and limits; NOTES-001's default when omitted.
    kappa
        Constant coefficient, or (N,) schedule (one value per control step).
    failures
        ``(joint number, time [s])`` pairs; joints lock in sequence, each at the first
        control step at or after its time.  ``scenario.lock_joint`` is not used here.
    """
    sc = JumpScenario() if scenario is None else scenario
    prob = _problem(model, sc)
    krow = _kappa_rows(prob, np.asarray(kappa, dtype=float)[None] if np.ndim(kappa) == 1 else kappa)
    cols, steps, rec = [], [], []
    for number, t_fail in failures:
        c = prob.model.index_of(int(number))
        if c in cols:
            raise ScenarioError(f"failures: joint {number} is listed twice")
        k = int(sc.step_of(t_fail))
        cols.append(c)
        steps.append(k)
        rec.append((int(number), float(t_fail), k))
    if len(cols) >= prob.n:
        raise ScenarioError(f"failures: at least one of the {prob.n} joints must stay healthy")
    fail_steps = np.array([steps], dtype=int).reshape(1, -1) if steps else np.full((1, 1), prob.N + 1)
    fail_cols = cols if cols else [0]
    out = _integrate(
        prob, krow, prob.q0[None], None, np.zeros(1, dtype=int), fail_steps, fail_cols, record=True
    )
    healthy = np.ones((prob.N, prob.n), dtype=bool)
    for c, k in zip(cols, steps):
        healthy[k:, c] = False
    limits = _limit_report(prob, [out], [None])
    return Trajectory(
        prob.t,
        out.q[0],
        out.qd[0],
        out.x[0],
        prob.x_nom,
        out.dev[0],
        healthy,
        krow[0],
        tuple(rec),
        limits,
        sc,
    )


@dataclass(frozen=True)
class JumpTable:
    """Velocity jumps at every control step for K healthy runs (one per kappa row).

    Failure of ``scenario.lock_joint`` at step ``k`` (time ``t[k]``); arrays are (K, N, ...).

    Attributes
    ----------
    t
        (N,) failure times ``k dt`` [s].
    kappa
        (K, N) coefficient schedules.
    joint_jump
        (K, N, n) ``qdot(t_f+) - qdot(t_f-)`` with re-planning (reduced law, padded) [rad/s].
    joint_jump_norm
        (K, N) its 2-norm, the objective of NOTES-001 [rad/s].
    joint_jump_noreplan
        (K, N) without re-planning only the locked joint stops: ``|qdot_j(t_f-)|`` [rad/s].
    task_jump_noreplan
        (K, N) ``||J_j qdot_j(t_f-)||`` [m/s].
    task_jump_replan
        (K, N) ``||J (qdot+ - qdot-)||`` [m/s]; zero (round-off) while ``J_r`` has full row rank.
    healthy_limits_ok
        (K,) the healthy run keeps every limit over the whole task.
    q
        (K, N + 1, n) healthy joint trajectories [rad].
    scenario
        The settings.
    """

    t: FloatArray
    kappa: FloatArray
    joint_jump: FloatArray
    joint_jump_norm: FloatArray
    joint_jump_noreplan: FloatArray
    task_jump_noreplan: FloatArray
    task_jump_replan: FloatArray
    healthy_limits_ok: np.ndarray
    q: FloatArray
    scenario: JumpScenario


def _healthy_runs(
    prob: _Problem, krows: FloatArray, *, k_stop: int | None = None, progress: Any = None
) -> _RunOut:
    K = krows.shape[0]
    return _integrate(
        prob,
        krows,
        np.repeat(prob.q0[None], K, axis=0),
        None,
        np.zeros(K, dtype=int),
        np.full((K, 1), prob.N + 1),
        [prob.lock_col],
        record=True,
        jump_col=prob.lock_col,
        k_stop=k_stop,
        progress=progress,
    )


def jump_table(model: ArmModel, scenario: JumpScenario | None = None, kappa: ArrayLike = 0.0) -> JumpTable:
    """Velocity jumps for a failure at every control step, from one healthy run per kappa.

    Parameters
    ----------
    model
        The arm.
    scenario
        Task, lock joint and limits (NOTES-001 default when omitted).
    kappa
        Number, (K,) constants or (K, N) schedules.
    """
    sc = JumpScenario() if scenario is None else scenario
    prob = _problem(model, sc)
    krows = _kappa_rows(prob, kappa)
    out = _healthy_runs(prob, krows)
    return _table(prob, krows, out)


def _table(prob: _Problem, krows: FloatArray, out: _RunOut) -> JumpTable:
    jump = out.qd_plus - out.qd
    return JumpTable(
        prob.t[:-1],
        krows,
        jump,
        np.linalg.norm(jump, axis=-1),
        np.abs(out.qd[..., prob.lock_col]),
        np.linalg.norm(out.task_noreplan, axis=-1),
        np.linalg.norm(out.task_plus, axis=-1),
        _ok(prob, out),
        out.q,
        prob.scenario,
    )


def _post_runs(
    prob: _Problem,
    krows: FloatArray,
    healthy: _RunOut,
    kidx: np.ndarray,
    fsteps: np.ndarray,
    progress: Any = None,
) -> tuple[_RunOut, np.ndarray]:
    """Runs after a failure of the lock joint at ``fsteps`` (R,) with kappa rows ``kidx`` (R,),
    started from the healthy history.  Returns the outputs in sorted order and the order."""
    order = np.argsort(fsteps, kind="stable")
    ks, fs = kidx[order], fsteps[order]
    q_init = healthy.q[ks, fs]
    rb_init = None if healthy.rb is None else healthy.rb[ks, fs]
    out = _integrate(prob, krows[ks], q_init, rb_init, fs, fs[:, None], [prob.lock_col], progress=progress)
    return out, order


def _unsort(values: FloatArray, order: np.ndarray) -> FloatArray:
    res = np.empty_like(values)
    res[order] = values
    return res


@dataclass(frozen=True)
class KappaSearch:
    """Optimal kappa per failure time (:func:`search_kappa`).

    Attributes
    ----------
    fail_times
        (F,) failure times [s] (multiples of dt).
    fail_steps
        (F,) their control steps.
    kappa_grid
        (K,) grid values searched.
    objective
        (K, F) ``||dqdot||`` [rad/s] at each grid value and failure time.
    feasible
        (K, F) every limit kept by the healthy run and by the run with the failure.
    interval
        (F, 2) feasible kappa interval (contiguous feasible grid run containing the optimum;
        resolution = grid step); NaN when none.
    kappa_opt
        (F,) optimal kappa (grid + golden-section refinement); NaN when infeasible.
    objective_opt, objective_zero
        (F,) ``||dqdot||`` at ``kappa_opt`` and at kappa = 0 [rad/s].
    zero_feasible
        (F,) kappa = 0 keeps every limit.
    probe_range
        (2,) kappa range ``[a, b]`` of the grid (where the healthy run keeps the limits).
    null_max
        Largest ``|(I - J^+J) grad w|_inf`` along the uncompensated run [rad/s per unit kappa].
    scenario
        The settings.
    options
        Keyword arguments of :func:`search_kappa` that reproduce this grid (used by
        :func:`fit_kappa` to add failure times around a breakpoint of kappa(t)).
    """

    fail_times: FloatArray
    fail_steps: np.ndarray
    kappa_grid: FloatArray
    objective: FloatArray
    feasible: np.ndarray
    interval: FloatArray
    kappa_opt: FloatArray
    objective_opt: FloatArray
    objective_zero: FloatArray
    zero_feasible: np.ndarray
    probe_range: FloatArray
    null_max: float
    scenario: JumpScenario
    options: Mapping[str, Any] = field(default_factory=dict)

    @property
    def reduction(self) -> FloatArray:
        """(F,) relative jump reduction ``1 - obj_opt / obj_zero``; NaN (undefined) where
        ``obj_zero`` is 0 (no jump to reduce), see :func:`jump_reduction`."""
        return jump_reduction(self.objective_zero, self.objective_opt)


def jump_reduction(before: ArrayLike, after: ArrayLike) -> Any:
    """Relative jump reduction ``1 - after / before``.

    Undefined -- NaN, written ``null`` in JSON and ``n/a`` in text -- where ``before`` is 0:
    without compensation there is no jump to reduce (e.g. a task that does not move,
    ``dx_m = [0, 0, 0]``), and a ratio would be 0/0 or hide a jump the compensation made.
    A float for scalar inputs, an array otherwise; never warns or raises.
    """
    b = np.asarray(before, dtype=float)
    a = np.asarray(after, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        out = np.where(b != 0.0, 1.0 - a / np.where(b != 0.0, b, 1.0), np.nan)
    return float(out) if out.ndim == 0 else out


def sample_failure_times(scenario: JumpScenario, n: int) -> FloatArray:
    """``n`` failure times uniform over the task (001 §4.3: 40), on the control grid,
    strictly inside ``(0, T)``: ``t_i = round(i T/(n+1) / dt) dt``, i = 1..n (duplicates removed)."""
    if n < 1:
        raise ScenarioError(f"number of failure times must be >= 1; got {n}")
    N = scenario.n_steps
    steps = np.unique(np.clip(np.round(np.arange(1, n + 1) * N / (n + 1)).astype(int), 1, N - 1))
    return steps * scenario.dt


def _probe(prob: _Problem) -> float:
    """Largest ``|(I - J^+ J) grad w|_inf`` along the kappa = 0 run (sets the kappa scale)."""
    out = _integrate(
        prob,
        np.zeros((1, prob.N)),
        prob.q0[None],
        None,
        np.zeros(1, dtype=int),
        np.full((1, 1), prob.N + 1),
        [prob.lock_col],
        null_norm=True,
    )
    return max(float(out.max_null[0]), 1e-12)


def _contiguous(mask: np.ndarray, i: int) -> tuple[int, int]:
    lo = hi = i
    while lo > 0 and mask[lo - 1]:
        lo -= 1
    while hi < mask.size - 1 and mask[hi + 1]:
        hi += 1
    return lo, hi


def search_kappa(
    model: ArmModel,
    scenario: JumpScenario | None = None,
    fail_times: ArrayLike | None = None,
    *,
    n_samples: int = 40,
    kappa_range: tuple[float, float] | None = None,
    n_probe: int = 41,
    n_grid: int = 17,
    refine_iter: int = 3,
    n_starts: int = 2,
    progress: Any = None,
) -> KappaSearch:
    """Optimal kappa for each failure time under the limits (NOTES-001 "Optimal kappa").

    1. *Probe*: ``n_probe`` values over ``kappa_range`` (default ``+-2 vmax / s`` with ``s`` the
       largest ``|(I - J^+J) grad w|`` along the uncompensated run), healthy runs only: the
       interval ``[a, b]`` around 0 where the healthy run keeps every limit.
    2. *Grid*: ``n_grid`` values over ``[a, b]`` (0 included), one healthy run per value (which
       gives the jump at every failure time) and one post-failure run per (value, failure
       time) for the limits, all batched.  Feasible interval per failure time = contiguous
       feasible run of grid values around the best one (resolution = grid step).
    3. *Refinement*: safeguarded parabolic interpolation of ``||dqdot||^2`` (nearly quadratic:
       ``dqdot`` is affine in kappa at a fixed configuration, NOTES-001 property 5) in the
       bracket of the best grid value, all failure times at once; a refined value is kept only
       if it lowers the objective and keeps every limit.  The refinement starts from the
       ``n_starts`` best feasible *local* minima of the grid objective, not only the best grid
       value: the objective can have a narrow valley between two grid values (``halt7``: the
       optimum near +2e-4 lies between the grid values 0 and 4e-4 and is 6x lower than the
       best grid value, at the band edge; with one start the search jumped to that edge for
       ``t_f >= 8.5 s`` -- a spurious branch switch that the kappa(t) fit could not follow).

    Parameters
    ----------
    model
        The arm.
    scenario
        Task, lock joint, limits (NOTES-001 default when omitted).
    fail_times
        (F,) failure times [s]; default ``n_samples`` uniform times (:func:`sample_failure_times`).
    n_samples
        Number of failure times when ``fail_times`` is omitted (001: 40).
    kappa_range
        ``(lo, hi)`` probed in step 1.
    n_probe, n_grid
        Sizes of the probe and of the grid (>= 3).
    refine_iter
        Refinement iterations (0: grid only, as in 001).
    n_starts
        Local grid minima refined per failure time (1: only the best grid value, the
        behaviour before multi-start).
    progress
        Optional :class:`jointlock.progress.Progress`-like object (``update()`` per time step).
    """
    sc = JumpScenario() if scenario is None else scenario
    prob = _problem(model, sc)
    times = (
        sample_failure_times(sc, n_samples)
        if fail_times is None
        else np.atleast_1d(np.asarray(fail_times, float))
    )
    fsteps = sc.step_of(times)
    times = fsteps * sc.dt
    F = fsteps.size
    if n_grid < 3 or n_probe < 3:
        raise ScenarioError(f"n_grid and n_probe must be >= 3; got {n_grid}, {n_probe}")
    null_max = _probe(prob)
    if kappa_range is None:
        rng_ = np.array([-2.0, 2.0]) * sc.vmax / null_max
    else:
        rng_ = np.asarray(kappa_range, dtype=float)
    if rng_.shape != (2,) or not np.all(np.isfinite(rng_)) or rng_[0] >= rng_[1]:
        raise ScenarioError(f"kappa_range must be (lo, hi) with lo < hi; got {kappa_range!r}")
    probe = np.unique(np.concatenate([np.linspace(rng_[0], rng_[1], n_probe), [0.0]]))
    ph = _healthy_runs(prob, _kappa_rows(prob, probe))
    pok = _ok(prob, ph)
    i0 = int(np.flatnonzero(probe == 0.0)[0])
    if pok[i0]:
        lo, hi = _contiguous(pok, i0)
        # the true edges lie between the last feasible and first infeasible probe values
        a = probe[max(lo - 1, 0)] if lo > 0 else probe[0]
        b = probe[min(hi + 1, probe.size - 1)] if hi < probe.size - 1 else probe[-1]
        a = 0.5 * (a + probe[lo]) if lo > 0 else a
        b = 0.5 * (b + probe[hi]) if hi < probe.size - 1 else b
    elif pok.any():
        best = int(np.flatnonzero(pok)[np.argmin(np.abs(probe[pok]))])
        lo, hi = _contiguous(pok, best)
        a, b = probe[lo], probe[hi]
    else:
        a = b = 0.0
    grid = np.unique(np.concatenate([np.linspace(a, b, n_grid), [0.0]])) if b > a else np.array([0.0])
    K = grid.size
    krows = _kappa_rows(prob, grid)
    healthy = _healthy_runs(prob, krows, progress=progress)
    table = _table(prob, krows, healthy)
    objective = table.joint_jump_norm[:, fsteps]  # (K, F)
    kidx = np.repeat(np.arange(K), F)
    fidx = np.tile(fsteps, K)
    post, order = _post_runs(prob, krows, healthy, kidx, fidx, progress=progress)
    post_ok = _unsort(_ok(prob, post), order).reshape(K, F)
    feasible = post_ok & table.healthy_limits_ok[:, None]
    g0 = int(np.flatnonzero(grid == 0.0)[0])
    zero_feasible = feasible[g0].copy()
    objective_zero = objective[g0].copy()

    interval = np.full((F, 2), np.nan)
    kappa_opt = np.full(F, np.nan)
    obj_opt = np.full(F, np.nan)
    # refinement starts: up to n_starts feasible local minima of the grid objective per time
    s_f, s_lo, s_x, s_hi, s_fx, s_run = [], [], [], [], [], []
    for f in range(F):  # reads off contiguous feasible runs; no simulation in this loop
        feas = feasible[:, f]
        if not feas.any():
            continue
        obj_f = np.where(feas, objective[:, f], np.inf)
        best = int(np.argmin(obj_f))
        lo, hi = _contiguous(feas, best)
        interval[f] = grid[lo], grid[hi]
        kappa_opt[f] = grid[best]
        obj_opt[f] = objective[best, f]
        left = np.concatenate([[np.inf], obj_f[:-1]])
        right = np.concatenate([obj_f[1:], [np.inf]])
        minima = np.flatnonzero(feas & (obj_f <= left) & (obj_f <= right))
        minima = minima[np.argsort(obj_f[minima], kind="stable")][: max(int(n_starts), 1)]
        if best not in minima:
            minima = np.concatenate([[best], minima[:-1]])
        for i in minima:
            rlo, rhi = _contiguous(feas, int(i))
            s_f.append(f)
            s_lo.append(grid[max(i - 1, rlo)])
            s_x.append(grid[i])
            s_hi.append(grid[min(i + 1, rhi)])
            s_fx.append(objective[i, f])
            s_run.append((grid[rlo], grid[rhi]))

    if refine_iter > 0 and s_f and K > 1:
        sf = np.asarray(s_f)
        cand, fcand = _refine(
            prob,
            fsteps[sf],
            np.asarray(s_lo),
            np.asarray(s_x),
            np.asarray(s_hi),
            np.asarray(s_fx),
            refine_iter,
        )
        better = fcand < obj_opt[sf]
        if better.any():
            rows = np.flatnonzero(better)
            krows_c = _kappa_rows(prob, cand[rows])
            h = _healthy_runs(prob, krows_c)
            p, order_c = _post_runs(prob, krows_c, h, np.arange(rows.size), fsteps[sf[rows]])
            ok = _unsort(_ok(prob, p), order_c) & _ok(prob, h)
            for r in rows[ok][np.argsort(-fcand[rows[ok]], kind="stable")]:  # best written last
                f = sf[r]
                if fcand[r] < obj_opt[f]:
                    kappa_opt[f] = cand[r]
                    obj_opt[f] = fcand[r]
                    interval[f] = s_run[r]
    return KappaSearch(
        times,
        fsteps,
        grid,
        objective,
        feasible,
        interval,
        kappa_opt,
        obj_opt,
        objective_zero,
        zero_feasible,
        np.array([a, b]),
        null_max,
        sc,
        {
            "kappa_range": None if kappa_range is None else tuple(float(v) for v in kappa_range),
            "n_probe": n_probe,
            "n_grid": n_grid,
            "refine_iter": refine_iter,
            "n_starts": n_starts,
        },
    )


def merge_searches(a: KappaSearch, b: KappaSearch) -> KappaSearch:
    """The samples of two searches on the same grid, sorted by failure time (``a`` wins on
    duplicates).  Raises :class:`~jointlock.errors.ScenarioError` if the grids differ."""
    if a.scenario != b.scenario or not np.array_equal(a.kappa_grid, b.kappa_grid):
        raise ScenarioError("merge_searches: the searches must share scenario and kappa grid")
    steps = np.concatenate([a.fail_steps, b.fail_steps])
    _, first = np.unique(steps, return_index=True)  # first occurrence: a before b
    idx = first[np.argsort(steps[first], kind="stable")]

    def cat(x: np.ndarray, y: np.ndarray, axis: int = 0) -> np.ndarray:
        return np.take(np.concatenate([x, y], axis=axis), idx, axis=axis)

    return KappaSearch(
        cat(a.fail_times, b.fail_times),
        cat(a.fail_steps, b.fail_steps),
        a.kappa_grid,
        cat(a.objective, b.objective, 1),
        cat(a.feasible, b.feasible, 1),
        cat(a.interval, b.interval),
        cat(a.kappa_opt, b.kappa_opt),
        cat(a.objective_opt, b.objective_opt),
        cat(a.objective_zero, b.objective_zero),
        cat(a.zero_feasible, b.zero_feasible),
        a.probe_range,
        a.null_max,
        a.scenario,
        a.options,
    )


def _refine(
    prob: _Problem,
    fsteps: np.ndarray,
    a: FloatArray,
    x: FloatArray,
    b: FloatArray,
    fx: FloatArray,
    iters: int,
) -> tuple[FloatArray, FloatArray]:
    """Safeguarded parabolic minimisation of ``||dqdot||^2`` in ``[a, b]`` (one per failure
    time, all batched); ``x`` is the best known point with value ``fx``."""
    k_stop = int(fsteps.max()) + 1
    rows = np.arange(fsteps.size)

    def obj(kap: FloatArray) -> FloatArray:
        out = _healthy_runs(prob, _kappa_rows(prob, kap), k_stop=k_stop)
        return np.linalg.norm(out.qd_plus - out.qd, axis=-1)[rows, fsteps]

    a, b, x, fx = a.copy(), b.copy(), x.copy(), fx.copy()
    fa = obj(a)
    fb = obj(b)
    for _ in range(iters):
        ya, yx, yb = fa**2, fx**2, fb**2
        num = (x - a) ** 2 * (yx - yb) - (x - b) ** 2 * (yx - ya)
        den = (x - a) * (yx - yb) - (x - b) * (yx - ya)
        with np.errstate(divide="ignore", invalid="ignore"):
            u = x - 0.5 * num / den
        width = b - a
        golden = np.where(b - x > x - a, x + (1 - _GOLDEN) * (b - x), x - (1 - _GOLDEN) * (x - a))
        bad = ~np.isfinite(u) | (u <= a) | (u >= b) | (np.abs(u - x) < 1e-3 * np.maximum(width, 1e-300))
        u = np.where(bad, golden, u)
        fu = obj(u)
        win = fu < fx
        right = u > x
        # bracket update (golden-section style)
        a_new = np.where(win, np.where(right, x, a), np.where(right, a, u))
        b_new = np.where(win, np.where(right, b, x), np.where(right, u, b))
        fa_new = np.where(win, np.where(right, fx, fa), np.where(right, fa, fu))
        fb_new = np.where(win, np.where(right, fb, fx), np.where(right, fu, fb))
        x = np.where(win, u, x)
        fx = np.where(win, fu, fx)
        a, b, fa, fb = a_new, b_new, fa_new, fb_new
    return x, fx


# -- kappa(t) -------------------------------------------------------------------------------


@dataclass(frozen=True)
class KappaPiece:
    """One polynomial piece of a piecewise kappa(t).

    ``kappa(t) = p((t - center) / half_width)`` for ``start <= t < end`` (coefficients
    ascending; the local variable keeps high orders on short pieces well conditioned).

    Attributes
    ----------
    start, end
        Time span where the piece applies [s] (kappa = 0 in gaps between pieces).
    order
        Polynomial order (raised from the requested one until the criterion holds).
    coefficients
        (order + 1,) ascending powers of the local variable.
    center, half_width
        Normalisation of the local variable [s].
    ssr, threshold, accepted
        Residual over the samples used, its threshold and ``ssr <= threshold``.
    n_samples
        Samples the piece was fitted to.
    source
        ``"fit"`` (fitted to its own segment's samples) or ``"continued"`` (its polynomial
        was carried over the next segment(s), where it beat that segment's own fit).
    """

    start: float
    end: float
    order: int
    coefficients: FloatArray
    center: float
    half_width: float
    ssr: float
    threshold: float
    accepted: bool
    n_samples: int
    source: str = "fit"

    def polynomial(self, t: ArrayLike) -> FloatArray:
        """The piece's polynomial at ``t`` [s] (no span check)."""
        u = (np.asarray(t, dtype=float) - self.center) / self.half_width
        return np.polynomial.polynomial.polyval(u, self.coefficients)


@dataclass(frozen=True)
class KappaFit:
    """Fitted kappa(t) and its piecewise form (001 §3.3, §4.3; NOTES-001 "Unknown failure time").

    ``kappa(t)`` is the sum of :attr:`pieces`, each a polynomial on its span, and 0 outside
    every piece.  With one segment this is 001's form: ``p(t)`` between the two segment
    points, 0 near the start and the end.

    Attributes
    ----------
    order
        Highest polynomial order among the pieces (the single polynomial's order when
        ``piecewise=False`` or when no piece is kept).
    coefficients
        (order + 1,) the *single* least-squares polynomial in ``tau = t/T`` over every
        feasible sample (001's form; kept for comparison, see :meth:`polynomial`).
    ssr
        Sum of squared residuals over the samples used [kappa^2] (sum over the pieces).
    threshold
        Acceptance threshold on ``ssr`` (001's criterion; sum over the pieces).
    accepted
        Every piece meets its criterion at ``order <= max_order``.
    segment_points
        (2,) ``t1, t2`` [s]: start of the first and end of the last piece (NaN, NaN when
        compensation never helps: kappa(t) = 0).
    used
        (F,) samples used by the pieces' fits.
    objective_fit, objective_zero
        (F,) ``||dqdot||`` at the samples with the fitted schedule (history included: the
        healthy run with kappa(t) up to the failure) and with kappa = 0 [rad/s].  With
        ``piecewise=False``: with the constant kappa = p(t_i), as before.
    duration
        ``T`` [s].
    pieces
        The :class:`KappaPiece` list, in time order (empty: kappa(t) = 0, or the single form).
    breaks
        Times [s] where the sampled optimum jumps (segment boundaries).
    search
        The search with the failure times added around the breaks (``None``: none added).
    segments
        One entry per segment of the samples: ``(start, end, decision)`` with decision
        ``"fit"``, ``"continued"`` or ``"zero"``.
    """

    order: int
    coefficients: FloatArray
    ssr: float
    threshold: float
    accepted: bool
    segment_points: FloatArray
    used: np.ndarray
    objective_fit: FloatArray
    objective_zero: FloatArray
    duration: float
    pieces: tuple[KappaPiece, ...] | None = None
    breaks: FloatArray = field(default_factory=lambda: np.zeros(0))
    search: KappaSearch | None = None
    segments: tuple[tuple[float, float, str], ...] = ()

    def polynomial(self, t: ArrayLike) -> FloatArray:
        """The single polynomial ``p(t/T)`` (001's form), without segments or pieces."""
        return np.polynomial.polynomial.polyval(np.asarray(t, dtype=float) / self.duration, self.coefficients)

    def __call__(self, t: ArrayLike) -> FloatArray:
        """Piecewise kappa(t): each piece on its span, 0 elsewhere."""
        t = np.asarray(t, dtype=float)
        if self.pieces is None:  # single form (piecewise=False)
            t1, t2 = self.segment_points
            if not np.isfinite(t1):
                return np.zeros_like(t)
            return np.where((t >= t1) & (t <= t2), self.polynomial(t), 0.0)
        return _eval_pieces(self.pieces, t, self.duration)


def _eval_pieces(pieces: Sequence[KappaPiece], t: FloatArray, duration: float) -> FloatArray:
    out = np.zeros_like(np.asarray(t, dtype=float))
    for pc in pieces:
        inside = (t >= pc.start) & ((t < pc.end) | ((pc.end >= duration) & (t <= pc.end)))
        out = np.where(inside, pc.polynomial(t), out)
    return out


def _polyfit(t: FloatArray, k: FloatArray, order: int, max_order: int, threshold: float | None, rtol: float):
    spread = float(np.sum((k - k.mean()) ** 2))
    thr = threshold if threshold is not None else rtol * max(spread, 1e-300)
    order = min(order, t.size - 1)
    while True:
        coef = np.polynomial.polynomial.polyfit(t, k, order)
        ssr = float(np.sum((np.polynomial.polynomial.polyval(t, coef) - k) ** 2))
        if ssr <= thr or order >= min(max_order, t.size - 1):
            return order, coef, ssr, thr, ssr <= thr
        order += 1


def _crossings(t: FloatArray, d: FloatArray, usable: np.ndarray, duration: float) -> FloatArray:
    """Segment points from d_i = obj(p(t_i)) - obj(0): first/last zero crossing into d < 0."""
    good = np.flatnonzero((d < 0) & usable)
    if good.size == 0:
        return np.array([np.nan, np.nan])
    i1, i2 = good[0], good[-1]
    if i1 == 0:
        t1 = 0.0
    else:
        a, b = d[i1 - 1], d[i1]
        t1 = t[i1 - 1] + (t[i1] - t[i1 - 1]) * (a / (a - b)) if np.isfinite(a) and a > 0 else t[i1]
    if i2 == t.size - 1:
        t2 = duration
    else:
        a, b = d[i2], d[i2 + 1]
        t2 = t[i2] + (t[i2 + 1] - t[i2]) * (a / (a - b)) if np.isfinite(b) and b > 0 else t[i2]
    return np.array([t1, t2])


def find_breaks(
    kappa: ArrayLike, width: float, *, jump_rtol: float = 0.1, jump_factor: float = 10.0
) -> np.ndarray:
    """Indices ``i`` such that samples ``i`` and ``i + 1`` lie on different branches.

    A jump between consecutive samples is a break when ``|kappa_{i+1} - kappa_i|`` exceeds
    both ``jump_rtol * width`` (``width``: the searched kappa range, e.g. the feasible band)
    and ``jump_factor`` times the median step between consecutive samples (what a smooth
    kappa(t) moves from one sample to the next).
    """
    k = np.asarray(kappa, dtype=float)
    if k.size < 2:
        return np.zeros(0, dtype=int)
    d = np.abs(np.diff(k))
    return np.flatnonzero((d > jump_rtol * width) & (d > jump_factor * np.median(d)))


def fit_pieces(
    t: ArrayLike,
    kappa: ArrayLike,
    cuts: ArrayLike = (),
    *,
    order: int = 5,
    max_order: int = 9,
    threshold: float | None = None,
    rtol: float = 0.1,
    span: tuple[float, float] | None = None,
) -> list[KappaPiece]:
    """Least-squares polynomial per segment of samples ``(t_i, kappa_i)`` (sorted by ``t``).

    ``cuts`` are sample indices ``i`` after which a new segment starts (e.g. from
    :func:`find_breaks`).  Each segment is fitted on its own (order raised from ``order`` up to
    ``max_order`` -- and at most samples - 1 -- until ``SSR <= threshold``, default
    ``rtol`` times the segment's spread ``sum (kappa_i - mean)^2``).  Adjacent pieces meet
    half-way between the last sample of one segment and the first of the next; the first
    starts at ``span[0]`` and the last ends at ``span[1]`` (default: the first / last sample).
    """
    t = np.asarray(t, dtype=float)
    k = np.asarray(kappa, dtype=float)
    if t.size == 0:
        return []
    lo, hi = (float(t[0]), float(t[-1])) if span is None else (float(span[0]), float(span[1]))
    bounds = [0] + [int(c) + 1 for c in np.unique(np.asarray(cuts, dtype=int))] + [t.size]
    pieces = []
    for s in range(len(bounds) - 1):
        ts, ks = t[bounds[s] : bounds[s + 1]], k[bounds[s] : bounds[s + 1]]
        start = lo if s == 0 else 0.5 * (t[bounds[s] - 1] + ts[0])
        end = hi if s == len(bounds) - 2 else 0.5 * (ts[-1] + t[bounds[s + 1]])
        center = 0.5 * (ts[0] + ts[-1])
        half = max(0.5 * (ts[-1] - ts[0]), 1e-9)
        ordr, coef, ssr, thr, acc = _polyfit((ts - center) / half, ks, order, max_order, threshold, rtol)
        pieces.append(
            KappaPiece(
                float(start), float(end), int(ordr), coef, center, half, ssr, float(thr), bool(acc), ts.size
            )
        )
    return pieces


def _feasible_samples(search: KappaSearch) -> np.ndarray:
    """Mask of the failure times with a feasible kappa; raise when fewer than two (no fit)."""
    finite = np.isfinite(search.kappa_opt)
    if finite.sum() < 2:
        raise InfeasibleError(
            f"fit_kappa: only {int(finite.sum())} failure time(s) have a feasible kappa; need >= 2 to fit kappa(t)"
        )
    return finite


def fit_kappa(
    model: ArmModel,
    search: KappaSearch,
    *,
    order: int = 5,
    max_order: int = 9,
    threshold: float | None = None,
    rtol: float = 0.1,
    piecewise: bool = True,
    jump_rtol: float = 0.1,
    jump_factor: float = 10.0,
    refine_breaks: bool = True,
    max_refine: int = 7,
    refine_rounds: int = 2,
) -> KappaFit:
    """Fit kappa(t) to the optimal kappa per failure time (001 §3.3 and §4.3), piecewise.

    The sampled optimum need not be smooth: it can switch branch from one failure time to the
    next (another local minimum of ``||dqdot||(kappa)`` wins, or the feasible band cuts one
    off).  One polynomial cannot follow such a step and ends up far from both branches (on
    ``halt7`` with the single-start search it made the jumps 4.5x larger).  So:

    1. *Breaks*: consecutive samples whose optimum jumps (:func:`find_breaks`: more than
       ``jump_rtol`` of the searched kappa range and ``jump_factor`` times the median step).
    2. *Refinement*: new failure times are searched between the two samples of each break
       (up to ``max_refine`` control steps, evenly spaced; ``refine_rounds`` rounds), so the
       break is located to a control step where the samples allow (001: "add samples").
    3. *Pieces*: one least-squares polynomial per segment between breaks (:func:`fit_pieces`;
       order from ``order`` raised to ``max_order`` until ``SSR <= threshold``, 001's
       criterion, per segment).
    4. *Decisions*, segment by segment in time order, each judged by the jumps at the
       segment's sampled failure times in the **healthy run with the schedule decided so far**
       (the jump at ``t_f`` depends on kappa over ``[0, t_f]``, not only on ``kappa(t_f)``; an
       optimum sampled with a constant kappa since ``t = 0`` can be useless after a different
       history): the segment's own piece; the previous piece continued (when a piece
       precedes); or kappa = 0.  The lowest mean jump wins; so kappa falls back to 0 on a
       segment where the fit does not beat kappa = 0.  A kept own piece is then trimmed to
       001's segment points: where ``d_i = ||dqdot||(fit) - ||dqdot||(kappa = 0)`` crosses
       zero, first/last crossing into ``d < 0`` (linear interpolation; samples whose fitted
       kappa lies outside their feasible interval do not count), refitted on the samples
       inside (001 drops the erratic end samples) and kept if that lowers the mean jump.

    Without breaks, this is 001's single polynomial with segment points (same result as
    ``piecewise=False`` up to the history-consistent comparison).  The verification
    (:func:`verify_kappa`) then injects the failure at *every* control step, including the
    steps between samples, which the decisions never looked at.

    Parameters
    ----------
    model
        The arm of the search.
    search
        Result of :func:`search_kappa`.
    order, max_order
        Starting and largest polynomial order (001: 5).
    threshold
        Absolute SSR threshold (per piece); ``None`` uses ``rtol``.
    rtol
        Relative threshold (fraction of the samples' spread, per piece).
    piecewise
        ``False``: the single polynomial of 001 with its two segment points (no breaks,
        decisions with constant-kappa runs), the behaviour before piecewise fitting.
    jump_rtol, jump_factor
        Break detection (:func:`find_breaks`).
    refine_breaks, max_refine, refine_rounds
        Sample refinement around the breaks (needs ``search.options``).
    """
    if not piecewise:
        return _fit_single(model, search, order=order, max_order=max_order, threshold=threshold, rtol=rtol)
    sc = search.scenario
    prob = _problem(model, sc)
    finite = _feasible_samples(search)
    width = float(search.probe_range[1] - search.probe_range[0]) or 1.0
    single = _polyfit(
        search.fail_times[finite] / sc.duration, search.kappa_opt[finite], order, max_order, threshold, rtol
    )

    def breaks_of(s: KappaSearch) -> tuple[np.ndarray, np.ndarray]:
        fin = np.flatnonzero(np.isfinite(s.kappa_opt))
        return fin, find_breaks(s.kappa_opt[fin], width, jump_rtol=jump_rtol, jump_factor=jump_factor)

    merged = search
    added = False
    fin, cuts = breaks_of(merged)
    for _ in range(refine_rounds if refine_breaks else 0):
        extra = []
        for c in cuts:
            k_a, k_b = merged.fail_steps[fin[c]], merged.fail_steps[fin[c + 1]]
            if k_b - k_a > 1:
                extra.append(
                    np.unique(np.round(np.linspace(k_a, k_b, min(k_b - k_a - 1, max_refine) + 2)[1:-1]))
                )
        if not extra:
            break
        more = search_kappa(model, sc, np.concatenate(extra) * sc.dt, **dict(merged.options))
        if not np.array_equal(more.kappa_grid, merged.kappa_grid):  # options not reproducible
            log.warning("fit_kappa: refined search used another grid; breaks not refined")
            break
        merged = merge_searches(merged, more)
        added = True
        fin, cuts = breaks_of(merged)
    t_all = merged.fail_times
    t_s, k_s = t_all[fin], merged.kappa_opt[fin]
    pieces = fit_pieces(
        t_s,
        k_s,
        cuts,
        order=order,
        max_order=max_order,
        threshold=threshold,
        rtol=rtol,
        span=(0.0, sc.duration),
    )
    steps = prob.t[:-1]
    seg_of = np.searchsorted([pc.start for pc in pieces[1:]], t_all, side="right")  # segment of every sample
    feasible_in = np.all(np.isfinite(merged.interval), axis=1)

    def jumps(schedules: list[FloatArray], k_stop: int) -> FloatArray:
        out = _healthy_runs(prob, np.stack(schedules), k_stop=k_stop)
        return np.linalg.norm(out.qd_plus - out.qd, axis=-1)[:, merged.fail_steps]

    kap = np.zeros(prob.N)
    kept: list[KappaPiece] = []
    decisions = []
    used = np.zeros(t_all.size, dtype=bool)
    for s, pc in enumerate(pieces):
        on = (steps >= pc.start) & ((steps < pc.end) | (s == len(pieces) - 1))
        here = (seg_of == s) & feasible_in
        k_stop = int(merged.fail_steps[seg_of == s].max()) + 1
        names = ["fit", "zero"]
        cands = [np.where(on, pc.polynomial(steps), kap), np.where(on, 0.0, kap)]
        if kept and kept[-1].end >= pc.start - 1e-12:  # the previous segment kept its piece
            names.append("continued")
            cands.append(np.where(on, kept[-1].polynomial(steps), kap))
        jm = jumps(cands, k_stop)
        best_piece = pc
        # 001's segment points inside the piece: trim where the fit does not beat kappa = 0
        d = jm[0] - jm[1]
        pk = pc.polynomial(t_all)
        inside = (pk >= merged.interval[:, 0] - 1e-15) & (pk <= merged.interval[:, 1] + 1e-15)
        idx = np.flatnonzero(seg_of == s)
        seg = _crossings(t_all[idx], d[idx], inside[idx] & feasible_in[idx], sc.duration)
        trimmed = None
        if np.isfinite(seg[0]):
            a_, b_ = (
                (pc.start if seg[0] <= t_all[idx[0]] else seg[0]),
                (pc.end if seg[1] >= t_all[idx[-1]] else seg[1]),
            )
            if (a_, b_) != (pc.start, pc.end):
                use = idx[np.isfinite(merged.kappa_opt[idx]) & (t_all[idx] >= a_) & (t_all[idx] <= b_)]
                if use.size >= 1:
                    trimmed = fit_pieces(
                        t_all[use],
                        merged.kappa_opt[use],
                        order=order,
                        max_order=max_order,
                        threshold=threshold,
                        rtol=rtol,
                        span=(a_, b_),
                    )[0]
                    on_t = (steps >= a_) & ((steps < b_) | (b_ >= sc.duration))
                    jt = jumps([np.where(on, np.where(on_t, trimmed.polynomial(steps), 0.0), kap)], k_stop)
                    names.append("trimmed")
                    cands.append(np.where(on, np.where(on_t, trimmed.polynomial(steps), 0.0), kap))
                    jm = np.concatenate([jm, jt])
        score = jm[:, here].mean(axis=1) if here.any() else jm[:, idx].mean(axis=1)
        # ties go to the simpler choice: zero before fit/continued
        pref = [1, 0] + list(range(2, len(names)))
        win = min(pref, key=lambda i: (score[i], pref.index(i)))
        choice = names[win]
        kap = cands[win]
        if choice == "fit":
            kept.append(best_piece)
            used[idx[np.isfinite(merged.kappa_opt[idx])]] = True
        elif choice == "trimmed":
            kept.append(trimmed)
            used[
                idx[
                    np.isfinite(merged.kappa_opt[idx])
                    & (t_all[idx] >= trimmed.start)
                    & (t_all[idx] <= trimmed.end)
                ]
            ] = True
            choice = "fit"
        elif choice == "continued":
            kept[-1] = dataclasses.replace(kept[-1], end=pc.end, source="continued")
        decisions.append((float(pc.start), float(pc.end), choice))
    obj_fit = jumps([kap], int(merged.fail_steps.max()) + 1)[0]
    seg_pts = np.array([kept[0].start, kept[-1].end]) if kept else np.array([np.nan, np.nan])
    if kept:
        ordr = max(pc.order for pc in kept)
        ssr = float(sum(pc.ssr for pc in kept))
        thr = float(sum(pc.threshold for pc in kept))
        acc = all(pc.accepted for pc in kept)
    else:
        ordr, ssr, thr, acc = int(single[0]), float(single[2]), float(single[3]), bool(single[4])
    break_times = 0.5 * (t_s[cuts] + t_s[cuts + 1]) if cuts.size else np.zeros(0)
    return KappaFit(
        int(ordr),
        single[1],
        ssr,
        thr,
        bool(acc),
        seg_pts,
        used,
        obj_fit,
        merged.objective_zero,
        sc.duration,
        tuple(kept),
        break_times,
        merged if added else None,
        tuple(decisions),
    )


def _fit_single(
    model: ArmModel,
    search: KappaSearch,
    *,
    order: int = 5,
    max_order: int = 9,
    threshold: float | None = None,
    rtol: float = 0.1,
) -> KappaFit:
    """001's single polynomial with two segment points (``fit_kappa(..., piecewise=False)``)."""
    sc = search.scenario
    prob = _problem(model, sc)
    t = search.fail_times
    finite = _feasible_samples(search)
    tau = t / sc.duration
    used = finite.copy()
    res = None
    for _ in range(2):
        ordr, coef, ssr, thr, acc = _polyfit(
            tau[used], search.kappa_opt[used], order, max_order, threshold, rtol
        )
        pk = np.polynomial.polynomial.polyval(tau, coef)
        table = _healthy_runs(prob, _kappa_rows(prob, pk), k_stop=int(search.fail_steps.max()) + 1)
        obj_fit = np.linalg.norm(table.qd_plus - table.qd, axis=-1)[np.arange(t.size), search.fail_steps]
        d = obj_fit - search.objective_zero
        inside = (pk >= search.interval[:, 0] - 1e-15) & (pk <= search.interval[:, 1] + 1e-15)
        seg = _crossings(t, d, inside, sc.duration)
        res = (ordr, coef, ssr, thr, acc, seg, used.copy(), obj_fit)
        if not np.isfinite(seg[0]):
            break
        new_used = finite & (t >= seg[0]) & (t <= seg[1])
        if new_used.sum() < 2 or np.array_equal(new_used, used):
            break
        used = new_used
    ordr, coef, ssr, thr, acc, seg, used, obj_fit = res
    return KappaFit(
        int(ordr), coef, ssr, float(thr), bool(acc), seg, used, obj_fit, search.objective_zero, sc.duration
    )


# -- verification ---------------------------------------------------------------------------


@dataclass(frozen=True)
class Verification:
    """kappa(t) checked with the failure injected at every control step (001 §4.4).

    Attributes
    ----------
    t
        (N,) failure times ``k dt`` [s].
    kappa
        (N,) the schedule used (after the fix, if any).
    jump_before, jump_after
        (N,) ``||dqdot||`` [rad/s] without (kappa = 0) and with the schedule.
    task_jump_noreplan_before, task_jump_noreplan_after
        (N,) ``||J_j qdot_j||`` [m/s], what the end effector would see without re-planning.
    task_jump_replan_max
        Largest ``||J dqdot||`` with re-planning [m/s] (round-off when ``J_r`` keeps full rank).
    mean_reduction
        ``1 - mean(after) / mean(before)``; NaN (undefined) when every ``before`` is 0
        (:func:`jump_reduction`).
    share_improved
        Fraction of failure steps with ``after < before``.
    limits
        Limits over the no-failure run and every run with a failure, with the schedule.
    healthy_ok
        The run without failure keeps every limit.
    limits_ok_per_step
        (N,) the motion with the failure at step k (healthy before, locked after) keeps
        every limit.
    broken_steps
        Failure times [s] at which a limit breaks.
    sampled_limits_ok
        Every sampled optimal kappa kept every limit (so a break is due to the fitted function).
    fix
        ``None``, ``"clip"`` (to the feasible band), ``"ramp"`` (rate-limited kappa) or
        ``"clip+ramp"``.
    scenario
        The settings.
    """

    t: FloatArray
    kappa: FloatArray
    jump_before: FloatArray
    jump_after: FloatArray
    task_jump_noreplan_before: FloatArray
    task_jump_noreplan_after: FloatArray
    task_jump_replan_max: float
    mean_reduction: float
    share_improved: float
    limits: LimitReport
    healthy_ok: bool
    limits_ok_per_step: np.ndarray
    broken_steps: FloatArray
    sampled_limits_ok: bool
    fix: str | None
    scenario: JumpScenario

    @property
    def limits_ok(self) -> bool:
        """Every limit kept, with or without a failure at any step."""
        return bool(self.healthy_ok and np.all(self.limits_ok_per_step))


def feasible_band(search: KappaSearch, t: ArrayLike) -> FloatArray:
    """(..., 2) feasible kappa interval interpolated linearly between the sampled failure
    times (held constant outside them); samples without a feasible kappa are skipped."""
    ok = np.all(np.isfinite(search.interval), axis=1)
    if not ok.any():
        raise InfeasibleError("feasible_band: no sampled failure time has a feasible kappa")
    ts = search.fail_times[ok]
    t = np.asarray(t, dtype=float)
    return np.stack([np.interp(t, ts, search.interval[ok, 0]), np.interp(t, ts, search.interval[ok, 1])], -1)


def ramp_schedule(kappa: ArrayLike, max_step: float) -> FloatArray:
    """Rate-limit a schedule: ``|kappa_{k+1} - kappa_k| <= max_step`` and ``|kappa'| <= |kappa|``
    (forward/backward min-envelope of the positive and negative parts, so a drop to 0 at a
    segment point starts early instead of happening in one step).

    The envelope of each part is computed in closed form (cumulative minima, no loop over the
    steps); ``kappa`` may carry leading batch axes, the steps run along the last one."""
    kap = np.asarray(kappa, dtype=float)
    shape = kap.shape
    kap = np.atleast_1d(kap)
    c = 0.5 * float(max_step)
    parts = []
    for part in (np.maximum(kap, 0.0), np.maximum(-kap, 0.0)):
        if math.isnan(c) or c == math.inf:  # no rate limit (as the step-by-step recursion)
            parts.append(part)
            continue
        # closed form of env[k] = min(part[k], env[k-1] + c) (forward) and then
        # env[k] = min(env[k], env[k+1] + c) (backward): cumulative minima of part[j] -+ c j;
        # the outer minimum keeps env <= part exactly despite round-off
        ramp = c * np.arange(kap.shape[-1])
        env = np.minimum(part, ramp + np.minimum.accumulate(part - ramp, axis=-1))
        back = np.flip(np.minimum.accumulate(np.flip(env + ramp, -1), axis=-1), -1) - ramp
        parts.append(np.minimum(env, back))
    return (parts[0] - parts[1]).reshape(shape)


def _step_limits(prob: _Problem, out: _RunOut) -> np.ndarray:
    """(B, N) the healthy record keeps every limit at the steps before k (prefix check)."""
    sc = prob.scenario
    slack = 1.0 + LIMIT_RTOL
    bad = np.abs(out.qd).max(-1) > sc.vmax * slack
    acc = np.abs(np.diff(out.qd, axis=1)).max(-1) / sc.dt
    bad[:, 1:] |= acc > sc.amax * slack
    if sc.rest_transitions:
        bad[:, 0] |= np.abs(out.qd[:, 0]).max(-1) / sc.dt > sc.amax * slack
    bad |= out.dev[:, :-1] > sc.eps * slack
    # failure at step k: steps 0..k-1 ran healthy; the acceleration into k is the jump (excluded
    # here, as bad[:, k] is not included) and the post-failure run checks k onwards
    before = np.concatenate(
        [np.zeros((bad.shape[0], 1), dtype=bool), np.cumsum(bad, axis=1)[:, :-1] > 0], axis=1
    )
    return ~before


def verify_kappa(
    model: ArmModel,
    scenario: JumpScenario | None,
    schedule: KappaFit | Callable[[FloatArray], FloatArray] | float,
    *,
    search: KappaSearch | None = None,
    fix: Literal["clip", "ramp", "clip+ramp"] | None = None,
    progress: Any = None,
) -> Verification:
    """Inject the failure at every control step with kappa(t) in the law (001 §4.4).

    Two healthy runs (kappa = 0 and kappa(t)) give the jumps before/after at all N steps;
    N post-failure runs (batched) check the limits with kappa(t).

    Parameters
    ----------
    model
        The arm.
    scenario
        Task, lock joint, limits (the search's when ``None`` and ``search`` is given).
    schedule
        :class:`KappaFit`, any callable ``t [s] -> kappa``, or a constant.
    search
        The :class:`KappaSearch` the schedule came from: needed for the fixes and for
        ``sampled_limits_ok``.
    fix
        Offered when the fitted function breaks a limit that the samples kept:
        ``"clip"`` clips kappa(t) to :func:`feasible_band`; ``"ramp"`` rate-limits it
        (:func:`ramp_schedule`) so that its change adds at most ``amax / 2`` of joint
        acceleration (``|dkappa| <= amax dt / (2 null_max)``), which removes the velocity step
        that kappa's drop to 0 at a segment point causes; ``"clip+ramp"`` does both.
    progress
        Optional progress reporter.
    """
    if scenario is None:
        if search is None:
            raise ScenarioError("verify_kappa: give a scenario or a search")
        scenario = search.scenario
    prob = _problem(model, scenario)
    t = prob.t[:-1]
    if callable(schedule):
        kap = np.asarray(schedule(t), dtype=float) * np.ones(prob.N)
    else:
        kap = np.full(prob.N, float(schedule))
    if fix not in (None, "clip", "ramp", "clip+ramp"):
        raise ScenarioError(f"fix must be None, 'clip', 'ramp' or 'clip+ramp'; got {fix!r}")
    if fix is not None:
        if search is None:
            raise ScenarioError(f"verify_kappa: fix={fix!r} needs the search (feasible band, kappa scale)")
        if "clip" in fix:
            band = feasible_band(search, t)
            kap = np.clip(kap, band[:, 0], band[:, 1])
        if "ramp" in fix:
            kap = ramp_schedule(kap, scenario.amax * scenario.dt / (2.0 * search.null_max))
    krows = np.stack([np.zeros(prob.N), kap])
    healthy = _healthy_runs(prob, krows, progress=progress)
    table = _table(prob, krows, healthy)
    steps = np.arange(prob.N)
    post, order = _post_runs(prob, krows, healthy, np.ones(prob.N, dtype=int), steps, progress=progress)
    post_ok = _unsort(_ok(prob, post), order)
    prefix_ok = _step_limits(prob, healthy)[1]
    ok_steps = post_ok & prefix_ok
    h_ok = bool(table.healthy_limits_ok[1])
    sel = np.array([False, True])
    limits = _limit_report(prob, [healthy, post], [sel, None])
    before, after = table.joint_jump_norm[0], table.joint_jump_norm[1]
    sampled_ok = bool(search is not None and np.all(np.isfinite(search.kappa_opt)))
    return Verification(
        t,
        kap,
        before,
        after,
        table.task_jump_noreplan[0],
        table.task_jump_noreplan[1],
        float(table.task_jump_replan.max()),
        jump_reduction(before.mean(), after.mean()),
        float(np.mean(after < before)),
        limits,
        h_ok,
        ok_steps,
        t[~ok_steps],
        sampled_ok,
        fix,
        scenario,
    )


# -- one failure time and the whole study ----------------------------------------------------


@dataclass(frozen=True)
class JumpAtTime:
    """Everything about one failure time (001 §4.2).

    Attributes
    ----------
    fail_time
        Failure time [s] (a multiple of dt).
    kappa
        The coefficient used (optimal or given).
    interval
        (2,) feasible kappa interval (NaN when not searched or none).
    joint_jump_before, joint_jump_after
        (n,) ``dqdot`` with re-planning at kappa = 0 and at ``kappa`` [rad/s].
    jump_before, jump_after
        Their 2-norms [rad/s].
    joint_jump_noreplan_before, joint_jump_noreplan_after
        ``|qdot_j(t_f-)|`` [rad/s] (only the locked joint stops).
    task_jump_noreplan_before, task_jump_noreplan_after
        ``||J_j qdot_j||`` [m/s].
    task_jump_replan_before, task_jump_replan_after
        ``||J dqdot||`` [m/s] (zero while ``J_r`` has full row rank).
    limits_before, limits_after
        Limits of the healthy run plus the run with the failure.
    search
        The search (None when ``kappa`` was given).
    scenario
        The settings.
    """

    fail_time: float
    kappa: float
    interval: FloatArray
    joint_jump_before: FloatArray
    joint_jump_after: FloatArray
    jump_before: float
    jump_after: float
    joint_jump_noreplan_before: float
    joint_jump_noreplan_after: float
    task_jump_noreplan_before: float
    task_jump_noreplan_after: float
    task_jump_replan_before: float
    task_jump_replan_after: float
    limits_before: LimitReport
    limits_after: LimitReport
    search: KappaSearch | None
    scenario: JumpScenario

    @property
    def reduction(self) -> float:
        """``1 - jump_after / jump_before``; NaN (undefined) when ``jump_before`` is 0, i.e.
        there is no jump to reduce (:func:`jump_reduction`)."""
        return jump_reduction(self.jump_before, self.jump_after)


def jump_at_time(
    model: ArmModel,
    scenario: JumpScenario | None = None,
    fail_time: float = 6.0,
    *,
    kappa: float | None = None,
    search_options: Mapping[str, Any] | None = None,
    progress: Any = None,
) -> JumpAtTime:
    """Jump metrics at one failure time, with the optimal kappa (``kappa=None``) or a given one."""
    sc = JumpScenario() if scenario is None else scenario
    prob = _problem(model, sc)
    k = int(sc.step_of(fail_time))
    search = None
    interval = np.array([np.nan, np.nan])
    if kappa is None:
        search = search_kappa(model, sc, [k * sc.dt], progress=progress, **dict(search_options or {}))
        kappa = float(search.kappa_opt[0])
        interval = search.interval[0]
        if not np.isfinite(kappa):
            raise InfeasibleError(
                f"no kappa in [{search.probe_range[0]:.4g}, {search.probe_range[1]:.4g}] keeps every limit "
                f"with joint {sc.lock_joint} locking at {k * sc.dt:g} s"
            )
    krows = _kappa_rows(prob, np.array([0.0, float(kappa)]))
    healthy = _healthy_runs(prob, krows)
    table = _table(prob, krows, healthy)
    post, order = _post_runs(prob, krows, healthy, np.array([0, 1]), np.array([k, k]))
    post = _RunOut(*(_unsort(getattr(post, f.name), order) for f in fields(_RunOut)[:5]))
    reps = []
    for r in range(2):
        sel = np.zeros(2, dtype=bool)
        sel[r] = True
        reps.append(_limit_report(prob, [healthy, post], [sel, sel]))
    return JumpAtTime(
        k * sc.dt,
        float(kappa),
        interval,
        table.joint_jump[0, k],
        table.joint_jump[1, k],
        float(table.joint_jump_norm[0, k]),
        float(table.joint_jump_norm[1, k]),
        float(table.joint_jump_noreplan[0, k]),
        float(table.joint_jump_noreplan[1, k]),
        float(table.task_jump_noreplan[0, k]),
        float(table.task_jump_noreplan[1, k]),
        float(table.task_jump_replan[0, k]),
        float(table.task_jump_replan[1, k]),
        reps[0],
        reps[1],
        search,
        sc,
    )


@dataclass(frozen=True)
class JumpStudy:
    """The full 001 pipeline: search over sampled failure times, kappa(t) fit, verification.

    Attributes
    ----------
    search, fit, verification
        The three stages (``search`` includes the failure times :func:`fit_kappa` added
        around the breaks of kappa(t)).
    verification_fixed
        Verification of the fixed kappa(t) (when asked, or automatically when the fitted
        kappa(t) breaks a limit and ``fix="auto"``).
    elapsed
        Wall time [s] per stage: ``{"search": ..., "fit": ..., "verify": ...}``.
    scenario
        The settings.
    """

    search: KappaSearch
    fit: KappaFit
    verification: Verification
    verification_fixed: Verification | None
    elapsed: dict[str, float] = field(default_factory=dict)
    scenario: JumpScenario = field(default_factory=JumpScenario)


def study_jump(
    model: ArmModel,
    scenario: JumpScenario | None = None,
    *,
    n_samples: int = 40,
    order: int = 5,
    max_order: int = 9,
    fix: Literal["auto", "clip", "ramp", "clip+ramp"] | None = "auto",
    search_options: Mapping[str, Any] | None = None,
    fit_options: Mapping[str, Any] | None = None,
    progress_factory: Callable[[int, str], Any] | None = None,
) -> JumpStudy:
    """Run the whole pipeline of 001 on a scenario (search, fit, verification at every step).

    Parameters
    ----------
    model
        The arm.
    scenario
        NOTES-001's default when omitted.
    n_samples
        Sampled failure times for the search (001: 40).
    order, max_order
        Polynomial order of kappa(t) (001: 5) and the largest order allowed.
    fix
        Also verify a fixed kappa(t) (see :func:`verify_kappa`): ``"auto"`` applies
        ``"clip+ramp"`` only when the fitted kappa(t) breaks a limit; ``None``: never.
    search_options
        Extra keyword arguments of :func:`search_kappa`.
    fit_options
        Extra keyword arguments of :func:`fit_kappa` (e.g. ``piecewise=False``).
    progress_factory
        ``(total, description) -> progress`` (e.g. :class:`jointlock.progress.Progress`).
    """
    sc = JumpScenario() if scenario is None else scenario
    N = sc.n_steps

    def bar(total: int, desc: str) -> Any:
        return progress_factory(total, desc) if progress_factory is not None else None

    t0 = time.perf_counter()
    p = bar(2 * N, "kappa search")
    search = search_kappa(model, sc, n_samples=n_samples, progress=p, **dict(search_options or {}))
    if p is not None:
        p.close()
    t1 = time.perf_counter()
    fit = fit_kappa(model, search, order=order, max_order=max_order, **dict(fit_options or {}))
    if fit.search is not None:  # failure times added around the breaks of kappa(t)
        search = fit.search
    t2 = time.perf_counter()
    p = bar(2 * N, "verification")
    ver = verify_kappa(model, sc, fit, search=search, progress=p)
    if p is not None:
        p.close()
    ver_c = None
    if fix == "auto":
        if not ver.limits_ok:
            ver_c = verify_kappa(model, sc, fit, search=search, fix="clip+ramp")
    elif fix is not None:
        ver_c = verify_kappa(model, sc, fit, search=search, fix=fix)
    t3 = time.perf_counter()
    log.info("jump study: search %.2fs fit %.2fs verify %.2fs", t1 - t0, t2 - t1, t3 - t2)
    return JumpStudy(search, fit, ver, ver_c, {"search": t1 - t0, "fit": t2 - t1, "verify": t3 - t2}, sc)


__all__ = [
    "CartesianPath",
    "JumpAtTime",
    "JumpScenario",
    "JumpStudy",
    "JumpTable",
    "KappaFit",
    "KappaPiece",
    "KappaSearch",
    "LimitReport",
    "SCENARIO_FIELDS",
    "Trajectory",
    "Verification",
    "cartesian_trapezoid",
    "compensated_rates",
    "feasible_band",
    "ramp_schedule",
    "find_breaks",
    "fit_kappa",
    "fit_pieces",
    "jump_at_time",
    "merge_searches",
    "jump_table",
    "load_scenario",
    "sample_failure_times",
    "scenario_from_mapping",
    "search_kappa",
    "simulate",
    "study_jump",
    "verify_kappa",
]
