"""The chain of a URDF tree from the command line and from a scenario (issue 15, item 1):
``--root LINK``, ``--tip LINK``, ``--freeze JOINT=VALUE`` (degrees for a revolute joint,
metres for a prismatic one) on the commands taking a ROBOT, and the scenario fields
``root_link``, ``tip_link``, ``freeze_deg``, ``freeze_m``.  Robots: the Franka Panda and Baxter
of the ``example-robot-data`` package; oracle: Pinocchio's reading of the same file with the
same joints locked."""

from __future__ import annotations

import json
import math
import shlex

import numpy as np
import pytest
from robot_data import BAXTER, PANDA, robot_file

import jointlock as jl
from jointlock.cli import main
from jointlock.errors import ScenarioError
from jointlock.scenario import load_scenario

PANDA_ARM = [f"panda_joint{i}" for i in range(1, 8)]


def _pinocchio_tip(path, keep: list[str], values: dict[str, float], tip: str, q: np.ndarray) -> np.ndarray:
    """Pinocchio's pose (4, 4) of frame ``tip`` at ``q`` (the joints ``keep``), every other
    joint of the file locked at ``values`` (0 otherwise)."""
    pin = pytest.importorskip("pinocchio")
    from pin_oracle import reduced_model

    reduced = reduced_model(pin.buildModelFromUrdf(str(path)), keep, values)
    data = reduced.createData()
    pin.framesForwardKinematics(reduced, data, q)
    return data.oMf[reduced.getFrameId(tip)].homogeneous


def _json(capsys, *argv: str) -> dict:
    assert main([*argv, "--json"]) == 0, capsys.readouterr().err
    return json.loads(capsys.readouterr().out)


@pytest.mark.oracle
def test_kinematics_of_the_panda_to_its_hand_fingers_in_metres_a_joint_in_degrees(capsys):
    """``--freeze`` takes metres for the prismatic finger and degrees for revolute joint 7:
    the pose printed is Pinocchio's with the finger (and its mimic) at 0.02 m and joint 7 at
    30 deg."""
    path = robot_file(PANDA)
    q_deg = [10.0, -40.0, 20.0, -120.0, 15.0, 100.0]
    out = _json(
        capsys, "kinematics", str(path), "--tip", "panda_hand", "--freeze", "panda_finger_joint1=0.02",
        "--freeze", "panda_joint7=30", "--q-deg", *map(str, q_deg),
    )  # fmt: skip
    assert out["robot"] == "panda" and out["joint_numbers"] == [1, 2, 3, 4, 5, 6]
    values = {"panda_finger_joint1": 0.02, "panda_finger_joint2": 0.02, "panda_joint7": math.radians(30)}
    expected = _pinocchio_tip(path, PANDA_ARM[:6], values, "panda_hand", np.radians(q_deg))
    np.testing.assert_allclose(out["pose"], expected, atol=1e-10)
    assert np.max(np.abs(np.array(out["pose"]) - _pinocchio_tip(path, PANDA_ARM[:6], {}, "panda_hand", np.radians(q_deg)))) > 1e-3


@pytest.mark.oracle
def test_export_urdf_of_baxter_s_left_arm_from_the_torso(tmp_path, capsys):
    """``--root torso --tip left_gripper``: the exported arm, read back, places the gripper
    where Pinocchio puts it in the torso's frame, the right arm frozen by ``--freeze``."""
    pin = pytest.importorskip("pinocchio")
    path = robot_file(BAXTER)
    target = tmp_path / "left.urdf"
    out = _json(
        capsys, "export-urdf", str(path), "--root", "torso", "--tip", "left_gripper", "--freeze", "right_e1=60",
        "--out", str(target),
    )  # fmt: skip
    assert out["joint_numbers"] == list(range(1, 8))
    arm = jl.read_urdf(target)
    keep = ["left_s0", "left_s1", "left_e0", "left_e1", "left_w0", "left_w1", "left_w2"]
    q = np.array([0.3, -0.5, 0.2, 1.1, -0.4, 0.6, 0.1])
    world_tip = _pinocchio_tip(path, keep, {"right_e1": math.radians(60)}, "left_gripper", q)
    full = pin.buildModelFromUrdf(str(path))
    data = full.createData()
    pin.framesForwardKinematics(full, data, pin.neutral(full))
    world_torso = data.oMf[full.getFrameId("torso")].homogeneous  # above every movable joint
    np.testing.assert_allclose(world_torso @ jl.ee_pose(arm, q), world_tip, atol=1e-10)


@pytest.mark.parametrize(
    "argv, words",
    [
        (["kinematics", "halt7", "--tip", "x"], ["--root, --tip and --freeze choose the chain of a URDF robot", "'halt7' is a built-in robot"]),
        (["export-urdf", "puma6", "--freeze", "j=1", "--out", "x.urdf"], ["'puma6' is a built-in robot"]),
        (["kinematics", "PANDA", "--freeze", "panda_finger_joint1=0.01", "--freeze", "panda_finger_joint1=0.02"], ["--freeze: joint 'panda_finger_joint1' given twice"]),
        (["kinematics", "PANDA", "--freeze", "nope=1"], ["freeze names joint 'nope', which is not in the robot"]),
        (["kinematics", "PANDA", "--tip", "panda_leftfinger"], ["joint 'panda_finger_joint1' on the chain is prismatic", "--freeze panda_finger_joint1=METRES"]),
        (["kinematics", "PANDA", "--tip", "panda_hnd"], ["tip_link 'panda_hnd' is not a link of the robot (did you mean 'panda_hand'?)"]),
        (["kinematics", "PANDA", "--tip", "panda_hand", "--freeze", "panda_fingerjoint1=0.01"], ["which is not in the robot (did you mean 'panda_finger_joint1'?)"]),
        (["kinematics", "PANDA", "--tip", "panda_hand", "--freeze", "panda_finger_joint1=1"], ["'panda_finger_joint1' is frozen at 1 m", "outside its limits [0, 0.04] m"]),
        (["kinematics", "PANDA", "--freeze", "panda_finger_joint1"], ["--freeze must look like JOINT=VALUE"]),
        (["kinematics", "PANDA", "--tip", "panda_hand", "--freeze", "panda_joint4=10"], ["'panda_joint4' is frozen at 10 deg", "outside its limits [-176.", "] deg"]),
    ],
)
def test_a_chain_option_that_cannot_apply_is_one_error_line(capsys, argv, words):
    argv = [str(robot_file(PANDA)) if a == "PANDA" else a for a in argv]
    try:
        code = main(argv)
    except SystemExit as exc:  # a usage error (argparse)
        code = exc.code
    assert code == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "Traceback" not in err, err
    for w in words:
        assert w in err, err


def _scenario(tmp_path, head: str) -> str:
    path = tmp_path / "s.toml"
    path.write_text(head + "\n[singular]\nq_deg = [10, -40, 20, -120, 15, 100, 45]\n")
    return str(path)


@pytest.mark.oracle
def test_a_scenario_names_the_chain_of_a_urdf_and_its_jobs_use_it(tmp_path, capsys):
    """``robot = panda.urdf`` with ``tip_link`` and ``freeze_m`` (the fingers):
    the scenario loads that chain and ``jointlock run`` analyses it (its Jacobian's singular
    values are Pinocchio's; a chain without the fingers frozen would refuse to load)."""
    pin = pytest.importorskip("pinocchio")
    path = robot_file(PANDA)
    head = f'robot = {json.dumps(str(path))}\ntip_link = "panda_hand"\nfreeze_m = {{ panda_finger_joint1 = 0.03 }}\n'
    sc = load_scenario(_scenario(tmp_path, head))
    assert sc.data["tip_link"] == "panda_hand" and sc.data["freeze_m"] == {"panda_finger_joint1": 0.03}
    results = _json(capsys, "run", _scenario(tmp_path, head), "--out", str(tmp_path / "out"), "--quiet")
    got = results["jobs"]["singular"]["result"]["singular_values"]
    from pin_oracle import reduced_model

    fingers = {"panda_finger_joint1": 0.03, "panda_finger_joint2": 0.03}
    reduced = reduced_model(pin.buildModelFromUrdf(str(path)), PANDA_ARM, fingers)
    data = reduced.createData()
    q = np.radians([10, -40, 20, -120, 15, 100, 45])
    jac = pin.computeFrameJacobian(reduced, data, q, reduced.getFrameId("panda_hand"), pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
    np.testing.assert_allclose(got, np.linalg.svd(jac, compute_uv=False), atol=1e-10)
    # the command the run records for the job names the same chain, and gives the same values
    command = results["jobs"]["singular"]["command"]
    assert "--tip panda_hand" in command and "--freeze panda_finger_joint1=0.03" in command
    argv = shlex.split(command)[1:]  # without "jointlock"
    if "--out" in argv:  # the recorded run writes its files; here only its numbers are wanted
        k = argv.index("--out")
        del argv[k : k + 2]
    again = _json(capsys, *[a for a in argv if a not in ("--json", "--quiet")])
    np.testing.assert_allclose(again["singular_values"], got, atol=1e-12)


@pytest.mark.parametrize(
    "head, words",
    [
        ('robot = "puma6"\ntip_link = "x"', ["s.toml: tip_link: chooses the chain of a URDF robot", "'puma6' is a built-in robot"]),
        ('robot = "PANDA"\ntip_link = "panda_hand"\nfreeze_deg = 3', ["freeze_deg must be a table {joint name = value} of finite numbers >= -360 and <= 360 [deg]"]),
        ('robot = "PANDA"\ntip_link = "panda_hand"\nfreeze_m = { panda_finger_joint1 = "a" }', ["freeze_m.panda_finger_joint1 must be"]),
        ('robot = "PANDA"\ntip_link = "panda_hand"\nfreeze_deg = { panda_finger_joint1 = 1 }', ["robot: cannot load", "joint 'panda_finger_joint1' is prismatic: give it in freeze_m"]),
        ('robot = "PANDA"\ntip_link = 3', ["tip_link must be a string"]),
        ('robot = "PANDA"\ntip_link = ""', ["s.toml: tip_link must name a link of the URDF; got an empty string"]),
    ],
)
def test_a_scenario_s_chain_fields_are_checked(tmp_path, head, words):
    head = head.replace('"PANDA"', json.dumps(str(robot_file(PANDA))))
    with pytest.raises(ScenarioError) as info:
        load_scenario(_scenario(tmp_path, head))
    assert "\n" not in str(info.value)
    for w in words:
        assert w in str(info.value), str(info.value)


def test_the_header_names_the_joints_left_to_move(capsys):
    """A joint frozen on the chain renumbers the others 1..n: the header says which URDF joint
    each number is (a built-in's joints keep the plain header)."""
    argv = ["kinematics", str(robot_file(PANDA)), "--tip", "panda_link7", "--freeze", "panda_joint4=-90"]
    assert main(argv) == 0
    first = capsys.readouterr().out.splitlines()[0]
    assert "6 movable joints [1, 2, 3, 4, 5, 6] (panda_joint1, panda_joint2, panda_joint3, panda_joint5," in first
    assert main(["kinematics", "puma6"]) == 0
    assert capsys.readouterr().out.splitlines()[0] == "puma6: 6 movable joints [1, 2, 3, 4, 5, 6], locked: none, base: fixed"
