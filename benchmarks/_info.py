"""Machine and library facts printed at the top of every benchmark."""

from __future__ import annotations

import os
import platform


def machine_info() -> str:
    import numpy as np

    cpu = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo") as fh:
            for line in fh:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    threads = {k: os.environ.get(k) for k in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")}
    blas = "unknown"
    try:
        cfg = np.show_config(mode="dicts")
        blas = cfg.get("Build Dependencies", {}).get("blas", {}).get("name", "unknown")
    except Exception:  # noqa: BLE001 - older numpy
        pass
    try:
        import pinocchio

        pin_version = pinocchio.__version__
    except ImportError:
        pin_version = "absent"
    return (
        f"CPU: {cpu} ({os.cpu_count()} logical cores)\n"
        f"python {platform.python_version()}, numpy {np.__version__} (BLAS: {blas}), pinocchio {pin_version}\n"
        f"thread env: {threads}"
    )
