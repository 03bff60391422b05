"""plan_halt's settings grouped into typed objects (issue 27, item 5): HaltLimits, HaltSearch,
HaltMotionSettings; the former keywords still work, warn once each and give the same plan."""

from __future__ import annotations

import json
import pickle
import warnings

import numpy as np
import pytest

import jointlock as jl
from jointlock import _deprecate
from jointlock.jobs.halt import FORMER_KEYWORDS
from jointlock.planning.ga import GASettings


@pytest.fixture
def fresh_warnings(monkeypatch):
    monkeypatch.setattr(_deprecate, "_WARNED", set())


def test_the_former_keywords_give_the_same_plan_and_warn_once_each(fresh_warnings):
    new = jl.plan_halt(
        "halt7", paper_qf=True,
        limits=jl.HaltLimits(vmax_deg=45.0, amax_deg=25.0, margin=0.01),
        motion=jl.HaltMotionSettings(n_samples=101, minimum_T=True, objective="peak_torque", prefer_margin=0.01),
    )  # fmt: skip
    with pytest.warns(FutureWarning) as caught:
        old = jl.plan_halt(
            "halt7", paper_qf=True, vmax_deg=45.0, amax_deg=25.0, margin=0.01, n_samples=101, minimum_T=True,
            objective="peak_torque", prefer_margin=0.01,
        )  # fmt: skip
    assert json.dumps(old.to_dict(), default=str) == json.dumps(new.to_dict(), default=str)
    said = [str(w.message) for w in caught]
    assert len(said) == 7
    assert "plan_halt(): the keyword vmax_deg= is deprecated: use limits=HaltLimits(vmax_deg=...)" in said[0]
    assert any("use motion=HaltMotionSettings(n_samples=...)" in m for m in said)
    assert all(w.filename == __file__ for w in caught)  # attributed to the caller
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        jl.plan_halt("halt7", paper_qf=True, n_samples=101)  # once per process: no second warning


def test_the_search_and_the_solver_keywords_too(fresh_warnings):
    with pytest.warns(FutureWarning) as caught:
        old = jl.plan_halt("halt7", samples=800, reachable=False, solver="ga", ga=GASettings(n_pop=6, n_gen=3))
    assert len(caught) == 4 and "use search=HaltSearch(samples=...)" in str(caught[0].message)
    new = jl.plan_halt(
        "halt7", search=jl.HaltSearch(samples=800, reachable=False),
        motion=jl.HaltMotionSettings(solver="ga", ga=GASettings(n_pop=6, n_gen=3)),
    )  # fmt: skip
    np.testing.assert_array_equal(old.problem.qf, new.problem.qf)
    assert float(old.motion.k) == float(new.motion.k) and old.samples == new.samples == 800


def test_one_setting_given_two_ways_an_unknown_keyword_and_a_wrong_type_are_refused(fresh_warnings):
    with pytest.raises(TypeError, match=r"got samples= and search=: .*give it once, in search=HaltSearch\(samples=...\)"):
        jl.plan_halt("halt7", samples=100, search=jl.HaltSearch(samples=200))
    with pytest.raises(TypeError, match=r"got vmax_deg= and limits=.*\(a JointLimits is used as it is\)"):
        model = jl.lock(jl.load_robot("halt7", base="floating"), 4, 0.0)
        jl.plan_halt("halt7", vmax_deg=40.0, limits=jl.halt_limits(model))
    with pytest.raises(TypeError, match=r"plan_halt\(\) got an unexpected keyword argument 'sample'"):
        jl.plan_halt("halt7", sample=100)
    with pytest.raises(jl.ScenarioError, match=r"^motion must be a HaltMotionSettings; got dict$"):
        jl.plan_halt("halt7", motion={"solver": "ga"})
    with pytest.raises(jl.ScenarioError, match=r"^limits must be a HaltLimits or JointLimits; got float$"):
        jl.plan_halt("halt7", limits=40.0)
    with pytest.raises(jl.ScenarioError, match=r"motion.n_samples must be an odd integer"):
        jl.plan_halt("halt7", motion=jl.HaltMotionSettings(n_samples=100))


def test_resolved_limits_keep_the_former_margin_keyword(fresh_warnings):
    """A JointLimits is used as it is; the former margin= still goes with it (as HaltLimits'
    margin does)."""
    model = jl.lock(jl.load_robot("halt7", base="floating"), 4, 0.0)
    with pytest.warns(FutureWarning, match="margin="):
        old = jl.plan_halt("halt7", paper_qf=True, limits=jl.halt_limits(model), margin=0.02)
    new = jl.plan_halt("halt7", paper_qf=True, limits=jl.HaltLimits(margin=0.02))
    assert float(old.motion.k) == float(new.motion.k) and old.margin == new.margin == 0.02


def test_settings_are_plain_and_picklable():
    settings = (
        jl.HaltLimits(vmax_deg=[40.0] * 6, torque_max_Nm=900.0, margin=0.05),
        jl.HaltSearch(samples=1000, reachable=False),
        jl.HaltMotionSettings(solver="ga", ga=GASettings(n_pop=8)),
    )
    for s in settings:
        assert json.loads(json.dumps(s.to_dict())) == s.to_dict()
        assert pickle.loads(pickle.dumps(s)).to_dict() == s.to_dict()
    assert settings[0].to_dict()["vmax_deg"] == [40.0] * 6 and settings[2].to_dict()["ga"]["n_pop"] == 8
    assert set(FORMER_KEYWORDS) >= {"vmax_deg", "samples", "solver", "ga", "moment_about"}


def test_a_former_none_is_the_default_and_settings_refuse_wrong_kinds_in_one_line(fresh_warnings):
    with pytest.warns(FutureWarning) as caught:
        plan = jl.plan_halt("halt7", paper_qf=True, ga=None, motion=None, n_samples=101)
    assert plan.motion.solver == "scan" and len(caught) == 2 and "ga=" in str(caught[0].message)
    for build, words in (
        (lambda: jl.HaltSearch(samples="200"), "search.samples must be an integer >= 2"),
        (lambda: jl.HaltSearch(reachable="no"), "search.reachable must be True or False"),
        (lambda: jl.HaltMotionSettings(solver="ga", ga={"n_pop": 4}), "motion.ga must be a GASettings"),
        (lambda: jl.HaltMotionSettings(solver="newton"), "motion.solver must be one of scan, ga, vector"),
        (lambda: jl.HaltLimits(vmax_deg="fast"), "limits.vmax_deg must be one number or one per joint"),
    ):
        with pytest.raises(jl.ScenarioError, match=words) as info:
            build()
        assert "\n" not in str(info.value)
