"""MJCF export (issue 30): every built-in arm, fixed and floating, locked and not, loads in
MuJoCo; MuJoCo's inverse dynamics of the file equal :func:`jointlock.rnea`; the floating
export's total mass, centre of mass and inertia equal the model's.  MuJoCo is a test-only
oracle here (the ``test`` extra brings it; the library writes the file without it)."""

from __future__ import annotations

import json
import math
import xml.etree.ElementTree as ET

import numpy as np
import pytest
from conftest import ROBOT_NAMES, random_q

import jointlock as jl
from jointlock.cli import main
from jointlock.dynamics import system_mass_matrix
from jointlock.kinematics import system_com
from jointlock.mjcf import mjcf_text, quaternion_from_matrix, write_mjcf

mujoco = pytest.importorskip("mujoco")

#: mj_inverse against jl.rnea, relative to the largest torque (the issue's bound; measured ~3e-15).
INVERSE_RTOL = 1e-10


def _load(text: str, constraints: bool = True):
    model = mujoco.MjModel.from_xml_string(text)
    if not constraints:  # contacts and limits would add constraint forces to mj_inverse
        model.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONSTRAINT
    return model, mujoco.MjData(model)


def _variants(name: str):
    for base in ("fixed", "floating"):
        arm = jl.load_robot(name, base=base)
        yield base, arm
        yield base, jl.lock(arm, 3, math.radians(20))
        yield base, jl.lock_joints(arm, {2: -0.4, arm.dof: 0.7})


@pytest.mark.parametrize("name", ROBOT_NAMES)
def test_every_builtin_export_loads(name):
    for base, model in _variants(name):
        for brakes in (False, True) if model.locked else (False,):
            mm, _ = _load(mjcf_text(model, brakes=brakes))
            free = 1 if base == "floating" else 0
            chain = model.unlocked if brakes else model
            assert mm.nv == 6 * free + chain.dof and mm.nq == 7 * free + chain.dof
            assert mm.nu == model.dof  # a motor per healthy joint, none on a brake
            assert mm.neq == (len(model.locked) if brakes else 0)
            assert mm.ngeom == sum(len(b.shapes) for b in (model.root_body, *model.bodies))
            assert mujoco.mj_name2id(mm, mujoco.mjtObj.mjOBJ_SITE, "tool") >= 0
            assert tuple(mm.opt.gravity) == (0.0, 0.0, 0.0)  # in orbit


@pytest.mark.parametrize("name", ROBOT_NAMES)
def test_mj_inverse_equals_rnea(name, rng):
    """Fixed base, random states: MuJoCo's inverse dynamics of the exported file equal
    jointlock's RNEA (locked models too: the file folds the locked joints in)."""
    for base, model in _variants(name):
        if base != "fixed":
            continue
        mm, data = _load(mjcf_text(model), constraints=False)
        for _ in range(5):
            q = random_q(model, rng)
            dq, ddq = rng.uniform(-1.5, 1.5, (2, model.dof))
            data.qpos[:], data.qvel[:], data.qacc[:] = q, dq, ddq
            mujoco.mj_inverse(mm, data)
            tau = jl.rnea(model, q, dq, ddq).torques
            assert np.abs(data.qfrc_inverse - tau).max() <= INVERSE_RTOL * np.abs(tau).max()


@pytest.mark.parametrize("name", ROBOT_NAMES)
def test_floating_export_mass_com_and_inertia(name, rng):
    """The free body's subtree: total mass, centre of mass, and the inertia about the system's
    centre of mass (from MuJoCo's mass matrix at the body origin, and jointlock's at the
    spacecraft's centre of mass), at a random configuration, locked and not."""
    for base, model in _variants(name):
        if base != "floating":
            continue
        mm, data = _load(mjcf_text(model), constraints=False)
        q = random_q(model, rng)
        data.qpos[:7] = [0, 0, 0, 1, 0, 0, 0]
        data.qpos[7:] = q
        mujoco.mj_forward(mm, data)
        total = model.root_body.mass + sum(b.mass for b in model.bodies)
        assert mm.body_subtreemass[1] == pytest.approx(total, rel=1e-14)
        com = system_com(model, q)
        np.testing.assert_allclose(data.subtree_com[1], com, rtol=0, atol=1e-12)
        full = np.zeros((mm.nv, mm.nv))
        for i in range(mm.nv):  # mass matrix column by column: qfrc_inverse of a unit qacc
            data.qvel[:] = 0.0
            data.qacc[:] = 0.0
            data.qacc[i] = 1.0
            mujoco.mj_inverse(mm, data)
            full[:, i] = data.qfrc_inverse
        # rotational blocks: MuJoCo's about the body origin, jointlock's about the spacecraft's com
        about_com_mj = full[3:6, 3:6] - total * (np.dot(com, com) * np.eye(3) - np.outer(com, com))
        jl_m = system_mass_matrix(model, q)
        r = com - model.root_body.com
        about_com_jl = jl_m[3:6, 3:6] - total * (np.dot(r, r) * np.eye(3) - np.outer(r, r))
        np.testing.assert_allclose(about_com_mj, about_com_jl, rtol=0, atol=1e-9 * np.abs(about_com_jl).max())
        np.testing.assert_allclose(full[6:, 6:], jl_m[6:, 6:], rtol=0, atol=1e-10 * np.abs(jl_m[6:, 6:]).max())


def test_brakes_hold_the_locked_joint_at_its_angle():
    """With ``brakes=True`` a locked joint is a hinge held by a joint equality at its angle: its
    constraint residual is zero at the lock angle and its motor is absent."""
    arm = jl.lock(jl.load_robot("halt7", base="floating"), 4, math.radians(30))
    text = mjcf_text(arm, brakes=True)
    root = ET.fromstring(text)
    (eq,) = list(root.find("equality"))
    assert eq.get("name") == "brake4" and float(eq.get("polycoef").split()[0]) == pytest.approx(math.radians(30))
    assert "joint4" not in {m.get("joint") for m in root.find("actuator")}
    mm, data = _load(text)
    data.qpos[3] = 1.0
    data.qpos[7 + 3] = math.radians(30)
    mujoco.mj_forward(mm, data)
    assert abs(data.efc_pos[data.efc_type == mujoco.mjtConstraint.mjCNSTR_EQUALITY]).max() < 1e-15


def test_numbers_written_in_full_precision_and_limits(tmp_path):
    arm = jl.lock(jl.load_robot("canadarm7"), 2, 0.123456789012345)
    path = write_mjcf(arm, tmp_path / "arm.xml")
    mm = mujoco.MjModel.from_xml_path(str(path))
    lo, hi = arm.angle_range()
    np.testing.assert_array_equal(mm.jnt_range[:, 0], lo)
    np.testing.assert_array_equal(mm.jnt_range[:, 1], hi)
    efforts = np.array([j.effort_limit for j in arm.joints])
    if np.all(np.isfinite(efforts)):
        np.testing.assert_array_equal(mm.actuator_ctrlrange[:, 1], efforts)
    assert "written by jointlock; locked: joint 2 at" in path.read_text()


def test_quaternion_from_matrix_round_trip(rng):
    from scipy.spatial.transform import Rotation

    for r in [*Rotation.random(50, random_state=1).as_matrix(), np.diag([1.0, -1.0, -1.0]), np.diag([-1.0, -1.0, 1.0])]:
        quat = quaternion_from_matrix(r)
        back = np.zeros(9)
        mujoco.mju_quat2Mat(back, quat)
        np.testing.assert_allclose(back.reshape(3, 3), r, atol=1e-15)
        assert quat[0] >= 0


@pytest.mark.parametrize("name", ROBOT_NAMES)
def test_no_contact_at_the_zero_pose(name):
    """Every body and its parent, and the pairs in contact at the zero pose (canadarm7's joint 1
    on its bus), are excluded from MuJoCo's contacts: none at the zero pose, fixed base (where
    MuJoCo does not filter a body welded to the world and its child) and floating, locked and
    not, folded and with brakes (the review found base-link1 contacts on fixed bases)."""
    for base in ("fixed", "floating"):
        arm = jl.load_robot(name, base=base)
        for model in (arm, jl.lock(arm, 1, 0.0), jl.lock(arm, 2, 0.0)):
            for brakes in (False, True) if model.locked else (False,):
                mm, data = _load(mjcf_text(model, brakes=brakes))
                if base == "floating":
                    data.qpos[3] = 1.0
                if brakes:
                    free = 7 if base == "floating" else 0
                    for lj in model.locked:
                        data.qpos[free + lj.number - 1] = lj.angle
                mujoco.mj_forward(mm, data)
                assert data.ncon == 0, (base, [lj.number for lj in model.locked], brakes)


def test_a_point_mass_and_a_massless_link_load():
    """MuJoCo refuses zero mass or a zero principal inertia on a moving body: the file asks for
    its floors (1e-9 kg, 1e-12 kg m^2), and its inverse dynamics still equal jointlock's to 1e-9."""
    point = jl.Body(10.0, [2.0, 0.0, 0.0], np.zeros((3, 3)))
    arm = jl.from_dh("two", a=[0.0, 1.0], alpha=[0.0, 0.0], d=[0.0, 0.0], convention="standard",
                     bodies=[point, jl.Body(0.0)])  # fmt: skip
    mm, data = _load(mjcf_text(arm), constraints=False)
    q, dq, ddq = np.array([0.3, -0.2]), np.array([0.5, 1.0]), np.array([-1.0, 2.0])
    data.qpos[:], data.qvel[:], data.qacc[:] = q, dq, ddq
    mujoco.mj_inverse(mm, data)
    tau = jl.rnea(arm, q, dq, ddq).torques
    assert np.abs(data.qfrc_inverse - tau).max() <= 1e-9 * np.abs(tau).max()


def test_cli_export_mjcf(tmp_path, capsys):
    out = tmp_path / "arm.xml"
    assert main(["export-mjcf", "halt7", "--lock", "4=0", "--base", "floating", "--out", str(out), "--json"]) == 0
    facts = json.loads(capsys.readouterr().out)
    assert facts["file"] == str(out) and facts["base"] == "floating" and facts["locked"] == {"4": 0.0}
    mm = mujoco.MjModel.from_xml_path(str(out))
    assert mm.nq == 7 + 6 and mm.nu == 6
    assert main(["export-mjcf", "puma6", "--out", str(tmp_path / "p.xml"), "--brakes"]) == 0  # nothing locked
    assert "wrote" in capsys.readouterr().out
