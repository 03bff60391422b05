"""A griffe extension for the API reference (mkdocs.yml): the docstrings are written for
Sphinx/numpydoc and cross-reference with roles (``:func:`plan_halt```, ``:class:`~x.Y```);
Markdown has no roles, so each becomes inline code naming its target (``~`` keeps the last
part, as Sphinx shows it)."""

from __future__ import annotations

import re
from typing import Any

import griffe

_ROLE = re.compile(r":(?:py:)?(?:func|class|meth|mod|data|attr|obj|exc|const|ref|doc|term):`~?([^`<]*?)(?:\s*<([^>]*)>)?`")


def _show(match: re.Match[str]) -> str:
    text, target = match.group(1).strip(), match.group(2)
    shown = text or (target or "")
    if match.group(0).split("`", 1)[1].startswith("~"):
        shown = shown.rsplit(".", 1)[-1]
    return f"`{shown}`"


class SphinxRoles(griffe.Extension):
    """Rewrite Sphinx roles in every docstring as Markdown inline code."""

    def on_instance(self, *, obj: Any, **kwargs: Any) -> None:
        if obj.docstring is not None:
            obj.docstring.value = _ROLE.sub(_show, obj.docstring.value)
