"""Fuzz: >= 1,000 generated malformed scenarios, each must give one clean ScenarioError --
naming the file, one line, no traceback, no NaN -- and the CLI must exit 2 with one line.
Validation only (no job runs), so it is fast."""

from __future__ import annotations

import contextlib
import copy
import io
import random
import tomllib
from pathlib import Path

import pytest

from jointlock.cli import main
from jointlock.errors import ScenarioError
from jointlock.scenario import ALL_TABLES, TOP_FIELDS, load_scenario

EXAMPLES = sorted((Path(__file__).resolve().parents[1] / "examples").glob("*.toml"))
N_CASES = 1200
#: Of those, how many also go through ``jointlock run`` in-process (exit code, stderr).
N_CLI = 60

BAD_VALUES = [
    "text",
    -1,
    0,
    -1e9,
    1e12,
    float("nan"),
    float("inf"),
    float("-inf"),
    True,
    [],
    [1, "x"],
    [float("nan")],
    {"a": 1},
    [[1, 2]],
    "",
]


def toml_value(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(v, float):
        return {"nan": "nan", "inf": "inf", "-inf": "-inf"}.get(repr(v), repr(v))
    if isinstance(v, int):
        return str(v)
    if isinstance(v, list):
        return "[" + ", ".join(toml_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{" + ", ".join(f"{k} = {toml_value(x)}" for k, x in v.items()) + "}"
    raise TypeError(v)


def dump(data: dict) -> str:
    top = [f"{k} = {toml_value(v)}" for k, v in data.items() if not isinstance(v, dict)]
    tables = [
        f"[{k}]\n" + "\n".join(f"{kk} = {toml_value(vv)}" for kk, vv in v.items())
        for k, v in data.items()
        if isinstance(v, dict)
    ]
    return "\n".join(top) + "\n\n" + "\n\n".join(tables) + "\n"


def typo(word: str, rnd: random.Random) -> str:
    i = rnd.randrange(len(word))
    op = rnd.randrange(3)
    if op == 0:
        return word[:i] + word[i + 1 :] or "x"
    if op == 1:
        return word[:i] + rnd.choice("abcdefgxyz_") + word[i:]
    return word + "_extra"


def is_bad_for(value, spec) -> bool:
    """True when ``value`` is certainly invalid for the field (so the case must fail)."""
    try:
        from jointlock.scenario import _check

        _check(value, spec, "f")
    except ScenarioError:
        return True
    return False


def mutate(base: dict, rnd: random.Random, tmp: Path) -> tuple[dict | str, str]:
    """One malformed scenario (a dict to dump, or raw text) and the kind of fault."""
    data = copy.deepcopy(base)
    kind = rnd.choice(
        [
            "unknown_top",
            "unknown_field",
            "bad_value",
            "bad_top",
            "robot",
            "syntax",
            "table_type",
            "model_file",
            "missing_robot",
            "lock",
        ]
    )
    tables = [k for k, v in data.items() if isinstance(v, dict)]
    if kind == "unknown_top":
        key = typo(rnd.choice(list(TOP_FIELDS) + list(ALL_TABLES)), rnd)
        if key in TOP_FIELDS or key in ALL_TABLES:
            key += "_zz"
        data[key] = 1
    elif kind == "unknown_field" and tables:
        t = rnd.choice(tables)
        if t not in ALL_TABLES:
            data["zz_" + t] = 1
        else:
            key = typo(rnd.choice(list(ALL_TABLES[t])), rnd)
            if key in ALL_TABLES[t]:
                key += "_zz"
            data[t][key] = 3
    elif kind in ("bad_value", "unknown_field") and tables:
        t = rnd.choice([t for t in tables if t in ALL_TABLES])
        field = rnd.choice(list(ALL_TABLES[t]))
        spec = ALL_TABLES[t][field]
        choices = [v for v in BAD_VALUES if is_bad_for(v, spec)]
        data[t][field] = rnd.choice(choices)
    elif kind == "bad_top":
        field = rnd.choice(["base", "seed", "robot", "title", "jobs"])
        choices = [v for v in BAD_VALUES + ["flying", ["nojob"]] if is_bad_for(v, TOP_FIELDS[field])]
        data[field] = rnd.choice(choices)
    elif kind == "robot":
        data["robot"] = rnd.choice(
            ["halt8", "puma", "arm.dae", "missing.urdf", "missing.toml", "../x.toml", "Canadarm7"]
        )
    elif kind == "syntax":
        lines = dump(data).splitlines(keepends=True)
        at = rnd.randrange(len(lines) + 1)
        junk = rnd.choice(["[\n", "= =\n", '"open\n', "[[\n", "x = [1,\nx = 2\n", "key value\n", "[a]]\n"])
        return "".join(lines[:at]) + junk + "".join(lines[at:]), kind
    elif kind == "table_type" and tables:
        data[rnd.choice(tables)] = rnd.choice([1, "x", [1, 2], True])
    elif kind == "model_file":
        suffix = rnd.choice([".urdf", ".toml"])
        name = f"m{rnd.randrange(10**6)}{suffix}"
        junk = rnd.choice(
            [
                "",
                "<robot>",
                "<robot name='r'><joint/></robot>",
                "[[joint]]\nx = 1\n",
                "name = 1\n",
                "<<<",
                "convention = 'dh_modified'\n",
            ]
        )
        (tmp / name).write_text(junk)
        data["robot"] = name
    elif kind == "missing_robot":
        data.pop("robot", None)
    else:  # an impossible failure
        data.setdefault("failure", {})
        if isinstance(data["failure"], dict):
            data["failure"]["joint"] = rnd.choice([0, 8, 99, -3])
            data["failure"].setdefault("angle_deg", 0.0)
        else:  # pragma: no cover
            data["failure"] = {"joint": 0}
    return data, kind


def cases(tmp_path: Path):
    rnd = random.Random(20260101)
    bases = [tomllib.loads(p.read_text()) for p in EXAMPLES]
    assert bases
    for i in range(N_CASES):
        data, kind = mutate(rnd.choice(bases), rnd, tmp_path)
        text = data if isinstance(data, str) else dump(data)
        path = tmp_path / f"case{i:04d}.toml"
        path.write_text(text, encoding="utf-8", errors="surrogateescape")
        yield path, kind


def test_malformed_scenarios_give_one_clean_error(tmp_path):
    kinds: dict[str, int] = {}
    for n, (path, kind) in enumerate(cases(tmp_path)):
        with pytest.raises(ScenarioError) as err:
            load_scenario(path)
        msg = str(err.value)
        kinds[kind] = kinds.get(kind, 0) + 1
        assert msg and "\n" not in msg, (path.read_text(), msg)  # one line
        assert "Traceback" not in msg
        assert str(path) in msg or "does not exist" in msg, (kind, msg)
        if "nan" not in path.read_text().lower():
            assert "nan" not in msg.lower(), msg  # no NaN made up by the validator
        if n < N_CLI:
            out, errbuf = io.StringIO(), io.StringIO()
            with contextlib.redirect_stdout(out), contextlib.redirect_stderr(errbuf):
                code = main(["run", str(path), "--out", str(tmp_path / "never")])
            assert code == 2 and out.getvalue() == ""
            assert (
                errbuf.getvalue().startswith("jointlock run: error: ")
                and "Traceback" not in errbuf.getvalue()
            )
            assert not (tmp_path / "never").exists()  # nothing written for a bad scenario
    assert sum(kinds.values()) >= 1000
    assert len(kinds) >= 8, kinds
