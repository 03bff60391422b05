"""The interactive 3-D view (issue 16, item 1) and the motions it reads (item 7): what is drawn
on each frame is where the arm, its locked joint and the spacecraft are."""

from __future__ import annotations

import json

import numpy as np
import pytest

import jointlock as jl
from jointlock.errors import ConfigurationError
from jointlock.jobs.halt import plan_halt
from jointlock.jobs.jump import run_jump_study
from jointlock.kinematics import com_positions, ee_pose
from jointlock.planning.jump import JumpScenario
from jointlock.plots.animation import animation_figure, animation_html, standalone_html
from jointlock.plots.motion import ArmMotion, frame_times, motion_points, spacecraft_box


def _frame_xyz(trace: dict) -> np.ndarray:
    return np.array([[np.nan if v is None else v for v in trace[a]] for a in "xyz"], dtype=float).T


@pytest.fixture(scope="module")
def floating_jump():
    arm = jl.load_robot("canadarm7", base="floating")
    task = JumpScenario(base="floating", dx=(0.3, -0.3, 0.2))
    return run_jump_study(arm, task, fail_at=6.0, kappa=0.0)


def test_a_motion_round_trips_through_its_json():
    t = np.linspace(0, 1, 5)
    q = np.outer(t, np.arange(1, 7)) * 0.1
    att = np.tile([1.0, 0, 0, 0], (5, 1))
    m = ArmMotion("a", t, q, ((2, 0.5),), np.zeros((5, 3)), att, target=np.ones((5, 3)), target_label="goal")
    back = ArmMotion.from_dict(json.loads(json.dumps(m.to_dict())))
    assert back.to_dict() == m.to_dict()
    np.testing.assert_allclose(back.q, q, atol=1e-12)
    assert back.locks == ((2, 0.5),) and back.moving_base and back.target_label == "goal"


@pytest.mark.parametrize(
    "kwargs, field",
    [
        ({"t": [0, 1], "q": np.zeros((3, 6))}, "q"),
        ({"t": [1, 0], "q": np.zeros((2, 6))}, "t"),
        ({"t": [0, 1], "q": np.zeros((2, 6)), "base_position": np.zeros((2, 3))}, "together"),
        ({"t": [0, 1], "q": np.full((2, 6), np.nan)}, "finite"),
        ({"t": [0, 1], "q": None}, "q is required"),
        ({"t": "ab", "q": np.zeros((2, 6))}, "must be numbers"),
        ({"t": [0, 1], "q": np.zeros((2, 6)), "locks": [3]}, "pairs"),
        ({"t": [0, 1], "q": np.zeros((2, 6)), "base_position": np.zeros((2, 3)), "base_attitude": np.zeros((2, 4))}, "unit quaternions"),
    ],
)
def test_a_bad_motion_is_refused_naming_what(kwargs, field):
    with pytest.raises(ConfigurationError, match=field):
        ArmMotion("bad", **kwargs)


def test_frames_include_the_failure_instant():
    t = np.linspace(0.0, 10.0, 1001)
    m = ArmMotion("x", t, np.zeros((t.size, 6)), ((3, 4.2371),))
    times = frame_times([m], 50)
    assert times.size == 51 and 4.2371 in times and times[0] == 0.0 and times[-1] == 10.0


def test_fixed_base_points_are_the_forward_kinematics():
    arm = jl.load_robot("puma6")
    rng = np.random.default_rng(3)
    q = rng.uniform(-1, 1, (7, 6))
    m = ArmMotion("x", np.arange(7.0), q)
    pts = motion_points(arm, m, m.t)
    np.testing.assert_allclose(pts["ee"], ee_pose(arm, q)[:, :3, 3], atol=1e-12)
    np.testing.assert_allclose(pts["coms"], com_positions(arm, q), atol=1e-12)
    assert np.all(pts["base"] == 0)


def test_floating_frames_keep_the_system_centre_of_mass(floating_jump):
    """Drawn link centres of mass and the spacecraft's (root pose from the spacecraft response)
    weighted by mass: the system's centre of mass stays put, as momentum conservation says."""
    model, motions = floating_jump.arm_motions()
    m = motions[1]
    assert m.moving_base
    pts = motion_points(model, m, m.t)
    sc = model.root_body
    sc_com = pts["base"] + np.einsum("fij,j->fi", pts["base_rotation"], sc.com)
    total = sc.mass + model.masses.sum()
    system = (sc.mass * sc_com + np.einsum("n,fni->fi", model.masses, pts["coms"])) / total
    drift = np.linalg.norm(system - system[0], axis=-1).max()
    assert drift < 1e-4, drift
    # the spacecraft really moves in this motion (the check is not vacuous)
    assert np.linalg.norm(pts["base"][-1] - pts["base"][0]) > 1e-3


def test_floating_end_effector_is_where_the_jump_integrator_put_it(floating_jump):
    model, motions = floating_jump.arm_motions()
    _, run, _ = floating_jump.runs()
    m = motions[1]
    pts = motion_points(model, m, m.t)
    k = np.searchsorted(run.t, m.t)
    assert np.abs(pts["ee"] - run.x[k]).max() < 1e-4  # trapezoidal drift vs the integrator's exact CoM


def test_the_locked_joint_is_marked_from_its_lock_on(floating_jump):
    model, motions = floating_jump.arm_motions()
    fig = animation_figure(model, motions, max_frames=40)
    names = [d.get("name") for d in fig["data"]]
    marker = names.index("locked joint")
    t_fail = motions[0].locks[0][1]
    times = frame_times(motions, 40)
    assert t_fail in times
    j = model.index_of(2)
    for f, frame in enumerate(fig["frames"]):
        slot = fig["frames"][f]["traces"].index(marker)
        pts = _frame_xyz(frame["data"][slot])
        if times[f] < t_fail:
            assert pts.shape[0] == 0 and "healthy" in frame["layout"]["title"]["text"]
        else:
            expected = motion_points(model, motions[0], times[f : f + 1])["joints"][0, j]
            np.testing.assert_allclose(pts[0], expected, atol=1e-5)
            assert "joint 2 locked" in frame["layout"]["title"]["text"]
    json.dumps(fig, allow_nan=False)  # plain JSON, no NaN


@pytest.mark.parametrize("base", ["fixed", "floating"])
def test_halt_motion_holds_the_locked_joint(base):
    """000's failure (halt7, joint 4 locked at 0 deg): joint 4 stays at 0 and is marked from
    the start; the halt ends at rest at the halt configuration; the spacecraft is held for
    000's fixed-base torque and moves when the base is free."""
    plan = plan_halt(
        "halt7",
        base=base,
        search=jl.HaltSearch(samples=500),
        motion=jl.HaltMotionSettings(n_samples=101),
    )
    model, (m,) = plan.arm_motions()
    assert model.dof == 7 and m.locks == ((4, 0.0),) and m.moving_base == (base == "floating")
    assert np.all(m.q[:, 3] == 0.0)
    np.testing.assert_allclose(m.q[-1, [0, 1, 2, 4, 5, 6]], plan.problem.qf, atol=1e-9)
    fig = animation_figure(model, m)
    wanted = "spacecraft" if base == "floating" else "spacecraft (held)"
    assert any(d.get("name") == wanted for d in fig["data"])


def test_coincident_joints_are_numbered_together():
    arm = jl.load_robot("puma6")
    fig = animation_figure(arm, ArmMotion("x", [0.0, 1.0], np.zeros((2, 6))))
    labels = next(d for d in fig["data"] if d.get("name") == "joint numbers")["text"]
    assert labels[0] == "1,2" and labels[1] == ""  # 002's arm: joints 1 and 2 share an origin


def test_spacecraft_box_has_the_mass_and_inertia_of_the_spacecraft():
    arm = jl.load_robot("canadarm7", base="floating")
    box = spacecraft_box(arm)
    sides = np.ptp(box @ np.linalg.eigh(arm.root_body.inertia)[1], axis=0)
    a, b, c = sides
    m = arm.root_body.mass
    moments = m / 12 * np.array([b * b + c * c, a * a + c * c, a * a + b * b])
    np.testing.assert_allclose(moments, np.linalg.eigvalsh(arm.root_body.inertia), rtol=1e-9)
    assert spacecraft_box(jl.load_robot("puma6")) is None  # a massless mounting: no box


@pytest.mark.parametrize("label", ["</script><b>x", "<!--<script>", "x</SCRIPT >"])
def test_html_cannot_be_closed_by_a_label(label):
    """The figure's JSON inside <script> holds no "<" at all (no end tag, no comment opening)."""
    from jointlock.plots.animation import plotly_js

    fig = animation_figure(jl.load_robot("puma6"), ArmMotion(label, [0.0, 1.0], np.zeros((2, 6))))
    frag = animation_html(fig)
    script = frag.split("<script>", 1)[1].rsplit("</script>", 1)[0]
    assert "<" not in script and "\\u003c" in script
    assert json.loads(script.split("var fig=", 1)[1].split(";var gd=", 1)[0])["data"][0]["name"] == label
    page = standalone_html(fig)
    assert page.count("<script>") == 2 and "src=" not in page.split("</script>", 1)[1]
    assert "</script" not in plotly_js().lower()  # the vendored library cannot end its element


def test_the_same_figure_gets_the_same_view_id():
    fig = animation_figure(jl.load_robot("puma6"), ArmMotion("x", [0.0, 1.0], np.zeros((2, 6))))
    assert animation_html(fig) == animation_html(fig)  # reports are reproducible


def test_a_locked_model_takes_its_movable_joints_angles():
    """A locked model's motion may give only the movable joints: the lock angle is inserted and
    the joint marked from the start."""
    arm = jl.lock(jl.load_robot("halt7"), 4, 0.3)
    t = np.linspace(0.0, 1.0, 5)
    fig = animation_figure(arm, ArmMotion("m", t, np.zeros((5, 6))))
    marker = next(d for d in fig["data"] if d.get("name") == "locked joint")
    assert marker["text"] == ["joint 4 locked"]
    full = jl.load_robot("halt7")
    expected = motion_points(full, ArmMotion("m", t, arm.expand(np.zeros((5, 6)))), t[:1])["joints"][0, 3]
    np.testing.assert_allclose(_frame_xyz(marker)[0], expected, atol=1e-5)


@pytest.mark.parametrize(
    "motions, match",
    [
        ([], "one or more ArmMotion"),
        (["not a motion"], "one or more ArmMotion"),
        ([ArmMotion("x", [0.0, 1.0], np.zeros((2, 6)), ((9, 0.5),))], r"locks joints \[9\]"),
        ([ArmMotion("x", [0.0, 1.0], np.zeros((2, 7)))], "has 7 joint angles"),
    ],
)
def test_bad_figures_are_refused_in_one_line(motions, match):
    with pytest.raises(ConfigurationError, match=match):
        animation_figure(jl.load_robot("puma6"), motions)


def test_full_and_locked_workspace_clouds_share_their_axis_scales():
    """Issue 16, item 2: the two clouds compare by eye: same limits on every axis."""
    from jointlock.plots._common import offscreen_figure
    from jointlock.plots.workspace import plot_workspace_clouds

    rng = np.random.default_rng(0)
    full = rng.normal(size=(2000, 3)) * [1.0, 2.0, 0.5]
    locked = full[:500] * 0.3 + [0.5, 0.0, 0.0]
    fig = plot_workspace_clouds(full, locked, fig=offscreen_figure((11, 5)))
    a, b = fig.axes
    for get in ("get_xlim", "get_ylim", "get_zlim"):
        assert getattr(a, get)() == getattr(b, get)()
    spans = [np.ptp(getattr(a, g)()) for g in ("get_xlim", "get_ylim", "get_zlim")]
    np.testing.assert_allclose(spans, spans[0])  # equal in x, y and z
    assert spans[0] >= np.ptp(full[:, 1])  # the widest extent fits
