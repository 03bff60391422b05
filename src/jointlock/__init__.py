"""jointlock: keep a space manipulator useful and safe after one of its joints locks.

Quick start::

    import numpy as np
    import jointlock as jl

    arm = jl.load_robot("halt7")                 # built-in, DH file or URDF
    crippled = jl.lock(arm, joint=4, angle=0.0)  # joints numbered from 1, as in the papers
    q = np.zeros((1000, crippled.dof))           # any leading batch shape
    J = jl.jacobian(crippled, q)                 # (1000, 6, 6), twist order (v, omega)

    plan = jl.plan_halt("halt7")                 # 000's whole halt strategy, typed result
    plan.summary(); plan.to_dict(); plan.write("out/halt")

    run = jl.run_scenario(jl.load_scenario("examples/halt_000.toml"))  # every job, in-process
    run.write("out/halt_000")                    # results.json, CSV, figures, report.html
"""

from __future__ import annotations

from ._lazy import lazy_attributes
from ._version import __version__
from .errors import (
    ConfigurationError,
    InfeasibleError,
    JointlockError,
    ModelError,
    ScenarioError,
    SingularityWarning,
)

#: The core (models, kinematics, dynamics, readers), imported on first use like everything else:
#: ``import jointlock`` stays light, so the command line can handle Ctrl-C from its first line.
_CORE = {
    "from_dh": "jointlock.dh",
    "InverseDynamics": "jointlock.dynamics",
    "base_wrench": "jointlock.dynamics",
    "generalized_inertia": "jointlock.dynamics",
    "joint_torques": "jointlock.dynamics",
    "mass_matrix": "jointlock.dynamics",
    "rnea": "jointlock.dynamics",
    "system_mass_matrix": "jointlock.dynamics",
    "read_model_toml": "jointlock.io",
    "read_urdf": "jointlock.io",
    "ChainState": "jointlock.kinematics",
    "VirtualManipulator": "jointlock.kinematics",
    "base_jacobian": "jointlock.kinematics",
    "chain_state": "jointlock.kinematics",
    "com_jacobians": "jointlock.kinematics",
    "com_positions": "jointlock.kinematics",
    "ee_pose": "jointlock.kinematics",
    "generalized_jacobian": "jointlock.kinematics",
    "jacobian": "jointlock.kinematics",
    "link_poses": "jointlock.kinematics",
    "momentum": "jointlock.kinematics",
    "momentum_matrix": "jointlock.kinematics",
    "system_com": "jointlock.kinematics",
    "virtual_link_vectors": "jointlock.kinematics",
    "virtual_manipulator": "jointlock.kinematics",
    "lock": "jointlock.locking",
    "lock_joints": "jointlock.locking",
    "ArmModel": "jointlock.model",
    "Body": "jointlock.model",
    "Joint": "jointlock.model",
    "LockedJoint": "jointlock.model",
    "as_joint_array": "jointlock.model",
    "BUILTIN_ROBOTS": "jointlock.robots",
    "load_robot": "jointlock.robots",
    "UrdfChain": "jointlock.robots",
    "Box": "jointlock.shapes",
    "Capsule": "jointlock.shapes",
    "Convex": "jointlock.shapes",
    "Sphere": "jointlock.shapes",
    "Clearance": "jointlock.collision",
    "clearance": "jointlock.collision",
    "ClearanceSettings": "jointlock.collision",
    "compiled_kernels": "jointlock.compiled",
    "compiled_mode": "jointlock.compiled",
    "set_compiled_mode": "jointlock.compiled",
}

#: Capability entry points, imported on first use (they pull in scipy.optimize and friends).
_LAZY = {
    **_CORE,
    "kinematic_indices": "jointlock.analysis.ability",
    "ahp_weights": "jointlock.analysis.ability",
    "entropy_weights": "jointlock.analysis.ability",
    "optimal_halt_configuration": "jointlock.planning.halt_config",
    "HaltConfiguration": "jointlock.planning.halt_config",
    "HaltProblem": "jointlock.planning.halt_motion",
    "HaltMotion": "jointlock.planning.halt_motion",
    "optimal_halt_motion": "jointlock.planning.halt_motion",
    "adaptive_ga": "jointlock.planning.ga",
    "Task": "jointlock.planning.task",
    "load_task_file": "jointlock.planning.task",
    "task_completion": "jointlock.planning.completion",
    "TaskCompletion": "jointlock.planning.completion",
    "WheelCapacity": "jointlock.analysis.attitude_control",
    "attitude_control_check": "jointlock.analysis.attitude_control",
    "JumpScenario": "jointlock.planning.jump",
    "simulate": "jointlock.planning.jump",
    "jump_at_time": "jointlock.planning.jump",
    "study_jump": "jointlock.planning.jump",
    "jacobian_derivatives": "jointlock.derivatives",
    "manipulability_gradient": "jointlock.derivatives",
    "solve_ik": "jointlock.ik",
    "ik_closed_form": "jointlock.ik",
    "ik_numeric": "jointlock.ik",
    "gamma_sweep": "jointlock.planning.replan",
    "gammas_for_lock": "jointlock.planning.replan",
    "replan_line": "jointlock.planning.replan",
    "compare_workspaces": "jointlock.analysis.workspace",
    "ee_positions": "jointlock.kinematics",
    # jobs: one call per job, typed results with to_dict() / summary() / write()
    **{name: "jointlock.jobs" for name in (
        "plan_halt", "HaltPlan", "FailureState", "JointLimits", "halt_limits",
        "HaltLimits", "HaltSearch", "HaltMotionSettings",
        "study_halt_configuration", "HaltConfigurationStudy",
        "run_jump_study", "JumpJobResult",
        "find_tolerance_angle", "ToleranceAngleResult",
        "plan_replan", "ReplanJobResult",
        "study_workspace", "WorkspaceStudy",
        "study_singularity", "verify_singularity_conditions", "search_singularities",
        "ReproductionReport",
        "describe_configuration", "KinematicsReport", "inverse_kinematics", "InverseKinematicsReport",
    )},  # fmt: skip
    "reproduce": "jointlock.jobs.reproduction",
    # scenarios in-process
    "load_scenario": "jointlock.scenario",
    "scenario_from_dict": "jointlock.scenario",
    "Scenario": "jointlock.scenario",
    "run_scenario": "jointlock.run",
    "RunResult": "jointlock.run",
    "run_demo": "jointlock.run._demo",
    "audit": "jointlock.campaign",  # every joint x instant of a planned motion (jointlock audit)
    # simulators
    "mjcf_text": "jointlock.mjcf",
    "write_mjcf": "jointlock.mjcf",
}

#: Subpackages reachable as attributes (``jl.plots``, ``jl.jobs``, ``jl.papers``), imported on first use.
_LAZY_MODULES = ("io", "plots", "jobs", "papers", "run", "report", "scenario", "analysis", "planning")


__getattr__, __dir__ = lazy_attributes(__name__, _LAZY, _LAZY_MODULES, globals())


__all__ = [
    "audit",
    "compiled_kernels",
    "compiled_mode",
    "set_compiled_mode",
    "Task",
    "load_task_file",
    "task_completion",
    "TaskCompletion",
    "WheelCapacity",
    "attitude_control_check",
    "mjcf_text",
    "write_mjcf",
    "ArmModel",
    "InverseDynamics",
    "base_wrench",
    "joint_torques",
    "rnea",
    "BUILTIN_ROBOTS",
    "Body",
    "Box",
    "Capsule",
    "Convex",
    "ChainState",
    "Clearance",
    "ClearanceSettings",
    "ConfigurationError",
    "InfeasibleError",
    "Joint",
    "JointlockError",
    "LockedJoint",
    "ModelError",
    "ScenarioError",
    "SingularityWarning",
    "Sphere",
    "VirtualManipulator",
    "__version__",
    "as_joint_array",
    "base_jacobian",
    "chain_state",
    "clearance",
    "com_jacobians",
    "com_positions",
    "ee_pose",
    "io",
    "read_model_toml",
    "read_urdf",
    "from_dh",
    "generalized_inertia",
    "generalized_jacobian",
    "jacobian",
    "link_poses",
    "load_robot",
    "UrdfChain",
    "lock",
    "lock_joints",
    "mass_matrix",
    "momentum",
    "momentum_matrix",
    "system_com",
    "system_mass_matrix",
    "virtual_link_vectors",
    "virtual_manipulator",
]
