"""Seed 002's jobs as library calls (tolerance_angle, replan, workspace): each equals its command.

For every mode of ``jointlock tolerance-angle``, ``replan`` and ``workspace``: the job's
``to_dict()`` is the JSON the command prints, ``summary()`` the lines it prints, ``write()``
the files its ``--out`` writes; results pickle; ``<job>_from_scenario`` equals the command that
``jointlock run`` forms from the example scenario; the plot functions make their own axes
without touching the backend.
"""

from __future__ import annotations

import json
import math
import pickle
from pathlib import Path

import numpy as np
import pytest

import jointlock as jl
from jointlock.cli import main
from jointlock.io.files import to_plain, with_svg
from jointlock.jobs.replan import ReplanJobResult, plan_replan, replan_from_scenario
from jointlock.jobs.tolerance_angle import (
    ToleranceAngleResult,
    find_tolerance_angle,
    tolerance_angle_from_scenario,
)
from jointlock.jobs.workspace import (
    VoxelTooSmallError,
    WorkspaceStudy,
    study_workspace,
    workspace_from_scenario,
)

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
Q_TARGET = [5.0, 60.0, 35.2, 10.0, -120.0, 90.0]  # 35.2 and 60 do not survive deg -> rad -> deg
Q_FROM = [0.0, 30.0, 30.0, 10.0, -80.0, 30.0]
Q_TO = [5.0, 60.0, 65.0, 10.0, -120.0, 90.0]
# the files each command's --out writes (as before the jobs moved into the library)
TOLERANCE_FILES = with_svg(["joints_vs_gamma.png", "joints_vs_gamma_zoom.png", "locked_joint_vs_gamma.png", "sweep.json"])
REPLAN_FILES = with_svg(["joints.png", "pose.png", "error.png", "velocity.png", "trajectory.csv", "plan.json", "motion.json"])
WORKSPACE_FILES = with_svg(["projections.png", "clouds.png", "points.npz", "workspace.json"])


def _cli(capsys, argv: list[str]) -> tuple[list[str], list[str]]:
    assert main(argv) == 0
    cap = capsys.readouterr()
    return cap.out.splitlines(), cap.err.splitlines()


def _cli_json(capsys, argv: list[str]) -> dict:
    out, _ = _cli(capsys, [*argv, "--json"])
    return json.loads("\n".join(out))


def _same_as_cli(capsys, result, argv: list[str]) -> None:
    assert to_plain(result.to_dict()) == _cli_json(capsys, argv)
    lines, _ = _cli(capsys, argv)
    assert result.summary() == lines


def _lock_args(joint: int, angle_deg: float) -> list[str]:
    return ["--lock", f"{joint}={angle_deg!r}"]


@pytest.fixture(scope="module")
def puma():
    return jl.load_robot("puma6")


# -- tolerance_angle -------------------------------------------------------------------------------

TOLERANCE_CASES = [
    # (lock angle [deg], options): roots found; none within a narrow limit; zoom = limit
    (59.4, {"gamma_limit_deg": 180.0, "zoom_deg": 2.0, "step_deg": 1.0}),
    (10.0, {"gamma_limit_deg": 30.0, "zoom_deg": 5.0, "step_deg": 0.5}),
    (60.3, {"gamma_limit_deg": 2.0, "zoom_deg": 2.0, "step_deg": 0.25}),
]


def _tolerance_argv(angle_deg: float, opts: dict) -> list[str]:
    argv = ["tolerance-angle", "puma6", *_lock_args(2, angle_deg), "--q-target-deg", *map(str, Q_TARGET)]
    for key, value in opts.items():
        argv += [f"--{key.replace('_', '-')}", repr(value)]
    return argv


@pytest.mark.parametrize("angle_deg, opts", TOLERANCE_CASES, ids=["roots", "no-root", "zoom-is-limit"])
def test_tolerance_angle_equals_the_command(capsys, puma, angle_deg, opts):
    result = find_tolerance_angle(puma, 2, math.radians(angle_deg), Q_TARGET, **opts)
    _same_as_cli(capsys, result, _tolerance_argv(angle_deg, opts))
    assert result.to_dict()["q_target_deg"] == Q_TARGET  # echoed as given
    assert (result.chosen is None) == (angle_deg == 10.0)


def test_tolerance_angle_defaults_are_the_commands(puma):
    result = find_tolerance_angle(puma, 2, math.radians(59.4), Q_TARGET)
    assert (result.gamma_limit_deg, result.zoom_deg, result.step_deg) == (180.0, 2.0, 0.1)
    assert result.chosen.gamma == pytest.approx(math.radians(-1.46574), abs=1e-6)


def test_tolerance_angle_checks_its_parameters(puma):
    with pytest.raises(jl.ScenarioError, match="step_deg 1e-07 gives 3600000001 gamma samples"):
        find_tolerance_angle(puma, 2, 1.0, Q_TARGET, step_deg=1e-7)
    with pytest.raises(jl.ScenarioError, match=r"zoom_deg must be in \(0, 180\]"):
        find_tolerance_angle(puma, 2, 1.0, Q_TARGET, zoom_deg=0.0)
    with pytest.raises(jl.ScenarioError, match="q_target_deg needs 6 values"):
        find_tolerance_angle(puma, 2, 1.0, Q_TARGET[:5])
    with pytest.raises(jl.ScenarioError, match="joint must be 1..6"):
        find_tolerance_angle(puma, 7, 1.0, Q_TARGET)


def test_tolerance_angle_writes_the_commands_files(tmp_path, puma):
    result = find_tolerance_angle(puma, 2, math.radians(59.4), Q_TARGET, step_deg=2.0)
    files = result.write(tmp_path)
    assert files == list(TOLERANCE_FILES)
    sweep = json.loads((tmp_path / "sweep.json").read_text())
    assert {k: v for k, v in sweep.items() if k not in ("gamma_deg", "q_deg")} == to_plain(result.to_dict())
    assert np.array(sweep["q_deg"]).shape == (len(result.sweep.gammas), 6)
    assert all(
        (tmp_path / n).read_bytes().startswith(b"\x89PNG") for n in TOLERANCE_FILES if n.endswith(".png")
    )


# -- replan ----------------------------------------------------------------------------------------

REPLAN_CASES = [
    # (lock angle [deg], options)
    (60.0, {"steps": 6}),
    (52.0547, {"steps": 6, "tolerance_deg": 10.3, "method": "pointwise"}),
    (52.0547, {"steps": 5, "tolerance_deg": 10.0, "step_weight": 0.1, "cycle": 0.3, "jump_deg": 3.0}),
]


def _replan_argv(angle_deg: float, opts: dict) -> list[str]:
    argv = ["replan", "puma6", *_lock_args(2, angle_deg), "--from-deg", *map(str, Q_FROM)]
    argv += ["--to-deg", *map(str, Q_TO)]
    for key, value in opts.items():
        argv += [f"--{key.replace('_', '-')}", value if isinstance(value, str) else repr(value)]
    return argv


def _replan(puma, angle_deg: float, opts: dict) -> ReplanJobResult:
    opts = dict(opts)
    jump = opts.pop("jump_deg", None)
    return plan_replan(
        puma,
        2,
        math.radians(angle_deg),
        np.radians(Q_FROM),
        np.radians(Q_TO),
        jump_threshold=None if jump is None else math.radians(jump),
        **opts,
    )


@pytest.mark.parametrize("angle_deg, opts", REPLAN_CASES, ids=["continuous", "pointwise", "jump-threshold"])
def test_replan_equals_the_command(capsys, puma, angle_deg, opts):
    result = _replan(puma, angle_deg, opts)
    _same_as_cli(capsys, result, _replan_argv(angle_deg, opts))
    assert result.plan.method == opts.get("method", "continuous")


def test_replan_reports_jumps_in_its_summary(puma):
    result = _replan(puma, *REPLAN_CASES[1])
    assert result.plan.jumps and any(line.startswith("  JUMP: joint") for line in result.summary())


def test_replan_checks_its_parameters(puma):
    q_from, q_to = np.radians(Q_FROM), np.radians(Q_TO)
    with pytest.raises(jl.ScenarioError, match="steps must be an integer >= 1"):
        plan_replan(puma, 2, 1.0, q_from, q_to, steps=0)
    with pytest.raises(jl.ScenarioError, match="tolerance_deg must be in"):
        plan_replan(puma, 2, 1.0, q_from, q_to, tolerance_deg=200.0)
    with pytest.raises(jl.ScenarioError, match="q_to needs 6 finite values"):
        plan_replan(puma, 2, 1.0, q_from, q_to[:5])
    with pytest.raises(jl.ScenarioError, match="cycle must be"):
        plan_replan(puma, 2, 1.0, q_from, q_to, cycle=math.inf)


def test_replan_writes_the_commands_files(tmp_path, puma):
    result = _replan(puma, 60.0, {"steps": 3})
    assert result.write(tmp_path) == list(REPLAN_FILES)
    assert json.loads((tmp_path / "plan.json").read_text()) == to_plain(result.to_dict())
    csv = (tmp_path / "trajectory.csv").read_text().splitlines()
    assert csv[0].startswith("time_s,q1_deg,") and len(csv) == 1 + result.plan.times.size


# -- workspace -------------------------------------------------------------------------------------

WORKSPACE_CASES = [
    # (robot, lock or None, samples, voxel, seed)
    ("puma6", (2, 59.4), 2000, None, 3),
    ("halt7", None, 2000, None, 0),
    ("puma6", (2, 60.0), 2000, 0.6, 1),
]


def _workspace_argv(robot, lk, samples, voxel, seed) -> list[str]:
    argv = ["workspace", robot, "--samples", str(samples), "--seed", str(seed)]
    argv += [] if lk is None else _lock_args(*lk)
    return argv + ([] if voxel is None else ["--voxel", repr(voxel)])


def _workspace(robot, lk, samples, voxel, seed) -> WorkspaceStudy:
    locked = None if lk is None else (lk[0], math.radians(lk[1]))
    return study_workspace(jl.load_robot(robot), locked, samples=samples, voxel=voxel, rng=seed)


@pytest.mark.parametrize("case", WORKSPACE_CASES, ids=["locked", "full-only", "given-voxel"])
def test_workspace_equals_the_command(capsys, case):
    result = _workspace(*case)
    _same_as_cli(capsys, result, _workspace_argv(*case))
    _, err = _cli(capsys, _workspace_argv(*case))
    assert err == [f"jointlock workspace: warning: {w}" for w in result.warnings()]
    assert result.seed == case[-1] and result.locked == (case[1] is not None)


def test_workspace_seed_is_recorded():
    model = jl.load_robot("puma6")
    fresh = study_workspace(model, samples=1000, rng=None)
    assert isinstance(fresh.seed, int)
    again = study_workspace(model, samples=1000, rng=fresh.seed)
    assert np.array_equal(again.full_points, fresh.full_points)
    from_gen = study_workspace(model, samples=1000, rng=np.random.default_rng(4))
    assert from_gen.seed is None and from_gen.to_dict()["seed"] is None
    assert np.array_equal(from_gen.full_points, study_workspace(model, samples=1000, rng=4).full_points)


def test_workspace_refuses_a_voxel_too_small():
    model = jl.load_robot("puma6")
    with pytest.raises(VoxelTooSmallError, match="voxel 0.001 m is too small for 2000 samples") as info:
        study_workspace(model, (2, 1.0), samples=2000, voxel=0.001)
    err = pickle.loads(pickle.dumps(info.value))
    assert str(err) == str(info.value) and err.message("--voxel").startswith("--voxel 0.001 m")
    with pytest.raises(jl.ScenarioError, match="samples must be an integer >= 1000"):
        study_workspace(model, samples=10)


def test_workspace_writes_the_commands_files(capsys, tmp_path):
    case = WORKSPACE_CASES[0]
    result = _workspace(*case)
    files = result.write(tmp_path / "lib")
    assert files == list(WORKSPACE_FILES)
    out = _cli_json(capsys, [*_workspace_argv(*case), "--out", str(tmp_path / "cli")])
    assert out.pop("files") == [str(tmp_path / "cli" / name) for name in WORKSPACE_FILES]
    assert json.loads((tmp_path / "lib" / "workspace.json").read_text()) == to_plain(result.to_dict()) == out
    with np.load(tmp_path / "lib" / "points.npz") as z:
        assert np.array_equal(z["full"], result.full_points) and np.array_equal(
            z["locked"], result.locked_points
        )
    for name in files:
        assert (tmp_path / "lib" / name).read_bytes() == (tmp_path / "cli" / name).read_bytes()


# -- every result: pickle, scenario ----------------------------------------------------------------


def test_results_pickle(puma):
    results = [
        find_tolerance_angle(puma, 2, math.radians(59.4), Q_TARGET, step_deg=1.0),
        _replan(puma, *REPLAN_CASES[1]),
        _workspace(*WORKSPACE_CASES[0]),
        _workspace(*WORKSPACE_CASES[1]),
    ]
    for r in results:
        back = pickle.loads(pickle.dumps(r))
        assert type(back) is type(r)
        assert to_plain(back.to_dict()) == to_plain(r.to_dict()) and back.summary() == r.summary()
    assert [type(r).job for r in results] == ["tolerance_angle", "replan", "workspace", "workspace"]
    assert isinstance(results[0], ToleranceAngleResult)


@pytest.mark.parametrize(
    "job, runner",
    [
        ("tolerance_angle", tolerance_angle_from_scenario),
        ("replan", replan_from_scenario),
        ("workspace", workspace_from_scenario),
    ],
)
def test_from_scenario_equals_the_runs_command(tmp_path, job, runner):
    from equivalent_commands import JOB_MODULE, call_subcommand, job_argv

    from jointlock.scenario import load_scenario

    overrides = {"workspace.samples": 4000, "replan.steps": 10, "tolerance_angle.step_deg": 0.5}
    scenario = load_scenario(EXAMPLES / "replan_002.toml", overrides)
    result = runner(scenario.data, {})
    argv = job_argv(job, scenario, tmp_path, {}, quiet=True)
    at = argv.index("--out")
    assert argv[at + 1] == str(tmp_path / job)
    del argv[at : at + 2]  # the files are checked above (test_*_writes_the_commands_files)
    expected, code = call_subcommand(JOB_MODULE[job], argv)
    assert code == 0
    assert to_plain(result.to_dict()) == expected


def test_from_scenario_without_a_lock_runs_the_full_workspace(tmp_path):
    from jointlock.scenario import scenario_from_dict

    scenario = scenario_from_dict({"robot": "puma6", "seed": 2, "workspace": {"samples": 1000}})
    result = workspace_from_scenario(scenario.data, {})
    assert not result.locked and result.seed == 2 and result.to_dict()["lock"] is None


# -- plots -----------------------------------------------------------------------------------------


def test_plot_functions_make_their_own_axes_and_keep_the_backend(puma):
    import matplotlib
    import matplotlib.pyplot as plt
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

    from jointlock.plots.replan import (
        plot_replan_errors,
        plot_replan_joints,
        plot_replan_pose,
        plot_replan_velocity,
    )
    from jointlock.plots.tolerance_angle import plot_joints_vs_gamma, plot_locked_joint_vs_gamma
    from jointlock.plots.workspace import (
        plot_workspace_cloud,
        plot_workspace_clouds,
        plot_workspace_projection,
        plot_workspace_projections,
    )

    backend = matplotlib.get_backend()
    ta = find_tolerance_angle(puma, 2, math.radians(59.4), Q_TARGET, step_deg=2.0)
    rp = _replan(puma, 60.0, {"steps": 3}).plan
    ws = _workspace("puma6", (2, 59.4), 1000, None, 0)
    drawn = [
        plot_joints_vs_gamma(ta.sweep, ta.joint, ta.angle, ta.roots),
        plot_joints_vs_gamma(ta.sweep, ta.joint, ta.angle, ta.roots, window_deg=2.0),
        plot_locked_joint_vs_gamma(ta.sweep, ta.joint, ta.angle),
        plot_replan_joints(rp),
        plot_replan_pose(rp),
        plot_replan_errors(rp),
        plot_replan_velocity(rp),
        plot_workspace_projection(ws.full_points, ws.locked_points, plane="xz"),
        plot_workspace_projections(ws.full_points, ws.locked_points),
        plot_workspace_cloud(ws.full_points),
        plot_workspace_clouds(ws.full_points, ws.locked_points),
        plot_workspace_clouds(ws.full_points),
    ]
    try:
        kinds = [type(d) for d in drawn]
        assert all(isinstance(d, (Axes, Figure)) for d in drawn), kinds
        assert [isinstance(d, Figure) for d in drawn] == [1, 1, 0, 0, 1, 1, 1, 0, 1, 0, 1, 1]
        assert len(drawn[0].axes) == 6 and len(drawn[-2].axes) == 2 and len(drawn[-1].axes) == 1
        assert matplotlib.get_backend() == backend
    finally:
        for d in drawn:
            plt.close(d if isinstance(d, Figure) else d.figure)
    # an axis given is drawn on, and returned
    fig, ax = plt.subplots()
    assert plot_locked_joint_vs_gamma(ta.sweep, 2, ta.angle, ax=ax) is ax and ax.lines
    plt.close(fig)
