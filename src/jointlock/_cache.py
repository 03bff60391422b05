"""Per-model constants computed once and kept on the (immutable) model.

A model never changes after it is built, so what is derived from it alone (e.g. the puma6
closed form's geometry fit) is computed on first use and stored on the instance, next to its
fields: every later call is a dictionary look-up.  A model made by ``dataclasses.replace`` is a
new instance and starts with no cache.  A computation that refuses the model (raises a
:class:`~jointlock.errors.JointlockError`) is remembered too and raises the same error again.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, TypeVar

from .errors import JointlockError

T = TypeVar("T")
_ATTRIBUTE = "_jointlock_cache"


def state_without_cache(obj: Any) -> dict[str, Any]:
    """``obj``'s ``__dict__`` without the cache, for a ``__getstate__``: what is derived is
    computed again after unpickling or copying, not carried (and stays read-only where the
    computation made it so)."""
    return {key: value for key, value in obj.__dict__.items() if key != _ATTRIBUTE}


def cached_on(obj: Any, name: str, compute: Callable[[], T]) -> T:
    """``compute()`` the first time ``name`` is asked of ``obj``, its stored value after."""
    store: dict[str, tuple[bool, Any]] | None = obj.__dict__.get(_ATTRIBUTE)
    if store is None:
        store = {}
        object.__setattr__(obj, _ATTRIBUTE, store)  # frozen dataclasses: not a field, not compared
    if name not in store:
        try:
            store[name] = (True, compute())
        except JointlockError as exc:
            store[name] = (False, exc)
    ok, value = store[name]
    if not ok:
        raise value
    return value
