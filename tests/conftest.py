"""Shared fixtures and tolerances for the test suite."""

from __future__ import annotations

import os

import numpy as np
import pytest
from hypothesis import HealthCheck, settings

import jointlock as jl

# Property-based fuzzing (tests/test_fuzz_inputs.py): the default profile is a fixed, derandomized
# example budget (the same 2,100 inputs every run, ~20 s); HYPOTHESIS_PROFILE=long draws fresh
# inputs, 20x as many, and keeps failures in the example database.
_FUZZ = dict(deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
settings.register_profile("default", derandomize=True, database=None, **_FUZZ)
settings.register_profile("long", max_examples=2000, **_FUZZ)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "default"))

#: Central finite-difference step [rad]; truncation error ~ h^2 * |f'''| ~ 1e-10 for these arms.
FD_STEP = 1e-6
#: Agreement of an analytic derivative with central differences (absolute, in the units of the
#: derivative; rounding error ~ eps * |f| / h ~ 1e-9 for 10 m arms).
FD_ATOL = 1e-7
#: Two exact computations of the same quantity (round-off only).
EXACT_ATOL = 1e-10
#: Pinocchio oracle agreement required by the foundation issue.
ORACLE_ATOL = 1e-10

ROBOT_NAMES = tuple(jl.BUILTIN_ROBOTS)


@pytest.fixture(autouse=True)
def _no_compiled_mode_leaks():
    """A test that sets the process's compiled mode (jl.set_compiled_mode) leaves it unset.
    (JOINTLOCK_COMPILED=always in the environment runs the suite on the compiled paths.)"""
    yield
    jl.set_compiled_mode(None)


@pytest.fixture
def rng() -> np.random.Generator:
    return np.random.default_rng(20261121)


def random_q(model: jl.ArmModel, rng: np.random.Generator, shape: tuple[int, ...] = ()) -> np.ndarray:
    """Uniform configurations within the joint limits (capped to +-pi)."""
    lo = np.maximum(model.lower, -np.pi)
    hi = np.minimum(model.upper, np.pi)
    return rng.uniform(lo, hi, size=shape + (model.dof,))
