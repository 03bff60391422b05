"""Seed 004 (singularity analysis of a Canadarm2-type 7-DOF space arm): the numbers it prints.

Virtual link lengths in m, angles in degrees, as printed (transcriptions in
docs/readings/canadarm7-004.md).  The arm (§5's lengths and masses, frames inferred from
eq. (15)) is :func:`jointlock.robots.canadarm7`; Cond1-Cond5 (eq. 30) are
:data:`jointlock.analysis.singularity.CONDITIONS`.
"""

from __future__ import annotations

from types import MappingProxyType

#: 004 §5 (and its Table 2): the virtual link lengths â, ĉ, d̂, ê, f̂, ĥ, k̂ of canadarm7 [m],
#: from its formula (S_i / M) L_i, printed to :data:`VIRTUAL_LENGTH_DECIMALS` decimals.
VIRTUAL_LENGTHS: MappingProxyType[str, float] = MappingProxyType(
    {"a": 0.38, "c": 0.39, "d": 2.15, "e": 2.33, "f": 0.48, "h": 0.49, "k": 0.5}
)

#: Decimals 004 prints the virtual lengths with.
VIRTUAL_LENGTH_DECIMALS = 2

#: 004 eq. (30): the singularity conditions as printed, ``Si = sin(theta_i)``, ``Cij =
#: cos(theta_i + theta_j)`` and so on, with the virtual lengths (hatted in 004); ``cond1f`` is
#: ours (Cond1 with the equation 004 leaves out, ``F`` of
#: :func:`jointlock.analysis.singularity.cond1_extra`).  The equations the code solves are
#: :func:`jointlock.analysis.singularity.condition_equations`.
CONDITION_TEXT: MappingProxyType[str, str] = MappingProxyType(
    {
        "cond1": "S4 = 0",
        "cond2": "S2 = 0 and S6 = 0",
        "cond3": "S2 = 0 and d C3 + e C34 + h S345 = 0",
        "cond4": "S6 = 0 and e C5 + d C45 - a S345 = 0",
        "cond5": "d C3 + e C34 + h S345 = 0 and a + h C345 - d S3 - e S34 = 0",
        "cond1f": "S4 = 0 and F = 0 (ours: the factor 004 leaves out)",
    }
)

#: 004 Table 3: one configuration per singularity condition, joint angles 1-7 [deg] as printed
#: (the angles of Cond3-Cond5 solve a length equation and are printed rounded to 0.1 deg).
TABLE3_DEG: MappingProxyType[str, tuple[float, ...]] = MappingProxyType(
    {
        "cond1": (25, 0, 90, 0, 45, 90, 0),
        "cond2": (25, 0, 34, 30, 45, 0, 0),
        "cond3": (25, 0, 20, 140, -139.1, 45, 0),
        "cond4": (25, 10, -132.9, 140, 20, 0, 0),
        "cond5": (25, 10, 24, 180, -44.9, 45, 0),
    }
)

#: 004 Table 3: det(Ĵm Ĵmᵀ) at each configuration, as printed.
TABLE3_DET: MappingProxyType[str, float] = MappingProxyType(
    {
        "cond1": -1.06608e-14,
        "cond2": -6.80933e-14,
        "cond3": 2.43766e-30,
        "cond4": 2.97193e-12,
        "cond5": -1.60952e-16,
    }
)
