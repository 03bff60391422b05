"""Jobs: one library call per job, typed inputs in, a typed, picklable result out.

Each result has ``to_dict()`` (the JSON of ``jointlock COMMAND --json``), ``summary()`` (the
lines the command prints) and ``write(out)`` (the files of ``--out``); figures come from
:mod:`jointlock.plots`.  The command line only parses options, calls these and prints.
"""

from ._common import JobResult

__all__ = ["JobResult"]
