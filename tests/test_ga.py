"""000's adaptive GA: coding, determinism, eqs. 37-38, and GA ~ exact scan."""

from __future__ import annotations

import math

import numpy as np
import pytest

import jointlock as jl
from jointlock.papers import p000
from jointlock.planning.ga import GASettings, _adaptive_probability, adaptive_ga, bits_for_precision, decode
from jointlock.planning.halt_motion import HaltProblem, optimal_halt_motion


def test_decode_and_bits():
    assert bits_for_precision(0.0, 0.1, 1e-4) == 10
    bits = np.array([[0] * 4, [1] * 4, [1, 0, 0, 0]], dtype=bool)
    np.testing.assert_allclose(decode(bits, -1.0, 2.0, 4)[:, 0], [-1.0, 2.0, -1.0 + 8 / 15 * 3])


def test_adaptive_probabilities_eqs_37_38():
    f = np.array([1.0, 2.0, 3.0, 4.0])  # avg 2.5, max 4
    p = _adaptive_probability(f, 4.0, 2.5, 1.0, 0.7)
    np.testing.assert_allclose(p, [0.7, 0.7, 1.0 / 1.5, 0.0])


def test_ga_is_seeded_and_batched():
    calls = []

    def fitness(x):
        calls.append(x.shape)
        return 1.0 / (1.0 + (x[:, 0] - 0.3) ** 2 + (x[:, 1] + 0.2) ** 2)

    st = GASettings(n_pop=20, n_gen=30, n_bits=12)
    a = adaptive_ga(fitness, [-1, -1], [1, 1], settings=st, rng=7)
    b = adaptive_ga(fitness, [-1, -1], [1, 1], settings=st, rng=7)
    c = adaptive_ga(fitness, [-1, -1], [1, 1], settings=st, rng=8)
    np.testing.assert_array_equal(a.x, b.x)
    np.testing.assert_array_equal(a.best_history, b.best_history)
    assert not np.array_equal(a.best_history, c.best_history) or not np.array_equal(a.x, c.x)
    assert all(len(s) == 2 and s[1] == 2 for s in calls)  # (n_new, n_genes) per call
    assert np.all(np.diff(a.best_history) >= 0)  # elitism
    np.testing.assert_allclose(a.x, [0.3, -0.2], atol=0.02)


def test_ga_lands_on_scan_optimum():
    model = jl.lock(jl.robots.halt7(base="floating"), 4, 0.0)
    d = np.radians
    p = HaltProblem(
        model,
        *(d(p000.SCENARIO[k]) for k in ("q0_deg", "dq0_deg", "ddq0_deg", "qf_deg")),  # 000 §5.2
        12.0,
        d(p000.SCENARIO["vmax_deg"]),
        d(p000.SCENARIO["amax_deg"]),
        n_samples=201,
    )
    scan = optimal_halt_motion(p, n_scan=201)
    ga = optimal_halt_motion(p, solver="ga", rng=3, ga_settings=GASettings(n_pop=30, n_gen=40))
    lo, hi = scan.k_interval
    assert ga.feasible and ga.seed == 3
    # one GA code step is (hi - lo) / 1023; allow three
    assert abs(ga.k - scan.k) <= 3 * (hi - lo) / 1023
    assert ga.global_torque == pytest.approx(scan.global_torque, rel=1e-4)


def test_ga_rejects_bad_fitness():
    with pytest.raises(jl.ScenarioError, match="fitness"):
        adaptive_ga(lambda x: -np.ones(len(x)), 0.0, 1.0, settings=GASettings(n_pop=4, n_gen=1), rng=0)
    assert math.isfinite(bits_for_precision(0, 1, 0.5))


def test_ga_default_seed_is_0_and_a_fresh_seed_is_recorded():
    st = GASettings(n_pop=10, n_gen=5, n_bits=8)

    def fitness(x):
        return 1.0 / (1.0 + (x[:, 0] - 0.3) ** 2)

    a = adaptive_ga(fitness, -1.0, 1.0, settings=st)
    b = adaptive_ga(fitness, -1.0, 1.0, settings=st)
    assert a.seed == 0
    np.testing.assert_array_equal(a.best_history, b.best_history)
    np.testing.assert_array_equal(
        a.mean_history, adaptive_ga(fitness, -1.0, 1.0, settings=st, rng=0).mean_history
    )
    fresh = adaptive_ga(fitness, -1.0, 1.0, settings=st, rng=None)
    assert isinstance(fresh.seed, int) and fresh.seed >= 0  # repeatable from the result
    again = adaptive_ga(fitness, -1.0, 1.0, settings=st, rng=fresh.seed)
    np.testing.assert_array_equal(fresh.mean_history, again.mean_history)


def test_bits_are_capped_at_52():
    from jointlock.planning.ga import MAX_BITS

    assert MAX_BITS == 52
    f = lambda x: np.ones(x.shape[0])  # noqa: E731
    with pytest.raises(jl.ScenarioError, match=r"n_bits must be an integer in \[1, 52\]"):
        adaptive_ga(f, 0.0, 1.0, settings=GASettings(n_bits=2000))  # was OverflowError
    with pytest.raises(jl.ScenarioError, match="n_bits"):
        decode(np.zeros((1, 60), bool), 0.0, 1.0, 60)
    with pytest.raises(jl.ScenarioError, match="precision"):
        bits_for_precision(0.0, 1.0, 1e-300)
    assert adaptive_ga(f, 0.0, 1.0, settings=GASettings(n_pop=4, n_gen=2, n_bits=52)).x.shape == (1,)
    with pytest.raises(jl.ScenarioError, match="finite"):
        adaptive_ga(f, -np.inf, np.inf)


def test_mutation_reading_of_eq_38_is_documented():
    import jointlock.planning.ga as ga

    assert "pre-crossover parent" in ga.__doc__ and "pre-crossover parent" in ga.adaptive_ga.__doc__
