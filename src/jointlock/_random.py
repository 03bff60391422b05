"""The one randomness convention of jointlock.

Every stochastic function takes ``rng: int | numpy.random.Generator | None`` (keyword) and its
result records the seed actually used:

- an ``int`` >= 0 is the seed (``numpy.random.default_rng(seed)``): same seed, same result;
- ``None`` draws a fresh seed from the operating system's entropy and uses it like an int, so
  the run is still reproducible from its recorded seed;
- a ``Generator`` is used as it is (its state is the caller's): the recorded seed is ``None``.

Anything else (a negative int, a bool, a float, a string, a legacy ``RandomState``) raises
:class:`~jointlock.errors.ConfigurationError` naming the parameter.  An int seed ``s`` gives the
stream of ``numpy.random.default_rng(s)``, so ``rng=s`` and ``rng=default_rng(s)`` draw the
same numbers (only the recorded seed differs).  A function draws its seed once, at its start,
with :func:`resolve_rng` (or :func:`resolve_seed` when it hands the seed on to another
stochastic function), and stores it in its result's ``seed`` field.
"""

from __future__ import annotations

from typing import TypeAlias

import numpy as np

from .errors import ConfigurationError

#: What every ``rng=`` parameter accepts.
RngLike: TypeAlias = "int | np.random.Generator | None"


def fresh_seed() -> int:
    """A new seed in [0, 2**63) from the operating system's entropy."""
    return int(np.random.SeedSequence().generate_state(1, dtype=np.uint64)[0] >> np.uint64(1))


def resolve_seed(rng: int | np.random.Generator | None, name: str = "rng") -> int | np.random.Generator:
    """``rng`` checked, with ``None`` replaced by a :func:`fresh_seed`: an int seed or the
    caller's Generator.  ``name`` names the parameter in the error message."""
    if isinstance(rng, np.random.Generator):
        return rng
    if rng is None:
        return fresh_seed()
    if isinstance(rng, (int, np.integer)) and not isinstance(rng, (bool, np.bool_)) and int(rng) >= 0:
        return int(rng)
    raise ConfigurationError(f"{name} must be None, an integer seed >= 0 or a numpy Generator; got {rng!r}")


def resolve_rng(
    rng: int | np.random.Generator | None, name: str = "rng"
) -> tuple[np.random.Generator, int | None]:
    """``(generator, seed)`` for ``rng`` (see the module docstring): the seed used (an int),
    or ``None`` when the caller passed a Generator."""
    seed = resolve_seed(rng, name)
    if isinstance(seed, np.random.Generator):
        return seed, None
    return np.random.default_rng(seed), seed
