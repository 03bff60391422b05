"""Shared by every benchmark: the machine and library facts printed at the top, and a best-of timer.

The scripts import it as ``from _info import best_of, machine_info`` (a script's own folder is on
``sys.path`` when it is run as ``python benchmarks/bench_*.py``).
"""

from __future__ import annotations

import os
import platform
import time
from collections.abc import Callable

THREAD_VARS = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")


def _cpu_model() -> str:
    cpu = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo") as fh:
            for line in fh:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return cpu


def _numpy_blas() -> str:
    import numpy as np

    try:
        cfg = np.show_config(mode="dicts")
        dep = cfg.get("Build Dependencies", {}).get("blas", {})
        return f"{dep.get('name', 'unknown')} {dep.get('version', '')}".strip()
    except Exception:  # noqa: BLE001 - older numpy: informational only
        return "unknown"


def machine_info() -> str:
    """CPU model, cores, Python, numpy + BLAS, Pinocchio, thread env and (if importable) threadpoolctl."""
    import numpy as np

    try:
        import pinocchio

        pin_version = pinocchio.__version__
    except ImportError:
        pin_version = "absent"
    cores = f"{os.cpu_count()} logical cores"
    if hasattr(os, "sched_getaffinity"):
        cores += f", {len(os.sched_getaffinity(0))} in affinity"
    threads = {k: os.environ.get(k) for k in THREAD_VARS}
    lines = [
        f"CPU: {_cpu_model()} ({cores})",
        f"python {platform.python_version()}, numpy {np.__version__} (BLAS: {_numpy_blas()}), "
        f"pinocchio {pin_version}",
        f"thread env: {threads}",
    ]
    try:
        from threadpoolctl import threadpool_info
    except ImportError:
        lines.append("threadpoolctl: not installed")
    else:
        for info in threadpool_info():
            lines.append(
                f"  {info.get('internal_api')} {info.get('version')} threads={info.get('num_threads')}"
            )
    return "\n".join(lines)


def best_of(fn: Callable[[], object], repeat: int = 3) -> float:
    """The shortest of ``repeat`` wall-clock timings of ``fn()``, in seconds."""
    best = float("inf")
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best
