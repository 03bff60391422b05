"""A planned motion (issue 28, jointlock.planning.task): q, dq, ddq at any time, checked against
finite differences; waypoints with quintic and trapezoidal time scaling, samples joined by a
spline, task files (CSV, NPZ); bad files refused in one line naming the row."""

from __future__ import annotations

import math

import numpy as np
import pytest

import jointlock as jl
from jointlock.errors import ScenarioError
from jointlock.planning.task import Task, load_task_file

WAYPOINTS = [[0.0, 10.0, -20.0], [45.0, -30.0, 10.0], [30.0, 0.0, 60.0], [-10.0, 5.0, 0.0]]
DURATIONS = [2.0, 1.5, 3.0]


def _fd_check(task: Task, times: np.ndarray, h: float = 1e-6) -> None:
    q, dq, ddq = task.state(times)
    qp, dqp, _ = task.state(times + h)
    qm, dqm, _ = task.state(times - h)
    np.testing.assert_allclose(dq, (qp - qm) / (2 * h), atol=1e-7)
    np.testing.assert_allclose(ddq, (dqp - dqm) / (2 * h), atol=1e-5)


@pytest.mark.parametrize("scaling", ["quintic", "trapezoidal"])
def test_waypoint_tasks_pass_through_their_waypoints_at_rest(scaling):
    task = Task.from_waypoints(WAYPOINTS, DURATIONS, scaling)
    assert task.duration == pytest.approx(6.5) and task.dof == 3
    q, dq, _ = task.state(task.t)
    np.testing.assert_allclose(np.degrees(q), WAYPOINTS, atol=1e-12)
    np.testing.assert_allclose(dq, 0.0, atol=1e-12)  # rest at every waypoint
    # interior times, away from the trapezoid's ramp corners (its acceleration steps there)
    inner = np.concatenate([task.t[k] + (task.t[k + 1] - task.t[k]) * np.array([0.1, 0.2, 0.5, 0.8, 0.9])
                            for k in range(3)])  # fmt: skip
    _fd_check(task, inner)


def test_quintic_acceleration_is_zero_at_the_waypoints_and_the_trapezoid_peaks_as_stated():
    quintic = Task.from_waypoints(WAYPOINTS, DURATIONS, "quintic")
    np.testing.assert_allclose(quintic.state(quintic.t)[2], 0.0, atol=1e-12)
    trap = Task.from_waypoints([[0.0], [90.0]], [3.0], "trapezoidal")
    _, dq, ddq = trap.state(np.array([1.5, 0.5]))
    # cruise rate 1/(1 - 1/3) of the mean: 1.5 x 30 deg/s; acceleration 45 deg/s over 1 s
    assert math.degrees(dq[0, 0]) == pytest.approx(45.0) and math.degrees(ddq[1, 0]) == pytest.approx(45.0)


def test_sampled_task_is_a_twice_differentiable_spline():
    t = np.linspace(0.0, 4.0, 9)
    q = np.column_stack([30 * np.sin(t), 10 * t, 5 * np.cos(2 * t)])
    task = Task.from_samples(t, q)
    np.testing.assert_allclose(np.degrees(task.state(t)[0]), q, atol=1e-10)
    _fd_check(task, np.array([0.3, 1.7, 2.2, 3.9]))
    with pytest.raises(ScenarioError, match=r"runs over \[0, 4\] s"):
        task.state(4.5)


def test_task_files_csv_and_npz(tmp_path):
    csv = tmp_path / "plan.csv"
    csv.write_text("# a planned motion\nt_s, q1_deg, q2_deg\n0, 0, 0\n1, 10, 5\n2, 20, 5\n3, 25, 0\n")
    a = load_task_file(csv)
    np.savez(tmp_path / "plan.npz", t_s=[0, 1, 2, 3], q_deg=[[0, 0], [10, 5], [20, 5], [25, 0]])
    b = load_task_file(tmp_path / "plan.npz")
    np.testing.assert_allclose(a.state(1.3)[0], b.state(1.3)[0], atol=1e-15)
    assert a.kind == "samples" and a.source.endswith("plan.csv")


@pytest.mark.parametrize(
    "text, words",
    [
        ("t_s, q1_deg\n0, 0\n2, 5\n1, 9\n", "line 4: t = 1 s is not after the line before's 2 s"),
        ("t_s, q1_deg, q2_deg\n0, 0, 0\n1, 5\n", "line 3 has 2 columns; the header has 3"),
        ("t_s, q1_deg\n0, 0\n1, nan\n", "line 3, column q1_deg: not a finite number"),
        ("t_s, q1_deg\n0, 0\n1, abc\n", "line 3: 'abc' is not a number"),
        ("t_s, q1_deg\n0, 0\n", "a header row and 2 or more rows"),
    ],
)
def test_bad_task_files_are_one_line_naming_the_row(tmp_path, text, words):
    path = tmp_path / "bad.csv"
    path.write_text(text)
    with pytest.raises(ScenarioError) as info:
        load_task_file(path)
    message = str(info.value)
    assert "\n" not in message and message.startswith(str(path)) and words in message


def test_a_waypoint_outside_the_limits_is_refused_naming_it():
    arm = jl.load_robot("puma6")
    lo, hi = arm.angle_range()
    rows = [[0.0] * 6, [0.0] * 6]
    rows[1][2] = math.degrees(hi[2]) + 5.0
    task = Task.from_waypoints(rows, [1.0], source="plan.toml: [task]")
    with pytest.raises(ScenarioError, match=r"plan.toml: \[task\]: waypoint 2: joint 3 at .* is outside its limits"):
        task.check(arm)
    with pytest.raises(ScenarioError, match="3 joint angles per row; puma6 has 6 joints"):
        Task.from_waypoints(WAYPOINTS, DURATIONS).check(arm)
    with pytest.raises(ScenarioError, match=r"waypoint 2 has 2 angles; waypoint 1 has 3"):
        Task.from_waypoints([[0, 0, 0], [1, 2]], [1.0])
    with pytest.raises(ScenarioError, match=r"durations_s entry 2 .* must be a duration"):
        Task.from_waypoints(WAYPOINTS, [1.0, -1.0, 2.0])


# -- [task] in a scenario: the halt starts from the plan at t ---------------------------------------

PLAN = """
robot = "halt7"
base = "floating"
[failure]
joint = 4
time_s = {time}
[task]
waypoints_deg = [[-170, -170, -95, 0, 10, 10, 0], [-150, -140, -80, 0, 60, 50, 20], [-120, -100, -60, 0, 90, 70, 30]]
durations_s = [6.0, 6.0]
[halt]
T = 12.0
samples = 2000
qf_deg = [-120, -100, -60, 90, 70, 30]
"""


def _scenario(tmp_path, text):
    path = tmp_path / "plan.toml"
    path.write_text(text)
    return jl.load_scenario(path)


def test_the_halt_starts_from_the_tasks_state_at_the_failure(tmp_path):
    scenario = _scenario(tmp_path, PLAN.format(time=3.0))
    task = Task.from_waypoints(
        [[-170, -170, -95, 0, 10, 10, 0], [-150, -140, -80, 0, 60, 50, 20], [-120, -100, -60, 0, 90, 70, 30]],
        [6.0, 6.0],
    )
    q, dq, ddq = (np.degrees(v) for v in task.state(3.0))
    healthy = [0, 1, 2, 4, 5, 6]
    st = scenario.data["state"]
    np.testing.assert_allclose(st["q0_deg"], q[healthy], atol=1e-12)
    np.testing.assert_allclose(st["dq0_deg"], dq[healthy], atol=1e-12)
    assert scenario.data["failure"]["angle_deg"] == pytest.approx(q[3])
    plan = jl.run_scenario(scenario)["halt"]
    assert plan.state_source == "task at t = 3 s"
    np.testing.assert_allclose(np.degrees(plan.problem.dq0), dq[healthy], atol=1e-9)
    # the same halt from the state typed by hand
    typed = jl.plan_halt(
        plan.problem.model,
        jl.FailureState.from_degrees(plan.problem.model, q[healthy], dq[healthy], ddq[healthy]),
        T=12.0,
        qf=np.radians([-120, -100, -60, 90, 70, 30]),
        base="floating",
        search=jl.HaltSearch(samples=2000),
    )  # fmt: skip
    assert typed.motion.global_torque == pytest.approx(plan.motion.global_torque, rel=1e-12)


@pytest.mark.parametrize(
    "edit, words",
    [
        (lambda t: t + "[state]\nq0_deg = [0, 0, 0, 0, 0, 0]\n", "state.q0_deg and [task] with failure.time_s both give"),
        (lambda t: t.replace("time_s = 3.0", "time_s = 13.0"), "failure.time_s = 13 s is outside the task, [0, 12] s"),
        (lambda t: t.replace("time_s = 3.0", "time_s = 3.0\nangle_deg = 5.0"), "the task has joint 4 at 0 deg"),
        (lambda t: t.replace("durations_s = [6.0, 6.0]", "durations_s = [6.0]"), "durations_s needs one duration per segment"),
        (lambda t: t.replace("[-120, -100, -60, 0, 90, 70, 30]]", "[-120, -100, -60, 0, 90, 70, 300]]"), "waypoint 3: joint 7 at 300 deg is outside"),
        (lambda t: t.replace("time_s = 3.0\n", ""), "[task] needs failure.time_s"),
    ],
)
def test_task_scenarios_refuse_bad_input_in_one_line(tmp_path, edit, words):
    with pytest.raises(ScenarioError) as info:
        _scenario(tmp_path, edit(PLAN.format(time=3.0)))
    assert words in str(info.value) and "\n" not in str(info.value)


def test_a_task_file_relative_to_the_scenario(tmp_path):
    (tmp_path / "motion.csv").write_text(
        "t_s, q1, q2, q3, q4, q5, q6\n0, 0, 60, 0, 0, 0, 0\n2, 10, 60, 20, 5, -30, 40\n4, 5, 60, 35, 10, -120, 90\n"
    )
    text = 'robot = "puma6"\n[failure]\njoint = 2\ntime_s = 1.0\n[task]\nfile = "motion.csv"\n[replan]\nto_deg = [5, 60, 35, 10, -120, 90]\n'
    scenario = _scenario(tmp_path, text)
    assert scenario.data["failure"]["angle_deg"] == pytest.approx(60.0)
    task = load_task_file(tmp_path / "motion.csv")
    np.testing.assert_allclose(scenario.data["replan"]["from_deg"], np.degrees(task.state(1.0)[0]), atol=1e-12)


def test_review_fixes_file_times_header_continuous_joints_npz(tmp_path):
    """A file's times are kept (6 s into a file from 5 s is 1 s in); a CSV without a header is
    refused (it would lose its first row); a continuous joint takes any angle; a complex NPZ is
    refused."""
    csv = tmp_path / "late.csv"
    csv.write_text("t_s, q1\n5, 0\n6, 10\n7, 30\n")
    task = load_task_file(csv)
    assert (task.start, task.end, task.duration) == (5.0, 7.0, 2.0)
    assert math.degrees(task.state(6.0)[0][0]) == pytest.approx(10.0)
    with pytest.raises(ScenarioError, match=r"runs over \[5, 7\] s"):
        task.state(1.0)
    bare = tmp_path / "bare.csv"
    bare.write_text("0, 0\n1, 10\n2, 30\n")
    with pytest.raises(ScenarioError, match="line 1 is numbers; a CSV task starts with a header row"):
        load_task_file(bare)
    body = jl.Body(1.0, [0.5, 0, 0], np.eye(3) * 0.01)
    free = jl.from_dh("spin", a=[1.0], alpha=[0.0], d=[0.0], convention="standard", bodies=[body],
                      lower=[-math.inf], upper=[math.inf])  # fmt: skip
    Task.from_waypoints([[0.0], [270.0]], [2.0]).check(free)  # no limit: any angle
    np.savez(tmp_path / "c.npz", t_s=[0.0, 1.0], q_deg=np.array([[0j], [1j]]))
    with pytest.raises(ScenarioError, match="must be real numbers"):
        load_task_file(tmp_path / "c.npz")
    (tmp_path / "junk.npz").write_bytes(b"not a zip")
    with pytest.raises(ScenarioError, match="not an NPZ file of numeric arrays"):
        load_task_file(tmp_path / "junk.npz")


# -- can the task still be finished (issue 28, item 3) -----------------------------------------------


def test_task_completion_after_a_lock():
    """A joint the plan does not move after the failure: every remaining pose is reachable (the
    plan's own configurations are solutions); puma6 (6 joints, no redundancy) with a joint the plan
    keeps moving: the next waypoint is out of reach, by a stated distance; canadarm7 (7 joints)
    keeps 001's line with joint 2 locked halfway."""
    from jointlock.planning.completion import task_completion

    puma = jl.load_robot("puma6")
    steady = Task.from_waypoints([[0, 30, 0, 0, 0, 15], [20, 40, 20, 10, -40, 15], [30, 50, 30, 20, -80, 15]], [3.0, 3.0])
    done = task_completion(puma, steady, 6, 1.0)
    assert done.completable and done.first_unreachable_s is None and list(done.times) == [3.0, 6.0]
    moving = Task.from_waypoints([[0, 30, 0, 0, 0, 0], [20, 40, 20, 10, -40, 30], [30, 50, 30, 20, -80, 60]], [3.0, 3.0])
    stuck = task_completion(puma, moving, 2, 1.0)
    assert not stuck.completable and stuck.first_unreachable_s == 3.0
    assert stuck.position_error[0] > 1e-3 and "NOT COMPLETABLE" in stuck.summary()[0]
    assert math.degrees(stuck.angle) == pytest.approx(math.degrees(moving.state(1.0)[0][1]))
    c7 = jl.load_robot("canadarm7")
    line = load_task_file("examples/audit_canadarm7_motion.csv")
    assert task_completion(c7, line, 2, 6.0, samples=4).completable
    with pytest.raises(jl.ConfigurationError, match="joint must be a joint number 1..6"):
        task_completion(puma, moving, 7, 1.0)
    with pytest.raises(jl.ConfigurationError, match=r"t_fail must lie in the task, \[0, 6\] s"):
        task_completion(puma, moving, 2, 9.0)
