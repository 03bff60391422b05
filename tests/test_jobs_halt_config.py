"""The halt_config job as a library call (jointlock.jobs.halt_config): the same JSON, text and
files as ``jointlock halt-config``, picklable results, ``halt_config_from_scenario`` = ``jointlock
run``'s command line, section plots that draw on a given axis or make their own without
touching the backend."""

from __future__ import annotations

import json
import math
import pickle
from pathlib import Path

import numpy as np
import pytest
from equivalent_commands import call_subcommand, job_argv

import jointlock as jl
from jointlock.cli import main as cli_main
from jointlock.io.files import to_plain, with_svg
from jointlock.jobs.halt import CLI_LIMIT_NAMES, FailureState
from jointlock.jobs.halt_config import (
    HaltConfigurationStudy,
    ReachabilitySettings,
    halt_config_from_scenario,
    study_halt_configuration,
    write_section_plots,
)
from jointlock.plots.halt_config import plot_section, section_figures
from jointlock.scenario import load_scenario

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "halt_000.toml"
#: Few samples keep the runs fast; the same search as the default 36000.
SAMPLES = 200
#: 000 §5.2's state at failure, healthy joints 1, 2, 3, 5, 6, 7 [deg, deg/s, deg/s^2].
Q0, DQ0, DDQ0 = [-180, -180, -100, -10, 20, 20], [20, 30, 15, 25, 40, 35], [8, 10, 12, 10, -8, 6]


def _nums(values) -> list[str]:
    return [str(v) for v in values]


STATE_ARGV = ["--from-q-deg", *_nums(Q0), "--from-dq-deg", *_nums(DQ0), "--from-ddq-deg", *_nums(DDQ0)]
STATE_ARGV += ["--halt-time", "10"]

#: mode -> (base, library keyword arguments, reachability settings (method, per_joint_k) or
#: None, the same options on the command line)
MODES = {
    "plain": ("fixed", {}, None, []),
    "readings": (
        "floating",
        {"refine": False, "renormalize": True, "assignment": "text", "length": 1.5, "jacobian": "fixed"},
        None,
        ["--no-refine", "--renormalize", "--assignment", "text", "--length", "1.5", "--jacobian", "fixed"],
    ),
    "exact": ("fixed", {}, ("exact", False), STATE_ARGV),
    "exact_per_joint_limits": (
        "floating",
        {"vmax_deg": [50, 35, 40, 40, 45, 40], "amax_deg": 25},
        ("exact", True),
        STATE_ARGV + ["--per-joint-k", "--vmax-deg", "50", "35", "40", "40", "45", "40", "--amax-deg", "25"],
    ),
    "bound": ("fixed", {}, ("bound", False), STATE_ARGV + ["--reachability", "bound"]),
}


def _argv(name: str) -> list[str]:
    base, _, _, extra = MODES[name]
    argv = ["halt-config", "halt7", "--lock", "4=0", "--base", base, "--samples", str(SAMPLES), "--seed", "3"]
    return argv + extra + ["--quiet"]


@pytest.fixture(scope="module")
def results() -> dict[str, HaltConfigurationStudy]:
    """One library result per mode."""
    out = {}
    for name, (base, kw, reach, _) in MODES.items():
        model = jl.lock(jl.load_robot("halt7", base=base), 4, 0.0)
        settings = None
        if reach is not None:
            state = FailureState(np.radians(Q0), np.radians(DQ0), np.radians(DDQ0))
            settings = ReachabilitySettings(state, 10.0, method=reach[0], per_joint_k=reach[1])
        kw = {"characteristic_length" if k == "length" else k: v for k, v in kw.items()}  # current name
        out[name] = study_halt_configuration(
            model, samples=SAMPLES, rng=3, reachability=settings, limit_names=CLI_LIMIT_NAMES, **kw
        )  # the limits' sources named as the command names them
    return out


@pytest.mark.parametrize("name", list(MODES))
def test_to_dict_and_summary_equal_the_command(name, results, capsys):
    r = results[name]
    assert cli_main(_argv(name) + ["--json"]) == 0
    assert to_plain(r.to_dict()) == json.loads(capsys.readouterr().out)
    assert cli_main(_argv(name)) == 0
    assert capsys.readouterr().out.splitlines() == r.summary()
    assert r.configuration.seed == 3 and r.job == "halt_config"
    assert (r.limits is None) == (MODES[name][2] is None)


def test_write_equals_the_command_files(results, tmp_path, capsys):
    r = results["exact"]
    cli_out = tmp_path / "cli"
    assert cli_main(_argv("exact") + ["--out", str(cli_out)]) == 0
    lines = capsys.readouterr().out.splitlines()
    names = r.write(tmp_path / "lib")
    assert names == with_svg(["result.json", "samples.npz", "samples.csv"] + [
        f"section_joint{n}.png" for n in (1, 2, 3, 5, 6, 7)
    ])
    assert sorted(names) == sorted(p.name for p in cli_out.iterdir())
    assert lines == r.summary() + ["", f"wrote {len(names)} files to {cli_out}: " + ", ".join(names)]
    written = json.loads((tmp_path / "lib" / "result.json").read_text())
    assert written == to_plain(r.to_dict()) == json.loads((cli_out / "result.json").read_text())
    for name in ("samples.csv", "samples.npz"):
        assert (tmp_path / "lib" / name).read_bytes() == (cli_out / name).read_bytes()
    with np.load(tmp_path / "lib" / "samples.npz") as npz:
        np.testing.assert_array_equal(npz["q_rad"], r.configuration.q_samples)


def test_json_with_out_lists_the_files(results, tmp_path, capsys):
    r = results["plain"]
    assert cli_main(_argv("plain") + ["--out", str(tmp_path), "--json"]) == 0
    printed = json.loads(capsys.readouterr().out)
    files = printed.pop("files")
    assert printed == to_plain(r.to_dict())
    expected = with_svg(["result.json", "samples.npz", "samples.csv"] + [
        f"section_joint{n}.png" for n in (1, 2, 3, 5, 6, 7)
    ])
    assert files == [str(tmp_path / name) for name in expected]
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(expected)


@pytest.mark.parametrize("name", list(MODES))
def test_results_pickle(name, results):
    r = results[name]
    back = pickle.loads(pickle.dumps(r))
    assert isinstance(back, HaltConfigurationStudy) and back.job == "halt_config"
    assert to_plain(back.to_dict()) == to_plain(r.to_dict())
    assert back.summary() == r.summary()


@pytest.mark.parametrize(
    "overrides",
    [{}, {"halt_config.reachable": False, "halt_config.no_refine": True}, {"halt_config.halt_time": 12.0}],
    ids=["reachable", "whole_ranges", "own_halt_time"],
)
def test_from_scenario_equals_the_run_command_line(overrides, tmp_path):
    sc = load_scenario(EXAMPLE, {"halt_config.samples": 300, **overrides})
    r = halt_config_from_scenario(sc.data, {})
    assert isinstance(r, HaltConfigurationStudy)
    argv = job_argv("halt_config", sc, tmp_path, {}, quiet=True)
    i = argv.index("--out")
    del argv[i : i + 2]  # the files do not change the JSON (and take time)
    printed, code = call_subcommand("halt_config", argv)
    assert code == 0
    # the same except where the limits came from: the scenario's fields, the command's options
    ours = json.loads(json.dumps(r.to_dict()).replace("limits.vmax_deg_s", "--vmax-deg").replace(
        "limits.amax_deg_s2", "--amax-deg"))  # fmt: skip
    assert ours == printed
    assert (r.configuration.reachability is None) == (overrides.get("halt_config.reachable") is False)


def test_library_checks_its_own_inputs():
    model = jl.lock(jl.load_robot("halt7"), 4, 0.0)
    state = FailureState(np.radians(Q0), np.radians(DQ0), np.radians(DDQ0))
    with pytest.raises(jl.ConfigurationError, match="halt_time must be a finite number > 0"):
        ReachabilitySettings(state, -1.0)
    with pytest.raises(jl.ConfigurationError, match="method must be 'exact' or 'bound'"):
        ReachabilitySettings(state, 10.0, method="box")  # type: ignore[arg-type]
    with pytest.raises(jl.ConfigurationError, match="needs a locked model"):
        study_halt_configuration(jl.load_robot("halt7"), samples=10)
    with pytest.raises(jl.ConfigurationError, match="samples must be an integer >= 2"):
        study_halt_configuration(model, samples=1)
    with pytest.raises(jl.ConfigurationError, match="length must be a finite length > 0"):
        study_halt_configuration(model, samples=10, characteristic_length=0.0)
    with pytest.raises(jl.ScenarioError, match="needs one value or 6 values"):
        study_halt_configuration(
            model, samples=10, reachability=ReachabilitySettings(state, 10.0), vmax_deg=[1, 2]
        )
    with pytest.raises(jl.InfeasibleError, match="already breaks a limit"):
        study_halt_configuration(
            model, samples=10, reachability=ReachabilitySettings(state, 10.0), amax_deg=5
        )


def test_section_plots_draw_on_a_given_axis_or_their_own(results):
    import matplotlib
    import matplotlib.axes
    import matplotlib.pyplot as plt

    backend = matplotlib.get_backend()
    r = results["exact"]
    try:
        ax = plot_section(r, 5)
        assert isinstance(ax, matplotlib.axes.Axes)
        assert (
            ax.get_xlabel() == "angle of joint 5 [deg]"
            and ax.get_title() == f"joint 5 - CP ({SAMPLES} samples)"
        )
        given = plt.figure().add_subplot()
        assert plot_section(r.configuration, 1, ax=given) is given
        with pytest.raises(jl.ConfigurationError, match="not a healthy joint"):
            plot_section(r, 4)
    finally:
        plt.close("all")
    figs = section_figures(r)
    assert len(figs) == 6 and tuple(figs[0].get_size_inches()) == (5.0, 3.4)
    texts = [t.get_text() for t in figs[0].axes[0].get_legend().get_texts()]
    n_ok = int(np.count_nonzero(r.configuration.reachable))  # reachable and clear of the bus
    assert f"admissible samples ({n_ok})" in texts and "best" in texts
    assert f"unreachable or too close samples ({SAMPLES - n_ok})" in texts
    assert matplotlib.get_backend() == backend


def test_planning_plot_functions_are_deprecated_wrappers(results):
    from jointlock.planning import halt_config as hc

    r = results["plain"].configuration
    with pytest.warns(DeprecationWarning, match="jointlock.plots.halt_config"):
        figs = hc.section_figures(r)
    assert len(figs) == 6
    with pytest.warns(DeprecationWarning, match="jointlock.jobs.halt_config.write_section_plots"):
        assert hc.write_section_plots is write_section_plots
    assert math.isfinite(results["plain"].cp_best)
