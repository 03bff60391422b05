"""Seed 004's structure-specific part for Canadarm2-structure arms (7 revolute joints, axes
3, 4, 5 parallel): link lengths, the Jacobian at 004's reference point (eq. 15) and its eq.-(24)
partition, the conditions Cond1-Cond5 (eq. 30, and our refined cond1f), their residuals and
004's analytic singular directions (eqs. 28 and 32)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike

from ..._deprecate import renamed_keyword
from ...errors import ConfigurationError, ModelError, ScenarioError
from ...kinematics import VMWeighting, chain_state, virtual_link_vectors, virtual_manipulator
from ...kinematics import jacobian as geometric_jacobian
from ...model import ArmModel, FloatArray

#: A condition holds when its residual (dimensionless, see :func:`condition_residuals`) is
#: below this.  Exact samples give ~ 1e-15; configurations found by the search lie within
#: ~ sigma_min / |grad sigma_min| ~ 1e-9 of the singular set.
CONDITION_TOL = 1e-6
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


@renamed_keyword(old="base", new="jacobian")
def arm_lengths(
    model: ArmModel, *, jacobian: Literal["fixed", "virtual"] = "virtual", weighting: VMWeighting = "segment"
) -> ArmLengths:
    """Lengths entering eq. (15): the norms of the virtual link vectors (``jacobian="virtual"``,
    004 Table 2 with ``weighting="segment"``: 0.38, 0.39, 2.15, 2.33, 0.48, 0.49, 0.5 m on
    ``canadarm7``) or of the real segments (``"fixed"``).  Formerly ``base=`` (a deprecated
    alias)."""
    _check_canadarm(model)
    if jacobian == "virtual":
        if not model.floating:
            raise ModelError(f"virtual lengths need a free-floating model; {model.name!r} has a fixed base")
        vec = virtual_link_vectors(model, weighting=weighting)
    elif jacobian != "fixed":
        raise ScenarioError(f"jacobian must be 'fixed' or 'virtual' for 004's conditions; got {jacobian!r}")
    real = ArmLengths(*(float(x) for x in np.linalg.norm(_real_segments(model), axis=1)))
    probe = np.radians(
        [[10.0, 20.0, 30.0, 40.0, 50.0, 60.0, 70.0], [-35.0, 75.0, -120.0, 150.0, 5.0, -95.0, 0.0]]
    )
    mismatch = float(
        np.abs(reference_jacobian(model, probe, jacobian="fixed") - eq15_jacobian(probe, real)).max()
    )
    if mismatch > _STRUCTURE_TOL:
        raise ModelError(
            f"{model.name!r} is not a Canadarm2-structure arm in 004's frames: its Jacobian at the eq.-(15) "
            f"reference point differs from eq. (15) by {mismatch:.3g} (allowed {_STRUCTURE_TOL:g}); see "
            "jointlock.robots.canadarm7 for the frames"
        )
    if jacobian == "fixed":
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
        return arm_lengths(lengths, jacobian="virtual" if lengths.floating else "fixed")
    return lengths


@renamed_keyword(old="base", new="jacobian")
def reference_jacobian(
    model: ArmModel,
    q: ArrayLike,
    *,
    jacobian: Literal["fixed", "virtual"] = "virtual",
    weighting: VMWeighting = "segment",
) -> FloatArray:
    """Our Jacobian in 004's reference frame and point (the numeric eq. 15).

    The twist ``(v, omega)`` of the point where axes 5 and 6 meet (origin of link frame 6,
    index 5; for ``jacobian="virtual"`` the virtual joint 6) with components in Sigma_ref =
    Sigma_4 (orientation of link frame 5, index 4): ``v_ref = v_e + omega x (p_ref - p_e)``,
    then both blocks rotated by ``R_ref^T`` (004 eqs. 16-20; the map has determinant 1, so the
    singularities are those of ``J^_m``).  ``jacobian``: formerly ``base=`` (a deprecated
    alias).

    Returns
    -------
    (..., 6, 7) rows (v_x, v_y, v_z [m/s], omega_x, omega_y, omega_z [rad/s]) in Sigma_ref.
    """
    _check_canadarm(model)
    state = chain_state(model, q)
    if jacobian == "virtual":
        vm = virtual_manipulator(model, q, weighting=weighting)
        jac, p_e, p_ref = vm.jacobian, vm.ee_position, vm.joint_positions[..., 5, :]
    elif jacobian == "fixed":
        jac = geometric_jacobian(model, q, state=state)
        p_e, p_ref = state.ee_position, state.positions[..., 5, :]
    else:
        raise ScenarioError(f"jacobian must be 'fixed' or 'virtual' for eq. (15); got {jacobian!r}")
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
