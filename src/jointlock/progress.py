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

    def __init__(self, total: int, desc: str = "", *, enabled: bool | None = None, stream=None) -> None:
        self.total = max(int(total), 1)
        self.desc = desc
        self.stream = stream if stream is not None else sys.stderr
        self.enabled = self.stream.isatty() if enabled is None else enabled
        self.done = 0
        self._start = time.perf_counter()
        self._last = 0.0

    def update(self, n: int = 1) -> None:
        self.done += n
        now = time.perf_counter()
        if self.enabled and (now - self._last > 0.1 or self.done >= self.total):
            self._last = now
            frac = min(self.done / self.total, 1.0)
            bar = "#" * int(30 * frac)
            self.stream.write(f"\r{self.desc} [{bar:<30}] {100 * frac:5.1f}% {now - self._start:6.1f}s")
            self.stream.flush()

    def close(self) -> None:
        if self.enabled:
            self.stream.write("\n")
            self.stream.flush()

    def __enter__(self) -> Progress:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def track(items: Iterable[T], total: int, desc: str = "", *, enabled: bool | None = None) -> Iterator[T]:
    """Iterate over ``items`` while showing a progress bar (see :class:`Progress`)."""
    with Progress(total, desc, enabled=enabled) as bar:
        for item in items:
            yield item
            bar.update()
