"""When the batched functions run compiled (jointlock.compiled, issue 29): the mode from the
environment or the program, each function's choice following it, a scenario's ``compiled``
field, and a campaign's workers running every batch compiled."""

from __future__ import annotations

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
