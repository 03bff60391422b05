"""Benchmark: what a failure case costs, and failure campaigns on each engine, in the same run.

Per-case cost (issue 29): cases of the three example campaigns (``examples/campaigns/``: the
halt7 halts, the canadarm7 jump runs, the puma6 tolerance angles), each run as a worker runs
it (:func:`jointlock.campaign.run_batch`: resolve, run, record, compress) in one warm process
(one case first, untimed: numba's load and the models' building), by this checkout in the
compiled mode ``always`` (what workers use) and ``auto``, and by the revision ``--before REV``
(default ``HEAD~1``; a temporary git worktree) in the same run.  Printed: median and min-max
seconds per case, the speed-up of the medians, and how far the recorded figures (k*, the
global torque, the smallest T, the verdicts, ...) moved against the revision before.

A halt campaign (halt7, 000's strategy: 7 joints x 8 locked angles x 2 halt times = 112 cases)
and a jump campaign (canadarm7, 001's task: 7 joints x 12 failure times = 84 cases), each run
serially in-process, on a local process pool of ``W`` workers and on a Dask LocalCluster of
``W`` workers (default 2), each twice on the same engine: cold (its workers start in the run:
imports, numba's load, the models) and warm (the same campaign again, on the started workers:
what a long campaign sees after its first seconds).  Printed per engine and run: wall time,
cases/s, speed-up over the serial run of the same kind and parallel efficiency (speed-up / W),
and the engine's overhead per case: ``(wall x W - sum of the cases' own times) / cases``
(scheduling, transfers, resolving, the ledger, workers' start-up, idle tails), also as a share
of the work.  Then the ledger's write
rate (one transaction per batch of 100 outcomes), and the driver planning 10^5 and 10^6 sampled
halt cases (``--plan``): wall time and peak RSS, each in a fresh process.  Aim: >= 1.8x serial with 2 workers, overhead
< 5 % of the work.

    python benchmarks/bench_campaign.py [WORKERS] [--before REV] [--cases N] [--costs-only | --engines-only] [--plan N,N]
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
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
"failure.angle_deg" = [-75.0, -50.0, -25.0, -5.0, 5.0, 25.0, 50.0, 75.0]
"halt.T" = [10.0, 12.0]
"""

JUMP = (ROOT / "examples" / "campaigns" / "jump_canadarm7.toml").read_text().replace(
    '"failure.time_s" = [1.0, 3.0, 5.0, 7.0, 9.0, 11.0]', f'"failure.time_s" = {[0.5 + i for i in range(12)]}'
)


def run_engines(name: str, text: str, workers: int, folder: Path) -> None:
    path = folder / f"{name}.toml"
    path.write_text(text)
    spec = campaign.load_campaign(path)
    rows = []
    serial = {}
    for label in ("serial (in-process)", f"process pool x{workers}", f"dask LocalCluster x{workers}"):
        start_s = 0.0
        t0 = time.perf_counter()
        if label.startswith("serial"):
            engine, n = campaign.in_process(), 1
        elif label.startswith("process"):
            engine, n = campaign.process_pool(workers), workers  # workers start in the first run
        else:
            engine, n = campaign.dask_cluster("local", workers=workers), workers
            start_s = time.perf_counter() - t0
        try:
            # cold: the engine's workers start (imports, numba's load, the models) in this run;
            # warm: the same campaign again on the same engine, its workers started
            for run in ("cold", "warm"):
                out = folder / f"{name}-{label.split()[0]}-{run}"
                res = campaign.run_campaign(spec, out, engine=engine, workers=workers, batch_seconds=10.0)
                cases = res.ok + res.failed
                wall = res.seconds
                serial.setdefault(run, wall)
                overhead = (wall * n - res.case_seconds) / cases
                rows.append(
                    (f"{label}, {run}", cases, wall, cases / wall, serial[run] / wall, serial[run] / wall / n,
                     1e3 * overhead, 100 * overhead * cases / res.case_seconds, start_s if run == "cold" else 0.0)
                )  # fmt: skip
        finally:
            engine.close()
    print(f"\n{name}: {spec.title} ({rows[0][1]} cases, {rows[1][2] / rows[1][1]:.3f} s per case serially, warm)")
    print(f"{'engine':<32}{'wall [s]':>9}{'cases/s':>9}{'speed-up':>10}{'efficiency':>11}"
          f"{'overhead/case':>15}{'of work':>9}{'cluster start':>15}")  # fmt: skip
    for label, _, wall, rate, speedup, eff, over_ms, over_pct, start_s in rows:
        start = f"{start_s:.1f} s" if start_s else "-"
        print(f"{label:<32}{wall:9.2f}{rate:9.2f}{speedup:9.2f}x{100 * eff:10.0f}%{over_ms:12.1f} ms"
              f"{over_pct:8.1f}%{start:>15}")  # fmt: skip


#: Run in a fresh interpreter on one source tree: cases of a campaign file as a worker runs them;
#: prints one JSON list of [key, seconds, record, error type] per case.
_CASES_SCRIPT = """
import json, sys
from jointlock import campaign
from jointlock.campaign._cases import plan_cases
from jointlock.campaign._columns import check_columns
spec = campaign.load_campaign(sys.argv[1])
plan = plan_cases(spec)
step = max(1, len(plan.cases) // int(sys.argv[2]))
cases = list(plan.cases[::step])[: int(sys.argv[2])]
columns = check_columns(spec, plan)
campaign.run_batch(campaign.make_task(spec, cases[:1], columns))  # warm: numba, models
outs = campaign.run_batch(campaign.make_task(spec, cases, columns))
print(json.dumps([[o.key, o.seconds, o.record, o.error_type] for o in outs]))
"""

CAMPAIGNS = ("halt7.toml", "jump_canadarm7.toml", "tolerance_puma6.toml")


def _run_cases(src: Path, campaign_file: Path, n: int, mode: str | None) -> list:
    env = {k: v for k, v in os.environ.items() if k not in ("JOINTLOCK_COMPILED", "PYTHONPATH")}
    env["PYTHONPATH"] = str(src)
    env["OMP_NUM_THREADS"] = env["OPENBLAS_NUM_THREADS"] = "1"
    if mode is not None:
        env["JOINTLOCK_COMPILED"] = mode
    out = subprocess.run(
        [sys.executable, "-c", _CASES_SCRIPT, str(campaign_file), str(n)],
        capture_output=True, text=True, env=env, check=True,
    )  # fmt: skip
    return json.loads(out.stdout.strip().splitlines()[-1])


def _moved(before: list, after: list) -> str:
    """The largest relative change of each recorded number, and the verdicts that changed."""
    rel: dict[str, float] = {}
    changed = 0
    for (_, _, a, ea), (_, _, b, eb) in zip(before, after):
        if ea != eb or (a is None) != (b is None):
            changed += 1
            continue
        for col, x in (a or {}).items():
            y = b.get(col)
            if isinstance(x, bool) or isinstance(y, bool) or x is None or y is None:
                changed += x != y
            elif isinstance(x, (int, float)) and isinstance(y, (int, float)):
                rel[col] = max(rel.get(col, 0.0), abs(x - y) / max(abs(x), abs(y), 1e-300))
    worst = sorted(rel.items(), key=lambda kv: -kv[1])[:4]
    text = ", ".join(f"{c.split('.', 1)[-1]} {v:.1e}" for c, v in worst) or "no numbers"
    return f"{changed} verdicts/errors changed; largest relative change: {text}"


def case_costs(before: str, n: int) -> None:
    """Seconds per case of the example campaigns: this checkout (always, auto) and ``before``."""
    with tempfile.TemporaryDirectory() as tmp:
        tree = Path(tmp) / "before"
        subprocess.run(["git", "-C", str(ROOT), "worktree", "add", "-q", "--detach", str(tree), before], check=True)
        try:
            rev = subprocess.run(["git", "-C", str(tree), "log", "-1", "--format=%h %s"], capture_output=True,
                                 text=True, check=True).stdout.strip()[:70]  # fmt: skip
            print(f"\nper-case cost, warm worker (run_batch), {n} cases of each campaign; before = {rev}")
            print(f"{'campaign':<22}{'code':<24}{'median [s]':>11}{'min-max [s]':>17}{'speed-up':>10}")
            for name in CAMPAIGNS:
                path = ROOT / "examples" / "campaigns" / name
                runs = {
                    "before": _run_cases(tree / "src", path, n, None),
                    "this, always (workers)": _run_cases(ROOT / "src", path, n, None),
                    "this, auto": _run_cases(ROOT / "src", path, n, "auto"),
                }
                base = statistics.median(r[1] for r in runs["before"])
                for label, rows in runs.items():
                    secs = [r[1] for r in rows]
                    med = statistics.median(secs)
                    print(f"{name:<22}{label:<24}{med:11.3f}{min(secs):8.3f}-{max(secs):<8.3f}{base / med:9.1f}x")
                print(f"{'':<22}always vs before: {_moved(runs['before'], runs['this, always (workers)'])}")
                print(f"{'':<22}auto vs before:   {_moved(runs['before'], runs['this, auto'])}")
        finally:
            subprocess.run(["git", "-C", str(ROOT), "worktree", "remove", "--force", str(tree)], check=False)


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


#: Run in a fresh interpreter: ``jointlock campaign plan`` of a sampled halt campaign of N cases
#: (no probe), then print its wall seconds and the process's peak RSS [MB].
_PLAN_SCRIPT = """
import resource, sys, time
from jointlock.cli import main
t0 = time.perf_counter()
main(["campaign", "plan", sys.argv[1], "--out", sys.argv[2], "--probe", "0", "--json"])
print(time.perf_counter() - t0, resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024)
"""


def driver_memory(folder: Path, sizes: list[int]) -> None:
    """The coordinator planning N sampled halt cases (joint and lock angle, as issue 29's
    100,002-case campaign): wall time and peak RSS, each in a fresh process."""
    print("\ndriver: `jointlock campaign plan` of a sampled halt7 campaign (--probe 0), a fresh process each")
    for n in sizes:
        path = folder / f"plan{n}.toml"
        path.write_text(
            f'title = "plan {n}"\nscenario = "{ROOT / "examples" / "halt_000.toml"}"\nseed = 0\n[set]\n'
            '"halt.minimum_T" = true\n"halt_config.samples" = 4000\n"halt_config.reachable" = false\n'
            f'[sample]\nn = {n}\nranges = {{ "failure.angle_deg" = [-170.0, 170.0], "failure.joint" = [1, 7] }}\n'
        )
        out = subprocess.run(
            [sys.executable, "-c", _PLAN_SCRIPT, str(path), str(folder / f"plan{n}-out")],
            capture_output=True, text=True, check=True,
        )  # fmt: skip
        seconds, rss = (float(x) for x in out.stdout.split()[-2:])
        print(f"  {n:>9,} planned cases: {seconds:7.1f} s ({1e3 * seconds / n:.2f} ms per case), peak RSS {rss:,.0f} MB")


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("workers", nargs="?", type=int, default=2)
    parser.add_argument("--before", default="HEAD~1", help="the revision the per-case cost is compared with")
    parser.add_argument("--cases", type=int, default=15, help="cases of each campaign in the per-case cost")
    parser.add_argument("--costs-only", action="store_true", help="the per-case cost only, no engines")
    parser.add_argument("--engines-only", action="store_true", help="the engines only, no per-case cost")
    parser.add_argument(
        "--plan", default="100000,1000000", help="planned cases the driver's memory is measured at (comma-separated; '' none)"
    )
    args = parser.parse_args(argv[1:])
    print(machine_info())
    if not args.engines_only:
        case_costs(args.before, args.cases)
    if args.costs_only:
        return 0
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        run_engines("halt", HALT, args.workers, folder)
        run_engines("jump", JUMP, args.workers, folder)
        ledger_rate(folder)
        driver_memory(folder, [int(n) for n in args.plan.split(",") if n.strip()])
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
