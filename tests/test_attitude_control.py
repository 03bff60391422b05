"""What the attitude control must absorb with the spacecraft held (issue 28, item 4): the base
moment's peak and the angular momentum handed to the wheels, against the wheels' capacities."""

from __future__ import annotations

import math

import numpy as np
import pytest

import jointlock as jl
from jointlock.analysis.attitude_control import WheelCapacity, attitude_control_check
from jointlock.errors import ConfigurationError
from jointlock.kinematics import momentum


def _one_link_arm() -> jl.ArmModel:
    """A point mass m at radius r on one joint about z through the spacecraft's centre of mass:
    the hand computation is I = m r^2."""
    body = jl.Body(10.0, [2.0, 0.0, 0.0], np.zeros((3, 3)))
    return jl.from_dh("one", a=[0.0], alpha=[0.0], d=[0.0], convention="standard", bodies=[body],
                      spacecraft=jl.Body(1000.0, [0.0, 0.0, 0.0], np.eye(3) * 100.0))  # fmt: skip


def test_hand_computed_case():
    """The link turning at w0 = 0.5 rad/s brought to rest over T = 2 s with a quintic-shaped rate:
    the wheels end up holding I w0 = 40 * 0.5 = 20 N m s about z; the peak torque is I * max|ddq|
    = 40 * (15/8 w0 / T) ... computed here from the profile."""
    arm = _one_link_arm()
    T, w0 = 2.0, 0.5
    t = np.linspace(0.0, T, 2001)
    u = t / T
    s = 1 - (10 * u**3 - 15 * u**4 + 6 * u**5)  # rate shape from 1 to 0, rest-to-rest derivative
    ds = -(30 * u**2 - 60 * u**3 + 30 * u**4) / T
    dq = (w0 * s)[:, None]
    ddq = (w0 * ds)[:, None]
    q = np.concatenate([[0.0], np.cumsum(0.5 * (dq[1:, 0] + dq[:-1, 0]) * np.diff(t))])[:, None]
    inertia = 10.0 * 2.0**2
    check = attitude_control_check(arm, t, q, dq, ddq, WheelCapacity(torque_max_Nm=20.0, momentum_max_Nms=25.0))
    assert check.final_momentum_Nms == pytest.approx(inertia * w0, rel=1e-6)
    assert check.peak_torque_Nm == pytest.approx(inertia * w0 * 15 / (8 * T), rel=1e-6)  # max |ds| = 15/8 at u = 1/2
    assert check.peak_momentum_Nms == pytest.approx(inertia * w0, rel=1e-6)
    margins = check.margins()
    assert margins["torque"] == pytest.approx(1 - 18.75 / 20.0) and margins["momentum"] == pytest.approx(1 - 20 / 25)
    assert check.within and check.verdict().startswith("attitude control: within")
    tight = attitude_control_check(arm, t, q, dq, ddq, WheelCapacity(torque_max_Nm=10.0))
    assert tight.within is False and tight.verdict().startswith("ATTITUDE CONTROL EXCEEDED") and "torque over" in tight.verdict()
    assert attitude_control_check(arm, t, q, dq, ddq).within is None


def test_the_wheels_end_with_the_arms_initial_momentum(rng):
    """Invariant: int tau_b dt = L_arm(0) - L_arm(T) about the held spacecraft's centre of mass
    (000's halt: the arm at rest at the end)."""
    plan = jl.plan_halt("halt7", progress=False)
    p = plan.problem
    t = p.times(4001)
    q, dq, ddq = plan.motion.trajectory(t)
    check = attitude_control_check(p.model, t, q, dq, ddq)
    h0 = momentum(p.model, q[0], dq[0])  # about the root origin, spacecraft held
    about_com = h0[3:] - np.cross(p.model.root_body.com, h0[:3])
    np.testing.assert_allclose(check.momentum[-1], about_com, rtol=1e-5)


def test_capacity_refuses_bad_numbers():
    for bad in (0.0, -1.0, math.inf, math.nan, True, "5"):
        with pytest.raises(ConfigurationError, match="wheel torque_max_Nm"):
            WheelCapacity(torque_max_Nm=bad)


def test_the_halt_reports_and_judges_the_attitude_control(tmp_path, capsys):
    """000's halt with wheels of 5000 N m: over (the first line after the clearance says so); with
    20 kN m and 20 kN m s: within, a line of the summary; in JSON, in the run's summary and report."""
    import json

    from jointlock.cli import main

    assert main(["halt", "halt7", "--wheel-torque-max-Nm", "5000", "--quiet", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)["attitude_control"]
    assert data["within"] is False and data["torque_margin"] < 0 and data["wheel_momentum_max_Nms"] is None
    assert main(["halt", "halt7", "--wheel-torque-max-Nm", "5000", "--quiet"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].startswith("CLEARANCE") and lines[1].startswith("ATTITUDE CONTROL EXCEEDED: peak torque 9243 N m")
    plan = jl.plan_halt("halt7", wheels=WheelCapacity(20_000.0, 20_000.0), progress=False)
    assert plan.attitude_control().within and any(
        line.startswith("attitude control: within") for line in plan.summary()
    )
    scenario = jl.load_scenario(
        "examples/halt_000.toml", {"jobs": ["halt"], "halt.samples": 2000, "spacecraft.wheel_torque_max_Nm": 5000.0}
    )
    result = jl.run_scenario(scenario)
    written = result.write(tmp_path)
    assert written["summary"]["halt"]["attitude_control"]["within"] is False
    assert "Attitude control" in (tmp_path / "report.html").read_text() or "ATTITUDE CONTROL EXCEEDED" in (
        tmp_path / "report.html"
    ).read_text()
    assert "--wheel-torque-max-Nm" in written["jobs"]["halt"]["command"]
