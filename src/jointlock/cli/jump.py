"""``jointlock jump``: keep following the path through an unexpected lock (seed 001).

At one failure time (``--fail-at S``): the velocity jump with and without compensation, the
optimal kappa and its feasible interval, the limits kept.  Over sampled failure times
(``--sweep N``, the default with N = 40): optimal kappa per time, the fitted piecewise
kappa(t), and its verification with the failure injected at every control step.  The optimal
kappa is searched by default (``--optimize`` says so explicitly); ``--kappa K`` uses a
constant instead.  Options that the chosen mode does not use (``--order``, ``--single``,
``--fix`` with ``--fail-at`` or ``--kappa``; ``--sweep`` with ``--kappa``) are reported on
stderr as ignored.
"""

from __future__ import annotations

import argparse
import sys
import warnings
from typing import TYPE_CHECKING, Any

from .._lazy import lazy_attributes
from ..errors import ScenarioError
from ..papers import p001
from ._common import add_robot_arguments, chain_from_args, check_out_dir, field_arg, number_arg, print_json
from ._constants import DEFAULT_ORDER, DEFAULT_SWEEP, KAPPA_UNIT, MAX_ORDER

if TYPE_CHECKING:
    from ..planning.jump import JumpScenario

# The library is imported once the options are parsed (not to print --help); the text helpers,
# formerly imported here, are re-exported on first use.
__getattr__, __dir__ = lazy_attributes(
    __name__,
    {"_interval_text": "jointlock.jobs.jump", "_less": "jointlock.jobs.jump", "_points_text": "jointlock.jobs.jump"},
    namespace=globals(),
)


def load_scenario(path: str) -> JumpScenario:
    """:func:`jointlock.planning.jump.load_jump_task` (this module's former name for it)."""
    from ..planning.jump import load_jump_task

    return load_jump_task(path)

#: A start of the example task shown when a robot needs its own q0_deg (NOTES-001's start,
#: cut or padded with zeros to the robot's joints).
_EXAMPLE_Q0 = p001.TASK["q0_deg"]


def _lock_joint(text: str) -> int:
    """``--lock J``: a joint number; ``J=DEG`` is refused (the joint locks where it is)."""
    if "=" in text:
        raise argparse.ArgumentTypeError(
            f"{text!r}: the jump study locks the joint at the angle it has when it fails; give the joint "
            "number only (e.g. --lock 2)"
        )
    return _JOINT_NUMBER(text)


_JOINT_NUMBER = number_arg(1, 10_000, integer=True)


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "jump",
        help="velocity jump at an unexpected lock: optimal kappa, fitted kappa(t), verification (001)",
        description=(
            "Resolved-rate path following with the null-space compensation kappa (I - J+J) grad w "
            "(seed 001, NOTES-001). Default: NOTES-001's scenario, joint 2 locking, --sweep 40. "
            "Jumps are 2-norms of joint-rate changes, printed and plotted in deg/s (rad/s in the JSON "
            f"output, as its key names say); kappa is in {KAPPA_UNIT}. The task (start q0_deg, line "
            "dx_m, ...) is NOTES-001's for canadarm7; any other robot needs a task file: --scenario "
            "FILE with q0_deg (one angle per joint) -- a flat TOML table, the fields of a run "
            "scenario's [jump] table (docs/jump.md)."
        ),
    )
    add_robot_arguments(
        p,
        lock=False,
        base_default=None,
        base_help="fixed base, or free-floating spacecraft (generalized Jacobian); "
        "default: the scenario file's base, else fixed",
    )
    p.add_argument(
        "--scenario",
        metavar="FILE",
        help="task file, a flat TOML table: q0_deg (one angle per joint [deg]), dx_m, duration_s, ... "
        "(needed for any robot but canadarm7; a `jointlock run` scenario file is run with `jointlock run`)",
    )
    p.add_argument(
        "--lock",
        "--lock-joint",
        dest="lock_joint",
        type=_lock_joint,
        metavar="J",
        help="joint that locks (from 1; default 2), at the angle it has when it fails: no =DEG here "
        "(--lock-joint is the former spelling)",
    )
    when = p.add_mutually_exclusive_group()
    when.add_argument(
        "--fail-at", type=field_arg("jump", "fail_at"), metavar="S", help="one failure time [s]"
    )
    when.add_argument(
        "--sweep", type=field_arg("jump", "sweep"), metavar="N", help="N sampled failure times (default 40)"
    )
    how = p.add_mutually_exclusive_group()
    how.add_argument(
        "--kappa",
        type=field_arg("jump", "kappa"),
        metavar="K",
        help=f"use this constant kappa [{KAPPA_UNIT}] (no search)",
    )
    how.add_argument(
        "--optimize",
        action="store_true",
        help="search the optimal kappa: the default mode, this flag only makes it explicit",
    )
    p.add_argument(
        "--order",
        type=field_arg("jump", "order"),
        default=None,
        help=f"polynomial order of kappa(t), 1..{MAX_ORDER} (default 5; sweep with the search only)",
    )
    p.add_argument(
        "--single",
        action="store_true",
        help="one polynomial for kappa(t) (001's form) instead of a piece per branch of the optimum",
    )
    p.add_argument(
        "--fix",
        choices=("auto", "clip", "ramp", "clip+ramp", "none"),
        default=None,
        help="fix of kappa(t) verified as well (default auto: clip+ramp only when a limit breaks; "
        "sweep with the search only)",
    )
    p.add_argument(
        "--on-infeasible",
        choices=("raise", "report"),
        default="raise",
        help="--fail-at without a kappa that keeps the limits: an error (raise, default), or the "
        "uncompensated jump with the reason (report: what an audit's cell records)",
    )
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.add_argument("--out", metavar="DIR", help="write results.json, CSV and figures (PNG) here")
    p.add_argument("--quiet", action="store_true", help="no progress bars")
    p.set_defaults(func=run)


#: What ``--scenario FILE`` prints once (issue 28: 001's task is a kind of ``[task]`` now).
TASK_FILE_NOTE = (
    "note: this task can also be the [task] table of a `jointlock run` scenario (its q0_deg, dx_m, duration_s, ...), "
    "which the halt, the audit and the jump study all follow (docs/audit.md)"
)


def _scenario(args: argparse.Namespace) -> JumpScenario:
    from ..planning.jump import JumpScenario, scenario_from_mapping

    sc = load_scenario(args.scenario) if args.scenario else JumpScenario()
    fields = sc.to_fields()
    if args.lock_joint is not None:
        fields["lock_joint"] = args.lock_joint
    if args.base is not None:  # the file's base (else the default, fixed) unless --base is given
        fields["base"] = args.base
    return scenario_from_mapping(fields, source="command line")


def _check_q0(args: argparse.Namespace, sc: JumpScenario, model: Any) -> None:
    """A start that does not fit the robot: say where it came from and what to give."""
    if len(sc.q0) == model.dof:
        return
    n = model.dof
    example_q0 = ", ".join(f"{v:g}" for v in (list(_EXAMPLE_Q0) + [0.0] * n)[:n])
    example = (
        f"e.g. a file task.toml with the lines `q0_deg = [{example_q0}]` and `dx_m = [0.2, -0.2, 0.1]`, "
        f"then `jointlock jump {args.robot} --scenario task.toml`"
    )
    joints = f"model {model.name!r} has {n} movable joints {list(model.joint_numbers)}"
    if args.scenario is None:
        raise ScenarioError(
            f"the default task is NOTES-001's for canadarm7 (q0_deg: 7 angles); {joints}: a robot other "
            f"than canadarm7 needs --scenario FILE with q0_deg ({n} values [deg]); {example}"
        )
    given = "q0_deg" in _file_fields(args.scenario)
    if not given:
        raise ScenarioError(
            f"{args.scenario} gives no q0_deg, and the default start is canadarm7's 7 angles; {joints}: "
            f"add q0_deg ({n} values [deg]); {example}"
        )
    raise ScenarioError(
        f"{args.scenario}: q0_deg has {len(sc.q0)} angles but {joints}; give {n} values [deg]"
    )


def _file_fields(path: str) -> set[str]:
    from ..io.files import read_toml_file

    try:
        return set(read_toml_file(path, "scenario file", ScenarioError))
    except ScenarioError:  # read before, by load_jump_task
        return set()


def _warn_ignored(args: argparse.Namespace) -> None:
    """Say on stderr which given options the chosen mode does not use."""
    if args.fail_at is not None or args.kappa is not None:
        mode = "--fail-at" if args.fail_at is not None else "--kappa"
        ignored = [
            opt
            for opt, given in (
                ("--order", args.order is not None),
                ("--single", args.single),
                ("--fix", args.fix is not None),
                ("--sweep", mode == "--kappa" and args.sweep is not None),
            )
            if given
        ]
        if ignored:
            what = (
                "one failure time, no kappa(t) fit"
                if mode == "--fail-at"
                else "a constant kappa verified at every step, no sampling or fit"
            )
            warnings.warn(f"{', '.join(ignored)} ignored with {mode} ({what})", UserWarning, stacklevel=2)
    if args.on_infeasible == "report" and (args.fail_at is None or args.kappa is not None):
        warnings.warn(
            "--on-infeasible report is used with --fail-at and the kappa search only (a sweep reports its failure "
            "times without a feasible kappa; a given kappa is verified as it is)",
            UserWarning,
            stacklevel=2,
        )


def run(args: argparse.Namespace) -> int:
    from ..jobs.jump import run_jump_study
    from ..robots import load_robot

    out_dir = check_out_dir(args.out)
    sc = _scenario(args)
    if args.scenario and not (args.quiet or args.json):
        print(TASK_FILE_NOTE, file=sys.stderr)
    model = load_robot(args.robot, base=sc.base, chain=chain_from_args(args))
    _check_q0(args, sc, model)
    _warn_ignored(args)
    result = run_jump_study(
        model,
        sc,
        fail_at=args.fail_at,
        sweep=DEFAULT_SWEEP if args.sweep is None else args.sweep,
        kappa=args.kappa,
        order=DEFAULT_ORDER if args.order is None else args.order,
        fix={None: "auto", "none": None}.get(args.fix, args.fix),
        single=args.single,
        progress=not args.quiet,
        on_infeasible=args.on_infeasible,
    )
    if out_dir is not None:
        result.write(out_dir)
    if args.json:
        print_json(result.to_dict())
        return 0
    for line in result.summary():
        print(line)
    if out_dir is not None:
        print(f"\nwrote {out_dir}/results.json and figures")
    return 0
