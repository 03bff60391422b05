"""When the batched functions run on the compiled kernels (:mod:`jointlock._kernels`, numba)
instead of their numpy references: one process-wide choice.

Every batched function that has a compiled kernel (:func:`jointlock.kinematics.jacobian`,
:func:`~jointlock.kinematics.generalized_jacobian`, :func:`jointlock.dynamics.rnea`,
:func:`jointlock.forward.ee_positions`, the kinematic indices of the halt-configuration search)
takes ``compiled=True/False`` per call; with ``compiled=None`` (the default) it asks
:func:`use_compiled`, which follows the mode:

``"auto"`` (the default)
    the kernels from :data:`jointlock.forward.COMPILED_MIN_BATCH` (200,000) configurations on:
    loading numba and the cached kernels costs a process 0.4-0.7 s (about 2 s on a busy core),
    which only large batches win back.  Right for a command run once.
``"always"``
    the kernels at every batch size, one configuration included.  Right for a long-lived process
    running many cases (a campaign's or an audit's workers, which use it unless told otherwise:
    :mod:`jointlock.campaign`), where numba's load is paid once and every small batch is then
    several times faster.
``"never"``
    the numpy references at every size (to compare, or where numba is unwelcome).

The mode is set by the environment variable ``JOINTLOCK_COMPILED`` (``auto``, ``always`` or
``never``; read on each use), or in the program by :func:`set_compiled_mode` (for the whole
process) or :func:`compiled_kernels` (a context manager, for the enclosed code in its thread),
which take precedence over the environment, the block over the process's setting.

The two paths give the same numbers to round-off (``tests/test_kernels*.py``), so a result that
is a smooth function of its inputs (a Jacobian, a torque, the halt's ``k`` for a given halt
configuration) agrees to ~1e-14 relative.  An optimiser started from the same point may follow
another path when its objective differs in the last bits: the halt-configuration refinement
(L-BFGS-B on a nearly flat combined index) then ends at a configuration whose index agrees to
~1e-9 relative but whose joint angles, and the halt to them, may differ by more (up to 0.3 % in
``k`` in a halt7 campaign).  To reproduce a campaign's case bit for bit, run it in the campaign's
mode: ``JOINTLOCK_COMPILED=always jointlock run ...``.
"""

from __future__ import annotations

import os
from collections.abc import Iterator
from contextlib import contextmanager
from contextvars import ContextVar
from typing import Literal

from .errors import ConfigurationError

CompiledMode = Literal["auto", "always", "never"]
#: The modes, in the order documented above.
COMPILED_MODES: tuple[CompiledMode, ...] = ("auto", "always", "never")
#: The environment variable that sets the mode.
ENVIRONMENT_VARIABLE = "JOINTLOCK_COMPILED"

_set_mode: CompiledMode | None = None  # set_compiled_mode: the process's; None: the environment's
#: compiled_kernels: the mode of the enclosed code, in this thread (or asyncio task) only
_context_mode: ContextVar[CompiledMode | None] = ContextVar("jointlock_compiled_mode", default=None)


def _checked(mode: object, where: str) -> CompiledMode:
    if mode not in COMPILED_MODES:
        raise ConfigurationError(f"{where} must be one of {', '.join(COMPILED_MODES)}; got {mode!r}")
    return mode


def compiled_mode() -> CompiledMode:
    """The mode now: :func:`compiled_kernels`' around this code, else :func:`set_compiled_mode`'s,
    else ``JOINTLOCK_COMPILED``, else ``"auto"``.

    Raises
    ------
    ConfigurationError
        ``JOINTLOCK_COMPILED`` holds something else than a mode.
    """
    return chosen_compiled_mode() or "auto"


def chosen_compiled_mode() -> CompiledMode | None:
    """The mode chosen in the program (:func:`compiled_kernels`, :func:`set_compiled_mode`), else
    by ``JOINTLOCK_COMPILED``; None when none chose one (a caller with another default, such as a
    campaign's ``"always"``, applies its own).

    Raises
    ------
    ConfigurationError
        ``JOINTLOCK_COMPILED`` holds something else than a mode.
    """
    mode = _context_mode.get()
    if mode is not None:
        return mode
    if _set_mode is not None:
        return _set_mode
    value = os.environ.get(ENVIRONMENT_VARIABLE, "").strip().lower()
    return None if value == "" else _checked(value, f"the environment variable {ENVIRONMENT_VARIABLE}")


def set_compiled_mode(mode: CompiledMode | None) -> CompiledMode | None:
    """Set the process's mode, for every thread (None: follow ``JOINTLOCK_COMPILED`` again);
    returns the mode set before (None if there was none).  A :func:`compiled_kernels` block
    takes precedence inside it."""
    global _set_mode
    checked = None if mode is None else _checked(mode, "the compiled mode")
    before, _set_mode = _set_mode, checked
    return before


@contextmanager
def compiled_kernels(mode: CompiledMode = "always") -> Iterator[None]:
    """Run the enclosed code in ``mode`` (default ``"always"``), then restore the mode before.

    The mode holds for this thread (a :class:`contextvars.ContextVar`): code running at the same
    time in other threads keeps its own mode, and blocks in several threads may end in any
    order.  A thread started inside the block starts without it (its mode is the process's)."""
    token = _context_mode.set(_checked(mode, "the compiled mode"))
    try:
        yield
    finally:
        _context_mode.reset(token)


def use_compiled(batch: int, threshold: int) -> bool:
    """Whether a function called with ``compiled=None`` on ``batch`` configurations runs on
    the compiled kernels: always, never, or (``"auto"``) from ``threshold`` configurations on
    (the caller's: :data:`jointlock.forward.COMPILED_MIN_BATCH` or
    :data:`~jointlock.forward.COMPILED_MIN_POSITIONS`)."""
    mode = compiled_mode()
    if mode != "auto":
        return mode == "always"
    return batch >= threshold
