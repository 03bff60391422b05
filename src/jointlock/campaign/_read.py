"""Reading a campaign file (:func:`load_campaign`): each section checked against the scenario
schema.

Every error is a :class:`~jointlock.errors.CampaignError` whose one line names the file, the
table and field, the value received and what is allowed (with a did-you-mean for names).
Nothing runs and nothing is written before the whole file is valid.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

from ..bounds import shown
from ..errors import CampaignError, ScenarioError
from ..io.files import check_path_text, path_inside, read_toml_file
from ..scenario import DEPRECATED_FIELDS, JOB_ORDER
from ..scenario._fields import _hint
from ..scenario._read import check_value as _check
from ._spec import (
    _REPORT_KEYS,
    _SAMPLE_KEYS,
    _TOP_KEYS,
    COMPARISONS,
    MAX_CASES,
    REDUCERS,
    SAMPLE_METHODS,
    CampaignSpec,
    ReportSpec,
    SampleSpec,
    scenario_field,
    varied_names,
)


def load_campaign(path: str | Path) -> CampaignSpec:
    """Read and validate a campaign file (format: ``docs/campaigns.md``).

    Raises
    ------
    CampaignError
        Missing or unreadable file, invalid TOML, an unknown table or field (with a
        did-you-mean), a value of the wrong type or out of range, an empty sweep, a range with
        ``lo > hi``, zipped lists of different lengths, a field varied twice, more than
        :data:`MAX_CASES` cases, or a base scenario that is itself invalid.
    """
    path = Path(path)
    data = read_toml_file(path, "campaign file", CampaignError)
    return campaign_from_dict(data, source=str(path), base_dir=path.resolve().parent)


def as_spec(campaign: CampaignSpec | str | Path) -> CampaignSpec:
    """``campaign`` itself, or the campaign file it names, read."""
    if isinstance(campaign, CampaignSpec):
        return campaign
    if isinstance(campaign, (str, Path)):
        return load_campaign(campaign)
    raise CampaignError(f"a campaign is a CampaignSpec or a campaign file's path; got {type(campaign).__name__}")


def campaign_from_dict(
    data: Mapping[str, Any], *, source: str = "campaign", base_dir: str | Path | None = None
) -> CampaignSpec:
    """Validate a campaign given as a mapping (the parsed TOML); see :func:`load_campaign`."""
    base_dir = Path.cwd() if base_dir is None else Path(base_dir)
    for key in data:
        if key not in _TOP_KEYS:
            raise CampaignError(
                f"{source}: unknown key {key!r}{_hint(key, _TOP_KEYS)}; allowed: {', '.join(_TOP_KEYS)}"
            )
    scenario, scenario_source, scenario_dir = _base_scenario(data.get("scenario"), source, base_dir)
    seed = data.get("seed", 0)
    if isinstance(seed, bool) or not isinstance(seed, int) or not 0 <= seed < 2**63:
        raise CampaignError(f"{source}: seed must be an integer >= 0; got {shown(seed)}")
    title = _string(data, "title", source) or Path(source).stem
    out = _string(data, "out", source)
    if out:
        path_inside(base_dir, out, f"{source}: out", CampaignError)
    _string(data, "description", source)
    fixed = {
        name: _value(value, name, f"{source}: set.{name}", base_dir)
        for name, value in _named_table(data, "set", source).items()
    }
    grid = {name: _sweep(values, name, f"{source}: grid.{name}", base_dir) for name, values in
            _named_table(data, "grid", source).items()}  # fmt: skip
    zipped = {name: _sweep(values, name, f"{source}: zip.{name}", base_dir) for name, values in
              _named_table(data, "zip", source).items()}  # fmt: skip
    lengths = {len(v) for v in zipped.values()}
    if len(lengths) > 1:
        sizes = ", ".join(f"{k}: {len(v)}" for k, v in zipped.items())
        raise CampaignError(f"{source}: [zip] lists must have equal lengths (one value per row); got {sizes}")
    sample = _sample(data.get("sample"), source)
    _check_once(source, grid, zipped, sample, fixed)
    if not (grid or zipped or sample):
        raise CampaignError(
            f"{source}: nothing varies: give at least one field in [grid], [zip] or [sample] "
            "(e.g. [grid] failure.joint = [1, 2, 3])"
        )
    spec = CampaignSpec(
        source=source,
        title=title,
        scenario=scenario,
        scenario_source=scenario_source,
        scenario_dir=scenario_dir,
        base_dir=base_dir,
        seed=seed,
        fixed=fixed,
        grid=grid,
        zipped=zipped,
        sample=sample,
        exclude=_filters(data.get("exclude", []), source, base_dir),
        columns=_columns(data.get("columns"), source),
        out=out,
        report=_report(data.get("report"), source),
    )
    _check_filters_and_report(spec)
    n = spec.count_before_filters()
    if n > MAX_CASES:
        raise CampaignError(
            f"{source}: the sweep describes {n:,} cases, more than the {MAX_CASES:,} one campaign may "
            "hold; split it into several campaign files"
        )
    return spec


def _string(data: Mapping[str, Any], key: str, source: str) -> str | None:
    value = data.get(key)
    if value is not None and not isinstance(value, str):
        raise CampaignError(f"{source}: {key} must be a string; got {shown(value)} ({type(value).__name__})")
    return value


def _base_scenario(value: Any, source: str, base_dir: Path) -> tuple[dict[str, Any], str, Path]:
    """The base scenario's TOML data, source and folder: ``scenario = "file.toml"`` (relative
    to the campaign file) or an inline ``[scenario]`` table."""
    if value is None:
        raise CampaignError(
            f'{source}: scenario is required: the base scenario file (scenario = "halt_000.toml") '
            "or an inline [scenario] table"
        )
    if isinstance(value, dict):
        return dict(value), f"{source} [scenario]", base_dir
    if not isinstance(value, str):
        raise CampaignError(
            f"{source}: scenario must be a scenario file's path or a [scenario] table; got "
            f"{type(value).__name__}"
        )
    path = check_path_text(value, f"{source}: scenario", CampaignError)
    path = path if path.is_absolute() else (base_dir / path).resolve()
    return read_toml_file(path, f"{source}: base scenario file", CampaignError), str(path), path.parent


def _flatten(table: Mapping[str, Any], prefix: str = "") -> dict[str, Any]:
    """``{"failure": {"joint": v}}`` (TOML's dotted keys) and ``{"failure.joint": v}`` (a
    quoted key) both as ``{"failure.joint": v}``; the value of a known field stays one value
    even when it is a table (an ``[[exclude]]`` condition such as ``{ lt = 2 }``)."""
    out: dict[str, Any] = {}
    fields = _known_names()
    for key, value in table.items():
        name = f"{prefix}{key}"
        if isinstance(value, dict) and value and name not in fields:
            out.update(_flatten(value, name + "."))
        else:
            out[name] = value
    return out


def _known_names() -> set[str]:
    """Every field name a campaign may use, former names included."""
    names = set(varied_names())
    names |= {f"{t}.{old}" for t, olds in DEPRECATED_FIELDS.items() for old in olds}
    return names


def _named_table(data: Mapping[str, Any], key: str, source: str) -> dict[str, Any]:
    raw = data.get(key, {})
    if not isinstance(raw, dict):
        raise CampaignError(
            f"{source}: [{key}] must be a table of scenario fields (e.g. failure.joint = ...); got "
            f"{type(raw).__name__}"
        )
    out: dict[str, Any] = {}
    for name, value in _flatten(raw).items():
        current, _ = scenario_field(name, f"{source}: [{key}]")
        if current in out:
            raise CampaignError(f"{source}: [{key}] gives {shown(current)} twice (under two names)")
        out[current] = value
    return out


def _value(value: Any, name: str, where: str, base_dir: Path) -> Any:
    """One value of field ``name`` checked against the scenario schema (a model file named in
    ``robot`` is made absolute against the campaign file's folder)."""
    _, spec = scenario_field(name, where)
    if isinstance(value, dict) and spec.kind != "locks":
        raise CampaignError(f"{where} must be {spec.allowed()}; got a table")
    try:
        checked = _check(value, spec, where)
    except ScenarioError as exc:
        in_set = isinstance(value, list) and ": set." in where and spec.kind not in ("numbers", "strings")
        vary = " -- to vary it, list its values in [grid] or [zip]" if in_set else ""
        raise CampaignError(f"{exc}{vary}") from None
    if name == "robot":
        check_path_text(checked, where, CampaignError)
    if name == "robot" and Path(checked).suffix.lower() in (".toml", ".urdf") and not Path(checked).is_absolute():
        checked = str((base_dir / checked).resolve())
    return checked


def _sweep(values: Any, name: str, where: str, base_dir: Path) -> tuple[Any, ...]:
    if not isinstance(values, list):
        raise CampaignError(
            f"{where} must be a list of the values to run (e.g. [1, 2, 3]); got {shown(values)} "
            f"({type(values).__name__})"
        )
    if not values:
        raise CampaignError(f"{where} is empty: give at least one value")
    checked = tuple(_value(v, name, f"{where}[{i}]", base_dir) for i, v in enumerate(values))
    seen: list[Any] = []
    for i, v in enumerate(checked):
        if v in seen:
            raise CampaignError(f"{where}[{i}] repeats the value {shown(v)}: each case would run twice")
        seen.append(v)
    return checked


def _sample(raw: Any, source: str) -> SampleSpec | None:
    if raw is None:
        return None
    where = f"{source}: [sample]"
    if not isinstance(raw, dict):
        raise CampaignError(f"{where} must be a table (method, n, ranges); got {type(raw).__name__}")
    for key in raw:
        if key not in _SAMPLE_KEYS:
            raise CampaignError(f"{where}: unknown key {key!r}{_hint(key, _SAMPLE_KEYS)}; allowed: method, n, ranges")
    method = raw.get("method", "random")
    if method not in SAMPLE_METHODS:
        hint = _hint(method, SAMPLE_METHODS) if isinstance(method, str) else ""
        raise CampaignError(f"{where}: method must be one of {', '.join(SAMPLE_METHODS)}; got {shown(method)}{hint}")
    n = raw.get("n")
    if isinstance(n, bool) or not isinstance(n, int) or not 1 <= n <= MAX_CASES:
        raise CampaignError(f"{where}: n must be an integer 1..{MAX_CASES:,} (points drawn); got {shown(n)}")
    if method == "sobol" and n & (n - 1):
        lo = 1 << (n.bit_length() - 1)
        raise CampaignError(
            f"{where}: n must be a power of 2 for method 'sobol' (its balance needs it); got {n}: "
            f"use {lo} or {2 * lo}, or method 'lhs' / 'random'"
        )
    ranges_raw = raw.get("ranges")
    if not isinstance(ranges_raw, dict) or not ranges_raw:
        raise CampaignError(
            f'{where}: ranges must be a table of fields with [lo, hi] (e.g. ranges = {{ "halt.T" = [8, 14] }}); '
            f"got {shown(ranges_raw)}"
        )
    ranges: dict[str, tuple[float, float]] = {}
    for name, bounds in _flatten(ranges_raw).items():
        current, spec = scenario_field(name, f"{where} ranges")
        at = f"{where}: ranges.{name}"
        if spec.kind not in ("number", "int"):
            raise CampaignError(f"{at}: only number and integer fields can be sampled; {current} is {spec.allowed()}")
        if not isinstance(bounds, list) or len(bounds) != 2:
            raise CampaignError(f"{at} must be [lo, hi]; got {shown(bounds)}")
        lo, hi = (_value(b, current, f"{at}[{i}]", Path.cwd()) for i, b in enumerate(bounds))
        if lo > hi:
            raise CampaignError(f"{at}: lo must be <= hi; got [{bounds[0]!r}, {bounds[1]!r}]")
        if current in ranges:
            raise CampaignError(f"{where}: ranges give {shown(current)} twice (under two names)")
        ranges[current] = (lo, hi)
    return SampleSpec(method, n, ranges)


def _check_once(source: str, grid: dict, zipped: dict, sample: SampleSpec | None, fixed: dict) -> None:
    """A field is set in one place only."""
    where: dict[str, str] = {}
    sections = (("set", fixed), ("grid", grid), ("zip", zipped), ("sample", sample.ranges if sample else {}))
    for section, names in sections:
        for name in names:
            if name in where:
                raise CampaignError(
                    f"{source}: {name} is given in [{where[name]}] and [{section}]; set each field in one place"
                )
            where[name] = section


def _filters(raw: Any, source: str, base_dir: Path) -> tuple[dict[str, Any], ...]:
    if isinstance(raw, dict):
        raw = [raw]
    if not isinstance(raw, list) or not all(isinstance(f, dict) and f for f in raw):
        raise CampaignError(
            f"{source}: exclude must be [[exclude]] tables of conditions (e.g. robot = \"puma6\" and "
            '"failure.joint" = 7); got ' + repr(raw)[:80]
        )
    out = []
    for i, table in enumerate(raw):
        conditions: dict[str, Any] = {}
        for name, cond in _flatten(table).items():
            current, _ = scenario_field(name, f"{source}: exclude[{i}]")
            where = f"{source}: exclude[{i}].{current}"
            if isinstance(cond, dict):
                for op in cond:
                    if op not in COMPARISONS:
                        raise CampaignError(f"{where}: unknown comparison {op!r}{_hint(op, COMPARISONS)}; allowed: {', '.join(COMPARISONS)}")
                conditions[current] = {
                    op: [_value(v, current, where, base_dir) for v in arg]
                    if op == "in" and isinstance(arg, list)
                    else _value(arg, current, where, base_dir)
                    for op, arg in cond.items()
                }
            else:
                conditions[current] = {"eq": _value(cond, current, where, base_dir)}
        out.append(conditions)
    return tuple(out)


def _columns(raw: Any, source: str) -> tuple[str, ...]:
    if raw is None:
        return ()
    if not isinstance(raw, list) or not raw or not all(isinstance(c, str) for c in raw):
        raise CampaignError(
            f'{source}: columns must be a non-empty list of result paths (e.g. ["halt.feasible", '
            f'"halt.peak_velocity_deg_s|max"]); got {raw!r}'
        )
    for col in raw:
        path, _, reducer = col.partition("|")
        job = path.split(".", 1)[0]
        if job not in JOB_ORDER or "." not in path:
            raise CampaignError(
                f"{source}: columns: {col!r} must start with a job name and a result key (JOB.KEY, "
                f"e.g. halt.global_torque_Nm){_hint(job, JOB_ORDER)}; jobs: {', '.join(JOB_ORDER)}"
            )
        if reducer and reducer not in REDUCERS:
            raise CampaignError(
                f"{source}: columns: {col!r}: unknown reduction {reducer!r}{_hint(reducer, REDUCERS)}; "
                f"allowed: {', '.join(REDUCERS)}"
            )
    if len(set(raw)) != len(raw):
        raise CampaignError(f"{source}: columns: a column is listed twice")
    return tuple(raw)


def _report(raw: Any, source: str) -> ReportSpec:
    if raw is None:
        return ReportSpec()
    if not isinstance(raw, dict):
        raise CampaignError(f"{source}: [report] must be a table ({', '.join(_REPORT_KEYS)})")
    for key, value in raw.items():
        if key not in _REPORT_KEYS:
            raise CampaignError(
                f"{source}: [report] unknown key {key!r}{_hint(key, _REPORT_KEYS)}; allowed: {', '.join(_REPORT_KEYS)}"
            )
        if not isinstance(value, str):
            raise CampaignError(f"{source}: report.{key} must be a string; got {shown(value)}")
    if raw.get("worse") not in (None, "higher", "lower"):
        raise CampaignError(f"{source}: report.worse must be 'higher' or 'lower'; got {raw['worse']!r}")
    names = {k: scenario_field(raw[k], f"{source}: report.{k}")[0] for k in ("x", "y") if k in raw}
    if len(names) == 2 and names["x"] == names["y"]:
        raise CampaignError(f"{source}: report.x and report.y are both {names['x']!r}; give two different fields")
    if "worst" in raw:
        _columns([raw["worst"]], f"{source}: report.worst")
    return ReportSpec(x=names.get("x"), y=names.get("y"), worst=raw.get("worst"), worse=raw.get("worse"))


def _check_filters_and_report(spec: CampaignSpec) -> None:
    varied = spec.varied
    for i, conditions in enumerate(spec.exclude):
        for name in conditions:
            if name not in varied:
                raise CampaignError(
                    f"{spec.source}: exclude[{i}]: {name!r} is not varied by this campaign (varied: "
                    f"{', '.join(varied)}); a filter on it would drop every case or none"
                )
    for axis in ("x", "y"):
        name = getattr(spec.report, axis)
        if name is not None and name not in varied:
            raise CampaignError(
                f"{spec.source}: report.{axis} = {name!r} is not varied by this campaign; varied: {', '.join(varied)}"
            )
