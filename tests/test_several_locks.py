"""Several locked joints (issue 14, item 5): ``[failure] also_locked_deg`` in scenario files,
``jointlock run --lock A --lock B``, the jobs that allow it (halt_config, halt, workspace,
singular) and the ones that say why not (tolerance_angle, replan, jump)."""

from __future__ import annotations

import contextlib
import io
import json

import numpy as np
import pytest
from equivalent_commands import call_subcommand, job_argv

import jointlock as jl
from jointlock.cli import main
from jointlock.jobs.halt import halt_from_scenario

TWO_LOCKS = """title = "two locks"
robot = "halt7"
base = "floating"
[failure]
joint = 4
angle_deg = 0.0
also_locked_deg = {{2 = 10.0}}
[state]
q0_deg = [-180, -100, -10, 20, 20]
dq0_deg = [5, 5, 5, 5, 5]
ddq0_deg = [0, 0, 0, 0, 0]
[limits]
brake_max_Nm = {brake}
[halt]
T = 10.0
samples = 2000
"""


def cli(*argv: str) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(list(argv))
    return code, out.getvalue(), err.getvalue()


def _write(tmp_path, text: str, name: str = "s.toml"):
    path = tmp_path / name
    path.write_text(text)
    return path


def test_a_scenario_file_locks_two_joints_and_the_halt_holds_both_brakes(tmp_path):
    sc = jl.load_scenario(_write(tmp_path, TWO_LOCKS.format(brake=400.0)))
    assert sc.locks == {2: 10.0, 4: 0.0}
    plan = halt_from_scenario(sc.data, {})
    model = plan.problem.model
    assert model.joint_numbers == (1, 3, 5, 6, 7)
    assert {lj.number: np.degrees(lj.angle) for lj in model.locked} == pytest.approx({2: 10.0, 4: 0.0})
    loads = plan.actuator_loads()
    assert loads.locked_numbers == (2, 4) and loads.brake.shape[1] == 2
    assert plan.limits.brake.tolist() == [400.0, 400.0]
    assert np.all(loads.peak_brake <= 400.0 * (1 + 1e-6)) or not plan.feasible


def test_run_with_two_locks_equals_the_file_and_the_equivalent_command(tmp_path):
    one = TWO_LOCKS.format(brake=400.0).replace("also_locked_deg = {2 = 10.0}\n", "")
    path = _write(tmp_path, one.replace("[-180, -100, -10, 20, 20]", "[-180, 10, -100, 0, -10, 20, 20]"))
    code, _, err = cli("run", str(path), "--lock", "2=10", "--lock", "4=0", "--out", str(tmp_path / "o"), "--quiet")
    assert code == 0, err
    by_options = json.loads((tmp_path / "o" / "results.json").read_text())
    assert by_options["scenario"]["failure"]["also_locked_deg"] == {"2": 10.0}
    sc = jl.load_scenario(_write(tmp_path, TWO_LOCKS.format(brake=400.0), "file.toml"))
    plan = halt_from_scenario(sc.data, {})
    assert by_options["jobs"]["halt"]["result"]["k"] == pytest.approx(plan.to_dict()["k"], rel=1e-12)
    argv = job_argv("halt", sc, tmp_path / "eq", {}, quiet=True)
    assert argv[2:6] == ["--lock", "2=10.0", "--lock", "4=0.0"]
    printed, code = call_subcommand("halt", argv)
    assert code == 0 and printed["k"] == pytest.approx(plan.to_dict()["k"], rel=1e-12)
    assert printed["locked"] == {"2": 10.0, "4": 0.0}


def test_a_single_lock_override_replaces_the_files_earlier_locks(tmp_path):
    text = 'robot = "halt7"\n[failure]\njoint = 4\nangle_deg = 0.0\nalso_locked_deg = {2 = 10.0}\n[workspace]\n'
    path = _write(tmp_path, text)
    assert jl.load_scenario(path).locks == {2: 10.0, 4: 0.0}
    overrides = {"failure.joint": 3, "failure.angle_deg": 5.0, "failure.also_locked_deg": None}
    assert jl.load_scenario(path, overrides).locks == {3: 5.0}  # what `run --lock 3=5` sets


@pytest.mark.parametrize("job", ["tolerance_angle", "replan", "jump"])
def test_jobs_with_one_locked_joint_by_method_say_why(tmp_path, job):
    text = 'robot = "puma6"\n[failure]\njoint = 2\nangle_deg = 10.0\nalso_locked_deg = {5 = 0.0}\n' + f"[{job}]\n"
    with pytest.raises(jl.ScenarioError, match=rf"\[{job}\] work with one locked joint"):
        jl.load_scenario(_write(tmp_path, text))


@pytest.mark.parametrize(
    ("field", "words"),
    [
        ("{9 = 1.0}", "joint 9 is no joint of halt7 (1..7)"),
        ("{4 = 1.0}", "joint 4 is the failure's own joint"),
        ('{2 = "x"}', "failure.also_locked_deg.2 must be a finite number >= -360 and <= 360 [deg]; got 'x'"),
        ("{2 = 1.0, 3 = 400.0}", "failure.also_locked_deg.3 must be a finite number >= -360 and <= 360 [deg]; got 400"),
        ("[2, 10.0]", "must be a table {joint number = angle}"),
        ("{x = 1.0}", "key 'x' is no joint number"),
        ("{2 = 300.0}", "failure.also_locked_deg.2: lock angle of joint 2 must lie within its limits"),
    ],
)
def test_bad_earlier_locks_get_one_line(tmp_path, field, words):
    text = f'robot = "halt7"\n[failure]\njoint = 4\nangle_deg = 0.0\nalso_locked_deg = {field}\n[workspace]\n'
    with pytest.raises(jl.ScenarioError) as err:
        jl.load_scenario(_write(tmp_path, text))
    assert words in str(err.value) and "\n" not in str(err.value)


def test_a_full_state_vector_must_hold_every_lock_angle(tmp_path):
    text = TWO_LOCKS.format(brake=400.0).replace("[-180, -100, -10, 20, 20]", "[-180, 0, -100, 0, -10, 20, 20]")
    with pytest.raises(jl.ScenarioError, match=r"entry 2 \(the locked joint\) must equal failure.also_locked_deg.2 = 10"):
        jl.load_scenario(_write(tmp_path, text))


def test_the_workspace_compares_before_and_after_the_failure(tmp_path):
    code, out, err = cli("workspace", "halt7", "--lock", "2=10", "--lock", "4=0", "--samples", "2000", "--json")
    assert code == 0, err
    res = json.loads(out)
    assert res["already_locked_deg"] == {"2": 10.0} and res["lock"]["joint"] == 4
    code, _, err = cli("workspace", "halt7", "--lock", "4=0", "--lock", "4=10", "--samples", "2000")
    assert code == 2 and "joint 4 given twice" in err


def test_a_campaign_can_set_and_sweep_the_earlier_locks(tmp_path):
    from campaign_helpers import write_campaign

    from jointlock.campaign import expand, load_campaign

    body = '[grid]\n"failure.also_locked_deg" = [{2 = 10.0}, {2 = 20.0, 6 = 0.0}]\n'
    cases = expand(load_campaign(write_campaign(tmp_path, body)))
    assert [c["failure.also_locked_deg"] for c in cases] == [{"2": 10.0}, {"2": 20.0, "6": 0.0}]


def test_overriding_the_earlier_locks_is_recorded_and_reported(tmp_path):
    text = 'robot = "halt7"\n[failure]\njoint = 4\nangle_deg = 0.0\nalso_locked_deg = {2 = 10.0}\n[workspace]\n'
    path = _write(tmp_path, text)
    sc = jl.load_scenario(path, {"failure.joint": 4, "failure.angle_deg": 0.0, "failure.also_locked_deg": None})
    assert sc.failure_overridden() and sc.overrides["failure.also_locked_deg"] == {"file": {"2": 10.0}, "value": None}
    plain = jl.load_scenario(_write(tmp_path, text.replace("also_locked_deg = {2 = 10.0}\n", ""), "p.toml"),
                             {"failure.also_locked_deg": None})  # fmt: skip
    assert "failure.also_locked_deg" not in plain.overrides  # nothing was overridden


@pytest.mark.parametrize("table", ['{"02" = 1.0}', '{2 = 1.0, "02" = 5.0}'])
def test_a_joint_is_named_once_and_in_one_spelling(tmp_path, table):
    text = f'robot = "halt7"\n[failure]\njoint = 4\nangle_deg = 0.0\nalso_locked_deg = {table}\n[workspace]\n'
    with pytest.raises(jl.ScenarioError, match="key '02' is no joint number"):
        jl.load_scenario(_write(tmp_path, text))
