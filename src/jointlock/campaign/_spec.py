"""A validated campaign (:class:`CampaignSpec`): the base scenario, what to vary, filters,
columns, report axes; and the scenario fields a campaign may vary (:func:`scenario_field`).
The file is read by ``_read``."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..errors import CampaignError
from ..scenario import ALL_TABLES, DEPRECATED_FIELDS, TOP_FIELDS, Field
from ..scenario._fields import _hint

#: Ways to draw ``[sample]`` points (``scipy.stats.qmc`` for the quasi-random ones).
SAMPLE_METHODS = ("random", "sobol", "lhs")
#: Comparisons an ``[[exclude]]`` filter may use on one field.
COMPARISONS = ("eq", "ne", "lt", "le", "gt", "ge", "in")
#: Reductions a column may apply to a list-valued result (``"halt.peak_velocity_deg_s|max"``).
REDUCERS = ("max", "min", "mean", "sum", "absmax", "len", "first", "last")
#: Cases above which running needs explicit consent (``--yes``, ``max_cases=None``).
CONFIRM_CASES = 100_000
#: Most cases one campaign file may describe (the plan is held in memory).
MAX_CASES = 2_000_000
#: Scenario fields a campaign may not vary (they do not change a result).
NOT_VARIED = ("title", "description", "out", "root_link", "tip_link", "freeze_deg", "freeze_m", "srdf", "meshes", "check_in")

_TOP_KEYS = (
    "title",
    "description",
    "scenario",
    "seed",
    "out",
    "columns",
    "set",
    "grid",
    "zip",
    "sample",
    "exclude",
    "report",
)
_SAMPLE_KEYS = ("method", "n", "ranges")
_REPORT_KEYS = ("x", "y", "worst", "worse")


@dataclass(frozen=True)
class SampleSpec:
    """``[sample]``: ``n`` points drawn from ``ranges`` (``{field: (lo, hi)}``, inclusive for
    integer fields) by ``method`` (``random``: numpy's generator; ``sobol``: scrambled Sobol',
    ``n`` a power of 2; ``lhs``: Latin hypercube), seeded by the campaign seed."""

    method: str
    n: int
    ranges: Mapping[str, tuple[float, float]]


@dataclass(frozen=True)
class ReportSpec:
    """``[report]``: heatmap axes ``x`` and ``y`` (varied fields; default: chosen from the
    sweep), the column the worst cases are ranked by and whether ``"higher"`` or ``"lower"``
    values are worse."""

    x: str | None = None
    y: str | None = None
    worst: str | None = None
    worse: str | None = None


@dataclass(frozen=True, eq=False)
class CampaignSpec:
    """A validated campaign file (see ``docs/campaigns.md`` for the format).

    Attributes
    ----------
    source
        The campaign file (or a label).
    title
        Title of the report.
    scenario, scenario_source, scenario_dir
        The base scenario as read (TOML data, not yet resolved), where it came from, and the
        folder its relative paths are resolved against.
    seed
        Campaign seed: each case's seed derives from it and the case's key; ``[sample]``
        draws from it.
    fixed
        ``[set]``: overrides applied to every case (``{"table.field": value}``).
    grid, zipped, sample
        What varies: ``[grid]`` (cartesian product), ``[zip]`` (one value of each per row,
        equal lengths) and ``[sample]`` draws; the three combine by cartesian product.
    exclude
        ``[[exclude]]`` filters: a case matching every condition of one filter is dropped.
    columns
        Result figures recorded per case (``"job.path|reducer"``); empty: each job's
        headline figures (:data:`jointlock.campaign.DEFAULT_COLUMNS`).
    out
        Default output folder (relative to the campaign file's folder).
    report
        Report axes and ranking.
    """

    source: str
    title: str
    scenario: Mapping[str, Any]
    scenario_source: str
    scenario_dir: Path
    seed: int = 0
    fixed: Mapping[str, Any] = field(default_factory=dict)
    grid: Mapping[str, tuple[Any, ...]] = field(default_factory=dict)
    zipped: Mapping[str, tuple[Any, ...]] = field(default_factory=dict)
    sample: SampleSpec | None = None
    exclude: tuple[Mapping[str, Any], ...] = ()
    columns: tuple[str, ...] = ()
    out: str | None = None
    report: ReportSpec = field(default_factory=ReportSpec)
    base_dir: Path = field(default_factory=Path.cwd)

    @property
    def varied(self) -> tuple[str, ...]:
        """The varied fields, in the order ``[grid]``, ``[zip]``, ``[sample]``."""
        sampled = tuple(self.sample.ranges) if self.sample else ()
        return tuple(self.grid) + tuple(self.zipped) + sampled

    def count_before_filters(self) -> int:
        """Cases described before ``[[exclude]]``: the product of the sections' sizes."""
        n = math.prod(len(v) for v in self.grid.values())
        if self.zipped:
            n *= len(next(iter(self.zipped.values())))
        if self.sample:
            n *= self.sample.n
        return n

    def default_out(self) -> Path:
        """The output folder: ``out``, else ``<campaign file stem>-campaign``, both relative to
        the campaign file's folder (so a run resumes from wherever it is started)."""
        path = Path(self.out or f"{Path(self.source).stem}-campaign")
        return path if path.is_absolute() else self.base_dir / path

    def to_dict(self) -> dict[str, Any]:
        """Plain data from which :func:`spec_from_dict` rebuilds the spec (kept in the ledger)."""
        return {
            "source": self.source,
            "title": self.title,
            "scenario": dict(self.scenario),
            "scenario_source": self.scenario_source,
            "scenario_dir": str(self.scenario_dir),
            "base_dir": str(self.base_dir),
            "seed": self.seed,
            "set": dict(self.fixed),
            "grid": {k: list(v) for k, v in self.grid.items()},
            "zip": {k: list(v) for k, v in self.zipped.items()},
            "sample": None
            if self.sample is None
            else {
                "method": self.sample.method,
                "n": self.sample.n,
                "ranges": {k: list(v) for k, v in self.sample.ranges.items()},
            },
            "exclude": [dict(f) for f in self.exclude],
            "columns": list(self.columns),
            "out": self.out,
            "report": {k: getattr(self.report, k) for k in _REPORT_KEYS},
        }


def spec_from_dict(data: Mapping[str, Any]) -> CampaignSpec:
    """The :class:`CampaignSpec` of :meth:`CampaignSpec.to_dict`'s data (already validated)."""
    sample = data.get("sample")
    return CampaignSpec(
        source=data["source"],
        title=data["title"],
        scenario=data["scenario"],
        scenario_source=data["scenario_source"],
        scenario_dir=Path(data["scenario_dir"]),
        base_dir=Path(data["base_dir"]),
        seed=int(data["seed"]),
        fixed=dict(data["set"]),
        grid={k: tuple(v) for k, v in data["grid"].items()},
        zipped={k: tuple(v) for k, v in data["zip"].items()},
        sample=None
        if sample is None
        else SampleSpec(sample["method"], int(sample["n"]), {k: tuple(v) for k, v in sample["ranges"].items()}),
        exclude=tuple(data["exclude"]),
        columns=tuple(data["columns"]),
        out=data.get("out"),
        report=ReportSpec(**data["report"]),
    )


def scenario_field(name: str, where: str) -> tuple[str, Field]:
    """The current dotted name and schema of the scenario field ``name`` (``"robot"``,
    ``"halt.T"``, a former name such as ``"limits.vmax_deg"``), or a :class:`CampaignError`
    naming ``where`` with a did-you-mean."""
    table, _, key = name.rpartition(".")
    if not table and key in TOP_FIELDS and key not in NOT_VARIED:
        return key, TOP_FIELDS[key]
    if table in ALL_TABLES:
        key = DEPRECATED_FIELDS.get(table, {}).get(key, key)
        if key in ALL_TABLES[table]:
            return f"{table}.{key}", ALL_TABLES[table][key]
    names = varied_names()
    if name in _TOP_KEYS:
        raise CampaignError(
            f"{where}: {name!r} is a top-level key of the campaign file: write it before the first "
            "[table] (TOML puts every line after a [table] header into that table)"
        )
    raise CampaignError(
        f"{where}: unknown scenario field {name!r}{_hint(name, names)}; fields are the names of "
        "`jointlock run --set`: TABLE.FIELD (e.g. failure.joint, halt.T) or a top-level field "
        f"({', '.join(k for k in TOP_FIELDS if k not in NOT_VARIED)})"
    )


def varied_names() -> list[str]:
    """Every field name a campaign may vary."""
    top = [k for k in TOP_FIELDS if k not in NOT_VARIED]
    return top + [f"{t}.{k}" for t, fields in ALL_TABLES.items() for k in fields]
