"""Test-only bridge to Pinocchio: the same arm as a ``pin.Model``, built from our model's
placements and bodies (not from our kinematics)."""

from __future__ import annotations

import numpy as np

import jointlock as jl

pin = __import__("pytest").importorskip("pinocchio")


def to_pinocchio(model: jl.ArmModel, *, free_flyer: bool = False):
    """(pin.Model, ee frame id).  With ``free_flyer`` the root body is the spacecraft on a
    free-flyer joint; otherwise the chain hangs from the universe."""
    pm = pin.Model()
    parent = 0
    if free_flyer:
        parent = pm.addJoint(0, pin.JointModelFreeFlyer(), pin.SE3.Identity(), "base")
        rb = model.root_body
        pm.appendBodyToJoint(
            parent, pin.Inertia(rb.mass, rb.com.copy(), rb.inertia.copy()), pin.SE3.Identity()
        )
    for joint, body in zip(model.joints, model.bodies):
        placement = pin.SE3(joint.placement[:3, :3].copy(), joint.placement[:3, 3].copy())
        jm = pin.JointModelRevoluteUnaligned(joint.axis.copy())
        parent = pm.addJoint(parent, jm, placement, joint.name)
        pm.appendBodyToJoint(
            parent, pin.Inertia(body.mass, body.com.copy(), body.inertia.copy()), pin.SE3.Identity()
        )
    tool = pin.SE3(model.tool[:3, :3].copy(), model.tool[:3, 3].copy())
    fid = pm.addFrame(pin.Frame("ee", parent, tool, pin.FrameType.OP_FRAME))
    return pm, fid


def pin_q(pm, q: np.ndarray, free_flyer: bool) -> np.ndarray:
    """Pinocchio configuration: free flyer at identity, continuous joints as (cos, sin)."""
    out = pin.neutral(pm)
    values = iter(np.asarray(q, dtype=float))
    for joint in pm.joints[1:]:
        if joint.nq == 7:
            continue  # free flyer: neutral = identity pose
        angle = next(values)
        if joint.nq == 2:
            out[joint.idx_q : joint.idx_q + 2] = [np.cos(angle), np.sin(angle)]
        else:
            out[joint.idx_q] = angle
    return out


def pin_kinematics(pm, fid, q: np.ndarray, free_flyer: bool = False):
    """EE pose (4, 4), fixed-base Jacobian (6, n) LOCAL_WORLD_ALIGNED, joint poses (n, 4, 4),
    mass matrix (n, n) [fixed base] or generalized Jacobian (6, n) [free flyer]."""
    data = pm.createData()
    qq = pin_q(pm, q, free_flyer)
    pin.forwardKinematics(pm, data, qq)
    pin.updateFramePlacements(pm, data)
    ee = data.oMf[fid].homogeneous.copy()
    jac = pin.computeFrameJacobian(pm, data, qq, fid, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED).copy()
    mass = pin.crba(pm, data, qq).copy()
    mass = np.triu(mass) + np.triu(mass, 1).T
    first = 2 if free_flyer else 1
    poses = np.array([data.oMi[i].homogeneous for i in range(first, pm.njoints)])
    out = {"ee": ee, "poses": poses}
    if free_flyer:
        hb, hbm = mass[:6, :6], mass[:6, 6:]
        out["generalized_jacobian"] = jac[:, 6:] - jac[:, :6] @ np.linalg.solve(hb, hbm)
        out["jacobian"] = jac[:, 6:]
    else:
        out["jacobian"] = jac
        out["mass_matrix"] = mass
    return out


def reduced_model(full, keep: list[str], values: dict[str, float]):
    """Pinocchio's ``full`` model with every joint but ``keep`` locked at ``values`` (0
    otherwise; Pinocchio ignores <mimic>, so a follower's value is given here), by its own
    ``buildReducedModel``: the reduced ``pin.Model``, its joints exactly ``keep``."""
    q_ref = pin.neutral(full)
    for name, v in values.items():
        q_ref[full.joints[full.getJointId(name)].idx_q] = v
    lock = [full.getJointId(n) for n in full.names[1:] if n not in keep]
    reduced = pin.buildReducedModel(full, lock, q_ref)
    assert list(reduced.names[1:]) == keep
    return reduced


def to_pinocchio_geometry(model: jl.ArmModel, pm):
    """(pin.GeometryModel, pair names) of ``model``'s collision shapes on ``pm`` (from
    :func:`to_pinocchio`, fixed base): coal capsules, spheres and boxes on the joints that
    carry them, and jointlock's checked pairs (:func:`jointlock.collision.collision_pairs`) as
    the collision pairs, in the same order."""
    import coal

    from jointlock.collision import collision_pairs

    pairs = collision_pairs(model)
    geom = pin.GeometryModel()

    def add(name: str, body: int, shape, placement: np.ndarray) -> int:
        parent = 0 if body < 0 else body + 1
        obj = pin.GeometryObject(name, parent, pin.SE3(placement[:3, :3].copy(), placement[:3, 3].copy()), shape)
        return geom.addGeometryObject(obj)

    capsules = []
    for c, (body, points, radius) in enumerate(zip(pairs.capsule_body, pairs.capsule_points, pairs.capsule_radii)):
        capsule = jl.Capsule(points[:3], points[3:], float(radius))
        shape = coal.Capsule(capsule.radius, capsule.length) if capsule.length > 0 else coal.Sphere(capsule.radius)
        capsules.append(add(f"capsule{c}", int(body), shape, capsule.frame))
    boxes = [
        add(f"box{b}", int(body), coal.Box(*(2 * half)), pose)
        for b, (body, pose, half) in enumerate(zip(pairs.box_body, pairs.box_poses, pairs.box_halves))
    ]
    for kind, i, j in pairs.pairs:
        geom.addCollisionPair(pin.CollisionPair(capsules[i], capsules[j] if kind == 0 else boxes[j]))
    return geom, pairs.names
