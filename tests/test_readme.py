"""The README is the front door (issue 30): its two commands are the first code block, every
link in it resolves, it stays short, and its short tour runs.  The long pages it links to keep
their own tests (docs/reproduce.md, docs/scenarios.md, the examples)."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
README = (ROOT / "README.md").read_text()

#: A front door, not a manual (the issue: the README was 47 KB; the long parts moved to docs/).
MAX_README_BYTES = 16_000


def _slug(heading: str) -> str:
    """GitHub's anchor of a heading: lower case, punctuation dropped, spaces to hyphens."""
    text = re.sub(r"[^\w\- ]", "", heading.strip().lower())
    return text.replace(" ", "-")


def _links(text: str) -> list[str]:
    return [m for m in re.findall(r"\]\(([^)\s]+)\)", text) if not re.match(r"[a-z]+://", m)]


def test_the_two_commands_are_the_first_code_block():
    first = re.search(r"```(\w*)\n(.*?)```", README, re.S)
    assert first is not None and first.group(1) == "bash"
    commands = [line.split("#")[0].strip() for line in first.group(2).splitlines() if line.split("#")[0].strip()]
    assert commands == ["bash scripts/demo.sh", "bash scripts/test.sh"]
    assert (ROOT / ".ci" / "run").read_text().strip().endswith("bash scripts/test.sh")


def test_every_link_resolves():
    headings = {_slug(h) for h in re.findall(r"(?m)^#+ (.*)$", README)}
    links = _links(README)
    assert len(links) > 20
    for link in links:
        path, _, anchor = link.partition("#")
        if path:
            assert (ROOT / path).exists(), link
        elif anchor:
            assert anchor in headings, link


def test_the_docs_pages_links_resolve():
    """The pages the README sends readers to (and the rest of docs/) link to files that exist."""
    for page in (ROOT / "docs").rglob("*.md"):
        for link in _links(page.read_text()):
            path = link.partition("#")[0]
            if path:
                assert (page.parent / path).resolve().exists(), f"{page.relative_to(ROOT)}: {link}"


def test_the_readme_is_a_front_door():
    assert len(README.encode()) < MAX_README_BYTES
    for moved in ("docs/guide.md", "docs/performance.md", "docs/campaigns.md", "docs/robots.md"):
        assert f"]({moved})" in README, moved
    # what moved is still there, where the README points
    assert "Issue 13's targets" in (ROOT / "docs" / "performance.md").read_text()
    assert "## What the example campaigns found" in (ROOT / "docs" / "campaigns.md").read_text()
    assert "## Command line" in (ROOT / "docs" / "guide.md").read_text()


def test_the_short_tour_runs(tmp_path, monkeypatch):
    """The README's Python tour, as printed (its output folder under tmp_path)."""
    pytest.importorskip("mujoco")
    monkeypatch.chdir(tmp_path)
    block = re.findall(r"```python\n(.*?)```", README, re.S)[0]
    namespace: dict = {}
    exec(compile(block, "README.md", "exec"), namespace)
    assert namespace["plan"].feasible and (tmp_path / "out" / "halt" / "result.json").is_file()
