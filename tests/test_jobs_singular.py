"""The singular job as library calls (jointlock.jobs.singular): the same JSON, text and files
as ``jointlock singular`` in its three modes (one configuration, --verify-conditions,
--search), picklable results, ``singular_from_scenario`` = ``jointlock run``'s command line,
plot functions that draw on a given axis or make their own without touching the backend."""

from __future__ import annotations

import contextlib
import io
import json
import math
import pickle
import re
from pathlib import Path

import matplotlib
import numpy as np
import pytest
from equivalent_commands import call_subcommand, job_argv

from jointlock.cli import main as cli_main
from jointlock.io.files import to_plain, with_svg
from jointlock.jobs.singular import (
    ConditionVerificationResult,
    SingularityResult,
    SingularitySearchResult,
    search_singularities,
    singular_from_scenario,
    singular_model,
    study_singularity,
    verify_singularity_conditions,
)
from jointlock.plots.singular import plot_family_joint_angles, plot_search_sigma_min, plot_singular_families
from jointlock.scenario import load_scenario

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "singular_004.toml"
#: Samples per condition for the verification (the 512-start completeness search dominates).
VERIFY_SAMPLES = 40

#: name -> (robot, locks {joint: rad}, library keywords, the same options on the command line)
SINGLE = {
    "puma_wrist": (
        "puma6",
        None,
        {"q_deg": [10, 20, 30, 40, 0, 60]},
        ["--q-deg", "10", "20", "30", "40", "0", "60"],
    ),
    "canadarm_virtual_cond1": (
        "canadarm7",
        None,
        {"q_deg": [25, 0, 90, 0, 45, 90, 0], "base": "virtual"},
        ["--base", "virtual", "--q-deg", "25", "0", "90", "0", "45", "90", "0"],
    ),
    "canadarm_fixed_real_lengths": (
        "canadarm7",
        None,
        {"q_deg": [10, 20, 30, 40, 50, 60, 70], "tol": 1e-3},
        ["--q-deg", "10", "20", "30", "40", "50", "60", "70", "--tol", "0.001"],
    ),
    "puma_locked_five_joints": (
        "puma6",
        {2: math.radians(30)},
        {"q_deg": [0, 0, 10, 20, 30], "length": 2.0},
        ["--lock", "2=30", "--q-deg", "0", "0", "10", "20", "30", "--length", "2"],
    ),
    "floating": ("canadarm7", None, {"base": "floating"}, ["--base", "floating"]),
}
#: name -> (robot, locks, library keywords, command-line options) of --search
SEARCH = {
    "puma6": ("puma6", None, {}, []),
    "canadarm7_conditions": (
        "canadarm7",
        None,
        {"samples": 12, "rng": 3},
        ["--samples", "12", "--seed", "3"],
    ),
    "puma6_locked": ("puma6", {2: math.radians(30)}, {}, ["--lock", "2=30"]),
    "halt7_two_starts": ("halt7", None, {"samples": 2}, ["--samples", "2"]),  # one family: quick figures
}
SEARCH_STARTS = 16


def _cli(argv: list[str]) -> str:
    """stdout of ``jointlock ARGV`` (in-process)."""
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        assert cli_main(argv) == 0
    return buf.getvalue()


def _single(name: str) -> SingularityResult:
    robot, locks, kw, _ = SINGLE[name]
    kw = dict(kw)
    base = kw.get("base", "fixed")
    model = singular_model(robot, locks, base)
    q = np.radians(kw.pop("q_deg")) if "q_deg" in kw else np.zeros(model.dof)
    renamed = {"base": "jacobian", "length": "characteristic_length"}  # the keywords' current names
    return study_singularity(model, q, **{renamed.get(k, k): v for k, v in kw.items()})


def _search(name: str) -> SingularitySearchResult:
    robot, locks, kw, _ = SEARCH[name]
    kw = {"samples": SEARCH_STARTS, **kw}
    return search_singularities(singular_model(robot, locks, "fixed"), **kw)


def _search_argv(name: str) -> list[str]:
    robot, _, _, opts = SEARCH[name]
    samples = [] if "--samples" in opts else ["--samples", str(SEARCH_STARTS)]
    return ["singular", robot, "--search", *samples, *opts, "--quiet"]


@pytest.fixture(scope="module")
def verify_scenario():
    return load_scenario(EXAMPLE, {"singular.samples": VERIFY_SAMPLES})


@pytest.fixture(scope="module")
def verification(verify_scenario) -> ConditionVerificationResult:
    """004's example scenario (verification on the virtual manipulator), fewer samples."""
    result = singular_from_scenario(verify_scenario.data, {})
    assert isinstance(result, ConditionVerificationResult)
    return result


# -- one configuration ---------------------------------------------------------------------------


@pytest.mark.parametrize("name", list(SINGLE))
def test_single_to_dict_and_summary_equal_the_command(name):
    robot, _, _, opts = SINGLE[name]
    result = _single(name)
    assert to_plain(result.to_dict()) == json.loads(_cli(["singular", robot, *opts, "--json"]))
    assert result.summary() == _cli(["singular", robot, *opts]).splitlines()


def test_single_modes_cover_the_conditions_and_the_five_joint_note():
    assert "conditions" in _single("canadarm_virtual_cond1").to_dict()
    assert "conditions" in _single("canadarm_fixed_real_lengths").to_dict()
    assert "conditions" not in _single("floating").to_dict()
    assert any("det(J J^T) = 0 always" in line for line in _single("puma_locked_five_joints").summary())
    assert _single("puma_wrist").lost_directions.shape == (6, 1)


def test_single_writes_no_files_like_the_command(tmp_path):
    robot, _, _, opts = SINGLE["puma_wrist"]
    assert _single("puma_wrist").write(tmp_path / "lib") == []
    _cli(["singular", robot, *opts, "--out", str(tmp_path / "cli")])
    assert not (tmp_path / "lib").exists() and not (tmp_path / "cli").exists()


def test_single_checks_its_own_inputs():
    model = singular_model("puma6")
    with pytest.raises(Exception, match="q must hold 6 angles"):
        study_singularity(model, np.zeros(5))
    with pytest.raises(Exception, match="weighting must be one of"):
        study_singularity(model, np.zeros(6), weighting="equal")  # type: ignore[arg-type]


# -- verification of Cond1-Cond5 -----------------------------------------------------------------


def test_verification_from_scenario_equals_the_run_command_line(verification, verify_scenario, tmp_path):
    argv = job_argv("singular", verify_scenario, tmp_path, {}, quiet=True)
    assert "--verify-conditions" in argv and "--out" not in argv
    printed, code = call_subcommand("singular", argv)
    assert code == 0
    assert to_plain(verification.to_dict()) == printed
    assert printed["seed"] == 0 and printed["conditions"]["cond1"]["samples"] == VERIFY_SAMPLES


def test_verification_summary_equals_the_command_text(verification):
    text = _cli(["singular", "canadarm7", "--verify-conditions", "--samples", str(VERIFY_SAMPLES), "--quiet"])
    assert verification.summary() == text.splitlines()
    assert verification.write("unused-folder") == []


def test_verification_checks_its_own_inputs():
    model = singular_model("canadarm7", None, "virtual")
    with pytest.raises(Exception, match="jacobian must be 'virtual'"):
        verify_singularity_conditions(model, jacobian="floating")  # type: ignore[arg-type]
    with pytest.raises(Exception, match="samples must be an integer >= 1"):
        verify_singularity_conditions(model, samples=0)


# -- search ----------------------------------------------------------------------------------------


@pytest.mark.parametrize("name", list(SEARCH))
def test_search_to_dict_and_summary_equal_the_command(name):
    result = _search(name)
    assert to_plain(result.to_dict()) == json.loads(_cli([*_search_argv(name), "--json"]))
    assert result.summary() == _cli(_search_argv(name)).splitlines()
    if name == "canadarm7_conditions":
        assert all("conditions" in fam for fam in result.to_dict()["families"])


def test_search_writes_the_files_of_the_command(tmp_path):
    result = _search("halt7_two_starts")
    names = result.write(tmp_path / "lib")
    assert names == with_svg(["search.json", "sigma_min.png", "families.png", "joint_angles.png"])
    assert sorted(p.name for p in (tmp_path / "lib").iterdir()) == sorted(names)
    written = json.loads((tmp_path / "lib" / "search.json").read_text())
    assert written == to_plain(result.search_json())
    found = {"found": len(result.search.q)}
    assert {k: v for k, v in written.items() if k not in ("q_deg", "sigma_min")} | found == to_plain(
        result.to_dict()
    )
    cli_out = tmp_path / "cli"
    printed = json.loads(_cli([*_search_argv("halt7_two_starts"), "--out", str(cli_out), "--json"]))
    assert printed["files"] == [str(cli_out / n) for n in names]
    assert printed == to_plain(result.to_dict(files=[cli_out / n for n in names]))
    assert json.loads((cli_out / "search.json").read_text()) == written
    assert sorted(p.name for p in cli_out.iterdir()) == sorted(names)


def test_search_from_scenario_equals_the_run_command_line(tmp_path):
    f = tmp_path / "s.toml"
    f.write_text(
        'robot = "puma6"\nseed = 2\n[failure]\njoint = 2\nangle_deg = 30\n[singular]\nsearch = true\nsamples = 8\n'
    )
    scenario = load_scenario(f)
    result = singular_from_scenario(scenario.data, {})
    assert isinstance(result, SingularitySearchResult)
    argv = job_argv("singular", scenario, tmp_path / "out", {}, quiet=True)
    printed, code = call_subcommand("singular", argv)
    assert code == 0 and printed["seed"] == 2 and printed["locked"] == {"2": pytest.approx(30.0)}
    assert to_plain(result.to_dict(files=printed["files"])) == printed


@pytest.mark.parametrize(
    "text",
    [
        'robot = "canadarm7"\n[singular]\nbase = "virtual"\nq_deg = [25, 0, 90, 0, 45, 90, 0]\nlength = 2.5\n',
        'robot = "canadarm7"\nbase = "floating"\n[singular]\nq_deg = [0, 10, 20, 30, 40, 50, 60]\n',
        'robot = "puma6"\n[failure]\njoint = 2\nangle_deg = 30\n[singular]\nq_deg = [0, 0, 10, 20, 30]\ntol = 1e-3\n',
    ],
    ids=["virtual", "inherited-floating", "locked"],
)
def test_single_from_scenario_equals_the_run_command_line(tmp_path, text):
    f = tmp_path / "s.toml"
    f.write_text(text)
    scenario = load_scenario(f)
    result = singular_from_scenario(scenario.data, {})
    assert isinstance(result, SingularityResult)
    printed, code = call_subcommand(
        "singular", job_argv("singular", scenario, tmp_path / "out", {}, quiet=True)
    )
    assert code == 0
    assert to_plain(result.to_dict()) == printed


# -- pickling, seeds -------------------------------------------------------------------------------


def test_results_pickle(verification):
    for result in (_single("canadarm_virtual_cond1"), verification, _search("canadarm7_conditions")):
        again = pickle.loads(pickle.dumps(result))
        assert type(again) is type(result) and again.job == "singular"
        assert to_plain(again.to_dict()) == to_plain(result.to_dict())
        assert again.summary() == result.summary()


def test_search_records_the_seed_it_drew():
    model = singular_model("puma6")
    result = search_singularities(model, samples=4, rng=None)
    assert isinstance(result.search.seed, int)
    again = search_singularities(model, samples=4, rng=result.search.seed)
    np.testing.assert_array_equal(again.search.q_start, result.search.q_start)
    assert search_singularities(model, samples=4, rng=np.random.default_rng(1)).search.seed is None


# -- plots -------------------------------------------------------------------------------------------


def test_plots_without_axes_make_their_own_and_keep_the_backend():
    import matplotlib.pyplot as plt
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

    result = _search("puma6")
    backend = matplotlib.get_backend()
    ax = plot_search_sigma_min(result.model, result.search)
    assert isinstance(ax, Axes) and ax.get_title() == "puma6: singularity search (fixed Jacobian)"
    fig = plot_singular_families(result.model, result.search)
    assert isinstance(fig, Figure) and len(fig.axes) == min(len(result.search.families), 6)
    fig2 = plot_family_joint_angles(result.model, result.search)
    assert isinstance(fig2, Figure) and len(fig2.axes) == result.model.dof
    assert matplotlib.get_backend() == backend
    for f in (ax.figure, fig, fig2):
        plt.close(f)


def test_plots_draw_on_the_given_axes():
    from jointlock.plots import offscreen_figure

    result = _search("puma6")
    fig = offscreen_figure((6.0, 4.0))
    ax = fig.add_subplot()
    assert plot_search_sigma_min(result.model, result.search, ax=ax) is ax
    fig = offscreen_figure((9.0, 4.0))
    assert plot_singular_families(result.model, result.search, fig=fig) is fig


#: Largest relative difference between the docs' completeness counts and the command's [-].
COUNT_SLACK = 0.03


def test_the_docs_completeness_counts_are_the_commands():
    """Issue 15, item 8: docs/singularity.md's completeness figures come from the code."""
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        assert cli_main(["singular", "canadarm7", "--verify-conditions", "--json"]) == 0
    c = json.loads(out.getvalue())["completeness"]
    n, per = c["found"], c["per_condition"]
    doc = (Path(__file__).resolve().parents[1] / "docs" / "singularity.md").read_text()
    found = re.search(r"- (\d+) of the (\d+) search starts converged", doc)
    explained = re.search(r"- All (\d+) satisfy one of Cond1–Cond5, and all (\d+) also", doc)
    listed = re.search(r"- Per condition: Cond1 (\d+) \(all of them also cond1f\), Cond2 (\d+), "
                       r"Cond3 (\d+), Cond4 (\d+), Cond5 (\d+)\.", doc)  # fmt: skip
    assert found and explained and listed, "the completeness paragraph of docs/singularity.md changed shape"
    assert int(found[2]) == c["starts"]
    # a start at the edge of the iteration budget converges on one machine's BLAS and not on
    # another's: the docs' counts (one machine's) may differ by a few (COUNT_SLACK)
    doc_counts = [int(found[1]), int(explained[1]), int(explained[2]), *(int(x) for x in listed.groups())]
    cmd_counts = [n, c["explained"], c["explained_refined"], *(per[f"cond{i}"] for i in range(1, 6))]
    for d, m in zip(doc_counts, cmd_counts):
        assert abs(d - m) <= max(1, COUNT_SLACK * m), (doc_counts, cmd_counts)
    assert per["cond1f"] == per["cond1"]
    assert c["explained"] == n and c["explained_refined"] == n  # nothing unexplained, on any machine
