"""Every Python example in examples/ runs on the public API and its checks hold."""

from __future__ import annotations

import runpy
import sys
from pathlib import Path

import pytest

EXAMPLES = sorted((Path(__file__).resolve().parents[1] / "examples").glob("*.py"))


def test_there_is_one_example_per_seed():
    assert {p.stem for p in EXAMPLES} >= {"halt_000", "jump_001", "replan_002", "singular_004"}


@pytest.mark.parametrize("path", EXAMPLES, ids=[p.stem for p in EXAMPLES])
def test_example_runs(path, tmp_path, monkeypatch, capsys):
    out = tmp_path / "out"
    monkeypatch.setattr(sys, "argv", [str(path), str(out)])
    monkeypatch.chdir(tmp_path)
    runpy.run_path(str(path), run_name="__main__")  # each ends with assertions on checked quantities
    assert any(out.rglob("*.png")), "an example writes its figures"
    assert capsys.readouterr().out.strip()
