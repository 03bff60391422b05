"""Scenario files: validation in one place, errors that name the file, the field and what is
allowed; the resolved scenario is plain data; CLI options override the file."""

from __future__ import annotations

import json
import math
import tomllib
import warnings
from pathlib import Path

import pytest

from jointlock.errors import ScenarioError
from jointlock.scenario import JOB_ORDER, load_scenario, parse_set, scenario_from_dict

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def write(tmp_path: Path, text: str, name: str = "s.toml") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


@pytest.mark.parametrize("name", ["halt_000", "jump_001", "replan_002", "singular_004"])
def test_examples_validate_and_resolve_to_plain_data(name):
    sc = load_scenario(EXAMPLES / f"{name}.toml")
    assert sc.jobs and set(sc.jobs) <= set(JOB_ORDER)
    data = sc.to_dict()
    text = json.dumps(data, allow_nan=False)  # plain data, no NaN
    assert json.loads(text) == data
    for job in sc.jobs:
        assert job in data  # every job's settings, defaults filled in


def test_defaults_are_filled_in(tmp_path):
    sc = load_scenario(write(tmp_path, 'robot = "halt7"\n[failure]\njoint = 4\nangle_deg = 0\n[halt]\n'))
    h = sc.data["halt"]
    assert h["T"] == 10.0 and h["solver"] == "scan" and h["n_samples"] == 501
    assert sc.data["state"]["q0_deg"] == [-180.0, -180.0, -100.0, -10.0, 20.0, 20.0]  # 000 §5.2
    assert sc.data["seed"] == 0 and sc.data["base"] == "fixed"


@pytest.mark.parametrize(
    "text, words",
    [
        ('robot = "halt7"\nsed = 1\n[workspace]\n', ["unknown key 'sed'", "did you mean 'seed'"]),
        (
            'robot = "halt7"\n[workspace]\nsamles = 10\n',
            ["[workspace]", "'samles'", "did you mean 'samples'"],
        ),
        ('robot = "halt7"\n[workspace]\nsamples = "many"\n', ["workspace.samples", "an integer", "'many'"]),
        ('robot = "halt7"\n[workspace]\nsamples = -5\n', ["workspace.samples", ">= 1", "-5"]),
        ('robot = "halt7"\n[workspace]\nvoxel = nan\n', ["workspace.voxel", "finite"]),
        ('robot = "halt7"\nbase = "floatin"\n[workspace]\n', ["base", "did you mean 'floating'"]),
        ('robot = "halt77"\n[workspace]\n', ["robot", "did you mean 'halt7'"]),
        ('robot = "nope.urdf"\n[workspace]\n', ["robot", "not found", "nope.urdf"]),
        ('robot = "halt7"\n', ["no job to run"]),
        ('robot = "halt7"\n[halt]\nT = 10\n', ["[halt] needs the failure", "failure.joint"]),
        ('robot = "halt7"\nT = 10\n[workspace]\n', ["unknown key 'T'", "belongs in [halt]"]),
        (
            'robot = "halt7"\n[failure]\njoint = 9\nangle_deg = 0\n[workspace]\n',
            ["failure.joint", "1..7", "9"],
        ),
        (
            'robot = "halt7"\n[failure]\njoint = 4\nangle_deg = 0\n[state]\nq0_deg = [1, 2]\n[halt]\n',
            ["state.q0_deg", "6 or 7 values", "got 2"],
        ),
        ('robot = "halt7"\n[failure]\njoint = 4\nangle_deg = 0\n[halt]\nn_samples = 500\n', ["odd"]),
        ('robot = "canadarm7"\n[jump]\nduration_s = 12.01\n', ["[jump]", "whole number"]),
        ('robot = "halt7"\n[workspace\n', ["not valid TOML"]),
    ],
)
def test_errors_name_file_field_and_what_is_allowed(tmp_path, text, words):
    path = write(tmp_path, text)
    with pytest.raises(ScenarioError) as err:
        load_scenario(path)
    msg = str(err.value)
    assert str(path) in msg and "\n" not in msg
    for w in words:
        assert w in msg


def test_missing_scenario_file(tmp_path):
    with pytest.raises(ScenarioError, match="does not exist"):
        load_scenario(tmp_path / "missing.toml")


def test_model_file_paths_are_resolved_against_the_scenario(tmp_path):
    data = Path(__file__).parent / "data" / "arm5.urdf"
    sub = tmp_path / "sub"
    sub.mkdir()
    (sub / "arm.urdf").write_text(data.read_text())
    sc = load_scenario(write(sub, 'robot = "arm.urdf"\n[workspace]\nsamples = 1000\n'))
    assert Path(sc.data["robot"]) == (sub / "arm.urdf").resolve()


@pytest.mark.parametrize(
    "content, suffix",
    [("<robot><link name='a'></robot", ".urdf"), ("[[joint]]\na_m = 'x'\n", ".toml"), ("", ".urdf")],
)
def test_malformed_model_files(tmp_path, content, suffix):
    (tmp_path / f"arm{suffix}").write_text(content)
    with pytest.raises(ScenarioError) as err:
        load_scenario(write(tmp_path, f'robot = "arm{suffix}"\n[workspace]\n'))
    assert "robot" in str(err.value) and f"arm{suffix}" in str(err.value)


def test_overrides_win_over_the_file(tmp_path):
    path = write(tmp_path, 'robot = "puma6"\nseed = 1\n[workspace]\nsamples = 100000\n')
    sc = load_scenario(
        path, {"seed": 7, "workspace.samples": 2000, "failure.joint": 2, "failure.angle_deg": 30.0}
    )
    assert sc.data["seed"] == 7 and sc.data["workspace"]["samples"] == 2000 and sc.lock == (2, 30.0)
    assert parse_set("halt.T=12") == ("halt.T", 12)
    assert parse_set("halt.solver=ga") == ("halt.solver", "ga")
    assert parse_set("state.q0_deg=[1, 2.5]") == ("state.q0_deg", [1, 2.5])


def test_jobs_list_selects_and_orders(tmp_path):
    sc = scenario_from_dict(
        {
            "robot": "puma6",
            "jobs": ["workspace"],
            "failure": {"joint": 2, "angle_deg": 60.0},
            "replan": {"from_deg": [0] * 6, "to_deg": [1] * 6},
        }
    )
    assert sc.jobs == ("workspace",)
    assert math.isclose(sc.lock[1], 60.0)


def test_full_arm_rates_need_a_zero_locked_entry(tmp_path):
    head = 'robot = "halt7"\n[failure]\njoint = 4\nangle_deg = 30\n[halt]\nT = 10.0\n[state]\n'  # not 000's failure: T given
    q0 = "q0_deg = [-180, -180, -100, 30, -10, 20, 20]\n"
    ok = write(
        tmp_path, head + q0 + "dq0_deg = [20, 30, 15, 0, 25, 40, 35]\nddq0_deg = [8, 10, 12, 0, 10, -8, 6]\n"
    )
    sc = load_scenario(ok)  # rates of every joint, the locked one 0: a correct scenario
    assert sc.data["state"]["dq0_deg"][3] == 0
    for key, values in (
        ("dq0_deg", "[20, 30, 15, 30, 25, 40, 35]"),
        ("ddq0_deg", "[8, 10, 12, 5, 10, -8, 6]"),
    ):
        other = (
            "ddq0_deg = [8, 10, 12, 10, -8, 6]" if key == "dq0_deg" else "dq0_deg = [20, 30, 15, 25, 40, 35]"
        )
        path = write(tmp_path, head + q0 + f"{key} = {values}\n{other}\n", name=f"{key}.toml")
        with pytest.raises(ScenarioError) as err:
            load_scenario(path)
        msg = str(err.value)
        assert f"state.{key}: entry 4 (the locked joint) must be 0" in msg
        assert "failure.angle_deg" not in msg
    # angles keep their rule
    bad_q = write(tmp_path, head + "q0_deg = [-180, -180, -100, 0, -10, 20, 20]\n", name="q.toml")
    with pytest.raises(
        ScenarioError, match=r"state.q0_deg: entry 4 \(the locked joint\) must equal failure.angle_deg"
    ):
        load_scenario(bad_q)


# -- UX review: bases, minimums, field table -------------------------------------------------


@pytest.mark.parametrize(
    "top, singular, expected",
    [
        ('base = "floating"\n', "search = true\n", "floating"),  # inherited, as every job
        ('base = "fixed"\n', "verify_conditions = true\n", "fixed"),
        ('base = "floating"\n', "verify_conditions = true\n", "virtual"),  # 004's free-floating case
        ("", "verify_conditions = true\n", None),  # no top-level base: the command's default
        ('base = "floating"\n', 'base = "fixed"\n', "fixed"),  # the table's own base wins
    ],
)
def test_singular_job_inherits_the_top_level_base(tmp_path, top, singular, expected):
    sc = load_scenario(write(tmp_path, f'robot = "canadarm7"\n{top}[singular]\n{singular}'))
    assert sc.data["singular"]["base"] == expected


def test_singular_job_command_line_uses_the_inherited_base(tmp_path):
    from equivalent_commands import job_argv

    sc = load_scenario(write(tmp_path, 'robot = "canadarm7"\nbase = "floating"\n[singular]\nsearch = true\n'))
    argv = job_argv("singular", sc, tmp_path / "out", {}, quiet=True)
    assert argv[argv.index("--base") + 1] == "floating"


@pytest.mark.parametrize(
    "text, words",
    [
        ('robot = "puma6"\n[workspace]\nsamples = 1\n', ["workspace.samples", ">= 1000", "got 1"]),
        (
            'robot = "puma6"\n[failure]\njoint = 2\nangle_deg = 0\n[replan]\nsteps = 0\n'
            "from_deg = [0, 0, 0, 0, 0, 0]\nto_deg = [1, 0, 0, 0, 0, 0]\n",
            ["replan.steps", ">= 1", "got 0"],
        ),
    ],
)
def test_degenerate_sample_and_step_counts_are_refused(tmp_path, text, words):
    with pytest.raises(ScenarioError) as err:
        load_scenario(write(tmp_path, text))
    for w in words:
        assert w in str(err.value)


def test_workspace_minimum_matches_the_library():
    from jointlock.analysis.workspace import MIN_SAMPLES
    from jointlock.scenario import WORKSPACE_MIN_SAMPLES

    assert WORKSPACE_MIN_SAMPLES == MIN_SAMPLES


def test_every_field_has_a_meaning_in_the_schema_and_the_docs():
    from jointlock.scenario import ALL_TABLES, TOP_FIELDS

    for table, fields in {"": TOP_FIELDS, **ALL_TABLES}.items():
        for name, spec in fields.items():
            assert spec.help, f"{table}.{name}"
    doc = (Path(__file__).resolve().parents[1] / "docs" / "scenarios.md").read_text()
    rows = [line for line in doc.splitlines() if line.startswith("| `")]
    assert len(rows) > 40
    for line in rows:
        cells = [c.strip() for c in line.replace("\\|", "/").strip("|").split("|")]
        assert cells[-1], line  # the "meaning" cell
    # one name per quantity: the limits' units are in their names, the former names documented
    assert "`vmax_deg_s` **[deg/s]**" in doc and "`amax_deg_s2` **[deg/s²]**" in doc
    assert "| `limits.vmax_deg` | `limits.vmax_deg_s` |" in doc
    assert "| `limits.amax_deg` | `limits.amax_deg_s2` |" in doc


def test_overrides_are_recorded_with_the_files_values(tmp_path):
    path = write(tmp_path, 'robot = "puma6"\n[failure]\njoint = 2\nangle_deg = 59.4\n[workspace]\n')
    assert load_scenario(path).overrides == {} and not load_scenario(path).failure_overridden()
    sc = load_scenario(path, {"failure.angle_deg": 52.0547, "seed": 3})
    assert sc.overrides["failure.angle_deg"] == {"file": 59.4, "value": 52.0547}
    assert sc.overrides["seed"] == {"file": None, "value": 3}
    assert sc.failure_overridden()
    assert not load_scenario(path, {"failure.angle_deg": 59.4}).failure_overridden()  # same value


# -- one name per quantity: former field names are deprecated aliases ------------------------

LIMITS_HEAD = 'robot = "halt7"\n[failure]\njoint = 4\nangle_deg = 0\n[halt]\n'
OLD_LIMITS = "[limits]\nvmax_deg = 30.0\namax_deg = 15.0\neps_m = 0.002\n"
NEW_LIMITS = "[limits]\nvmax_deg_s = 30.0\namax_deg_s2 = 15.0\neps_m = 0.002\n"


@pytest.fixture
def fresh_warnings(monkeypatch):
    """Forget which former names warned already (they warn once per process)."""
    import jointlock._deprecate as deprecate  # the one warn-once memory of the package

    monkeypatch.setattr(deprecate, "_WARNED", set())


def former_name_warnings(record: list[warnings.WarningMessage]) -> list[str]:
    return [str(w.message) for w in record if issubclass(w.category, FutureWarning)]


def test_new_limit_names_resolve_to_the_same_keys(tmp_path, fresh_warnings):
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # the new names do not warn
        sc = load_scenario(write(tmp_path, LIMITS_HEAD + NEW_LIMITS))
    torques = {"torque_max_Nm": None, "brake_max_Nm": None, "clearance_min_m": None, "check_clearance": True}
    assert sc.data["limits"] == {"vmax_deg": 30.0, "amax_deg": 15.0, "eps_m": 0.002, **torques}


def test_former_limit_names_work_and_warn_once(tmp_path, fresh_warnings):
    new = load_scenario(write(tmp_path, LIMITS_HEAD + NEW_LIMITS, "new.toml"))
    path = write(tmp_path, LIMITS_HEAD + OLD_LIMITS, "old.toml")
    with warnings.catch_warnings(record=True) as record:
        warnings.simplefilter("always")  # count every warning given, not Python's own once-filter
        first = load_scenario(path)
        second = load_scenario(path, {"limits.vmax_deg": 30.0})  # an override by the former name
    assert first.data == second.data == new.data and first.jobs == new.jobs
    assert list(first.data["limits"]) == list(new.data["limits"]) == [
        "vmax_deg", "amax_deg", "eps_m", "torque_max_Nm", "brake_max_Nm", "clearance_min_m", "check_clearance"
    ]
    assert former_name_warnings(record) == [
        f"{path}: limits.vmax_deg is deprecated: write limits.vmax_deg_s instead (the same quantity, "
        "in deg/s); the old name still works for now",
        f"{path}: limits.amax_deg is deprecated: write limits.amax_deg_s2 instead (the same quantity, "
        "in deg/s^2); the old name still works for now",
    ]
    assert all(w.filename == __file__ for w in record)  # points at the caller, not the package


def test_both_names_of_one_quantity_are_an_error(tmp_path, fresh_warnings):
    path = write(tmp_path, LIMITS_HEAD + "[limits]\namax_deg_s2 = 15.0\namax_deg = 15.0\n")
    with pytest.raises(ScenarioError) as err:
        load_scenario(path)
    msg = str(err.value)
    assert str(path) in msg and "[limits]" in msg and "'amax_deg_s2'" in msg and "'amax_deg'" in msg
    ok = write(tmp_path, LIMITS_HEAD + NEW_LIMITS, "ok.toml")
    with pytest.raises(ScenarioError, match="'limits.vmax_deg' and 'limits.vmax_deg_s' set the same"):
        load_scenario(ok, {"limits.vmax_deg": 1.0, "limits.vmax_deg_s": 2.0})


@pytest.mark.parametrize("file_limits", [OLD_LIMITS, NEW_LIMITS])
@pytest.mark.parametrize("key", ["limits.vmax_deg_s", "limits.vmax_deg"])
def test_an_override_replaces_the_files_value_under_either_name(tmp_path, fresh_warnings, file_limits, key):
    path = write(tmp_path, LIMITS_HEAD + file_limits)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", FutureWarning)
        sc = load_scenario(path, {key: 12.5})
    torques = {"torque_max_Nm": None, "brake_max_Nm": None, "clearance_min_m": None, "check_clearance": True}
    assert sc.data["limits"] == {"vmax_deg": 12.5, "amax_deg": 15.0, "eps_m": 0.002, **torques}
    assert list(sc.data["limits"]) == ["vmax_deg", "amax_deg", "eps_m", *torques]  # the file's order, then defaults
    assert sc.overrides == {key: {"file": 30.0, "value": 12.5}}


def test_limit_names_in_errors_and_hints(tmp_path, fresh_warnings):
    cases = [
        (
            "[limits]\nvmax_dg = 1\n",
            ["[limits]", "'vmax_dg'", "did you mean 'vmax_deg_s'", "allowed: vmax_deg_s, amax_deg_s2, eps_m, torque_max_Nm, brake_max_Nm"],
        ),
        ("[limits]\namax_deg_s2 = -1\n", ["limits.amax_deg_s2 must be a finite number > 0 and <= 1e+06 [deg/s^2]"]),
        ("[limits]\nvmax_deg = -1\n", ["limits.vmax_deg must be a finite number > 0 and <= 1e+06 [deg/s]"]),
        ("[jump]\nvmax_deg = 1\n", ["[jump] unknown field 'vmax_deg'", "did you mean 'vmax_deg_s'"]),
    ]
    for i, (table, words) in enumerate(cases):
        path = write(tmp_path, 'robot = "canadarm7"\n' + table, f"c{i}.toml")
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", FutureWarning)
            with pytest.raises(ScenarioError) as err:
                load_scenario(path)
        for w in words:
            assert w in str(err.value), (w, str(err.value))
    top = write(tmp_path, 'robot = "halt7"\namax_deg = 1\n[workspace]\n', "top.toml")
    with pytest.raises(ScenarioError, match=r"unknown key 'amax_deg' \(it belongs in \[limits\]\)"):
        load_scenario(top)


def test_examples_use_the_current_names(fresh_warnings):
    from jointlock.scenario import DEPRECATED_FIELDS

    for path in sorted(EXAMPLES.glob("*.toml")):
        raw = tomllib.loads(path.read_text())
        for table, former in DEPRECATED_FIELDS.items():
            assert not set(raw.get(table, {})) & set(former), path
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            load_scenario(path)


# -- two readers, two names: jump task files are read by load_jump_task ----------------------


def test_load_jump_task_and_its_former_name(tmp_path, monkeypatch):
    import jointlock._deprecate as deprecate
    from jointlock.planning.jump import load_jump_task
    from jointlock.planning.jump import load_scenario as former

    monkeypatch.setattr(deprecate, "_WARNED", set())
    f = write(tmp_path, "q0_deg = [0, 30, -60, 90, -60, 30, 0]\ndx_m = [0.5, 0, 0]\nduration_s = 6.0\n")
    with warnings.catch_warnings(record=True) as record:
        warnings.simplefilter("always")
        assert former(f) == load_jump_task(f) == former(f)
    assert former_name_warnings(record) == [
        "jointlock.planning.jump.load_scenario is deprecated: use jointlock.planning.jump.load_jump_task "
        "(the same jump task-file reader; jointlock.load_scenario reads `jointlock run` scenario files)"
    ]
    assert record[0].filename == __file__
    import jointlock.planning.jump as jump

    assert "load_jump_task" in jump.__all__ and "load_scenario" not in jump.__all__
