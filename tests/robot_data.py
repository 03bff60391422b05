"""Test-only access to the real-robot URDFs of the ``example-robot-data`` package on PyPI
(the test extra): found through :mod:`importlib.metadata`, never copied into the repository.
A test asking for one is skipped, saying why, when the distribution is not installed."""

from __future__ import annotations

import importlib.metadata
from pathlib import Path

import pytest

#: Where the wheel puts the robots (a cmeel package: under its ``cmeel.prefix``).
ROBOTS = "cmeel.prefix/share/example-robot-data/robots"
PANDA = "panda_description/urdf/panda.urdf"
BAXTER = "baxter_description/urdf/baxter.urdf"
TIAGO_DUAL = "tiago_description/robots/tiago_dual.urdf"


def robot_file(relative: str) -> Path:
    """The installed file ``robots/<relative>`` of example-robot-data; skips the test when the
    distribution (or that file in it) is absent."""
    try:
        dist = importlib.metadata.distribution("example-robot-data")
    except importlib.metadata.PackageNotFoundError:
        pytest.skip("example-robot-data is not installed (pip install 'jointlock[test]' brings it)")
    path = Path(str(dist.locate_file(f"{ROBOTS}/{relative}")))
    if not path.is_file():
        pytest.skip(f"example-robot-data {dist.version} has no {ROBOTS}/{relative}")
    return path
