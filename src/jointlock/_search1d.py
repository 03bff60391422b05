"""Batched one-dimensional searches: golden-section minimisation and bisection.

Every function works on a batch of independent 1-D problems at once: the brackets ``lo``,
``hi`` are arrays of any (broadcast) shape ``(...)`` and the user's function maps an array
of that shape to one of the same shape, element by element (one batched call per step, no
loop over the batch).  Each element is its own problem: the result of a batched call is the
same, bit for bit, as calling the search once per element with the same settings (the
function is still evaluated on the whole batch at every step; elements that have already
met their tolerance are simply no longer updated).

Termination is set by exactly one of

``iterations``
    a fixed number of steps for every element (no early stop); or
``xtol``
    an absolute tolerance on the bracket width [unit of ``x``]: an element stops as soon as
    its bracket is no wider than ``xtol`` (or when round-off stops it from shrinking).

Tolerances reached
------------------
Golden section: the bracket shrinks by ``GOLDEN = (sqrt 5 - 1) / 2 ~ 0.618`` per step, so
after ``n`` steps it is ``|hi - lo| * GOLDEN**n`` wide; for a unimodal function the
returned point and the minimiser both lie in it (64 steps: ``4e-14 |hi - lo|``) -- as long
as the function values it compares differ: near a smooth minimum ``f(x* + e) - f(x*) ~ e^2``
is lost to round-off for ``e`` below about ``sqrt(eps) ~ 1.5e-8`` times the scale of ``x``,
so ties make the result no more accurate than that, whatever ``xtol`` (a kink, as in
``|x - c|``, is located to ``xtol``).
Bisection: the bracket halves per step (``|hi - lo| / 2**n`` after ``n``); the two ends
returned straddle the boundary (or the sign change) and the root returned by
:func:`bisect_root` is the midpoint, within half the final width of it.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike

from .errors import ScenarioError
from .model import FloatArray

#: Golden-ratio conjugate ``(sqrt 5 - 1) / 2``: the factor a golden-section bracket shrinks by per step.
GOLDEN = (math.sqrt(5.0) - 1.0) / 2.0

BatchFunction = Callable[[FloatArray], ArrayLike]


class GoldenResult(NamedTuple):
    """Result of :func:`golden_section_minimize`, each array (...) (the batch shape).

    Attributes
    ----------
    x
        Best point found (the better of the two interior points).
    fun
        ``fun(x)``.
    lower, upper
        Final bracket (``lower <= x <= upper`` for ``lo <= hi``).
    iterations
        Steps taken by the element that took the most.
    """

    x: FloatArray
    fun: FloatArray
    lower: FloatArray
    upper: FloatArray
    iterations: int


class Bracket(NamedTuple):
    """Result of :func:`bisect_boundary`, each array (...) (the batch shape).

    Attributes
    ----------
    false_end
        End of the final bracket where the predicate is False (it started at ``a``).
    true_end
        End where the predicate is True (it started at ``b``).
    iterations
        Steps taken by the element that took the most.
    """

    false_end: FloatArray
    true_end: FloatArray
    iterations: int


def _termination(iterations: int | None, xtol: ArrayLike | None) -> tuple[int | None, FloatArray | None]:
    if (iterations is None) == (xtol is None):
        raise ScenarioError(
            f"give exactly one of iterations (a step count) and xtol (a bracket width); "
            f"got iterations={iterations!r}, xtol={xtol!r}"
        )
    if iterations is not None:
        if isinstance(iterations, bool) or not isinstance(iterations, (int, np.integer)) or iterations < 0:
            raise ScenarioError(f"iterations must be an integer >= 0; got {iterations!r}")
        return int(iterations), None
    tol = np.asarray(xtol, dtype=float)
    if np.any(np.isnan(tol)) or np.any(tol < 0):
        raise ScenarioError(f"xtol must be >= 0 (a bracket width, unit of x), not NaN; got {xtol!r}")
    return None, tol


def _brackets(lo: ArrayLike, hi: ArrayLike) -> tuple[FloatArray, FloatArray]:
    a, b = np.broadcast_arrays(np.asarray(lo, dtype=float), np.asarray(hi, dtype=float))
    return a.copy(), b.copy()


def golden_section_minimize(
    fun: BatchFunction,
    lo: ArrayLike,
    hi: ArrayLike,
    *,
    iterations: int | None = None,
    xtol: ArrayLike | None = None,
) -> GoldenResult:
    """Golden-section minimisation of a batch of 1-D functions on ``[lo, hi]``.

    Parameters
    ----------
    fun
        Maps points (...) to values (...), element by element.  NaN or ``+inf`` values are
        treated as "not smaller" (the search then keeps the left part of the bracket).
    lo, hi
        (...) bracket ends (broadcast together).
    iterations, xtol
        Exactly one: a fixed number of steps, or the bracket width at which an element
        stops (see the module docstring; the width after ``n`` steps is
        ``|hi - lo| GOLDEN**n``).

    Returns
    -------
    GoldenResult
        ``x`` (...) the minimiser found (exact to the final bracket width for a unimodal
        function), ``fun`` its value, the final bracket and the step count.
    """
    n_fixed, tol = _termination(iterations, xtol)
    a, b = _brackets(lo, hi)
    c = b - GOLDEN * (b - a)
    d = a + GOLDEN * (b - a)
    fc, fd = np.asarray(fun(c), dtype=float), np.asarray(fun(d), dtype=float)
    active = np.ones(a.shape, dtype=bool) if tol is None else np.abs(b - a) > tol
    steps = 0
    while (steps < n_fixed) if n_fixed is not None else bool(np.any(active)):
        left = ~(fc > fd)  # minimum in [a, d]; NaN/inf compare False -> keep left
        nb = np.where(left, d, b)
        na = np.where(left, a, c)
        new = np.where(left, nb - GOLDEN * (nb - na), na + GOLDEN * (nb - na))
        fnew = np.asarray(fun(new), dtype=float)
        nc, nd, nfc, nfd = (
            np.where(left, new, d),
            np.where(left, c, new),
            np.where(left, fnew, fd),
            np.where(left, fc, fnew),
        )
        if tol is None:
            a, b, c, d, fc, fd = na, nb, nc, nd, nfc, nfd
        else:  # elements within tolerance keep their bracket
            shrunk = np.abs(nb - na) < np.abs(b - a)
            new_state, old_state = (na, nb, nc, nd, nfc, nfd), (a, b, c, d, fc, fd)
            a, b, c, d, fc, fd = (np.where(active, n, o) for n, o in zip(new_state, old_state))
            active = active & shrunk & (np.abs(b - a) > tol)
        steps += 1
    better = fc <= fd
    return GoldenResult(np.where(better, c, d), np.where(better, fc, fd), a, b, steps)


def bisect_boundary(
    predicate: Callable[[FloatArray], ArrayLike],
    a: ArrayLike,
    b: ArrayLike,
    *,
    iterations: int | None = None,
    xtol: ArrayLike | None = None,
) -> Bracket:
    """Bisection of the boundary of a batch of 1-D predicates.

    ``predicate`` is False at ``a`` and True at ``b`` (either may be the larger end); each
    step evaluates it at the midpoints and moves the end with the same value there.  For a
    predicate that changes once between ``a`` and ``b`` (e.g. "feasible" for a monotone
    problem) the final bracket straddles the change.

    Parameters
    ----------
    predicate
        Maps points (...) to bool (...), element by element.
    a, b
        (...) ends where the predicate is False and True (broadcast together; not checked).
    iterations, xtol
        Exactly one: a fixed number of halvings, or the width ``|b - a|`` at which an
        element stops.

    Returns
    -------
    Bracket
        ``false_end``, ``true_end`` (...) of the final bracket, ``|hi - lo| / 2**n`` wide
        after ``n`` steps, and the step count.
    """
    n_fixed, tol = _termination(iterations, xtol)
    a, b = _brackets(a, b)
    active = np.ones(a.shape, dtype=bool) if tol is None else np.abs(b - a) > tol
    steps = 0
    while (steps < n_fixed) if n_fixed is not None else bool(np.any(active)):
        mid = 0.5 * (a + b)
        m = np.asarray(predicate(mid), dtype=bool)
        if tol is None:
            a, b = np.where(m, a, mid), np.where(m, mid, b)
        else:  # elements within tolerance keep their bracket
            na, nb = np.where(active & ~m, mid, a), np.where(active & m, mid, b)
            moved = (na != a) | (nb != b)  # False once round-off stops the bracket shrinking
            a, b = na, nb
            active = active & moved & (np.abs(b - a) > tol)
        steps += 1
    return Bracket(a, b, steps)


def bisect_root(
    fun: BatchFunction,
    lo: ArrayLike,
    hi: ArrayLike,
    *,
    f_lo: ArrayLike | None = None,
    iterations: int | None = None,
    xtol: ArrayLike | None = None,
) -> FloatArray:
    """Bisection root finder for a batch of 1-D functions with a sign change on ``[lo, hi]``.

    The end ``lo`` keeps the sign of ``fun(lo)``; the midpoint moves ``lo`` when ``fun``
    has that sign there, else ``hi`` (a zero or NaN counts as "other sign").

    Parameters
    ----------
    fun
        Maps points (...) to values (...), element by element.
    lo, hi
        (...) bracket ends (broadcast together); ``fun(lo)`` and ``fun(hi)`` should differ
        in sign (not checked: otherwise the result converges to ``hi``).
    f_lo
        ``fun(lo)`` when already known (saves one evaluation).
    iterations, xtol
        Exactly one: a fixed number of halvings, or the bracket width at which an element
        stops.

    Returns
    -------
    (...) the midpoint of the final bracket: within half its width (``|hi - lo| /
    2**(n + 1)`` after ``n`` steps) of a sign change of ``fun``.
    """
    lo_a, hi_a = _brackets(lo, hi)
    sign_lo = np.sign(np.asarray(fun(lo_a) if f_lo is None else f_lo, dtype=float))
    br = bisect_boundary(
        lambda x: np.sign(np.asarray(fun(x), dtype=float)) != sign_lo,
        lo_a,
        hi_a,
        iterations=iterations,
        xtol=xtol,
    )
    return 0.5 * (br.false_end + br.true_end)


def true_segments(
    predicate: Callable[[FloatArray], ArrayLike], lo: float, hi: float, n_scan: int, rtol: float
) -> list[tuple[float, float]]:
    """The stretches of ``[lo, hi]`` where a batched 1-D ``predicate`` (points (m,) -> bool (m,))
    holds: a scan of ``n_scan`` points, each True/False boundary between neighbours bisected
    (all at once, :func:`bisect_boundary`) to ``rtol`` of the width, the refined end kept on the
    True side.  A stretch narrower than the scan's step can be missed."""
    grid = np.linspace(lo, hi, max(n_scan, 2)) if hi > lo else np.array([lo])
    ok = np.asarray(predicate(grid), dtype=bool)
    if not ok.any():
        return []
    change = np.flatnonzero(ok[1:] != ok[:-1])  # a boundary between grid[c] and grid[c + 1]
    refined: dict[int, float] = {}  # c -> the boundary, on its True side
    if change.size:
        true_side = np.where(ok[change], grid[change], grid[change + 1])
        false_side = np.where(ok[change], grid[change + 1], grid[change])
        ends = bisect_boundary(predicate, false_side, true_side, xtol=rtol * max(hi - lo, 1e-300)).true_end
        refined = {int(c): float(end) for c, end in zip(change, np.atleast_1d(ends))}
    segments = []
    i = 0
    while i < grid.size:
        if ok[i]:
            first = i
            while i + 1 < grid.size and ok[i + 1]:
                i += 1
            a = refined[first - 1] if first > 0 else float(grid[first])
            b = refined[i] if i + 1 < grid.size else float(grid[i])
            segments.append((a, b))
        i += 1
    return segments
