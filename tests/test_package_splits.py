"""The packages split out of ik.py, planning/replan.py and analysis/ability.py (issue 11):
every old name still importable from the old path, the rng convention of the IK, and 000's
AHP numbers taken from jointlock.papers.p000."""

from __future__ import annotations

import importlib

import numpy as np
import pytest

import jointlock as jl
from jointlock.analysis import ability
from jointlock.ik import ik_numeric, pose_from_zyx, solve_ik
from jointlock.papers import p000

#: Names (private ones included) that code written before the split imports from the old
#: module paths.
OLD_NAMES = {
    "jointlock.ik": [
        "EXACT_POSITION_TOL", "EXACT_ROTATION_TOL", "FAMILY_FIT_TOL", "DUPLICATE_TOL", "PUMA6_ALPHA",
        "pose_from_zyx", "zyx_angles", "wrap_angle", "_as_poses", "Puma6Geometry", "_dh_chain",
        "puma6_fk", "puma6_geometry", "_rot03", "_position_branches", "_wrist_branches",
        "puma6_branches", "IKBranches", "ik_closed_form", "IKSolution", "IKResult", "_distinct",
        "NumericIK", "_residual", "ik_numeric", "_select_state", "solve_ik",
    ],
    "jointlock.planning.replan": [
        "ROOT_BISECTIONS", "DEFAULT_GAMMA_STEP", "tool_x_rotation", "_full_geometry", "_full_branches",
        "_pick_branch", "GammaSweep", "gamma_sweep", "_continuous", "LockRange", "absorbable_range",
        "GammaRoot", "_locked_value", "_bisect", "_brackets", "gammas_for_lock", "line_waypoints",
        "PATH_GAMMA_STEP", "PATH_MAX_GAMMAS", "REFINE_STEPS", "DEFAULT_STEP_WEIGHT", "GOAL_WEIGHT",
        "JUMP_MEDIAN_FACTOR", "JUMP_MIN_STEP", "JUMP_MAX_STEP", "StepFlag", "ReplanResult",
        "replan_line", "_flags", "_pointwise_grid", "_pointwise_plan", "_pointwise_absorbed",
        "_continuous_plan", "_branch_error", "_golden", "_shortest_path",
    ],
    "jointlock.analysis.ability": [
        "INDEX_NAMES", "PAPER_JUDGMENT", "PAPER_RI", "SAATY_RI", "CR_LIMIT", "RECIPROCITY_RTOL",
        "Assignment", "RITable", "KinematicIndices", "scale_linear_rows", "GRAM_CONDITION_LIMIT",
        "singular_values", "kinematic_indices", "Normalization", "StandardizedIndices", "_minmax",
        "standardize", "AHPResult", "_format_matrix", "ahp_weights", "EntropyResult",
        "entropy_weights", "ahp_to_canonical", "combine_weights", "combined_index", "AbilityModel",
        "fit_ability_model", "_flatten", "JacobianKind", "DEFAULT_BATCH", "configuration_indices",
    ],
}  # fmt: skip


@pytest.mark.parametrize("module", sorted(OLD_NAMES))
def test_old_names_importable_from_the_old_path(module):
    mod = importlib.import_module(module)
    assert [n for n in OLD_NAMES[module] if not hasattr(mod, n)] == []
    assert all(hasattr(mod, n) for n in mod.__all__)


def test_paper_ahp_numbers_come_from_p000():
    assert ability.PAPER_JUDGMENT.dtype == np.float64 and not ability.PAPER_JUDGMENT.flags.writeable
    np.testing.assert_array_equal(ability.PAPER_JUDGMENT, p000.JUDGMENT)
    assert type(ability.PAPER_RI) is dict and ability.PAPER_RI == dict(p000.RANDOM_INDEX)
    assert type(ability.CR_LIMIT) is float and ability.CR_LIMIT == p000.CR_LIMIT


@pytest.fixture(scope="module")
def puma():
    return jl.load_robot("puma6")


def test_ik_numeric_records_its_seed(puma):
    t = pose_from_zyx([0.5, 0.3, 0.8], np.radians([10.0, 20.0, 30.0]))
    by_int = ik_numeric(puma, t, starts=3, rng=4, max_iter=5)
    by_gen = ik_numeric(puma, t, starts=3, rng=np.random.default_rng(4), max_iter=5)
    np.testing.assert_array_equal(by_int.q, by_gen.q)  # same numbers for an int and its Generator
    assert by_int.seed == 4 and by_gen.seed is None
    fresh = ik_numeric(puma, t, starts=3, rng=None, max_iter=5)
    assert isinstance(fresh.seed, int)
    np.testing.assert_array_equal(ik_numeric(puma, t, starts=3, rng=fresh.seed, max_iter=5).q, fresh.q)


def test_solve_ik_records_its_seed(puma):
    t = pose_from_zyx([0.5, 0.3, 0.8], np.radians([10.0, 20.0, 30.0]))
    res = solve_ik(puma, t, method="numeric", starts=4, rng=5)
    assert res.seed == 5
    assert solve_ik(puma, t, method="numeric", starts=4, rng=np.random.default_rng(5)).seed is None
    fresh = solve_ik(puma, t, method="numeric", starts=4, rng=None)
    again = solve_ik(puma, t, method="numeric", starts=4, rng=fresh.seed)
    assert isinstance(fresh.seed, int)
    np.testing.assert_array_equal(
        np.array([c.q for c in fresh.candidates]), np.array([c.q for c in again.candidates])
    )
