"""``jointlock reproduce --json`` has a row for every headline figure of the four seeds; the
library call behind it (:func:`jointlock.jobs.reproduction.reproduce`) gives the same table, and
the papers' values in it are :mod:`jointlock.papers`'s."""

from __future__ import annotations

import contextlib
import io
import json
import pickle
import re
from pathlib import Path

import pytest

from jointlock.cli import main
from jointlock.errors import ScenarioError
from jointlock.jobs.reproduction import ReproductionReport, ReproductionRow, reproduce
from jointlock.papers import p000, p002, p004

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
    ("002", "gamma"): "not reproduced",  # -1.4694 is 0.019 deg from the printed -1.45: over half a digit
    ("002", "range_180"): "not reproduced",  # 47.35 rounds to 47, not 002's 48
    ("002", "range_2"): "reproduced",
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


# -- the library call ---------------------------------------------------------------------------


@pytest.fixture(scope="module")
def report_002() -> ReproductionReport:
    return reproduce("002")


def _cli(argv: list[str]) -> str:
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        assert main(argv) == 0
    return out.getvalue()


def _untimed(lines: list[str]) -> list[str]:
    """The printed lines without the one giving each paper's wall time."""
    return [line for line in lines if "ours only; " not in line]


def test_library_equals_cli(report_002):
    cli = json.loads(_cli(["reproduce", "--paper", "002", "--json"]))
    ours = report_002.plain()
    assert set(cli["elapsed_s"]) == set(ours["elapsed_s"]) == {"002"}
    cli.pop("elapsed_s"), ours.pop("elapsed_s")
    assert ours == cli
    text = _cli(["reproduce", "--paper", "002"]).splitlines()
    assert _untimed(report_002.summary()) == _untimed(text)
    assert len(report_002.summary()) == len(text)
    totals = [line for line in report_002.summary() if "ours only; " in line]
    assert totals == [f"9 reproduced, 2 not reproduced, 0 ours only; 002: {report_002.elapsed_s[0]:.1f} s"]


def test_report_is_picklable_and_writes_its_json(report_002, tmp_path):
    back = pickle.loads(pickle.dumps(report_002))
    assert back.to_dict() == report_002.to_dict() and back.summary() == report_002.summary()
    assert report_002.write(tmp_path) == ["result.json"]
    assert json.loads((tmp_path / "result.json").read_text()) == report_002.plain()
    assert isinstance(report_002.rows[0], ReproductionRow) and report_002.job == "reproduce"


def test_papers_run_in_table_order_and_unknown_ones_are_refused(monkeypatch):
    import jointlock.jobs.reproduction as rep

    for paper in rep.PAPERS:  # stand-ins: one row per paper, no experiment
        row = ReproductionRow(paper, "k", "q", "1", "1", "reproduced")
        monkeypatch.setitem(rep.PAPER_ROWS, paper, lambda row=row: [row])
    got = reproduce(["004", "000", "004"])
    assert got.papers == ("000", "004") and [r.paper for r in got.rows] == ["000", "004"]
    assert [n[:3] for n in got.notes] == ["000", "004"] and len(got.elapsed_s) == 2
    with pytest.raises(ScenarioError, match="papers must name some of 000, 001, 002, 004; unknown: '003'"):
        reproduce(["002", "003"])
    with pytest.raises(ScenarioError, match="got none"):
        reproduce([])


def test_paper_values_are_the_papers_constants(table, report_002):
    value = {(r["paper"], r["key"]): r["paper_value"] for r in table["rows"]}
    assert value["000", "cp_q_sub"] == f"{p000.CP_Q_SUB:g}"
    assert value["000", "cp_gain"] == f"{100 * p000.CP_GAIN:+.1f} %"
    assert value["000", "torque_k0"] == f"{p000.HALT_RESULTS['global_torque_k0_Nm']:g}"
    assert value["000", "torque_reduction"] == f"{-100 * p000.HALT_RESULTS['reduction']:+.1f} %"
    assert value["002", "q_at_gamma"] == str(list(p002.A_Q_AT_GAMMA_DEG))
    assert value["002", "eq22"] == str(list(p002.EQ22_DEG))
    for name, printed in p004.VIRTUAL_LENGTHS.items():
        assert value["004", f"virtual_{name}"] == f"{printed:g}"
    for name, det in p004.TABLE3_DET.items():
        assert float(value["004", f"table3_{name}"]) == det
    assert report_002.row("002", "gamma").paper_value == f"{p002.A_GAMMA_DEG:g}"
    with pytest.raises(KeyError):
        report_002.row("000", "cp_q_sub")


#: Numbers below this in magnitude are round-off (a det of 1e-15, a median sigma_min of 1e-16):
#: their digits depend on the machine's BLAS kernels, so the docs' table is compared without them.
ROUNDOFF = 1e-12
_NUMBER = re.compile(r"-?\d+(?:\.\d+)?e[-+]\d+")


def _without_roundoff(text: str) -> str:
    return _NUMBER.sub(lambda m: "ROUNDOFF" if abs(float(m[0])) < ROUNDOFF else m[0], text)


def test_docs_print_the_output_of_the_code(table):
    """Issue 15, item 8: docs/reproduce.md's table is what the command prints, row for row
    (round-off-level numbers aside: one machine's, said above the table)."""
    doc = _without_roundoff((Path(__file__).resolve().parents[1] / "docs" / "reproduce.md").read_text())
    for r in table["rows"]:
        cells = [r["paper"], r["quantity"], r["paper_value"], r["ours"], r["agreement"]]
        line = _without_roundoff("| " + " | ".join(str(c).replace("|", "/") for c in cells) + " |")
        assert line in doc, line
    assert _without_roundoff("det 3.38e-15, sigma 8.9e-17, kept 2.97193e-12") == "det ROUNDOFF, sigma ROUNDOFF, kept 2.97193e-12"


def test_one_rule_for_every_tolerance():
    """Half a unit of the paper's last printed digit, nothing looser."""
    from jointlock.jobs.reproduction._report import within_printed

    assert within_printed(47.5, 48, 0) and not within_printed(47.35, 48, 0)
    assert within_printed(-1.455, -1.45, 2) and not within_printed(-1.4694, -1.45, 2)
    assert within_printed(-30.14, -30.1, 1) and not within_printed(-11.5, -30.1, 1)
