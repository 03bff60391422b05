"""Monte Carlo workspace of the full and the locked arm (seed 002 Figs. 2-3)."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import jointlock as jl
from jointlock.analysis.workspace import (
    compare_workspaces,
    ee_positions,
    sample_configurations,
    sample_workspace,
    voxel_keys,
)
from jointlock.cli import main
from jointlock.errors import ConfigurationError
from jointlock.ik import ik_closed_form

#: Position-only FK against full-pose FK: round-off [m].
FK_ATOL = 1e-12


@pytest.fixture(scope="module")
def puma() -> jl.ArmModel:
    return jl.load_robot("puma6")


@pytest.mark.parametrize("name", ["puma6", "halt7", "canadarm7"])
def test_fast_positions_equal_full_fk(name, rng):
    arm = jl.load_robot(name)
    for model in (arm, jl.lock(arm, 2, 0.4), jl.lock(arm, arm.dof, -1.0)):
        q = sample_configurations(model, 3000, rng)
        assert np.abs(ee_positions(model, q, chunk=1000) - jl.ee_pose(model, q)[:, :3, 3]).max() < FK_ATOL


def test_locked_poses_are_reached_by_the_full_arm(puma, rng):
    """Subset, exactly: every locked-arm pose has an exact full-arm IK branch."""
    locked = jl.lock(puma, 2, math.radians(60.0))
    q = sample_configurations(locked, 5000, rng)
    res = ik_closed_form(puma, jl.ee_pose(locked, q))
    assert res.exact.any(axis=-1).all()


def test_locked_workspace_is_a_subset_of_the_full_one(puma):
    cmp = compare_workspaces(puma, 2, math.radians(60.0), samples=100_000, rng=5)
    assert cmp.volume_locked < cmp.volume_full
    assert 0.2 < cmp.share_kept < 0.6
    assert cmp.outside < 0.03  # sampling only: locked voxels the full cloud's samples missed


def test_full_volume_is_the_reach_sphere(puma):
    """puma6 reaches every point within a2 + |d4| + d6 = 2.132 m (the inner hole is tiny)."""
    ws = sample_workspace(puma, samples=200_000, voxel=0.2, rng=1)
    sphere = 4 / 3 * math.pi * (0.985 + 0.765 + 0.382) ** 3
    # voxel occupancy: under-sampled shell vs half a voxel layer of over-estimate
    assert 0.85 < ws.volume / sphere < 1.2
    assert np.linalg.norm(ws.points, axis=1).max() <= 0.985 + 0.765 + 0.382 + 1e-9


def test_seeded_and_reproducible(puma):
    a = compare_workspaces(puma, 3, 0.5, samples=2000, rng=9)
    b = compare_workspaces(puma, 3, 0.5, samples=2000, rng=9)
    assert np.array_equal(a.full, b.full) and np.array_equal(a.locked, b.locked)
    assert a.seed == 9


def test_voxel_keys_match_unique_rows(rng):
    pts = rng.normal(size=(3000, 3))
    assert np.array_equal(voxel_keys(pts, 0.3), np.unique(np.floor(pts / 0.3).astype(np.int64), axis=0))


def test_errors(puma):
    with pytest.raises(ConfigurationError, match="samples"):
        sample_configurations(puma, 0)
    with pytest.raises(ConfigurationError, match="voxel"):
        voxel_keys(np.zeros((2, 3)), 0.0)


def test_cli_workspace(capsys, tmp_path):
    assert (
        main(["workspace", "puma6", "--lock", "2=60", "--samples", "20000", "--json", "--out", str(tmp_path)])
        == 0
    )
    out = json.loads(capsys.readouterr().out)
    assert 0 < out["share_kept"] < 1
    assert (tmp_path / "projections.png").exists() and (tmp_path / "points.npz").exists()
