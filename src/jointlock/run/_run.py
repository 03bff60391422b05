"""Running a scenario in-process: :func:`run_scenario` -> :class:`RunResult`.

Each job of the scenario (in :data:`~jointlock.scenario.JOB_ORDER`) is one library call
(``jointlock.jobs.<job>.<job>_from_scenario``) that receives the resolved scenario and the typed
results of the jobs before it (the halt uses the halt configuration found by ``halt_config``).
Nothing is parsed from a command line or read back from printed text.

:meth:`RunResult.write` writes what ``jointlock run`` writes: ``results.json`` (the resolved
scenario, seed, versions, each job's result dictionary and equivalent command, the headline
``summary``, the ``files``), each job's own files under ``<job>/``, the summary figures under
``figures/`` and a self-contained ``report.html``; every file atomically, ``results.json`` and
``report.html`` last.
"""

from __future__ import annotations

import importlib
import importlib.metadata
import platform
import sys
from collections.abc import Callable, Mapping, Sequence
from contextlib import nullcontext
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..compiled import compiled_kernels, compiled_mode
from ..errors import JointlockError, ScenarioError
from ..io.files import atomic_write_json, atomic_write_text, to_plain
from ..jobs._common import JobResult
from ..scenario import JOB_PAPER, TOP_FIELDS, Scenario, load_scenario
from ._commands import KEEP_OUT_FILE, job_command, jump_task_toml, keep_out_toml
from ._summary import summarize, summary_lines

#: The library call of each job: (module, function) taking ``(data, previous, *, progress)``.
JOB_RUNNERS: dict[str, tuple[str, str]] = {
    "halt_config": ("jointlock.jobs.halt_config", "halt_config_from_scenario"),
    "halt": ("jointlock.jobs.halt", "halt_from_scenario"),
    "jump": ("jointlock.jobs.jump", "jump_from_scenario"),
    "tolerance_angle": ("jointlock.jobs.tolerance_angle", "tolerance_angle_from_scenario"),
    "replan": ("jointlock.jobs.replan", "replan_from_scenario"),
    "workspace": ("jointlock.jobs.workspace", "workspace_from_scenario"),
    "singular": ("jointlock.jobs.singular", "singular_from_scenario"),
}


def job_runner(job: str) -> Callable[..., JobResult]:
    """The ``<job>_from_scenario`` function of ``job`` (imported on first use)."""
    module, name = JOB_RUNNERS[job]
    return getattr(importlib.import_module(module), name)


def versions() -> dict[str, str]:
    """Versions of jointlock, Python and the core dependencies."""
    import scipy

    from .._version import __version__

    # matplotlib's from its metadata unless it is loaded: a campaign worker's case draws
    # nothing, and importing matplotlib for its version cost each worker's start 0.1 s
    plotting = sys.modules.get("matplotlib")
    return {
        "jointlock": __version__,
        "python": platform.python_version(),
        "numpy": np.__version__,
        "scipy": scipy.__version__,
        "matplotlib": plotting.__version__ if plotting is not None else importlib.metadata.version("matplotlib"),
        "platform": platform.platform(),
    }


def default_out_dir(scenario: Scenario) -> Path:
    """The output folder of a scenario: its ``out`` field, else ``<file stem>-results``."""
    if scenario.data.get("out"):
        return Path(scenario.data["out"])
    return Path(f"{Path(scenario.source).stem}-results")


def run_title(scenario: Scenario) -> str:
    """The file's title (else its name); when an override changed the failure, the file's
    title no longer describes the run: it is marked, with the failure actually run."""
    title = scenario.data.get("title") or Path(scenario.source).stem
    if not scenario.failure_overridden():
        return title
    lk = scenario.lock
    fail = scenario.data["failure"]
    what = (
        f"joint {lk[0]} locked at {lk[1]:g} deg"
        if lk is not None
        else (f"joint {fail['joint']} locks" if fail["joint"] is not None else "no locked joint")
    )
    return f"{title} [failure overridden: {what}]"


def _with_context(exc: JointlockError, where: str) -> JointlockError:
    """``exc`` with ``where`` in front of its message: the same class when it can be made from
    a message alone, else a :class:`ScenarioError` (an error class with other arguments)."""
    message = f"{where}: {exc}"
    try:
        return type(exc)(message)
    except TypeError:
        return ScenarioError(message)


def run_scenario(
    scenario: Scenario | str | Path, *, progress: bool = False, check_in: str | None = None
) -> RunResult:
    """Run every job of ``scenario`` in-process, each on the typed results of those before it.

    Parameters
    ----------
    scenario
        A validated scenario (:func:`jointlock.scenario.load_scenario` or
        :func:`~jointlock.scenario.scenario_from_dict`), or the path of a scenario file (read
        with :func:`~jointlock.scenario.load_scenario`, no overrides).
    progress
        Show progress bars on stderr.
    check_in
        ``"mujoco"``: replay the motions the jobs produce in MuJoCo and compare
        (:func:`jointlock.sim.replay_jobs`; the optional extra ``jointlock[mujoco]``); default:
        the scenario's ``check_in`` field ("none": no replay).

    Raises
    ------
    JointlockError
        From a job, with the scenario's source and the job's name in front of the message.
    """
    if isinstance(scenario, (str, Path)):
        scenario = load_scenario(scenario)
    elif not isinstance(scenario, Scenario):
        raise ScenarioError(
            f"run_scenario needs a Scenario (jointlock.load_scenario(path)) or a scenario file's path; "
            f"got {type(scenario).__name__}"
        )
    simulator = check_in if check_in is not None else scenario.data.get("check_in", "none")
    if simulator not in CHECK_IN:
        raise ScenarioError(f"check_in must be one of {', '.join(map(repr, CHECK_IN))}; got {simulator!r}")
    if simulator == "mujoco":  # before the jobs run: a missing extra is said at once
        from ..sim import require_mujoco

        require_mujoco()
    results: dict[str, JobResult] = {}
    mode = scenario.data.get("compiled")
    compiled_mode()  # a bad JOINTLOCK_COMPILED is said now, in one line, not deep in a job
    with compiled_kernels(mode) if mode is not None else nullcontext():
        for job in scenario.jobs:
            try:
                results[job] = job_runner(job)(scenario.data, dict(results), progress=progress)
            except JointlockError as exc:
                raise _with_context(exc, f"{scenario.source}: job [{job}]") from exc
    checks: dict[str, Any] = {}
    if simulator == "mujoco":
        from ..sim import replay_jobs

        try:
            with compiled_kernels(mode) if mode is not None else nullcontext():
                checks = dict(replay_jobs(results))
        except JointlockError as exc:
            raise _with_context(exc, f"{scenario.source}: check in MuJoCo") from exc
    return RunResult(scenario, results, versions(), checks)


#: The simulators a run can replay its motions in (the scenario's ``check_in`` choices).
CHECK_IN = TOP_FIELDS["check_in"].choices


#: Keys before which a command's JSON lists its ``files`` (else they come last).
_FILES_BEFORE = ("trajectory", "found")


def _with_files(data: dict[str, Any], files: list[str]) -> dict[str, Any]:
    """``data`` with ``"files"`` where the command's ``--json --out`` output has it."""
    out: dict[str, Any] = {}
    for key, value in data.items():
        if key in _FILES_BEFORE and "files" not in out:
            out["files"] = files
        out[key] = value
    out.setdefault("files", files)
    return out


@dataclass(frozen=True, eq=False)  # arrays inside: compare to_dict() instead
class RunResult:
    """The results of one scenario run (picklable).

    Attributes
    ----------
    scenario
        The scenario that ran.
    jobs
        Each job's typed result, in the order they ran.
    versions
        Versions of jointlock, Python and the core dependencies.
    checks
        ``{job: Replay}``: the job's motion replayed in MuJoCo (:mod:`jointlock.sim`), with
        ``check_in="mujoco"``; empty otherwise.
    """

    scenario: Scenario
    jobs: Mapping[str, JobResult]
    versions: Mapping[str, str] = field(default_factory=dict)
    checks: Mapping[str, Any] = field(default_factory=dict)

    @property
    def title(self) -> str:
        return run_title(self.scenario)

    @property
    def seed(self) -> int:
        return self.scenario.data["seed"]

    def __getitem__(self, job: str) -> JobResult:
        if job not in self.jobs:
            raise KeyError(f"job {job!r} did not run in this scenario; it ran: {', '.join(self.jobs) or 'none'}")
        return self.jobs[job]

    def _job_dicts(self, out: Path) -> dict[str, dict[str, Any]]:
        jobs: dict[str, dict[str, Any]] = {}
        for job, result in self.jobs.items():
            previous = {k: v["result"] for k, v in jobs.items()}
            data = result.to_dict()
            if hasattr(result, "file_names"):  # the command's JSON lists the files it writes
                data = _with_files(data, [str(out / job / name) for name in result.file_names()])
            jobs[job] = {
                "paper": JOB_PAPER[job],
                "command": job_command(job, self.scenario, out, previous),
                "exit_code": 0,
                "result": to_plain(data),
            }
        return jobs

    def to_dict(self, out: str | Path | None = None) -> dict[str, Any]:
        """results.json's content without ``files``: plain JSON data.  ``out`` is the output
        folder the equivalent commands name (default: :func:`default_out_dir`)."""
        out = Path(out) if out is not None else default_out_dir(self.scenario)
        jobs = self._job_dicts(out)
        return {
            "title": self.title,
            "scenario_file": self.scenario.source,
            "overrides": to_plain(dict(self.scenario.overrides)),
            "scenario": to_plain(self.scenario.to_dict()),
            "seed": self.seed,
            "versions": dict(self.versions),
            "jobs": jobs,
            "summary": to_plain(summarize(jobs)),
            **({"checks": {job: to_plain(r.to_dict()) for job, r in self.checks.items()}} if self.checks else {}),
        }

    def summary(self) -> list[str]:
        """The lines ``jointlock run`` prints (a few per job)."""
        return summary_lines(self.to_dict())

    def write(
        self,
        out: str | Path,
        *,
        title: str | None = None,
        extra: Mapping[str, Any] | None = None,
        extra_sections: Sequence[Any] = (),
    ) -> dict[str, Any]:
        """Write every output to ``out`` (see the module docstring); returns results.json's
        content (with ``files``).  ``title``, ``extra`` (more top-level keys of results.json)
        and ``extra_sections`` (more report sections) let a caller such as the demo add to it."""
        from .. import report as rp
        from ._report import report_sections

        out = Path(out)
        out.mkdir(parents=True, exist_ok=True)
        results = self.to_dict(out)
        if self.scenario.data.get("keep_out"):  # the keep-outs the equivalent commands read
            atomic_write_text(out / KEEP_OUT_FILE, keep_out_toml(self.scenario))
        for job, result in self.jobs.items():
            if job == "jump":  # the task file its equivalent command reads
                atomic_write_text(out / "jump" / "task.toml", jump_task_toml(self.scenario))
            if not result.write(out / job):  # a job with no files of its own: its result dictionary
                atomic_write_json(out / job / "result.json", results["jobs"][job]["result"])
        for job, replay in self.checks.items():
            replay.write(out / "checks", f"mujoco_{job}")
        if "halt" in self.checks:  # the halt's attitude plot with MuJoCo's trace on top
            from ..sim import write_attitude_with_replay

            write_attitude_with_replay(self.jobs["halt"], self.checks["halt"], out / "halt")
        results.update(to_plain(dict(extra or {})))
        sections = report_sections(self.scenario, results, dict(self.jobs), out) + list(extra_sections)
        files = {str(p.relative_to(out)) for p in out.rglob("*") if p.is_file() and not p.name.startswith(".")}
        results["files"] = sorted(files | {"results.json", "report.html"})
        page = rp.render_html(
            title or f"jointlock run: {results['title']}",
            sections,
            intro=(
                f"Scenario <code>{rp.html.escape(self.scenario.source)}</code>, jointlock "
                f"{self.versions.get('jointlock', '')}, seed {self.seed}. Jobs: {', '.join(self.scenario.jobs)}."
            ),
            toc=True,
            footer="Generated by <code>jointlock</code>; every number is also in results.json.",
        )
        atomic_write_text(out / "report.html", page)
        atomic_write_json(out / "results.json", results)
        return results

