"""Seed 001 (velocity-jump compensation through an unexpected lock): no printed number
survived.

001's equations, its arm's table and its results were lost; the method implemented is the
reconstruction in ``docs/reconstruction-001.md`` (docs/jump.md), on ``canadarm7`` (004's arm, the
SSRMS-type structure of 001).  What is left to type once is NOTES-001's task, the study
``jointlock reproduce`` runs and reports as "ours only".
"""

from __future__ import annotations

from types import MappingProxyType
from typing import Any

#: 001's printed results: none survived (``jointlock reproduce`` prints "(lost)").
PRINTED: MappingProxyType[str, Any] = MappingProxyType({})

#: NOTES-001's task on canadarm7, in task-file units (docs/jump.md, "Task files"): start
#: configuration [deg], straight-line displacement of the end effector [m], task time, blend
#: time of the trapezoid and control step [s], the joint that locks, joint speed [deg/s] and
#: acceleration [deg/s^2] limits, position-deviation threshold [m] and feedback gain [1/s].
TASK: MappingProxyType[str, Any] = MappingProxyType(
    {
        "q0_deg": (10.0, 40.0, -70.0, 100.0, -60.0, 30.0, 20.0),
        "dx_m": (1.2, -1.5, 0.8),
        "duration_s": 12.0,
        "blend_s": 2.0,
        "dt_s": 0.05,
        "lock_joint": 2,
        "vmax_deg_s": 10.0,
        "amax_deg_s2": 5.0,
        "eps_m": 1e-3,
        "kp": 2.0,
    }
)
