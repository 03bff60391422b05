"""Sparse-row arithmetic: batched 3-vectors stored as three rows, constants folded.

A batched vector is a list of rows, one ``(N,)`` array (or a Python float, for a quantity
the same for every sample) per component, ``None`` standing for an exactly zero component.
Constant matrices (placements, inertias, centres of mass) are applied entry by entry: zero
entries are skipped and unit entries are not multiplied, so a signed-permutation placement
(every DH model) costs nothing and a rotation about ``z`` is four products and two sums per
vector.  Used by the position-only forward kinematics (:func:`jointlock.kinematics.ee_positions`),
the momentum matrix and the recursive Newton-Euler algorithm (:mod:`jointlock._chain`,
:mod:`jointlock.dynamics`).

Nothing here knows about arms: the functions only combine rows.
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any

from numpy.typing import NDArray

#: One component of a batched vector: an (N,) array, a constant float, or None (exactly zero).
Row = Any


def lc(terms: Iterable[tuple[float, Row]], const: float = 0.0) -> Row:
    """Sum of ``coef * row`` over ``terms`` plus ``const``; zero coefficients and ``None``
    rows skipped, unit coefficients not multiplied; ``None`` when everything is zero.

    The sum runs left to right, ``const`` added last (the order fixes the round-off)."""
    out = None
    owned = False
    for coef, row in terms:
        if row is None or coef == 0.0:
            continue
        if out is None:
            if coef == 1.0:
                out = row
            else:
                out = row * coef
                owned = True
        elif coef == 1.0:
            if owned:
                out += row
            else:
                out = out + row
                owned = True
        elif coef == -1.0:
            if owned:
                out -= row
            else:
                out = out - row
                owned = True
        else:
            if owned:
                out += coef * row
            else:
                out = out + coef * row
                owned = True
    if const != 0.0:
        out = const if out is None else out + const
    return out


def add(a: Row, b: Row) -> Row:
    """``a + b`` with ``None`` as zero."""
    if a is None:
        return b
    if b is None:
        return a
    return a + b


def sub(a: Row, b: Row) -> Row:
    """``a - b`` with ``None`` as zero."""
    if b is None:
        return a
    if a is None:
        return -b
    return a - b


def mul(a: Row, b: Row) -> Row:
    """``a * b`` with ``None`` as zero."""
    if a is None or b is None:
        return None
    return a * b


def nz(x: Row) -> Row:
    """``x`` with ``None`` turned into ``0.0``."""
    return 0.0 if x is None else x


def add3(a: list, b: list, c: list) -> list:
    """Sum of three row vectors."""
    return [add(add(x, y), z) for x, y, z in zip(a, b, c)]


def cmv(c: NDArray, v: list) -> list:
    """Constant (3, 3) matrix times a row vector."""
    return [lc(((c[r, 0], v[0]), (c[r, 1], v[1]), (c[r, 2], v[2]))) for r in range(3)]


def cross(a: list, b: list) -> list:
    """Cross product of two row vectors."""
    return [
        sub(mul(a[1], b[2]), mul(a[2], b[1])),
        sub(mul(a[2], b[0]), mul(a[0], b[2])),
        sub(mul(a[0], b[1]), mul(a[1], b[0])),
    ]


def cross_vc(v: list, p: NDArray) -> list:
    """Row vector ``v`` cross a constant vector ``p``."""
    return [
        lc(((p[2], v[1]), (-p[1], v[2]))),
        lc(((p[0], v[2]), (-p[2], v[0]))),
        lc(((p[1], v[0]), (-p[0], v[1]))),
    ]


def cross_cv(p: NDArray, v: list) -> list:
    """Constant vector ``p`` cross a row vector ``v``."""
    return [
        lc(((p[1], v[2]), (-p[2], v[1]))),
        lc(((p[2], v[0]), (-p[0], v[2]))),
        lc(((p[0], v[1]), (-p[1], v[0]))),
    ]


def rz(c: Row, s: Row, v: list, transpose: bool = False) -> list:
    """``Rot(z, q) v`` (or its transpose) for rows ``c = cos q``, ``s = sin q``; a vector on
    the ``z`` axis (first two rows ``None``) is returned as it is."""
    x, y = v[0], v[1]
    if x is None and y is None:
        return [None, None, v[2]]
    if transpose:
        return [add(mul(c, x), mul(s, y)), sub(mul(c, y), mul(s, x)), v[2]]
    return [sub(mul(c, x), mul(s, y)), add(mul(s, x), mul(c, y)), v[2]]
