"""``jointlock reproduce --json`` has a row for every headline figure of the four seeds."""

from __future__ import annotations

import contextlib
import io
import json

import pytest

from jointlock.cli import main

#: Headline figures (row keys) per seed: 000 §5 (CP, gain, torques, k*, feasibility); 001 (no
#: numbers survived: ours only); 002 (worked examples, eq. 21/22, ranges, gamma, q at gamma);
#: 004 (virtual lengths, eq. 15, Table 3, sufficiency of Cond1-Cond5).
HEADLINES = {
    "000": ["cp_q_sub", "cp_gain", "torque_k0", "torque_k", "torque_reduction", "k_opt", "feasible"],
    "001": ["mean_reduction", "share_improved", "limits"],
    "002": [f"example_E{i}" for i in range(1, 6)]
    + ["eq21", "range_180", "range_2", "gamma", "q_at_gamma", "eq22"],
    "004": [f"virtual_{k}" for k in "acdefhk"]
    + ["eq15"]
    + [f"table3_cond{i}" for i in range(1, 6)]
    + [f"sufficient_cond{i}" for i in range(1, 6)],
}
#: What we expect of each (the reproduce table in README.md).
EXPECTED = {
    ("000", "cp_q_sub"): "not reproduced",
    ("000", "torque_k0"): "not reproduced",
    ("000", "feasible"): "not reproduced",
    ("001", "mean_reduction"): "ours only",
    ("002", "gamma"): "reproduced",
    ("002", "eq22"): "reproduced",
    ("004", "sufficient_cond1"): "not reproduced",
    ("004", "sufficient_cond2"): "reproduced",
    ("004", "table3_cond3"): "reproduced",
}


@pytest.fixture(scope="module")
def table():
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        assert main(["reproduce", "--json"]) == 0
    return json.loads(out.getvalue())


def test_every_headline_figure_has_a_row(table):
    keys = {(r["paper"], r["key"]) for r in table["rows"]}
    for paper, names in HEADLINES.items():
        for name in names:
            assert (paper, name) in keys, (paper, name)
    for r in table["rows"]:
        assert r["quantity"] and r["paper_value"] and r["ours"]
        assert r["status"] in ("reproduced", "not reproduced", "ours only")
        assert r["agreement"].startswith(r["status"])
        if r["status"] == "not reproduced":
            assert r["reason"]  # a one-line reason
    assert sum(table["elapsed_s"].values()) < 60


def test_statuses(table):
    status = {(r["paper"], r["key"]): r["status"] for r in table["rows"]}
    for key, want in EXPECTED.items():
        assert status[key] == want, key


def test_text_table_for_one_paper():
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        assert main(["reproduce", "--paper", "002"]) == 0
    text = out.getvalue()
    assert text.startswith("| paper | quantity | paper's value | ours | agreement |")
    assert "| 002 |" in text and "| 000 |" not in text
