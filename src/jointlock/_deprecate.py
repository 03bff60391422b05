"""Renamed keyword arguments: the former name keeps working as a deprecated alias.

``@renamed_keyword(old="length", new="characteristic_length")`` on a public function makes a
call with ``length=`` run as ``characteristic_length=`` and warn once per process and
(function, former name) pair (``FutureWarning``, naming the new keyword, attributed to the first
caller outside this module).  Passing both names is a ``TypeError`` naming both.  A jointlock
error raised about the renamed argument (its message starts with the new name) names the former
one when the caller used it, so that the message names the argument the caller typed.
"""

from __future__ import annotations

import functools
import inspect
import sys
import warnings
from collections.abc import Callable
from typing import Any, TypeVar

from .errors import JointlockError

F = TypeVar("F", bound=Callable[..., Any])

#: What has already been warned about in this process (one warning per key).
_WARNED: set[str] = set()


def warn_once(key: str, message: str) -> None:
    """Warn ``message`` (``FutureWarning``) the first time ``key`` is seen in this process,
    attributed to the first caller outside jointlock: the one deprecation mechanism of the
    package (renamed keywords, former scenario fields, renamed functions)."""
    if key in _WARNED:
        return
    _WARNED.add(key)
    frame, level = sys._getframe(), 1
    while frame.f_back is not None and frame.f_globals.get("__name__", "").startswith("jointlock."):
        frame, level = frame.f_back, level + 1
    warnings.warn(message, FutureWarning, stacklevel=level)


def _warn_once(where: str, name: str, old: str, new: str) -> None:
    warn_once(
        f"keyword {where}:{old}",
        f"{name}(): the keyword {old}= is deprecated: use {new}= instead (the same argument); "
        f"{old}= still works for now",
    )


def _name_former(exc: JointlockError, old: str, new: str) -> None:
    """Rewrite ``exc``'s message in place when it names the renamed argument (``new ...`` or
    ``new=...``) so that it names ``old``, the spelling the caller used."""
    if not exc.args or not isinstance(exc.args[0], str):
        return
    message = exc.args[0]
    if message.startswith((f"{new} ", f"{new}=")):
        exc.args = (f"{old}{message[len(new) :]} ({old}= is now {new}=)", *exc.args[1:])


def renamed_keyword(*, old: str, new: str) -> Callable[[F], F]:
    """Decorator: keyword ``old`` of the decorated function is now ``new``.

    Parameters
    ----------
    old
        The former keyword, accepted as a deprecated alias of ``new`` (warns once per process
        and function, ``FutureWarning``).
    new
        The keyword in the function's signature.

    Raises
    ------
    TypeError
        At decoration, when ``new`` is not a parameter of the function or ``old`` still is; at
        a call, when both ``old`` and ``new`` are given.
    """

    def decorate(func: F) -> F:
        params = inspect.signature(func).parameters
        if new not in params or old in params:
            raise TypeError(f"renamed_keyword({old!r} -> {new!r}) does not fit {func.__qualname__}{params}")
        where = f"{func.__module__}.{func.__qualname__}"
        name = func.__name__

        @functools.wraps(func)
        def wrapper(*args: Any, **kwargs: Any) -> Any:
            if old not in kwargs:
                return func(*args, **kwargs)
            if new in kwargs:
                raise TypeError(
                    f"{name}() got both {old}= and {new}=: {old}= is the deprecated name of {new}=; pass only {new}="
                )
            kwargs[new] = kwargs.pop(old)
            _warn_once(where, name, old, new)
            try:
                return func(*args, **kwargs)
            except JointlockError as exc:
                _name_former(exc, old, new)
                raise

        renamed = dict(getattr(func, "__renamed_keywords__", {}))
        renamed[old] = new
        wrapper.__renamed_keywords__ = renamed  # type: ignore[attr-defined]
        return wrapper  # type: ignore[return-value]

    return decorate
