"""What a worker runs: one batch of cases (:func:`run_batch`), on any engine.

A batch carries the base scenario once and, per case, only its key and its overrides (a few
hundred bytes); the worker resolves each case, runs it in-process
(:func:`jointlock.run.run_scenario`) and returns small outcomes: the recorded columns, the
jobs' result dictionaries compressed, or the error's type and message.  A case that raises is
an outcome, not a failure of the batch.  Models are built once per worker process
(:func:`jointlock.robots.load_robot` keeps them), BLAS runs one thread per worker (the
matrices are 6x7; threads only contend), so a case gives the same numbers on every engine.
"""

from __future__ import annotations

import dataclasses
import json
import os
import signal
import socket
import threading
import time
import warnings
import zlib
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from .._version import __version__
from ..compiled import CompiledMode, chosen_compiled_mode, compiled_kernels
from ..io.files import json_text
from ..run import run_scenario
from ._cases import Case, case_key, case_overrides, resolve_case
from ._columns import record
from ._spec import CampaignSpec

#: The error type of a case whose worker was lost again and again (it runs again on resume).
WORKER_LOST = "WorkerLost"
#: One batch at a time per process: the BLAS limit and the recorded warnings are the
#: process's (a Dask worker may run several tasks in threads).
_BATCH_LOCK = threading.Lock()
#: Longest error message kept per case [characters].
MAX_MESSAGE = 2000
#: Distinct warnings kept per case.
MAX_WARNINGS = 5


@dataclass(frozen=True)
class BatchTask:
    """The work of one task: cases of one campaign.

    Attributes
    ----------
    scenario, scenario_source, scenario_dir
        The base scenario (TOML data), where it came from and its folder.
    campaign_seed
        The campaign seed (part of each key; checked against the coordinator's key).
    cases
        ``(key, overrides, seed)`` per case: its key, its overrides of the base scenario and
        the seed it runs with (:func:`~jointlock.campaign.case_seed`).
    columns
        Columns to record.
    version
        The coordinator's jointlock version (a worker with another one refuses the batch).
    compiled
        The mode the cases run in (:mod:`jointlock.compiled`): the coordinator's
        ``JOINTLOCK_COMPILED`` when set, else ``"always"`` (a worker runs many cases, so it
        pays numba's load once and runs every batch compiled); the same on every engine and
        worker, so that a case gives the same numbers wherever it runs.
    """

    scenario: Mapping[str, Any]
    scenario_source: str
    scenario_dir: str
    campaign_seed: int
    cases: tuple[tuple[str, Mapping[str, Any], int], ...]
    columns: tuple[str, ...]
    version: str = __version__
    compiled: CompiledMode = "always"


@dataclass(frozen=True)
class CaseOutcome:
    """What one case gave.

    Attributes
    ----------
    key
        The case's key.
    ok
        Whether every job ran.
    record
        ``{column: value}`` (None when the case failed).
    result
        ``{job: to_dict()}`` as zlib-compressed JSON (None when the case failed).
    error_type, error_message
        The exception's class name and message (None when ok).
    warnings
        Distinct warning messages raised while the case ran (at most :data:`MAX_WARNINGS`).
    seconds
        Time the case took in the worker [s].
    worker
        ``host:pid`` of the worker.
    """

    key: str
    ok: bool
    record: Mapping[str, Any] | None
    result: bytes | None
    error_type: str | None
    error_message: str | None
    warnings: tuple[str, ...]
    seconds: float
    worker: str


def encode_result(results: Mapping[str, Any]) -> bytes:
    """``{job: to_dict()}`` as stored in outcomes and the ledger: zlib-compressed compact JSON."""
    return zlib.compress(json_text(results, compact=True).encode(), 6)


def decode_result(blob: bytes) -> dict[str, Any]:
    """The ``{job: to_dict()}`` of :func:`encode_result`'s bytes."""
    return json.loads(zlib.decompress(blob))


def make_task(
    spec: CampaignSpec, cases: Sequence[Case], columns: Sequence[str], *, compiled: CompiledMode | None = None
) -> BatchTask:
    """The task of running ``cases`` of ``spec`` and recording ``columns``, in the compiled mode
    ``compiled`` (default :func:`campaign_compiled_mode`)."""
    return BatchTask(
        scenario=spec.scenario,
        scenario_source=spec.scenario_source,
        scenario_dir=str(spec.scenario_dir),
        campaign_seed=spec.seed,
        cases=tuple((c.key, case_overrides(spec, c.params), c.seed) for c in cases),
        columns=tuple(columns),
        compiled=campaign_compiled_mode() if compiled is None else compiled,
    )


def campaign_compiled_mode() -> CompiledMode:
    """The mode a campaign's cases run in: ``JOINTLOCK_COMPILED`` when set (or a mode set in
    the program), else ``"always"``."""
    return chosen_compiled_mode() or "always"


def run_batch(task: BatchTask) -> list[CaseOutcome]:
    """Run every case of ``task`` in this process; never raises for a case's error.

    Raises
    ------
    RuntimeError
        This worker's jointlock is another version than the coordinator's.
    """
    from threadpoolctl import threadpool_limits

    if task.version != __version__:
        raise RuntimeError(
            f"jointlock {__version__} on worker {socket.gethostname()}, {task.version} in the coordinator: "
            "install the same version everywhere"
        )

    spec = CampaignSpec(
        source=task.scenario_source,
        title="",
        scenario=task.scenario,
        scenario_source=task.scenario_source,
        scenario_dir=Path(task.scenario_dir),
        seed=task.campaign_seed,
    )
    worker = f"{socket.gethostname()}:{os.getpid()}"
    with _BATCH_LOCK, threadpool_limits(limits=1), compiled_kernels(task.compiled):
        return [_run_case(spec, key, overrides, seed, task.columns, worker) for key, overrides, seed in task.cases]


def _run_case(
    spec: CampaignSpec, key: str, overrides: Mapping[str, Any], seed: int, columns: tuple[str, ...], worker: str
) -> CaseOutcome:
    start = time.perf_counter()
    outcome: tuple[dict[str, Any] | None, bytes | None, str | None, str | None]
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            scenario = resolve_case(spec, overrides)
            if case_key(scenario, spec.seed) != key:  # the coordinator and the worker disagree
                raise RuntimeError(
                    "the case resolves to other inputs in this worker than in the coordinator "
                    "(different jointlock versions or model files?)"
                )
            scenario = dataclasses.replace(scenario, data={**scenario.data, "seed": seed})
            run = run_scenario(scenario)
            results = {job: result.to_dict() for job, result in run.jobs.items()}
            outcome = (record(results, columns), encode_result(results), None, None)
        except Exception as exc:  # a case that raises is recorded, and the campaign goes on
            message = str(exc)
            if len(message) > MAX_MESSAGE:
                message = message[: MAX_MESSAGE - 3] + "..."
            outcome = (None, None, type(exc).__name__, message)
    seen: list[str] = []
    for w in caught:
        text = f"{w.category.__name__}: {w.message}"
        if text not in seen and len(seen) < MAX_WARNINGS:
            seen.append(text)
    rec, blob, etype, emsg = outcome
    return CaseOutcome(key, etype is None, rec, blob, etype, emsg, tuple(seen), time.perf_counter() - start, worker)


def init_worker(coordinator_pid: int) -> None:
    """Initializer of a local pool's worker process: Ctrl-C is the coordinator's to handle
    (it stops the campaign and commits), and the worker exits when the coordinator is gone,
    even when it was killed and could not shut the pool down.  The parent (the coordinator,
    or the forkserver that exits with it) dying re-parents the worker: that is the signal, as
    a killed coordinator may linger as a zombie until its own parent reaps it."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    parent = os.getppid()

    def watch() -> None:
        while True:
            time.sleep(0.5)
            if os.getppid() != parent or not _alive(coordinator_pid):
                os._exit(1)

    threading.Thread(target=watch, name="jointlock-coordinator-watch", daemon=True).start()


def _alive(pid: int) -> bool:
    """Whether process ``pid`` runs (on Linux a zombie does not: killed, not yet reaped)."""
    if os.path.isdir("/proc/self"):
        try:
            with open(f"/proc/{pid}/stat") as fh:
                return fh.read().rsplit(")", 1)[1].split()[0] != "Z"
        except OSError:
            return False
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:  # exists, another user's: our coordinator's pid was reused
        return False
    return True
