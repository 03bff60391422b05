"""The adaptive genetic algorithm of seed 000 §4.2 (Steps 1-4, eqs. 35-38).

Binary coding of each gene on ``[lower, upper]`` with a resolution of ``precision``, an
elite kept unchanged, fitness-proportional (roulette) selection (eq. 36), single-point
crossover with the adaptive probability of eq. 37, bit-flip mutation with the adaptive
probability of eq. 38, whose ``f'`` is read as the fitness of the pre-crossover parent
(children are not scored before mutation).  This is Srinivas & Patnaik's adaptive GA, which
000 follows; their recommended constants ``g1 = g2 = 1.0``, ``g3 = g4 = 0.5`` are the
defaults.  The whole
population is scored in one call ``(n_pop, n_genes) -> (n_pop,)``; chromosomes already
scored are not scored again (the GA converges onto a few codes, so this saves most calls
without changing the result).

000 prints neither the population size nor the number of generations; the defaults here
(50 individuals, 100 generations, 10-bit genes for a resolution of 1e-4 of the paper's
k range) are ours.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from .._random import resolve_rng
from ..errors import ScenarioError
from ..model import FloatArray

FitnessFn = Callable[[FloatArray], FloatArray]


#: Most bits per gene: a double's 52-bit mantissa resolves no finer grid on a gene's range
#: (and ``2 ** n_bits`` must stay a finite float).
MAX_BITS = 52


@dataclass(frozen=True)
class GASettings:
    """Settings of :func:`adaptive_ga` (see there): ``n_pop >= 2``, ``n_gen >= 0`` and
    ``1 <= n_bits <=`` :data:`MAX_BITS`, checked when the GA starts."""

    n_pop: int = 50
    n_gen: int = 100
    n_bits: int = 10
    g1: float = 1.0
    g2: float = 1.0
    g3: float = 0.5
    g4: float = 0.5


@dataclass(frozen=True)
class GAResult:
    """Outcome of :func:`adaptive_ga`.

    Attributes
    ----------
    x
        (n_genes,) best decoded genes found over all generations.
    fitness
        Fitness of ``x`` (the value maximised).
    best_history
        (n_gen + 1,) best fitness after each generation (index 0: initial population).
    mean_history
        (n_gen + 1,) mean fitness of each generation.
    n_evaluations
        Distinct chromosomes scored.
    settings
        The :class:`GASettings` used.
    seed
        The seed the run started from (the fresh one drawn for ``rng=None``), or None when a
        ``Generator`` was passed (:mod:`jointlock._random`).
    lower, upper
        (n_genes,) search bounds.
    """

    x: FloatArray
    fitness: float
    best_history: FloatArray
    mean_history: FloatArray
    n_evaluations: int
    settings: GASettings
    seed: int | None
    lower: FloatArray = field(repr=False)
    upper: FloatArray = field(repr=False)


def bits_for_precision(lower: float, upper: float, precision: float) -> int:
    """Smallest number of bits whose grid on ``[lower, upper]`` has steps <= ``precision``
    (000 Step 1: "according to the accuracy of the solution and the solution space")."""
    if not precision > 0:
        raise ScenarioError(f"precision must be > 0; got {precision}")
    bits = max(1, math.ceil(math.log2((upper - lower) / precision + 1.0)))
    if bits > MAX_BITS:
        raise ScenarioError(
            f"precision {precision:g} on [{lower:g}, {upper:g}] needs {bits} bits per gene, more than "
            f"the {MAX_BITS} a float resolves; give a precision >= {(upper - lower) / (2.0**MAX_BITS - 1):.3g}"
        )
    return bits


def _check_bits(n_bits: Any) -> None:
    if isinstance(n_bits, bool) or not isinstance(n_bits, (int, np.integer)) or not 1 <= n_bits <= MAX_BITS:
        raise ScenarioError(f"n_bits must be an integer in [1, {MAX_BITS}] (bits per gene); got {n_bits!r}")


def decode(chromosomes: ArrayLike, lower: ArrayLike, upper: ArrayLike, n_bits: int) -> FloatArray:
    """Binary chromosomes (n_pop, n_genes * n_bits) -> genes (n_pop, n_genes), linear map of
    the unsigned integer (most significant bit first) onto ``[lower, upper]``."""
    _check_bits(n_bits)
    bits = np.asarray(chromosomes, dtype=bool)
    lower = np.atleast_1d(np.asarray(lower, dtype=float))
    upper = np.atleast_1d(np.asarray(upper, dtype=float))
    n_genes = lower.size
    weights = 2.0 ** np.arange(n_bits - 1, -1, -1)
    ints = bits.reshape(bits.shape[:-1] + (n_genes, n_bits)) @ weights
    return lower + ints / (2.0**n_bits - 1.0) * (upper - lower)


def _adaptive_probability(f: FloatArray, f_max: float, f_avg: float, g_hi: float, g_lo: float) -> FloatArray:
    """000 eqs. 37-38: ``g_hi (f_max - f) / (f_max - f_avg)`` for ``f >= f_avg``, else ``g_lo``.
    When the population has converged (``f_max == f_avg``) the first branch is 0."""
    spread = f_max - f_avg
    ratio = np.where(spread > 0, (f_max - f) / np.where(spread > 0, spread, 1.0), 0.0)
    return np.where(f >= f_avg, g_hi * np.clip(ratio, 0.0, 1.0), g_lo)


# Over 100 lines: 25 are the docstring; the generation loop (eqs. 36-38) shares its population state.
def adaptive_ga(
    fitness: FitnessFn,
    lower: ArrayLike,
    upper: ArrayLike,
    *,
    settings: GASettings | None = None,
    rng: int | np.random.Generator | None = 0,
    progress: Any = None,
) -> GAResult:
    """Maximise ``fitness`` over a box with 000's adaptive GA.

    Parameters
    ----------
    fitness
        Batched fitness, ``(n_pop, n_genes) -> (n_pop,)``, larger is better and >= 0 (000
        eq. 35 uses ``1 / tau_b_bar``); roulette selection needs non-negative values.
    lower, upper
        (n_genes,) bounds of the genes (scalars for one gene).
    settings
        Population size, generations, bits per gene and the constants ``g1..g4`` of eqs.
        37-38 (``pc``: ``g1``, ``g2``; ``pm``, per bit: ``g3``, ``g4``).  Eq. 38's ``f'``
        is the fitness of the pre-crossover parent (a child is not scored before mutation).
    rng
        Seed (int >= 0) or ``numpy.random.Generator``, recorded in the result (default 0: the
        same run every time).  ``None`` draws a fresh seed from the operating system and
        records that seed, so the run can still be repeated; a Generator records None.
        Anything else raises :class:`~jointlock.errors.ConfigurationError`.
    progress
        Optional :class:`jointlock.progress.Progress`-like object (``update()`` per generation).

    Returns
    -------
    GAResult
        Best genes over all generations and the fitness histories.
    """
    st = settings or GASettings()
    if st.n_pop < 2 or st.n_gen < 0 or st.n_bits < 1:
        raise ScenarioError(f"GA needs n_pop >= 2, n_gen >= 0, n_bits >= 1; got {st}")
    _check_bits(st.n_bits)
    lo = np.atleast_1d(np.asarray(lower, dtype=float))
    hi = np.atleast_1d(np.asarray(upper, dtype=float))
    if lo.shape != hi.shape or not np.all(lo <= hi):
        raise ScenarioError(f"GA bounds must satisfy lower <= upper; got {lo.tolist()}, {hi.tolist()}")
    if not (np.all(np.isfinite(lo)) and np.all(np.isfinite(hi))):
        raise ScenarioError(f"GA bounds must be finite; got {lo.tolist()}, {hi.tolist()}")
    gen, seed = resolve_rng(rng)
    n_genes = lo.size
    length = n_genes * st.n_bits
    cache: dict[bytes, float] = {}

    def score(pop: np.ndarray) -> FloatArray:
        keys = [row.tobytes() for row in pop]
        new = {k: i for i, k in enumerate(keys) if k not in cache}
        if new:
            idx = np.fromiter(new.values(), dtype=int)
            values = np.asarray(fitness(decode(pop[idx], lo, hi, st.n_bits)), dtype=float)
            if values.shape != (idx.size,) or np.any(~np.isfinite(values)) or np.any(values < 0):
                raise ScenarioError("GA fitness must return (n_pop,) finite values >= 0")
            cache.update(zip(new.keys(), values.tolist()))
        return np.array([cache[k] for k in keys])

    # Step 1: initial population
    pop = gen.random((st.n_pop, length)) < 0.5
    fit = score(pop)
    best_i = int(np.argmax(fit))
    best_chrom, best_fit = pop[best_i].copy(), float(fit[best_i])
    best_hist, mean_hist = [best_fit], [float(fit.mean())]
    for _ in range(st.n_gen):
        f_max, f_avg = float(fit.max()), float(fit.mean())
        elite = pop[int(np.argmax(fit))].copy()
        # Step 3 (1): roulette selection, eq. 36
        total = fit.sum()
        p = fit / total if total > 0 else np.full(st.n_pop, 1.0 / st.n_pop)
        parents = gen.choice(st.n_pop, size=st.n_pop, p=p)
        children = pop[parents].copy()
        child_fit = fit[parents]
        # Step 3 (2): single-point crossover of consecutive pairs, pc of eq. 37
        n_pairs = st.n_pop // 2
        a, b = np.arange(0, 2 * n_pairs, 2), np.arange(1, 2 * n_pairs, 2)
        f_pair = np.maximum(child_fit[a], child_fit[b])
        pc = _adaptive_probability(f_pair, f_max, f_avg, st.g1, st.g2)
        do = gen.random(n_pairs) < pc
        cut = gen.integers(1, max(length, 2), size=n_pairs)
        swap = (np.arange(length)[None, :] >= cut[:, None]) & do[:, None]
        tmp = children[a].copy()
        children[a] = np.where(swap, children[b], children[a])
        children[b] = np.where(swap, tmp, children[b])
        # Step 3 (3): bit-flip mutation, pm of eq. 38.  Eq. 38's f' (the fitness of the
        # individual to be mutated) is read as the fitness of the selected parent before
        # crossover: the child is not evaluated between crossover and mutation (that would
        # cost a second fitness call per generation), so a crossed-over child is mutated with
        # the probability of the parent whose slot it holds.
        pm = _adaptive_probability(child_fit, f_max, f_avg, st.g3, st.g4)
        children ^= gen.random((st.n_pop, length)) < pm[:, None]
        # elitism: the best individual survives unchanged (replaces the first child)
        children[0] = elite
        pop = children
        fit = score(pop)  # Step 2: evaluation, eq. 35
        i = int(np.argmax(fit))
        if fit[i] > best_fit:
            best_chrom, best_fit = pop[i].copy(), float(fit[i])
        best_hist.append(best_fit)
        mean_hist.append(float(fit.mean()))
        if progress is not None:
            progress.update()
    x = decode(best_chrom[None], lo, hi, st.n_bits)[0]
    return GAResult(
        x=x,
        fitness=best_fit,
        best_history=np.array(best_hist),
        mean_history=np.array(mean_hist),
        n_evaluations=len(cache),
        settings=st,
        seed=seed,
        lower=lo,
        upper=hi,
    )
