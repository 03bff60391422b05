"""A target typed with rounded numbers is reachable within a tolerance (issue 15, item 5): 002's
eq. (21) pose, printed to four decimals, with joint 2 locked at 52.0547 deg."""

from __future__ import annotations

import contextlib
import io
import json

import numpy as np
import pytest

import jointlock as jl
from jointlock.cli import main
from jointlock.papers import p002


def _eq21():
    t = np.array(p002.EQ21_POSE, dtype=float)
    t[:3, 3] /= 1000.0  # printed in mm
    u, _, vt = np.linalg.svd(t[:3, :3])  # printed to 4 decimals: the nearest rotation
    t[:3, :3] = u @ vt
    return t


@pytest.mark.paper
def test_the_printed_eq21_pose_is_reached_within_a_hundredth_of_a_millimetre():
    arm = jl.lock(jl.load_robot("puma6"), 2, np.radians(p002.B_LOCK_DEG))
    exact = jl.solve_ik(arm, _eq21())
    assert not exact.reachable and exact.nearest.position_error == pytest.approx(8.0e-6, rel=0.01)
    within = jl.solve_ik(arm, _eq21(), tolerance=(1e-5, np.radians(1e-3)))
    assert within.reachable and within.within_tolerance and len(within.solutions) == 2  # the wrist's two
    assert all(s.position_error <= 1e-5 and s.rotation_error <= np.radians(1e-3) for s in within.solutions)
    closest = min(within.solutions, key=lambda s: np.abs(np.degrees(s.q_full) - p002.EQ22_DEG).max())
    np.testing.assert_allclose(np.degrees(closest.q_full), p002.EQ22_DEG, atol=0.02)  # eq. (22), from a rounded pose
    tight = jl.solve_ik(arm, _eq21(), tolerance=(1e-6, np.radians(1e-3)))
    assert not tight.reachable  # 8 micrometres is more than 1


def test_the_command_takes_the_tolerance_in_mm_and_deg():
    t = _eq21()
    argv = ["ik", "puma6", "--lock", f"2={p002.B_LOCK_DEG}", "--matrix", *map(str, t.ravel()), "--json"]
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        assert main(argv) == 0
    assert json.loads(out.getvalue())["reachable"] is False
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        assert main([*argv, "--tol-mm", "0.01", "--tol-deg", "0.001"]) == 0
    res = json.loads(out.getvalue())
    assert res["reachable"] and res["within_tolerance"] and res["tolerance"]["position_m"] == pytest.approx(1e-5)


def test_a_bad_tolerance_is_refused():
    with pytest.raises(jl.ConfigurationError, match="tolerance must be"):
        jl.solve_ik(jl.load_robot("puma6"), np.eye(4), tolerance=(-1.0, 0.0))
