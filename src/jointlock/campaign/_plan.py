"""What a campaign would run, without running it: :func:`plan_campaign` counts the cases and
those already finished, and times a few of the others for an estimate."""

from __future__ import annotations

import statistics
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..progress import Progress
from ._cases import plan_cases
from ._columns import check_columns, missing_columns
from ._engines import default_workers
from ._ledger import LEDGER_NAME, open_ledger
from ._read import as_spec
from ._spec import CampaignSpec
from ._worker import decode_result, make_task, run_batch


@dataclass(frozen=True)
class CampaignPlan:
    """What a campaign would run (:func:`plan_campaign`)."""

    title: str
    source: str
    out: str
    varied: dict[str, str]
    cases: int
    described: int
    excluded: int
    duplicates: int
    ok: int
    failed: int
    to_run: int
    jobs: tuple[str, ...]
    workers: int
    probe_seconds: tuple[float, ...] = ()
    probe_errors: tuple[str, ...] = ()
    unknown_columns: tuple[str, ...] = ()

    @property
    def seconds_per_case(self) -> float | None:
        return statistics.median(self.probe_seconds) if self.probe_seconds else None

    @property
    def estimate_s(self) -> float | None:
        """Wall time to run what is left on ``workers`` workers [s], from the timed cases."""
        per = self.seconds_per_case
        return None if per is None else per * self.to_run / self.workers

    def to_dict(self) -> dict[str, Any]:
        return {
            "title": self.title,
            "campaign_file": self.source,
            "out": self.out,
            "varied": self.varied,
            "cases": self.cases,
            "described": self.described,
            "excluded": self.excluded,
            "duplicates": self.duplicates,
            "ok": self.ok,
            "failed": self.failed,
            "to_run": self.to_run,
            "jobs": list(self.jobs),
            "workers": self.workers,
            "probe_seconds": list(self.probe_seconds),
            "probe_errors": list(self.probe_errors),
            "unknown_columns": list(self.unknown_columns),
            "seconds_per_case": self.seconds_per_case,
            "estimate_s": self.estimate_s,
        }

    def summary(self) -> list[str]:
        lines = [f"{self.title} ({self.source}); jobs: {', '.join(self.jobs)}"]
        lines += [f"  {name}: {how}" for name, how in self.varied.items()]
        dropped = []
        if self.excluded:
            dropped.append(f"{self.excluded} excluded by filters")
        if self.duplicates:
            dropped.append(f"{self.duplicates} duplicate(s)")
        lines.append(
            f"cases: {self.cases}" + (f" ({self.described} described, {', '.join(dropped)})" if dropped else "")
        )
        lines.append(f"finished in {self.out}: {self.ok} ok, {self.failed} failed; to run: {self.to_run}")
        if self.seconds_per_case is not None:
            est = self.estimate_s or 0.0
            lines.append(
                f"timed {len(self.probe_seconds)} case(s): {self.seconds_per_case:.3g} s each (median) -> about "
                f"{_duration(est)} with {self.workers} worker(s) if they scale perfectly (cases sharing a "
                "machine's memory run slower: allow up to 1.5x)"
            )
        if self.probe_errors:
            lines.append(f"{len(self.probe_errors)} timed case(s) raised (recorded, not fatal, in a run); first: "
                         f"{self.probe_errors[0]}")  # fmt: skip
        lines += [f"column {text}" for text in self.unknown_columns]
        return lines


def _duration(seconds: float) -> str:
    if seconds < 90:
        return f"{seconds:.0f} s"
    if seconds < 5400:
        return f"{seconds / 60:.0f} min"
    return f"{seconds / 3600:.1f} h"


def _varied_text(spec: CampaignSpec) -> dict[str, str]:
    out = {}
    for name, values in spec.grid.items():
        out[name] = f"{len(values)} value(s) [grid]: " + _values_text(values)
    for name, values in spec.zipped.items():
        out[name] = f"{len(values)} value(s) [zip]: " + _values_text(values)
    if spec.sample:
        for name, (lo, hi) in spec.sample.ranges.items():
            out[name] = f"{spec.sample.n} {spec.sample.method} draw(s) in [{lo:g}, {hi:g}] [sample]"
    return out


def _values_text(values: Sequence[Any]) -> str:
    text = ", ".join(f"{v:g}" if isinstance(v, float) else str(v) for v in values)
    return text if len(text) <= 70 else text[:67] + "..."


def plan_campaign(
    campaign: CampaignSpec | str | Path,
    out: str | Path | None = None,
    *,
    workers: int | None = None,
    probe: int = 3,
    max_cases: int | None = None,
    progress: bool = False,
) -> CampaignPlan:
    """Count a campaign's cases, those already finished in ``out``, and time ``probe`` of the
    cases still to run (in this process; nothing is written).

    Parameters
    ----------
    campaign
        A :class:`CampaignSpec` or the campaign file's path.
    out
        The output folder (default: the file's ``out``, else ``<file stem>-campaign``).
    workers
        Workers the estimate assumes (default: one per core).
    probe
        Cases to run and time for the estimate (0: none).
    max_cases
        Refuse larger campaigns (None: any size up to :data:`MAX_CASES`).
    progress
        A progress bar on stderr while the cases are resolved (from 1000 cases on).
    """
    spec = as_spec(campaign)
    n = spec.count_before_filters()
    with Progress(n, "resolving cases", enabled=None if progress and n >= 1000 else False) as bar:
        plan = plan_cases(spec, max_cases=max_cases, progress=bar.update)
    columns = check_columns(spec, plan)
    out = Path(out) if out is not None else spec.default_out()
    ok = failed = 0
    if (out / LEDGER_NAME).is_file():
        with open_ledger(out) as ledger:
            done_ok, done_err = ledger.finished_keys(status="ok"), ledger.finished_keys(status="error")
        keys = {c.key for c in plan.cases}
        ok, failed = len(keys & done_ok), len(keys & done_err)
        todo = [c for c in plan.cases if c.key not in done_ok and c.key not in done_err]
    else:
        todo = list(plan.cases)
    timings: list[float] = []
    errors: list[str] = []
    unknown: list[str] = []
    if probe > 0 and todo:
        picks = {round(i * (len(todo) - 1) / max(probe - 1, 1)) for i in range(min(probe, len(todo)))}
        outcomes = run_batch(make_task(spec, [todo[i] for i in sorted(picks)], columns))
        timings = [o.seconds for o in outcomes]
        errors = [f"{o.error_type}: {o.error_message}" for o in outcomes if not o.ok]
        for o in outcomes:
            if o.ok and o.result is not None:
                unknown += [t for t in missing_columns(decode_result(o.result), columns) if t not in unknown]
    return CampaignPlan(
        title=spec.title,
        source=spec.source,
        out=str(out),
        varied=_varied_text(spec),
        cases=len(plan),
        described=plan.described,
        excluded=plan.excluded,
        duplicates=plan.duplicates,
        ok=ok,
        failed=failed,
        to_run=len(todo),
        jobs=plan.jobs,
        workers=default_workers() if workers is None else workers,
        probe_seconds=tuple(timings),
        probe_errors=tuple(errors),
        unknown_columns=tuple(unknown),
    )


