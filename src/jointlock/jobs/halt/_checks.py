"""The checks of :func:`~jointlock.jobs.halt.plan_halt` before any work -- its settings, and a
state at failure that already breaks a limit or eats into the margin -- and the names that
refer to its settings in messages (library keywords, CLI options, scenario fields)."""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any, Literal

import numpy as np

from ...analysis.actuators import actuator_torques
from ...errors import InfeasibleError, ScenarioError
from ...model import ArmModel
from ...planning.ga import GASettings
from ...planning.halt_config import HaltReachability
from ._inputs import (
    CLI_LIMIT_NAMES,
    CLI_TORQUE_NAMES,
    SCENARIO_LIMIT_NAMES,
    SCENARIO_TORQUE_NAMES,
    FailureState,
    JointLimits,
    limits_text,
)

#: Smallest number of time samples of the objective (Simpson's rule, odd).
MIN_N_SAMPLES = 11


def _check_start(
    model: ArmModel, state: FailureState, T: float, limits: JointLimits, state_name: str = "state"
) -> None:
    """Refuse a state at failure that itself breaks a limit before any search: every halt
    starts from it (the k-part vanishes at t = 0 with two derivatives), so no halt
    configuration, halt time or k helps, and a Monte Carlo search would be pointless."""
    reach = HaltReachability(state.q, state.dq, state.ddq, T, limits.velocity, limits.acceleration)
    bad = reach.bind(model).start_violations(model.joint_numbers)
    if bad:
        nums = model.joint_numbers
        raise InfeasibleError(
            f"the state at failure ({state_name}) already breaks a limit, and every "
            "halt starts from it, so no halt configuration, halt time or k helps: "
            + "; ".join(bad)
            + f" (speed limits: {limits_text(nums, limits.velocity, limits.velocity_source, 'deg/s')}; "
            f"acceleration limits: "
            f"{limits_text(nums, limits.acceleration, limits.acceleration_source, 'deg/s^2')}); "
            "no halt configuration searched"
        )


def _check_start_margin(
    model: ArmModel, state: FailureState, T: float, kept: JointLimits, margin: float, names: Mapping[str, Any]
) -> None:
    """Refuse a margin the state at failure already eats into: every halt starts from that
    state, so the margin cannot be kept from t = 0."""
    reach = HaltReachability(state.q, state.dq, state.ddq, T, kept.velocity, kept.acceleration)
    bad = reach.bind(model).start_violations(model.joint_numbers)
    if bad:
        scale = 1.0 - margin  # back to the limits themselves
        room = float(
            min(
                np.min(1.0 - np.abs(state.dq) / (kept.velocity / scale)),
                np.min(1.0 - np.abs(state.ddq) / (kept.acceleration / scale)),
            )
        )
        name = names.get("margin", "margin")
        hint = (
            f"no {name} can be kept: the state starts at a limit"
            if room < 1e-9
            else f"a {name} up to {room:.3g} can be kept"
        )
        raise InfeasibleError(
            f"the state at failure ({names['state']}) is already within the {100 * margin:g} % margin of a limit, "
            f"and every halt starts from it: {'; '.join(bad)} (the limits reduced by the margin); {hint}"
        )


def _check_start_torques(
    model: ArmModel,
    state: FailureState,
    base: Literal["fixed", "floating"],
    kept: JointLimits,
    margin: float,
    names: Mapping[str, Any],
) -> None:
    """Refuse torque limits the state at failure already breaks: the torques at t = 0 depend
    on that state alone (the k-part and its two derivatives vanish there), whatever the halt
    configuration, T and k."""
    if kept.torque is None and kept.brake is None:
        return
    motor, brake = actuator_torques(model, state.q, state.dq, state.ddq, base=base)
    bad = []
    for what, values, limits, numbers in (
        ("motor torque", motor, kept.torque, model.joint_numbers),
        ("brake torque (locked)", brake, kept.brake, [lj.number for lj in model.locked]),
    ):
        if limits is None:
            continue
        bad += [
            f"joint {num} {what} {abs(v):.4g} N m > {lim:.4g} N m"
            for num, v, lim in zip(numbers, values, limits)
            if abs(v) > lim * (1 + 1e-9)
        ]
    if bad:
        within = f" (the limits reduced by the {100 * margin:g} % margin)" if margin else ""
        raise InfeasibleError(
            f"the state at failure ({names['state']}) already needs more torque than a limit allows{within}, "
            f"with the {base} base, and every halt starts from it: {'; '.join(bad)}; no halt configuration, "
            "halt time or k helps"
        )


#: How :func:`check_halt_settings` names the settings: plan_halt's keywords, or the CLI's options.
LIBRARY_NAMES = {"T": "T", "n_samples": "motion.n_samples", "samples": "search.samples",
                 "population": "motion.ga.n_pop", "generations": "motion.ga.n_gen", "qf": "qf", "state": "state",
                 "limits": ("limits.vmax_deg", "limits.amax_deg"), "margin": "limits.margin",
                 "torques": ("limits.torque_max_Nm", "limits.brake_max_Nm"),
                 "prefer_margin": "motion.prefer_margin"}  # fmt: skip


CLI_NAMES = {"T": "--T", "n_samples": "--n-samples", "samples": "--samples", "population": "--population",
             "generations": "--generations", "qf": "--qf-deg", "state": "--q0-deg, --dq0-deg, --ddq0-deg",
             "limits": CLI_LIMIT_NAMES, "margin": "--margin", "torques": CLI_TORQUE_NAMES,
             "prefer_margin": "--prefer-margin"}  # fmt: skip


SCENARIO_NAMES = {"T": "halt.T", "n_samples": "halt.n_samples", "samples": "halt.samples",
                  "population": "halt.population", "generations": "halt.generations", "qf": "halt.qf_deg",
                  "state": "state.q0_deg, state.dq0_deg, state.ddq0_deg", "limits": SCENARIO_LIMIT_NAMES,
                  "margin": "halt.margin", "torques": SCENARIO_TORQUE_NAMES,
                  "prefer_margin": "halt.prefer_margin"}  # fmt: skip


def check_halt_settings(
    T: float | None,
    n_samples: int,
    samples: int,
    solver: str,
    ga: GASettings,
    names: Mapping[str, Any] = LIBRARY_NAMES,
) -> None:
    """Refuse settings :func:`plan_halt` cannot use, before any work; ``names`` name them in
    the messages (:data:`LIBRARY_NAMES`, or :data:`CLI_NAMES` for the command line)."""
    if T is not None and not (math.isfinite(T) and T > 0):
        raise ScenarioError(f"{names['T']} must be a finite halt time > 0 [s]; got {T:g}")
    if n_samples < MIN_N_SAMPLES or n_samples % 2 == 0:
        raise ScenarioError(
            f"{names['n_samples']} must be an odd integer >= {MIN_N_SAMPLES} (time samples of the objective, "
            f"Simpson's rule); got {n_samples}"
        )
    if samples < 2:
        raise ScenarioError(
            f"{names['samples']} must be an integer >= 2 (Monte Carlo samples); got {samples}"
        )
    if solver == "ga":
        bad = []
        if ga.n_pop < 2:
            bad.append(f"{names['population']} must be >= 2 (GA population); got {ga.n_pop}")
        if ga.n_gen < 0:
            bad.append(f"{names['generations']} must be >= 0 (GA generations); got {ga.n_gen}")
        if bad:
            raise ScenarioError("; ".join(bad))
