"""Batched time stepping of the jump study (issue 13): stepping runs together -- different
failure times and kappa in one batch, and runs after a failure branching off the healthy runs
in the same pass -- gives each run what stepping it alone gives (round-off only)."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

import jointlock as jl
from jointlock.derivatives import jacobian_derivatives
from jointlock.kinematics import chain_state, jacobian
from jointlock.planning.jump import JumpScenario, compensated_rates, simulate
from jointlock.planning.jump._control import (
    CYCLIC,
    RUNNING_SUM_LOOP_FROM,
    _running_sum,
    cross_cyclic,
    law,
)
from jointlock.planning.jump._engine import _branched_runs, _healthy_runs, _integrate, _post_runs, _problem

#: Agreement of a run stepped in a batch and alone, relative to the largest entry [-].
RTOL = 1e-12
#: A shorter task keeps the test fast (40 steps; same law).
TASK = JumpScenario(duration=2.0, blend=0.5, dx=(0.1, -0.12, 0.06))
#: Runs of the batch: (kappa [rad^2/(s m^3)], failure step).
RUNS = [(0.0, 0), (3e-3, 7), (-2e-3, 19), (8e-3, 33), (1e-3, 39)]

ROOT = Path(__file__).resolve().parents[1]


def _close(a: np.ndarray, b: np.ndarray) -> bool:
    return bool(np.all(np.abs(a - b) <= RTOL * max(np.abs(b).max(), 1e-300)))


@pytest.fixture(scope="module")
def prob():
    return _problem(jl.load_robot("canadarm7"), TASK)


def test_a_batch_of_runs_equals_each_run_stepped_alone(prob):
    kap = np.array([k for k, _ in RUNS])
    steps = np.array([s for _, s in RUNS])
    B = len(RUNS)
    out = _integrate(
        prob,
        np.repeat(kap[:, None], prob.N, axis=1),
        np.repeat(prob.q0[None], B, axis=0),
        None,
        np.zeros(B, dtype=int),
        steps[:, None],
        [prob.lock_col],
        record=B,
    )
    assert out.q is not None and out.qd is not None and out.x is not None
    for b, (k, step) in enumerate(RUNS):
        alone = simulate(prob.model, TASK, k, failures=[(TASK.lock_joint, step * TASK.dt)])
        assert _close(out.q[b], alone.q) and _close(out.qd[b], alone.qd) and _close(out.x[b], alone.x)
        assert np.all(out.qd[b, step:, prob.lock_col] == 0.0)  # locked from its failure step on


def test_runs_branching_off_in_the_same_pass_equal_them_stepped_after(prob):
    krows = np.repeat(np.array([[0.0], [4e-3], [-1e-3]]), prob.N, axis=1)
    kidx = np.array([1, 0, 2, 1, 2, 0])
    fsteps = np.array([25, 3, 0, 38, 12, 25])
    healthy, post = _branched_runs(prob, krows, kidx, fsteps)
    # the former way: the healthy runs first, then the post-failure runs from their records
    h_ref = _healthy_runs(prob, krows)
    p_ref, order = _post_runs(prob, krows, h_ref, kidx, fsteps)
    for name in ("q", "qd", "qd_plus", "task_plus", "task_noreplan", "dev", "x"):
        assert _close(getattr(healthy, name), getattr(h_ref, name)), name
    for name in ("max_vel", "max_acc", "max_dev", "min_w"):
        ref = np.empty_like(getattr(p_ref, name))
        ref[order] = getattr(p_ref, name)
        assert _close(getattr(post, name), ref), name
        # and each post-failure run alone, from its own healthy history
        for r in range(kidx.size):
            one, _ = _post_runs(prob, krows, h_ref, kidx[r : r + 1], fsteps[r : r + 1])
            assert _close(getattr(post, name)[r : r + 1], getattr(one, name)), (name, r)


def test_the_fixed_base_frames_equal_the_library_kinematics():
    # arm5 has joints about x and y: the z-joint frames of _FixedChain are not the identity
    for arm in (jl.load_robot("canadarm7"), jl.load_robot(ROOT / "tests" / "data" / "arm5.urdf")):
        rng = np.random.default_rng(3)
        q0 = tuple(rng.uniform(-1.0, 1.0, arm.dof))
        p = _problem(arm, JumpScenario(q0=q0))
        q = np.asarray(q0) + rng.uniform(-0.5, 0.5, (9, arm.dof))
        frame = p.frame(q, None)
        state = chain_state(p.model, q)
        assert _close(frame.x.T, state.ee_position)
        assert _close(np.moveaxis(frame.jac, -1, 0), jacobian(p.model, q)[:, :3])
        assert _close(np.moveaxis(frame.axes, -1, 0), np.swapaxes(state.axes, -1, -2))


def test_the_closed_form_gradient_equals_the_derivatives_one():
    arm = jl.load_robot("canadarm7").fixed()
    rng = np.random.default_rng(5)
    q = np.asarray(JumpScenario().q0) + rng.uniform(-0.4, 0.4, (12, arm.dof))
    healthy = np.ones((12, arm.dof), dtype=bool)
    healthy[np.arange(12), rng.integers(0, arm.dof, 12)] = False  # one joint locked per run
    xdot, kappa = rng.normal(size=(12, 3)), rng.normal(size=12)
    jac = jacobian(arm, q)[:, :3]
    ref, w_ref = compensated_rates(jac, jacobian_derivatives(arm, q)[:, :, :3], xdot, kappa, healthy)
    state = chain_state(arm, q)
    qdot, w, _ = law(np.moveaxis(jac, 0, -1), healthy.T, xdot.T, kappa, axes=np.moveaxis(state.axes, 0, -1).swapaxes(0, 1))
    assert np.all(np.abs(qdot.T - ref) <= 1e-12 * np.abs(ref).max(axis=1, keepdims=True))
    assert _close(w, w_ref)
    assert np.all(qdot.T[~healthy] == 0.0)


@pytest.mark.parametrize("batch", [5, RUNNING_SUM_LOOP_FROM + 3])
@pytest.mark.parametrize("joints", [0, 1, 2, 7])
def test_running_sums_add_as_cumsum_does(batch, joints):
    # below the threshold one cumsum, from it one add per joint in place: the same additions
    # in the same order, so the same values to the bit
    terms = np.random.default_rng(7).normal(size=(3, joints, batch))
    loop = batch >= RUNNING_SUM_LOOP_FROM
    for reverse, ref in ((False, np.cumsum(terms, axis=1)), (True, np.cumsum(terms[:, ::-1], axis=1)[:, ::-1])):
        work = terms.copy()
        got = _running_sum(work, reverse=reverse)
        assert (got is work) == loop  # the branch the batch size asks for ran
        assert np.array_equal(got, ref)


def test_the_cyclic_cross_product_is_the_cross_product():
    a, b = np.random.default_rng(8).normal(size=(2, 3, 7, 11))
    ref = np.moveaxis(np.cross(np.moveaxis(a, 0, -1), np.moveaxis(b, 0, -1)), -1, 0)
    assert _close(cross_cyclic(a[CYCLIC], b[CYCLIC]), ref)


def test_one_lock_step_for_several_joints_locks_them_together(prob):
    # fail_steps with one column and several fail_cols: every listed joint locks at that step
    krows = np.zeros((2, prob.N))
    q0 = np.repeat(prob.q0[None], 2, axis=0)
    k0 = np.zeros(2, dtype=int)
    cols = [0, prob.lock_col]
    one = _integrate(prob, krows, q0, None, k0, np.array([[10], [25]]), cols, record=2)
    each = _integrate(prob, krows, q0, None, k0, np.array([[10, 10], [25, 25]]), cols, record=2)
    assert one.qd is not None and each.qd is not None
    assert np.array_equal(one.qd, each.qd)
    assert np.all(one.qd[0][10:][:, cols] == 0.0)
    assert np.all(one.qd[1][:25][:, cols] != 0.0) and np.all(one.qd[1][25:][:, cols] == 0.0)


def test_the_law_of_a_large_batch_equals_it_in_small_batches():
    # a batch from RUNNING_SUM_LOOP_FROM runs takes the other running-sum branch of the gradient
    arm = jl.load_robot("canadarm7").fixed()
    rng = np.random.default_rng(9)
    runs = 2 * RUNNING_SUM_LOOP_FROM
    q = np.asarray(JumpScenario().q0) + rng.uniform(-0.4, 0.4, (runs, arm.dof))
    frame = _problem(arm, JumpScenario()).frame(q, None)
    healthy = np.ones((arm.dof, runs), dtype=bool)
    healthy[rng.integers(0, arm.dof, runs), np.arange(runs)] = False
    xdot, kappa = rng.normal(size=(3, runs)), rng.normal(size=runs)
    whole = law(frame.jac, healthy, xdot, kappa, axes=frame.axes)
    half = RUNNING_SUM_LOOP_FROM // 2
    for start in range(0, runs, half):
        part = slice(start, start + half)
        small = law(frame.jac[..., part], healthy[:, part], xdot[:, part], kappa[part], axes=frame.axes[..., part])
        for got, ref in zip(whole, small):
            assert _close(got[..., part], ref)


def _spy_jump_kernels(monkeypatch) -> list[str]:
    from jointlock import _kernels

    calls: list[str] = []
    for name in ("fixed_frame", "rate_law", "integrate_steps"):
        real = getattr(_kernels, name)
        monkeypatch.setattr(_kernels, name, lambda *a, _real=real, _name=name: (calls.append(_name), _real(*a))[1])
    return calls


def test_the_compiled_step_equals_the_numpy_one(monkeypatch):
    """issue 29: in the compiled mode "always" the integrator's frame and law run as kernels
    (jointlock._kernels._jump), with numpy's numbers to round-off; a run whose Gram matrix is
    singular (two locked joints of a 3-joint reach) goes to numpy's SVD, as in numpy."""
    monkeypatch.delenv("JOINTLOCK_COMPILED", raising=False)
    calls = _spy_jump_kernels(monkeypatch)
    for arm in (jl.load_robot("canadarm7"), jl.load_robot(ROOT / "tests" / "data" / "arm5.urdf")):
        rng = np.random.default_rng(11)
        q0 = tuple(rng.uniform(-1.0, 1.0, arm.dof))
        p = _problem(arm, JumpScenario(q0=q0))
        runs = 40
        q = np.asarray(q0) + rng.uniform(-0.5, 0.5, (runs, arm.dof))
        healthy = np.ones((arm.dof, runs), dtype=bool)
        healthy[rng.integers(0, arm.dof, runs), np.arange(runs)] = False
        healthy[:, -1] = False
        healthy[:2, -1] = True  # two joints left: J_h J_h^T of rank 2, by the SVD
        xdot, kappa = rng.normal(size=(3, runs)), rng.normal(size=runs)
        frame = p.frame(q, None)
        reference = law(frame.jac, healthy, xdot, kappa, axes=frame.axes)
        with jl.compiled_kernels("always"):
            compiled_frame = p.frame(q, None)
            compiled = law(compiled_frame.jac, healthy, xdot, kappa, axes=compiled_frame.axes)
        for got, ref in ((compiled_frame.x, frame.x), (compiled_frame.jac, frame.jac), (compiled_frame.axes, frame.axes)):
            assert _close(got, ref)
        for got, ref in zip(compiled, reference):
            assert np.all(np.abs(got - ref) <= 1e-11 * np.abs(ref).max())
        assert np.all(compiled[0][~healthy] == 0.0)
    assert calls.count("fixed_frame") == 2 and calls.count("rate_law") == 2  # only in "always"
    with jl.compiled_kernels("always"):  # a mask and a velocity of one run, broadcast as numpy does
        one = law(frame.jac, healthy[:, :1], xdot[:, :1], kappa, axes=frame.axes)
    np.testing.assert_allclose(one[0], law(frame.jac, healthy[:, :1], xdot[:, :1], kappa, axes=frame.axes)[0],
                               rtol=0, atol=1e-11 * np.abs(one[0]).max())  # fmt: skip


def test_a_jump_in_either_mode_gives_the_same_numbers(monkeypatch):
    """001's jump at one failure time with the optimal kappa (the search, then the runs), in
    the compiled mode "always" and in numpy: the same kappa, interval and jumps to round-off."""
    import math

    from jointlock.planning.jump import jump_at_time

    arm = jl.load_robot("canadarm7")
    task = JumpScenario(duration=2.0, blend=0.5, dx=(0.1, -0.12, 0.06), vmax=math.radians(10), amax=math.radians(10),
                        eps=0.01)  # fmt: skip
    monkeypatch.delenv("JOINTLOCK_COMPILED", raising=False)
    reference = jump_at_time(arm, task, 1.0)
    calls = _spy_jump_kernels(monkeypatch)
    with jl.compiled_kernels("always"):
        compiled = jump_at_time(arm, task, 1.0)
    assert "integrate_steps" in calls  # the whole loop compiled (its frame and law inside it)
    assert reference.jump_after < 0.5 * reference.jump_before  # the compensation works here
    for name in ("kappa", "jump_before", "jump_after", "interval", "joint_jump_after"):
        assert np.allclose(getattr(compiled, name), getattr(reference, name), rtol=1e-9, atol=1e-15), name


def _run_out_fields(out) -> dict[str, np.ndarray]:
    from dataclasses import fields

    return {f.name: getattr(out, f.name) for f in fields(out) if getattr(out, f.name) is not None}


def _both_loops(monkeypatch, run) -> tuple[dict, dict, list[str]]:
    """``run()`` (-> a _RunOut) in the compiled mode "always" by the compiled loop and by the
    reference loop (the same frame and law kernels, a Python step each); the kernels the
    compiled loop's run called."""
    from jointlock.planning.jump import _engine

    monkeypatch.delenv("JOINTLOCK_COMPILED", raising=False)
    calls = _spy_jump_kernels(monkeypatch)
    with jl.compiled_kernels("always"):
        compiled = _run_out_fields(run())
        compiled_calls = list(calls)
        with monkeypatch.context() as m:
            m.setattr(_engine, "_compiled_steps", lambda *a: None)
            reference = _run_out_fields(run())
    assert len(calls) > len(compiled_calls)  # the reference loop took its steps by the kernels
    return compiled, reference, compiled_calls


def test_the_compiled_loop_equals_the_python_loop(monkeypatch, prob):
    """issue 29: the integrator's whole loop compiled (jointlock._kernels.integrate_steps) gives
    what its Python loop gives with the same kernels, bit for bit where a step holds two runs
    or more: runs branching off healthy runs (parents, the jump column, records), a stop
    before the end, a task that starts and ends at rest (its first and last steps are
    accelerations too).  With one run, numpy's einsum adds the deviation's three squares in
    another order: the probe's run (and its null-space norm) to an ulp."""
    krows = np.repeat(np.array([[0.0], [4e-3], [-1e-3]]), prob.N, axis=1)
    kidx, fsteps = np.array([1, 0, 2, 1, 2, 0]), np.array([25, 3, 0, 38, 12, 25])
    at_rest = _problem(prob.model, dataclasses.replace(TASK, rest_transitions=True))
    for run, one_run in (
        (lambda: _branched_runs(prob, krows, kidx, fsteps)[0], False),
        (lambda: _branched_runs(prob, krows, kidx, fsteps)[1], False),
        (lambda: _healthy_runs(prob, krows, k_stop=17), False),
        (lambda: _branched_runs(at_rest, krows, kidx, fsteps)[0], False),
        (lambda: _integrate(prob, krows[:1], prob.q0[None], None, np.zeros(1, dtype=int), np.full((1, 1), prob.N + 1),
                            [prob.lock_col], null_norm=True), True),  # fmt: skip
    ):
        compiled, reference, calls = _both_loops(monkeypatch, run)
        assert calls.count("integrate_steps") >= 1 and "rate_law" not in calls  # the loop, not a step
        assert compiled.keys() == reference.keys()
        for name, ref in reference.items():
            if one_run:
                np.testing.assert_allclose(compiled[name], ref, rtol=4e-16, atol=0, err_msg=name)
            else:
                assert np.array_equal(compiled[name].view(np.int64), ref.view(np.int64)), name  # zeros' signs too
        if "qd" in compiled:  # the speed maximum over every joint, the last one included
            assert np.array_equal(compiled["max_vel"], np.abs(compiled["qd"]).max(axis=(1, 2)))
    assert at_rest.scenario.rest_transitions


def test_the_compiled_loop_leaves_singular_and_diverging_steps_to_the_reference(monkeypatch):
    """A step the compiled loop cannot take -- a Gram matrix of rank 2 (three of arm5's five
    joints locked in sequence: numpy's SVD; after 8 such steps in a row the pass goes on in
    Python), every run diverging (refused in one line) -- is taken by the Python step.  A run
    diverging among others is stopped in the kernel as the Python step stops it (recorded,
    then held)."""
    arm = jl.load_robot(ROOT / "tests" / "data" / "arm5.urdf")
    task = JumpScenario(q0=(0.3, -0.6, 0.9, -0.4, 0.5), duration=2.0, blend=0.5, dx=(0.05, -0.04, 0.03))

    def three_locks():
        p = _problem(arm, task)
        steps = np.array([[5, 9, 14]])
        return _integrate(p, np.zeros((1, p.N)), p.q0[None], None, np.zeros(1, dtype=int), steps, [0, 2, 4],
                          record=1)  # fmt: skip

    with pytest.warns(jl.SingularityWarning, match="1 of 1 runs passed within"):  # two joints left
        compiled, reference, calls = _both_loops(monkeypatch, three_locks)
    # steps 0-13 compiled, then 8 refusals in a row, then Python's steps to the end (40 steps)
    assert calls.count("integrate_steps") == 9 and "rate_law" in calls
    for name, ref in reference.items():
        assert _close(compiled[name], ref), name
    assert np.all(compiled["qd"][0, 14:, [0, 2, 4]] == 0.0)

    canadarm = _problem(jl.load_robot("canadarm7"), TASK)
    wild = np.repeat(np.array([[0.0], [1e9]]), canadarm.N, axis=1)  # the second run diverges

    def diverging():
        return _healthy_runs(canadarm, wild)

    compiled, reference, calls = _both_loops(monkeypatch, diverging)
    assert calls.count("integrate_steps") == 1 and "rate_law" not in calls  # stopped in the kernel
    for name, ref in reference.items():
        assert np.array_equal(compiled[name].view(np.int64), ref.view(np.int64)), name  # zeros' signs too
    assert compiled["max_vel"][1] > 1e3 and np.all(compiled["q"][1, 2:] == compiled["q"][1, 1])  # held
    with jl.compiled_kernels("always"), pytest.raises(jl.InfeasibleError, match="kappa is far too large"):
        _healthy_runs(canadarm, wild[1:])


def test_the_compiled_loop_moves_a_progress_bar_once_per_step(monkeypatch, prob):
    class Count:
        done = 0

        def update(self) -> None:
            self.done += 1

    monkeypatch.delenv("JOINTLOCK_COMPILED", raising=False)
    bar = Count()
    with jl.compiled_kernels("always"):
        _healthy_runs(prob, np.zeros((2, prob.N)), progress=bar)
    assert bar.done == prob.N
    arm = jl.load_robot(ROOT / "tests" / "data" / "arm5.urdf")  # Python steps among the compiled ones
    p = _problem(arm, JumpScenario(q0=(0.3, -0.6, 0.9, -0.4, 0.5), duration=2.0, blend=0.5, dx=(0.05, -0.04, 0.03)))
    bar = Count()
    with jl.compiled_kernels("always"), pytest.warns(jl.SingularityWarning):
        _integrate(p, np.zeros((1, p.N)), p.q0[None], None, np.zeros(1, dtype=int), np.array([[5, 9, 14]]), [0, 2, 4],
                   progress=bar)  # fmt: skip
    assert bar.done == p.N
