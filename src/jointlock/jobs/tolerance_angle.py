"""Job ``tolerance_angle``: the fault-tolerance angle gamma of seed 002 (Figs. 5-8).

Rotate the pose of a desired configuration about the tool x axis by gamma, solve the full-arm
closed-form IK on the branch of that configuration for every gamma of a sweep, and find the
gammas at which the locked joint sits exactly at its locked angle (002 eq. 18 and steps 1-5).
The command ``jointlock tolerance-angle`` is this call plus printing.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any, ClassVar

import numpy as np
from numpy.typing import ArrayLike

from ..errors import ScenarioError
from ..io.files import atomic_write_json, with_svg, write_figure
from ..kinematics import ee_pose
from ..model import ArmModel
from ..planning.replan import GammaRoot, GammaSweep, LockRange, absorbable_range, gamma_sweep, gammas_for_lock
from ..progress import Progress
from ..robots import UrdfChain, load_robot
from ._common import JobResult, scenario_lock

#: Most gamma samples of one sweep (steps of about 0.0018 deg over +-180 deg; some 1.5 GB and
#: 15 s): each is an IK solution, and a tiny step would otherwise try to allocate many GiB.
MAX_GAMMA_SAMPLES = 200_000

#: Size of the two six-panel figures [inch] and of the locked-joint figure.
PANELS_FIGSIZE = (12.0, 6.0)
LOCKED_FIGSIZE = (6.0, 4.0)


def gamma_sample_count(gamma_limit_deg: float, step_deg: float) -> int:
    """Number of gamma samples of a sweep over ``[-gamma_limit_deg, gamma_limit_deg]`` in steps
    of about ``step_deg`` [deg] (both ends included); a step so small that the count overflows
    counts as 10**15 (far above any allowed sweep)."""
    limit, step = math.radians(gamma_limit_deg), math.radians(step_deg)
    with np.errstate(over="ignore", divide="ignore"):
        ratio = float(np.float64(2 * limit) / np.float64(step)) if step > 0 else math.inf
    return int(round(ratio)) + 1 if ratio < 1e15 else 10**15


@dataclass(frozen=True, eq=False)  # arrays inside: compare to_dict() instead
class ToleranceAngleResult(JobResult):
    """The gamma sweep of one desired configuration and the gammas absorbing a lock.

    Attributes
    ----------
    robot
        Name of the arm.
    q_target_deg
        (6,) the desired configuration, every joint, as given [deg].
    joint, angle
        The locked joint (1-based) and its angle [rad].
    gamma_limit_deg, zoom_deg, step_deg
        The sweep's half-width, the narrow range's half-width and the step [deg].
    sweep
        Full-arm IK along the sweep (``sweep.gammas`` (G,) [rad], ``sweep.q`` (G, 6) [rad]).
    wide, narrow
        Lock angles of ``joint`` absorbable within ``|gamma| <= gamma_limit`` and within
        ``|gamma| <= min(zoom, gamma_limit)`` (002: 48..123 deg and 59.2..60.8 deg).
    roots
        Every gamma within the limit that puts ``joint`` at ``angle``, smallest ``|gamma|``
        first (empty when the lock cannot be absorbed); the first is the one chosen.
    """

    job: ClassVar[str] = "tolerance_angle"

    robot: str
    q_target_deg: tuple[float, ...]
    joint: int
    angle: float
    gamma_limit_deg: float
    zoom_deg: float
    step_deg: float
    sweep: GammaSweep
    wide: LockRange
    narrow: LockRange
    roots: tuple[GammaRoot, ...]

    @property
    def chosen(self) -> GammaRoot | None:
        """The root of smallest ``|gamma|``, or None."""
        return self.roots[0] if self.roots else None

    def absorbable_range_deg(self) -> dict[str, list[float]]:
        """``{"gamma_within_<limit>_deg": [lower, upper], "gamma_within_<zoom>_deg": ...}`` [deg]."""
        return {
            f"gamma_within_{self.gamma_limit_deg:g}_deg": [
                math.degrees(self.wide.lower),
                math.degrees(self.wide.upper),
            ],
            f"gamma_within_{self.zoom_deg:g}_deg": [
                math.degrees(self.narrow.lower),
                math.degrees(self.narrow.upper),
            ],
        }

    def to_dict(self) -> dict[str, Any]:
        """The JSON object of ``jointlock tolerance-angle --json`` (without ``files``)."""
        ch = self.chosen
        return {
            "robot": self.robot,
            "q_target_deg": list(self.q_target_deg),
            "lock": {"joint": self.joint, "angle_deg": math.degrees(self.angle)},
            "branch": self.sweep.branch,
            "absorbable_range_deg": self.absorbable_range_deg(),
            "roots": [
                {"gamma_deg": math.degrees(r.gamma), "q_deg": np.degrees(r.q_full)} for r in self.roots
            ],
            "chosen": None
            if ch is None
            else {"gamma_deg": math.degrees(ch.gamma), "q_deg": np.degrees(ch.q_full)},
        }

    def summary(self) -> list[str]:
        """The lines ``jointlock tolerance-angle`` prints."""
        joint, angle_deg = self.joint, math.degrees(self.angle)
        lines = [
            f"{self.robot}: gamma sweep on IK branch {self.sweep.branch}, joint {joint} locked at {angle_deg:g} deg"
        ]
        for key, (lo, hi) in self.absorbable_range_deg().items():
            lines.append(
                f"  lock angles of joint {joint} absorbable with {key.replace('_', ' ')}: {lo:.4f} .. {hi:.4f} deg"
            )
        if not self.roots:
            lines.append(
                f"  no gamma within +-{self.gamma_limit_deg:g} deg puts joint {joint} at {angle_deg:g} deg"
            )
        for r in self.roots:
            q = " ".join(f"{v:9.4f}" for v in np.degrees(r.q_full))
            lines.append(f"  gamma = {math.degrees(r.gamma):10.5f} deg   q [deg] = {q}")
        return lines

    def file_names(self) -> list[str]:
        """The names :meth:`write` writes (its JSON lists them as paths)."""
        return with_svg(["joints_vs_gamma.png", "joints_vs_gamma_zoom.png", "locked_joint_vs_gamma.png", "sweep.json"])

    def write(self, out: str | Path) -> list[str]:
        """Write ``joints_vs_gamma.png`` (002 Fig. 7), ``joints_vs_gamma_zoom.png`` (Fig. 8),
        ``locked_joint_vs_gamma.png`` (Figs. 5-6) and ``sweep.json`` (:meth:`to_dict` plus the
        sweep: ``gamma_deg`` (G,), ``q_deg`` (G, 6)) to the folder ``out``; returns their
        names."""
        from ..plots._common import offscreen_figure
        from ..plots.tolerance_angle import plot_joints_vs_gamma, plot_locked_joint_vs_gamma

        folder = Path(out)
        folder.mkdir(parents=True, exist_ok=True)
        zoom = math.degrees(math.radians(self.zoom_deg))  # as the command always computed it
        for name, window in (("joints_vs_gamma.png", None), ("joints_vs_gamma_zoom.png", zoom)):
            fig = plot_joints_vs_gamma(
                self.sweep,
                self.joint,
                self.angle,
                self.roots,
                window_deg=window,
                fig=offscreen_figure(PANELS_FIGSIZE),
            )
            write_figure(fig, folder, name, tight=False)
        fig = offscreen_figure(LOCKED_FIGSIZE)
        plot_locked_joint_vs_gamma(self.sweep, self.joint, self.angle, ax=fig.add_subplot())
        fig.tight_layout()
        write_figure(fig, folder, "locked_joint_vs_gamma.png", tight=False)
        sweep = {"gamma_deg": np.degrees(self.sweep.gammas), "q_deg": np.degrees(self.sweep.q)}
        atomic_write_json(folder / "sweep.json", {**self.to_dict(), **sweep})
        return self.file_names()


def find_tolerance_angle(
    model: ArmModel,
    joint: int,
    angle: float,
    q_target_deg: ArrayLike,
    *,
    gamma_limit_deg: float = 180.0,
    zoom_deg: float = 2.0,
    step_deg: float = 0.1,
    progress: bool = False,
) -> ToleranceAngleResult:
    """The fault-tolerance angle gamma absorbing a lock (002 eq. 18, steps 1-5, Figs. 5-8).

    Parameters
    ----------
    model
        A ``puma6``-family arm (6 joints with 002 Table 1's structure), healthy: its
        closed-form IK is used.
    joint, angle
        The locked joint (1-based) and its locked angle [rad].
    q_target_deg
        (6,) desired configuration, every joint [deg]; its pose (forward kinematics) is the
        target, and its IK branch is followed along the sweep.  Degrees, as the result echoes
        them.
    gamma_limit_deg
        Sweep ``|gamma| <= gamma_limit_deg`` [deg], in (0, 180].
    zoom_deg
        Half-width of the second, narrow gamma range [deg], in (0, 180] (002 Fig. 6: 2).
    step_deg
        Sweep step [deg], in (0, 180]; the sweep has at most :data:`MAX_GAMMA_SAMPLES` points.
    progress
        Show a progress bar on stderr (when it is a terminal).

    Returns
    -------
    ToleranceAngleResult

    Raises
    ------
    ScenarioError
        A parameter out of range (the message names it).
    ConfigurationError
        The arm is not of the puma6 family, or the target is out of its reach.
    """
    q_deg = tuple(float(v) for v in np.asarray(q_target_deg, dtype=float).ravel())
    if not 1 <= joint <= model.dof:
        raise ScenarioError(f"joint must be 1..{model.dof}; got {joint}")
    if len(q_deg) != model.dof:
        raise ScenarioError(f"q_target_deg needs {model.dof} values [deg]; got {len(q_deg)}")
    if not math.isfinite(angle):
        raise ScenarioError(f"angle must be a finite number [rad]; got {angle}")
    for name, val in (("gamma_limit_deg", gamma_limit_deg), ("zoom_deg", zoom_deg), ("step_deg", step_deg)):
        if not (0 < val <= 180):
            raise ScenarioError(f"{name} must be in (0, 180]; got {val}")
    count = gamma_sample_count(gamma_limit_deg, step_deg)
    if count > MAX_GAMMA_SAMPLES:
        raise ScenarioError(
            f"step_deg {step_deg:g} gives {count} gamma samples over +-{gamma_limit_deg:g} deg; at most "
            f"{MAX_GAMMA_SAMPLES} are allowed: use step_deg >= "
            f"{2 * gamma_limit_deg / (MAX_GAMMA_SAMPLES - 1):.2g} or a smaller gamma_limit_deg"
        )
    q_target = np.radians(q_deg)
    limit, zoom, step = (math.radians(v) for v in (gamma_limit_deg, zoom_deg, step_deg))
    with Progress(1, "tolerance-angle", enabled=None if progress else False) as bar:
        target = ee_pose(model, q_target)
        sweep = gamma_sweep(model, target, np.linspace(-limit, limit, count), q_ref=q_target)
        wide = absorbable_range(sweep, joint, limit)
        narrow = absorbable_range(sweep, joint, min(zoom, limit))
        roots = gammas_for_lock(
            model, target, joint, angle, branch=sweep.branch, gamma_limit=limit, step=step
        )
        bar.update()
    return ToleranceAngleResult(
        robot=model.name,
        q_target_deg=q_deg,
        joint=int(joint),
        angle=float(angle),
        gamma_limit_deg=float(gamma_limit_deg),
        zoom_deg=float(zoom_deg),
        step_deg=float(step_deg),
        sweep=sweep,
        wide=wide,
        narrow=narrow,
        roots=tuple(roots),
    )


def tolerance_angle_from_scenario(
    data: Mapping[str, Any], previous: Mapping[str, JobResult], *, progress: bool = False
) -> ToleranceAngleResult:
    """Run the job for a resolved scenario (``Scenario.data``: the top-level ``robot``, ``base``
    and ``[failure]``, and the ``[tolerance_angle]`` table, in degrees); ``previous`` is not
    used.  Same result as ``jointlock tolerance-angle`` with the scenario's options."""
    joint, angle = scenario_lock(data, "tolerance_angle")
    t = data["tolerance_angle"]
    model = load_robot(data["robot"], base=data["base"], chain=UrdfChain.from_fields(data))
    return find_tolerance_angle(
        model,
        joint,
        angle,
        [float(v) for v in t["q_target_deg"]],
        gamma_limit_deg=float(t["gamma_limit_deg"]),
        zoom_deg=float(t["zoom_deg"]),
        step_deg=float(t["step_deg"]),
        progress=progress,
    )
