"""A precomputed chain state is used only for the joint angles it was computed at; the
position-only forward kinematics equals the full one; kinematics and dynamics share their
chain arithmetic without importing each other upwards; the link constants are cached by the
model's numbers, not by object identity."""

from __future__ import annotations

import ast
import dataclasses
from pathlib import Path

import numpy as np
import pytest
from conftest import ROBOT_NAMES, random_q

import jointlock as jl
from jointlock import _chain, derivatives, dynamics, kinematics
from jointlock.analysis import workspace
from jointlock.errors import ConfigurationError

SRC = Path(jl.__file__).parent

#: Every public function taking ``q`` and ``state=``, called with the state by keyword.
STATE_FUNCTIONS = {
    "jacobian": lambda m, q, s: kinematics.jacobian(m, q, state=s),
    "jacobian_ee": lambda m, q, s: kinematics.jacobian(m, q, frame="ee", state=s),
    "generalized_jacobian": lambda m, q, s: kinematics.generalized_jacobian(m, q, state=s),
    "com_positions": lambda m, q, s: kinematics.com_positions(m, q, state=s),
    "com_jacobians": lambda m, q, s: kinematics.com_jacobians(m, q, state=s),
    "momentum_matrix": lambda m, q, s: kinematics.momentum_matrix(m, q, state=s),
    "base_jacobian": lambda m, q, s: kinematics.base_jacobian(m, q, state=s),
    "system_com": lambda m, q, s: kinematics.system_com(m, q, state=s),
    "mass_matrix": lambda m, q, s: dynamics.mass_matrix(m, q, state=s),
    "system_mass_matrix": lambda m, q, s: dynamics.system_mass_matrix(m, q, state=s),
    "jacobian_derivatives": lambda m, q, s: derivatives.jacobian_derivatives(m, q, state=s),
}


@pytest.fixture
def arm() -> jl.ArmModel:
    return jl.load_robot("halt7", base="floating")


@pytest.mark.parametrize("name", sorted(STATE_FUNCTIONS))
def test_state_of_other_angles_raises(name, arm, rng):
    fn = STATE_FUNCTIONS[name]
    q1, q2 = random_q(arm, rng, (2, 3))
    state = jl.chain_state(arm, q1)
    with pytest.raises(ConfigurationError, match="state was computed at other joint angles"):
        fn(arm, q2, state)
    q_close = q1.copy()
    q_close[1, 2] += 1e-15  # exact comparison: any difference is another configuration
    with pytest.raises(ConfigurationError, match="other joint angles"):
        fn(arm, q_close, state)
    with pytest.raises(ConfigurationError, match="shape"):
        fn(arm, q1[None], state)  # another batch shape, same numbers


@pytest.mark.parametrize("name", sorted(STATE_FUNCTIONS))
def test_state_of_the_same_angles_is_used(name, arm, rng):
    fn = STATE_FUNCTIONS[name]
    q = random_q(arm, rng, (2, 3))
    state = jl.chain_state(arm, q)
    expected = fn(arm, q, None)
    for q_given in (q, q.copy(), q.tolist(), state.q, None):  # None: the state's own angles
        np.testing.assert_array_equal(fn(arm, q_given, state), expected)


@pytest.mark.parametrize("name", sorted(STATE_FUNCTIONS))
def test_neither_q_nor_state_raises(name, arm):
    with pytest.raises(ConfigurationError, match="give the joint angles q or a precomputed state"):
        STATE_FUNCTIONS[name](arm, None, None)


def test_state_of_a_model_with_other_joints_raises(arm, rng):
    locked = jl.lock(arm, 4, 0.0)
    state = jl.chain_state(locked, random_q(locked, rng))
    with pytest.raises(ConfigurationError, match="state has 6 joints but model"):
        jl.jacobian(arm, None, state=state)
    with pytest.raises(ConfigurationError, match="ChainState"):
        jl.jacobian(arm, None, state=np.zeros(7))


def test_state_keeps_a_read_only_copy_of_its_angles(arm, rng):
    q = random_q(arm, rng, (4,))
    state = jl.chain_state(arm, q)
    assert state.q is not q and not state.q.flags.writeable
    np.testing.assert_array_equal(state.q, q)
    expected = jl.jacobian(arm, q)
    q[0, 0] += 0.5  # the caller moves its array on: the state still belongs to the old angles
    with pytest.raises(ConfigurationError, match="other joint angles"):
        jl.jacobian(arm, q, state=state)
    np.testing.assert_array_equal(jl.jacobian(arm, None, state=state), expected)


def test_select_chooses_the_angles_with_the_frames(arm, rng):
    qa, qb = random_q(arm, rng, (2, 5))
    mask = np.array([True, False, True, False, False])
    chosen = jl.ChainState.select(mask, jl.chain_state(arm, qa), jl.chain_state(arm, qb))
    q = np.where(mask[:, None], qa, qb)
    np.testing.assert_array_equal(chosen.q, q)
    np.testing.assert_array_equal(jl.jacobian(arm, q, state=chosen), jl.jacobian(arm, q))
    with pytest.raises(ConfigurationError, match="other joint angles"):
        jl.jacobian(arm, qa, state=chosen)


def test_state_at_returns_the_given_state(arm, rng):
    q = random_q(arm, rng, (3,))
    state = jl.chain_state(arm, q)
    assert kinematics.state_at(arm, q, state) is state
    assert kinematics.state_at(arm, None, state) is state
    fresh = kinematics.state_at(arm, q)
    np.testing.assert_array_equal(fresh.soa_rotations, state.soa_rotations)


# -- position-only forward kinematics ----------------------------------------------------------


def _models():
    for name in ROBOT_NAMES:
        for base in ("fixed", "floating"):
            model = jl.load_robot(name, base=base)
            yield f"{name}-{base}", model
            yield f"{name}-{base}-lock2", jl.lock(model, 2, 0.3)
    yield "arm5-urdf", jl.load_robot(Path(__file__).parent / "data" / "arm5.urdf")


@pytest.mark.parametrize(("label", "model"), list(_models()), ids=lambda x: x if isinstance(x, str) else "")
def test_ee_positions_equal_the_pose_translation(label, model, rng):
    q = random_q(model, rng, (3, 40))
    fast = kinematics.ee_positions(model, q)
    assert fast.shape == (3, 40, 3)
    np.testing.assert_allclose(fast, jl.ee_pose(model, q)[..., :3, 3], rtol=0, atol=1e-12)
    np.testing.assert_allclose(fast, jl.chain_state(model, q).ee_position, rtol=0, atol=1e-12)


def test_ee_positions_batched_equals_looped(rng):
    model = jl.lock(jl.load_robot("puma6"), 3, -0.4)
    q = random_q(model, rng, (2, 7))
    batched = kinematics.ee_positions(model, q)
    looped = np.array([[kinematics.ee_positions(model, qq) for qq in row] for row in q])
    np.testing.assert_array_equal(batched, looped)
    assert kinematics.ee_positions(model, q[0, 0]).shape == (3,)
    np.testing.assert_array_equal(
        kinematics.ee_positions(model, q, chunk=3), batched
    )  # chunks change nothing
    assert kinematics.ee_positions(model, np.zeros((0, model.dof))).shape == (0, 3)


def test_ee_positions_errors():
    model = jl.load_robot("puma6")
    with pytest.raises(ConfigurationError, match="chunk"):
        kinematics.ee_positions(model, np.zeros(6), chunk=0)
    with pytest.raises(ConfigurationError, match=r"shape \(\.\.\., 6\)"):
        kinematics.ee_positions(model, np.zeros(5))


def test_workspace_uses_the_kinematics_engine():
    assert workspace.ee_positions is kinematics.ee_positions
    assert workspace.DEFAULT_CHUNK == kinematics.DEFAULT_CHUNK


# -- one-way imports and caches -----------------------------------------------------------------


def _imported_modules(path: Path) -> set[str]:
    """Every module a source file imports, at top level or inside functions (relative
    imports resolved to ``jointlock.*``)."""
    package = "jointlock" + "".join(f".{p}" for p in path.parent.relative_to(SRC).parts)
    out = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            out.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = package.rsplit(".", node.level - 1)[0] if node.level else ""
            mod = ".".join(x for x in (base, node.module or "") if x)
            out.add(mod)
            out.update(f"{mod}.{alias.name}" for alias in node.names)
    return out


#: What each low module may import from the package (function-level imports included).
LOW_MODULES = {
    "_rows": set(),
    "spatial": set(),
    "_chain": {"_rows", "model", "_cache"},
    "forward": {"_chain", "errors", "model", "spatial", "_kernels", "compiled"},
    "kinematics": {"_chain", "bounds", "errors", "forward", "model", "_kernels", "compiled"},
}


@pytest.mark.parametrize("module", sorted(LOW_MODULES))
def test_low_modules_never_import_dynamics(module):
    imported = {m for m in _imported_modules(SRC / f"{module}.py") if m.startswith("jointlock")}
    top = {m.split(".")[1] for m in imported if m.count(".") >= 1}
    assert top <= LOW_MODULES[module], top - LOW_MODULES[module]
    assert "dynamics" not in top


def test_link_constants_are_keyed_by_the_model_numbers(arm):
    for module in (kinematics, dynamics, _chain):  # no module-level table keyed by id(model)
        assert not [k for k, v in vars(module).items() if isinstance(v, dict) and not k.startswith("__")]
    origin = np.zeros(3)
    links = _chain.link_constants(arm, origin)
    twin = dataclasses.replace(arm, name="another name, same numbers")
    assert _chain.link_constants(twin, origin) is links
    heavier = jl.Body(arm.bodies[2].mass + 1.0, arm.bodies[2].com, arm.bodies[2].inertia)
    other = dataclasses.replace(arm, bodies=arm.bodies[:2] + (heavier,) + arm.bodies[3:])
    assert _chain.link_constants(other, origin) is not links
    assert _chain.link_constants(other, origin)[2].mass == links[2].mass + 1.0
    assert _chain.link_constants(arm, arm.root_body.com) is not links  # another origin
    assert not links[0].rot.flags.writeable  # shared through the cache: read-only


def test_rnea_follows_the_model_not_a_stale_cache(rng):
    """Models made and dropped in a loop (ids get recycled) each get their own dynamics."""
    base = jl.load_robot("puma6")
    q, dq, ddq = random_q(base, rng, (3, 5))
    for mass in (1.0, 2.0, 3.0):
        bodies = tuple(jl.Body(mass * b.mass, b.com, mass * b.inertia) for b in base.bodies)
        model = dataclasses.replace(base, bodies=bodies)
        np.testing.assert_allclose(
            dynamics.rnea(model, q, dq, ddq).torques,
            mass * dynamics.rnea(base, q, dq, ddq).torques,
            rtol=1e-12,
        )
        del model


def test_a_state_of_another_arm_is_refused():
    """A state is tied to the arm it was computed for, not only to its joint count."""
    halt7 = jl.load_robot("halt7")
    third, fourth = jl.lock(halt7, 3, 0.0), jl.lock(halt7, 4, 0.0)  # same joint count, other arms
    q = np.zeros(6)
    with pytest.raises(jl.ConfigurationError, match="computed for another arm"):
        jl.jacobian(third, q, state=jl.chain_state(fourth, q))
    # an equal copy of the same arm (e.g. unpickled in a worker) is the same arm
    import pickle

    copy = pickle.loads(pickle.dumps(fourth))
    np.testing.assert_array_equal(jl.jacobian(copy, q, state=jl.chain_state(fourth, q)), jl.jacobian(fourth, q))


def test_ee_pose_of_a_large_batch_is_computed_in_chunks(monkeypatch):
    """Issue 13, bounded memory: ee_pose holds one chunk's frames at a time; the poses are
    those of the whole-batch chain state."""
    from jointlock import forward

    model = jl.lock(jl.load_robot("canadarm7"), 2, 0.3)
    q = np.random.default_rng(11).uniform(-np.pi, np.pi, (5, 13, model.dof))
    s = forward.chain_state(model, q)
    whole = jl.spatial.pose(s.ee_rotation, s.ee_position)
    calls = []
    real = forward.chain_state
    monkeypatch.setattr(forward, "chain_state", lambda m, x: (calls.append(np.shape(x)), real(m, x))[1])
    monkeypatch.setattr(forward, "DEFAULT_CHUNK", 20)
    chunked = forward.ee_pose(model, q)
    assert chunked.shape == (5, 13, 4, 4)
    assert calls == [(20, model.dof)] * 3 + [(5, model.dof)]
    np.testing.assert_allclose(chunked, whole, rtol=0, atol=1e-14)
