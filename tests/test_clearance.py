"""Collision geometry and clearance (issue 27): every primitive pair against coal (hpp-fcl),
analytic cases, the built-in arms' shapes, lock invariance, keep-outs and the figures the issue
measured on halt7 (000's halt configuration 0.1 m into the bus; 41 % of the Monte Carlo
population colliding)."""

from __future__ import annotations

import json
import math
from dataclasses import replace

import numpy as np
import pytest

import jointlock as jl
from jointlock._kernels._distance import pair_distances
from jointlock.collision import clearance, collision_pairs, margin_floor, smallest_excess
from jointlock.errors import ConfigurationError, ModelError
from jointlock.geometry import with_link_capsules
from jointlock.shapes import Box, Capsule, Sphere
from jointlock.spatial import translation

coal = pytest.importorskip("coal")

#: Agreement with coal [m] (measured: 1e-14 on every pair, penetration included).
COAL_ATOL = 1e-9


def _coal_capsule(a: np.ndarray, b: np.ndarray, r: float):
    """coal's capsule (centred, along its z) placed on the segment a-b; a sphere if a == b."""
    length = float(np.linalg.norm(b - a))
    if length == 0:
        return coal.Sphere(r), coal.Transform3s(np.eye(3), a)
    z = (b - a) / length
    v = np.cross([0.0, 0.0, 1.0], z)
    s, c = np.linalg.norm(v), z[2]
    if s < 1e-12:
        rot = np.eye(3) if c > 0 else np.diag([1.0, -1.0, -1.0])
    else:
        k = np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])
        rot = np.eye(3) + k + k @ k * ((1 - c) / s**2)
    return coal.Capsule(r, length), coal.Transform3s(rot, (a + b) / 2)


def _coal_distance(g1, t1, g2, t2) -> float:
    request = coal.DistanceRequest()
    request.enable_signed_distance = True
    request.gjk_tolerance = 1e-12
    request.epa_tolerance = 1e-12
    result = coal.DistanceResult()
    coal.distance(g1, t1, g2, t2, request, result)
    return float(result.min_distance)


def _random_rotation(rng: np.random.Generator) -> np.ndarray:
    q, r = np.linalg.qr(rng.normal(size=(3, 3)))
    q = q * np.sign(np.diag(r))
    return q if np.linalg.det(q) > 0 else -q


@pytest.mark.oracle
def test_every_primitive_pair_equals_coal_penetration_included():
    rng = np.random.default_rng(27)
    count = 1500
    caps = rng.normal(size=(count, 2, 6)) * rng.uniform(0.2, 1.5, size=(count, 2, 1))
    caps[::5, 1, 3:] = caps[::5, 1, :3]  # spheres
    caps[1::7, 1, 3:] = caps[1::7, 1, :3] + 2 * (caps[1::7, 0, 3:] - caps[1::7, 0, :3])  # parallel
    caps[2::9, 0, 3:] = caps[2::9, 0, :3]  # sphere against sphere, and against the box
    radii = np.array([0.3, 0.2])
    halves = np.array([[0.5, 0.8, 0.3]])
    boxes = np.empty((count, 1, 12))
    for n in range(count):
        boxes[n, 0] = np.r_[_random_rotation(rng).ravel(), rng.normal(size=3) * 0.5]
    pairs = np.array([[0, 0, 1], [1, 0, 0], [1, 1, 0]], dtype=np.int64)
    dist = np.empty((count, 3))
    closest = np.empty(count, dtype=np.int64)
    witness = np.empty((count, 2, 3))
    pair_distances(caps, radii, boxes, halves, pairs, np.zeros(3), dist, closest, witness)
    box = coal.Box(*(2 * halves[0]))
    expected = np.empty((count, 3))
    for n in range(count):
        g = [_coal_capsule(caps[n, i, :3], caps[n, i, 3:], radii[i]) for i in range(2)]
        frame = coal.Transform3s(boxes[n, 0, :9].reshape(3, 3), boxes[n, 0, 9:])
        expected[n] = [_coal_distance(*g[0], *g[1]), _coal_distance(*g[0], box, frame), _coal_distance(*g[1], box, frame)]
    assert np.max(np.abs(dist - expected)) < COAL_ATOL
    # the sample covers separate and overlapping pairs of each kind
    assert np.all((dist < 0).mean(axis=0) > 0.2) and np.all((dist > 0).mean(axis=0) > 0.2)
    # the witness points of the closest pair are |distance| apart
    gap = np.linalg.norm(witness[:, 1] - witness[:, 0], axis=1)
    assert np.allclose(gap, np.abs(dist[np.arange(count), closest]), atol=1e-12)


def _model_with(shapes_link: list, root_shapes: list) -> jl.ArmModel:
    """A 3-joint arm with the given shapes on its links and root (for analytic cases)."""
    arm = jl.from_dh("probe", a=[0.0, 1.0, 1.0], alpha=[0.0, 0.0, 0.0], d=[0.0, 0.0, 0.0], convention="modified")
    bodies = tuple(replace(b, shapes=tuple(s)) for b, s in zip(arm.bodies, shapes_link))
    return replace(arm, bodies=bodies, root_body=replace(arm.root_body, shapes=tuple(root_shapes)))


def test_analytic_cases():
    # a capsule through the middle of a box along z: the smallest translation out is along
    # x, half the box's x side plus the radius
    box = Box(np.eye(4), [1.0, 2.0, 3.0], name="block")
    through = Capsule([0.0, 0.0, -5.0], [0.0, 0.0, 5.0], 0.25, name="rod")
    keep = clearance(_model_with([[], [], [through]], []), np.zeros(3), keep_out=[box])
    # link 3's frame is 2 m along x at q = 0: the rod passes 1 m beyond the box's face
    assert keep.distance == pytest.approx(1.0 - 0.25, abs=1e-12)
    keep = clearance(_model_with([[], [], [through]], []), [0.0, math.pi / 2, math.pi / 2], keep_out=[box])
    # frame 3 at (1, 1, 0): the rod runs along z through the box, 0 m to its x face: depth 0 + r
    d_face = min(1.0 - 1.0, 2.0 - 1.0)
    assert keep.distance == pytest.approx(-(d_face + 0.25), abs=1e-12)
    # two parallel capsules: gap minus the radii
    pair = _model_with([[Capsule([0, 0, 0], [0, 0, 1], 0.1)], [], [Capsule([0, 0, 0], [0, 0, 1], 0.2)]], [])
    assert clearance(pair, np.zeros(3)).distance == pytest.approx(2.0 - 0.3, abs=1e-12)
    # a sphere at the centre of a box (link 3's origin, 2 m along x at q = 0): the nearest
    # face's half side plus the radius; 0.8 m beside a box at the origin
    sphere = _model_with([[], [], [Sphere([0, 0, 0], 0.5)]], [])
    centred = Box(translation([2.0, 0.0, 0.0]), [0.7, 3, 3])
    assert clearance(sphere, np.zeros(3), keep_out=[centred]).distance == pytest.approx(-(0.7 + 0.5), abs=1e-12)
    beside = Box(np.eye(4), [0.7, 3, 3])
    assert clearance(sphere, np.zeros(3), keep_out=[beside]).distance == pytest.approx(2.0 - 0.7 - 0.5, abs=1e-12)


def test_halt7_halt_configuration_of_000s_scenario_cuts_into_the_bus():
    """Issue 27's measurement (coal on the exported arm): -0.102 m between the boom after joint 3
    and the bus at the demo's halt configuration; the known colliding configuration too."""
    arm = jl.lock(jl.load_robot("halt7", base="floating"), 4, 0.0)
    q = np.radians([-52.51, 65.04, -177.54, -11.49, 140.76, 135.99])
    result = clearance(arm, q)
    assert result.pair_at() == "link3 - bus"
    assert result.distance == pytest.approx(-0.102, abs=5e-4)
    assert result.summary().split(":")[-1].strip() == "COLLIDES"
    known = clearance(arm, np.radians([-174.3, 114.8, 161.0, -173.0, -22.2, -58.4]))
    assert known.distance < 0 and "bus" in known.pair_at()


@pytest.mark.oracle
def test_halt7_population_against_coal_and_the_share_colliding():
    arm = jl.lock(jl.load_robot("halt7"), 4, 0.0)
    q = np.random.default_rng(0).uniform(-np.pi, np.pi, (36000, arm.dof))
    result = clearance(arm, q)
    assert 0.40 < float(np.mean(result.distance < 0)) < 0.43  # the 41 % (coal)
    # every pair of 100 configurations against coal, shape by shape in the root frame
    pairs = collision_pairs(arm)
    state = jl.chain_state(arm, q[:100])
    for n in range(100):
        frames = [np.eye(4)] + [np.block([[state.rotations[n, i], state.positions[n, i][:, None]], [np.zeros((1, 3)), 1.0]]) for i in range(arm.dof)]

        def world(index: int, kind: str, frames: list = frames):
            if kind == "capsule":
                frame = frames[pairs.capsule_body[index] + 1]
                a, b = pairs.capsule_points[index, :3], pairs.capsule_points[index, 3:]
                return _coal_capsule(frame[:3, :3] @ a + frame[:3, 3], frame[:3, :3] @ b + frame[:3, 3], pairs.capsule_radii[index])
            frame = frames[pairs.box_body[index] + 1] @ pairs.box_poses[index]
            return coal.Box(*(2 * pairs.box_halves[index])), coal.Transform3s(frame[:3, :3], frame[:3, 3])

        for p, (kind, i, j) in enumerate(pairs.pairs):
            expected = _coal_distance(*world(i, "capsule"), *world(j, "capsule" if kind == 0 else "box"))
            assert result.pair_distance[n, p] == pytest.approx(expected, abs=COAL_ATOL)


@pytest.mark.parametrize("name", ["halt7", "canadarm7", "puma6"])
def test_locked_model_clearance_equals_the_full_arm_frozen(name):
    full = jl.load_robot(name, base="floating")
    rng = np.random.default_rng(3)
    compared = 0
    for joint in (1, 3, full.dof):
        angle = float(rng.uniform(-2, 2))
        locked = jl.lock(full, joint, angle)
        q = rng.uniform(-np.pi, np.pi, (50, locked.dof))
        a, b = clearance(locked, q), clearance(full, locked.expand(q))
        assert a.names == b.names and a.mounted == b.mounted
        assert np.allclose(a.pair_distance, b.pair_distance, atol=1e-12)
        # witness points of separate shapes (an overlap's deepest point is ambiguous where two
        # directions of escape are equally short, and a tie between pairs may pick either)
        same = (a.closest == b.closest) & (a.distance > 0) & np.isfinite(a.distance)
        assert np.allclose(a.witness[same], b.witness[same], atol=1e-9)
        compared += int(same.sum())
    assert compared > 20


def test_shapes_move_to_the_parent_on_lock_and_the_base_mode_keeps_the_bus():
    locked = jl.lock(jl.load_robot("halt7"), 4, 0.3)
    assert [s.link for s in locked.bodies[2].shapes] == [3, 4]
    assert locked.bodies[2].shapes[1].name == "link4"
    for base in ("fixed", "floating"):
        assert [s.name for s in jl.load_robot("halt7", base=base).root_body.shapes] == ["post", "bus"]
    q = np.random.default_rng(1).uniform(-3, 3, (20, 7))
    assert np.array_equal(
        clearance(jl.load_robot("halt7"), q).pair_distance, clearance(jl.load_robot("halt7", base="floating"), q).pair_distance
    )


def test_pairs_rules_adjacent_same_body_zero_pose_and_keep_outs():
    arm = jl.load_robot("canadarm7")
    pairs = collision_pairs(arm)
    # canadarm7's link 2 starts on the bus's top face (joint 2 stands there): a mounted pair,
    # measured from its depth at the zero pose (its capsule's end 0.1 m into the face)
    assert pairs.mounted == ("link2 - bus",)
    assert pairs.offsets[list(pairs.names).index("link2 - bus")] == pytest.approx(-0.1, abs=1e-12)
    assert all(abs(a - b) > 1 for a, b in pairs.links)
    home = clearance(arm, np.zeros(7), margin=0.05)
    assert not home.colliding() and home.pair_distance[list(home.names).index("link2 - bus")] == pytest.approx(0.0, abs=1e-12)
    assert home.pair_distance[list(home.names).index("link3 - bus")] == pytest.approx(0.5 - 0.1, abs=1e-12)
    # link 2 tipped over about joint 2 (on the face) dips into the bus: deeper than mounted
    tipped = clearance(arm, np.radians([0.0, 180.0, 0.0, 0.0, 0.0, 0.0, 0.0]))
    assert tipped.pair_distance[list(tipped.names).index("link2 - bus")] < -0.1
    # the boom swung down through the bus is caught (review finding: it was once ignored)
    swung = clearance(arm, np.radians([150.9, 117.7, 138.8, 57.7, -91.6, 96.7, -103.8]), margin=0.05)
    assert swung.colliding() and swung.pair_at() == "link3 - bus" and swung.distance < -1.0
    arm = jl.load_robot("halt7")
    tip = jl.ee_pose(arm, np.zeros(7))[:3, 3]
    keep = clearance(arm, np.zeros(7), keep_out=[Sphere(tip, 0.05, name="payload")])
    assert keep.pair_at() == "link6 - payload" or keep.pair_at() == "link7 - payload"
    assert keep.distance == pytest.approx(-0.15, abs=1e-12)
    assert not any("bus - payload" in n or "post - payload" in n for n in keep.names)


def test_batch_shapes_and_plain_data():
    arm = jl.lock(jl.load_robot("puma6"), 2, 0.4)
    q = np.random.default_rng(2).uniform(-3, 3, (2, 3, arm.dof))
    result = clearance(arm, q, margin=0.05)
    assert result.distance.shape == (2, 3) and result.witness.shape == (2, 3, 2, 3)
    assert result.pair_distance.shape == (2, 3, len(result.names))
    assert np.array_equal(result.distance, result.pair_distance.min(axis=-1))
    data = result.to_dict()
    assert data["configurations"] == 6 and data["margin_m"] == 0.05
    allowed = np.where(result.mounted_pairs, 0.0, 0.05)
    assert data["closer_than_allowed"] == int(np.count_nonzero(np.any(result.pair_distance < allowed, axis=-1)))
    assert "configurations closer than allowed" in result.summary()
    # a function, called twice (the module is jointlock.collision: review finding)
    assert jl.clearance(arm, q).distance.shape == jl.clearance(arm, q).distance.shape == (2, 3)
    empty = jl.clearance(arm, np.zeros((0, arm.dof)))
    assert empty.summary().startswith("clearance: no configuration") and empty.to_dict()["checked_pairs"]
    bare = jl.from_dh("bare", a=[0.0, 1.0], alpha=[0.0, 0.0], d=[0.0, 0.0], convention="modified")
    assert clearance(bare, [0.0, 0.0]).summary().startswith("clearance: no pair checked")


def test_bad_input_is_refused_in_one_line():
    arm = jl.load_robot("halt7")
    with pytest.raises(ConfigurationError, match=r"margin must be a finite real number >= 0 and <= 1e\+06 \[m\]; got -0.1"):
        clearance(arm, np.zeros(7), margin=-0.1)
    with pytest.raises(ModelError, match=r"keep_out: shapes\[0\] must be a Capsule, Sphere, Box or Convex"):
        clearance(arm, np.zeros(7), keep_out=["box"])
    with pytest.raises(ModelError, match="radius must be finite, >= 0"):
        Capsule([0, 0, 0], [1, 0, 0], -0.1)
    with pytest.raises(ModelError, match="half_extents must all be > 0"):
        Box(np.eye(4), [1.0, 0.0, 1.0])
    with pytest.raises(ModelError, match="then lock it"):
        with_link_capsules(jl.lock(arm, 2, 0.0), 0.1)
    with pytest.raises(ConfigurationError, match="must have shape"):
        clearance(arm, np.zeros(6))


@pytest.mark.oracle
def test_pinocchio_geometry_model_compute_distances_equals_clearance():
    """Pinocchio's GeometryModel (coal shapes on the joints, jointlock's pairs) and
    computeDistances: the same signed distance for every pair at random configurations."""
    from pin_oracle import pin, pin_q, to_pinocchio, to_pinocchio_geometry

    for name, lock_at in (("halt7", (4, 0.0)), ("canadarm7", (3, 0.4)), ("puma6", None)):
        arm = jl.load_robot(name)
        arm = jl.lock(arm, *lock_at) if lock_at else arm
        pm, _ = to_pinocchio(arm)
        geom, names = to_pinocchio_geometry(arm, pm)
        data, gdata = pm.createData(), pin.GeometryData(geom)
        q = np.random.default_rng(5).uniform(-np.pi, np.pi, (40, arm.dof))
        ours = clearance(arm, q)
        assert ours.names == names
        raw = ours.pair_distance + collision_pairs(arm).offsets  # mounted pairs: from their zero-pose depth
        for n in range(q.shape[0]):
            pin.computeDistances(pm, data, geom, gdata, pin_q(pm, q[n], False))
            theirs = [r.min_distance for r in gdata.distanceResults]
            assert np.allclose(raw[n], theirs, atol=1e-6), name


#: Issue 27's known colliding halt7 configuration (joint 4 at 0): the boom crosses the bus.
KNOWN_COLLIDING_DEG = [-174.3, 114.8, 161.0, -173.0, -22.2, -58.4]


def test_the_search_excludes_configurations_closer_than_required_and_refines_within():
    from jointlock.planning.halt_config import optimal_halt_configuration

    arm = jl.lock(jl.load_robot("halt7", base="floating"), 4, 0.0)
    assert clearance(arm, np.radians(KNOWN_COLLIDING_DEG)).distance < 0
    plain = optimal_halt_configuration(arm, samples=3000, rng=1)
    kept = optimal_halt_configuration(arm, samples=3000, rng=1, clearance_min_m=0.05)
    # the same samples; the admissible ones are exactly those keeping 0.05 m
    assert np.array_equal(plain.q_samples, kept.q_samples)
    assert np.array_equal(kept.reachable, ~clearance(arm, kept.q_samples).colliding(0.05))
    assert kept.colliding_samples == 3000 - int(kept.reachable.sum()) > 0.3 * 3000
    assert plain.colliding_samples is None and plain.best_clearance is not None  # reported either way
    for candidate in (kept.best, kept.best_sample, kept.runner_up):
        assert not clearance(arm, candidate.q).colliding(0.05)
    assert kept.best.cp >= kept.best_sample.cp
    assert kept.to_dict()["clearance"]["colliding_samples"] == kept.colliding_samples
    with pytest.raises(jl.InfeasibleError, match="keeps a clearance of 50 m"):
        optimal_halt_configuration(arm, samples=200, rng=1, clearance_min_m=50.0)
    # the post and link 2 are 0.3 m apart whatever the angles: the error names them
    with pytest.raises(jl.InfeasibleError, match=r"of 0.4 m .*the nearest keeps \+0.300 m between post - link2"):
        optimal_halt_configuration(arm, samples=200, rng=1, clearance_min_m=0.4)


def test_a_given_halt_configuration_closer_than_required_is_refused_naming_the_pair():
    arm = jl.load_robot("halt7", base="floating")
    with pytest.raises(jl.ScenarioError, match=r"qf: the halt configuration keeps -\d\.\d{3} m between link3 - bus"):
        jl.plan_halt("halt7", qf=np.radians(KNOWN_COLLIDING_DEG), motion=jl.HaltMotionSettings(n_samples=101))
    # reported, not refused, when the clearance is not required
    plan = jl.plan_halt(
        "halt7",
        qf=np.radians(KNOWN_COLLIDING_DEG),
        clearance=jl.ClearanceSettings.off(),
        motion=jl.HaltMotionSettings(n_samples=101),
    )
    data = plan.to_dict()["clearance"]
    assert data["halt_configuration_m"] < 0 and data["halt_configuration_pair"] == "link3 - bus"
    assert plan.collision_free is False and plan.summary()[0].startswith("COLLIDES")
    del arm


def test_the_cli_refuses_a_colliding_qf_in_one_line(capsys):
    from jointlock.cli import main

    cmd = ["halt", "halt7", "--qf-deg", *map(str, KNOWN_COLLIDING_DEG), "--n-samples", "101", "--quiet"]
    assert main(cmd) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--qf-deg: the halt configuration keeps" in err[0] and "link3 - bus" in err[0]


def test_000s_scenario_halts_clear_of_the_bus_and_says_where_it_starts():
    """The demo's scenario (HCOM on J_F, halt torque with the spacecraft held): the halt
    configuration keeps the 0.05 m required, and the halt comes no closer to the bus than 000's
    state at failure, which is already 0.051 m into it under halt7's geometry (said first)."""
    from jointlock.papers import p000

    sc = p000.SCENARIO
    plan = jl.plan_halt(
        "halt7",
        search=jl.HaltSearch(samples=4000),
        motion=jl.HaltMotionSettings(n_samples=201),
    )
    motion = plan.clearance()
    assert motion is not None and motion.distance[-1] >= 0.05 - 1e-9
    assert motion.distance[0] == pytest.approx(-0.0510, abs=5e-4)
    # collision free exactly when no pair comes closer than min(required, where it started)
    floor = np.minimum(0.05, motion.pair_distance[0])
    assert plan.collision_free == bool(np.all(motion.pair_distance >= floor))
    data = plan.to_dict()["clearance"]
    assert data["start_pair"] == "link3 - bus" and data["required_m"] == 0.05
    assert plan.summary()[0].startswith(("CLEARANCE: the state at failure already reaches 0.051 m into link3 - bus",
                                         "COLLIDES: the state at failure already reaches 0.051 m into link3 - bus"))
    assert list(sc["q0_deg"]) == [-180.0, -180.0, -100.0, -10.0, 20.0, 20.0]


def test_clearance_settings_are_checked_and_plain():
    with pytest.raises(ConfigurationError, match="clearance min_m must be a finite real number >= 0"):
        jl.ClearanceSettings(min_m=-1.0)
    with pytest.raises(ModelError, match=r"keep_out: shapes\[0\]"):
        jl.ClearanceSettings(keep_out=[1.0])
    assert jl.ClearanceSettings.off().to_dict() == {"min_m": None, "keep_out": []}
    assert jl.ClearanceSettings().margin == 0.05 and not jl.ClearanceSettings.off().required


def test_the_halt_motion_moves_k_to_keep_the_clearance():
    """000's scenario with 2000 samples: the optimum over the limits alone (k* = 7.70e-4
    deg/s^6) drives the boom 3 mm deeper into the bus than the state at failure; the halt keeps
    to the stretch of k whose motions come no closer, and says so."""
    from jointlock.planning.halt_motion import clear_k_segments, clearance_shortfall

    off = jl.plan_halt(
        "halt7",
        clearance=jl.ClearanceSettings.off(),
        search=jl.HaltSearch(samples=2000),
        motion=jl.HaltMotionSettings(n_samples=101),
    )
    kept = jl.plan_halt(
        "halt7",
        search=jl.HaltSearch(samples=2000),
        motion=jl.HaltMotionSettings(n_samples=101),
    )
    assert not np.allclose(off.problem.qf, kept.problem.qf)  # the search moved too
    same_qf = jl.plan_halt(
        "halt7",
        qf=kept.problem.qf,
        clearance=jl.ClearanceSettings.off(),
        motion=jl.HaltMotionSettings(n_samples=101),
    )
    assert same_qf.collision_free is False  # the limits' optimum on this configuration comes closer
    assert kept.collision_free is True and kept.feasible
    assert any(note.startswith("k moved from 0.000770194 to") for note in kept.notes)
    p = kept.problem
    lo, hi = (float(v) for v in same_qf.motion.k_interval)
    segments = clear_k_segments(p, lo, hi, 0.05)
    assert any(a <= float(kept.motion.k) <= b for a, b in segments)
    assert clearance_shortfall(p, np.asarray(float(kept.motion.k)), 0.05) <= 0
    assert clearance_shortfall(p, np.asarray(float(same_qf.motion.k)), 0.05) > 0
    # a boundary of a stretch is refined: just outside it the halt comes closer
    a, b = segments[0]
    width = hi - lo
    outside = [x for x in (a - 1e-6 * width, b + 1e-6 * width) if lo <= x <= hi]
    assert outside and np.all(clearance_shortfall(p, np.asarray(outside), 0.05) > 0)


def test_dh_tables_and_model_files_carry_link_radii_and_a_bus(tmp_path):
    one = jl.from_dh("r", a=[0.0, 1.0, 1.0], alpha=[0.0, 0.0, 0.0], d=[0.3, 0.0, 0.0], convention="modified", radius=0.05)
    assert [s.radius for s in one.root_body.shapes] == [0.05]
    assert [[s.radius for s in b.shapes] for b in one.bodies] == [[0.05], [0.05], [0.05]]
    rows = jl.from_dh(
        "r", a=[0.0, 1.0, 1.0, 0.5], alpha=[0.0] * 4, d=[0.3, 0.0, 0.0, 0.0], convention="modified",
        radius=[0.1, 0.2, 0.3, 0.4], prismatic=[False, False, True, False],
    )  # fmt: skip
    # row 3 is held (prismatic): its link is merged into link 2, so its radius is not used
    assert [[s.radius for s in b.shapes] for b in rows.bodies] == [[0.1], [0.2], [0.4]]
    with pytest.raises(ModelError, match="radius must be a length"):
        jl.from_dh("r", a=[0.0], alpha=[0.0], d=[0.0], convention="modified", radius="thick")
    with pytest.raises(ModelError, match=r"radius must be lengths in \[0"):
        jl.from_dh("r", a=[0.0], alpha=[0.0], d=[0.0], convention="modified", radius=-1.0)
    path = tmp_path / "arm.toml"
    path.write_text(
        'name = "boxed"\nconvention = "dh_modified"\n'
        "[[joint]]\nd_m = 0.5\nradius_m = 0.1\n"
        "[[joint]]\nalpha_deg = 90.0\nradius_m = 0.1\n"
        "[[joint]]\na_m = 2.0\nradius_m = 0.1\n"
        "[base]\nmass_kg = 500.0\ncom_m = [0.0, 0.0, -0.6]\ninertia_kgm2 = [100.0, 100.0, 100.0]\nbox_m = [1.0, 1.0, 1.0]\n"
    )
    for base in ("fixed", "floating"):
        arm = jl.load_robot(str(path), base=base)
        assert [s.name for s in arm.root_body.shapes] == ["post", "bus"]
        # the 2 m link 2 level with the shoulder at q = 0 (0.6 m above the bus top, 0.1 m
        # radius), turned down through it by joint 2
        assert clearance(arm, [0.0, 0.0, 0.0]).distance == pytest.approx(0.6 - 0.1, abs=1e-12)
        down = [clearance(arm, [0.0, side * math.pi / 2, 0.0]) for side in (1, -1)]
        assert min(float(c.distance) for c in down) < 0
        assert all(c.pair_at().endswith(" - bus") for c in down if c.distance < 0)
    path.write_text(path.read_text().replace("box_m = [1.0, 1.0, 1.0]", "box_m = [1.0, 0.0, 1.0]"))
    with pytest.raises(ModelError, match=r"\[base\]: field 'box_m' must be 3 side lengths > 0"):
        jl.load_robot(str(path))


def test_the_3d_view_marks_the_deepest_overlap_frame_by_frame():
    """000's halt starts with the boom 0.051 m into the bus (halt7's geometry): the animated
    view's overlap trace joins the witness points on the first frame, names the pair, and is
    empty once the arm is clear."""
    from jointlock.plots.animation import animation_figure

    plan = jl.plan_halt(
        "halt7",
        search=jl.HaltSearch(samples=500),
        motion=jl.HaltMotionSettings(n_samples=101),
    )
    model, (motion,) = plan.arm_motions()
    fig = animation_figure(model, motion, max_frames=30)
    names = [d.get("name") for d in fig["data"]]
    slot = names.index("overlap (deepest pair)")
    first = fig["data"][slot]
    assert len(first["x"]) == 2 and first["hovertext"][0].startswith("link3 - bus: 0.051 m overlap")
    gap = np.linalg.norm(np.subtract([first["x"][1], first["y"][1], first["z"][1]], [first["x"][0], first["y"][0], first["z"][0]]))
    assert gap == pytest.approx(0.051, abs=5e-4)
    last = fig["frames"][-1]["data"][fig["frames"][-1]["traces"].index(slot)]
    assert last["x"] == []  # the halt configuration keeps its clearance


@pytest.mark.oracle
def test_exported_urdf_collision_geometry_read_back_by_pinocchio_gives_the_same_distances(tmp_path):
    """export-urdf writes each capsule as a cylinder and its two end spheres (URDF has no
    capsule): Pinocchio's buildGeomFromUrdf + computeDistances on the file give, for every
    separate pair of jointlock's, the same distance (the minimum over the parts' pairs); and
    jointlock reads the file back to the same clearance."""
    from pin_oracle import pin

    from jointlock.io.urdf_export import write_urdf

    arm = jl.lock(jl.load_robot("halt7", base="floating"), 4, 0.0)
    path = write_urdf(arm, tmp_path / "arm.urdf")
    model = pin.buildModelFromUrdf(str(path))
    geom = pin.buildGeomFromUrdf(model, str(path), pin.GeometryType.COLLISION)
    # the parts of each of our shapes, in the order they were written (3 for a capsule)
    parts: list[list[int]] = []
    by_joint: dict[int, list[int]] = {}
    for index, obj in enumerate(geom.geometryObjects):
        by_joint.setdefault(obj.parentJoint, []).append(index)
    pairs = collision_pairs(arm)
    shapes = [(-1, s) for s in arm.root_body.shapes] + [(b, s) for b, body in enumerate(arm.bodies) for s in body.shapes]
    cursor = {joint: 0 for joint in by_joint}
    for body, shape in shapes:
        joint = body + 1
        count = 3 if isinstance(shape, Capsule) and shape.length > 0 else 1
        parts.append(by_joint[joint][cursor[joint] : cursor[joint] + count])
        cursor[joint] += count
    assert all(cursor[j] == len(by_joint[j]) for j in by_joint)
    capsule_index = [k for k, (_, s) in enumerate(shapes) if not isinstance(s, Box)]
    box_index = [k for k, (_, s) in enumerate(shapes) if isinstance(s, Box)]
    element_pairs = []
    for kind, i, j in pairs.pairs:
        a, b = parts[capsule_index[i]], parts[capsule_index[j] if kind == 0 else box_index[j]]
        element_pairs.append([(x, y) for x in a for y in b])
        for x, y in element_pairs[-1]:
            geom.addCollisionPair(pin.CollisionPair(x, y))
    index = {(p.first, p.second): k for k, p in enumerate(geom.collisionPairs)}
    data, gdata = model.createData(), pin.GeometryData(geom)
    q = np.random.default_rng(8).uniform(-np.pi, np.pi, (30, arm.dof))
    ours = clearance(arm, q)
    checked = 0
    for n in range(q.shape[0]):
        pin.computeDistances(model, data, geom, gdata, q[n])
        results = gdata.distanceResults
        for p, elems in enumerate(element_pairs):
            if ours.pair_distance[n, p] > 0.01:  # separate: the union's distance is the capsule's
                theirs = min(results[index[e]].min_distance for e in elems)
                assert theirs == pytest.approx(ours.pair_distance[n, p], abs=1e-6)
                checked += 1
    assert checked > 500
    # read back, the joints are numbered 1..n (the merged links 3 and 4 are one link 3, so link 5,
    # now link 4, is adjacent to both): two pairs fewer, the others' distances the same
    back = clearance(jl.read_urdf(path, base="floating"), q)
    assert len(back.names) == len(ours.names) - 2
    assert np.all(back.distance >= ours.distance - 1e-12)
    assert np.mean(np.isclose(back.distance, ours.distance, rtol=0, atol=1e-12)) > 0.9
    found = np.sort(back.pair_distance, axis=1)
    assert all(np.all(np.isin(np.round(found[n], 9), np.round(ours.pair_distance[n], 9))) for n in range(q.shape[0]))


@pytest.mark.oracle
def test_panda_collision_urdf_equals_pinocchio_geometry_model():
    """A real robot's collision geometry: example-robot-data's panda_collision.urdf (capsules
    written as a cylinder and two end spheres, as URDF needs).  jointlock reads each as the
    capsule; between every two links that jointlock checks and that are apart, the smallest
    distance equals Pinocchio's GeometryModel (buildGeomFromUrdf + computeDistances over the
    two links' elements)."""
    from pin_oracle import pin
    from robot_data import robot_file

    path = robot_file("panda_description/urdf/panda_collision.urdf")
    arm = jl.read_urdf(path, tip_link="panda_hand")
    assert any(isinstance(s, Capsule) for b in arm.bodies for s in b.shapes)
    ours_pairs = collision_pairs(arm)
    full = pin.buildModelFromUrdf(str(path))
    geom = pin.buildGeomFromUrdf(full, str(path), pin.GeometryType.COLLISION)
    links = [obj.name.rsplit("_", 1)[0] for obj in geom.geometryObjects]
    link_pairs = sorted({tuple(name.split(" #")[0].split(" - ")) for name in ours_pairs.names})
    for a, b in link_pairs:
        for x in [i for i, n in enumerate(links) if n == a]:
            for y in [i for i, n in enumerate(links) if n == b]:
                geom.addCollisionPair(pin.CollisionPair(x, y))
    data, gdata = full.createData(), pin.GeometryData(geom)
    for request in gdata.distanceRequests:  # coal's GJK to its tightest (default 1e-6 relative)
        request.gjk_tolerance = 1e-12
    q = np.random.default_rng(11).uniform(arm.lower, arm.upper, (25, arm.dof))
    ours = clearance(arm, q)
    checked = exact = 0
    for n in range(q.shape[0]):
        qq = pin.neutral(full)
        qq[: arm.dof] = q[n]  # the arm's joints first; the fingers at 0, as read
        pin.computeDistances(full, data, geom, gdata, qq)
        theirs: dict[tuple[str, str], float] = {}
        for pair, result in zip(geom.collisionPairs, gdata.distanceResults):
            key = (links[pair.first], links[pair.second])
            theirs[key] = min(theirs.get(key, np.inf), result.min_distance)
        raw = ours.pair_distance[n] + ours_pairs.offsets  # mounted pairs: from their zero-pose depth
        for a, b in link_pairs:
            mine = min(d for name, d in zip(ours.names, raw) if name.split(" #")[0] == f"{a} - {b}")
            if mine > 0.01:
                # the same to GJK's tolerance, except where the file's cylinder is not quite
                # between its spheres (the hand's, turned by rpy 1.57, not pi/2: 6e-5 m off), where
                # jointlock's capsule envelope is closer, never farther
                gap = theirs[(a, b)] - mine
                assert -1e-6 <= gap <= 1e-4, (a, b, gap, n)
                exact += abs(gap) <= 1e-6
                checked += 1
    assert checked > 100 and exact > 0.7 * checked


URDF_TWO_LINKS = """<robot name="probe">
  <link name="base"><collision><origin xyz="0 0 -0.5"/><geometry><box size="1 1 1"/></geometry></collision></link>
  <link name="arm">COLLISION</link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
</robot>"""


@pytest.mark.parametrize(
    ("collision", "error"),
    [
        ("<collision><geometry><cone radius='1'/></geometry></collision>", "<cone> is not a URDF geometry"),
        ("<collision><origin xyz='0 0 1'/></collision>", "needs a <geometry>"),
        ("<collision><geometry><sphere radius='-1'/></geometry></collision>", "radius must be finite, > 0"),
        ("<collision><geometry><box size='1 1'/></geometry></collision>", "<box size>"),
    ],
)
def test_urdf_collision_elements_are_refused_in_one_line(tmp_path, collision, error):
    path = tmp_path / "probe.urdf"
    path.write_text(URDF_TWO_LINKS.replace("COLLISION", collision))
    with pytest.raises(ModelError, match=error) as info:
        jl.read_urdf(path)
    assert "link 'arm' <collision> 1" in str(info.value) and "\n" not in str(info.value)


def test_urdf_collision_primitives_are_read_and_meshes_skipped_when_asked(tmp_path):
    path = tmp_path / "probe.urdf"
    path.write_text(
        URDF_TWO_LINKS.replace(
            "COLLISION",
            "<collision><origin xyz='0 0 1'/><geometry><cylinder radius='0.1' length='2'/></geometry></collision>"
            "<collision><geometry><mesh filename='arm.stl'/></geometry></collision>",
        )
    )
    # a mesh that is not there: the model's clearance is refused (a link left geometry-blind is
    # not a safe default), naming the mesh
    unread = jl.read_urdf(path)
    with pytest.raises(ModelError, match=r"link 'arm': mesh file 'arm.stl' not found .*meshes='skip'") as info:
        clearance(unread, np.zeros(1))
    assert "\n" not in str(info.value)
    arm = jl.read_urdf(path, meshes="skip")
    (capsule,) = arm.bodies[0].shapes
    assert isinstance(capsule, Capsule) and np.allclose([capsule.a, capsule.b], [[0, 0, 0], [0, 0, 2]])
    assert [type(s).__name__ for s in arm.root_body.shapes] == ["Box"]
    assert "1 <collision> mesh(es) left out (meshes='skip')" in arm.description


def test_crossing_capsules_have_witness_points_their_depth_apart():
    """Segments that cross (distance 0 up to round-off): the normal is their common normal, and
    the witness points are r1 + r2 apart (review finding: a round-off gap once set it)."""
    rng = np.random.default_rng(4)
    count = 500
    a, b = rng.normal(size=(count, 3)), rng.normal(size=(count, 3))
    u = rng.normal(size=(count, 3))
    mid = (a + b) / 2
    caps = np.empty((count, 2, 6))
    caps[:, 0] = np.hstack([a, b])
    caps[:, 1] = np.hstack([mid - u, mid + u])
    dist, closest, witness = np.empty((count, 1)), np.empty(count, dtype=np.int64), np.empty((count, 2, 3))
    pair_distances(caps, np.array([0.05, 0.05]), np.zeros((count, 1, 12)), np.ones((1, 3)),
                   np.array([[0, 0, 1]], dtype=np.int64), np.zeros(1), dist, closest, witness)  # fmt: skip
    assert np.allclose(dist[:, 0], -0.1, atol=1e-12)
    assert np.allclose(np.linalg.norm(witness[:, 1] - witness[:, 0], axis=1), 0.1, atol=1e-9)


def test_a_report_opens_with_the_clearance_verdict(tmp_path):
    """000's scenario: the state at failure is already 0.051 m into halt7's bus, so the run
    report's first section says so, before the scenario itself."""
    from pathlib import Path

    examples = Path(__file__).resolve().parents[1] / "examples"
    scenario = jl.load_scenario(examples / "halt_000.toml", {"halt_config.samples": 2000, "halt.n_samples": 101})
    jl.run_scenario(scenario).write(tmp_path)
    page = (tmp_path / "report.html").read_text()
    first = page.index("<h2")
    assert page[first:].startswith('<h2 id="') and "Clearance: read this first" in page[first : first + 200]
    assert "the state at failure already reaches 0.051 m into link3 - bus" in page
    assert page.index("Clearance: read this first</h2>") < page.index("Scenario</h2>")


def test_the_per_joint_solver_searches_within_the_halts_that_keep_the_clearance():
    """000's scenario on the configuration whose limits' optimum comes closer (as in
    test_the_halt_motion_moves_k_to_keep_the_clearance): the vector solver's per-joint optimum
    comes closer too, so the halt is the best per-joint k found among the clear halts, from the
    best shared k that keeps the clearance: clear (samples and between them), within each joint's
    interval, no worse than that shared k and no better than the unconstrained per-joint optimum."""
    from jointlock.planning.halt_motion import clearance_shortfall

    kept = jl.plan_halt(
        "halt7",
        search=jl.HaltSearch(samples=2000),
        motion=jl.HaltMotionSettings(n_samples=101),
    )
    alone = jl.plan_halt(
        "halt7",
        qf=kept.problem.qf,
        clearance=jl.ClearanceSettings.off(),
        motion=jl.HaltMotionSettings(n_samples=101, solver="vector"),
    )
    assert alone.motion.per_joint
    assert clearance_shortfall(alone.problem, np.asarray(alone.motion.k), 0.05, per_joint=True) > 0
    vector = jl.plan_halt(
        "halt7",
        qf=kept.problem.qf,
        motion=jl.HaltMotionSettings(n_samples=101, solver="vector"),
    )
    assert vector.motion.per_joint and vector.motion.solver == "vector"
    assert vector.collision_free is True and vector.feasible
    assert vector.notes[0].startswith("solver 'vector': the per-joint optimum comes closer than allowed (0.05 m)")
    assert "the best per-joint k found among the halts that keep it" in vector.notes[0]
    k = np.asarray(vector.motion.k)
    assert clearance_shortfall(vector.problem, k, 0.05, per_joint=True) <= 0
    per = vector.motion.joint_intervals
    assert np.all((per[:, 0] <= k) & (k <= per[:, 1]))
    shared = float(kept.motion.objective_value)
    assert alone.motion.objective_value <= vector.motion.objective_value < shared
    assert vector.motion.objective_value == pytest.approx(
        float(jl.planning.halt_motion.halt_objective(vector.problem, k, per_joint=True)), rel=1e-12
    )
    assert vector.to_dict()["notes"][0] == vector.notes[0]  # said in the JSON too
    from jointlock.errors import ConfigurationError

    with pytest.raises(ConfigurationError, match=r"per_joint: k must be one halt's per-joint k, shape \(6,\)"):
        clearance_shortfall(alone.problem, np.zeros((2, 6)), 0.05, per_joint=True)


@pytest.mark.oracle
def test_the_fused_kernels_primitives_equal_coal():
    """The branch-free distances of the fused kernel (:mod:`jointlock._kernels._lanes`) on
    the random pairs of the scalar kernel's coal test: segment-segment and segment-box, the
    latter where the segment is apart from the box (nearer ones go to the scalar kernel)."""
    from jointlock._kernels._lanes import NEAR_BOX_M, _segment_box_sq, _segments_sq

    rng = np.random.default_rng(28)
    count = 600
    caps = rng.normal(size=(count, 2, 6)) * rng.uniform(0.2, 1.5, size=(count, 2, 1))
    caps[::5, 1, 3:] = caps[::5, 1, :3]  # spheres
    caps[1::7, 1, 3:] = caps[1::7, 1, :3] + 2 * (caps[1::7, 0, 3:] - caps[1::7, 0, :3])  # parallel
    caps[3::11, 1, 3:] = caps[3::11, 1, :3] + np.array([0.4, 0.0, 0.0])  # along a box axis
    radius, halves = 0.1, np.array([0.5, 0.8, 0.3])
    box = coal.Box(*(2 * halves))
    apart = 0
    for n in range(count):
        (a, b), (c, d) = caps[n, 0].reshape(2, 3), caps[n, 1].reshape(2, 3)
        ours = math.sqrt(_segments_sq(*a, *(b - a), *c, *(d - c))) - 2 * radius
        theirs = _coal_distance(*_coal_capsule(a, b, radius), *_coal_capsule(c, d, radius))
        assert abs(ours - theirs) < COAL_ATOL, n
        rot = _random_rotation(rng) if n % 3 else np.eye(3)  # axis-aligned segments too
        centre = rng.normal(size=3) * 0.5
        p, v = rot.T @ (c - centre), rot.T @ (d - c)
        squared = _segment_box_sq(*p, *v, *halves)
        if squared > NEAR_BOX_M**2:
            theirs = _coal_distance(*_coal_capsule(c, d, radius), box, coal.Transform3s(rot, centre))
            assert abs(math.sqrt(squared) - radius - theirs) < COAL_ATOL, n
            apart += 1
        else:
            assert squared <= 1e-20  # near the box means in it, in this sample
    assert apart > count / 3


def test_the_fused_kernels_depth_near_a_box_is_the_scalar_kernels_bit_for_bit():
    """Capsule-box pairs whose segment comes within NEAR_BOX_M of the box go to a branch-free
    copy of the scalar kernel's distance (its pieces between sorted breakpoints, then the
    penetration depth over the box axes and their cross products): the same bits as
    ``_distance._capsule_box`` on segments through the box, inside it, touching a face, lying
    in a face plane, along an edge, parallel to an axis, of zero length, ending on a face, and
    grazing a face or a corner within 1e-9 m, for boxes turned and not, with a pair's offset
    subtracted; several blocks of lanes, a partial one included.  Only the lanes marked NaN
    (near or in the box) are computed again: the others keep their value."""
    from jointlock._kernels._common import BLOCK
    from jointlock._kernels._distance import _capsule_box
    from jointlock._kernels._near_box import _near_box_lanes

    rng = np.random.default_rng(31)
    halves = np.array([0.5, 0.8, 0.3])
    for block in range(24):
        lanes = BLOCK if block < 23 else 37
        rot = np.eye(3) if block % 2 else _random_rotation(rng)
        centre = rng.normal(size=3)
        a = rng.uniform(-1.0, 1.0, (lanes, 3)) * halves * 1.3
        v = rng.normal(size=(lanes, 3)) * rng.uniform(0.0, 2.0, (lanes, 1))
        v[::9] = 0.0  # a sphere
        v[1::9, 1:] = 0.0  # along the box's x axis
        a[2::9, 2] = halves[2]  # in the plane of the top face
        v[2::9, 2] = 0.0
        a[3::9, 1:] = halves[1:]  # along an edge
        v[3::9, 1:] = 0.0
        a[4::9] = halves * np.array([1.0, 0.2, -0.4])  # starting on a face
        a[5::9] = -a[5::9] * 0.1  # from the middle
        v[6::9] = -2.0 * a[6::9]  # through the centre
        a[7::9] = halves * np.sign(rng.normal(size=(len(a[7::9]), 3))) * (1 + 1e-9)  # at a corner
        a[8::9, 0] = halves[0] + rng.uniform(0, 1e-9, len(a[8::9]))  # grazing the +x face
        v[8::9, 0] = 0.0
        ends = np.hstack([a, a + v])  # box frame
        world = np.hstack([ends[:, :3] @ rot.T + centre, ends[:, 3:] @ rot.T + centre])
        caps = np.zeros((6, BLOCK))
        caps[:, :lanes] = world.T
        box = np.zeros((12, BLOCK))
        box[:9, :lanes] = rot.reshape(9, 1)
        box[9:, :lanes] = centre.reshape(3, 1)
        values = np.full(BLOCK, np.nan)
        kept = np.arange(lanes) % 5 == 4  # lanes the fused kernel found apart: left as they are
        values[:lanes][kept] = 7.0
        offset = -0.01 if block % 3 else 0.0
        _near_box_lanes(
            caps, box, values, lanes, np.empty(BLOCK, dtype=np.uint64), *halves, 0.1, offset,
            np.empty(BLOCK), np.empty((6, BLOCK)), np.empty((12, BLOCK)),
        )  # fmt: skip
        w, work = np.empty((2, 3)), np.empty(14)
        pose = np.concatenate([rot.ravel(), centre])
        scalar = np.array([_capsule_box(world[t], 0.1, pose, halves, w, work) for t in range(lanes)]) - offset
        assert np.array_equal(values[:lanes][~kept], scalar[~kept]) and np.all(values[:lanes][kept] == 7.0)
        assert np.any(values[:lanes] < -0.1) and np.any(values[:lanes][~kept] > 0.0)


def _shape_by_shape(model: jl.ArmModel, q: np.ndarray, keep_out=()) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The scalar kernel on shapes placed by numpy's forward kinematics: the fused kernel's
    reference (its pairs' distances, closest pair and witness points)."""
    from jointlock.forward import chain_state

    pairs = collision_pairs(model, keep_out)
    state = chain_state(model, q)
    count = q.shape[0]

    def place(body: int, points: np.ndarray) -> np.ndarray:  # (3,) body frame -> (N, 3) root
        if body < 0:
            return np.broadcast_to(points, (count, 3))
        return np.einsum("nij,j->ni", state.rotations[..., body, :, :], points) + state.positions[..., body, :]

    caps = np.stack(
        [np.hstack([place(b, p[:3]), place(b, p[3:])]) for b, p in zip(pairs.capsule_body, pairs.capsule_points)], axis=1
    )
    boxes = np.empty((count, max(len(pairs.box_body), 1), 12))
    for k, (body, pose) in enumerate(zip(pairs.box_body, pairs.box_poses)):
        rot = pose[:3, :3] if body < 0 else state.rotations[..., body, :, :] @ pose[:3, :3]
        boxes[:, k, :9] = np.broadcast_to(rot, (count, 3, 3)).reshape(count, 9)
        boxes[:, k, 9:] = place(body, pose[:3, 3])
    dist = np.empty((count, len(pairs.names)))
    closest = np.empty(count, dtype=np.int64)
    witness = np.zeros((count, 2, 3))
    halves = pairs.box_halves if len(pairs.box_body) else np.ones((1, 3))
    pair_distances(caps, pairs.capsule_radii, boxes, halves, pairs.pairs, pairs.offsets, dist, closest, witness)
    return dist, closest, witness


def ours_offsets(model: jl.ArmModel, keep_out) -> np.ndarray:
    """(P,) the pairs' zero-pose offsets (a mounted pair's witness points are its raw distance
    apart)."""
    return collision_pairs(model, keep_out).offsets


def _kernel_arm(name: str) -> tuple[jl.ArmModel, tuple]:
    """An arm of the kernels' tests and keep-outs for it: the built-ins, the Panda's collision
    URDF, and the UR5 (joints 2-4 and 6 turn about y: the kernel's z-joint frames differ from
    the bodies') with capsules along its links and a box on a moving link."""
    from robot_data import robot_file

    if name == "panda":
        arm = jl.read_urdf(robot_file("panda_description/urdf/panda_collision.urdf"), tip_link="panda_hand")
    elif name == "ur5":
        arm = with_link_capsules(jl.read_urdf(robot_file("ur_description/urdf/ur5_robot.urdf"), meshes="skip"), 0.04)
        housing = Box(translation([0.05, 0.02, 0.2]) @ np.diag([1.0, -1.0, -1.0, 1.0]), (0.06, 0.05, 0.08), name="housing")
        # one box, on a moving link (two boxes, one moving, go to coal: tests/test_meshes.py)
        bodies = [replace(b, shapes=tuple(s for s in b.shapes if not isinstance(s, Box))) for b in arm.bodies]
        bodies[2] = replace(bodies[2], shapes=bodies[2].shapes + (housing,))
        arm = replace(arm, bodies=tuple(bodies))
        assert any(isinstance(s, Box) and s.link == 3 for s in arm.bodies[2].shapes)
    else:
        arm = jl.load_robot(name)
    keep_out = (
        Box(half_extents=(0.3, 0.2, 0.4), pose=translation([0.8, 0.3, 0.5]), name="dock"),
        Sphere(center=(0.2, -0.6, 0.9), radius=0.25, name="payload"),
    )
    if name == "ur5":
        keep_out = (keep_out[1], Capsule([0.3, 0.3, 0.0], [0.3, 0.3, 0.8], 0.1, name="mast"))
    assert not (collision_pairs(arm, keep_out).pairs[:, 0] == 2).any()
    return arm, keep_out


@pytest.mark.parametrize("name", ["halt7", "canadarm7", "puma6", "panda", "ur5"])
def test_the_fused_kernel_equals_the_scalar_kernel_on_placed_shapes(name):
    """clearance() (frames, placements and distances in one compiled pass) against the scalar
    kernel on shapes placed by numpy: every pair, the closest one and its witness points, on
    random configurations (most halt7 ones colliding), with keep-outs (a box, a sphere), and on
    the UR5 (:func:`_kernel_arm`)."""
    arm, keep_out = _kernel_arm(name)
    q = np.random.default_rng(5).uniform(-np.pi, np.pi, (700, arm.dof))  # > one block of 128
    q[0] = 0.0
    for keep in ((), keep_out):
        dist, closest, witness = _shape_by_shape(arm, q, keep)
        ours = clearance(arm, q, keep_out=keep)
        assert np.allclose(ours.pair_distance, dist, rtol=0, atol=1e-12)
        assert np.array_equal(ours.closest, closest) or np.allclose(
            dist[np.arange(len(q)), ours.closest], dist[np.arange(len(q)), closest], atol=1e-12
        )
        same = ours.closest == closest
        # the witness points' offset (their position along a face parallel to the segment is
        # not unique: any point of it is as deep), and their distance
        offset = ours.witness[:, 1] - ours.witness[:, 0]
        assert np.allclose(offset[same], (witness[:, 1] - witness[:, 0])[same], atol=1e-9)
        counted = np.isfinite(ours.distance)
        gap = np.linalg.norm(offset, axis=1)[counted]
        raw = ours.distance[counted] + ours_offsets(arm, keep)[ours.closest[counted]]
        assert np.allclose(gap, np.abs(raw), atol=1e-9)
        assert np.any(dist < 0) and np.any(dist > 0)
        quick = clearance(arm, q, keep_out=keep, witness=False)
        assert np.array_equal(quick.pair_distance, ours.pair_distance) and np.all(np.isnan(quick.witness))
        assert quick.to_dict()["witness_points_m"] is None


@pytest.mark.parametrize("name", ["halt7", "canadarm7", "puma6", "panda", "ur5"])
def test_the_smallest_excess_is_that_of_every_pairs_distance_bit_for_bit(name):
    """smallest_excess (the jobs' screens: pairs that cannot be the closest, bounded from their
    shapes' centres, are not computed) against clearance()'s every pair: the smallest
    ``pair_distance - floor`` and its first pair, bit for bit.

    Floors: 0; a margin (0 for mounted pairs: ``colliding`` is ``excess < 0``); random per-pair
    ones, negative included; ones larger than the arm (every pair near); and each pair's own
    distance at one configuration (every excess there exactly 0: a tie of every pair, the
    first wins).  Configurations: random ones (most halt7 ones colliding), small motions about
    one (a halt's grid), the zero pose (mounted pairs at their offsets), with and without
    keep-outs (a box, a sphere, a capsule)."""
    arm, keep_out = _kernel_arm(name)
    rng = np.random.default_rng(11)
    wide = rng.uniform(-np.pi, np.pi, (400, arm.dof))
    near = wide[:3, None, :] + rng.normal(0.0, 0.02, (3, 150, arm.dof))  # (3, 150, n): a batch shape
    for keep in ((), keep_out):
        names = collision_pairs(arm, keep).names
        mounted = collision_pairs(arm, keep).offsets < 0
        for q in (wide, near, np.zeros((2, arm.dof))):
            every = clearance(arm, q, keep_out=keep, witness=False).pair_distance
            tie = every.reshape(-1, len(names))[0]
            floors = (
                np.zeros(len(names)),
                margin_floor(arm, 0.05, keep),
                rng.normal(0.0, 0.3, len(names)),
                np.full(len(names), 50.0),
                tie,
            )
            for floor in floors:
                excess, pair = smallest_excess(arm, q, floor, keep_out=keep)
                assert excess.shape == pair.shape == q.shape[:-1]
                assert np.array_equal(excess, (every - floor).min(axis=-1))
                assert np.array_equal(pair, (every - floor).argmin(axis=-1))
            assert np.array_equal(
                smallest_excess(arm, q, margin_floor(arm, 0.05, keep), keep_out=keep)[0] < 0,
                clearance(arm, q, keep_out=keep).colliding(0.05),
            )
            assert np.array_equal(margin_floor(arm, 0.05, keep), np.where(mounted, 0.0, 0.05))
            first = q.reshape(-1, arm.dof)[:1]
            assert smallest_excess(arm, first, tie, keep_out=keep)[1][0] == 0  # every pair tied
    with pytest.raises(ConfigurationError, match=r"floor must be one distance \[m\] per checked pair, shape \(\d+,\); got shape \(2,\)"):
        smallest_excess(arm, wide, np.zeros(2))
    with pytest.raises(ConfigurationError, match=r"floor must be finite \[m\]; got nan \(pair "):
        smallest_excess(arm, wide, np.full(len(collision_pairs(arm).names), np.nan))


def test_the_smallest_excess_keeps_the_pairs_a_computed_distance_makes_the_closest():
    """Where a computed distance errs more than round-off, or round-off grows with the size of
    the numbers, the pair it makes the closest is still computed (from an independent
    review): a keep-out rod crossing halt7's longest boom at its centre 1e-7 rad off parallel
    (the segment distance leaves out the interior point: 5e-9 m too far, against a centre
    bound that is exact), with a far sphere's floor set 5e-9 m below it; and two spheres tied to
    half an ulp under floors of 1e5-1e12 m."""
    arm = jl.load_robot("halt7")
    q = np.full((1, arm.dof), 0.3)
    shapes = collision_pairs(arm)
    state = jl.forward.chain_state(arm, q)
    lengths = np.linalg.norm(shapes.capsule_points[:, 3:] - shapes.capsule_points[:, :3], axis=1)
    c = int(np.argmax(np.where(shapes.capsule_body >= 0, lengths, 0.0)))
    body, points = shapes.capsule_body[c], shapes.capsule_points[c]
    a, b = (state.rotations[0, body] @ points[s] + state.positions[0, body] for s in (slice(0, 3), slice(3, 6)))
    centre, along = 0.5 * (a + b), (b - a) / np.linalg.norm(b - a)
    across = np.cross(along, [1.0, 0.0, 0.0])
    across /= np.linalg.norm(across)
    rod = Capsule(tuple(centre - 0.2 * along - 1e-8 * across), tuple(centre + 0.2 * along + 1e-8 * across), 0.02, name="rod")
    keep = (rod, Sphere(center=(3.0, 3.0, 3.0), radius=0.1, name="ball"))
    names = collision_pairs(arm, keep).names
    d = clearance(arm, q, keep_out=keep, witness=False).pair_distance[0]
    by_rod = min((k for k, name in enumerate(names) if "rod" in name), key=lambda k: d[k])
    by_ball = names.index(names[by_rod].replace("rod", "ball"))
    floor = np.full(len(names), -10.0)
    floor[by_rod] = 0.0
    floor[by_ball] = d[by_ball] - d[by_rod] + 5e-9
    excess, pair = smallest_excess(arm, q, floor, keep_out=keep)
    assert pair[0] == by_ball and excess[0] == (d - floor).min()

    rng = np.random.default_rng(3)
    for _ in range(20):
        keep = tuple(Sphere(center=tuple(rng.uniform(-1.5, 1.5, 3)), radius=0.1, name=n) for n in "AB")
        names = collision_pairs(arm, keep).names
        q = rng.uniform(-np.pi, np.pi, (1, arm.dof))
        d = clearance(arm, q, keep_out=keep, witness=False).pair_distance[0]
        first, second = (min((k for k, name in enumerate(names) if name.endswith(f"- {s}")), key=lambda k: d[k]) for s in "AB")
        for size in 10.0 ** rng.uniform(5, 12, 4):
            for step in range(-3, 4):
                floor = np.full(len(names), size - 1e3)
                floor[first] = size
                floor[second] = size + d[second] - d[first] + step * np.spacing(size) * 0.5
                excess, pair = smallest_excess(arm, q, floor, keep_out=keep)
                assert excess[0] == (d - floor).min() and pair[0] == (d - floor).argmin()


def test_the_singularity_search_may_leave_out_colliding_configurations(tmp_path, capsys):
    """Issue 27: the search's singular configurations closer than the clearance required are
    left out before clustering (each one kept is clear, each one left out is not); reported only,
    the overlapping ones are counted per family; unset, nothing changes (004's way)."""
    from jointlock.cli import main
    from jointlock.jobs.singular import search_singularities

    arm = jl.load_robot("canadarm7")
    plain = search_singularities(arm, samples=96)
    screened = search_singularities(arm, samples=96, clearance=jl.ClearanceSettings(min_m=0.05))
    reported = search_singularities(arm, samples=96, clearance=jl.ClearanceSettings.off())
    assert plain.clearance is None and "clearance" not in plain.to_dict()
    measured = clearance(arm, plain.search.q, margin=0.05)
    closer = measured.colliding()
    report = screened.to_dict()["clearance"]
    assert report["checked"] == len(plain.search.q) and report["left_out"] == report["closer_than_allowed"] == int(closer.sum())
    assert 0 < report["left_out"] < report["checked"]
    np.testing.assert_array_equal(screened.search.q, plain.search.q[~closer])
    assert not clearance(arm, screened.search.q, margin=0.05).colliding().any()
    assert sorted(i for f in screened.search.families for i in f.members) == list(range(len(screened.search.q)))
    assert screened.summary()[0].startswith(f"clearance: {report['left_out']} of {report['checked']} singular configurations")
    overlap = clearance(arm, plain.search.q).colliding()
    kept_all = reported.to_dict()
    assert kept_all["found"] == len(plain.search.q) and kept_all["clearance"]["left_out"] == 0
    assert sum(f["closer_than_allowed"] for f in kept_all["families"]) == int(overlap.sum())
    # the scenario's [singular] skip_colliding, and the command line
    path = tmp_path / "s.toml"
    path.write_text('robot = "canadarm7"\n[singular]\nsearch = true\nsamples = 96\nskip_colliding = true\n')
    from jointlock.jobs.singular import singular_from_scenario

    scenario = jl.load_scenario(path)
    assert singular_from_scenario(scenario.data, {}).to_dict() == screened.to_dict()
    assert main(["singular", "canadarm7", "--search", "--samples", "96", "--skip-colliding", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["clearance"]["left_out"] == report["left_out"]
    assert main(["singular", "canadarm7", "--keep-out", "x.toml"]) == 2
    assert "--keep-out: with --search --skip-colliding only" in capsys.readouterr().err
    path.write_text('robot = "canadarm7"\n[singular]\nskip_colliding = true\n')
    with pytest.raises(jl.ScenarioError, match="singular.skip_colliding: with singular.search = true only"):
        singular_from_scenario(jl.load_scenario(path).data, {})
