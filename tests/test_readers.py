"""Model readers: TOML model files, URDF (structure and errors), built-in readings."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from conftest import EXACT_ATOL, random_q

import jointlock as jl
from jointlock.papers import p000

DATA = Path(__file__).parent / "data"


def _halt7_toml(tmp_path: Path, extra_base: bool = True) -> Path:
    model = jl.load_robot("halt7")
    rows = [
        (0, 0, 0.6, 0),
        (0, 90, 0.5, 0),
        (0, -90, 0.5, 0),
        (5, 0, 0.5, 0),
        (5, 0, 0.5, 0),
        (0, 90, 0.5, 0),
        (0, -90, 0.6, 0),
    ]
    lines = ['name = "halt7-from-file"', 'convention = "dh_modified"']
    for (a, alpha, d, theta), body in zip(rows, model.bodies):
        lines += [
            "[[joint]]",
            f"a_m = {a}\nalpha_deg = {alpha}\nd_m = {d}\ntheta_deg = {theta}",
            f"mass_kg = {body.mass}",
            f"com_m = {body.com.tolist()}",
            f"inertia_kgm2 = {np.diag(body.inertia).tolist()}",
        ]
    if extra_base:
        lines += [
            "[base]",
            "mass_kg = 2000.0",
            "com_m = [0.0, 0.0, -1.0]",
            "inertia_kgm2 = [1333.3333333333333, 1333.3333333333333, 1333.3333333333333]",
        ]
    path = tmp_path / "halt7.toml"
    path.write_text("\n".join(lines) + "\n")
    return path


def test_toml_model_equals_the_builtin(tmp_path, rng):
    path = _halt7_toml(tmp_path)
    ours = jl.load_robot(path, base="floating")
    ref = jl.load_robot("halt7", base="floating")
    q = random_q(ref, rng, (5,))
    np.testing.assert_allclose(jl.ee_pose(ours, q), jl.ee_pose(ref, q), atol=EXACT_ATOL)
    np.testing.assert_allclose(jl.generalized_jacobian(ours, q), jl.generalized_jacobian(ref, q), atol=1e-9)
    assert not jl.load_robot(path).floating


@pytest.mark.parametrize(
    "content, message",
    [
        (
            'convention = "dh_modified"\n[[joint]]\nalpha_degs = 1\n',
            r"unknown field 'alpha_degs' \(did you mean 'alpha_deg'\?\)",
        ),
        ('convention = "dh_modifed"\n[[joint]]\n', "field 'convention' must be one of"),
        ('convention = "dh_standard"\n', r"at least one \[\[joint\]\]"),
        (
            'convention = "dh_standard"\n[[joint]]\nd_m = "long"\n',
            r"field 'd_m' must be a finite real number >= -1e\+06 and <= 1e\+06 \[m\]; got 'long'",
        ),
        (
            'convention = "dh_standard"\n[[joint]]\nmass_kg = -3\n',
            r"joint 1: .*mass must be a number in \[0, 1e\+09\] kg",
        ),
        (
            'convention = "dh_standard"\n[[joint]]\nlower_deg = 10\nupper_deg = -10\n',
            "lower_deg must be <= upper_deg",
        ),
        (
            'convention = "dh_standard"\n[[joint]]\n[base]\nmass_kg = 0\n',
            "must be > 0 for a free-floating base",
        ),
        ("convention = \n", "not valid TOML"),
    ],
)
def test_toml_errors_name_file_and_field(tmp_path, content, message):
    path = tmp_path / "bad.toml"
    path.write_text(content)
    with pytest.raises(jl.ModelError, match=message):
        jl.read_model_toml(path)


def test_missing_model_file():
    with pytest.raises(jl.ModelError, match="model file .* does not exist"):
        jl.read_model_toml("/nonexistent/arm.toml")


def test_urdf_structure():
    model = jl.read_urdf(DATA / "arm5.urdf", base="floating")
    assert model.dof == 5
    assert [j.name for j in model.joints] == [
        "shoulder_yaw",
        "shoulder_pitch",
        "elbow",
        "wrist_pitch",
        "wrist_roll",
    ]
    # camera (fixed on l2) merged into link 2; flange + tool tip merged into link 5
    assert model.bodies[1].mass == pytest.approx(22.0)
    assert model.bodies[4].mass == pytest.approx(4.0)
    assert model.root_body.mass == 800.0
    assert math.isinf(model.joints[2].lower)  # continuous
    # the end effector defaults to the deepest link after the last movable joint (tool_tip)
    np.testing.assert_allclose(model.tool[:3, 3], [0, 0, 0.13])
    flange = jl.read_urdf(DATA / "arm5.urdf", ee_link="flange")
    np.testing.assert_allclose(flange.tool[:3, 3], [0, 0, 0.08])


def _urdf(body: str) -> str:
    return f'<robot name="r"><link name="a"/><link name="b"/>{body}</robot>'


@pytest.mark.parametrize(
    "xml, message",
    [
        (
            _urdf('<joint name="j" type="planar"><parent link="a"/><child link="b"/></joint>'),
            "joint 'j': type 'planar' is not supported",
        ),
        (
            _urdf('<joint name="j" type="prismatic"><parent link="a"/><child link="b"/></joint>'),
            "joint 'j': a prismatic joint needs <limit",
        ),
        (
            '<robot name="r"><link name="a"/><link name="b"/><link name="c"/>'
            '<joint name="r1" type="continuous"><parent link="a"/><child link="b"/></joint>'
            '<joint name="j" type="prismatic"><parent link="b"/><child link="c"/><limit lower="0" upper="1"/></joint>'
            "</robot>",
            "joint 'j' on the chain is prismatic; jointlock's chain has revolute joints only: freeze it",
        ),
        (
            _urdf('<joint name="j" type="revolute"><parent link="a"/><child link="b"/></joint>'),
            r"joint 'j': a revolute joint needs <limit",
        ),
        (
            _urdf(
                '<joint name="j" type="revolute"><parent link="a"/><child link="c"/><limit lower="0" upper="1"/></joint>'
            ),
            "child link 'c' is not defined",
        ),
        (
            _urdf(
                '<joint name="j" type="continuous"><parent link="a"/><child link="b"/><origin xyz="1 2"/></joint>'
            ),
            r"joint 'j' <origin xyz>: expected 3 finite numbers",
        ),
        (_urdf(""), "expected exactly one root link"),
        ("<robot><link name='a'>", "malformed XML"),
        (
            '<robot name="r"><link name="a"><inertial><mass value="-2"/></inertial></link><link name="b"/>'
            '<joint name="j" type="continuous"><parent link="a"/><child link="b"/></joint></robot>',
            "link 'a' <inertial>: .*mass must be",
        ),
        (
            _urdf('<joint name="j" type="continuous"><parent link="a"/><child link="b"/></joint>'),
            "base='floating' needs an <inertial>",
        ),
    ],
)
def test_urdf_errors_name_the_element(xml, message):
    base = "floating" if "base='floating'" in message else "fixed"
    with pytest.raises(jl.ModelError, match=message):
        jl.read_urdf(xml, base=base)


def test_urdf_branching_movable_joints_are_refused():
    xml = (
        '<robot name="r"><link name="a"/><link name="b"/><link name="c"/>'
        '<joint name="j1" type="continuous"><parent link="a"/><child link="b"/></joint>'
        '<joint name="j2" type="continuous"><parent link="a"/><child link="c"/></joint></robot>'
    )
    with pytest.raises(jl.ModelError, match="the tree branches at link 'a' into joints \\['j1', 'j2'\\]; name the chain's end"):
        jl.read_urdf(xml)


def test_halt7_readings_are_selectable(rng):
    from jointlock.robots import halt7

    with_offsets = halt7(theta_offsets=True)
    without = halt7()
    q = random_q(with_offsets, rng)
    shifted = q + np.radians([0, 90, 0, 0, 0, -90, 0])
    np.testing.assert_allclose(jl.ee_pose(with_offsets, q), jl.ee_pose(without, shifted), atol=EXACT_ATOL)


def test_halt7_default_reading_keeps_000s_halt_configurations_regular():
    """000 §5.1's q_best and q_sub (joint 4 locked at 0): exactly singular if the theta column
    is added, regular under the default reading (the test that chose the default)."""
    from jointlock.robots import halt7

    q_best = np.radians(p000.Q_BEST_DEG)
    q_sub = np.radians(p000.Q_SUB_DEG)
    for offsets, singular in ((True, True), (False, False)):
        model = jl.lock(halt7(theta_offsets=offsets), 4, 0.0)
        for q in (q_best, q_sub):
            sigma_min = np.linalg.svd(jl.jacobian(model, q), compute_uv=False)[-1]
            assert (sigma_min < 1e-9) == singular
