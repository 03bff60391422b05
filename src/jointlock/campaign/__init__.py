"""Failure campaigns: sweep thousands of locked-joint cases on one machine or a Dask cluster,
resumable, queryable, plotted (SPEC piece 13).

A campaign file (TOML) names a base scenario and what to vary, with the names of
``jointlock run --set``::

    title = "halt7: which locked joint needs the longest halt"
    scenario = "halt_000.toml"        # the base scenario, relative to this file
    seed = 0                          # each case's seed derives from it and the case's key

    [set]                             # the same for every case
    "halt.minimum_T" = true

    [grid]                            # cartesian product
    "failure.joint" = [1, 2, 3, 4, 5, 6, 7]
    "failure.angle_deg" = [-60, 0, 60]

    [sample]                          # seeded draws (random, sobol, lhs: scipy.stats.qmc)
    method = "lhs"
    n = 16
    ranges = { "halt.T" = [8.0, 14.0] }

From Python::

    import jointlock as jl
    from jointlock import campaign

    spec = campaign.load_campaign("examples/campaigns/halt7.toml")
    print("\\n".join(campaign.plan_campaign(spec).summary()))
    run = campaign.run_campaign(spec, "out/halt7", progress=True)   # local process pool
    table = campaign.campaign_table("out/halt7")                       # one row per case
    campaign.write_campaign_report("out/halt7")                       # report.html

Each case is keyed by a hash of its resolved inputs and its result goes to one SQLite ledger
(``OUT/ledger.sqlite``, written by the coordinating process only, one transaction per batch);
running again resumes exactly the cases not finished.  Engines: :func:`in_process`,
:func:`process_pool` (default) and :func:`dask_cluster`.  Format and commands:
``docs/campaigns.md``.

Modules (private; import from ``jointlock.campaign``): ``_spec`` (the validated campaign),
``_read`` (the file), ``_cases``
(expansion, keys, seeds), ``_columns`` (recorded figures), ``_worker`` (a batch), ``_engines``,
``_ledger`` (SQLite), ``_plan`` (count and time), ``_runner`` (the coordinator), ``_results`` (status, table, export),
``_report`` (HTML report).
"""

from __future__ import annotations

from ._audit import (
    AUDIT_COLUMNS,
    AUDIT_JUMP_COLUMNS,
    AuditResult,
    AuditWindows,
    audit,
    audit_campaign,
    audit_windows,
    run_audit,
)
from ._cases import Case, CasePlan, case_key, case_seed, expand, plan_cases, resolve_case
from ._columns import DEFAULT_COLUMNS, column_value, default_columns
from ._engines import Engine, InProcessExecutor, dask_cluster, default_workers, in_process, process_pool
from ._ledger import LEDGER_NAME, Ledger, open_ledger
from ._plan import CampaignPlan, plan_campaign
from ._read import campaign_from_dict, load_campaign
from ._report import CampaignReport, campaign_report, write_campaign_report
from ._results import CampaignStatus, CampaignTable, campaign_status, campaign_table
from ._runner import BATCH_SECONDS, CampaignRun, run_campaign
from ._spec import (
    CONFIRM_CASES,
    MAX_CASES,
    REDUCERS,
    SAMPLE_METHODS,
    CampaignSpec,
    ReportSpec,
    SampleSpec,
)
from ._worker import BatchTask, CaseOutcome, make_task, run_batch

__all__ = [
    "AUDIT_COLUMNS",
    "AUDIT_JUMP_COLUMNS",
    "audit",
    "AuditResult",
    "AuditWindows",
    "audit_campaign",
    "audit_windows",
    "run_audit",
    "BATCH_SECONDS",
    "CONFIRM_CASES",
    "DEFAULT_COLUMNS",
    "LEDGER_NAME",
    "MAX_CASES",
    "REDUCERS",
    "SAMPLE_METHODS",
    "BatchTask",
    "CampaignPlan",
    "CampaignReport",
    "CampaignRun",
    "CampaignSpec",
    "CampaignStatus",
    "CampaignTable",
    "Case",
    "CaseOutcome",
    "CasePlan",
    "Engine",
    "InProcessExecutor",
    "Ledger",
    "ReportSpec",
    "SampleSpec",
    "campaign_from_dict",
    "campaign_report",
    "campaign_status",
    "campaign_table",
    "case_key",
    "case_seed",
    "column_value",
    "dask_cluster",
    "default_columns",
    "default_workers",
    "expand",
    "in_process",
    "load_campaign",
    "make_task",
    "open_ledger",
    "plan_campaign",
    "plan_cases",
    "process_pool",
    "resolve_case",
    "run_batch",
    "run_campaign",
    "write_campaign_report",
]
