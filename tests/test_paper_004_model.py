"""canadarm7 against seed 004: virtual link lengths (§5) and the simplified Jacobian eq. (15).

Provenance: seed 004 §5 (a = c = f = h = k = l = 0.5 m, d = e = 2.5 m, m0 = 1000 kg,
m1 = m2 = m5 = m6 = m7 = 30 kg, m3 = m4 = 100 kg) and its printed virtual lengths
â = 0.38, ĉ = 0.39, d̂ = 2.15, ê = 2.33, f̂ = 0.48, ĥ = 0.49, k̂ = 0.5 (two decimals: half a
unit of the last digit = 0.005 m).  Eq. (15) transcribed in ``docs/readings/canadarm7-004.md``:
rows (v, ω), reference frame Σ_4 = Craig frame {5}, reference point = where axes 5 and 6 meet.
"""

from __future__ import annotations

import numpy as np
import pytest
from conftest import random_q

import jointlock as jl
from jointlock.papers import p004

pytestmark = pytest.mark.paper

#: 004 §5's printed virtual lengths [m] and half a unit of their last printed digit [m].
PRINTED_VIRTUAL = p004.VIRTUAL_LENGTHS
HALF_UNIT = 0.5 * 10.0**-p004.VIRTUAL_LENGTH_DECIMALS


def test_virtual_lengths_reproduce_004_with_its_segment_weighting():
    model = jl.load_robot("canadarm7", base="floating")
    lengths = np.linalg.norm(jl.virtual_link_vectors(model, weighting="segment"), axis=1)
    ours = dict(zip("lacdefhk", lengths))
    for name, printed in PRINTED_VIRTUAL.items():
        assert ours[name] == pytest.approx(printed, abs=HALF_UNIT), name
    # the exact (Vafa-Dubowsky) weighting gives different lengths: d̂ = 2.056, not 2.15
    exact = np.linalg.norm(jl.virtual_link_vectors(model), axis=1)
    assert abs(exact[3] - PRINTED_VIRTUAL["d"]) > 0.05


def eq15(q: np.ndarray, L: dict) -> np.ndarray:
    """004 eq. (15) as printed, (6, 7), for lengths ``L`` (real or virtual)."""
    t1, t2, t3, t4, t5, t6, t7 = q
    S, C = np.sin, np.cos
    a, c, d, e, f, h = L["a"], L["c"], L["d"], L["e"], L["f"], L["h"]
    C345, S345 = C(t3 + t4 + t5), S(t3 + t4 + t5)
    S45, C45, S34, C34 = S(t4 + t5), C(t4 + t5), S(t3 + t4), C(t3 + t4)
    return np.array(
        [
            [
                C(t2) * (a * C345 + e * S(t5) + d * S45) - (c + f) * S(t2) * S345,
                -(c + f) * C345,
                e * S(t5) + d * S45,
                e * S(t5),
                0,
                0,
                -h * C(t6),
            ],
            [
                -(c + f) * S(t2) * C345 + C(t2) * (-a * S345 + e * C(t5) + d * C45),
                (c + f) * S345,
                e * C(t5) + d * C45,
                e * C(t5),
                0,
                0,
                0,
            ],
            [-S(t2) * (a - d * S(t3) - e * S34), d * C(t3) + e * C34, 0, 0, 0, 0, -h * S(t6)],
            [C345 * S(t2), -S345, 0, 0, 0, 0, -S(t6)],
            [-S(t2) * S345, -C345, 0, 0, 0, -1, 0],
            [C(t2), 0, 1, 1, 1, 0, C(t6)],
        ]
    )


def referred(jac: np.ndarray, p_ee: np.ndarray, p_ref: np.ndarray, rot_ref: np.ndarray) -> np.ndarray:
    """Move a twist Jacobian's reference point from p_ee to p_ref and express it in rot_ref."""
    lin = jac[:3] + np.cross(jac[3:].T, p_ref - p_ee).T
    return np.vstack([rot_ref.T @ lin, rot_ref.T @ jac[3:]])


def test_geometric_jacobian_equals_eq15_with_real_lengths(rng):
    model = jl.load_robot("canadarm7")
    for q in random_q(model, rng, (10,)):
        state = jl.chain_state(model, q)
        # reference point: J6 = frame 6 origin (axes 5 and 6 meet); frame: orientation of frame 5
        ours = referred(
            jl.jacobian(model, q, state=state), state.ee_position, state.positions[5], state.rotations[4]
        )
        np.testing.assert_allclose(ours, eq15(q, jl.robots.CANADARM7_LENGTHS), atol=1e-12)


def test_virtual_jacobian_equals_eq15_with_virtual_lengths(rng):
    model = jl.load_robot("canadarm7", base="floating")
    hats = dict(zip("lacdefhk", np.linalg.norm(jl.virtual_link_vectors(model, weighting="segment"), axis=1)))
    for q in random_q(model, rng, (10,)):
        state = jl.chain_state(model, q)
        vm = jl.virtual_manipulator(model, q, weighting="segment")
        ours = referred(vm.jacobian, vm.ee_position, vm.joint_positions[5], state.rotations[4])
        np.testing.assert_allclose(ours, eq15(q, hats), atol=1e-12)


def test_another_frame_reading_does_not_give_eq15(rng):
    """The comparison can fail: the same arm with a 90 deg offset on joint 2 misses eq. (15)."""
    L = jl.robots.CANADARM7_LENGTHS
    deg = np.radians
    other = jl.from_dh(
        "canadarm7-offset",
        a=[0, 0, 0, L["d"], L["e"], 0, 0],
        alpha=deg([0, 90, -90, 0, 0, 90, -90]),
        d=[L["l"], L["a"], L["c"], 0, L["f"], L["h"], 0],
        theta=deg([0, 90, 0, 0, 0, 0, 0]),
        convention="modified",
        tool=np.array([[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, L["k"]], [0, 0, 0, 1.0]]),
    )
    q = random_q(other, rng)
    state = jl.chain_state(other, q)
    ours = referred(
        jl.jacobian(other, q, state=state), state.ee_position, state.positions[4], state.rotations[4]
    )
    assert np.abs(ours - eq15(q, L)).max() > 1e-2
