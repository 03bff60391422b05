"""One locked arm in MuJoCo for a replay (:class:`_Player`): the model written by
:func:`jointlock.mjcf.mjcf_text` with brakes, contacts and limits off, the indices a replay needs,
what it records at each instant, and MuJoCo's warnings caught (an unstable replay is one
:class:`~jointlock.errors.ModelError`)."""

from __future__ import annotations

from typing import Any

import numpy as np

from ..analysis.spacecraft import SpacecraftResponse
from ..errors import ConfigurationError, ModelError
from ..mjcf import mjcf_text
from ..model import ArmModel, FloatArray
from ._replay import Replay

#: The one line a user without the extra sees.
MUJOCO_MISSING = "the MuJoCo check needs MuJoCo: pip install 'jointlock[mujoco]' (or pip install mujoco)"


def _mujoco() -> Any:
    try:
        import mujoco
    except ImportError:
        raise ConfigurationError(MUJOCO_MISSING) from None
    return mujoco


def require_mujoco() -> None:
    """Raise :data:`MUJOCO_MISSING` now (before a long computation whose motions would be
    replayed) when MuJoCo is not installed."""
    _mujoco()


class _Player:
    """A locked arm in MuJoCo (:func:`~jointlock.mjcf.mjcf_text` with brakes), contacts and
    control limits off, with the indices a replay needs, and what it records at each instant.
    Used as a context manager: MuJoCo's warnings are caught (no ``MUJOCO_LOG.TXT`` in the
    user's folder) and an unstable replay raises one :class:`ModelError`."""

    def __init__(
        self, model: ArmModel, floating: bool, timestep: float, samples: int, *, brakes_engaged: bool = True
    ) -> None:
        mujoco = self.mujoco = _mujoco()
        chain = model.unlocked if model.locked else model
        assert chain is not None
        mode = "floating" if floating else "fixed"
        text = mjcf_text(model, brakes=True, timestep=timestep, base=mode, brakes_engaged=brakes_engaged)
        try:
            self.mm = mujoco.MjModel.from_xml_string(text)
        except ValueError as exc:  # MuJoCo's compiler refused the model
            raise ModelError(f"MuJoCo cannot load {model.name!r}: {' '.join(str(exc).split())}") from None
        # contacts off (the clearance is jointlock's), and the joint limits: a motion that leaves
        # them is jointlock's to report, not MuJoCo's to stop
        self.mm.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONTACT | mujoco.mjtDisableBit.mjDSBL_LIMIT
        self.mm.actuator_ctrllimited[:] = 0
        self.data = mujoco.MjData(self.mm)
        self.floating, self.timestep = floating, timestep
        free = 7 if floating else 0
        numbers = list(chain.joint_numbers)
        #: qpos index of each joint of the chain (its number's order), and of the model's healthy
        #: and locked joints; qvel has 6 free coordinates where qpos has 7
        self.qpos = np.array([free + numbers.index(j) for j in numbers], dtype=int)
        self.healthy = np.array([free + numbers.index(j) for j in model.joint_numbers], dtype=int)
        self.braked = np.array([free + numbers.index(lj.number) for lj in model.locked], dtype=int)
        self.shift = 1 if floating else 0
        self.lock_angles = np.array([lj.angle for lj in model.locked])
        self.base_body = mujoco.mj_name2id(self.mm, mujoco.mjtObj.mjOBJ_BODY, "base")
        if floating:
            self.data.qpos[3:7] = [1.0, 0.0, 0.0, 0.0]
        self.q = np.empty((samples, self.healthy.size))
        self.locked_angle = np.empty((samples, self.braked.size))
        self.brake = np.empty((samples, self.braked.size))
        self.attitude = np.empty((samples, 4)) if floating else None
        self.com = np.empty((samples, 3)) if floating else None
        self.rate = np.empty((samples, 3)) if floating else None
        self.caught: list[str] = []

    def __enter__(self) -> _Player:
        self._previous = self.mujoco.get_mju_user_warning()
        self.mujoco.set_mju_user_warning(self.caught.append)
        return self

    def __exit__(self, *exc: object) -> None:
        self.mujoco.set_mju_user_warning(self._previous)

    def record(self, k: int) -> bool:
        """Compute the state's forces (:func:`mujoco.mj_forward`: the brake's constraint torque)
        and record sample ``k``; False once MuJoCo has warned (the replay is unstable)."""
        data = self.data
        self.mujoco.mj_forward(self.mm, data)
        self.q[k] = data.qpos[self.healthy]
        self.locked_angle[k] = data.qpos[self.braked] - self.lock_angles
        self.brake[k] = data.qfrc_constraint[self.braked - self.shift]
        if self.attitude is not None and self.com is not None and self.rate is not None:
            self.attitude[k] = data.qpos[3:7]
            self.com[k] = data.xipos[self.base_body]
            self.rate[k] = data.qvel[3:6]
        return not self.caught

    def step(self, ctrl: FloatArray) -> None:
        self.data.ctrl[:] = ctrl
        self.mujoco.mj_step(self.mm, self.data)

    def result(
        self,
        model: ArmModel,
        label: str,
        t: FloatArray,
        q_ref: FloatArray,
        brake_ref: FloatArray,
        reference: SpacecraftResponse | None,
    ) -> Replay:
        """The :class:`Replay` of what was recorded (one :class:`ModelError` if it diverged)."""
        if self.caught or not (np.all(np.isfinite(self.q)) and np.all(np.isfinite(self.brake))):
            raise ModelError(
                f"the MuJoCo replay of {label} became unstable ({(self.caught or ['non-finite state'])[0].strip()}); "
                f"try a smaller timestep than {self.timestep:g} s"
            )
        com = None if self.com is None else self.com - self.com[0]
        return Replay(
            label=label,
            t=t,
            joint_numbers=model.joint_numbers,
            locked_numbers=tuple(lj.number for lj in model.locked),
            q=self.q,
            q_ref=q_ref,
            locked_angle=self.locked_angle,
            brake=self.brake,
            brake_ref=brake_ref.reshape(t.size, -1),
            attitude=self.attitude,
            com_displacement=com,
            angular_velocity=self.rate,
            reference=reference if self.floating else None,
            timestep=float(self.timestep),
            mujoco_version=str(self.mujoco.__version__),
        )


def _check_base(model: ArmModel, base: str | None) -> bool:
    """Whether the replay floats the spacecraft (``base``: None, the model's; or as given)."""
    if base not in (None, "fixed", "floating") or (base == "floating" and not model.floating):
        raise ConfigurationError(
            f"base must be 'fixed', or 'floating' for a model with a spacecraft ({model.name!r} floats: "
            f"{model.floating}); got {base!r}"
        )
    if model.locked and model.unlocked is None:
        raise ModelError(f"{model.name!r}: the replay needs the unlocked arm to hold the locked joints by brakes")
    return model.floating if base is None else base == "floating"
