"""Denavit-Hartenberg readers: standard (distal) and modified (Craig, proximal) tables into
the one internal chain form of :mod:`jointlock.model`.

Standard DH, joint ``i``:  ``T_{i-1,i} = Rz(theta_i + q_i) Tz(d_i) Tx(a_i) Rx(alpha_i)``; the
body of link ``i`` (its centre of mass, its inertia) is given in DH frame ``i`` (at the distal
end of the link).

Modified DH, joint ``i``:  ``T_{i-1,i} = Rx(alpha_{i-1}) Tx(a_{i-1}) Rz(theta_i + q_i) Tz(d_i)``;
row ``i`` of the arrays passed here holds ``(a_{i-1}, alpha_{i-1}, d_i, theta_i)``, and the
body of link ``i`` is given in DH frame ``i`` (at joint ``i``).

In the internal form frame ``i`` is the frame that rotates with joint ``i``.  For modified DH
it *is* DH frame ``i``.  For standard DH it is DH frame ``i-1`` rotated by ``theta_i + q_i``,
and DH frame ``i`` is frame ``i`` times the fixed ``Tz(d_i) Tx(a_i) Rx(alpha_i)``: the reader
moves each body into frame ``i`` so that dynamics are unchanged.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike

from .bounds import MAX_LENGTH_M, shown
from .errors import ModelError
from .geometry import with_link_capsules
from .model import ArmModel, Body, Joint
from .spatial import rot_x, rot_z, translation

DHConvention = Literal["standard", "modified"]


def _column(
    values: ArrayLike | None, n: int, name: str, default: float = 0.0, *, unbounded: float = 0.0
) -> np.ndarray:
    """(n,) finite numbers; ``unbounded`` (-inf or +inf) is allowed too (a limit without a
    bound: a continuous joint)."""
    if values is None:
        return np.full(n, default)
    arr = np.asarray(values, dtype=float)
    if arr.shape != (n,) or not np.all(np.isfinite(arr) | (arr == unbounded if unbounded else False)):
        also = f" (or {unbounded:g} for no limit)" if unbounded else ""
        raise ModelError(
            f"DH column {name} must hold {n} finite numbers{also}; got {shown(np.asarray(values).tolist())}"
        )
    return arr


def from_dh(
    name: str,
    *,
    a: ArrayLike,
    alpha: ArrayLike,
    d: ArrayLike,
    theta: ArrayLike | None = None,
    convention: DHConvention,
    bodies: Sequence[Body] | None = None,
    tool: ArrayLike | None = None,
    lower: ArrayLike | None = None,
    upper: ArrayLike | None = None,
    velocity_limit: ArrayLike | None = None,
    effort_limit: ArrayLike | None = None,
    spacecraft: Body | None = None,
    description: str = "",
    base: ArrayLike | None = None,
    flip: Sequence[bool] | None = None,
    prismatic: Sequence[bool] | None = None,
    radius: float | Sequence[float] | None = None,
) -> ArmModel:
    """Build an arm from a DH table.

    Parameters
    ----------
    name
        Model name.
    a, alpha, d, theta
        (n,) DH columns: link lengths [m], twists [rad], offsets along z [m], joint-angle
        offsets [rad] added to ``q`` (``theta=None`` means zero).  For ``"modified"``, entry
        ``i`` of ``a`` and ``alpha`` is ``a_{i-1}`` and ``alpha_{i-1}`` (Craig's row layout).
    convention
        ``"standard"`` or ``"modified"`` (see the module docstring).
    bodies
        (n,) bodies, each expressed in its DH frame ``i``; massless points when omitted.
    tool
        (4, 4) pose of the end-effector frame in DH frame ``n`` [m]; identity when omitted.
    lower, upper, velocity_limit
        (n,) joint limits [rad], [rad/s]; +-pi and unlimited speed when omitted; ``-inf`` /
        ``inf`` for a joint without angle limits (continuous), and limits past +-pi as given.
    effort_limit
        (n,) motor torque limits [N m]; unlimited when omitted.
    spacecraft
        Spacecraft body (centre of mass and inertia in the root frame: DH frame 0 unless
        ``base`` moves it); the arm is free-floating when given, fixed-base otherwise.
    description
        Provenance and readings, kept with the model.
    base
        (4, 4) pose of DH frame 0 in the root frame (the arm's mounting on its spacecraft or
        pedestal) [m]; identity when omitted.
    flip
        (n,) True for a joint whose positive rotation is about -z (``theta_i - q_i`` in the
        table, roboticstoolbox's ``flip``); all False when omitted.
    prismatic
        (n,) True for a row whose joint slides along z (its variable is ``d``): the chain model
        turns its joints and does not slide them, so a prismatic joint is held at the table's
        ``d`` (and ``theta``) and its link merged into the one before, as a frozen URDF joint
        is.  Its limits, if given, are ignored.  The model has one joint fewer, numbered
        1..m along the chain, each named after its table row (a prismatic row 3 of 6: joints
        1-5 named ``joint1, joint2, joint4, joint5, joint6``).  All False when omitted.
    radius
        Collision geometry (issue 27): one radius [m], or (n,) one per row, of a capsule along
        each link of the stick figure (:func:`jointlock.geometry.with_link_capsules`; the root
        post takes row 1's radius; a prismatic row's link is merged into the one before, so its
        radius is not used; 0: no shape).  None (default): no shapes.
    """
    if convention not in ("standard", "modified"):
        raise ModelError(f"convention must be 'standard' or 'modified'; got {shown(convention)}")
    a_arr = np.asarray(a, dtype=float)
    n = a_arr.size
    if n == 0:
        raise ModelError("a DH table needs at least one row")
    a_arr = _column(a, n, "a")
    alpha_arr = _column(alpha, n, "alpha")
    d_arr = _column(d, n, "d")
    theta_arr = _column(theta, n, "theta")
    lo = _column(lower, n, "lower", -math.pi, unbounded=-math.inf)
    hi = _column(upper, n, "upper", math.pi, unbounded=math.inf)
    vmax = np.full(n, math.inf) if velocity_limit is None else np.asarray(velocity_limit, dtype=float)
    if vmax.shape != (n,) or not np.all(vmax > 0):
        raise ModelError(
            f"velocity_limit must hold {n} numbers > 0 [rad/s] (inf for unlimited); "
            f"got {shown(np.asarray(velocity_limit).tolist())}"
        )
    effort = np.full(n, math.inf) if effort_limit is None else np.asarray(effort_limit, dtype=float)
    if effort.shape != (n,) or not np.all(effort > 0):
        raise ModelError(
            f"effort_limit must hold {n} numbers > 0 [N m] (inf for unlimited); "
            f"got {shown(np.asarray(effort_limit).tolist())}"
        )
    if bodies is None:
        bodies = [Body(0.0, name=f"link{i + 1}") for i in range(n)]
    if len(bodies) != n:
        raise ModelError(f"bodies must hold one body per DH row ({n}); got {len(bodies)}")
    tool_arr = np.eye(4) if tool is None else np.asarray(tool, dtype=float)
    base_arr = np.eye(4) if base is None else np.asarray(base, dtype=float)
    if base_arr.shape != (4, 4) or not np.all(np.isfinite(base_arr)):
        raise ModelError(f"base must be a (4, 4) pose of DH frame 0 [m]; got shape {base_arr.shape}")
    flips = [False] * n if flip is None else list(flip) if isinstance(flip, Sequence | np.ndarray) else [flip]
    if len(flips) != n or not all(isinstance(f, (bool, np.bool_)) for f in flips):
        raise ModelError(f"flip must hold {n} booleans (True: the joint turns about -z); got {shown(flip)}")
    slides = (
        [False] * n
        if prismatic is None
        else list(prismatic)
        if isinstance(prismatic, Sequence | np.ndarray)
        else [prismatic]
    )
    if len(slides) != n or not all(isinstance(f, (bool, np.bool_)) for f in slides):
        raise ModelError(f"prismatic must hold {n} booleans (True: held at the row's d); got {shown(prismatic)}")
    if all(slides):
        raise ModelError("prismatic: at least one DH row must be a revolute joint (prismatic joints are held)")

    if convention == "modified":
        placements = [
            rot_x(alpha_arr[i])
            @ translation([a_arr[i], 0.0, 0.0])
            @ rot_z(theta_arr[i])
            @ translation([0.0, 0.0, d_arr[i]])
            for i in range(n)
        ]
        frame_bodies = list(bodies)
        model_tool = tool_arr
    else:
        # fixed part after the joint rotation: F_i = Rz(theta_i) Tz(d_i) Tx(a_i) Rx(alpha_i)
        fixed = [
            rot_z(theta_arr[i])
            @ translation([0.0, 0.0, d_arr[i]])
            @ translation([a_arr[i], 0.0, 0.0])
            @ rot_x(alpha_arr[i])
            for i in range(n)
        ]
        placements = [np.eye(4)] + fixed[:-1]
        frame_bodies = [bodies[i].transformed(fixed[i]) for i in range(n)]
        model_tool = fixed[-1] @ tool_arr

    placements[0] = base_arr @ placements[0]
    root_body = spacecraft if spacecraft is not None else Body(0.0, name="root")
    kept: list[int] = []
    carried = np.eye(4)  # the held rows' transforms since the last kept joint
    for i in range(n):
        if not slides[i]:
            placements[i] = carried @ placements[i]
            kept.append(i)
            carried = np.eye(4)
            continue
        # held at q = 0: frame i is frame i-1 times its placement, its body joins link i-1's
        carried = carried @ placements[i]
        if kept:
            k = kept[-1]
            frame_bodies[k] = frame_bodies[k].merged(frame_bodies[i], carried)
        else:
            root_body = root_body.merged(frame_bodies[i], carried)
    model_tool = carried @ model_tool
    joints = tuple(
        Joint(
            placements[i],
            np.array([0.0, 0.0, -1.0 if flips[i] else 1.0]),
            lo[i],
            hi[i],
            vmax[i],
            number=k + 1,
            name=f"joint{i + 1}",
            effort_limit=effort[i],
        )
        for k, i in enumerate(kept)
    )
    model = ArmModel(
        name=name,
        joints=joints,
        bodies=tuple(frame_bodies[i] for i in kept),
        tool=model_tool,
        root_body=root_body,
        floating=spacecraft is not None,
        description=description,
    )
    if radius is None:
        return model
    try:
        if isinstance(radius, (bool, np.bool_, str, bytes)) or np.asarray(radius).dtype.kind == "b":
            raise TypeError
        radii = np.full(n, float(radius)) if np.ndim(radius) == 0 else _column(radius, n, "radius")  # type: ignore[arg-type]
    except (TypeError, ValueError):
        raise ModelError(f"radius must be a length [m] or {n} lengths, one per row; got {shown(radius)}") from None
    if not np.all(np.isfinite(radii)) or np.any(radii < 0) or np.any(radii > MAX_LENGTH_M):
        raise ModelError(f"radius must be lengths in [0, {MAX_LENGTH_M:g}] m; got {shown(np.asarray(radius).tolist())}")
    return with_link_capsules(model, [float(radii[kept[0]])] + [float(radii[i]) for i in kept])
