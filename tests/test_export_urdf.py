"""The crippled arm exported as URDF (issue 16, item 7): Pinocchio loads the file and gives the
locked model's FK, Jacobian, mass matrix (fixed base) and generalized Jacobian (free-flyer),
for every built-in with one and two locks; jointlock reads it back to the same model."""

from __future__ import annotations

import json

import numpy as np
import pytest
from conftest import ROBOT_NAMES, random_q

import jointlock as jl
from jointlock.io.urdf_export import rpy_from_matrix, urdf_text, write_urdf
from jointlock.spatial import rpy_matrix

LOCKS = [{}, {4: 0.3}, {2: -0.4, 5: 0.7}]


def _locked(name: str, locks: dict[int, float], base: str) -> jl.ArmModel:
    model = jl.load_robot(name, base=base)
    return jl.lock_joints(model, locks) if locks else model


@pytest.mark.oracle
@pytest.mark.parametrize("name", ROBOT_NAMES)
@pytest.mark.parametrize("locks", LOCKS, ids=["none", "one", "two"])
def test_pinocchio_loads_the_exported_arm_as_the_locked_model(tmp_path, rng, name, locks):
    pin = pytest.importorskip("pinocchio")
    model = _locked(name, locks, "floating")
    path = write_urdf(model, tmp_path / "arm.urdf")
    q = random_q(model, rng, (4,))
    # fixed base: pose, Jacobian and mass matrix
    pm = pin.buildModelFromUrdf(str(path))
    pm.gravity = pin.Motion.Zero()
    data, fid = pm.createData(), pm.getFrameId("tool")
    fixed = model.fixed()
    for qi in q:
        pin.forwardKinematics(pm, data, qi)
        pin.updateFramePlacements(pm, data)
        np.testing.assert_allclose(data.oMf[fid].homogeneous, jl.ee_pose(fixed, qi), atol=1e-12)
        jac = pin.computeFrameJacobian(pm, data, qi, fid, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
        np.testing.assert_allclose(jac, jl.jacobian(fixed, qi), atol=1e-12)
        mass = pin.crba(pm, data, qi)
        mass = np.triu(mass) + np.triu(mass, 1).T
        np.testing.assert_allclose(mass, jl.mass_matrix(fixed, qi), atol=1e-9 * max(1.0, np.abs(mass).max()))
    # free-floating: the spacecraft is the root link's inertial
    pf = pin.buildModelFromUrdf(str(path), pin.JointModelFreeFlyer())
    dataf, fidf = pf.createData(), pf.getFrameId("tool")
    for qi in q:
        qq = np.concatenate([[0, 0, 0, 0, 0, 0, 1.0], qi])
        jac = pin.computeFrameJacobian(pf, dataf, qq, fidf, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
        mass = pin.crba(pf, dataf, qq)
        mass = np.triu(mass) + np.triu(mass, 1).T
        gen = jac[:, 6:] - jac[:, :6] @ np.linalg.solve(mass[:6, :6], mass[:6, 6:])
        np.testing.assert_allclose(gen, jl.generalized_jacobian(model, qi), atol=1e-10)


@pytest.mark.parametrize("name", ROBOT_NAMES)
@pytest.mark.parametrize("locks", LOCKS, ids=["none", "one", "two"])
@pytest.mark.parametrize("base", ["fixed", "floating"])
def test_jointlock_reads_the_exported_arm_back(rng, name, locks, base):
    model = _locked(name, locks, base)
    back = jl.read_urdf(urdf_text(model), base=base)
    assert back.dof == model.dof and back.floating == model.floating
    assert [j.name for j in back.joints] == [j.name for j in model.joints]
    np.testing.assert_allclose(back.lower, model.lower)
    np.testing.assert_allclose([j.velocity_limit for j in back.joints], [j.velocity_limit for j in model.joints])
    q = random_q(model, rng, (6,))
    np.testing.assert_allclose(jl.ee_pose(back, q), jl.ee_pose(model, q), atol=1e-12)
    np.testing.assert_allclose(jl.mass_matrix(back, q), jl.mass_matrix(model, q), atol=1e-9)
    if base == "floating":
        np.testing.assert_allclose(jl.generalized_jacobian(back, q), jl.generalized_jacobian(model, q), atol=1e-10)


def test_roll_pitch_yaw_inverts_the_urdf_rotation(rng):
    rpy = np.column_stack([rng.uniform(-np.pi, np.pi, 200), rng.uniform(-1.5, 1.5, 200), rng.uniform(-np.pi, np.pi, 200)])
    for angles in rpy:
        np.testing.assert_allclose(rpy_matrix(rpy_from_matrix(rpy_matrix(angles))), rpy_matrix(angles), atol=1e-12)
    for pitch in (np.pi / 2, -np.pi / 2):  # gimbal lock
        r = rpy_matrix([0.3, pitch, -0.2])
        np.testing.assert_allclose(rpy_matrix(rpy_from_matrix(r)), r, atol=1e-12)


def test_the_command_writes_the_file_and_says_what_it_holds(tmp_path, capsys):
    from jointlock.cli import main

    out = tmp_path / "h.urdf"
    assert main(["export-urdf", "halt7", "--lock", "4=0", "--lock", "2=10", "--base", "floating", "--out", str(out), "--json"]) == 0
    facts = json.loads(capsys.readouterr().out)
    assert facts["joint_numbers"] == [1, 3, 5, 6, 7] and facts["locked"] == {"4": 0.0, "2": pytest.approx(10.0)}
    text = out.read_text()
    assert "locked: joint 4 at 0 deg, joint 2 at 10 deg" in text and text.count('type="revolute"') == 5
    assert main(["export-urdf", "halt7", "--lock", "9=0", "--out", str(out)]) == 2
    assert "joint must be one of the movable joints" in capsys.readouterr().err


def test_odd_names_and_one_sided_limits_still_give_a_valid_file(tmp_path):
    pin = pytest.importorskip("pinocchio")
    arm = jl.from_dh('arm--"x"&<y>', a=[0.3, 0.2], alpha=[0, 0], d=[0, 0], convention="standard",
                     lower=[-np.inf, 0.5], upper=[1.0, 5.5],
                     bodies=[jl.Body(1.0, [0.1, 0, 0], [0.01] * 3)] * 2)  # fmt: skip
    path = write_urdf(arm, tmp_path / "odd.urdf")
    back = jl.read_urdf(path)
    assert back.name == arm.name and back.lower[0] == pytest.approx(1.0 - 2 * np.pi)  # one turn below
    model = pin.buildModelFromUrdf(str(path))
    assert model.nq == 2 and model.lowerPositionLimit[0] == pytest.approx(1.0 - 2 * np.pi)
