"""The search (000 eqs. 19-24, HCOM): :func:`optimal_halt_configuration` samples the healthy
joints, scores each sample by CP (fitted on the sample set, then frozen), refines the best ones
and picks a runner-up; :func:`evaluate_cp` scores other configurations on the same scale."""

from __future__ import annotations

import logging
import math
from collections.abc import Callable, Sequence

import numpy as np
from numpy.typing import ArrayLike

from ..._random import resolve_rng
from ...analysis.ability import (
    DEFAULT_BATCH,
    PAPER_JUDGMENT,
    Assignment,
    JacobianKind,
    KinematicIndices,
    RITable,
    configuration_indices,
    fit_ability_model,
)
from ...collision import (
    check_clearance_m,
    clearance,
    collision_pairs,
    margin_floor,
    reports_clearance,
    smallest_excess,
)
from ...compiled import use_compiled
from ...errors import ConfigurationError, InfeasibleError
from ...forward import COMPILED_MIN_BATCH
from ...model import ArmModel, FloatArray, as_joint_array
from ...progress import Progress
from ...shapes import Shape
from ._bound import ReachabilityBound, _readonly
from ._reachability import HaltReachability
from ._refine import _refine
from ._result import HaltCandidate, HaltConfiguration
from ._sampling import _search_box

#: The name the search logs under (that of the module it was before the split).
logger = logging.getLogger("jointlock.planning.halt_config")

#: Default minimum separation of the runner-up from the best configuration (largest joint
#: difference) [rad]: 10 deg, so that the runner-up is another configuration, not the best
#: one nudged.
RUNNER_UP_SEPARATION = math.radians(10.0)


#: Two configurations whose CP differ by less than this (relative) are equivalents of one
#: another, not a runner-up [-] (refined starts agree to ~1e-10 at a common optimum).
EQUIVALENT_CP_RTOL = 1e-6


def _candidate(q: FloatArray, cp: float | FloatArray, ind: KinematicIndices) -> HaltCandidate:
    return HaltCandidate(
        _readonly(q),
        float(cp),
        float(ind.sigma_min),
        float(ind.condition_number),
        float(ind.manipulability),
    )


# Over 100 lines for its numpydoc docstring (every option of 000's HCOM); the body is ~85.
def optimal_halt_configuration(
    model_locked: ArmModel,
    *,
    samples: int = 36000,
    rng: int | np.random.Generator | None = None,
    jacobian: JacobianKind = "generalized",
    refine: bool = True,
    refine_starts: int = 8,
    assignment: Assignment = "equation",
    renormalize: bool = False,
    judgment: ArrayLike = PAPER_JUDGMENT,
    ri: RITable = "paper",
    characteristic_length: float | None = None,
    lower: ArrayLike | None = None,
    upper: ArrayLike | None = None,
    reachability: ReachabilityBound | HaltReachability | None = None,
    runner_up_separation: float = RUNNER_UP_SEPARATION,
    batch_size: int = DEFAULT_BATCH,
    progress: Progress | None = None,
    clearance_min_m: float | None = None,
    keep_out: Sequence[Shape] = (),
) -> HaltConfiguration:
    """Optimal halt configuration of an arm with locked joints (000 HCOM, eqs. 19-24).

    Parameters
    ----------
    model_locked
        The arm after the lock (:func:`jointlock.lock`); its movable joints are the healthy
        joints searched over.
    samples
        ``K``, Monte Carlo samples (000: 36000), K >= 2.
    rng
        Seed (int >= 0) or ``numpy.random.Generator`` (:mod:`jointlock._random`); None draws a
        fresh seed, which is recorded in ``seed`` (a Generator records None).
    jacobian
        ``"generalized"`` (default): 000 §3.1.2 analyses the generalized Jacobian ``J~_F`` of
        the free-floating arm (eq. 5), which is also what the crippled arm's operator sees in
        orbit.  A fixed-base model has no spacecraft to react, and its generalized Jacobian is
        the fixed-base one; load the robot with ``base="floating"`` for 000's ``J_F``.
        ``"fixed"``: the geometric Jacobian with the base held, whatever the model.
    refine
        Polish the best ``refine_starts`` samples with L-BFGS-B inside the box, CP's
        normalisation and weights frozen from the sample set; the best is never worse than
        the best sample.
    assignment, renormalize, judgment, ri
        Readings of 000's ambiguities and the AHP inputs, see
        :mod:`jointlock.analysis.ability`.  Defaults: eq. (19)'s index order
        (``"equation"``: the condition number receives the AHP weight 1/2), weights summed as
        printed in eq. (18) (not renormalised), 000's judgment matrix eq. (39) and RI table.
    characteristic_length
        ``L`` [m] to scale the Jacobian's linear rows; None (000) uses the raw matrix.
    lower, upper
        (n,) sampling box [rad]; default the joint limits capped to +-pi (000: [-180, 180] deg),
        so a joint without angle limits (continuous, limits +-inf) is sampled over [-pi, pi]
        (every angle, once) and has no angle constraint in the reachability check.
    reachability
        :class:`HaltReachability` (exact): only configurations that 000's halt polynomial
        reaches from the given state within ``T`` under the limits.  The sampling box is the
        bounding box of the reachable set (within the bang-bang bound and ``lower``/``upper``);
        samples outside the set are masked (they cannot be the best or the runner-up); the
        refinement keeps the constraint (a refined point that leaves the set is pulled back
        along the segment from its start, which is reachable, the set being convex).
        :class:`ReachabilityBound` (bang-bang, necessary only): the box is intersected with
        each joint's reachable rest angles.
    runner_up_separation
        Minimum largest-joint difference of the runner-up from the best [rad].
    batch_size
        Samples per batched evaluation.
    progress
        Optional progress bar (advanced per batch).
    clearance_min_m
        Beyond 000 (issue 27): the clearance a halt configuration must keep [m] between the
        arm's links, its spacecraft bus and the ``keep_out`` volumes
        (:func:`jointlock.collision.clearance`).  Samples closer than that are excluded like
        unreachable ones (they keep their CP in the fitted scale, but can be neither the best
        nor the runner-up; counted in ``colliding_samples``), and a refined point that comes
        closer is pulled back along its path from its start.  None (default, 000's search):
        nothing is excluded; the best configuration's clearance is reported either way when the
        model has collision shapes.
    keep_out
        Keep-out volumes, shapes in the root frame (:mod:`jointlock.shapes`).

    Returns
    -------
    HaltConfiguration

    Raises
    ------
    InfeasibleError
        When the reachability bound leaves no admissible angle for some joint, or no
        configuration is reachable under :class:`HaltReachability` (the message gives the
        state, ``T`` and the smallest halt time with a reachable configuration), or none of
        the samples is.
    """
    if isinstance(samples, bool) or not isinstance(samples, (int, np.integer)) or samples < 2:
        raise ConfigurationError(f"samples must be an integer >= 2; got {samples!r}")
    if jacobian not in ("generalized", "fixed"):
        raise ConfigurationError(f"jacobian must be 'generalized' or 'fixed'; got {jacobian!r}")
    if int(refine_starts) < 1:
        raise ConfigurationError(f"refine_starts must be >= 1; got {refine_starts!r}")
    margin = 0.0 if clearance_min_m is None else check_clearance_m(clearance_min_m, "clearance_min_m")
    generator, seed = resolve_rng(rng)
    lo, hi, reachability, k_range = _search_box(model_locked, lower, upper, reachability)
    exact_reach = reachability if isinstance(reachability, HaltReachability) else None
    n = model_locked.dof
    k = int(samples)

    q = lo + (hi - lo) * generator.random((k, n))  # 000 eq. (21)-(22), one row per sample
    reachable = None if exact_reach is None else exact_reach.contains(q)
    if reachable is not None and not reachable.any():
        assert exact_reach is not None  # reachable is only set with an exact reachability
        raise InfeasibleError(
            f"none of the {k} samples is reachable within T = {exact_reach.halt_time:g} s, although "
            f"reachable configurations exist in the box [{', '.join(f'{v:.4g}' for v in np.degrees(lo))}] .. "
            f"[{', '.join(f'{v:.4g}' for v in np.degrees(hi))}] deg (a thin set): increase samples or T"
        )
    n_reachable = None if reachable is None else int(np.count_nonzero(reachable))
    # required: refused for a model whose meshes were not read; reported only: None then
    checked = bool(collision_pairs(model_locked, keep_out).names) if clearance_min_m is not None else reports_clearance(
        model_locked, keep_out
    )
    clear = None
    keeps_clear: Callable[[FloatArray], np.ndarray] | None = None
    if clearance_min_m is not None and checked:
        keeps_clear = _clearance_test(model_locked, margin_floor(model_locked, margin, keep_out), keep_out)
        clear = keeps_clear(q)
        admissible = clear if reachable is None else clear & reachable
        if not admissible.any():
            # the sample that comes nearest to keeping it, and the pair that stops it
            sampled = clearance(model_locked, q, keep_out=keep_out, margin=margin, witness=False)
            short = sampled.shortfall()
            pool = np.flatnonzero(reachable) if reachable is not None and reachable.any() else np.arange(k)
            near = pool[int(np.argmin(short[pool].max(axis=1)))]
            pair = int(np.argmax(short[near]))
            raise InfeasibleError(
                f"none of the {k} samples keeps a clearance of {margin:g} m"
                + ("" if reachable is None else f" among the {int(reachable.sum())} reachable")
                + f" (links, spacecraft bus, keep-outs); the nearest keeps {sampled.pair_distance[near, pair]:+.3f} m "
                f"between {sampled.names[pair]}: lower clearance_min_m, widen the ranges, raise samples, or leave "
                "out a pair close by design (an SRDF's disable_collisions: srdf, --srdf)"
            )
        reachable = admissible
    ind = configuration_indices(
        model_locked,
        q,
        # compiled one-sided Jacobi (as exact as LAPACK) where the batch pays numba's start-up
        method="jacobi" if use_compiled(k, COMPILED_MIN_BATCH) else "gram",
        batch_size=batch_size,
        progress=progress,
        jacobian=jacobian,
        characteristic_length=characteristic_length,
    )
    ability = fit_ability_model(ind, judgment=judgment, assignment=assignment, renormalize=renormalize, ri=ri)
    cp = ability(ind)
    order = np.argsort(-cp if reachable is None else np.where(reachable, -cp, np.inf), kind="stable")
    n_ok = k if reachable is None else int(reachable.sum())

    def exact(qs: FloatArray) -> tuple[FloatArray, KinematicIndices]:
        i = configuration_indices(
            model_locked,
            qs,
            # LAPACK's SVD (the reference) on the refinement's small batches, unless the
            # process runs every batch compiled (jointlock.compiled)
            method="jacobi" if use_compiled(np.size(qs) // n, COMPILED_MIN_BATCH) else "svd",
            jacobian=jacobian,
            characteristic_length=characteristic_length,
        )
        return ability(i), i

    cp0, ind0 = exact(q[order[0]])
    best_sample = _candidate(q[order[0]], cp0, ind0)

    refined_q: list[FloatArray] = []
    refined_cp: list[float] = []
    evaluations = 0
    if refine:
        starts = q[order[: min(int(refine_starts), n_ok)]]

        # exact()'s CP, bit for bit, in one compiled call in a worker
        cp_of = ability.evaluator(model_locked, jacobian=jacobian, characteristic_length=characteristic_length)

        # the starts in lockstep where every batch of CP is the compiled kernel's (a worker),
        # whose numbers for a configuration do not depend on the batch: the same points
        refined_q, refined_cp, evaluations = _refine(
            cp_of, starts, lo, hi, exact_reach, keeps_clear,
            lockstep=use_compiled(2 * n + 1, COMPILED_MIN_BATCH),
        )  # fmt: skip
    best = best_sample
    if refined_cp and max(refined_cp) > best_sample.cp:
        j = int(np.argmax(refined_cp))
        c, i = exact(refined_q[j])
        best = _candidate(refined_q[j], c, i)

    pool_q = np.vstack([np.asarray(refined_q).reshape(-1, n), q if reachable is None else q[reachable]])
    pool_cp = np.concatenate(
        [np.asarray(refined_cp, dtype=float), cp if reachable is None else cp[reachable]]
    )
    runner_up = _runner_up(exact, best, pool_q, pool_cp, runner_up_separation)

    gain = best.cp - best_sample.cp
    logger.info("HCOM: best sample CP %.6g, refined %.6g (gain %.3g)", best_sample.cp, best.cp, gain)
    q.setflags(write=False)
    cp.setflags(write=False)
    if reachable is not None:
        reachable.setflags(write=False)
    if clear is not None:
        clear.setflags(write=False)
    return HaltConfiguration(
        best=best,
        best_sample=best_sample,
        runner_up=runner_up,
        refinement_gain=float(gain),
        ability=ability,
        samples=k,
        seed=seed,
        jacobian=jacobian,
        base="floating" if model_locked.floating else "fixed",
        joint_numbers=model_locked.joint_numbers,
        locked={lj.number: lj.angle for lj in model_locked.locked},
        lower=lo,
        upper=hi,
        characteristic_length=characteristic_length,
        reachability=reachability,
        q_samples=q,
        cp_samples=cp,
        indices_samples=ind,
        refine_evaluations=evaluations,
        reachable=reachable,
        reachable_samples=n_reachable,
        k_range=k_range,
        clearance_min_m=None if clear is None else margin,
        colliding_samples=None if clear is None else int(k - np.count_nonzero(clear)),
        best_clearance=clearance(model_locked, best.q, keep_out=keep_out, margin=margin)
        if checked
        else None,
    )


def _runner_up(
    exact: Callable[[FloatArray], tuple[FloatArray, KinematicIndices]],
    best: HaltCandidate,
    pool_q: FloatArray,
    pool_cp: FloatArray,
    separation: float,
) -> HaltCandidate | None:
    """The best of the pool (m, n) [rad] with CP (m,) that is far from ``best`` and not an
    equivalent of it (same CP: e.g. joint 1 of a fixed base, or a joint turning about the tool
    axis, leaves every index unchanged); None if there is none."""
    far = (np.max(np.abs(pool_q - best.q), axis=-1) > separation) & (
        np.abs(pool_cp - best.cp) > EQUIVALENT_CP_RTOL * max(1.0, abs(best.cp))
    )
    if not np.any(far):
        return None
    j = int(np.argmax(np.where(far, pool_cp, -np.inf)))
    c, i = exact(pool_q[j])
    return _candidate(pool_q[j], c, i)


def evaluate_cp(result: HaltConfiguration, model_locked: ArmModel, q: ArrayLike) -> FloatArray:
    """CP (...) of configurations (..., n) [rad] on the frozen scale of a search result
    (same Jacobian, normalisation and weights), e.g. 000's printed ``q_best`` and ``q_sub``."""
    q = as_joint_array(model_locked, q)
    ind = configuration_indices(
        model_locked, q, jacobian=result.jacobian, characteristic_length=result.characteristic_length
    )
    return result.ability(ind)


def _clearance_test(model: ArmModel, floor: FloatArray, keep_out: Sequence[Shape]) -> Callable[[FloatArray], np.ndarray]:
    """(K, n) configurations -> (K,) whether each keeps every pair above its floor (P,) [m]:
    ``~Clearance.colliding(margin)`` for the floors of a margin, without the distances of pairs
    far from their floor (:func:`jointlock.collision.smallest_excess`)."""

    def keeps_clear(qs: FloatArray) -> np.ndarray:
        return ~(smallest_excess(model, qs, floor, keep_out=keep_out)[0] < 0)

    return keeps_clear
