"""One name per quantity in the library's keywords (docs/conventions.md, "Names"): the
characteristic length is ``characteristic_length=`` and "which Jacobian" is ``jacobian=``
everywhere.  The former keywords (``length=``, ``base=`` of the singularity analysis and the
singular / halt_config jobs) still work as deprecated aliases: same result, one
``FutureWarning`` per process and function naming the new keyword; both at once is a
``TypeError``.  Nothing inside the package calls a former keyword."""

from __future__ import annotations

import ast
import dataclasses
import importlib
import inspect
import pickle
import pkgutil
import warnings
from pathlib import Path

import numpy as np
import pytest

import jointlock as jl
from jointlock import _deprecate
from jointlock._deprecate import renamed_keyword
from jointlock.analysis import singularity as sg
from jointlock.cli import main as cli_main
from jointlock.io.files import to_plain
from jointlock.jobs.halt_config import study_halt_configuration
from jointlock.jobs.singular import (
    conditions_at,
    search_singularities,
    singular_model,
    study_singularity,
    verify_singularity_conditions,
)

SRC = Path(jl.__file__).resolve().parent
Q7 = np.radians([10.0, 40.0, -70.0, 100.0, -60.0, 30.0, 20.0])


@pytest.fixture(autouse=True)
def fresh_warnings(monkeypatch):
    """Each test starts as a fresh process would: nothing warned yet."""
    monkeypatch.setattr(_deprecate, "_WARNED", set())


@pytest.fixture(scope="module")
def floating_arm():
    return jl.load_robot("canadarm7", base="floating")


@pytest.fixture(scope="module")
def locked_halt7():
    return jl.lock(jl.load_robot("halt7"), 4, 0.0)


def _future(record) -> list[warnings.WarningMessage]:
    return [w for w in record if issubclass(w.category, FutureWarning)]


def _call_twice(fun, *args, **kwargs):
    """``fun`` called twice with the same arguments; (first result, FutureWarnings raised)."""
    with warnings.catch_warnings(record=True) as record:
        warnings.simplefilter("always")
        first = fun(*args, **kwargs)
        fun(*args, **kwargs)
    return first, _future(record)


def _same(a, b) -> None:
    """Two results hold the same numbers (job results by their JSON; dataclasses, mappings,
    sequences and arrays entry by entry)."""
    if isinstance(a, jl.ArmModel):
        assert (a.name, a.joint_numbers, a.floating) == (b.name, b.joint_numbers, b.floating)
    elif hasattr(a, "to_dict"):
        assert to_plain(a.to_dict()) == to_plain(b.to_dict())
    elif dataclasses.is_dataclass(a):
        assert type(a) is type(b)
        for f in dataclasses.fields(a):
            _same(getattr(a, f.name), getattr(b, f.name))
    elif isinstance(a, dict):
        assert a.keys() == b.keys()
        for k in a:
            _same(a[k], b[k])
    elif isinstance(a, (tuple, list)):
        assert len(a) == len(b)
        for x, y in zip(a, b):
            _same(x, y)
    else:
        np.testing.assert_array_equal(a, b)


# -- every renamed keyword: (function, args, kwargs, old, new, value) ------------------------------


def _cases(arm, locked):
    q = np.radians([[10.0, 40.0, -70.0, 100.0, -60.0, 30.0, 20.0], [0, 90, 0, 0, 0, 90, 0]])
    found = np.radians([[0.0, 0.0, 30.0, 60.0, -20.0, 40.0, 10.0]])
    lengths = sg.arm_lengths(arm)
    return [
        (sg.task_jacobian, (arm, q), {}, "length", "characteristic_length", 2.0),
        (sg.task_jacobian, (arm, q), {}, "base", "jacobian", "virtual"),
        (sg.analyse_singularity, (arm, q), {}, "length", "characteristic_length", 2.0),
        (sg.analyse_singularity, (arm, q), {}, "base", "jacobian", "floating"),
        (sg.singularity_of_jacobian, (sg.task_jacobian(arm, q),), {}, "length", "characteristic_length", 2.0),
        (sg.singularity_of_jacobian, (sg.task_jacobian(arm, q),), {}, "base", "jacobian", "fixed"),
        (
            sg.find_singularities,
            (arm,),
            {"samples": 4, "max_iter": 3},
            "length",
            "characteristic_length",
            2.0,
        ),
        (sg.find_singularities, (arm,), {"samples": 4, "max_iter": 3}, "base", "jacobian", "virtual"),
        (sg.cluster_singularities, (arm, found), {}, "length", "characteristic_length", 2.0),
        (sg.cluster_singularities, (arm, found), {}, "base", "jacobian", "generalized"),
        (sg.arm_lengths, (arm,), {}, "base", "jacobian", "fixed"),
        (sg.reference_jacobian, (arm, q), {}, "base", "jacobian", "fixed"),
        (sg.verify_conditions, (arm,), {"samples": 4, "search_samples": 4}, "base", "jacobian", "fixed"),
        (study_singularity, (arm, Q7), {}, "length", "characteristic_length", 2.0),
        (study_singularity, (arm, Q7), {}, "base", "jacobian", "virtual"),
        (search_singularities, (arm,), {"samples": 4, "max_iter": 3}, "length", "characteristic_length", 2.0),
        (search_singularities, (arm,), {"samples": 4, "max_iter": 3}, "base", "jacobian", "floating"),
        (
            verify_singularity_conditions,
            (arm,),
            {"samples": 4, "search_samples": 4},
            "base",
            "jacobian",
            "fixed",
        ),
        (conditions_at, (arm, Q7, lengths), {}, "base", "jacobian", "virtual"),
        (singular_model, ("canadarm7",), {}, "base", "jacobian", "virtual"),
        (
            study_halt_configuration,
            (locked,),
            {"samples": 50, "rng": 0, "refine": False},
            "length",
            "characteristic_length",
            2.0,
        ),
    ]


CASE_IDS = [
    "task_jacobian-length",
    "task_jacobian-base",
    "analyse_singularity-length",
    "analyse_singularity-base",
    "singularity_of_jacobian-length",
    "singularity_of_jacobian-base",
    "find_singularities-length",
    "find_singularities-base",
    "cluster_singularities-length",
    "cluster_singularities-base",
    "arm_lengths-base",
    "reference_jacobian-base",
    "verify_conditions-base",
    "study_singularity-length",
    "study_singularity-base",
    "search_singularities-length",
    "search_singularities-base",
    "verify_singularity_conditions-base",
    "conditions_at-base",
    "singular_model-base",
    "study_halt_configuration-length",
]


@pytest.mark.parametrize("index", range(len(CASE_IDS)), ids=CASE_IDS)
def test_old_keyword_works_warns_once_and_gives_the_same_result(index, floating_arm, locked_halt7):
    fun, args, kwargs, old, new, value = _cases(floating_arm, locked_halt7)[index]
    assert fun.__renamed_keywords__[old] == new
    with warnings.catch_warnings():
        warnings.simplefilter("error", FutureWarning)  # the new keyword never warns
        expected = fun(*args, **kwargs, **{new: value})
    got, future = _call_twice(fun, *args, **kwargs, **{old: value})
    _same(got, expected)
    assert len(future) == 1, [str(w.message) for w in future]
    message = str(future[0].message)
    assert f"{old}=" in message and f"use {new}=" in message and fun.__name__ in message
    assert future[0].filename == __file__  # attributed to the caller, not to jointlock
    with pytest.raises(TypeError, match=f"got both {old}= and {new}="):
        fun(*args, **kwargs, **{old: value, new: value})


def test_warns_once_per_function_and_former_name(floating_arm):
    q = Q7
    with warnings.catch_warnings(record=True) as record:
        warnings.simplefilter("always")
        for _ in range(3):
            sg.task_jacobian(floating_arm, q, length=2.0)
            sg.task_jacobian(floating_arm, q, base="fixed")
            sg.analyse_singularity(floating_arm, q, length=2.0)
            study_singularity(floating_arm, q, length=2.0, base="fixed")
    heads = sorted(str(w.message).split(" is deprecated")[0] for w in _future(record))
    assert heads == [
        "analyse_singularity(): the keyword length=",
        "study_singularity(): the keyword base=",
        "study_singularity(): the keyword length=",
        "task_jacobian(): the keyword base=",
        "task_jacobian(): the keyword length=",
    ]


def test_the_renamed_signatures_show_the_new_names():
    for fun in (sg.task_jacobian, sg.analyse_singularity, sg.find_singularities, study_singularity):
        params = inspect.signature(fun).parameters
        assert "jacobian" in params and "characteristic_length" in params
        assert "base" not in params and "length" not in params
    assert "characteristic_length" in inspect.signature(study_halt_configuration).parameters


def test_floating_is_the_generalized_jacobian(floating_arm):
    q = np.radians([[10.0, 40.0, -70.0, 100.0, -60.0, 30.0, 20.0], [5, -30, 60, 20, 10, -45, 0]])
    np.testing.assert_array_equal(
        sg.task_jacobian(floating_arm, q, jacobian="generalized"),
        sg.task_jacobian(floating_arm, q, jacobian="floating"),
    )
    np.testing.assert_allclose(
        sg.task_jacobian(floating_arm, q, jacobian="generalized"), jl.generalized_jacobian(floating_arm, q)
    )
    assert sg.jacobian_kind("floating") == "generalized"
    assert [sg.jacobian_kind(k) for k in sg.JACOBIAN_KINDS] == list(sg.JACOBIAN_KINDS)
    gen = study_singularity(floating_arm, Q7, jacobian="generalized")
    flo = study_singularity(floating_arm, Q7, jacobian="floating")
    assert gen.base == "generalized" and flo.base == "floating"  # recorded as given
    np.testing.assert_array_equal(gen.analysis.singular_values, flo.analysis.singular_values)
    assert gen.conditions is None and flo.conditions is None  # 004's conditions: fixed or virtual only
    assert sg.BASE_KINDS == ("fixed", "floating", "virtual")  # the CLI's --base choices, unchanged


def test_errors_name_the_keyword_the_caller_used(floating_arm, locked_halt7):
    with pytest.raises(jl.ScenarioError, match=r"^jacobian must be one of .*got 'moving'$"):
        sg.analyse_singularity(floating_arm, Q7, jacobian="moving")  # type: ignore[arg-type]
    with pytest.warns(FutureWarning, match="use jacobian="):
        with pytest.raises(
            jl.ScenarioError, match=r"^base must be one of .*got 'moving' \(base= is now jacobian=\)$"
        ):
            sg.analyse_singularity(floating_arm, Q7, base="moving")
    with pytest.raises(jl.ModelError, match=r"^jacobian='virtual' needs a free-floating model"):
        sg.task_jacobian(jl.load_robot("puma6"), np.zeros(6), jacobian="virtual")
    with pytest.raises(jl.ScenarioError, match=r"^characteristic_length must be a positive"):
        sg.task_jacobian(floating_arm, Q7, characteristic_length=-1.0)
    with pytest.warns(FutureWarning, match="use characteristic_length="):
        with pytest.raises(
            jl.ScenarioError, match=r"^length must be a positive.*\(length= is now characteristic_length=\)$"
        ):
            sg.task_jacobian(floating_arm, Q7, length=-1.0)
    with pytest.raises(jl.ConfigurationError, match=r"^characteristic_length must be a finite length > 0"):
        study_halt_configuration(locked_halt7, samples=10, characteristic_length=0.0)
    with pytest.raises(jl.ScenarioError, match="^jacobian must be 'virtual'"):
        verify_singularity_conditions(floating_arm, jacobian="floating")  # type: ignore[arg-type]
    with pytest.raises(jl.ScenarioError, match="^jacobian must be one of"):
        search_singularities(floating_arm, samples=2, jacobian="moving")  # type: ignore[arg-type]


def test_the_decorator_checks_what_it_wraps():
    def f(*, new_name: int = 0) -> int:
        return new_name

    with pytest.raises(TypeError, match="does not fit"):
        renamed_keyword(old="old_name", new="missing")(f)

    def g(*, old_name: int = 0, new_name: int = 0) -> int:
        return new_name

    with pytest.raises(TypeError, match="does not fit"):
        renamed_keyword(old="old_name", new="new_name")(g)
    h = renamed_keyword(old="old_name", new="new_name")(f)
    assert h.__wrapped__ is f and h.__name__ == "f"
    with pytest.warns(FutureWarning, match=r"f\(\): the keyword old_name= is deprecated: use new_name="):
        assert h(old_name=3) == 3
    assert h(new_name=4) == 4 and h() == 0
    with pytest.raises(TypeError, match="got both old_name= and new_name="):
        h(old_name=1, new_name=2)


def test_results_stay_picklable_and_keep_their_field_names(floating_arm):
    res = sg.analyse_singularity(floating_arm, Q7, jacobian="virtual", characteristic_length=2.0)
    assert res.base == "virtual" and res.length == 2.0  # fields keep their names
    again = pickle.loads(pickle.dumps(study_singularity(floating_arm, Q7, jacobian="virtual")))
    assert again.to_dict()["base"] == "virtual"
    assert pickle.loads(pickle.dumps(sg.task_jacobian)) is sg.task_jacobian  # the wrapper pickles by name


# -- nothing in the package uses a former keyword ---------------------------------------------------


def _renamed_functions() -> dict[str, dict[str, str]]:
    """``{function name: {former keyword: new keyword}}`` over every module of the package."""
    found: dict[str, dict[str, str]] = {}
    for info in pkgutil.walk_packages(jl.__path__, "jointlock."):
        if info.name.endswith(".__main__"):  # runs the command line
            continue
        module = importlib.import_module(info.name)
        for name, obj in vars(module).items():
            renamed = getattr(obj, "__renamed_keywords__", None)
            if callable(obj) and isinstance(renamed, dict):
                found.setdefault(name, {}).update(renamed)
    return found


def test_no_call_inside_the_package_uses_a_former_keyword():
    renamed = _renamed_functions()
    assert {"task_jacobian", "study_singularity", "study_halt_configuration", "singular_model"} <= set(
        renamed
    )
    offenders = []
    for path in sorted(SRC.rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if not isinstance(node, ast.Call):
                continue
            func = node.func
            name = (
                func.id
                if isinstance(func, ast.Name)
                else func.attr
                if isinstance(func, ast.Attribute)
                else ""
            )
            for kw in node.keywords:
                if kw.arg in renamed.get(name, {}):
                    offenders.append(f"{path.relative_to(SRC)}:{node.lineno}: {name}({kw.arg}=...)")
    assert not offenders, offenders


@pytest.mark.parametrize(
    "argv",
    [
        ["singular", "canadarm7", "--q-deg", "10", "40", "-70", "100", "-60", "30", "20", "--length", "2"],
        ["singular", "canadarm7", "--base", "floating", "--length", "2"],
        [
            "singular",
            "canadarm7",
            "--search",
            "--samples",
            "4",
            "--length",
            "2",
            "--base",
            "virtual",
            "--quiet",
        ],
        ["singular", "canadarm7", "--verify-conditions", "--samples", "4", "--quiet"],
        [
            "halt-config",
            "halt7",
            "--lock",
            "4=0",
            "--samples",
            "50",
            "--seed",
            "0",
            "--length",
            "2",
            "--no-refine",
        ],
    ],
    ids=["singular", "singular-floating", "search", "verify", "halt-config"],
)
def test_the_commands_trigger_no_deprecation(argv, capsys):
    with warnings.catch_warnings():
        warnings.simplefilter("error", FutureWarning)
        assert cli_main([*argv, "--json"]) == 0
    assert capsys.readouterr().out.startswith("{")
