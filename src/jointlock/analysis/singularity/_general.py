"""Singularity analysis of any arm: the task Jacobian, its singular values, rank, ``det(J J^T)``
and lost directions (batched SVD)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike

from ..._deprecate import renamed_keyword
from ..._random import resolve_rng
from ...errors import ConfigurationError, ModelError, ScenarioError
from ...kinematics import VMWeighting, generalized_jacobian, virtual_manipulator
from ...kinematics import jacobian as geometric_jacobian
from ...model import ArmModel, FloatArray

#: The Jacobians whose singularities are analysed, the keyword ``jacobian=`` (the spelling of
#: :mod:`jointlock.analysis.ability` and the halt configuration): ``"fixed"`` (geometric),
#: ``"generalized"`` (zero momentum) and ``"virtual"`` (004's virtual manipulator).
JACOBIAN_KINDS: tuple[str, ...] = ("fixed", "generalized", "virtual")
#: Other spellings accepted for a kind: ``"floating"`` is ``"generalized"`` (what
#: ``jointlock singular --base floating`` and the scenario field ``singular.base`` say).
JACOBIAN_SYNONYMS: dict[str, str] = {"floating": "generalized"}
#: What ``jacobian=`` accepts: a kind of :data:`JACOBIAN_KINDS` or ``"floating"``.
TaskJacobianKind = Literal["fixed", "generalized", "virtual", "floating"]
#: The spellings of ``jointlock singular --base`` (its choices).
BaseKind = Literal["fixed", "floating", "virtual"]
BASE_KINDS: tuple[str, ...] = ("fixed", "floating", "virtual")

#: Rank tolerance on a singular value (raw Jacobian: m/s or rad/s per rad/s).  Exactly
#: singular configurations of the built-in arms give sigma_min ~ 1e-15; the smallest
#: sigma_min of 10^5 random configurations is ~ 1e-3, so 1e-8 separates them by 5 decades.
RANK_TOL = 1e-8


#: The package's one rng convention (:func:`jointlock._random.resolve_rng`): ``(generator,
#: seed)``, the seed a fresh one for ``rng=None`` and None for a Generator.  (The name the
#: singularity modules used before it was shared.)
_rng = resolve_rng


def _check_base(base: str) -> None:
    if base not in BASE_KINDS:
        raise ScenarioError(f"base must be one of {BASE_KINDS}; got {base!r}")


def jacobian_kind(kind: str) -> str:
    """The kind of :data:`JACOBIAN_KINDS` that ``kind`` names (``"floating"`` ->
    ``"generalized"``); :class:`~jointlock.ScenarioError` naming ``jacobian`` otherwise."""
    canonical = JACOBIAN_SYNONYMS.get(kind, kind) if isinstance(kind, str) else kind
    if canonical not in JACOBIAN_KINDS:
        raise ScenarioError(
            f"jacobian must be one of {JACOBIAN_KINDS} ('floating': the same as 'generalized'); got {kind!r}"
        )
    return canonical


@renamed_keyword(old="base", new="jacobian")
@renamed_keyword(old="length", new="characteristic_length")
def task_jacobian(
    model: ArmModel,
    q: ArrayLike,
    *,
    jacobian: TaskJacobianKind = "fixed",
    weighting: VMWeighting = "segment",
    characteristic_length: float | None = None,
) -> FloatArray:
    """The Jacobian whose singularities are analysed.

    Parameters
    ----------
    model
        The arm.  ``jacobian="generalized"`` and ``"virtual"`` need a free-floating model
        (``model.floating``).
    q
        (..., n) joint angles [rad] of the movable joints.
    jacobian
        ``"fixed"``: geometric Jacobian of the end effector (fixed base, or a spacecraft held
        still), root-frame components.  ``"generalized"`` (or ``"floating"``, the same):
        generalized Jacobian, zero momentum (000 eq. 5).  ``"virtual"``: Jacobian ``J^_m`` of
        the virtual manipulator (004 eqs. 10-12: free-flying arm with attitude held, or eq. 14
        with the measured base rate subtracted).  Formerly ``base=`` (deprecated alias).
    weighting
        Virtual link lengths for ``jacobian="virtual"`` (see
        :func:`jointlock.virtual_link_vectors`); ``"segment"`` is 004's formula.
    characteristic_length
        ``L`` [m]: the linear rows are divided by it.  ``None``: raw.  Formerly ``length=``
        (deprecated alias).

    Returns
    -------
    (..., 6, n): twist ``(v, omega)`` of the end-effector origin, root-frame components.
    """
    kind = jacobian_kind(jacobian)
    if kind != "fixed" and not model.floating:
        raise ModelError(
            f"jacobian={jacobian!r} needs a free-floating model (a spacecraft base); {model.name!r} has a "
            "fixed base — load it with base='floating' or use jacobian='fixed'"
        )
    if kind == "fixed":
        jac = geometric_jacobian(model, q)
    elif kind == "generalized":
        jac = generalized_jacobian(model, q)
    else:
        jac = virtual_manipulator(model, q, weighting=weighting).jacobian
    length = characteristic_length
    if length is not None:
        if not (math.isfinite(length) and length > 0):
            raise ScenarioError(f"characteristic_length must be a positive number of metres; got {length!r}")
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
        The settings that produced it: the rank tolerance, the Jacobian kind as given
        (``jacobian=``), the virtual lengths and the characteristic length [m]
        (``characteristic_length=``).
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


@renamed_keyword(old="base", new="jacobian")
@renamed_keyword(old="length", new="characteristic_length")
def singularity_of_jacobian(
    jac: ArrayLike,
    *,
    tol: float = RANK_TOL,
    jacobian: str = "given",
    weighting: str = "",
    characteristic_length: float | None = None,
) -> SingularityAnalysis:
    """:class:`SingularityAnalysis` of given Jacobians (..., 6, n) (batched SVD).  ``jacobian``,
    ``weighting`` and ``characteristic_length`` only label the result (``base``, ``weighting``,
    ``length``); formerly ``base=`` and ``length=`` (deprecated aliases)."""
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
        base=jacobian,
        weighting=weighting,
        length=characteristic_length,
    )


@renamed_keyword(old="base", new="jacobian")
@renamed_keyword(old="length", new="characteristic_length")
def analyse_singularity(
    model: ArmModel,
    q: ArrayLike,
    *,
    jacobian: TaskJacobianKind = "fixed",
    weighting: VMWeighting = "segment",
    tol: float = RANK_TOL,
    characteristic_length: float | None = None,
) -> SingularityAnalysis:
    """sigma_min, rank, det(J J^T) and lost directions of ``model`` at ``q`` (..., n) [rad].

    The Jacobian is :func:`task_jacobian` (``jacobian``, ``weighting``,
    ``characteristic_length`` as there; formerly ``base=`` and ``length=``, deprecated aliases).
    ``tol`` is the rank tolerance on singular values (units of the analysed matrix).  The lost
    directions are left singular vectors: task-space twists ``(v, omega)`` (root frame) the
    end effector cannot produce to first order.
    """
    jac = task_jacobian(
        model, q, jacobian=jacobian, weighting=weighting, characteristic_length=characteristic_length
    )
    return singularity_of_jacobian(
        jac, tol=tol, jacobian=jacobian, weighting=weighting, characteristic_length=characteristic_length
    )
