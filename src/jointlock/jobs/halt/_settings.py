"""What :func:`~jointlock.jobs.halt.plan_halt` takes, grouped into typed settings (issue 27,
item 5): the limits a halt keeps (:class:`HaltLimits`), the search of the halt configuration
(:class:`HaltSearch`, 000 §3) and the halt motion (:class:`HaltMotionSettings`, 000 §4) -- as
:class:`~jointlock.planning.ga.GASettings` groups the GA's and ``scipy.optimize.minimize``'s
``options`` a method's.  The clearance is its own setting,
:class:`~jointlock.collision.ClearanceSettings`, because every job takes it (the
halt-configuration study, the halt, the jump runs).

The keywords these replace (``vmax_deg=``, ``samples=``, ``solver=``, ...) keep working: each
warns once per process (``FutureWarning``) naming its new place, and giving one both ways is a
``TypeError`` (:func:`settings_from_keywords`).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, fields, replace
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike

from ..._deprecate import warn_once
from ...bounds import shown
from ...errors import ScenarioError
from ...papers import p000
from ...planning.ga import GASettings
from ...planning.halt_motion import MomentAbout

Solver = Literal["scan", "ga", "vector"]
SOLVERS = ("scan", "ga", "vector")
MOMENT_POINTS = ("spacecraft_com", "joint1")


def _refuse(where: str, value: Any, what: str) -> None:
    raise ScenarioError(f"{where} must be {what}; got {shown(value)}")


def _is_int(value: Any) -> bool:
    return isinstance(value, (int, np.integer)) and not isinstance(value, (bool, np.bool_))


def _is_real(value: Any) -> bool:
    return isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, (bool, np.bool_))


def _is_bool(value: Any) -> bool:
    return isinstance(value, (bool, np.bool_))


def _plain(value: Any) -> Any:
    return np.asarray(value, dtype=float).tolist() if value is not None and not isinstance(value, str) else value


@dataclass(frozen=True, eq=False)
class HaltLimits:
    """The limits a halt keeps, as people give them (resolved on the arm by
    :func:`~jointlock.jobs.halt.halt_limits`'s rule).

    Attributes
    ----------
    vmax_deg, amax_deg
        Speed [deg/s] and acceleration [deg/s^2] limits of the healthy joints: one value or one
        per joint; None: the model's speed limits where finite, else 000's (40 deg/s), and 000's
        20 deg/s^2.
    torque_max_Nm, brake_max_Nm
        The healthy joints' motor torque limits (capped by the model's effort limits; None: the
        model's) and the locked joints' brake torque limits (None: none) [N m], one value or
        one per joint.  Torque limits are kept on every sample of the constraint grid by
        ``solver="scan"``.
    margin
        Share of each speed and acceleration limit kept free (0 .. 0.5): the halt is chosen
        under the limits scaled by ``1 - margin`` and its margins are reported against the
        limits themselves.
    """

    vmax_deg: ArrayLike | None = None
    amax_deg: ArrayLike | None = None
    torque_max_Nm: ArrayLike | None = None
    brake_max_Nm: ArrayLike | None = None
    margin: float = 0.0

    def __post_init__(self) -> None:
        # the values are checked against the arm by halt_limits; their kind here, in one line
        for name in ("vmax_deg", "amax_deg", "torque_max_Nm", "brake_max_Nm"):
            value = getattr(self, name)
            if value is None:
                continue
            try:
                ok = np.asarray(value).dtype.kind in "iuf" and np.asarray(value).ndim <= 1
            except (TypeError, ValueError):
                ok = False
            if not ok:
                _refuse(f"limits.{name}", value, "one number or one per joint (None: the default)")
        if not _is_real(self.margin):
            _refuse("limits.margin", self.margin, "a number (share of each limit kept free, 0 .. 0.5)")

    def to_dict(self) -> dict[str, Any]:
        """Plain data: each limit as given (None: the rule's default) and the margin."""
        return {f.name: _plain(getattr(self, f.name)) for f in fields(self)}


@dataclass(frozen=True)
class HaltSearch:
    """How the halt configuration is searched (000 §3, HCOM).

    Attributes
    ----------
    samples
        Monte Carlo samples (000's K, :data:`jointlock.papers.p000.SAMPLES`), >= 2.
    reachable
        Search only the configurations the halt polynomial reaches within the limits (exact;
        default) or the whole joint ranges (000's way).
    """

    samples: int = p000.SAMPLES
    reachable: bool = True

    def __post_init__(self) -> None:
        if not _is_int(self.samples):
            _refuse("search.samples", self.samples, "an integer >= 2 (Monte Carlo samples)")
        if not _is_bool(self.reachable):
            _refuse("search.reachable", self.reachable, "True or False")

    def to_dict(self) -> dict[str, Any]:
        """Plain data: samples and whether only reachable configurations are searched."""
        return {"samples": self.samples, "reachable": self.reachable}


@dataclass(frozen=True)
class HaltMotionSettings:
    """How the halt motion is chosen (000 §4).

    Attributes
    ----------
    solver
        ``"scan"`` (exact), ``"ga"`` (000's adaptive GA with ``ga``) or ``"vector"`` (one k
        per joint).
    ga
        The GA's settings (default: population 50, 100 generations).
    n_samples
        Time samples of the objective (odd, Simpson's rule).
    minimum_T
        Also find the smallest halt time with a feasible ``k`` (and, with the clearance
        required, the smallest whose halt keeps it).
    objective
        What ``k`` minimises: ``"mean_torque"`` (000 eq. 32), ``"peak_torque"`` or
        ``"attitude_change"``.
    prefer_margin
        A share of the best objective (0 .. 0.5): among the ``k`` within it, the one whose halt
        keeps the largest smallest margin to every limit (0: the optimum itself, 000's).
    moment_about
        Point of the base torque: ``"spacecraft_com"`` (default) or ``"joint1"``.
    """

    solver: Solver = "scan"
    ga: GASettings = field(default_factory=lambda: GASettings(n_pop=50, n_gen=100))
    n_samples: int = 501
    minimum_T: bool = False
    objective: str = "mean_torque"
    prefer_margin: float = 0.0
    moment_about: MomentAbout = "spacecraft_com"

    def __post_init__(self) -> None:
        if self.solver not in SOLVERS:
            _refuse("motion.solver", self.solver, f"one of {', '.join(SOLVERS)}")
        if not isinstance(self.ga, GASettings):
            _refuse("motion.ga", self.ga, "a GASettings")
        if not _is_int(self.n_samples):
            _refuse("motion.n_samples", self.n_samples, "an odd integer (time samples of the objective)")
        if not _is_bool(self.minimum_T):
            _refuse("motion.minimum_T", self.minimum_T, "True or False")
        if not isinstance(self.objective, str):
            _refuse("motion.objective", self.objective, "the name of an objective (mean_torque, ...)")
        if not _is_real(self.prefer_margin):
            _refuse("motion.prefer_margin", self.prefer_margin, "a number (share of the best objective)")
        if self.moment_about not in MOMENT_POINTS:
            _refuse("motion.moment_about", self.moment_about, f"one of {', '.join(MOMENT_POINTS)}")

    def to_dict(self) -> dict[str, Any]:
        """Plain data: every setting, the GA's as a table."""
        out = {f.name: getattr(self, f.name) for f in fields(self)}
        out["ga"] = {f.name: getattr(self.ga, f.name) for f in fields(self.ga)}
        return out


#: The keywords plan_halt took before these settings: keyword -> (its setting, the field).
FORMER_KEYWORDS: dict[str, tuple[str, str]] = {
    **{name: ("limits", name) for name in ("vmax_deg", "amax_deg", "torque_max_Nm", "brake_max_Nm", "margin")},
    **{name: ("search", name) for name in ("samples", "reachable")},
    **{
        name: ("motion", name)
        for name in ("solver", "ga", "n_samples", "minimum_T", "objective", "prefer_margin", "moment_about")
    },
}

_CLASSES = {"limits": HaltLimits, "search": HaltSearch, "motion": HaltMotionSettings}


def settings_from_keywords(
    function: str, former: Mapping[str, Any], given: Mapping[str, Any]
) -> dict[str, Any]:
    """The settings ``given`` (``{"limits": ..., "search": ..., "motion": ...}``, None where not
    given) completed by the former keywords in ``former``, each warned about once.

    A former keyword whose setting was also given is a ``TypeError``, and so is an unknown
    keyword.  ``limits`` may be a resolved :class:`~jointlock.jobs.halt.JointLimits` (used as
    it is): then only the former ``margin=`` may go with it, kept under ``"margin"``.
    """
    unknown = sorted(set(former) - set(FORMER_KEYWORDS))
    if unknown:
        raise TypeError(f"{function}() got an unexpected keyword argument {unknown[0]!r}")
    out: dict[str, Any] = dict(given)
    out.setdefault("margin", None)
    moved: dict[str, dict[str, Any]] = {}
    for name, value in former.items():
        group, attribute = FORMER_KEYWORDS[name]
        resolved = group == "limits" and given.get("limits") is not None and not isinstance(given["limits"], HaltLimits)
        with_resolved = resolved and name == "margin"
        if given.get(group) is not None and not with_resolved and value is not None:
            raise TypeError(
                f"{function}() got {name}= and {group}=: {name}= is the former way to give {group}.{attribute}; "
                f"give it once, in {group}={_CLASSES[group].__name__}({attribute}=...)"
                + (" (a JointLimits is used as it is)" if resolved else "")
            )
        warn_once(
            f"keyword {function}:{name}",
            f"{function}(): the keyword {name}= is deprecated: use {group}={_CLASSES[group].__name__}({attribute}=...) "
            f"(the same setting); {name}= still works for now",
        )
        if value is None:  # the former keywords' None meant their default
            continue
        if with_resolved:
            out["margin"] = value
        else:
            moved.setdefault(group, {})[attribute] = value
    for group, values in moved.items():
        out[group] = replace(_CLASSES[group](), **values)
    for group, cls in _CLASSES.items():
        if out.get(group) is None:
            out[group] = cls()
    return out
