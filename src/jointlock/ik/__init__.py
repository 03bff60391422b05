"""Inverse kinematics: closed form for the ``puma6`` family (seed 002), the UR family
(three parallel axes, :mod:`jointlock.ik._ur`) and the spherical-wrist family (Pieper's
condition with parallel shoulder-elbow axes: PUMA with offsets, KUKA KR, ABB IRB, Staeubli;
:mod:`jointlock.ik._spherical`), numerical otherwise.

Closed form (:func:`ik_closed_form`)
------------------------------------
The ``puma6`` family is every arm whose kinematics equal 002 Table 1 read as standard DH
(``alpha = [-90, 0, 90, -90, 90, 0] deg``, ``a = [0, a2, 0, 0, 0, 0]``,
``d = [0, 0, 0, d4, 0, d6]``, no base transform) followed by any tool transform.  Membership
is decided numerically by :func:`puma6_geometry` (a least-squares fit of ``a2, d4, d6`` and
the tool against the model's own forward kinematics), never by the model's name.

With ``n, o, a, p`` the columns of the target ``T_0_6`` and the wrist centre
``p_w = p - d6 a`` (002 eq. 1 keeps ``A6^-1`` on the left side):

* ``theta1`` from 002 eq. (2): ``-s1 p_wx + c1 p_wy = 0``, the two branches of eqs. (3)/(4)
  (printed in swapped order in eq. (16); both are returned).
* ``U = c1 p_wx + s1 p_wy``, ``V = -p_wz``; 002 eq. (5) reads
  ``d4 s3 = U c2 + V s2 - a2`` and ``d4 c3 = U s2 - V c2``.
* ``theta2 = atan2(W, +-sqrt(1 - W^2)) - atan2(U, V)`` with
  ``W = (U^2 + V^2 + a2^2 - d4^2) / (2 a2 sqrt(U^2 + V^2))`` (002 eq. 16, correct as printed).
* ``theta3`` from eq. (5) -- **corrected**, see below.
* The wrist: ``M = R_0_3^T R_0_6 = Rz(theta4) Ry(theta5) Rz(theta6)`` (ZYZ).  ``theta5 =
  atan2(+-sqrt(1 - h^2), h)`` with ``h = M[2, 2]`` is eq. (8) (its ``h`` is the printed one);
  ``theta4 = atan2(M[1, 2] / s5, M[0, 2] / s5)`` is eq. (11); ``theta6`` is eqs. (13)-(15),
  computed here as the remaining ``Rz`` of ``Ry(-theta5) Rz(-theta4) M`` so that it stays
  exact at the wrist singularity ``s5 = 0``.

Printed 002 equations corrected here (judged by round trips ``FK(IK(T)) = T``, not by the
printed formulas; see ``docs/replan.md``):

1. **theta3, eqs. (6) and (16)** print ``atan2(U c2 + V s2 - a2, U s2 - V c2)``.  That drops
   the factor ``1/d4`` of eq. (5) and is right only for ``d4 > 0``; 002's own numbers force
   ``d4 = -0.765 m`` (with Table 1's ``alpha3 = +90 deg``), where the printed form returns
   ``theta3 + 180 deg`` (e.g. -113.8085 deg instead of eq. (22)'s 66.1915 deg).  Used:
   ``atan2((U c2 + V s2 - a2) / d4, (U s2 - V c2) / d4)``.
2. **theta4, eq. (17)** prints ``atan2(-ax s1 + ay c1, ...)`` without the ``1/s5`` that
   eq. (11) has in the first argument; the quadrant is wrong whenever ``s5 < 0`` (every
   002 example has ``theta5 ~ -120 deg``).  Used: eq. (11).
3. **Eq. (18)** (in :mod:`jointlock.planning.replan`) prints the (1, 1) element of the tool
   rotation as 0; it is 1.

With both fixes every one of the 8 branches round-trips (tests: thousands of seeded random
poses); with either printed form none does.

Locked joints (closed form, 002 §"Analytical inverse kinematics of a 5-DOF manipulator")
-----------------------------------------------------------------------------------------
The locked angle is substituted and a subset of five equations is solved; the pose error of
each branch (from the model's own forward kinematics) tells whether the target is reachable:

* joint 1: ``theta1`` given; ``theta2`` (2 branches) and ``theta3`` as above; wrist 2 branches.
  Eq. (2) is not enforced: its residual (the wrist centre off the arm's plane) is the error.
* joint 2 (002's case): ``theta1`` two branches from eq. (2), ``theta3`` from corrected eq.
  (5)/(6) with the locked ``theta2``; wrist 2 branches.
* joint 3 (derived): eq. (5) says ``[U, V] = Rz(theta2) [a2 + d4 s3, -d4 c3]``, so
  ``theta2 = atan2(V, U) - atan2(-d4 c3, a2 + d4 s3)``; ``theta1`` 2 branches; wrist 2.
* joints 4, 5, 6 (derived): the wrist centre fixes ``theta1..3`` (4 branches); the wrist
  ``Rz(theta4) Ry(theta5) Rz(theta6) = M`` with one angle known gives the other two:
  ``theta5 = atan2(M'[0,2], M'[2,2])``, ``theta6 = atan2(M'[1,0], M'[1,1])`` with
  ``M' = Rz(-theta4) M`` (joint 4); ``theta4 = atan2(sign(s5) M[1,2], sign(s5) M[0,2])``
  (joint 5); ``theta4 = atan2(-M''[0,1], M''[1,1])``, ``theta5 = atan2(-M''[2,0], M''[2,2])``
  with ``M'' = M Rz(-theta6)`` (joint 6).

Each is exact whenever the target is reachable by the locked arm (four branches, of which
the exact ones are flagged).

Numerical fallback (:func:`ik_numeric`)
---------------------------------------
Levenberg-Marquardt (damped least squares with Marquardt's diagonal scaling) on any
:class:`~jointlock.model.ArmModel`, locked or not, from several starts at once (batched over
targets and starts), optionally with the rotation ``gamma`` about the tool x axis as a free
task variable (002 §"Fault-tolerant planning based on the inverse solution of 6-DOF
manipulator"): the target becomes ``T Rx(gamma)``.  The residual is
``(p_t - p, L * log(R_t R^T))`` with a characteristic length ``L`` [m]; when no exact
solution exists it converges to the *nearest reachable pose* in that metric.

Everything here is in SI units and radians; 002's ZYX Euler angles are converted by
:func:`pose_from_zyx` / :func:`zyx_angles`.

Modules (private; every name, private ones included, is re-exported here): ``_pose`` (002's
ZYX Euler angles, angle wrapping, target checks and the tolerances that call a pose exact),
``_puma6`` (the closed form of the family, full arm and every lock, and the dispatch between
the closed forms), ``_ur`` and ``_spherical`` (the other two families), ``_numeric``
(Levenberg-Marquardt, batched) and ``_solve`` (:func:`solve_ik`: every solution of one
target, dispatching between the two).
"""

from __future__ import annotations

# Private names (marked F401) are re-exported too: code written before the split imports them
# from here (e.g. jointlock.planning.replan uses _as_poses).
from ._numeric import NumericIK, _residual, _select_state, ik_numeric  # noqa: F401
from ._pose import (  # noqa: F401
    EXACT_POSITION_TOL,
    EXACT_ROTATION_TOL,
    _as_poses,
    pose_from_zyx,
    wrap_angle,
    zyx_angles,
)
from ._puma6 import (  # noqa: F401
    FAMILY_FIT_TOL,
    PUMA6_ALPHA,
    IKBranches,
    Puma6Geometry,
    _dh_chain,
    _position_branches,
    _rot03,
    _wrist_branches,
    closed_form_family,
    ik_closed_form,
    puma6_branches,
    puma6_fk,
    puma6_geometry,
)
from ._solve import DUPLICATE_TOL, IKResult, IKSolution, _distinct, solve_ik  # noqa: F401
from ._spherical import (
    SPHERICAL_FIT_TOL,
    SphericalWristGeometry,
    spherical_wrist_branches,
    spherical_wrist_geometry,
)
from ._ur import URGeometry, ur_branches, ur_fk, ur_geometry

__all__ = [
    "DUPLICATE_TOL",
    "EXACT_POSITION_TOL",
    "EXACT_ROTATION_TOL",
    "FAMILY_FIT_TOL",
    "PUMA6_ALPHA",
    "IKBranches",
    "IKResult",
    "IKSolution",
    "NumericIK",
    "Puma6Geometry",
    "SPHERICAL_FIT_TOL",
    "SphericalWristGeometry",
    "URGeometry",
    "closed_form_family",
    "ik_closed_form",
    "ik_numeric",
    "pose_from_zyx",
    "puma6_branches",
    "puma6_fk",
    "puma6_geometry",
    "solve_ik",
    "spherical_wrist_branches",
    "spherical_wrist_geometry",
    "ur_branches",
    "ur_fk",
    "ur_geometry",
    "wrap_angle",
    "zyx_angles",
]
