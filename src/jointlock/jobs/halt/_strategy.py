"""000's halt strategy (:func:`plan_halt`): the checks before any work, the halt-configuration
search among the configurations the halt reaches (with its fallback), then the halt motion;
the arm it runs on (:func:`halt_model`) and the ``[halt]`` job of a scenario
(:func:`halt_from_scenario`)."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import replace
from typing import Any, Literal, cast

import numpy as np
from numpy.typing import ArrayLike

from ..._random import resolve_seed
from ...analysis.attitude_control import WheelCapacity
from ...bounds import as_real
from ...collision import ClearanceSettings, collision_pairs
from ...collision import clearance as clearance_of
from ...errors import InfeasibleError, ModelError, ScenarioError
from ...locking import lock_joints
from ...model import ArmModel
from ...papers import p000
from ...planning.completion import TaskCompletion, task_completion
from ...planning.ga import GASettings
from ...planning.halt_config import HaltConfiguration, HaltReachability, optimal_halt_configuration
from ...planning.halt_motion import (
    HaltMotion,
    HaltProblem,
    clear_k_segments,
    clear_per_joint_k,
    clearance_shortfall,
    constraint_violations,
    global_base_torque,
    halt_objective,
    minimum_clear_halt_time,
    optimal_halt_motion,
)
from ...progress import Progress
from ...robots import UrdfChain, load_robot
from ...scenario._task import scenario_task, task_given
from .._common import JobResult, joint_vector_deg, locked_deg, locked_text, scenario_clearance, scenario_locks
from ._checks import (
    LIBRARY_NAMES,
    SCENARIO_NAMES,
    _check_start,
    _check_start_margin,
    _check_start_torques,
    check_halt_settings,
)
from ._inputs import (
    FailureState,
    JointLimits,
    halt_limits,
    is_000_failure,
)
from ._result import HaltPlan
from ._settings import HaltLimits, HaltMotionSettings, HaltSearch, Solver, settings_from_keywords

#: Jacobian of the halt-configuration search (CP): 000 §3.1.2's generalized Jacobian J_F of
#: the free-floating arm, whatever the base of the disturbance torque.
HCOM_JACOBIAN: Literal["generalized"] = "generalized"

#: Largest margin kept free on each limit (half of it: beyond, the "limits" are others).
MAX_MARGIN = 0.5


def halt_model(
    robot: str, locks: Mapping[int, float] | None, base: str = "fixed", chain: UrdfChain | None = None
) -> ArmModel:
    """The locked arm ``jointlock halt`` uses for ``robot`` (a built-in name or model file).

    The base torque is taken about the spacecraft's centre of mass (000 eq. 30), so the model
    is loaded with its spacecraft even when the base is held fixed (``base`` only picks the
    torque's base mode); a robot without one is loaded fixed (then the moment point is the
    root frame's origin).  ``locks``: ``{joint number: angle [rad]}``; ``chain``: the chain of a
    URDF tree (:class:`jointlock.robots.UrdfChain`).
    """
    try:
        model = load_robot(robot, base="floating", chain=chain)
    except ModelError:
        if base == "floating":
            raise
        model = load_robot(robot, base="fixed", chain=chain)
    return lock_joints(model, dict(locks)) if locks else model


def _is_paper_state(model: ArmModel, state: FailureState, T: float, limits: JointLimits) -> bool:
    """True for 000 §5's scenario on halt7: joint 4 locked at 0, §5.2's state, T and limits."""
    ps = p000.SCENARIO
    if not is_000_failure(model):
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
    clearance: ClearanceSettings,
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
    bar = Progress(samples, "halt configuration", enabled=None if progress else False)
    try:
        hc = optimal_halt_configuration(
            model, samples=samples, rng=seed, jacobian=HCOM_JACOBIAN, progress=bar, reachability=reach,
            clearance_min_m=clearance.min_m, keep_out=clearance.keep_out,
        )  # fmt: skip
    except InfeasibleError as exc:
        if reach is None:
            raise
        note = f"not met, searched the whole ranges instead (000's way): {exc}"
        bar.close()
        bar = Progress(samples, "halt configuration", enabled=None if progress else False)
        hc = optimal_halt_configuration(
            model, samples=samples, rng=seed, jacobian=HCOM_JACOBIAN, progress=bar,
            clearance_min_m=clearance.min_m, keep_out=clearance.keep_out,
        )  # fmt: skip
    bar.close()
    if reach is not None and hc.reachability is not None:
        note = (
            f"exact: {hc.reachable_samples} of {samples} samples reachable by the halt polynomial "
            f"within T = {float(T):g} s under the limits"
        )
    return hc, note


def _arm_state_and_time(
    robot: ArmModel | str,
    state: FailureState | None,
    locks: Mapping[int, float] | None,
    T: float | None,
    base: Literal["fixed", "floating"] | None,
    state_names: tuple[str, str, str],
) -> tuple[ArmModel, FailureState, float, Literal["fixed", "floating"], bool]:
    """:func:`plan_halt`'s arm (loaded and locked when given by name), state at failure, halt
    time and base, with 000 §5's as defaults on halt7; and whether the arm is halt7."""
    if isinstance(robot, str):
        if locks is None and robot == "halt7":
            locks = {j: math.radians(a) for j, a in p000.SCENARIO["lock"].items()}
        base = base or "fixed"  # 000 computes the torque with the spacecraft held
        model = halt_model(robot, locks, base)  # a name that is no robot is refused here
    else:
        model = robot
        base = base or ("floating" if model.floating else "fixed")  # the model's own base
    paper = is_000_failure(model)  # 000's state and T belong to 000's failure only
    defaults = p000.SCENARIO if paper else {}
    if state is None and not paper:
        raise ScenarioError(
            f"plan_halt needs the state at failure of {model.name!r} (locked: {locked_text(locked_deg(model))}; "
            "state=FailureState(...)): 000's is the default only for halt7 with joint 4 locked at 0 deg"
        )
    if T is None and "T" not in defaults:
        raise ScenarioError(f"plan_halt needs the halt time T [s] for {model.name!r}")
    T = float(T if T is not None else defaults["T"])
    if state is None:
        state = FailureState.from_degrees(
            model, defaults["q0_deg"], defaults["dq0_deg"], defaults["ddq0_deg"],
            names=state_names,
        )  # fmt: skip
    if state.q.size != model.dof:
        raise ScenarioError(
            f"plan_halt: the state has {state.q.size} joints but {model.name!r} has {model.dof} movable joints "
            f"{list(model.joint_numbers)} (FailureState.from_degrees accepts the full arm too)"
        )
    return model, state, T, base, paper


# Over 100 lines: 19 keyword inputs and their numpydoc take about 80; the strategy itself is ~45 lines.
def plan_halt(
    robot: ArmModel | str,
    state: FailureState | None = None,
    *,
    locks: Mapping[int, float] | None = None,
    T: float | None = None,
    qf: ArrayLike | None = None,
    paper_qf: bool = False,
    limits: HaltLimits | JointLimits | None = None,
    clearance: ClearanceSettings | None = None,
    search: HaltSearch | None = None,
    motion: HaltMotionSettings | None = None,
    base: Literal["fixed", "floating"] | None = None,
    rng: int | np.random.Generator | None = 0,
    wheels: WheelCapacity | None = None,
    progress: bool = False,
    state_source: str | None = None,
    _names: Mapping[str, Any] = LIBRARY_NAMES,
    _state_names: tuple[str, str, str] = ("state.q", "state.dq", "state.ddq"),
    **former: Any,
) -> HaltPlan:
    """000's halt strategy: optimal halt configuration, then optimal halt motion (000 §3-§4).

    Parameters
    ----------
    robot
        A built-in name or model file (loaded by :func:`halt_model`, with ``locks``), or a
        locked :class:`ArmModel` (used as given: the base torque is taken about its
        spacecraft's centre of mass when it has one, else about its root frame's origin).
    state
        State at failure; None on 000's failure (halt7, joint 4 locked at 0 deg: see
        :func:`is_000_failure`) = 000 §5.2's (:data:`jointlock.papers.p000.SCENARIO`); needed for
        any other failure.
    locks
        ``{joint number: angle [rad]}`` when ``robot`` is a name; None on halt7 = 000's
        (joint 4 at 0).
    T
        Halt time [s]; None on 000's failure = 000's 10 s; needed for any other.
    qf
        (n,) halt configuration [rad]; None = search it (HCOM), unless ``paper_qf`` (000's
        printed q_best, on 000's failure only).
    limits
        The limits the halt keeps (:class:`HaltLimits`: speed, acceleration, motor and brake
        torque limits as given, resolved on the arm by :func:`halt_limits`'s rule, and the
        margin kept free), or resolved :class:`JointLimits` used as they are.  Default: the
        rule's defaults, no margin.
    clearance
        Beyond 000 (issue 27): the clearance required between the arm's links, its spacecraft
        bus and keep-out volumes (:class:`~jointlock.collision.ClearanceSettings`; default:
        0.05 m).  The search excludes configurations closer than that; a given ``qf`` closer
        than that is refused; ``k`` keeps to the halts that keep it; a halt motion that still
        comes closer is reported (:attr:`HaltPlan.collision_free` False, the first line of the
        summary: which pair, when and by how much; ``feasible`` is the limits' verdict).
        ``ClearanceSettings.off()``: reported only (000's way; ``paper_qf`` is 000's
        configuration and is only reported).
    search
        How the halt configuration is searched (:class:`HaltSearch`: Monte Carlo samples,
        reachable configurations only); unused when ``qf`` or ``paper_qf`` gives it.
    motion
        How the halt motion is chosen (:class:`HaltMotionSettings`: solver, GA settings, time
        samples, smallest halt time, objective, preference for margin, moment point).
    base
        Base of the disturbance torque: ``"fixed"`` (000) or ``"floating"``; None: ``"fixed"``
        for a robot given by name (000's), the model's own base for a model.  The halt
        configuration is searched on J_F either way (000 §3.1.2).
    rng
        Seed of the Monte Carlo search and the GA (:mod:`jointlock._random`: ``None`` draws a
        fresh seed; the seed used is :attr:`HaltPlan.seed`).
    wheels
        Beyond 000 (issue 28): what the spacecraft's attitude control can absorb
        (:class:`~jointlock.analysis.attitude_control.WheelCapacity`: torque [N m], stored
        momentum [N m s]); the halt's peak base moment and the momentum it hands the wheels are
        judged against them (:meth:`HaltPlan.attitude_control`; over capacity: the summary's
        first line).  Default: reported, not judged.
    progress
        Show progress bars on stderr.
    state_source
        Where ``state`` comes from, in words, recorded in the result and printed with it
        (default: "000 §5.2" when ``state`` is None or is 000's on 000's scenario, else "given").
    **former
        The keywords these settings replaced (``vmax_deg``, ``amax_deg``, ``torque_max_Nm``,
        ``brake_max_Nm``, ``margin``; ``samples``, ``reachable``; ``solver``, ``ga``,
        ``n_samples``, ``minimum_T``, ``objective``, ``prefer_margin``, ``moment_about``): still
        accepted, each warning once (``FutureWarning``) with its new place
        (:mod:`jointlock.jobs.halt._settings`); one given both ways is a ``TypeError``.

    Raises
    ------
    ScenarioError
        Missing or malformed inputs.
    InfeasibleError
        The state at failure itself breaks a limit (no halt can help), or (with
        ``reachable=False``) nothing sampled satisfies the search's constraints.
    """
    settings = settings_from_keywords("plan_halt", former, {"limits": limits, "search": search, "motion": motion})
    spec, search, halting = settings["limits"], settings["search"], settings["motion"]
    clearance = clearance if clearance is not None else ClearanceSettings()
    for name, value, kind in (
        ("limits", spec, (HaltLimits, JointLimits)), ("clearance", clearance, (ClearanceSettings,)),
        ("search", search, (HaltSearch,)), ("motion", halting, (HaltMotionSettings,)),
    ):  # fmt: skip
        if not isinstance(value, kind):
            allowed = " or ".join(k.__name__ for k in kind)
            raise ScenarioError(f"{name} must be a {allowed}; got {type(value).__name__}")
    solver, ga, n_samples, minimum_T = halting.solver, halting.ga, halting.n_samples, halting.minimum_T
    objective, prefer_margin, moment_about = halting.objective, halting.prefer_margin, halting.moment_about
    samples, reachable = search.samples, search.reachable
    check_halt_settings(T, n_samples, samples, solver, ga, _names)
    state_given = state is not None
    model, state, T, base, paper = _arm_state_and_time(robot, state, locks, T, base, _state_names)
    model_torques = True  # the model's effort limits, not limits given: kept by the scan only
    if isinstance(spec, HaltLimits):
        joint_limits = halt_limits(
            model, spec.vmax_deg, spec.amax_deg, torque_max_Nm=spec.torque_max_Nm, brake_max_Nm=spec.brake_max_Nm,
            names=_names["limits"], torque_names=_names["torques"],
        )  # fmt: skip
        margin = spec.margin
        model_torques = spec.torque_max_Nm is None and spec.brake_max_Nm is None
    else:
        joint_limits, margin = spec, settings["margin"] if settings["margin"] is not None else 0.0
    paper_scenario = _is_paper_state(model, state, T, joint_limits)
    margin = as_real(margin, _names.get("margin", "margin"), lo=0.0, hi=MAX_MARGIN, error=ScenarioError)
    prefer_margin = as_real(
        prefer_margin, _names.get("prefer_margin", "prefer_margin"), lo=0.0, hi=MAX_MARGIN, error=ScenarioError
    )
    kept = joint_limits.scaled(1 - margin)
    notes: tuple[str, ...] = ()
    if solver != "scan" and kept.torque is not None and model_torques:
        # the model's own effort limits: kept by the exact scan only; reported, not kept, by the others
        kept = replace(kept, torque=None)
        notes = (f"the model's motor torque limits are reported, not kept: solver {solver!r} keeps speed and "
                 "acceleration limits only (--solver scan keeps torque limits too)",)  # fmt: skip
    _check_start_torques(model, state, base, kept, margin, _names)
    if state_source is None:
        state_source = "given" if state_given and not paper_scenario else "000 §5.2"
    rng = resolve_seed(rng)  # one seed for the search and the GA, recorded
    configuration, reach_note = None, None
    if qf is not None:
        qf_arr, qf_source = np.asarray(qf, dtype=float), _names["qf"]
    elif paper_qf:
        if not paper:
            raise ScenarioError(
                "paper_qf is 000's q_best for halt7 with joint 4 locked at 0 deg only; give qf"
            )
        qf_arr, qf_source = (
            joint_vector_deg(model, list(p000.SCENARIO["qf_deg"]), "paper_qf"),
            "000's printed q_best",
        )
    else:
        _check_start(model, state, T, joint_limits, _names["state"])
        if margin:
            _check_start_margin(model, state, T, kept, margin, _names)
        configuration, reach_note = _search_halt_configuration(
            model, state, T, kept, samples=samples, seed=rng, reachable=reachable,
            per_joint=solver == "vector", progress=progress, clearance=clearance,
        )  # fmt: skip
        qf_arr = np.asarray(configuration.q_best, dtype=float)
        seed_text = "a numpy Generator" if isinstance(rng, np.random.Generator) else rng
        qf_source = f"optimal halt configuration (Monte Carlo, {samples} samples, seed {seed_text})"
    problem = HaltProblem(
        model, state.q, state.dq, state.ddq, qf_arr, T, kept.velocity, kept.acceleration,
        base=base, n_samples=n_samples, moment_about=moment_about, tau_max=kept.torque, brake_max=kept.brake,
        objective=objective,
    )  # fmt: skip
    if qf is not None:  # checked by HaltProblem first: one value or one per healthy joint
        _check_qf_clearance(model, problem.qf, clearance, _names["qf"])
    bar = Progress(ga.n_gen, "GA generations", enabled=None if progress else False) if solver == "ga" else None
    def solve(k_bounds: tuple[float, float] | None = None, with_solver: Solver | None = None) -> HaltMotion:
        return optimal_halt_motion(
            problem, solver=with_solver or solver, rng=rng, ga_settings=ga, find_minimum_T=minimum_T,
            progress=bar if k_bounds is None and with_solver is None else None, prefer_margin=prefer_margin,
            k_bounds=k_bounds,
        )  # fmt: skip

    chosen = solve()
    if bar is not None:
        bar.close()
    chosen, clear_note = _keep_clear(chosen, clearance, solve)
    notes += clear_note
    minimum_T_clear = None
    if chosen.minimum_T is not None and _keeps_clearance_as_constraint(chosen, clearance):
        minimum_T_clear = minimum_clear_halt_time(problem, clearance.margin, clearance.keep_out, start=chosen.minimum_T)
    return HaltPlan(
        motion=chosen,
        limits=joint_limits,
        qf_source=qf_source,
        paper_scenario=paper_scenario,
        configuration=configuration,
        reachability=reach_note,
        samples=samples,
        reachability_requested=reachable,
        seed=None if isinstance(rng, np.random.Generator) else rng,
        state_source=state_source,
        margin=margin,
        notes=notes,
        clearance_settings=clearance,
        wheels=wheels if wheels is not None else WheelCapacity(),
        minimum_T_clear=minimum_T_clear,
    )


def _keeps_clearance_as_constraint(motion: HaltMotion, settings: ClearanceSettings) -> bool:
    """Whether the halt's smallest clear halt time applies: the clearance required, shapes to
    check, and a shared ``k`` (the smallest clear halt time is a shared ``k``'s: not computed
    for a per-joint halt, whose ``minimum_T`` is the limits' alone)."""
    return settings.required and not motion.per_joint and bool(collision_pairs(motion.problem.model, settings.keep_out).names)


def _keep_clear(
    motion: HaltMotion, settings: ClearanceSettings, solve: Any
) -> tuple[HaltMotion, tuple[str, ...]]:
    """The halt motion keeping the clearance required (issue 27): the optimum when its halt
    keeps it; else the best optimum over the stretches of the feasible ``k`` whose halts keep
    it (:func:`~jointlock.planning.halt_motion.clear_k_segments`, each solved with
    ``k_bounds``; the result keeps the limits' interval of ``k``, the note gives the stretch);
    else the optimum as it is (reported as colliding).  The per-joint solver's halt when it keeps
    the clearance; else the best shared ``k`` of solver "scan" that keeps it, with a note.  Returns
    the motion and the notes."""
    problem = motion.problem
    if not settings.required or not motion.feasible or not collision_pairs(problem.model, settings.keep_out).names:
        return motion, ()
    margin, keep_out = settings.margin, settings.keep_out
    if motion.per_joint:
        if clearance_shortfall(problem, np.asarray(motion.k), margin, keep_out, per_joint=True) <= 0:
            return motion, ()
        shared, notes = _keep_clear(solve(None, "scan"), settings, lambda segment: solve(segment, "scan"))
        head = f"solver 'vector': the per-joint optimum comes closer than allowed ({margin:g} m)"
        if shared.feasible and clearance_shortfall(problem, np.asarray(float(shared.k)), margin, keep_out) <= 0:
            k, record = clear_per_joint_k(problem, motion.joint_intervals, float(shared.k), margin, keep_out)
            if np.ndim(k) == 1 and not np.all(k == k[0]):
                # the shared solve's own notes describe the shared k, not this halt: not repeated
                return _per_joint_motion(shared, k, record, motion), (
                    f"{head}; the halt is the best per-joint k found among the halts that keep it (Powell from the "
                    f"best shared k that keeps it, {float(shared.k) * 180.0 / math.pi:.6g} deg/s^6, on the limits the "
                    "vector solver keeps)",
                )
            return shared, (
                f"{head}; the halt is the best shared k that keeps the clearance (solver 'scan', on the limits the "
                "vector solver keeps): no per-joint k that keeps it does better",
            ) + notes
        why = "no shared k keeps the clearance either" if shared.feasible else "no shared k keeps the limits"
        return motion, (f"{head}, and {why}: the halt below is the per-joint optimum over the limits alone",)
    if clearance_shortfall(problem, np.asarray(float(motion.k)), margin, keep_out) <= 0:
        return motion, ()
    lo, hi = (float(v) for v in motion.k_interval)
    scale = math.pi / 180.0  # deg/s^6
    candidates = [solve(segment) for segment in clear_k_segments(problem, lo, hi, margin, keep_out)]
    candidates = [m for m in candidates if m.feasible]
    if not candidates:
        return motion, (
            f"no k in the feasible [{lo / scale:.6g}, {hi / scale:.6g}] deg/s^6 gives a halt that keeps the "
            f"clearance ({margin:g} m): the halt below is the optimum over the limits alone",
        )
    best = min(candidates, key=lambda m: m.objective_value)
    stretch = tuple(float(v) / scale for v in best.k_interval)
    return replace(best, k_interval=motion.k_interval, joint_intervals=motion.joint_intervals), (
        f"k moved from {float(motion.k) / scale:.6g} to {float(best.k) / scale:.6g} deg/s^6 to keep the clearance "
        f"({margin:g} m): the halts of k in [{stretch[0]:.6g}, {stretch[1]:.6g}] deg/s^6 keep it, the optimum "
        "over the limits alone came closer",
    )


def _per_joint_motion(shared: HaltMotion, k: np.ndarray, record: Mapping[str, Any], vector: HaltMotion) -> HaltMotion:
    """The halt at the per-joint ``k`` (n,) [rad/s^6], built on the shared-``k`` halt ``shared``
    (same problem): its torque, verdicts and objective at ``k``, the vector solver's intervals."""
    problem = shared.problem
    violations = constraint_violations(problem, k, per_joint=True)
    return replace(
        shared,
        k=k,
        solver="vector",
        global_torque=float(global_base_torque(problem, k, per_joint=True)),
        feasible=not violations,
        violations=violations,
        objective_value=float(halt_objective(problem, k, per_joint=True)),
        k_interval=vector.k_interval,
        joint_intervals=vector.joint_intervals,
        settings={**vector.settings, "scipy": dict(record)},
        k_segments=None,
        k_optimum=None,
    )


def _check_qf_clearance(model: ArmModel, qf: np.ndarray, settings: ClearanceSettings, name: str) -> None:
    """Refuse a given halt configuration closer than the clearance required (naming the pair)."""
    if not settings.required or not collision_pairs(model, settings.keep_out).names:
        return
    result = clearance_of(model, qf, keep_out=settings.keep_out, margin=settings.margin)
    if bool(result.colliding()):
        raise ScenarioError(
            f"{name}: the halt configuration keeps {float(result.distance):+.3f} m between {result.pair_at()} "
            f"(clearance required: {settings.margin:g} m); choose another, or turn the requirement off "
            "(limits.check_clearance = false, --no-clearance)"
        )


def halt_from_scenario(
    data: Mapping[str, Any], previous: Mapping[str, JobResult], *, progress: bool = False
) -> HaltPlan:
    """The ``[halt]`` job of a resolved scenario (``Scenario.data``): the state, limits and
    failure of the scenario; the halt configuration from ``[halt] qf_deg``, 000's q_best
    (``paper_qf``), else the ``halt_config`` job that ran before it, else searched here."""
    t, st, lim = data["halt"], data["state"], data["limits"]
    locks = scenario_locks(data)
    base = t.get("base") or data["base"]
    model = halt_model(data["robot"], locks, base, chain=UrdfChain.from_fields(data))
    state = FailureState.from_degrees(
        model,
        st["q0_deg"],
        st["dq0_deg"],
        st["ddq0_deg"],
        names=("state.q0_deg", "state.dq0_deg", "state.ddq0_deg"),
    )
    names = dict(SCENARIO_NAMES)
    from_task = task_given(data) and data["failure"]["time_s"] is not None
    state_source = f"task at t = {data['failure']['time_s']:g} s" if from_task else None
    qf = None
    if t["qf_deg"] is not None:
        qf = joint_vector_deg(model, list(t["qf_deg"]), "halt.qf_deg")
    elif not t["paper_qf"] and "halt_config" in previous:
        qf = np.asarray(cast(Any, previous["halt_config"]).q_best, dtype=float)  # the typed result, in radians
        names["qf"] = "the halt_config job's optimal halt configuration"
    plan = plan_halt(
        model,
        state,
        T=float(t["T"]),
        qf=qf,
        paper_qf=bool(t["paper_qf"]) and qf is None,
        limits=HaltLimits(
            vmax_deg=lim["vmax_deg"], amax_deg=lim["amax_deg"], torque_max_Nm=lim["torque_max_Nm"],
            brake_max_Nm=lim["brake_max_Nm"], margin=float(t["margin"]),
        ),
        search=HaltSearch(samples=int(t["samples"])),
        motion=HaltMotionSettings(
            solver=t["solver"], ga=GASettings(n_pop=int(t["population"]), n_gen=int(t["generations"])),
            n_samples=int(t["n_samples"]), minimum_T=bool(t["minimum_T"]), objective=t["objective"],
            prefer_margin=float(t["prefer_margin"]), moment_about=t["moment_about"],
        ),
        base=base,
        rng=data["seed"],
        progress=progress,
        clearance=scenario_clearance(data),
        wheels=WheelCapacity(
            data["spacecraft"]["wheel_torque_max_Nm"], data["spacecraft"]["wheel_momentum_max_Nms"]
        ),
        state_source=state_source,
        _names=names,
    )
    if from_task and not data["failure"].get("also_locked_deg"):
        plan = replace(plan, task_completion=_task_completion(data, base))
    return plan


#: The remaining times of a sampled task (a CSV/NPZ trajectory) at which the halt job checks
#: that the rest of the task is still reachable (an IK solve each, ~0.06 s on a 7-joint arm).
COMPLETION_SAMPLES = 6


def _task_completion(data: Mapping[str, Any], base: str) -> TaskCompletion:
    """Whether the scenario's task could be finished with ``failure.joint`` locked from
    ``failure.time_s`` on (:func:`jointlock.planning.completion.task_completion`): its remaining
    waypoints, or :data:`COMPLETION_SAMPLES` times of a sampled task."""
    task = scenario_task(dict(data))
    assert task is not None  # from_task: the scenario has one
    whole = halt_model(data["robot"], None, base, chain=UrdfChain.from_fields(data))
    fail = data["failure"]
    return task_completion(whole, task, int(fail["joint"]), float(fail["time_s"]), samples=COMPLETION_SAMPLES)
