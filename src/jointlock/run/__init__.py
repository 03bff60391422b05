"""Scenarios in-process: :func:`run_scenario` runs every job of a scenario as library calls
and returns a picklable :class:`RunResult` (``to_dict()``, ``summary()``, ``write(out)``: the
results.json, time series, figures and report.html of ``jointlock run``)."""

from ._run import JOB_RUNNERS, RunResult, default_out_dir, run_scenario, run_title, versions

__all__ = ["JOB_RUNNERS", "RunResult", "default_out_dir", "run_scenario", "run_title", "versions"]
