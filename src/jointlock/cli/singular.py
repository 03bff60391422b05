"""``jointlock singular``: singularity analysis at one configuration, verification of seed
004's conditions Cond1-Cond5, and a search for the singular configurations of any arm.

Parses the options and calls :mod:`jointlock.jobs.singular` (:func:`study_singularity`,
:func:`verify_singularity_conditions`, :func:`search_singularities`); prints the result's
summary or JSON and writes its files."""

from __future__ import annotations

import argparse
import sys
import warnings
from pathlib import Path
from typing import TYPE_CHECKING

from ..errors import ScenarioError
from ._common import (
    add_clearance_options,
    add_robot_arguments,
    chain_from_args,
    check_out_dir,
    clearance_from_args,
    deg_arg,
    field_arg,
    lock_map,
    print_json,
    seed_arg,
)
from ._constants import RANK_TOL, SINGULAR_BASE_KINDS

if TYPE_CHECKING:
    from ..analysis.singularity import BaseKind
    from ..jobs.singular import SingularJobResult
    from ..model import ArmModel


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "singular",
        help="singular values, rank, lost directions; 004's Cond1-Cond5; singularity search",
        description=(
            "Singularity analysis. Jacobian: twist (v [m/s], omega [rad/s]) of the end-effector origin, "
            "base-frame components; --base fixed (geometric), floating (generalized, zero momentum) or "
            "virtual (004's virtual manipulator). For a Canadarm2-structure arm (canadarm7) the conditions "
            "Cond1-Cond5 of seed 004 are evaluated too."
        ),
    )
    add_robot_arguments(
        p,
        base_choices=SINGULAR_BASE_KINDS,
        base_default=None,
        base_help="fixed, floating (generalized Jacobian) or virtual (virtual manipulator); "
        "default: virtual with --verify-conditions, fixed otherwise",
    )
    p.add_argument(
        "--weighting",
        choices=("segment", "vafa-dubowsky"),
        default="segment",
        help="virtual link lengths: 004's formula (segment, default) or the exact Vafa-Dubowsky one",
    )
    p.add_argument(
        "--q-deg", type=deg_arg, nargs="+", metavar="DEG", help="joint angles [deg] (default: zeros)"
    )
    p.add_argument(
        "--tol",
        type=field_arg("singular", "tol"),
        default=RANK_TOL,
        help=f"rank tolerance on singular values (default {RANK_TOL:g})",
    )
    p.add_argument(
        "--length",
        type=field_arg("singular", "length"),
        default=None,
        metavar="L",
        help="characteristic length [m] dividing the linear rows",
    )
    mode = p.add_mutually_exclusive_group()
    mode.add_argument(
        "--verify-conditions", action="store_true", help="check 004's Cond1-Cond5 by sampling and search"
    )
    mode.add_argument(
        "--search", action="store_true", help="search for singular configurations and cluster them"
    )
    p.add_argument(
        "--samples",
        type=field_arg("singular", "samples"),
        default=None,
        help="samples per condition (2000) or search starts (512)",
    )
    p.add_argument("--seed", type=seed_arg, default=0, help="random seed, integer >= 0 (default 0)")
    p.add_argument(
        "--out", type=Path, default=None, metavar="DIR", help="--search: write search.json and plots here"
    )
    p.add_argument(
        "--skip-colliding",
        action="store_true",
        help="--search: leave out the singular configurations closer than --clearance-min-m (default 0.05) to the "
        "arm itself, the spacecraft bus or --keep-out volumes, before clustering (--no-clearance: count them only)",
    )
    add_clearance_options(p)
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.set_defaults(func=run)


def _model(args: argparse.Namespace, base: str) -> ArmModel:
    from ..jobs.singular import singular_model
    from ..locking import lock_joints

    model = singular_model(args.robot, None, base, chain=chain_from_args(args))
    locks = lock_map(args.lock)
    return lock_joints(model, locks) if locks else model


def _progress(args: argparse.Namespace) -> bool:
    return not args.quiet and sys.stderr.isatty()


def run(args: argparse.Namespace) -> int:
    from ..jobs._common import joint_vector_deg
    from ..jobs.singular import (
        SEARCH_SAMPLES,
        VERIFY_SAMPLES,
        SingularitySearchResult,
        search_singularities,
        study_singularity,
        verify_singularity_conditions,
    )

    check_out_dir(args.out)
    given = [o for o, v in (("--clearance-min-m", args.clearance_min_m), ("--no-clearance", args.no_clearance),
                            ("--keep-out", args.keep_out)) if v]  # fmt: skip
    if given and not (args.search and args.skip_colliding):
        raise ScenarioError(f"{', '.join(given)}: with --search --skip-colliding only (the search's clearance)")
    if args.skip_colliding and not args.search:
        raise ScenarioError("--skip-colliding: with --search only (it screens the singular configurations found)")
    if args.out is not None and not args.search:
        warnings.warn("--out: nothing written (only --search writes files: search.json and plots)", UserWarning, stacklevel=1)
    if args.verify_conditions:
        base: BaseKind = args.base or "virtual"
        if base == "floating":
            raise ScenarioError(
                "--verify-conditions needs --base virtual (004's case) or fixed; got floating"
            )
        result: SingularJobResult = verify_singularity_conditions(
            _model(args, base),
            samples=args.samples or VERIFY_SAMPLES,
            rng=args.seed,
            jacobian=base,
            weighting=args.weighting,
            tol=args.tol,
            progress=_progress(args),
        )
    elif args.search:
        base = args.base or "fixed"
        clearance = clearance_from_args(args) if args.skip_colliding else None
        result = search_singularities(
            _model(args, base),
            samples=args.samples or SEARCH_SAMPLES,
            rng=args.seed,
            jacobian=base,
            weighting=args.weighting,
            characteristic_length=args.length,
            clearance=clearance,
            progress=_progress(args),
        )
    else:
        base = args.base or "fixed"
        model = _model(args, base)
        q = joint_vector_deg(model, args.q_deg, "--q-deg")
        result = study_singularity(
            model, q, jacobian=base, weighting=args.weighting, tol=args.tol, characteristic_length=args.length
        )
    files: list[Path] = []
    if args.out is not None and isinstance(result, SingularitySearchResult):  # --out is for --search
        files = [args.out / name for name in result.write(args.out)]
    if args.json:
        if isinstance(result, SingularitySearchResult):
            print_json(result.to_dict(files=files if args.out is not None else None))
        else:
            print_json(result.to_dict())
        return 0
    for line in result.summary():
        print(line)
    for f in files:
        print(f"wrote {f}")
    return 0
