"""A planned motion of the arm (issue 28): the joint angles, rates and accelerations at any
instant, so that a failure can start from "the plan at t".

Two forms:

* **waypoints** (K, n) [rad] with a duration per segment (K - 1,) [s] and a standard time
  scaling from rest to rest at every waypoint: ``"quintic"`` (``s = 10 u^3 - 15 u^4 + 6 u^5``:
  zero rate and acceleration at both ends) or ``"trapezoidal"`` (constant acceleration over
  the first and the last :data:`TRAPEZOID_RAMP` of the segment, constant rate between);
* **samples** of a trajectory, times (m,) [s] and angles (m, n) [rad] (a CSV or NPZ file in
  degrees: :func:`load_task_file`), joined by a cubic spline (twice differentiable, not-a-knot
  ends: :class:`scipy.interpolate.CubicSpline`).

:meth:`Task.state` gives ``q``, ``dq``, ``ddq`` at any times in ``[0, duration]``
(``tests/test_task.py`` checks the rates and accelerations against finite differences).  001's
Cartesian task (a straight line followed by resolved rates) stays the jump study's own
(:class:`jointlock.planning.jump.JumpScenario`).
"""

from __future__ import annotations

import io
import math
import zipfile
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from ..bounds import MAX_OPTION_DEG, MAX_TIME_S, shown
from ..errors import ScenarioError
from ..io.files import read_input_bytes
from ..model import ArmModel, FloatArray

__all__ = ["TIME_SCALINGS", "TRAPEZOID_RAMP", "Task", "load_task_file"]

#: The time scalings of a waypoint task.
TIME_SCALINGS = ("quintic", "trapezoidal")
#: Share of a trapezoidal segment spent accelerating (and as much decelerating) [-].
TRAPEZOID_RAMP = 1.0 / 3.0


def _profile(u: FloatArray, scaling: str) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Normalised path s(u), s'(u), s''(u) on u in [0, 1] (s(0) = 0, s(1) = 1, rest at both ends
    for the rate)."""
    if scaling == "quintic":
        return (
            u**3 * (10.0 - 15.0 * u + 6.0 * u**2),
            30.0 * u**2 * (1.0 - u) ** 2,
            60.0 * u * (1.0 - u) * (1.0 - 2.0 * u),
        )
    a = TRAPEZOID_RAMP
    v = 1.0 / (1.0 - a)  # cruise rate: the area under the trapezoid is 1
    acc = v / a
    s = np.where(u < a, 0.5 * acc * u**2, np.where(u > 1.0 - a, 1.0 - 0.5 * acc * (1.0 - u) ** 2, 0.5 * acc * a**2 + v * (u - a)))
    ds = np.where(u < a, acc * u, np.where(u > 1.0 - a, acc * (1.0 - u), v))
    dds = np.where(u < a, acc, np.where(u > 1.0 - a, -acc, 0.0))
    return s, ds, dds


@dataclass(frozen=True, eq=False)  # arrays inside
class Task:
    """A planned joint motion (see the module docstring).

    Attributes
    ----------
    t
        (K,) knot times [s]: the waypoints' arrival times from 0, or the samples' own times (a
        file's times are kept: a failure at ``t = 6 s`` of a file starting at 5 s is 1 s in).
    q
        (K, n) joint angles at those times [rad], every joint of the arm.
    kind
        ``"waypoints"`` or ``"samples"``.
    scaling
        ``"quintic"`` or ``"trapezoidal"`` (waypoints), ``"spline"`` (samples).
    source
        Where it came from (a file name, "[task] waypoints_deg"), for messages.
    """

    t: FloatArray
    q: FloatArray
    kind: str = "waypoints"
    scaling: str = "quintic"
    source: str = "task"

    def __post_init__(self) -> None:
        t = np.asarray(self.t, dtype=float)
        q = np.asarray(self.q, dtype=float)
        where = self.source
        if t.ndim != 1 or t.size < 2:
            raise ScenarioError(f"{where}: a task needs 2 or more times; got {t.size}")
        if q.ndim != 2 or q.shape[0] != t.size or q.shape[1] < 1:
            raise ScenarioError(f"{where}: angles must be one row of joint angles per time; got shape {q.shape}")
        _check_rows(t, q, where, "row" if self.kind == "samples" else "waypoint")
        if self.kind not in ("waypoints", "samples"):
            raise ScenarioError(f"{where}: kind must be 'waypoints' or 'samples'; got {self.kind!r}")
        allowed = TIME_SCALINGS if self.kind == "waypoints" else ("spline",)
        if self.scaling not in allowed:
            raise ScenarioError(f"{where}: scaling must be one of {', '.join(map(repr, allowed))}; got {shown(self.scaling)}")
        for name, value in (("t", t), ("q", q)):
            value.setflags(write=False)
            object.__setattr__(self, name, value)
        if self.kind == "samples":
            from scipy.interpolate import CubicSpline

            object.__setattr__(self, "_spline", CubicSpline(t, q, axis=0))

    @classmethod
    def from_waypoints(
        cls, q_deg: ArrayLike, durations_s: ArrayLike, scaling: str = "quintic", *, source: str = "task"
    ) -> Task:
        """Waypoints (K, n) [deg] reached after ``durations_s`` (K - 1,) [s], rest at each."""
        q = _finite_rows(q_deg, source, "waypoints_deg", "waypoint")
        d = np.asarray(durations_s, dtype=float).ravel()
        if d.size != q.shape[0] - 1:
            raise ScenarioError(
                f"{source}: durations_s needs one duration per segment ({q.shape[0] - 1} for {q.shape[0]} waypoints); "
                f"got {d.size}"
            )
        for k, value in enumerate(d):
            if not (math.isfinite(value) and 0 < value <= MAX_TIME_S):
                raise ScenarioError(
                    f"{source}: durations_s entry {k + 1} (waypoint {k + 1} to {k + 2}) must be a duration in "
                    f"(0, {MAX_TIME_S:g}] s; got {value!r}"
                )
        return cls(np.concatenate([[0.0], np.cumsum(d)]), np.radians(q), "waypoints", scaling, source)

    @classmethod
    def from_samples(cls, t_s: ArrayLike, q_deg: ArrayLike, *, source: str = "task") -> Task:
        """Samples of a trajectory: times (m,) [s] and angles (m, n) [deg], joined by a spline."""
        q = _finite_rows(q_deg, source, "q_deg", "row")
        t = np.asarray(t_s, dtype=float).ravel()
        return cls(t, np.radians(q), "samples", "spline", source)

    @property
    def start(self) -> float:
        """First time of the task [s] (0 for waypoints)."""
        return float(self.t[0])

    @property
    def end(self) -> float:
        """Last time of the task [s]."""
        return float(self.t[-1])

    @property
    def duration(self) -> float:
        """Length of the task [s]."""
        return self.end - self.start

    @property
    def dof(self) -> int:
        """Joints per row."""
        return int(self.q.shape[1])

    def state(self, t: ArrayLike) -> tuple[FloatArray, FloatArray, FloatArray]:
        """``q`` [rad], ``dq`` [rad/s], ``ddq`` [rad/s^2] at times ``t`` [s] in ``[start, end]``,
        each of shape ``t.shape + (n,)``."""
        times = np.asarray(t, dtype=float)
        slack = 1e-12 * max(1.0, abs(self.end))
        inside = np.isfinite(times) & (times >= self.start - slack) & (times <= self.end + slack)
        if not np.all(inside):
            bad = times[~inside]
            raise ScenarioError(
                f"{self.source}: the task runs over [{self.start:g}, {self.end:g}] s; asked at t = "
                f"{shown([float(v) for v in bad.ravel()[:3]])} s"
            )
        flat = np.clip(times.ravel(), self.start, self.end)
        if self.kind == "samples":
            spline: Any = self._spline  # type: ignore[attr-defined]
            out = spline(flat), spline(flat, 1), spline(flat, 2)
        else:
            seg = np.clip(np.searchsorted(self.t, flat, side="right") - 1, 0, self.t.size - 2)
            length = self.t[seg + 1] - self.t[seg]
            u = (flat - self.t[seg]) / length
            s, ds, dds = _profile(u, self.scaling)
            delta = self.q[seg + 1] - self.q[seg]
            out = (
                self.q[seg] + s[:, None] * delta,
                (ds / length)[:, None] * delta,
                (dds / length**2)[:, None] * delta,
            )
        shape = times.shape + (self.dof,)
        return out[0].reshape(shape), out[1].reshape(shape), out[2].reshape(shape)

    def check(self, model: ArmModel) -> None:
        """Refuse a task that does not fit ``model`` (the whole arm): the joint count, and a
        waypoint (or sample) outside the joint limits, in one line naming the row."""
        if self.dof != model.dof:
            raise ScenarioError(
                f"{self.source}: {self.dof} joint angles per row; {model.name} has {model.dof} joints"
            )
        # the joints' own limits: a continuous joint (no limit) takes any angle
        lo = np.array([j.lower for j in model.joints])
        hi = np.array([j.upper for j in model.joints])
        word = "row" if self.kind == "samples" else "waypoint"
        outside = (self.q < lo - 1e-12) | (self.q > hi + 1e-12)
        if np.any(outside):
            row, col = (int(v) for v in np.argwhere(outside)[0])
            raise ScenarioError(
                f"{self.source}: {word} {row + 1}: joint {col + 1} at {math.degrees(self.q[row, col]):.6g} deg is outside "
                f"its limits [{math.degrees(lo[col]):.6g}, {math.degrees(hi[col]):.6g}] deg"
            )

    def to_dict(self) -> dict[str, Any]:
        """Plain JSON: kind, scaling, duration [s], the knot times [s] and angles [deg]."""
        return {
            "kind": self.kind,
            "scaling": self.scaling,
            "start_s": self.start,
            "duration_s": self.duration,
            "t_s": self.t.tolist(),
            "q_deg": np.degrees(self.q).tolist(),
            "source": self.source,
        }


def _finite_rows(values: ArrayLike, source: str, field: str, word: str) -> FloatArray:
    """(K, n) finite angles within +-MAX_OPTION_DEG [deg] from a list of rows (one line naming
    the row when one is short, long, not numbers or not finite)."""
    rows = values.tolist() if isinstance(values, np.ndarray) else list(values)  # type: ignore[arg-type]
    if not rows:
        raise ScenarioError(f"{source}: {field} is empty")
    width = None
    for k, row in enumerate(rows):
        try:
            arr = np.asarray(row, dtype=float).ravel()
        except (TypeError, ValueError):
            raise ScenarioError(f"{source}: {field} {word} {k + 1} must be numbers; got {shown(row)}") from None
        if width is None:
            width = arr.size
        if arr.size != width or arr.size == 0:
            raise ScenarioError(f"{source}: {field} {word} {k + 1} has {arr.size} angles; {word} 1 has {width}")
        if not np.all(np.isfinite(arr)) or np.any(np.abs(arr) > MAX_OPTION_DEG):
            raise ScenarioError(
                f"{source}: {field} {word} {k + 1} must be finite angles within +-{MAX_OPTION_DEG:g} deg; got {shown(arr.tolist())}"
            )
    return np.asarray(rows, dtype=float).reshape(len(rows), -1)


def _check_rows(t: FloatArray, q: FloatArray, where: str, word: str) -> None:
    """Times finite, within bounds and increasing; angles finite (one line naming the row)."""
    for k in range(t.size):
        if not math.isfinite(t[k]) or not 0 <= t[k] - t[0] <= MAX_TIME_S or abs(t[k]) > MAX_TIME_S:
            raise ScenarioError(
                f"{where}: {word} {k + 1}: time {float(t[k])!r} s is not a finite time within {MAX_TIME_S:g} s"
            )
        if k and not t[k] > t[k - 1]:
            raise ScenarioError(
                f"{where}: {word} {k + 1}: t = {t[k]:g} s is not after {word} {k}'s {t[k - 1]:g} s (times must increase)"
            )
        if not np.all(np.isfinite(q[k])):
            col = int(np.argmin(np.isfinite(q[k])))
            raise ScenarioError(f"{where}: {word} {k + 1}: joint {col + 1}'s angle is not a finite number")


def load_task_file(path: str | Path) -> Task:
    """A sampled task from a file: CSV (a header row, then ``t_s`` and one angle per joint [deg]
    per row; ``#`` comments allowed) or NPZ (arrays ``t_s`` (m,) [s] and ``q_deg`` (m, n) [deg]).

    Raises
    ------
    ScenarioError
        An unreadable file, a wrong column count, a value that is no number, a time that does
        not increase, a NaN: one line naming the file and the row.
    """
    path = Path(path)
    data = read_input_bytes(path, "task file", ScenarioError)
    label = str(path)
    if path.suffix.lower() == ".npz":
        try:
            with np.load(io.BytesIO(data), allow_pickle=False) as npz:
                files = list(npz.files)
                arrays = {k: np.asarray(npz[k]) for k in ("t_s", "q_deg") if k in files}
        except (ValueError, OSError, EOFError, zipfile.BadZipFile):
            raise ScenarioError(f"{label}: not an NPZ file of numeric arrays (numpy.savez, no pickled objects)") from None
        missing = [k for k in ("t_s", "q_deg") if k not in arrays]
        if missing:
            raise ScenarioError(f"{label}: an NPZ task needs arrays t_s and q_deg; missing {', '.join(missing)}")
        if any(a.dtype.kind not in "iuf" for a in arrays.values()):
            raise ScenarioError(f"{label}: t_s and q_deg must be real numbers; got {arrays['t_s'].dtype} and {arrays['q_deg'].dtype}")
        t, q = arrays["t_s"].astype(float), arrays["q_deg"].astype(float)
        if q.ndim != 2 or t.ndim != 1 or q.shape[0] != t.size or q.shape[1] == 0:
            raise ScenarioError(f"{label}: t_s must be (m,) and q_deg (m, n), n >= 1; got {t.shape} and {q.shape}")
        return Task.from_samples(t, q, source=label)
    if path.suffix.lower() != ".csv":
        raise ScenarioError(f"{label}: a task file is .csv or .npz; got {shown(path.suffix or 'no suffix')}")
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError:
        raise ScenarioError(f"{label}: not UTF-8 text") from None
    lines = [(k + 1, line) for k, line in enumerate(text.splitlines()) if line.strip() and not line.lstrip().startswith("#")]
    if len(lines) < 3:
        raise ScenarioError(f"{label}: a CSV task needs a header row and 2 or more rows of t_s and angles [deg]")
    header = [c.strip() for c in lines[0][1].split(",")]
    if all(_is_float(c) for c in header):
        raise ScenarioError(
            f"{label}: line {lines[0][0]} is numbers; a CSV task starts with a header row (t_s, q1_deg, ...)"
        )
    if len(header) < 2:
        raise ScenarioError(f"{label}: line {lines[0][0]}: the header needs t_s and one column per joint; got {shown(lines[0][1])}")
    times: list[float] = []
    rows: list[list[float]] = []
    for number, line in lines[1:]:
        cells = [c.strip() for c in line.split(",")]
        if len(cells) != len(header):
            raise ScenarioError(
                f"{label}: line {number} has {len(cells)} columns; the header has {len(header)} (t_s and {len(header) - 1} angles)"
            )
        try:
            values = [float(c) for c in cells]
        except ValueError:
            bad = next(c for c in cells if not _is_float(c))
            raise ScenarioError(f"{label}: line {number}: {shown(bad)} is not a number") from None
        if not all(math.isfinite(v) for v in values):
            col = next(i for i, v in enumerate(values) if not math.isfinite(v))
            raise ScenarioError(f"{label}: line {number}, column {header[col]}: not a finite number")
        if times and not values[0] > times[-1]:
            raise ScenarioError(
                f"{label}: line {number}: t = {values[0]:g} s is not after the line before's {times[-1]:g} s "
                "(times must increase)"
            )
        times.append(values[0])
        rows.append(values[1:])
    return Task.from_samples(times, rows, source=label)


def _is_float(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True
