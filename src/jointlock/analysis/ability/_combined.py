"""The combined weights and index CP of 000 eqs. (18)-(19), and :class:`AbilityModel`: CP with
its normalisation and weights frozen from a sample set (the readings of 000's ambiguities are
in :mod:`jointlock.analysis.ability`)."""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike

from ..._chain import kernel_input, kernel_mass_program, kernel_program
from ...compiled import use_compiled
from ...errors import ConfigurationError, ScenarioError
from ...model import ArmModel, FloatArray, as_joint_array
from ._ahp import PAPER_JUDGMENT, AHPResult, RITable, ahp_weights
from ._entropy import EntropyResult, entropy_weights
from ._indices import (
    INDEX_NAMES,
    JacobianKind,
    KinematicIndices,
    Normalization,
    StandardizedIndices,
    configuration_indices,
    standardize,
)

Assignment = Literal["text", "equation"]


def ahp_to_canonical(weights: ArrayLike, assignment: Assignment) -> FloatArray:
    """Reorder a 3-vector of AHP weights into the canonical order ``(s, kappa, w)``.

    ``"text"``: the AHP vector is ``(s, w, kappa)`` (000 eq. 12 and §5.1).  ``"equation"``:
    it is ``(s, kappa, w)`` (the index order of 000 eq. 19).
    """
    w = np.asarray(weights, dtype=float)
    if w.shape != (3,):
        raise ConfigurationError(f"AHP weights must be 3 numbers (one per index); got shape {w.shape}")
    if assignment == "text":
        return w[[0, 2, 1]]
    if assignment == "equation":
        return w.copy()
    raise ScenarioError(f"assignment must be 'text' or 'equation'; got {assignment!r}")


def combine_weights(
    ahp: ArrayLike,
    entropy: ArrayLike,
    *,
    assignment: Assignment = "equation",
    renormalize: bool = False,
) -> FloatArray:
    """Combined weights ``omega_C = omega_CR + omega_CP`` (000 eq. 18), canonical order.

    Parameters
    ----------
    ahp
        (3,) AHP weights in the judgment matrix's row order (see :func:`ahp_to_canonical`).
    entropy
        (3,) entropy weights in canonical order.
    assignment
        ``"equation"`` (default) or ``"text"``; see the module docstring.
    renormalize
        Divide by the sum (2) so the weights sum to 1.  Default False, as eq. (18) is printed.

    Returns
    -------
    (3,) weights of ``(s_hat, kappa_hat, w_hat)``.
    """
    ent = np.asarray(entropy, dtype=float)
    if ent.shape != (3,):
        raise ConfigurationError(f"entropy weights must be 3 numbers; got shape {ent.shape}")
    combined = ahp_to_canonical(ahp, assignment) + ent
    if renormalize:
        combined = combined / combined.sum()
    return combined


def combined_index(standardized: StandardizedIndices, weights: ArrayLike) -> FloatArray:
    """CP of 000 eq. (19): ``w_1 s_hat + w_2 kappa_hat + w_3 w_hat``, shape (...).

    ``weights`` is (3,) in canonical order (from :func:`combine_weights`).
    """
    w = np.asarray(weights, dtype=float)
    if w.shape != (3,):
        raise ConfigurationError(f"weights must be 3 numbers (s_hat, kappa_hat, w_hat); got shape {w.shape}")
    return w[0] * standardized.s_hat + w[1] * standardized.kappa_hat + w[2] * standardized.w_hat


@dataclass(frozen=True)
class AbilityModel:
    """CP with its normalisation and weights frozen from a sample set: a function of indices.

    Build it with :func:`fit_ability_model`; call it on any :class:`KinematicIndices` to get
    CP (...).

    Attributes
    ----------
    normalization
        Min-max bounds of ``s`` and ``w`` over the sample set.
    weights
        (3,) combined weights, canonical order.
    ahp
        The AHP result (weights in the judgment matrix's row order).
    entropy
        The entropy result (canonical order) over the sample set.
    assignment, renormalize
        The readings used (see the module docstring).
    """

    normalization: Normalization
    weights: FloatArray
    ahp: AHPResult
    entropy: EntropyResult
    assignment: Assignment = "equation"
    renormalize: bool = False
    ahp_canonical: FloatArray = field(default_factory=lambda: np.zeros(3))

    def standardize(self, indices: KinematicIndices) -> StandardizedIndices:
        """Standardise with the frozen bounds."""
        return standardize(indices, self.normalization)

    def __call__(self, indices: KinematicIndices) -> FloatArray:
        """CP (...) of ``indices`` with the frozen normalisation and weights."""
        return combined_index(self.standardize(indices), self.weights)

    def of_configurations(
        self,
        model: ArmModel,
        q: ArrayLike,
        *,
        jacobian: JacobianKind = "generalized",
        characteristic_length: float | None = None,
    ) -> FloatArray:
        """CP (...) of ``model`` at configurations ``q`` (..., n) [rad]: this model applied to
        :func:`~jointlock.analysis.ability.configuration_indices`, the same numbers bit for bit.
        Where that would run its compiled kernel (:func:`jointlock.compiled.use_compiled`: a
        campaign's workers, or a large batch), in one compiled call with the indices, their
        standardisation and the sum (:func:`jointlock._kernels.combined_index`): the halt
        configuration's refinement asks it of 13 configurations at a time."""
        return self.evaluator(model, jacobian=jacobian, characteristic_length=characteristic_length)(q)

    def evaluator(
        self,
        model: ArmModel,
        *,
        jacobian: JacobianKind = "generalized",
        characteristic_length: float | None = None,
    ) -> Callable[[ArrayLike], FloatArray]:
        """``cp(q)``: :meth:`of_configurations` of ``model`` with these arguments, bit for bit,
        with what does not depend on ``q`` (the arguments' checks, the kernel's model arrays,
        the frozen bounds) prepared once: the refinement calls it ~40 times per start, where
        that preparation cost a third of each 13-configuration call."""
        from ...forward import COMPILED_MIN_BATCH  # on first use, as configuration_indices takes it

        def numpy_route(q: ArrayLike) -> FloatArray:  # which also says what is wrong with the arguments, first
            indices = configuration_indices(model, q, jacobian=jacobian, characteristic_length=characteristic_length)
            return self(indices)

        try:
            length = 1.0 if characteristic_length is None else float(characteristic_length)
        except (TypeError, ValueError):
            return numpy_route
        if (
            jacobian not in ("generalized", "fixed")
            or not (math.isfinite(length) and length > 0)
            or np.shape(self.weights) != (3,)
        ):
            return numpy_route
        floating = jacobian == "generalized" and model.floating
        s_lo, s_hi = self.normalization.sigma_min_range
        w_lo, w_hi = self.normalization.manipulability_range
        bounds = np.array([s_lo, s_hi - s_lo, w_lo, w_hi - w_lo])
        weights = kernel_input(np.asarray(self.weights, dtype=float))
        prepared: list[tuple[Any, ...]] = []  # the kernel and its model arrays, on the first compiled call

        def cp(q: ArrayLike) -> FloatArray:
            arr = as_joint_array(model, q)
            flat = arr.reshape(-1, model.dof)
            if not use_compiled(flat.shape[0], COMPILED_MIN_BATCH):
                return numpy_route(q)
            if not prepared:
                from ... import _kernels  # numba on first use

                masses = kernel_mass_program(model) if floating else _no_masses(model.dof)
                prepared.append((_kernels.combined_index, *kernel_program(model)[:3], *masses))
            kernel, *arrays = prepared[0]
            rows = flat.shape[0]
            lanes = -(-rows // SIMD_LANES) * SIMD_LANES
            if lanes > rows:  # copies of the last configuration: every lane is its own, the same bits
                flat = np.concatenate([flat, np.repeat(flat[-1:], lanes - rows, axis=0)])
            out = np.empty(lanes)
            kernel(kernel_input(flat), *arrays, floating, length, bounds, weights, out)
            return out[:rows].reshape(arr.shape[:-1])[()]  # one configuration: a numpy float, as numpy's route

        return cp

    def weights_dict(self) -> dict[str, dict[str, float]]:
        """``{"ahp" | "entropy" | "combined": {index name: weight}}``."""
        return {
            "ahp": dict(zip(INDEX_NAMES, map(float, self.ahp_canonical))),
            "entropy": dict(zip(INDEX_NAMES, map(float, self.entropy.weights))),
            "combined": dict(zip(INDEX_NAMES, map(float, self.weights))),
        }


def fit_ability_model(
    indices: KinematicIndices,
    *,
    judgment: ArrayLike = PAPER_JUDGMENT,
    assignment: Assignment = "equation",
    renormalize: bool = False,
    ri: RITable | Mapping[int, float] = "paper",
) -> AbilityModel:
    """Fix the normalisation and the weights of CP from a sample set (000 §3.1.2-3.1.3).

    Parameters
    ----------
    indices
        Indices of the K sample configurations (any shape, flattened; K >= 2).
    judgment
        (3, 3) AHP judgment matrix; default 000 eq. (39).  Its row order is ``(s, w, kappa)``
        under ``assignment="text"`` and ``(s, kappa, w)`` under ``"equation"``.
    assignment, renormalize
        The readings of 000's ambiguities (module docstring); defaults ``"equation"``, False.
    ri
        RI table for the consistency test (:func:`ahp_weights`).

    Returns
    -------
    AbilityModel
    """
    ahp = ahp_weights(judgment, ri=ri)
    if ahp.weights.shape != (3,):
        raise ScenarioError(
            f"judgment matrix must be 3 x 3 (one row per index); got {ahp.matrix.shape[0]} x "
            f"{ahp.matrix.shape[0]}"
        )
    flat = indices[...] if np.ndim(indices.sigma_min) == 1 else _flatten(indices)
    norm = Normalization.from_samples(flat)
    std = standardize(flat, norm)
    ent = entropy_weights(std.stacked())
    weights = combine_weights(ahp.weights, ent.weights, assignment=assignment, renormalize=renormalize)
    for arr in (weights,):
        arr.setflags(write=False)
    return AbilityModel(
        normalization=norm,
        weights=weights,
        ahp=ahp,
        entropy=ent,
        assignment=assignment,
        renormalize=bool(renormalize),
        ahp_canonical=ahp_to_canonical(ahp.weights, assignment),
    )


def _flatten(indices: KinematicIndices) -> KinematicIndices:
    return KinematicIndices(
        np.ravel(indices.sigma_min),
        np.ravel(indices.condition_number),
        np.ravel(indices.manipulability),
        np.ravel(indices.inverse_condition),
    )


#: The kernel's batch is padded to a multiple of this many configurations: its loops over a
#: block run SIMD lanes (8 doubles with AVX-512, twice 4 with AVX2) and a scalar remainder
#: about ten times slower per configuration (13 configurations cost 64 us, 16 cost 36 us).
#: The configurations never mix (each lane's operations are its own, and a converged Jacobi
#: lane is left exactly as it is), so the padding changes no bit.  (What a block of 128
#: decides as a whole -- its Jacobi sweeps; libm's sine and cosine for every lane when one
#: angle reaches ``TRIG_LIMIT`` -- is unchanged too: the copies are of a row already in the
#: last block.)
SIMD_LANES = 8


def _no_masses(n: int) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """Stand-ins for the masses of :func:`jointlock._kernels.combined_index` on a fixed base
    (not read; the arrays of the types the floating case passes, so numba compiles it once)."""
    return np.zeros(n), np.zeros((n, 3)), np.zeros((n, 3, 3)), np.zeros(13)
