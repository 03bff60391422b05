"""The scenario schema: jobs, field specifications and the tables of a scenario file."""

from __future__ import annotations

import difflib
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any

from ..bounds import (
    MAX_GAIN,
    MAX_KAPPA,
    MAX_LENGTH_M,
    MAX_OPTION_DEG,
    MAX_RATE_DEG,
    MAX_SEED,
    MAX_TIME_S,
    MAX_TORQUE_NM,
    MIN_LENGTH_M,
    MIN_STEP_S,
    MIN_TIME_S,
)

#: Jobs a scenario can run, in the order they run (a halt uses the halt configuration found
#: before it).
JOB_ORDER: tuple[str, ...] = (
    "halt_config",
    "halt",
    "jump",
    "tolerance_angle",
    "replan",
    "workspace",
    "singular",
)

#: Which seed paper each job implements (for reports).
JOB_PAPER: dict[str, str] = {
    "halt_config": "000 §3 (HCOM)",
    "halt": "000 §4 (HMOM)",
    "jump": "001 (reconstructed: docs/reconstruction-001.md)",
    "tolerance_angle": "002 (tolerance angle)",
    "replan": "002 (re-planning)",
    "workspace": "002 (workspace)",
    "singular": "004 (singularity)",
}

#: Largest |angle| accepted in an ``*_deg`` field [deg] (one turn either way).
MAX_ABS_DEG = 360.0

#: Fewest ``workspace.samples`` (:data:`jointlock.analysis.workspace.MIN_SAMPLES`).
WORKSPACE_MIN_SAMPLES = 1000


@dataclass(frozen=True)
class Field:
    """Schema of one scenario field.

    ``kind``: ``"int"``, ``"number"``, ``"bool"``, ``"str"``, ``"choice"``, ``"numbers"``
    (list of numbers), ``"rows"`` (a list of equally long lists of numbers: waypoints),
    ``"strings"`` (list of choices), ``"locks"`` (a table of joint numbers to angles),
    ``"joint_values"`` (a table of joint names to numbers).  ``lo``/``hi`` bound numbers
    (``lo_open``: strictly greater); ``choices`` lists allowed strings.
    """

    kind: str
    default: Any = None
    lo: float | None = None
    hi: float | None = None
    lo_open: bool = False
    choices: tuple[str, ...] = ()
    length: int | None = None
    unit: str = ""
    help: str = ""

    def allowed(self) -> str:
        """What the field accepts, in words."""
        unit = f" [{self.unit}]" if self.unit else ""
        if self.kind == "bool":
            return "true or false"
        if self.kind == "str":
            return "a string" + unit
        if self.kind == "locks":
            return f"a table {{joint number = angle}} of finite numbers >= {self.lo:g} and <= {self.hi:g}{unit}"
        if self.kind == "joint_values":
            return f"a table {{joint name = value}} of finite numbers >= {self.lo:g} and <= {self.hi:g}{unit}"
        if self.kind in ("choice", "strings"):
            opts = ", ".join(repr(c) for c in self.choices)
            return ("one of " if self.kind == "choice" else "a list of ") + opts
        what = {
            "int": "an integer",
            "number": "a finite number",
            "numbers": "a list of finite numbers",
            "rows": "a list of 2 or more equally long rows of finite numbers",
        }[self.kind]
        if self.length is not None:
            what = f"a list of {self.length} finite numbers"
        rng = []

        def num(v: float) -> str:
            return str(int(v)) if self.kind == "int" else f"{v:g}"

        if self.lo is not None:
            rng.append(f"{'>' if self.lo_open else '>='} {num(self.lo)}")
        if self.hi is not None:
            rng.append(f"<= {num(self.hi)}")
        each = " each" if self.kind in ("numbers", "rows") else ""
        return what + (f"{each} " + " and ".join(rng) if rng else "") + unit


def _deg(help_: str, *, unit: str = "deg", lo: float = -MAX_ABS_DEG, hi: float = MAX_ABS_DEG) -> Field:
    return Field("numbers", lo=lo, hi=hi, unit=unit, help=help_)


def _pos(unit: str, help_: str, default: Any = None, *, hi: float | None = None) -> Field:
    return Field("number", default, lo=0.0, lo_open=True, hi=hi, unit=unit, help=help_)


def _time(help_: str, default: Any = None, *, lo: float = MIN_TIME_S) -> Field:
    """A duration [s] within the physical bounds of :mod:`jointlock.bounds`."""
    return Field("number", default, lo=lo, hi=MAX_TIME_S, unit="s", help=help_)


def _length(help_: str, default: Any = None, *, lo: float = MIN_LENGTH_M) -> Field:
    """A length [m] a computation divides by, within the bounds of :mod:`jointlock.bounds`."""
    return Field("number", default, lo=lo, hi=MAX_LENGTH_M, unit="m", help=help_)



#: Top-level scalar fields.
TOP_FIELDS: dict[str, Field] = {
    "title": Field("str", "", help="a title for the report"),
    "description": Field("str", "", help="free text shown in the report"),
    "robot": Field("str", None, help="built-in name or model file (.toml DH table, .urdf)"),
    "root_link": Field("str", None, help="URDF robot only: the link its chain starts from (default: the tree's root)"),
    "tip_link": Field(
        "str", None, help="URDF robot only: the link its chain ends at (needed when the tree branches: two arms, fingers)"
    ),
    "freeze_deg": Field(
        "joint_values", None, lo=-MAX_ABS_DEG, hi=MAX_ABS_DEG, unit="deg",
        help="URDF robot only: revolute joints held at these angles, their links merged (other joints off the "
        "chain are held at 0; a <mimic> joint follows its leader)",
    ),  # fmt: skip
    "srdf": Field(
        "str", None, help="URDF robot only: an SRDF file (relative to the scenario's folder) whose "
        "<disable_collisions> link pairs the clearance never checks",
    ),
    "meshes": Field(
        "choice", None, choices=("convex", "skip"),
        help="URDF robot only: its <collision> meshes read as their convex hulls (default; needs the mesh "
        "extra) or left out (skip: those links are then geometry-blind)",
    ),  # fmt: skip
    "freeze_m": Field(
        "joint_values", None, lo=-MAX_LENGTH_M, hi=MAX_LENGTH_M, unit="m",
        help="URDF robot only: prismatic joints held at these positions (gripper fingers, a torso lift)",
    ),  # fmt: skip
    "base": Field("choice", "fixed", choices=("fixed", "floating"), help="spacecraft held or free-floating"),
    "seed": Field("int", 0, lo=0, hi=MAX_SEED, help="seed of every stochastic job (Monte Carlo, GA)"),
    "out": Field(
        "str",
        None,
        help="output folder, relative to the file's folder and inside it (default: <scenario name>-results "
        "in the working folder); --out overrides, with any folder",
    ),
    "jobs": Field("strings", None, choices=JOB_ORDER, help="jobs to run (default: every job table given)"),
    "check_in": Field(
        "choice",
        "none",
        choices=("none", "mujoco"),
        help="replay the halt, the jump runs and the re-plan in this simulator and compare the spacecraft's attitude, "
        "drift and the brake torque with jointlock's ('mujoco': the optional extra jointlock[mujoco]; docs/simulators.md)",
    ),
    "compiled": Field(
        "choice",
        None,
        choices=("auto", "always", "never"),
        help="when the jobs run on the compiled kernels: 'always' (every batch: a campaign's workers), 'auto' (large "
        "batches only) or 'never'; the same numbers to round-off (default: the environment's JOINTLOCK_COMPILED, "
        "else 'auto'; docs/performance.md)",
    ),
}

#: Tables shared by the jobs.
SHARED_TABLES: dict[str, dict[str, Field]] = {
    "failure": {
        "joint": Field("int", None, lo=1, help="the joint that locks, numbered from 1"),
        "angle_deg": Field(
            "number", None, lo=-MAX_ABS_DEG, hi=MAX_ABS_DEG, unit="deg", help="angle it locks at"
        ),
        "time_s": Field(
            "number",
            None,
            lo=0.0,
            hi=MAX_TIME_S,
            unit="s",
            help="time it locks during a task: the jump study's, or [task]'s (then the halt starts from the task's "
            "state at that instant and the joint locks at the task's angle)",
        ),
        "also_locked_deg": Field(
            "locks",
            None,
            lo=-MAX_ABS_DEG,
            hi=MAX_ABS_DEG,
            unit="deg",
            help="joints locked before this failure, {joint = angle}, e.g. {2 = 10.0} (halt_config, halt, "
            "workspace, singular; not tolerance_angle, replan, jump: one locked joint by their method)",
        ),
    },
    "state": {
        "q0_deg": _deg("angles at failure (healthy joints, or the full arm)"),
        "dq0_deg": _deg("rates at failure", unit="deg/s", lo=-1e4, hi=1e4),
        "ddq0_deg": _deg("accelerations at failure", unit="deg/s^2", lo=-1e5, hi=1e5),
    },
    "limits": {
        "vmax_deg_s": _pos(
            "deg/s", "joint speed limit (halt, halt_config, jump); formerly vmax_deg", hi=MAX_RATE_DEG
        ),
        "amax_deg_s2": _pos(
            "deg/s^2", "joint acceleration limit (halt, halt_config, jump); formerly amax_deg", hi=MAX_RATE_DEG
        ),
        "eps_m": _pos("m", "end-effector position-deviation threshold (jump)", hi=MAX_LENGTH_M),
        "torque_max_Nm": _pos(
            "N m", "motor torque limit of every healthy joint, capped by the model's own (halt)", hi=MAX_TORQUE_NM
        ),
        "brake_max_Nm": _pos("N m", "brake torque limit of every locked joint (halt)", hi=MAX_TORQUE_NM),
        "clearance_min_m": Field(
            "number",
            None,
            lo=0.0,
            hi=MAX_LENGTH_M,
            unit="m",
            help="clearance kept between the links, the spacecraft bus and keep-outs (halt_config, halt; "
            "default 0.05)",
        ),
        "check_clearance": Field(
            "bool", True, help="require the clearance (false: report it only, the papers' way) (halt_config, halt)"
        ),
    },
    "task": {
        "file": Field(
            "str",
            None,
            help="the planned motion as a CSV (header, then t_s and one angle per joint [deg] per row) or NPZ "
            "(t_s, q_deg) file, relative to the scenario's folder; joined by a cubic spline",
        ),
        "waypoints_deg": Field(
            "rows",
            None,
            lo=-MAX_OPTION_DEG,
            hi=MAX_OPTION_DEG,
            unit="deg",
            help="or the planned motion as waypoints, every joint of the arm per row, rest at each",
        ),
        "durations_s": Field(
            "numbers", None, lo=0.0, lo_open=True, hi=MAX_TIME_S, unit="s", help="time from each waypoint to the next"
        ),
        "scaling": Field(
            "choice", "quintic", choices=("quintic", "trapezoidal"), help="time scaling of each waypoint segment"
        ),
        "dx_m": Field(
            "numbers",
            None,
            lo=-1e3,
            hi=1e3,
            length=3,
            unit="m",
            help="or a Cartesian task (001's): the end effector's straight-line displacement, followed by resolved "
            "rates from task.q0_deg (the jump study's task, [jump]'s fields)",
        ),
        "q0_deg": _deg("Cartesian task: its start, every joint of the arm"),
        "duration_s": _time("Cartesian task: its time (default 12)"),
        "blend_s": _pos("s", "Cartesian task: parabolic blend time (default 2)", hi=MAX_TIME_S),
        "dt_s": _time("Cartesian task: control step (default 0.05)", lo=MIN_STEP_S),
        "kp": Field("number", None, lo=0.0, hi=MAX_GAIN, unit="1/s", help="Cartesian task: feedback gain (default 2)"),
        "feedforward": Field(
            "choice", None, choices=("step", "instant"), help="Cartesian task: feed-forward over a control step"
        ),
        "base": Field(
            "choice",
            None,
            choices=("fixed", "floating"),
            help="Cartesian task: base of its resolved rates (default jump.base, else the top-level base)",
        ),
    },
    "spacecraft": {
        "wheel_torque_max_Nm": _pos(
            "N m", "torque the attitude control can give (halt: its peak base moment is judged against it)",
            hi=MAX_TORQUE_NM,
        ),  # fmt: skip
        "wheel_momentum_max_Nms": _pos(
            "N m s", "angular momentum the wheels can store (halt: the momentum it hands them)", hi=MAX_TORQUE_NM
        ),
    },
}

_BASE2 = ("fixed", "floating")

#: Job tables: field name (as the CLI option, dashes -> underscores) -> schema.
JOB_TABLES: dict[str, dict[str, Field]] = {
    "halt_config": {
        "samples": Field("int", 36000, lo=2, hi=5_000_000, help="Monte Carlo samples K (000: 36000)"),
        "jacobian": Field(
            "choice",
            "generalized",
            choices=("generalized", "fixed"),
            help="Jacobian of the indices: 000's generalized J_F (free-floating; differs from fixed "
            "only with base 'floating') or the fixed-base one",
        ),
        "assignment": Field(
            "choice",
            "equation",
            choices=("equation", "text"),
            help="which index gets AHP weight 1/2: the condition number (000 eq. 19) or the "
            "manipulability (000 §5.1 text)",
        ),
        "renormalize": Field(
            "bool", False, help="divide the combined weights by their sum (000 eq. 18 does not)"
        ),
        "length": _length("characteristic length dividing the linear rows"),
        "no_refine": Field("bool", False, help="plain Monte Carlo, as 000"),
        "reachable": Field(
            "bool",
            None,
            help="require the halt configuration to be reachable by the halt polynomial from [state] "
            "within halt.T (or halt_time) under the limits; default: yes when the state and a halt "
            "time are given",
        ),
        "halt_time": _time("halt time of the reachability bound (default: halt.T)"),
        "base": Field("choice", None, choices=_BASE2, help="base of this job (default: the top-level base)"),
    },
    "halt": {
        "T": _time("halt time (000: 10)"),
        "qf_deg": _deg("halt configuration (default: from halt_config, or a Monte Carlo search)"),
        "paper_qf": Field("bool", False, help="000's printed q_best (halt7 only)"),
        "solver": Field(
            "choice",
            "scan",
            choices=("scan", "ga", "vector"),
            help="scan: exact search of the shared k; ga: 000's adaptive GA; vector: one k per "
            "joint (extension)",
        ),
        "samples": Field("int", 36000, lo=2, hi=5_000_000, help="Monte Carlo samples when no halt_config"),
        "n_samples": Field("int", 501, lo=11, hi=200_001, help="time samples of the objective (odd)"),
        "generations": Field("int", 100, lo=0, hi=100_000, help="GA generations (0: the first population only)"),
        "population": Field("int", 50, lo=2, hi=100_000, help="GA population"),
        "margin": Field(
            "number",
            0.0,
            lo=0.0,
            hi=0.5,
            help="share of each speed, acceleration and torque limit kept free by the halt (0.05: 5 %)",
        ),
        "prefer_margin": Field(
            "number",
            0.0,
            lo=0.0,
            hi=0.5,
            help="share of the best objective given up, at most, for the k whose halt keeps the largest "
            "smallest margin to every limit (0.01: 1 %; 0: the optimum itself)",
        ),
        "objective": Field(
            "choice",
            "mean_torque",
            choices=("mean_torque", "peak_torque", "attitude_change"),
            help="what k minimises: 000's time-averaged base torque, the peak base torque, or the free "
            "spacecraft's attitude change at the end",
        ),
        "moment_about": Field(
            "choice",
            "spacecraft_com",
            choices=("spacecraft_com", "joint1"),
            help="point of the base torque: the spacecraft's centre of mass (physical) or joint 1's "
            "origin (an independent reproduction of 000's reading)",
        ),
        "minimum_T": Field(
            "bool",
            False,
            help="also find the smallest feasible halt time when the halt is feasible (an "
            "infeasible halt always reports it)",
        ),
        "base": Field(
            "choice",
            None,
            choices=_BASE2,
            help="base of the disturbance torque: 'fixed' = spacecraft held, as 000 (default: the "
            "top-level base)",
        ),
    },
    "jump": {
        "fail_at": Field(
            "number", None, lo=0.0, hi=MAX_TIME_S, unit="s", help="one failure time (default failure.time_s)"
        ),
        "sweep": Field("int", None, lo=2, hi=10_000, help="sampled failure times (default 40; kappa(t) is fitted to >= 2)"),
        "kappa": Field(
            "number",
            None,
            lo=-MAX_KAPPA,
            hi=MAX_KAPPA,
            unit="rad^2/(s m^3)",
            help="constant kappa instead of the search",
        ),
        "order": Field("int", 5, lo=1, hi=9, help="polynomial order of kappa(t)"),
        "on_infeasible": Field(
            "choice",
            None,
            choices=("raise", "report"),
            help="one failure time without a kappa that keeps the limits: an error (raise, the default), or the "
            "uncompensated jump with the reason (report: an audit's cells)",
        ),
        "fix": Field(
            "choice",
            "auto",
            choices=("auto", "clip", "ramp", "clip+ramp", "none"),
            help="fix of kappa(t) verified as well: clip to the feasible band, ramp (rate-limit "
            "kappa), both, none; auto = clip+ramp only when kappa(t) breaks a limit",
        ),
        "q0_deg": _deg("task start, every joint of the arm"),
        "dx_m": Field(
            "numbers", None, lo=-1e3, hi=1e3, length=3, unit="m", help="straight-line displacement"
        ),
        "duration_s": _time("task time"),
        "blend_s": _pos("s", "parabolic blend time", hi=MAX_TIME_S),
        "dt_s": _time("control step", lo=MIN_STEP_S),
        "vmax_deg_s": _pos("deg/s", "joint speed limit (default limits.vmax_deg_s, else 10)", hi=MAX_RATE_DEG),
        "amax_deg_s2": _pos(
            "deg/s^2", "joint acceleration limit (default limits.amax_deg_s2, else 5)", hi=MAX_RATE_DEG
        ),
        "eps_m": _pos("m", "position-deviation threshold (default limits.eps_m, else 0.001)", hi=MAX_LENGTH_M),
        "kp": Field("number", None, lo=0.0, hi=MAX_GAIN, unit="1/s", help="feedback gain"),
        "rest_transitions": Field(
            "bool", None, help="also check the start from rest and the stop at the end (default false)"
        ),
        "feedforward": Field(
            "choice",
            None,
            choices=("step", "instant"),
            help="feed-forward over a control step: nominal displacement / dt (step, default) or "
            "the nominal velocity at the step's start (instant)",
        ),
        "base": Field("choice", None, choices=_BASE2, help="base of this job (default: the top-level base)"),
    },
    "tolerance_angle": {
        "q_target_deg": _deg("desired joints, every joint of the arm"),
        "gamma_limit_deg": Field(
            "number", 180.0, lo=0.0, lo_open=True, hi=180.0, unit="deg", help="sweep |gamma| <= this"
        ),
        "zoom_deg": Field(
            "number",
            2.0,
            lo=0.0,
            lo_open=True,
            hi=180.0,
            unit="deg",
            help="half-width of the second, narrow gamma range (002 Fig. 6: 2)",
        ),
        "step_deg": Field("number", 0.1, lo=0.0, lo_open=True, hi=180.0, unit="deg", help="gamma sweep step"),
    },
    "replan": {
        "from_deg": _deg("start joints, every joint of the arm"),
        "to_deg": _deg("goal joints, every joint of the arm"),
        "steps": Field("int", 40, lo=1, hi=100_000, help="interior points N of 002 eq. (19)"),
        "cycle": _time("time between points (002: 0.25)", 0.25, lo=MIN_STEP_S),
        "tolerance_deg": Field("number", 0.0, lo=0.0, hi=180.0, unit="deg", help="largest |gamma|"),
    },
    "workspace": {
        "samples": Field(
            "int",
            200_000,
            lo=WORKSPACE_MIN_SAMPLES,
            hi=20_000_000,
            help="configurations per arm (fewer than 1000 say little about a volume)",
        ),
        "voxel": _length("voxel side (default automatic)"),
    },
    "singular": {
        "verify_conditions": Field("bool", False, help="check 004's Cond1-Cond5"),
        "search": Field("bool", False, help="search for singular configurations"),
        "base": Field(
            "choice",
            None,
            choices=("fixed", "floating", "virtual"),
            help="Jacobian: fixed, floating (generalized) or virtual (004's virtual manipulator); "
            "default: the top-level base if given (floating -> virtual with verify_conditions), "
            "else virtual with verify_conditions and fixed otherwise",
        ),
        "weighting": Field(
            "choice",
            "segment",
            choices=("segment", "vafa-dubowsky"),
            help="virtual link lengths: 004's formula (segment) or the exact Vafa-Dubowsky one",
        ),
        "q_deg": _deg("configuration analysed (default zeros)"),
        "tol": _pos("", "rank tolerance on singular values", 1e-8, hi=1e3),
        "length": _length("characteristic length"),
        "samples": Field("int", None, lo=1, hi=1_000_000, help="samples per condition / search starts"),
        "skip_colliding": Field(
            "bool", None,
            help="search: leave out the singular configurations closer than limits.clearance_min_m to the arm, "
            "its bus or the keep-outs, before clustering (false: count them only; default: not checked)",
        ),  # fmt: skip
    },
}

#: Jobs that need ``[failure] joint`` and ``angle_deg``.
NEEDS_LOCK = ("halt_config", "halt", "tolerance_angle", "replan")

ALL_TABLES: dict[str, dict[str, Field]] = {**SHARED_TABLES, **JOB_TABLES}

#: Former field names still read from files and overrides (table -> {old name: new name}): an
#: old name works as the new one and warns once per process (``FutureWarning``); giving both
#: names of one quantity is an error.  One name per quantity: ``[limits]`` now spells its rates
#: as ``[jump]`` does.
DEPRECATED_FIELDS: dict[str, dict[str, str]] = {
    "limits": {"vmax_deg": "vmax_deg_s", "amax_deg": "amax_deg_s2"},
}

#: Fields stored under another key in :attr:`Scenario.data` (table -> {field: key}): the
#: resolved limits keep the keys the jobs read (``data["limits"]["vmax_deg"]``).
RESOLVED_KEYS: dict[str, dict[str, str]] = {
    "limits": {"vmax_deg_s": "vmax_deg", "amax_deg_s2": "amax_deg"},
}


def _spellings(table: str, name: str) -> tuple[str, ...]:
    """Every name of one field of ``table`` in a file: the current name, then its former ones."""
    old = DEPRECATED_FIELDS.get(table, {})
    new = old.get(name, name)
    return (new, *(o for o, n in old.items() if n == new))


def _hint(key: str, allowed: Iterable[str]) -> str:
    close = difflib.get_close_matches(key, list(allowed), n=1, cutoff=0.6)
    if close:
        return f" (did you mean {close[0]!r}?)"
    owners = [t for t, fields in ALL_TABLES.items() if key in fields or key in DEPRECATED_FIELDS.get(t, {})]
    if owners:
        return f" (it belongs in [{owners[0]}])"
    return ""
