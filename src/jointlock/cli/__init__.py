"""The ``jointlock`` command line: one entry point, one module per subcommand.

Each subcommand module defines ``register(subparsers)``, which adds its parser and sets
``func`` (``args -> exit code``).  The CLI only parses, calls the library and writes files.
"""

from __future__ import annotations

import argparse
import importlib
import importlib.util
import os
import re
import sys
import warnings
from collections.abc import Sequence
from typing import NoReturn

from .._version import __version__
from ..errors import JointlockError

#: Every subcommand, in the order ``--help`` lists them: its module and its line of help (the
#: module's own parser says the same: tested).  Only the module of the command given is
#: imported (the others, with numpy, scipy and matplotlib behind them, are not needed to list
#: them), so ``jointlock --help`` and a command's start-up stay short.
COMMANDS: dict[str, tuple[str, str]] = {
    "robots": ("robots", "list the built-in robots (name, DOF, masses, lengths, base)"),
    "kinematics": ("kinematics", "end-effector pose, Jacobian and its singular values at one configuration"),
    "halt-config": ("halt_config", "optimal halt configuration after a lock (000 HCOM: Monte Carlo + refinement)"),
    "halt": ("halt", "optimal halt configuration and optimal halt motion after a lock (seed 000)"),
    "jump": ("jump", "velocity jump at an unexpected lock: optimal kappa, fitted kappa(t), verification (001)"),
    "ik": ("ik", "inverse kinematics: every branch, full arm or with a locked joint"),
    "tolerance-angle": ("tolerance_angle", "gamma sweep (rotate the target about the tool x axis) and the gamma absorbing a lock "
                        "(puma6-family arms only)"),
    "replan": ("replan", "straight-line Cartesian plan through the locked-arm IK, with the tolerance angle gamma "
               "(puma6-family arms only)"),
    "workspace": ("workspace", "Monte Carlo workspace, full arm vs locked arm: clouds, projections, volume, share kept"),
    "singular": ("singular", "singular values, rank, lost directions; 004's Cond1-Cond5; singularity search"),
    "export-urdf": ("export_urdf", "write the (locked) arm as URDF, locked joints folded in and bodies merged"),
    "export-mjcf": ("export_mjcf", "write the (locked) arm and its spacecraft as a MuJoCo model (MJCF)"),
    "run": ("run", "run every job of a scenario file; results.json, CSV, plots and report.html in one folder"),
    "campaign": ("campaign", "sweep thousands of failure cases (process pool or Dask), resumable"),
    "audit": ("audit", "audit a planned motion: every joint locking at every instant of the scenario's [task]"),
    "reproduce": ("reproduce", "re-run each seed paper's published experiment and compare with its printed numbers"),
    "demo": ("demo", "run the main job on the built-in arms and write a report"),
}  # fmt: skip
#: The subcommand modules, in order.
COMMAND_MODULES: tuple[str, ...] = tuple(module for module, _ in COMMANDS.values())


#: Help of ``--debug`` (accepted before and after the subcommand).
DEBUG_HELP = "show tracebacks and debug logs"


class Parser(argparse.ArgumentParser):
    """:class:`argparse.ArgumentParser` whose usage errors are one line pointing to ``--help``
    (instead of the whole usage).  Subparsers made by ``add_subparsers`` are of this class too."""

    def error(self, message: str) -> NoReturn:
        self.exit(2, f"{self.prog}: error: {message} (see '{self.prog} --help')\n")


def build_parser(argv: Sequence[str] | None = None) -> argparse.ArgumentParser:
    """The command-line parser.  With ``argv`` (what :func:`main` parses) only the command it
    names gets its full parser (its module imported); the others are listed by name and help.
    Without, every subcommand's full parser (for tools and tests that walk them)."""
    chosen = None if argv is None else _command_in(argv)
    parser = Parser(
        prog="jointlock",
        description="Space manipulators after a locked-joint failure: halt, compensate, re-plan, analyse.",
    )
    parser.add_argument("--version", action="version", version=f"jointlock {__version__}")
    parser.add_argument("--debug", action="store_true", help=DEBUG_HELP)
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    sub.required = True
    for name, (module, help_text) in COMMANDS.items():
        if argv is not None and name != chosen:
            sub.add_parser(name, help=help_text)  # listed; parsed only when it is the command
        elif importlib.util.find_spec(f"{__name__}.{module}") is not None:
            importlib.import_module(f"{__name__}.{module}").register(sub)
    for command_parser in _all_parsers(sub):
        # --debug after the subcommand too; SUPPRESS keeps the top-level value when absent
        if not any("--debug" in a.option_strings for a in command_parser._actions):
            command_parser.add_argument(
                "--debug", action="store_true", default=argparse.SUPPRESS, help=DEBUG_HELP
            )
    parser.set_defaults(_commands=sub.choices)
    return parser


def _command_in(argv: Sequence[str]) -> str | None:
    """The subcommand ``argv`` names: its first word that is not an option (the top-level
    parser takes only options before the command); None when there is none or it is unknown."""
    for word in argv:
        if not word.startswith("-"):
            return word if word in COMMANDS else None
    return None


def _all_parsers(sub: argparse._SubParsersAction) -> list[argparse.ArgumentParser]:
    """The subcommands' parsers, those of nested subcommands (``campaign run``) included."""
    out = []
    for parser in sub.choices.values():
        out.append(parser)
        for action in parser._actions:
            if isinstance(action, argparse._SubParsersAction):
                out += _all_parsers(action)
    return out


def _os_error_text(exc: OSError) -> str:
    """One line naming the path(s) and the reason of an :class:`OSError`."""
    reason = exc.strerror or type(exc).__name__
    if exc.filename is None:
        return str(exc) or reason
    paths = repr(str(exc.filename))
    if exc.filename2 is not None:
        paths += f" -> {str(exc.filename2)!r}"
    return f"{paths}: {reason}"


def _headless_backend() -> None:
    """Choose matplotlib's non-interactive backend when there is no display (and the user set
    none): the command line only writes files.  Only this entry point ever chooses a backend;
    the library never does."""
    if not (os.environ.get("MPLBACKEND") or os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")):
        os.environ["MPLBACKEND"] = "Agg"


def main(argv: Sequence[str] | None = None) -> int:
    """Run the CLI; returns the process exit code (0 ok, 2 usage or input error, including a
    file or folder that cannot be read or written; 130 interrupted; tracebacks only with
    ``--debug``).

    Ctrl-C is handled from the first line: the subcommands (and numpy, scipy, matplotlib
    behind them) are imported inside this function, so an interrupt during start-up says
    "interrupted" like one during the run.  Warnings are collected while the command runs and
    printed after its output, one line each -- never ahead of an error (an error prints only
    its line).  numpy floating-point overflow, invalid values and division by zero raise (one
    error line): a result is never printed from inf/NaN."""
    try:
        return _main(argv)
    except KeyboardInterrupt:
        print("jointlock: interrupted", file=sys.stderr)
        return 130


def _main(argv: Sequence[str] | None) -> int:
    _headless_backend()
    _forgiving_streams()
    argv = list(sys.argv[1:] if argv is None else argv)
    parser = build_parser(argv)
    args, extra = parser.parse_known_args(argv)
    commands = vars(args).pop("_commands", {})
    if extra:  # named by the subcommand, so that the hint points to its --help
        commands.get(args.command, parser).error(f"unrecognized arguments: {' '.join(extra)}")
    import logging

    logging.basicConfig(
        level=logging.DEBUG if args.debug else logging.WARNING, format="%(levelname)s: %(message)s"
    )
    prefix = f"jointlock {args.command}"
    import numpy as np  # imported by every subcommand already

    # numpy's floating-point overflow, invalid value and division by zero raise (an error line)
    # instead of warning and returning inf/NaN; Python's own warning filters are kept.
    with warnings.catch_warnings(record=True) as caught, np.errstate(over="raise", invalid="raise", divide="raise"):
        try:
            code = int(args.func(args) or 0)
            _print_warnings(prefix, caught)
            if sys.stdout is not None:  # a closed pipe or a full disk shows here, not at exit
                sys.stdout.flush()
            return code
        except JointlockError as exc:
            if args.debug:
                raise
            print(f"{prefix}: error: {_short_words(str(exc))}", file=sys.stderr)
            return 2
        except BrokenPipeError:  # e.g. `jointlock ... | head`: the reader left; exit quietly
            _silence_stdout()
            return 141 if os.name == "posix" else 1
        except OSError as exc:  # a file or folder that cannot be read or written (e.g. --out)
            if args.debug:
                raise
            if exc.filename is None:  # no path: standard output (e.g. `> /dev/full`)
                exc.filename = "<standard output>"
                _silence_stdout()
            print(f"{prefix}: error: {_os_error_text(exc)}", file=sys.stderr)
            return 2
        except MemoryError:
            if args.debug:
                raise
            print(f"{prefix}: error: not enough memory for this run: ask for fewer samples or steps", file=sys.stderr)
            return 2
        except Exception as exc:
            if args.debug or not _numerical_failure(exc):
                raise
            print(f"{prefix}: error: {_numerical_text(exc)}", file=sys.stderr)
            return 2


#: Longest run of characters without a space an error line echoes whole: every message
#: shortens the names it quotes (:func:`jointlock.bounds.shown`); this is the net for one that
#: does not (a 10,000-character link name, an XML entity expanded to a page).
LONGEST_WORD = 200


def _short_words(message: str) -> str:
    """``message`` with every run of more than :data:`LONGEST_WORD` non-space characters cut
    to its first and last 60 around "..." (a path keeps its file name; one error line stays a
    line or two)."""
    return re.sub(rf"\S{{{LONGEST_WORD + 1},}}", lambda m: m.group(0)[:60] + "..." + m.group(0)[-60:], message)


def _forgiving_streams() -> None:
    """Standard output and error that never fail on a character their encoding lacks (an
    ASCII locale printing "§" or a model's name) -- it is written escaped -- and a closed
    stdout (``>&-``) that swallows output instead of raising."""
    for name in ("stdout", "stderr"):
        stream = getattr(sys, name)
        if stream is None:
            setattr(sys, name, open(os.devnull, "w"))  # lives as long as the process
        elif hasattr(stream, "reconfigure"):
            try:
                stream.reconfigure(errors="backslashreplace")
            except (ValueError, OSError, AttributeError):  # a replaced stream (tests) or detached
                pass


def _print_warnings(prefix: str, caught: list[warnings.WarningMessage]) -> None:
    """The warnings a command raised, one line each (repeats once), after its output."""
    seen: set[str] = set()
    for w in caught:
        text = " ".join(str(w.message).split())
        if text not in seen:
            seen.add(text)
            print(f"{prefix}: warning: {text}", file=sys.stderr)


def _numerical_failure(exc: BaseException) -> bool:
    """Whether ``exc`` is floating-point arithmetic failing (overflow, invalid value, division
    by zero under the CLI's ``np.errstate``, a linear-algebra routine that did not converge)."""
    if isinstance(exc, ArithmeticError):  # numpy's FloatingPointError, OverflowError, ZeroDivisionError
        return True
    linalg = sys.modules.get("numpy.linalg")
    return linalg is not None and isinstance(exc, linalg.LinAlgError)


def _numerical_text(exc: BaseException) -> str:
    return (
        f"numerical failure ({type(exc).__name__}: {' '.join(str(exc).split())}): an input is too large or "
        "too small for float64 arithmetic; every input within the documented bounds (docs/validation.md) "
        "should compute, so please report it with --debug's traceback"
    )


def _silence_stdout() -> None:
    """Point stdout at /dev/null so that the interpreter's final flush of a closed pipe does
    not print another error."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError, AttributeError):  # stdout replaced (tests) or already closed
        pass


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
