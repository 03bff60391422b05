"""jointlock: keep a space manipulator useful and safe after one of its joints locks.

Quick start::

    import numpy as np
    import jointlock as jl

    arm = jl.load_robot("halt7")                 # built-in, DH file or URDF
    crippled = jl.lock(arm, joint=4, angle=0.0)  # joints numbered from 1, as in the papers
    q = np.zeros((1000, crippled.dof))           # any leading batch shape
    J = jl.jacobian(crippled, q)                 # (1000, 6, 6), twist order (v, omega)
"""

from __future__ import annotations

from . import io
from .dh import from_dh
from .dynamics import (
    InverseDynamics,
    base_wrench,
    generalized_inertia,
    joint_torques,
    mass_matrix,
    rnea,
    system_mass_matrix,
)
from .errors import (
    ConfigurationError,
    InfeasibleError,
    JointlockError,
    ModelError,
    ScenarioError,
    SingularityWarning,
)
from .io import read_model_toml, read_urdf
from .kinematics import (
    ChainState,
    VirtualManipulator,
    base_jacobian,
    chain_state,
    com_jacobians,
    com_positions,
    ee_pose,
    generalized_jacobian,
    jacobian,
    link_poses,
    momentum,
    momentum_matrix,
    system_com,
    virtual_link_vectors,
    virtual_manipulator,
)
from .locking import lock, lock_joints
from .model import ArmModel, Body, Joint, LockedJoint, as_joint_array
from .robots import BUILTIN_ROBOTS, load_robot

__version__ = "0.1.0"

#: Capability entry points, imported on first use (they pull in scipy.optimize and friends).
_LAZY = {
    "kinematic_indices": "jointlock.analysis.ability",
    "ahp_weights": "jointlock.analysis.ability",
    "entropy_weights": "jointlock.analysis.ability",
    "optimal_halt_configuration": "jointlock.planning.halt_config",
    "HaltConfiguration": "jointlock.planning.halt_config",
    "HaltProblem": "jointlock.planning.halt_motion",
    "HaltMotion": "jointlock.planning.halt_motion",
    "optimal_halt_motion": "jointlock.planning.halt_motion",
    "adaptive_ga": "jointlock.planning.ga",
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
}


def __getattr__(name: str):
    if name in _LAZY:
        import importlib

        return getattr(importlib.import_module(_LAZY[name]), name)
    raise AttributeError(f"module 'jointlock' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_LAZY))


__all__ = [
    "ArmModel",
    "InverseDynamics",
    "base_wrench",
    "joint_torques",
    "rnea",
    "BUILTIN_ROBOTS",
    "Body",
    "ChainState",
    "ConfigurationError",
    "InfeasibleError",
    "Joint",
    "JointlockError",
    "LockedJoint",
    "ModelError",
    "ScenarioError",
    "SingularityWarning",
    "VirtualManipulator",
    "__version__",
    "as_joint_array",
    "base_jacobian",
    "chain_state",
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
