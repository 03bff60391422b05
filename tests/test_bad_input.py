"""Bad input never gets a traceback: one regression test per class of issue 17 (a fuzzing run of
15,675 generated inputs found 216 tracebacks, 59 multi-line errors and 6 inf/NaN results).

Every CLI case asserts exit code 2 and exactly one stderr line, ``jointlock CMD: error: ...``,
naming what was wrong; every library case a :class:`JointlockError` whose message is one line.
"""

from __future__ import annotations

import errno
import json
import os
import subprocess
import sys
import tomllib
from pathlib import Path

import numpy as np
import pytest

import jointlock as jl
from jointlock.bounds import MAX_JOINT_VALUE, shown
from jointlock.cli import main
from jointlock.errors import JointlockError, ScenarioError
from jointlock.io.files import atomic_write_bytes

ROOT = Path(__file__).resolve().parents[1]
ARM5 = ROOT / "tests" / "data" / "arm5.urdf"
MODEL_TOML = """name = "t3"
convention = "dh_modified"
[[joint]]
d_m = 0.5
mass_kg = 10.0
inertia_kgm2 = [1.0, 1.0, 1.0]
[[joint]]
a_m = 1.0
alpha_deg = 90.0
mass_kg = 10.0
com_m = [0.5, 0.0, 0.0]
inertia_kgm2 = [1.0, 1.0, 1.0]
[[joint]]
a_m = 1.0
mass_kg = 10.0
com_m = [0.5, 0.0, 0.0]
inertia_kgm2 = [1.0, 1.0, 1.0]
"""
JUMP_TASK = "q0_deg = [10.0, 40.0, -70.0, 100.0, -60.0, 30.0, 20.0]\ndx_m = [1.2, -1.5, 0.8]\n"
BIG = "9" * 400
#: Valid leading options of the replan and tolerance-angle commands (puma6, joint 2 at 59.4 deg).
REPLAN = ["replan", "puma6", "--lock", "2=59.4", "--from-deg", "0", "60", "0", "0", "0", "0"]
REPLAN += ["--to-deg", "5", "60", "35", "10", "-120", "90"]
TOLERANCE = [
    "tolerance-angle",
    "puma6",
    "--lock",
    "2=59.4",
    "--q-target-deg",
    "5",
    "60",
    "35",
    "10",
    "-120",
    "90",
]


def cli(capsys, *argv: str) -> tuple[int, str, str]:
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def assert_one_error_line(code: int, err: str, *words: str) -> None:
    assert code == 2, err
    assert err.count("\n") == 1 and ": error: " in err and "Traceback" not in err, err
    assert len(err) < 600, err
    for w in words:
        assert w in err, (w, err)


# --- encodings ------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("name", "data", "words"),
    [
        ("bin.urdf", bytes(range(256)) * 4, ["a binary file, not text"]),
        (
            "latin1.urdf",
            ARM5.read_text().replace("arm5", "arm5\u00e9").encode("latin-1"),
            ["not UTF-8 text", "line 4"],
        ),
        ("latin1.toml", MODEL_TOML.replace("t3", "t3\u00e9").encode("latin-1"), ["not UTF-8 text", "line 1"]),
        ("bin.toml", b"\x00\x01\x02name = 1\n\xff", ["a binary file"]),
        (
            "bom_garbage.toml",
            b"\xef\xbb\xbfname = '\xff'",
            ["not valid UTF-8 text after its byte-order mark"],
        ),
    ],
)
def test_model_files_in_another_encoding_give_one_line(capsys, tmp_path, name, data, words):
    path = tmp_path / name
    path.write_bytes(data)
    assert_one_error_line(*cli(capsys, "kinematics", path)[::2], str(path), *words)


@pytest.mark.parametrize("encoding", ["utf-16", "utf-8-sig", "utf-32"])
def test_unicode_with_a_byte_order_mark_is_read(tmp_path, encoding):
    """UTF-16/32 with a BOM (Windows editors write them) and UTF-8 with a BOM are text: read."""
    ref_urdf, ref_toml = jl.read_urdf(ARM5), jl.io.read_model_toml(_write(tmp_path / "ref.toml", MODEL_TOML))
    urdf = tmp_path / "arm.urdf"
    urdf.write_bytes(ARM5.read_text().encode(encoding))
    toml = tmp_path / "arm.toml"
    toml.write_bytes(MODEL_TOML.encode(encoding))
    q = np.linspace(-1, 1, ref_urdf.dof)
    np.testing.assert_array_equal(jl.ee_pose(jl.load_robot(urdf), q), jl.ee_pose(ref_urdf, q))
    np.testing.assert_array_equal(
        jl.ee_pose(jl.load_robot(toml), [0.1, 0.2, 0.3]), jl.ee_pose(ref_toml, [0.1, 0.2, 0.3])
    )


def test_a_urdf_declaring_latin1_is_decoded_by_its_declaration(tmp_path):
    text = ARM5.read_text().replace('<?xml version="1.0"?>', '<?xml version="1.0" encoding="ISO-8859-1"?>')
    path = tmp_path / "decl.urdf"
    path.write_bytes(text.replace("arm5", "arm5\u00e9").encode("latin-1"))
    assert jl.read_urdf(path).name == "arm5\u00e9"


def test_scenario_and_task_files_in_another_encoding(capsys, tmp_path):
    scen = tmp_path / "s.toml"
    scen.write_bytes(
        (ROOT / "examples" / "replan_002.toml").read_text().replace("002:", "002\u00e9:").encode("latin-1")
    )
    assert_one_error_line(*cli(capsys, "run", scen)[::2], "not UTF-8 text")
    task = tmp_path / "task.toml"
    task.write_bytes(JUMP_TASK.encode("latin-1") + b"# \xe9\n")
    assert_one_error_line(
        *cli(capsys, "jump", "canadarm7", "--scenario", task, "--fail-at", "3")[::2], "not UTF-8"
    )


# --- numbers TOML allows but floats do not ------------------------------------------------------


def test_a_400_digit_integer_in_a_model_file(capsys, tmp_path):
    path = _write(tmp_path / "big.toml", MODEL_TOML.replace("d_m = 0.5", f"d_m = {BIG}"))
    assert_one_error_line(*cli(capsys, "kinematics", path)[::2], "joint #1.d_m", "400 digits")


@pytest.mark.parametrize(
    ("old", "new", "field"),
    [("seed = 0", f"seed = {BIG}", "seed"), ("steps = 40", f"steps = {BIG}", "replan.steps")],
)
def test_a_400_digit_integer_in_a_scenario(capsys, tmp_path, old, new, field):
    path = _write(tmp_path / "s.toml", (ROOT / "examples" / "replan_002.toml").read_text().replace(old, new))
    assert_one_error_line(*cli(capsys, "run", path)[::2], field, "400 digits")


def test_a_400_digit_integer_in_a_jump_task(capsys, tmp_path):
    path = _write(tmp_path / "t.toml", JUMP_TASK + f"duration_s = {BIG}\n")
    assert_one_error_line(
        *cli(capsys, "jump", "canadarm7", "--scenario", path, "--fail-at", "3")[::2], "duration_s"
    )


@pytest.mark.parametrize(
    ("field", "value", "words"),
    [
        ("duration_s", "1e308", ["jump.duration_s", "<= 1e+06 [s]"]),
        ("dt_s", "1e-300", ["jump.dt_s", ">= 1e-06"]),
        ("kappa", "1e308", ["jump.kappa", "1e+06"]),
        ("kp", "1e300", ["jump.kp"]),
    ],
)
def test_extreme_jump_fields_in_a_scenario(capsys, tmp_path, field, value, words):
    text = (ROOT / "examples" / "jump_001.toml").read_text()  # its last table is [jump]
    text = "\n".join(line for line in text.splitlines() if not line.startswith(f"{field} ="))
    path = _write(tmp_path / "j.toml", text + f"\n{field} = {value}\n")
    assert_one_error_line(*cli(capsys, "run", path, "--out", tmp_path / "o")[::2], *words)


def test_a_jump_task_too_many_steps(capsys, tmp_path):
    """1e-6 s steps over 1e6 s: each value within its bounds, the step count (1e12) is not."""
    path = _write(tmp_path / "t.toml", JUMP_TASK + "duration_s = 1000000.0\ndt_s = 1e-6\nblend_s = 1.0\n")
    assert_one_error_line(
        *cli(capsys, "jump", "canadarm7", "--scenario", path, "--fail-at", "3")[::2], "control steps"
    )


@pytest.mark.parametrize(
    ("argv", "words"),
    [
        (["workspace", "puma6", "--voxel", "1e-300", "--samples", "1000"], ["--voxel", ">= 1e-06"]),
        (["workspace", "puma6", "--voxel", "1e308", "--samples", "1000"], ["--voxel", "<= 1e+06"]),
        (
            [*TOLERANCE, "--step-deg", "1e-320"],
            ["--step-deg"],
        ),
        (["halt-config", "halt7", "--lock", "4=0", "--length", "1e-320", "--samples", "100"], ["--length"]),
        (["singular", "canadarm7", "--length", "1e-320"], ["--length"]),
        (["halt", "halt7", "--lock", "4=0", "--T", "1e308"], ["--T", "[s]"]),
        (["halt", "halt7", "--lock", "4=0", "--T", "1e-300"], ["--T"]),
        (
            [*REPLAN, "--cycle", "1e-320"],
            ["--cycle"],
        ),
        (["jump", "canadarm7", "--kappa", "1e308", "--fail-at", "3"], ["--kappa"]),
        (["ik", "puma6", "--pose", "1e308", "0", "0", "0", "0", "0"], ["--pose"]),
        (
            ["ik", "puma6", "--pose", "0.5", "0.2", "0.3", "0", "0", "0", "--length-scale", "1e-320"],
            ["--length-scale"],
        ),
        (["kinematics", "halt7", "--q-deg", "1e308", "0", "0", "0", "0", "0", "0"], ["--q-deg"]),
    ],
)
def test_extreme_option_values_name_the_option(capsys, argv, words):
    assert_one_error_line(*cli_usage(capsys, argv), *words)


@pytest.mark.parametrize(
    "argv",
    [
        ["halt-config", "halt7", "--lock", "4=0", "--samples", "4294967297"],
        ["workspace", "puma6", "--samples", "4294967297"],
        [*REPLAN, "--steps", "4294967297"],
        ["singular", "canadarm7", "--search", "--samples", "4294967297"],
        ["jump", "canadarm7", "--sweep", "4294967297"],
        ["halt", "halt7", "--lock", "4=0", "--samples", "4294967297"],
    ],
)
def test_sizes_have_the_scenario_formats_upper_bound(capsys, argv):
    assert_one_error_line(*cli_usage(capsys, argv), "--" + argv[-2].lstrip("-"), "<=")


def cli_usage(capsys, argv: list[str]) -> tuple[int, str]:
    """(exit code, stderr) of an option refused by argparse (SystemExit) or by the command."""
    try:
        code = main(argv)
    except SystemExit as exc:
        code = int(exc.code)
    return code, capsys.readouterr().err


def test_a_fast_arm_keeps_its_kappa_search(tmp_path, capsys):
    """A speed limit of 20,000 deg/s (within its bound): the search's candidates run fast
    without counting as diverged, and one candidate that diverges does not stop the search."""
    path = _write(tmp_path / "fast.toml", JUMP_TASK + "vmax_deg_s = 20000.0\namax_deg_s2 = 20000.0\n")
    code, out, err = cli(
        capsys, "jump", "canadarm7", "--scenario", path, "--fail-at", "5", "--json", "--quiet"
    )
    assert code == 0, err


def test_a_kappa_that_makes_the_motion_diverge_is_reported_finite(capsys):
    """kappa within its bound but far too large for the task: the diverging run is stopped
    (its rates frozen once past 100x the speed limit) and reported as breaking the limits
    with finite numbers -- no error about an internal ``q``, no inf/NaN."""
    code, out, err = cli(capsys, "jump", "canadarm7", "--kappa", "1e6", "--fail-at", "3", "--json", "--quiet")
    assert code == 0 and "NaN" not in out and "Infinity" not in out, err
    assert json.loads(out)["limits_ok"] is False


# --- odd files ------------------------------------------------------------------------------


def test_a_urdf_with_a_disconnected_cycle(capsys, tmp_path):
    loop = """<link name="c1"/><link name="c2"/>
<joint name="cj1" type="revolute"><parent link="c1"/><child link="c2"/><limit lower="-1" upper="1"/></joint>
<joint name="cj2" type="revolute"><parent link="c2"/><child link="c1"/><limit lower="-1" upper="1"/></joint>
</robot>"""
    path = _write(tmp_path / "cycle.urdf", ARM5.read_text().replace("</robot>", loop))
    assert_one_error_line(*cli(capsys, "kinematics", path)[::2], "'c1', 'c2'", "closed loop")


def test_a_urdf_origin_beyond_physical_lengths(capsys, tmp_path):
    path = _write(tmp_path / "far.urdf", ARM5.read_text().replace('xyz="0 0 -0.8"', 'xyz="0 0 1.7e308"', 1))
    assert_one_error_line(*cli(capsys, "kinematics", path)[::2], str(path), "<origin xyz>", "1e+06 m")


def test_a_null_character_in_a_robot_path(capsys, tmp_path):
    text = (
        (ROOT / "examples" / "replan_002.toml")
        .read_text()
        .replace('robot = "puma6"', 'robot = "\\u0000.urdf"')
    )
    path = _write(tmp_path / "s.toml", text)
    assert_one_error_line(*cli(capsys, "run", path)[::2], "NUL character")
    assert_one_error_line(*cli(capsys, "kinematics", "a\x00b.urdf")[::2], "NUL character")


# --- timing ---------------------------------------------------------------------------------


#: A child process that sends itself SIGINT the moment ``module`` starts being imported: the
#: same moment on every run, however loaded the machine is.
INTERRUPT_AT_IMPORT = """
import os, signal, sys
class Interrupt:
    def find_spec(self, name, path=None, target=None):
        if name == {module!r}:
            sys.meta_path.remove(self)
            os.kill(os.getpid(), signal.SIGINT)
        return None
sys.meta_path.insert(0, Interrupt())
from jointlock.cli import main
sys.exit(main(["workspace", "halt7", "--samples", "1000", "--json"]))
"""


@pytest.mark.parametrize("module", ["numpy", "jointlock.cli.workspace", "jointlock.kinematics", "jointlock.jobs.workspace"])
def test_an_interrupt_during_start_up_imports_is_one_line(module):
    """SIGINT while the command imports its modules (numpy, the subcommands, the core): one
    line and exit 130, never a KeyboardInterrupt traceback.  (The interpreter's own start-up,
    before ``main`` runs -- ~20 ms, a few light modules -- is Python's to handle.)"""
    proc = subprocess.run(
        [sys.executable, "-c", INTERRUPT_AT_IMPORT.format(module=module)],
        capture_output=True,
        text=True,
        timeout=120,
        env={**os.environ, "MPLBACKEND": "Agg"},
    )
    assert proc.returncode == 130, (proc.returncode, proc.stderr[-2000:])
    assert proc.stderr == "jointlock: interrupted\n", proc.stderr[-2000:]


def test_import_jointlock_is_light():
    """What makes the start-up interrupt clean: the package and the CLI module import no
    numpy (everything is imported on first use, inside the CLI's Ctrl-C handling)."""
    code = "import sys, jointlock, jointlock.cli; print('numpy' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "False"


# --- messages -------------------------------------------------------------------------------


def test_no_warning_is_printed_ahead_of_an_error(capsys):
    """``--single`` is ignored with ``--fail-at`` (a warning), and 20 s is past the task (an
    error): only the error is printed."""
    code, _, err = cli(capsys, "jump", "canadarm7", "--fail-at", "20", "--single")
    assert_one_error_line(code, err, "failure time")
    assert "warning" not in err


def test_warnings_come_after_the_output_one_line_each(capsys):
    code, out, err = cli(capsys, "jump", "canadarm7", "--fail-at", "3", "--single", "--quiet")
    assert code == 0 and out
    assert (
        err
        == "jointlock jump: warning: --single ignored with --fail-at (one failure time, no kappa(t) fit)\n"
    )


def test_a_numpy_warning_is_an_error_not_a_result(capsys, monkeypatch):
    """Last line of defence: a numpy floating-point warning inside a command becomes one error
    line (never a printed inf/NaN)."""
    import jointlock.cli.kinematics as kin

    def overflow(args):
        np.float64(1e308) * np.float64(10.0)
        return 0

    monkeypatch.setattr(kin, "run", overflow)
    parser_func = main.__globals__["build_parser"]
    monkeypatch.setitem(main.__globals__, "build_parser", lambda *a: _with_func(parser_func(*a), overflow))
    code, out, err = cli(capsys, "kinematics", "halt7")
    assert_one_error_line(code, err, "numerical failure", "overflow")


def _with_func(parser, func):
    for action in parser._actions:
        if hasattr(action, "choices") and isinstance(action.choices, dict) and "kinematics" in action.choices:
            action.choices["kinematics"].set_defaults(func=func)
    return parser


def test_disk_full_names_the_path(tmp_path, monkeypatch):
    if Path("/dev/full").exists():
        with pytest.raises(OSError) as info:
            atomic_write_bytes("/dev/full", b"x" * 100_000)
        assert info.value.filename == "/dev/full" and info.value.errno == errno.ENOSPC

    def full(*args, **kwargs):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(os, "replace", full)
    target = tmp_path / "out" / "results.json"
    with pytest.raises(OSError) as info:
        atomic_write_bytes(target, b"{}")
    assert info.value.filename == str(target) and "No space left" in str(info.value)
    assert not list((tmp_path / "out").iterdir())  # no temporary file left


def test_a_long_value_is_shortened_in_the_error(capsys):
    code, _, err = cli(capsys, "kinematics", "x" * 5000)
    assert_one_error_line(code, err)
    assert len(err) < 400
    assert shown("y" * 5000).endswith("...") and len(shown("y" * 5000)) == 80


@pytest.mark.parametrize(
    "urdf",
    [
        "<" + "N" * 10_000 + "/>",  # the root element's tag
        '<?xml version="1.0"?><!DOCTYPE r [<!ENTITY a "' + "A" * 100 + '"><!ENTITY b "' + "&a;" * 100
        + '">]><robot name="r"><link name="base"/><joint name="j" type="revolute"><parent link="base"/>'
        '<child link="&b;"/><axis xyz="0 0 1"/></joint></robot>',
    ],
    ids=["long-root-tag", "entity-in-a-link-name"],
)
def test_a_urdf_with_a_very_long_name_is_shortened_in_the_error(tmp_path, capsys, urdf):
    """The held-out fuzz (issue 30): a 10,000-character name, or an entity expanded to one, is
    echoed shortened (the URDF reader shortens what it quotes; the command line cuts any longer
    run as the net)."""
    path = tmp_path / "long.urdf"
    path.write_text(urdf)
    code, _, err = cli(capsys, "kinematics", str(path))
    assert_one_error_line(code, err)
    assert len(err) < 400 and "..." in err


def test_the_error_line_net_cuts_long_words():
    from jointlock.cli import LONGEST_WORD, _short_words

    assert _short_words("ok: short words stay") == "ok: short words stay"
    cut = _short_words("name 'x" + "y" * 5000 + "z' is bad")
    assert cut.startswith("name 'xyy") and "...yyy" in cut and cut.endswith("z' is bad") and len(cut) < 150
    path = "/tmp/" + "/".join(["deep_folder_name"] * 20) + "/model.urdf"
    assert _short_words(f"looked for {path}").endswith("/model.urdf")  # the file name stays
    assert _short_words("p" * LONGEST_WORD) == "p" * LONGEST_WORD


def test_a_scenario_field_holding_a_long_string_is_shortened(tmp_path):
    path = _write(tmp_path / "s.toml", 'robot = "halt7"\nbase = "' + "z" * 5000 + '"\n[workspace]\n')
    with pytest.raises(ScenarioError) as info:
        jl.load_scenario(path)
    assert len(str(info.value)) < 400 and "..." in str(info.value)


# --- library boundary -----------------------------------------------------------------------


def test_lock_with_an_angle_that_is_not_a_number():
    arm = jl.load_robot("halt7")
    for angle in (None, "0", complex(1, 1), [0.0], True):
        with pytest.raises(JointlockError, match="angle"):
            jl.lock(arm, 1, angle)


def test_compare_workspaces_with_a_negative_seed():
    from jointlock.analysis.workspace import compare_workspaces

    with pytest.raises(JointlockError, match="rng"):
        compare_workspaces(jl.load_robot("puma6"), 2, 1.0, samples=1000, rng=-1)


def test_compare_workspaces_with_a_voxel_out_of_bounds():
    from jointlock.analysis.workspace import compare_workspaces

    for voxel in (1e-300, 1e308, float("nan")):
        with pytest.raises(JointlockError, match="voxel"):
            compare_workspaces(jl.load_robot("puma6"), 2, 1.0, samples=1000, voxel=voxel, rng=0)


def test_rnea_with_absurd_rates_is_refused_not_inf():
    arm = jl.load_robot("halt7")
    with pytest.raises(JointlockError, match=r"rnea: the result overflows float64 .*\|dq\| up to 1e\+300"):
        jl.rnea(arm, np.zeros(7), np.full(7, 1e300), np.zeros(7))
    result = jl.rnea(arm, np.zeros(7), np.full(7, MAX_JOINT_VALUE), np.zeros(7))  # the bound itself: finite
    for values in (result.torques, result.base_force, result.base_moment):
        assert np.all(np.isfinite(values))


@pytest.mark.parametrize("bad", [np.ones(7, dtype=complex), np.ones(7, dtype=bool), np.array(["1"] * 7)])
def test_complex_bool_and_text_joint_arrays_are_refused(bad):
    with pytest.raises(JointlockError, match="real numbers"):
        jl.ee_pose(jl.load_robot("halt7"), bad)


# --- the scenario path rule -----------------------------------------------------------------


def test_a_scenarios_out_resolves_against_its_folder_and_stays_inside(tmp_path, monkeypatch):
    folder = tmp_path / "scenarios"
    folder.mkdir()
    body = 'robot = "puma6"\nout = "{}"\n[workspace]\nsamples = 1000\n'
    monkeypatch.chdir(tmp_path)
    sc = jl.load_scenario(_write(folder / "a.toml", body.format("results/a")))
    assert sc.data["out"] == os.path.join(os.path.abspath(folder), "results", "a")
    (folder / "scratch").symlink_to(tmp_path)  # a link inside the folder to elsewhere: as written, fine
    assert (
        jl.load_scenario(_write(folder / "l.toml", body.format("scratch/r")))
        .data["out"]
        .endswith("scratch/r")
    )
    for outside in ("../..", str(tmp_path / "elsewhere"), "../x"):
        with pytest.raises(ScenarioError, match="inside the file's folder.*--out"):
            jl.load_scenario(_write(folder / "b.toml", body.format(outside)))
    sc = jl.load_scenario(_write(folder / "c.toml", body.format("../..")), {"out": "../anywhere"})
    assert sc.data["out"] == "../anywhere"  # the command line's --out: the working folder's
    data = tomllib.loads(body.format(tmp_path / "py"))  # Python's scenario_from_dict: its own choice
    assert jl.scenario_from_dict(data).data["out"] == str(tmp_path / "py")


def _write(path: Path, text: str) -> Path:
    path.write_text(text, encoding="utf-8")
    return path


# --- found by a first-user walkthrough of the above -----------------------------------------


def _jointlock(args: str, **env: str) -> subprocess.CompletedProcess:
    """``jointlock ARGS`` through a shell (for redirections such as ``>&-``)."""
    return subprocess.run(
        f"{sys.executable} -m jointlock.cli {args}", shell=True, capture_output=True, text=True, timeout=120,
        env={**os.environ, "MPLBACKEND": "Agg", **env},
    )  # fmt: skip


def test_odd_standard_streams():
    closed = _jointlock("robots >&-")
    assert closed.returncode == 0 and "Traceback" not in closed.stderr, closed.stderr
    ascii_only = _jointlock("robots", PYTHONIOENCODING="ascii")
    assert ascii_only.returncode == 0 and "\\xa75" in ascii_only.stdout, ascii_only.stderr  # "§5" escaped
    if Path("/dev/full").exists():
        full = _jointlock("robots > /dev/full")
        assert (
            full.returncode == 2
            and full.stderr == "jointlock robots: error: '<standard output>': No space left on device\n"
        )


def test_inputs_that_are_not_regular_files(capsys, tmp_path):
    (tmp_path / "zero.toml").symlink_to("/dev/zero")
    assert_one_error_line(*cli(capsys, "kinematics", tmp_path / "zero.toml")[::2], "not a regular file")
    assert_one_error_line(*cli(capsys, "run", tmp_path / "zero.toml")[::2], "not a regular file")
    (tmp_path / "dir.urdf").mkdir()
    assert_one_error_line(*cli(capsys, "kinematics", tmp_path / "dir.urdf")[::2], "is a folder")
    (tmp_path / "a.urdf").symlink_to(tmp_path / "b.urdf")
    (tmp_path / "b.urdf").symlink_to(tmp_path / "a.urdf")
    scenario = _write(tmp_path / "s.toml", 'robot = "a.urdf"\n[workspace]\nsamples = 1000\n')
    assert_one_error_line(*cli(capsys, "run", scenario)[::2], "robot: cannot use model file")


def test_the_largest_seed_is_accepted(capsys):
    top = str(2**63 - 1)
    assert cli(capsys, "workspace", "puma6", "--samples", "1000", "--seed", top, "--json")[0] == 0
    assert_one_error_line(
        *cli_usage(capsys, ["workspace", "puma6", "--seed", str(2**63)]), "<= 9223372036854775807"
    )


def test_a_large_arm_can_be_locked(tmp_path):
    """Each model-file length within 1e6 m: locking composes two of them, still accepted."""
    big = ARM5.read_text().replace(
        '<origin xyz="1.0 0 0" rpy="0 0 0"/>', '<origin xyz="900000 0 0" rpy="0 0 0"/>'
    )
    big = big.replace(
        '<origin xyz="0.8 0 0" rpy="0 -1.5707963267948966 0"/>',
        '<origin xyz="900000 0 0" rpy="0 -1.5707963267948966 0"/>',
    )
    arm = jl.read_urdf(_write(tmp_path / "big.urdf", big))
    locked = jl.lock(arm, 4, 0.0)
    assert np.all(np.isfinite(jl.ee_pose(locked, np.zeros(locked.dof))))


def test_a_robot_given_on_the_command_line_is_relative_to_the_working_folder(tmp_path, monkeypatch):
    folder = tmp_path / "scenarios"
    folder.mkdir()
    scenario = _write(folder / "s.toml", 'robot = "puma6"\n[workspace]\nsamples = 1000\n')
    monkeypatch.chdir(tmp_path)
    _write(tmp_path / "arm.urdf", ARM5.read_text())
    assert jl.load_scenario(scenario, {"robot": "arm.urdf"}).data["robot"] == str(tmp_path / "arm.urdf")


def test_a_campaign_files_out_stays_in_its_folder(tmp_path):
    from jointlock.campaign import load_campaign

    body = 'scenario = "{}"\nout = "../../evil"\n[grid]\n"workspace.samples" = [1000, 2000]\n'
    scenario = _write(tmp_path / "s.toml", 'robot = "puma6"\n[workspace]\nsamples = 1000\n')
    with pytest.raises(JointlockError, match="out must be a folder inside the file's folder"):
        load_campaign(_write(tmp_path / "c.toml", body.format(scenario)))


def test_control_characters_in_a_model_name_are_refused(capsys, tmp_path):
    path = _write(
        tmp_path / "esc.toml", MODEL_TOML.replace('name = "t3"', 'name = "\\u001b[2J\\u001b[31mPWNED"')
    )
    assert_one_error_line(*cli(capsys, "kinematics", path)[::2], "control characters")


def test_a_urdf_without_links(capsys, tmp_path):
    path = _write(tmp_path / "empty.urdf", '<robot name="x"/>')
    assert_one_error_line(*cli(capsys, "kinematics", path)[::2], "no <link> found")


def test_a_task_too_fast_even_without_compensation(capsys, tmp_path):
    path = _write(tmp_path / "fast.toml", JUMP_TASK.replace("[1.2, -1.5, 0.8]", "[1000.0, 1000.0, 1000.0]"))
    code, _, err = cli(capsys, "jump", "canadarm7", "--scenario", path, "--fail-at", "3", "--quiet")
    assert_one_error_line(code, err, "kappa = 0", "the task itself is too fast")


def test_a_search_whose_candidates_are_large_kappas_runs(capsys, tmp_path):
    """A floating base's search scales its candidates with vmax / |grad w|: far above the bound
    on a user's kappa, and accepted (the bound is on what a user types)."""
    path = _write(tmp_path / "t.toml", JUMP_TASK)
    code, out, err = cli(
        capsys,
        "jump",
        "canadarm7",
        "--base",
        "floating",
        "--scenario",
        path,
        "--fail-at",
        "3",
        "--json",
        "--quiet",
    )
    assert code in (0, 2) and "kappa must be finite" not in err, err


@pytest.mark.parametrize(
    ("text", "words"),
    [
        ("hi", "not a scheduler's JSON"),
        ("{}", "no scheduler address"),
        ('{"address": 5}', "no scheduler address"),
    ],
)
def test_a_dask_scheduler_file_that_is_not_one(tmp_path, text, words):
    pytest.importorskip("distributed")
    from jointlock.campaign._engines import dask_cluster

    with pytest.raises(JointlockError, match=words):
        dask_cluster(scheduler_file=str(_write(tmp_path / "scheduler.json", text)))
