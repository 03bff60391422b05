"""Attributes of a package imported on first use (PEP 562 ``__getattr__`` / ``__dir__``).

The package ``__init__`` modules of jointlock expose many names without importing the
modules behind them (they pull in scipy and matplotlib), one mechanism for all of them.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Iterable, Mapping
from typing import Any


def lazy_attributes(
    package: str, names: Mapping[str, str], modules: Iterable[str] = (), namespace: Mapping[str, Any] | None = None
) -> tuple[Callable[[str], Any], Callable[[], list[str]]]:
    """``(__getattr__, __dir__)`` for ``package``: ``names`` maps an attribute to the module
    (absolute name) that defines it; ``modules`` are subpackages or submodules reachable as
    attributes; ``namespace`` (the package's ``globals()``) is listed by ``__dir__`` too."""
    modules = tuple(modules)

    def __getattr__(name: str) -> Any:
        if name in names:
            return getattr(importlib.import_module(names[name]), name)
        if name in modules:
            return importlib.import_module(f"{package}.{name}")
        raise AttributeError(f"module {package!r} has no attribute {name!r}")

    def __dir__() -> list[str]:
        return sorted(set(namespace or {}) | set(names) | set(modules))

    return __getattr__, __dir__
