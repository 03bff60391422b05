"""Reading a campaign back: :func:`campaign_status` (counts, runs, failures) and
:func:`campaign_table` (one row per case: key, parameters, recorded columns, error), written as
CSV or Parquet."""

from __future__ import annotations

import csv
import io
import json
import shlex
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..errors import CampaignError
from ..io.files import atomic_write_bytes, atomic_write_text
from ._cases import params_text
from ._guard import running_pid
from ._ledger import open_ledger

#: Failures listed by ``status`` (all of them are in the ledger and the export).
MAX_FAILURES_SHOWN = 20


@dataclass(frozen=True)
class CampaignStatus:
    """Where a campaign stands (``jointlock campaign status DIR``).

    Attributes
    ----------
    planned, ok, failed, remaining
        Cases of the campaign file as last run, and how many finished or not.
    outside
        Finished cases no longer in the campaign file (kept in the ledger, not exported).
    runs
        One entry per ``run`` (engine, workers, counts, ``stopped_by``).
    failures
        Failed cases: ``index``, ``key``, ``params``, ``error_type``, ``error_message``.
    case_seconds
        Sum of the finished cases' own times [s].
    """

    title: str
    source: str
    out: str
    planned: int
    ok: int
    failed: int
    remaining: int
    outside: int
    runs: tuple[dict[str, Any], ...]
    failures: tuple[dict[str, Any], ...]
    case_seconds: float
    warned: int = 0
    columns: tuple[str, ...] = field(default_factory=tuple)
    running_pid: str | None = None

    @property
    def complete(self) -> bool:
        return self.remaining == 0

    @property
    def infeasible(self) -> int:
        """Of ``failed``, the cases whose answer is that nothing keeps the limits
        (``InfeasibleError``, its binding limit in the message): an answer, not an error."""
        return sum(1 for f in self.failures if f["error_type"] == "InfeasibleError")

    def to_dict(self) -> dict[str, Any]:
        return {
            "title": self.title,
            "campaign_file": self.source,
            "out": self.out,
            "planned": self.planned,
            "ok": self.ok,
            "failed": self.failed,
            "infeasible": self.infeasible,
            "errors": self.failed - self.infeasible,
            "remaining": self.remaining,
            "outside": self.outside,
            "complete": self.complete,
            "running_pid": self.running_pid,
            "case_seconds": self.case_seconds,
            "cases_with_warnings": self.warned,
            "columns": list(self.columns),
            "runs": list(self.runs),
            "failures": list(self.failures),
        }

    def summary(self) -> list[str]:
        state = "complete" if self.complete else f"{self.remaining} to run"
        if self.running_pid is not None:
            state += f"; a run is in progress (pid {self.running_pid})"
        lines = [
            f"{self.title} ({self.source})",
            f"cases: {self.planned} planned, {self.ok} ok, "
            + (f"{self.infeasible} infeasible (an answer), {self.failed - self.infeasible} failed" if self.infeasible
               else f"{self.failed} failed")
            + f", {state}"
            + (f"; {self.outside} older case(s) no longer in the file" if self.outside else ""),
            f"work: {self.case_seconds:.1f} s over {len(self.runs)} run(s)"
            + (f"; {self.warned} case(s) raised warnings" if self.warned else ""),
        ]
        for i, r in enumerate(self.runs):
            running = self.running_pid is not None and i == len(self.runs) - 1 and not r["finished_at"]
            how = run_ending(r, running=running)
            source = f" ({r['source']})" if r.get("source") and r["source"] != self.source else ""
            lines.append(
                f"  run {r['id']} {r['started_at']}{source}: {r['engine']}; {r['ok']} ok, {r['failed']} failed "
                f"of {r['to_run']} sent; {how}"
            )
        for title, group in (
            ("infeasible cases (nothing keeps the limits: why, for each)", [f for f in self.failures if f["error_type"] == "InfeasibleError"]),
            ("failed cases", [f for f in self.failures if f["error_type"] != "InfeasibleError"]),
        ):  # fmt: skip
            if not group:
                continue
            lines.append(f"{title} ({len(group)}):")
            for f in group[:MAX_FAILURES_SHOWN]:
                message = _one_line(_without_prefix(f["error_message"] or ""), limit=240)
                lines.append(f"  #{f['index']} ({params_text(f['params'], limit=80)}): {f['error_type']}: {message}")
            if len(group) > MAX_FAILURES_SHOWN:
                lines.append(f"  ... and {len(group) - MAX_FAILURES_SHOWN} more (export lists them all)")
        if not self.complete and self.running_pid is None:
            lines.append(f"resume: {shlex.join(['jointlock', 'campaign', 'run', self.source, '--out', self.out])}")
        return lines


def run_ending(run: dict[str, Any], *, running: bool = False) -> str:
    """How a run ended, in words."""
    if running:
        return "running"
    if run["stopped_by"]:
        return f"stopped by {run['stopped_by']}"
    return "finished" if run["finished_at"] else "cut off (the coordinator was killed)"


def _without_prefix(message: str) -> str:
    """A case's error without the scenario file in front (the same for every case): from the
    job's name on (``job [halt]: ...``)."""
    at = message.find("job [")
    return message[at:] if at > 0 else message


def _one_line(text: str | None, limit: int = 160) -> str:
    line = " ".join((text or "").split())
    return line if len(line) <= limit else line[: limit - 3] + "..."


def campaign_status(out: str | Path) -> CampaignStatus:
    """The status of the campaign whose output folder is ``out``."""
    with open_ledger(out) as ledger:
        spec = ledger.meta("spec") or {}
        counts = ledger.counts()
        rows = ledger.rows()
        failures = tuple(
            {k: r[k] for k in ("index", "key", "params", "error_type", "error_message")}
            for r in rows
            if r["status"] == "error"
        )
        return CampaignStatus(
            title=spec.get("title", str(out)),
            source=spec.get("source", "?"),
            out=str(out),
            planned=counts["planned"],
            ok=counts["ok"],
            failed=counts["failed"],
            remaining=counts["remaining"],
            outside=counts["outside"],
            runs=tuple(ledger.runs()),
            failures=failures,
            case_seconds=sum(r["seconds"] or 0.0 for r in rows),
            warned=sum(1 for r in rows if r["warnings"]),
            columns=tuple(ledger.meta("columns") or ()),
            running_pid=running_pid(out),
        )


@dataclass(frozen=True, eq=False)
class CampaignTable:
    """The finished cases of a campaign, one row each.

    Attributes
    ----------
    params
        The varied fields (columns named as in the campaign file, e.g. ``failure.joint``).
    metrics
        The recorded result columns (``halt.feasible``, ...).
    rows
        ``{"key", "index", "status", "case_seed", <params>, <metrics>, "error_type",
        "error_message", "warnings", "seconds"}`` per case, in plan order (``case_seed``: the
        seed the case ran with; a varied ``seed`` is a parameter like any other).
    """

    params: tuple[str, ...]
    metrics: tuple[str, ...]
    rows: tuple[dict[str, Any], ...]

    @property
    def names(self) -> list[str]:
        return ["key", "index", "status", "case_seed", *self.params, *self.metrics, "error_type", "error_message",
                "warnings", "seconds"]  # fmt: skip

    def column(self, name: str) -> list[Any]:
        if name not in self.names:
            raise CampaignError(f"no column {name!r} in this campaign; columns: {', '.join(self.names)}")
        return [row.get(name) for row in self.rows]

    def to_dict(self) -> dict[str, list[Any]]:
        """``{column: values}`` (plain JSON data)."""
        return {name: self.column(name) for name in self.names}

    def csv_text(self) -> str:
        """The table as CSV (lists and dictionaries as JSON text, None as an empty cell)."""
        buf = io.StringIO()
        writer = csv.writer(buf, lineterminator="\n")
        writer.writerow(self.names)
        for row in self.rows:
            writer.writerow([_csv_cell(row.get(n)) for n in self.names])
        return buf.getvalue()

    def write_csv(self, path: str | Path) -> Path:
        atomic_write_text(path, self.csv_text())
        return Path(path)

    def write_parquet(self, path: str | Path) -> Path:
        """Write the table as Parquet (needs pyarrow: the ``parquet`` extra); a column whose
        values mix types is written as JSON text."""
        try:
            import pyarrow as pa
            import pyarrow.parquet as pq
        except ImportError:
            raise CampaignError(
                "Parquet export needs pyarrow: pip install 'jointlock[parquet]' (or export --csv)"
            ) from None
        arrays = {}
        for name in self.names:
            values = self.column(name)
            try:
                arrays[name] = pa.array(values)
            except (pa.ArrowInvalid, pa.ArrowTypeError):
                arrays[name] = pa.array([None if v is None else json.dumps(v) for v in values], type=pa.string())
        buf = pa.BufferOutputStream()
        pq.write_table(pa.table(arrays), buf)
        atomic_write_bytes(path, buf.getvalue().to_pybytes())
        return Path(path)


def _csv_cell(value: Any) -> Any:
    if value is None:
        return ""
    if isinstance(value, (list, dict)):
        return json.dumps(value)
    return value


def campaign_table(out: str | Path, *, include_outside: bool = False) -> CampaignTable:
    """The finished cases of the campaign in ``out`` (only those of the campaign file as last
    run, unless ``include_outside``)."""
    with open_ledger(out) as ledger:
        spec = ledger.meta("spec") or {}
        columns = tuple(ledger.meta("columns") or ())
        rows = ledger.rows(planned_only=not include_outside)
    params = _param_names(spec, rows)
    table_rows = []
    for r in rows:
        row = {"key": r["key"], "index": r["index"], "status": r["status"], "case_seed": r["seed"]}
        row.update({p: r["params"].get(p) for p in params})
        rec = r["record"] or {}
        row.update({m: rec.get(m) for m in columns})
        row.update(error_type=r["error_type"], error_message=r["error_message"], warnings=r["warnings"] or None,
                   seconds=r["seconds"])  # fmt: skip
        table_rows.append(row)
    return CampaignTable(params, columns, tuple(table_rows))


def _param_names(spec: dict[str, Any], rows: Sequence[dict[str, Any]]) -> tuple[str, ...]:
    names = list(spec.get("grid", {})) + list(spec.get("zip", {}))
    names += list((spec.get("sample") or {}).get("ranges", {}))
    for r in rows:  # cases of an earlier version of the file
        names += [p for p in r["params"] if p not in names]
    return tuple(dict.fromkeys(names))
