"""The library is the product: every scenario runs in-process and gives exactly what
``jointlock run --json`` prints; ``plan_halt`` is ``jointlock halt``; results pickle; the
library never chooses a plotting backend; imports point one way (import-linter contracts)."""

from __future__ import annotations

import contextlib
import io
import json
import pickle
import re
from pathlib import Path

import matplotlib
import numpy as np
import pytest

import jointlock as jl
from jointlock.cli import main
from jointlock.ik import pose_from_zyx
from jointlock.io.files import to_plain
from jointlock.planning.ga import GASettings

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"

#: Reduced settings per example (the same as tests/test_run.py: the equality does not depend
#: on them, and the full settings take minutes).
FAST = {
    "halt_000": {"halt_config.samples": 3000, "halt.n_samples": 201},
    "jump_001": {"jump.sweep": 6},
    "replan_002": {"workspace.samples": 4000, "replan.steps": 10},
    "singular_004": {"singular.samples": 50},
}


def cli_json(*argv: str) -> dict:
    out = io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(io.StringIO()):
        assert main(list(argv)) == 0
    return json.loads(out.getvalue())


#: Keys that hold wall-clock times (they differ between two runs of the same scenario).
TIMING_KEYS = {"elapsed_s"}


def _untimed(data):
    if isinstance(data, dict):
        return {k: _untimed(v) for k, v in data.items() if k not in TIMING_KEYS}
    if isinstance(data, list):
        return [_untimed(v) for v in data]
    return data


def _set_args(overrides: dict) -> list[str]:
    return [a for k, v in overrides.items() for a in ("--set", f"{k}={v}")]


@pytest.mark.parametrize("name", sorted(FAST))
def test_run_json_equals_the_in_process_run(tmp_path, name):
    path = EXAMPLES / f"{name}.toml"
    out = tmp_path / "cli"
    printed = cli_json("run", str(path), "--out", str(out), "--json", *_set_args(FAST[name]))
    overrides = {k: v for k, v in FAST[name].items()} | {"out": str(out)}
    run = jl.run_scenario(jl.load_scenario(path, overrides))
    in_process = _untimed(run.to_dict(out))
    assert set(printed) - set(in_process) == {"files"}
    assert in_process == _untimed({k: v for k, v in printed.items() if k != "files"})
    # the same files, written by the library
    written = run.write(tmp_path / "lib")
    assert written["files"] == printed["files"]
    assert _untimed(json.loads((tmp_path / "lib" / "results.json").read_text())["summary"]) == _untimed(
        printed["summary"]
    )


def test_run_result_pickles(tmp_path):
    sc = jl.load_scenario(EXAMPLES / "singular_004.toml", FAST["singular_004"])
    run = jl.run_scenario(sc)
    back = pickle.loads(pickle.dumps(run))
    assert _untimed(back.to_dict(tmp_path)) == _untimed(run.to_dict(tmp_path))
    assert back.summary() == run.summary()


def test_plan_halt_is_jointlock_halt():
    """000's scenario: the same halt configuration, k* and torques from Python and the CLI."""
    printed = cli_json("halt", "halt7", "--samples", "6000", "--json")
    plan = jl.plan_halt("halt7", search=jl.HaltSearch(samples=6000))
    assert to_plain(plan.to_dict()) == printed
    assert plan.feasible and printed["feasible"]
    np.testing.assert_array_equal(np.degrees(plan.problem.qf), printed["q_final_deg"])
    assert plan.motion.global_torque == printed["global_torque_Nm"]
    # the documented Python calls: the model with its spacecraft, locked, 000's state
    model = jl.lock(jl.load_robot("halt7", base="floating"), 4, 0.0)
    state = jl.FailureState.from_degrees(model, [-180, -180, -100, -10, 20, 20], [20, 30, 15, 25, 40, 35],
                                         [8, 10, 12, 10, -8, 6])  # fmt: skip
    same = jl.plan_halt(model, state, T=10.0, base="fixed", search=jl.HaltSearch(samples=6000))  # limits: halt7's 40 deg/s, 000's 20
    assert to_plain(same.to_dict()) == printed


def test_plan_halt_text_is_the_cli_text(capsys):
    assert main(["halt", "halt7", "--paper-qf", "--n-samples", "101"]) == 0
    printed = capsys.readouterr().out.splitlines()
    assert jl.plan_halt("halt7", paper_qf=True, motion=jl.HaltMotionSettings(n_samples=101)).summary() == printed


def test_plan_halt_needs_a_state_for_other_robots():
    with pytest.raises(jl.ScenarioError, match="state at failure of 'puma6'"):
        jl.plan_halt("puma6", locks={2: 0.5}, T=5.0)


def test_plan_halt_errors_name_its_own_inputs():
    with pytest.raises(jl.ModelError, match="did you mean 'halt7'"):
        jl.plan_halt("halt8")  # the name is checked before anything else
    with pytest.raises(jl.ScenarioError, match=r"of 'halt7' \(locked: none; .*only for halt7 with joint 4 locked at 0 deg"):
        jl.plan_halt(jl.load_robot("halt7"))  # 000's state needs 000's lock
    with pytest.raises(jl.ScenarioError, match="^T must be a finite halt time") as err:
        jl.plan_halt("halt7", T=-1.0)
    assert "--" not in str(err.value)  # a keyword, not a CLI option
    with pytest.raises(jl.ScenarioError, match="ga.n_pop must be >= 2"):
        jl.plan_halt("halt7", motion=jl.HaltMotionSettings(solver="ga", ga=GASettings(n_pop=1)))


def test_plan_halt_base_follows_the_model_given():
    model = jl.lock(jl.load_robot("halt7", base="floating"), 4, 0.0)
    assert jl.plan_halt(model, paper_qf=True, motion=jl.HaltMotionSettings(n_samples=101)).problem.base == "floating"
    assert jl.plan_halt("halt7", paper_qf=True, motion=jl.HaltMotionSettings(n_samples=101)).problem.base == "fixed"  # 000's, by name


def test_run_scenario_takes_a_path_and_names_missing_jobs():
    path = EXAMPLES / "singular_004.toml"
    run = jl.run_scenario(path)
    assert run.to_dict()["summary"] == jl.run_scenario(jl.load_scenario(path)).to_dict()["summary"]
    with pytest.raises(KeyError, match="it ran: singular"):
        run["halt"]
    with pytest.raises(jl.ScenarioError, match="needs a Scenario"):
        jl.run_scenario(42)


def test_the_library_never_chooses_a_backend(tmp_path, monkeypatch):
    def refuse(*args, **kwargs):
        raise AssertionError("matplotlib.use called by the library")

    monkeypatch.setattr(matplotlib, "use", refuse)
    sc = jl.load_scenario(EXAMPLES / "halt_000.toml", {"halt_config.samples": 500, "halt.n_samples": 101})
    jl.run_scenario(sc).write(tmp_path)
    assert (tmp_path / "report.html").is_file()
    src = ROOT / "src" / "jointlock"
    offenders = [
        str(p.relative_to(src))
        for p in src.rglob("*.py")
        if "cli" not in p.relative_to(src).parts and re.search(r"matplotlib\.use\(", p.read_text())
    ]
    assert offenders == []


def test_plot_functions_draw_on_the_axes_given(tmp_path):
    from matplotlib.figure import Figure

    plan = jl.plan_halt("halt7", paper_qf=True, motion=jl.HaltMotionSettings(n_samples=101))
    fig = Figure()
    ax = fig.add_subplot()
    assert jl.plots.halt.plot_global_torque_vs_k(plan.motion, ax=ax) is ax
    assert ax.lines and ax.get_xlabel() == "k [deg/s$^6$]"
    fig = Figure()
    assert jl.plots.halt.plot_joint_profiles(plan.motion, fig=fig) is fig
    assert len(fig.axes) == 3 * plan.problem.dof


def _lint(tmp_path: Path, layers: list[str] | None = None) -> int:
    from importlinter.cli import lint_imports

    config = ROOT / "pyproject.toml"
    if layers is not None:  # a copy of the contract with another layer order
        text = config.read_text()
        block = re.search(r"layers = \[\n(.*?)\n\]", text, re.S)
        assert block is not None
        text = text.replace(block.group(1), "\n".join(f'    "{name}",' for name in layers))
        config = tmp_path / "pyproject.toml"
        config.write_text(text)
    with contextlib.redirect_stdout(io.StringIO()):
        return lint_imports(config_filename=str(config), no_cache=True)


def test_import_layers_hold(tmp_path):
    pytest.importorskip("importlinter")
    assert _lint(tmp_path) == 0


def test_import_layer_contract_catches_an_upward_import(tmp_path):
    pytest.importorskip("importlinter")
    # kinematics imports model: with model placed above kinematics the contract must break
    assert _lint(tmp_path, ["jointlock.model", "jointlock.kinematics"]) != 0


@pytest.mark.parametrize(
    "argv, call",
    [
        (["kinematics", "halt7", "--lock", "4=0", "--q-deg", "-180", "-180", "-100", "-10", "20", "20"],
         lambda: jl.describe_configuration(jl.lock(jl.load_robot("halt7"), 4, 0.0),
                                           np.radians([-180, -180, -100, -10, 20, 20]))),
        (["kinematics", "canadarm7", "--base", "floating"],
         lambda: jl.describe_configuration(jl.load_robot("canadarm7", base="floating"))),
        (["ik", "puma6", "--lock", "2=30", "--pose", "0.5", "0.3", "0.8", "10", "20", "30"],
         lambda: jl.inverse_kinematics(jl.lock(jl.load_robot("puma6"), 2, np.radians(30.0)),
                                       pose_from_zyx([0.5, 0.3, 0.8], np.radians([10, 20, 30])))),
    ],
)  # fmt: skip
def test_kinematics_and_ik_jobs_are_their_commands(argv, call, capsys):
    report = call()
    assert main([*argv, "--json"]) == 0
    assert to_plain(report.to_dict()) == json.loads(capsys.readouterr().out)
    assert main(argv) == 0
    assert report.summary() == capsys.readouterr().out.splitlines()
    assert to_plain(pickle.loads(pickle.dumps(report)).to_dict()) == to_plain(report.to_dict())


def test_a_job_error_with_its_own_arguments_keeps_the_scenario_context(tmp_path):
    path = tmp_path / "voxel.toml"
    path.write_text('robot = "puma6"\n[failure]\njoint = 2\nangle_deg = 10\n[workspace]\nvoxel = 1e-5\nsamples = 2000\n')
    with pytest.raises(jl.ScenarioError, match=r"voxel\.toml: job \[workspace\]: voxel 1e-05 m is too small"):
        jl.run_scenario(path)


def test_results_print_in_one_line_and_show_their_summary_in_a_notebook():
    """Issue 16, item 3: a result's repr is one line (not its arrays); _repr_html_ is its summary."""
    from jointlock.jobs.ik import inverse_kinematics
    from jointlock.jobs.kinematics import describe_configuration
    from jointlock.jobs.workspace import study_workspace

    puma = jl.load_robot("puma6")
    results = [
        jl.plan_halt("halt7", paper_qf=True, motion=jl.HaltMotionSettings(n_samples=101)),
        describe_configuration(puma, [0.1] * 6),
        inverse_kinematics(puma, jl.ee_pose(puma, [0.1] * 6)),
        study_workspace(puma, (2, 1.0), samples=1000),
    ]
    for res in results:
        text = repr(res)
        assert "\n" not in text and len(text) < 300 and text.startswith(f"<{type(res).__name__}: ")
        page = res._repr_html_()
        assert page.startswith("<pre>") and res.summary()[0].split(":")[0] in page
        has_figure = type(res).__name__ in {"HaltPlan", "WorkspaceStudy"}  # kinematics, ik: none
        assert ('<img src="data:image/png;base64,' in page) == has_figure
        assert (res.main_figure() is not None) == has_figure


QUICK_EXAMPLES = {
    "halt_000": {"halt_config.samples": 2000, "halt.n_samples": 101},
    "jump_001": {"jump.sweep": 6},
    "replan_002": {"workspace.samples": 2000},
}


@pytest.mark.parametrize("example", sorted(QUICK_EXAMPLES))
def test_every_job_with_figures_has_a_main_figure_for_notebooks(example):
    """Issue 16, item 3: _repr_html_ shows the summary and the main figure, with data drawn."""
    import base64
    import io
    import re

    import matplotlib.image as mpimg

    from jointlock.scenario import load_scenario

    examples = Path(__file__).resolve().parents[1] / "examples"
    run = jl.run_scenario(load_scenario(examples / f"{example}.toml", QUICK_EXAMPLES[example]))
    for job in run.scenario.jobs:
        res = run[job]
        fig = res.main_figure()
        assert fig is not None, job
        assert any(ax.has_data() for ax in fig.axes), job
        page = res._repr_html_()
        png = re.search(r'src="data:image/png;base64,([^"]+)"', page)
        assert png is not None, job
        pixels = mpimg.imread(io.BytesIO(base64.b64decode(png.group(1))))
        assert pixels.std() > 0.05, job  # not a blank image

