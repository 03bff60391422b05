"""What the spacecraft feels during a free-floating motion: its attitude, angular rate and the
drift of its centre of mass, from the zero-momentum condition (a free-floating system starting
at rest keeps zero linear and angular momentum).

At each sample the spacecraft's twist follows from the joint rates alone,
``nu_0 = -H_b^{-1} h_arm(q, dq)`` (:func:`jointlock.dynamics.rnea`'s ``base_twist``, in the
spacecraft's own frame).  Zero momentum is assumed throughout, as the free-floating dynamics do:
the system at rest before the motion (an arm already moving when it fails would have given the
spacecraft its share of that momentum).  The attitude is the ordered product of the rotations over
each time step, ``R(t_k) = R(t_{k-1}) exp([omega_k] dt)`` with ``omega_k`` the average of the
step's end rates (second order in ``dt``), composed as unit quaternions by a parallel prefix scan
(log2 of the samples' count of batched products, no Python loop over samples).  The centre of
mass moves by ``int R(t) v_0(t) dt`` (trapezoidal).  The attitude is relative to the spacecraft's
attitude at the first sample, the drift in that first frame.  Checked in the tests: the whole
system's centre of mass stays put.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike

from ..dynamics import rnea
from ..errors import ModelError
from ..model import ArmModel, FloatArray
from ..spatial import quaternion_matrix


@dataclass(frozen=True, eq=False)  # arrays inside: compare to_dict() instead
class SpacecraftResponse:
    """The spacecraft's motion while the arm moves, its base free.

    Attributes
    ----------
    t
        (m,) times [s].
    attitude
        (m, 4) unit quaternions ``(w, x, y, z)`` (Hamilton, active): the spacecraft's attitude
        relative to its attitude at ``t[0]``, mapping spacecraft-frame components into the
        first frame.
    angular_velocity
        (m, 3) angular velocity [rad/s], spacecraft frame.
    com_displacement
        (m, 3) displacement of the spacecraft's centre of mass [m], in its frame at ``t[0]``.
    """

    t: FloatArray
    attitude: FloatArray
    angular_velocity: FloatArray
    com_displacement: FloatArray

    @property
    def attitude_change_deg(self) -> FloatArray:
        """(m,) angle of the smallest rotation from the first attitude to each [deg], in
        [0, 180] (see :attr:`rotation_path_deg` for the angle turned along the way)."""
        half_sin = np.linalg.norm(self.attitude[:, 1:], axis=-1)
        return np.degrees(2.0 * np.arctan2(half_sin, np.abs(self.attitude[:, 0])))  # exact near 0 too

    @property
    def rotation_path_deg(self) -> float:
        """Angle turned along the way, ``int |omega| dt`` [deg] (>= the final attitude change)."""
        rate = np.linalg.norm(self.angular_velocity, axis=-1)
        return float(np.degrees(np.sum(0.5 * (rate[1:] + rate[:-1]) * np.diff(self.t))))

    @property
    def final_attitude_change_deg(self) -> float:
        """Attitude change at the end of the motion [deg]."""
        return float(self.attitude_change_deg[-1])

    @property
    def peak_rate_deg_s(self) -> float:
        """Largest angular rate of the spacecraft [deg/s]."""
        return float(np.degrees(np.linalg.norm(self.angular_velocity, axis=-1).max()))

    @property
    def com_drift_m(self) -> float:
        """Distance of the spacecraft's centre of mass from where it started, at the end [m]."""
        return float(np.linalg.norm(self.com_displacement[-1]))

    def root_positions(self, com: ArrayLike) -> FloatArray:
        """(m, 3) origin of the root (spacecraft) frame [m], in the first frame, for the
        spacecraft's centre of mass at ``com`` (3,) [m] in its own frame: ``c + d(t) - R(t) c``
        (the root frame starts at the origin of the first frame)."""
        c = np.asarray(com, dtype=float)
        return c + self.com_displacement - quaternion_matrix(self.attitude) @ c

    def summary(self, label: str = "spacecraft (free)") -> list[str]:
        """One line: final attitude change, peak rate, centre-of-mass drift."""
        return [
            f"{label}: attitude change {self.final_attitude_change_deg:.4g} deg "
            f"(largest {self.attitude_change_deg.max():.4g} deg, {self.rotation_path_deg:.4g} deg turned along the "
            f"way), peak rate {self.peak_rate_deg_s:.4g} deg/s, centre-of-mass drift {self.com_drift_m:.4g} m"
        ]

    def to_dict(self) -> dict[str, Any]:
        """The headline figures (degrees, metres); the histories are in :meth:`time_series`."""
        return {
            "attitude_change_deg": self.final_attitude_change_deg,
            "max_attitude_change_deg": float(self.attitude_change_deg.max()),
            "rotation_path_deg": self.rotation_path_deg,
            "peak_rate_deg_s": self.peak_rate_deg_s,
            "com_drift_m": self.com_drift_m,
        }

    def time_series(self) -> dict[str, FloatArray]:
        """``t`` [s], ``attitude`` (m, 4), ``angular_velocity`` (m, 3) [rad/s],
        ``com_displacement`` (m, 3) [m], ``attitude_change_deg`` (m,)."""
        return {
            "t": self.t,
            "attitude": self.attitude,
            "angular_velocity": self.angular_velocity,
            "com_displacement": self.com_displacement,
            "attitude_change_deg": self.attitude_change_deg,
        }


def spacecraft_response(
    model: ArmModel, t: ArrayLike, q: ArrayLike, dq: ArrayLike, *, rates: Literal["linear", "hold"] = "linear"
) -> SpacecraftResponse:
    """The spacecraft's attitude, rate and drift while the joints follow ``q(t)``, ``dq(t)``.

    Parameters
    ----------
    model
        A free-floating arm (with its spacecraft; locked joints allowed).
    t
        (m,) increasing times [s], m >= 2.
    q, dq
        (m, n) joint angles [rad] and rates [rad/s] at those times.
    rates
        ``"linear"``: a smooth motion sampled at ``t`` (each step turns by the average of its
        end rates, second order).  ``"hold"``: a control loop's steps, ``dq[k]`` applied over
        ``[t_k, t_{k+1})`` from ``q[k]`` (each step turns by its own rate, as the jump study's
        integrator does; the last row's rate is the one after the motion).

    Returns
    -------
    SpacecraftResponse
    """
    if not model.floating:
        raise ModelError(
            f"spacecraft_response needs a free-floating model (a spacecraft body); {model.name!r} has a "
            "fixed base: load it with base='floating'"
        )
    t = np.asarray(t, dtype=float)
    if t.ndim != 1 or t.size < 2 or not np.all(np.isfinite(t)) or np.any(np.diff(t) <= 0):
        raise ModelError(f"t must be (m,) increasing finite times, m >= 2 [s]; got shape {t.shape}")
    q = np.asarray(q, dtype=float)
    dq = np.asarray(dq, dtype=float)
    if q.shape != (t.size, model.dof) or dq.shape != q.shape:
        raise ModelError(f"q and dq must have shape ({t.size}, {model.dof}); got {q.shape} and {dq.shape}")
    twist = rnea(model, q, dq, np.zeros_like(q), base="floating").base_twist  # needs no ddq
    v0, w0 = twist[:, :3], twist[:, 3:]
    dt = np.diff(t)
    if rates not in ("linear", "hold"):
        raise ModelError(f"rates must be 'linear' or 'hold'; got {rates!r}")
    w_step = 0.5 * (w0[1:] + w0[:-1]) if rates == "linear" else w0[:-1]
    steps = _rotvec_quaternions(w_step * dt[:, None])
    attitude = np.concatenate([[[1.0, 0.0, 0.0, 0.0]], _prefix_products(steps)])
    velocity = _rotate(attitude, v0)  # the centre of mass's velocity in the first frame
    v_step = 0.5 * (velocity[1:] + velocity[:-1]) if rates == "linear" else velocity[:-1]
    drift = np.concatenate([np.zeros((1, 3)), np.cumsum(v_step * dt[:, None], axis=0)])
    return SpacecraftResponse(t, attitude, w0, drift)


def final_attitude_change_deg(model: ArmModel, t: ArrayLike, q: ArrayLike, dq: ArrayLike) -> FloatArray:
    """The spacecraft's attitude change at the end of many motions at once [deg], (...):
    :func:`spacecraft_response`'s ``final_attitude_change_deg`` (``rates="linear"``) for
    ``q``, ``dq`` (..., m, n) on the times ``t`` (m,), the ordered product of the steps taken by
    a pairwise tree (log2 m batched products).  ``model`` must be free-floating."""
    t = np.asarray(t, dtype=float)
    q = np.asarray(q, dtype=float)
    twist = rnea(model, q, dq, np.zeros_like(q), base="floating").base_twist
    w0 = twist[..., 3:]
    steps = _rotvec_quaternions(0.5 * (w0[..., 1:, :] + w0[..., :-1, :]) * np.diff(t)[:, None])
    while steps.shape[-2] > 1:
        if steps.shape[-2] % 2:  # an identity after the last step keeps the pairs in order
            identity = np.zeros(steps.shape[:-2] + (1, 4))
            identity[..., 0] = 1.0
            steps = np.concatenate([steps, identity], axis=-2)
        steps = _quaternion_product(steps[..., 0::2, :], steps[..., 1::2, :])
    final = steps[..., 0, :] / np.linalg.norm(steps[..., 0, :], axis=-1, keepdims=True)
    return np.degrees(2.0 * np.arctan2(np.linalg.norm(final[..., 1:], axis=-1), np.abs(final[..., 0])))


def _rotvec_quaternions(rotvec: FloatArray) -> FloatArray:
    """(..., 4) unit quaternions ``(w, x, y, z)`` of rotation vectors (..., 3) [rad]."""
    angle = np.linalg.norm(rotvec, axis=-1)
    half = 0.5 * angle
    # sin(a/2)/a, with its limit 1/2 at a = 0
    scale = np.where(angle > 1e-12, np.sin(half) / np.where(angle > 1e-12, angle, 1.0), 0.5 - angle**2 / 48.0)
    return np.concatenate([np.cos(half)[..., None], rotvec * scale[..., None]], axis=-1)


def _quaternion_product(a: FloatArray, b: FloatArray) -> FloatArray:
    """(..., 4) Hamilton products ``a b`` (rotation ``b`` first, in ``a``'s frame)."""
    aw, ax, ay, az = np.moveaxis(a, -1, 0)
    bw, bx, by, bz = np.moveaxis(b, -1, 0)
    return np.stack(
        [
            aw * bw - ax * bx - ay * by - az * bz,
            aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
        ],
        axis=-1,
    )


def _prefix_products(steps: FloatArray) -> FloatArray:
    """(k, 4) ordered products ``s_0 s_1 ... s_i`` of unit quaternions (k, 4): a Hillis-Steele
    scan, ceil(log2 k) batched products (the product is associative, not commutative: the
    earlier step stays on the left), renormalised against round-off."""
    out = steps.copy()
    offset = 1
    while offset < len(out):
        out[offset:] = _quaternion_product(out[:-offset], out[offset:])
        offset *= 2
    return out / np.linalg.norm(out, axis=-1, keepdims=True)


def _rotate(quaternion: FloatArray, vector: FloatArray) -> FloatArray:
    """(m, 3) vectors (m, 3) rotated by unit quaternions (m, 4)."""
    w, xyz = quaternion[:, :1], quaternion[:, 1:]
    cross = np.cross(xyz, vector)
    return vector + 2.0 * w * cross + 2.0 * np.cross(xyz, cross)

