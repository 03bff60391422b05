"""Batched search for the singular configurations of any arm (Gauss-Newton on sigma_min)
and their clustering into families."""

from __future__ import annotations

import logging
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import cast

import numpy as np
from numpy.typing import ArrayLike

from ..._deprecate import renamed_keyword
from ..._random import resolve_rng
from ...errors import ScenarioError
from ...kinematics import VMWeighting, chain_state
from ...model import ArmModel, FloatArray, as_joint_array
from ...spatial import turns_into_limits
from ._general import TaskJacobianKind, task_jacobian

log = logging.getLogger(__package__)

#: A search start counts as converged to a singularity when sigma_min falls below this.
#: Gauss-Newton reaches ~ 1e-13 on the built-in arms; near cone-shaped singular sets the
#: last digits converge linearly, hence a looser bound than :data:`RANK_TOL`.
SEARCH_TOL = 1e-9
#: Central-difference step for the gradient of sigma_min [rad]: truncation ~ h^2 ~ 1e-12,
#: round-off ~ eps / h ~ 1e-10, both far below the Newton step until sigma_min ~ 1e-10.
_FD_STEP = 1e-6


def _sigma_min_and_gradient(
    fun: Callable[[FloatArray], FloatArray], q: FloatArray
) -> tuple[FloatArray, FloatArray]:
    """sigma_min (N,) and its gradient (N, n): ``d sigma / d q_j = u^T (dJ/dq_j) v`` with
    ``u, v`` the singular vectors of sigma_min and dJ/dq_j by central differences (all
    perturbed configurations in one batched call)."""
    n = q.shape[-1]
    steps = _FD_STEP * np.eye(n)
    stacked = np.concatenate([q[None], q[None] + steps[:, None, :], q[None] - steps[:, None, :]])
    jacs = fun(stacked)  # (1 + 2n, N, 6, n)
    u, s, vh = np.linalg.svd(jacs[0])
    k = s.shape[-1]
    umin, vmin = u[..., :, k - 1], vh[..., k - 1, :]
    djac = (jacs[1 : 1 + n] - jacs[1 + n :]) / (2.0 * _FD_STEP)  # (n, N, 6, n)
    grad = np.einsum("ni,jnik,nk->nj", umin, djac, vmin)
    return s[..., -1], grad


def _sigma_min(fun: Callable[[FloatArray], FloatArray], q: FloatArray) -> FloatArray:
    return cast(FloatArray, np.linalg.svd(fun(q), compute_uv=False)[..., -1])  # numpy stubs: floating[Any]


def _project(model: ArmModel, q: FloatArray) -> FloatArray:
    """Back into the limits: joints whose range holds [-pi, pi] wrap into [-pi, pi); others
    move by whole turns into their limits (past +-pi too), then clip."""
    lo, hi = np.asarray(model.lower, float), np.asarray(model.upper, float)
    wrap = (lo <= -np.pi + 1e-12) & (hi >= np.pi - 1e-12)
    wrapped = np.mod(q + np.pi, 2.0 * np.pi) - np.pi
    return np.where(wrap, wrapped, np.clip(turns_into_limits(q, lo, hi), lo, hi))


@dataclass(frozen=True)
class SingularFamily:
    """One family of singular configurations found by the search.

    Attributes
    ----------
    label
        Short description, e.g. ``"sin q5 = 0; joints 4, 6 dependent"``.
    members
        (m,) indices into :attr:`SingularitySearch.q`.
    zero_sine_joints
        Joint numbers (from 1) with ``|sin q| < zero_tol`` in every member.
    dependent_joints
        Joint numbers whose columns take part in the lost rank: those with a nonzero entry
        on the diagonal of the projector onto the *extra* null space the singularity opens
        (basis-independent; for a 6 x 6 arm the support of the null vector).
    representative
        (n,) [rad] the member with the smallest sigma_min.
    sigma_min
        sigma_min at the representative.
    lost_direction
        (6,) unit lost direction at the representative, root frame, twist ``(v, omega)``;
        its sign is arbitrary.
    lost_direction_ee
        (6,) the same direction in end-effector-frame components.
    """

    label: str
    members: np.ndarray
    zero_sine_joints: tuple[int, ...]
    dependent_joints: tuple[int, ...]
    representative: FloatArray
    sigma_min: float
    lost_direction: FloatArray
    lost_direction_ee: FloatArray


@dataclass(frozen=True)
class SingularitySearch:
    """Result of :func:`find_singularities`.

    Attributes
    ----------
    q_start
        (S, n) [rad] the seeded starts.
    q_final
        (S, n) [rad] where each start ended.
    sigma_final
        (S,) sigma_min at ``q_final``.
    converged
        (S,) ``sigma_final < tol``.
    q
        (m, n) [rad] the converged configurations (the singular ones found).
    sigma_min
        (m,) their sigma_min.
    families
        The clustering of ``q`` (:func:`cluster_singularities`).
    iterations, tol, base, weighting, length, seed
        Settings (``base``: the Jacobian kind as given, ``jacobian=``; ``length``: the
        ``characteristic_length`` [m]); ``seed`` is the seed the starts were drawn with (the int
        given as ``rng``, the fresh one drawn for ``rng=None``; ``None`` for a Generator).
    """

    q_start: FloatArray
    q_final: FloatArray
    sigma_final: FloatArray
    converged: np.ndarray
    q: FloatArray
    sigma_min: FloatArray
    families: tuple[SingularFamily, ...]
    iterations: int
    tol: float
    base: str
    weighting: str
    length: float | None
    seed: int | None
    joint_numbers: tuple[int, ...] = field(default=())


# Over 100 lines: half of it is the docstring, the rest one batched Newton loop best read whole.
@renamed_keyword(old="base", new="jacobian")
@renamed_keyword(old="length", new="characteristic_length")
def find_singularities(
    model: ArmModel,
    *,
    samples: int = 512,
    rng: int | np.random.Generator | None = 0,
    jacobian: TaskJacobianKind = "fixed",
    weighting: VMWeighting = "segment",
    tol: float = SEARCH_TOL,
    max_iter: int = 80,
    characteristic_length: float | None = None,
    q_start: ArrayLike | None = None,
    progress: object | None = None,
) -> SingularitySearch:
    """Find singular configurations of any arm from many seeded starts (batched).

    Parameters
    ----------
    model
        Any arm (locked joints allowed).
    samples
        Number of starts ``S``, drawn uniformly within the joint limits (capped to +-pi).
    rng
        Seed (int >= 0, default 0), ``numpy.random.Generator``, or None (a fresh seed) for the
        starts, recorded in ``seed`` (:mod:`jointlock._random`).
    jacobian, weighting, characteristic_length
        Which Jacobian (:func:`task_jacobian`; formerly ``base=`` and ``length=``, deprecated
        aliases).
    tol
        A start has converged when sigma_min < ``tol``.
    max_iter
        Iterations (each: one batched Jacobian evaluation of ``(1 + 2n) S`` configurations
        plus one of ``5 S`` for the line search).
    q_start
        (S, n) [rad] explicit starts instead of random ones.
    progress
        A :class:`jointlock.progress.Progress`-like object (``update(k)``), or ``None``.

    Notes
    -----
    sigma_min behaves like the distance to the singular set (times a slope), so minimising
    it is a root-finding problem.  Each iteration takes the minimum-norm Newton step for
    ``sigma_min(q) = 0``, ``dq = -sigma g / |g|^2`` with ``g = grad sigma_min =
    (u^T dJ/dq_j v)_j``, capped to 0.5 rad, tries the fractions 1, 1/2, 1/4, 1/8, 1/16 of it
    and keeps, per start, the best (or stays).  Starts that converge stop moving.  A start
    stuck at a nonzero local minimum of sigma_min is reported as not converged.
    """
    if samples < 1:
        raise ScenarioError(f"samples must be >= 1; got {samples}")
    if max_iter < 1:
        raise ScenarioError(f"max_iter must be >= 1; got {max_iter}")
    gen, seed = resolve_rng(rng)
    if q_start is None:
        lo, hi = model.angle_range()  # the limits as given, past +-pi too
        q0 = gen.uniform(lo, hi, size=(samples, model.dof))
    else:
        q0 = as_joint_array(model, q_start, "q_start").reshape(-1, model.dof)

    def fun(qq: FloatArray) -> FloatArray:
        return task_jacobian(
            model, qq, jacobian=jacobian, weighting=weighting, characteristic_length=characteristic_length
        )

    q = q0.copy()
    sigma = _sigma_min(fun, q)
    fractions = np.array([1.0, 0.5, 0.25, 0.125, 0.0625])
    iterations = 0
    for _ in range(max_iter):
        active = sigma >= tol
        if not active.any():
            break
        iterations += 1
        qa = q[active]
        sa, grad = _sigma_min_and_gradient(fun, qa)
        gnorm2 = np.einsum("ij,ij->i", grad, grad)
        step = -(sa / np.maximum(gnorm2, 1e-300))[:, None] * grad
        norm = np.linalg.norm(step, axis=1)
        step *= np.minimum(1.0, 0.5 / np.maximum(norm, 1e-300))[:, None]
        trials = _project(model, qa[None] + fractions[:, None, None] * step[None])  # (5, A, n)
        st = _sigma_min(fun, trials)
        best = np.argmin(st, axis=0)
        sbest = st[best, np.arange(st.shape[1])]
        better = sbest < sa
        idx = np.flatnonzero(active)
        q[idx[better]] = trials[best[better], np.flatnonzero(better)]
        sigma[idx[better]] = sbest[better]
        if progress is not None:
            progress.update(1)  # type: ignore[attr-defined]
    converged = sigma < tol
    log.info(
        "singularity search: %d of %d starts converged in %d iterations", converged.sum(), len(q), iterations
    )
    found = q[converged]
    families = cluster_singularities(
        model, found, jacobian=jacobian, weighting=weighting, characteristic_length=characteristic_length
    )
    return SingularitySearch(
        q_start=q0,
        q_final=q,
        sigma_final=sigma,
        converged=converged,
        q=found,
        sigma_min=sigma[converged],
        families=families,
        iterations=iterations,
        tol=float(tol),
        base=jacobian,
        weighting=weighting,
        length=characteristic_length,
        seed=seed,
        joint_numbers=tuple(model.joint_numbers),
    )


@renamed_keyword(old="base", new="jacobian")
@renamed_keyword(old="length", new="characteristic_length")
def cluster_singularities(
    model: ArmModel,
    q: ArrayLike,
    *,
    jacobian: TaskJacobianKind = "fixed",
    weighting: VMWeighting = "segment",
    characteristic_length: float | None = None,
    zero_tol: float = 1e-4,
    rank_tol: float = 1e-6,
) -> tuple[SingularFamily, ...]:
    """Group singular configurations (m, n) [rad] into families.

    Two configurations are in one family when the same joints sit at 0 or pi
    (``|sin q| < zero_tol``) and their *dependent* joints are nested: with ``v_k`` the right
    singular vector of sigma_min (the joint motion that no longer reaches the task space),
    joint ``j`` is dependent when ``sum_i v_ij^2 > 1e-4`` over the singular values below
    ``rank_tol`` — the diagonal of the projector onto that subspace, which does not depend
    on the SVD's choice of basis.  A dependent set inside another one with the same zero
    joints and as many ranks lost is the same singularity where some entry of the null vector
    vanishes by coincidence (UR5's shoulder singularity shows six such sets): it joins the
    one maximal set that holds it (a set under two maximal ones stays its own family, and so
    does a configuration losing two ranks at once).  The keys are discrete, so the grouping is
    deterministic.
    Families are sorted by size.  ``jacobian``, ``weighting``, ``characteristic_length``: the
    Jacobian, as in :func:`task_jacobian` (formerly ``base=`` and ``length=``, deprecated aliases).
    """
    q = np.asarray(q, dtype=float).reshape(-1, model.dof)
    if len(q) == 0:
        return ()
    jac = task_jacobian(
        model, q, jacobian=jacobian, weighting=weighting, characteristic_length=characteristic_length
    )
    u, s, vh = np.linalg.svd(jac)
    k = s.shape[-1]
    small = s < rank_tol  # (m, k); the singular subspace (always contains sigma_min's)
    small[:, -1] = True
    weight = np.einsum("mi,mij->mj", small.astype(float), vh[:, :k, :] ** 2)
    dependent = weight > 1e-4
    zero = np.abs(np.sin(q)) < zero_tol
    keys = _merged_keys(zero, dependent, small.sum(axis=1))
    rot_ee = chain_state(model, q).ee_rotation
    numbers = np.asarray(model.joint_numbers)
    n = model.dof
    families: list[SingularFamily] = []
    for key in dict.fromkeys(keys):
        members = np.flatnonzero([k_ == key for k_ in keys])
        rep = members[np.argmin(s[members, -1])]
        direction = u[rep, :, k - 1]
        r = rot_ee[rep]
        zs = tuple(int(j) for j in numbers[np.flatnonzero(key[:n])])
        dep = tuple(int(j) for j in numbers[np.flatnonzero(key[n : 2 * n])])
        label = " and ".join(f"sin q{j} = 0" for j in zs) or "no joint at 0/pi"
        label += "; dependent joints " + ", ".join(str(j) for j in dep)
        families.append(
            SingularFamily(
                label=label,
                members=members,
                zero_sine_joints=zs,
                dependent_joints=dep,
                representative=q[rep].copy(),
                sigma_min=float(s[rep, -1]),
                lost_direction=direction,
                lost_direction_ee=np.concatenate([r.T @ direction[:3], r.T @ direction[3:]]),
            )
        )
    families.sort(key=lambda f: -len(f.members))
    return tuple(families)


def _merged_keys(zero: np.ndarray, dependent: np.ndarray, lost: np.ndarray) -> list[tuple]:
    """Each configuration's family key ``zero joints + dependent joints + ranks lost``: a
    dependent set inside exactly one maximal set of its group (same zero joints, same ranks
    lost) takes that set; sets that do not nest, or that nest in two maximal sets, stay apart."""
    items = [(tuple(z), int(k), tuple(d)) for z, d, k in zip(zero.tolist(), dependent.tolist(), lost.tolist())]
    sets = set(items)

    def inside(a: tuple, b: tuple) -> bool:
        return a[:2] == b[:2] and all(x <= y for x, y in zip(a[2], b[2]))

    maximal = [m for m in sets if not any(o != m and inside(m, o) for o in sets)]
    target: dict[tuple, tuple] = {}
    for item in sets:
        above = [m for m in maximal if inside(item, m)]
        target[item] = above[0] if len(above) == 1 else item
    return [item[0] + target[item][2] + (item[1],) for item in items]
