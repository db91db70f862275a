"""A Gymnasium 1.x environment: curvature tracking with one bending actuator, on MuJoCo 3.17
and 4.x (no dm_control).

:class:`CurvatureTrackingEnv` poses the task of the dm_env environment
(:mod:`mjeap.envs.environment`) with the same pieces (:mod:`mjeap.envs.tracking`): the drive is stepped
in lockstep with MuJoCo (one drive update per MuJoCo step, the voltage held over the control
interval), SI at the API. ``import mjeap`` registers it as ``mjeap/CurvatureTracking-v0``
(:mod:`mjeap.envs.registration`)::

    import gymnasium, mjeap
    env = gymnasium.make("mjeap/CurvatureTracking-v0", actuator="pedot-micro")

Rendering: the modes that work in the process are declared (:mod:`mjeap.envs.rendering`):
``rgb_array`` needs an OpenGL backend chosen before mujoco is imported, ``MUJOCO_GL=egl`` or
``osmesa`` (mjeap sets ``disable`` when MUJOCO_GL is unset); ``human`` a display.
"""
from __future__ import annotations

from typing import Callable, Optional, Tuple

import mujoco
import numpy as np

try:
    import gymnasium
    from gymnasium import spaces
except ImportError as e:  # pragma: no cover - the optional extra
    raise ImportError("mjeap.envs.gymnasium_env needs gymnasium 1.x: pip install 'mjeap[gym]'") from e

from ..model.catalog import get_actuator
from ..model.discretize import Payload
from ..drives import make_drive
from ..errors import ParameterError, check_integer, check_positive, check_range
from ..engines.loop import divergence_error, window_state
from ..simulation.scene import Scene, diverged
from .registration import register_envs
from .rendering import MAX_IMAGE_SIZE, SceneRenderer, check_render_mode, render_modes
from .system_env import float32_inside
from .tracking import (VoltageLimiter, check_curvature_range, check_mass_range, default_reference, draw_episode, observe, step_lockstep, tracking_reward, warn_heavy_range)

__all__ = ["CurvatureTrackingEnv", "ENV_ID"]

#: the id of :class:`CurvatureTrackingEnv` (:mod:`mjeap.envs.registration`)
ENV_ID = "mjeap/CurvatureTracking-v0"
#: MuJoCo's warnings of a state gone bad (with autoreset off the state is kept, not reset)
BAD_STATE_WARNINGS = (mujoco.mjtWarning.mjWARN_BADQPOS, mujoco.mjtWarning.mjWARN_BADQVEL,
                      mujoco.mjtWarning.mjWARN_BADQACC)


class CurvatureTrackingEnv(gymnasium.Env):
    """Track ``reference(t)`` (1/m; default a 0.05 Hz sine of 50 1/m, Dadras et al. 2021's closed-loop
    case) with the tip curvature of ``actuator``.

    * Action: the drive's voltage (V), a float32 ``Box`` of shape (1,) spanning the drive's
      safe range (float32 bounds rounded inwards); an action outside it is clipped, counted
      in ``info["saturated_steps"]`` and warned about once per episode. It is held for
      ``control_interval`` s (rounded to whole MuJoCo steps: :attr:`control_timestep`).
    * Observation: a ``Dict`` of float64 ``Box`` es, SI: ``tip_curvature`` (1/m, the arc
      through clamp and tip), ``reference`` (1/m), ``tip_position`` (m, clamp frame: axial,
      deflection, out of plane), ``drive_state`` (the drive's signals, names and units in
      :attr:`drive_state_names`) and ``current`` (A) for a drive that reports one.
    * Reward: ``reward_fn(kappa, kappa_ref)`` after each step, default a Gaussian of the
      error, 1 on target and 0.1 at ``reward_margin`` 1/m (as the dm_env task).
    * Episode: at every reset the payload mass is drawn uniformly in ``payload_mass_range``
      (kg; None: the nominal ``payload``) and the initial curvature in
      ``initial_curvature_range`` (1/m, within rollout's bounds), from the env's
      ``np_random`` (``reset(seed=...)``): the same seed gives the same episode and, for the
      same actions, the same trajectory. ``info["episode"]`` holds the draw.
    * ``terminated`` when the simulation diverges (a MuJoCo bad-state warning or a state
      that is not finite): ``info["divergence"]`` says why, the observation returned is the
      last finite one and the reward 0. ``truncated`` once ``time_limit`` s are simulated.

    The payload is changed in place (as :mod:`mjeap.envs.environment` does): timestep and
    damping stay those of the nominal payload. Parameters are checked before the scene is
    built, each refusal a :class:`~mjeap.ParameterError` naming the parameter and its range.
    """

    #: the modes that work in this process (:func:`~mjeap.envs.rendering.render_modes`); render_fps: per env
    metadata = {"render_modes": list(render_modes()), "render_fps": None}

    def __init__(self, actuator: str = "pedot-micro", reference: Optional[Callable[[float], float]] = None,
                 *, orientation: str = "up", payload: Optional[Payload] = Payload(12.6e-6, 6.27e-3),
                 payload_mass_range: Optional[Tuple[float, float]] = None,
                 initial_curvature_range: Tuple[float, float] = (0.0, 0.0), control_interval: float = 1e-2,
                 time_limit: float = 20.0, drive: Optional[str] = None, drive_params: Optional[dict] = None,
                 reward_margin: float = 5.0, reward_fn: Optional[Callable[[float, float], float]] = None,
                 segments: int = 20, render_mode: Optional[str] = None, width: int = 480, height: int = 480):
        # -- parameters, before any work --------------------------------------------------
        check_render_mode(render_mode)
        width = check_integer("width", width, 1, MAX_IMAGE_SIZE)
        height = check_integer("height", height, 1, MAX_IMAGE_SIZE)
        act = get_actuator(actuator)
        mass_range = check_mass_range(payload_mass_range)
        if mass_range is not None and payload is None:
            raise ParameterError("payload_mass_range", payload_mass_range,
                                 "None without a payload (give a nominal payload to randomise its mass)")
        self.initial_curvature_range = check_curvature_range(initial_curvature_range, act.length)
        self.reward_margin = check_positive("reward_margin", reward_margin, "1/m")
        time_limit = check_positive("time_limit", time_limit, "s")
        check_positive("control_interval", control_interval, "s")
        for name, f in (("reference", reference), ("reward_fn", reward_fn)):
            if f is not None and not callable(f):
                raise ParameterError(name, f, "None or a callable")

        # -- the scene and its drive ----------------------------------------------------
        self.scene = Scene(act, orientation=orientation, payload=payload, segments=segments)
        warn_heavy_range(mass_range, self.scene)       # the Scene's unit check, on the masses drawn
        self.drive = make_drive(drive, self.scene, **(drive_params or {}))
        check_range("control_interval", control_interval, self.scene.timestep, time_limit, "s")
        self.reference = default_reference if reference is None else reference
        self.reward_fn, self.payload_mass_range, self.time_limit = reward_fn, mass_range, time_limit
        self._n_sub = max(1, int(round(control_interval / self.scene.timestep)))
        #: the agent's step (s): control_interval rounded to whole MuJoCo steps
        self.control_timestep = self._n_sub * self.scene.timestep
        self._step_limit = time_limit / self.control_timestep     # as dm_control's control.Environment
        self.metadata = {**type(self).metadata, "render_fps": 1.0 / self.control_timestep}
        self._limiter = VoltageLimiter()
        self._window = None
        self.episode, self._steps = {}, 0
        self.scene.reset()
        self.drive.reset(0.0)
        self.voltage = self.drive.rest_voltage()
        self._signal_names = list(self.drive.signals())
        self._last_obs = self._observe()          # at rest; reset() draws an episode

        # -- spaces -------------------------------------------------------------------------
        lo, hi = float32_inside(*([v] for v in self.drive.voltage_range()))
        self.action_space = spaces.Box(lo, hi, shape=(1,), dtype=np.float32)
        self.observation_space = spaces.Dict(
            {k: spaces.Box(-np.inf, np.inf, shape=v.shape, dtype=np.float64) for k, v in self._last_obs.items()})

        # -- rendering ----------------------------------------------------------------------
        self.render_mode = render_mode
        self._renderer = None if render_mode is None else \
            SceneRenderer(render_mode, self.scene.model, self.scene.data, width, height, self._side_camera())

    # -- read-outs ---------------------------------------------------------------------
    @property
    def drive_state_names(self):
        """Names (with units) of the entries of the ``drive_state`` observation."""
        return list(self._signal_names)

    def _observe(self):
        return dict(observe(self.scene, self.drive, self.reference, self._signal_names))

    def _info(self) -> dict:
        return {"time_s": self.scene.time, "voltage_V": self.voltage,
                "saturated_steps": self._limiter.saturated_steps, "episode": dict(self.episode)}

    def _divergence(self) -> str:
        """'' while the simulation is sound, else why not: the rollout loop's message and
        MuJoCo's bad-state warnings."""
        d = self.scene.data
        warned = [w.name for w in BAD_STATE_WARNINGS if d.warning[w].number > 0]
        if not warned and not diverged(d):
            return ""
        why = str(divergence_error(self.scene, self.drive, self.voltage, self.scene.step_count,
                                   window=(self._window, self._n_sub)))
        return why + (f" MuJoCo warned: {', '.join(warned)}." if warned else "")

    # -- the Gymnasium API -------------------------------------------------------------
    @property
    def dt(self) -> float:
        """The agent's step in s (Gymnasium's MuJoCo environments' ``dt``: the model's timestep
        times the MuJoCo steps per action): :attr:`control_timestep`."""
        return self.control_timestep

    def reset(self, *, seed: Optional[int] = None, options: Optional[dict] = None):
        """Start an episode: the payload mass and initial curvature drawn from ``np_random``
        (seeded by ``seed``), the beam at rest as a uniform arc, the drive reset. ``options``
        takes nothing (None or {})."""
        super().reset(seed=seed)
        if options:
            raise ParameterError("options", options, "None or {} (an episode is drawn from the env's ranges)")
        self.episode = draw_episode(self.scene, self.np_random, self.payload_mass_range,
                                    self.initial_curvature_range)
        kappa0 = self.episode["initial_curvature_per_m"]
        self.scene.reset(curvature=kappa0)
        self.drive.reset(kappa0)
        self.voltage = self.drive.rest_voltage()
        self._limiter.reset()
        self._steps = 0
        self._last_obs = self._observe()
        return self._copy(self._last_obs), self._info()

    def step(self, action):
        """Hold the action's voltage (V) for one control step; returns (observation, reward,
        terminated, truncated, info) with ``info``: time_s, voltage_V (the voltage applied),
        saturated_steps, episode and, on divergence, divergence."""
        self.voltage = self._limiter(action, self.drive)
        self._window = window_state(self.scene, self._window)   # a divergence in this step replays from here
        step_lockstep(self.scene, self.drive, self.voltage, self._n_sub)
        self._steps += 1
        info = self._info()
        why = self._divergence()
        if why:
            info["divergence"] = why
            return self._copy(self._last_obs), 0.0, True, False, info
        self.scene.update_kinematics()
        obs = self._observe()
        k, ref = float(obs["tip_curvature"][0]), float(obs["reference"][0])
        reward = float(self.reward_fn(k, ref)) if self.reward_fn is not None else \
            tracking_reward(k, ref, self.reward_margin)
        self._last_obs = obs
        return self._copy(obs), reward, False, self._steps >= self._step_limit, info

    @staticmethod
    def _copy(obs):
        return {k: v.copy() for k, v in obs.items()}

    # -- rendering ---------------------------------------------------------------------
    def _side_camera(self) -> mujoco.MjvCamera:
        """A free camera on the hinge axis, looking at the bending plane (from above where
        the plane is horizontal), framing the model's extent."""
        m = self.scene.model
        cam = mujoco.MjvCamera()
        mujoco.mjv_defaultFreeCamera(m, cam)
        axis = self.scene.rotation[:, 2]
        look = axis if axis[2] <= 0 else -axis
        cam.azimuth = float(np.degrees(np.arctan2(look[1], look[0])))
        cam.elevation = float(np.degrees(np.arcsin(np.clip(look[2], -1.0, 1.0))))
        return cam

    def render(self):
        """An (height, width, 3) uint8 image of the beam now (``render_mode="rgb_array"``;
        ``"human"``: the viewer synchronised, None); None without a render mode; refused
        after :meth:`close`."""
        return None if self.render_mode is None else self._renderer.render()

    def close(self) -> None:
        """Release the renderer (its GL context or window); safe to call twice."""
        if self._renderer is not None:
            self._renderer.close()
        super().close()

register_envs()         # mjeap's ids, where ``import mjeap`` has not (a second call changes nothing)
