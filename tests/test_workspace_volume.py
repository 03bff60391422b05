"""Workspace volume with its error (issue 15 item 6), against arms whose workspace is known
in closed form: a spatial 3R arm (joint 1 about z, joints 2 and 3 about parallel horizontal
axes, links l1 > l2) reaches a spherical shell about its shoulder; with joint 2 limited, a
sector of it."""

from __future__ import annotations

import math

import numpy as np
import pytest

import jointlock as jl
from jointlock.analysis.workspace import compare_workspaces, estimate_volume, sample_workspace

L1, L2 = 1.0, 0.5
#: Joint 2 range of the sector [rad]: b - a >= 2 asin(l2/l1), |a|, |b| + asin(l2/l1) <= pi/2.
A, B = math.radians(-20.0), math.radians(45.0)
#: Samples per test, and the largest relative error the estimate may state [-].
SAMPLES = 200_000
MAX_RELATIVE_ERROR = 0.06


def arm3r(lo2: float = -math.pi, hi2: float = math.pi) -> jl.ArmModel:
    return jl.from_dh(
        "shell3r",
        a=[0.0, L1, L2],
        alpha=[math.pi / 2, 0.0, 0.0],
        d=[0.0, 0.0, 0.0],
        convention="standard",
        lower=[-math.pi, lo2, -math.pi],
        upper=[math.pi, hi2, math.pi],
    )


def shell_volume() -> float:
    """4 pi / 3 ((l1 + l2)^3 - |l1 - l2|^3) [m^3]."""
    return 4.0 / 3.0 * math.pi * ((L1 + L2) ** 3 - abs(L1 - L2) ** 3)


def sector_volume() -> float:
    """Joint 2 within [a, b]: at radius r the elevation spans [a - psi(r), b + psi(r)], psi the
    angle at the shoulder between link 1 and the end-effector (cos psi = (r^2 + l1^2 - l2^2) /
    (2 l1 r)), so V = 2 pi int r^2 (sin(b + psi) - sin(a - psi)) dr
    = 2 pi ((sin b - sin a) int r^2 cos psi dr + (cos a + cos b) int r^2 sin psi dr)
    with int r^2 cos psi dr = 2 l1^2 l2 and int r^2 sin psi dr = pi l1 l2^2 / 2 over
    [|l1 - l2|, l1 + l2] [m^3]."""
    return (
        2.0
        * math.pi
        * (
            (math.sin(B) - math.sin(A)) * 2 * L1**2 * L2
            + (math.cos(A) + math.cos(B)) * math.pi * L1 * L2**2 / 2
        )
    )


def test_sector_formula_by_quadrature():
    r = np.linspace(abs(L1 - L2), L1 + L2, 200_001)
    psi = np.arccos(np.clip((r**2 + L1**2 - L2**2) / (2 * L1 * r), -1, 1))
    f = r**2 * (np.sin(np.minimum(B + psi, math.pi / 2)) - np.sin(np.maximum(A - psi, -math.pi / 2)))
    assert 2 * math.pi * float(np.sum((f[1:] + f[:-1]) / 2 * np.diff(r))) == pytest.approx(
        sector_volume(), rel=1e-7
    )


def test_sector_points_obey_the_elevation_bounds():
    ws = sample_workspace(arm3r(A, B), samples=20_000, rng=3)
    r = np.linalg.norm(ws.points, axis=1)
    psi = np.arccos(np.clip((r**2 + L1**2 - L2**2) / (2 * L1 * r), -1, 1))
    elevation = np.arcsin(ws.points[:, 2] / r)
    assert np.all(elevation >= A - psi - 1e-9) and np.all(elevation <= B + psi + 1e-9)


@pytest.mark.parametrize(
    ("lo", "hi", "truth"),
    [(-math.pi, math.pi, shell_volume()), (A, B, sector_volume())],
    ids=["shell", "sector"],
)
def test_volume_within_its_error_of_the_closed_form(lo, hi, truth):
    ws = sample_workspace(arm3r(lo, hi), samples=SAMPLES, rng=11)
    assert ws.warnings() == []
    assert abs(ws.volume - truth) <= ws.volume_error
    assert ws.volume_error <= MAX_RELATIVE_ERROR * truth
    assert ws.occupancy > truth  # the plain occupancy is biased high


def test_too_few_samples_gives_no_number_and_says_why():
    ws = sample_workspace(arm3r(), samples=2000, rng=0)
    assert math.isnan(ws.volume) and math.isnan(ws.volume_error)
    assert "too few samples" in ws.warnings()[0]
    assert math.isnan(estimate_volume(np.zeros((0, 3))).volume)


@pytest.mark.parametrize("seed", [0, 2, 3])
def test_locked_arm_is_a_subset_by_construction(seed):
    """The sector arm with joint 2 locked: the full arm's estimate (counting the locked
    samples too) still finds the sector's volume; the locked arm has two joints left, so its
    workspace is a surface: volume 0 within its error, never below 0, and so the share kept."""
    cmp = compare_workspaces(arm3r(A, B), 2, math.radians(10.0), samples=SAMPLES // 2, rng=seed)
    assert abs(cmp.volume_full - sector_volume()) <= cmp.volume_full_error
    assert 0.0 <= cmp.volume_locked <= cmp.volume_locked_error
    assert 0.0 <= cmp.share_kept <= cmp.share_kept_error < 0.1
