"""Lean start-up (issue 13): the command line lists its commands without importing them, a
command imports only its own module, and nothing imports scipy.optimize or matplotlib before
it needs them.  (What it costs is measured in benchmarks/, not asserted here.)"""

from __future__ import annotations

import argparse
import subprocess
import sys

from jointlock.cli import COMMANDS, build_parser


def _imported_after(code: str) -> set[str]:
    """The modules imported by ``code`` in a fresh interpreter (printed one per line)."""
    script = f"import sys\n{code}\nprint('\\n'.join(sorted(sys.modules)))"
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120, env={"MPLBACKEND": "Agg", "PATH": ""})
    return set(out.stdout.split())


def _subparsers(parser: argparse.ArgumentParser) -> dict[str, argparse.ArgumentParser]:
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return dict(sub.choices)


def test_help_lists_every_command_without_importing_any():
    mods = _imported_after(
        "from jointlock.cli import main\ntry:\n    main(['--help'])\nexcept SystemExit:\n    pass"
    )
    assert "numpy" not in mods and not any(m.startswith("jointlock.cli.") and m != "jointlock.cli._common" for m in mods)


def test_a_command_imports_its_module_only_and_no_optimizer_or_plotting():
    mods = _imported_after("from jointlock.cli import main\nmain(['robots', '--json'])")
    assert "jointlock.cli.robots" in mods and "jointlock.cli.halt" not in mods
    assert "scipy.optimize" not in mods and "matplotlib" not in mods


def test_import_jointlock_is_light():
    mods = _imported_after("import jointlock as jl\njl.plan_halt, jl.jacobian, jl.load_robot")
    assert "scipy.optimize" not in mods and "matplotlib" not in mods


def test_the_listed_help_is_each_commands_own():
    """The lean listing says what each command's own parser says (no drift)."""
    full = _subparsers(build_parser())
    lean = _subparsers(build_parser(["--help"]))
    assert list(full) == list(lean) == list(COMMANDS)
    for parser in (build_parser(), build_parser(["--help"])):
        sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
        assert {a.dest: a.help for a in sub._choices_actions} == {n: text for n, (_, text) in COMMANDS.items()}


def test_only_the_named_command_is_parsed_in_full():
    parsers = _subparsers(build_parser(["robots", "--json"]))
    assert any("--json" in a.option_strings for a in parsers["robots"]._actions)
    assert not any("--samples" in a.option_strings for a in parsers["halt-config"]._actions)  # a listing
