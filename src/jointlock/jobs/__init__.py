"""Jobs: one library call per job, typed inputs in, a typed, picklable result out.

Each result has ``to_dict()`` (the JSON of ``jointlock COMMAND --json``), ``summary()`` (the
lines the command prints) and ``write(out)`` (the files of ``--out``); figures come from
:mod:`jointlock.plots`.  The command line only parses options, calls these and prints.
``<job>_from_scenario(data, previous)`` runs a job of a scenario (:func:`jointlock.run_scenario`).

==========================  ==================================================  =====
job                         call                                                paper
==========================  ==================================================  =====
halt                        :func:`plan_halt` -> :class:`HaltPlan`              000
halt_config                 :func:`study_halt_configuration`                    000
jump                        :func:`run_jump_study`                              001
tolerance_angle             :func:`find_tolerance_angle`                        002
replan                      :func:`plan_replan`                                 002
workspace                   :func:`study_workspace`                             002
singular                    :func:`study_singularity`, :func:`verify_singularity_conditions`,
                            :func:`search_singularities`                        004
reproduce                   :func:`reproduce` (every seed's headline figures)
kinematics                  :func:`describe_configuration` (pose, Jacobian, σ)
ik                          :func:`inverse_kinematics` (every branch, nearest)  002
==========================  ==================================================  =====

The job modules are imported on first use.
"""

from __future__ import annotations

from .._lazy import lazy_attributes
from ._common import JobResult

#: Public names of each job module (imported on first use).
_NAMES: dict[str, tuple[str, ...]] = {
    "halt": (
        "plan_halt", "HaltPlan", "FailureState", "JointLimits", "halt_limits", "halt_model",
        "HaltLimits", "HaltSearch", "HaltMotionSettings",
    ),  # fmt: skip
    "halt_config": ("study_halt_configuration", "HaltConfigurationStudy", "ReachabilitySettings"),
    "jump": ("run_jump_study", "JumpJobResult"),
    "tolerance_angle": ("find_tolerance_angle", "ToleranceAngleResult"),
    "replan": ("plan_replan", "ReplanJobResult"),
    "workspace": ("study_workspace", "WorkspaceStudy"),
    "singular": (
        "study_singularity",
        "verify_singularity_conditions",
        "search_singularities",
        "SingularityResult",
        "ConditionVerificationResult",
        "SingularitySearchResult",
    ),
    "reproduction": ("reproduce", "ReproductionReport"),
    "kinematics": ("describe_configuration", "KinematicsReport"),
    "ik": ("inverse_kinematics", "InverseKinematicsReport"),
}
_WHERE = {name: module for module, names in _NAMES.items() for name in names}
_MODULES = tuple(_NAMES)


__getattr__, __dir__ = lazy_attributes(
    __name__, {name: f"{__name__}.{module}" for name, module in _WHERE.items()}, _MODULES, globals()
)


__all__ = ["JobResult", *_WHERE]
