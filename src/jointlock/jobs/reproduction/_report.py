"""The table of :func:`jointlock.jobs.reproduction.reproduce`: its rows and the report."""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any, ClassVar

from ...io.files import atomic_write_json
from .._common import JobResult

REPRODUCED = "reproduced"
NOT_REPRODUCED = "not reproduced"
OURS_ONLY = "ours only"
#: The statuses of a row, in the order the summary counts them.
STATUSES: tuple[str, ...] = (REPRODUCED, NOT_REPRODUCED, OURS_ONLY)
#: The paper's value of a row whose paper's number did not survive (001).
LOST = "(lost)"


@dataclass(frozen=True)
class ReproductionRow:
    """One line of the table.

    Attributes
    ----------
    paper
        The seed (``"000"``, ``"001"``, ``"002"``, ``"004"``).
    key
        Stable id of the quantity within its paper (e.g. ``"torque_k0"``).
    quantity
        What is compared, in words (with units).
    paper_value, ours
        The paper's printed value and ours, as text.
    status
        ``"reproduced"``, ``"not reproduced"`` or ``"ours only"``.
    reason
        One line saying why (empty where nothing needs saying).
    """

    paper: str
    key: str
    quantity: str
    paper_value: str
    ours: str
    status: str
    reason: str = ""

    @property
    def agreement(self) -> str:
        """The status, with the reason after a colon when there is one."""
        return self.status + (f": {self.reason}" if self.reason else "")

    def to_dict(self) -> dict[str, str]:
        """The row's JSON object: its fields and ``agreement``."""
        return asdict(self) | {"agreement": self.agreement}


@dataclass(frozen=True, eq=False)  # arrays inside: compare to_dict() instead
class ReproductionReport(JobResult):
    """What :func:`reproduce` returns: the rows of the papers it ran, how long each paper
    took and the readings behind them.

    Attributes
    ----------
    papers
        The seeds that ran, in table order.
    rows
        The table's rows, paper after paper.
    elapsed_s
        Wall time of each paper's experiments [s], aligned with ``papers``.
    notes
        One line per paper: the readings and sample counts.
    """

    job: ClassVar[str] = "reproduce"

    papers: tuple[str, ...]
    rows: tuple[ReproductionRow, ...]
    elapsed_s: tuple[float, ...]
    notes: tuple[str, ...]

    def row(self, paper: str, key: str) -> ReproductionRow:
        """The row of ``paper`` with ``key`` (KeyError if there is none)."""
        for r in self.rows:
            if r.paper == paper and r.key == key:
                return r
        raise KeyError((paper, key))

    @property
    def counts(self) -> dict[str, int]:
        """Number of rows per status, ``{"reproduced": n, "not reproduced": n, "ours only": n}``."""
        return {s: sum(r.status == s for r in self.rows) for s in STATUSES}

    def table(self) -> str:
        """The table as Markdown (also readable as plain text)."""
        header = ["paper", "quantity", "paper's value", "ours", "agreement"]
        lines = ["| " + " | ".join(header) + " |", "|" + "|".join(" --- " for _ in header) + "|"]
        for r in self.rows:
            cells = [r.paper, r.quantity, r.paper_value, r.ours, r.agreement]
            lines.append("| " + " | ".join(str(c).replace("|", "/") for c in cells) + " |")
        return "\n".join(lines)

    def to_dict(self) -> dict[str, Any]:
        """``{"rows": [...], "elapsed_s": {paper: s}, "notes": [...]}``: what
        ``jointlock reproduce --json`` prints."""
        return {
            "rows": [r.to_dict() for r in self.rows],
            "elapsed_s": dict(zip(self.papers, self.elapsed_s)),
            "notes": list(self.notes),
        }

    def summary(self) -> list[str]:
        """The lines ``jointlock reproduce`` prints: the table, the counts and timings, the notes."""
        counts = self.counts
        totals = (
            f"{counts[REPRODUCED]} reproduced, {counts[NOT_REPRODUCED]} not reproduced, "
            f"{counts[OURS_ONLY]} ours only; "
            + ", ".join(f"{p}: {t:.1f} s" for p, t in zip(self.papers, self.elapsed_s))
        )
        return [*self.table().split("\n"), "", totals, *(f"- {n}" for n in self.notes)]

    def write(self, out: str | Path) -> list[str]:
        """Write ``result.json`` (= :meth:`to_dict`) into the folder ``out``; returns its name."""
        folder = Path(out)
        folder.mkdir(parents=True, exist_ok=True)
        atomic_write_json(folder / "result.json", self.to_dict())
        return ["result.json"]


def within_printed(value: float, printed: float, decimals: int) -> bool:
    """The one rule of every ``reproduce`` row: ``value`` is within half a unit of the paper's
    last printed digit of ``printed`` (``decimals`` after the point; 0 for an integer)."""
    return abs(value - printed) <= 0.5 * 10.0 ** (-decimals) * (1 + 1e-9)


def _g(x: float, digits: int = 4) -> str:
    return f"{x:.{digits}g}"


def _pct(x: float) -> str:
    return f"{100 * x:+.1f} %"


def _list(values: Iterable[float]) -> str:
    """A printed vector as the paper's ``[a, b, ...]`` (Python's list text)."""
    return str(list(values))
