"""URDF meshes as convex hulls (issue 27): read through trimesh, distances through coal.

Oracles: a mesh of a box gives the box primitive's distances (jointlock's exact compiled
kernel); the UR5 of example-robot-data gives the distances of its meshes as Pinocchio reads and
places them (assimp), turned into coal's own convex hulls; the locked model equals the full one
frozen; exports read back give the same hulls.

(Pinocchio's ``buildConvexRepresentation`` route -- a BVH's ``.convex`` put in the geometry
model -- gave distances larger than the nearest pair of hull vertices on this UR5, which no
distance between the hulls can be: not used as an oracle.)
"""

from __future__ import annotations

import sys

import numpy as np
import pytest

import jointlock as jl
from jointlock.collision import clearance, collision_pairs, margin_floor, smallest_excess
from jointlock.errors import ModelError
from jointlock.geometry import with_root_shapes
from jointlock.io.urdf_export import write_urdf
from jointlock.shapes import Box, Capsule, Convex, Sphere

trimesh = pytest.importorskip("trimesh")
pytest.importorskip("coal")

UR5 = "ur_description/urdf/ur5_robot.urdf"

URDF = """<robot name="probe">
  <link name="base"><collision><origin xyz="0 0 -0.6"/><geometry><cylinder radius="0.3" length="0.4"/></geometry></collision></link>
  <link name="l1"/>
  <link name="l2"><collision><origin xyz="0.4 0 0" rpy="0.3 -0.2 0.5"/><geometry>GEOMETRY</geometry></collision></link>
  <link name="l3"><collision><origin xyz="0.3 0 0"/><geometry><cylinder radius="0.08" length="0.6"/></geometry></collision></link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/><origin xyz="0 0 0.2"/><axis xyz="0 1 0"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="j3" type="revolute"><parent link="l2"/><child link="l3"/><origin xyz="0.8 0 0"/><axis xyz="0 1 0"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
</robot>"""


def _probe(tmp_path, geometry: str, **kwargs) -> jl.ArmModel:
    path = tmp_path / "probe.urdf"
    path.write_text(URDF.replace("GEOMETRY", geometry))
    return jl.read_urdf(path, **kwargs)


def test_a_box_mesh_gives_the_box_primitives_distances_penetration_included(tmp_path):
    """coal's GJK/EPA on the hull of a box mesh (scaled, placed by the collision origin) against
    jointlock's exact segment-box kernel on the <box>: every pair, apart and overlapping."""
    trimesh.creation.box(extents=(1.0, 1.0, 1.0)).export(tmp_path / "cube.stl")
    meshed = _probe(tmp_path, '<mesh filename="cube.stl" scale="0.5 0.3 0.2"/>')
    boxed = _probe(tmp_path, '<box size="0.5 0.3 0.2"/>')
    (hull,) = meshed.bodies[1].shapes
    assert isinstance(hull, Convex) and hull.vertices.shape == (8, 3) and hull.source.endswith("cube.stl")
    assert isinstance(boxed.bodies[1].shapes[0], Box)
    keep_out = (Capsule((0.5, -0.3, 0.2), (0.9, 0.4, 0.6), 0.1, name="probe"), Sphere((-0.6, 0.2, 0.3), 0.2, name="ball"))
    q = np.random.default_rng(2).uniform(-3, 3, (300, 3))
    ours = clearance(meshed, q, keep_out=keep_out)
    reference = clearance(boxed, q, keep_out=keep_out)
    assert sorted(ours.names) == sorted(reference.names)
    same = [reference.names.index(name) for name in ours.names]
    assert np.allclose(ours.pair_distance, reference.pair_distance[:, same], rtol=0, atol=1e-9)
    hull_pairs = [k for k, name in enumerate(ours.names) if "l2" in name]
    assert np.any(ours.pair_distance[:, hull_pairs] < 0) and np.any(ours.pair_distance[:, hull_pairs] > 0)
    assert np.allclose(ours.distance, reference.distance, atol=1e-9)
    # witness points: |w2 - w1| = |distance| wherever a hull pair is the closest
    by_hull = np.isin(ours.closest, hull_pairs)
    gap = np.linalg.norm(ours.witness[by_hull, 1] - ours.witness[by_hull, 0], axis=1)
    assert by_hull.any() and np.allclose(gap, np.abs(ours.distance[by_hull]), atol=1e-9)
    # the screens' smallest excess with a hull: from every pair's distance, the same bits
    floor = margin_floor(meshed, 0.05, keep_out)
    excess, pair = smallest_excess(meshed, q, floor, keep_out=keep_out)
    assert np.array_equal(excess, (ours.pair_distance - floor).min(axis=1))
    assert np.array_equal(pair, (ours.pair_distance - floor).argmin(axis=1)) and np.isin(pair, hull_pairs).any()


def test_ur5_meshes_equal_coal_hulls_of_pinocchios_meshes():
    """example-robot-data's UR5 (STL collision meshes).  The oracle reads it independently:
    Pinocchio's GeometryModel (buildGeomFromUrdf: meshes loaded by assimp, placed by Pinocchio's
    kinematics), each mesh turned into coal's own convex hull (ConvexBase.convexHull, coal's
    Qhull), distances by coal.distance: equal to jointlock's pair by pair.  And the mesh itself
    (Pinocchio's computeDistances on the raw meshes) is never nearer than its hull."""
    import coal
    from pin_oracle import pin
    from robot_data import robot_file

    path = robot_file(UR5)
    arm = jl.read_urdf(path)
    assert all(isinstance(s, Convex) for b in arm.bodies[:5] for s in b.shapes)
    full = pin.buildModelFromUrdf(str(path))
    packages = str(path.parents[4])  # .../share: holds example-robot-data/
    geom = pin.buildGeomFromUrdf(full, str(path), pin.GeometryType.COLLISION, package_dirs=[packages])
    links = [obj.name.rsplit("_", 1)[0] for obj in geom.geometryObjects]
    hulls = []
    for obj in geom.geometryObjects:
        g = obj.geometry
        if hasattr(g, "vertices"):
            points = coal.StdVec_Vec3s()
            for v in np.asarray(g.vertices()):
                points.append(np.array(v))
            g = coal.Convex.convexHull(points, False, "")
        hulls.append(g)
    names = collision_pairs(arm).names
    index = [(links.index(a), links.index(b)) for a, b in (name.split(" - ") for name in names)]
    for a, b in index:
        geom.addCollisionPair(pin.CollisionPair(a, b))
    data, gdata = full.createData(), pin.GeometryData(geom)
    request = coal.DistanceRequest()
    request.enable_signed_distance = True
    request.gjk_tolerance = request.epa_tolerance = 1e-12
    q = np.random.default_rng(3).uniform(-np.pi, np.pi, (20, arm.dof))
    ours = clearance(arm, q)
    for n in range(len(q)):
        pin.computeDistances(full, data, geom, gdata, q[n])
        theirs = np.empty(len(index))
        for k, (a, b) in enumerate(index):
            result = coal.DistanceResult()
            place = [coal.Transform3s(gdata.oMg[i].rotation, gdata.oMg[i].translation) for i in (a, b)]
            coal.distance(hulls[a], place[0], hulls[b], place[1], request, result)
            theirs[k] = result.min_distance
        assert np.allclose(ours.pair_distance[n], theirs, rtol=0, atol=1e-9), n
        apart = theirs > 1e-3
        meshes = np.array([r.min_distance for r in gdata.distanceResults])
        assert np.all(meshes[apart] >= ours.pair_distance[n, apart] - 1e-9)
    assert np.any(ours.pair_distance < 0) and np.any(ours.pair_distance > 0.05)


def test_a_locked_ur5_has_the_full_arms_hull_distances_with_the_joint_frozen():
    from robot_data import robot_file

    arm = jl.read_urdf(robot_file(UR5))
    locked = jl.lock(arm, 3, 0.7)
    q = np.random.default_rng(4).uniform(-np.pi, np.pi, (15, locked.dof))
    frozen = np.insert(q, 2, 0.7, axis=1)
    mine, theirs = clearance(locked, q), clearance(arm, frozen)
    kept = [theirs.names.index(name) for name in mine.names]
    assert np.allclose(mine.pair_distance, theirs.pair_distance[:, kept], atol=1e-9)


def test_meshes_skip_and_missing_extras_are_said_in_one_line(tmp_path, monkeypatch):
    trimesh.creation.box(extents=(1.0, 1.0, 1.0)).export(tmp_path / "cube.stl")
    skipped = _probe(tmp_path, '<mesh filename="cube.stl"/>', meshes="skip")
    assert skipped.bodies[1].shapes == () and "1 <collision> mesh(es) left out" in skipped.description
    with pytest.raises(ModelError, match=r"meshes must be one of convex, skip; got 'hull'"):
        _probe(tmp_path, '<mesh filename="cube.stl"/>', meshes="hull")
    # a mesh that cannot be read leaves the model usable, but its clearance refuses it in one line
    lost = _probe(tmp_path, '<mesh filename="package://nowhere/cube.stl"/>')
    assert "1 <collision> mesh(es) not read" in lost.description and len(lost.unread_meshes) == 1
    jl.ee_pose(lost, np.zeros(3))  # kinematics need no mesh
    with pytest.raises(ModelError, match=r"its clearance needs the <collision> meshes .* link 'l2': .*package 'nowhere' "
                       r"is not in package_dirs, ROS_PACKAGE_PATH.*meshes='skip'") as info:
        clearance(jl.lock(lost, 2, 0.3), np.zeros(2))  # a lock keeps them unread
    assert "\n" not in str(info.value)
    (tmp_path / "pkg").mkdir()
    trimesh.creation.box(extents=(1.0, 1.0, 1.0)).export(tmp_path / "pkg" / "cube.stl")
    found = _probe(tmp_path, '<mesh filename="package://pkg/cube.stl"/>', package_dirs=[tmp_path / "pkg"])
    assert found.bodies[1].shapes[0].source.endswith("pkg/cube.stl")
    (tmp_path / "flat.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2 4 3\n")
    with pytest.raises(ModelError, match=r"flat \(no volume\)"):
        clearance(_probe(tmp_path, '<mesh filename="flat.obj"/>'), np.zeros(3))
    from jointlock.io import mesh

    mesh._hull.cache_clear()
    monkeypatch.setitem(sys.modules, "trimesh", None)  # import trimesh raises ImportError
    without = _probe(tmp_path, '<mesh filename="cube.stl" scale="2 2 2"/>')
    with pytest.raises(ModelError, match=r"needs trimesh: pip install 'jointlock\[mesh\]'") as info:
        clearance(without, np.zeros(3))
    assert "\n" not in str(info.value)
    from jointlock.mjcf import mjcf_text

    # an export would silently lack the mesh (and read back complete): refused in one line
    for export in (lambda: mjcf_text(without), lambda: write_urdf(without, tmp_path / "without.urdf")):
        with pytest.raises(ModelError, match=r"export of 'probe': 1 <collision> mesh\(es\) could not be read"):
            export()
    jl.ee_pose(without, np.zeros(3))  # kinematics need no mesh
    with pytest.raises(ModelError, match=r"<mesh scale>: must be 3 numbers, none 0"):
        _probe(tmp_path, '<mesh filename="cube.stl" scale="1 0 1"/>')
    with pytest.raises(ModelError, match=r"package_dirs must be a folder or a list of folders"):
        _probe(tmp_path, '<mesh filename="cube.stl"/>', package_dirs=5)
    monkeypatch.setitem(sys.modules, "coal", None)
    with pytest.raises(ModelError, match=r"needs coal for its distances .*pip install 'jointlock\[mesh\]'"):
        clearance(found, np.zeros(3))


def test_exports_write_the_hull_back(tmp_path):
    """export-urdf writes the <mesh> it came from (read back: the same hull); MJCF writes the
    hull's vertices as a mesh asset that MuJoCo compiles."""
    trimesh.creation.box(extents=(1.0, 1.0, 1.0)).export(tmp_path / "cube.stl")
    arm = _probe(tmp_path, '<mesh filename="cube.stl" scale="0.5 0.3 0.2"/>')
    out = tmp_path / "out.urdf"
    write_urdf(arm, out)
    back = jl.read_urdf(out)
    (hull,), (again,) = arm.bodies[1].shapes, back.bodies[1].shapes
    assert hull.source.startswith("/")  # absolute: an export elsewhere still finds it
    assert np.allclose(again.vertices, hull.vertices) and np.allclose(again.pose, hull.pose, atol=1e-12)
    q = np.random.default_rng(6).uniform(-3, 3, (50, 3))
    assert np.allclose(clearance(back, q).pair_distance, clearance(arm, q).pair_distance, atol=1e-9)
    with pytest.raises(ModelError, match="URDF has no inline mesh"):
        built = with_root_shapes(arm, [Convex(np.eye(4), hull.vertices, name="dock")])
        write_urdf(built, tmp_path / "x.urdf")
    mujoco = pytest.importorskip("mujoco")
    from jointlock.mjcf import mjcf_text

    compiled = mujoco.MjModel.from_xml_string(mjcf_text(arm))
    assert compiled.nmesh == 1 and compiled.mesh_vertnum[0] == 8


def test_the_reach_bound_holds_for_hulls_and_a_ur5_halt_keeps_its_clearance_between_samples():
    """pair_reach (how fast a pair can close per radian) with the hulls' extents, by finite
    differences on the UR5; and a halt of the UR5 (its SRDF leaving out the pairs close by design)
    keeps the clearance on its samples and between them."""
    from robot_data import robot_file

    from jointlock.sweep import pair_reach

    arm = jl.read_urdf(robot_file(UR5))
    reach = pair_reach(arm)
    rng = np.random.default_rng(7)
    moved_pairs = 0
    for _ in range(6):
        q = rng.uniform(-np.pi, np.pi, arm.dof)
        steps = q + 1e-6 * np.eye(arm.dof)
        change = np.abs(clearance(arm, steps, witness=False).pair_distance - clearance(arm, q).pair_distance)
        assert np.all(change <= reach.T * 1e-6 * (1 + 1e-6) + 1e-11)
        assert np.all(change[reach.T == 0] <= 1e-11)
        moved_pairs += int(np.count_nonzero(change > 1e-9))
    assert moved_pairs > 0
    srdf = robot_file("ur_description/srdf/ur5.srdf")
    model = jl.load_robot(str(robot_file(UR5)), chain=jl.UrdfChain(srdf=str(srdf)))
    locked = jl.lock(model, 3, np.radians(30))
    state = jl.FailureState(np.radians([0, -60, 0, -60, 0]), np.radians([10.0] * 5), np.zeros(5))
    plan = jl.plan_halt(
        locked,
        state,
        T=3.0,
        search=jl.HaltSearch(samples=400),
        motion=jl.HaltMotionSettings(n_samples=101),
    )
    report = plan.to_dict()["clearance"]
    assert plan.feasible and plan.collision_free
    assert report["between_samples_clear"] and report["collides"] is False
    assert report["motion_min_m"] >= 0.05 and report["between_samples_min_m"] >= 0.05 - 1e-3  # less the tunnel tolerance


def test_a_scenario_and_the_command_line_choose_how_meshes_are_read(tmp_path, capsys):
    from robot_data import robot_file

    from jointlock.cli import main
    from jointlock.errors import ScenarioError
    from jointlock.robots import UrdfChain
    from jointlock.run._commands import _chain_args

    urdf = robot_file(UR5)
    path = tmp_path / "s.toml"
    path.write_text(f'robot = "{urdf}"\nmeshes = "skip"\n[workspace]\n')
    scenario = jl.load_scenario(path)
    chain = UrdfChain.from_fields(scenario.data)
    assert chain is not None and chain.meshes == "skip" and _chain_args(scenario.data)[-2:] == ["--meshes", "skip"]
    skipped = jl.load_robot(str(urdf), chain=chain)
    assert not any(isinstance(s, Convex) for b in skipped.bodies for s in b.shapes)
    assert "left out (meshes='skip')" in skipped.description
    assert any(isinstance(s, Convex) for b in jl.load_robot(str(urdf)).bodies for s in b.shapes)
    path.write_text('robot = "puma6"\nmeshes = "skip"\n[workspace]\n')
    with pytest.raises(ScenarioError, match="meshes: chooses the chain of a URDF robot"):
        jl.load_scenario(path)
    path.write_text(f'robot = "{urdf}"\nmeshes = "hull"\n[workspace]\n')
    with pytest.raises(ScenarioError, match="meshes"):
        jl.load_scenario(path)
    for mode, meshes in (("skip", 0), ("convex", 7)):
        out = tmp_path / f"{mode}.urdf"
        assert main(["export-urdf", str(urdf), "--meshes", mode, "--out", str(out)]) == 0
        assert out.read_text().count("<mesh ") == meshes
    assert "Traceback" not in capsys.readouterr().err


def test_campaign_keys_say_how_a_urdfs_meshes_are_read(tmp_path):
    """A URDF with collision meshes: unset meant "left out" before meshes were read and means
    "convex" now, so the key holds the mode read (a ledger of the earlier reading does not
    resume into this one); a URDF without meshes keeps its keys."""
    from robot_data import robot_file

    from jointlock.campaign._cases import case_key

    def key(robot: str, extra: str = "") -> str:
        path = tmp_path / "s.toml"
        path.write_text(f'robot = "{robot}"\n{extra}[workspace]\nsamples = 1000\n')
        return case_key(jl.load_scenario(path), 0)

    ur5 = str(robot_file(UR5))
    assert key(ur5) == key(ur5, 'meshes = "convex"\n') != key(ur5, 'meshes = "skip"\n')
    bare = tmp_path / "bare.urdf"
    bare.write_text(URDF.replace("GEOMETRY", '<box size="0.5 0.3 0.2"/>'))
    assert key(str(bare)) != key(str(bare), 'meshes = "convex"\n')  # unset stays unset: no mesh to read


def test_unread_meshes_are_said_where_the_clearance_is_reported_and_refused_where_required(monkeypatch):
    """Without the mesh extra: a halt with the clearance reported only runs and says first that
    the clearance was not checked; one that requires it is refused; once the extra is back,
    load_robot reads the meshes (no stale model from its cache)."""
    from robot_data import robot_file

    from jointlock import robots
    from jointlock.io import mesh

    path = str(robot_file(UR5))
    mesh._hull.cache_clear()
    robots._read_model_file.cache_clear()  # read in this test, not by an earlier one
    monkeypatch.setitem(sys.modules, "trimesh", None)
    arm = jl.load_robot(path)
    assert len(arm.unread_meshes) == 7
    locked = jl.lock(arm, 3, np.radians(30))
    state = jl.FailureState(np.radians([0, -60, 0, -60, 0]), np.radians([10.0] * 5), np.zeros(5))
    settings = {"T": 3.0, "search": jl.HaltSearch(samples=200), "motion": jl.HaltMotionSettings(n_samples=101)}
    plan = jl.plan_halt(locked, state, clearance=jl.ClearanceSettings.off(), **settings)
    assert plan.summary()[0].startswith("CLEARANCE NOT CHECKED: 7 <collision> mesh(es) of the URDF could not be read")
    assert plan.clearance() is None
    with pytest.raises(ModelError, match=r"its clearance needs the <collision> meshes .*needs trimesh") as info:
        jl.plan_halt(locked, state, **settings)
    assert "\n" not in str(info.value) and "'base.stl'" in str(info.value)
    monkeypatch.delitem(sys.modules, "trimesh")
    assert not jl.load_robot(path).unread_meshes
