"""Batched Newton-Euler (000 eqs. 28-31): Pinocchio oracle, dynamics identities, momentum,
locked joints, batching."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import jointlock as jl
import jointlock.model
import jointlock.spatial
from jointlock.dynamics import base_wrench, mass_matrix, rnea

#: Two exact computations of a torque/wrench on 10 m, 100 kg arms [N m]: round-off only
#: (values reach ~1e5 N m for random rates of a few rad/s, eps * 1e5 * n ~ 1e-10).
WRENCH_ATOL = 1e-7
#: Central-difference step along a trajectory [s] and its agreement [N m]: truncation
#: ~ h^2 |L'''| / 6 with |L'''| ~ 1e4 for the halt7 test motion.
FD_DT = 1e-4
FD_WRENCH_ATOL = 1e-3


URDF_ARM = Path(__file__).parent / "data" / "arm5.urdf"


def _arm(name: str = "halt7", base: str = "floating") -> jl.ArmModel:
    """A built-in, or "arm5": the URDF test arm (axes other than z, off-diagonal inertias)."""
    if name == "arm5":
        return jl.read_urdf(URDF_ARM, base=base)
    return jl.load_robot(name, base=base)


def _states(model, rng, shape=(5,)):
    q = rng.uniform(-np.pi, np.pi, shape + (model.dof,))
    dq = rng.uniform(-1.0, 1.0, shape + (model.dof,))
    ddq = rng.uniform(-2.0, 2.0, shape + (model.dof,))
    return q, dq, ddq


@pytest.mark.oracle
@pytest.mark.parametrize("compiled", [False, True])
@pytest.mark.parametrize("name", ["halt7", "canadarm7", "puma6", "arm5"])
def test_rnea_matches_pinocchio(name, compiled, rng):
    po = pytest.importorskip("pin_oracle")
    pin = po.pin
    model = _arm(name)
    pm, _ = po.to_pinocchio(model)
    pm.gravity.linear[:] = [0.0, 0.0, -9.81]
    data = pm.createData()
    q, dq, ddq = _states(model, rng, (4,))
    ours = rnea(model, q, dq, ddq, gravity=[0.0, 0.0, -9.81], compiled=compiled)
    c0 = model.root_body.com
    for i in range(q.shape[0]):
        qq = po.pin_q(pm, q[i], False)
        tau = pin.rnea(pm, data, qq, dq[i], ddq[i])
        pin.forwardKinematics(pm, data, qq)
        rot, p1 = data.oMi[1].rotation, data.oMi[1].translation
        f1, n1 = rot @ data.f[1].linear, rot @ data.f[1].angular
        np.testing.assert_allclose(ours.torques[i], tau, atol=WRENCH_ATOL)
        np.testing.assert_allclose(ours.base_force[i], -f1, atol=WRENCH_ATOL)
        np.testing.assert_allclose(ours.base_moment[i], -(n1 + np.cross(p1 - c0, f1)), atol=WRENCH_ATOL)


@pytest.mark.oracle
@pytest.mark.parametrize("compiled", [False, True])
@pytest.mark.parametrize("name", ["halt7", "arm5"])
def test_floating_base_matches_pinocchio_free_flyer(name, compiled, rng):
    """With the base acceleration we solve for, Pinocchio's free-flyer rnea needs no base
    wrench (the spacecraft is free) and gives the same joint torques."""
    po = pytest.importorskip("pin_oracle")
    pin = po.pin
    model = _arm(name)
    pm, _ = po.to_pinocchio(model, free_flyer=True)
    pm.gravity.linear[:] = 0.0
    data = pm.createData()
    q, dq, ddq = _states(model, rng, (3,))
    res = rnea(model, q, dq, ddq, base="floating", compiled=compiled)
    c0 = model.root_body.com
    for i in range(3):
        v0, w0 = res.base_twist[i, :3], res.base_twist[i, 3:]
        a0, al0 = res.base_acceleration[i, :3], res.base_acceleration[i, 3:]
        v_o = v0 + np.cross(w0, -c0)
        a_o = a0 + np.cross(al0, -c0) + np.cross(w0, np.cross(w0, -c0))
        v = np.concatenate([v_o, w0, dq[i]])
        a = np.concatenate([a_o - np.cross(w0, v_o), al0, ddq[i]])  # body-frame derivative
        tau = pin.rnea(pm, data, po.pin_q(pm, q[i], True), v, a)
        np.testing.assert_allclose(tau[:6], 0.0, atol=WRENCH_ATOL)
        np.testing.assert_allclose(tau[6:], res.torques[i], atol=WRENCH_ATOL)


@pytest.mark.parametrize("name", ["halt7", "puma6"])
def test_rne_is_mass_matrix_plus_bias(name, rng):
    model = _arm(name, "fixed")
    q, dq, ddq = _states(model, rng, (6,))
    m = mass_matrix(model, q)
    lhs = rnea(model, q, dq, ddq).torques
    rhs = np.einsum("...ij,...j->...i", m, ddq) + rnea(model, q, dq, np.zeros_like(ddq)).torques
    np.testing.assert_allclose(lhs, rhs, atol=WRENCH_ATOL)
    np.testing.assert_allclose(m, np.swapaxes(m, -1, -2), atol=1e-9)
    assert np.all(np.linalg.eigvalsh(m) > 0)
    # columns of M from RNE with unit accelerations and no velocity
    eye = np.broadcast_to(np.eye(model.dof), (6, model.dof, model.dof))
    cols = rnea(model, q[:, None, :], np.zeros_like(eye), eye).torques
    np.testing.assert_allclose(np.swapaxes(cols, -1, -2), m, atol=WRENCH_ATOL)


def _smooth_motion(model, t):
    """A smooth joint motion (n_t, n) and its derivatives."""
    n = model.dof
    amp = np.linspace(0.4, 1.0, n)
    freq = np.linspace(0.7, 1.3, n)
    phase = np.linspace(0.0, 2.0, n)
    arg = freq * t[:, None] + phase
    return amp * np.sin(arg), amp * freq * np.cos(arg), -amp * freq**2 * np.sin(arg)


def test_base_moment_is_rate_of_arm_momentum():
    """Fixed base: the wrench on the base is minus the rate of change of the arm's momentum
    (linear, and angular about the spacecraft's centre of mass), by central differences."""
    model = _arm()
    t0 = 0.8
    t = np.array([t0 - FD_DT, t0, t0 + FD_DT])
    q, dq, ddq = _smooth_motion(model, t)
    mom = jl.momentum(model.fixed(), q, dq)  # base still; L about the root origin
    c0 = model.root_body.com
    ang_c0 = mom[:, 3:] - np.cross(c0, mom[:, :3])
    d_lin = (mom[2, :3] - mom[0, :3]) / (2 * FD_DT)
    d_ang = (ang_c0[2] - ang_c0[0]) / (2 * FD_DT)
    w = base_wrench(model, q[1], dq[1], ddq[1])
    np.testing.assert_allclose(w[:3], -d_lin, atol=FD_WRENCH_ATOL)
    np.testing.assert_allclose(w[3:], -d_ang, atol=FD_WRENCH_ATOL)


def test_floating_base_conserves_momentum():
    """Free-floating: total momentum stays zero with the base twist reported, and the base
    acceleration is the inertial derivative of that twist (central differences)."""
    model = _arm()
    t0 = 1.3
    t = np.array([t0 - FD_DT, t0, t0 + FD_DT])
    q, dq, ddq = _smooth_motion(model, t)
    res = rnea(model, q, dq, ddq, base="floating")
    np.testing.assert_allclose(jl.momentum(model, q, dq, res.base_twist), 0.0, atol=1e-8)
    nu = res.base_twist
    w0 = nu[1, 3:]
    d_root = (nu[2] - nu[0]) / (2 * FD_DT)  # derivative of root-frame components
    inertial = np.concatenate([d_root[:3] + np.cross(w0, nu[1, :3]), d_root[3:]])
    np.testing.assert_allclose(res.base_acceleration[1], inertial, atol=1e-5)
    # the arm's wrench on the spacecraft is exactly what accelerates it
    sc = model.root_body
    np.testing.assert_allclose(res.base_force[1], sc.mass * res.base_acceleration[1, :3], atol=WRENCH_ATOL)
    np.testing.assert_allclose(
        res.base_moment[1],
        sc.inertia @ res.base_acceleration[1, 3:] + np.cross(w0, sc.inertia @ w0),
        atol=1e-6,
    )


@pytest.mark.parametrize("base", ["fixed", "floating"])
@pytest.mark.parametrize("joint", [2, 4, 7])
def test_locked_model_equals_frozen_full_model(base, joint, rng):
    full = _arm()
    angle = 0.3
    locked = jl.lock(full, joint, angle)
    q, dq, ddq = _states(locked, rng, (5,))
    i = joint - 1
    qf = locked.expand(q)
    dqf = np.insert(dq, i, 0.0, axis=-1)
    ddqf = np.insert(ddq, i, 0.0, axis=-1)
    a = rnea(locked, q, dq, ddq, base=base)
    b = rnea(full, qf, dqf, ddqf, base=base)
    np.testing.assert_allclose(a.base_wrench, b.base_wrench, atol=WRENCH_ATOL)
    np.testing.assert_allclose(a.torques, np.delete(b.torques, i, axis=-1), atol=WRENCH_ATOL)
    np.testing.assert_allclose(a.base_acceleration, b.base_acceleration, atol=1e-9)


@pytest.mark.parametrize("base", ["fixed", "floating"])
def test_batched_equals_looped(base, rng):
    model = jl.lock(_arm(), 4, 0.0)
    q, dq, ddq = _states(model, rng, (3, 4))
    batched = rnea(model, q, dq, ddq, base=base)
    for i in range(3):
        for j in range(4):
            one = rnea(model, q[i, j], dq[i, j], ddq[i, j], base=base)
            np.testing.assert_allclose(batched.torques[i, j], one.torques, atol=1e-9)
            np.testing.assert_allclose(batched.base_wrench[i, j], one.base_wrench, atol=1e-9)


def test_errors():
    model = _arm("halt7", "fixed")
    z = np.zeros(7)
    with pytest.raises(jl.ModelError, match="free-floating"):
        rnea(model, z, z, z, base="floating")
    with pytest.raises(jl.ModelError, match="gravity"):
        rnea(_arm(), z, z, z, base="floating", gravity=[0, 0, -9.81])
    with pytest.raises(jl.ConfigurationError, match="ddq"):
        rnea(model, z, z, np.zeros(6))


@pytest.mark.oracle
def test_general_axes_match_pinocchio(rng):
    """Joints about non-z axes (the Rodrigues branch) against Pinocchio."""
    po = pytest.importorskip("pin_oracle")
    pin = po.pin
    axes = [(1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.6, 0.0, 0.8), (0.0, 0.0, 1.0)]
    placements = [np.eye(4)] + [jl.spatial.translation([0.3, 0.1, 0.5]) @ jl.spatial.rot_x(0.4)] * 3
    bodies = [jl.Body(5.0 + i, [0.1, 0.05 * i, 0.2], [0.3, 0.4, 0.5]) for i in range(4)]
    model = jl.model.chain_from_placements("axes", placements, bodies, axes=axes)
    pm, _ = po.to_pinocchio(model)
    pm.gravity.linear[:] = 0.0
    data = pm.createData()
    q, dq, ddq = _states(model, rng, (3,))
    ours = rnea(model, q, dq, ddq)
    for i in range(3):
        tau = pin.rnea(pm, data, po.pin_q(pm, q[i], False), dq[i], ddq[i])
        np.testing.assert_allclose(ours.torques[i], tau, atol=WRENCH_ATOL)
