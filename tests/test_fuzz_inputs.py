"""Property-based fuzzing of every public boundary (Hypothesis): model files (TOML and URDF, in
any encoding), scenario files, the options of every subcommand, joint arrays and lock calls.

The property, for every generated input: either a valid result whose numbers are all finite,
or one project error (:class:`JointlockError`) whose message is one line -- never another
exception, never a traceback, never NaN/inf, never a numpy warning (pytest turns
RuntimeWarning into an error).  On the command line: exit 0 with finite JSON, or exit 2 with
exactly one stderr line.

Budget: the default profile draws a fixed, derandomized set (:func:`budget` examples per
test, 2,100 in all, ~20 s on one core); ``HYPOTHESIS_PROFILE=long`` draws 20x as many fresh ones.  The
outcome counts are Hypothesis events: ``pytest tests/test_fuzz_inputs.py
--hypothesis-show-statistics`` prints them.
"""

from __future__ import annotations

import dataclasses
import itertools
import json
import math
import os
import re
import tomllib
from pathlib import Path
from xml.sax.saxutils import quoteattr

import numpy as np
import pytest
from hypothesis import event, given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

import jointlock as jl
from jointlock.cli import build_parser, main
from jointlock.errors import JointlockError
from jointlock.io.files import toml_value  # the project's TOML value writer (nan, inf, any int)

ROOT = Path(__file__).resolve().parents[1]
ARM5 = (ROOT / "tests" / "data" / "arm5.urdf").read_text()
EXAMPLES = {p.stem: tomllib.loads(p.read_text()) for p in sorted((ROOT / "examples").glob("*.toml"))}
LONG = os.environ.get("HYPOTHESIS_PROFILE") == "long"


def budget(n: int) -> int:
    """Examples of one test: ``n`` by default, 20x with HYPOTHESIS_PROFILE=long."""
    return n * 20 if LONG else n


# --- what every outcome must satisfy -----------------------------------------------------------


def check_outcome(call) -> str:
    """Run ``call()``: a finite result ("ok") or one one-line JointlockError (its class name)."""
    try:
        result = call()
    except JointlockError as exc:
        message = str(exc)
        assert message and "\n" not in message and len(message) < 1000, repr(message)
        event(f"error: {type(exc).__name__}")
        return type(exc).__name__
    assert_finite(result)
    event("ok")
    return "ok"


def assert_finite(obj, where: str = "result") -> None:
    """Every float reachable from ``obj`` (arrays, dataclasses, mappings, sequences) is finite."""
    if isinstance(obj, np.ndarray):
        if obj.dtype.kind in "fc":
            assert np.all(np.isfinite(obj)), f"{where}: non-finite values"
    elif isinstance(obj, float):
        assert math.isfinite(obj), f"{where}: {obj}"
    elif dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        for f in dataclasses.fields(obj):
            assert_finite(getattr(obj, f.name), f"{where}.{f.name}")
    elif isinstance(obj, dict):
        for k, v in obj.items():
            assert_finite(v, f"{where}[{k!r}]")
    elif isinstance(obj, (list, tuple)):
        for i, v in enumerate(obj):
            assert_finite(v, f"{where}[{i}]")


def exercise(model: jl.ArmModel, q: np.ndarray) -> dict:
    """What a user computes first with a model: poses, Jacobian, mass matrix, torques."""
    out = {
        "ee": jl.ee_pose(model, q),
        "jacobian": jl.jacobian(model, q),
        "mass": jl.mass_matrix(model, q),
        "torques": jl.rnea(model, q, np.full(model.dof, 0.1), np.full(model.dof, 0.2)).torques,
    }
    if model.floating:
        out["generalized"] = jl.generalized_jacobian(model, q)
    return out


def run_cli(capsys, argv: list[str]) -> tuple[int, str, str]:
    """(exit code, stdout, stderr) of the CLI in-process, with the CLI's own properties checked."""
    try:
        code = main(argv)
    except SystemExit as exc:  # argparse refusing an option
        code = int(exc.code)
    out, err = capsys.readouterr()
    assert code in (0, 2), (argv, code, err[-2000:])
    assert "Traceback" not in err, err
    if code == 2:
        assert err.count("\n") == 1 and "error:" in err, (argv, err)
        event("cli: exit 2, one line")
    else:
        event("cli: exit 0")
        if "--json" in argv:
            assert "NaN" not in out and "Infinity" not in out
            json.loads(out)
    return code, out, err


# --- strategies ----------------------------------------------------------------------------------

#: Numbers as a user may type them, the extremes floats cannot hold included (half the draws
#: plausible, so that accepted values go on through the maths).
NUMBER_TEXT = st.one_of(
    st.floats(min_value=-500, max_value=500).map(lambda x: f"{x:.4g}"),
    st.integers(min_value=0, max_value=3000).map(str),
    st.floats(min_value=1e-3, max_value=20).map(lambda x: f"{x:.3g}"),
    st.floats(allow_nan=True, allow_infinity=True).map(repr),
    st.floats(min_value=-1e4, max_value=1e4).map(lambda x: f"{x:g}"),
    st.integers(min_value=-(10**450), max_value=10**450).map(str),
    st.sampled_from(["1e308", "-1e308", "1e-320", "1e-300", "4294967297", "0", "-0", "nan", "inf", "-inf",
                     "1e999", "0x10", "", " ", "abc", "1_000", "\u0663", "1e6", "1000001", "2e-6"]),
)  # fmt: skip
#: Values a careful user writes (half the draws reach the maths behind the readers) ...
PLAUSIBLE_VALUE = st.one_of(
    st.floats(min_value=-100, max_value=100),
    st.integers(min_value=0, max_value=2000),
    st.lists(st.floats(min_value=-10, max_value=10), min_size=3, max_size=3),
    st.lists(st.floats(min_value=0, max_value=100), min_size=6, max_size=6),
)
#: ... and TOML values of every type, numbers at every scale, odd strings.
HOSTILE_VALUE = st.recursive(
    st.one_of(
        st.floats(allow_nan=True, allow_infinity=True),
        st.integers(min_value=-(10**450), max_value=10**450),
        st.integers(min_value=-10, max_value=10**7),
        st.booleans(),
        st.text(max_size=12),
        st.sampled_from(["", "\x00.urdf", "../..", "/", "halt7", "puma6.urdf"]),
        st.integers(3000, 6000).map(lambda n: "x" * n),
    ),
    lambda inner: st.lists(inner, max_size=8),
    max_leaves=10,
)
TOML_VALUE = st.one_of(PLAUSIBLE_VALUE, HOSTILE_VALUE)


def toml_text(data: dict) -> str:
    lines = [f"{json.dumps(k)} = {toml_value(v)}" for k, v in data.items() if not _is_table(v)]
    for key, value in data.items():
        if isinstance(value, dict):
            lines += ["", f"[{json.dumps(key)}]"] + [f"{json.dumps(k)} = {toml_value(v)}" for k, v in value.items()]
        elif _is_table(value):
            for row in value:
                lines += ["", f"[[{json.dumps(key)}]]"] + [f"{json.dumps(k)} = {toml_value(v)}" for k, v in row.items()]
    return "\n".join(lines) + "\n"


def _is_table(v) -> bool:
    return isinstance(v, dict) or (isinstance(v, list) and bool(v) and all(isinstance(r, dict) for r in v))


def encoded(text: str, how: str) -> bytes:
    """``text`` as bytes in one of the encodings users' editors produce (or broken)."""
    if how == "utf-8":
        return text.encode()
    if how == "latin-1":
        return ("# caf\u00e9\n" + text).encode("latin-1", errors="replace")
    if how == "utf-16":
        return text.encode("utf-16")
    if how == "utf-16-no-bom":
        return text.encode("utf-16-le")
    if how == "truncated":
        return text.encode()[: len(text) // 2] + b"\xff\xfe\x00"
    raise ValueError(how)


ENCODINGS = st.sampled_from(["utf-8"] * 6 + ["latin-1", "utf-16", "utf-16-no-bom", "truncated"])

MODEL_BASE = {
    "name": "fuzz3",
    "convention": "dh_modified",
    "joint": [
        {"d_m": 0.5, "mass_kg": 10.0, "inertia_kgm2": [1.0, 1.0, 1.0]},
        {"a_m": 1.0, "alpha_deg": 90.0, "mass_kg": 10.0, "com_m": [0.5, 0.0, 0.0], "inertia_kgm2": [1.0, 1.0, 1.0]},
        {"a_m": 1.0, "mass_kg": 5.0, "com_m": [0.5, 0.0, 0.0], "inertia_kgm2": [0.5, 0.5, 0.5]},
    ],
    "tool": {"xyz_m": [0.1, 0.0, 0.0], "rpy_deg": [0.0, 0.0, 0.0]},
    "base": {"mass_kg": 500.0, "com_m": [0.0, 0.0, -1.0], "inertia_kgm2": [100.0, 100.0, 100.0]},
}
MODEL_KEYS = {
    "joint": ["a_m", "alpha_deg", "d_m", "theta_deg", "lower_deg", "upper_deg", "velocity_limit_deg_s",
              "mass_kg", "com_m", "inertia_kgm2", "name", "a_mm"],
    "tool": ["xyz_m", "rpy_deg", "xyz"],
    "base": ["mass_kg", "com_m", "inertia_kgm2", "mass"],
    "": ["name", "convention", "description", "joints"],
}  # fmt: skip


@st.composite
def model_toml_files(draw) -> bytes:
    data = json.loads(json.dumps(MODEL_BASE))
    for _ in range(draw(st.integers(1, 3))):
        table = draw(st.sampled_from(sorted(MODEL_KEYS)))
        key = draw(st.sampled_from(MODEL_KEYS[table]))
        value = draw(TOML_VALUE)
        if table == "joint":
            rows = data["joint"]
            rows[draw(st.integers(0, len(rows) - 1))][key] = value
        elif table:
            data[table][key] = value
        else:
            data[key] = value
    if draw(st.booleans()):
        data["joint"] = data["joint"][: draw(st.integers(0, 3))] or draw(st.sampled_from([[], 0, "x"]))
    return encoded(toml_text(data), draw(ENCODINGS))


URDF_ATTRIBUTE = re.compile(r'(\w+)="([^"]*)"')
URDF_SLOTS = [m.span(2) for m in URDF_ATTRIBUTE.finditer(ARM5)]


@st.composite
def urdf_files(draw) -> bytes:
    """arm5.urdf with 1-4 attribute values replaced (numbers, names, types, links), and at times
    an extra link or joint (a cycle, a dangling parent, a duplicate)."""
    text = ARM5
    slots = sorted(draw(st.lists(st.sampled_from(URDF_SLOTS), min_size=1, max_size=3, unique=True)), reverse=True)
    for start, end in slots:
        value = draw(st.one_of(
            st.tuples(*[st.floats(-2, 2).map(lambda x: f"{x:.3g}")] * 3).map(" ".join),
            st.floats(0, 50).map(lambda x: f"{x:.3g}"),
            st.tuples(NUMBER_TEXT, NUMBER_TEXT, NUMBER_TEXT).map(" ".join),
            NUMBER_TEXT,
            st.sampled_from(["revolute", "prismatic", "continuous", "fixed", "floating", "l1", "l2", "l3",
                             "spacecraft", "camera", "nowhere", ""]),
            st.integers(3000, 6000).map(lambda n: "x" * n),
        ))  # fmt: skip
        text = text[:start] + quoteattr(value)[1:-1] + text[end:]
    extra = draw(st.sampled_from([
        "",
        "",
        "",
        '<link name="c1"/><link name="c2"/><joint name="a" type="revolute"><parent link="c1"/><child link="c2"/>'
        '<limit lower="-1" upper="1"/></joint><joint name="b" type="revolute"><parent link="c2"/><child link="c1"/>'
        '<limit lower="-1" upper="1"/></joint>',
        '<joint name="d" type="fixed"><parent link="nowhere"/><child link="l1"/></joint>',
        '<link name="l1"/>',
        '<joint name="e" type="continuous"><parent link="spacecraft"/><child link="extra"/></joint><link name="extra"/>',
    ]))  # fmt: skip
    text = text.replace("</robot>", extra + "</robot>")
    return encoded(text, draw(ENCODINGS))


# --- the properties ------------------------------------------------------------------------------

_counter = itertools.count()


@pytest.fixture(scope="module")
def fuzz_dir(tmp_path_factory) -> Path:
    return tmp_path_factory.mktemp("fuzz")


def _file(folder: Path, suffix: str, data: bytes) -> Path:
    path = folder / f"f{next(_counter)}{suffix}"  # a new name each time: no model cache hit
    path.write_bytes(data)
    return path


@settings(max_examples=budget(300))
@given(data=model_toml_files(), base=st.sampled_from(["fixed", "floating"]), q=st.floats(-4, 4))
def test_model_toml_files(fuzz_dir, data, base, q):
    path = _file(fuzz_dir, ".toml", data)
    check_outcome(lambda: exercise(jl.load_robot(path, base=base), np.full(3, q)))


@settings(max_examples=budget(300))
@given(data=urdf_files(), base=st.sampled_from(["fixed", "floating"]), q=st.floats(-4, 4))
def test_urdf_files(fuzz_dir, data, base, q):
    path = _file(fuzz_dir, ".urdf", data)

    def load_and_use():
        model = jl.load_robot(path, base=base)
        return exercise(model, np.full(model.dof, q))

    check_outcome(load_and_use)


SCENARIO_FIELDS = sorted(
    {(t, f) for t, fields in jl.scenario.ALL_TABLES.items() for f in fields}
    | {("", f) for f in jl.scenario.TOP_FIELDS}
    | {("halt", "Tt"), ("", "jobz"), ("nosuch", "x")}
)


def in_schema(table: str, field: str) -> st.SearchStrategy:
    """Values of the field's own kind within its bounds (valid alone; maybe not together)."""
    fields = jl.scenario.ALL_TABLES.get(table) if table else jl.scenario.TOP_FIELDS
    spec = (fields or {}).get(field)
    if spec is None:
        return TOML_VALUE
    lo = -1e6 if spec.lo is None else spec.lo
    hi = 1e6 if spec.hi is None else spec.hi
    if spec.kind == "int":
        return st.integers(int(math.ceil(lo)), int(min(hi, lo + 10_000)))
    if spec.kind == "number":
        return st.floats(lo, hi, exclude_min=spec.lo_open)
    if spec.kind == "numbers":
        return st.lists(st.floats(lo, hi), min_size=spec.length or 1, max_size=spec.length or 8)
    if spec.kind == "bool":
        return st.booleans()
    if spec.kind == "choice":
        return st.sampled_from(spec.choices)
    return TOML_VALUE


@st.composite
def scenario_files(draw) -> bytes:
    data = json.loads(json.dumps(EXAMPLES[draw(st.sampled_from(sorted(EXAMPLES)))]))
    for _ in range(draw(st.integers(1, 2))):
        table, field = draw(st.sampled_from(SCENARIO_FIELDS))
        value = draw(st.one_of(in_schema(table, field), in_schema(table, field), TOML_VALUE))
        if table:
            holder = data.setdefault(table, {})
            if isinstance(holder, dict):
                holder[field] = value
        else:
            data[field] = value
    return encoded(toml_text(data), draw(ENCODINGS))


@settings(max_examples=budget(400))
@given(data=scenario_files())
def test_scenario_files(fuzz_dir, data):
    path = _file(fuzz_dir, ".toml", data)
    check_outcome(lambda: jl.load_scenario(path))


#: Every numeric option of every subcommand: (argv before it, option, values it takes).
OPTIONS = [
    (["kinematics", "halt7"], "--q-deg", 7), (["halt", "halt7", "--lock", "4=0"], "--T", 1),
    (["halt", "halt7", "--lock", "4=0"], "--samples", 1), (["halt", "halt7", "--lock", "4=0"], "--n-samples", 1),
    (["halt", "halt7", "--lock", "4=0"], "--vmax-deg", 1), (["halt", "halt7", "--lock", "4=0"], "--amax-deg", 1),
    (["halt", "halt7", "--lock", "4=0"], "--dq0-deg", 6), (["halt", "halt7", "--lock", "4=0"], "--generations", 1),
    (["halt", "halt7", "--lock", "4=0"], "--population", 1), (["halt-config", "halt7", "--lock", "4=0"], "--samples", 1),
    (["halt-config", "halt7", "--lock", "4=0"], "--length", 1), (["halt-config", "halt7", "--lock", "4=0"], "--halt-time", 1),
    (["jump", "canadarm7"], "--fail-at", 1), (["jump", "canadarm7"], "--sweep", 1), (["jump", "canadarm7"], "--kappa", 1),
    (["jump", "canadarm7"], "--order", 1), (["jump", "canadarm7"], "--lock-joint", 1), (["ik", "puma6"], "--pose", 6),
    (["ik", "puma6", "--pose", "0.5", "0.2", "0.3", "0", "0", "0"], "--length-scale", 1),
    (["tolerance-angle", "puma6", "--lock", "2=59.4"], "--step-deg", 1),
    (["tolerance-angle", "puma6", "--lock", "2=59.4"], "--gamma-limit-deg", 1), (["replan", "puma6", "--lock", "2=59.4"], "--steps", 1),
    (["replan", "puma6", "--lock", "2=59.4"], "--cycle", 1), (["replan", "puma6", "--lock", "2=59.4"], "--step-weight", 1),
    (["replan", "puma6", "--lock", "2=59.4"], "--jump-deg", 1), (["replan", "puma6", "--lock", "2=59.4"], "--tolerance-deg", 1),
    (["workspace", "puma6"], "--samples", 1), (["workspace", "puma6"], "--voxel", 1), (["singular", "canadarm7"], "--tol", 1),
    (["singular", "canadarm7"], "--length", 1), (["singular", "canadarm7"], "--samples", 1), (["run", "x.toml"], "--seed", 1),
    (["kinematics", "halt7"], "--lock", 1), (["campaign", "run", "c.toml"], "--workers", 1),
]  # fmt: skip


@settings(max_examples=budget(500))
@given(which=st.sampled_from(OPTIONS), values=st.lists(NUMBER_TEXT, min_size=1, max_size=7), data=st.data())
def test_every_numeric_option_parses_or_gives_one_line(capsys, which, values, data):
    """Parsing only (no run): the option's own check accepts a value or refuses it in one line."""
    prefix, option, count = which
    if option == "--lock":
        values = [f"{data.draw(NUMBER_TEXT)}={v}" for v in values]
    argv = prefix + [option, *values[:count]] if len(values) >= count else prefix + [option, *values]
    parser = build_parser()
    try:
        parser.parse_args(argv)
        event("parse: accepted")
    except SystemExit as exc:
        err = capsys.readouterr().err
        assert exc.code == 2 and err.count("\n") == 1 and "error:" in err, (argv, err)
        event("parse: refused, one line")


#: Cheap runs end to end: the option's value goes through the whole command.
RUNS = [
    (["kinematics", "halt7", "--json", "--q-deg"], 7),
    (["kinematics", "canadarm7", "--base", "floating", "--json", "--lock", "3=10", "--q-deg"], 6),
    (["ik", "puma6", "--json", "--pose"], 6),
    (["singular", "canadarm7", "--json", "--tol", "1e-8", "--q-deg"], 7),
    (["singular", "puma6", "--json", "--length"], 1),
    (["workspace", "puma6", "--samples", "1000", "--json", "--voxel"], 1),
    (["jump", "canadarm7", "--fail-at", "3", "--json", "--quiet", "--kappa"], 1),
    (["jump", "canadarm7", "--kappa", "0", "--json", "--quiet", "--fail-at"], 1),
    (["tolerance-angle", "puma6", "--lock", "2=59.4", "--q-target-deg", "5", "60", "35", "10", "-120", "90",
      "--gamma-limit-deg", "5", "--json", "--step-deg"], 1),
]  # fmt: skip
RUN_VALUES = st.one_of(NUMBER_TEXT, st.floats(-400, 400).map(repr), st.floats(-1e3, 1e3).map(lambda x: f"{x:.3g}"))


@settings(max_examples=budget(150))
@given(which=st.sampled_from(RUNS), values=st.lists(RUN_VALUES, min_size=7, max_size=7))
def test_cheap_commands_end_to_end(capsys, which, values):
    prefix, count = which
    run_cli(capsys, prefix + values[:count])


ROBOTS = {name: jl.load_robot(name) for name in jl.BUILTIN_ROBOTS}
FLOATING = {name: jl.load_robot(name, base="floating") for name in jl.BUILTIN_ROBOTS}
JOINT_DTYPES = st.sampled_from([np.float64, np.float32, np.int64, np.bool_, np.complex128, np.uint8])
JOINT_VALUES = st.floats(allow_nan=True, allow_infinity=True, width=64) | st.floats(-7, 7) | st.sampled_from([1e6, -1e6, 1e300])


@st.composite
def joint_arrays(draw, dof: int):
    shape = draw(st.sampled_from([(dof,), (2, dof), (3, 1, dof), (dof + 1,), (0, dof), (), (dof, 1)]))
    dtype = draw(JOINT_DTYPES)
    elements = JOINT_VALUES if np.dtype(dtype).kind == "f" else None
    arr = draw(hnp.arrays(np.float64, shape, elements=elements if elements is not None else st.floats(-7, 7)))
    with np.errstate(all="ignore"):
        return arr.astype(dtype) if dtype is not np.float64 else arr


@settings(max_examples=budget(300))
@given(name=st.sampled_from(sorted(ROBOTS)), floating=st.booleans(), data=st.data())
def test_joint_arrays_at_the_library_boundary(name, floating, data):
    model = (FLOATING if floating else ROBOTS)[name]
    q, dq, ddq = (data.draw(joint_arrays(model.dof)) for _ in range(3))
    which = data.draw(st.sampled_from(["ee_pose", "jacobian", "mass_matrix", "rnea", "generalized_jacobian"]))

    def call():
        if which == "rnea":
            return jl.rnea(model, q, dq, ddq)
        return getattr(jl, which)(model, q)

    check_outcome(call)


@settings(max_examples=budget(150))
@given(
    name=st.sampled_from(sorted(ROBOTS)),
    joint=st.one_of(st.integers(-2, 9), st.sampled_from([None, "2", 2.0, True, 10**40])),
    angle=st.one_of(st.floats(allow_nan=True, allow_infinity=True), st.floats(-4, 4),
                    st.sampled_from([None, "0", complex(1, 1), [0.0], True, 10**400])),
)  # fmt: skip
def test_lock_calls(name, joint, angle):
    def call():
        locked = jl.lock(ROBOTS[name], joint, angle)
        return exercise(locked, np.zeros(locked.dof))

    check_outcome(call)
