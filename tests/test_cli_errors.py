"""Command-line errors and edge cases: a bad option or an unusable path gives exit code 2 and
one line naming it (no traceback), options mean what they say, files are written atomically."""

from __future__ import annotations

import argparse
import json
import math
import os
from pathlib import Path

import numpy as np
import pytest

import jointlock as jl
from jointlock.cli import build_parser, main
from jointlock.cli._common import check_out_dir, joint_vector_deg, lock_map, seed_arg

#: A short task for ``jump`` (the NOTES-001 law on 20 control steps).
SHORT_JUMP = "duration_s = 1.0\nblend_s = 0.25\ndx_m = [0.05, -0.05, 0.03]\n"


def err_line(capsys) -> str:
    """The stderr of the last command: exactly one line, no traceback."""
    err = capsys.readouterr().err.strip()
    assert "Traceback" not in err
    assert len(err.splitlines()) == 1, err
    return err


def jump_json(capsys, *argv: str) -> dict:
    assert main(["jump", *argv, "--json", "--quiet"]) == 0
    return json.loads(capsys.readouterr().out)


# -- 1. jump --scenario FILE keeps the file's base ------------------------------------------------


def test_jump_uses_the_scenario_files_base_unless_base_is_given(tmp_path, capsys):
    f = tmp_path / "floating.toml"
    f.write_text(SHORT_JUMP + 'base = "floating"\n')
    common = ["canadarm7", "--scenario", str(f), "--fail-at", "0.5", "--kappa", "0.001"]
    out = jump_json(capsys, *common)
    assert out["scenario"]["base"] == "floating"
    model = jl.load_robot("canadarm7", base="floating")
    sc = jl.planning.jump.load_jump_task(f)
    ref = jl.planning.jump.jump_at_time(model, sc, 0.5, kappa=0.001)
    assert out["jump_after"] == pytest.approx(ref.jump_after, rel=1e-12)
    assert jump_json(capsys, *common, "--base", "fixed")["scenario"]["base"] == "fixed"


# -- 2. full-arm rate vectors: the locked joint's rate is 0 ---------------------------------------


def test_joint_vector_deg_rates_need_a_zero_locked_entry():
    model = jl.lock(jl.load_robot("halt7"), 4, math.radians(30.0))
    full = [20.0, 30.0, 15.0, 0.0, 25.0, 40.0, 35.0]
    np.testing.assert_allclose(
        joint_vector_deg(model, full, "--dq0-deg", rates=True), np.radians([20, 30, 15, 25, 40, 35])
    )
    with pytest.raises(jl.ScenarioError, match=r"--dq0-deg: the entries of locked joints \[4\] must be 0"):
        joint_vector_deg(model, [20.0, 30.0, 15.0, 5.0, 25.0, 40.0, 35.0], "--dq0-deg", rates=True)
    # angles keep their rule: the locked entry is the lock angle
    q = joint_vector_deg(model, [0, 0, 0, 30, 0, 0, 0], "--q0-deg")
    np.testing.assert_allclose(q, np.zeros(6))


def test_run_passes_the_healthy_rates_of_a_full_arm_state(tmp_path):
    from equivalent_commands import job_argv

    from jointlock.scenario import load_scenario

    f = tmp_path / "s.toml"
    f.write_text(
        'robot = "halt7"\n[failure]\njoint = 4\nangle_deg = 0\n[state]\n'
        "q0_deg = [-180, -180, -100, 0, -10, 20, 20]\n"
        "dq0_deg = [20, 30, 15, 0, 25, 40, 35]\nddq0_deg = [8, 10, 12, 0, 10, -8, 6]\n"
        "[halt]\nT = 10\n"
    )
    sc = load_scenario(f)
    argv = job_argv("halt", sc, tmp_path / "out", {}, quiet=True)

    def values(option: str) -> list[float]:
        i = argv.index(option) + 1
        vals = []
        while i < len(argv) and not argv[i].startswith("--"):
            vals.append(float(argv[i]))
            i += 1
        return vals

    assert values("--dq0-deg") == [20, 30, 15, 25, 40, 35]
    assert values("--ddq0-deg") == [8, 10, 12, 10, -8, 6]
    assert values("--q0-deg") == [-180, -180, -100, 0, -10, 20, 20]


# -- 3. no jump to reduce: the reduction is n/a ---------------------------------------------------


@pytest.mark.parametrize("mode", [["--fail-at", "0.5"], ["--kappa", "0"]])
def test_jump_reduction_is_na_when_there_is_no_jump(tmp_path, capsys, mode):
    f = tmp_path / "still.toml"
    f.write_text("duration_s = 1.0\nblend_s = 0.25\ndx_m = [0, 0, 0]\n")
    assert main(["jump", "canadarm7", "--scenario", str(f), *mode, "--quiet"]) == 0
    text = capsys.readouterr().out
    assert "reduction n/a" in text and "nan" not in text
    out = jump_json(capsys, "canadarm7", "--scenario", str(f), *mode)
    assert out["mean_reduction"] is None


# -- 4. --out that cannot be a folder; OSError at the CLI boundary -------------------------------


def _out_commands(out: str, scenario: Path) -> list[list[str]]:
    return [
        ["workspace", "halt7", "--samples", "1000", "--out", out],
        ["replan", "puma6", "--lock", "2=0", "--from-deg", *"0 0 0 0 0 0".split()]
        + ["--to-deg", *"10 0 0 0 0 0".split(), "--steps", "2", "--out", out],
        ["tolerance-angle", "puma6", "--lock", "2=0", "--q-target-deg", *"0 10 0 0 0 0".split()]
        + ["--out", out],
        ["singular", "halt7", "--search", "--samples", "2", "--out", out],
        ["jump", "canadarm7", "--fail-at", "0.5", "--kappa", "0", "--quiet", "--out", out],
        ["run", str(scenario), "--out", out, "--quiet"],
    ]


@pytest.mark.parametrize(
    "index", range(6), ids=["workspace", "replan", "tolerance-angle", "singular", "jump", "run"]
)
def test_out_pointing_at_a_file_is_refused_up_front(tmp_path, capsys, index):
    scenario = tmp_path / "s.toml"
    scenario.write_text('robot = "halt7"\n[workspace]\nsamples = 1000\n')
    existing = tmp_path / "results"
    existing.write_text("not a folder")
    argv = _out_commands(str(existing), scenario)[index]
    assert main(argv) == 2
    line = err_line(capsys)
    assert str(existing) in line and "not a folder" in line
    assert existing.read_text() == "not a folder"
    # below a file, too
    argv = _out_commands(str(existing / "sub"), scenario)[index]
    assert main(argv) == 2
    assert "not a folder" in err_line(capsys)


def test_check_out_dir():
    assert check_out_dir(None) is None
    assert check_out_dir("does/not/exist/yet") == Path("does/not/exist/yet")


def _run_with_blocked_job_folder(tmp_path: Path) -> tuple[list[str], Path]:
    scenario = tmp_path / "s.toml"
    scenario.write_text('robot = "canadarm7"\n[jump]\nfail_at = 0.5\nkappa = 0.0\n')
    out = tmp_path / "res"
    out.mkdir()
    (out / "jump").write_text("a file where the job's folder goes")
    return ["run", str(scenario), "--out", str(out), "--quiet"], out / "jump"


def test_os_error_is_one_line_with_the_path(tmp_path, capsys):
    argv, blocked = _run_with_blocked_job_folder(tmp_path)
    assert main(argv) == 2
    line = err_line(capsys)
    assert line.startswith("jointlock run: error: ") and str(blocked) in line


def test_os_error_traceback_with_debug(tmp_path):
    argv, _ = _run_with_blocked_job_folder(tmp_path)
    with pytest.raises(OSError):
        main(["--debug", *argv])


# -- 5. --seed must be >= 0 -----------------------------------------------------------------------


def test_seed_arg():
    assert seed_arg("0") == 0 and seed_arg("42") == 42
    for bad in ("-1", "1.5", "x", str(2**63), "9" * 400):
        with pytest.raises(argparse.ArgumentTypeError, match="integer >= 0 and <= 9223372036854775807"):
            seed_arg(bad)


@pytest.mark.parametrize(
    "argv",
    [
        ["workspace", "halt7", "--samples", "1000", "--seed", "-1"],
        ["singular", "halt7", "--search", "--samples", "2", "--seed", "-1"],
        ["ik", "halt7", "--pose", "1", "0", "0", "0", "0", "0", "--method", "numeric", "--seed", "-1"],
        ["run", "s.toml", "--seed", "-1"],
        ["halt", "halt7", "--seed", "-1"],
        ["halt-config", "halt7", "--lock", "4=0", "--seed", "-1"],
    ],
    ids=lambda a: a[0],
)
def test_negative_seed_is_a_usage_error(capsys, argv):
    with pytest.raises(SystemExit) as exc:
        main(argv)
    assert exc.value.code == 2
    assert "--seed: must be an integer >= 0 and <= 9223372036854775807; got '-1'" in capsys.readouterr().err


def test_every_seed_option_uses_seed_arg():
    parser = build_parser()
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    checked = []
    for name, p in sub.choices.items():
        for action in p._actions:
            if "--seed" in action.option_strings:
                assert action.type is seed_arg, name
                checked.append(name)
    assert {"workspace", "singular", "ik", "run"} <= set(checked)


# -- 8. a joint locked twice ----------------------------------------------------------------------


def test_lock_map_refuses_a_joint_given_twice():
    assert lock_map([(2, 0.5), (4, 0.1)]) == {2: 0.5, 4: 0.1}
    assert lock_map(None) == {}
    with pytest.raises(jl.ScenarioError, match="joint 2 given twice"):
        lock_map([(2, math.radians(30)), (2, math.radians(50))])


@pytest.mark.parametrize("command", ["kinematics", "singular", "ik"])
def test_a_joint_locked_twice_is_refused(capsys, command):
    argv = [command, "halt7", "--lock", "2=30", "--lock", "2=50"]
    if command == "ik":
        argv += ["--pose", "1", "0", "0", "0", "0", "0"]
    assert main(argv) == 2
    line = err_line(capsys)
    assert "--lock: joint 2 given twice (30 and 50 deg)" in line


# -- 9. non-finite option values ------------------------------------------------------------------


@pytest.mark.parametrize(
    "argv, words",
    [
        (["jump", "canadarm7", "--fail-at", "0.5", "--kappa", "nan"], "argument --kappa: must be a finite number"),
        (["jump", "canadarm7", "--kappa", "inf"], "argument --kappa: must be a finite number"),
        (
            ["ik", "halt7", "--pose", "1", "0", "0", "0", "0", "0", "--length-scale", "nan"],
            "argument --length-scale: must be a finite number",
        ),
        (
            ["ik", "halt7", "--pose", "1", "0", "0", "0", "0", "0", "--length-scale", "-1"],
            "argument --length-scale: must be a finite number >= 1e-06 and <= 1e+06 [m]; got '-1'",
        ),
        (
            ["replan", "puma6", "--lock", "2=0", "--from-deg", *"0 0 0 0 0 0".split()]
            + ["--to-deg", *"10 0 0 0 0 0".split(), "--cycle", "inf"],
            "argument --cycle: must be a finite number",
        ),
        (["workspace", "halt7", "--samples", "1000", "--voxel", "inf"], "argument --voxel: must be a finite number"),
    ],
)
def test_non_finite_options_are_refused(capsys, argv, words):
    """Refused by the option's type (its scenario field's bounds), before anything runs."""
    assert exit_code(argv) == 2
    assert words in err_line(capsys)


# -- 7. tolerance-angle grid size -----------------------------------------------------------------


def test_tolerance_angle_bounds_the_grid(capsys, monkeypatch):
    from jointlock.cli import tolerance_angle

    argv = ["tolerance-angle", "puma6", "--lock", "2=0", "--q-target-deg", *"0 10 0 0 0 0".split()]
    with monkeypatch.context() as m:  # first with a small cap (the old code had none)
        m.setattr(tolerance_angle, "MAX_GAMMA_SAMPLES", 1000)
        assert main([*argv, "--json"]) == 2  # 3601 samples at the default 0.1 deg
        assert "3601 gamma samples" in err_line(capsys)
        assert main([*argv, "--step-deg", "0.5", "--json"]) == 0  # 721 samples
        capsys.readouterr()
    assert main([*argv, "--step-deg", "1e-7"]) == 2  # 3.6e9 samples: refused before allocating
    line = err_line(capsys)
    assert "--step-deg 1e-07 gives 3600000001 gamma samples" in line and "--step-deg >=" in line


# -- 10. result files are written atomically ------------------------------------------------------


@pytest.mark.parametrize("command", ["workspace", "replan", "tolerance-angle"])
def test_result_files_are_written_atomically(tmp_path, monkeypatch, command):
    import jointlock.io.files as files_io  # every writer goes through its atomic_write_bytes

    written: list[str] = []
    real = files_io.atomic_write_bytes

    def spy(path, data):
        written.append(Path(path).name)
        real(path, data)

    monkeypatch.setattr(files_io, "atomic_write_bytes", spy)
    out = tmp_path / "out"
    argv = {
        "workspace": ["workspace", "halt7", "--lock", "2=0", "--samples", "1000", "--json"],
        "replan": ["replan", "puma6", "--lock", "2=0", "--from-deg", *"0 0 0 0 0 0".split()]
        + ["--to-deg", *"10 0 0 0 0 0".split(), "--steps", "2", "--json"],
        "tolerance-angle": ["tolerance-angle", "puma6", "--lock", "2=0"]
        + ["--q-target-deg", *"0 10 0 0 0 0".split(), "--step-deg", "1", "--json"],
    }[command]
    assert main([*argv, "--out", str(out)]) == 0
    files = sorted(p.name for p in out.iterdir())
    assert files and sorted(written) == files
    for name in files:
        if name.endswith(".png"):
            assert (out / name).read_bytes().startswith(b"\x89PNG")
    if command == "workspace":
        with np.load(out / "points.npz") as z:
            assert z["full"].shape == (1000, 3) and z["locked"].shape == (1000, 3)


# -- 13. small things -----------------------------------------------------------------------------


def test_jump_order_is_capped_at_9(capsys):
    assert exit_code(["jump", "canadarm7", "--order", "10", "--scenario", "missing.toml"]) == 2
    assert "argument --order: must be an integer >= 1 and <= 9; got '10'" in err_line(capsys)
    assert exit_code(["jump", "canadarm7", "--order", "0"]) == 2
    assert "argument --order: must be an integer >= 1 and <= 9; got '0'" in err_line(capsys)


@pytest.mark.parametrize(
    "extra, ignored",
    [
        (
            ["--fail-at", "0.5", "--kappa", "0", "--order", "3", "--fix", "clip"],
            "--order, --fix ignored with --fail-at",
        ),
        (["--fail-at", "0.5", "--kappa", "0", "--single"], "--single ignored with --fail-at"),
        (["--kappa", "0", "--fix", "ramp", "--sweep", "4"], "--fix, --sweep ignored with --kappa"),
    ],
)
def test_jump_warns_about_ignored_options(tmp_path, capsys, extra, ignored):
    f = tmp_path / "s.toml"
    f.write_text(SHORT_JUMP)
    assert main(["jump", "canadarm7", "--scenario", str(f), *extra, "--json", "--quiet"]) == 0
    err = capsys.readouterr().err
    assert f"jointlock jump: warning: {ignored}" in err


def test_jump_no_warning_for_the_default_mode_options(tmp_path, capsys):
    from equivalent_commands import job_argv

    from jointlock.scenario import load_scenario

    f = tmp_path / "s.toml"
    f.write_text('robot = "canadarm7"\n[jump]\nkappa = 0.0\norder = 3\nfix = "clip"\n')
    argv = job_argv("jump", load_scenario(f), tmp_path / "out", {}, quiet=True)
    assert "--kappa" in argv and not {"--order", "--fix", "--sweep"} & set(argv)
    f.write_text('robot = "canadarm7"\n[jump]\nsweep = 4\norder = 3\n')
    argv = job_argv("jump", load_scenario(f), tmp_path / "out", {}, quiet=True)
    assert argv[argv.index("--order") + 1] == "3" and "--sweep" in argv and "--fix" in argv


def test_help_texts(capsys):
    with pytest.raises(SystemExit):
        main(["jump", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert "--optimize" in text and "the default mode" in text and "1..9" in text
    with pytest.raises(SystemExit):
        main(["reproduce", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert "About 5 s" in text and "20 s" not in text


# -- UX review: usage errors, --debug, broken pipes, help texts -----------------------------------


@pytest.mark.parametrize(
    "argv, prog",
    [
        (["workspace"], "jointlock workspace"),  # a required argument missing
        (["replan", "puma6", "--steps", "x"], "jointlock replan"),  # a bad value
        (["robots", "--bogus"], "jointlock robots"),  # an unknown option after the subcommand
        (["nope"], "jointlock"),  # an unknown subcommand
        ([], "jointlock"),
    ],
)
def test_usage_errors_are_one_line_pointing_to_help(capsys, argv, prog):
    with pytest.raises(SystemExit) as exc:
        main(argv)
    assert exc.value.code == 2
    line = err_line(capsys)
    assert line.startswith(f"{prog}: error: ") and line.endswith(f"(see '{prog} --help')")
    assert "usage:" not in line


def test_every_subparser_has_the_one_line_error():
    from jointlock.cli import Parser

    parser = build_parser()
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    assert sub.choices and all(isinstance(p, Parser) for p in sub.choices.values())


@pytest.mark.parametrize("where", ["before", "after"])
def test_debug_is_accepted_before_and_after_the_subcommand(tmp_path, where):
    argv, _ = _run_with_blocked_job_folder(tmp_path)
    argv = ["--debug", *argv] if where == "before" else [*argv, "--debug"]
    with pytest.raises(OSError):  # --debug: the traceback, not the one-line error
        main(argv)
    args = build_parser().parse_args(["robots", "--debug"])
    assert args.debug is True
    assert build_parser().parse_args(["robots"]).debug is False


def test_broken_pipe_exits_quietly():
    import subprocess
    import sys

    code = "import sys\nfrom jointlock.cli import main\nsys.exit(main(['robots']))\n"
    proc = subprocess.Popen(
        [sys.executable, "-c", code],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        env={**os.environ, "MPLBACKEND": "Agg"},
    )
    proc.stdout.close()  # the reader has left before the first line (as `| head -0`)
    err = proc.stderr.read().decode()
    proc.wait(timeout=120)
    assert "Broken pipe" not in err and "Traceback" not in err and "Exception ignored" not in err, err
    assert proc.returncode == 141


def _help(command: str) -> str:
    parser = build_parser()
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return " ".join(sub.choices[command].format_help().split())


@pytest.mark.parametrize(
    "command, words",
    [
        ("tolerance-angle", ["--gamma-limit-deg DEG", "this [deg]", "--zoom-deg DEG", "--step-deg DEG"]),
        ("tolerance-angle", ["--q-target-deg DEG", "every joint of the arm [deg]", "puma6-family arms only"]),
        ("replan", ["start configuration, every joint of the arm [deg]", "goal configuration"]),
        ("replan", ["puma6-family arms only", ">= 1"]),
        ("ik", ["closed-form: analytic IK", "spherical-wrist", "numeric: Levenberg", "auto (default)"]),
        ("workspace", ["voxel occupancy", "from half the samples", ">= 1000"]),
        ("jump", ["--kappa K", "rad^2/(s m^3)", "deg/s", "q0_deg"]),
    ],
)
def test_help_texts_give_units_and_scope(command, words):
    text = _help(command)
    for w in words:
        assert w in text, (command, w)


def test_readme_row_says_which_arms_tolerance_angle_and_replan_take():
    readme = (Path(__file__).resolve().parents[1] / "README.md").read_text()
    row = next(line for line in readme.splitlines() if line.startswith("| re-plan a 6-DOF arm"))
    assert "puma6-family arms only" in row


# -- UX review: jump errors and output --------------------------------------------------------------


def test_jump_on_another_robot_asks_for_a_task_with_q0(capsys, tmp_path):
    assert main(["jump", "puma6", "--quiet"]) == 2
    line = err_line(capsys)
    assert "other than canadarm7 needs --scenario FILE with q0_deg (6 values [deg])" in line
    assert "q0_deg = [10, 40, -70, 100, -60, 30]" in line and "has 7 angles" not in line
    f = tmp_path / "t.toml"
    f.write_text("dx_m = [0.1, 0, 0]\n")
    assert main(["jump", "puma6", "--scenario", str(f), "--quiet"]) == 2
    assert "gives no q0_deg" in err_line(capsys)


def test_jump_refuses_a_run_scenario_file_with_advice(capsys):
    example = Path(__file__).resolve().parents[1] / "examples" / "jump_001.toml"
    assert main(["jump", "canadarm7", "--scenario", str(example), "--quiet"]) == 2
    line = err_line(capsys)
    assert "is a `jointlock run` scenario file" in line and f"jointlock run {example}" in line
    assert "unknown field" not in line


def test_jump_text_output_units_and_words(capsys, tmp_path):
    f = tmp_path / "t.toml"
    f.write_text(SHORT_JUMP)
    assert (
        main(["jump", "canadarm7", "--scenario", str(f), "--fail-at", "0.5", "--kappa", "0.5", "--quiet"])
        == 0
    )
    text = capsys.readouterr().out
    assert "nan" not in text
    assert "kappa = 0.5 rad^2/(s m^3) (given, feasible interval not searched)" in text
    jump_line = next(line for line in text.splitlines() if line.startswith("joint jump"))
    assert "deg/s" in jump_line and "rad/s" not in jump_line
    out = jump_json(capsys, "canadarm7", "--scenario", str(f), "--fail-at", "0.5", "--kappa", "0.5")
    assert out["kappa_unit"] == "rad^2/(s m^3)"
    if out["jump_after"] > out["jump_before"]:
        assert "x larger" in jump_line or "% larger" in jump_line


def test_jump_text_helpers():
    from jointlock.cli.jump import _interval_text, _less, _points_text

    assert _less(0.25) == "25.0 % less"
    assert _less(-33.405) == "34.4x larger"
    assert _less(-0.05) == "5.0 % larger"
    assert _less(None).startswith("reduction n/a")
    assert _interval_text({"kappa_interval": [None, None]}, given=False) == "no feasible kappa"
    assert _interval_text({"kappa_interval": [-1e-3, 2e-3]}, given=False) == "feasible [-0.001, 0.002]"
    assert _points_text([None, None]) == "none (kappa = 0 everywhere)"
    assert _points_text([float("nan"), float("nan")]) == "none (kappa = 0 everywhere)"
    assert _points_text([0.0, 12.0]) == "0 s, 12 s"


# -- halt: errors name the options, missing options all at once ------------------------------------


@pytest.mark.parametrize(
    "extra, words",
    [
        (["--T", "0"], "argument --T: must be a finite number >= 0.001 and <= 1e+06 [s]; got '0'"),
        (["--T", "nan"], "argument --T: must be a finite number >= 0.001 and <= 1e+06 [s]; got 'nan'"),
        (["--n-samples", "12"], "--n-samples must be an odd integer >= 11"),  # was "n_samples must be odd"
        (["--n-samples", "5"], "argument --n-samples: must be an integer >= 11 and <= 200001; got '5'"),
        (["--solver", "ga", "--population", "1"], "argument --population: must be an integer >= 2"),
        (["--solver", "ga", "--generations", "-1"], "argument --generations: must be an integer >= 0"),
        (["--vmax-deg", "40", "30"], "--vmax-deg needs one value or 6 values, finite and > 0"),
    ],
)
def test_halt_errors_name_the_option(capsys, extra, words):
    assert exit_code(["halt", "halt7", "--paper-qf", "--quiet", *extra]) == 2
    err = err_line(capsys)
    assert words in err
    assert "GASettings" not in err and "halt_time" not in err and "n_samples" not in err


def test_halt_lists_every_missing_option_at_once(capsys):
    assert main(["halt", "canadarm7", "--lock", "4=0", "--dq0-deg", *["0"] * 6, "--quiet"]) == 2
    err = err_line(capsys)
    assert "this robot needs --q0-deg, --ddq0-deg, --T " in err  # was one per run
    assert main(["halt", "canadarm7", "--lock", "4=0", "--quiet"]) == 2
    assert "needs --q0-deg, --dq0-deg, --ddq0-deg, --T " in err_line(capsys)


def test_halt_continuous_joint_error_names_options_in_degrees(capsys):
    urdf = str(Path(__file__).parent / "data" / "arm5.urdf")
    argv = ["halt", urdf, "--lock", "2=20", "--q0-deg", "0", "10", "20", "30", "--dq0-deg", *["0"] * 4]
    argv += ["--ddq0-deg", "0", "0", "30", "0", "--T", "5", "--quiet"]
    assert main(argv) == 2  # an impossible start: named by option, in degrees, no search
    err = err_line(capsys)
    assert "--ddq0-deg" in err and "joint 4 starts with acceleration 30 deg/s^2" in err
    assert "[rad]" not in err and "angle_lower" not in err and "q_min" not in err


def exit_code(argv: list[str]) -> int:
    """The CLI's exit code, in-process: an option refused by argparse (its type) exits."""
    try:
        return main(argv)
    except SystemExit as exc:
        return int(exc.code)


# -- halt: the state at failure is 000's only for 000's failure (issue 14, item 4) -----------------


def test_halt_refuses_000s_state_for_another_lock(capsys):
    assert exit_code(["halt", "halt7", "--lock", "3=0", "--quiet"]) == 2
    err = err_line(capsys)
    assert "halt7 with joint 3 at 0 deg needs --q0-deg, --dq0-deg, --ddq0-deg, --T" in err and "--from-rest" in err
    assert exit_code(["halt", "halt7", "--lock", "3=0", "--paper-qf", "--q0-deg", *["0"] * 6, "--from-rest", "--T", "10"]) == 2
    assert "--paper-qf is 000's q_best for halt7 with joint 4 locked at 0 deg only" in err_line(capsys)


def test_halt_from_rest_says_it_is_a_reconfiguration(capsys):
    argv = ["halt", "halt7", "--lock", "3=0", "--from-rest", "--q0-deg", "10", "20", "30", "40", "50", "60"]
    argv += ["--T", "10", "--qf-deg", "0", "0", "0", "0", "0", "0", "--quiet"]
    assert exit_code([*argv, "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["from_rest"] and data["state_source"] == "--q0-deg, from rest"
    assert data["dq_initial_deg_s"] == [0.0] * 6 and data["ddq_initial_deg_s2"] == [0.0] * 6
    assert np.allclose(data["q_initial_deg"], [10.0, 20.0, 30.0, 40.0, 50.0, 60.0], rtol=0, atol=1e-12)
    assert exit_code(argv) == 0
    out = capsys.readouterr().out
    assert "state at failure (--q0-deg, from rest): q0 = [10, 20, 30, 40, 50, 60] deg" in out
    assert "from rest: the halt is a reconfiguration from q0 to the halt configuration" in out
    assert "-0 " not in out and "-0," not in out and "= -0" not in out
    assert exit_code([*argv, "--dq0-deg", *["1"] * 6]) == 2
    assert "--from-rest means zero rates" in err_line(capsys)


def test_halt_prints_the_state_it_starts_from(capsys):
    assert exit_code(["halt", "halt7", "--paper-qf", "--quiet"]) == 0
    out = capsys.readouterr().out
    assert "state at failure (000 §5.2): q0 = [-180, -180, -100, -10, 20, 20] deg; dq0 = [20, 30, 15, 25, 40, 35] deg/s" in out
    scenario = jl.load_scenario(Path(__file__).resolve().parents[1] / "examples" / "halt_000.toml")
    data = scenario.data
    from jointlock.jobs.halt import halt_from_scenario

    data = {**data, "halt": {**data["halt"], "paper_qf": True}}
    assert halt_from_scenario(data, {}).state_source == "000 §5.2"  # the example's state is 000's


def test_000s_defaults_belong_to_joint_4_at_0_only(tmp_path, capsys):
    """A scenario (or the library) with joint 4 locked at 30 deg gets no 000 state or T; 000's lock
    given explicitly does; giving part of the state on 000's failure warns."""
    path = tmp_path / "j4at30.toml"
    path.write_text('robot = "halt7"\n[failure]\njoint = 4\nangle_deg = 30.0\n[halt]\nqf_deg = [0, 0, 0, 0, 0, 0]\n')
    with pytest.raises(jl.ScenarioError, match=r"job \[halt\] needs state.q0_deg"):
        jl.load_scenario(path)
    model = jl.lock(jl.load_robot("halt7", base="floating"), 3, 0.0)
    state = jl.FailureState.from_degrees(model, [0.0] * 6)
    with pytest.raises(jl.ScenarioError, match="needs the halt time T"):
        jl.plan_halt(model, state, qf=np.zeros(6))
    assert exit_code(["halt", "halt7", "--lock", "4=0", "--paper-qf", "--quiet", "--n-samples", "101"]) == 0
    assert "state at failure (000 §5.2)" in capsys.readouterr().out
    assert exit_code(["halt", "halt7", "--paper-qf", "--quiet", "--n-samples", "101", "--q0-deg", *["0"] * 6]) == 0
    err = capsys.readouterr().err
    assert "warning: --q0-deg given, the rest of the state is 000 §5.2's" in err


def test_run_keeps_every_lock_or_says_why_it_cannot(capsys):
    scenario = str(Path(__file__).resolve().parents[1] / "examples" / "replan_002.toml")
    assert exit_code(["run", scenario, "--lock", "2=59.4", "--lock", "3=0"]) == 2  # not the last one silently
    assert "[replan] work with one locked joint" in err_line(capsys)
    assert exit_code(["run", scenario, "--lock", "2=59.4", "--lock", "2=0"]) == 2
    assert "--lock: each joint once; got joints [2, 2]" in err_line(capsys)
