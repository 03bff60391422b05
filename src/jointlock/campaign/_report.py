"""The report of a campaign: a self-contained HTML page (:func:`write_campaign_report`) with
what varied, the headline numbers, heatmaps of every recorded result over two varied fields
(e.g. failure joint x failure time -> share of feasible halts, smallest halt time, base torque,
jump reduction), their distributions, the worst cases -- each written as a plain scenario file
that ``jointlock run`` re-runs exactly -- and the failed cases with their errors."""

from __future__ import annotations

import html
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from .. import report as rp
from ..errors import CampaignError
from ..io.files import atomic_write_text, figure_png, toml_document
from ..plots._common import offscreen_figure
from ..plots.campaign import plot_distribution, plot_heatmap
from ..scenario import apply_overrides
from ..scenario._fields import _hint
from ._cases import params_text
from ._columns import WORSE, is_numeric
from ._ledger import open_ledger
from ._results import CampaignStatus, CampaignTable, campaign_status, campaign_table, run_ending
from ._spec import spec_from_dict

#: Distinct values above which a numeric field is binned on a heatmap axis.
MAX_CATEGORIES = 24
#: Bins of a binned heatmap axis.
AXIS_BINS = 10
#: Most heatmaps and histograms in one report (the rest are named in a note).
MAX_FIGURES = 16
#: Folder (in the campaign's output folder) of the worst cases' scenario files.
WORST_DIR = "worst"
#: Columns that rank the worst cases by default, the first recorded one (else any of
#: :data:`~jointlock.campaign._columns.WORSE`).
WORST_FIRST = (
    "halt.minimum_T_s",
    "halt.global_torque_Nm",
    "jump.jump_after|mean",
    "jump.mean_reduction",
    "replan.max_tracking_position_error_m",
    "workspace.share_kept",
    "singular.sigma_min",
)
#: Preferred heatmap axes, in order (y first: the failing joint reads best down the side).
_PREFERRED_Y = ("failure.joint", "robot", "base")
_PREFERRED_X = ("failure.time_s", "failure.angle_deg", "halt.T")


@dataclass(frozen=True, eq=False)
class CampaignReport:
    """What a campaign's report shows (``write()`` writes it).

    Attributes
    ----------
    status, table
        The campaign's counts and its finished cases.
    x, y
        The varied fields of the heatmaps' axes (None when fewer are varied).
    worst_column, worse
        The result the worst cases are ranked by and which way is worse.
    worst
        The worst cases' table rows, worst first.
    compiled
        The mode the cases ran in (:mod:`jointlock.compiled`; None for a campaign run before
        it was recorded): the worst cases' scenario files say it, so that ``jointlock run``
        gives their numbers bit for bit.
    """

    status: CampaignStatus
    table: CampaignTable
    spec: dict[str, Any]
    x: str | None
    y: str | None
    worst_column: str | None
    worse: str
    worst: tuple[dict[str, Any], ...]
    compiled: str | None = None

    def to_dict(self) -> dict[str, Any]:
        return {
            "status": self.status.to_dict(),
            "x": self.x,
            "y": self.y,
            "worst_column": self.worst_column,
            "worse": self.worse,
            "worst": [{k: r[k] for k in ("index", "key", *self.table.params, self.worst_column)} for r in self.worst]
            if self.worst_column
            else [],
        }

    def summary(self) -> list[str]:
        lines = self.status.summary()[:3]
        if self.worst_column and self.worst:
            lines.append(f"worst cases by {self.worst_column} ({self.worse} is worse):")
            for r in self.worst[:5]:
                lines.append(f"  #{r['index']} ({params_text({p: r[p] for p in self.table.params}, limit=80)}): "
                             f"{_fmt(r[self.worst_column])}")  # fmt: skip
        return lines

    def write(self, path: str | Path | None = None) -> list[Path]:
        """Write ``report.html`` (default: in the campaign's output folder) and the worst
        cases' scenario files (``worst/case-INDEX.toml`` beside it); returns the paths."""
        out = Path(self.status.out)
        page = Path(path) if path is not None else out / "report.html"
        page.parent.mkdir(parents=True, exist_ok=True)
        written = self._write_worst(page.parent)
        atomic_write_text(page, self.html(page.parent))
        return [page, *written]

    def _case_file(self, row: dict[str, Any]) -> str:
        return f"{WORST_DIR}/case-{row['index']}-{row['key'][:8]}.toml"

    def _write_worst(self, folder: Path) -> list[Path]:
        spec = spec_from_dict(self.spec)
        written = []
        for row in self.worst:
            overrides = {**spec.fixed, **{p: row[p] for p in self.table.params if row.get(p) is not None}}
            overrides["seed"] = row["case_seed"]  # the seed the case ran with (from its key)
            data = apply_overrides(spec.scenario, overrides, source=spec.scenario_source)
            data["title"] = f"{spec.title}: case {row['index']} ({params_text({p: row[p] for p in self.table.params})})"
            data.pop("out", None)
            robot = Path(str(data.get("robot", "")))
            if robot.suffix.lower() in (".toml", ".urdf") and not robot.is_absolute():
                data["robot"] = str((spec.scenario_dir / robot).resolve())
            if self.compiled is not None:  # the mode the case ran in: the same numbers, bit for bit
                data.setdefault("compiled", self.compiled)
            task_file = (data.get("task") or {}).get("file")
            if task_file and not Path(task_file).is_absolute():  # relative to the base scenario's folder
                data["task"] = {**data["task"], "file": str((spec.scenario_dir / task_file).resolve())}
            header = (
                f"# Case {row['index']} of the campaign {spec.source} (key {row['key']}), as a plain scenario:\n"
                f"#   jointlock run {self._case_file(row)}\n# gives the same numbers as the campaign (same seed).\n"
            )
            path = folder / self._case_file(row)
            atomic_write_text(path, header + toml_document(data))
            written.append(path)
        return written

    def html(self, folder: Path | None = None) -> str:
        """The report page (links to the worst cases' files relative to ``folder``)."""
        s, t = self.status, self.table
        sections: list[rp.Section | None] = [
            _audit_section(Path(s.out), t.rows, {f["key"]: f["error_message"] for f in s.failures}),
            _overview(s, self.spec),
            _varied(self.spec),
        ]
        ok_rows = [r for r in t.rows if r["status"] == "ok"]
        numeric = [m for m in t.metrics if is_numeric([r.get(m) for r in ok_rows])]
        sections.append(_headline(ok_rows, numeric))
        # a result with one value over every case says all in the table: no figure for it
        varying = [m for m in numeric if len({r.get(m) for r in ok_rows if r.get(m) is not None}) > 1]
        if self.x or self.y:
            sections.append(self._heatmaps(list(t.rows), varying))
        sections.append(_distributions(ok_rows, varying))
        if self.worst_column:
            sections.append(self._worst_section())
        sections.append(_failures(s, t))
        page = rp.render_html(
            f"jointlock campaign: {s.title}",
            [sec for sec in sections if sec is not None],
            intro=(
                f"Campaign <code>{html.escape(s.source)}</code>: {s.planned} cases, {s.ok} ok, "
                + (f"{s.infeasible} infeasible (an answer: nothing keeps the limits), {s.failed - s.infeasible} failed"
                   if s.infeasible else f"{s.failed} failed")
                + (f", <b>{s.remaining} not run yet</b>" if s.remaining else "")
                + f". Every number is in <code>{html.escape(str(Path(s.out) / 'ledger.sqlite'))}</code> "
                "(<code>jointlock campaign export</code> writes it as CSV or Parquet)."
            ),
            toc=True,
            footer="Generated by <code>jointlock campaign report</code>.",
        )
        return page

    def _heatmaps(self, rows: list[dict[str, Any]], numeric: list[str]) -> rp.Section:
        """One heatmap per result over (x, y); first, when some cases failed, the share of
        cases that ran every job."""
        sec = rp.Section("Heatmaps")
        xs, x_labels = _axis(rows, self.x)
        ys, y_labels = _axis(rows, self.y)
        sec.paragraphs.append(
            f"Each cell: the mean over the cases in it (a share for yes/no results) of "
            f"{html.escape(self.y or '-')} (rows) x {html.escape(self.x or '-')} (columns), other varied "
            "fields pooled; blank: no finished case."
        )
        ran = "ran every job (no error)"
        failed = any(r["status"] != "ok" for r in rows)
        if len(numeric) > MAX_FIGURES:
            sec.notes.append(f"not drawn (more than {MAX_FIGURES} results): {', '.join(numeric[MAX_FIGURES:])}")
        for metric in ([ran] if failed else []) + numeric[:MAX_FIGURES]:
            values = [r["status"] == "ok" for r in rows] if metric == ran else [r.get(metric) for r in rows]
            share = all(isinstance(v, bool) for v in values if v is not None)
            v = np.array([np.nan if x is None else float(x) for x in values])
            ok = np.isfinite(v)
            cell = (np.asarray(ys)[ok], np.asarray(xs)[ok])
            sums = np.zeros((len(y_labels), len(x_labels)))
            n = np.zeros_like(sums)
            np.add.at(sums, cell, v[ok])
            np.add.at(n, cell, 1.0)
            grid = np.full_like(sums, np.nan)
            np.divide(sums, n, out=grid, where=n > 0)
            fig = offscreen_figure((min(2.5 + 0.6 * len(x_labels), 12.0), min(2.0 + 0.45 * len(y_labels), 9.0)))
            plot_heatmap(
                grid, x_labels, y_labels, x_name=self.x or "", y_name=self.y or "",
                label=("share " if share else "mean ") + metric, title=metric, share=share, ax=fig.add_subplot(),
            )  # fmt: skip
            fig.tight_layout()
            sec.images.append(((f"share of cases with {metric} = yes" if share else f"mean of {metric}"), figure_png(fig)))
        return sec

    def _worst_section(self) -> rp.Section:
        col = self.worst_column or ""
        sec = rp.Section(f"Worst cases by {col}")
        sec.paragraphs.append(
            f"The {len(self.worst)} cases with the {'highest' if self.worse == 'higher' else 'lowest'} "
            f"{html.escape(col)}. Each is a plain scenario file: <code>jointlock run FILE</code> re-runs it "
            "with the campaign's seed for that case and writes its full report."
        )
        others = [m for m in self.table.metrics if m != col][:4]
        header = ["#", *self.table.params, col, *others]
        sec.tables.append((header, [[r["index"], *(r[p] for p in self.table.params), r[col], *(r.get(m) for m in others)]
                                    for r in self.worst]))  # fmt: skip
        links = ", ".join(
            f'<a href="{html.escape(self._case_file(r))}">case {r["index"]}</a>' for r in self.worst
        )
        sec.paragraphs.append(f"Scenario files: {links}.")
        return sec


def _fmt(v: Any) -> str:
    if isinstance(v, float):
        return f"{v:.6g}"
    return str(v)


def _overview(s: CampaignStatus, spec: dict[str, Any]) -> rp.Section:
    sec = rp.Section("Campaign")
    sec.facts += [
        ("campaign file", s.source),
        ("base scenario", spec.get("scenario_source", "?")),
        ("campaign seed", spec.get("seed")),
        ("cases", f"{s.planned} planned: {s.ok} ok, {s.failed} failed, {s.remaining} not run"),
        ("work", f"{s.case_seconds:.1f} s of case time over {len(s.runs)} run(s)"),
    ]
    if spec.get("set"):
        sec.facts.append(("the same for every case", params_text(spec["set"], limit=400)))
    sec.tables.append(
        (
            ["run", "started", "engine", "sent", "ok", "failed", "ended"],
            [
                [r["id"], r["started_at"], r["engine"], r["to_run"], r["ok"], r["failed"], run_ending(r)]
                for r in s.runs
            ],
        )
    )  # fmt: skip
    return sec


def _varied(spec: dict[str, Any]) -> rp.Section:
    sec = rp.Section("What varied")
    rows = [[name, "grid", len(v), _values(v)] for name, v in spec.get("grid", {}).items()]
    rows += [[name, "zip", len(v), _values(v)] for name, v in spec.get("zip", {}).items()]
    sample = spec.get("sample")
    if sample:
        rows += [
            [name, f"sample ({sample['method']})", sample["n"], f"[{lo:g}, {hi:g}]"]
            for name, (lo, hi) in sample["ranges"].items()
        ]
    sec.tables.append((["field", "how", "values", "of"], rows))
    if spec.get("exclude"):
        sec.notes += [f"excluded: cases with {params_text(f, limit=300)}" for f in spec["exclude"]]
    return sec


def _values(values: Sequence[Any]) -> str:
    text = ", ".join(_fmt(v) for v in values)
    return text if len(text) <= 120 else text[:117] + "..."


def _headline(rows: list[dict[str, Any]], numeric: list[str]) -> rp.Section:
    sec = rp.Section("Results over every finished case")
    table = []
    for m in numeric:
        vals = [r[m] for r in rows if r.get(m) is not None]
        if vals and all(isinstance(v, bool) for v in vals):
            table.append([m, len(vals), f"yes in {100 * sum(vals) / len(vals):.1f} %", None, None, None])
        elif vals:
            a = np.asarray(vals, dtype=float)
            table.append([m, len(vals), float(a.min()), float(np.median(a)), float(a.mean()), float(a.max())])
    sec.tables.append((["result", "cases", "min", "median", "mean", "max"], table))
    if not rows:
        sec.paragraphs.append("No case finished yet.")
    return sec


def _distributions(rows: list[dict[str, Any]], numeric: list[str]) -> rp.Section | None:
    metrics = [m for m in numeric if not all(isinstance(r.get(m), bool) for r in rows if r.get(m) is not None)]
    if not rows or not metrics:
        return None
    sec = rp.Section("Distributions")
    if len(metrics) > MAX_FIGURES:
        sec.notes.append(f"not drawn (more than {MAX_FIGURES} results): {', '.join(metrics[MAX_FIGURES:])}")
    for m in metrics[:MAX_FIGURES]:
        fig = offscreen_figure((5.0, 3.2))
        plot_distribution([np.nan if r.get(m) is None else float(r[m]) for r in rows], name=m, ax=fig.add_subplot())
        fig.tight_layout()
        sec.images.append((f"distribution of {m}", figure_png(fig)))
    return sec


def _failures(s: CampaignStatus, t: CampaignTable) -> rp.Section:
    sec = rp.Section("Failed cases")
    if not s.failures:
        sec.paragraphs.append("None: every finished case ran every job.")
        return sec
    sec.paragraphs.append(
        f"{len(s.failures)} case(s) raised; each is recorded with its error and the campaign went on. "
        "<code>jointlock campaign status</code> lists them; <code>run --retry-failed</code> runs them again."
    )
    sec.tables.append(
        (
            ["#", *t.params, "error", "message"],
            [[f["index"], *(f["params"].get(p) for p in t.params), f["error_type"], (f["error_message"] or "")[:300]]
             for f in s.failures[:100]],
        )
    )  # fmt: skip
    return sec


def _axis(rows: list[dict[str, Any]], name: str | None) -> tuple[list[int], list[str]]:
    """Each row's position on one heatmap axis and the axis labels: one per distinct value
    (sorted), or :data:`AXIS_BINS` equal bins of a numeric field with many values."""
    if name is None:
        return [0] * len(rows), ["all"]
    values = [r.get(name) for r in rows]
    distinct = sorted({_hashable(v) for v in values}, key=_sort_key)
    numeric = all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in distinct)
    if len(distinct) <= MAX_CATEGORIES or not numeric:
        where = {v: i for i, v in enumerate(distinct)}
        return [where[_hashable(v)] for v in values], [_fmt(v) for v in distinct]
    lo, hi = float(min(distinct)), float(max(distinct))
    edges = np.linspace(lo, hi, AXIS_BINS + 1)
    index = np.clip(np.searchsorted(edges, np.asarray(values, dtype=float), side="right") - 1, 0, AXIS_BINS - 1)
    labels = [f"{0.5 * (a + b):.3g}" for a, b in zip(edges[:-1], edges[1:])]
    return [int(i) for i in index], labels


def _hashable(v: Any) -> Any:
    return tuple(v) if isinstance(v, list) else v


def _sort_key(v: Any) -> tuple[int, Any]:
    return (0, v) if isinstance(v, (int, float)) else (1, str(v))


def _choose_axes(params: Sequence[str], rows: list[dict[str, Any]], x: str | None, y: str | None) -> tuple[str | None, str | None]:
    """The heatmap axes: those given, else the preferred names present (failure joint down
    the side, failure time / angle / halt time across), else the first varied fields."""
    varied = [p for p in params if len({_hashable(r.get(p)) for r in rows}) > 1] or list(params)
    if y is None:
        y = next((p for p in _PREFERRED_Y if p in varied and p != x), None)
    if x is None:
        x = next((p for p in _PREFERRED_X if p in varied and p != y), None)
        x = x or next((p for p in varied if p != y), None)
    if y is None:
        y = next((p for p in varied if p != x), None)
    return x, y


def campaign_report(
    out: str | Path,
    *,
    x: str | None = None,
    y: str | None = None,
    worst: str | None = None,
    worse: str | None = None,
    top: int = 10,
) -> CampaignReport:
    """The report of the campaign in ``out`` (axes and ranking default to the file's
    ``[report]``, else chosen from what varied and the recorded columns).

    Parameters
    ----------
    x, y
        Varied fields of the heatmaps' axes.
    worst, worse
        Column ranking the worst cases and ``"higher"``/``"lower"`` (which way is worse;
        default: known for the headline columns, else higher).
    top
        Worst cases listed (and written as scenario files).
    """
    status = campaign_status(out)
    table = campaign_table(out)
    with open_ledger(out) as ledger:
        spec = ledger.meta("spec") or {}
        compiled = ledger.meta("compiled")
    conf = spec.get("report", {})
    x, y = x or conf.get("x"), y or conf.get("y")
    for axis, name in (("x", x), ("y", y)):
        if name is not None and name not in table.params:
            raise CampaignError(
                f"report {axis} = {name!r} is not a varied field{_hint(name, table.params)}; varied: "
                f"{', '.join(table.params)}"
            )
    ok_rows = [r for r in table.rows if r["status"] == "ok"]
    x, y = _choose_axes(table.params, ok_rows, x, y)
    has_values = [m for m in table.metrics if any(r.get(m) is not None for r in ok_rows)]
    worst = worst or conf.get("worst") or next((m for m in WORST_FIRST if m in has_values), None)
    worst = worst or next((m for m in has_values if m in WORSE), None)
    if worst is not None and worst not in table.metrics:
        raise CampaignError(f"report: worst = {worst!r} is not a recorded column; columns: {', '.join(table.metrics)}")
    values = [r.get(worst) for r in ok_rows] if worst is not None else []
    if worst is not None and not any(v is not None for v in values):
        raise CampaignError(
            f"report: worst = {worst!r} has no value in any finished case (e.g. halt.minimum_T_s of a feasible "
            "halt needs halt.minimum_T = true); choose another column"
        )
    if worst is not None and not is_numeric(values):
        raise CampaignError(f"report: worst = {worst!r} does not hold numbers or yes/no values; it cannot rank cases")
    if x is not None and x == y:
        raise CampaignError(f"report: x and y are both {x!r}; give two different varied fields")
    worse = worse or conf.get("worse") or WORSE.get(worst or "", "higher")
    if worse not in ("higher", "lower"):
        raise CampaignError(f"report: worse must be 'higher' or 'lower'; got {worse!r}")
    ranked: list[dict[str, Any]] = []
    if worst is not None:
        scored = [r for r in ok_rows if r.get(worst) is not None]
        ranked = sorted(scored, key=lambda r: float(r[worst]), reverse=worse == "higher")[: max(int(top), 0)]
    return CampaignReport(status, table, spec, x, y, worst, worse, tuple(ranked), compiled)


def write_campaign_report(out: str | Path, path: str | Path | None = None, **options: Any) -> list[Path]:
    """Write the report of the campaign in ``out`` (:func:`campaign_report`'s ``options``);
    returns the files written (``report.html`` first)."""
    return campaign_report(out, **options).write(path)


def _audit_section(
    out: Path, table_rows: Sequence[dict[str, Any]] = (), messages: dict[str, str] | None = None
) -> rp.Section | None:
    """An audit's answer first (``audit.json``, :func:`~jointlock.campaign.run_audit`): the safe
    windows, the risk timeline (each joint's lock at each instant, safe or not) and the same grid
    interactive, each cell's numbers on hover (from the campaign table's ``table_rows``)."""
    path = out / "audit.json"
    if not path.is_file():
        return None
    import json

    try:
        data = json.loads(path.read_text())
        times, unsafe = [float(t) for t in data["times_s"]], [set(j) for j in data["unsafe_joints"]]
        windows, worst = data["windows_s"], data["worst_joint"]
    except (ValueError, KeyError, TypeError, OSError) as exc:  # a damaged file: said, not a traceback
        return rp.Section("Audit: safe windows", notes=[f"audit.json could not be read ({exc!r}); run the audit again"])
    sec = rp.Section("Audit: safe windows")
    if windows:
        text = ", ".join(f"[{a:g}, {b:g}] s" if b > a else f"{a:g} s" for a, b in windows)
        sec.paragraphs.append(f"<b>Safe windows</b> (at every audited instant in them, every audited lock leaves a "
                              f"feasible, clear halt within the attitude control's capacity; only the audited "
                              f"instants were checked): {html.escape(text)}.")  # fmt: skip
    else:
        sec.paragraphs.append("<b>NO SAFE WINDOW</b>: at every audited instant some lock leaves no safe halt.")
    joints = sorted({j for js in data["unsafe_joints"] for j in js} | set(data.get("joints", [])))
    rows = [[f"{t:g}", ", ".join(map(str, sorted(js))) or "none", "" if w is None else str(w)]
            for t, js, w in zip(times, unsafe, worst)]  # fmt: skip
    sec.tables.append((["t [s]", "locks with no safe halt", "worst joint"], rows, "risk timeline"))
    if joints and len(times) > 1:
        fig = offscreen_figure((min(3.0 + 0.5 * len(times), 12.0), 1.5 + 0.35 * max(len(joints), 1)))
        ax = fig.add_subplot()
        for t, js in zip(times, unsafe):
            for j in joints:
                ax.plot(t, j, "s", color="#b00020" if j in js else "#176f2c", markersize=9)
        for a, b in windows:
            ax.axvspan(a, b if b > a else a + 1e-9, color="#176f2c", alpha=0.12)
        ax.set_xlabel("failure instant t [s]")
        ax.set_ylabel("locked joint")
        ax.set_yticks(joints)
        ax.set_title("risk timeline: red, the lock leaves no safe halt; shaded, the safe windows", fontsize=9)
        fig.tight_layout()
        sec.images.append(("risk timeline", figure_png(fig)))
    cells = [r for r in table_rows if r.get("failure.joint") is not None and r.get("failure.time_s") is not None]
    if cells:
        sec.animations.append(
            ("every cell, interactive: hover a square for its numbers (green safe, red not, grey no halt)",
             audit_cell_figure(cells, messages))
        )  # fmt: skip
    return sec


#: What the interactive audit grid shows of a cell on hover: (column, label, format).
AUDIT_HOVER = (
    ("halt.feasible", "halt within the limits", "yes"),
    ("halt.collision_free", "clear of the bus and the arm", "yes"),
    ("halt.attitude_control.within", "within the wheels' capacity", "yes"),
    ("halt.minimum_T_s", "smallest feasible halt time [s]", ".3f"),
    ("halt.minimum_T_clear_s", "... keeping the clearance too [s]", ".3f"),
    ("halt.binding_limit", "binding limit", "s"),
    ("halt.clearance.motion_min_m", "closest approach [m]", "+.3f"),
    ("halt.spacecraft.attitude_change_deg", "free spacecraft turns [deg]", ".2f"),
    ("halt.attitude_control.peak_torque_Nm", "wheels' peak torque [N m]", ".4g"),
    ("halt.attitude_control.peak_momentum_Nms", "wheels' momentum [N m s]", ".4g"),
    ("halt.actuators.peak_brake_torque_Nm|max", "brake's peak torque [N m]", ".4g"),
    ("halt.sigma_min_at_failure", "sigma_min at the failure", ".3g"),
    ("halt.task_completion.completable", "task could be finished instead", "yes"),
    ("halt.task_completion.first_unreachable_s", "first pose out of reach at [s]", "g"),
    ("jump.jump_before", "joint-rate jump, uncompensated [rad/s]", ".4g"),
    ("jump.jump_after", "joint-rate jump, compensated [rad/s]", ".4g"),
    ("jump.limits_ok", "jump study keeps the limits", "yes"),
)


def _hover_value(value: Any, fmt: str) -> str:
    if value is None:
        return "n/a"
    if fmt == "yes":
        return "yes" if value else "NO"
    if fmt == "s":
        return html.escape(str(value))
    try:
        return format(float(value), fmt)
    except (TypeError, ValueError):
        return html.escape(str(value))


def audit_cell_figure(rows: Sequence[dict[str, Any]], messages: dict[str, str] | None = None) -> dict[str, Any]:
    """A plotly figure of an audit's cells (campaign-table rows with ``failure.joint`` and
    ``failure.time_s``): one square per cell at (instant, joint), green where the cell is safe
    (:func:`~jointlock.campaign._columns.audit_cell_safe`), red where its halt is not, grey where
    it has none (an infeasible or failed cell); hovering shows the cell's numbers, or the reason
    it has none (``messages``: case key -> error message)."""
    from ._columns import audit_cell_safe

    groups: dict[str, dict[str, list[Any]]] = {}
    for row in rows:
        ok = row.get("status") == "ok"
        kind = "safe" if audit_cell_safe(row) else ("no safe halt" if ok else "no halt")
        lines = [f"<b>joint {row['failure.joint']} locks at t = {float(row['failure.time_s']):g} s</b>"]
        if ok:
            lines += [f"{label}: {_hover_value(row.get(col), fmt)}" for col, label, fmt in AUDIT_HOVER if col in row]
        else:
            message = str((messages or {}).get(row.get("key", ""), "") or row.get("status"))
            lines.append(html.escape(message[:160]))
        g = groups.setdefault(kind, {"x": [], "y": [], "text": []})
        g["x"].append(float(row["failure.time_s"]))
        g["y"].append(int(row["failure.joint"]))
        g["text"].append("<br>".join(lines))
    colours = {"safe": "#176f2c", "no safe halt": "#b00020", "no halt": "#8a8f98"}
    data = [
        {"type": "scatter", "mode": "markers", "name": kind, "x": g["x"], "y": g["y"], "text": g["text"],
         "hoverinfo": "text", "marker": {"symbol": "square", "size": 18, "color": colours[kind]}}
        for kind, g in groups.items()
    ]  # fmt: skip
    joints = sorted({int(r["failure.joint"]) for r in rows})
    layout = {
        "xaxis": {"title": {"text": "failure instant t [s]"}},
        "yaxis": {"title": {"text": "locked joint"}, "tickvals": joints, "range": [min(joints) - 0.7, max(joints) + 0.7]},
        "margin": {"l": 60, "r": 20, "t": 20, "b": 50},
        "hovermode": "closest",
        "legend": {"orientation": "h"},
    }
    return {"data": data, "layout": layout, "config": {"displaylogo": False, "responsive": True}, "frames": []}
