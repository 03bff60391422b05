"""URDF as people have it (issue 15, item 1): trees (two arms), grippers (prismatic fingers, a
<mimic> pair), a sensor on a fixed joint.  The chain from root_link to tip_link moves; every
other joint is frozen and merged.  Oracle: Pinocchio reads the same XML itself and locks the
same joints at the same values (``buildReducedModel``)."""

from __future__ import annotations

import numpy as np
import pytest

import jointlock as jl
from jointlock.errors import ModelError


def _inertial(mass: float, com: tuple[float, float, float], moments: tuple[float, float, float]) -> str:
    x, y, z = com
    ixx, iyy, izz = moments
    return (
        f'<inertial><origin xyz="{x} {y} {z}" rpy="0.1 0.2 0.3"/><mass value="{mass}"/>'
        f'<inertia ixx="{ixx}" ixy="{0.05 * ixx}" ixz="0" iyy="{iyy}" iyz="{0.05 * iyy}" izz="{izz}"/></inertial>'
    )


def _link(name: str, mass: float = 0.0, com=(0.0, 0.0, 0.0), moments=(0.01, 0.02, 0.03)) -> str:
    return f'<link name="{name}">{_inertial(mass, com, moments) if mass else ""}</link>'


def _joint(name: str, kind: str, parent: str, child: str, xyz: str, axis: str = "0 0 1", extra: str = "") -> str:
    limit = '<limit lower="-2.5" upper="2.5" effort="100" velocity="1"/>' if kind == "revolute" else ""
    if kind == "prismatic":
        limit = '<limit lower="0" upper="0.04" effort="20" velocity="0.1"/>'
    return (
        f'<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
        f'<origin xyz="{xyz}" rpy="0.05 -0.1 0.2"/><axis xyz="{axis}"/>{limit}{extra}</joint>'
    )


def _arm(side: str, sign: float) -> str:
    s = side
    return "".join(
        [
            _link(f"{s}_upper", 3.0, (0.0, 0.0, 0.15), (0.05, 0.05, 0.01)),
            _link(f"{s}_fore", 2.0, (0.0, 0.01, 0.12), (0.03, 0.03, 0.005)),
            _link(f"{s}_hand", 0.8, (0.01, 0.0, 0.04), (0.002, 0.003, 0.002)),
            _link(f"{s}_finger_a", 0.1, (0.0, 0.01, 0.02), (1e-4, 1e-4, 1e-4)),
            _link(f"{s}_finger_b", 0.1, (0.0, -0.01, 0.02), (1e-4, 1e-4, 1e-4)),
            _link(f"{s}_tcp"),
            _joint(f"{s}1", "revolute", "torso", f"{s}_upper", f"0 {0.3 * sign} 0.4", "0 1 0"),
            _joint(f"{s}2", "revolute", f"{s}_upper", f"{s}_fore", "0 0 0.4", "0 1 0"),
            _joint(f"{s}3", "continuous", f"{s}_fore", f"{s}_hand", "0 0 0.3", "1 0 0"),
            _joint(f"{s}_finger_a", "prismatic", f"{s}_hand", f"{s}_finger_a", "0 0.02 0.08", "0 1 0"),
            _joint(f"{s}_finger_b", "prismatic", f"{s}_hand", f"{s}_finger_b", "0 -0.02 0.08", "0 -1 0",
                   f'<mimic joint="{s}_finger_a" multiplier="1.0" offset="0.0"/>'),  # fmt: skip
            _joint(f"{s}_tcp_joint", "fixed", f"{s}_hand", f"{s}_tcp", "0 0 0.12"),
        ]
    )


#: A dual-arm robot on a torso that turns, each arm ending in a two-finger gripper, a camera.
DUAL_ARM = (
    '<robot name="dual">'
    + _link("base", 50.0, (0.0, 0.0, 0.1), (2.0, 2.0, 3.0))
    + _link("torso", 10.0, (0.0, 0.0, 0.3), (0.5, 0.4, 0.2))
    + _link("camera", 0.5, (0.02, 0.0, 0.0), (1e-3, 1e-3, 1e-3))
    + _joint("torso_yaw", "revolute", "base", "torso", "0 0 0.5")
    + _joint("camera_mount", "fixed", "torso", "camera", "0.1 0 0.7")
    + _arm("l", 1.0)
    + _arm("r", -1.0)
    + "</robot>"
)


def _pinocchio_chain(xml: str, keep: list[str], values: dict[str, float], tip: str):
    """Pinocchio's own reading of ``xml`` with every joint but ``keep`` locked at ``values``
    (0 otherwise): (model, data, frame id of ``tip``)."""
    pin = pytest.importorskip("pinocchio")
    from pin_oracle import reduced_model

    reduced = reduced_model(pin.buildModelFromXML(xml), keep, values)
    return reduced, reduced.createData(), reduced.getFrameId(tip)


def _compare(model: jl.ArmModel, reduced, data, fid, rng) -> None:
    pin = pytest.importorskip("pinocchio")
    for q in rng.uniform(-2.0, 2.0, (5, model.dof)):
        pq = np.concatenate([[np.cos(v), np.sin(v)] if reduced.joints[i + 1].nq == 2 else [v] for i, v in enumerate(q)])
        pin.forwardKinematics(reduced, data, pq)
        pin.updateFramePlacements(reduced, data)
        np.testing.assert_allclose(jl.ee_pose(model, q), data.oMf[fid].homogeneous, atol=1e-12)
        jac = pin.computeFrameJacobian(reduced, data, pq, fid, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
        np.testing.assert_allclose(jl.jacobian(model, q), jac, atol=1e-12)
        np.testing.assert_allclose(jl.mass_matrix(model, q), pin.crba(reduced, data, pq), atol=1e-10)


def test_a_tree_needs_its_tip_named():
    with pytest.raises(ModelError, match=r"the tree branches at link 'torso' into joints \['l1', 'r1'\]; name the chain's end with tip_link"):
        jl.read_urdf(DUAL_ARM)


@pytest.mark.oracle
def test_one_arm_of_a_dual_arm_robot_equals_pinocchio_with_the_rest_locked():
    """The left arm to its tool point: the right arm frozen at 0 except r2 at 0.4 rad, the left
    fingers at 2 cm (the mimic finger following), the camera merged."""
    freeze = {"r2": 0.4, "l_finger_a": 0.02}
    model = jl.read_urdf(DUAL_ARM, tip_link="l_tcp", freeze=freeze)
    assert [j.name for j in model.joints] == ["torso_yaw", "l1", "l2", "l3"]
    assert "frozen:" in model.description and "r2 = 0.4" in model.description
    reduced, data, fid = _pinocchio_chain(
        DUAL_ARM, ["torso_yaw", "l1", "l2", "l3"], {**freeze, "l_finger_b": 0.02}, "l_tcp"
    )
    _compare(model, reduced, data, fid, np.random.default_rng(0))
    total = 50 + 10 + 0.5 + 2 * (3 + 2 + 0.8 + 0.2)
    assert model.total_mass == pytest.approx(total)  # nothing lost, nothing counted twice


@pytest.mark.oracle
def test_a_chain_from_a_link_inside_the_tree():
    """root_link = the torso: the base and the torso joint are left out; the right arm hangs
    from the chain's root body."""
    model = jl.read_urdf(DUAL_ARM, root_link="torso", tip_link="r_hand")
    assert [j.name for j in model.joints] == ["r1", "r2", "r3"] and "left out" in model.description
    pin = pytest.importorskip("pinocchio")
    full = pin.buildModelFromXML(DUAL_ARM)
    q_ref = pin.neutral(full)
    lock = [full.getJointId(n) for n in full.names[1:] if n not in ("torso_yaw", "r1", "r2", "r3")]
    reduced = pin.buildReducedModel(full, lock, q_ref)
    data = reduced.createData()
    fid = reduced.getFrameId("r_hand")
    rng = np.random.default_rng(1)
    for q in rng.uniform(-2.0, 2.0, (4, 3)):
        pq = np.concatenate([[0.0], q[:2], [np.cos(q[2]), np.sin(q[2])]])
        pin.forwardKinematics(reduced, data, pq)
        pin.updateFramePlacements(reduced, data)
        torso = data.oMi[1].homogeneous  # the torso joint at 0: the chain's root frame
        np.testing.assert_allclose(torso @ jl.ee_pose(model, q), data.oMf[fid].homogeneous, atol=1e-12)


@pytest.mark.parametrize(
    "kwargs, match",
    [
        ({"tip_link": "l_finger_a"}, r"joint 'l_finger_a' on the chain is prismatic; .*freeze it"),
        ({"tip_link": "l_finger_b", "freeze": {"l_finger_a": 0.01}}, r"joint 'l_finger_b' on the chain mimics 'l_finger_a'"),
        ({"tip_link": "nowhere"}, r"tip_link 'nowhere' is not a link"),
        ({"root_link": "l_hand", "tip_link": "r_tcp"}, r"tip_link 'r_tcp' is not below root_link 'l_hand'"),
        ({"tip_link": "l_tcp", "freeze": {"nope": 1.0}}, r"freeze names joint 'nope', which is not in the robot"),
        ({"tip_link": "l_tcp", "freeze": {"l_tcp_joint": 1.0}}, r"'l_tcp_joint', which is fixed already"),
        ({"tip_link": "l_tcp", "freeze": {"r1": 3.0}}, r"joint 'r1' is frozen at 3 rad \(off the chain, or named in freeze\), outside its limits \[-2.5, 2.5\] rad"),
        ({"tip_link": "l_tcp", "ee_link": "r_tcp"}, r"ee_link 'r_tcp' and tip_link 'l_tcp' differ"),
    ],
)
def test_a_chain_that_cannot_be_made_is_refused_naming_why(kwargs, match):
    with pytest.raises(ModelError, match=match):
        jl.read_urdf(DUAL_ARM, **kwargs)


def test_a_serial_arm_reads_as_before():
    """No tree, no selection: the chain is the one path (what read_urdf always did)."""
    xml = (
        '<robot name="s">' + _link("a", 5.0) + _link("b", 1.0) + _link("c", 1.0) + _link("tool")
        + _joint("j1", "revolute", "a", "b", "0 0 0.3") + _joint("j2", "continuous", "b", "c", "0 0 0.4", "0 1 0")
        + _joint("t", "fixed", "c", "tool", "0 0 0.1") + "</robot>"
    )  # fmt: skip
    model = jl.read_urdf(xml)
    assert [j.name for j in model.joints] == ["j1", "j2"]
    np.testing.assert_allclose(model.tool[:3, 3], jl.read_urdf(xml, tip_link="tool").tool[:3, 3])


def test_a_model_file_names_the_chain_so_every_command_takes_it(tmp_path, capsys):
    """The TOML model form ``urdf = ...`` with root_link, tip_link and the frozen joints in
    degrees and metres: load_robot and the command line take it like any model file."""
    import json

    from jointlock.cli import main

    (tmp_path / "dual.urdf").write_text(DUAL_ARM)
    model_file = tmp_path / "left.toml"
    model_file.write_text(
        'name = "dual-left"\nurdf = "dual.urdf"\ntip_link = "l_tcp"\n'
        "freeze_deg = { r2 = 22.918311805232928 }\nfreeze_m = { l_finger_a = 0.02 }\n"
    )
    direct = jl.read_urdf(DUAL_ARM, tip_link="l_tcp", freeze={"r2": 0.4, "l_finger_a": 0.02})
    loaded = jl.load_robot(str(model_file))
    assert loaded.name == "dual-left" and not loaded.floating and loaded.dof == 4
    q = np.array([0.1, -0.2, 0.3, 0.4])
    np.testing.assert_allclose(jl.ee_pose(loaded, q), jl.ee_pose(direct, q), atol=1e-12)
    floating = jl.load_robot(str(model_file), base="floating")
    assert floating.floating and floating.root_body.mass == pytest.approx(50.0)
    assert main(["kinematics", str(model_file), "--q-deg", "10", "20", "30", "40", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["robot"] == "dual-left"
    model_file.write_text('urdf = "dual.urdf"\nfreeze_deg = { r2 = "a" }\n')
    with pytest.raises(ModelError, match=r"freeze_deg\.r2"):
        jl.read_model_toml(model_file)


def test_review_fixes_units_mimic_followers_and_a_changed_urdf(tmp_path):
    """freeze_deg / freeze_m are checked against the joint's type; a mimic follower is no
    branch (the default tip passes a gripper whose master finger is frozen); a model file
    naming a URDF sees the URDF's edits; a joint above root_link cannot be frozen."""
    model = jl.read_urdf(DUAL_ARM, root_link="l_upper", freeze={"l_finger_a": 0.01})
    assert [j.name for j in model.joints] == ["l2", "l3"] and "'l_tcp'" in model.description
    with pytest.raises(ModelError, match=r"not below root_link 'l_upper'"):
        jl.read_urdf(DUAL_ARM, root_link="l_upper", freeze={"l_finger_a": 0.01, "r1": 0.1})
    (tmp_path / "dual.urdf").write_text(DUAL_ARM)
    model_file = tmp_path / "m.toml"
    model_file.write_text('urdf = "dual.urdf"\ntip_link = "l_tcp"\nfreeze_m = { r2 = 0.4 }\n')
    with pytest.raises(ModelError, match=r"m.toml: .*dual.urdf: joint 'r2' is revolute: give it in freeze_deg"):
        jl.load_robot(str(model_file))
    model_file.write_text('urdf = "dual.urdf"\ntip_link = "l_tcp"\nfreeze_deg = { l_finger_a = 1.0 }\n')
    with pytest.raises(ModelError, match=r"joint 'l_finger_a' is prismatic: give it in freeze_m"):
        jl.load_robot(str(model_file))
    model_file.write_text('urdf = "dual.urdf"\ntip_link = "l_tcp"\n')
    before = jl.load_robot(str(model_file)).tool[2, 3]
    (tmp_path / "dual.urdf").write_text(DUAL_ARM.replace('"0 0 0.12"', '"0 0 0.5"'))
    assert jl.load_robot(str(model_file)).tool[2, 3] != pytest.approx(before)
