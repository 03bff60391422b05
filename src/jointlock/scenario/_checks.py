"""Cross-field checks of a scenario: bases, the robot file, the failure, joint vectors, jobs."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

from ..bounds import shown
from ..errors import JointlockError, ScenarioError
from ..io.files import check_path_text
from ..robots import BUILTIN_ROBOTS, CHAIN_FIELDS, UrdfChain
from ._defaults import _defaults_000, _is_000_failure
from ._fields import _BASE2, NEEDS_LOCK, _hint
from ._jump import _check_jump
from ._task import state_from_task


def _inherit_singular_base(out: dict[str, Any], jobs: tuple[str, ...], *, given_base: bool) -> None:
    """``singular.base`` falls back to the top-level ``base`` when the file gives one, as every
    other job's base does (with ``verify_conditions``, a floating base is analysed on 004's
    virtual manipulator, the free-floating arm's equivalent).  Without either, the ``singular``
    command's own default holds (virtual with ``verify_conditions``, fixed otherwise)."""
    if "singular" not in jobs or not given_base:
        return
    s = out["singular"]
    if s["base"] is None:
        top = out["base"]
        s["base"] = "virtual" if top == "floating" and s["verify_conditions"] else top


def _resolve_robot(out: dict[str, Any], source: str, base_dir: Path) -> None:
    name = out["robot"]
    chain = next((k for k in CHAIN_FIELDS if out.get(k) is not None), None)
    if chain is not None and (name in BUILTIN_ROBOTS or Path(name).suffix.lower() != ".urdf"):
        what = "a built-in robot" if name in BUILTIN_ROBOTS else "not a .urdf file"
        raise ScenarioError(
            f"{source}: {chain}: chooses the chain of a URDF robot; robot {shown(name)} is {what} (allowed with "
            "robot = a .urdf file; a .toml model file names its chain itself)"
        )
    if out.get("srdf") is not None:
        out["srdf"] = _existing_file(out["srdf"], base_dir, f"{source}: srdf", "SRDF file")
    if name in BUILTIN_ROBOTS:
        return
    check_path_text(name, f"{source}: robot: model file", ScenarioError)
    suffix = Path(name).suffix.lower()
    if suffix not in (".toml", ".urdf"):
        raise ScenarioError(
            f"{source}: robot must be a built-in name ({', '.join(BUILTIN_ROBOTS)}) or a .toml/.urdf "
            f"model file; got {shown(name)}{_hint(name, BUILTIN_ROBOTS)}"
        )
    path = Path(name)
    try:
        if not path.is_absolute():
            path = (base_dir / path).resolve()
        found, folder = path.is_file(), path.is_dir()
    except (OSError, RuntimeError) as exc:  # a loop of symbolic links, a name too long
        raise ScenarioError(f"{source}: robot: cannot use model file {shown(name)}: {exc}") from None
    if folder:
        raise ScenarioError(f"{source}: robot: {shown(name)} is a folder, not a model file (looked at {path})")
    if not found:
        raise ScenarioError(f"{source}: robot: model file {shown(name)} not found (looked for {path})")
    out["robot"] = str(path)


def _existing_file(name: str, base_dir: Path, where: str, what: str) -> str:
    """``name`` as an absolute path (relative to ``base_dir``), checked to be a file."""
    check_path_text(name, where, ScenarioError)
    path = Path(name) if Path(name).is_absolute() else (base_dir / name).resolve()
    if not path.is_file():
        raise ScenarioError(f"{where}: {what} {shown(name)} not found (looked for {path})")
    return str(path)


def _load(out: dict[str, Any], base: str, source: str, cache: dict) -> Any:
    from ..robots import load_robot

    try:
        chain = UrdfChain.from_fields(out)
    except JointlockError as exc:
        raise ScenarioError(f"{source}: {exc}") from None
    key = (out["robot"], base, chain)
    if key not in cache:
        try:
            cache[key] = load_robot(out["robot"], base=base, chain=chain)  # type: ignore[arg-type]
        except JointlockError as exc:
            field = "base" if base == "floating" and "base" in str(exc) else "robot"
            raise ScenarioError(
                f"{source}: {field}: cannot load {out['robot']!r} ({base} base): {exc}"
            ) from None
        except Exception as exc:  # a reader failing on a malformed file it did not anticipate
            raise ScenarioError(
                f"{source}: robot: malformed model file {out['robot']!r}: {type(exc).__name__}: {exc}"
            ) from None
    return cache[key]


#: Jobs whose method has one locked joint: 002's tolerance angle and re-planning are about the
#: one joint that locked (closed-form on 002's arm), 001's jump locks one joint during a task.
ONE_LOCK_JOBS = ("tolerance_angle", "replan", "jump")


def _check_earlier_locks(
    earlier: dict[int, float], fail: dict[str, Any], jobs: tuple[str, ...], source: str, robot: str, n: int
) -> None:
    """``failure.also_locked_deg``: joints of the arm, not the failure's own, with a failure to
    add them to, and only for jobs whose method allows several locked joints."""
    if fail["joint"] is None or fail["angle_deg"] is None:
        raise ScenarioError(
            f"{source}: failure.also_locked_deg lists joints locked before the failure: give failure.joint and "
            "failure.angle_deg too"
        )
    for j in earlier:
        if not 1 <= j <= n:
            raise ScenarioError(
                f"{source}: failure.also_locked_deg: joint {j} is no joint of {robot} (1..{n})"
            )
        if j == fail["joint"]:
            raise ScenarioError(
                f"{source}: failure.also_locked_deg: joint {j} is the failure's own joint (failure.joint); "
                "list only the joints locked before it"
            )
    if len(earlier) + 1 >= n:
        raise ScenarioError(f"{source}: failure.also_locked_deg: {len(earlier) + 1} locks leave no movable joint of {robot}")
    bad = [job for job in jobs if job in ONE_LOCK_JOBS]
    if bad:
        raise ScenarioError(
            f"{source}: failure.also_locked_deg: job(s) {', '.join(f'[{b}]' for b in bad)} work with one locked "
            "joint (002's tolerance angle and re-planning are closed-form for the one joint that locked; "
            "001's jump locks one joint during the task); remove also_locked_deg or these jobs"
        )


def _check_semantics(out: dict[str, Any], jobs: tuple[str, ...], source: str) -> None:
    """Cross-field checks of ``out`` (in place: a few defaults depend on other fields).

    Over 100 lines: one flat list of independent rules, each a few lines, in the order the
    tables appear; splitting it would scatter the rules without making any of them simpler.
    """
    from ..locking import check_lock

    cache: dict = {}
    model = _load(out, out["base"], source, cache)
    for job in jobs:
        b = out[job].get("base")
        if b in _BASE2:
            _load(out, b, source, cache)
    fail = out["failure"]
    n = model.dof
    state_from_task(out, jobs, source, model)  # [task] + failure.time_s: the state and the angle from it
    if fail["joint"] is not None and not 1 <= fail["joint"] <= n:
        raise ScenarioError(
            f"{source}: failure.joint must be a joint number 1..{n} of {model.name}; got {fail['joint']}"
        )
    if fail["angle_deg"] is not None and fail["joint"] is None:
        raise ScenarioError(f"{source}: failure.angle_deg needs failure.joint (the joint that locks, 1..{n})")
    if fail["joint"] is not None and fail["angle_deg"] is None and set(jobs) - {"jump"}:
        raise ScenarioError(
            f"{source}: failure.joint needs failure.angle_deg (the locked angle [deg]); only [jump] "
            "works without it"
        )
    for job in jobs:
        if job in NEEDS_LOCK and fail["angle_deg"] is None:
            raise ScenarioError(
                f"{source}: job [{job}] needs the failure: set failure.joint (1..{n}) and failure.angle_deg"
            )
    earlier = {int(j): a for j, a in (fail.get("also_locked_deg") or {}).items()}
    if earlier:
        _check_earlier_locks(earlier, fail, jobs, source, model.name, n)
    locks_deg: dict[int, float] = {}
    if fail["joint"] is not None and fail["angle_deg"] is not None:
        locks_deg = {**earlier, int(fail["joint"]): float(fail["angle_deg"])}
    for j, a in locks_deg.items():
        # lock()'s checks without building the locked arm (distinct joints and at least one
        # left movable are checked above, so checking each on the arm as loaded is the same)
        try:
            check_lock(model, j, math.radians(a))
        except JointlockError as exc:
            where = "failure.angle_deg" if j == fail["joint"] else f"failure.also_locked_deg.{j}"
            raise ScenarioError(f"{source}: {where}: {exc}") from None
    locked_dof = n - len(locks_deg) if locks_deg else None
    _defaults_000(out, jobs, model)

    def vector(
        where: str, values: list[float] | None, *, full_only: bool = False, rates: bool = False
    ) -> None:
        """Check a joint vector's length; with every joint given (and a lock), the locked
        joint's entry must equal its lock angle (angles) or be 0 (``rates``: rates and
        accelerations, as a locked joint does not move)."""
        if values is None:
            return
        sizes = {n} if full_only or locked_dof is None else {locked_dof, n}
        if len(values) not in sizes:
            want = " or ".join(str(s) for s in sorted(sizes))
            what = (
                "every joint of the arm" if full_only or locked_dof is None else "healthy joints, or every joint"
            )
            raise ScenarioError(
                f"{source}: {where} needs {want} values ({what} of {model.name}); got {len(values)}"
            )
        if locked_dof is not None and not full_only and len(values) == n:
            for number, angle in locks_deg.items():
                j = number - 1
                if rates:
                    if not math.isclose(values[j], 0.0, abs_tol=1e-9):
                        raise ScenarioError(
                            f"{source}: {where}: entry {j + 1} (the locked joint) must be 0, as a locked "
                            f"joint does not move; got {values[j]:g} (or give only the healthy joints)"
                        )
                    continue
                if not math.isclose(values[j], angle, abs_tol=1e-9):
                    name = "failure.angle_deg" if number == fail["joint"] else f"failure.also_locked_deg.{number}"
                    raise ScenarioError(
                        f"{source}: {where}: entry {j + 1} (the locked joint) must equal {name} = "
                        f"{angle:g}; got {values[j]:g} (or give only the healthy joints)"
                    )

    for key in ("q0_deg", "dq0_deg", "ddq0_deg"):
        vector(f"state.{key}", out["state"][key], rates=key != "q0_deg")
    if "halt" in jobs:
        h = out["halt"]
        vector("halt.qf_deg", h["qf_deg"])
        if h["paper_qf"] and h["qf_deg"] is not None:
            raise ScenarioError(f"{source}: halt.paper_qf and halt.qf_deg exclude each other; give one")
        if h["paper_qf"] and not _is_000_failure(model.name, fail):
            raise ScenarioError(
                f"{source}: halt.paper_qf is 000's q_best for halt7 with joint 4 locked at 0 deg only; give halt.qf_deg"
            )
        if h["n_samples"] % 2 == 0:
            raise ScenarioError(
                f"{source}: halt.n_samples must be odd (Simpson's rule); got {h['n_samples']}"
            )
        for key in ("q0_deg", "dq0_deg", "ddq0_deg"):
            if out["state"][key] is None:
                raise ScenarioError(f"{source}: job [halt] needs state.{key} (the state at failure)")
        if h["T"] is None:
            raise ScenarioError(f"{source}: job [halt] needs halt.T (halt time [s], 000: 10)")
    if "halt_config" in jobs and out["halt_config"]["reachable"] is None:
        hc = out["halt_config"]
        has_time = hc["halt_time"] is not None or out.get("halt", {}).get("T") is not None
        hc["reachable"] = out["state"]["q0_deg"] is not None and has_time
    if "halt_config" in jobs and out["halt_config"]["reachable"]:
        hc = out["halt_config"]
        if out["state"]["q0_deg"] is None:
            raise ScenarioError(f"{source}: halt_config.reachable needs state.q0_deg")
        if hc["halt_time"] is None and out.get("halt", {}).get("T") is None:
            raise ScenarioError(f"{source}: halt_config.reachable needs halt_config.halt_time or halt.T")
    if "jump" in jobs:
        _check_jump(out, source, model)
    if "tolerance_angle" in jobs:
        t = out["tolerance_angle"]
        if t["q_target_deg"] is None:
            raise ScenarioError(
                f"{source}: job [tolerance_angle] needs tolerance_angle.q_target_deg ({n} values)"
            )
        vector("tolerance_angle.q_target_deg", t["q_target_deg"], full_only=True)
    if "replan" in jobs:
        r = out["replan"]
        for key in ("from_deg", "to_deg"):
            if r[key] is None:
                raise ScenarioError(f"{source}: job [replan] needs replan.{key} ({n} values)")
            vector(f"replan.{key}", r[key], full_only=True)
    if "singular" in jobs:
        s = out["singular"]
        if s["verify_conditions"] and s["search"]:
            raise ScenarioError(
                f"{source}: singular.verify_conditions and singular.search exclude each other"
            )
        if s["verify_conditions"] and s["base"] == "floating":
            raise ScenarioError(
                f"{source}: singular.verify_conditions needs base 'virtual' or 'fixed'; got 'floating'"
            )
        if s["verify_conditions"] and locked_dof is not None:
            raise ScenarioError(
                f"{source}: singular.verify_conditions analyses the whole 7-joint arm; remove [failure] "
                "or set verify_conditions = false"
            )
        if s["base"] in (None, "virtual") and (s["verify_conditions"] or s["base"] == "virtual"):
            _load(out, "floating", source, cache)
        vector("singular.q_deg", s["q_deg"])
