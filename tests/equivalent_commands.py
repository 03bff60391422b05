"""Running a scenario job's equivalent command line in-process, for tests that check the
library call behind a scenario job gives what the stand-alone command gives."""

from __future__ import annotations

import argparse
import contextlib
import importlib
import io
import json
import shlex
from collections.abc import Mapping
from pathlib import Path

from jointlock.errors import ScenarioError
from jointlock.io.files import atomic_write_text
from jointlock.run._commands import job_argv as _job_argv
from jointlock.run._commands import jump_task_toml
from jointlock.scenario import JOB_ORDER, Scenario

#: Subcommand module of each job (``jointlock.cli.<module>``).
JOB_MODULE = {job: job for job in JOB_ORDER}


def job_argv(
    job: str, scenario: Scenario, out: Path, previous: Mapping[str, dict], *, quiet: bool
) -> list[str]:
    """The equivalent command line of ``job`` (:func:`jointlock.run._commands.job_argv`); for
    the jump job it also writes the task file the command reads (``out/jump/task.toml``)."""
    if job == "jump":
        atomic_write_text(Path(out) / "jump" / "task.toml", jump_task_toml(scenario))
    return _job_argv(job, scenario, Path(out), previous, quiet=quiet)


def call_subcommand(module: str, argv: list[str]) -> tuple[dict, int]:
    """Run ``jointlock <argv>`` in-process through the subcommand ``module`` and return the
    JSON object it prints (``--json`` must be in ``argv``) and its exit code."""
    mod = importlib.import_module(f"jointlock.cli.{module}")
    parser = argparse.ArgumentParser(prog="jointlock")
    mod.register(parser.add_subparsers(dest="command"))
    err = io.StringIO()
    try:
        with contextlib.redirect_stderr(err):
            args = parser.parse_args(argv)
    except SystemExit:
        msg = err.getvalue().strip().splitlines()
        raise ScenarioError(
            f"cannot form the command line `jointlock {shlex.join(argv)}`: {msg[-1] if msg else '?'}"
        ) from None
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        code = int(args.func(args) or 0)
    text = buf.getvalue()
    return (json.loads(text) if text.strip() else {}), code
