"""The one rng convention (jointlock._random), checked on one stochastic function of each module
that follows it: ``rng=None`` draws a fresh seed and records it (rerunning with that seed gives
the same numbers), an int seed is reproducible and recorded, a Generator is used as given (same
stream as its seed, its state advanced, seed recorded as None), anything else raises
ConfigurationError naming ``rng``."""

from __future__ import annotations

import functools
from collections.abc import Callable
from typing import Any

import numpy as np
import pytest

import jointlock as jl
from jointlock._random import fresh_seed, resolve_rng, resolve_seed
from jointlock.analysis import singularity as sg
from jointlock.analysis.workspace import compare_workspaces
from jointlock.errors import ConfigurationError
from jointlock.papers import p000
from jointlock.planning.ga import GASettings, adaptive_ga
from jointlock.planning.halt_config import optimal_halt_configuration
from jointlock.planning.halt_motion import HaltProblem, optimal_halt_motion

BAD_RNGS = (-1, True, 1.5, "3", np.random.RandomState(0))


@functools.cache
def _halt7_locked() -> jl.ArmModel:
    return jl.lock(jl.load_robot("halt7", base="floating"), 4, 0.0)


@functools.cache
def _halt_problem() -> HaltProblem:
    d = np.radians
    return HaltProblem(
        _halt7_locked(),
        *(d(p000.SCENARIO[k]) for k in ("q0_deg", "dq0_deg", "ddq0_deg", "qf_deg")),  # 000 §5.2
        12.0,
        d(p000.SCENARIO["vmax_deg"]),
        d(p000.SCENARIO["amax_deg"]),
        n_samples=51,
    )


def _ga(rng: Any):
    st = GASettings(n_pop=10, n_gen=4, n_bits=8)
    return adaptive_ga(lambda x: 1.0 / (1.0 + (x[:, 0] - 0.3) ** 2), -1.0, 1.0, settings=st, rng=rng)


def _halt_config(rng: Any):
    return optimal_halt_configuration(_halt7_locked(), samples=40, rng=rng, refine=False)


def _halt_motion(rng: Any):
    return optimal_halt_motion(_halt_problem(), solver="ga", rng=rng, ga_settings=GASettings(n_pop=8, n_gen=3))


def _workspace(rng: Any):
    return compare_workspaces(jl.load_robot("puma6"), 3, 0.5, samples=200, rng=rng)


def _singularity_search(rng: Any):
    return sg.find_singularities(jl.load_robot("puma6"), samples=4, max_iter=2, rng=rng)


def _condition_verification(rng: Any):
    return sg.verify_conditions(jl.load_robot("canadarm7", base="floating"), samples=8, search_samples=2, rng=rng)


#: name -> (run(rng) -> result with a ``seed``, the numbers the draw decides)
CASES: dict[str, tuple[Callable[[Any], Any], Callable[[Any], tuple]]] = {
    "planning.ga.adaptive_ga": (_ga, lambda r: (r.x, r.mean_history)),
    "planning.halt_config.optimal_halt_configuration": (_halt_config, lambda r: (r.q_samples, r.cp_samples)),
    "planning.halt_motion.optimal_halt_motion": (_halt_motion, lambda r: (r.k, r.ga.mean_history)),
    "analysis.workspace.compare_workspaces": (_workspace, lambda r: (r.full, r.locked)),
    "analysis.singularity.find_singularities": (_singularity_search, lambda r: (r.q_start, r.q_final)),
    "analysis.singularity.verify_conditions": (
        _condition_verification,
        lambda r: tuple(c.sigma_min_median for c in r.checks.values()) + (r.completeness.unexplained,),
    ),
}


def _same(a: tuple, b: tuple) -> bool:
    return len(a) == len(b) and all(np.array_equal(x, y, equal_nan=True) for x, y in zip(a, b))


@pytest.mark.parametrize("name", CASES)
def test_none_records_a_fresh_seed_that_reproduces_the_run(name):
    run, numbers = CASES[name]
    fresh = run(None)
    assert type(fresh.seed) is int and 0 <= fresh.seed < 2**63
    assert _same(numbers(fresh), numbers(run(fresh.seed)))
    assert run(None).seed != fresh.seed  # a new seed each time (2^-63 to collide)


@pytest.mark.parametrize("name", CASES)
def test_int_seed_is_reproducible_and_recorded(name):
    run, numbers = CASES[name]
    a, b = run(5), run(np.int64(5))
    assert a.seed == 5 and type(b.seed) is int and b.seed == 5
    assert _same(numbers(a), numbers(b))
    assert not _same(numbers(a), numbers(run(6)))


@pytest.mark.parametrize("name", CASES)
def test_generator_is_used_as_given_and_records_no_seed(name):
    run, numbers = CASES[name]
    gen = np.random.default_rng(5)
    before = gen.bit_generator.state
    result = run(gen)
    assert result.seed is None
    # the caller's generator was drawn from (or spawned children: verify_conditions), not a copy
    assert gen.bit_generator.state != before or gen.bit_generator.seed_seq.n_children_spawned > 0
    assert _same(numbers(result), numbers(run(5)))  # the stream of default_rng(seed)


@pytest.mark.parametrize("name", CASES)
@pytest.mark.parametrize("bad", BAD_RNGS, ids=repr)
def test_bad_rng_raises_configuration_error(name, bad):
    run, _ = CASES[name]
    with pytest.raises(ConfigurationError, match="rng must be None, an integer seed >= 0 or a numpy Generator"):
        run(bad)


def test_halt_motion_checks_rng_whatever_the_solver():
    assert optimal_halt_motion(_halt_problem(), n_scan=11, rng=None).seed is None  # scan draws nothing
    with pytest.raises(ConfigurationError, match="rng"):
        optimal_halt_motion(_halt_problem(), n_scan=11, rng=-1)


def test_the_convention_itself():
    assert resolve_seed(7) == 7 and type(resolve_seed(np.uint8(7))) is int
    gen = np.random.default_rng(1)
    assert resolve_seed(gen) is gen and resolve_rng(gen) == (gen, None)
    g, seed = resolve_rng(None)
    assert type(seed) is int and 0 <= seed < 2**63
    assert g.random() == np.random.default_rng(seed).random()
    assert 0 <= fresh_seed() < 2**63
    with pytest.raises(ConfigurationError, match="^q_seed must be None"):
        resolve_seed(-2, name="q_seed")
