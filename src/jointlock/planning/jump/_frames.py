"""What the law needs at one control step, for B runs at once, batch last (:class:`_Frame`),
and the fixed-base forward kinematics that feeds it (:class:`_FixedChain`).

The integrator evaluates the law once per control step for every run together; with the small
batches of a search (one to a few hundred runs) the cost is the number of numpy calls per step,
not the arithmetic.  :class:`_FixedChain` therefore folds the model's constants once per
problem and keeps the batch as the last axis, as :func:`jointlock.kinematics.chain_state` does,
but computes only the joint axes, the joint positions and the tool point.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..._chain import axis_frame, kernel_input
from ...compiled import use_compiled
from ...forward import COMPILED_MIN_BATCH
from ...model import ArmModel, FloatArray
from ._control import CYCLIC, cross_cyclic, law

#: ``(s, -s)``: the signs of the sines in ``Rz``'s first two columns.
_SIGNS = np.array([1.0, -1.0])[:, None]


@dataclass
class _Frame:
    """The law's inputs at one step for B runs, batch last (see :func:`law`)."""

    x: FloatArray  # (3, B) end-effector position [m]
    jac: FloatArray  # (3, n, B) position Jacobian [m/rad]
    axes: FloatArray | None = None  # (3, n, B) joint axes: fixed base, closed-form gradient
    djac: FloatArray | None = None  # (n, 3, n, B) Jacobian derivatives [m/rad^2]: floating base
    base_jac: FloatArray | None = None  # (B, 3, n) base angular-velocity Jacobian (floating)

    def rates(
        self, healthy: np.ndarray, xdot: FloatArray, kappa: FloatArray, plus: np.ndarray | None = None
    ) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray | None]:
        """:func:`law` for the B runs: ``qdot`` (n, B) [rad/s], ``w`` (B,) [m^3] and the
        null-space term (n, B), from ``healthy`` (n, B), ``xdot`` (3, B) [m/s] and ``kappa``
        (B,) [rad^2/(s m^3)].  With ``plus`` (n, R), also ``qdot`` (n, R) of the first R runs
        with those joints healthy instead (the rates right after a lock), in the same call:
        one law evaluation over B + R columns costs about what one over B does."""
        if plus is None:
            return (*law(self.jac, healthy, xdot, kappa, axes=self.axes, djac=self.djac), None)
        R = plus.shape[1]

        def more(a: FloatArray | None) -> FloatArray | None:  # the first R runs appended
            return None if a is None else np.concatenate([a, a[..., :R]], axis=-1)

        jac, axes, djac = more(self.jac), more(self.axes), more(self.djac)
        assert jac is not None
        qdot, w, null = law(
            jac,
            np.concatenate([healthy, plus], axis=1),
            np.concatenate([xdot, xdot[:, :R]], axis=1),
            np.concatenate([kappa, kappa[:R]]),
            axes=axes,
            djac=djac,
        )
        B = healthy.shape[1]
        return qdot[:, :B], w[:B], null[:, :B], qdot[:, B:]


@dataclass(frozen=True)
class _FixedChain:
    """Forward kinematics of a fixed-base chain, constants folded once.

    Joint ``i`` is described in its z-joint frame (turned by ``Q_i``, ``Q_i e_z`` = its axis):
    with ``R'_i = R_i Q_i``, ``R'_i = R'_{i-1} M_i Rz(q_i)`` where ``M_i = Q_{i-1}^T P_i Q_i``
    (``P_i`` the placement's rotation), the axis is ``R'_i e_z`` and the joint origin
    ``p_i = p_{i-1} + R'_{i-1} u_i`` with ``u_i = Q_{i-1}^T t_i``.  ``[R'_i | p_i]`` (3 x 4) is
    carried as one array: one product with the constant ``H_i = [[M_i, u_i], [0, 1]]`` gives both
    the next rotation and the next origin, and ``Rz`` then mixes the first two columns only.
    """

    link_t: tuple[FloatArray, ...]  # (n,) H_i^T (4, 4), for the batch-last product [R'|p] H
    tool: FloatArray  # (4,) homogeneous tool point in the last z-joint frame [m]
    link_h: FloatArray  # (n, 4, 4) H_i, for the compiled frame (jointlock._kernels.fixed_frame)

    @classmethod
    def of(cls, model: ArmModel) -> _FixedChain:
        """The constants of ``model`` (its joints and tool; the base is the root frame)."""
        links = []
        q_prev = np.eye(3)
        for joint in model.joints:
            q_axis = axis_frame(joint.axis)
            h = np.eye(4)
            h[:3, :3] = q_prev.T @ joint.placement[:3, :3] @ q_axis
            h[:3, 3] = q_prev.T @ joint.placement[:3, 3]
            links.append(np.ascontiguousarray(h.T))
            q_prev = q_axis
        return cls(
            tuple(links), np.append(q_prev.T @ model.tool[:3, 3], 1.0), np.ascontiguousarray([h.T for h in links])
        )

    def frame(self, q: FloatArray) -> _Frame:
        """Tool point, joint axes and position Jacobian at ``q`` (B, n) [rad], batch last."""
        n, B = len(self.link_t), q.shape[0]
        if use_compiled(B, COMPILED_MIN_BATCH):  # the same numbers to round-off, one call
            from ... import _kernels

            x, jac, axes = np.empty((3, B)), np.empty((3, n, B)), np.empty((3, n, B))
            _kernels.fixed_frame(kernel_input(q), self.link_h, self.tool, x, jac, axes)
            return _Frame(x, jac, axes=axes)
        qt = q.T
        cos = np.cos(qt)  # (n, B)
        sin_pm = np.sin(qt)[:, None, :] * _SIGNS  # (n, 2, B): s, -s
        links = np.empty((n, 3, 4, B))  # [R'_i | p_i]
        for i in range(n):
            r = links[i]  # [R'_{i-1} | p_{i-1}] H_i first (row by row), then turned by Rz(q_i)
            if i == 0:
                r[...] = self.link_t[0].T[:3, :, None]
            else:
                np.matmul(self.link_t[i], links[i - 1], out=r)
            # Rz(q) mixes the first two columns, (a0, a1) -> (a0 c + a1 s, a1 c - a0 s); the
            # axis and the origin stay
            np.add(r[:, :2] * cos[i], r[:, 1::-1] * sin_pm[i], out=r[:, :2])
        x = self.tool @ links[-1]  # (3, B)
        axes = links[:, :, 2].transpose(1, 0, 2)  # (3, n, B)
        lever = x[CYCLIC, None, :] - links[:, CYCLIC, 3].transpose(1, 0, 2)  # (5, n, B), cyclic
        jac = cross_cyclic(axes[CYCLIC], lever)
        return _Frame(x, jac, axes=axes)
