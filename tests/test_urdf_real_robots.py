"""URDF as people have it (issue 15, item 1), on real robots: the URDFs shipped in the
``example-robot-data`` package on PyPI (Franka Panda: an arm with a two-finger gripper whose
second finger is a ``<mimic>``; Baxter: two arms on a torso, grippers, sensors, ``<gazebo>``
and ``<transmission>`` tags, mesh paths).  Oracle: Pinocchio reads the same file itself and
locks the same joints at the same values (``buildReducedModel``); the chain read by
:func:`jointlock.read_urdf` must give the same tip pose, 6xn geometric Jacobian and joint-space
mass matrix at random configurations within the limits.  Skipped, saying why, without
example-robot-data or Pinocchio."""

from __future__ import annotations

import math

import numpy as np
import pytest
from robot_data import BAXTER, PANDA, TIAGO_DUAL, robot_file

import jointlock as jl

pytestmark = pytest.mark.oracle

#: Pinocchio oracle agreement (round-off of two independent computations).
ATOL = 1e-10
PANDA_ARM = [f"panda_joint{i}" for i in range(1, 8)]
BAXTER_LEFT = ["left_s0", "left_s1", "left_e0", "left_e1", "left_w0", "left_w1", "left_w2"]


def _pinocchio_reduced(path, keep: list[str], values: dict[str, float]):
    """Pinocchio's own reading of the file with every joint but ``keep`` locked at ``values``
    (0 otherwise; mimic tags ignored, so a follower's value is given here): (model, data)."""
    pin = pytest.importorskip("pinocchio")
    from pin_oracle import reduced_model

    reduced = reduced_model(pin.buildModelFromUrdf(str(path)), keep, values)
    return reduced, reduced.createData()


def _deviations(model: jl.ArmModel, reduced, data, root: str, tip: str, n: int = 6, seed: int = 0) -> dict[str, float]:
    """Largest |ours - Pinocchio| of the tip pose, the Jacobian (twist about the tip origin,
    world axes) and the mass matrix over ``n`` configurations drawn within the joint limits.
    Our chain starts at ``root``: its pose in Pinocchio's world (fixed: every joint above it is
    locked) maps our frame to Pinocchio's."""
    pin = pytest.importorskip("pinocchio")
    rng = np.random.default_rng(seed)
    lower = np.array([j.lower for j in model.joints])
    upper = np.array([j.upper for j in model.joints])
    root_id, tip_id = reduced.getFrameId(root), reduced.getFrameId(tip)
    worst = {"pose": 0.0, "jacobian": 0.0, "mass_matrix": 0.0}
    for q in rng.uniform(lower, upper, (n, model.dof)):
        pq = np.concatenate([[math.cos(v), math.sin(v)] if reduced.joints[i + 1].nq == 2 else [v] for i, v in enumerate(q)])
        pin.forwardKinematics(reduced, data, pq)
        pin.updateFramePlacements(reduced, data)
        world_root = data.oMf[root_id].homogeneous
        rot = np.kron(np.eye(2), world_root[:3, :3])  # both halves of the twist to world axes
        jac = pin.computeFrameJacobian(reduced, data, pq, tip_id, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
        deviation = {
            "pose": world_root @ jl.ee_pose(model, q) - data.oMf[tip_id].homogeneous,
            "jacobian": rot @ jl.jacobian(model, q) - jac,
            "mass_matrix": jl.mass_matrix(model, q) - pin.crba(reduced, data, pq),
        }
        for key, d in deviation.items():
            worst[key] = max(worst[key], float(np.max(np.abs(d))))
    print(f"{model.name} {root}->{tip}: max |ours - Pinocchio| " + ", ".join(f"{k} {v:.1e}" for k, v in worst.items()))
    return worst


def test_panda_arm_to_its_hand_equals_pinocchio_fingers_frozen_and_merged():
    """The Panda to ``panda_hand``, fingers frozen at 2 cm (the mimic finger following): tip
    pose, Jacobian and mass matrix as Pinocchio's; the fingers' mass is in the model (its total
    mass is the reduced Pinocchio model's, the fixed base included)."""
    path = robot_file(PANDA)
    model = jl.read_urdf(path, tip_link="panda_hand", freeze={"panda_finger_joint1": 0.02})
    assert [j.name for j in model.joints] == PANDA_ARM
    reduced, data = _pinocchio_reduced(path, PANDA_ARM, {"panda_finger_joint1": 0.02, "panda_finger_joint2": 0.02})
    worst = _deviations(model, reduced, data, "panda_link0", "panda_hand")
    assert max(worst.values()) < ATOL, worst
    pin_total = sum(inertia.mass for inertia in reduced.inertias)  # inertias[0]: the links fixed to the world
    assert model.total_mass == pytest.approx(pin_total, abs=1e-12)
    fingers = 2 * 0.015  # each finger link's <mass value="0.015"/>
    assert model.total_mass == pytest.approx(jl.read_urdf(path, tip_link="panda_hand").total_mass)
    assert model.bodies[-1].mass > fingers  # the hand and both fingers ride on joint 7's body


def test_panda_mimic_finger_follows_its_leader_when_frozen():
    """``panda_finger_joint2`` mimics ``panda_finger_joint1`` (multiplier 1, offset 0): with
    the leader frozen at v the follower's link sits at v too, so the body merged onto joint 7
    equals Pinocchio's with both fingers at v -- and differs from the follower left at 0."""
    pin = pytest.importorskip("pinocchio")
    path = robot_file(PANDA)
    v = 0.03
    model = jl.read_urdf(path, tip_link="panda_hand", freeze={"panda_finger_joint1": v})
    assert model.description.count("panda_finger_joint2 = 0.03") == 1
    ours = model.bodies[-1]  # in joint 7's frame, as Pinocchio's inertia of its joint 7

    def pin_body(follower: float) -> np.ndarray:
        reduced, _ = _pinocchio_reduced(path, PANDA_ARM, {"panda_finger_joint1": v, "panda_finger_joint2": follower})
        return reduced.inertias[7].matrix()

    mine = pin.Inertia(ours.mass, ours.com.copy(), ours.inertia.copy()).matrix()
    deviation = float(np.max(np.abs(mine - pin_body(v))))
    print(f"panda joint-7 body with the mimic finger at {v} m: max |ours - Pinocchio| {deviation:.1e}")
    assert deviation < ATOL
    assert np.max(np.abs(mine - pin_body(0.0))) > 1e-5  # the check sees where the follower is
    reduced, data = _pinocchio_reduced(path, PANDA_ARM, {"panda_finger_joint1": v, "panda_finger_joint2": v})
    tip = jl.read_urdf(path, tip_link="panda_rightfinger", freeze={"panda_finger_joint1": v, "panda_finger_joint2": v})
    worst = _deviations(tip, reduced, data, "panda_link0", "panda_rightfinger", n=3)
    assert max(worst.values()) < ATOL, worst


@pytest.mark.parametrize(
    "tip, freeze, match",
    [
        ("panda_leftfinger", {}, r"joint 'panda_finger_joint1' on the chain is prismatic; .*freeze it"),
        ("panda_rightfinger", {}, r"joint 'panda_finger_joint2' on the chain mimics 'panda_finger_joint1'"),
        ("panda_rightfinger", {"panda_finger_joint1": 0.01}, r"joint 'panda_finger_joint2' on the chain mimics"),
    ],
)
def test_panda_chain_to_a_finger_is_refused_in_one_line_naming_the_joint(tip, freeze, match):
    path = robot_file(PANDA)
    with pytest.raises(jl.ModelError, match=match) as info:
        jl.read_urdf(path, tip_link=tip, freeze=freeze)
    assert "\n" not in str(info.value)


def test_panda_limits_are_the_urdf_s_past_pi_included():
    """Every limit read equals Pinocchio's reading of the file (joint 6 up to 3.7525 rad, past
    pi: kept, not cut to pi), velocity and effort limits too."""
    pin = pytest.importorskip("pinocchio")
    path = robot_file(PANDA)
    model = jl.read_urdf(path, tip_link="panda_hand")
    full = pin.buildModelFromUrdf(str(path))
    ids = [full.getJointId(n) for n in PANDA_ARM]
    idx = [full.joints[i].idx_q for i in ids]
    np.testing.assert_array_equal([j.lower for j in model.joints], full.lowerPositionLimit[idx])
    np.testing.assert_array_equal([j.upper for j in model.joints], full.upperPositionLimit[idx])
    np.testing.assert_array_equal([j.velocity_limit for j in model.joints], full.velocityLimit[idx])
    np.testing.assert_array_equal([j.effort_limit for j in model.joints], full.effortLimit[idx])
    assert model.joints[5].upper == 3.7525 > math.pi and model.joints[5].lower == -0.0175


def test_baxter_left_arm_from_the_torso_equals_pinocchio_other_arm_frozen():
    """Baxter (a tree: head, two arms, grippers, sonar, cameras) from ``torso`` to the left
    gripper's end point; the right arm frozen at a pose, the head turned, the left fingers
    open (the mimic finger following), everything else at 0 and merged."""
    path = robot_file(BAXTER)
    freeze = {"right_s0": 0.3, "right_e1": 1.2, "head_pan": -0.4, "l_gripper_l_finger_joint": 0.01}
    model = jl.read_urdf(path, root_link="torso", tip_link="left_gripper", freeze=freeze)
    assert [j.name for j in model.joints] == BAXTER_LEFT
    assert "links above the root left out" in model.description
    # Pinocchio ignores <mimic>: the follower's value (multiplier -1 in this file) is given here.
    follower = {"l_gripper_r_finger_joint": -0.01}
    reduced, data = _pinocchio_reduced(path, BAXTER_LEFT, {**freeze, **follower})
    worst = _deviations(model, reduced, data, "torso", "left_gripper", seed=1)
    assert max(worst.values()) < ATOL, worst
    # The root body keeps the torso and all hanging from it (the right arm, head, sonar) but not the base.
    base_mass = sum(inertia.mass for inertia in reduced.inertias) - model.total_mass
    assert base_mass == pytest.approx(_link_mass(path, "base") + _link_mass(path, "collision_head_link_1") + _link_mass(path, "collision_head_link_2"), abs=1e-9)


def test_tiago_dual_left_arm_from_the_lifting_torso_equals_pinocchio():
    """TIAGo dual (mobile base with wheels and casters, a prismatic torso lift, a head, two
    arms with many-jointed hands): the left arm from ``torso_lift_link`` to its tool link,
    the lift frozen at 0.2 m, the right arm frozen at a pose."""
    pin = pytest.importorskip("pinocchio")
    path = robot_file(TIAGO_DUAL)
    freeze = {"torso_lift_joint": 0.2, "arm_right_2_joint": 0.5, "arm_right_4_joint": 1.0}
    keep = [f"arm_left_{i}_joint" for i in range(1, 8)]
    model = jl.read_urdf(path, root_link="torso_lift_link", tip_link="arm_left_tool_link", freeze=freeze)
    assert [j.name for j in model.joints] == keep
    full = pin.buildModelFromUrdf(str(path))
    values = dict(freeze)
    for name in full.names[1:]:  # a joint frozen at 0 outside its limits would be refused by read_urdf
        j = full.joints[full.getJointId(name)]
        if j.nq == 1 and name not in values and not full.lowerPositionLimit[j.idx_q] <= 0 <= full.upperPositionLimit[j.idx_q]:
            pytest.fail(f"{name}: 0 is outside its limits; freeze it")
    reduced, data = _pinocchio_reduced(path, keep, values)
    worst = _deviations(model, reduced, data, "torso_lift_link", "arm_left_tool_link", seed=2)
    assert max(worst.values()) < ATOL, worst


def _link_mass(path, link: str) -> float:
    """The ``<mass value>`` of ``link`` in the file (0 without an inertial)."""
    import xml.etree.ElementTree as ET

    for el in ET.parse(path).getroot().findall("link"):
        if el.get("name") == link:
            mass = el.find("inertial/mass")
            return float(mass.get("value")) if mass is not None else 0.0
    raise AssertionError(f"no link {link!r}")


def test_a_floating_joint_above_the_root_link_is_left_out():
    """A URDF written for a simulator joins a ``world`` link to the robot's base with a
    floating (or planar) joint: with ``root_link`` at the base it is left out (the chain as
    without it, Pinocchio's reading of the original file the oracle); below the root it is
    refused in one line naming it and saying where to start."""
    path = robot_file(PANDA)
    text = path.read_text()
    world = '<link name="world"/><joint name="world_joint" type="floating"><parent link="world"/><child link="panda_link0"/></joint>'
    xml = text.replace("</robot>", world + "</robot>")
    freeze = {"panda_finger_joint1": 0.02}
    # the text has no folder to find its meshes from: the kinematics are what is checked here
    model = jl.read_urdf(xml, root_link="panda_link0", tip_link="panda_hand", freeze=freeze, meshes="skip")
    assert "1 links above the root left out" in model.description
    reduced, data = _pinocchio_reduced(path, PANDA_ARM, {**freeze, "panda_finger_joint2": 0.02})
    worst = _deviations(model, reduced, data, "panda_link0", "panda_hand", n=3)
    assert max(worst.values()) < ATOL, worst
    with pytest.raises(jl.ModelError, match=r"joint 'world_joint': type 'floating' is not supported below root_link 'world' .*root_link = 'panda_link0'") as info:
        jl.read_urdf(xml, tip_link="panda_hand", freeze=freeze, meshes="skip")
    assert "\n" not in str(info.value)
    planar = xml.replace('type="floating"', 'type="planar"')
    assert jl.read_urdf(planar, root_link="panda_link0", tip_link="panda_hand", freeze=freeze, meshes="skip").dof == 7
