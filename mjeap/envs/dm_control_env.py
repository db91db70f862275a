"""The dm_env environment through dm_control (MuJoCo 3.x): ``control.Environment`` with the
curvature-tracking task (:class:`mjeap.envs.dm_tracking.CurvatureTrackingTask`) as a dm_control
``Task`` and the scene as a dm_control ``Physics``. Imported by
:func:`mjeap.envs.environment.make_environment` only where dm_control's Physics runs
(:func:`mjeap.versions.dm_control_problem`); elsewhere the same task runs on ``dm_env``
directly (:class:`mjeap.envs.dm_tracking.TrackingEnvironment`).

:class:`DmControlBeamPhysics` is a dm_control ``Physics`` on a :class:`mjeap.Scene`'s model
and data whose ``step`` runs the drive in lockstep with MuJoCo (one drive update per MuJoCo
step, the voltage held over the control interval), so ``control.Environment``'s sub-steps
keep the drive exact.
"""
from __future__ import annotations

from dm_control.mujoco import engine, wrapper
from dm_control.rl import control
from dm_control.suite import base

from ..errors import install_mujoco_warnings
from ..simulation.scene import Scene
from .dm_tracking import CurvatureTrackingTask, check_dm_control
from .tracking import step_lockstep

install_mujoco_warnings()         # dm_control's import installed its own MuJoCo warning handler

__all__ = ["DmControlBeamPhysics", "DmControlTrackingTask", "make_dm_control_environment"]


class DmControlBeamPhysics(engine.Physics):
    """dm_control Physics sharing a Scene's MjModel and MjData; stepping also steps the drive."""

    @classmethod
    def from_scene(cls, scene: Scene, drive) -> "DmControlBeamPhysics":
        check_dm_control()
        physics = cls.from_model(wrapper.MjModel(scene.model))
        scene.data = physics.data.ptr       # the scene's read-outs now see the physics' state
        physics.scene, physics.drive, physics.voltage = scene, drive, 0.0
        return physics

    def timestep(self) -> float:
        """MuJoCo timestep in s (the model runs in scaled internal units)."""
        return self.scene.timestep

    def time(self) -> float:
        """Simulated time in s."""
        return self.scene.time

    def step(self, nstep: int = 1) -> None:
        with self.check_invalid_state():
            step_lockstep(self.scene, self.drive, self.voltage, nstep)     # on the physics' model and data
        self.scene.check_finite()
        self.scene.update_kinematics()


class DmControlTrackingTask(CurvatureTrackingTask, base.Task):
    """:class:`~mjeap.envs.dm_tracking.CurvatureTrackingTask` as a dm_control ``Task``."""

    def __init__(self, *args, **kwargs):
        CurvatureTrackingTask.__init__(self, *args, **kwargs)
        base.Task.__init__(self, random=self.random)


def make_dm_control_environment(scene: Scene, drive, reference, *, payload_mass_range, initial_curvature_range,
                                reward_margin: float, seed, time_limit: float, n_sub: int) -> control.Environment:
    """``control.Environment`` of the task on ``scene`` with ``drive`` (the parameters checked
    by :func:`mjeap.envs.environment.make_environment`)."""
    physics = DmControlBeamPhysics.from_scene(scene, drive)
    task = DmControlTrackingTask(reference, payload_mass_range, initial_curvature_range, reward_margin, random=seed)
    return control.Environment(physics, task, time_limit=time_limit, n_sub_steps=n_sub)
