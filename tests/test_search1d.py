"""Batched 1-D searches (jointlock._search1d): known minima and roots, tolerances, batched = looped."""

from __future__ import annotations

import math

import numpy as np
import pytest

from jointlock._search1d import GOLDEN, bisect_boundary, bisect_root, golden_section_minimize
from jointlock.errors import ScenarioError

#: Centres of the test parabolas, a (2, 3) batch (leading batch dimensions).
CENTRES = np.array([[-1.5, 0.0, 0.3], [2.0, 7.25, -0.01]])


def _vee(x: np.ndarray) -> np.ndarray:
    return np.abs(x - CENTRES) + 1.0


def test_golden_finds_known_minima_to_xtol():
    lo, hi = CENTRES - 1.0 - np.arange(6).reshape(2, 3), CENTRES + 2.5
    res = golden_section_minimize(_vee, lo, hi, xtol=1e-11)
    assert res.x.shape == (2, 3)
    assert np.all(np.abs(res.x - CENTRES) <= 1e-11)
    assert np.all(np.abs(res.upper - res.lower) <= 1e-11)
    assert np.all((res.lower <= res.x) & (res.x <= res.upper))
    np.testing.assert_array_equal(res.fun, _vee(res.x))
    # a smooth minimum: values closer than ~sqrt(eps) are equal in floating point
    res = golden_section_minimize(lambda x: (x - CENTRES) ** 2 + 1.0, lo, hi, xtol=1e-7)
    assert np.all(np.abs(res.x - CENTRES) <= 1e-7)
    # cos has its minimum at pi on [2, 4]; a scalar problem is a 0-d batch
    res = golden_section_minimize(np.cos, 2.0, 4.0, xtol=1e-8)
    assert res.x.shape == () and abs(float(res.x) - math.pi) <= 1e-8


def test_golden_fixed_steps_shrink_by_the_golden_ratio():
    lo, hi = np.zeros(3), np.array([1.0, 10.0, 100.0])
    n = 40
    res = golden_section_minimize(lambda x: (x - 0.3 * hi) ** 2, lo, hi, iterations=n)
    assert res.iterations == n
    np.testing.assert_allclose(res.upper - res.lower, hi * GOLDEN**n, rtol=1e-6)
    assert np.all(np.abs(res.x - 0.3 * hi) <= hi * GOLDEN**n)


def test_golden_batched_equals_looped():
    rng = np.random.default_rng(3)
    c = rng.normal(size=7)
    lo, hi = c - rng.uniform(0.1, 5.0, 7), c + rng.uniform(0.1, 5.0, 7)

    def f(x, c=c):
        return np.cosh(x - c)

    for kw in ({"xtol": 1e-7}, {"iterations": 30}):
        batched = golden_section_minimize(f, lo, hi, **kw)
        for i in range(c.size):
            one = golden_section_minimize(lambda x, i=i: np.cosh(x - c[i]), lo[i], hi[i], **kw)
            assert one.x == batched.x[i] and one.fun == batched.fun[i]
            assert one.lower == batched.lower[i] and one.upper == batched.upper[i]


def test_golden_treats_nan_and_inf_as_not_smaller():
    # undefined right of 1: the search keeps to the left and finds the minimum at 0.5
    res = golden_section_minimize(lambda x: np.where(x < 1.0, (x - 0.5) ** 2, np.nan), 0.0, 3.0, xtol=1e-9)
    assert abs(float(res.x) - 0.5) <= 1e-9


def test_bisect_root_finds_known_roots_to_xtol():
    c = np.array([[0.5, 2.0, 9.0], [1e-4, 3.0, 100.0]])
    root = bisect_root(lambda x: x**2 - c, np.zeros_like(c), np.full_like(c, 11.0), xtol=1e-10)
    assert root.shape == c.shape
    assert np.all(np.abs(root - np.sqrt(c)) <= 0.5e-10)
    # a bracket given high end first, and a decreasing function
    assert abs(float(bisect_root(np.cos, 3.0, 0.0, xtol=1e-12)) - math.pi / 2) <= 0.5e-12


def test_bisect_root_fixed_steps_and_known_f_lo():
    c = np.linspace(0.1, 0.9, 5)
    n = 30
    calls = []

    def f(x):
        calls.append(1)
        return x - c

    root = bisect_root(f, 0.0, 1.0, iterations=n)
    assert len(calls) == n + 1  # fun(lo), then one call per step
    assert np.all(np.abs(root - c) <= 2.0 ** -(n + 1))
    calls.clear()
    again = bisect_root(f, 0.0, 1.0, f_lo=-c, iterations=n)
    assert len(calls) == n
    np.testing.assert_array_equal(again, root)


def test_bisect_root_batched_equals_looped():
    rng = np.random.default_rng(11)
    c = rng.uniform(-3, 3, size=9)
    lo, hi = c - rng.uniform(0.01, 4.0, 9), c + rng.uniform(0.01, 4.0, 9)
    for kw in ({"xtol": 1e-9}, {"iterations": 25}):
        batched = bisect_root(lambda x: np.tanh(x - c), lo, hi, **kw)
        looped = [float(bisect_root(lambda x, i=i: np.tanh(x - c[i]), lo[i], hi[i], **kw)) for i in range(9)]
        np.testing.assert_array_equal(batched, looped)


def test_bisect_boundary_straddles_the_change():
    edge = np.array([0.25, 0.5, 0.8])
    br = bisect_boundary(lambda x: x >= edge, np.zeros(3), np.ones(3), xtol=1e-6)
    assert np.all(br.false_end < edge) and np.all(br.true_end >= edge)
    assert np.all(br.true_end - br.false_end <= 1e-6)
    # false end above the true end: the predicate is True below the edge
    br = bisect_boundary(lambda x: x <= edge, np.ones(3), np.zeros(3), iterations=20)
    assert br.iterations == 20
    assert np.all(br.false_end > edge) and np.all(br.true_end <= edge)
    np.testing.assert_allclose(br.false_end - br.true_end, 2.0**-20)


def test_bisect_stops_when_round_off_stops_the_bracket():
    # xtol = 0 cannot be met once the ends are adjacent floats: the search still ends there
    br = bisect_boundary(lambda x: x >= 1.0 / 3.0, 0.0, 1.0, xtol=0.0)
    assert np.nextafter(float(br.false_end), 1.0) == float(br.true_end)
    res = golden_section_minimize(lambda x: (x - 1.0 / 3.0) ** 2, 0.0, 1.0, xtol=0.0)
    assert abs(float(res.x) - 1.0 / 3.0) < 1e-7  # golden section: sqrt(eps) of a smooth minimum


@pytest.mark.parametrize(
    "kw", [{}, {"iterations": 3, "xtol": 1e-3}, {"iterations": -1}, {"iterations": 2.5}, {"xtol": np.nan}]
)
def test_termination_must_be_one_valid_setting(kw):
    with pytest.raises(ScenarioError, match="iterations|xtol"):
        bisect_root(lambda x: x, -1.0, 1.0, **kw)
    with pytest.raises(ScenarioError, match="iterations|xtol"):
        golden_section_minimize(lambda x: x**2, -1.0, 1.0, **kw)
