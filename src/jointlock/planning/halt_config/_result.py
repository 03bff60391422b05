"""Results of the halt-configuration search: :class:`HaltCandidate` (one configuration and
its kinematic ability) and :class:`HaltConfiguration`."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np

from ...analysis.ability import INDEX_NAMES, AbilityModel, JacobianKind, KinematicIndices
from ...collision import Clearance
from ...model import FloatArray
from ._bound import ReachabilityBound
from ._reachability import HaltReachability


@dataclass(frozen=True)
class HaltCandidate:
    """One configuration and its kinematic ability.

    Attributes
    ----------
    q
        (n,) healthy-joint angles [rad], chain order (``joint_numbers`` of the result).
    cp
        Combined index CP (000 eq. 19) on the frozen scale of the sample set.
    sigma_min, condition_number, manipulability
        The unilateral indices (000 Table 3) at ``q``, computed by SVD.
    """

    q: FloatArray
    cp: float
    sigma_min: float
    condition_number: float
    manipulability: float

    def to_dict(self) -> dict[str, Any]:
        """Plain data, angles in degrees."""
        return {
            "q_deg": np.degrees(self.q).tolist(),
            "cp": self.cp,
            "sigma_min": self.sigma_min,
            "condition_number": self.condition_number,
            "manipulability": self.manipulability,
        }


@dataclass(frozen=True)
class HaltConfiguration:
    """Result of :func:`optimal_halt_configuration`.

    Attributes
    ----------
    best
        The optimal halt configuration (after refinement when enabled).
    best_sample
        The best of the ``samples`` Monte Carlo configurations (000's answer).
    runner_up
        The best configuration at least ``runner_up_separation`` away from ``best`` (largest
        joint difference) and not equivalent to it (CP differing by more than
        :data:`EQUIVALENT_CP_RTOL`), among refined candidates and samples; None if none.
    refinement_gain
        ``best.cp - best_sample.cp`` (>= 0; 0 without refinement).
    ability
        CP's frozen normalisation and weights (AHP, entropy, combined).
    samples
        ``K``.
    seed
        The seed the samples were drawn with (an int; the fresh one drawn for ``rng=None``),
        or None when a ``Generator`` was passed.
    jacobian, base
        Jacobian used (``"generalized"`` / ``"fixed"``) and the model's base
        (``"floating"`` / ``"fixed"``); the generalized Jacobian of a fixed base is the
        fixed-base Jacobian.
    joint_numbers
        Numbers (1-based, full arm) of the healthy joints, the order of every ``q``.
    locked
        ``{joint number: angle [rad]}``.
    lower, upper
        (n,) the box that was sampled [rad] (limits, intersected with the reachable box).
    characteristic_length
        ``L`` [m] or None (raw Jacobian, as 000).
    reachability
        The reachability constraint applied (:class:`HaltReachability`, exact, or
        :class:`ReachabilityBound`, bang-bang box only), or None.
    q_samples, cp_samples
        (K, n) [rad] and (K,): the sample set and its CP.
    indices_samples
        Indices of the sample set, arrays (K,).
    refine_evaluations
        Configurations evaluated by the refinement.
    reachable
        (K,) bool: samples whose halt motion is feasible (:class:`HaltReachability`), or
        None.  Unreachable samples keep their CP (the normalisation and entropy weights are
        fitted on the whole sample set) but can be neither the best nor the runner-up.
    reachable_samples
        How many samples are reachable (None without :class:`HaltReachability`).
    k_range
        Feasible shared ``k`` [rad/s^6] over the reachable set (shared-``k`` constraint only).
    clearance_min_m
        The clearance required of the halt configuration [m] (None: not required, 000's way).
    colliding_samples
        Samples excluded for coming closer than that (None when not required).
    best_clearance
        Clearance of :attr:`q_best` (:class:`jointlock.collision.Clearance`), whenever the
        model has collision shapes (None otherwise).

    With ``clearance_min_m``, :attr:`reachable` marks the samples that are reachable *and*
    keep the clearance (the admissible ones); ``reachable_samples`` still counts reachability
    alone.
    """

    best: HaltCandidate
    best_sample: HaltCandidate
    runner_up: HaltCandidate | None
    refinement_gain: float
    ability: AbilityModel
    samples: int
    seed: int | None
    jacobian: JacobianKind
    base: Literal["fixed", "floating"]
    joint_numbers: tuple[int, ...]
    locked: dict[int, float]
    lower: FloatArray
    upper: FloatArray
    characteristic_length: float | None
    reachability: ReachabilityBound | HaltReachability | None
    q_samples: FloatArray = field(repr=False)
    cp_samples: FloatArray = field(repr=False)
    indices_samples: KinematicIndices = field(repr=False)
    refine_evaluations: int = 0
    reachable: np.ndarray | None = field(default=None, repr=False)
    reachable_samples: int | None = None
    k_range: tuple[float, float] | None = None
    clearance_min_m: float | None = None
    colliding_samples: int | None = None
    best_clearance: Clearance | None = field(default=None, repr=False)

    @property
    def q_best(self) -> FloatArray:
        """(n,) the optimal halt configuration, healthy joints [rad]."""
        return self.best.q

    @property
    def cp_best(self) -> float:
        """CP at :attr:`q_best`."""
        return self.best.cp

    @property
    def weights(self) -> dict[str, dict[str, float]]:
        """``{"ahp" | "entropy" | "combined": {index name: weight}}``."""
        return self.ability.weights_dict()

    def to_dict(self) -> dict[str, Any]:
        """Plain data for JSON (degrees for angles; the samples themselves are left out)."""
        ahp = self.ability.ahp
        return {
            "best": self.best.to_dict(),
            "best_sample": self.best_sample.to_dict(),
            "runner_up": None if self.runner_up is None else self.runner_up.to_dict(),
            "refinement": {
                "gain": self.refinement_gain,
                "relative_gain": self.refinement_gain / abs(self.best_sample.cp)
                if self.best_sample.cp
                else None,
                "evaluations": self.refine_evaluations,
            },
            "weights": self.weights,
            "ahp": {
                "matrix": ahp.matrix.tolist(),
                "lambda_max": ahp.lambda_max,
                "ci": ahp.ci,
                "cr": ahp.cr,
                "ri": ahp.ri,
            },
            "entropy": {
                "entropy": dict(zip(INDEX_NAMES, self.ability.entropy.entropy.tolist())),
                "divergence": dict(zip(INDEX_NAMES, self.ability.entropy.divergence.tolist())),
            },
            "normalization": {
                "sigma_min": list(self.ability.normalization.sigma_min_range),
                "manipulability": list(self.ability.normalization.manipulability_range),
            },
            "readings": {"assignment": self.ability.assignment, "renormalize": self.ability.renormalize},
            "seed": self.seed,
            "samples": self.samples,
            "jacobian": self.jacobian,
            "base": self.base,
            "characteristic_length_m": self.characteristic_length,
            "joint_numbers": list(self.joint_numbers),
            "locked_deg": {str(k): math.degrees(v) for k, v in self.locked.items()},
            "lower_deg": np.degrees(self.lower).tolist(),
            "upper_deg": np.degrees(self.upper).tolist(),
            "reachability": self._reachability_dict(),
            "clearance": self._clearance_dict(),
        }

    def _clearance_dict(self) -> dict[str, Any] | None:
        if self.best_clearance is None:
            return None
        return {
            "required_m": self.clearance_min_m,
            "colliding_samples": self.colliding_samples,
            "best": self.best_clearance.to_dict(),
        }

    def _reachability_dict(self) -> dict[str, Any] | None:
        r = self.reachability
        if r is None:
            return None
        out: dict[str, Any] = {
            "kind": "exact" if isinstance(r, HaltReachability) else "bang-bang bound",
            "halt_time_s": r.halt_time,
            "q0_deg": np.degrees(r.q0).tolist(),
            "dq0_deg": np.degrees(r.dq0).tolist(),
            "ddq0_deg": None if r.ddq0 is None else np.degrees(r.ddq0).tolist(),
            "velocity_limit_deg": np.degrees(r.velocity_limit).tolist(),
            "acceleration_limit_deg": np.degrees(r.acceleration_limit).tolist(),
        }
        if isinstance(r, HaltReachability):
            scale = math.pi / 180.0  # k in deg/s^6, 000's reading
            out.update(
                per_joint_k=r.per_joint,
                reachable_samples=self.reachable_samples,
                k_range_deg_s6=None if self.k_range is None else [v / scale for v in self.k_range],
            )
        return out
