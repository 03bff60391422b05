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
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, ClassVar, Literal

import numpy as np
from numpy.typing import ArrayLike

from ..errors import InfeasibleError, ModelError, ScenarioError
from ..io.files import (
    atomic_write_bytes,
    atomic_write_json,
    atomic_write_text,
    csv_text,
    figure_png,
    npz_bytes,
)
from ..locking import lock_joints
from ..model import ArmModel
from ..papers import p000
from ..planning.ga import GASettings
from ..planning.halt_config import HaltConfiguration, HaltReachability, optimal_halt_configuration
from ..planning.halt_motion import (
    K_UNIT_SCALE,
    HaltMotion,
    HaltProblem,
    base_torque_history,
    infeasibility_message,
    optimal_halt_motion,
)
from ..plots._common import offscreen_figure
from ..plots.halt import (
    global_torque_curve,
    k_text,
    plot_base_torque_vs_time,
    plot_global_torque_vs_k,
    plot_joint_profiles,
)
from ..progress import Progress
from ..robots import load_robot
from ._common import JobResult, joint_vector_deg, locked_deg, locked_text

#: 000's limits (§5.2), the fallback where neither the caller nor the model gives one
#: [deg/s, deg/s^2].
DEFAULT_VMAX_DEG = p000.VELOCITY_LIMIT_DEG_S
DEFAULT_AMAX_DEG = p000.ACCELERATION_LIMIT_DEG_S2

#: Smallest number of time samples of the objective (Simpson's rule, odd).
MIN_N_SAMPLES = 11

#: Jacobian of the halt-configuration search (CP): 000 §3.1.2's generalized Jacobian J_F of
#: the free-floating arm, whatever the base of the disturbance torque.
HCOM_JACOBIAN = "generalized"

Solver = Literal["scan", "ga", "vector"]


@dataclass(frozen=True)
class FailureState:
    """State of the healthy joints when the failure is detected.

    Attributes
    ----------
    q, dq, ddq
        (n,) angles [rad], rates [rad/s] and accelerations [rad/s^2] of the movable joints
        (the locked model's joint order, :attr:`ArmModel.joint_numbers`).
    """

    q: np.ndarray
    dq: np.ndarray
    ddq: np.ndarray

    @classmethod
    def from_degrees(
        cls,
        model: ArmModel,
        q_deg: ArrayLike,
        dq_deg: ArrayLike | None = None,
        ddq_deg: ArrayLike | None = None,
        *,
        names: tuple[str, str, str] = ("q0_deg", "dq0_deg", "ddq0_deg"),
    ) -> FailureState:
        """From degrees, one value per movable joint or per joint of the full arm (a locked
        joint's angle must then equal its lock angle, its rate and acceleration 0); ``None``
        rates or accelerations are zeros.  ``names`` name the inputs in error messages."""
        return cls(
            joint_vector_deg(model, list(np.ravel(q_deg)), names[0]),
            joint_vector_deg(model, None if dq_deg is None else list(np.ravel(dq_deg)), names[1], rates=True),
            joint_vector_deg(
                model, None if ddq_deg is None else list(np.ravel(ddq_deg)), names[2], rates=True
            ),
        )


@dataclass(frozen=True)
class JointLimits:
    """Symmetric speed and acceleration limits of the healthy joints, and where each came from.

    Attributes
    ----------
    velocity, acceleration
        (n,) ``v_max`` [rad/s] and ``a_max`` [rad/s^2].
    velocity_source, acceleration_source
        (n,) plain-language origin of each joint's limit.
    """

    velocity: np.ndarray
    acceleration: np.ndarray
    velocity_source: tuple[str, ...]
    acceleration_source: tuple[str, ...]


def _limit_values(values: Any, name: str, n: int) -> np.ndarray | None:
    """None, or (n,) from one value or n values (finite, > 0)."""
    if values is None:
        return None
    arr = np.asarray(values, dtype=float).ravel()
    if arr.size == 1:
        arr = np.full(n, arr[0])
    if arr.shape != (n,) or not np.all(np.isfinite(arr) & (arr > 0)):
        raise ScenarioError(f"{name} needs one value or {n} values, finite and > 0; got {np.ravel(values).tolist()}")
    return arr


def halt_limits(
    model: ArmModel,
    vmax_deg: ArrayLike | None = None,
    amax_deg: ArrayLike | None = None,
    *,
    names: tuple[str, str] = ("--vmax-deg", "--amax-deg"),
) -> JointLimits:
    """Speed and acceleration limits of the healthy joints by ``jointlock halt``'s rule.

    A joint's speed limit is ``vmax_deg`` capped by the model's own ``velocity_limit`` (the
    smaller of the two); without ``vmax_deg``, the model's limit where finite, else 000's
    :data:`DEFAULT_VMAX_DEG`.  The acceleration limit is ``amax_deg``, else
    :data:`DEFAULT_AMAX_DEG` (a model has no acceleration limit).

    Parameters
    ----------
    vmax_deg, amax_deg
        One value or one per healthy joint [deg/s, deg/s^2] (limits are typed by people, in
        degrees), or None.
    names
        How the two inputs are named in the sources and in error messages (the CLI's options).
    """
    n = model.dof
    v_opt = _limit_values(vmax_deg, names[0], n)
    a_opt = _limit_values(amax_deg, names[1], n)
    v_model = np.degrees([j.velocity_limit for j in model.joints])
    vmax, v_src = np.empty(n), []
    for i in range(n):
        finite = math.isfinite(v_model[i])
        if v_opt is not None and (not finite or v_opt[i] <= v_model[i]):
            vmax[i] = v_opt[i]
            v_src.append(names[0])
        elif v_opt is not None:
            vmax[i] = v_model[i]
            v_src.append(f"model's limit, below {names[0]} {v_opt[i]:g}")
        elif finite:
            vmax[i] = v_model[i]
            v_src.append("model's limit")
        else:
            vmax[i] = DEFAULT_VMAX_DEG
            v_src.append("000's default; the model gives none")
    if a_opt is not None:
        amax, a_src = a_opt, [names[1]] * n
    else:
        amax, a_src = np.full(n, DEFAULT_AMAX_DEG), ["000's default"] * n
    return JointLimits(np.radians(vmax), np.radians(amax), tuple(v_src), tuple(a_src))


def resolve_limits(
    model: ArmModel, vmax_deg: Sequence[float] | None, amax_deg: Sequence[float] | None
) -> tuple[np.ndarray, np.ndarray, list[str], list[str]]:
    """:func:`halt_limits` as a tuple ``(vmax [rad/s], amax [rad/s^2], vmax_source,
    amax_source)`` (the CLI's form)."""
    lim = halt_limits(model, vmax_deg, amax_deg)
    return lim.velocity, lim.acceleration, list(lim.velocity_source), list(lim.acceleration_source)


def limits_text(numbers: Sequence[int], values_rad: ArrayLike, sources: Sequence[str], unit: str) -> str:
    """``"40 deg/s (model's limit)"`` when every joint has the same limit from the same
    source, else the joints grouped: ``"joints 1, 2: 10 deg/s (model's limit); joint 4: ..."``."""
    groups: dict[tuple[str, str], list[int]] = {}
    for num, v, src in zip(numbers, np.degrees(values_rad), sources):
        groups.setdefault((f"{v:.6g}", src), []).append(num)
    if len(groups) == 1:
        (value, src), _ = next(iter(groups.items()))
        return f"{value} {unit} ({src})"
    parts = []
    for (value, src), nums in groups.items():
        label = "joint" if len(nums) == 1 else "joints"
        parts.append(f"{label} {', '.join(map(str, nums))}: {value} {unit} ({src})")
    return "; ".join(parts)


def halt_model(robot: str, locks: Mapping[int, float] | None, base: str = "fixed") -> ArmModel:
    """The locked arm ``jointlock halt`` uses for ``robot`` (a built-in name or model file).

    The base torque is taken about the spacecraft's centre of mass (000 eq. 30), so the model
    is loaded with its spacecraft even when the base is held fixed (``base`` only picks the
    torque's base mode); a robot without one is loaded fixed (then the moment point is the
    root frame's origin).  ``locks``: ``{joint number: angle [rad]}``.
    """
    try:
        model = load_robot(robot, base="floating")
    except ModelError:
        if base == "floating":
            raise
        model = load_robot(robot, base="fixed")
    return lock_joints(model, dict(locks)) if locks else model


def _is_paper_state(model: ArmModel, state: FailureState, T: float, limits: JointLimits) -> bool:
    """True for 000 §5's scenario on halt7: joint 4 locked at 0, §5.2's state, T and limits."""
    ps = p000.SCENARIO
    if model.name != "halt7" or {lj.number: lj.angle for lj in model.locked} != ps["lock"]:
        return False
    same = all(
        np.allclose(np.degrees(v), ps[key], atol=1e-9)
        for v, key in ((state.q, "q0_deg"), (state.dq, "dq0_deg"), (state.ddq, "ddq0_deg"))
    )
    return (
        same
        and T == ps["T"]
        and np.allclose(np.degrees(limits.velocity), ps["vmax_deg"])
        and np.allclose(np.degrees(limits.acceleration), ps["amax_deg"])
    )


def _check_start(model: ArmModel, state: FailureState, T: float, limits: JointLimits) -> None:
    """Refuse a state at failure that itself breaks a limit before any search: every halt
    starts from it (the k-part vanishes at t = 0 with two derivatives), so no halt
    configuration, halt time or k helps, and a Monte Carlo search would be pointless."""
    reach = HaltReachability(state.q, state.dq, state.ddq, T, limits.velocity, limits.acceleration)
    bad = reach.bind(model).start_violations(model.joint_numbers)
    if bad:
        nums = model.joint_numbers
        raise InfeasibleError(
            "the state at failure (--q0-deg, --dq0-deg, --ddq0-deg) already breaks a limit, and every "
            "halt starts from it, so no halt configuration, halt time or k helps: "
            + "; ".join(bad)
            + f" (speed limits: {limits_text(nums, limits.velocity, limits.velocity_source, 'deg/s')}; "
            f"acceleration limits: "
            f"{limits_text(nums, limits.acceleration, limits.acceleration_source, 'deg/s^2')}); "
            "no halt configuration searched"
        )


def _search_halt_configuration(
    model: ArmModel,
    state: FailureState,
    T: float,
    limits: JointLimits,
    *,
    samples: int,
    seed: Any,
    reachable: bool,
    per_joint: bool,
    progress: bool,
) -> tuple[HaltConfiguration, str | None]:
    """000's HCOM on J_F among the configurations the halt reaches (unless ``reachable`` is
    False), falling back to the whole ranges when none is; returns it and the reachability
    note (None when not constrained)."""
    reach = None
    if reachable:
        reach = HaltReachability(
            state.q, state.dq, state.ddq, float(T), limits.velocity, limits.acceleration, per_joint=per_joint
        )
    note = None
    bar = Progress(samples, "halt configuration", enabled=progress)
    try:
        hc = optimal_halt_configuration(
            model, samples=samples, rng=seed, jacobian=HCOM_JACOBIAN, progress=bar, reachability=reach
        )
    except InfeasibleError as exc:
        if reach is None:
            raise
        note = f"not met, searched the whole ranges instead (000's way): {exc}"
        bar.close()
        bar = Progress(samples, "halt configuration", enabled=progress)
        hc = optimal_halt_configuration(model, samples=samples, rng=seed, jacobian=HCOM_JACOBIAN, progress=bar)
    bar.close()
    if reach is not None and hc.reachability is not None:
        note = (
            f"exact: {hc.reachable_samples} of {samples} samples reachable by the halt polynomial "
            f"within T = {float(T):g} s under the limits"
        )
    return hc, note


def check_halt_settings(T: float | None, n_samples: int, samples: int, solver: str, ga: GASettings) -> None:
    """Refuse settings :func:`plan_halt` cannot use, before any work (named as the CLI's options)."""
    if T is not None and not (math.isfinite(T) and T > 0):
        raise ScenarioError(f"--T must be a finite halt time > 0 [s]; got {T:g}")
    if n_samples < MIN_N_SAMPLES or n_samples % 2 == 0:
        raise ScenarioError(
            f"--n-samples must be an odd integer >= {MIN_N_SAMPLES} (time samples of the objective, "
            f"Simpson's rule); got {n_samples}"
        )
    if samples < 2:
        raise ScenarioError(f"--samples must be an integer >= 2 (Monte Carlo samples); got {samples}")
    if solver == "ga":
        bad = []
        if ga.n_pop < 2:
            bad.append(f"--population must be >= 2 (GA population); got {ga.n_pop}")
        if ga.n_gen < 0:
            bad.append(f"--generations must be >= 0 (GA generations); got {ga.n_gen}")
        if bad:
            raise ScenarioError("; ".join(bad))


def plan_halt(
    robot: ArmModel | str,
    state: FailureState | None = None,
    *,
    locks: Mapping[int, float] | None = None,
    T: float | None = None,
    qf: ArrayLike | None = None,
    paper_qf: bool = False,
    vmax_deg: ArrayLike | None = None,
    amax_deg: ArrayLike | None = None,
    limits: JointLimits | None = None,
    base: Literal["fixed", "floating"] = "fixed",
    solver: Solver = "scan",
    rng: int = 0,
    samples: int = 36000,
    reachable: bool = True,
    n_samples: int = 501,
    ga: GASettings | None = None,
    progress: bool = False,
) -> HaltPlan:
    """000's halt strategy: optimal halt configuration, then optimal halt motion (000 §3-§4).

    Parameters
    ----------
    robot
        A built-in name or model file (loaded by :func:`halt_model`, with ``locks``), or a
        locked :class:`ArmModel` (used as given: the base torque is taken about its
        spacecraft's centre of mass when it has one, else about its root frame's origin).
    state
        State at failure; None on halt7 = 000 §5.2's (:data:`jointlock.papers.p000.SCENARIO`).
    locks
        ``{joint number: angle [rad]}`` when ``robot`` is a name; None on halt7 = 000's
        (joint 4 at 0).
    T
        Halt time [s]; None on halt7 = 000's 10 s.
    qf
        (n,) halt configuration [rad]; None = search it (HCOM), unless ``paper_qf`` (000's
        printed q_best, halt7 only).
    vmax_deg, amax_deg, limits
        The limits by :func:`halt_limits`'s rule from ``vmax_deg`` [deg/s] and ``amax_deg``
        [deg/s^2], or ``limits`` as they are.
    base
        Base of the disturbance torque: ``"fixed"`` (000) or ``"floating"``; the halt
        configuration is searched on J_F either way (000 §3.1.2).
    solver
        ``"scan"`` (exact), ``"ga"`` (000's adaptive GA, ``ga`` settings: default population
        50, 100 generations) or ``"vector"`` (one k per joint).
    rng
        Seed of the Monte Carlo search and the GA (recorded in the result).
    samples
        Monte Carlo samples of the halt configuration (000: K = 36000).
    reachable
        Search only configurations the halt polynomial reaches (exact; default) or the whole
        ranges (000's way).
    n_samples
        Time samples of the objective (odd, Simpson's rule).
    progress
        Show progress bars on stderr.

    Raises
    ------
    ScenarioError
        Missing or malformed inputs.
    InfeasibleError
        The state at failure itself breaks a limit (no halt can help), or (with
        ``reachable=False``) nothing sampled satisfies the search's constraints.
    """
    ga = ga if ga is not None else GASettings(n_pop=50, n_gen=100)
    named = isinstance(robot, str)
    paper = robot == "halt7" if named else robot.name == "halt7"
    defaults = p000.SCENARIO if paper else {}
    check_halt_settings(T, n_samples, samples, solver, ga)
    if state is None and not paper:
        raise ScenarioError("plan_halt needs the state at failure (state=FailureState(...)) for this robot")
    if T is None and "T" not in defaults:
        raise ScenarioError("plan_halt needs the halt time T [s] for this robot")
    T = float(T if T is not None else defaults["T"])
    if named:
        if locks is None:
            locks = {j: math.radians(a) for j, a in defaults.get("lock", {}).items()}
        model = halt_model(robot, locks, base)
    else:
        model = robot
    if state is None:
        state = FailureState.from_degrees(
            model, defaults["q0_deg"], defaults["dq0_deg"], defaults["ddq0_deg"],
            names=("--q0-deg", "--dq0-deg", "--ddq0-deg"),
        )  # fmt: skip
    if limits is None:
        limits = halt_limits(model, vmax_deg, amax_deg)
    paper_scenario = _is_paper_state(model, state, T, limits)
    configuration, reach_note = None, None
    if qf is not None:
        qf_arr, qf_source = np.asarray(qf, dtype=float), "--qf-deg"
    elif paper_qf:
        if not paper:
            raise ScenarioError("--paper-qf is 000's q_best for halt7 only; give --qf-deg")
        qf_arr, qf_source = joint_vector_deg(model, list(p000.SCENARIO["qf_deg"]), "--paper-qf"), "000's printed q_best"
    else:
        _check_start(model, state, T, limits)
        configuration, reach_note = _search_halt_configuration(
            model, state, T, limits, samples=samples, seed=rng, reachable=reachable,
            per_joint=solver == "vector", progress=progress,
        )  # fmt: skip
        qf_arr = np.asarray(configuration.q_best, dtype=float)
        qf_source = f"optimal halt configuration (Monte Carlo, {samples} samples, seed {rng})"
    problem = HaltProblem(
        model, state.q, state.dq, state.ddq, qf_arr, T, limits.velocity, limits.acceleration,
        base=base, n_samples=n_samples,
    )  # fmt: skip
    bar = Progress(ga.n_gen, "GA generations", enabled=progress) if solver == "ga" else None
    motion = optimal_halt_motion(problem, solver=solver, rng=rng, ga_settings=ga, progress=bar)
    if bar is not None:
        bar.close()
    return HaltPlan(
        motion=motion,
        limits=limits,
        qf_source=qf_source,
        paper_scenario=paper_scenario,
        configuration=configuration,
        reachability=reach_note,
        samples=samples,
        reachability_requested=reachable,
    )


@dataclass(frozen=True)
class HaltPlan(JobResult):
    """The result of :func:`plan_halt`: where the arm halts and how it gets there.

    Attributes
    ----------
    motion
        The optimal halt motion (its ``problem`` holds the model, state, halt configuration,
        T and limits).
    limits
        The limits applied and their sources.
    qf_source
        Where the halt configuration came from.
    paper_scenario
        Whether this is 000 §5's scenario (then ``to_dict()["paper"]`` holds 000's numbers).
    configuration
        The halt-configuration search (None when ``qf`` was given).
    reachability
        How the reachability constraint went (None when not searched or not constrained).
    samples
        Monte Carlo samples of the search.
    reachability_requested
        Whether the search was asked to keep to reachable configurations.
    """

    job: ClassVar[str] = "halt"

    motion: HaltMotion
    limits: JointLimits
    qf_source: str
    paper_scenario: bool = False
    configuration: HaltConfiguration | None = field(default=None, repr=False)
    reachability: str | None = None
    samples: int = 36000
    reachability_requested: bool = True

    @property
    def problem(self) -> HaltProblem:
        return self.motion.problem

    @property
    def feasible(self) -> bool:
        return bool(self.motion.feasible)

    @property
    def k_deg(self) -> Any:
        """The chosen k [deg/s^6] (an array with one k per joint for the vector solver)."""
        return np.asarray(self.motion.k) / K_UNIT_SCALE["deg/s^6"]

    def _notes(self) -> dict[str, Any]:
        """Where the limits and the halt configuration came from (keys in the CLI's order)."""
        notes: dict[str, Any] = {
            "velocity_limit_source": list(self.limits.velocity_source),
            "acceleration_limit_source": list(self.limits.acceleration_source),
            "paper_scenario": self.paper_scenario,
        }
        hc = self.configuration
        if hc is not None and self.reachability is not None:
            notes["reachability"] = self.reachability
            if hc.reachability is not None:
                notes["reachable_samples"] = hc.reachable_samples
        notes["qf_source"] = self.qf_source
        if hc is not None:
            notes["cp_best"] = float(getattr(hc, "cp_best", float("nan")))
            notes["hcom_jacobian"] = hc.jacobian
            notes["hcom_base"] = hc.base
        return notes

    def to_dict(self) -> dict[str, Any]:
        """What ``jointlock halt --json`` prints: degrees, deg/s^6 for k, N m for torques."""
        res, p = self.motion, self.problem
        scale = K_UNIT_SCALE["deg/s^6"]
        _, dq, ddq = res.trajectory(p.times(p.n_check))
        return {
            "robot": p.model.name,
            "base": p.base,
            "joint_numbers": list(p.model.joint_numbers),
            "locked": locked_deg(p.model),
            "T_s": p.T,
            "k": np.asarray(res.k) / scale,
            "k_unit": "deg/s^6",
            "k_rad": res.k,
            "global_torque_Nm": res.global_torque,
            "global_torque_k0_Nm": res.global_torque_k0,
            "reduction": None if math.isnan(res.reduction) else res.reduction,
            "feasible": res.feasible,
            "violations": [_violation(v) for v in res.violations],
            "violations_k0": [_violation(v) for v in res.violations_k0],
            "k_interval_deg": res.k_interval / scale,
            **({"joint_k_intervals_deg": res.joint_intervals / scale} if res.per_joint else {}),
            "minimum_T_s": res.minimum_T,
            "q_initial_deg": np.degrees(p.q0),
            "q_final_deg": np.degrees(p.qf),
            "peak_velocity_deg_s": np.degrees(np.abs(dq).max(axis=0)),
            "peak_acceleration_deg_s2": np.degrees(np.abs(ddq).max(axis=0)),
            "velocity_limit_deg_s": np.degrees(p.dq_max),
            "acceleration_limit_deg_s2": np.degrees(p.ddq_max),
            "solver": res.solver,
            "seed": res.seed,
            # 000's printed numbers, for 000 §5's scenario on halt7 only (None otherwise)
            "paper": dict(p000.HALT_RESULTS) if self.paper_scenario else None,
            **self._notes(),
        }

    def summary(self) -> list[str]:
        """The lines ``jointlock halt`` prints."""
        res, p = self.motion, self.problem
        nums = list(p.model.joint_numbers)
        lines = [
            f"{p.model.name}: healthy joints {nums}, locked: {locked_text(locked_deg(p.model))}, "
            f"base torque with {p.base} base",
            f"halt configuration ({self.qf_source}): " + ", ".join(f"{v:.2f}" for v in np.degrees(p.qf)) + " deg",
        ]
        hc = self.configuration
        if hc is not None:
            lines.append(
                f"  (CP with the {_jacobian_text(hc.base)}; --base sets the base of the disturbance torque only)"
            )
        if self.reachability is not None:
            lines.append(f"reachability: {self.reachability}")
        lim = self.limits
        lines += [
            f"halt time T = {p.T:g} s",
            f"speed limits: {limits_text(nums, p.dq_max, lim.velocity_source, 'deg/s')}",
            f"acceleration limits: {limits_text(nums, p.ddq_max, lim.acceleration_source, 'deg/s^2')}",
        ]
        scale = K_UNIT_SCALE["deg/s^6"]
        if not res.feasible:
            lines += ["", "INFEASIBLE: " + infeasibility_message(res)]
        elif res.per_joint:  # one k per joint: each within its own joint's interval
            lines += ["", f"feasible k per joint [deg/s^6]; solver {res.solver}"]
            for num, (lo, hi), kj in zip(nums, res.joint_intervals / scale, np.asarray(res.k) / scale):
                lines.append(f"  joint {num}: [{lo:.6g}, {hi:.6g}], k* = {kj:.6g}")
        else:
            lo, hi = res.k_interval / scale
            lines += ["", f"feasible k: [{lo:.6g}, {hi:.6g}] deg/s^6; solver {res.solver}", f"k* = {k_text(res)}"]
        at = "k*" if res.feasible else "least-violating k (infeasible)"
        lines.append(
            f"global base torque: k = 0: {res.global_torque_k0:.4f} N m; {at}: {res.global_torque:.4f} N m "
            f"({_change_text(res)})"
        )
        if self.paper_scenario:  # 000's numbers belong to 000 §5's scenario on halt7 only
            lines.append(
                "000 printed: k = 0.0018, 22.25 -> 15.55 N m (30.1 %) -- not reproduced, see docs/halt-motion.md"
            )
        _, dq, ddq = res.trajectory(p.times(p.n_check))
        peak_v, peak_a = np.degrees(np.abs(dq).max(axis=0)), np.degrees(np.abs(ddq).max(axis=0))
        v_lim, a_lim = np.degrees(p.dq_max), np.degrees(p.ddq_max)
        lines += ["", "joint   peak |dq| [deg/s] (limit)   peak |ddq| [deg/s^2] (limit)"]
        for j, num in enumerate(nums):
            v_text = f"({v_lim[j]:.6g})"
            lines.append(f"{num:>5}   {peak_v[j]:10.3f} {v_text:<14}  {peak_a[j]:10.3f} ({a_lim[j]:.6g})")
        return "\n".join(lines).split("\n")  # one entry per printed line

    def time_series(self) -> dict[str, np.ndarray]:
        """The halt on the objective's time grid: ``t`` (m,) [s]; ``q``, ``dq``, ``ddq`` (m, n)
        [rad, rad/s, rad/s^2]; base torque ``tau_b`` and ``tau_b_k0`` (at k = 0) (m, 3) [N m]."""
        res, p = self.motion, self.problem
        t = p.times()
        q, dq, ddq = res.trajectory(t)
        tb = base_torque_history(p, res.k, t, per_joint=res.per_joint)
        tb0 = base_torque_history(p, 0.0, t)
        return {"t": t, "q": q, "dq": dq, "ddq": ddq, "tau_b": tb, "tau_b_k0": tb0}

    def write(self, out: str | Path) -> list[str]:
        """Plots like 000 Figs. 8-9, base torque vs time, time series (CSV, NPZ) and
        result.json in ``out``; returns the file names."""
        out = Path(out)
        out.mkdir(parents=True, exist_ok=True)
        res, p = self.motion, self.problem
        grid, tau = global_torque_curve(res)
        ts = self.time_series()
        figures = (
            ("global_torque_vs_k.png", (7, 4), lambda fig: plot_global_torque_vs_k(res, ax=fig.add_subplot())),
            ("joint_profiles.png", (3 * p.dof, 7), lambda fig: plot_joint_profiles(res, fig=fig)),
            ("base_torque_vs_time.png", (7, 4), lambda fig: plot_base_torque_vs_time(res, ax=fig.add_subplot())),
        )
        written = []
        for name, size, draw in figures:
            fig = offscreen_figure(size)
            draw(fig)
            atomic_write_bytes(out / name, figure_png(fig))
            written.append(name)
        cols = {"t_s": ts["t"]}
        for j, num in enumerate(p.model.joint_numbers):
            cols[f"q{num}_deg"] = np.degrees(ts["q"][:, j])
            cols[f"dq{num}_deg_s"] = np.degrees(ts["dq"][:, j])
            cols[f"ddq{num}_deg_s2"] = np.degrees(ts["ddq"][:, j])
        for i, ax_name in enumerate("xyz"):
            cols[f"tau_b_{ax_name}_Nm"] = ts["tau_b"][:, i]
        for i, ax_name in enumerate("xyz"):
            cols[f"tau_b0_{ax_name}_Nm"] = ts["tau_b_k0"][:, i]
        atomic_write_text(out / "halt_motion.csv", csv_text(cols))
        atomic_write_bytes(out / "halt_motion.npz", npz_bytes(**ts, k_grid=grid, global_torque_grid=tau))
        atomic_write_json(out / "result.json", self.to_dict())
        return written + ["halt_motion.csv", "halt_motion.npz", "result.json"]


def _violation(v: Any) -> dict[str, Any]:
    return {
        "joint": v.joint,
        "limit": v.kind,
        "limit_value_deg": math.degrees(v.limit),
        "value_deg": math.degrees(v.value),
        "excess_deg": math.degrees(v.excess),
        "time_s": v.time,
    }


def _jacobian_text(hcom_base: str) -> str:
    if hcom_base == "fixed":  # a robot without a spacecraft: J_F is the fixed-base one
        return "generalized Jacobian, which for this fixed-base model is the fixed-base Jacobian"
    return "free-floating arm's generalized Jacobian J_F (000 §3.1.2)"


def _change_text(res: HaltMotion) -> str:
    """The torque change from k = 0 to the chosen k, in words."""
    if math.isnan(res.reduction):
        return "reduction n/a: no torque at k = 0"
    if res.reduction >= 0:
        return f"{100 * res.reduction:.1f} % lower"
    if res.violations_k0:
        return f"{-100 * res.reduction:.1f} % higher: k = 0 breaks a limit"
    return f"{-100 * res.reduction:.1f} % higher"


def halt_from_scenario(
    data: Mapping[str, Any], previous: Mapping[str, JobResult], *, progress: bool = False
) -> HaltPlan:
    """The ``[halt]`` job of a resolved scenario (``Scenario.data``): the state, limits and
    failure of the scenario; the halt configuration from ``[halt] qf_deg``, 000's q_best
    (``paper_qf``), else the ``halt_config`` job that ran before it, else searched here."""
    t, st, lim = data["halt"], data["state"], data["limits"]
    fail = data["failure"]
    locks = {int(fail["joint"]): math.radians(float(fail["angle_deg"]))} if fail.get("angle_deg") is not None else {}
    base = t.get("base") or data["base"]
    model = halt_model(data["robot"], locks, base)
    state = FailureState.from_degrees(
        model, st["q0_deg"], st["dq0_deg"], st["ddq0_deg"], names=("--q0-deg", "--dq0-deg", "--ddq0-deg")
    )
    qf = None
    if t["qf_deg"] is not None:
        qf = joint_vector_deg(model, list(t["qf_deg"]), "--qf-deg")
    elif not t["paper_qf"] and "halt_config" in previous:
        qf = joint_vector_deg(model, list(previous["halt_config"].to_dict()["best"]["q_deg"]), "--qf-deg")
    return plan_halt(
        model,
        state,
        T=float(t["T"]),
        qf=qf,
        paper_qf=bool(t["paper_qf"]) and qf is None,
        vmax_deg=lim["vmax_deg"],
        amax_deg=lim["amax_deg"],
        base=base,
        solver=t["solver"],
        rng=data["seed"],
        samples=int(t["samples"]),
        n_samples=int(t["n_samples"]),
        ga=GASettings(n_pop=int(t["population"]), n_gen=int(t["generations"])),
        progress=progress,
    )
