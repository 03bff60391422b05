"""L-BFGS-B from several starts in lockstep (issue 29): scipy's own L-BFGS-B, each start driven
exactly as ``scipy.optimize.minimize(fun, x0, jac=True, method="L-BFGS-B", bounds=...)``
drives it, and the function evaluations the starts ask for at one step made in one batched
call.

Why.  The halt configuration's refinement runs 8 starts of about 43 evaluations each, and an
evaluation is CP at 13 configurations (the point and its central differences): one compiled
call of ~36 us, plus ~40 us of ``minimize``'s Python around it.  Eight starts' 104
configurations cost ~140 us in one call, and the loop below is lighter than ``minimize``'s.

How.  ``minimize`` drives scipy's reverse-communication routine ``setulb`` (the C translation
of L-BFGS-B 3.0 in ``scipy.optimize._lbfgsb``, scipy >= 1.15): it returns to its caller with
``task = FG`` when it needs the function and the gradient at its ``x``, with ``task = NEW_X``
after each iteration, and with anything else when it stops.  :func:`minimize_lockstep` keeps
one such loop per start (``_minimize_lbfgsb``'s: the same workspace, tolerances, iteration and
evaluation limits, and its memo that does not evaluate again at the ``x`` last evaluated),
steps every running start to its next request, and evaluates the requests together.  The
starts do not interact, and each start's ``setulb`` sees the numbers it would see alone, so
each ends where ``minimize`` ends, bit for bit, when the batched evaluation gives each point
the value it gives alone (the caller's to ensure: ``_refine`` runs in lockstep only where the
compiled CP kernel does, inside a box of angles below its ``TRIG_LIMIT``;
``tests/test_halt_config.py`` compares).

``setulb`` is private to scipy: :func:`lockstep_available` accepts only the versions whose
driver loop this module follows (checked by the tests); elsewhere the caller runs
``minimize`` itself.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ...model import FloatArray

#: ``minimize``'s L-BFGS-B defaults (``scipy.optimize._lbfgsb_py._minimize_lbfgsb``).
MAXCOR = 10
FTOL = 2.2204460492503131e-09
GTOL = 1e-5
MAXFUN = 15000
MAXITER = 15000
MAXLS = 20
#: The scipy versions (major, minor) whose ``_minimize_lbfgsb`` loop is the one below.
SCIPY_VERSIONS = ((1, 15), (1, 17))

_FG, _NEW_X = 3, 1  # setulb's task codes: wants f and g at x; finished an iteration


def lockstep_available() -> bool:
    """Whether this scipy's L-BFGS-B can be driven here (see the module)."""
    import scipy

    try:
        version = tuple(int(part) for part in scipy.__version__.split(".")[:2])
        from scipy.optimize import _lbfgsb
    except (ImportError, ValueError):
        return False
    return SCIPY_VERSIONS[0] <= version <= SCIPY_VERSIONS[1] and hasattr(_lbfgsb, "setulb")


def minimize_lockstep(
    evaluate: Callable[[FloatArray], tuple[FloatArray, FloatArray]],
    starts: FloatArray,
    lo: FloatArray,
    hi: FloatArray,
) -> FloatArray:
    """L-BFGS-B from every start (m, n) inside the box ``[lo, hi]`` (n,), all finite with
    ``lo < hi``; returns each start's final ``x`` (m, n), ``minimize``'s ``res.x``.

    ``evaluate(xs)`` gives ``(f (k,), g (k, n))`` at the points ``xs`` (k, n), each point's
    numbers independent of the others.  It is called as often as ``minimize`` calls the
    function where the function is finite (at a NaN ``x``, ``minimize``'s memo misses and it
    calls the function twice per request; here once, with the same points).
    """
    from scipy.optimize import _lbfgsb

    m_starts, n = starts.shape
    if m_starts == 0:
        return np.empty((0, n))
    m = MAXCOR
    factr = FTOL / np.finfo(float).eps
    nbd = np.full(n, 2, dtype=np.int32)  # bounded on both sides
    low, upp = np.array(lo, dtype=np.float64), np.array(hi, dtype=np.float64)
    x = [np.array(np.clip(s, low, upp), dtype=np.float64) for s in starts]
    # minimize evaluates at x0 before the first step (ScalarFunction); setulb's first request
    # is x0 again, which its memo answers
    f0, g0 = evaluate(np.array(x))
    f: list[float | FloatArray] = [np.array(0.0, dtype=np.float64) for _ in range(m_starts)]
    g = [np.zeros(n, dtype=np.float64) for _ in range(m_starts)]
    memo = [(x[i].copy(), float(f0[i]), g0[i].copy()) for i in range(m_starts)]
    nfev = [1] * m_starts
    iterations = [0] * m_starts
    work = [
        (
            np.zeros(2 * m * n + 5 * n + 11 * m * m + 8 * m, np.float64),
            np.zeros(3 * n, dtype=np.int32),
            np.zeros(2, dtype=np.int32),  # task
            np.zeros(4, dtype=np.int32),
            np.zeros(44, dtype=np.int32),
            np.zeros(29, dtype=np.float64),
            np.zeros(2, dtype=np.int32),  # ln_task
        )
        for _ in range(m_starts)
    ]
    running = list(range(m_starts))
    while running:
        asking = []
        for i in list(running):
            wa, iwa, task, lsave, isave, dsave, ln_task = work[i]
            while True:  # to this start's next request for f and g, or its end
                g[i] = np.asarray(g[i]).astype(np.float64)
                _lbfgsb.setulb(m, x[i], low, upp, nbd, f[i], g[i], factr, GTOL, wa, iwa, task, lsave, isave,
                               dsave, MAXLS, ln_task)  # fmt: skip
                if task[0] == _FG:
                    last_x, last_f, last_g = memo[i]
                    if np.array_equal(x[i], last_x):
                        f[i], g[i] = last_f, last_g
                        continue
                    asking.append(i)
                    break
                if task[0] == _NEW_X:
                    iterations[i] += 1
                    if iterations[i] >= MAXITER:
                        task[0], task[1] = 5, 504
                    elif nfev[i] > MAXFUN:
                        task[0], task[1] = 5, 502
                    continue
                running.remove(i)
                break
        if asking:
            values, grads = evaluate(np.array([x[i] for i in asking]))
            for i, value, grad in zip(asking, values, grads):
                memo[i] = (x[i].copy(), float(value), grad.copy())
                f[i], g[i] = float(value), grad.copy()
                nfev[i] += 1
    return np.array(x)
