"""Campaign files: validation (one clear line, nothing started), expansion of [grid] x [zip] x
[sample] with [[exclude]], case keys and per-case seeds."""

from __future__ import annotations

import contextlib
import io
from pathlib import Path

import numpy as np
import pytest
from campaign_helpers import EXAMPLES, write_campaign

from jointlock.campaign import (
    CONFIRM_CASES,
    case_seed,
    expand,
    load_campaign,
    plan_cases,
)
from jointlock.cli import main
from jointlock.errors import CampaignError


def cli(*argv: str) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(list(argv))
    return code, out.getvalue(), err.getvalue()


# -- bad campaign files: one line naming the field, nothing started --------------------------

BAD = {
    "unknown field, did-you-mean": ('[grid]\n"failure.joitn" = [1, 2]\n', "did you mean 'failure.joint'"),
    "unknown table": ('[grdi]\n"failure.joint" = [1, 2]\n', "did you mean 'grid'"),
    "empty sweep": ('[grid]\n"failure.joint" = []\n', "grid.failure.joint is empty"),
    "range lo > hi": ('[sample]\nn = 4\nranges = { "halt.T" = [12.0, 8.0] }\n', "lo must be <= hi"),
    "wrong type": ('[grid]\n"failure.joint" = [1, "two"]\n', "grid.failure.joint[1] must be an integer"),
    "out of range": ('[grid]\n"halt.T" = [10.0, -1.0]\n', "grid.halt.T[1] must be a finite number >= 0.001 and <= 1e+06 [s]"),
    "not a list": ('[grid]\n"failure.joint" = 3\n', "must be a list of the values to run"),
    "zip lengths": ('[zip]\n"failure.joint" = [1, 2]\n"halt.T" = [8.0]\n', "equal lengths"),
    "field twice": ('[grid]\n"halt.T" = [8.0]\n[zip]\n"halt.T" = [9.0]\n', "in one place"),
    "nothing varies": ("", "nothing varies"),
    "sobol not power of 2": ('[sample]\nmethod = "sobol"\nn = 100\nranges = { "halt.T" = [8.0, 12.0] }\n', "power of 2"),
    "sample method": ('[sample]\nmethod = "sobel"\nn = 4\nranges = { "halt.T" = [8.0, 12.0] }\n', "did you mean 'sobol'"),
    "sample a choice": ('[sample]\nn = 4\nranges = { "halt.solver" = [0, 1] }\n', "only number and integer"),
    "repeated value": ('[grid]\n"failure.joint" = [1, 1]\n', "repeats the value 1"),
    "bad column": ('columns = ["hlat.feasible"]\n[grid]\n"failure.joint" = [1, 2]\n', "did you mean 'halt'"),
    "bad reducer": ('columns = ["halt.peak_velocity_deg_s|maxx"]\n[grid]\n"failure.joint" = [1]\n', "unknown reduction"),
    "filter on a fixed field": ('[grid]\n"failure.joint" = [1, 2]\n[[exclude]]\n"halt.T" = 8.0\n', "is not varied"),
    "invalid case": ('[grid]\n"failure.joint" = [1, 9]\n', "case 1 (failure.joint=9) is not a valid scenario"),
    "filters drop all": ('[grid]\n"failure.joint" = [1]\n[[exclude]]\n"failure.joint" = 1\n', "drop every case"),
    "bad comparison": ('[grid]\n"failure.joint" = [1, 2]\n[[exclude]]\n"failure.joint" = { less = 2 }\n',
                       "unknown comparison 'less'"),  # fmt: skip
    "a list in [set]": ('[set]\n"failure.joint" = [1, 2]\n[grid]\n"halt.T" = [9.0]\n', "to vary it, list its values in [grid]"),
    "top-level key after a table": ('[grid]\n"halt.T" = [9.0]\ncolumns = ["halt.k"]\n', "write it before the first [table]"),
    "x equals y": ('[grid]\n"halt.T" = [9.0, 10.0]\n[report]\nx = "halt.T"\ny = "halt.T"\n', "both 'halt.T'"),
}


@pytest.mark.parametrize("name", sorted(BAD))
def test_bad_campaign_files_give_one_line_and_start_nothing(tmp_path, name):
    body, expected = BAD[name]
    path = write_campaign(tmp_path, body, fast="[set]" not in body)
    out = tmp_path / "out"
    for argv in (("plan", str(path), "--probe", "0"), ("run", str(path), "--out", str(out), "--in-process")):
        code, stdout, stderr = cli("campaign", *argv)
        assert code == 2, (name, stderr)
        assert stdout == ""
        assert stderr.count("\n") == 1 and stderr.startswith("jointlock campaign: error: "), stderr
        assert expected in stderr, stderr
        assert str(path) in stderr or "campaign.toml" in stderr
    assert not out.exists()  # nothing started


def test_a_million_case_grid_needs_yes(tmp_path):
    path = write_campaign(
        tmp_path,
        '[grid]\n"failure.angle_deg" = ['
        + ", ".join(str(float(a)) for a in np.linspace(-179, 179, 1000))
        + ']\n"halt.T" = ['
        + ", ".join(str(float(t)) for t in np.linspace(5, 15, 1000))
        + "]\n",
    )
    out = tmp_path / "out"
    code, _, stderr = cli("campaign", "run", str(path), "--out", str(out), "--in-process")
    assert code == 2 and "1,000,000 cases" in stderr and "--yes" in stderr
    assert stderr.count("\n") == 1 and not out.exists()
    assert CONFIRM_CASES < 1_000_000


def test_missing_files_and_bad_toml_are_one_line(tmp_path):
    code, _, err = cli("campaign", "plan", str(tmp_path / "none.toml"))
    assert code == 2 and "does not exist" in err and err.count("\n") == 1
    bad = tmp_path / "bad.toml"
    bad.write_text("[grid\n")
    code, _, err = cli("campaign", "plan", str(bad))
    assert code == 2 and "not valid TOML" in err
    nobase = tmp_path / "nobase.toml"
    nobase.write_text('scenario = "missing.toml"\n[grid]\n"failure.joint" = [1]\n')
    code, _, err = cli("campaign", "plan", str(nobase))
    assert code == 2 and "base scenario file" in err and "missing.toml' does not exist" in err
    code, _, err = cli("campaign", "status", str(tmp_path))
    assert code == 2 and "holds no campaign ledger" in err


# -- expansion ---------------------------------------------------------------------------------


def test_grid_is_a_cartesian_product_last_field_fastest(tmp_path):
    spec = load_campaign(write_campaign(tmp_path, '[grid]\n"failure.joint" = [1, 2]\nfailure.angle_deg = [0.0, 10.0, 20.0]\n'))
    cases = expand(spec)
    assert len(cases) == spec.count_before_filters() == 6
    assert cases[0] == {"failure.joint": 1, "failure.angle_deg": 0.0}
    assert cases[1] == {"failure.joint": 1, "failure.angle_deg": 10.0}
    assert cases[5] == {"failure.joint": 2, "failure.angle_deg": 20.0}


def test_dotted_keys_quoted_or_not_are_one_name(tmp_path):
    a = load_campaign(write_campaign(tmp_path, '[grid]\n"failure.joint" = [1, 2]\n', name="a.toml"))
    b = load_campaign(write_campaign(tmp_path, "[grid]\nfailure.joint = [1, 2]\n", name="b.toml"))
    c = load_campaign(write_campaign(tmp_path, "[grid.failure]\njoint = [1, 2]\n", name="c.toml"))
    assert expand(a) == expand(b) == expand(c)


def test_former_field_names_are_accepted_as_the_current_ones(tmp_path):
    spec = load_campaign(write_campaign(tmp_path, '[grid]\n"limits.vmax_deg" = [40.0, 45.0]\n'))
    assert list(spec.grid) == ["limits.vmax_deg_s"]


def test_zip_varies_together_and_combines_with_grid(tmp_path):
    body = '[grid]\n"failure.joint" = [1, 2]\n[zip]\n"halt.T" = [8.0, 12.0]\n"limits.vmax_deg_s" = [40.0, 50.0]\n'
    cases = expand(load_campaign(write_campaign(tmp_path, body)))
    assert len(cases) == 4
    assert {(c["halt.T"], c["limits.vmax_deg_s"]) for c in cases} == {(8.0, 40.0), (12.0, 50.0)}


def test_exclude_filters_drop_matching_cases(tmp_path):
    body = (
        '[grid]\n"failure.joint" = [1, 2, 3]\n"halt.T" = [8.0, 10.0, 12.0]\n'
        '[[exclude]]\n"failure.joint" = 2\n"halt.T" = { lt = 11.0 }\n'
        '[[exclude]]\n"failure.joint" = { in = [3] }\n"halt.T" = 12.0\n'
    )
    spec = load_campaign(write_campaign(tmp_path, body))
    cases = expand(spec)
    assert len(cases) == 9 - 2 - 1
    assert {"failure.joint": 2, "halt.T": 8.0} not in cases and {"failure.joint": 3, "halt.T": 12.0} not in cases
    assert {"failure.joint": 2, "halt.T": 12.0} in cases
    plan = plan_cases(spec)
    assert (plan.described, plan.excluded, len(plan)) == (9, 3, 6)


@pytest.mark.parametrize("method,n", [("random", 20), ("sobol", 16), ("lhs", 20)])
def test_samples_are_seeded_within_their_ranges(tmp_path, method, n):
    body = f'seed = 5\n[sample]\nmethod = "{method}"\nn = {n}\nranges = {{ "halt.T" = [8.0, 12.0], "failure.joint" = [2, 5] }}\n'
    spec = load_campaign(write_campaign(tmp_path, body))
    points = expand(spec)
    assert len(points) == n
    t = np.array([p["halt.T"] for p in points])
    j = [p["failure.joint"] for p in points]
    assert np.all((t >= 8.0) & (t <= 12.0)) and all(isinstance(v, int) and 2 <= v <= 5 for v in j)
    assert set(j) == {2, 3, 4, 5}  # every integer reachable
    assert expand(spec) == points  # same seed, same draws
    other = load_campaign(write_campaign(tmp_path, body.replace("seed = 5", "seed = 6"), name="o.toml"))
    assert expand(other) != points
    if method == "lhs":  # one point per stratum of each range
        assert sorted(np.floor((t - 8.0) / 4.0 * n).astype(int).tolist()) == list(range(n))


# -- keys and seeds ----------------------------------------------------------------------------


def test_keys_follow_the_resolved_inputs_not_the_file(tmp_path):
    a = plan_cases(load_campaign(write_campaign(tmp_path, '[grid]\n"halt.T" = [8.0, 10.0]\n', name="a.toml")))
    # same cases written otherwise: an int for a float, another order, another section
    b = plan_cases(load_campaign(write_campaign(tmp_path, '[zip]\n"halt.T" = [10, 8]\n', name="b.toml")))
    assert {c.key for c in a.cases} == {c.key for c in b.cases}
    # one more value: only one new key
    c = plan_cases(load_campaign(write_campaign(tmp_path, '[grid]\n"halt.T" = [8.0, 10.0, 12.0]\n', name="c.toml")))
    assert len({x.key for x in c.cases} - {x.key for x in a.cases}) == 1
    # the campaign seed is an input
    d = plan_cases(load_campaign(write_campaign(tmp_path, 'seed = 1\n[grid]\n"halt.T" = [8.0, 10.0]\n', name="d.toml")))
    assert not {x.key for x in d.cases} & {x.key for x in a.cases}
    # a default written out explicitly is the same input
    e = plan_cases(load_campaign(write_campaign(tmp_path, '[grid]\n"halt.T" = [8.0, 10.0]\n"halt.solver" = ["scan"]\n', name="e.toml")))
    assert {x.key for x in e.cases} == {x.key for x in a.cases}


def test_case_seeds_derive_from_the_key(tmp_path):
    plan = plan_cases(load_campaign(write_campaign(tmp_path, '[grid]\n"halt.T" = [8.0, 10.0, 12.0]\n')))
    seeds = [c.seed for c in plan.cases]
    assert len(set(seeds)) == 3 and all(0 <= s < 2**32 for s in seeds)
    assert seeds == [case_seed(c.key) for c in plan.cases]
    assert case_seed("a" * 24) == case_seed("a" * 24) != case_seed("b" * 24)


def test_duplicate_draws_run_once(tmp_path):
    body = '[sample]\nn = 30\nranges = { "failure.joint" = [3, 4] }\n'
    plan = plan_cases(load_campaign(write_campaign(tmp_path, body)))
    assert len(plan) == 2 and plan.duplicates == 28


def test_model_files_are_keyed_by_content(tmp_path):
    import shutil

    src = EXAMPLES.parent / "tests" / "data" / "arm5.urdf"
    shutil.copy(src, tmp_path / "arm.urdf")
    (tmp_path / "base.toml").write_text('robot = "arm.urdf"\n[failure]\njoint = 2\nangle_deg = 10.0\n[workspace]\nsamples = 1000\n')
    body = 'scenario = "base.toml"\n[grid]\n"failure.angle_deg" = [10.0, 20.0]\n'
    (tmp_path / "c.toml").write_text(body)
    keys = {c.key for c in plan_cases(load_campaign(tmp_path / "c.toml")).cases}
    moved = tmp_path / "moved"
    moved.mkdir()
    for name in ("arm.urdf", "base.toml", "c.toml"):
        shutil.copy(tmp_path / name, moved / name)
    assert {c.key for c in plan_cases(load_campaign(moved / "c.toml")).cases} == keys  # path-independent
    (moved / "arm.urdf").write_text((moved / "arm.urdf").read_text().replace("<robot", "<!-- edited -->\n<robot", 1))
    assert not {c.key for c in plan_cases(load_campaign(moved / "c.toml")).cases} & keys


def test_inline_base_scenario(tmp_path):
    path = tmp_path / "c.toml"
    path.write_text(
        '[scenario]\nrobot = "puma6"\n[scenario.failure]\njoint = 2\nangle_deg = 59.4\n'
        "[scenario.workspace]\nsamples = 1000\n"
        '[grid]\n"failure.angle_deg" = [50.0, 60.0]\n'
    )
    spec = load_campaign(path)
    assert spec.scenario["robot"] == "puma6" and len(plan_cases(spec)) == 2
    with pytest.raises(CampaignError, match="scenario is required"):
        from jointlock.campaign import campaign_from_dict

        campaign_from_dict({"grid": {"halt.T": [1.0]}})


# -- the example campaigns and the documented file ---------------------------------------------


@pytest.mark.parametrize("name,cases", [("halt7", 105), ("jump_canadarm7", 42), ("tolerance_puma6", 66)])
def test_example_campaigns_plan_and_their_first_case_runs(name, cases, tmp_path):
    from jointlock.campaign import plan_campaign

    plan = plan_campaign(EXAMPLES / "campaigns" / f"{name}.toml", tmp_path / "out", probe=1)
    assert plan.cases == plan.to_run == cases
    assert len(plan.probe_seconds) == 1 and plan.estimate_s > 0
    assert plan.probe_errors == () and plan.unknown_columns == ()  # the case ran every job


def test_the_campaign_file_in_the_docs_is_valid(tmp_path):
    import re

    doc = (EXAMPLES.parent / "docs" / "campaigns.md").read_text()
    block = re.search(r"## The campaign file\n\n```toml\n(.*?)```", doc, re.S).group(1)
    path = tmp_path / "doc.toml"
    path.write_text(block.replace('scenario = "halt_000.toml"', f'scenario = "{EXAMPLES / "halt_000.toml"}"'))
    plan = plan_cases(load_campaign(path))
    assert (plan.described, plan.excluded) == (7 * 3 * 2 * 16, 2 * 16)


def test_the_default_output_folder_is_beside_the_campaign_file(tmp_path, monkeypatch):
    path = write_campaign(tmp_path, '[grid]\n"halt.T" = [9.0]\n', name="mine.toml")
    monkeypatch.chdir(EXAMPLES)
    assert load_campaign(path).default_out() == tmp_path / "mine-campaign"
    other = write_campaign(tmp_path, 'out = "results/here"\n[grid]\n"halt.T" = [9.0]\n', name="o.toml")
    assert load_campaign(other).default_out() == tmp_path / "results" / "here"


def test_the_example_campaigns_keep_their_keys():
    """The fields added since (srdf, a Cartesian [task]'s, jump.on_infeasible) leave the keys of
    the example campaigns' cases as they were (computed by the code before them)."""
    for name, first in (
        ("jump_canadarm7.toml", ["e5f4cd52837b6cf10bbd0f05", "d7bfc767402d750d906a076d"]),
        ("halt7.toml", ["265d6274313541bc56dc22c8", "8e0625a5b093cff6b1b94882"]),
    ):
        spec = load_campaign(Path(__file__).resolve().parents[1] / "examples" / "campaigns" / name)
        assert [c.key for c in plan_cases(spec).cases][:2] == first, name


def test_keys_do_not_move_with_fields_added_later(tmp_path):
    """A field added to scenarios after the key format was set (``compiled``) leaves the keys of
    cases that do not set it as they were (so their seeds, and resume, stay); set, it counts."""
    plain = load_campaign(write_campaign(tmp_path, '[grid]\n"halt.T" = [8.0, 10.0]\n'))
    keys = [c.key for c in plan_cases(plain).cases]
    assert keys == ["35a7bb766881cdd35ef3a310", "0af85a422d5bc3122bafcf36"]  # the keys before the field
    told = load_campaign(write_campaign(tmp_path, '[grid]\n"halt.T" = [8.0, 10.0]\n"compiled" = ["always"]\n',
                                        name="told.toml"))  # fmt: skip
    assert not set(keys) & {c.key for c in plan_cases(told).cases}
