"""What every job result shares, and the input helpers the jobs use.

A *job* is one library call that takes typed inputs and returns a typed result: a frozen
dataclass deriving from :class:`JobResult`, picklable (it crosses process boundaries in
campaigns), with

- ``to_dict()``: plain JSON data (the object ``jointlock COMMAND --json`` prints: same keys,
  same units),
- ``summary()``: the lines ``jointlock COMMAND`` prints,
- ``write(out)``: the files ``jointlock COMMAND --out DIR`` writes (plots, time series,
  ``result.json``), atomically; returns their names,

and plots through :mod:`jointlock.plots`.
"""

from __future__ import annotations

import base64
import dataclasses
import functools
import html
import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any, ClassVar, overload

import numpy as np

from ..collision import DEFAULT_CLEARANCE_MIN_M, ClearanceSettings
from ..errors import ScenarioError
from ..io.files import atomic_write_json, figure_png, json_text, to_plain
from ..model import ArmModel
from ..plots.animation import animation_figure
from ..plots.motion import ArmMotion


class JobResult:
    """Base of every job's result (mix into a frozen dataclass; ``eq=False``: results hold
    arrays, compare their ``to_dict()``).

    A subclass's ``to_dict`` is wrapped so that it returns plain JSON data
    (:func:`~jointlock.io.files.to_plain`: lists, Python numbers, None for NaN), so
    ``json.dumps(result.to_dict())`` always works; the arrays stay on the result's fields.
    """

    #: Name of the job (``"halt"``, ``"jump"``, ...), as in scenario files.
    job: ClassVar[str] = ""

    def __init_subclass__(cls, **kwargs: Any) -> None:
        super().__init_subclass__(**kwargs)
        if "__repr__" not in cls.__dict__:  # set before @dataclass, which then keeps it
            cls.__repr__ = JobResult._short_repr  # type: ignore[method-assign, assignment]
        raw = cls.__dict__.get("to_dict")
        if raw is None or getattr(raw, "_returns_plain", False):
            return

        @functools.wraps(raw)
        def to_dict(self: Any, *args: Any, **kw: Any) -> dict[str, Any]:
            return to_plain(raw(self, *args, **kw))

        to_dict._returns_plain = True  # type: ignore[attr-defined]
        cls.to_dict = to_dict  # type: ignore[method-assign]

    def to_dict(self) -> dict[str, Any]:  # pragma: no cover - every result overrides it
        raise NotImplementedError

    def summary(self) -> list[str]:  # pragma: no cover - every result overrides it
        raise NotImplementedError

    def _short_repr(self) -> str:
        """One line: the class and the first line of :meth:`summary` (the fields hold arrays:
        ``to_dict()`` has every number)."""
        try:
            head = self.summary()[0]
        except Exception:  # noqa: BLE001 - a repr must not raise
            head = "..."
        return f"<{type(self).__name__}: {head}>"

    def main_figure(self) -> Any | None:
        """The job's main figure (a matplotlib Figure outside pyplot: ``fig.savefig(...)``), or
        None for a result without one (:func:`jointlock.jobs._figures.main_figure`)."""
        from ._figures import main_figure

        return main_figure(self)

    def _repr_html_(self) -> str:
        """What a notebook shows: the lines the command prints, in a ``<pre>`` block, and the
        main figure (:meth:`main_figure`, PNG)."""
        try:
            text = "\n".join(self.summary())
        except Exception as exc:  # noqa: BLE001 - a notebook display must not raise
            text = f"{type(self).__name__}: summary unavailable ({type(exc).__name__}: {exc})"
        page = "<pre>" + html.escape(text) + "</pre>"
        try:
            fig = self.main_figure()
            if fig is not None:
                png = base64.b64encode(figure_png(fig, dpi=80)).decode("ascii")
                page += f'<img src="data:image/png;base64,{png}" alt="{html.escape(type(self).__name__)}: main figure">'
        except Exception as exc:  # noqa: BLE001 - a notebook display must not raise
            page += f"<p>(main figure unavailable: {html.escape(type(exc).__name__)}: {html.escape(str(exc))})</p>"
        return page

    def write(self, out: str | Path) -> list[str]:  # pragma: no cover - every result overrides it
        raise NotImplementedError

    def arm_motions(self) -> tuple[ArmModel, list[ArmMotion]] | None:
        """The arm and its motions in this result (halt, jump, re-plan), for the 3-D animation
        and ``motion.json``; None for a result without a motion."""
        return None

    def animation(self, *, title: str = "", max_frames: int = 120) -> dict[str, Any] | None:
        """The interactive 3-D view of :meth:`arm_motions` as a plotly figure
        (:func:`~jointlock.plots.animation.animation_figure`; write it with
        :func:`~jointlock.plots.animation.standalone_html`); None without a motion."""
        got = self.arm_motions()
        if got is None:
            return None
        return animation_figure(got[0], got[1], title=title or f"{got[0].name}: {self.job}", max_frames=max_frames)

    def _write_motions(self, out: Path) -> list[str]:
        """``motion.json`` (:meth:`arm_motions`, what the animation reads) in ``out``."""
        got = self.arm_motions()
        if got is None:
            return []
        atomic_write_json(out / "motion.json", {"robot": got[0].name, "motions": [m.to_dict() for m in got[1]]})
        return ["motion.json"]

    def to_json(self) -> str:
        """:meth:`to_dict` as JSON text (non-finite numbers as null)."""
        return json_text(self.to_dict())

    def plain(self) -> dict[str, Any]:
        """:meth:`to_dict` (already plain JSON data; kept for compatibility)."""
        return self.to_dict()


@overload
def scenario_lock(data: Mapping[str, Any], job: str) -> tuple[int, float]: ...
@overload
def scenario_lock(data: Mapping[str, Any], job: None = None) -> tuple[int, float] | None: ...
def scenario_lock(data: Mapping[str, Any], job: str | None = None) -> tuple[int, float] | None:
    """``(joint number, angle [rad])`` of a resolved scenario's ``[failure]`` when it gives both
    (the jobs that lock a joint at a known angle), else None -- or, when ``job`` is given (a
    job that needs the lock), a :class:`ScenarioError` naming it."""
    failure = data.get("failure") or {}
    if failure.get("joint") is None or failure.get("angle_deg") is None:
        if job is not None:
            raise ScenarioError(f"job [{job}] needs [failure] joint and angle_deg")
        return None
    return int(failure["joint"]), math.radians(float(failure["angle_deg"]))


def scenario_locks(data: Mapping[str, Any]) -> dict[int, float]:
    """``{joint number: angle [rad]}`` of every locked joint of a resolved scenario: the joints
    of ``[failure] also_locked_deg``, then the failure's (empty without a failure)."""
    lk = scenario_lock(data)
    if lk is None:
        return {}
    earlier = (data.get("failure") or {}).get("also_locked_deg") or {}
    return {**{int(j): math.radians(float(a)) for j, a in earlier.items()}, lk[0]: lk[1]}


def clearance_settings(minimum_m: float | None, check: bool = True) -> ClearanceSettings:
    """The clearance required: ``minimum_m`` [m] (None: the default,
    :data:`~jointlock.collision.DEFAULT_CLEARANCE_MIN_M`), or reported only when ``check`` is
    False (``--no-clearance``, ``[limits] check_clearance = false``)."""
    if not check:
        return ClearanceSettings.off()
    return ClearanceSettings(DEFAULT_CLEARANCE_MIN_M if minimum_m is None else minimum_m)


def scenario_clearance(data: Mapping[str, Any]) -> ClearanceSettings:
    """The clearance a resolved scenario requires (``[limits] clearance_min_m`` and
    ``check_clearance``, :func:`clearance_settings`) and its keep-out volumes (``[[keep_out]]``)."""
    from ..scenario._keep_out import keep_out_shapes

    lim = data.get("limits") or {}
    settings = clearance_settings(lim.get("clearance_min_m"), lim.get("check_clearance") is not False)
    shapes = keep_out_shapes(data)
    return dataclasses.replace(settings, keep_out=shapes) if shapes else settings


def locked_deg(model: ArmModel) -> dict[str, float]:
    """``{"J": angle [deg]}`` of the locked joints, for JSON output."""
    return {str(lj.number): math.degrees(lj.angle) for lj in model.locked}


#: A limit met with less than this share of it free is "at the limit", not "kept" (halt tables,
#: the run report's limits).
AT_LIMIT = 0.01


def locked_text(locked: dict[str, float]) -> str:
    """``"joint J at DEG deg, ..."`` (or ``"none"``) from :func:`locked_deg`'s mapping."""
    return ", ".join(f"joint {k} at {v + 0.0:g} deg" for k, v in locked.items()) or "none"  # + 0.0: no "-0"


def joint_vector_deg(
    model: ArmModel, values: Any, option: str, *, rates: bool = False
) -> np.ndarray:
    """Angles [rad] of the movable joints from degrees (or, with ``rates=True``, rates
    [rad/s] or accelerations [rad/s^2] from deg/s or deg/s^2); ``option`` names the option or
    field in error messages.

    Accepts either one value per movable joint, or one per joint of the full arm: the locked
    joints' entries must then equal their lock angles (angles) or be 0 (``rates=True``: a
    locked joint does not move).  ``None`` gives zeros.
    """
    if values is None:
        return np.zeros(model.dof)
    arr = np.radians(np.asarray(values, dtype=float))
    if not np.all(np.isfinite(arr)):
        raise ScenarioError(f"{option} must be finite numbers [deg]; got {list(values)}")
    if arr.size == model.dof:
        return arr
    if arr.size == model.full_dof and model.locked and rates:
        bad = [lj.number for lj in model.locked if not abs(arr[lj.number - 1]) <= 1e-9]
        if bad:
            raise ScenarioError(
                f"{option}: the entries of locked joints {bad} must be 0 (a locked joint does not "
                "move; or give only the movable joints)"
            )
        return model.healthy(arr)
    if arr.size == model.full_dof and model.locked:
        full_locked = model.expand(model.healthy(arr))
        if not np.allclose(full_locked, arr, atol=1e-9):
            bad = [
                lj.number
                for lj in model.locked
                if not math.isclose(arr[lj.number - 1], lj.angle, abs_tol=1e-9)
            ]
            raise ScenarioError(
                f"{option}: the entries of locked joints {bad} must equal their lock angles "
                "(or give only the movable joints)"
            )
        return model.healthy(arr)
    raise ScenarioError(
        f"{option} needs {model.dof} values (movable joints {list(model.joint_numbers)}) "
        f"[deg]; got {arr.size}"
    )


def format_matrix(mat: np.ndarray, fmt: str = "{:>11.5f}", col_labels: list[str] | None = None) -> str:
    """The rows of ``mat`` (one line each, every entry formatted with ``fmt``) under
    right-aligned column labels 11 characters wide when ``col_labels`` is given: the matrix
    layout the commands print."""
    lines = []
    if col_labels is not None:
        lines.append(" ".join(f"{c:>11}" for c in col_labels))
    for row in np.atleast_2d(mat):
        lines.append(" ".join(fmt.format(v) for v in row))
    return "\n".join(lines)
