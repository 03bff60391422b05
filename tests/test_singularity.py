"""General singularity analysis (jointlock.analysis.singularity): rank, det(J J^T), lost
directions, the batched search and its clustering, and the ``jointlock singular`` CLI."""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest
from conftest import EXACT_ATOL, random_q

import jointlock as jl
from jointlock.analysis import singularity as sg
from jointlock.cli import main

#: |J^T u| of a lost direction found by the search: sigma_min < SEARCH_TOL = 1e-9, so
#: |J^T u| = sigma_min < 1e-9 (u the left singular vector); 1e-8 leaves a margin.
LEFT_NULL_ATOL = 1e-8


def test_batched_analysis_equals_loop(rng):
    model = jl.load_robot("halt7", base="floating")
    q = random_q(model, rng, (4, 3))
    for base in sg.BASE_KINDS:
        batch = sg.analyse_singularity(model, q, jacobian=base)
        assert batch.singular_values.shape == (4, 3, 6)
        for idx in np.ndindex(4, 3):
            one = sg.analyse_singularity(model, q[idx], jacobian=base)
            np.testing.assert_allclose(batch.singular_values[idx], one.singular_values, atol=EXACT_ATOL)
            assert batch.det_jjt[idx] == pytest.approx(float(one.det_jjt), rel=1e-9)
            assert batch.rank[idx] == one.rank


def test_task_jacobians_are_the_kinematics_ones(rng):
    model = jl.load_robot("canadarm7", base="floating")
    q = random_q(model, rng, (3,))
    np.testing.assert_allclose(sg.task_jacobian(model, q, jacobian="fixed"), jl.jacobian(model, q))
    np.testing.assert_allclose(sg.task_jacobian(model, q, jacobian="floating"), jl.generalized_jacobian(model, q))
    np.testing.assert_allclose(
        sg.task_jacobian(model, q, jacobian="virtual", weighting="vafa-dubowsky"),
        jl.virtual_manipulator(model, q).jacobian,
    )
    scaled = sg.task_jacobian(model, q, characteristic_length=2.0)
    np.testing.assert_allclose(scaled[:, :3], jl.jacobian(model, q)[:, :3] / 2.0)


def test_puma_wrist_singularity_and_its_lost_direction(rng):
    model = jl.load_robot("puma6")
    q = random_q(model, rng, (20,))
    regular = sg.analyse_singularity(model, q)
    assert not regular.singular.any()
    np.testing.assert_allclose(regular.det_jjt, np.prod(regular.singular_values**2, axis=-1), rtol=1e-8)
    q[:, 4] = 0.0  # theta5 = 0: axes 4 and 6 align
    res = sg.analyse_singularity(model, q)
    assert res.singular.all() and (res.rank == 5).all()
    assert np.abs(res.det_jjt).max() < 1e-12
    for i in range(len(q)):
        u = res.lost_directions((i,))
        assert u.shape == (6, 1)
        np.testing.assert_allclose(res.jacobian[i].T @ u, 0.0, atol=1e-12)
        # the lost rank is theirs: the columns of joints 4 and 6 are parallel
        pair = res.jacobian[i][:, [3, 5]]
        assert np.linalg.svd(pair, compute_uv=False)[-1] < 1e-12


def test_locked_arm_analysis_uses_healthy_columns(rng):
    model = jl.lock(jl.load_robot("halt7"), joint=4, angle=0.3)
    res = sg.analyse_singularity(model, random_q(model, rng))
    assert res.jacobian.shape == (6, 6) and res.singular_values.shape == (6,)


def test_gradient_of_sigma_min_matches_finite_differences(rng):
    model = jl.load_robot("halt7")
    q = random_q(model, rng, (5,))

    def fun(qq):
        return sg.task_jacobian(model, qq)

    sigma, grad = sg._sigma_min_and_gradient(fun, q)
    h = 1e-5
    for j in range(model.dof):
        e = np.zeros(model.dof)
        e[j] = h
        fd = (sg._sigma_min(fun, q + e) - sg._sigma_min(fun, q - e)) / (2 * h)
        np.testing.assert_allclose(grad[:, j], fd, atol=1e-6)


def test_search_finds_puma_wrist_family_and_is_reproducible():
    model = jl.load_robot("puma6")
    res = sg.find_singularities(model, samples=64, rng=3)
    start = sg.analyse_singularity(model, res.q_start)
    assert start.sigma_min.min() > 1e-4  # the starts were not singular
    assert len(res.q) >= 48
    assert (res.sigma_min < sg.SEARCH_TOL).all()
    wrist = [f for f in res.families if f.zero_sine_joints == (5,)]
    assert wrist and wrist[0].dependent_joints == (4, 6)
    jac = jl.jacobian(model, res.q)
    for fam in res.families:
        u = fam.lost_direction
        j_rep = jl.jacobian(model, fam.representative)
        assert np.linalg.norm(j_rep.T @ u) < LEFT_NULL_ATOL
    assert sum(len(f.members) for f in res.families) == len(res.q)
    assert np.linalg.svd(jac, compute_uv=False)[:, -1].max() < sg.SEARCH_TOL
    again = sg.find_singularities(model, samples=64, rng=3)
    np.testing.assert_array_equal(again.q, res.q)


@pytest.mark.parametrize("base", ["fixed", "floating"])
def test_search_finds_halt7_singularities(base):
    model = jl.load_robot("halt7", base=base)
    res = sg.find_singularities(model, samples=48, rng=1, jacobian=base)
    assert len(res.q) >= 10
    ana = sg.analyse_singularity(model, res.q, jacobian=base, tol=1e-8)
    assert ana.singular.all()
    jac = ana.jacobian
    u = ana.directions[..., :, 5]
    assert np.linalg.norm(np.einsum("mij,mi->mj", jac, u), axis=-1).max() < LEFT_NULL_ATOL


def test_errors_are_precise():
    with pytest.raises(jl.ModelError, match="free-floating"):
        sg.task_jacobian(jl.load_robot("puma6"), np.zeros(6), jacobian="virtual")
    with pytest.raises(jl.ScenarioError, match="jacobian must be one of"):
        sg.analyse_singularity(jl.load_robot("puma6"), np.zeros(6), jacobian="moving")  # type: ignore[arg-type]
    with pytest.raises(jl.ModelError, match="7-joint"):
        sg.arm_lengths(jl.load_robot("puma6"), jacobian="fixed")
    with pytest.raises(jl.ModelError, match="not a Canadarm2-structure"):
        sg.arm_lengths(jl.load_robot("halt7"), jacobian="fixed")
    with pytest.raises(jl.ScenarioError, match="condition must be one of"):
        sg.sample_condition("cond9", 3, sg.arm_lengths(jl.load_robot("canadarm7"), jacobian="fixed"))


def _cli_json(capsys, argv):
    assert main(argv) == 0
    return json.loads(capsys.readouterr().out)


def test_cli_single_configuration(capsys):
    out = _cli_json(capsys, ["singular", "puma6", "--q-deg", "10", "20", "30", "40", "0", "60", "--json"])
    assert out["singular"] and out["rank"] == 5 and len(out["lost_directions"]) == 1
    out = _cli_json(
        capsys,
        [
            "singular",
            "canadarm7",
            "--base",
            "virtual",
            "--q-deg",
            "25",
            "0",
            "90",
            "0",
            "45",
            "90",
            "0",
            "--json",
        ],
    )
    res = out["conditions"]["residuals"]
    assert res["cond1"]["holds"] and res["cond1f"]["holds"] and not res["cond5"]["holds"]
    assert out["conditions"]["analytic_directions"]["cond1"]["alignment"] == pytest.approx(1.0, abs=1e-9)


def test_cli_verify_conditions_json(capsys):
    out = _cli_json(capsys, ["singular", "canadarm7", "--verify-conditions", "--samples", "40", "--json"])
    assert set(out["conditions"]) == {"cond1", "cond2", "cond3", "cond4", "cond5"}
    assert out["conditions"]["cond1"]["singular"] == 0
    assert all(out["conditions"][k]["fraction_singular"] == 1.0 for k in ("cond2", "cond3", "cond4", "cond5"))
    comp = out["completeness"]
    assert comp["found"] > 0 and comp["explained"] == comp["found"]


def test_cli_search_writes_files(capsys, tmp_path):
    assert main(["singular", "puma6", "--search", "--samples", "16", "--out", str(tmp_path), "--quiet"]) == 0
    assert "families" in capsys.readouterr().out
    assert {p.name for p in tmp_path.iterdir()} >= {"search.json", "sigma_min.png", "families.png"}
    assert json.loads((tmp_path / "search.json").read_text())["converged"] > 0


def test_cli_errors(capsys):
    assert main(["singular", "puma6", "--verify-conditions", "--samples", "5"]) == 2
    assert "7-joint" in capsys.readouterr().err
    assert main(["singular", "puma6", "--q-deg", "1", "2"]) == 2


def test_installed_cli_runs():
    exe = [
        sys.executable,
        "-m",
        "jointlock.cli",
        "singular",
        "puma6",
        "--q-deg",
        "0",
        "0",
        "0",
        "0",
        "0",
        "0",
        "--json",
    ]
    proc = subprocess.run(exe, capture_output=True, text=True, check=True)
    assert json.loads(proc.stdout)["robot"] == "puma6"


# -- UX review: arms with fewer than 6 joints, labelled search output -------------------------------


def test_cli_single_reports_det_jtj_below_six_joints(capsys):
    q = ["0", "0", "10", "20", "30"]
    assert main(["singular", "puma6", "--lock", "2=30", "--q-deg", *q, "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    sv = np.asarray(out["singular_values"])
    assert out["det_jjt"] == pytest.approx(0.0, abs=1e-12)  # identically 0 with 5 joints (kept)
    assert out["gram_det_kind"] == "det(J^T J)" and out["gram_det"] == pytest.approx(np.prod(sv**2))
    assert out["gram_det"] > 1e-6 and not out["singular"]
    assert main(["singular", "puma6", "--lock", "2=30", "--q-deg", *q]) == 0
    text = capsys.readouterr().out
    assert "det(J^T J) = " in text and "det(J J^T) = 0 always" in text
    assert "det(J J^T) = 0 " not in text.split("->")[0]
    # six joints: det(J J^T), as before
    assert main(["singular", "puma6", "--q-deg", "0", "10", "20", "30", "40", "50", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["gram_det_kind"] == "det(J J^T)" and out["gram_det"] == pytest.approx(out["det_jjt"], rel=1e-9)


def test_cli_search_labels_joints_and_names_the_lock(capsys):
    assert main(["singular", "puma6", "--lock", "2=30", "--search", "--samples", "16", "--quiet"]) == 0
    text = capsys.readouterr().out
    assert text.splitlines()[0].startswith(
        "puma6: 5 movable joints [1, 3, 4, 5, 6], locked: joint 2 at 30 deg"
    )
    rep = next(line for line in text.splitlines() if "representative q [deg]" in line)
    assert "q1=" in rep and "q3=" in rep and "q2=" not in rep


def test_ur5_has_its_three_singularities_as_three_families():
    """Issue 15, item 7: UR5's shoulder, elbow and wrist singularities are three families (the
    shoulder's dependent joints vary where a null-vector entry vanishes by coincidence: nested
    sets of one zero group are one family)."""
    d1, a2, a3, d4, d5, d6 = (0.089159, -0.425, -0.39225, 0.10915, 0.09465, 0.0823)
    ur5 = jl.from_dh("ur5", a=[0, a2, a3, 0, 0, 0], alpha=[np.pi / 2, 0, 0, np.pi / 2, -np.pi / 2, 0],
                     d=[d1, 0, 0, d4, d5, d6], convention="standard")  # fmt: skip
    res = sg.find_singularities(ur5, samples=128, rng=0)
    assert sorted(f.zero_sine_joints for f in res.families) == [(), (3,), (5,)]
    shoulder = next(f for f in res.families if f.zero_sine_joints == ())
    assert shoulder.dependent_joints == (1, 2, 3, 4, 5, 6)
    assert sum(len(f.members) for f in res.families) == len(res.q)
    puma = sg.find_singularities(jl.load_robot("puma6"), samples=128, rng=0)
    assert len(puma.families) == 3  # elbow and shoulder: both no joint at 0, not nested


def test_nested_dependent_sets_join_only_their_one_maximal_set():
    """A set inside one maximal set joins it; sets that do not nest stay apart; a set inside
    two maximal sets, or a configuration losing two ranks, is its own family."""
    from jointlock.analysis.singularity._search import _merged_keys

    def joints(*js):
        return [j in js for j in range(1, 7)]

    dependent = np.array([joints(2, 3, 4, 5, 6), joints(1, 4, 5, 6), joints(1, 2, 3, 4, 5, 6), joints(2, 3, 4, 5), joints(4, 5, 6)])
    zero = np.zeros((5, 6), dtype=bool)
    lost = np.array([1, 1, 2, 1, 1])
    keys = _merged_keys(zero, dependent, lost)
    assert keys[3] == keys[0]  # {2..5} inside {2..6} only
    assert len({keys[0], keys[1], keys[2], keys[4]}) == 4  # elbow, shoulder, both at once, {4,5,6} under two
