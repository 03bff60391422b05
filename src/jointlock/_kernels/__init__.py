"""Compiled batch kernels (numba): chain forward kinematics, the fixed-base geometric Jacobian,
the free-floating generalized Jacobian, singular values by one-sided Jacobi (alone, or fused
with either Jacobian), end-effector positions, and the Newton-Euler joint torques and base
wrench, fixed base and free-floating (:mod:`jointlock._kernels._dynamics`).

The numpy implementations (:mod:`jointlock.forward`, :mod:`jointlock.kinematics`,
:func:`jointlock.dynamics.rnea`, ``np.linalg.svd``) are the reference these kernels are tested
against (``tests/test_kernels.py``, ``tests/test_kernels_dynamics.py``); the public functions
call the kernels.  Their inputs reach them as C-contiguous, writable float64 arrays (copied
where they are not), so that numba compiles one specialisation per kernel.

Layout.  Configurations are processed in blocks of :data:`BLOCK` with the block as the
innermost (contiguous) axis of every work array ("structure of arrays"), so that each step
is a plain loop over the block, which LLVM turns into SIMD code (8 lanes with AVX-512) when
it can prove the loop's arrays do not overlap.  It checks that at run time, and gives up when
a loop touches more than a few separately addressed rows ("too many memory checks"): rows of
a 2-D work array count separately, since its row stride is a run-time value.  So a loop
should touch few arrays, each at constant offsets: the Newton-Euler kernels keep a block's
work in one flat vector plus one per link (:mod:`jointlock._kernels._dynamics`).  Nothing here
calls LAPACK or allocates per configuration.

Chain convention (the one of :func:`jointlock._chain.link_constants` and
:func:`jointlock._chain.position_program`): every link in its ``z``-joint frame; link ``i``
has the constant turn ``E_i`` (3, 3) and offset ``p_i`` (3,) from its parent, then turns by
``Rot(z, q_i)``; the tool point ``t`` (3,) is given in the last link's frame.  Locked
joints are already folded into the constants.

Generalized Jacobian.  From the composite masses of the links outboard of each joint and the
system's inertia about its centre of mass (a 3 x 3 solve per configuration instead of the
6 x 6 one of :func:`jointlock.kinematics.base_jacobian`): see
:func:`jointlock._kernels._arm._generalized_block`.

Numba is imported with this package, and only the public functions that take these
kernels import it (lazily), from :data:`jointlock.forward.COMPILED_MIN_BATCH` configurations
on: loading numba and the cached kernels costs a process 0.4-0.7 s on an idle core (about 2 s
on a busy one), the first compilation on a machine 5-25 s (cached afterwards, ``cache=True``;
numba checks only the calling kernel's own file, so after editing a module whose kernels
others call -- ``_dynamics``, ``_arm``, ``_common`` -- clear ``__pycache__`` here;
README, "Speed").

Sines and cosines.  libm's scalar ``sin``/``cos`` cost ~25 ns each and block SIMD, so
:func:`_sincos` evaluates them branch-free: Cody-Waite reduction by ``pi/2`` in three parts
(musl's ``__rem_pio2`` constants; exact for ``|q| <`` :data:`TRIG_LIMIT`) and musl's
``__sin``/``__cos`` minimax polynomials on ``[-pi/4, pi/4]`` (error below 1 ulp).  Angles
beyond :data:`TRIG_LIMIT` (never joint angles in practice) take ``math.sin``/``math.cos``.

Singular values.  :func:`_jacobi_block` is the one-sided (Hestenes) Jacobi method:
columns of ``A`` are rotated pairwise, cyclically, until every pair is orthogonal to
``m * eps`` relative (the stopping rule of LAPACK's ``dgesvj``); the singular values are
then the column norms.  It computes every singular value to high relative accuracy
(Demmel & Veselic, "Jacobi's method is more accurate than QR", SIAM J. Matrix Anal. Appl.
13 (1992) 1204-1245), so in particular to ``~1e-15 * sigma_max`` absolute, as LAPACK's SVD.
"""

from ._ability import combined_index
from ._arm import (
    ee_positions,
    fixed_singular_values,
    generalized_jacobian,
    generalized_singular_values,
    jacobian,
)
from ._common import BLOCK, MAX_SWEEPS, TRIG_LIMIT, sincos
from ._dynamics import rnea_fixed, rnea_floating
from ._halt import base_moment_norms, k_intervals, least_violation_scan, screen_k_bounds
from ._jump import fixed_frame, integrate_steps, rate_law
from ._svd import singular_values

__all__ = [
    "BLOCK",
    "MAX_SWEEPS",
    "TRIG_LIMIT",
    "base_moment_norms",
    "combined_index",
    "ee_positions",
    "fixed_frame",
    "fixed_singular_values",
    "generalized_jacobian",
    "generalized_singular_values",
    "integrate_steps",
    "jacobian",
    "k_intervals",
    "least_violation_scan",
    "rate_law",
    "rnea_fixed",
    "rnea_floating",
    "screen_k_bounds",
    "sincos",
    "singular_values",
]
