"""The validated scenario (:class:`Scenario`): resolved plain data, its jobs and overrides."""

from __future__ import annotations

import copy
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

#: The overrides that change the failure (``jointlock run --lock`` sets them all).
FAILURE_KEYS = ("failure.joint", "failure.angle_deg", "failure.also_locked_deg")


@dataclass(frozen=True)
class Scenario:
    """A validated scenario.

    Attributes
    ----------
    data
        The resolved scenario: every table with its defaults, file paths absolute; plain
        data (str, int, float, bool, lists, dicts) in file units (degrees).
    jobs
        Jobs to run, in :data:`JOB_ORDER`.
    source
        The file it came from (or a label such as ``"built-in demo scenario"``).
    overrides
        The command-line overrides applied to the file: ``{"table.field": {"file": value in
        the file or None, "value": value used}}`` (empty when none).
    """

    data: dict[str, Any]
    jobs: tuple[str, ...]
    source: str
    base_dir: Path = field(default_factory=Path.cwd)
    overrides: Mapping[str, Any] = field(default_factory=dict)

    def failure_overridden(self) -> bool:
        """Whether an override changed the file's failure (joint, angle or the joints locked
        before it)."""
        return any(
            key in FAILURE_KEYS and item["file"] != item["value"]
            for key, item in self.overrides.items()
        )

    def to_dict(self) -> dict[str, Any]:
        return copy.deepcopy(self.data) | {"jobs": list(self.jobs)}

    def table(self, name: str) -> dict[str, Any]:
        return dict(self.data.get(name, {}))

    @property
    def lock(self) -> tuple[int, float] | None:
        """(joint number, angle [deg]) of the failure, or None."""
        f = self.data.get("failure", {})
        if f.get("joint") is None or f.get("angle_deg") is None:
            return None
        return int(f["joint"]), float(f["angle_deg"])

    @property
    def locks(self) -> dict[int, float]:
        """``{joint number: angle [deg]}`` of every locked joint: ``[failure] also_locked_deg``,
        then the failure's own (empty without a failure)."""
        lk = self.lock
        if lk is None:
            return {}
        earlier = self.data.get("failure", {}).get("also_locked_deg") or {}
        return {**{int(j): float(a) for j, a in earlier.items()}, lk[0]: lk[1]}


def job_lock_args(scenario: Scenario) -> list[str]:
    """``["--lock", "J=DEG", ...]`` for every locked joint (those locked before the failure,
    then the failure's), or ``[]``."""
    return [arg for j, a in scenario.locks.items() for arg in ("--lock", f"{j}={a!r}")]
