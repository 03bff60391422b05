"""puma6 reproduces every end-effector position and Euler triple 002 prints.

Provenance: seed 002, the worked examples of its re-planning sections and eqs. (21)-(22);
the reading (standard DH, theta column not added, a2 = 985 mm, d4 = -765 mm, d6 = 382 mm)
is documented in ``jointlock.robots.puma6`` and ``docs/readings/puma6-002.md``.  Positions
are printed in mm, Euler angles as ZYX [yaw, pitch, roll] in rad.  Examples printed with 4
decimals must match to half a unit of the last digit (rounding); the 2-decimal examples of
002 §6.1 are truncated toward zero, not rounded, so they must equal trunc(ours, 2).
"""

from __future__ import annotations

import numpy as np
import pytest

import jointlock as jl
from jointlock.papers import p002

pytestmark = pytest.mark.paper

#: 002's worked examples E1-E5 (q [deg], position [mm], ZYX Euler [rad], printed decimals).
EXAMPLES = p002.EXAMPLES

#: Eq. (21): the target pose of the 52.0547 deg example (rotation and mm), 4 decimals.
EQ21 = np.array(p002.EQ21_POSE)


def zyx_euler(rot: np.ndarray) -> np.ndarray:
    return np.array(
        [np.arctan2(rot[1, 0], rot[0, 0]), -np.arcsin(rot[2, 0]), np.arctan2(rot[2, 1], rot[2, 2])]
    )


@pytest.mark.parametrize("q_deg, position_mm, euler, decimals", list(EXAMPLES.values()), ids=list(EXAMPLES))
def test_printed_example(q_deg, position_mm, euler, decimals):
    pose = jl.ee_pose(jl.load_robot("puma6"), np.radians(q_deg))
    ours_pos = pose[:3, 3] * 1000.0
    ours_euler = zyx_euler(pose[:3, :3])
    if decimals == 2:
        np.testing.assert_array_equal(np.trunc(ours_pos * 100) / 100, position_mm)
        np.testing.assert_array_equal(np.trunc(ours_euler * 100) / 100, euler)
    else:
        half_unit = 0.5 * 10.0**-decimals + 1e-9
        np.testing.assert_allclose(ours_pos, position_mm, atol=half_unit, rtol=0)
        np.testing.assert_allclose(ours_euler, euler, atol=half_unit, rtol=0)


def test_eq22_joints_give_eq21_pose():
    pose = jl.ee_pose(jl.load_robot("puma6"), np.radians(p002.EQ22_DEG))
    ours = pose.copy()
    ours[:3, 3] *= 1000.0
    # eq. (22) itself is rounded to 1e-4 deg; that moves the rotation entries by < 1e-5
    np.testing.assert_allclose(ours[:3, :3], EQ21[:3, :3], atol=0.5e-4 + 1e-5)
    np.testing.assert_allclose(ours[:3, 3], EQ21[:3, 3], atol=0.5e-4)


def test_the_other_readings_do_not_reproduce_002():
    """The test can fail: adding Table 1's theta column moves the tip by metres."""
    from jointlock.robots import PUMA6_A2, PUMA6_D4, PUMA6_D6

    deg = np.radians
    offsets = jl.from_dh(
        "puma6-offsets",
        a=[0, PUMA6_A2, 0, 0, 0, 0],
        alpha=deg([-90, 0, 90, -90, 90, 0]),
        d=[0, 0, 0, PUMA6_D4, 0, PUMA6_D6],
        theta=deg([90, 0, 90, 0, 0, 0]),
        convention="standard",
    )
    q_deg, position_mm, _, _ = EXAMPLES["E3"]
    error = np.linalg.norm(jl.ee_pose(offsets, deg(q_deg))[:3, 3] * 1000 - position_mm)
    assert error > 100.0
