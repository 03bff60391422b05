"""The halt-motion problem (000 eq. 34): :class:`HaltProblem` and its input checks."""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike

from ..._cache import cached_on, state_without_cache
from ...dynamics import BaseMode
from ...errors import ScenarioError
from ...model import ArmModel, FloatArray
from ._constants import MIN_SAMPLES
from ._polynomial import halt_coefficients, k_shape, polynomial_profile


def _angle_limit(value: ArrayLike, n: int, name: str) -> FloatArray:
    """Angle limits (n,) [rad]: finite, or -inf/+inf for a joint without a limit (a continuous
    joint: its angle constraint is absent); NaN is refused."""
    arr = np.asarray(value, dtype=float)
    if arr.ndim == 0:
        arr = np.full(n, float(arr))
    if arr.shape != (n,) or np.any(np.isnan(arr)):
        raise ScenarioError(
            f"{name} must be one value or {n} values [rad], -inf/+inf for no limit, not NaN; "
            f"got {arr.tolist()}"
        )
    out = arr.copy()
    out.setflags(write=False)
    return out


def _vec(value: ArrayLike, n: int, name: str, unit: str, *, positive: bool = False) -> FloatArray:
    arr = np.asarray(value, dtype=float)
    if arr.ndim == 0:
        arr = np.full(n, float(arr))
    if arr.shape != (n,) or not np.all(np.isfinite(arr)):
        raise ScenarioError(f"{name} must be one finite value or {n} values [{unit}]; got {arr.tolist()}")
    if positive and not np.all(arr > 0):
        raise ScenarioError(f"{name} must be > 0 [{unit}]; got {arr.tolist()}")
    out = arr.copy()
    out.setflags(write=False)
    return out


@dataclass(frozen=True)
class HaltProblem:
    """A halt-motion problem (000 eq. 34), in SI units and radians.

    Attributes
    ----------
    model
        The locked arm (healthy joints only); for ``base="floating"`` it must carry a spacecraft.
    q0, dq0, ddq0
        (n,) state at failure [rad, rad/s, rad/s^2].
    qf
        (n,) halt configuration [rad] (000: ``q_best``).
    T
        Halt time [s].
    dq_max, ddq_max
        (n,) speed and acceleration limits [rad/s, rad/s^2] (symmetric).
    q_min, q_max
        (n,) angle limits [rad]; default the model's.  ``-inf``/``+inf`` (a continuous
        joint): no angle constraint for that joint.
    base
        ``"fixed"`` (000) or ``"floating"`` base for the disturbance torque.
    n_samples
        Time samples of the objective (odd; Simpson's rule).
    n_check
        Time samples of the constraint check.
    moment_about
        Point of the base disturbance torque (000 eqs. 30-31): ``"spacecraft_com"`` (default,
        the physical choice: the spacecraft turns about its centre of mass; the root frame's
        origin for a model without a spacecraft) or ``"joint1"``, joint 1's origin: the root
        frame's origin, where joint 1 is mounted on the spacecraft (DH frame 0; 000 eq. 30's
        ``bP_1`` ends there) -- the reading of an independent reproduction of 000.
    tau_max
        (n,) motor torque limits of the healthy joints [N m], ``inf`` for none; None: none.
    brake_max
        (n_locked,) brake torque limits of the locked joints [N m] (:attr:`ArmModel.locked`
        order), ``inf`` for none; None: none.  Torque limits are checked on the ``n_check``
        grid (:mod:`._actuator_limits`) with ``solver="scan"``.
    objective
        What the halt minimises over ``k`` (:func:`~._objective.halt_objective`):
        ``"mean_torque"`` (000 eq. 32, default), ``"peak_torque"`` (the largest base torque) or
        ``"attitude_change"`` (the free spacecraft's attitude change at the end; needs a model
        with a spacecraft).
    compiled
        Passed to :func:`~jointlock.dynamics.rnea` for every evaluation of the torque
        objectives: True runs the compiled Newton-Euler kernels (an optimiser scores many
        candidate motions in one process: the 50 x 100 GA spends ~80 % of its time there, and
        the kernels are 3-5x faster once numba is loaded, 0.4-2 s per process); None (default)
        leaves the choice to :func:`~jointlock.dynamics.rnea` (numpy below 200,000 samples per
        call, so the defaults stay on numpy); False: numpy.  The same numbers to round-off.
    """

    model: ArmModel
    q0: FloatArray
    dq0: FloatArray
    ddq0: FloatArray
    qf: FloatArray
    T: float
    dq_max: FloatArray
    ddq_max: FloatArray
    q_min: FloatArray | None = None
    q_max: FloatArray | None = None
    base: BaseMode = "fixed"
    n_samples: int = 501
    n_check: int = 2001
    moment_about: MomentAbout = "spacecraft_com"
    tau_max: FloatArray | None = None
    brake_max: FloatArray | None = None
    objective: str = "mean_torque"
    compiled: bool | None = None

    def __post_init__(self) -> None:
        n = self.model.dof
        for name, unit in (("q0", "rad"), ("dq0", "rad/s"), ("ddq0", "rad/s^2"), ("qf", "rad")):
            object.__setattr__(self, name, _vec(getattr(self, name), n, name, unit))
        object.__setattr__(self, "dq_max", _vec(self.dq_max, n, "dq_max", "rad/s", positive=True))
        object.__setattr__(self, "ddq_max", _vec(self.ddq_max, n, "ddq_max", "rad/s^2", positive=True))
        lo = self.model.lower if self.q_min is None else self.q_min
        hi = self.model.upper if self.q_max is None else self.q_max
        lo, hi = _angle_limit(lo, n, "q_min"), _angle_limit(hi, n, "q_max")
        if np.any(lo > hi):
            raise ScenarioError(f"q_min must be <= q_max [rad]; got {lo.tolist()} and {hi.tolist()}")
        object.__setattr__(self, "q_min", lo)
        object.__setattr__(self, "q_max", hi)
        T = float(self.T)
        if not (math.isfinite(T) and T > 0):
            raise ScenarioError(f"halt time T must be a finite number > 0 [s]; got {self.T}")
        object.__setattr__(self, "T", T)
        if self.base not in ("fixed", "floating"):
            raise ScenarioError(f"base must be 'fixed' or 'floating'; got {self.base!r}")
        if self.base == "floating" and not self.model.floating:
            raise ScenarioError(
                "base='floating' needs a model with a spacecraft (load it with base='floating')"
            )
        for name in ("n_samples", "n_check"):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, (int, np.integer)):
                raise ScenarioError(f"{name} must be an integer; got {v!r}")
        if self.n_samples < MIN_SAMPLES or self.n_samples % 2 == 0:
            raise ScenarioError(f"n_samples must be odd and >= {MIN_SAMPLES}; got {self.n_samples}")
        if self.n_check < 3:
            raise ScenarioError(f"n_check must be >= 3; got {self.n_check}")
        for name, size in (("tau_max", n), ("brake_max", len(self.model.locked))):
            value = getattr(self, name)
            if value is not None:
                arr = np.asarray(value, dtype=float)
                arr = np.full(size, float(arr)) if arr.ndim == 0 else arr
                if arr.shape != (size,) or np.any(np.isnan(arr)) or not np.all(arr > 0):
                    raise ScenarioError(
                        f"{name} must be one value or {size} values > 0 [N m] (inf: no limit); got {arr.tolist()}"
                    )
                arr = arr.copy()
                arr.setflags(write=False)
                object.__setattr__(self, name, arr)
        if self.objective not in HALT_OBJECTIVES:
            raise ScenarioError(f"objective must be one of {', '.join(HALT_OBJECTIVES)}; got {self.objective!r}")
        if self.objective == "attitude_change" and not self.model.floating:
            raise ScenarioError(
                "objective 'attitude_change' needs a model with a spacecraft (load it with base='floating')"
            )
        if self.compiled is not None and not isinstance(self.compiled, (bool, np.bool_)):
            raise ScenarioError(f"compiled must be True, False or None; got {self.compiled!r}")
        if self.moment_about not in MOMENT_POINTS:
            raise ScenarioError(
                f"moment_about must be one of {', '.join(MOMENT_POINTS)}; got {self.moment_about!r}"
            )

    @property
    def moment_point(self) -> FloatArray | None:
        """(3,) point of the base torque in the root frame [m], or None for the spacecraft's
        centre of mass (:func:`~jointlock.dynamics.rnea`'s default)."""
        return np.zeros(3) if self.moment_about == "joint1" else None

    def torque_limits(self) -> tuple[FloatArray, FloatArray]:
        """``(tau_max (n,), brake_max (n_locked,))`` [N m], ``inf`` where there is none."""
        tau = np.full(self.dof, np.inf) if self.tau_max is None else self.tau_max
        brake = np.full(len(self.model.locked), np.inf) if self.brake_max is None else self.brake_max
        return tau, brake

    @property
    def has_torque_limits(self) -> bool:
        """Whether some motor or brake torque limit is finite."""
        tau, brake = self.torque_limits()
        return bool(np.any(np.isfinite(tau)) or np.any(np.isfinite(brake)))

    @property
    def dof(self) -> int:
        return self.model.dof

    def with_time(self, T: float) -> HaltProblem:
        """The same problem with another halt time [s]."""
        return replace(self, T=T)

    def times(self, n: int | None = None) -> FloatArray:
        """(n,) uniform times [s] from 0 to T (``n_samples`` points by default)."""
        return np.linspace(0.0, self.T, self.n_samples if n is None else n)

    def __getstate__(self) -> dict[str, Any]:
        return state_without_cache(self)  # the cached profiles are not pickled

    def profiles(
        self, n: int | None = None
    ) -> tuple[FloatArray, tuple[FloatArray, FloatArray, FloatArray], tuple[FloatArray, FloatArray, FloatArray]]:
        """``(t, base_profile(t), k_shape(t))`` on ``t = times(n)``, read-only, computed once per
        problem and grid: the optimal ``k``'s scan and bounded search evaluate the objective on
        the same grid some 30 times, the limits are checked on the same grid by several
        steps, and each time the halt polynomial's powers cost about as much as the rest."""

        def compute() -> tuple[FloatArray, tuple[FloatArray, ...], tuple[FloatArray, ...]]:
            t = self.times(n)
            base, shape = self.base_profile(t), self.k_shape(t)
            for x in (t, *base, *shape):
                x.setflags(write=False)
            return t, base, shape

        return cached_on(self, f"profiles_{self.n_samples if n is None else n}", compute)  # type: ignore[return-value]

    def base_profile(self, t: ArrayLike) -> tuple[FloatArray, FloatArray, FloatArray]:
        """The ``k = 0`` (quintic) part: q, dq, ddq each (n_t, n)."""
        coef = halt_coefficients(self.q0, self.dq0, self.ddq0, self.qf, self.T, 0.0)
        return polynomial_profile(coef, t)

    def k_shape(self, t: ArrayLike) -> tuple[FloatArray, FloatArray, FloatArray]:
        """``phi(t) = t^3 (t - T)^3`` and its first two derivatives, each (n_t,) [s^6, s^5, s^4]."""
        return k_shape(t, self.T)

    def trajectory(
        self, k: ArrayLike, t: ArrayLike | None = None, *, per_joint: bool = False
    ) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Joint angles, rates and accelerations of the halt for one or many ``k``.

        Parameters
        ----------
        k
            [rad/s^6]: shape (...) for one shared ``k`` per candidate (000), or (..., n) with
            ``per_joint=True`` (one per joint).
        t
            (n_t,) times [s]; default :meth:`times`.

        Returns
        -------
        q, dq, ddq
            each (..., n_t, n) [rad, rad/s, rad/s^2].
        """
        if t is None:
            return self.on_grid(k, per_joint=per_joint)
        t = np.asarray(t, dtype=float)
        return _halt(_k_array(k, self.dof, per_joint), self.base_profile(t), self.k_shape(t))

    def on_grid(
        self, k: ArrayLike, n: int | None = None, index: np.ndarray | None = None, *, per_joint: bool = False
    ) -> tuple[FloatArray, FloatArray, FloatArray]:
        """:meth:`trajectory` on ``times(n)`` (``n_samples`` by default; ``n_check``: the
        constraint grid), or on the times ``times(n)[index]``, from :meth:`profiles`: the same
        numbers, as the halt polynomial at a time does not depend on the other times it is
        evaluated with (``tests/test_halt_motion.py``), without evaluating it again."""
        _, base, shape = self.profiles(n)
        if index is not None:
            base, shape = tuple(b[index] for b in base), tuple(s[index] for s in shape)
        return _halt(_k_array(k, self.dof, per_joint), base, shape)


#: What the halt can minimise over k (:attr:`HaltProblem.objective`).
HALT_OBJECTIVES = ("mean_torque", "peak_torque", "attitude_change")

#: Points about which the base torque can be taken (:attr:`HaltProblem.moment_about`).
MOMENT_POINTS = ("spacecraft_com", "joint1")
MomentAbout = Literal["spacecraft_com", "joint1"]


def _halt(
    k: FloatArray, base: tuple[FloatArray, ...], shape: tuple[FloatArray, ...]
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """q, dq, ddq (..., n_t, n) of the halts ``base + k phi`` (eq. 27): ``k`` (..., n), the
    ``k = 0`` part (n_t, n) and ``phi`` and its derivatives (n_t,) each."""
    kk = k[..., None, :]
    return tuple(b + kk * s[:, None] for b, s in zip(base, shape))  # type: ignore[return-value]


def _k_array(k: ArrayLike, n: int, per_joint: bool) -> FloatArray:
    k = np.asarray(k, dtype=float)
    if per_joint:
        if k.ndim == 0 or k.shape[-1] != n:
            raise ScenarioError(f"per-joint k must have shape (..., {n}) [rad/s^6]; got {k.shape}")
        return k
    return np.broadcast_to(k[..., None], k.shape + (n,))
