"""The dm_env environment's pieces without dm_control (:mod:`mjeap.envs.environment` makes it):
:class:`BeamPhysics` (a scene and its drive stepped in lockstep), :class:`CurvatureTrackingTask`
(the task, with dm_control's ``Task`` interface) and :class:`TrackingEnvironment` (dm_control's
``control.Environment`` semantics written on ``dm_env.Environment``), which run on MuJoCo 3.17
and 4.x. :mod:`mjeap.envs.dm_control_env` poses the same task and physics through dm_control
where its ``Physics`` runs (MuJoCo 3.x)."""
from __future__ import annotations

import collections
from typing import Callable, Optional, Tuple

import dm_env
import mujoco
import numpy as np
from dm_env import specs

from ..errors import DivergenceError, MjeapError, check_positive
from ..simulation.scene import Scene
from .tracking import check_curvature_range, check_mass_range, draw_episode, observe, step_lockstep, tracking_reward, VoltageLimiter
from ..versions import dm_control_problem

__all__ = ["BeamPhysics", "CurvatureTrackingTask", "TrackingEnvironment", "check_dm_control"]


class BeamPhysics:
    """A scene and its drive as the task's physics, without dm_control: ``model`` and ``data``
    (the scene's), ``voltage`` (V, held over the next step), ``timestep()`` and ``time()``
    (s); ``step(n)`` runs the drive in lockstep with MuJoCo. The same contract as
    :class:`mjeap.envs.dm_control_env.DmControlBeamPhysics` (dm_control's ``Physics``), and the
    same arithmetic: ``reset`` and ``after_reset`` recompute the state with actuation disabled,
    a step that raises one of MuJoCo's warnings is refused (dm_control's ``PhysicsError``,
    here a :class:`~mjeap.DivergenceError` naming them)."""

    def __init__(self, scene: Scene, drive):
        self.scene, self.drive, self.voltage = scene, drive, 0.0

    @classmethod
    def from_scene(cls, scene: Scene, drive) -> "BeamPhysics":
        return cls(scene, drive)

    @property
    def model(self) -> mujoco.MjModel:
        return self.scene.model

    @property
    def data(self) -> mujoco.MjData:
        return self.scene.data

    def timestep(self) -> float:
        """MuJoCo timestep in s (the model runs in scaled internal units)."""
        return self.scene.timestep

    def time(self) -> float:
        """Simulated time in s."""
        return self.scene.time

    def forward(self) -> None:
        """``mj_forward`` with actuation disabled (dm_control's ``after_reset``)."""
        m = self.model
        flags = m.opt.disableflags
        m.opt.disableflags = flags | int(mujoco.mjtDisableBit.mjDSBL_ACTUATION)
        try:
            mujoco.mj_forward(m, self.data)
        finally:
            m.opt.disableflags = flags
        self._check_warnings(self._warnings())

    after_reset = forward

    def reset(self) -> None:
        """``mj_resetData``, then :meth:`forward` (dm_control's ``Physics.reset``)."""
        mujoco.mj_resetData(self.model, self.data)
        self.forward()

    def _warnings(self) -> np.ndarray:
        return np.array([w.number for w in self.data.warning])

    def _check_warnings(self, before: np.ndarray) -> None:
        new = self._warnings() > before
        if new.any():
            names = [w.name for w, n in zip(mujoco.mjtWarning, new) if n and w.name != "mjNWARNING"]
            raise DivergenceError(f"MuJoCo warned of an invalid physics state ({', '.join(names)}) at t = "
                                  f"{self.time():.6g} s, voltage {self.voltage:.4g} V; drive {self.drive.describe()}")

    def step(self, nstep: int = 1) -> None:
        before = self._warnings()
        step_lockstep(self.scene, self.drive, self.voltage, nstep)     # on the physics' model and data
        self._check_warnings(before)
        self.scene.check_finite()
        self.scene.update_kinematics()


class CurvatureTrackingTask:
    """Track ``reference(t)`` (1/m) with the tip curvature. Reward per step:
    ``reward_fn(kappa, kappa_ref)``, default a Gaussian of the error with width
    ``reward_margin`` (1/m), 1 on target (dm_control.utils.rewards.tolerance).

    Randomised at every reset (``random``: seed or numpy RandomState): the payload
    mass uniformly in ``payload_mass_range`` (kg, needs a scene with a payload), the initial
    curvature uniformly in ``initial_curvature_range`` (1/m, both bounds within rollout's:
    finite, at most a full circle over the beam). An action is one voltage (shape (1,));
    more values are refused, not cut. Actions outside the safe range
    are clipped, counted in ``saturated_steps`` and warned about once per episode. The task of
    both backends (dm_control's ``Task`` interface: :mod:`mjeap.envs.dm_control_env`)."""

    def __init__(self, reference: Callable[[float], float], payload_mass_range: Optional[Tuple[float, float]] = None,
                 initial_curvature_range: Tuple[float, float] = (0.0, 0.0), reward_margin: float = 5.0,
                 reward_fn: Optional[Callable[[float, float], float]] = None, random=None):
        # dm_control's base.Task draws from a RandomState (a seed, None or one given): so here
        self._random = random if isinstance(random, np.random.RandomState) else np.random.RandomState(random)
        self.reference = reference
        self.payload_mass_range = check_mass_range(payload_mass_range)
        self.initial_curvature_range = check_curvature_range(initial_curvature_range, None)   # bounds: per beam
        self.reward_margin = check_positive("reward_margin", reward_margin, "1/m")
        self.reward_fn = reward_fn
        self.limiter = VoltageLimiter("the action_spec")
        self.episode = {}
        self._signal_names = None           # the drive's signals: set at the first reset or observation

    @property
    def random(self) -> np.random.RandomState:
        """The task's generator (the episode draws)."""
        return self._random

    @property
    def saturated_steps(self) -> int:
        """Actions clipped to the safe range in this episode."""
        return self.limiter.saturated_steps

    # -- episode -----------------------------------------------------------------------
    def initialize_episode(self, physics: BeamPhysics) -> None:
        sc = physics.scene
        sc.part.after_data_reset()          # Physics.reset cleared xfrc_applied: the tip loads persist
        check_curvature_range(self.initial_curvature_range, sc.layout.length)
        self.episode = draw_episode(sc, self.random, self.payload_mass_range, self.initial_curvature_range)
        kappa0 = self.episode["initial_curvature_per_m"]
        if kappa0:
            sc.set_hinge_angles(np.full(sc.layout.segments, kappa0 * sc.layout.ds))
        sc.step_count = 0
        physics.drive.reset(kappa0)
        physics.voltage = physics.drive.rest_voltage()
        self.limiter.reset()
        self._signal_names = list(physics.drive.signals())

    def action_spec(self, physics: BeamPhysics):
        lo, hi = physics.drive.voltage_range()
        return specs.BoundedArray((1,), np.float64, lo, hi, name="voltage (V)")

    def before_step(self, action, physics: BeamPhysics) -> None:
        physics.voltage = self.limiter(action, physics.drive)

    def after_step(self, physics: BeamPhysics) -> None:
        """Nothing after a step (dm_control's Task hook)."""

    def get_termination(self, physics: BeamPhysics):
        """None: an episode ends at its time limit only (a diverged step raises)."""
        return None

    # -- read-outs ---------------------------------------------------------------------
    def get_observation(self, physics: BeamPhysics):
        """tip_curvature (1/m), reference (1/m), tip_position (m, clamp frame), drive_state
        (SI, see drive_state_names) and current (A) where the drive reports one."""
        if self._signal_names is None:      # before the first reset (an agent reads the specs first)
            self._signal_names = list(physics.drive.signals())
        return observe(physics.scene, physics.drive, self.reference, self._signal_names)

    @property
    def drive_state_names(self):
        return list(self._signal_names or ())

    def get_reward(self, physics: BeamPhysics) -> float:
        sc = physics.scene
        k, ref = sc.tip_curvature(), float(self.reference(sc.time))
        if self.reward_fn is not None:
            return float(self.reward_fn(k, ref))
        return tracking_reward(k, ref, self.reward_margin)


class TrackingEnvironment(dm_env.Environment):
    """A dm_env environment of a task and its physics without dm_control: dm_control's
    ``control.Environment`` semantics (its reset and step, ``n_sub_steps`` physics steps per
    agent step, the time limit as a truncation with discount 1, a step after the last one
    starting a new episode), with ``physics``, ``task`` and ``control_timestep()`` as there."""

    def __init__(self, physics: BeamPhysics, task: CurvatureTrackingTask, time_limit: float = float("inf"),
                 n_sub_steps: int = 1):
        self._physics, self._task = physics, task
        self._n_sub_steps = int(n_sub_steps)
        self._step_limit = float("inf") if time_limit == float("inf") else \
            time_limit / (physics.timestep() * self._n_sub_steps)
        self._step_count, self._reset_next_step = 0, True

    @property
    def physics(self) -> BeamPhysics:
        return self._physics

    @property
    def task(self) -> CurvatureTrackingTask:
        return self._task

    def control_timestep(self) -> float:
        """The interval between agent actions in s."""
        return self._physics.timestep() * self._n_sub_steps

    def reset(self) -> dm_env.TimeStep:
        self._reset_next_step, self._step_count = False, 0
        try:
            self._physics.reset()
        except DivergenceError:         # as dm_control's reset_context: the episode's state is set next
            pass
        self._task.initialize_episode(self._physics)
        self._physics.after_reset()
        return dm_env.restart(self._task.get_observation(self._physics))

    def step(self, action) -> dm_env.TimeStep:
        if self._reset_next_step:
            return self.reset()
        self._task.before_step(action, self._physics)
        self._physics.step(self._n_sub_steps)
        self._task.after_step(self._physics)
        reward = self._task.get_reward(self._physics)
        observation = self._task.get_observation(self._physics)
        self._step_count += 1
        discount = 1.0 if self._step_count >= self._step_limit else self._task.get_termination(self._physics)
        if discount is None:
            return dm_env.transition(reward, observation)
        self._reset_next_step = True
        return dm_env.TimeStep(dm_env.StepType.LAST, reward, discount, observation)

    def action_spec(self):
        return self._task.action_spec(self._physics)

    def observation_spec(self):
        """The observations' specs, from an observation (as control.Environment infers them)."""
        obs = self._task.get_observation(self._physics)
        return collections.OrderedDict((k, specs.Array(v.shape, v.dtype, name=k)) for k, v in obs.items())


def check_dm_control() -> None:
    """Refuse, naming the versions, where dm_control's Physics cannot run on this MuJoCo."""
    why = dm_control_problem()
    if why:
        raise MjeapError(f"no dm_control environment here (backend='dm_env' runs on this MuJoCo): {why}")
