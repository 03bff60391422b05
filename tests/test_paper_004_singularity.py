"""Seed 004's singularity analysis on canadarm7: eq. (15) and its eq.-(24) reordering,
Cond1-Cond5 (eq. 30) with their singular directions (eqs. 28, 32), and Table 3.

Provenance: seed 004 (Chen et al. 2014) §§3-5; transcriptions in
``docs/readings/canadarm7-004.md``.  Virtual lengths: 004's formula (``weighting="segment"``),
unrounded (â = 0.38148, ĉ = 0.39259, d̂ = 2.14815, ê = 2.33333, f̂ = 0.47778, ĥ = 0.48889,
k̂ = 0.5 m; printed to two decimals).

Table 3 (printed angles [deg]; the angles of Cond3-Cond5 solve a length equation and are
printed rounded to 0.1 deg, so they are re-solved here with the unrounded virtual lengths,
keeping every other angle as printed):

======  ==========================================  =================  ===========================  ===============
cond    printed angles                              solved angle(s)    004 det(Ĵm Ĵmᵀ)              ours (solved)
======  ==========================================  =================  ===========================  ===============
Cond1   {25, 0, 90, 0, 45, 90, 0}                   (none)             -1.06608e-14                 -5.07e-15
Cond2   {25, 0, 34, 30, 45, 0, 0}                   (none)             -6.80933e-14                  8.16e-14
Cond3   {25, 0, 20, 140, -139.1, 45, 0}             θ5 = -139.149      2.43766e-30                  -6.78e-16
Cond4   {25, 10, -132.9, 140, 20, 0, 0}             θ3 = -132.860      2.97193e-12                   1.57e-15
Cond5   {25, 10, 24, 180, -44.9, 45, 0}             θ3, θ5 = 24.767,   -1.60952e-16                 -2.01e-17
                                                    -44.885 (θ4 = 180)
======  ==========================================  =================  ===========================  ===============

Both columns are round-off (the largest singular value product is ~ 10^2; random
configurations give |det| ≥ 2e-5, median ~ 70).  At the printed, rounded angles Cond3-Cond5
are only near-singular (sigma_min 2.1e-4, 2.3e-5, 1.0e-3): the paper's determinants need the
unrounded angles.  Cond1's example is singular because it also has S2 = 0 and C3 = 0 (then
F = 0); Cond5's has θ4 = 180 deg, so S4 = 0 as well.
"""

from __future__ import annotations

import numpy as np
import pytest

import jointlock as jl
from jointlock.analysis import singularity as sg
from jointlock.jobs.reproduction import solve_table3  # Table 3's angles re-solved, unrounded
from jointlock.papers import p004

pytestmark = pytest.mark.paper

#: Table 3's printed configurations [deg] and det(Ĵm Ĵmᵀ).
TABLE3_DEG = p004.TABLE3_DEG
TABLE3_DET = p004.TABLE3_DET
#: |det(Ĵm Ĵmᵀ)| below which a configuration counts as singular: the paper's largest printed
#: value is 2.97e-12; random configurations give >= 2e-5 (10^4 samples).
DET_SINGULAR = 1e-11
#: An exact sample is singular to round-off: sigma_min ~ 1e-15 (raw Jacobian units).
SIGMA_EXACT = 1e-12


@pytest.fixture(scope="module")
def arm():
    return jl.load_robot("canadarm7", base="floating")


@pytest.fixture(scope="module")
def lengths(arm):
    return sg.arm_lengths(arm)


def test_virtual_lengths_are_004s(lengths):
    for k, v in p004.VIRTUAL_LENGTHS.items():
        assert getattr(lengths, k) == pytest.approx(v, abs=0.005)  # half a unit of 2 decimals


@pytest.mark.parametrize("name", sg.CONDITIONS)
def test_table3_configurations_are_singular(arm, lengths, name):
    q = solve_table3(name, lengths)
    assert sg.condition_residuals(q, lengths)[name] < 1e-12
    assert abs(np.degrees(q) - TABLE3_DEG[name]).max() < 0.8  # only the rounding moved
    res = sg.analyse_singularity(arm, q, jacobian="virtual")
    assert abs(res.det_jjt) < DET_SINGULAR
    assert abs(TABLE3_DET[name]) < DET_SINGULAR
    assert res.rank == 5


def test_table3_solved_angles(lengths):
    assert np.degrees(solve_table3("cond3", lengths)[4]) == pytest.approx(-139.149, abs=1e-3)
    assert np.degrees(solve_table3("cond4", lengths)[2]) == pytest.approx(-132.860, abs=1e-3)
    q5 = np.degrees(solve_table3("cond5", lengths))
    assert (q5[2], q5[4]) == pytest.approx((24.767, -44.885), abs=1e-3)


@pytest.mark.parametrize("name", ["cond3", "cond4", "cond5"])
def test_table3_printed_rounded_angles_are_only_near_singular(arm, name):
    res = sg.analyse_singularity(arm, np.radians(TABLE3_DEG[name]), jacobian="virtual")
    assert 1e-6 < res.sigma_min < 1e-2 and res.rank == 6


def test_random_configurations_are_not_singular(arm, rng):
    res = sg.analyse_singularity(arm, rng.uniform(-np.pi, np.pi, (2000, 7)), jacobian="virtual")
    assert np.abs(res.det_jjt).min() > 1e3 * DET_SINGULAR
    assert not res.singular.any()


@pytest.mark.parametrize("base", ["fixed", "virtual"])
def test_reference_jacobian_is_eq15_and_eq24_has_the_zero_block(rng, base):
    arm = jl.load_robot("canadarm7", base="floating" if base == "virtual" else "fixed")
    lg = sg.arm_lengths(arm, jacobian=base)
    q = rng.uniform(-np.pi, np.pi, (50, 7))
    ref = sg.reference_jacobian(arm, q, jacobian=base)
    np.testing.assert_allclose(ref, sg.eq15_jacobian(q, lg), atol=1e-12)
    part = sg.reorder_eq24(ref)
    assert np.abs(part.zero).max() < 1e-12
    np.testing.assert_allclose(np.linalg.det(part.j12), lg.d * lg.e * np.sin(q[:, 3]), atol=1e-12)
    # same singularities as the inertial-frame Jacobian: same det(J J^T), same rank
    inertial = sg.analyse_singularity(arm, q, jacobian=base)
    reordered = sg.singularity_of_jacobian(part.matrix)
    np.testing.assert_allclose(reordered.det_jjt, inertial.det_jjt, rtol=1e-9)
    np.testing.assert_array_equal(reordered.rank, inertial.rank)
    # ... but not the same singular values: moving the reference point is not orthogonal
    assert np.abs(reordered.sigma_min - inertial.sigma_min).max() > 1e-3


def test_reordering_preserves_rank_at_singular_configurations(arm, lengths):
    q = np.concatenate([sg.sample_condition(c, 20, lengths, rng=5) for c in sg.CONDITIONS[1:]])
    part = sg.reorder_eq24(sg.reference_jacobian(arm, q))
    np.testing.assert_array_equal(
        sg.singularity_of_jacobian(part.matrix).rank, sg.analyse_singularity(arm, q, jacobian="virtual").rank
    )


@pytest.mark.parametrize("name", sg.CONDITIONS + sg.REFINED_CONDITIONS)
def test_condition_residuals_vanish_on_sampler_output(lengths, name, rng):
    q = sg.sample_condition(name, 300, lengths, rng=11)
    assert q.shape == (300, 7)
    assert sg.condition_residuals(q, lengths, refined=True)[name].max() < 1e-13
    other = rng.uniform(-np.pi, np.pi, (300, 7))
    assert sg.condition_residuals(other, lengths, refined=True)[name].min() > 1e-6


def test_sufficiency_counts(arm, lengths):
    """Cond2-Cond5 are sufficient; Cond1 (S4 = 0) is NOT: not one sample is singular, unless
    F = 0 is added (cond1f)."""
    ver = sg.verify_conditions(arm, samples=400, search_samples=64, rng=2)
    counts = {k: c.singular for k, c in ver.checks.items()}
    assert counts == {"cond1": 0, "cond2": 400, "cond3": 400, "cond4": 400, "cond5": 400, "cond1f": 400}
    assert ver.checks["cond1"].sigma_min_median > 0.05
    for k in ("cond2", "cond3", "cond4", "cond5", "cond1f"):
        assert ver.checks[k].direction_residual < 1e-12  # 004's analytic direction is left-null
        assert ver.checks[k].direction_alignment == pytest.approx(1.0, abs=1e-9)
    comp = ver.completeness
    assert comp.found >= 32 and comp.explained == comp.found and comp.explained_refined == comp.found


def test_analytic_directions_are_in_eq24_order_not_ref(arm, lengths):
    """Eq. (32) is printed under "ref" but only the eq.-(24) row order makes it left-null."""
    q = sg.sample_condition("cond2", 50, lengths, rng=4)
    part = sg.reorder_eq24(sg.reference_jacobian(arm, q))
    u = sg.analytic_directions(q, lengths)["cond2"]
    assert np.abs(np.einsum("mij,mi->mj", part.matrix, u)).max() < 1e-12
    ref = sg.reference_jacobian(arm, q)
    assert np.abs(np.einsum("mij,mi->mj", ref, u)).max() > 1e-2


def test_cond1_extra_factor_separates_singular_from_regular(arm, lengths):
    q = sg.sample_condition("cond1", 500, lengths, rng=8)
    res = sg.analyse_singularity(arm, q, jacobian="virtual")
    f = np.abs(sg.cond1_extra(q, lengths))
    assert not res.singular.any() and f.min() > 1e-8
