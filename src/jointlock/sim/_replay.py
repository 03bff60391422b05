"""What a replay in a simulator gives (:class:`Replay`): MuJoCo's spacecraft and brakes next to
jointlock's own figures of the same motion, as rows, a summary, JSON, CSV and a figure."""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..analysis.spacecraft import SpacecraftResponse
from ..io.files import atomic_write_json, atomic_write_text, csv_text, with_svg, write_figure
from ..model import FloatArray


@dataclass(frozen=True, eq=False)  # arrays inside
class Replay:
    """A motion played in MuJoCo next to jointlock's own figures of it.

    Attributes
    ----------
    label
        What was replayed (``"halt"``).
    t
        (m,) times [s] (every MuJoCo step).
    joint_numbers, locked_numbers
        The healthy (driven) and the locked (braked) joints, 1-based.
    q, q_ref
        (m, n) healthy-joint angles in MuJoCo and the reference [rad].
    locked_angle
        (m, n_locked) the locked joints' angles in MuJoCo minus their lock angles [rad] (how
        far the brakes give).
    brake, brake_ref
        (m, n_locked) brake torques [N m]: MuJoCo's joint-equality constraint torque and
        jointlock's (:func:`~jointlock.analysis.actuators.actuator_torques`).
    attitude, com_displacement
        (m, 4) MuJoCo's spacecraft attitude ``(w, x, y, z)`` and (m, 3) centre-of-mass
        displacement [m], in the spacecraft's first frame; None with a fixed base.
    angular_velocity
        (m, 3) MuJoCo's spacecraft angular velocity [rad/s], its own frame; None with a fixed base.
    reference
        jointlock's :class:`~jointlock.analysis.spacecraft.SpacecraftResponse` on the same times;
        None with a fixed base.
    timestep
        MuJoCo's step [s].
    mujoco_version
        ``mujoco.__version__``.
    """

    label: str
    t: FloatArray
    joint_numbers: tuple[int, ...]
    locked_numbers: tuple[int, ...]
    q: FloatArray
    q_ref: FloatArray
    locked_angle: FloatArray
    brake: FloatArray
    brake_ref: FloatArray
    attitude: FloatArray | None
    com_displacement: FloatArray | None
    angular_velocity: FloatArray | None
    reference: SpacecraftResponse | None
    timestep: float
    mujoco_version: str

    @property
    def spacecraft(self) -> str:
        """``"free"`` (a free body in MuJoCo) or ``"held"`` (welded to the world)."""
        return "free" if self.attitude is not None else "held"

    @property
    def tracking_error_deg(self) -> float:
        """Largest |q - q_ref| of the driven joints over the replay [deg]."""
        return float(np.degrees(np.abs(self.q - self.q_ref).max())) if self.q.size else 0.0

    @property
    def brake_give_deg(self) -> float:
        """Largest |angle - lock angle| of the braked joints [deg] (the joint equality is soft)."""
        return float(np.degrees(np.abs(self.locked_angle).max())) if self.locked_angle.size else 0.0

    @property
    def attitude_change_deg(self) -> float | None:
        """MuJoCo's final spacecraft attitude change [deg] (None: fixed base)."""
        simulated = self.simulated_response()
        return None if simulated is None else simulated.final_attitude_change_deg

    @property
    def attitude_difference_deg(self) -> float | None:
        """Angle of the rotation between MuJoCo's and jointlock's final attitudes [deg]."""
        if self.attitude is None or self.reference is None:
            return None
        a, b = self.attitude[-1], self.reference.attitude[-1]
        # the rotation a^-1 b: its vector part without cancellation (acos of the dot is 0 below 1e-8)
        vector = a[0] * b[1:] - b[0] * a[1:] - np.cross(a[1:], b[1:])
        scalar = float(np.dot(a, b))
        return float(np.degrees(2.0 * math.atan2(float(np.linalg.norm(vector)), abs(scalar))))

    def simulated_response(self) -> SpacecraftResponse | None:
        """MuJoCo's spacecraft as a :class:`~jointlock.analysis.spacecraft.SpacecraftResponse`
        (attitude, rate, drift on :attr:`t`); None with the spacecraft held."""
        if self.attitude is None or self.angular_velocity is None or self.com_displacement is None:
            return None
        return SpacecraftResponse(self.t, self.attitude, self.angular_velocity, self.com_displacement)

    def rows(self) -> list[dict[str, Any]]:
        """The comparison: ``{"quantity", "short", "unit", "jointlock", "mujoco", "difference"}``
        per figure (``difference`` = MuJoCo - jointlock; for the attitude, the angle between the
        two final attitudes; ``short``: the name in a one-line summary, empty for the replay's own
        diagnostics: tracking error, brake give)."""
        out: list[dict[str, Any]] = []

        def row(quantity: str, unit: str, ours: float, theirs: float, diff: float | None = None, short: str = "") -> None:
            out.append(
                {
                    "quantity": quantity,
                    "short": short,
                    "unit": unit,
                    "jointlock": ours,
                    "mujoco": theirs,
                    "difference": theirs - ours if diff is None else diff,
                }
            )

        ref, simulated = self.reference, self.simulated_response()
        if ref is not None and simulated is not None:
            row(
                "spacecraft attitude change at the end",
                "deg",
                ref.final_attitude_change_deg,
                simulated.final_attitude_change_deg,
                float(self.attitude_difference_deg or 0.0),
                "attitude change",
            )
            row(
                "spacecraft peak rate",
                "deg/s",
                ref.peak_rate_deg_s,
                simulated.peak_rate_deg_s,
                short="peak rate",
            )
            row("spacecraft centre-of-mass drift", "m", ref.com_drift_m, simulated.com_drift_m, short="drift")
        for i, j in enumerate(self.locked_numbers):
            row(
                f"peak brake torque, joint {j} (spacecraft {self.spacecraft})",
                "N m",
                float(np.abs(self.brake_ref[:, i]).max()),
                float(np.abs(self.brake[:, i]).max()),
                short=f"brake {j} peak",
            )
        row("joint tracking error (largest)", "deg", 0.0, self.tracking_error_deg)
        if self.locked_numbers:
            row("locked joint give (largest)", "deg", 0.0, self.brake_give_deg)
        return out

    def summary(self) -> list[str]:
        """One line per figure: quantity, jointlock, MuJoCo, difference."""
        lines = [
            f"checked in MuJoCo {self.mujoco_version} ({self.label}: {self.t.size - 1} steps of "
            f"{self.timestep:g} s, RK4, contacts off):"
        ]
        for r in self.rows():
            lines.append(
                f"  {r['quantity']:<46} jointlock {r['jointlock']:>12.6g}  MuJoCo {r['mujoco']:>12.6g}  "
                f"difference {r['difference']:+.3g} {r['unit']}"
            )
        return lines

    def to_dict(self) -> dict[str, Any]:
        """The comparison rows and the replay's settings (plain JSON)."""
        return {
            "simulator": f"MuJoCo {self.mujoco_version}",
            "label": self.label,
            "timestep_s": self.timestep,
            "steps": int(self.t.size - 1),
            "spacecraft": self.spacecraft,
            "rows": self.rows(),
        }

    def time_series(self) -> dict[str, FloatArray]:
        """``t`` [s], MuJoCo's ``attitude_change_deg`` (fixed base: absent) and each
        ``brake{j}_Nm``, for CSV and plots."""
        cols: dict[str, FloatArray] = {"t": self.t}
        if (simulated := self.simulated_response()) is not None:
            cols["attitude_change_deg"] = simulated.attitude_change_deg
        for i, j in enumerate(self.locked_numbers):
            cols[f"brake{j}_Nm"] = self.brake[:, i]
        return cols

    def file_names(self, stem: str = "mujoco") -> list[str]:
        """The names :meth:`write` writes."""
        return with_svg([f"{stem}.png"]) + [f"{stem}.csv", f"{stem}.json"]

    def write(self, out: str | Path, stem: str = "mujoco") -> list[str]:
        """Write ``<stem>.png`` (and ``.svg``: :func:`jointlock.plots.sim.plot_replay`),
        ``<stem>.csv`` (MuJoCo's series next to jointlock's: ``t``, ``attitude_change_deg`` and
        ``attitude_change_jointlock_deg``, ``brake{j}_Nm`` and ``brake{j}_jointlock_Nm``) and
        ``<stem>.json`` (:meth:`to_dict`) to the folder ``out``; returns their names."""
        from ..plots._common import offscreen_figure
        from ..plots.sim import plot_replay

        folder = Path(out)
        folder.mkdir(parents=True, exist_ok=True)
        names = write_figure(plot_replay(self, fig=offscreen_figure((7.0, 5.6))), folder, f"{stem}.png")
        cols = self.time_series()
        if self.reference is not None:
            cols["attitude_change_jointlock_deg"] = self.reference.attitude_change_deg
        for i, j in enumerate(self.locked_numbers):
            cols[f"brake{j}_jointlock_Nm"] = self.brake_ref[:, i]
        atomic_write_text(folder / f"{stem}.csv", csv_text(cols))
        atomic_write_json(folder / f"{stem}.json", self.to_dict())
        return names + [f"{stem}.csv", f"{stem}.json"]
