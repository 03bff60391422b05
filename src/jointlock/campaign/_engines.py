"""Where a campaign's batches run: one code path, the :class:`concurrent.futures.Executor`
protocol, behind three engines.

* :func:`in_process` -- this process, one batch at a time (tests, debugging).
* :func:`process_pool` -- the default: a local :class:`~concurrent.futures.ProcessPoolExecutor`,
  one worker per core, started by ``forkserver`` (``spawn`` where there is none), never
  ``fork`` (a forked numpy/BLAS state is not safe); a broken pool (a worker died) is restarted.
* :func:`dask_cluster` -- a Dask cluster when one machine is not enough: a ``LocalCluster``
  (``"local"``), a running scheduler (``"tcp://HOST:8786"``) or a scheduler file (HPC, e.g. one
  started by dask-jobqueue); through ``Client.get_executor()``.  Dask is the optional ``dask``
  extra, imported only here and only when asked for.  Dask re-runs the tasks of a worker that
  died on the others.

An :class:`Engine` is the parallel resource passed to
:func:`~jointlock.campaign.run_campaign`: an argument, not hidden state.
"""

from __future__ import annotations

import concurrent.futures as cf
import difflib
import logging
import multiprocessing
import os
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..bounds import shown
from ..errors import CampaignError


class InProcessExecutor(cf.Executor):
    """An executor that runs each call at once, in the calling process."""

    def submit(self, fn: Callable[..., Any], /, *args: Any, **kwargs: Any) -> cf.Future:
        future: cf.Future = cf.Future()
        future.set_running_or_notify_cancel()
        try:
            future.set_result(fn(*args, **kwargs))
        except Exception as exc:  # handed to the caller through the future (not Ctrl-C: that stops)
            future.set_exception(exc)
        return future


@dataclass
class Engine:
    """A campaign's parallel resource.

    Attributes
    ----------
    name
        ``"in-process"``, ``"process pool"`` or ``"dask"``.
    executor
        Where batches are submitted.
    workers
        How many batches run at once (sizes the batches and the number in flight).
    description
        One line for people (workers, start method, scheduler address).
    dashboard
        Dask's dashboard link (None for the local engines).
    """

    name: str
    executor: cf.Executor
    workers: int
    description: str
    dashboard: str | None = None
    _restart: Callable[[], cf.Executor] | None = field(default=None, repr=False)
    _close: Callable[[], None] | None = field(default=None, repr=False)
    _kill: Callable[[], None] | None = field(default=None, repr=False)
    _count: Callable[[], int] | None = field(default=None, repr=False)
    _closed: bool = field(default=False, repr=False)

    def current_workers(self) -> int:
        """Workers now (a Dask cluster may grow or shrink while a campaign runs; >= 1)."""
        return max(self._count(), 1) if self._count is not None else self.workers

    def restart(self) -> bool:
        """Replace a broken executor (a local pool whose worker died); False when this engine
        cannot (Dask replaces its workers itself)."""
        if self._restart is None:
            return False
        self.executor = self._restart()
        return True

    def close(self, *, cancel: bool = False) -> None:
        """Release the workers; ``cancel``: drop queued batches and stop running ones now."""
        if self._closed:
            return
        self._closed = True
        if cancel and self._kill is not None:
            self._kill()
        if self._close is not None:
            self._close()
        else:
            self.executor.shutdown(wait=not cancel, cancel_futures=cancel)

    def __enter__(self) -> Engine:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def in_process() -> Engine:
    """Run every batch in this process, one after the other."""
    return Engine("in-process", InProcessExecutor(), 1, "in-process (1 worker)")


def default_workers() -> int:
    """Cores this process may use."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        return os.cpu_count() or 1


def _start_method() -> str:
    return "forkserver" if "forkserver" in multiprocessing.get_all_start_methods() else "spawn"


def process_pool(workers: int | None = None) -> Engine:
    """A local process pool of ``workers`` processes (default: one per core)."""
    from ._worker import init_worker

    n = default_workers() if workers is None else workers
    if isinstance(n, bool) or not isinstance(n, int) or n < 1:
        raise CampaignError(f"workers must be an integer >= 1; got {workers!r}")
    method = _start_method()
    ctx = multiprocessing.get_context(method)
    if method == "forkserver":  # workers fork from a server that has imported jointlock once
        ctx.set_forkserver_preload(["jointlock.campaign._worker"])

    def make() -> cf.ProcessPoolExecutor:
        return cf.ProcessPoolExecutor(
            max_workers=n, mp_context=ctx, initializer=init_worker, initargs=(os.getpid(),)
        )

    engine = Engine("process pool", make(), n, f"process pool, {n} worker(s) ({method})")

    def restart() -> cf.Executor:
        engine.executor.shutdown(wait=False, cancel_futures=True)
        return make()

    def kill() -> None:
        processes = getattr(engine.executor, "_processes", None) or {}
        engine.executor.shutdown(wait=False, cancel_futures=True)
        for process in list(processes.values()):
            process.terminate()

    engine._restart, engine._kill = restart, kill
    return engine


def dask_cluster(
    address: str | None = "local",
    *,
    scheduler_file: str | None = None,
    workers: int | None = None,
    timeout_s: float = 20.0,
) -> Engine:
    """A Dask cluster as a campaign engine.

    Parameters
    ----------
    address
        ``"local"``: start a ``LocalCluster`` of ``workers`` processes (default one per core),
        one thread each; ``"tcp://HOST:PORT"``: connect to a running scheduler.
    scheduler_file
        Connect through a scheduler file instead (``dask scheduler --scheduler-file F``; on
        SLURM/PBS, dask-jobqueue or ``dask-mpi`` write one).
    workers
        Workers of a ``LocalCluster``.
    timeout_s
        How long to wait for the scheduler to answer [s].  Workers may join later (a batch
        queue may start them after the campaign): batches wait on the scheduler for them.
    """
    try:
        import dask
        from distributed import Client, LocalCluster
    except ImportError:
        raise CampaignError(
            "the Dask engine needs the optional 'dask' extra: pip install 'jointlock[dask]'"
        ) from None
    if scheduler_file is not None:
        _check_scheduler_file(scheduler_file)
    if address not in (None, "local") and "://" not in address and ":" not in address:
        hint = " (did you mean 'local'?)" if difflib.get_close_matches(address, ["local"], cutoff=0.6) else ""
        raise CampaignError(f"--dask must be 'local' or a scheduler's address tcp://HOST:PORT; got {address!r}{hint}")
    if logging.getLogger().getEffectiveLevel() > logging.DEBUG:  # Dask's INFO lines, unless --debug
        logging.getLogger("distributed").setLevel(logging.ERROR)
    cluster = None
    try:
        if scheduler_file is not None:
            client = Client(scheduler_file=scheduler_file, timeout=timeout_s)
            where = f"scheduler file {scheduler_file}"
        elif address in (None, "local"):
            n = default_workers() if workers is None else workers
            # Dask's nannies set MALLOC_TRIM_THRESHOLD_, which fixes glibc's mmap threshold: every
            # large numpy temporary is then mapped and unmapped, ~1.3x slower halt cases
            with dask.config.set({"distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_": None}):
                cluster = LocalCluster(
                    n_workers=n,
                    threads_per_worker=1,
                    processes=True,
                    dashboard_address=":0",
                    silence_logs=logging.getLogger("distributed").getEffectiveLevel(),
                )
            client = Client(cluster)
            client.wait_for_workers(n, timeout=max(timeout_s, 60.0))
            where = "LocalCluster"
        else:
            client = Client(address, timeout=timeout_s)
            where = address
    except (OSError, TimeoutError, ValueError, TypeError, AssertionError) as exc:  # Dask's own checks
        if cluster is not None:
            cluster.close()
        raise CampaignError(
            f"cannot reach the Dask cluster ({scheduler_file or address}): {type(exc).__name__}: {exc}"
        ) from None

    known = {"workers": 0, "at": -1e9}

    def count() -> int:
        """Worker processes now (asked at most every 2 s; the last answer while the scheduler
        does not reply).  ``Client.nthreads`` lists every worker, whatever the cluster's size."""
        now = time.monotonic()
        if now - known["at"] > 2.0:
            known["at"] = now
            try:
                known["workers"] = len(client.nthreads())
            except Exception:  # noqa: BLE001 - a busy or restarting scheduler: keep the last count
                pass
        return int(known["workers"])

    executor = client.get_executor(pure=False)

    def close() -> None:
        executor.shutdown(wait=False)
        client.close()
        if cluster is not None:
            cluster.close()

    n_workers = count()
    return Engine(
        "dask",
        executor,
        max(n_workers, 1),
        f"dask ({where}), {n_workers} worker(s)" + ("" if n_workers else " so far"),
        dashboard=client.dashboard_link,
        _close=close,
        _count=count,
    )


def _check_scheduler_file(path: str) -> None:
    """A Dask scheduler file: a JSON object with the scheduler's ``address`` (a string), as
    ``dask scheduler --scheduler-file F`` writes it; anything else in one line."""
    import json

    file = Path(path)
    if file.is_dir():
        raise CampaignError(f"Dask scheduler file {shown(path)} is a folder, not a file")
    if not file.is_file():
        raise CampaignError(
            f"Dask scheduler file {shown(path)} does not exist: start the scheduler first "
            f"(dask scheduler --scheduler-file {path})"
        )
    try:
        data = json.loads(file.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, ValueError) as exc:
        raise CampaignError(f"Dask scheduler file {shown(path)} is not a scheduler's JSON: {exc}") from None
    if not isinstance(data, dict) or not isinstance(data.get("address"), str):
        raise CampaignError(
            f"Dask scheduler file {shown(path)} has no scheduler address (a JSON object with \"address\": "
            f"\"tcp://HOST:PORT\", as `dask scheduler --scheduler-file` writes)"
        )
