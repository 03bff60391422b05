"""The smallest halt time that keeps the clearance too (issue 27: "clearance in the smallest
feasible T"): on halt7 with joint 4 locked at -45 deg from 000 §5.2's state, the limits alone
allow 9.44 s, but that halt sweeps a link through the bus; the clearance needs 9.60 s, and a
halt of that length keeps it (the halt configuration of examples/campaigns/halt7.toml's case, its
seed)."""

from __future__ import annotations

import pytest

import jointlock as jl

#: The seed examples/campaigns/halt7.toml gives that case (joint 4 at -45 deg, T = 8 s).
CASE_SEED = 556167727


def _halt(joint: int, angle_deg: float, T: float, minimum_T: bool = True, seed: int = CASE_SEED):
    base = jl.load_scenario("examples/halt_000.toml").data["state"]
    scenario = jl.scenario_from_dict(
        {
            "robot": "halt7",
            "seed": seed,
            "base": "floating",
            "failure": {"joint": joint, "angle_deg": angle_deg},
            "halt": {"T": T, "minimum_T": minimum_T},
            "halt_config": {"samples": 4000, "reachable": False},
            "state": {key: base[key] for key in ("q0_deg", "dq0_deg", "ddq0_deg")},
        },
        base_dir=".",
    )
    return jl.run_scenario(scenario)


def test_the_smallest_clear_halt_time_is_longer_and_its_halt_keeps_the_clearance():
    plan = _halt(4, -45.0, 8.0)["halt"]
    limits_T, clear_T = plan.motion.minimum_T, plan.minimum_T_clear
    assert limits_T == pytest.approx(9.44, abs=0.01) and clear_T == pytest.approx(9.60, abs=0.01)
    assert plan.to_dict()["minimum_T_clear_s"] == clear_T
    assert f"keeping the clearance (0.05 m) as well: T = {clear_T:.3f} s" in "\n".join(plan.summary())
    # the halt configuration is the search's for this state: the same at any T
    at_clear = _halt(4, -45.0, clear_T + 1e-3, minimum_T=False)["halt"]
    assert at_clear.feasible and at_clear.collision_free is True
    at_limits = _halt(4, -45.0, limits_T + 1e-3, minimum_T=False)["halt"]
    assert at_limits.feasible and at_limits.collision_free is False


def test_no_clear_halt_time_is_said_with_the_range_looked_at():
    plan = _halt(4, 45.0, 10.0)["halt"]
    assert plan.motion.minimum_T is not None and plan.minimum_T_clear is None
    text = "\n".join(plan.summary())
    assert f"no halt time up to {2 * max(10.0, plan.motion.minimum_T):.3g} s keeps the clearance (0.05 m) as well" in text


def test_not_computed_without_the_clearance_required():
    plan = jl.plan_halt(
        "halt7",
        clearance=jl.ClearanceSettings.off(),
        search=jl.HaltSearch(samples=2000),
        motion=jl.HaltMotionSettings(n_samples=101, minimum_T=True),
    )
    assert plan.motion.minimum_T is not None and not plan.clearance_checked_for_T
    assert plan.minimum_T_clear is None and "keeping the clearance" not in "\n".join(plan.summary())
