"""The ``jointlock`` command line: one entry point, one module per subcommand.

Each subcommand module defines ``register(subparsers)``, which adds its parser and sets
``func`` (``args -> exit code``).  The CLI only parses, calls the library and writes files.
"""

from __future__ import annotations

import argparse
import importlib
import importlib.util
import logging
import sys
from collections.abc import Sequence

from .. import __version__
from ..errors import JointlockError

#: Subcommand modules, in the order ``--help`` lists them.  A module listed here that is not
#: installed (a capability still being written) is left out of the parser.
COMMAND_MODULES: tuple[str, ...] = (
    "robots",
    "kinematics",
    "halt_config",
    "halt",
    "jump",
    "ik",
    "tolerance_angle",
    "replan",
    "workspace",
    "singular",
    "run",
    "reproduce",
    "demo",
)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="jointlock",
        description="Space manipulators after a locked-joint failure: halt, compensate, re-plan, analyse.",
    )
    parser.add_argument("--version", action="version", version=f"jointlock {__version__}")
    parser.add_argument("--debug", action="store_true", help="show tracebacks and debug logs")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    sub.required = True
    for name in COMMAND_MODULES:
        if importlib.util.find_spec(f"{__name__}.{name}") is None:
            continue
        importlib.import_module(f"{__name__}.{name}").register(sub)
    return parser


def _os_error_text(exc: OSError) -> str:
    """One line naming the path(s) and the reason of an :class:`OSError`."""
    reason = exc.strerror or type(exc).__name__
    if exc.filename is None:
        return str(exc) or reason
    paths = repr(str(exc.filename))
    if exc.filename2 is not None:
        paths += f" -> {str(exc.filename2)!r}"
    return f"{paths}: {reason}"


def main(argv: Sequence[str] | None = None) -> int:
    """Run the CLI; returns the process exit code (0 ok, 2 usage or input error, including a
    file or folder that cannot be read or written; tracebacks only with ``--debug``)."""
    parser = build_parser()
    args = parser.parse_args(argv)
    logging.basicConfig(
        level=logging.DEBUG if args.debug else logging.WARNING, format="%(levelname)s: %(message)s"
    )
    try:
        return int(args.func(args) or 0)
    except JointlockError as exc:
        if args.debug:
            raise
        print(f"jointlock {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except OSError as exc:  # a file or folder that cannot be read or written (e.g. --out)
        if args.debug:
            raise
        print(f"jointlock {args.command}: error: {_os_error_text(exc)}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("jointlock: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
