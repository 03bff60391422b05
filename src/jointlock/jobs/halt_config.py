"""The ``halt_config`` job (``jointlock halt-config``): the optimal halt configuration of an arm
with a locked joint (seed 000 §3, HCOM), optionally among the configurations 000's halt
polynomial can reach from the state at failure within a halt time.

:func:`study_halt_configuration` runs it on a locked model with typed inputs and returns a
:class:`HaltConfigurationStudy`: the search (:class:`~jointlock.planning.halt_config.HaltConfiguration`),
the limits of the reachability constraint and where they came from, with ``to_dict()`` /
``summary()`` / ``write(out)`` giving the command's JSON, text and files.
:func:`halt_config_from_scenario` runs the ``[halt_config]`` table of a scenario.
"""

from __future__ import annotations

import io
import math
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any, ClassVar, Literal

import numpy as np

from .._deprecate import renamed_keyword
from ..analysis.ability import INDEX_NAMES, Assignment, JacobianKind
from ..collision import ClearanceSettings
from ..errors import ConfigurationError
from ..io.files import atomic_write_bytes, atomic_write_json, with_svg, write_figure
from ..locking import lock_joints
from ..model import ArmModel
from ..papers import p000
from ..planning.halt_config import (
    HaltConfiguration,
    HaltReachability,
    ReachabilityBound,
    optimal_halt_configuration,
)
from ..plots.halt_config import section_figures
from ..progress import Progress
from ..robots import UrdfChain, load_robot
from ._common import JobResult, scenario_clearance, scenario_locks
from .halt import SCENARIO_LIMIT_NAMES, FailureState, JointLimits, halt_limits, limits_text

#: Below this many samples no progress bar is shown (the run takes well under a second).
PROGRESS_MIN_SAMPLES = 20000

#: Resolution of the section plots [dots per inch].
SECTION_DPI = 110

ReachabilityMethod = Literal["exact", "bound"]


@dataclass(frozen=True)
class ReachabilitySettings:
    """Require the halt configuration to be reachable from the state at failure within the
    halt time, under the speed and acceleration limits (given to
    :func:`study_halt_configuration`).

    Attributes
    ----------
    state
        The state of the healthy joints at failure: (n,) angles [rad], rates [rad/s],
        accelerations [rad/s^2].
    halt_time
        ``T`` [s], > 0.
    method
        ``"exact"`` (default): 000's halt polynomial (eq. 27) must have a feasible ``k``
        (:class:`~jointlock.planning.halt_config.HaltReachability`); ``"bound"``: only the
        bang-bang box of rest angles (:class:`~jointlock.planning.halt_config.ReachabilityBound`,
        necessary, not sufficient; ``state.ddq`` is recorded only).
    per_joint_k
        Exact reachability with one ``k`` per joint instead of a shared ``k`` (000).
    """

    state: FailureState
    halt_time: float
    method: ReachabilityMethod = "exact"
    per_joint_k: bool = False

    def __post_init__(self) -> None:
        t = self.halt_time
        if (
            isinstance(t, bool)
            or not isinstance(t, (int, float, np.number))
            or not (math.isfinite(t) and t > 0)
        ):
            raise ConfigurationError(f"halt_time must be a finite number > 0 [s]; got {t!r}")
        if not isinstance(self.state, FailureState):
            raise ConfigurationError(f"state must be a FailureState; got {type(self.state).__name__}")
        if self.method not in ("exact", "bound"):
            raise ConfigurationError(f"method must be 'exact' or 'bound'; got {self.method!r}")
        object.__setattr__(self, "halt_time", float(t))
        object.__setattr__(self, "per_joint_k", bool(self.per_joint_k))

    def constraint(self, limits: JointLimits) -> ReachabilityBound | HaltReachability:
        """The constraint of the search under ``limits``."""
        s = self.state
        if self.method == "bound":
            return ReachabilityBound(s.q, s.dq, self.halt_time, limits.velocity, limits.acceleration, s.ddq)
        return HaltReachability(
            s.q, s.dq, s.ddq, self.halt_time, limits.velocity, limits.acceleration, per_joint=self.per_joint_k
        )


@dataclass(frozen=True, eq=False)  # arrays inside: compare to_dict() instead
class HaltConfigurationStudy(JobResult):
    """The result of :func:`study_halt_configuration`.

    Attributes
    ----------
    robot
        Name of the arm model.
    configuration
        The search: best configuration, best sample, runner-up, weights, the sample set
        ((K, n) angles [rad] and their CP) and the reachability constraint applied.
    limits
        Speed and acceleration limits of the reachability constraint and where each came
        from; None without a reachability constraint.
    """

    job: ClassVar[str] = "halt_config"

    robot: str
    configuration: HaltConfiguration
    limits: JointLimits | None = None

    @property
    def q_best(self) -> np.ndarray:
        """(n,) the optimal halt configuration, healthy joints [rad]."""
        return self.configuration.q_best

    @property
    def cp_best(self) -> float:
        """CP at :attr:`q_best`."""
        return self.configuration.cp_best

    def to_dict(self) -> dict[str, Any]:
        """The JSON object of ``jointlock halt-config --json`` (angles in degrees)."""
        data = {"robot": self.robot, **self.configuration.to_dict()}
        if self.limits is not None and data.get("reachability") is not None:
            data["reachability"]["velocity_limit_source"] = list(self.limits.velocity_source)
            data["reachability"]["acceleration_limit_source"] = list(self.limits.acceleration_source)
        return data

    def summary(self) -> list[str]:
        """The lines ``jointlock halt-config`` prints."""
        r = self.configuration
        reach = r.reachability
        out = []
        locked = ", ".join(f"joint {k} at {math.degrees(v):g} deg" for k, v in r.locked.items())
        out.append(
            f"{self.robot}: healthy joints {list(r.joint_numbers)}, locked: {locked}, base: {r.base}, "
            f"Jacobian: {r.jacobian}"
        )
        if r.jacobian == "generalized" and r.base == "fixed":
            out.append(
                "  (fixed base: the generalized Jacobian is the fixed-base one; --base floating for 000's J_F)"
            )
        out.append(f"samples: {r.samples}, seed: {r.seed}")
        if r.colliding_samples is not None:
            out.append(
                f"clearance required: {r.clearance_min_m:g} m (links, spacecraft bus, keep-outs): "
                f"{r.colliding_samples} of {r.samples} samples excluded"
            )
        if r.best_clearance is not None:
            out.append(f"best: {r.best_clearance.summary()}")
        if isinstance(reach, HaltReachability):
            k_txt = ""
            if r.k_range is not None:
                lo, hi = np.degrees(r.k_range)
                k_txt = f", shared k in [{lo:.4g}, {hi:.4g}] deg/s^6"
            out.append(
                f"reachability (exact, halt polynomial, {'one k per joint' if reach.per_joint else 'shared k'}, "
                f"T = {reach.halt_time:g} s): {r.reachable_samples} of {r.samples} samples reachable"
                f"{k_txt}; box {_fmt_q(r.lower)} .. {_fmt_q(r.upper)} deg"
            )
        elif reach is not None:
            out.append(f"reachability: bang-bang bound, box {_fmt_q(r.lower)} .. {_fmt_q(r.upper)} deg")
        if reach is not None and self.limits is not None:
            nums, lim = r.joint_numbers, self.limits
            out.append(
                f"  speed limits: {limits_text(nums, reach.velocity_limit, lim.velocity_source, 'deg/s')}"
            )
            out.append(
                "  acceleration limits: "
                + limits_text(nums, reach.acceleration_limit, lim.acceleration_source, "deg/s^2")
            )
        out += ["", f"{'':<14}{'q [deg]':<62}{'CP':>9}{'sigma_min':>11}{'kappa':>11}{'w':>11}"]
        for label, c in (("best", r.best), ("best sample", r.best_sample), ("runner-up", r.runner_up)):
            if c is None:
                continue
            out.append(
                f"{label:<14}{_fmt_q(c.q):<62}{c.cp:9.5f}{c.sigma_min:11.5g}{c.condition_number:11.5g}"
                f"{c.manipulability:11.5g}"
            )
        gain = r.refinement_gain
        rel = f"{100 * gain / abs(r.best_sample.cp):+.2f} %" if r.best_sample.cp else "n/a: CP of the best sample is 0"
        out.append(f"refinement gain: {gain:+.5f} CP ({rel}), {r.refine_evaluations} evaluations")
        w, ahp = r.weights, r.ability.ahp
        out += [
            "",
            f"weights ({r.ability.assignment} reading, "
            f"{'renormalised' if r.ability.renormalize else 'not renormalised'}):",
            f"  {'':<10}" + "".join(f"{name:>18}" for name in INDEX_NAMES),
        ]
        for key in ("ahp", "entropy", "combined"):
            out.append(f"  {key:<10}" + "".join(f"{w[key][name]:18.5f}" for name in INDEX_NAMES))
        out.append(
            f"  AHP: lambda_max = {ahp.lambda_max:.6g}, CI = {ahp.ci:.3g}, CR = {ahp.cr:.3g} (RI = {ahp.ri:g})"
        )
        return out

    def samples_csv(self) -> bytes:
        """The sample set as CSV: angles [deg], the three indices and CP, one row per sample."""
        r = self.configuration
        ind = r.indices_samples
        table = np.column_stack(
            [np.degrees(r.q_samples), ind.sigma_min, ind.condition_number, ind.manipulability, r.cp_samples]
        )
        header = ",".join([f"q{n}_deg" for n in r.joint_numbers] + list(INDEX_NAMES) + ["cp"])
        buf = io.StringIO()
        np.savetxt(buf, table, delimiter=",", header=header, comments="", fmt="%.10g")
        return buf.getvalue().encode("utf-8")

    def samples_npz(self) -> bytes:
        """The sample set as compressed NPZ (angles [rad], joint numbers, indices, CP)."""
        r = self.configuration
        ind = r.indices_samples
        buf = io.BytesIO()
        np.savez_compressed(
            buf,
            q_rad=r.q_samples,
            joint_numbers=np.array(r.joint_numbers),
            sigma_min=ind.sigma_min,
            condition_number=ind.condition_number,
            manipulability=ind.manipulability,
            cp=r.cp_samples,
        )
        return buf.getvalue()

    def file_names(self) -> list[str]:
        """The names :meth:`write` writes (the command's JSON lists them as paths)."""
        names = ["result.json", "samples.npz", "samples.csv"]
        return with_svg(names + [f"section_joint{number}.png" for number in self.configuration.joint_numbers])

    def write(self, out: str | Path) -> list[str]:
        """Write ``result.json``, ``samples.npz``, ``samples.csv`` and one section plot per
        healthy joint (``section_joint<N>.png``, 000 Fig. 7) into ``out``; returns the names."""
        out = Path(out)
        atomic_write_json(out / "result.json", self.to_dict())
        atomic_write_bytes(out / "samples.npz", self.samples_npz())
        atomic_write_bytes(out / "samples.csv", self.samples_csv())
        write_section_plots(self.configuration, out)
        return self.file_names()


def write_section_plots(result: Any, folder: str | Path, *, dpi: int = SECTION_DPI) -> list[Path]:
    """Write the section plots (:func:`jointlock.plots.halt_config.section_figures`, 000 Fig. 7)
    of a search (a :class:`~jointlock.planning.halt_config.HaltConfiguration` or a
    :class:`HaltConfigurationStudy`) as ``section_joint<N>.png`` in ``folder``; returns the paths."""
    folder = Path(folder)
    configuration = getattr(result, "configuration", result)
    paths = []
    for number, fig in zip(configuration.joint_numbers, section_figures(configuration)):
        write_figure(fig, folder, f"section_joint{number}.png", dpi=dpi)
        paths.append(folder / f"section_joint{number}.png")
    return paths


def _fmt_q(q: np.ndarray) -> str:
    return "[" + ", ".join(f"{v:8.3f}" for v in np.degrees(q)) + "]"


@renamed_keyword(old="length", new="characteristic_length")
def study_halt_configuration(
    model: ArmModel,
    *,
    samples: int = p000.SAMPLES,
    rng: int | np.random.Generator | None = None,
    jacobian: JacobianKind = "generalized",
    assignment: Assignment = "equation",
    renormalize: bool = False,
    refine: bool = True,
    characteristic_length: float | None = None,
    reachability: ReachabilitySettings | None = None,
    vmax_deg: float | list[float] | None = None,
    amax_deg: float | list[float] | None = None,
    limit_names: tuple[str, str] = ("vmax_deg", "amax_deg"),
    progress: bool = False,
    clearance: ClearanceSettings | None = None,
) -> HaltConfigurationStudy:
    """The optimal halt configuration of a locked arm (000 HCOM: Monte Carlo over the healthy
    joints, CP from AHP + entropy weights, eqs. 8-24), refined locally, as
    ``jointlock halt-config`` computes it.

    Parameters
    ----------
    model
        The arm after the lock (:func:`jointlock.lock`), with at least one locked joint.
    samples
        Monte Carlo samples ``K`` (000's, :data:`jointlock.papers.p000.SAMPLES`), >= 2.
    rng
        Seed or ``numpy.random.Generator``; None draws a fresh seed (recorded in the result).
    jacobian
        ``"generalized"`` (000's ``J_F``; differs from ``"fixed"`` only on a floating base) or
        ``"fixed"``.
    assignment
        Which index gets AHP weight 1/2: ``"equation"`` (condition number, 000 eq. 19) or
        ``"text"`` (manipulability, 000 §5.1).
    renormalize
        Divide the combined weights by their sum (000 eq. 18 does not).
    refine
        Polish the best samples locally (False: plain Monte Carlo, as 000).
    characteristic_length
        ``L`` [m] dividing the Jacobian's linear rows; None: raw (000).  Formerly ``length=`` (a
        deprecated alias).
    reachability
        Keep to configurations reachable from the state at failure within ``T``; None: the
        whole joint ranges (000).
    vmax_deg, amax_deg
        Speed [deg/s] and acceleration [deg/s^2] limits of the reachability constraint: one
        value or one per healthy joint, by ``jointlock halt``'s rule
        (:func:`jointlock.jobs.halt.halt_limits`: the speed limit capped by the model's own,
        defaults the model's, else 000's); used only with ``reachability``.
    limit_names
        How the two limits are named in the limit sources (the CLI passes its options).
    progress
        Show a progress bar on stderr (when it is a terminal).
    clearance
        Beyond 000 (issue 27): the clearance a halt configuration must keep between the arm's
        links, its spacecraft bus and keep-out volumes (:class:`~jointlock.collision.
        ClearanceSettings`; default: :data:`~jointlock.collision.DEFAULT_CLEARANCE_MIN_M`);
        closer samples are excluded and counted.  ``ClearanceSettings.off()``: 000's search,
        the clearance only reported.

    Returns
    -------
    HaltConfigurationStudy

    Raises
    ------
    ConfigurationError
        Invalid inputs (named as the parameters).
    InfeasibleError
        The state at failure breaks a limit, or no configuration is reachable within ``T``.
    """
    if isinstance(samples, bool) or not isinstance(samples, (int, np.integer)) or samples < 2:
        raise ConfigurationError(f"samples must be an integer >= 2; got {samples!r}")
    if not model.locked:
        raise ConfigurationError(
            "study_halt_configuration needs a locked model (jointlock.lock(model, J, angle))"
        )
    length = characteristic_length
    if length is not None and not (math.isfinite(length) and length > 0):
        raise ConfigurationError(f"characteristic_length must be a finite length > 0 [m]; got {length}")
    if reachability is not None and not isinstance(reachability, ReachabilitySettings):
        raise ConfigurationError(f"reachability must be ReachabilitySettings or None; got {reachability!r}")
    clearance = clearance if clearance is not None else ClearanceSettings()
    if not isinstance(clearance, ClearanceSettings):
        raise ConfigurationError(f"clearance must be ClearanceSettings or None; got {type(clearance).__name__}")
    limits = constraint = None
    if reachability is not None:
        limits = halt_limits(model, vmax_deg, amax_deg, names=limit_names)
        constraint = reachability.constraint(limits)
    with Progress(samples, "sampling", enabled=None if progress else False) as bar:
        result = optimal_halt_configuration(
            model,
            samples=samples,
            rng=rng,
            jacobian=jacobian,
            refine=refine,
            assignment=assignment,
            renormalize=renormalize,
            characteristic_length=length,
            reachability=constraint,
            progress=bar,
            clearance_min_m=clearance.min_m,
            keep_out=clearance.keep_out,
        )
    return HaltConfigurationStudy(robot=model.name, configuration=result, limits=limits)


def halt_config_from_scenario(
    data: Mapping[str, Any], previous: Mapping[str, JobResult], *, progress: bool = False
) -> HaltConfigurationStudy:
    """The ``[halt_config]`` job of a resolved scenario (``Scenario.data``): the robot, failure,
    base and seed of the scenario; with ``halt_config.reachable`` the state at failure
    (``[state]``), the halt time (``halt_config.halt_time``, else ``halt.T``) and the limits
    (``[limits]``).  ``previous`` is not used (the job runs first).  The progress bar is
    shown from :data:`PROGRESS_MIN_SAMPLES` samples on, as the command does."""
    t, st, lim = data["halt_config"], data["state"], data["limits"]
    model = load_robot(data["robot"], base=t.get("base") or data["base"], chain=UrdfChain.from_fields(data))
    locks = scenario_locks(data)
    if locks:
        model = lock_joints(model, locks)
    reach = None
    if t["reachable"]:
        state = FailureState.from_degrees(
            model,
            st["q0_deg"],
            st["dq0_deg"] or None,
            st["ddq0_deg"] or None,
            names=("state.q0_deg", "state.dq0_deg", "state.ddq0_deg"),
        )
        halt_time = t["halt_time"] if t["halt_time"] is not None else data["halt"]["T"]
        reach = ReachabilitySettings(state, float(halt_time))
    samples = int(t["samples"])
    return study_halt_configuration(
        model,
        samples=samples,
        rng=data["seed"],
        jacobian=t["jacobian"],
        assignment=t["assignment"],
        renormalize=bool(t["renormalize"]),
        refine=not t["no_refine"],
        characteristic_length=None if t["length"] is None else float(t["length"]),
        reachability=reach,
        vmax_deg=lim["vmax_deg"],
        limit_names=SCENARIO_LIMIT_NAMES,
        amax_deg=lim["amax_deg"],
        progress=progress and samples >= PROGRESS_MIN_SAMPLES,
        clearance=scenario_clearance(data),
    )
