"""A robot (a :class:`~mjeap.System`) as a Gymnasium environment: what the robot tasks
(:mod:`mjeap.envs.hamr_walk`, :mod:`mjeap.envs.gripper_grasp`) share.

The action is one voltage per driven actuator (V, the drives' safe ranges as float32 bounds
rounded inwards), held for ``control_interval`` s rounded to whole MuJoCo steps; the drives
run in the compiled model (native), as :meth:`System.rollout` runs them. An action outside
the range is clipped and counted (``info["saturated_steps"]``). A state that blows up ends
the episode (``terminated``, ``info["divergence"]``, reward 0); ``truncated`` once
``time_limit`` s are simulated. ``reset`` puts the robot at its builder's start (qpos0, the
beams straight, the drives at rest, contacts and warm starts cleared: mj_resetData), so the
same seed and actions give the same trajectory, contacts included.
"""
from __future__ import annotations

from typing import Optional

import gymnasium
import numpy as np
from gymnasium import spaces

from ..errors import DivergenceError, ParameterError, check_positive, check_range
from ..simulation.system import System
from .rendering import SceneRenderer, check_render_mode, render_modes

__all__ = ["SystemEnv", "float32_inside"]


def float32_inside(lo, hi):
    """float32 bounds inside [lo, hi] (arrays): a sampled action is never clipped by the float64 check."""
    lo, hi = np.asarray(lo, dtype=float), np.asarray(hi, dtype=float)
    l32, h32 = lo.astype(np.float32), hi.astype(np.float32)
    l32 = np.where(l32 < lo, np.nextafter(l32, np.float32(np.inf)), l32)
    h32 = np.where(h32 > hi, np.nextafter(h32, np.float32(-np.inf)), h32)
    return l32.astype(np.float32), h32.astype(np.float32)


class SystemEnv(gymnasium.Env):
    """Base of the robot environments: a subclass builds its :class:`System`, passes it here
    and defines :meth:`_observe` (a float64 vector, SI), :meth:`_reward` and
    :meth:`_terminated` (both after a step; the latter returns '' or why the episode
    ended), and may define :meth:`_before_step` (e.g. a scripted host motion)."""

    metadata = {"render_modes": list(render_modes()), "render_fps": None}

    def __init__(self, system: System, control_interval: float, time_limit: float,
                 render_mode: Optional[str] = None, width: int = 480, height: int = 480, camera=None):
        check_render_mode(render_mode)
        self.time_limit = check_positive("time_limit", time_limit, "s")
        check_range("control_interval", control_interval, system.timestep, self.time_limit, "s")
        self.system = system
        self.driven = [a for a in system.actuators if a.drive is not None]
        if not self.driven:
            raise ParameterError("system", "no driven actuator", "a system with at least one driven actuator")
        self._n_sub = max(1, int(round(control_interval / system.timestep)))
        #: the agent's step (s): control_interval rounded to whole MuJoCo steps
        self.control_timestep = self._n_sub * system.timestep
        self._step_limit = int(round(self.time_limit / self.control_timestep))
        self.metadata = {**type(self).metadata, "render_fps": 1.0 / self.control_timestep}
        #: the driven actuators' ctrl indices: an action, checked finite and clipped to the drives'
        #: safe ranges here, is written to them directly (System.set_voltages would check it again)
        self._ctrl = np.array([system.actuator_ids[system.index(a.prefix)] for a in self.driven], dtype=int)
        ranges = np.array([a.drive.voltage_range() for a in self.driven], dtype=float)
        self._v_lo, self._v_hi = ranges[:, 0], ranges[:, 1]
        lo, hi = float32_inside(self._v_lo, self._v_hi)
        self.action_space = spaces.Box(lo, hi, dtype=np.float32)
        self.system.reset()
        self._steps, self._saturated = 0, 0
        self.voltages = np.array([a.drive.rest_voltage() for a in self.driven])
        n = len(self._observe())
        self.observation_space = spaces.Box(-np.inf, np.inf, shape=(n,), dtype=np.float64)
        self.render_mode = render_mode
        self._renderer = None if render_mode is None else \
            SceneRenderer(render_mode, system.model, system.data, width, height, camera)

    # -- to define --------------------------------------------------------------------
    def _observe(self) -> np.ndarray:
        raise NotImplementedError

    def _reward(self) -> float:
        raise NotImplementedError

    def _terminated(self) -> str:
        return ""

    def _before_step(self) -> None:
        """Called before each control step (the system at the step's start)."""

    def _episode_start(self) -> None:
        """Called at reset, after the system's reset, before the first observation."""

    # -- the Gymnasium API -------------------------------------------------------------
    @property
    def time(self) -> float:
        """Simulated time (s) since the episode began."""
        return self.system.time

    def _info(self) -> dict:
        return {"time_s": self.time, "voltages_V": self.voltages.copy(), "saturated_steps": self._saturated}

    @property
    def dt(self) -> float:
        """The agent's step in s (Gymnasium's MuJoCo environments' ``dt``: the model's timestep
        times the MuJoCo steps per action): :attr:`control_timestep`."""
        return self.control_timestep

    def reset(self, *, seed: Optional[int] = None, options: Optional[dict] = None):
        """Start an episode at the robot's start state (the seed seeds ``np_random``; the
        start itself is always the same). ``options`` takes nothing (None or {})."""
        super().reset(seed=seed)
        if options:
            raise ParameterError("options", options, "None or {} (the episode starts at the robot's start state)")
        self.system.reset()
        self._steps, self._saturated = 0, 0
        self.voltages = np.array([a.drive.rest_voltage() for a in self.driven])
        self._episode_start()
        if self.render_mode == "human":
            self.render()
        return self._observe(), self._info()

    def step(self, action):
        """Hold the action's voltages (V, one per driven actuator, clipped to their safe
        ranges) for one control step; returns (observation, reward, terminated, truncated,
        info) with ``info``: time_s, voltages_V (applied), saturated_steps and, when the
        episode ends early, divergence or ended."""
        a = np.asarray(action, dtype=float).reshape(-1)
        if a.shape != self._v_lo.shape or not np.all(np.isfinite(a)):
            raise ParameterError("action", action, f"{len(self._v_lo)} finite voltages (V), one per driven actuator")
        v = np.clip(a, self._v_lo, self._v_hi)
        self._saturated += int(np.any(v != a))
        self.voltages = v
        self.system.data.ctrl[self._ctrl] = v
        self._before_step()
        self._steps += 1
        info = self._info()
        try:
            self.system.step(self._n_sub)
        except DivergenceError as e:
            info["divergence"] = str(e)
            return self._last_obs(), 0.0, True, False, {**info, "time_s": self.time}
        obs = self._observe()
        reward = float(self._reward())
        why = self._terminated()
        if why:
            info["ended"] = why
        info["time_s"] = self.time
        if self.render_mode == "human":
            self.render()
        return obs, reward, bool(why), self._steps >= self._step_limit, info

    def _last_obs(self) -> np.ndarray:
        """The observation where the state is not finite: zeros in its place (the episode ends)."""
        obs = self._observe()
        return np.where(np.isfinite(obs), obs, 0.0)

    def render(self):
        """An (height, width, 3) uint8 image (``rgb_array``), the viewer synchronised
        (``human``, None), or None without a render mode."""
        return None if self._renderer is None else self._renderer.render()

    def close(self) -> None:
        """Release the renderer; safe to call twice."""
        if self._renderer is not None:
            self._renderer.close()
        super().close()
