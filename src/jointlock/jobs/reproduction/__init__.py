"""Reproduce the seeds: each seed paper's published experiment, re-run with the documented
readings, as one table -- quantity, the paper's value, ours, and whether it is reproduced.

The papers' values come from :mod:`jointlock.papers` (typed there once); this package only
computes ours and compares.  Nothing here is tuned to approach a printed number: the readings
are those chosen in the robot factories and ``docs/`` (halt7: modified DH, theta column not
added; k in deg/s^6; puma6: standard DH, a2/d4/d6 recovered; canadarm7: frames from 004's
eq. 15, 004's virtual length formula).  Sample counts are the papers' (000's K = 36000) or the
CLI defaults (001: 40 failure times; 004: 2000 samples per condition); only 004's completeness
search, which no row reports, runs from 64 starts instead of 256.  The whole table takes
about 5 s (001's study most of it).

Use :func:`reproduce` (``jointlock reproduce`` prints its :class:`ReproductionReport`);
one module per paper computes its rows (``_p000`` ... ``_p004``), ``_report`` holds the table.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterable, Mapping

from ...errors import ScenarioError
from ...papers import p000, p001
from ...progress import Progress
from ...robots import PUMA6_A2, PUMA6_D4, PUMA6_D6
from ._p000 import rows_000
from ._p001 import JUMP_FAILURE_TIMES, notes_001_task, rows_001
from ._p002 import rows_002
from ._p004 import (
    COMPLETENESS_STARTS,
    DET_SINGULAR,
    EQ15_SAMPLES,
    SUFFICIENCY_SAMPLES,
    rows_004,
    solve_table3,
)
from ._report import (
    LOST,
    NOT_REPRODUCED,
    OURS_ONLY,
    REPRODUCED,
    STATUSES,
    ReproductionReport,
    ReproductionRow,
)

__all__ = [
    "COMPLETENESS_STARTS",
    "DET_SINGULAR",
    "EQ15_SAMPLES",
    "JUMP_FAILURE_TIMES",
    "LOST",
    "NOT_REPRODUCED",
    "OURS_ONLY",
    "PAPERS",
    "PAPER_ROWS",
    "REPRODUCED",
    "STATUSES",
    "SUFFICIENCY_SAMPLES",
    "ReproductionReport",
    "ReproductionRow",
    "notes_001_task",
    "reproduce",
    "rows_000",
    "rows_001",
    "rows_002",
    "rows_004",
    "solve_table3",
]

#: The seeds with a reproduction, in the order of the table.
PAPERS: tuple[str, ...] = ("000", "001", "002", "004")

#: Each paper's experiments.
PAPER_ROWS: Mapping[str, Callable[[], list[ReproductionRow]]] = {
    "000": rows_000,
    "001": rows_001,
    "002": rows_002,
    "004": rows_004,
}


def _notes() -> dict[str, str]:
    """One line per paper: the readings and sample counts behind its rows."""
    ((joint, angle),) = p000.SCENARIO["lock"].items()
    task = p001.TASK
    steps = round(task["duration_s"] / task["dt_s"])
    return {
        "000": f"000: halt7 read as modified DH with the theta column not added, joint {joint} locked at "
        f"{angle:g} deg, K = {p000.SAMPLES} (000's), seed 0, no refinement; k in deg/s^6.",
        "001": "001: NOTES-001's task on canadarm7 (001's own arm was lost), "
        f"{JUMP_FAILURE_TIMES} failure times, verification at all {steps} control steps.",
        "002": f"002: puma6 with a2 = {PUMA6_A2:g}, d4 = {PUMA6_D4:g}, d6 = {PUMA6_D6:g} m; "
        "002 prints 2-decimal vectors truncated.",
        "004": "004: 004's virtual-length formula, unrounded; Table 3's Cond3-Cond5 angles re-solved with them "
        "(004 prints them rounded to 0.1 deg, where they are only near-singular); "
        f"{SUFFICIENCY_SAMPLES} samples per condition.",
    }


def reproduce(papers: str | Iterable[str] = PAPERS, *, progress: bool = False) -> ReproductionReport:
    """Re-run the published experiments of ``papers`` and compare with their printed numbers.

    Parameters
    ----------
    papers
        Seeds to run, any of :data:`PAPERS` (one name or several); they run, and appear in
        the table, in the order of :data:`PAPERS`.  Default: all four (about 5 s).
    progress
        Show a progress bar on stderr (one step per paper) when it is a terminal.

    Returns
    -------
    ReproductionReport
        The rows, each paper's wall time [s] and the readings behind them.

    Raises
    ------
    ScenarioError
        A name in ``papers`` that is not one of :data:`PAPERS`, or none given.
    """
    wanted = {papers} if isinstance(papers, str) else set(papers)
    unknown = sorted(wanted - set(PAPERS), key=str)
    if unknown or not wanted:
        raise ScenarioError(
            f"papers must name some of {', '.join(PAPERS)}; "
            + (f"unknown: {', '.join(map(repr, unknown))}" if unknown else "got none")
        )
    chosen = tuple(p for p in PAPERS if p in wanted)
    rows: list[ReproductionRow] = []
    elapsed: list[float] = []
    with Progress(len(chosen), "reproduce", enabled=None if progress else False) as bar:
        for paper in chosen:
            t0 = time.perf_counter()
            rows += PAPER_ROWS[paper]()
            elapsed.append(time.perf_counter() - t0)
            bar.update()
    notes = _notes()
    return ReproductionReport(chosen, tuple(rows), tuple(elapsed), tuple(notes[p] for p in chosen))
