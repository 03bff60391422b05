"""When the batched functions run compiled (jointlock.compiled, issue 29): the mode from the
environment or the program, each function's choice following it, a scenario's ``compiled``
field, and a campaign's workers running every batch compiled."""

from __future__ import annotations

import sqlite3

import numpy as np
import pytest

import jointlock as jl
from jointlock import _kernels
from jointlock.analysis.ability import configuration_indices
from jointlock.campaign import load_campaign, make_task
from jointlock.compiled import ENVIRONMENT_VARIABLE, compiled_mode, use_compiled
from jointlock.errors import ConfigurationError


@pytest.fixture
def arm():
    return jl.lock(jl.robots.halt7(base="floating"), 4, 0.0)


def test_the_mode_comes_from_the_program_else_the_environment(monkeypatch):
    monkeypatch.delenv(ENVIRONMENT_VARIABLE, raising=False)
    assert compiled_mode() == "auto"
    monkeypatch.setenv(ENVIRONMENT_VARIABLE, " Always ")
    assert compiled_mode() == "always"
    with jl.compiled_kernels("never"):
        assert compiled_mode() == "never"
        with jl.compiled_kernels():
            assert compiled_mode() == "always" and use_compiled(1, 10**9)
        assert compiled_mode() == "never" and not use_compiled(10**9, 1)
    assert compiled_mode() == "always"
    monkeypatch.setenv(ENVIRONMENT_VARIABLE, "fast")
    with pytest.raises(ConfigurationError, match=f"{ENVIRONMENT_VARIABLE} must be one of auto, always, never; got 'fast'"):
        compiled_mode()
    with pytest.raises(ConfigurationError, match="must be one of auto, always, never"):
        jl.set_compiled_mode("yes")  # type: ignore[arg-type]
    monkeypatch.delenv(ENVIRONMENT_VARIABLE)
    assert not use_compiled(10, 11) and use_compiled(11, 11)  # auto: from the threshold on


def test_every_batched_function_follows_the_mode(arm, monkeypatch, rng):
    """One configuration runs on the kernels in "always" and on numpy in "auto" (spied), with
    the same numbers to round-off."""
    monkeypatch.delenv(ENVIRONMENT_VARIABLE, raising=False)
    calls = []
    for name in ("generalized_jacobian", "jacobian", "rnea_floating", "generalized_singular_values", "ee_positions"):
        real = getattr(_kernels, name)
        monkeypatch.setattr(_kernels, name, lambda *a, _real=real, _name=name: (calls.append(_name), _real(*a))[1])
    q = rng.uniform(-2, 2, size=(3, arm.dof))

    def everything():
        return (
            jl.generalized_jacobian(arm, q[0]),
            jl.jacobian(arm, q),
            jl.rnea(arm, q, q, q, base="floating").torques,
            configuration_indices(arm, q).sigma_min,
            jl.ee_positions(arm, q),
        )

    reference = everything()
    assert calls == []
    with jl.compiled_kernels("always"):
        compiled = everything()
    assert set(calls) == {"generalized_jacobian", "jacobian", "rnea_floating", "generalized_singular_values",
                          "ee_positions"}  # fmt: skip
    for a, b in zip(reference, compiled):
        np.testing.assert_allclose(b, a, rtol=1e-11, atol=1e-11)


def test_a_scenario_can_say_its_mode(monkeypatch):
    """The scenario's ``compiled`` field is the mode its jobs run in (then the process's again)."""
    import jointlock.run._run as run_module

    monkeypatch.delenv(ENVIRONMENT_VARIABLE, raising=False)
    seen = []
    real = run_module.job_runner

    def spy(job):
        def runner(*args, **kwargs):
            seen.append(compiled_mode())
            return real(job)(*args, **kwargs)

        return runner

    monkeypatch.setattr(run_module, "job_runner", spy)
    data = {"robot": "puma6", "failure": {"joint": 2, "angle_deg": 10.0}, "workspace": {"samples": 2000}}
    for mode in ("always", "never"):
        jl.run_scenario(jl.scenario_from_dict({**data, "compiled": mode}))
        assert seen[-1] == mode and compiled_mode() == "auto"  # restored after the run
    with pytest.raises(jl.ScenarioError, match="compiled"):
        jl.scenario_from_dict({**data, "compiled": "fast"})


def test_a_campaign_runs_its_cases_compiled_unless_told_otherwise(tmp_path, monkeypatch):
    (tmp_path / "base.toml").write_text(
        'robot = "puma6"\n[failure]\njoint = 2\nangle_deg = 10.0\n[state]\nq0_deg = [0, 0, 0, 0, 0]\n'
        "dq0_deg = [0, 0, 0, 0, 0]\nddq0_deg = [0, 0, 0, 0, 0]\n[halt]\nT = 3.0\n"
    )
    (tmp_path / "campaign.toml").write_text('title = "t"\nscenario = "base.toml"\n[grid]\n"halt.T" = [3.0, 4.0]\n')
    spec = load_campaign(tmp_path / "campaign.toml")
    monkeypatch.delenv(ENVIRONMENT_VARIABLE, raising=False)
    assert make_task(spec, [], ()).compiled == "always"
    monkeypatch.setenv(ENVIRONMENT_VARIABLE, "never")
    assert make_task(spec, [], ()).compiled == "never"
    with jl.compiled_kernels("auto"):
        assert make_task(spec, [], ()).compiled == "auto"


def test_a_block_s_mode_is_its_thread_s():
    """Blocks in two threads, ending in the other order than they began, leave each thread's
    mode its own and the process's as it was."""
    import threading

    entered, first_done = threading.Barrier(2), threading.Event()
    seen = {}

    def worker(name, mode, wait):
        with jl.compiled_kernels(mode):
            entered.wait()
            if wait:
                first_done.wait()
            seen[name] = compiled_mode()
        if not wait:
            first_done.set()
        seen[name + " after"] = compiled_mode()

    threads = [threading.Thread(target=worker, args=("a", "always", True)),
               threading.Thread(target=worker, args=("b", "never", False))]  # fmt: skip
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert seen["a"] == "always" and seen["b"] == "never"
    assert seen["a after"] == seen["b after"] == compiled_mode()


TOLERANCE = """
title = "two locks"
[scenario]
robot = "puma6"
[scenario.failure]
joint = 6
angle_deg = 10.0
[scenario.tolerance_angle]
q_target_deg = [5.0, 60.0, 35.0, 10.0, -120.0, 90.0]
[grid]
"failure.angle_deg" = [10.0, 20.0]
"""


def test_a_campaign_keeps_the_mode_its_cases_ran_in(tmp_path, monkeypatch):
    """Resumed, a campaign runs in the mode its finished cases ran in (recorded in the ledger,
    "auto" for a ledger from before the mode existed); the environment asking for another is
    one clear error, not a campaign computed two ways."""
    from jointlock.campaign import in_process, open_ledger, run_campaign
    from jointlock.errors import CampaignError

    path = tmp_path / "c.toml"
    path.write_text(TOLERANCE)
    out = tmp_path / "out"
    monkeypatch.setenv(ENVIRONMENT_VARIABLE, "never")
    assert run_campaign(path, out, engine=in_process()).ok == 2
    monkeypatch.delenv(ENVIRONMENT_VARIABLE)
    run_campaign(path, out, engine=in_process(), retry_failed=True)
    with open_ledger(out) as ledger:
        assert ledger.meta("compiled") == "never"
    monkeypatch.setenv(ENVIRONMENT_VARIABLE, "always")
    with pytest.raises(CampaignError, match="ran in the compiled mode 'never'.*JOINTLOCK_COMPILED=never"):
        run_campaign(path, out, engine=in_process())
    monkeypatch.delenv(ENVIRONMENT_VARIABLE)
    with sqlite3.connect(out / "ledger.sqlite") as db:  # a ledger from before issue 29
        db.execute("DELETE FROM meta WHERE name = 'compiled'")
    run_campaign(path, out, engine=in_process())
    with open_ledger(out) as ledger:
        assert ledger.meta("compiled") == "auto"
