"""Singularity analysis (seed 004, Chen et al. 2014): singular values, rank and singular
directions of any arm, a batched search for singular configurations, and the closed-form
conditions Cond1-Cond5 of Canadarm2-structure arms checked against the numerical test.

**General part** (any model, any batch of configurations):

* :func:`task_jacobian` picks the Jacobian whose singularities are studied: ``"fixed"``
  (geometric Jacobian, :func:`jointlock.jacobian`), ``"floating"`` (generalized Jacobian with
  zero momentum, :func:`jointlock.generalized_jacobian`) or ``"virtual"`` (the Jacobian
  ``J^_m`` of the virtual manipulator, 004 eqs. 10-14, :func:`jointlock.virtual_manipulator`).
* :func:`analyse_singularity` gives sigma_min, the numerical rank (tolerance by argument),
  ``det(J J^T)`` (004's test, Whitney) and the lost task directions: the left singular vectors
  ``u`` whose singular values fell below the tolerance, so that ``J^T u ~ 0``.
* :func:`find_singularities` drives many seeded starts to ``sigma_min = 0`` at once (batched
  Gauss-Newton on the smallest singular value, see its Notes) and
  :func:`cluster_singularities` groups what it finds into families.

**Structure-specific part** (Canadarm2 / SSRMS structure: 7 revolute joints, axes 3, 4, 5
parallel, frames of ``jointlock.robots.canadarm7``):

* :func:`reference_jacobian` is our Jacobian referred to 004's reference point (the point
  where axes 5 and 6 meet, origin of link frame 6, index 5) and expressed in its reference
  frame Sigma_4 (orientation of link frame 5, index 4); :func:`eq15_jacobian` is eq. (15) as
  printed.  They are equal (tested).
* :func:`reorder_eq24` permutes it into eq. (24) ``[[J11, J12], [J21, O3]]``.
* :func:`condition_equations` / :func:`condition_residuals` evaluate Cond1-Cond5 (eq. 30),
  :func:`analytic_directions` the singular directions of eqs. (28) and (32),
  :func:`sample_condition` draws configurations that satisfy a condition exactly, and
  :func:`verify_conditions` checks each condition by sampling (is it sufficient?) and the list
  by searching (is it complete?).

**What the verification finds** (``docs/singularity.md``): Cond2-Cond5 are sufficient — every
sample is singular.  Cond1 (``S4 = 0``, the determinant ``d^ e^ S4`` of J12) is *not*: no
sample with ``S4 = 0`` alone is singular.  With ``S4 = 0`` the rank drops only if in addition
``F = 0`` (:func:`cond1_extra`, a closed form found with sympy; 004 does not state it), and
that refined condition ``"cond1f"`` is sufficient.  Every singular configuration the search
finds satisfies one of Cond1-Cond5 (the list is complete).

**Units.**  A 6 x n Jacobian mixes m/s and rad/s rows.  As in 004 the raw matrix is used;
``length=L`` [m] divides the linear rows by ``L`` (``docs/conventions.md``).  Tolerances on
sigma_min are therefore in the raw matrix's mixed units.

**Which virtual lengths.**  ``weighting="segment"`` (default here) is 004's formula and
reproduces its printed virtual lengths and Table 3; ``"vafa-dubowsky"`` is the exact virtual
manipulator (:func:`jointlock.virtual_link_vectors`).  The conditions hold for any lengths.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike

from ..errors import ConfigurationError, ModelError, ScenarioError
from ..kinematics import (
    VMWeighting,
    chain_state,
    generalized_jacobian,
    jacobian,
    virtual_link_vectors,
    virtual_manipulator,
)
from ..model import ArmModel, FloatArray, as_joint_array

log = logging.getLogger(__name__)

BaseKind = Literal["fixed", "floating", "virtual"]
BASE_KINDS: tuple[str, ...] = ("fixed", "floating", "virtual")

# -- named tolerances ---------------------------------------------------------------------

#: Rank tolerance on a singular value (raw Jacobian: m/s or rad/s per rad/s).  Exactly
#: singular configurations of the built-in arms give sigma_min ~ 1e-15; the smallest
#: sigma_min of 10^5 random configurations is ~ 1e-3, so 1e-8 separates them by 5 decades.
RANK_TOL = 1e-8
#: A search start counts as converged to a singularity when sigma_min falls below this.
#: Gauss-Newton reaches ~ 1e-13 on the built-in arms; near cone-shaped singular sets the
#: last digits converge linearly, hence a looser bound than :data:`RANK_TOL`.
SEARCH_TOL = 1e-9
#: A condition holds when its residual (dimensionless, see :func:`condition_residuals`) is
#: below this.  Exact samples give ~ 1e-15; configurations found by the search lie within
#: ~ sigma_min / |grad sigma_min| ~ 1e-9 of the singular set.
CONDITION_TOL = 1e-6
#: Central-difference step for the gradient of sigma_min [rad]: truncation ~ h^2 ~ 1e-12,
#: round-off ~ eps / h ~ 1e-10, both far below the Newton step until sigma_min ~ 1e-10.
_FD_STEP = 1e-6
#: An arm passes as Canadarm2-structured when its Jacobian at 004's reference point equals
#: eq. (15) to this [m/s or rad/s per rad/s] (round-off is ~1e-15).
_STRUCTURE_TOL = 1e-9

CONDITIONS: tuple[str, ...] = ("cond1", "cond2", "cond3", "cond4", "cond5")
#: Cond1 with 004's missing second equation (``S4 = 0`` and ``F = 0``).
REFINED_CONDITIONS: tuple[str, ...] = ("cond1f",)

#: Eq. (24): rows (omega_z, v_x, v_y, v_z, omega_x, omega_y) = eq.-(15) rows [6,1,2,3,4,5].
EQ24_ROWS: tuple[int, ...] = (5, 0, 1, 2, 3, 4)
#: Eq. (24): columns (theta1, theta2, theta7, theta6, theta3, theta4, theta5).
EQ24_COLS: tuple[int, ...] = (0, 1, 6, 5, 2, 3, 4)
#: Names of the eq.-(24) rows, in order.
EQ24_ROW_NAMES: tuple[str, ...] = ("wz", "vx", "vy", "vz", "wx", "wy")


def _rng(rng: int | np.random.Generator | None) -> tuple[np.random.Generator, int | None]:
    if isinstance(rng, np.random.Generator):
        return rng, None
    if rng is not None and not isinstance(rng, (int, np.integer)):
        raise ScenarioError(f"rng must be an int seed, a numpy Generator or None; got {rng!r}")
    return np.random.default_rng(rng), None if rng is None else int(rng)


def _check_base(base: str) -> None:
    if base not in BASE_KINDS:
        raise ScenarioError(f"base must be one of {BASE_KINDS}; got {base!r}")


# == general part ==========================================================================


def task_jacobian(
    model: ArmModel,
    q: ArrayLike,
    *,
    base: BaseKind = "fixed",
    weighting: VMWeighting = "segment",
    length: float | None = None,
) -> FloatArray:
    """The Jacobian whose singularities are analysed.

    Parameters
    ----------
    model
        The arm.  ``base="floating"`` and ``"virtual"`` need a free-floating model
        (``model.floating``).
    q
        (..., n) joint angles [rad] of the movable joints.
    base
        ``"fixed"``: geometric Jacobian of the end effector (fixed base, or a spacecraft held
        still), root-frame components.  ``"floating"``: generalized Jacobian, zero momentum
        (000 eq. 5).  ``"virtual"``: Jacobian ``J^_m`` of the virtual manipulator (004 eqs.
        10-12: free-flying arm with attitude held, or eq. 14 with the measured base rate
        subtracted).
    weighting
        Virtual link lengths for ``base="virtual"`` (see :func:`jointlock.virtual_link_vectors`);
        ``"segment"`` is 004's formula.
    length
        Characteristic length ``L`` [m]: the linear rows are divided by it.  ``None``: raw.

    Returns
    -------
    (..., 6, n): twist ``(v, omega)`` of the end-effector origin, root-frame components.
    """
    _check_base(base)
    if base != "fixed" and not model.floating:
        raise ModelError(
            f"base={base!r} needs a free-floating model (a spacecraft base); {model.name!r} has a fixed "
            "base — load it with base='floating' or use base='fixed'"
        )
    if base == "fixed":
        jac = jacobian(model, q)
    elif base == "floating":
        jac = generalized_jacobian(model, q)
    else:
        jac = virtual_manipulator(model, q, weighting=weighting).jacobian
    if length is not None:
        if not (math.isfinite(length) and length > 0):
            raise ScenarioError(f"length must be a positive number of metres; got {length!r}")
        jac = jac.copy()
        jac[..., :3, :] /= length
    return jac


@dataclass(frozen=True)
class SingularityAnalysis:
    """Singular values, rank and lost task directions of a batch of Jacobians.

    Attributes
    ----------
    jacobian
        (..., 6, n) the analysed Jacobian (see :func:`task_jacobian`).
    singular_values
        (..., k) descending, ``k = min(6, n)``.
    directions
        (..., 6, 6) left singular vectors (columns), in the order of ``singular_values``;
        columns ``k..5`` (only when ``n < 6``) span the directions the arm can never move in.
    sigma_min
        (...,) smallest singular value ``sigma_k``.
    rank
        (...,) number of singular values above ``tol``.
    det_jjt
        (...,) ``det(J J^T)`` (004's numerical test, Table 3); exactly 0 when ``n < 6``.
    singular
        (...,) ``rank < k``: the arm lost a direction it normally has.
    lost
        (..., 6) boolean mask over the columns of ``directions``: the lost directions
        (``j < k`` and ``sigma_j <= tol``).  Each satisfies ``J^T u ~ 0``.
    tol, base, weighting, length
        The settings that produced it.
    """

    jacobian: FloatArray
    singular_values: FloatArray
    directions: FloatArray
    sigma_min: FloatArray
    rank: np.ndarray
    det_jjt: FloatArray
    singular: np.ndarray
    lost: np.ndarray
    tol: float
    base: str
    weighting: str
    length: float | None

    def lost_directions(self, index: tuple[int, ...] = ()) -> FloatArray:
        """(6, r) lost directions of one configuration of the batch (``index`` into the
        batch shape; ``()`` for an unbatched analysis), unit columns."""
        return self.directions[index][:, self.lost[index]]


def singularity_of_jacobian(
    jac: ArrayLike,
    *,
    tol: float = RANK_TOL,
    base: str = "given",
    weighting: str = "",
    length: float | None = None,
) -> SingularityAnalysis:
    """:class:`SingularityAnalysis` of given Jacobians (..., 6, n) (batched SVD)."""
    jac = np.asarray(jac, dtype=float)
    if jac.ndim < 2 or jac.shape[-2] != 6:
        raise ConfigurationError(f"jac must have shape (..., 6, n); got {jac.shape}")
    if not (math.isfinite(tol) and tol >= 0):
        raise ScenarioError(f"tol must be a finite number >= 0; got {tol!r}")
    u, s, _ = np.linalg.svd(jac, full_matrices=True)
    k = s.shape[-1]
    rank = np.count_nonzero(s > tol, axis=-1)
    lost = np.zeros(jac.shape[:-2] + (6,), dtype=bool)
    lost[..., :k] = s <= tol
    return SingularityAnalysis(
        jacobian=jac,
        singular_values=s,
        directions=u,
        sigma_min=s[..., -1],
        rank=rank,
        det_jjt=np.linalg.det(jac @ np.swapaxes(jac, -1, -2)),
        singular=rank < k,
        lost=lost,
        tol=float(tol),
        base=base,
        weighting=weighting,
        length=length,
    )


def analyse_singularity(
    model: ArmModel,
    q: ArrayLike,
    *,
    base: BaseKind = "fixed",
    weighting: VMWeighting = "segment",
    tol: float = RANK_TOL,
    length: float | None = None,
) -> SingularityAnalysis:
    """sigma_min, rank, det(J J^T) and lost directions of ``model`` at ``q`` (..., n) [rad].

    The Jacobian is :func:`task_jacobian` (``base``, ``weighting``, ``length`` as there).
    ``tol`` is the rank tolerance on singular values (units of the analysed matrix).  The lost
    directions are left singular vectors: task-space twists ``(v, omega)`` (root frame) the
    end effector cannot produce to first order.
    """
    jac = task_jacobian(model, q, base=base, weighting=weighting, length=length)
    return singularity_of_jacobian(jac, tol=tol, base=base, weighting=weighting, length=length)


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
    return np.linalg.svd(fun(q), compute_uv=False)[..., -1]


def _project(model: ArmModel, q: FloatArray) -> FloatArray:
    """Joints with a range of a full turn or more wrap into [-pi, pi); others clip."""
    lo, hi = np.asarray(model.lower, float), np.asarray(model.upper, float)
    wrap = (hi - lo) >= 2.0 * np.pi - 1e-12
    wrapped = np.mod(q + np.pi, 2.0 * np.pi) - np.pi
    return np.where(wrap, wrapped, np.clip(q, lo, hi))


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
        Settings; ``seed`` is the int given as ``rng`` (``None`` for a Generator).
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


def find_singularities(
    model: ArmModel,
    *,
    samples: int = 512,
    rng: int | np.random.Generator | None = 0,
    base: BaseKind = "fixed",
    weighting: VMWeighting = "segment",
    tol: float = SEARCH_TOL,
    max_iter: int = 80,
    length: float | None = None,
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
        Seed or Generator for the starts.
    base, weighting, length
        Which Jacobian (:func:`task_jacobian`).
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
    gen, seed = _rng(rng)
    if q_start is None:
        lo = np.maximum(model.lower, -np.pi)
        hi = np.minimum(model.upper, np.pi)
        q0 = gen.uniform(lo, hi, size=(samples, model.dof))
    else:
        q0 = as_joint_array(model, q_start, "q_start").reshape(-1, model.dof)

    def fun(qq: FloatArray) -> FloatArray:
        return task_jacobian(model, qq, base=base, weighting=weighting, length=length)

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
    families = cluster_singularities(model, found, base=base, weighting=weighting, length=length)
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
        base=base,
        weighting=weighting,
        length=length,
        seed=seed,
        joint_numbers=tuple(model.joint_numbers),
    )


def cluster_singularities(
    model: ArmModel,
    q: ArrayLike,
    *,
    base: BaseKind = "fixed",
    weighting: VMWeighting = "segment",
    length: float | None = None,
    zero_tol: float = 1e-4,
    rank_tol: float = 1e-6,
) -> tuple[SingularFamily, ...]:
    """Group singular configurations (m, n) [rad] into families.

    Two configurations are in one family when the same joints sit at 0 or pi
    (``|sin q| < zero_tol``) and the same joints are *dependent*: with ``v_k`` the right
    singular vector of sigma_min (the joint motion that no longer reaches the task space),
    joint ``j`` is dependent when ``sum_i v_ij^2 > 1e-4`` over the singular values below
    ``rank_tol`` — the diagonal of the projector onto that subspace, which does not depend
    on the SVD's choice of basis.  Both keys are discrete, so the grouping is deterministic.
    Families are sorted by size.
    """
    q = np.asarray(q, dtype=float).reshape(-1, model.dof)
    if len(q) == 0:
        return ()
    jac = task_jacobian(model, q, base=base, weighting=weighting, length=length)
    u, s, vh = np.linalg.svd(jac)
    k = s.shape[-1]
    small = s < rank_tol  # (m, k); the singular subspace (always contains sigma_min's)
    small[:, -1] = True
    weight = np.einsum("mi,mij->mj", small.astype(float), vh[:, :k, :] ** 2)
    dependent = weight > 1e-4
    zero = np.abs(np.sin(q)) < zero_tol
    keys = [tuple(z) + tuple(d) for z, d in zip(zero, dependent)]
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
        dep = tuple(int(j) for j in numbers[np.flatnonzero(key[n:])])
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


# == Canadarm2-structure part ==============================================================


@dataclass(frozen=True)
class ArmLengths:
    """Link lengths of a Canadarm2-structure arm [m] (004 Fig. 2 / Table 1 names): ``l``
    spacecraft centre of mass to joint 1, then the segments ``a, c, d, e, f, h`` and the tool
    ``k``.  Real lengths, or the virtual ones (hatted in 004)."""

    l: float  # noqa: E741 - 004's name
    a: float
    c: float
    d: float
    e: float
    f: float
    h: float
    k: float


def arm_lengths(
    model: ArmModel, *, base: Literal["fixed", "virtual"] = "virtual", weighting: VMWeighting = "segment"
) -> ArmLengths:
    """Lengths entering eq. (15): the norms of the virtual link vectors (``base="virtual"``,
    004 Table 2 with ``weighting="segment"``: 0.38, 0.39, 2.15, 2.33, 0.48, 0.49, 0.5 m on
    ``canadarm7``) or of the real segments (``"fixed"``)."""
    _check_canadarm(model)
    if base == "virtual":
        if not model.floating:
            raise ModelError(f"virtual lengths need a free-floating model; {model.name!r} has a fixed base")
        vec = virtual_link_vectors(model, weighting=weighting)
    elif base != "fixed":
        raise ScenarioError(f"base must be 'fixed' or 'virtual' for 004's conditions; got {base!r}")
    real = ArmLengths(*(float(x) for x in np.linalg.norm(_real_segments(model), axis=1)))
    probe = np.radians(
        [[10.0, 20.0, 30.0, 40.0, 50.0, 60.0, 70.0], [-35.0, 75.0, -120.0, 150.0, 5.0, -95.0, 0.0]]
    )
    mismatch = float(
        np.abs(reference_jacobian(model, probe, base="fixed") - eq15_jacobian(probe, real)).max()
    )
    if mismatch > _STRUCTURE_TOL:
        raise ModelError(
            f"{model.name!r} is not a Canadarm2-structure arm in 004's frames: its Jacobian at the eq.-(15) "
            f"reference point differs from eq. (15) by {mismatch:.3g} (allowed {_STRUCTURE_TOL:g}); see "
            "jointlock.robots.canadarm7 for the frames"
        )
    if base == "fixed":
        return real
    return ArmLengths(*(float(x) for x in np.linalg.norm(vec, axis=1)))


def _real_segments(model: ArmModel) -> FloatArray:
    """(8, 3) spacecraft-to-joint-1 vector and the 7 segments, each in its own frame [m]."""
    return np.array([j.placement[:3, 3] for j in model.joints] + [model.tool[:3, 3]])


def _check_canadarm(model: ArmModel) -> None:
    if model.dof != 7 or model.locked:
        raise ModelError(
            f"004's conditions need the full 7-joint Canadarm2-structure arm; {model.name!r} has "
            f"{model.dof} movable joints{' (locked: ' + str([lj.number for lj in model.locked]) + ')' if model.locked else ''}"
        )


def _lengths(lengths: ArmLengths | ArmModel) -> ArmLengths:
    if isinstance(lengths, ArmModel):
        return arm_lengths(lengths, base="virtual" if lengths.floating else "fixed")
    return lengths


def reference_jacobian(
    model: ArmModel,
    q: ArrayLike,
    *,
    base: Literal["fixed", "virtual"] = "virtual",
    weighting: VMWeighting = "segment",
) -> FloatArray:
    """Our Jacobian in 004's reference frame and point (the numeric eq. 15).

    The twist ``(v, omega)`` of the point where axes 5 and 6 meet (origin of link frame 6,
    index 5; for ``base="virtual"`` the virtual joint 6) with components in Sigma_ref =
    Sigma_4 (orientation of link frame 5, index 4): ``v_ref = v_e + omega x (p_ref - p_e)``,
    then both blocks rotated by ``R_ref^T`` (004 eqs. 16-20; the map has determinant 1, so the
    singularities are those of ``J^_m``).

    Returns
    -------
    (..., 6, 7) rows (v_x, v_y, v_z [m/s], omega_x, omega_y, omega_z [rad/s]) in Sigma_ref.
    """
    _check_canadarm(model)
    state = chain_state(model, q)
    if base == "virtual":
        vm = virtual_manipulator(model, q, weighting=weighting)
        jac, p_e, p_ref = vm.jacobian, vm.ee_position, vm.joint_positions[..., 5, :]
    elif base == "fixed":
        jac, p_e, p_ref = jacobian(model, q, state=state), state.ee_position, state.positions[..., 5, :]
    else:
        raise ScenarioError(f"base must be 'fixed' or 'virtual' for eq. (15); got {base!r}")
    ang = jac[..., 3:, :]
    lin = jac[..., :3, :] + np.swapaxes(
        np.cross(np.swapaxes(ang, -1, -2), (p_ref - p_e)[..., None, :]), -1, -2
    )
    rt = np.swapaxes(state.rotations[..., 4, :, :], -1, -2)
    return np.concatenate([rt @ lin, rt @ ang], axis=-2)


def _trig(q: FloatArray) -> dict[str, FloatArray]:
    t2, t3, t4, t5, t6 = (q[..., i] for i in (1, 2, 3, 4, 5))
    return {
        "S2": np.sin(t2), "C2": np.cos(t2), "S3": np.sin(t3), "C3": np.cos(t3), "S4": np.sin(t4),
        "S5": np.sin(t5), "C5": np.cos(t5), "S6": np.sin(t6), "C6": np.cos(t6),
        "S34": np.sin(t3 + t4), "C34": np.cos(t3 + t4), "S45": np.sin(t4 + t5), "C45": np.cos(t4 + t5),
        "S345": np.sin(t3 + t4 + t5), "C345": np.cos(t3 + t4 + t5), "S35": np.sin(t3 + t5),
    }  # fmt: skip


def eq15_jacobian(q: ArrayLike, lengths: ArmLengths) -> FloatArray:
    """004 eq. (15) as printed: (..., 6, 7) for joint angles ``q`` (..., 7) [rad] and lengths
    (real, or virtual for ``J^_ref^ref``).  Rows (v; omega) in Sigma_ref."""
    q = np.asarray(q, dtype=float)
    t = _trig(q)
    a, c, d, e, f, h = lengths.a, lengths.c, lengths.d, lengths.e, lengths.f, lengths.h
    z, one = np.zeros(q.shape[:-1]), np.ones(q.shape[:-1])
    S2, C2, S345, C345 = t["S2"], t["C2"], t["S345"], t["C345"]
    rows = [
        [C2 * (a * C345 + e * t["S5"] + d * t["S45"]) - (c + f) * S2 * S345, -(c + f) * C345,
         e * t["S5"] + d * t["S45"], e * t["S5"], z, z, -h * t["C6"]],
        [-(c + f) * S2 * C345 + C2 * (-a * S345 + e * t["C5"] + d * t["C45"]), (c + f) * S345,
         e * t["C5"] + d * t["C45"], e * t["C5"], z, z, z],
        [-S2 * (a - d * t["S3"] - e * t["S34"]), d * t["C3"] + e * t["C34"], z, z, z, z, -h * t["S6"]],
        [C345 * S2, -S345, z, z, z, z, -t["S6"]],
        [-S2 * S345, -C345, z, z, z, -one, z],
        [C2, z, one, one, one, z, t["C6"]],
    ]  # fmt: skip
    return np.stack([np.stack(r, axis=-1) for r in rows], axis=-2)


@dataclass(frozen=True)
class Eq24Partition:
    """Eq. (24)/(26): ``J' = [[J11, J12], [J21, O3]]``.

    Attributes
    ----------
    matrix
        (..., 6, 7) the reordered Jacobian (rows :data:`EQ24_ROWS`, columns :data:`EQ24_COLS`).
    j11, j12, j21, zero
        (..., 3, 4), (..., 3, 3), (..., 3, 4), (..., 3, 3) blocks; ``zero`` vanishes for a
        Canadarm2-structure arm.
    """

    matrix: FloatArray
    j11: FloatArray
    j12: FloatArray
    j21: FloatArray
    zero: FloatArray


def reorder_eq24(jac_ref: ArrayLike) -> Eq24Partition:
    """Reorder an eq.-(15) Jacobian (..., 6, 7) into eq. (24) and partition it (eq. 26).

    Rows become (omega_z, v_x, v_y, v_z, omega_x, omega_y) and columns (theta1, theta2,
    theta7, theta6, theta3, theta4, theta5); a permutation, so rank and ``det(J J^T)`` are
    unchanged.  ``det J12 = d^ e^ S4`` (Cond1).
    """
    jac_ref = np.asarray(jac_ref, dtype=float)
    if jac_ref.shape[-2:] != (6, 7):
        raise ConfigurationError(f"jac_ref must have shape (..., 6, 7); got {jac_ref.shape}")
    m = jac_ref[..., list(EQ24_ROWS), :][..., list(EQ24_COLS)]
    return Eq24Partition(m, m[..., :3, :4], m[..., :3, 4:], m[..., 3:, :4], m[..., 3:, 4:])


def condition_equations(q: ArrayLike, lengths: ArmLengths | ArmModel) -> dict[str, FloatArray]:
    """The equations of 004's conditions (eq. 30), signed, for ``q`` (..., 7) [rad].

    Returns
    -------
    ``{"cond1": (..., 1), "cond2".."cond5": (..., 2), "cond1f": (..., 2)}``.  Sine equations
    are dimensionless; the length equations are in metres:

    * cond1: ``S4``
    * cond2: ``S2``, ``S6``
    * cond3: ``S2``, ``d C3 + e C34 + h S345``
    * cond4: ``S6``, ``e C5 + d C45 - a S345``
    * cond5: ``d C3 + e C34 + h S345``, ``a + h C345 - d S3 - e S34``
    * cond1f (ours): ``S4``, ``F`` [m^3] (:func:`cond1_extra`)

    All lengths are the ones given (virtual, hatted, for 004's space arm).
    """
    lg = _lengths(lengths)
    q = np.asarray(q, dtype=float)
    if q.shape[-1:] != (7,):
        raise ConfigurationError(f"q must have shape (..., 7) [rad]; got {q.shape}")
    t = _trig(q)
    a, d, e, h = lg.a, lg.d, lg.e, lg.h
    g3 = d * t["C3"] + e * t["C34"] + h * t["S345"]
    g4 = e * t["C5"] + d * t["C45"] - a * t["S345"]
    g5 = a + h * t["C345"] - d * t["S3"] - e * t["S34"]
    return {
        "cond1": t["S4"][..., None],
        "cond2": np.stack([t["S2"], t["S6"]], axis=-1),
        "cond3": np.stack([t["S2"], g3], axis=-1),
        "cond4": np.stack([t["S6"], g4], axis=-1),
        "cond5": np.stack([g3, g5], axis=-1),
        "cond1f": np.stack([t["S4"], cond1_extra(q, lg)], axis=-1),
    }


def cond1_extra(q: ArrayLike, lengths: ArmLengths | ArmModel) -> FloatArray:
    """``F(q)`` [m^3]: with ``S4 = 0`` the Jacobian is rank deficient iff ``F = 0``.

    Found with sympy (all seven 6 x 6 minors of eq. 15 with ``S4 = 0`` share this factor;
    ``docs/readings/canadarm7-004.md``); 004 omits it.  With ``s = C4 = +-1`` (theta4 = 0 or
    pi) and ``D = d + s e``::

        F = S2 [(c+f) S6 (a C3 + s h C5) + h C5 C6 (D C5 - a S35)]
            - a C2 C3 S6 (D C3 + s h S35)

    evaluated with ``s = sign(C4)`` (so it is meaningful only where ``S4 ~ 0``).  Shape (...,).
    """
    lg = _lengths(lengths)
    q = np.asarray(q, dtype=float)
    t = _trig(q)
    s = np.where(np.cos(q[..., 3]) >= 0.0, 1.0, -1.0)
    a, c, d, e, f, h = lg.a, lg.c, lg.d, lg.e, lg.f, lg.h
    big_d = d + s * e
    return t["S2"] * (
        (c + f) * t["S6"] * (a * t["C3"] + s * h * t["C5"])
        + h * t["C5"] * t["C6"] * (big_d * t["C5"] - a * t["S35"])
    ) - a * t["C2"] * t["C3"] * t["S6"] * (big_d * t["C3"] + s * h * t["S35"])


def condition_residuals(
    q: ArrayLike, lengths: ArmLengths | ArmModel, *, refined: bool = False
) -> dict[str, FloatArray]:
    """Residual of each condition, (...,) dimensionless: the largest ``|equation|`` of the
    condition, length equations divided by the reach ``d + e`` (``F`` by ``(d + e)^3``), so one
    tolerance fits all.  A condition holds where its residual is ~ 0.  ``refined=True`` adds
    ``"cond1f"``."""
    lg = _lengths(lengths)
    eqs = condition_equations(q, lg)
    reach = lg.d + lg.e
    scale = {
        "cond1": np.array([1.0]),
        "cond2": np.array([1.0, 1.0]),
        "cond3": np.array([1.0, reach]),
        "cond4": np.array([1.0, reach]),
        "cond5": np.array([reach, reach]),
        "cond1f": np.array([1.0, reach**3]),
    }
    names = CONDITIONS + (REFINED_CONDITIONS if refined else ())
    return {name: np.max(np.abs(eqs[name]) / scale[name], axis=-1) for name in names}


def conditions_hold(
    q: ArrayLike, lengths: ArmLengths | ArmModel, *, tol: float = CONDITION_TOL, refined: bool = False
) -> dict[str, np.ndarray]:
    """``{name: (...,) bool}``: residual below ``tol`` (see :func:`condition_residuals`)."""
    return {k: v < tol for k, v in condition_residuals(q, lengths, refined=refined).items()}


def analytic_directions(q: ArrayLike, lengths: ArmLengths | ArmModel) -> dict[str, FloatArray]:
    """004's singular directions (eqs. 28 and 32), unit vectors (..., 6) in eq.-(24) row order
    (omega_z, v_x, v_y, v_z, omega_x, omega_y), Sigma_ref components.

    * cond1 (eq. 28): ``{0, -C5 S6, S5 S6, N_a, -h N_a + h C5 C6, 0}``,
      ``N_a = (-(c+f) C34 S6 + h S345 C5 C6) / (h S345 + e C34 + d C3)``
    * cond2, cond4 (eq. 32, U_s1 and U_s3): ``{0, 0, 0, S345, d C3 + e C34, 0}``
    * cond3, cond5 (eq. 32, U_s2 and U_s4): ``{0, 0, 0, 1, -h, 0}``

    Eq. (32) prints them under "ref"; they are in the eq.-(24) order ("ref'"), the only order
    in which they annihilate ``J21`` (checked: ``J'^T u = 0`` at every exact sample).  The pairing
    U_s1..U_s4 <-> Cond2..Cond5 is the printed order.  Where a direction is undefined (zero
    vector, or N_a's denominator 0) the entries are NaN.
    """
    lg = _lengths(lengths)
    q = np.asarray(q, dtype=float)
    t = _trig(q)
    c, d, e, f, h = lg.c, lg.d, lg.e, lg.f, lg.h
    z, one = np.zeros(q.shape[:-1]), np.ones(q.shape[:-1])
    with np.errstate(divide="ignore", invalid="ignore"):
        n_a = (-(c + f) * t["C34"] * t["S6"] + h * t["S345"] * t["C5"] * t["C6"]) / (
            h * t["S345"] + e * t["C34"] + d * t["C3"]
        )
        u1 = np.stack(
            [z, -t["C5"] * t["S6"], t["S5"] * t["S6"], n_a, -h * n_a + h * t["C5"] * t["C6"], z], axis=-1
        )
        u24 = np.stack([z, z, z, t["S345"], d * t["C3"] + e * t["C34"], z], axis=-1)
        u35 = np.stack([z, z, z, one, -h * one, z], axis=-1)
        out = {"cond1": u1, "cond2": u24, "cond3": u35, "cond4": u24, "cond5": u35}
        return {k: v / np.linalg.norm(v, axis=-1, keepdims=True) for k, v in out.items()}


def sample_condition(
    name: str,
    size: int,
    lengths: ArmLengths | ArmModel,
    *,
    rng: int | np.random.Generator | None = 0,
) -> FloatArray:
    """(size, 7) [rad] configurations that satisfy condition ``name`` exactly.

    The free angles are uniform in [-pi, pi); the condition's equations are solved in closed
    form for the others (batched; draws that have no solution are redrawn):

    * cond1: theta4 in {0, pi}.  cond2: theta2, theta6 in {0, pi}.
    * cond3: theta2 in {0, pi}; given theta3 and phi = theta3+theta4+theta5,
      ``cos(theta3+theta4) = -(d C3 + h sin phi) / e`` (both branches).
    * cond4: theta6 in {0, pi}; given theta5 and phi,
      ``cos(theta4+theta5) = (a sin phi - e C5) / d``.
    * cond5: given phi, a planar two-link problem
      ``d C3 + e C34 = -h sin phi``, ``d S3 + e S34 = a + h cos phi``.
    * cond1f: cond1 plus ``F = 0`` solved for theta6 (``F = A S6 + B C6``).
    """
    names = CONDITIONS + REFINED_CONDITIONS
    if name not in names:
        raise ScenarioError(f"condition must be one of {names}; got {name!r}")
    if size < 0:
        raise ScenarioError(f"size must be >= 0; got {size}")
    lg = _lengths(lengths)
    gen, _ = _rng(rng)
    a, d, e, h = lg.a, lg.d, lg.e, lg.h
    out: list[FloatArray] = []
    have = 0
    while have < size:
        m = max(2 * (size - have), 16)
        q = gen.uniform(-np.pi, np.pi, (m, 7))
        ok = np.ones(m, dtype=bool)
        branch = gen.choice([-1.0, 1.0], m)
        if name in ("cond1", "cond1f"):
            q[:, 3] = gen.integers(0, 2, m) * np.pi
        if name == "cond2":
            q[:, 1], q[:, 5] = gen.integers(0, 2, m) * np.pi, gen.integers(0, 2, m) * np.pi
        elif name == "cond3":
            q[:, 1] = gen.integers(0, 2, m) * np.pi
            phi = q[:, 4]
            cc = -(d * np.cos(q[:, 2]) + h * np.sin(phi)) / e
            ok = np.abs(cc) <= 1.0
            t34 = branch * np.arccos(np.clip(cc, -1, 1))
            q[:, 3], q[:, 4] = t34 - q[:, 2], phi - t34
        elif name == "cond4":
            q[:, 5] = gen.integers(0, 2, m) * np.pi
            phi = q[:, 2]
            cc = (a * np.sin(phi) - e * np.cos(q[:, 4])) / d
            ok = np.abs(cc) <= 1.0
            t45 = branch * np.arccos(np.clip(cc, -1, 1))
            q[:, 3], q[:, 2] = t45 - q[:, 4], phi - t45
        elif name == "cond5":
            phi = q[:, 4]
            x, y = -h * np.sin(phi), a + h * np.cos(phi)
            c4 = (x * x + y * y - d * d - e * e) / (2 * d * e)
            ok = np.abs(c4) <= 1.0
            t4 = branch * np.arccos(np.clip(c4, -1, 1))
            t3 = np.arctan2(y, x) - np.arctan2(e * np.sin(t4), d + e * np.cos(t4))
            q[:, 2], q[:, 3], q[:, 4] = t3, t4, phi - t3 - t4
        elif name == "cond1f":
            t = _trig(q)
            s = np.cos(q[:, 3])
            big_d = d + s * e
            coef_s6 = t["S2"] * (lg.c + lg.f) * (a * t["C3"] + s * h * t["C5"]) - a * t["C2"] * t["C3"] * (
                big_d * t["C3"] + s * h * t["S35"]
            )
            coef_c6 = t["S2"] * h * t["C5"] * (big_d * t["C5"] - a * t["S35"])
            q[:, 5] = np.arctan2(-coef_c6, coef_s6) + gen.integers(0, 2, m) * np.pi
            ok = np.hypot(coef_s6, coef_c6) > 1e-6
        q = np.mod(q + np.pi, 2 * np.pi) - np.pi
        out.append(q[ok])
        have += int(ok.sum())
    return np.concatenate(out)[:size] if out else np.empty((0, 7))


@dataclass(frozen=True)
class ConditionCheck:
    """Sufficiency check of one condition: how many exact samples are singular.

    Attributes
    ----------
    name
        ``"cond1"`` .. ``"cond5"`` or ``"cond1f"``.
    samples, singular
        Number of samples and how many have sigma_min(J^_m) < ``tol``.
    fraction_singular
        ``singular / samples``.
    sigma_min_median, sigma_min_max
        Of the samples [raw Jacobian units].
    max_residual
        Largest condition residual over the samples (should be ~1e-15).
    direction_residual
        Median ``|J'^T u| / |J'|`` of 004's analytic direction over the singular samples
        (NaN if none).
    direction_alignment
        Median ``|u_analytic . u_numeric|`` over the singular samples (1 = same direction).
    """

    name: str
    samples: int
    singular: int
    fraction_singular: float
    sigma_min_median: float
    sigma_min_max: float
    max_residual: float
    direction_residual: float
    direction_alignment: float

    @property
    def sufficient(self) -> bool:
        """Every sample was singular."""
        return self.samples > 0 and self.singular == self.samples


@dataclass(frozen=True)
class Completeness:
    """Completeness check: of the singular configurations found by the search, how many
    satisfy some condition.

    Attributes
    ----------
    found
        Singular configurations found (search converged).
    explained
        How many satisfy at least one of Cond1-Cond5 (residual < ``tol``).
    explained_refined
        How many satisfy at least one of cond1f, Cond2-Cond5 (Cond1 with ``F = 0``).
    per_condition
        ``{name: count}`` over found configurations, Cond1-Cond5 and cond1f (a configuration
        may satisfy several).
    unexplained
        (u, 7) [rad] those satisfying none.
    starts
        Number of search starts.
    """

    found: int
    explained: int
    explained_refined: int
    per_condition: dict[str, int]
    unexplained: FloatArray
    starts: int

    @property
    def fraction_explained(self) -> float:
        return self.explained / self.found if self.found else math.nan


@dataclass(frozen=True)
class ConditionVerification:
    """Result of :func:`verify_conditions`: sufficiency per condition and completeness."""

    checks: dict[str, ConditionCheck]
    completeness: Completeness
    lengths: ArmLengths
    base: str
    weighting: str
    sigma_tol: float
    condition_tol: float
    seed: int | None


def verify_conditions(
    model: ArmModel,
    *,
    samples: int = 2000,
    search_samples: int = 256,
    rng: int | np.random.Generator | None = 0,
    base: Literal["fixed", "virtual"] = "virtual",
    weighting: VMWeighting = "segment",
    sigma_tol: float = RANK_TOL,
    condition_tol: float = CONDITION_TOL,
    progress: object | None = None,
) -> ConditionVerification:
    """Check 004's conditions against the numerical test on a Canadarm2-structure arm.

    Sufficiency: for each of Cond1-Cond5 (and our refined ``cond1f``) draw ``samples``
    configurations satisfying it exactly (:func:`sample_condition`) and count those with
    sigma_min(J^_m) < ``sigma_tol``.  Completeness: run :func:`find_singularities` from
    ``search_samples`` starts and count the singular configurations found that satisfy some
    condition (residual < ``condition_tol``).  One child generator per task (spawned from
    ``rng``), so results do not depend on order.

    ``base="virtual"`` uses the virtual manipulator (needs a floating model, 004's case);
    ``"fixed"`` the real arm.
    """
    gen, seed = _rng(rng)
    lengths = arm_lengths(model, base=base, weighting=weighting)
    children = gen.spawn(len(CONDITIONS + REFINED_CONDITIONS) + 1)
    tb: BaseKind = base
    checks: dict[str, ConditionCheck] = {}
    for child, name in zip(children, CONDITIONS + REFINED_CONDITIONS):
        q = sample_condition(name, samples, lengths, rng=child)
        res = singularity_of_jacobian(task_jacobian(model, q, base=tb, weighting=weighting), tol=sigma_tol)
        max_res = float(condition_residuals(q, lengths, refined=True)[name].max()) if samples else math.nan
        dir_res, align = math.nan, math.nan
        sing = res.singular
        analytic_name = "cond1" if name == "cond1f" else name
        if sing.any():
            part = reorder_eq24(reference_jacobian(model, q[sing], base=base, weighting=weighting))
            ua = analytic_directions(q[sing], lengths)[analytic_name]
            jt_u = np.einsum("...ij,...i->...j", part.matrix, ua)
            dir_res = float(
                np.nanmedian(np.linalg.norm(jt_u, axis=-1) / np.linalg.norm(part.matrix, axis=(-2, -1)))
            )
            un = np.linalg.svd(part.matrix)[0][..., :, 5]
            align = float(np.nanmedian(np.abs(np.einsum("...i,...i->...", ua, un))))
        checks[name] = ConditionCheck(
            name=name,
            samples=int(samples),
            singular=int(sing.sum()),
            fraction_singular=float(sing.mean()) if samples else math.nan,
            sigma_min_median=float(np.median(res.sigma_min)) if samples else math.nan,
            sigma_min_max=float(res.sigma_min.max()) if samples else math.nan,
            max_residual=max_res,
            direction_residual=dir_res,
            direction_alignment=align,
        )
        if progress is not None:
            progress.update(1)  # type: ignore[attr-defined]
    search = find_singularities(model, samples=search_samples, rng=children[-1], base=tb, weighting=weighting)
    held = conditions_hold(search.q, lengths, tol=condition_tol, refined=True)
    any_held = np.zeros(len(search.q), dtype=bool)
    for name in CONDITIONS:
        any_held |= held[name]
    any_refined = held["cond1f"].copy()
    for name in CONDITIONS[1:]:
        any_refined |= held[name]
    completeness = Completeness(
        found=len(search.q),
        explained=int(any_held.sum()),
        explained_refined=int(any_refined.sum()),
        per_condition={k: int(v.sum()) for k, v in held.items()},
        unexplained=search.q[~any_held],
        starts=search_samples,
    )
    if progress is not None:
        progress.update(1)  # type: ignore[attr-defined]
    return ConditionVerification(
        checks=checks,
        completeness=completeness,
        lengths=lengths,
        base=base,
        weighting=weighting,
        sigma_tol=sigma_tol,
        condition_tol=condition_tol,
        seed=seed,
    )
