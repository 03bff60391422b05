"""Keep-out volumes in scenario files (issue 27: ``[[keep_out]]``): boxes, spheres and capsules in
the root frame that the halt configuration and the halt keep clear of, like the spacecraft bus;
bad entries refused in one line; the run's equivalent commands read them back (--keep-out)."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

import jointlock as jl
from jointlock.errors import ScenarioError

#: A sphere around where the demo's halt configuration puts halt7's wrist (-5.9, 2.0, -7.3 m).
KEEP_OUT = """
[[keep_out]]
name = "docked vehicle"
sphere_m = 1.5
center_m = [-5.9, 2.0, -7.3]

[[keep_out]]
name = "solar array"
box_m = [4.0, 0.2, 2.0]
center_m = [8.0, 0.0, -2.0]
rpy_deg = [0.0, 0.0, 30.0]
"""

BASE = """
robot = "halt7"
base = "floating"
[failure]
joint = 4
angle_deg = 0.0
[halt_config]
samples = 4000
"""


def test_the_search_keeps_clear_of_a_keep_out(tmp_path):
    """A sphere of 1 m where the plain search puts the end effector: the search with the
    keep-out picks another configuration, 0.05 m clear of it (and of the bus and the arm)."""
    import tomllib

    from jointlock.jobs._common import scenario_clearance

    plain = jl.run_scenario(jl.scenario_from_dict(tomllib.loads(BASE), base_dir=tmp_path))["halt_config"]
    model = jl.lock(jl.load_robot("halt7", base="floating"), 4, 0.0)
    tip = jl.ee_pose(model, plain.q_best)[:3, 3]
    path = tmp_path / "k.toml"
    path.write_text(BASE + KEEP_OUT.replace("[-5.9, 2.0, -7.3]", "[" + ", ".join(f"{v:.6f}" for v in tip) + "]")
                    .replace("sphere_m = 1.5", "sphere_m = 1.0"))  # fmt: skip
    scenario = jl.load_scenario(path)
    assert [e["name"] for e in scenario.data["keep_out"]] == ["docked vehicle", "solar array"]
    guarded = jl.run_scenario(scenario)["halt_config"]
    settings = scenario_clearance(scenario.data)
    before = jl.clearance(model, plain.q_best, keep_out=settings.keep_out)
    after = jl.clearance(model, guarded.q_best, keep_out=settings.keep_out)
    assert float(before.distance) < 0 and "docked vehicle" in before.pair_at(())  # the plain choice is inside
    assert float(after.distance) >= 0.05 - 1e-9  # the guarded one keeps clear of everything


@pytest.mark.parametrize(
    "entry, words",
    [
        ('sphere_m = 0.5\ncenter_m = [0, 0]', "center_m must be 3 finite numbers"),
        ('sphere_m = -1\ncenter_m = [0, 0, 0]', "sphere_m must be a radius"),
        ('box_m = [1, 1, 1]\nsphere_m = 1.0\ncenter_m = [0, 0, 0]', "needs exactly one of box_m"),
        ('capsule_m = 0.1\nfrom_m = [0, 0, 0]\nto_m = [0, 0, 1]\ncenter_m = [0, 0, 0]', "center_m does not belong to a capsule"),
        ('box_m = [1, 0, 1]\ncenter_m = [0, 0, 0]', "box_m must be 3 numbers > 0"),
        ('sphere_m = 1.0\ncenter_m = [0, 0, 0]\ncolour = "red"', "unknown field 'colour'"),
    ],
)
def test_bad_keep_outs_are_one_line(tmp_path, entry, words):
    path = tmp_path / "k.toml"
    path.write_text(BASE + "\n[[keep_out]]\n" + entry + "\n")
    with pytest.raises(ScenarioError) as info:
        jl.load_scenario(path)
    assert words in str(info.value) and "keep_out entry 1" in str(info.value) and "\n" not in str(info.value)


def test_the_runs_equivalent_command_reads_the_keep_outs(tmp_path):
    path = tmp_path / "k.toml"
    path.write_text(BASE + KEEP_OUT)
    out = tmp_path / "out"
    written = jl.run_scenario(jl.load_scenario(path)).write(out)
    command = written["jobs"]["halt_config"]["command"]
    assert f"--keep-out {out / 'keep_out.toml'}" in command and (out / "keep_out.toml").is_file()
    argv = command.split()[1:]  # without "jointlock"
    proc = subprocess.run([sys.executable, "-m", "jointlock", *argv], capture_output=True, text=True, check=True)
    import json

    again = json.loads(proc.stdout)
    np.testing.assert_allclose(again["best"]["q_deg"], written["jobs"]["halt_config"]["result"]["best"]["q_deg"], atol=1e-9)
