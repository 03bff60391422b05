"""Shared pieces of the campaign tests: a fast base scenario (halt7, 000 §5's state, a small
Monte Carlo: ~0.1 s a case) and a writer of campaign files."""

from __future__ import annotations

import os
import sqlite3
import subprocess
import sys
import time
from pathlib import Path

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"

#: Settings that make one halt case take ~0.1 s (the numbers checked do not depend on them).
FAST_SET = """
[set]
"halt_config.samples" = 300
"halt_config.no_refine" = true
"halt.n_samples" = 101
"""


def write_campaign(folder: Path, body: str, *, name: str = "campaign.toml", fast: bool = True) -> Path:
    """A campaign file on examples/halt_000.toml with ``body`` (then :data:`FAST_SET`: a body
    that ends inside a table is fine, one with its own ``[set]`` passes ``fast=False``)."""
    text = f'scenario = "{EXAMPLES / "halt_000.toml"}"\n' + body + (FAST_SET if fast else "")
    path = folder / name
    path.write_text(text)
    return path


def cli_env() -> dict[str, str]:
    env = dict(os.environ)
    env["MPLBACKEND"] = "Agg"
    env.pop("PYTEST_CURRENT_TEST", None)
    return env


def start_cli(*argv: str) -> subprocess.Popen:
    """``jointlock ARGV`` as a separate process (stdout and stderr captured)."""
    return subprocess.Popen(
        [sys.executable, "-m", "jointlock.cli", *argv],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=cli_env(),
    )


def ledger_count(out: Path) -> int:
    """Cases finished in the ledger of ``out`` (0 while it does not exist yet)."""
    path = out / "ledger.sqlite"
    if not path.exists():
        return 0
    try:
        with sqlite3.connect(str(path), timeout=5) as db:
            return db.execute("SELECT COUNT(*) FROM cases").fetchone()[0]
    except sqlite3.OperationalError:  # the tables are being created
        return 0


def wait_for_cases(out: Path, n: int, proc: subprocess.Popen, timeout: float = 120.0) -> int:
    """Wait until ``out``'s ledger holds at least ``n`` cases (or ``proc`` ended)."""
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        done = ledger_count(out)
        if done >= n or proc.poll() is not None:
            return done
        time.sleep(0.05)
    raise TimeoutError(f"{out}: fewer than {n} cases after {timeout} s")


def records(out: Path) -> dict[str, tuple[str, str | None, str | None]]:
    """``{key: (status, record JSON, error_type)}`` of a ledger."""
    with sqlite3.connect(str(out / "ledger.sqlite")) as db:
        return {k: (s, r, e) for k, s, r, e in db.execute("SELECT key, status, record, error_type FROM cases")}


def descendants(pid: int) -> dict[int, tuple[int, str]]:
    """``{pid: (parent pid, command line)}`` of every process under ``pid`` (Linux /proc)."""
    table = {}
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            stat = (entry / "stat").read_text()
            ppid = int(stat.rsplit(")", 1)[1].split()[1])
            cmd = (entry / "cmdline").read_bytes().replace(b"\0", b" ").decode(errors="replace")
        except (OSError, IndexError, ValueError):
            continue
        table[int(entry.name)] = (ppid, cmd)
    out: dict[int, tuple[int, str]] = {}
    frontier = [pid]
    while frontier:
        parent = frontier.pop()
        for child, (ppid, cmd) in table.items():
            if ppid == parent and child not in out:
                out[child] = (ppid, cmd)
                frontier.append(child)
    return out
