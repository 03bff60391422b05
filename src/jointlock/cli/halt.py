"""``jointlock halt``: the halt strategy of seed 000 -- optimal halt configuration (unless
``--qf-deg``/``--paper-qf``), then the optimal halt motion (§4), with plots and time series.

A thin shell over :func:`jointlock.jobs.halt.plan_halt`: parse, call, print, write.  With no
options beyond the robot, ``halt7`` runs 000 §5's scenario (:mod:`jointlock.papers.p000`).
Limits follow :func:`jointlock.jobs.halt.halt_limits`; the output says where each came from.
"""

from __future__ import annotations

import argparse
import math
import sys
import warnings
from pathlib import Path
from typing import TYPE_CHECKING, Any

from .._lazy import lazy_attributes
from ..errors import ScenarioError
from ..papers import p000
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
from ._constants import MIN_N_SAMPLES

if TYPE_CHECKING:
    from ..jobs.halt import HaltPlan

# The library is imported once the options are parsed (not to print --help); these names,
# formerly imported here, are re-exported on first use.
__getattr__, __dir__ = lazy_attributes(
    __name__,
    {
        **{name: "jointlock.jobs.halt" for name in (
            "CLI_NAMES", "FailureState", "HaltPlan", "check_halt_settings", "halt_model", "is_000_failure",
            "limits_text", "plan_halt", "resolve_limits")},
        "GASettings": "jointlock.planning.ga",
        "joint_vector_deg": "jointlock.jobs._common",
        "locked_text": "jointlock.jobs._common",
    },
    namespace=globals(),
)  # fmt: skip

#: 000's speed and acceleration limits, the halt's defaults where a model gives none
#: (:data:`jointlock.jobs.halt.DEFAULT_VMAX_DEG`, ``DEFAULT_AMAX_DEG``) [deg/s, deg/s^2].
DEFAULT_VMAX_DEG = p000.VELOCITY_LIMIT_DEG_S
DEFAULT_AMAX_DEG = p000.ACCELERATION_LIMIT_DEG_S2

#: 000 §5.1-5.2 scenario on halt7 (healthy joints 1, 2, 3, 5, 6, 7) [deg, deg/s, deg/s^2, s].
PAPER_SCENARIO: dict[str, Any] = {
    k: (dict(v) if k == "lock" else list(v) if isinstance(v, tuple) else v) for k, v in p000.SCENARIO.items()
}
#: 000's printed results (§5.2): k [deg/s^6], global torque at k = 0 and at k* [N m].
PAPER_RESULTS = dict(p000.HALT_RESULTS)

LIMITS_HELP = (
    "Limits: a joint's speed limit is --vmax-deg capped by the model's own velocity limit (the "
    "smaller of the two); without --vmax-deg the model's limit where it gives one, else 000's "
    f"{DEFAULT_VMAX_DEG:g} deg/s. The acceleration limit is --amax-deg, else 000's "
    f"{DEFAULT_AMAX_DEG:g} deg/s^2 (models give none). The output says where each limit came from."
)
BASE_HELP = (
    "base of the disturbance torque: fixed (000, default) or free-floating spacecraft; the halt "
    "configuration is searched with the free-floating arm's generalized Jacobian J_F either way "
    "(000 §3.1.2)"
)


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "halt",
        help="optimal halt configuration and optimal halt motion after a lock (seed 000)",
        description=(
            "Halt a crippled arm: optimal halt configuration (Monte Carlo + refinement) unless --qf-deg "
            "or --paper-qf is given, then the 6th-order halt polynomial with the free coefficient k "
            "(000 eq. 27) minimising the global base disturbance torque (eq. 32) under angle/velocity/"
            "acceleration limits. k is reported in deg/s^6 (000's reading). Without options, halt7 runs "
            "000 §5's scenario; other robots need --q0-deg, --dq0-deg, --ddq0-deg and --T. "
            + LIMITS_HELP
            + " A joint without angle limits (continuous) has no angle constraint; its halt "
            "configuration is searched within [-180, 180] deg."
        ),
    )
    add_robot_arguments(p, base_help=BASE_HELP)
    p.add_argument("--q0-deg", type=deg_arg, nargs="+", metavar="DEG", help="angles at failure [deg]")
    p.add_argument(
        "--dq0-deg",
        type=field_arg("state", "dq0_deg"),
        nargs="+",
        metavar="DEG",
        help="rates at failure [deg/s]",
    )
    p.add_argument(
        "--ddq0-deg",
        type=field_arg("state", "ddq0_deg"),
        nargs="+",
        metavar="DEG",
        help="accelerations at failure [deg/s^2]",
    )
    p.add_argument(
        "--margin",
        type=field_arg("halt", "margin"),
        default=0.0,
        help="share of each speed, acceleration and torque limit the halt keeps free, 0 .. 0.5 (default 0; "
        "0.05: 5 %%); each limit's margin is reported either way",
    )
    p.add_argument(
        "--prefer-margin",
        type=field_arg("halt", "prefer_margin"),
        default=0.0,
        metavar="SHARE",
        help="give up at most this share of the best objective (0.01: 1 %%) for the k whose halt keeps the "
        "largest smallest margin to every limit (default 0: the optimum itself)",
    )
    p.add_argument(
        "--objective",
        choices=("mean_torque", "peak_torque", "attitude_change"),
        default="mean_torque",
        help="what k minimises: 000's time-averaged base torque (default), the peak base torque, or the "
        "free spacecraft's attitude change at the end of the halt",
    )
    p.add_argument(
        "--moment-about",
        choices=("spacecraft_com", "joint1"),
        default="spacecraft_com",
        help="point of the base torque: the spacecraft's centre of mass (default, physical) or joint 1's "
        "mount, the root frame's origin (an independent reproduction's reading of 000)",
    )
    p.add_argument(
        "--from-rest",
        action="store_true",
        help="the arm was at rest when the joint locked: zero rates and accelerations (the halt is "
        "then a reconfiguration to the halt configuration)",
    )
    p.add_argument("--T", type=field_arg("halt", "T"), help="halt time [s], 0.001 .. 1e6 (000: 10)")
    qf = p.add_mutually_exclusive_group()
    qf.add_argument("--qf-deg", type=deg_arg, nargs="+", metavar="DEG", help="halt configuration [deg]")
    qf.add_argument(
        "--paper-qf",
        action="store_true",
        help="use 000's printed q_best (000's failure only: halt7, joint 4 locked at 0)",
    )
    p.add_argument(
        "--vmax-deg",
        type=field_arg("limits", "vmax_deg_s"),
        nargs="+",
        metavar="DEG",
        help="speed limit(s) [deg/s], one or one per healthy joint, capped by the model's own limit "
        f"(default: the model's, else {DEFAULT_VMAX_DEG:g} as 000)",
    )
    p.add_argument(
        "--amax-deg",
        type=field_arg("limits", "amax_deg_s2"),
        nargs="+",
        metavar="DEG",
        help=f"acceleration limit(s) [deg/s^2], one or one per healthy joint (default {DEFAULT_AMAX_DEG:g}, as 000)",
    )
    p.add_argument(
        "--torque-max-Nm",
        type=field_arg("limits", "torque_max_Nm"),
        nargs="+",
        metavar="NM",
        help="motor torque limit(s) [N m], one or one per healthy joint, capped by the model's own effort "
        "limit (default: the model's, else none); kept on every sample of the halt (solver scan)",
    )
    p.add_argument(
        "--brake-max-Nm",
        type=field_arg("limits", "brake_max_Nm"),
        nargs="+",
        metavar="NM",
        help="brake torque limit(s) of the locked joint(s) [N m], one or one per locked joint in the order of "
        "--lock (default none)",
    )
    p.add_argument("--solver", choices=("scan", "ga", "vector"), default="scan", help="default scan (exact)")
    p.add_argument(
        "--seed", type=seed_arg, default=0, help="seed of the GA and the Monte Carlo search (default 0)"
    )
    p.add_argument(
        "--samples",
        type=field_arg("halt", "samples"),
        default=p000.SAMPLES,
        help="Monte Carlo samples for the halt configuration",
    )
    p.add_argument(
        "--no-reachability",
        action="store_true",
        help="search the halt configuration over the whole joint ranges (000's way) instead of only "
        "among configurations the halt polynomial reaches from the state within T under the limits "
        "(exact constraint, the default)",
    )
    p.add_argument(
        "--n-samples",
        type=field_arg("halt", "n_samples"),
        default=501,
        help=f"time samples of the objective (odd, >= {MIN_N_SAMPLES}; default 501)",
    )
    p.add_argument(
        "--minimum-T",
        action="store_true",
        help="also find the smallest feasible halt time when the halt is feasible (an infeasible "
        "halt always reports it)",
    )
    p.add_argument(
        "--generations",
        type=field_arg("halt", "generations"),
        default=100,
        help="GA generations, >= 0 (default 100)",
    )
    p.add_argument(
        "--population",
        type=field_arg("halt", "population"),
        default=50,
        help="GA population, >= 2 (default 50)",
    )
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.add_argument("--out", metavar="DIR", help="write plots (PNG), time series (CSV, NPZ) and result.json")
    p.add_argument("--quiet", action="store_true", help="no progress bars")
    p.add_argument(
        "--check-in",
        choices=("none", "mujoco"),
        default="none",
        help="replay the halt in this simulator, the spacecraft free, and compare its attitude, drift and brake "
        "torque with jointlock's (mujoco: the optional extra jointlock[mujoco]; written as mujoco.* with --out)",
    )
    add_clearance_options(p)
    p.add_argument(
        "--wheel-torque-max-Nm",
        type=field_arg("spacecraft", "wheel_torque_max_Nm"),
        metavar="T",
        help="torque the attitude control can give [N m]: the halt's peak base moment (spacecraft held) is "
        "judged against it (default: reported only)",
    )
    p.add_argument(
        "--wheel-momentum-max-Nms",
        type=field_arg("spacecraft", "wheel_momentum_max_Nms"),
        metavar="H",
        help="angular momentum the wheels can store [N m s]: the momentum the halt hands them is judged "
        "against it (default: reported only)",
    )
    p.set_defaults(func=run)


def plan_from_args(args: argparse.Namespace, progress: bool) -> HaltPlan:
    """The options as :func:`plan_halt`'s inputs (errors name the options), and its result."""
    from ..analysis.attitude_control import WheelCapacity
    from ..jobs._common import joint_vector_deg, locked_text
    from ..jobs.halt import (
        CLI_NAMES,
        FailureState,
        HaltLimits,
        HaltMotionSettings,
        HaltSearch,
        check_halt_settings,
        halt_model,
        is_000_failure,
        plan_halt,
    )
    from ..planning.ga import GASettings

    ga = GASettings(n_pop=args.population, n_gen=args.generations)
    check_halt_settings(args.T, args.n_samples, args.samples, args.solver, ga, CLI_NAMES)
    paper_lock = {j: math.radians(a) for j, a in PAPER_SCENARIO["lock"].items()}
    locks = lock_map(args.lock) if args.lock else (paper_lock if args.robot == "halt7" else {})
    model = halt_model(args.robot, locks, args.base, chain=chain_from_args(args))
    paper = is_000_failure(model)  # 000's state at failure belongs to 000's failure only
    defaults = PAPER_SCENARIO if paper else {}
    if args.from_rest:
        if args.dq0_deg is not None or args.ddq0_deg is not None:
            raise ScenarioError("--from-rest means zero rates and accelerations: drop --dq0-deg / --ddq0-deg")
        args.dq0_deg = args.ddq0_deg = [0.0]
    missing = [
        option
        for option, value, key in (
            ("--q0-deg", args.q0_deg, "q0_deg"),
            ("--dq0-deg", args.dq0_deg, "dq0_deg"),
            ("--ddq0-deg", args.ddq0_deg, "ddq0_deg"),
            ("--T", args.T, "T"),
        )
        if value is None and key not in defaults
    ]
    if missing:
        which = (
            f"halt7 with {locked_text({str(j): math.degrees(a) for j, a in locks.items()})}"
            if args.robot == "halt7"
            else "this robot"
        )
        raise ScenarioError(
            f"{which} needs {', '.join(missing)} (the state at failure [deg, deg/s, deg/s^2] and the halt "
            "time [s]; 000's scenario is the default only for halt7 with joint 4 locked at 0 deg; "
            "--from-rest sets zero rates and accelerations)"
        )
    given = [
        opt
        for opt, v in (("--q0-deg", args.q0_deg), ("--dq0-deg", args.dq0_deg), ("--ddq0-deg", args.ddq0_deg))
        if v
    ]
    rest = [0.0] * model.dof
    state = FailureState.from_degrees(
        model,
        args.q0_deg or defaults["q0_deg"],
        (rest if args.from_rest else args.dq0_deg) or defaults["dq0_deg"],
        (rest if args.from_rest else args.ddq0_deg) or defaults["ddq0_deg"],
        names=("--q0-deg", "--dq0-deg", "--ddq0-deg"),
    )
    source = (
        "000 §5.2"
        if not given
        else "given"
        if len(given) == 3
        else f"{', '.join(given)} given, the rest 000 §5.2's"
    )
    if args.from_rest:
        source = "--q0-deg, from rest" if args.q0_deg else "000 §5.2's angles, from rest"
    elif 0 < len(given) < 3:
        warnings.warn(
            f"{', '.join(given)} given, the rest of the state is 000 §5.2's: give all three (or --from-rest) "
            "for a state of your own",
            UserWarning,
            stacklevel=1,
        )
    if args.paper_qf and not paper:
        raise ScenarioError(
            "--paper-qf is 000's q_best for halt7 with joint 4 locked at 0 deg only; give --qf-deg"
        )
    return plan_halt(
        model,
        state,
        T=float(args.T if args.T is not None else defaults["T"]),
        qf=None if args.qf_deg is None else joint_vector_deg(model, args.qf_deg, "--qf-deg"),
        paper_qf=args.paper_qf,
        limits=HaltLimits(
            vmax_deg=args.vmax_deg, amax_deg=args.amax_deg, torque_max_Nm=args.torque_max_Nm,
            brake_max_Nm=args.brake_max_Nm, margin=args.margin,
        ),
        search=HaltSearch(samples=args.samples, reachable=not args.no_reachability),
        motion=HaltMotionSettings(
            solver=args.solver, ga=ga, n_samples=args.n_samples, minimum_T=args.minimum_T, objective=args.objective,
            prefer_margin=args.prefer_margin, moment_about=args.moment_about,
        ),
        base=args.base,
        rng=args.seed,
        progress=progress,
        state_source=source,
        clearance=clearance_from_args(args),
        wheels=WheelCapacity(args.wheel_torque_max_Nm, args.wheel_momentum_max_Nms),
        _names=CLI_NAMES,
    )


def run(args: argparse.Namespace) -> int:
    check_out_dir(args.out)
    if args.check_in == "mujoco":  # before the halt is computed: a missing extra is said at once
        from ..sim import require_mujoco

        require_mujoco()
    plan = plan_from_args(args, not args.quiet and sys.stderr.isatty())
    written = plan.write(Path(args.out)) if args.out else []  # the plan first, whatever the replay does
    replays = {}
    if args.check_in == "mujoco":
        from ..sim import replay_jobs

        replays = replay_jobs({"halt": plan})  # free, and held when the torques hold the spacecraft
    if args.out:
        for key, replay in replays.items():
            written += replay.write(Path(args.out), "mujoco" + key[len("halt") :])
        if "halt" in replays:  # the attitude plot with MuJoCo's trace on top
            from ..sim import write_attitude_with_replay

            write_attitude_with_replay(plan, replays["halt"], Path(args.out))
    if args.json:
        data = plan.to_dict()
        if replays:
            data["checked_in_mujoco"] = {key: replay.to_dict() for key, replay in replays.items()}
        print_json(data)
        return 0
    for line in plan.summary():
        print(line)
    for replay in replays.values():
        print()
        for line in replay.summary():
            print(line)
    if written:
        print(f"\nwrote {', '.join(written)} to {args.out}")
    return 0
