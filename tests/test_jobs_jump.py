"""The jump job as a library call (jointlock.jobs.jump): the same JSON, text and files as
``jointlock jump``, picklable results, ``jump_from_scenario`` = ``jointlock run``'s command line,
plot functions that draw on a given axis or make their own without touching the backend."""

from __future__ import annotations

import json
import pickle
from pathlib import Path

import pytest
from equivalent_commands import call_subcommand, job_argv

import jointlock as jl
from jointlock.cli import main as cli_main
from jointlock.io.files import to_plain, with_svg
from jointlock.jobs.jump import (
    JumpJobResult,
    jump_from_scenario,
    run_jump_study,
    task_as_the_command_reads_it,
)
from jointlock.planning.jump import JumpScenario
from jointlock.planning.jump import load_jump_task as load_task
from jointlock.plots.jump import (
    plot_joint_rates,
    plot_jump_vs_failure_time,
    plot_kappa_fit,
    plot_objective_vs_kappa,
    plot_position_deviation,
)
from jointlock.scenario import load_scenario

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "jump_001.toml"
#: A short task (60 control steps) keeps the runs fast; the same law and checks as the default.
SHORT_FIELDS = {"duration_s": 3.0, "blend_s": 0.75, "dx_m": [0.1, -0.125, 0.07]}
SHORT_TOML = "duration_s = 3.0\nblend_s = 0.75\ndx_m = [0.1, -0.125, 0.07]\n"

#: mode name -> (library keyword arguments, the same on the command line)
MODES = {
    "fail_at": ({"fail_at": 1.5}, ["--fail-at", "1.5"]),
    "fail_at_kappa": ({"fail_at": 1.5, "kappa": 1e-3}, ["--fail-at", "1.5", "--kappa", "0.001"]),
    "sweep": ({"sweep": 3, "order": 2, "fix": "clip"}, ["--sweep", "3", "--order", "2", "--fix", "clip"]),
    "constant": ({"kappa": 2e-3}, ["--kappa", "0.002"]),
}


def _no_wall_times(d: dict) -> dict:
    """The JSON without ``elapsed_s`` (wall time per stage of the sweep: differs run to run)."""
    return {k: v for k, v in d.items() if k != "elapsed_s"}


@pytest.fixture(scope="module")
def task_file(tmp_path_factory) -> Path:
    f = tmp_path_factory.mktemp("jump") / "short.toml"
    f.write_text(SHORT_TOML)
    return f


@pytest.fixture(scope="module")
def results(task_file) -> dict[str, JumpJobResult]:
    """One library result per mode, on the task the command reads from ``task_file``."""
    model = jl.load_robot("canadarm7")
    task = task_as_the_command_reads_it(load_task(task_file))
    return {name: run_jump_study(model, task, **kw) for name, (kw, _) in MODES.items()}


@pytest.mark.parametrize("name", list(MODES))
def test_to_dict_equals_the_command_json(name, results, task_file, capsys):
    assert cli_main(["jump", "canadarm7", "--scenario", str(task_file), *MODES[name][1], "--json", "--quiet"]) == 0
    printed = json.loads(capsys.readouterr().out)
    assert _no_wall_times(to_plain(results[name].to_dict())) == _no_wall_times(printed)
    assert results[name].mode == ("fail_at" if name.startswith("fail_at") else name)


@pytest.mark.parametrize("name", ["fail_at", "fail_at_kappa", "constant"])
def test_summary_equals_the_command_text(name, results, task_file, capsys):
    assert cli_main(["jump", "canadarm7", "--scenario", str(task_file), *MODES[name][1], "--quiet"]) == 0
    assert capsys.readouterr().out.splitlines() == results[name].summary()


def test_sweep_summary_and_files_equal_the_command(results, task_file, tmp_path, capsys):
    """The sweep's text and ``--out`` files (the slowest mode: one command run for both)."""
    cli_out = tmp_path / "cli"
    argv = ["jump", "canadarm7", "--scenario", str(task_file), *MODES["sweep"][1], "--quiet", "--out", str(cli_out)]
    assert cli_main(argv) == 0
    lines = capsys.readouterr().out.splitlines()
    r = results["sweep"]
    assert lines == r.summary() + ["", f"wrote {cli_out}/results.json and figures"]
    names = r.write(tmp_path / "lib")
    assert sorted(names) == sorted(p.name for p in cli_out.iterdir())
    assert {"results.json", "verification.csv", "fig8_kappa_fit.png", "fig9_jump_vs_failure_time.png"} <= set(names)
    written = json.loads((tmp_path / "lib" / "results.json").read_text())
    assert written == to_plain(r.to_dict())
    assert _no_wall_times(written) == _no_wall_times(json.loads((cli_out / "results.json").read_text()))
    assert (tmp_path / "lib" / "verification.csv").read_text() == (cli_out / "verification.csv").read_text()


def test_write_fail_at_files(results, tmp_path):
    r = results["fail_at_kappa"]  # kappa given: no search, so no objective figure
    names = r.write(tmp_path)
    assert names == with_svg(["results.json", "fig6_joint_velocities.png", "fig7_position_deviation.png"]) + [
        "runs.csv",
        "motion.json",
    ]
    runs = (tmp_path / "runs.csv").read_text().splitlines()
    assert runs[0].startswith("t_s,k0_q1_deg,") and runs[0].endswith(",comp_deviation_mm")
    r0, r1, _ = r.runs()
    assert len(runs) == r0.t.size + 1 and float(runs[-1].split(",")[-1]) == pytest.approx(1e3 * r1.deviation[-1])
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(names)
    assert json.loads((tmp_path / "results.json").read_text()) == to_plain(r.to_dict())


@pytest.mark.parametrize("name", list(MODES))
def test_results_pickle(name, results):
    r = results[name]
    back = pickle.loads(pickle.dumps(r))
    assert isinstance(back, JumpJobResult) and back.job == "jump"
    assert to_plain(back.to_dict()) == to_plain(r.to_dict())
    assert back.summary() == r.summary()


def test_library_checks_its_own_inputs():
    model = jl.load_robot("canadarm7")
    task = JumpScenario(duration=3.0, blend=0.75, dx=(0.1, -0.125, 0.07))
    with pytest.raises(jl.ScenarioError, match="order must be an integer 1..9"):
        run_jump_study(model, task, order=10)
    with pytest.raises(jl.ScenarioError, match="sweep must be an integer >= 1"):
        run_jump_study(model, task, sweep=0)
    with pytest.raises(jl.ScenarioError, match="fix must be"):
        run_jump_study(model, task, fix="none")  # the command's "none" is None here
    with pytest.raises(jl.ScenarioError, match="kappa must be a finite number"):
        run_jump_study(model, task, kappa=float("nan"))
    with pytest.raises(jl.ScenarioError, match="task.q0 has 7 angles"):
        run_jump_study(jl.load_robot("puma6"), task, fail_at=1.0)


@pytest.mark.parametrize(
    "overrides",
    [
        {"jump.sweep": 3, "jump.order": 2},
        {"jump.kappa": 0.002},
    ],
    ids=["sweep", "constant"],
)
def test_from_scenario_equals_the_run_command_line(overrides, tmp_path):
    short = {f"jump.{k}": v for k, v in SHORT_FIELDS.items()}
    sc = load_scenario(EXAMPLE, {**short, **overrides})
    r = jump_from_scenario(sc.data, {})
    argv = job_argv("jump", sc, tmp_path, {}, quiet=True)
    i = argv.index("--out")
    del argv[i : i + 2]  # the figures do not change the JSON (and take time)
    printed, code = call_subcommand("jump", argv)
    assert code == 0
    assert _no_wall_times(to_plain(r.to_dict())) == _no_wall_times(printed)


def test_from_scenario_fail_at(tmp_path):
    """A scenario without a sweep whose failure has a time: one failure time."""
    f = tmp_path / "s.toml"
    f.write_text(
        'robot = "canadarm7"\n[failure]\njoint = 3\ntime_s = 1.2\n[jump]\n'
        + "".join(f"{k} = {json.dumps(v)}\n" for k, v in SHORT_FIELDS.items())
    )
    sc = load_scenario(f)
    r = jump_from_scenario(sc.data, {})
    assert r.mode == "fail_at" and r.task.lock_joint == 3
    argv = job_argv("jump", sc, tmp_path, {}, quiet=True)
    i = argv.index("--out")
    del argv[i : i + 2]
    printed, code = call_subcommand("jump", argv)
    assert code == 0 and to_plain(r.to_dict()) == printed


def test_plots_make_their_own_axes_without_changing_the_backend(results):
    import matplotlib.axes
    import matplotlib.figure
    import matplotlib.pyplot as plt

    backend = matplotlib.get_backend()
    st = results["sweep"]
    r0, r1, t_fail = st.runs()
    try:
        for ax in (
            plot_objective_vs_kappa(st.study.search, 1, title="x"),
            plot_kappa_fit(st.study.search, st.study.fit, st.task.duration),
            plot_jump_vs_failure_time(st.verification, st.study.verification_fixed),
            plot_position_deviation(r0, r1, t_fail, st.task.eps),
        ):
            assert isinstance(ax, matplotlib.axes.Axes)
        fig = plot_joint_rates(st.model, st.task.lock_joint, r0, r1, t_fail)
        assert isinstance(fig, matplotlib.figure.Figure) and len(fig.axes) == 2
        assert "(locked)" in fig.axes[0].get_title()
        given = plt.figure().add_subplot()
        assert plot_objective_vs_kappa(st.study.search, ax=given) is given
    finally:
        plt.close("all")
    assert matplotlib.get_backend() == backend


def test_a_floating_jump_without_a_feasible_kappa_says_the_task_breaks_the_limits(capsys):
    """Issue 14, item 6: NOTES-001's task on the free-floating canadarm7 breaks the limits with
    no compensation and no failure (the spacecraft's reaction adds joint motion): the error
    names the limits, by how much and when, instead of only 'no feasible kappa'."""
    from jointlock.cli import main

    assert main(["jump", "canadarm7", "--base", "floating", "--sweep", "6", "--quiet"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert "with kappa = 0 and no failure, the free-floating arm (generalized Jacobian) already breaks its limits" in err
    assert "joint speed 27.78 deg/s > limit 10 deg/s (joint 5" in err and "path deviation" in err


def test_uncompensated_violations_is_empty_for_a_task_within_the_limits():
    import jointlock as jl
    from jointlock.planning.jump import JumpScenario
    from jointlock.planning.jump._simulate import uncompensated_violations

    assert uncompensated_violations(jl.load_robot("canadarm7"), JumpScenario()) == []


def test_jump_spells_the_lock_as_every_command_does(capsys):
    """Issue 16, item 8: ``--lock J`` (the former ``--lock-joint J`` still works); the jump study
    locks the joint where it is, so ``J=DEG`` is refused in one line."""
    from jointlock.cli import main

    args = ["jump", "canadarm7", "--fail-at", "5", "--kappa", "0", "--json"]
    assert main([*args, "--lock", "3"]) == 0
    new = capsys.readouterr().out
    assert main([*args, "--lock-joint", "3"]) == 0
    assert capsys.readouterr().out == new and '"lock_joint": 3' in new
    with pytest.raises(SystemExit) as exit_:
        main([*args, "--lock", "3=20"])
    assert exit_.value.code == 2
    assert "locks the joint at the angle it has when it fails" in capsys.readouterr().err
