"""Regression against the numbers of the pre-refactor code: each example scenario's job results
and summary, recorded with the original command-line implementation (commit 44d6d37, files in
tests/data/golden/), must be reproduced by the in-process library run -- every number to a
relative 1e-9 (summation order may differ in the last bits), every flag and every key.  Text
fields may be reworded (they are not compared); timings and file paths are left out."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

import jointlock as jl
from jointlock.io.files import to_plain

ROOT = Path(__file__).resolve().parents[1]
GOLDEN = ROOT / "tests" / "data" / "golden"

#: The reduced settings the golden files were recorded with (those of tests/test_run.py).
FAST = {
    "halt_000": {"halt_config.samples": 3000, "halt.n_samples": 201},
    "jump_001": {"jump.sweep": 6},
    "replan_002": {"workspace.samples": 4000, "replan.steps": 10},
    "singular_004": {"singular.samples": 50},
}
#: Relative tolerance on a number [-]: bit-level differences only (summation order).
RTOL = 1e-9
#: Keys left out of the comparison: wall-clock timings and the paths of written files.
SKIP = {"elapsed_s", "files"}
#: Quantities that are zero up to round-off in these runs, compared to an absolute floor (a
#: relative tolerance on round-off itself fails whenever a summation order changes): the jump
#: task velocity with re-planning [m/s] (0 while J_r has full row rank) and the SSR of a fit
#: through as many samples as coefficients [kappa^2].
ROUNDOFF = {"task_jump_replan_max_m_s": 1e-12, "ssr": 1e-20}


def _compare(old, new, path: str, problems: list[str]) -> None:
    if isinstance(old, dict):
        if not isinstance(new, dict):
            problems.append(f"{path}: a table became {type(new).__name__}")
            return
        for key in sorted(set(old) - SKIP):
            if key not in new:
                problems.append(f"{path}/{key}: missing")
            else:
                _compare(old[key], new[key], f"{path}/{key}", problems)
    elif isinstance(old, list):
        if not isinstance(new, list) or len(new) != len(old):
            problems.append(f"{path}: list of {len(old)} became {new!r:.60}")
            return
        for i, (a, b) in enumerate(zip(old, new)):
            _compare(a, b, f"{path}[{i}]", problems)
    elif isinstance(old, bool) or old is None:
        if new != old:
            problems.append(f"{path}: {old!r} -> {new!r}")
    elif isinstance(old, (int, float)):
        floor = ROUNDOFF.get(path.rsplit("/", 1)[-1], 1e-300)
        if not isinstance(new, (int, float)) or not math.isclose(old, new, rel_tol=RTOL, abs_tol=floor):
            problems.append(f"{path}: {old!r} -> {new!r}")


@pytest.mark.parametrize("name", sorted(FAST))
def test_example_runs_reproduce_the_pre_refactor_numbers(name):
    golden = json.loads((GOLDEN / f"run_{name}.json").read_text())
    run = jl.run_scenario(jl.load_scenario(ROOT / "examples" / f"{name}.toml", FAST[name]))
    new = to_plain(run.to_dict())
    problems: list[str] = []
    for job, result in golden["jobs"].items():
        _compare(result, new["jobs"][job]["result"], f"jobs/{job}", problems)
    _compare(golden["summary"], new["summary"], "summary", problems)
    assert not problems, "\n".join(problems[:20])


def test_the_comparison_can_fail():
    problems: list[str] = []
    _compare({"a": 1.0, "b": [True, 2], "c": {"d": 3}}, {"a": 1.0 + 1e-6, "b": [False, 2], "c": {}}, "", problems)
    assert problems == ["/a: 1.0 -> 1.000001", "/b[0]: True -> False", "/c/d: missing"]
