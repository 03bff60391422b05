"""Seed 002 (fault tolerance of a 6-DOF PUMA-like arm with one locked joint): its worked
examples and the numbers it prints.

Angles in degrees, tip positions in mm, Euler angles ZYX ``[yaw, pitch, roll]`` in rad, as
printed.  002 prints 2-decimal vectors truncated toward zero and 4-decimal ones rounded
(docs/readings/puma6-002.md, which quotes every number below with its place).  The arm
(Table 1, with a2, d4, d6 recovered from these examples) is :func:`jointlock.robots.puma6`.

Two examples run through the paper, both with joint 2 failing:

- *example A* (§"The analysis of fault tolerance under a single joint failure", Figs. 5-8):
  the motion ``A_Q0_DEG -> A_QF_DEG``, joint 2 locked at 59.4 deg, tolerance angle -1.45 deg;
- *example B* (§"The straight trajectory planning ... (fault-tolerant attitude error <=
  10 deg)", eqs. (21)-(22)): joint 2 locked at 52.0547 deg, tolerance angle -10 deg.
"""

from __future__ import annotations

from types import MappingProxyType
from typing import NamedTuple


class WorkedExample(NamedTuple):
    """One printed forward-kinematics example: joint angles [deg], the tip position [mm] and
    ZYX Euler angles [rad] 002 prints for them, and how many decimals it prints."""

    q_deg: tuple[float, ...]
    position_mm: tuple[float, ...]
    euler_zyx: tuple[float, ...]
    decimals: int


#: 002's worked examples, by label: E1 / E2 the initial / terminal configuration of
#: §"The straight trajectory planning ... (without fault-tolerant attitude error)" (§6.1,
#: 2 decimals, truncated); E3 / E4 those of §"... (fault-tolerant attitude error <= 10 deg)"
#: (4 decimals, rounded); E5 eq. (22)'s joints with eq. (21)'s position and the Euler angles
#: printed after eq. (22).
EXAMPLES: MappingProxyType[str, WorkedExample] = MappingProxyType(
    {
        "E1": WorkedExample((0, 60, 30, 10, -80, 30), (-206.16, -65.32, -482.55), (0.54, 0.06, 0.23), 2),
        "E2": WorkedExample((5, 60, 65, 10, -120, 90), (-98.33, -66.26, -37.81), (1.55, -0.14, 0.09), 2),
        "E3": WorkedExample(
            (0, 30, 30, 10, -80, 30), (62.7315, -65.3258, -520.9870), (0.5931, -0.3826, -0.0452), 4
        ),
        "E4": WorkedExample(
            (5, 60, 65, 10, -120, 90), (-98.3390, -66.2696, -37.8197), (1.5573, -0.1427, 0.0945), 4
        ),
        "E5": WorkedExample(
            (10.5789, 52.0547, 66.1915, 8.5610, -124.0978, 82.7611),
            (-98.3390, -66.2696, -37.8197),
            (1.5573, -0.1427, -0.0801),
            4,
        ),
    }
)

#: The joint that fails in both examples (1-based).
LOCKED_JOINT = 2

# -- example A (Figs. 5-8) ----------------------------------------------------------------------

#: Example A's initial and terminal ("desired") configurations, "q0 = [0, 60, 0, 0, 0, 0]°"
#: and "qf = [5, 60, 35, 10, -120, 90]°" [deg].
A_Q0_DEG: tuple[float, ...] = (0, 60, 0, 0, 0, 0)
A_QF_DEG: tuple[float, ...] = (5, 60, 35, 10, -120, 90)

#: "fault compensation range of joint 2 is 48° to 123°" with the tolerance angle gamma in
#: [-180°, 180°] (ends read off Fig. 5) [deg]: (gamma bound, (lowest, highest lock angle)).
A_WIDE_GAMMA_DEG = 180.0
A_WIDE_RANGE_DEG: tuple[float, float] = (48.0, 123.0)

#: "59.2° to 60.8°" with gamma in [-2°, 2°] (Fig. 6) [deg].
A_NARROW_GAMMA_DEG = 2.0
A_NARROW_RANGE_DEG: tuple[float, float] = (59.2, 60.8)

#: "a failure occurs in the second joint ... when its angle is 59.4° and we can get
#: γ = −1.45": the lock angle and the printed tolerance angle [deg].
A_LOCK_DEG = 59.4
A_GAMMA_DEG = -1.45

#: "... qf = [5.18, 59.40, 35.51, 9.89, −121.40, 89.76]°": the re-planned terminal
#: configuration at gamma = -1.45 deg (2 decimals, truncated) [deg].
A_Q_AT_GAMMA_DEG: tuple[float, ...] = (5.18, 59.40, 35.51, 9.89, -121.40, 89.76)

# -- example B (eqs. 21-22) ----------------------------------------------------------------------

#: Example B's initial and terminal configurations before the failure (= E3's and E4's
#: joints) [deg].
B_Q0_DEG: tuple[float, ...] = EXAMPLES["E3"].q_deg
B_QF_DEG: tuple[float, ...] = EXAMPLES["E4"].q_deg

#: "the posture tolerance that the end-effector rotates around the X-axis is −10°" [deg].
B_GAMMA_DEG = -10.0

#: Eq. (21): the target pose T06 (rotation [-], position [mm]), 4 decimals as printed.
EQ21_POSE: tuple[tuple[float, ...], ...] = (
    (0.0134, -0.9966, -0.0819, -98.3390),
    (0.9897, 0.0249, -0.1407, -66.2696),
    (0.1422, -0.0792, 0.9867, -37.8197),
    (0.0, 0.0, 0.0, 1.0),
)

#: Eq. (22): the re-planned joint angles "qq" for eq. (21) with joint 2 locked [deg].
EQ22_DEG: tuple[float, ...] = EXAMPLES["E5"].q_deg

#: "When the joint fails at 52.0547°": joint 2's lock angle of example B (eq. (22)'s theta2) [deg].
B_LOCK_DEG: float = EQ22_DEG[1]
