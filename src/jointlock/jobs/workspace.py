"""Job ``workspace``: Monte Carlo workspace of the full arm and of the locked arm (002 Figs. 2-3).

Joint angles are sampled uniformly within the limits (capped to +-180 deg); the end-effector
positions of the full arm and, with a lock, of the arm with that joint locked give each
volume, extrapolated to a zero voxel side with its error (the full arm's counting the locked
arm's positions too: a subset by construction), the share of the full workspace that the
locked arm keeps, and the plain voxel occupancies on one common grid (:mod:`jointlock.analysis.workspace` does the sampling; this job adds the
settings, the checks and the outputs).  The command ``jointlock workspace`` is this call plus
printing.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, ClassVar

import numpy as np

from .._random import resolve_seed
from ..analysis.workspace import (
    MIN_SAMPLES,
    MIN_SAMPLES_PER_VOXEL,
    Workspace,
    WorkspaceComparison,
    _auto_voxel,
    compare_workspaces,
    sample_workspace,
)
from ..errors import ScenarioError
from ..io import files as _files
from ..io.files import atomic_write_json, npz_bytes, with_svg, write_figure
from ..locking import lock_joints
from ..model import ArmModel
from ..progress import Progress
from ..robots import UrdfChain, load_robot
from ._common import JobResult, locked_deg, locked_text, scenario_lock, scenario_locks

#: Points of each cloud drawn in the projections, and in the 3-D clouds.
PROJECTION_POINTS = 20000
CLOUD_POINTS = 5000

#: Size of the projections figure [inch], and of the clouds figure.
PROJECTIONS_FIGSIZE = (14.0, 4.5)
CLOUDS_FIGSIZE = (11.0, 5.0)


class VoxelTooSmallError(ScenarioError):
    """A given voxel holds fewer than :data:`~jointlock.analysis.workspace.MIN_SAMPLES_PER_VOXEL`
    samples on average: the volume would be about ``samples x voxel^3``, not the workspace's.

    Attributes
    ----------
    voxel
        The voxel side given [m].
    samples
        Configurations per arm.
    density
        Mean samples per occupied voxel [-].
    auto_voxel
        The automatic voxel side for these samples [m].
    """

    def __init__(self, voxel: float, samples: int, density: float, auto_voxel: float) -> None:
        self.voxel, self.samples, self.density, self.auto_voxel = voxel, samples, density, auto_voxel
        super().__init__(self.message("voxel"))

    def message(self, option: str) -> str:
        """The error's text, naming the parameter or option ``option`` (e.g. ``"--voxel"``)."""
        return (
            f"{option} {self.voxel:g} m is too small for {self.samples} samples: only {self.density:.2g} samples "
            f"per occupied voxel on average, so the volume is about samples x voxel^3, not the workspace's; use a "
            f"larger {option} (automatic for these samples: {self.auto_voxel:.3g} m) or more samples"
        )

    def __reduce__(self) -> tuple[Any, ...]:
        return (type(self), (self.voxel, self.samples, self.density, self.auto_voxel))


@dataclass(frozen=True, eq=False)  # arrays inside: compare to_dict() instead
class WorkspaceStudy(JobResult):
    """The Monte Carlo workspace of an arm, and of the arm with one joint locked.

    Attributes
    ----------
    robot
        Name of the arm.
    samples
        Configurations per arm.
    seed
        The seed the samples were drawn with (None when a Generator was passed).
    workspace
        Without a lock: the full arm's :class:`~jointlock.analysis.workspace.Workspace`
        (``points`` (N, 3) [m], ``voxel`` [m], ``volume`` and ``volume_error`` [m^3]).  With one: the
        :class:`~jointlock.analysis.workspace.WorkspaceComparison` (``full`` (N, 3), ``locked``
        (N, 3) [m], both volumes with their errors, the share kept, the occupancies and the
        half-sample estimate).
    already_locked
        ``{joint: angle [deg]}`` locked before the failure (``model.locked`` of the arm given):
        then "full" is the arm before this failure, with those joints locked.
    """

    job: ClassVar[str] = "workspace"

    robot: str
    samples: int
    seed: int | None
    workspace: Workspace | WorkspaceComparison
    already_locked: dict[str, float] = field(default_factory=dict)

    @property
    def _before(self) -> str:
        """How the summary names the arm before the failure."""
        return "full arm" if not self.already_locked else f"arm before ({locked_text(self.already_locked)})"

    @property
    def locked(self) -> bool:
        """A joint was locked (the study compares two workspaces)."""
        return isinstance(self.workspace, WorkspaceComparison)

    @property
    def full_points(self) -> np.ndarray:
        """(N, 3) end-effector positions of the full arm [m]."""
        ws = self.workspace
        return ws.full if isinstance(ws, WorkspaceComparison) else ws.points

    @property
    def locked_points(self) -> np.ndarray | None:
        """(N, 3) end-effector positions of the locked arm [m], or None."""
        ws = self.workspace
        return ws.locked if isinstance(ws, WorkspaceComparison) else None

    @property
    def samples_per_voxel(self) -> float:
        """Mean full-arm samples per occupied voxel [-]."""
        return self.workspace.samples_per_voxel

    def warnings(self) -> list[str]:
        """Why the volumes or the share kept should not be trusted to their digits (empty when
        they look converged)."""
        return self.workspace.warnings()

    def to_dict(self) -> dict[str, Any]:
        """The JSON object of ``jointlock workspace --json`` (without ``files``): the robot, the
        samples and the seed, then the workspace's own :meth:`~jointlock.analysis.workspace.
        WorkspaceComparison.to_dict` (numbers, ``None`` and a "no estimate" text where a figure
        has no estimate)."""
        head: dict[str, Any] = {"robot": self.robot, "samples": self.samples, "seed": self.seed}
        if not self.locked:
            head["lock"] = None
        out = head | self.workspace.to_dict()
        if self.already_locked:  # "full" is the arm before the failure
            out["already_locked_deg"] = dict(self.already_locked)
        return out

    def summary(self) -> list[str]:
        """The lines ``jointlock workspace`` prints on stdout (the warnings, which it prints on
        stderr, are :meth:`warnings`)."""
        ws = self.workspace
        density = self.samples_per_voxel
        density_text = f"{density:.3g}" if math.isfinite(density) else "no"
        return [
            f"{self.robot}: {self.samples} samples per arm (seed {self.seed}), voxel {ws.voxel:.3g} m "
            f"({density_text} samples per occupied voxel)",
            *ws.summary(self._before),
            "  volumes extrapolated to a zero voxel side; ± bounds the extrapolation's bias and the sampling "
            "(not a standard deviation)",
        ]

    def file_names(self) -> list[str]:
        """The names :meth:`write` writes (its JSON lists them as paths)."""
        return with_svg(["projections.png", "clouds.png", "points.npz", "workspace.json"])

    def write(self, out: str | Path) -> list[str]:
        """Write ``projections.png`` (xy, xz, yz), ``clouds.png`` (002 Figs. 2-3),
        ``points.npz`` (``full`` (N, 3) and, with a lock, ``locked`` [m]; compressed) and
        ``workspace.json`` (:meth:`to_dict`) to the folder ``out``; returns their
        names."""
        from ..plots._common import offscreen_figure
        from ..plots.workspace import plot_workspace_clouds, plot_workspace_projections

        folder = Path(out)
        folder.mkdir(parents=True, exist_ok=True)
        full, locked = self.full_points, self.locked_points
        fig = plot_workspace_projections(full, locked, fig=offscreen_figure(PROJECTIONS_FIGSIZE))
        write_figure(fig, folder, "projections.png", tight=False)
        fig = plot_workspace_clouds(full, locked, fig=offscreen_figure(CLOUDS_FIGSIZE))
        write_figure(fig, folder, "clouds.png", tight=False)
        arrays = {"full": full} if locked is None else {"full": full, "locked": locked}
        _files.atomic_write_bytes(folder / "points.npz", npz_bytes(compressed=True, **arrays))  # spies see it
        atomic_write_json(folder / "workspace.json", self.to_dict())
        return self.file_names()


def study_workspace(
    model: ArmModel,
    locked: tuple[int, float] | None = None,
    *,
    samples: int = 200_000,
    voxel: float | None = None,
    rng: int | np.random.Generator | None = 0,
    progress: bool = False,
) -> WorkspaceStudy:
    """Monte Carlo workspace of ``model`` and, with ``locked``, of ``model`` with that joint
    locked (002 Figs. 2-3).

    Parameters
    ----------
    model
        The healthy arm.
    locked
        ``(joint, angle)``: the joint to lock (1-based) and its angle [rad]; None: the full
        arm alone.
    samples
        Configurations per arm, >= :data:`~jointlock.analysis.workspace.MIN_SAMPLES`.
    voxel
        Voxel side [m] of the volume estimate, > 0; None: automatic (about
        :data:`~jointlock.analysis.workspace.SAMPLES_PER_VOXEL` samples per voxel).
    rng
        Seed (integer >= 0) or Generator; None draws a fresh seed, which is recorded
        (``result.seed``).  The full arm's samples come first, then the locked arm's.
    progress
        Show a progress bar on stderr (when it is a terminal).

    Returns
    -------
    WorkspaceStudy

    Raises
    ------
    ScenarioError
        A parameter out of range (the message names it).
    ConfigurationError
        ``rng`` is not None, an integer seed >= 0 or a numpy Generator.
    VoxelTooSmallError
        A given ``voxel`` holds too few samples for a meaningful volume.
    """
    if not (isinstance(samples, (int, np.integer)) and samples >= MIN_SAMPLES):
        raise ScenarioError(
            f"samples must be an integer >= {MIN_SAMPLES} (a voxel-occupancy volume from fewer samples says "
            f"little); got {samples}"
        )
    if voxel is not None and not (math.isfinite(voxel) and voxel > 0):
        raise ScenarioError(f"voxel must be a finite number > 0 [m]; got {voxel}")
    seed = resolve_seed(rng)  # None: a fresh seed, recorded in the result
    samples = int(samples)
    with Progress(1, "workspace", enabled=None if progress else False) as bar:
        if locked is not None:
            joint, angle = locked
            comparison = compare_workspaces(model, joint, angle, samples=samples, voxel=voxel, rng=seed)
            ws: Workspace | WorkspaceComparison = comparison
            points = comparison.full
        else:
            ws = sample_workspace(model, samples=samples, voxel=voxel, rng=seed)
            points = ws.points
        bar.update()
    density = ws.samples_per_voxel
    if voxel is not None and not density >= MIN_SAMPLES_PER_VOXEL:
        raise VoxelTooSmallError(float(voxel), samples, density, _auto_voxel(points))
    return WorkspaceStudy(
        robot=model.name,
        samples=samples,
        seed=None if isinstance(seed, np.random.Generator) else seed,
        workspace=ws,
        already_locked=locked_deg(model),
    )


def workspace_from_scenario(
    data: Mapping[str, Any], previous: Mapping[str, JobResult], *, progress: bool = False
) -> WorkspaceStudy:
    """Run the job for a resolved scenario (``Scenario.data``: the top-level ``robot``, ``base``,
    ``seed`` and ``[failure]`` (optional), and the ``[workspace]`` table); ``previous`` is not
    used.  Same result as ``jointlock workspace`` with the scenario's options."""
    t = data["workspace"]
    locks = scenario_locks(data)
    failure = scenario_lock(data)
    model = load_robot(data["robot"], base=data["base"], chain=UrdfChain.from_fields(data))
    if failure is not None:  # joints locked before the failure: the arm before it
        model = lock_joints(model, {j: a for j, a in locks.items() if j != failure[0]})
    return study_workspace(
        model,
        failure,
        samples=int(t["samples"]),
        voxel=None if t["voxel"] is None else float(t["voxel"]),
        rng=int(data["seed"]),
        progress=progress,
    )
