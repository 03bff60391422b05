"""An SRDF's disabled collision pairs (issue 27: "an SRDF's disable_collisions read when given"):
read as Pinocchio reads them (removeCollisionPairs on the same files), skipped by the clearance,
given by a scenario (`srdf`, relative to its folder) or the command line (`--srdf`), carried
through a lock; bad files are one line."""

from __future__ import annotations

import json

import numpy as np
import pytest

import jointlock as jl
from jointlock.collision import clearance, collision_pairs
from jointlock.errors import ModelError, ScenarioError
from jointlock.io.srdf import read_srdf
from jointlock.robots import UrdfChain

URDF = "panda_description/urdf/panda_collision.urdf"
SRDF = "panda_description/srdf/panda.srdf"


def _files():
    from robot_data import robot_file

    return robot_file(URDF), robot_file(SRDF)


def _link_pairs(names) -> set[tuple[str, str]]:
    return {tuple(sorted(name.split(" #")[0].split(" - "))) for name in names}  # type: ignore[misc]


def test_the_pairs_are_pinocchios_and_the_clearance_skips_them():
    from pin_oracle import pin

    urdf, srdf = _files()
    disabled = read_srdf(srdf)
    assert len(disabled) == 35 and ("panda_link0", "panda_link1") in disabled
    plain = jl.read_urdf(urdf, tip_link="panda_hand")
    arm = jl.load_robot(urdf, chain=UrdfChain(tip_link="panda_hand", srdf=str(srdf)))
    before, after = _link_pairs(collision_pairs(plain).names), _link_pairs(collision_pairs(arm).names)
    assert after == before - set(disabled) and after < before  # the SRDF removes some of ours
    # Pinocchio's reading of the same SRDF: every pair it keeps between two links is kept by us
    # unless our own rules skip it (adjacent links, one rigid body), and none it removes is ours
    full = pin.buildModelFromUrdf(str(urdf))
    geom = pin.buildGeomFromUrdf(full, str(urdf), pin.GeometryType.COLLISION)
    geom.addAllCollisionPairs()
    pin.removeCollisionPairs(full, geom, str(srdf))
    links = [obj.name.rsplit("_", 1)[0] for obj in geom.geometryObjects]
    kept_by_pin = {tuple(sorted((links[p.first], links[p.second]))) for p in geom.collisionPairs}
    assert after <= kept_by_pin and not (after & set(disabled))
    # the distances of the pairs left are the same with and without the SRDF
    q = np.random.default_rng(3).uniform(arm.lower, arm.upper, (50, arm.dof))
    with_srdf, without = clearance(arm, q), clearance(plain, q)
    for k, name in enumerate(with_srdf.names):
        j = without.names.index(name)
        assert np.allclose(with_srdf.pair_distance[:, k], without.pair_distance[:, j], atol=1e-12)


def test_a_lock_keeps_the_disabled_pairs():
    urdf, srdf = _files()
    arm = jl.load_robot(urdf, chain=UrdfChain(tip_link="panda_hand", srdf=str(srdf)))
    locked = jl.lock(arm, joint=4, angle=-1.5)
    assert locked.disabled_pairs == arm.disabled_pairs
    assert not (_link_pairs(collision_pairs(locked).names) & set(arm.disabled_pairs))


def test_a_scenario_and_the_command_line_give_it(tmp_path, capsys):
    from jointlock.cli import main

    urdf, srdf = _files()
    (tmp_path / "panda.srdf").write_bytes(srdf.read_bytes())
    path = tmp_path / "ik.toml"
    path.write_text(
        f'robot = "{urdf}"\ntip_link = "panda_hand"\nsrdf = "panda.srdf"\n'
        "[singular]\nq_deg = [0, -45, 0, -135, 0, 90, 45]\n"
    )
    scenario = jl.load_scenario(path)
    assert scenario.data["srdf"] == str((tmp_path / "panda.srdf").resolve())
    assert UrdfChain.from_fields(scenario.data).srdf == scenario.data["srdf"]
    from jointlock.run._commands import _chain_args

    assert _chain_args(scenario.data)[-2:] == ["--srdf", scenario.data["srdf"]]
    argv = ["ik", str(urdf), "--tip", "panda_hand", "--pose", "0.4", "0.1", "0.5", "0", "180", "0", "--json"]
    assert main([*argv, "--srdf", str(srdf)]) == 0
    assert json.loads(capsys.readouterr().out)["solutions"]
    assert main(["ik", "puma6", "--srdf", str(srdf), "--pose", "0.4", "0.1", "0.5", "0", "180", "0"]) == 2
    assert "(--srdf its pairs not checked for clearance, --meshes how its meshes are read); ROBOT 'puma6' is a built-in robot" in capsys.readouterr().err


@pytest.mark.parametrize(
    "text, words",
    [
        ("<robot><disable_collisions link1='a'/></robot>", "<disable_collisions> 1 needs link1 and link2"),
        ("<robot><disable_collisions", "malformed XML"),
        ("<srdf/>", "the root element must be <robot>"),
    ],
)
def test_bad_srdf_files_are_one_line(tmp_path, text, words):
    path = tmp_path / "bad.srdf"
    path.write_text(text)
    with pytest.raises(ModelError) as err:
        read_srdf(path)
    assert words in str(err.value) and "\n" not in str(err.value)
    with pytest.raises(ModelError, match="not found|no such|does not exist|cannot"):
        read_srdf(tmp_path / "missing.srdf")


def test_an_srdf_needs_a_urdf_robot(tmp_path):
    path = tmp_path / "s.toml"
    path.write_text('robot = "puma6"\nsrdf = "x.srdf"\n[workspace]\n')
    with pytest.raises(ScenarioError, match="srdf: chooses the chain of a URDF robot"):
        jl.load_scenario(path)


def test_a_campaign_keys_the_srdf_by_content_and_another_robots_srdf_is_said(tmp_path):
    from jointlock.campaign import case_key

    urdf, srdf = _files()
    keys = []
    for folder, text in (("a", srdf.read_text()), ("b", srdf.read_text()), ("c", "<robot/>")):
        (tmp_path / folder).mkdir()
        (tmp_path / folder / "p.srdf").write_text(text)
        path = tmp_path / folder / "s.toml"
        path.write_text(f'robot = "{urdf}"\ntip_link = "panda_hand"\nsrdf = "p.srdf"\n[workspace]\n')
        keys.append(case_key(jl.load_scenario(path), 0))
    assert keys[0] == keys[1] != keys[2]  # the same file in two folders; another content
    other = tmp_path / "other.srdf"
    other.write_text("<robot><disable_collisions link1='wheel' link2='mast'/></robot>")
    with pytest.warns(UserWarning, match="is it this robot's SRDF"):
        jl.load_robot(urdf, chain=UrdfChain(tip_link="panda_hand", srdf=str(other)))


@pytest.mark.parametrize("pair", [("a", "b", "c"), "ab", ("a", 3)])
def test_disabled_pairs_must_be_two_names(pair):
    from jointlock.geometry import with_disabled_pairs

    with pytest.raises(ModelError, match="pairs of shape names"):
        with_disabled_pairs(jl.load_robot("puma6"), [pair])
