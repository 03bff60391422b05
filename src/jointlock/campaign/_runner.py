"""The coordinator: :func:`run_campaign` sends batches of cases to an engine and writes what
comes back to the ledger.

Batches are sized from the measured time per case so that each carries about
``batch_seconds`` of work (a task costs a few milliseconds on Dask; a case 0.1-2 s here), never
more than a fair share of what is left, with at most two batches per worker in flight.  A
batch lost with its worker (a local pool that broke, a Dask ``KilledWorker``) is sent again;
after :data:`MAX_ATTEMPTS` losses it is split, and a single case lost that often is recorded
as an error (``WorkerLost``).  SIGINT and SIGTERM stop the run: running batches are dropped
(they run again on resume), everything returned is already committed.
"""

from __future__ import annotations

import concurrent.futures as cf
import contextlib
import math
import os
import signal
import threading
import time
from collections import deque
from collections.abc import Iterator, Sequence
from concurrent.futures.process import BrokenProcessPool
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from .._version import __version__
from ..errors import CampaignError
from ..progress import Progress
from ._cases import Case, CasePlan, plan_cases
from ._columns import default_columns, record
from ._engines import Engine, in_process, process_pool
from ._ledger import LEDGER_NAME, Ledger, open_ledger
from ._read import as_spec
from ._spec import CONFIRM_CASES, CampaignSpec
from ._worker import CaseOutcome, make_task, run_batch

#: Times a batch may be lost with its worker before it is split (and a single case recorded
#: as an error).
MAX_ATTEMPTS = 3
#: Most cases in one batch.
MAX_BATCH = 2000
#: Default work per batch [s] (5-30 s keeps a Dask task's overhead far below 1 %).
BATCH_SECONDS = 10.0


@dataclass(frozen=True)
class CampaignRun:
    """What one :func:`run_campaign` did (picklable; ``to_dict()`` is ``--json``'s output).

    Attributes
    ----------
    title, out, engine, workers
        The campaign, its output folder, the engine and its workers.
    planned, done_before, to_run
        Cases of the campaign file, finished before this run, and sent in this run.
    ok, failed
        Cases of this run that finished, and that raised (recorded with their error).
    remaining
        Cases of the plan still not finished (after an interruption).
    seconds, case_seconds
        Wall time of the run, and the sum of the cases' own times [s].
    stopped_by
        ``"SIGINT"``/``"SIGTERM"`` when interrupted, else None.
    lost_batches, restarts
        Batches lost with a worker (and sent again), restarts of a broken local pool.
    """

    title: str
    out: str
    engine: str
    workers: int
    planned: int
    done_before: int
    to_run: int
    ok: int
    failed: int
    remaining: int
    seconds: float
    case_seconds: float
    stopped_by: str | None = None
    lost_batches: int = 0
    restarts: int = 0
    excluded: int = 0
    duplicates: int = 0
    columns: tuple[str, ...] = field(default_factory=tuple)

    @property
    def interrupted(self) -> bool:
        return self.stopped_by is not None

    @property
    def rate(self) -> float:
        """Cases finished per second of wall time in this run."""
        return (self.ok + self.failed) / self.seconds if self.seconds > 0 else 0.0

    def to_dict(self) -> dict[str, Any]:
        return {
            "title": self.title,
            "out": self.out,
            "ledger": str(Path(self.out) / LEDGER_NAME),
            "engine": self.engine,
            "workers": self.workers,
            "planned": self.planned,
            "done_before": self.done_before,
            "to_run": self.to_run,
            "ok": self.ok,
            "failed": self.failed,
            "remaining": self.remaining,
            "seconds": self.seconds,
            "case_seconds": self.case_seconds,
            "cases_per_second": self.rate,
            "stopped_by": self.stopped_by,
            "lost_batches": self.lost_batches,
            "restarts": self.restarts,
            "excluded": self.excluded,
            "duplicates": self.duplicates,
            "columns": list(self.columns),
        }

    def summary(self) -> list[str]:
        lines = [
            f"{self.title}: {self.planned} cases planned, {self.done_before} finished before, "
            f"{self.ok + self.failed} run now ({self.ok} ok, {self.failed} failed) in {self.seconds:.1f} s "
            f"with {self.engine} ({self.rate:.3g} cases/s)",
        ]
        if self.lost_batches:
            lines.append(f"  {self.lost_batches} batch(es) lost with a worker and sent again; pool restarts: {self.restarts}")
        if self.failed:
            lines.append(f"  failed cases are recorded with their error: jointlock campaign status {self.out}")
        lines.append(f"  ledger: {Path(self.out) / LEDGER_NAME}")
        return lines


@contextlib.contextmanager
def _exclusive(out: Path) -> Iterator[None]:
    """Hold ``out/.campaign.lock`` for the run: one coordinator writes a ledger at a time."""
    try:
        import fcntl
    except ImportError:  # not POSIX: no lock
        yield
        return
    out.mkdir(parents=True, exist_ok=True)
    with open(out / ".campaign.lock", "a+") as fh:
        try:
            fcntl.flock(fh, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            fh.seek(0)
            other = fh.read().strip() or "?"
            raise CampaignError(
                f"another `jointlock campaign run` (pid {other}) is writing {str(out)!r}; wait for it or stop it"
            ) from None
        fh.seek(0)
        fh.truncate()
        fh.write(str(os.getpid()))
        fh.flush()
        try:
            yield
        finally:
            fcntl.flock(fh, fcntl.LOCK_UN)


class _Stop:
    """SIGINT/SIGTERM while a campaign runs: remember which, and raise KeyboardInterrupt
    where the coordinator is (everything it committed stays; the ledger rolls back a
    transaction cut short)."""

    def __init__(self) -> None:
        self.signal: str | None = None
        self._old: dict[int, Any] = {}

    def __enter__(self) -> _Stop:
        if threading.current_thread() is threading.main_thread():
            for sig in (signal.SIGINT, signal.SIGTERM):
                self._old[sig] = signal.signal(sig, self._handle)
        return self

    def _handle(self, signum: int, frame: Any) -> None:
        if self.signal is None:
            self.signal = signal.Signals(signum).name
            raise KeyboardInterrupt

    def quiet(self) -> None:
        """Ignore further signals while the run closes."""
        for sig in self._old:
            signal.signal(sig, signal.SIG_IGN)

    def __exit__(self, *exc: object) -> None:
        for sig, old in self._old.items():
            signal.signal(sig, old)


def run_campaign(
    campaign: CampaignSpec | str | Path,
    out: str | Path | None = None,
    *,
    engine: Engine | None = None,
    workers: int | None = None,
    retry_failed: bool = False,
    max_cases: int | None = CONFIRM_CASES,
    batch_seconds: float = BATCH_SECONDS,
    progress: bool = False,
) -> CampaignRun:
    """Run every case of a campaign not yet in its ledger; resumable.

    Parameters
    ----------
    campaign
        A :class:`CampaignSpec` or the campaign file's path.
    out
        The output folder holding ``ledger.sqlite`` (default: the file's ``out``, else
        ``<file stem>-campaign``).  Running again resumes exactly the cases not finished.
    engine
        Where batches run (:func:`process_pool`, :func:`dask_cluster`, :func:`in_process`);
        default: a local process pool of ``workers`` processes (one per core), closed at the end.
        An engine passed in stays open.
    retry_failed
        Run again the cases recorded as failed (they are skipped otherwise: a case's error is
        deterministic).
    max_cases
        Refuse a larger campaign (None: any size); the CLI's ``--yes`` lifts it.
    batch_seconds
        Work per batch [s] (> 0).
    progress
        Show a progress bar on stderr (cases done, rate, time left, failures).

    Returns
    -------
    CampaignRun
        With ``stopped_by`` set when SIGINT/SIGTERM stopped it (nothing finished is lost).
    """
    if not (isinstance(batch_seconds, (int, float)) and math.isfinite(batch_seconds) and batch_seconds > 0):
        raise CampaignError(f"batch_seconds must be a finite number > 0 [s]; got {batch_seconds!r}")
    spec = as_spec(campaign)
    many = progress and spec.count_before_filters() >= 1000  # resolving takes ~1 ms a case
    with Progress(spec.count_before_filters(), "resolving cases", enabled=None if many else False) as bar:
        plan = plan_cases(spec, max_cases=max_cases, progress=bar.update)
    out = Path(out) if out is not None else spec.default_out()
    if out.exists() and not out.is_dir():
        raise CampaignError(f"output folder {str(out)!r} exists and is not a folder")
    columns = spec.columns or default_columns(plan.jobs)
    with _exclusive(out), open_ledger(out, create=True) as ledger:
        _remember(ledger, spec, columns)
        ledger.set_plan(plan.cases)
        finished = ledger.finished_keys(status=None if not retry_failed else "ok")
        todo = [c for c in plan.cases if c.key not in finished]
        own = engine is None
        if engine is None:
            engine = process_pool(workers) if todo else in_process()
        try:
            return _coordinate(spec, plan, todo, columns, ledger, engine, out, batch_seconds, progress, own)
        finally:
            if own:
                engine.close()


def _remember(ledger: Ledger, spec: CampaignSpec, columns: Sequence[str]) -> None:
    """Store the campaign in the ledger; when the columns changed, recompute the finished
    cases' records from their stored results (nothing runs again)."""
    if ledger.meta("columns") not in (None, list(columns)):
        keys = ledger.finished_keys(status="ok")
        ledger.update_records({key: record(res, columns) for key, res in ledger.results(keys)})
    ledger.set_meta(spec=spec.to_dict(), columns=list(columns), jointlock=__version__)


def _coordinate(
    spec: CampaignSpec,
    plan: CasePlan,
    todo: list[Case],
    columns: Sequence[str],
    ledger: Ledger,
    engine: Engine,
    out: Path,
    batch_seconds: float,
    progress: bool,
    own_engine: bool,
) -> CampaignRun:
    """The coordinator's loop (see the module docstring)."""
    by_key = {c.key: c for c in todo}
    queue: deque[Case] = deque(todo)
    retry: deque[tuple[list[Case], int]] = deque()
    in_flight: dict[cf.Future, tuple[list[Case], int]] = {}
    done_before = len(plan) - len(todo)
    run_id = ledger.start_run(engine.description, engine.workers, len(plan), len(todo))
    counts = {"ok": 0, "failed": 0, "lost": 0, "restarts": 0}
    case_seconds = 0.0
    max_in_flight = 2 * engine.workers
    start = time.perf_counter()
    bar = Progress(len(plan), "cases", enabled=None if progress else False, unit="cases", initial=done_before)

    def batch_size() -> int:
        finished = counts["ok"] + counts["failed"]
        if finished == 0:
            return 1  # the first batches measure the time per case
        want = max(1, int(batch_seconds / max(case_seconds / finished, 1e-6)))
        return max(1, min(want, math.ceil(len(queue) / max_in_flight), MAX_BATCH))

    def lost(batch: list[Case], attempts: int, reason: str) -> None:
        counts["lost"] += 1
        attempts += 1
        if attempts < MAX_ATTEMPTS:
            retry.appendleft((batch, attempts))
        elif len(batch) > 1:
            half = len(batch) // 2
            retry.appendleft((batch[half:], MAX_ATTEMPTS - 1))
            retry.appendleft((batch[:half], MAX_ATTEMPTS - 1))
        else:
            message = f"the worker running this case was lost {attempts} times ({reason})"
            store([CaseOutcome(batch[0].key, False, None, None, "WorkerLost", message, (), 0.0, "")])

    def store(outcomes: list[CaseOutcome]) -> None:
        nonlocal case_seconds
        ledger.record(outcomes, by_key, run_id)
        for o in outcomes:
            counts["ok" if o.ok else "failed"] += 1
            case_seconds += o.seconds
        bar.update(len(outcomes), note=f"{counts['failed']} failed" if counts["failed"] else "")

    stop = _Stop()
    with stop:
        try:
            while queue or retry or in_flight:
                max_in_flight = 2 * engine.current_workers()
                while len(in_flight) < max_in_flight and (queue or retry):
                    if retry:
                        batch, attempts = retry.popleft()
                    else:
                        batch, attempts = [queue.popleft() for _ in range(min(batch_size(), len(queue)))], 0
                    future = engine.executor.submit(run_batch, make_task(spec, batch, columns))
                    in_flight[future] = (batch, attempts)
                finished, _ = cf.wait(list(in_flight), timeout=0.25, return_when=cf.FIRST_COMPLETED)
                broken = False
                for future in finished:
                    batch, attempts = in_flight.pop(future)
                    try:
                        outcomes = future.result()
                    except BrokenProcessPool:
                        broken = True
                        lost(batch, attempts, "its process died")
                    except cf.CancelledError:
                        retry.appendleft((batch, attempts))
                    except Exception as exc:  # e.g. Dask's KilledWorker: the batch is sent again
                        lost(batch, attempts, f"{type(exc).__name__}: {str(exc)[:200]}")
                    else:
                        store(outcomes)
                if broken:  # a local pool breaks whole: every batch in flight went with it
                    for batch, attempts in in_flight.values():
                        lost(batch, attempts, "its pool broke")
                    in_flight.clear()
                    if not engine.restart():
                        raise CampaignError(f"the engine ({engine.description}) broke and cannot restart")
                    counts["restarts"] += 1
        except KeyboardInterrupt:
            stop.signal = stop.signal or "SIGINT"
        finally:
            if stop.signal is not None or in_flight:
                stop.quiet()
                for future in in_flight:
                    future.cancel()
                if own_engine:
                    engine.close(cancel=True)
            bar.close()
            ledger.finish_run(run_id, counts["ok"], counts["failed"], stop.signal)
    remaining = ledger.counts()["remaining"]
    return CampaignRun(
        title=spec.title,
        out=str(out),
        engine=engine.description,
        workers=engine.workers,
        planned=len(plan),
        done_before=done_before,
        to_run=len(todo),
        ok=counts["ok"],
        failed=counts["failed"],
        remaining=remaining,
        seconds=time.perf_counter() - start,
        case_seconds=case_seconds,
        stopped_by=stop.signal,
        lost_batches=counts["lost"],
        restarts=counts["restarts"],
        excluded=plan.excluded,
        duplicates=plan.duplicates,
        columns=tuple(columns),
    )
