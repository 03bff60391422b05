"""Lean start-up (issue 13): the command line lists its commands without importing them, a
command imports only its own module, and nothing imports scipy.optimize or matplotlib before
it needs them.  (What it costs is measured in benchmarks/, not asserted here.)"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys

from jointlock.cli import COMMANDS, build_parser


def _imported_after(code: str) -> set[str]:
    """The modules imported by ``code`` in a fresh interpreter (printed one per line)."""
    script = f"import sys\n{code}\nprint('\\n'.join(sorted(sys.modules)))"
    env = {"MPLBACKEND": "Agg", "PATH": ""}
    if "PYTHONPATH" in os.environ:  # the checkout under test, not an installed copy
        env["PYTHONPATH"] = os.environ["PYTHONPATH"]
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120, env=env)
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


def test_no_command_s_help_imports_numpy():
    """A command's parser is built from the light modules only; the library (numpy, scipy,
    matplotlib behind it) is imported once its options are parsed."""
    code = (
        "from jointlock.cli import COMMANDS, main\n"
        "import contextlib, io\n"
        "for name in COMMANDS:\n"
        "    with contextlib.suppress(SystemExit), contextlib.redirect_stdout(io.StringIO()):\n"
        "        main([name, '--help'])"
    )
    mods = _imported_after(code)
    assert all(f"jointlock.cli.{module}" in mods for module, _ in COMMANDS.values())
    assert "numpy" not in mods, sorted(m for m in mods if m.startswith("jointlock"))


def test_the_parsers_constants_are_the_library_s():
    """jointlock.cli._constants copies what the parsers print (no drift)."""
    from jointlock.analysis import singularity as sg
    from jointlock.analysis.workspace import MIN_SAMPLES
    from jointlock.cli import _constants as c
    from jointlock.cli.halt import DEFAULT_AMAX_DEG, DEFAULT_VMAX_DEG
    from jointlock.jobs import halt, jump
    from jointlock.jobs.reproduction import PAPERS
    from jointlock.jobs.tolerance_angle import MAX_GAMMA_SAMPLES
    from jointlock.planning.replan import DEFAULT_STEP_WEIGHT
    from jointlock.robots import BUILTIN_ROBOTS
    from jointlock.scenario import JOB_ORDER, MAX_ABS_DEG

    assert c.BUILTIN_ROBOTS == BUILTIN_ROBOTS and c.MIN_N_SAMPLES == halt.MIN_N_SAMPLES
    assert (c.KAPPA_UNIT, c.MAX_ORDER, c.DEFAULT_ORDER, c.DEFAULT_SWEEP) == (
        jump.KAPPA_UNIT, jump.MAX_ORDER, jump.DEFAULT_ORDER, jump.DEFAULT_SWEEP)  # fmt: skip
    assert (c.DEFAULT_STEP_WEIGHT, c.MAX_ABS_DEG, c.JOB_ORDER, c.PAPERS) == (
        DEFAULT_STEP_WEIGHT, MAX_ABS_DEG, JOB_ORDER, PAPERS)  # fmt: skip
    assert (c.SINGULAR_BASE_KINDS, c.RANK_TOL, c.WORKSPACE_MIN_SAMPLES) == (sg.BASE_KINDS, sg.RANK_TOL, MIN_SAMPLES)
    assert (DEFAULT_VMAX_DEG, DEFAULT_AMAX_DEG) == (halt.DEFAULT_VMAX_DEG, halt.DEFAULT_AMAX_DEG)
    assert c.MAX_GAMMA_SAMPLES == MAX_GAMMA_SAMPLES


def test_the_former_imports_of_the_command_modules_still_resolve():
    from jointlock.cli import _common, demo
    from jointlock.cli import halt as cli_halt
    from jointlock.cli import jump as cli_jump
    from jointlock.jobs import halt, jump

    assert cli_halt.resolve_limits is halt.resolve_limits and cli_halt.plan_halt is halt.plan_halt
    assert cli_jump._points_text is jump._points_text and callable(cli_jump.load_scenario)
    assert callable(demo.run_demo) and callable(_common.joint_vector_deg) and callable(_common.json_text)
    assert _common.deg_arg("12") == 12.0 and _common.seed_arg("3") == 3 and _common.seed_arg.__name__ == "int"
