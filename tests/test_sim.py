"""Motions replayed in MuJoCo (issue 30, :mod:`jointlock.sim`): 000's halt played with the
spacecraft free ends with MuJoCo's attitude, drift and brake torque on jointlock's; played with
the spacecraft held, the brake torque is :meth:`HaltPlan.actuator_loads`'s.  MuJoCo integrates
its own dynamics (composite rigid bodies, a constraint solver, RK4): agreement checks the model
transfer, the inverse dynamics, the zero-momentum spacecraft and the brake torque at once."""

from __future__ import annotations

import json
import sys

import numpy as np
import pytest

import jointlock as jl
from jointlock.cli import main
from jointlock.errors import ConfigurationError

mujoco = pytest.importorskip("mujoco")

from jointlock.sim import MUJOCO_MISSING, replay_halt, replay_jobs, replay_motion  # noqa: E402

#: Stated tolerances of the replay of 000's halt (1 ms RK4 steps; measured on MuJoCo 4.0.1:
#: attitude 3.8e-6 deg apart, drift 3.5e-9 m, free brake peak 2.5e-5 N m of 272.6 N m, held
#: brake peak 5.5e-4 N m of 2220.5 N m, tracking 1e-4 deg).
ATTITUDE_TOL_DEG = 1e-3
DRIFT_TOL_M = 1e-6
BRAKE_RTOL = 1e-5
#: ... sample by sample, of the peak: the soft joint equality settles in the first steps (measured
#: 4.1e-3 N m at t = 0 of the free replay's 272.6 N m peak, 1.5e-5).
BRAKE_SERIES_RTOL = 5e-5
TRACKING_TOL_DEG = 1e-3


@pytest.fixture(scope="module")
def plan_000():
    """The demo's halt: 000 §5's failure on halt7, the spacecraft free in the model, 000's torques
    with it held."""
    return jl.plan_halt("halt7", progress=False)


def test_halt_000_replayed_with_the_spacecraft_free(plan_000):
    replay = replay_halt(plan_000)
    ref = plan_000.spacecraft_response()  # jointlock's own figure, on its own grid
    assert replay.spacecraft == "free" and replay.reference is not None
    assert replay.attitude_difference_deg < ATTITUDE_TOL_DEG
    assert abs(replay.attitude_change_deg - ref.final_attitude_change_deg) < ATTITUDE_TOL_DEG
    assert np.linalg.norm(replay.com_displacement[-1] - replay.reference.com_displacement[-1]) < DRIFT_TOL_M
    # the plan's own figure integrates on a coarser grid (its 10 ms step): 1.7e-6 m apart
    assert np.linalg.norm(replay.com_displacement[-1] - ref.com_displacement[-1]) < 10 * DRIFT_TOL_M
    assert replay.tracking_error_deg < TRACKING_TOL_DEG
    # the brake torque with the spacecraft free, sample by sample
    scale = np.abs(replay.brake_ref).max()
    assert np.abs(replay.brake - replay.brake_ref).max() < BRAKE_SERIES_RTOL * scale
    assert np.abs(replay.brake).max() == pytest.approx(scale, rel=BRAKE_RTOL)
    rows = {r["quantity"]: r for r in replay.rows()}
    assert rows["spacecraft attitude change at the end"]["jointlock"] == pytest.approx(
        replay.reference.final_attitude_change_deg, abs=1e-12
    )
    json.dumps(replay.to_dict(), allow_nan=False)


def test_halt_000_replayed_with_the_spacecraft_held_gives_000s_brake_torque(plan_000):
    replay = replay_halt(plan_000, base="fixed")
    loads = plan_000.actuator_loads()  # 000's reading: the spacecraft held
    assert replay.spacecraft == "held" and replay.attitude is None
    assert np.abs(replay.brake).max() == pytest.approx(loads.peak_brake[0], rel=BRAKE_RTOL)
    # on the constraint grid's times (every step of the replay is on them when T / step divides)
    at = np.searchsorted(replay.t, loads.t)
    np.testing.assert_allclose(replay.t[at], loads.t, atol=1e-12)
    np.testing.assert_allclose(replay.brake[at, 0], loads.brake[:, 0], atol=BRAKE_SERIES_RTOL * loads.peak_brake[0])
    assert [r["short"] for r in replay.rows() if r["short"]] == ["brake 4 peak"]


def test_replay_jobs_plays_000s_halt_free_and_held(plan_000):
    replays = replay_jobs({"halt": plan_000})
    assert set(replays) == {"halt", "halt_held"}
    free_only = jl.plan_halt("halt7", base="floating", progress=False)
    assert set(replay_jobs({"halt": free_only})) == {"halt"}  # torques already with the spacecraft free


def test_an_inconsistent_motion_is_seen(plan_000):
    """A test that can fail: rates 10 % off the angles' own derivative (jointlock's figures from
    the wrong rates, MuJoCo's from the motion the joints really make) disagree by degrees.
    (The same path run faster would not do: with zero momentum the attitude change depends on
    the path only, not on how fast it is followed; MuJoCo agrees to 1e-8 deg.)"""
    problem = plan_000.problem

    def inconsistent(t):
        q, dq, ddq = plan_000.motion.trajectory(t)
        return q, 1.1 * dq, ddq

    bad = replay_motion(problem.model, inconsistent, problem.T)
    assert bad.attitude_difference_deg > 1.0
    brake = next(r for r in bad.rows() if r["short"] == "brake 4 peak")
    assert abs(brake["difference"]) > 1.0


def test_bad_inputs_are_one_line(plan_000, monkeypatch):
    problem = plan_000.problem
    with pytest.raises(ConfigurationError, match="duration"):
        replay_motion(problem.model, plan_000.motion.trajectory, -1.0)
    with pytest.raises(ConfigurationError, match="timestep"):
        replay_motion(problem.model, plan_000.motion.trajectory, 1.0, timestep=2.0)
    fixed = jl.lock(jl.load_robot("puma6"), 2, 0.3)
    with pytest.raises(ConfigurationError, match="base"):
        replay_motion(fixed, lambda t: (np.zeros((t.size, 5)),) * 3, 1.0, base="floating")
    monkeypatch.setitem(sys.modules, "mujoco", None)  # as if the extra were not installed
    with pytest.raises(ConfigurationError) as info:
        replay_halt(plan_000)
    assert str(info.value) == MUJOCO_MISSING and "jointlock[mujoco]" in MUJOCO_MISSING


def test_an_unstable_replay_is_one_error_and_no_log_file(plan_000, tmp_path, monkeypatch):
    """50 ms steps are too coarse for the stiff brake: one ModelError naming the step, MuJoCo's
    warning in it, and no MUJOCO_LOG.TXT left in the working folder."""
    from jointlock.errors import ModelError

    monkeypatch.chdir(tmp_path)
    with pytest.raises(ModelError, match=r"unstable .*smaller timestep than 0.05 s"):
        replay_halt(plan_000, timestep=0.05)
    assert not list(tmp_path.iterdir())


def test_fixed_base_arm_without_spacecraft(rng):
    """puma6 on a fixed base, joint 3 locked, a smooth motion of the others: no spacecraft rows,
    the brake torque MuJoCo's and jointlock's."""
    model = jl.lock(jl.load_robot("puma6"), 3, 0.4)
    q0, q1 = rng.uniform(-0.5, 0.5, (2, model.dof))

    def smooth(t):
        s = t / 2.0
        h, dh, ddh = 10 * s**3 - 15 * s**4 + 6 * s**5, (30 * s**2 - 60 * s**3 + 30 * s**4) / 2.0, (60 * s - 180 * s**2 + 120 * s**3) / 4.0
        return q0 + np.outer(h, q1 - q0), np.outer(dh, q1 - q0), np.outer(ddh, q1 - q0)

    replay = replay_motion(model, smooth, 2.0, label="quintic")
    assert replay.reference is None and replay.attitude_change_deg is None
    assert np.abs(replay.brake - replay.brake_ref).max() < BRAKE_SERIES_RTOL * np.abs(replay.brake_ref).max()
    assert [r["short"] for r in replay.rows() if r["short"]] == ["brake 3 peak"]


def test_cli_halt_check_in_mujoco(tmp_path, capsys):
    assert main(["halt", "halt7", "--check-in", "mujoco", "--quiet", "--json", "--out", str(tmp_path)]) == 0
    data = json.loads(capsys.readouterr().out)
    checked = data["checked_in_mujoco"]
    assert set(checked) == {"halt", "halt_held"}
    attitude = next(r for r in checked["halt"]["rows"] if r["short"] == "attitude change")
    assert abs(attitude["difference"]) < ATTITUDE_TOL_DEG
    for name in ("mujoco.png", "mujoco.csv", "mujoco.json", "mujoco_held.png"):
        assert (tmp_path / name).is_file()


def test_run_check_in_mujoco_writes_the_table_and_the_figure(tmp_path):
    from jointlock.run._summary import summary_lines

    scenario = jl.load_scenario("examples/halt_000.toml", {"jobs": ["halt_config", "halt"], "check_in": "mujoco"})
    result = jl.run_scenario(scenario)
    assert set(result.checks) == {"halt", "halt_held"}
    written = result.write(tmp_path)
    assert "checks/mujoco_halt.png" in written["files"] and written["checks"]["halt"]["spacecraft"] == "free"
    page = (tmp_path / "report.html").read_text()
    assert "Checked in MuJoCo" in page and "spacecraft attitude change at the end" in page
    assert any(line.startswith("  checked in MuJoCo") for line in summary_lines(written))
    # without the flag nothing is replayed and results.json has no "checks"
    plain = jl.run_scenario(jl.load_scenario("examples/halt_000.toml", {"jobs": ["halt_config"]}))
    assert plain.checks == {} and "checks" not in plain.to_dict()


# -- the jump study's runs and the re-plan ---------------------------------------------------------


@pytest.fixture(scope="module")
def floating_jump():
    """001's task on the free-floating canadarm7, joint 2 locking at 6 s; the limits relaxed so
    that kappa(t) can be fitted (with 001's limits the floating arm breaks them without a
    failure: tests/test_jobs_jump.py)."""
    scenario = jl.load_scenario(
        "examples/jump_001.toml",
        {"jobs": ["jump"], "base": "floating", "limits.vmax_deg_s": 60.0, "limits.amax_deg_s2": 60.0,
         "limits.eps_m": 0.01, "jump.sweep": 8},
    )  # fmt: skip
    return jl.run_scenario(scenario)["jump"]


def test_jump_runs_replayed_with_the_spacecraft_free(floating_jump):
    """The rates change at every 50 ms control step and jump at the lock: MuJoCo's spacecraft
    takes each step as a momentum-keeping impulse computed from its own mass matrix.  Measured:
    attitude 2.4e-6 deg apart (26.74 deg turned), drift 7e-9 m, brake peak 5.8e-5 N m of 1.62."""
    from jointlock.sim import replay_jump

    replays = replay_jump(floating_jump)
    assert set(replays) == {"jump_uncompensated", "jump_compensated"}
    own = floating_jump.spacecraft_responses()
    for key, replay in replays.items():
        assert replay.attitude_difference_deg < ATTITUDE_TOL_DEG, key
        assert np.linalg.norm(replay.com_displacement[-1] - replay.reference.com_displacement[-1]) < DRIFT_TOL_M
        assert np.abs(replay.brake).max() == pytest.approx(np.abs(replay.brake_ref).max(), rel=1e-4)
        assert replay.tracking_error_deg < TRACKING_TOL_DEG and replay.locked_numbers == (2,)
        # the study's own figure integrates the attitude at the 50 ms control step (first order):
        # 0.17 % off the fine one, which MuJoCo confirms
        ref = replay.reference.final_attitude_change_deg
        mine = own[key.removeprefix("jump_")].final_attitude_change_deg
        assert 0 < abs(mine - ref) < 0.005 * ref


def test_replan_replayed(tmp_path):
    """002's re-plan (puma6, joint 2 locked at 59.4 deg) on a free spacecraft: the waypoints joined
    by a cubic spline; fixed base (the example's), only the brake."""
    from jointlock.sim import replay_replan

    floating = jl.run_scenario(jl.load_scenario("examples/replan_002.toml", {"jobs": ["replan"], "base": "floating"}))
    replay = replay_replan(floating["replan"])
    assert replay.attitude_difference_deg < ATTITUDE_TOL_DEG and replay.reference is not None
    own = floating["replan"].spacecraft_response()  # central differences on the waypoints
    assert abs(replay.reference.final_attitude_change_deg - own.final_attitude_change_deg) < 1e-3
    assert np.abs(replay.brake).max() == pytest.approx(np.abs(replay.brake_ref).max(), rel=1e-4)
    fixed = jl.run_scenario(jl.load_scenario("examples/replan_002.toml", {"jobs": ["replan"], "check_in": "mujoco"}))
    assert set(fixed.checks) == {"replan"} and fixed.checks["replan"].spacecraft == "held"


def test_the_replay_ends_at_the_motions_end_and_a_refused_model_is_one_line(plan_000):
    """A step that does not divide T: the replay takes the next smaller one that does (the review:
    1.5 ms ran to 10.0005 s, past the halt polynomial); a massless arm loads (MuJoCo's floors)."""
    replay = replay_halt(plan_000, timestep=0.0015)
    assert replay.t[-1] == pytest.approx(plan_000.problem.T, abs=1e-12) and replay.timestep <= 0.0015
    assert replay.attitude_difference_deg < ATTITUDE_TOL_DEG
    with pytest.raises(ConfigurationError, match="timestep"):
        replay_halt(plan_000, timestep=True)
    # a massless arm (MuJoCo's floors: 1e-9 kg) replays, its brake holding nothing
    massless = jl.lock(jl.from_dh("m", a=[0.0, 1.0], alpha=[0.0, 0.0], d=[0.0, 0.0], convention="standard",
                                  bodies=[jl.Body(0.0), jl.Body(0.0)]), 1, 0.0)  # fmt: skip
    still = replay_motion(massless, lambda t: (np.zeros((t.size, 1)),) * 3, 1.0)
    assert np.abs(still.brake).max() < 1e-6


def test_the_attitude_plot_carries_mujocos_trace(plan_000, tmp_path):
    """Issue 30: the halt's attitude figure with MuJoCo's attitude and rate dashed on top."""
    from jointlock.plots._common import offscreen_figure
    from jointlock.plots.halt import plot_spacecraft_response
    from jointlock.sim import write_attitude_with_replay

    replay = replay_halt(plan_000)
    fig = plot_spacecraft_response(plan_000.spacecraft_response(), fig=offscreen_figure(), simulated=replay.simulated_response())
    labels = [line.get_label() for ax in fig.axes for line in ax.get_lines()]
    assert "MuJoCo: attitude change" in labels and "MuJoCo: rate" in labels
    write_attitude_with_replay(plan_000, replay, tmp_path)
    assert (tmp_path / "spacecraft_attitude.png").is_file() and (tmp_path / "spacecraft_attitude.svg").is_file()
    held = replay_halt(plan_000, base="fixed")
    assert held.simulated_response() is None
