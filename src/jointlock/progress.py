"""A small progress bar for long runs (sampling, GA generations, kappa sweeps).

Shown on stderr only when stderr is a terminal and not disabled; never mixes into stdout
(so ``--json`` output stays clean).  Library code passes ``progress=None`` by default; the
CLI passes a :class:`Progress` unless ``--quiet``.
"""

from __future__ import annotations

import sys
import time
from collections.abc import Iterable, Iterator
from typing import TypeVar

T = TypeVar("T")


class Progress:
    """Progress reporter: ``with Progress(total, "sampling") as p: p.update(k)``."""

    def __init__(
        self,
        total: int,
        desc: str = "",
        *,
        enabled: bool | None = None,
        stream=None,
        unit: str | None = None,
        initial: int = 0,
        log_every_s: float | None = None,
    ) -> None:
        self.total = max(int(total), 1)
        self.desc = desc
        self.stream = stream if stream is not None else sys.stderr
        tty = self.stream.isatty()
        self.enabled = tty if enabled is None else enabled
        # off a terminal (a batch job's log): a plain line every log_every_s seconds instead
        self._log_every = log_every_s if enabled is None and not tty else None
        self.unit = unit
        self.done = int(initial)
        self._initial = int(initial)
        self._start = time.perf_counter()
        self._last = 0.0
        self._width = 0

    def update(self, n: int = 1, *, note: str = "") -> None:
        """Count ``n`` more items done; ``note`` (e.g. "3 failed") is shown after the bar.

        With a ``unit`` the line also shows done/total, the rate since the bar started (items
        counted in ``initial`` excluded) and the time left at that rate."""
        self.done += n
        now = time.perf_counter()
        if self._log_every is not None and (now - self._last >= self._log_every or self.done >= self.total):
            self._last = now
            self.stream.write(self._status(now).lstrip("\r") + (f", {note}" if note else "") + "\n")
            self.stream.flush()
        elif self.enabled and (now - self._last > 0.1 or self.done >= self.total):
            self._last = now
            line = self._status(now)
            if note:
                line += f", {note}"
            self.stream.write(line + " " * max(self._width - len(line), 0))
            self._width = len(line)
            self.stream.flush()

    def _status(self, now: float) -> str:
        frac = min(self.done / self.total, 1.0)
        bar = "#" * int(30 * frac)
        elapsed = now - self._start
        line = f"\r{self.desc} [{bar:<30}] {100 * frac:5.1f}% {elapsed:6.1f}s"
        if self.unit is not None:
            rate = (self.done - self._initial) / elapsed if elapsed > 0 else 0.0
            left = (self.total - self.done) / rate if rate > 0 else float("nan")
            eta = _clock(left) if left == left else "?"
            line += f" {self.done}/{self.total} {self.unit}, {rate:.3g}/s, ETA {eta}"
        return line

    def close(self) -> None:
        if self.enabled:
            self.stream.write("\n")
            self.stream.flush()

    def __enter__(self) -> Progress:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def _clock(seconds: float) -> str:
    """``"1:02:03"`` / ``"2:03"`` from seconds."""
    m, sec = divmod(int(round(seconds)), 60)
    h, m = divmod(m, 60)
    return f"{h}:{m:02d}:{sec:02d}" if h else f"{m}:{sec:02d}"


def track(items: Iterable[T], total: int, desc: str = "", *, enabled: bool | None = None) -> Iterator[T]:
    """Iterate over ``items`` while showing a progress bar (see :class:`Progress`)."""
    with Progress(total, desc, enabled=enabled) as bar:
        for item in items:
            yield item
            bar.update()
