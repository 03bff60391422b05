"""Seed 001 / NOTES-001: global compensation, jump metrics, kappa search, kappa(t), verification."""

from __future__ import annotations

import json
import math
import warnings

import numpy as np
import pytest

import jointlock as jl
from jointlock.cli import main as cli_main
from jointlock.derivatives import jacobian_derivatives
from jointlock.jobs.reproduction import notes_001_task
from jointlock.planning.jump import (
    JumpScenario,
    cartesian_trapezoid,
    compensated_rates,
    find_breaks,
    fit_kappa,
    fit_pieces,
    improved_share,
    jump_reduction,
    jump_table,
    load_jump_task,
    ramp_schedule,
    scenario_from_mapping,
    search_kappa,
    simulate,
    verify_kappa,
)

#: Round-off level of products of 10 m Jacobians with rad/s rates [m/s].
EXACT = 1e-10
#: A shorter task keeps the tests fast (same law, same checks).
SHORT = JumpScenario(duration=3.0, blend=0.75, dx=(0.1, -0.125, 0.07))


@pytest.fixture(scope="module")
def arm():
    return jl.load_robot("canadarm7")


def test_default_scenario_is_notes_001_task():
    """JumpScenario's defaults are NOTES-001's task (jointlock.papers.p001.TASK; 001's own
    numbers were lost), the task ``jointlock reproduce`` runs."""
    assert JumpScenario() == notes_001_task()
    assert JumpScenario(duration=6.0) != notes_001_task()


def test_trapezoid_endpoints_and_continuity():
    T, tb = 12.0, 2.0
    t = np.linspace(0, T, 24001)
    p = cartesian_trapezoid([1.0, 2.0, 3.0], [1.2, -1.5, 0.8], t, duration=T, blend=tb)
    np.testing.assert_allclose(p.x[0], [1, 2, 3], atol=1e-15)
    np.testing.assert_allclose(p.x[-1], [2.2, 0.5, 3.8], atol=1e-12)
    assert p.sd[0] == 0 and abs(p.sd[-1]) < 1e-12
    dt = t[1] - t[0]
    assert np.max(np.abs(np.diff(p.s))) < 1.01 * dt / (T - tb)  # position continuous
    assert np.max(np.abs(np.diff(p.sd))) < 1.01 * dt / (tb * (T - tb))  # velocity continuous
    np.testing.assert_allclose(np.gradient(p.s, dt)[1:-1], p.sd[1:-1], atol=1e-3)  # sd is ds/dt
    for knot in (tb, T - tb):  # both sides of the blend knots agree
        lo = cartesian_trapezoid(0, [1, 0, 0], knot - 1e-9, duration=T, blend=tb)
        hi = cartesian_trapezoid(0, [1, 0, 0], knot + 1e-9, duration=T, blend=tb)
        assert abs(lo.s - hi.s) < 1e-8 and abs(lo.sd - hi.sd) < 1e-8


def test_property1_null_space_never_moves_end_effector(arm, rng):
    q = rng.uniform(-2, 2, (20, 7))
    jac = jl.jacobian(arm, q)[:, :3]
    djac = jacobian_derivatives(arm, q)[:, :, :3]
    xd = rng.normal(size=(20, 3))
    mask = np.ones((20, 7), bool)
    mask[10:, 1] = False
    for kappa in (0.0, 0.3, -2.0):
        qd, _ = compensated_rates(jac, djac, xd, np.full(20, kappa), mask)
        np.testing.assert_allclose(np.einsum("brc,bc->br", jac, qd), xd, atol=EXACT)
    # the null-space term alone gives zero end-effector velocity
    null, _ = compensated_rates(jac, djac, np.zeros(3), np.ones(20), mask)
    np.testing.assert_allclose(np.einsum("brc,bc->br", jac, null), 0, atol=EXACT)
    assert np.abs(null).max() > 1e-3  # and is not trivially zero


def test_property2_kappa_zero_is_pseudoinverse(arm, rng):
    q = rng.uniform(-2, 2, (5, 7))
    jac = jl.jacobian(arm, q)[:, :3]
    xd = rng.normal(size=(5, 3))
    qd, _ = compensated_rates(jac, jacobian_derivatives(arm, q)[:, :, :3], xd, np.zeros(5))
    np.testing.assert_allclose(qd, np.einsum("bij,bj->bi", np.linalg.pinv(jac), xd), atol=1e-10)


def test_property3_locked_joint_rate_is_exactly_zero(arm):
    tr = simulate(arm, SHORT, 0.004, failures=[(2, 1.0)])
    k = SHORT.step_of(1.0)
    assert np.all(tr.qd[k:, 1] == 0.0)
    assert np.all(tr.q[k:, 1] == tr.q[k, 1])
    assert np.any(tr.qd[:k, 1] != 0.0)


def test_several_joints_lock_in_sequence(arm):
    tr = simulate(arm, SHORT, 0.002, failures=[(2, 0.8), (5, 1.7)])
    k1, k2 = SHORT.step_of(0.8), SHORT.step_of(1.7)
    assert np.all(tr.qd[k1:, 1] == 0.0) and np.all(tr.qd[k2:, 4] == 0.0)
    assert np.any(tr.qd[k1:k2, 4] != 0.0)
    assert tr.limits.max_deviation < 5e-3  # still follows the path with 5 joints


def test_property4_motion_before_failure_independent_of_failure_time(arm):
    base = simulate(arm, SHORT, 0.003)
    for tf in (0.5, 1.5, 2.5):
        k = SHORT.step_of(tf)
        tr = simulate(arm, SHORT, 0.003, failures=[(2, tf)])
        np.testing.assert_array_equal(tr.q[: k + 1], base.q[: k + 1])
        np.testing.assert_array_equal(tr.qd[:k], base.qd[:k])
        # and the jump table (from the healthy run only) predicts the realised jump
        table = jump_table(arm, SHORT, 0.003)
        np.testing.assert_allclose(tr.qd[k] - base.qd[k], table.joint_jump[0, k], atol=1e-14)


def test_property5_jump_affine_in_kappa_at_fixed_configuration(arm, rng):
    q = rng.uniform(-2, 2, (4, 7))
    jac = jl.jacobian(arm, q)[:, :3]
    djac = jacobian_derivatives(arm, q)[:, :, :3]
    xd = rng.normal(size=(4, 3))
    mask = np.ones(7, bool)
    mask[1] = False

    def dq(k):
        kk = np.full(4, k)
        return compensated_rates(jac, djac, xd, kk, mask)[0] - compensated_rates(jac, djac, xd, kk)[0]

    d0, d1, d2 = dq(0.0), dq(1.0), dq(2.5)
    np.testing.assert_allclose(d2, d0 + 2.5 * (d1 - d0), atol=1e-10)


def test_replanning_zero_task_jump_and_noreplan_value(arm):
    table = jump_table(arm, SHORT, [0.0, 0.004])
    assert table.task_jump_replan.max() < EXACT  # J_r keeps full row rank along the path
    assert table.task_jump_noreplan[:, 10:-10].min() > 1e-4  # without re-planning it is not 0
    np.testing.assert_allclose(
        table.joint_jump_noreplan[:, 5:], np.abs(table.joint_jump[:, 5:, 1]), rtol=1e-12
    )


def test_batched_equals_looped(arm):
    kappas = [0.0, 0.002, 0.005]
    table = jump_table(arm, SHORT, kappas)
    for i, k in enumerate(kappas):
        single = jump_table(arm, SHORT, k)
        np.testing.assert_allclose(table.joint_jump[i], single.joint_jump[0], atol=1e-13)
        tr = simulate(arm, SHORT, k)
        np.testing.assert_allclose(table.q[i], tr.q, atol=1e-13)


def test_search_fit_verify_short(arm):
    s = search_kappa(arm, SHORT, n_samples=8, n_grid=9, n_probe=21)
    ok = np.isfinite(s.kappa_opt)
    assert ok.all()
    assert np.all(s.objective_opt <= s.objective_zero + 1e-15)  # 0 is in the grid
    assert np.all((s.kappa_opt >= s.interval[:, 0]) & (s.kappa_opt <= s.interval[:, 1]))
    # the optimum found beats every feasible grid value at each failure time
    best_grid = np.where(s.feasible, s.objective, np.inf).min(axis=0)
    assert np.all(s.objective_opt <= best_grid + 1e-15)
    fit = fit_kappa(arm, s, order=3)
    assert fit.order >= 3 and np.isfinite(fit.ssr)
    v = verify_kappa(arm, None, fit, search=s)
    assert v.jump_before.shape == (SHORT.n_steps,)
    assert 0.0 <= v.share_improved <= 1.0
    assert v.mean_reduction == pytest.approx(1 - v.jump_after.mean() / v.jump_before.mean())
    # constant kappa = 0 "after" equals "before"
    v0 = verify_kappa(arm, SHORT, 0.0)
    np.testing.assert_array_equal(v0.jump_after, v0.jump_before)
    assert v0.limits_ok == (v0.healthy_ok and v0.limits_ok_per_step.all())


def test_verification_detects_limit_break_and_ramp_fix(arm):
    """A schedule that drops abruptly breaks the acceleration limit; the ramp fix removes it."""
    sc = SHORT
    s = search_kappa(arm, sc, n_samples=4, n_grid=5, n_probe=11, refine_iter=0)
    step = np.where(sc.times[:-1] < 1.5, 0.6 * s.probe_range[1], 0.0)
    bad = verify_kappa(arm, sc, lambda t: np.interp(t, sc.times[:-1], step), search=s)
    assert not bad.limits_ok and any("acceleration" in m for m in bad.limits.broken())
    fixed = verify_kappa(arm, sc, lambda t: np.interp(t, sc.times[:-1], step), search=s, fix="ramp")
    assert np.abs(np.diff(fixed.kappa)).max() <= sc.amax * sc.dt / (2 * s.null_max) + 1e-15
    assert fixed.limits.max_acceleration < bad.limits.max_acceleration


def test_ramp_schedule():
    k = np.array([0, 0, 1, 1, 1, 0, 0, -1, -1], float)
    r = ramp_schedule(k, 0.5)
    assert np.abs(np.diff(r)).max() <= 0.5 + 1e-15
    assert np.all(np.abs(r) <= np.abs(k) + 1e-15)


def test_deterministic(arm):
    a = search_kappa(arm, SHORT, n_samples=3, n_grid=5, n_probe=9, refine_iter=1)
    b = search_kappa(arm, SHORT, n_samples=3, n_grid=5, n_probe=9, refine_iter=1)
    np.testing.assert_array_equal(a.kappa_opt, b.kappa_opt)
    np.testing.assert_array_equal(a.objective, b.objective)


def test_scenario_file_and_errors(tmp_path):
    f = tmp_path / "s.toml"
    f.write_text("q0_deg = [0, 30, -60, 90, -60, 30, 0]\ndx_m = [0.5, 0, 0]\nduration_s = 6.0\nkp = 1.5\n")
    sc = load_jump_task(f)
    assert sc.duration == 6.0 and sc.kp == 1.5 and sc.q0[1] == pytest.approx(math.radians(30))
    assert sc == load_jump_task(f)
    with pytest.raises(jl.ScenarioError, match="did you mean 'duration_s'"):
        scenario_from_mapping({"duraton_s": 3.0})
    with pytest.raises(jl.ScenarioError, match="'kp' must be a number"):
        scenario_from_mapping({"kp": "fast"})
    with pytest.raises(jl.ScenarioError, match="list of 3 numbers"):
        scenario_from_mapping({"dx_m": [1, 2]})
    with pytest.raises(jl.ScenarioError, match="whole number"):
        JumpScenario(duration=6.01, dt=0.05)
    with pytest.raises(jl.ScenarioError, match="failure time"):
        SHORT.step_of(5.0)


def test_floating_base_runs(arm):
    model = jl.load_robot("canadarm7", base="floating")
    sc = JumpScenario(duration=1.0, blend=0.25, dx=(0.05, -0.05, 0.03), base="floating")
    tr = simulate(model, sc, 0.002, failures=[(2, 0.5)])
    assert np.all(tr.qd[10:, 1] == 0.0)
    assert tr.limits.max_deviation < 1e-3
    with pytest.raises(jl.ModelError, match="free-floating"):
        simulate(arm, sc)


def test_cli_fail_at_json(capsys, tmp_path):
    f = tmp_path / "s.toml"
    f.write_text("duration_s = 3.0\nblend_s = 0.75\ndx_m = [0.1, -0.125, 0.07]\n")
    rc = cli_main(["jump", "halt7", "--scenario", str(f), "--fail-at", "1.5", "--json", "--quiet"])
    assert rc == 0
    out = json.loads(capsys.readouterr().out)
    for key in ("kappa", "jump_before", "jump_after", "mean_reduction", "share_improved", "limits_ok"):
        assert key in out
    assert out["jump_after"] <= out["jump_before"]


def test_cli_sweep_and_errors(capsys, tmp_path):
    f = tmp_path / "s.toml"
    f.write_text("duration_s = 3.0\nblend_s = 0.75\ndx_m = [0.1, -0.125, 0.07]\n")
    rc = cli_main(
        ["jump", "canadarm7", "--scenario", str(f), "--sweep", "6", "--order", "2", "--json", "--quiet"]
    )
    out = json.loads(capsys.readouterr().out)
    assert rc == 0 and len(out["jump_before"]) == 60 and 0 <= out["share_improved"] <= 1
    bad = tmp_path / "bad.toml"
    bad.write_text("vmax_deg = 10\n")
    assert cli_main(["jump", "canadarm7", "--scenario", str(bad)]) == 2
    assert "did you mean 'vmax_deg_s'" in capsys.readouterr().err


def test_piecewise_fit_follows_a_step_single_polynomial_cannot():
    """A kappa(t) with a branch switch (like halt7's at 8.5 s): one piece per branch."""
    t = np.arange(1, 41) * 12.0 / 41
    k = np.where(t < 8.4, 1e-4 + 1.5e-5 * t, -4.26e-3)
    cuts = find_breaks(k, 8.8e-3)
    assert cuts.tolist() == [int(np.flatnonzero(t < 8.4)[-1])]
    pieces = fit_pieces(t, k, cuts, order=5, span=(0.0, 12.0))
    assert len(pieces) == 2 and pieces[0].start == 0.0 and pieces[1].end == 12.0
    assert t[cuts[0]] < pieces[0].end == pieces[1].start < t[cuts[0] + 1]
    fitted = np.where(t < pieces[1].start, pieces[0].polynomial(t), pieces[1].polynomial(t))
    assert np.abs(fitted - k).max() < 1e-9
    single = np.polynomial.polynomial.polyval(t / 12, np.polynomial.polynomial.polyfit(t / 12, k, 5))
    assert np.abs(single - k).max() > 5e-4  # the old single polynomial misses both branches
    assert find_breaks(1e-3 * np.sin(t / 4), 8.8e-3).size == 0  # smooth: no break


@pytest.fixture(scope="module")
def halt7_search():
    """halt7, default scenario, with the single-start search: its optimum steps from about
    +2e-4 to the band edge -4.3e-3 at 8.5 s (a search artefact, but a real step to fit)."""
    return jl.load_robot("halt7"), search_kappa(jl.load_robot("halt7"), JumpScenario(), n_starts=1)


def test_halt7_step_piecewise_fit_beats_single_polynomial(halt7_search):
    model, s = halt7_search
    assert s.kappa_opt[s.fail_times < 8.3].max() < 5e-4 and s.kappa_opt[s.fail_times > 8.4][0] < -4e-3
    single = fit_kappa(model, s, piecewise=False)
    v_single = verify_kappa(model, None, single, search=s)
    assert v_single.mean_reduction < 0  # the old behaviour: jumps made worse
    fit = fit_kappa(model, s)
    assert fit.breaks.size >= 1 and 8.2 < fit.breaks[0] < 8.5
    assert fit.search is not None and fit.search.fail_times.size > s.fail_times.size
    assert np.all(np.diff(fit.search.fail_steps) > 0)
    assert len(fit.segments) == fit.breaks.size + 1 and len(fit.pieces) >= 1
    v = verify_kappa(model, None, fit, search=fit.search)
    assert v.mean_reduction > 0.5 and v.share_improved > 0.8
    assert v.mean_reduction == pytest.approx(1 - v.jump_after.mean() / v.jump_before.mean())
    fixed = verify_kappa(model, None, fit, search=fit.search, fix="clip+ramp")
    assert fixed.limits_ok and fixed.mean_reduction > 0.5  # limits still checked and reported


def test_multistart_search_finds_narrow_valley(halt7_search):
    model, s = halt7_search
    i = int(np.argmin(np.abs(s.fail_times - 8.5)))
    multi = search_kappa(model, JumpScenario(), [s.fail_times[i]])
    assert 0 < multi.kappa_opt[0] < 5e-4
    assert multi.objective_opt[0] < 0.3 * s.objective_opt[i]
    assert multi.interval[0, 0] <= multi.kappa_opt[0] <= multi.interval[0, 1]


# -- review fixes ---------------------------------------------------------------------------------


def _ramp_loop(kappa, max_step):
    """The step-by-step ramp_schedule this module used to have (reference)."""
    kap = np.asarray(kappa, dtype=float)
    parts = []
    for part in (np.maximum(kap, 0.0), np.maximum(-kap, 0.0)):
        env = part.copy()
        for k in range(1, env.size):
            env[k] = min(env[k], env[k - 1] + 0.5 * max_step)
        for k in range(env.size - 2, -1, -1):
            env[k] = min(env[k], env[k + 1] + 0.5 * max_step)
        parts.append(env)
    return parts[0] - parts[1]


def test_ramp_schedule_closed_form_equals_the_loop(rng):
    for _ in range(200):
        n = int(rng.integers(1, 400))
        scale = float(rng.choice([1e-4, 1.0, 1e3]))
        k = rng.normal(size=n) * scale
        k[rng.random(n) < 0.3] = 0.0
        step = float(rng.choice([0.0, 1e-3, 0.1, 1.0, 10.0, np.inf])) * scale
        r = ramp_schedule(k, step)
        np.testing.assert_allclose(r, _ramp_loop(k, step), rtol=1e-12, atol=1e-12 * scale)
        assert np.all(np.abs(r) <= np.abs(k))  # exact, despite round-off
    batch = rng.normal(size=(3, 50))
    np.testing.assert_allclose(
        ramp_schedule(batch, 0.2), np.stack([_ramp_loop(b, 0.2) for b in batch]), rtol=1e-12, atol=1e-14
    )
    assert float(ramp_schedule(2.5, 0.1)) == 2.5


def test_ramp_schedule_does_not_loop_in_python(monkeypatch):
    import builtins

    calls = []
    real_min = builtins.min

    def counting_min(*a, **kw):
        calls.append(1)
        return real_min(*a, **kw)

    monkeypatch.setattr(builtins, "min", counting_min)
    ramp_schedule(np.linspace(-1, 1, 1000), 0.01)
    assert not calls


def test_reduction_is_undefined_without_a_jump(arm):
    still = JumpScenario(duration=1.0, blend=0.25, dx=(0.0, 0.0, 0.0))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        r = jl.planning.jump.jump_at_time(arm, still, 0.5, kappa=0.0)
        assert r.jump_before == 0.0 and math.isnan(r.reduction)
        v = verify_kappa(arm, still, 0.0)
        assert math.isnan(v.mean_reduction) and math.isnan(v.share_improved)  # no step with a jump
    assert jump_reduction(2.0, 0.5) == 0.75 and math.isnan(jump_reduction(0.0, 0.0))
    assert math.isnan(jump_reduction(0.0, 1.0))  # a jump the compensation made: no ratio
    # a jump of round-off is none: canadarm7's last joint does not move the tool point, and its
    # "jumps" of 1e-18..1e-17 rad/s gave reductions of 0..99 % that moved with the last bits
    assert math.isnan(jump_reduction(1.2e-17, 2.0e-19)) and jump_reduction(1e-9, 5e-10) == 0.5
    assert math.isnan(improved_share([1e-17, 0.0], [1e-19, 0.0])) and improved_share([1.0, 1e-17], [0.5, 0.0]) == 1.0
    # a jump the compensation made where there was none counts, as not improved
    assert improved_share([1.0, 0.0], [0.5, 0.3]) == 0.5 and improved_share([0.0], [0.3]) == 0.0
    np.testing.assert_array_equal(jump_reduction([1.0, 0.0], [0.5, 0.0]), [0.5, np.nan])


def test_load_jump_task_unreadable_files(tmp_path):
    with pytest.raises(jl.ScenarioError, match="scenario file .* is a folder, not a file"):
        load_jump_task(tmp_path)
    bad = tmp_path / "latin1.toml"
    bad.write_bytes("kp = 1.5 # \xe9\n".encode("latin-1"))
    with pytest.raises(jl.ScenarioError, match="not UTF-8 text"):
        load_jump_task(bad)


# -- UX review: the default task on another robot, run-scenario files --------------------------------


def test_default_task_on_another_robot_says_where_q0_comes_from():
    with pytest.raises(jl.ScenarioError, match="default task's, NOTES-001's start for canadarm7"):
        jl.planning.jump.jump_table(jl.load_robot("puma6"))


def test_load_jump_task_refuses_a_run_scenario_file(tmp_path):
    from pathlib import Path

    example = Path(__file__).resolve().parents[1] / "examples" / "jump_001.toml"
    with pytest.raises(jl.ScenarioError) as err:
        load_jump_task(example)
    msg = str(err.value)
    assert "`jointlock run` scenario file" in msg and "[jump]" in msg and "unknown field" not in msg
    f = tmp_path / "task.toml"
    f.write_text('title = "x"\nq0_deg = [0, 0, 0, 0, 0, 0, 0]\n')
    with pytest.raises(jl.ScenarioError, match="title"):
        load_jump_task(f)
    f.write_text('q0_deg = [10, 40, -70, 100, -60, 30, 20]\nbase = "fixed"\n')  # a task file: fine
    assert load_jump_task(f).base == "fixed"


def test_kappa_unit_is_in_the_figures(tmp_path, monkeypatch):
    import matplotlib.axes

    from jointlock.cli.jump import KAPPA_UNIT

    labels: list[str] = []
    for name in ("set_xlabel", "set_ylabel"):
        real = getattr(matplotlib.axes.Axes, name)

        def spy(self, text, *a, _real=real, **k):
            labels.append(text)
            return _real(self, text, *a, **k)

        monkeypatch.setattr(matplotlib.axes.Axes, name, spy)
    out = tmp_path / "o"
    assert cli_main(["jump", "canadarm7", "--sweep", "4", "--quiet", "--out", str(out)]) == 0
    assert f"kappa [{KAPPA_UNIT}]" in labels  # fig5 x, fig8 y
    assert labels.count(f"kappa [{KAPPA_UNIT}]") >= 2
    jump_labels = [t for t in labels if "jump" in t]
    assert jump_labels and all("deg/s" in t for t in jump_labels)
