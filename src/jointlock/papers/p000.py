"""Seed 000 (halt strategy of a 7-DOF space arm with a locked joint): §5's scenario and the
numbers it prints.

Angles in degrees, as printed; ``SCENARIO`` is the failure of §5.1–5.2 on ``halt7`` (joint 4
locked at 0, healthy joints 1, 2, 3, 5, 6, 7).  The printed results were not reproduced under
any reading we tried (docs/halt-motion.md, docs/halt-config.md): they are compared with, never
tuned to.  000's arm (Tables 6-7) is :func:`jointlock.robots.halt7`.
"""

from __future__ import annotations

from types import MappingProxyType
from typing import Any

#: 000 §5.1's printed optimal halt configuration q_best, healthy joints 1, 2, 3, 5, 6, 7 [deg].
Q_BEST_DEG: tuple[float, ...] = (-167.0, -90.0, 40.0, -158.0, 90.0, -62.0)

#: 000 §5.1's printed sub-optimal configuration q_sub it compares q_best with, same joints [deg].
Q_SUB_DEG: tuple[float, ...] = (-52.0, 90.0, 84.0, 148.0, -90.0, 157.0)

#: 000 §5.1: the number K of Monte Carlo samples of the halt-configuration search.
SAMPLES = 36000

#: 000 §5.1: the comprehensive performance index CP at q_sub [-].
CP_Q_SUB = 0.2969

#: 000 §5.1: q_best's CP is "236.8 %" above q_sub's, (CP(q_best) - CP(q_sub)) / CP(q_sub) [-]
#: (its arithmetic (1 - 0.2969) / 0.2969 takes CP(q_best) = 1).
CP_GAIN = 2.368

#: 000 eq. (39): the AHP judgment matrix of §5.1 [-].  Rows/columns are (s, w, kappa) in the
#: order of the text (eq. 12, §5.1), (s, kappa, w) in that of eq. (19).
JUDGMENT: tuple[tuple[float, ...], ...] = ((1.0, 0.5, 1.0), (2.0, 1.0, 2.0), (1.0, 0.5, 1.0))

#: 000 §5.1: the AHP weights of eq. (39), "1/4, 1/2 and 1/4" [-] (eigenvalue 3, CR = 0).
AHP_WEIGHTS: tuple[float, ...] = (0.25, 0.5, 0.25)

#: 000 Table 5: the random consistency index RI by matrix order N [-].
RANDOM_INDEX: MappingProxyType[int, float] = MappingProxyType(
    {1: 0.0, 2: 0.0, 3: 0.52, 4: 0.89, 5: 1.12, 6: 1.24}
)

#: 000 §3.1.3 step 3: the consistency ratio CR must stay below 0.10 [-].
CR_LIMIT = 0.10

#: 000 §5.1–5.2 on halt7: locked joint {number: angle [deg]}, state at failure of the healthy
#: joints [deg, deg/s, deg/s^2], halt time T [s], limits [deg/s, deg/s^2] (40 deg/s = halt7's
#: own velocity_limit) and 000's printed halt configuration q_best [deg] (:data:`Q_BEST_DEG`).
SCENARIO: MappingProxyType[str, Any] = MappingProxyType(
    {
        "lock": MappingProxyType({4: 0.0}),
        "q0_deg": (-180.0, -180.0, -100.0, -10.0, 20.0, 20.0),
        "dq0_deg": (20.0, 30.0, 15.0, 25.0, 40.0, 35.0),
        "ddq0_deg": (8.0, 10.0, 12.0, 10.0, -8.0, 6.0),
        "T": 10.0,
        "vmax_deg": 40.0,
        "amax_deg": 20.0,
        "qf_deg": Q_BEST_DEG,
    }
)

#: 000 §5.2's printed halt-motion results: k [deg/s^6], global base torque at k = 0 and at k*
#: [N m], and the relative reduction.
HALT_RESULTS: MappingProxyType[str, float] = MappingProxyType(
    {"k": 0.0018, "global_torque_k0_Nm": 22.25, "global_torque_Nm": 15.55, "reduction": 0.301}
)

#: 000's limits (§5.2), the fallback where neither the user nor the model gives one
#: [deg/s, deg/s^2].
VELOCITY_LIMIT_DEG_S = SCENARIO["vmax_deg"]
ACCELERATION_LIMIT_DEG_S2 = SCENARIO["amax_deg"]
