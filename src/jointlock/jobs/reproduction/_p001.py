"""001's rows: no number survived; NOTES-001's study on canadarm7, "ours only"."""

from __future__ import annotations

import math

from ...papers import p001
from ...planning.jump import JumpScenario, study_jump
from ...robots import load_robot
from ._report import LOST, OURS_ONLY, ReproductionRow

#: 001: sampled failure times of the study (``jointlock jump``'s default).
JUMP_FAILURE_TIMES = 40


def notes_001_task() -> JumpScenario:
    """NOTES-001's task (:data:`jointlock.papers.p001.TASK`) as a :class:`JumpScenario`."""
    t = p001.TASK
    return JumpScenario(
        q0=tuple(math.radians(v) for v in t["q0_deg"]),
        dx=t["dx_m"],
        duration=t["duration_s"],
        blend=t["blend_s"],
        dt=t["dt_s"],
        lock_joint=t["lock_joint"],
        vmax=math.radians(t["vmax_deg_s"]),
        amax=math.radians(t["amax_deg_s2"]),
        eps=t["eps_m"],
        kp=t["kp"],
    )


def rows_001() -> list[ReproductionRow]:
    """001: no number survived; NOTES-001's study on canadarm7, reported as ours only."""
    t = p001.TASK
    st = study_jump(load_robot("canadarm7"), notes_001_task(), n_samples=JUMP_FAILURE_TIMES, fix="auto")
    v = st.verification
    rows = [
        ReproductionRow(
            "001",
            "mean_reduction",
            f"mean velocity-jump reduction, kappa(t), failure at every {1e3 * t['dt_s']:g} ms step "
            "(NOTES-001 task, canadarm7)",
            LOST,
            f"{100 * v.mean_reduction:.1f} %",
            OURS_ONLY,
            "001's numbers did not survive; NOTES-001's task",
        ),
        ReproductionRow(
            "001",
            "share_improved",
            "share of failure times with a smaller jump",
            LOST,
            f"{100 * v.share_improved:.1f} %",
            OURS_ONLY,
            "",
        ),
        ReproductionRow(
            "001",
            "limits",
            f"kappa(t) keeps {t['vmax_deg_s']:g} deg/s, {t['amax_deg_s2']:g} deg/s^2, {1e3 * t['eps_m']:g} mm",
            LOST,
            "yes" if v.limits_ok else "no (fitted kappa(t) exceeds a limit)",
            OURS_ONLY,
            "",
        ),
    ]
    if st.verification_fixed is not None:
        f = st.verification_fixed
        rows.append(
            ReproductionRow(
                "001",
                "fixed",
                f"same with the {f.fix} fix: reduction / improved / limits",
                LOST,
                f"{100 * f.mean_reduction:.1f} % / {100 * f.share_improved:.1f} % / "
                + ("kept" if f.limits_ok else "broken"),
                OURS_ONLY,
                "",
            )
        )
    return rows
