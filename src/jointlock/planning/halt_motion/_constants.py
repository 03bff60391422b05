"""Constants and type aliases of the halt motion (000 §4), shared by its modules."""

from __future__ import annotations

import math
from typing import Literal

#: Factor from the unit of ``k`` to rad/s^6: 000's reading is deg/s^6.
K_UNIT_SCALE: dict[str, float] = {"deg/s^6": math.pi / 180.0, "rad/s^6": 1.0}
#: Slack on every limit when checking feasibility (relative to the limit) [-]: round-off only.
LIMIT_RTOL = 1e-9
#: Samples below which Simpson's rule on the halt is refused.
MIN_SAMPLES = 11
#: Largest number of (candidate, time) samples passed to one :func:`rnea` call.
CHUNK_SAMPLES = 60_000
#: Floor of the global torque in the GA's fitness ``1 / tau_bar`` (eq. 35) [N m]: a halt
#: without base torque scores ``1e300``, finite, and a population's sum stays finite too.
TORQUE_FLOOR = 1e-300

Solver = Literal["scan", "ga", "vector"]
LimitKind = Literal["angle", "velocity", "acceleration", "torque", "brake"]
