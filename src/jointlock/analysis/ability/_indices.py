"""The three unilateral kinematic-ability indices of 000 Table 3 (sigma_min, condition number,
manipulability) of a batch of Jacobians or of an arm's configurations, and their
standardisation (000 eqs. 6-9; see :mod:`jointlock.analysis.ability`)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal, cast

import numpy as np
from numpy.typing import ArrayLike

from ..._chain import kernel_input, kernel_mass_program, kernel_program
from ...compiled import use_compiled
from ...errors import ConfigurationError
from ...model import ArmModel, FloatArray
from ...progress import Progress

#: Names of the three unilateral indices, in the canonical order used by every vector here.
INDEX_NAMES: tuple[str, str, str] = ("sigma_min", "condition_number", "manipulability")


# -- the three indices ----------------------------------------------------------------------


@dataclass(frozen=True)
class KinematicIndices:
    """The unilateral kinematic-ability indices of 000 Table 3 for a batch of Jacobians.

    Attributes
    ----------
    sigma_min
        (...) minimum singular value ``s`` [units of the Jacobian].
    condition_number
        (...) ``kappa = sigma_max / sigma_min`` [-]; ``inf`` where ``sigma_min = 0``.
    manipulability
        (...) ``w`` = product of all singular values.
    inverse_condition
        (...) ``1 / kappa = sigma_min / sigma_max`` in ``[0, 1]`` (0 at a singularity), the
        standardised condition number of 000 eq. (9).
    """

    sigma_min: FloatArray
    condition_number: FloatArray
    manipulability: FloatArray
    inverse_condition: FloatArray

    def __getitem__(self, key) -> KinematicIndices:
        return KinematicIndices(
            self.sigma_min[key],
            self.condition_number[key],
            self.manipulability[key],
            self.inverse_condition[key],
        )

    def as_dict(self) -> dict[str, FloatArray]:
        """``{index name: values}`` in :data:`INDEX_NAMES` order."""
        return {
            "sigma_min": self.sigma_min,
            "condition_number": self.condition_number,
            "manipulability": self.manipulability,
        }


def scale_linear_rows(jac: ArrayLike, characteristic_length: float) -> FloatArray:
    """Divide the linear-velocity rows (0-2) of a (..., 6, k) Jacobian by a length ``L`` [m].

    The result maps joint rates [rad/s] to ``(v / L, omega)``, all in [1/s], so that singular
    values no longer mix m/s and rad/s.
    """
    jac = np.asarray(jac, dtype=float)
    length = float(characteristic_length)
    if not (math.isfinite(length) and length > 0):
        raise ConfigurationError(f"characteristic_length must be a finite length > 0 [m]; got {length}")
    if jac.ndim < 2 or jac.shape[-2] != 6:
        raise ConfigurationError(
            f"jacobian must have shape (..., 6, k) to scale its linear rows; got {jac.shape}"
        )
    out = jac.copy()
    out[..., :3, :] /= length
    return out


#: Above this condition number :func:`singular_values` with ``method="auto"`` falls back to
#: the SVD: the Gram route's relative error on ``sigma_i`` is ~ eps * kappa_i^2 / 2, i.e.
#: below 1.2e-8 up to here.
GRAM_CONDITION_LIMIT = 1e4


#: Largest entry magnitude the compiled SVD takes (squares of column norms must not
#: overflow); larger or tiny-scaled matrices go to LAPACK.
_COMPILED_RANGE = (1e-120, 1e120)


SVMethod = Literal["svd", "jacobi", "gram", "auto"]


def singular_values(jac: ArrayLike, *, method: SVMethod = "svd") -> FloatArray:
    """Singular values of a batch of matrices, descending.

    Parameters
    ----------
    jac
        (..., m, k) matrices.
    method
        ``"svd"``: LAPACK's batched SVD (one call per matrix), exact to round-off.
        ``"jacobi"``: one-sided (Hestenes) Jacobi, compiled
        (:func:`jointlock._kernels.singular_values`, several times faster on 6 x 6 batches):
        every singular value to high relative accuracy (Demmel & Veselic 1992), within
        ~1e-15 * sigma_max of LAPACK's (LAPACK is used instead for non-finite matrices or
        entries beyond 1e120 or below 1e-120); the round-off of values at the noise level
        (``sigma ~ 1e-16 sigma_max``) differs from LAPACK's.  ``"gram"``: square
        roots of the eigenvalues of the smaller Gram matrix (relative error
        ~ eps * kappa_i^2 / 2 on ``sigma_i``).  ``"auto"``: ``"gram"`` with the SVD redone for
        the matrices whose condition number exceeds :data:`GRAM_CONDITION_LIMIT`, so the
        relative error stays below ~1.2e-8 for every matrix.

    Returns
    -------
    (..., min(m, k)) singular values.
    """
    arr = np.asarray(jac, dtype=float)
    if method == "svd":
        return np.linalg.svd(arr, compute_uv=False)
    if method == "jacobi":
        return _jacobi_values(arr)
    if method not in ("gram", "auto"):
        raise ConfigurationError(f"method must be 'svd', 'jacobi', 'gram' or 'auto'; got {method!r}")
    jt = np.swapaxes(arr, -1, -2)
    gram = jt @ arr if arr.shape[-1] <= arr.shape[-2] else arr @ jt
    sv = np.sqrt(np.clip(np.linalg.eigvalsh(gram), 0.0, None))[..., ::-1]
    if method == "auto":
        bad = sv[..., -1] * GRAM_CONDITION_LIMIT < sv[..., 0]
        if np.any(bad):
            sv[bad] = np.linalg.svd(arr[bad], compute_uv=False)
    return sv


def _jacobi_values(arr: FloatArray) -> FloatArray:
    """Singular values by the compiled one-sided Jacobi kernel; LAPACK outside its range."""
    if arr.ndim < 2 or 0 in arr.shape[-2:]:
        return cast(FloatArray, np.linalg.svd(arr, compute_uv=False))
    flat = kernel_input(arr.reshape((-1,) + arr.shape[-2:]))
    big = np.max(np.abs(flat), initial=0.0)
    if not np.isfinite(big) or big > _COMPILED_RANGE[1] or 0.0 < big < _COMPILED_RANGE[0]:
        return cast(FloatArray, np.linalg.svd(arr, compute_uv=False))
    from ... import _kernels  # numba is imported on first use, not with the package

    out = np.empty((flat.shape[0], min(arr.shape[-2:])))
    _kernels.singular_values(flat, out)
    return out.reshape(arr.shape[:-2] + out.shape[-1:])


def kinematic_indices(
    jac: ArrayLike,
    *,
    characteristic_length: float | None = None,
    method: SVMethod = "svd",
) -> KinematicIndices:
    """Minimum singular value, condition number and manipulability (000 Table 3, eqs. 6-7).

    Parameters
    ----------
    jac
        (..., m, k) Jacobians, any leading batch shape; for an arm with a locked joint, the
        Jacobian of the locked model (000's ``J~_F``, or the fixed-base ``J~``), twist order
        ``(v [m/s], omega [rad/s])`` when ``m = 6``.
    characteristic_length
        ``L`` [m]: divide the linear rows by ``L`` first (``m`` must be 6).  ``None`` (default,
        as 000): the raw matrix.
    method
        ``"svd"`` (default): LAPACK's batched singular value decomposition, exact to
        round-off.  ``"jacobi"``: compiled one-sided Jacobi (see :func:`singular_values`),
        as accurate, several times faster.
        ``"gram"``: square roots of the eigenvalues of the smaller Gram matrix (``J^T J`` or
        ``J J^T``), about 1.5x faster on 6 x 6 batches; absolute error of ``sigma_min`` about
        ``eps sigma_max^2 / sigma_min`` (1e-8 at ``sigma_min = 1e-6``, ``sigma_max = 10``),
        harmless for ranking samples.  Negative round-off eigenvalues are clipped to 0.
        ``"auto"``: ``"gram"``, with the SVD redone where the condition number exceeds
        :data:`GRAM_CONDITION_LIMIT` (see :func:`singular_values`).

    Returns
    -------
    KinematicIndices
        Arrays of shape (...).  The singular values are the ``min(m, k)`` values of the
        batched SVD; ``w`` is their product (``sqrt(det(J J^T))`` when ``k >= m``).
    """
    arr = np.asarray(jac, dtype=float)
    if arr.ndim < 2 or 0 in arr.shape[-2:]:
        raise ConfigurationError(f"jacobian must have shape (..., m, k) with m, k >= 1; got {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ConfigurationError("jacobian must be finite; got NaN or inf entries")
    if characteristic_length is not None:
        arr = scale_linear_rows(arr, characteristic_length)
    return _from_singular_values(singular_values(arr, method=method))


def _from_singular_values(sv: FloatArray) -> KinematicIndices:
    """The indices of singular values (..., r), descending."""
    smax = sv[..., 0]
    smin = sv[..., -1]
    positive = smin > 0
    kappa = np.divide(smax, smin, out=np.full(smin.shape, np.inf), where=positive)
    inv_kappa = np.divide(smin, smax, out=np.zeros(smin.shape), where=smax > 0)
    return KinematicIndices(smin, kappa, np.prod(sv, axis=-1), inv_kappa)


# -- standardisation (000 eqs. 8-9) -----------------------------------------------------------


@dataclass(frozen=True)
class Normalization:
    """Min-max bounds of 000 eq. (8), frozen from a sample set.

    Attributes
    ----------
    sigma_min_range
        ``(a, b)``: min and max of ``s`` over the sample set.
    manipulability_range
        ``(a, b)``: min and max of ``w`` over the sample set.
    """

    sigma_min_range: tuple[float, float]
    manipulability_range: tuple[float, float]

    @classmethod
    def from_samples(cls, indices: KinematicIndices) -> Normalization:
        """Bounds over every sample of ``indices`` (any shape, at least one sample)."""
        s = np.asarray(indices.sigma_min).ravel()
        w = np.asarray(indices.manipulability).ravel()
        if s.size == 0:
            raise ConfigurationError("the sample set for min-max standardisation is empty")
        return cls((float(s.min()), float(s.max())), (float(w.min()), float(w.max())))


@dataclass(frozen=True)
class StandardizedIndices:
    """Standardised indices (000 eqs. 8-9), each (...), bigger is better.

    Attributes
    ----------
    s_hat
        ``(s - a) / (b - a)``: in ``[0, 1]`` over the sample set that fixed the bounds.
    kappa_hat
        ``1 / kappa`` in ``[0, 1]`` (eq. 9; not min-max standardised, as 000 writes it).
    w_hat
        ``(w - a) / (b - a)``.
    """

    s_hat: FloatArray
    kappa_hat: FloatArray
    w_hat: FloatArray

    def stacked(self) -> FloatArray:
        """(..., 3) in canonical order ``(s_hat, kappa_hat, w_hat)``."""
        return np.stack([self.s_hat, self.kappa_hat, self.w_hat], axis=-1)


def _minmax(x: FloatArray, bounds: tuple[float, float]) -> FloatArray:
    a, b = bounds
    span = b - a
    if span <= 0:  # constant over the sample set: carries no information
        return np.zeros(np.shape(x))
    return (x - a) / span


def standardize(indices: KinematicIndices, normalization: Normalization | None = None) -> StandardizedIndices:
    """Standardise the indices as 000 eqs. (8)-(9) write them.

    Parameters
    ----------
    indices
        Indices of shape (...).
    normalization
        Min-max bounds; ``None`` takes them from ``indices`` itself (the sample set).  Values
        outside the frozen bounds map outside ``[0, 1]`` (used by the refinement).
    """
    norm = Normalization.from_samples(indices) if normalization is None else normalization
    return StandardizedIndices(
        _minmax(np.asarray(indices.sigma_min), norm.sigma_min_range),
        np.asarray(indices.inverse_condition),
        _minmax(np.asarray(indices.manipulability), norm.manipulability_range),
    )



# -- indices of an arm over configurations ----------------------------------------------------

JacobianKind = Literal["generalized", "fixed"]

#: Configurations evaluated per batched call (keeps the temporaries in cache; ~4 MB each).
DEFAULT_BATCH = 4096


def configuration_indices(
    model: ArmModel,
    q: ArrayLike,
    *,
    jacobian: JacobianKind = "generalized",
    characteristic_length: float | None = None,
    method: Literal["jacobi", "svd", "gram"] | None = None,
    batch_size: int = DEFAULT_BATCH,
    progress: Progress | None = None,
) -> KinematicIndices:
    """Kinematic-ability indices of an arm at a batch of configurations.

    Parameters
    ----------
    model
        The arm (for 000: the locked model, so the locked joint's column is already gone).
    q
        (..., n) angles of the model's movable joints [rad].
    jacobian
        ``"generalized"``: the free-floating generalized Jacobian ``J_F`` with zero momentum
        (000 eq. 5, what 000 §3.1.2 analyses); for a fixed-base model it *is* the fixed-base
        Jacobian (infinite base mass).  ``"fixed"``: the geometric Jacobian with the base held.
        Both: end-effector origin, root-frame components, twist order ``(v, omega)``.
    characteristic_length
        See :func:`kinematic_indices`.
    method
        ``None`` (default): ``"jacobi"`` for batches of
        :data:`jointlock.forward.COMPILED_MIN_BATCH` configurations or more, else ``"svd"``
        (the same values to round-off; small batches do not pay numba's start-up).
        ``"jacobi"``: compiled; one kernel builds each block's Jacobian
        (:func:`jointlock._kernels.fixed_singular_values`, or
        :func:`jointlock._kernels.generalized_singular_values` for the generalized Jacobian
        of a floating model) and its singular values by one-sided Jacobi, within
        ~1e-15 * sigma_max of LAPACK's.  ``"svd"``, ``"gram"``: see
        :func:`kinematic_indices` (``"svd"`` is LAPACK's, the reference of ``"jacobi"``).
    batch_size
        Configurations per batched call (memory/cache only; results do not depend on it).
    progress
        Optional :class:`~jointlock.progress.Progress`, advanced by the number of
        configurations done.

    Returns
    -------
    KinematicIndices
        Arrays of shape (...).
    """
    from ...kinematics import generalized_jacobian
    from ...kinematics import jacobian as fixed_jacobian
    from ...model import as_joint_array

    if jacobian not in ("generalized", "fixed"):
        raise ConfigurationError(f"jacobian must be 'generalized' or 'fixed'; got {jacobian!r}")
    if int(batch_size) < 1:
        raise ConfigurationError(f"batch_size must be >= 1; got {batch_size!r}")
    arr = as_joint_array(model, q)
    batch = arr.shape[:-1]
    flat = kernel_input(arr.reshape(-1, model.dof))
    if method is None:
        from ...forward import COMPILED_MIN_BATCH

        method = "jacobi" if use_compiled(flat.shape[0], COMPILED_MIN_BATCH) else "svd"
    fused = method == "jacobi"
    if fused:  # the compiled kernel builds each block's Jacobian and its singular values at once
        from ... import _kernels  # numba is imported on first use, not with the package

        program = kernel_program(model)[:3]
        floating = jacobian == "generalized" and model.floating
        masses = kernel_mass_program(model) if floating else None
        length = 1.0 if characteristic_length is None else float(characteristic_length)
        if not (math.isfinite(length) and length > 0):
            raise ConfigurationError(f"characteristic_length must be a finite length > 0 [m]; got {length}")
    # outputs allocated once, filled chunk by chunk: memory is the result's plus one chunk's
    out = [np.empty(flat.shape[0]) for _ in INDEX_NAMES + ("inverse_condition",)]
    step = int(batch_size)
    for start in range(0, flat.shape[0], step):  # chunks of the batch, not single samples
        chunk = flat[start : start + step]
        if fused:
            sv = np.empty((chunk.shape[0], min(6, model.dof)))
            if masses is None:
                _kernels.fixed_singular_values(chunk, *program, length, sv)
            else:
                _kernels.generalized_singular_values(chunk, *program, *masses, length, sv)
            part = _from_singular_values(sv)
        else:
            jac = (generalized_jacobian if jacobian == "generalized" else fixed_jacobian)(model, chunk)
            part = kinematic_indices(jac, characteristic_length=characteristic_length, method=method)
        for dst, src in zip(out, (part.sigma_min, part.condition_number, part.manipulability, part.inverse_condition)):
            dst[start : start + chunk.shape[0]] = src
        if progress is not None:
            progress.update(chunk.shape[0])
    return KinematicIndices(*(x.reshape(batch) for x in out))
