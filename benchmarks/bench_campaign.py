"""Benchmark: failure campaigns on each engine, in the same run.

A halt campaign (halt7, 000's strategy: 7 joints x 4 locked angles x 2 halt times = 56 cases)
and a jump campaign (canadarm7, 001's task: 7 joints x 4 failure times = 28 cases), each run
serially in-process, on a local process pool of ``W`` workers and on a Dask LocalCluster of
``W`` workers (default 2).  Printed per engine: wall time, cases/s, speed-up over the serial
run and parallel efficiency (speed-up / W), and the engine's overhead per case:
``(wall x W - sum of the cases' own times) / cases`` (scheduling, transfers, resolving, the
ledger, workers' start-up, idle tails), also as a share of the work.  Then the ledger's write
rate (one transaction per batch of 100 outcomes).  Aim: >= 1.8x serial with 2 workers, overhead
< 5 % of the work.

    python benchmarks/bench_campaign.py [WORKERS]
"""

from __future__ import annotations

import sys
import tempfile
import time
from pathlib import Path

from _info import machine_info

from jointlock import campaign

ROOT = Path(__file__).resolve().parents[1]

HALT = f"""
title = "bench: halt7 halts"
scenario = "{ROOT / "examples" / "halt_000.toml"}"
[set]
"halt_config.samples" = 4000
"halt_config.reachable" = false
"halt.minimum_T" = true
[grid]
"failure.joint" = [1, 2, 3, 4, 5, 6, 7]
"failure.angle_deg" = [-60.0, -20.0, 20.0, 60.0]
"halt.T" = [10.0, 12.0]
"""

JUMP = (ROOT / "examples" / "campaigns" / "jump_canadarm7.toml").read_text().replace(
    '"failure.time_s" = [1.0, 3.0, 5.0, 7.0, 9.0, 11.0]', '"failure.time_s" = [2.0, 5.0, 8.0, 11.0]'
)


def run_engines(name: str, text: str, workers: int, folder: Path) -> None:
    path = folder / f"{name}.toml"
    path.write_text(text)
    spec = campaign.load_campaign(path)
    rows = []
    serial_wall = None
    for label in ("serial (in-process)", f"process pool x{workers}", f"dask LocalCluster x{workers}"):
        out = folder / f"{name}-{label.split()[0]}"
        start_s = 0.0
        if label.startswith("serial"):
            engine, n = campaign.in_process(), 1
        elif label.startswith("process"):
            engine, n = None, workers  # created (and its workers started) inside the run: start-up counted
        else:
            t0 = time.perf_counter()
            engine, n = campaign.dask_cluster("local", workers=workers), workers
            start_s = time.perf_counter() - t0
        try:
            res = campaign.run_campaign(spec, out, engine=engine, workers=workers, batch_seconds=10.0)
        finally:
            if engine is not None:
                engine.close()
        cases = res.ok + res.failed
        wall = res.seconds
        serial_wall = wall if serial_wall is None else serial_wall
        overhead = (wall * n - res.case_seconds) / cases
        rows.append(
            (label, cases, wall, cases / wall, serial_wall / wall, serial_wall / wall / n, 1e3 * overhead,
             100 * overhead * cases / res.case_seconds, start_s)
        )  # fmt: skip
    print(f"\n{name}: {spec.title} ({rows[0][1]} cases, {rows[0][2] / rows[0][1]:.3f} s per case serially)")
    print(f"{'engine':<26}{'wall [s]':>9}{'cases/s':>9}{'speed-up':>10}{'efficiency':>11}"
          f"{'overhead/case':>15}{'of work':>9}{'cluster start':>15}")  # fmt: skip
    for label, _, wall, rate, speedup, eff, over_ms, over_pct, start_s in rows:
        start = f"{start_s:.1f} s" if start_s else "-"
        print(f"{label:<26}{wall:9.2f}{rate:9.2f}{speedup:9.2f}x{100 * eff:10.0f}%{over_ms:12.1f} ms"
              f"{over_pct:8.1f}%{start:>15}")  # fmt: skip


def ledger_rate(folder: Path, n: int = 20000, batch: int = 100) -> None:
    """Outcomes of the size a halt case gives (a 2 kB compressed result), written as the
    coordinator writes them."""
    import os

    from jointlock.campaign import Case, CaseOutcome, open_ledger

    blob = os.urandom(2000)
    record = {f"halt.col{i}": 1.0 + i for i in range(12)}
    cases = {f"{i:024x}": Case(i, {"failure.joint": i % 7 + 1, "halt.T": 10.0}, f"{i:024x}", i) for i in range(n)}
    keys = list(cases)
    with open_ledger(folder / "ledger-bench", create=True) as ledger:
        ledger.set_plan(list(cases.values()))
        t0 = time.perf_counter()
        for start in range(0, n, batch):
            outs = [CaseOutcome(k, True, record, blob, None, None, (), 0.1, "host:1") for k in keys[start:start + batch]]
            ledger.record(outs, cases, 1)
        dt = time.perf_counter() - t0
    print(f"\nledger: {n} outcomes in batches of {batch}: {n / dt:,.0f} cases/s ({1e6 * dt / n:.0f} us per case)")


def main(argv: list[str]) -> int:
    workers = int(argv[1]) if len(argv) > 1 else 2
    print(machine_info())
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        run_engines("halt", HALT, workers, folder)
        run_engines("jump", JUMP, workers, folder)
        ledger_rate(folder)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
