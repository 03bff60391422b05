"""The ledger of a campaign: one SQLite file (``OUT/ledger.sqlite``), written only by the
coordinating process, one transaction per returned batch.

Tables (queryable with any SQLite client; ``params`` and ``record`` are JSON text, e.g.
``SELECT json_extract(params, '$."failure.joint"'), json_extract(record, '$."halt.feasible"')
FROM cases``):

* ``meta(name, value)`` -- the campaign (``spec``, JSON), the ledger format, creation time.
* ``planned(key, idx, params, seed)`` -- the cases of the campaign file as last run.
* ``cases(key, status, params, seed, record, result, error_type, error_message, warnings,
  seconds, worker, finished_at, run_id)`` -- one row per case ever finished (``status`` 'ok' or
  'error'; ``result`` is the jobs' ``to_dict()`` as zlib-compressed JSON).
* ``runs(id, started_at, finished_at, engine, workers, planned, to_run, ok, failed, stopped_by,
  source, jointlock)``: each ``run`` with its campaign file and jointlock version.

Keys identify cases by their resolved inputs, so a row is never written twice for one case: a
re-run case (``--retry-failed``) replaces its row.
"""

from __future__ import annotations

import datetime as _dt
import json
import sqlite3
from collections.abc import Iterable, Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from ..errors import CampaignError
from ._cases import Case
from ._worker import CaseOutcome, decode_result

#: File name of the ledger in a campaign's output folder.
LEDGER_NAME = "ledger.sqlite"
#: Version of the ledger's tables.
LEDGER_FORMAT = 1

_SCHEMA = """
CREATE TABLE IF NOT EXISTS meta (name TEXT PRIMARY KEY, value TEXT NOT NULL);
CREATE TABLE IF NOT EXISTS planned (
    key TEXT PRIMARY KEY, idx INTEGER NOT NULL, params TEXT NOT NULL, seed INTEGER NOT NULL);
CREATE TABLE IF NOT EXISTS cases (
    key TEXT PRIMARY KEY,
    status TEXT NOT NULL CHECK (status IN ('ok', 'error')),
    params TEXT NOT NULL,
    seed INTEGER NOT NULL,
    record TEXT,
    result BLOB,
    error_type TEXT,
    error_message TEXT,
    warnings TEXT NOT NULL DEFAULT '[]',
    seconds REAL,
    worker TEXT,
    finished_at TEXT NOT NULL,
    run_id INTEGER);
CREATE TABLE IF NOT EXISTS runs (
    id INTEGER PRIMARY KEY AUTOINCREMENT,
    started_at TEXT NOT NULL, finished_at TEXT, engine TEXT NOT NULL, workers INTEGER NOT NULL,
    planned INTEGER NOT NULL, to_run INTEGER NOT NULL, ok INTEGER NOT NULL DEFAULT 0,
    failed INTEGER NOT NULL DEFAULT 0, stopped_by TEXT, source TEXT, jointlock TEXT);
"""


def _now() -> str:
    return _dt.datetime.now(_dt.UTC).isoformat(timespec="seconds")


def _json(value: Any) -> str:
    return json.dumps(value, separators=(",", ":"), allow_nan=False)


class Ledger:
    """An open ledger (use :func:`open_ledger`; close it, or use it as a context manager)."""

    def __init__(self, path: Path, connection: sqlite3.Connection) -> None:
        self.path = path
        self._db = connection

    # -- lifetime ----------------------------------------------------------------------------

    def close(self) -> None:
        self._db.close()

    def __enter__(self) -> Ledger:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    @contextmanager
    def _transaction(self) -> Iterator[sqlite3.Connection]:
        with self._db:  # commits, or rolls back on an exception
            yield self._db

    # -- meta --------------------------------------------------------------------------------

    def meta(self, name: str, default: Any = None) -> Any:
        row = self._db.execute("SELECT value FROM meta WHERE name = ?", (name,)).fetchone()
        return default if row is None else json.loads(row[0])

    def set_meta(self, **values: Any) -> None:
        with self._transaction() as db:
            db.executemany(
                "INSERT OR REPLACE INTO meta (name, value) VALUES (?, ?)",
                [(k, _json(v)) for k, v in values.items()],
            )

    # -- the plan ----------------------------------------------------------------------------

    def set_plan(self, cases: Sequence[Case]) -> None:
        """Replace the planned cases with ``cases`` (one transaction)."""
        with self._transaction() as db:
            db.execute("DELETE FROM planned")
            db.executemany(
                "INSERT INTO planned (key, idx, params, seed) VALUES (?, ?, ?, ?)",
                [(c.key, c.index, _json(dict(c.params)), c.seed) for c in cases],
            )

    def finished_keys(self, *, status: str | None = None) -> set[str]:
        """Keys of the finished cases (of one ``status`` when given)."""
        if status is None:
            rows = self._db.execute("SELECT key FROM cases")
        else:
            rows = self._db.execute("SELECT key FROM cases WHERE status = ?", (status,))
        return {r[0] for r in rows}

    def keys_with_error(self, error_type: str) -> set[str]:
        """Keys of the cases that failed with ``error_type``."""
        return {r[0] for r in self._db.execute("SELECT key FROM cases WHERE error_type = ?", (error_type,))}

    # -- runs and outcomes -------------------------------------------------------------------

    def start_run(self, engine: str, workers: int, planned: int, to_run: int, source: str, version: str) -> int:
        """Record a run of the campaign file ``source`` by jointlock ``version``; its id."""
        with self._transaction() as db:
            cur = db.execute(
                "INSERT INTO runs (started_at, engine, workers, planned, to_run, source, jointlock) "
                "VALUES (?, ?, ?, ?, ?, ?, ?)",
                (_now(), engine, workers, planned, to_run, source, version),
            )
        assert cur.lastrowid is not None  # set by the INSERT
        return int(cur.lastrowid)

    def finish_run(self, run_id: int, ok: int, failed: int, stopped_by: str | None) -> None:
        with self._transaction() as db:
            db.execute(
                "UPDATE runs SET finished_at = ?, ok = ?, failed = ?, stopped_by = ? WHERE id = ?",
                (_now(), ok, failed, stopped_by, run_id),
            )

    def record(self, outcomes: Iterable[CaseOutcome], cases: dict[str, Case], run_id: int) -> None:
        """Store one returned batch (one transaction)."""
        now = _now()
        rows = []
        for o in outcomes:
            case = cases[o.key]
            rows.append(
                (
                    o.key,
                    "ok" if o.ok else "error",
                    _json(dict(case.params)),
                    case.seed,
                    None if o.record is None else _json(dict(o.record)),
                    o.result,
                    o.error_type,
                    o.error_message,
                    _json(list(o.warnings)),
                    o.seconds,
                    o.worker,
                    now,
                    run_id,
                )
            )
        with self._transaction() as db:
            db.executemany(
                "INSERT OR REPLACE INTO cases (key, status, params, seed, record, result, error_type, "
                "error_message, warnings, seconds, worker, finished_at, run_id) "
                "VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)",
                rows,
            )

    def update_records(self, records: dict[str, dict[str, Any]]) -> None:
        """Replace the recorded columns of finished cases (after the columns changed)."""
        with self._transaction() as db:
            db.executemany(
                "UPDATE cases SET record = ? WHERE key = ?", [(_json(r), k) for k, r in records.items()]
            )

    # -- reading -----------------------------------------------------------------------------

    def counts(self) -> dict[str, int]:
        """``planned``, ``ok``, ``failed``, ``remaining`` (of the plan) and ``outside`` (finished
        cases no longer in the plan)."""
        planned = self._db.execute("SELECT COUNT(*) FROM planned").fetchone()[0]
        by = dict(
            self._db.execute(
                "SELECT c.status, COUNT(*) FROM cases c JOIN planned p ON p.key = c.key GROUP BY c.status"
            ).fetchall()
        )
        total = self._db.execute("SELECT COUNT(*) FROM cases").fetchone()[0]
        ok, failed = by.get("ok", 0), by.get("error", 0)
        return {
            "planned": planned,
            "ok": ok,
            "failed": failed,
            "remaining": planned - ok - failed,
            "outside": total - ok - failed,
        }

    def rows(self, *, planned_only: bool = True, status: str | None = None) -> list[dict[str, Any]]:
        """Finished cases as dictionaries (``params``, ``record``, ``warnings`` decoded; no
        ``result``), in plan order (cases outside the plan last)."""
        where = []
        if planned_only:
            where.append("p.key IS NOT NULL")
        if status is not None:
            where.append("c.status = ?")
        sql = (
            "SELECT c.key, p.idx, c.status, c.params, c.seed, c.record, c.error_type, c.error_message, "
            "c.warnings, c.seconds, c.worker, c.finished_at, c.run_id FROM cases c "
            "LEFT JOIN planned p ON p.key = c.key"
            + (" WHERE " + " AND ".join(where) if where else "")
            + " ORDER BY p.idx IS NULL, p.idx, c.finished_at"
        )
        names = ("key", "index", "status", "params", "seed", "record", "error_type", "error_message",
                 "warnings", "seconds", "worker", "finished_at", "run_id")  # fmt: skip
        out = []
        for row in self._db.execute(sql, (status,) if status is not None else ()):
            item = dict(zip(names, row))
            item["params"] = json.loads(item["params"])
            item["record"] = None if item["record"] is None else json.loads(item["record"])
            item["warnings"] = json.loads(item["warnings"])
            out.append(item)
        return out

    def result(self, key: str) -> dict[str, Any] | None:
        """The jobs' ``to_dict()`` of a finished case, or None."""
        row = self._db.execute("SELECT result FROM cases WHERE key = ?", (key,)).fetchone()
        return None if row is None or row[0] is None else decode_result(row[0])

    def results(self, keys: Iterable[str]) -> Iterator[tuple[str, dict[str, Any]]]:
        """``(key, result)`` of the finished, successful cases among ``keys``."""
        for key in keys:
            res = self.result(key)
            if res is not None:
                yield key, res

    def runs(self) -> list[dict[str, Any]]:
        cur = self._db.execute(
            "SELECT id, started_at, finished_at, engine, workers, planned, to_run, ok, failed, stopped_by, "
            "source, jointlock FROM runs ORDER BY id"
        )
        names = [d[0] for d in cur.description]
        return [dict(zip(names, row)) for row in cur]


def ledger_path(out: str | Path) -> Path:
    return Path(out) / LEDGER_NAME


def open_ledger(out: str | Path, *, create: bool = False) -> Ledger:
    """Open the ledger of the campaign output folder ``out`` (``create``: make the folder and
    the ledger when absent).

    Raises
    ------
    CampaignError
        No ledger in ``out`` (and not ``create``), or a file that is not a jointlock ledger.
    """
    path = ledger_path(out)
    if not create and not path.is_file():
        raise CampaignError(
            f"{str(out)!r} holds no campaign ledger ({LEDGER_NAME}); run `jointlock campaign run "
            "CAMPAIGN.toml --out DIR` first"
        )
    try:
        if create:  # the coordinator: the only writer
            Path(out).mkdir(parents=True, exist_ok=True)
            db = sqlite3.connect(str(path), timeout=30.0)
            db.execute("PRAGMA journal_mode=WAL")
            db.execute("PRAGMA synchronous=NORMAL")  # a power cut may lose the last batches: they run again
            db.executescript(_SCHEMA)
        else:  # readers (status, export, report, plan) never write, and work on a read-only copy
            db = sqlite3.connect(f"{path.resolve().as_uri()}?mode=ro", uri=True, timeout=30.0)
        ledger = Ledger(path, db)
        fmt = ledger.meta("format")
        if fmt is None and create:
            ledger.set_meta(format=LEDGER_FORMAT, created_at=_now())
        elif fmt != LEDGER_FORMAT:
            raise CampaignError(f"{path}: ledger format {fmt} is not {LEDGER_FORMAT} (another jointlock version?)")
    except sqlite3.OperationalError as exc:
        raise CampaignError(f"{path}: cannot open the campaign ledger: {exc}") from None
    except sqlite3.DatabaseError as exc:
        raise CampaignError(f"{path}: not a jointlock campaign ledger ({exc})") from None
    return ledger
