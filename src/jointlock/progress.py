"""Progress of long runs (sampling, GA generations, kappa sweeps, campaigns), through tqdm.

A bar is shown on a terminal's stderr (tqdm) or, in a Jupyter notebook, as tqdm's notebook
widget (its text bar where ipywidgets is missing); never on stdout, so ``--json``
output stays clean.  Off a terminal and outside a notebook (a batch job's log) nothing is
drawn; a caller that asks for it (``log_every_s``, campaigns) gets a plain line now and then
instead.  Library code passes ``progress=None``/``False`` by default; the CLI passes on what
the user asked for (``--quiet``, ``--json``, whether stderr is a terminal).
"""

from __future__ import annotations

import importlib.util
import math
import shutil
import sys
import time
from collections.abc import Iterable, Iterator
from typing import Any, TypeVar

T = TypeVar("T")


def in_notebook() -> bool:
    """True inside a Jupyter kernel (where stderr is not a terminal but a bar still shows)."""
    shell = sys.modules.get("IPython")
    if shell is None:
        return False
    ip = getattr(shell, "get_ipython", lambda: None)()
    return ip is not None and "IPKernelApp" in getattr(ip, "config", {})


def _isatty(stream: Any) -> bool:
    try:
        return bool(stream.isatty())
    except (AttributeError, ValueError):  # no isatty, or a closed stream
        return False


class Progress:
    """Progress reporter: ``with Progress(total, "sampling") as p: p.update(k)``.

    ``enabled``: None = a bar on a terminal or in a notebook, nothing elsewhere (or a line every
    ``log_every_s`` seconds when given); True / False = a bar always / never.  ``unit`` names
    what is counted (rate and time left are shown); ``initial`` counts items already done
    (a resumed campaign) without counting them in the rate.
    """

    def __init__(
        self,
        total: int,
        desc: str = "",
        *,
        enabled: bool | None = None,
        stream: Any = None,
        unit: str | None = None,
        initial: int = 0,
        log_every_s: float | None = None,
    ) -> None:
        self.total = max(int(total), 1)
        self.desc = desc
        self.unit = unit
        self.stream = stream if stream is not None else sys.stderr
        interactive = _isatty(self.stream) or (stream is None and in_notebook())
        self.enabled = interactive if enabled is None else bool(enabled)
        # off a terminal (a batch job's log): a plain line every log_every_s seconds instead
        self._log_every = log_every_s if enabled is None and not interactive else None
        self.done = int(initial)
        self._initial = int(initial)
        self._start = time.perf_counter()
        self._last = -math.inf  # the first update logs (perf_counter's zero is arbitrary: boot, on Linux)
        self._bar: Any = None
        if self.enabled:
            # a terminal that reports no size (a fresh pty) would hide the bar or draw it empty
            size = shutil.get_terminal_size((100, 24)) if _isatty(self.stream) else None
            self._bar = _tqdm(stream)(
                total=self.total,
                desc=desc,
                unit=f" {unit}" if unit else "it",
                initial=self.done,
                file=self.stream,
                ncols=None if size is None else size.columns,
                nrows=None if size is None else max(size.lines, 2),
                mininterval=0.1,
                leave=True,
            )

    def update(self, n: int = 1, *, note: str = "") -> None:
        """Count ``n`` more items done; ``note`` (e.g. "3 failed") is shown after the bar."""
        self.done += n
        if self._bar is not None:
            if note:
                self._bar.set_postfix_str(note, refresh=False)
            self._bar.update(n)
            return
        now = time.perf_counter()
        if self._log_every is not None and (now - self._last >= self._log_every or self.done >= self.total):
            self._last = now
            self.stream.write(self._status(now) + (f", {note}" if note else "") + "\n")
            self.stream.flush()

    def _status(self, now: float) -> str:
        """``desc [#####     ]  50.0%   12.0s 5/10 cases, 0.4/s, ETA 0:12`` (the log line)."""
        frac = min(self.done / self.total, 1.0)
        elapsed = now - self._start
        line = f"{self.desc} [{'#' * int(30 * frac):<30}] {100 * frac:5.1f}% {elapsed:6.1f}s"
        if self.unit is not None:
            rate = (self.done - self._initial) / elapsed if elapsed > 0 else 0.0
            left = (self.total - self.done) / rate if rate > 0 else float("nan")
            eta = _clock(left) if left == left else "?"
            line += f" {self.done}/{self.total} {self.unit}, {rate:.3g}/s, ETA {eta}"
        return line

    def close(self) -> None:
        if self._bar is not None:
            self._bar.close()
            self._bar = None

    def __enter__(self) -> Progress:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def _tqdm(stream: Any) -> Any:
    """tqdm's notebook widget for stderr in a notebook with ipywidgets, else its text bar."""
    if stream is None and in_notebook() and importlib.util.find_spec("ipywidgets") is not None:
        from tqdm.notebook import tqdm as notebook_tqdm

        return notebook_tqdm
    from tqdm import tqdm as text_tqdm

    return text_tqdm


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
