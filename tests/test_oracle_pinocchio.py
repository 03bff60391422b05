"""Pinocchio as an independent oracle (test-only extra; skipped when absent): forward
kinematics, Jacobian, mass matrix and the free-floating generalized Jacobian, on every
built-in (full and locked) and on a URDF arm read by Pinocchio's own parser."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from conftest import ORACLE_ATOL, ROBOT_NAMES, random_q

import jointlock as jl

pin = pytest.importorskip("pinocchio")
from pin_oracle import pin_kinematics, to_pinocchio  # noqa: E402

pytestmark = pytest.mark.oracle
URDF = Path(__file__).parent / "data" / "arm5.urdf"


def _variants(name):
    full = jl.load_robot(name)
    yield full
    yield jl.lock(full, 2, 0.4)
    yield jl.lock_joints(full, {1: -0.3, full.dof: 1.1})


@pytest.mark.parametrize("name", ROBOT_NAMES)
def test_fixed_base_against_pinocchio(name, rng):
    for model in _variants(name):
        pm, fid = to_pinocchio(model)
        for q in random_q(model, rng, (4,)):
            ref = pin_kinematics(pm, fid, q)
            np.testing.assert_allclose(jl.ee_pose(model, q), ref["ee"], atol=ORACLE_ATOL)
            np.testing.assert_allclose(jl.link_poses(model, q), ref["poses"], atol=ORACLE_ATOL)
            np.testing.assert_allclose(jl.jacobian(model, q), ref["jacobian"], atol=ORACLE_ATOL)
            np.testing.assert_allclose(
                jl.mass_matrix(model, q), ref["mass_matrix"], atol=ORACLE_ATOL * 1e3, rtol=1e-12
            )


@pytest.mark.parametrize("name", ROBOT_NAMES)
def test_generalized_jacobian_against_pinocchio_free_flyer(name, rng):
    for model in _variants(name):
        floating = model.with_base(jl.load_robot(name, base="floating").root_body)
        pm, fid = to_pinocchio(floating, free_flyer=True)
        for q in random_q(floating, rng, (4,)):
            ref = pin_kinematics(pm, fid, q, free_flyer=True)
            np.testing.assert_allclose(
                jl.generalized_jacobian(floating, q), ref["generalized_jacobian"], atol=ORACLE_ATOL
            )


def _pin_urdf(free_flyer: bool):
    xml = URDF.read_text()
    if free_flyer:
        return pin.buildModelFromXML(xml, pin.JointModelFreeFlyer())
    return pin.buildModelFromXML(xml)


def test_urdf_reader_against_pinocchio_parser(rng):
    ours = jl.io.read_urdf(URDF)
    pm = _pin_urdf(False)
    fid = pm.getFrameId("tool_tip")
    assert ours.dof == pm.nv == 5
    for q in random_q(ours, rng, (6,)):
        ref = pin_kinematics(pm, fid, q)
        np.testing.assert_allclose(jl.ee_pose(ours, q), ref["ee"], atol=ORACLE_ATOL)
        np.testing.assert_allclose(jl.link_poses(ours, q), ref["poses"], atol=ORACLE_ATOL)
        np.testing.assert_allclose(jl.jacobian(ours, q), ref["jacobian"], atol=ORACLE_ATOL)
        np.testing.assert_allclose(jl.mass_matrix(ours, q), ref["mass_matrix"], atol=1e-9)


def test_urdf_floating_against_pinocchio_free_flyer(rng):
    ours = jl.io.read_urdf(URDF, base="floating")
    pm = _pin_urdf(True)
    fid = pm.getFrameId("tool_tip")
    for q in random_q(ours, rng, (6,)):
        ref = pin_kinematics(pm, fid, q, free_flyer=True)
        np.testing.assert_allclose(
            jl.generalized_jacobian(ours, q), ref["generalized_jacobian"], atol=ORACLE_ATOL
        )
        locked = jl.lock(ours, 3, q[2])
        keep = [0, 1, 3, 4]
        np.testing.assert_allclose(
            jl.generalized_jacobian(locked, q[keep]), ref["generalized_jacobian"][:, keep], atol=ORACLE_ATOL
        )
