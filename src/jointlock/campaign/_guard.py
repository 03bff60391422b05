"""What keeps a campaign's ledger whole: one coordinator per output folder (a lock file), and
SIGINT/SIGTERM turned into an orderly stop."""

from __future__ import annotations

import contextlib
import os
import signal
import threading
from collections.abc import Iterator
from pathlib import Path
from typing import Any

from ..errors import CampaignError


@contextlib.contextmanager
def exclusive(out: Path) -> Iterator[None]:
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


def running_pid(out: str | Path) -> str | None:
    """The pid of the coordinator writing ``out`` now, or None when no run holds its lock."""
    path = Path(out) / ".campaign.lock"
    try:
        import fcntl
    except ImportError:
        return None
    try:
        with open(path) as fh:
            try:
                fcntl.flock(fh, fcntl.LOCK_SH | fcntl.LOCK_NB)
            except OSError:
                return fh.read().strip() or "?"
            fcntl.flock(fh, fcntl.LOCK_UN)
    except OSError:  # no lock file: never run here
        return None
    return None


class Stop:
    """SIGINT/SIGTERM while a campaign runs: remember which, and raise KeyboardInterrupt
    where the coordinator is (everything it committed stays; the ledger rolls back a
    transaction cut short)."""

    def __init__(self) -> None:
        self.signal: str | None = None
        self._old: dict[int, Any] = {}

    def __enter__(self) -> Stop:
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
