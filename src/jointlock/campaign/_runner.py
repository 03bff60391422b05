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
import dataclasses
import math
import shlex
import time
from collections import deque
from collections.abc import Callable, Sequence
from concurrent.futures.process import BrokenProcessPool
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from .._version import __version__
from ..compiled import ENVIRONMENT_VARIABLE, CompiledMode, chosen_compiled_mode
from ..errors import CampaignError
from ..progress import Progress
from ._cases import Case, CasePlan, plan_cases
from ._columns import check_columns, missing_columns, record
from ._engines import Engine, in_process, process_pool
from ._guard import Stop, exclusive
from ._ledger import LEDGER_NAME, Ledger, open_ledger
from ._read import as_spec
from ._spec import CONFIRM_CASES, CampaignSpec
from ._worker import WORKER_LOST, CaseOutcome, campaign_compiled_mode, decode_result, make_task, run_batch

#: Times a batch may be lost while alone in flight before it is split (a single case is then
#: recorded as ``WorkerLost``, and runs again on resume).
MAX_ATTEMPTS = 2
#: Local pool breaks in a row, with no batch returned, after which the run stops.
MAX_BREAKS = 40
#: Exceptions (by class name: Dask's are imported only with Dask) that mean a batch's worker,
#: or the connection to it, was lost: the batch is sent again.
LOSS_NAMES = ("KilledWorker", "CommClosedError", "FutureCancelledError")
#: Most cases in one batch.
MAX_BATCH = 2000
#: Off a terminal (a batch job's log), a progress line this often [s].
LOG_EVERY_S = 30.0
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
    infeasible
        Of ``failed``, the cases whose answer is that nothing keeps the limits
        (``InfeasibleError``: an answer, with its binding limit in the message, not an error).
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
    unknown_columns: tuple[str, ...] = field(default_factory=tuple)
    other_campaign: str | None = None
    infeasible: int = 0

    @property
    def errors(self) -> int:
        """Cases that raised anything but ``InfeasibleError``."""
        return self.failed - self.infeasible

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
            "infeasible": self.infeasible,
            "errors": self.errors,
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
            "unknown_columns": list(self.unknown_columns),
            "other_campaign": self.other_campaign,
        }

    def summary(self) -> list[str]:
        lines = [
            f"{self.title}: {self.planned} cases planned, {self.done_before} finished before, "
            f"{self.ok + self.failed} run now ({self.ok} ok, {_failed_text(self.failed, self.infeasible)}) in {self.seconds:.1f} s "
            f"with {self.engine} ({self.rate:.3g} cases/s)",
        ]
        if self.lost_batches:
            lines.append(f"  {self.lost_batches} batch(es) lost with a worker and sent again; pool restarts: {self.restarts}")
        if self.failed:
            lines.append(
                f"  {'infeasible and failed' if self.infeasible and self.errors else 'infeasible' if self.infeasible else 'failed'} "
                f"cases are recorded with their reason: jointlock campaign status {shlex.quote(self.out)}"
            )
        if self.other_campaign:
            lines.append(
                f"  note: this folder held another campaign ({self.other_campaign}); its cases stay in the "
                "ledger, outside this campaign's plan (status counts them as older cases)"
            )
        for text in self.unknown_columns:
            lines.append(f"  column {text}; fix `columns` and run again: nothing is computed again")
        lines.append(f"  ledger: {Path(self.out) / LEDGER_NAME}")
        return lines


def run_campaign(
    campaign: CampaignSpec | str | Path,
    out: str | Path | None = None,
    *,
    engine: Engine | Callable[[], Engine] | None = None,
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
        default: a local process pool of ``workers`` processes (one per core).  An engine
        passed in stays open; a function returning one is called once the campaign is checked
        and there is work (nothing starts for a bad file), and its engine is closed at the end.
    retry_failed
        Run again the cases recorded as failed (they are skipped otherwise: a case's error is
        deterministic; a case whose worker was lost runs again in any case).
    max_cases
        Refuse a larger campaign (None: any size); the CLI's ``--yes`` lifts it.
    batch_seconds
        Work per batch [s] (> 0).
    progress
        Show a progress bar on stderr (cases done, rate, time left, failures); off a terminal,
        a line every :data:`LOG_EVERY_S` seconds.

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
    columns = check_columns(spec, plan)
    with exclusive(out), open_ledger(out, create=True) as ledger:
        previous = (ledger.meta("spec") or {}).get("source")
        other = previous if previous is not None and not _same_file(previous, spec.source) else None
        compiled = _remember(ledger, spec, columns)
        ledger.set_plan(plan.cases)
        finished = ledger.finished_keys(status="ok")
        if not retry_failed:
            finished |= ledger.finished_keys(status="error") - ledger.keys_with_error(WORKER_LOST)
        todo = [c for c in plan.cases if c.key not in finished]
        own = not isinstance(engine, Engine)  # made here: closed here
        if isinstance(engine, Engine):
            pass
        elif not todo:
            engine = dataclasses.replace(in_process(), description="none (nothing left to run)")
        elif engine is None:
            engine = process_pool(workers)
        else:
            engine = engine()
        try:
            result = _coordinate(
                spec, plan, todo, columns, ledger, engine, out, batch_seconds, progress, own, compiled
            )
            return dataclasses.replace(result, other_campaign=other)
        finally:
            if own:
                engine.close()


def _same_file(a: str, b: str) -> bool:
    try:
        return Path(a).resolve() == Path(b).resolve()
    except OSError:
        return a == b


def _remember(ledger: Ledger, spec: CampaignSpec, columns: Sequence[str]) -> CompiledMode:
    """Store the campaign in the ledger; when the columns changed, recompute the finished
    cases' records from their stored results (nothing runs again).  Returns the compiled mode
    its cases run in (:mod:`jointlock.compiled`): the one its finished cases ran in (``"auto"``
    for cases run before the mode was recorded), else the environment's, else ``"always"``.

    Raises
    ------
    CampaignError
        The environment asks for another mode than the finished cases ran in (the campaign's
        cases would not all be computed the same way).
    """
    if ledger.meta("columns") not in (None, list(columns)):
        keys = ledger.finished_keys(status="ok")
        ledger.update_records({key: record(res, columns) for key, res in ledger.results(keys)})
    recorded = ledger.meta("compiled")
    if recorded is None and ledger.finished_keys():
        recorded = "auto"  # finished before the mode was recorded: numpy below the thresholds, as auto
    chosen = chosen_compiled_mode()
    if recorded is not None and chosen is not None and chosen != recorded:
        raise CampaignError(
            f"the finished cases of this campaign ran in the compiled mode {recorded!r}, and {ENVIRONMENT_VARIABLE} "
            f"(or the program) asks for {chosen!r}: run it with {ENVIRONMENT_VARIABLE}={recorded}, so that every case "
            "is computed the same way, or into a new output folder"
        )
    mode: CompiledMode = recorded or chosen or campaign_compiled_mode()
    ledger.set_meta(spec=spec.to_dict(), columns=list(columns), jointlock=__version__, compiled=mode)
    return mode


@dataclass
class _Batch:
    """Cases sent together; ``attempts``: times lost while alone in flight (the culprit for
    sure); ``suspect``: lost with others, so sent again alone to find which one killed the pool."""

    cases: list[Case]
    attempts: int = 0
    suspect: bool = False


def _is_loss(exc: BaseException) -> bool:
    """Whether a batch's exception means its worker (or the connection to it) was lost, rather
    than a fault that would recur (a version mismatch, something that cannot be pickled)."""
    return isinstance(exc, (BrokenProcessPool, cf.CancelledError)) or type(exc).__name__ in LOSS_NAMES


class _Coordinator:
    """The loop of :func:`run_campaign` (see the module docstring)."""

    def __init__(
        self,
        spec: CampaignSpec,
        todo: list[Case],
        columns: Sequence[str],
        ledger: Ledger,
        engine: Engine,
        run_id: int,
        batch_seconds: float,
        bar: Progress,
        compiled: CompiledMode,
    ) -> None:
        self.spec, self.columns, self.ledger, self.engine = spec, tuple(columns), ledger, engine
        self.compiled = compiled
        self.run_id, self.batch_seconds, self.bar = run_id, batch_seconds, bar
        self.by_key = {c.key: c for c in todo}
        self.queue: deque[Case] = deque(todo)
        self.retry: deque[_Batch] = deque()
        self.in_flight: dict[cf.Future, _Batch] = {}
        self.counts = {"ok": 0, "failed": 0, "infeasible": 0, "lost": 0, "restarts": 0}
        self.case_seconds = 0.0
        self.breaks = 0  # pool breaks since a batch last came back
        self.unknown_columns: tuple[str, ...] | None = None

    def run(self) -> None:
        while self.queue or self.retry or self.in_flight:
            self._submit()
            self._collect()

    # -- sending -----------------------------------------------------------------------------

    def _batch_size(self, limit: int) -> int:
        finished = self.counts["ok"] + self.counts["failed"]
        if finished == 0:
            return 1  # the first batches measure the time per case
        want = max(1, int(self.batch_seconds / max(self.case_seconds / finished, 1e-6)))
        fair = math.ceil(len(self.queue) / (2 * limit))  # the last batches end together
        return max(1, min(want, fair, MAX_BATCH))

    def _submit(self) -> None:
        limit = 2 * self.engine.current_workers()
        while len(self.in_flight) < limit and (self.queue or self.retry):
            if any(b.suspect for b in self.in_flight.values()):
                return  # a suspect runs alone
            if self.retry and self.retry[0].suspect:
                if self.in_flight:
                    return  # wait until it can run alone
                batch = self.retry.popleft()
            elif self.retry:
                batch = self.retry.popleft()
            else:
                batch = _Batch([self.queue.popleft() for _ in range(min(self._batch_size(limit), len(self.queue)))])
            future = self.engine.executor.submit(
                run_batch, make_task(self.spec, batch.cases, self.columns, compiled=self.compiled)
            )
            self.in_flight[future] = batch

    # -- receiving ---------------------------------------------------------------------------

    def _collect(self) -> None:
        finished, _ = cf.wait(list(self.in_flight), timeout=0.25, return_when=cf.FIRST_COMPLETED)
        broken: list[_Batch] = []
        for future in finished:
            batch = self.in_flight.pop(future)
            try:
                outcomes = future.result()
            except BrokenProcessPool:
                broken.append(batch)
            except Exception as exc:
                if not _is_loss(exc):
                    raise CampaignError(
                        f"a batch failed in the engine ({self.engine.description}), not in one of its cases: "
                        f"{type(exc).__name__}: {str(exc)[:300]}"
                    ) from exc
                self._lost(batch, alone=True, reason=f"{type(exc).__name__}: {str(exc)[:200]}")
            else:
                self.store(outcomes)
        if broken:
            self._pool_broke(broken)

    def _pool_broke(self, broken: list[_Batch]) -> None:
        """A local pool breaks whole when one worker dies: batches that came back before are
        kept, every other one in flight is lost with it (charged only when it was alone)."""
        broken += [batch for _, batch in self._drain()]
        for batch in broken:
            self._lost(batch, alone=len(broken) == 1, reason="its worker process died")
        self.breaks += 1
        if self.breaks >= MAX_BREAKS:
            raise CampaignError(
                f"the local pool broke {self.breaks} times in a row without returning a batch: a worker "
                "process dies at start or on every case. From a script, guard its entry point with "
                "`if __name__ == \"__main__\":` (the workers import it again); else run with "
                "--in-process (engine=in_process()) to see the error"
            )
        if not self.engine.restart():
            raise CampaignError(f"the engine ({self.engine.description}) broke and cannot restart")
        self.counts["restarts"] += 1

    def _drain(self) -> list[tuple[cf.Future, _Batch]]:
        """Empty the in-flight set: store the batches that came back, return the others."""
        rest = []
        for future, batch in self.in_flight.items():
            if future.done() and not future.cancelled() and future.exception() is None:
                self.store(future.result())
            else:
                rest.append((future, batch))
        self.in_flight.clear()
        return rest

    def _lost(self, batch: _Batch, *, alone: bool, reason: str) -> None:
        self.counts["lost"] += 1
        if not alone:  # lost with others: which one killed the worker is not known yet
            self.retry.appendleft(_Batch(batch.cases, batch.attempts, suspect=True))
            return
        attempts = batch.attempts + 1
        if attempts < MAX_ATTEMPTS:
            self.retry.appendleft(_Batch(batch.cases, attempts, suspect=True))
        elif len(batch.cases) > 1:  # split, to find the case
            half = len(batch.cases) // 2
            self.retry.appendleft(_Batch(batch.cases[half:], MAX_ATTEMPTS - 1, suspect=True))
            self.retry.appendleft(_Batch(batch.cases[:half], MAX_ATTEMPTS - 1, suspect=True))
        else:
            message = f"the worker running this case was lost {attempts} times ({reason}); it runs again on resume"
            self.store([CaseOutcome(batch.cases[0].key, False, None, None, WORKER_LOST, message, (), 0.0, "")])

    def store(self, outcomes: list[CaseOutcome]) -> None:
        """Commit one returned batch (one transaction) and count it."""
        self.ledger.record(outcomes, self.by_key, self.run_id)
        self.breaks = 0 if any(o.error_type != WORKER_LOST for o in outcomes) else self.breaks
        for o in outcomes:
            self.counts["ok" if o.ok else "failed"] += 1
            self.counts["infeasible"] += int(not o.ok and o.error_type == INFEASIBLE)
            self.case_seconds += o.seconds
        if self.unknown_columns is None:
            first = next((o.result for o in outcomes if o.ok and o.result is not None), None)
            if first is not None:
                self.unknown_columns = tuple(missing_columns(decode_result(first), self.columns))
        failed = self.counts["failed"]
        self.bar.update(len(outcomes), note=f"{failed} failed" if failed else "")

    def stop(self, own_engine: bool) -> None:
        """After SIGINT/SIGTERM: keep the batches that came back, drop the others (they run
        again on resume), stop the workers of an engine this run made."""
        for future, _ in self._drain():
            future.cancel()
        if own_engine:
            self.engine.close(cancel=True)


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
    compiled: CompiledMode,
) -> CampaignRun:
    done_before = len(plan) - len(todo)
    run_id = ledger.start_run(engine.description, engine.workers, len(plan), len(todo), spec.source, __version__)
    start = time.perf_counter()
    bar = Progress(len(plan), "cases", enabled=None if progress else False, unit="cases", initial=done_before,
                   log_every_s=LOG_EVERY_S)  # fmt: skip
    loop = _Coordinator(spec, todo, columns, ledger, engine, run_id, batch_seconds, bar, compiled)
    stop = Stop()
    with stop:
        try:
            loop.run()
        except KeyboardInterrupt:
            stop.signal = stop.signal or "SIGINT"
        finally:
            stop.quiet()
            if stop.signal is not None or loop.in_flight:
                loop.stop(own_engine)
            bar.close()
            ledger.finish_run(run_id, loop.counts["ok"], loop.counts["failed"], stop.signal)
    return CampaignRun(
        title=spec.title,
        out=str(out),
        engine=engine.description,
        workers=engine.workers,
        planned=len(plan),
        done_before=done_before,
        to_run=len(todo),
        ok=loop.counts["ok"],
        failed=loop.counts["failed"],
        infeasible=loop.counts["infeasible"],
        remaining=ledger.counts()["remaining"],
        seconds=time.perf_counter() - start,
        case_seconds=loop.case_seconds,
        stopped_by=stop.signal,
        lost_batches=loop.counts["lost"],
        restarts=loop.counts["restarts"],
        excluded=plan.excluded,
        duplicates=plan.duplicates,
        columns=tuple(columns),
        unknown_columns=loop.unknown_columns or (),
    )


#: The error class of a case whose answer is "nothing keeps the limits" (counted apart).
INFEASIBLE = "InfeasibleError"


def _failed_text(failed: int, infeasible: int) -> str:
    """``"3 failed"``, or ``"4 infeasible, 0 failed"`` when some failures are answers."""
    return f"{infeasible} infeasible, {failed - infeasible} failed" if infeasible else f"{failed} failed"
