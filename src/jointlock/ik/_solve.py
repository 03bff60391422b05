"""Every IK solution of one target (:func:`solve_ik`): the closed form for the ``puma6``, UR
and spherical-wrist families, Levenberg-Marquardt otherwise, and the nearest reachable pose when no exact solution
exists (see :mod:`jointlock.ik`)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike

from .._random import resolve_seed
from ..errors import ConfigurationError, ModelError
from ..kinematics import ee_pose
from ..model import ArmModel, FloatArray
from ._numeric import ik_numeric
from ._pose import _as_poses, wrap_angle
from ._puma6 import closed_form_family, ik_closed_form

#: Two solutions closer than this (max wrapped joint difference) [rad] are the same: angles a
#: whole turn apart (a joint allowed more than one turn) give one pose and count once.
DUPLICATE_TOL = 1e-6


@dataclass(frozen=True)
class IKSolution:
    """One IK branch.

    Attributes
    ----------
    q
        (n,) movable-joint angles [rad].
    q_full
        (full_dof,) every joint in joint-number order, locked ones included [rad].
    branch
        Closed-form branch index (see :func:`puma6_branches`), or the start index for the
        numerical method.
    position_error
        ``|p - p_target|`` [m].
    rotation_error
        Rotation angle between target and reached orientation [rad].
    exact
        Both errors within :data:`EXACT_POSITION_TOL` / :data:`EXACT_ROTATION_TOL`.
    """

    q: FloatArray
    q_full: FloatArray
    branch: int
    position_error: float
    rotation_error: float
    exact: bool


@dataclass(frozen=True)
class IKResult:
    """Every IK solution of one target.

    Attributes
    ----------
    target
        (4, 4) requested pose [m].
    method
        ``"closed-form"`` or ``"numeric"``.
    solutions
        The exact solutions (distinct), best first.
    candidates
        Every branch computed, exact or not (closed form: all valid branches).
    nearest
        When no exact solution exists: the configuration whose pose is nearest to the target
        in the metric ``sqrt(|dp|^2 + (L dtheta)^2)`` (local optimum of Levenberg-Marquardt
        from every candidate and ``starts`` random starts); None otherwise.
    nearest_pose
        (4, 4) the pose reached by ``nearest`` [m], or None.
    length_scale
        ``L`` [m] of that metric.
    seed
        The seed of the numerical method's random starts (``rng`` an int, or the fresh seed
        drawn for ``rng=None``); None when ``rng`` was a Generator (see
        :mod:`jointlock._random`).
    tolerance
        ``(position [m], rotation [rad])`` within which a pose counts as reached when no exact
        solution exists (a target typed with rounded numbers); ``solutions`` then lists the
        distinct nearest configurations within it (``exact`` False).  None: exact only.
    family
        The closed form used (``"puma6"``, ``"ur"`` or ``"spherical-wrist"``), None for the
        numerical method.
    """

    target: FloatArray
    method: Literal["closed-form", "numeric"]
    solutions: tuple[IKSolution, ...]
    candidates: tuple[IKSolution, ...]
    nearest: IKSolution | None
    nearest_pose: FloatArray | None
    length_scale: float
    seed: int | None = None
    tolerance: tuple[float, float] | None = None
    family: str | None = None

    @property
    def reachable(self) -> bool:
        """True when at least one solution exists (exact, or within :attr:`tolerance`)."""
        return bool(self.solutions)

    @property
    def within_tolerance(self) -> bool:
        """Reached within :attr:`tolerance` only: no exact solution, some within it."""
        return bool(self.solutions) and not any(s.exact for s in self.solutions)


def _distinct(solutions: list[IKSolution]) -> list[IKSolution]:
    out: list[IKSolution] = []
    for s in solutions:
        if all(np.max(np.abs(wrap_angle(s.q - o.q))) > DUPLICATE_TOL for o in out):
            out.append(s)
    return out


def solve_ik(
    model: ArmModel,
    target: ArrayLike,
    *,
    method: Literal["auto", "closed-form", "numeric"] = "auto",
    starts: int = 16,
    rng: int | np.random.Generator | None = 0,
    length_scale: float = 1.0,
    tolerance: tuple[float, float] | None = None,
) -> IKResult:
    """Every IK solution of one target, and the nearest reachable pose when there is none.

    Parameters
    ----------
    model
        Any arm, possibly locked.  ``"auto"`` uses the closed form when the model is of the
        ``puma6``, UR or spherical-wrist family (:func:`closed_form_family`) and
        Levenberg-Marquardt otherwise.
    target
        (4, 4) pose in the root frame [m].
    starts, rng
        Random starts of the numerical method (also used to search the nearest reachable
        pose of a locked arm); ``rng`` as in :mod:`jointlock._random` (both searches start
        from the same seed), the seed used is ``IKResult.seed``.
    length_scale
        ``L`` [m] of the nearest-pose metric ``sqrt(|dp|^2 + (L dtheta)^2)``.
    tolerance
        ``(position [m], rotation [rad])``, each >= 0: when no exact solution exists, the
        distinct nearest configurations (from every candidate and start) within both are the
        solutions -- a target typed with rounded numbers (002's eq. (21) pose, printed to four
        decimals) is reached.  None (default): exact solutions only (1e-7 m, 1e-7 rad).

    Returns
    -------
    IKResult
    """
    if method not in ("auto", "closed-form", "numeric"):
        raise ConfigurationError(f"method must be 'auto', 'closed-form' or 'numeric'; got {method!r}")
    t = _as_poses(target)
    if t.shape != (4, 4):
        raise ConfigurationError(
            f"target must be one 4x4 pose; got shape {t.shape} (use ik_closed_form for batches)"
        )
    use_closed = method == "closed-form"
    if method == "auto":
        try:
            closed_form_family(model)
            use_closed = True
        except ModelError:
            use_closed = False
    if tolerance is not None:
        try:
            tol = np.asarray(tolerance, dtype=float)
        except (TypeError, ValueError):
            tol = np.full(3, np.nan)  # refused just below
        if tol.shape != (2,) or not np.all(np.isfinite(tol)) or np.any(tol < 0):
            raise ConfigurationError(
                f"tolerance must be (position [m], rotation [rad]), two finite numbers >= 0; got {tolerance!r}"
            )
        tolerance = (float(tol[0]), float(tol[1]))
    source = resolve_seed(rng)  # an int seed (fresh for None) or the caller's Generator
    seed = None if isinstance(source, np.random.Generator) else source
    cands, kind = _candidates(model, t, use_closed, starts, source, length_scale)
    exact = _distinct([c for c in cands if c.exact])
    nearest = None
    nearest_pose = None
    if not exact:
        seeds = [c.q for c in cands]
        refined = ik_numeric(
            model,
            t,
            q0=np.array(seeds) if seeds else None,
            starts=starts,
            rng=source,
            length_scale=length_scale,
        )
        metric = refined.position_error**2 + (length_scale * refined.rotation_error) ** 2
        k = int(np.argmin(metric))
        nearest = IKSolution(
            refined.q[k],
            model.expand(refined.q[k]),
            k,
            float(refined.position_error[k]),
            float(refined.rotation_error[k]),
            bool(refined.exact[k]),
        )
        nearest_pose = ee_pose(model, refined.q[k])
        if nearest.exact:  # the closed form missed it (singular target): report as a solution
            exact = [nearest]
            nearest, nearest_pose = None, None
        elif tolerance is not None:
            within = (refined.position_error <= tolerance[0]) & (refined.rotation_error <= tolerance[1])
            order = np.argsort(metric)
            exact = _distinct(
                [
                    IKSolution(refined.q[k], model.expand(refined.q[k]), int(k), float(refined.position_error[k]),
                               float(refined.rotation_error[k]), False)  # fmt: skip
                    for k in order
                    if within[k]
                ]
            )
    family = closed_form_family(model) if kind == "closed-form" else None
    return IKResult(
        t, kind, tuple(exact), tuple(cands), nearest, nearest_pose, float(length_scale), seed, tolerance, family
    )


#: Rounds of starts made from the solutions found (their symmetric images) in the numerical
#: method: other branches of the same pose lie there (a wrist flip, an elbow turned over).
#: Arms of at most six movable joints only (a redundant arm's solutions are a continuum).
SYMMETRY_ROUNDS = 2
#: Levenberg-Marquardt iterations from those starts (one near a branch converges in a few).
SYMMETRY_ITERATIONS = 40


def _symmetric_starts(found: FloatArray) -> FloatArray:
    """(m k, n) starts from each solution (m, n) [rad]: every joint turned by pi, every joint
    mirrored (-q), and the last three joints' wrist flip ``(q4 + pi, -q5, q6 + pi)``.  Exact for
    a spherical wrist (the flip), close to another branch elsewhere: Levenberg-Marquardt from
    there finds branches that random starts miss (12 % on puma6 and UR5 with 8 starts)."""
    n = found.shape[-1]
    images = []
    for j in range(n):
        turned = found.copy()
        turned[:, j] += np.pi
        images.append(turned)
    if n >= 3:
        flip = found.copy()
        flip[:, -3] += np.pi
        flip[:, -2] *= -1.0
        flip[:, -1] += np.pi
        images.append(flip)
    return np.concatenate(images, axis=0)


def _distinct_q(found: FloatArray, q: FloatArray) -> FloatArray:
    """The rows of ``found`` that are the configuration ``q`` (within DUPLICATE_TOL)."""
    d = np.max(np.abs(wrap_angle(found - q)), axis=-1)
    return found[d < DUPLICATE_TOL]


def _candidates(
    model: ArmModel,
    t: FloatArray,
    use_closed: bool,
    starts: int,
    rng: int | np.random.Generator,
    length_scale: float,
) -> tuple[list[IKSolution], Literal["closed-form", "numeric"]]:
    """Every branch of :func:`solve_ik`: the closed form's valid branches, or one per start of
    the numerical method; and the method's name."""
    cands: list[IKSolution] = []
    if use_closed:
        br = ik_closed_form(model, t)
        for b in np.flatnonzero(br.valid):
            cands.append(
                IKSolution(
                    br.q[b],
                    br.q_full[b],
                    int(b),
                    float(br.position_error[b]),
                    float(br.rotation_error[b]),
                    bool(br.exact[b]),
                )
            )
        kind: Literal["closed-form", "numeric"] = "closed-form"
    else:
        num = ik_numeric(model, t, starts=starts, rng=rng, length_scale=length_scale)
        runs = [num]
        found = frontier = num.q[num.exact]
        # a redundant arm (more than six movable joints) has a continuum of solutions, not branches
        for _ in range(SYMMETRY_ROUNDS if model.dof <= 6 else 0):
            if not len(frontier):
                break
            more = ik_numeric(model, t, q0=_symmetric_starts(frontier), starts=0, rng=rng, length_scale=length_scale,
                              max_iter=SYMMETRY_ITERATIONS)
            runs.append(more)
            new: list[FloatArray] = []
            for q in more.q[more.exact]:
                if not len(_distinct_q(found, q)):
                    new.append(q)
                    found = np.concatenate([found, q[None]])
            frontier = np.array(new).reshape(-1, found.shape[-1])
        for num in runs:
            for k in range(num.q.shape[0]):
                cands.append(
                    IKSolution(
                        num.q[k],
                        model.expand(num.q[k]),
                        len(cands),
                        float(num.position_error[k]),
                        float(num.rotation_error[k]),
                        bool(num.exact[k]),
                    )
                )
        kind = "numeric"
    return cands, kind
