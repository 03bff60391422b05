"""Inverse kinematics as one call (``jointlock ik``): every branch of an arm, full or with a
locked joint, or the nearest reachable pose when the target cannot be reached (002 §3)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any, ClassVar, Literal

import numpy as np
from numpy.typing import ArrayLike

from .._cache import cached_on
from ..collision import clearance, reports_clearance, unread_meshes_line
from ..ik import IKResult, solve_ik, zyx_angles
from ..io.files import atomic_write_json
from ..model import ArmModel
from ._common import JobResult, format_matrix, locked_deg, locked_text


def _solution(sol: Any, clear: tuple[float, str] | None = None) -> dict[str, Any]:
    out = {
        "branch": sol.branch,
        "q_deg": np.degrees(sol.q_full),
        "position_error_m": sol.position_error,
        "rotation_error_deg": math.degrees(sol.rotation_error),
        "exact": sol.exact,
    }
    if clear is not None:
        out.update(clearance_m=clear[0], clearance_pair=clear[1], collides=clear[0] < 0)
    return out


@dataclass(frozen=True, eq=False)  # arrays inside: compare to_dict() instead
class InverseKinematicsReport(JobResult):
    """Every IK solution of ``model`` for ``target``, or the nearest reachable pose.

    Attributes
    ----------
    model
        The arm (locked joints allowed).
    target
        (4, 4) desired end-effector pose ``T_base_ee`` [m].
    result
        The solver's result (:class:`jointlock.ik.IKResult`: solutions, candidates, nearest).
    """

    job: ClassVar[str] = "ik"

    model: ArmModel
    target: np.ndarray
    result: IKResult

    def clearances(self) -> list[tuple[float, str]] | None:
        """Clearance [m] and closest pair of each solution (:func:`jointlock.collision.
        clearance`; negative: the arm overlaps its spacecraft bus or itself), in the solver's
        order; None for a model without collision shapes."""
        solutions = self.result.solutions
        if not solutions or not reports_clearance(self.model):
            return None

        def compute() -> list[tuple[float, str]]:
            result = clearance(self.model, self.model.healthy(np.array([s.q_full for s in solutions])))
            return [(float(result.distance[i]), result.pair_at((i,))) for i in range(len(solutions))]

        return cached_on(self, "clearances", compute)

    def ranked(self) -> list[tuple[Any, tuple[float, str] | None]]:
        """The solutions with their clearance, the colliding ones last (the solver's order
        otherwise)."""
        clear = self.clearances()
        pairs: list[tuple[Any, tuple[float, str] | None]] = list(
            zip(self.result.solutions, clear if clear is not None else [None] * len(self.result.solutions))
        )
        return sorted(pairs, key=lambda item: item[1] is not None and item[1][0] < 0)

    def to_dict(self) -> dict[str, Any]:
        """What ``jointlock ik --json`` prints (angles of every joint, the locked ones included)."""
        res, target = self.result, self.target
        out: dict[str, Any] = {
            "robot": self.model.name,
            "locked": locked_deg(self.model),
            "method": res.method,
            "family": res.family,
            "target": target,
            "target_position_m": target[:3, 3],
            "target_zyx_deg": np.degrees(zyx_angles(target[:3, :3])),
            "reachable": res.reachable,
            "within_tolerance": res.within_tolerance,
            "tolerance": None
            if res.tolerance is None
            else {"position_m": res.tolerance[0], "rotation_deg": math.degrees(res.tolerance[1])},
            "solutions": [_solution(s, c) for s, c in self.ranked()],
            "candidates": [_solution(s) for s in res.candidates],
            "nearest": None,
        }
        if res.nearest is not None:
            near = res.nearest_pose
            assert near is not None  # there is a nearest solution
            out["nearest"] = {
                **_solution(res.nearest),
                "pose": near,
                "position_m": near[:3, 3],
                "zyx_deg": np.degrees(zyx_angles(near[:3, :3])),
                "distance_position_m": res.nearest.position_error,
                "distance_rotation_deg": math.degrees(res.nearest.rotation_error),
                "length_scale_m": res.length_scale,
            }
        return out

    def summary(self) -> list[str]:
        """The lines ``jointlock ik`` prints."""
        res, model = self.result, self.model
        lines = unread_meshes_line(model) + [
            f"{model.name}: {res.method}{f' ({res.family} family)' if res.family else ''} IK, "
            f"locked: {locked_text(locked_deg(model))}",
            "target T_base_ee [m]:",
            format_matrix(self.target, "{:>11.6f}"),
        ]
        if res.reachable:
            within = ""
            if res.within_tolerance and res.tolerance is not None:
                within = (
                    f" within {1e3 * res.tolerance[0]:g} mm and {math.degrees(res.tolerance[1]):g} deg "
                    "(no exact one)"
                )
            lines.append(
                f"\n{len(res.solutions)} solution(s){within}, q [deg] (all joints), position error [m], "
                "rotation error [deg]:"
            )
            ranked = self.ranked()
            for s, clear in ranked:
                q = " ".join(f"{v:9.4f}" for v in np.degrees(s.q_full))
                flag = "" if clear is None else f"   clearance {clear[0]:+.3f} m" + (f" COLLIDES ({clear[1]})" if clear[0] < 0 else "")
                lines.append(
                    f"  branch {s.branch}: {q}   {s.position_error:.2e}  {math.degrees(s.rotation_error):.2e}{flag}"
                )
            colliding = [s.branch for s, clear in ranked if clear is not None and clear[0] < 0]
            if colliding:
                verdict = "every branch" if len(colliding) == len(ranked) else f"branches {colliding} (listed last)"
                lines.insert(0, f"COLLIDES: {verdict} overlap the spacecraft bus or the arm itself")
        else:
            n = self.to_dict()["nearest"]
            lines.append("\nnot reachable by this arm" + (" with the locked joint" if model.locked else ""))
            if n is not None:
                lines += [
                    "nearest reachable pose [m]:",
                    format_matrix(n["pose"], "{:>11.6f}"),
                    f"distance: {n['distance_position_m']:.6g} m, {n['distance_rotation_deg']:.6g} deg; "
                    "q [deg]: " + " ".join(f"{v:.4f}" for v in n["q_deg"]),
                ]
        return "\n".join(lines).split("\n")

    def write(self, out: str | Path) -> list[str]:
        """``result.json`` (:meth:`to_dict`) in ``out``; returns its name."""
        atomic_write_json(Path(out) / "result.json", self.to_dict())
        return ["result.json"]


def inverse_kinematics(
    model: ArmModel,
    target: ArrayLike,
    *,
    method: Literal["auto", "closed-form", "numeric"] = "auto",
    rng: int | np.random.Generator | None = 0,
    length_scale: float = 1.0,
    tolerance: tuple[float, float] | None = None,
) -> InverseKinematicsReport:
    """Every IK branch of ``model`` for the pose ``target`` (4, 4) [m]
    (:func:`jointlock.ik.solve_ik`: the closed form of the puma6, UR or spherical-wrist
    family, Levenberg-Marquardt from several seeded starts otherwise), or the nearest reachable pose, with ``length_scale``
    [m] weighing rotation against position in the distance; ``tolerance`` ``(position [m],
    rotation [rad])`` accepts a target reached within it (see :func:`~jointlock.ik.solve_ik`)."""
    target = np.asarray(target, dtype=float)
    res = solve_ik(model, target, method=method, rng=rng, length_scale=length_scale, tolerance=tolerance)
    return InverseKinematicsReport(model, target, res)
