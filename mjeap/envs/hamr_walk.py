"""``mjeap/HamrWalk-v0``: the HAMR-VI walker (:mod:`mjeap.robots.hamr_walk`) as a Gymnasium
environment, and its open-loop trot as a scripted baseline (:func:`trot_policy`,
:func:`run_trot`).

* The model: the walker of :func:`mjeap.robots.hamr_walk.build` with LEARNING_SEGMENTS = 2
  segments per actuator (the fewest an actuator takes) stepped at LEARNING_TIMESTEP = 100 us,
  a step sized for the loaded system (the transmissions' 80-100 Hz modes, 100-125 steps a
  period; the step's own damping h K is taken out of the legs' joints, and the contact's time
  constant is 2 steps, MuJoCo's floor) instead of the free beam's 4.51 us: the robot's trot
  runs within 5 % of the default model's speed at 10-65 Hz (docs/robots/hamr-walk.md) at
  about real time on one core (scripts/bench.py ``hamr_walk_env``). ``segments=4,
  timestep=None`` is the default model itself.
* Action: the eight actuators' voltages (V, 0..200 at the walker's 200 V bias), in the
  order of :attr:`HamrWalkEnv.actuator_names` (FL_swing, FL_lift, FR_swing, ...), held for
  ``control_interval`` s (default 0.5 ms, rounded to whole steps: 5 at 100 us).
* Observation (float64, SI, 27 values): the body's height above the ground (m), its
  orientation (quaternion, world), its velocity (m/s, world) and angular velocity (rad/s,
  body frame), the eight leg joints' angles (rad) and rates (rad/s), in the order of
  :attr:`HamrWalkEnv.observation_names`.
* Reward after each step: the body's forward speed over the step (m/s along the ground's x)
  divided by ``speed_scale`` (0.1 m/s, about the trot's at 10 Hz) plus ``upright_weight``
  (0.5) times the cosine of the body's tilt from the ground's normal.
* ``terminated`` on roll-over (tilt beyond ``rollover_deg``, 60 deg) or divergence;
  ``truncated`` after ``time_limit`` s (1 s).

The walker's own trot (:func:`mjeap.robots.hamr_walk.walk`) drives every MuJoCo step from
its waveforms; through the environment the same waveforms are held over each control step,
sampled at its middle (:func:`trot_policy`; by default the robot's trot drive,
:func:`mjeap.robots.hamr_walk.trot_drive`).
"""
from __future__ import annotations

import functools
from typing import Optional

import mujoco
import numpy as np

from ..errors import check_range
from ..robots.hamr_leg.model import design
from ..robots.hamr_walk.experiments import trot_drive, trot_durations, trot_voltages
from ..robots.hamr_walk.model import LEGS, MU, body_position, body_rotation, build, ground_rotation
from .rendering import check_render_mode
from .system_env import SystemEnv

__all__ = ["HamrWalkEnv", "ENV_ID", "trot_policy", "run_trot", "leg_design"]

ENV_ID = "mjeap/HamrWalk-v0"
SPEED_SCALE = 0.1           # m/s: the forward speed that earns a reward of 1 (the 10 Hz trot's 0.093 m/s)
UPRIGHT_WEIGHT = 0.5
ROLLOVER_DEG = 60.0         # deg: beyond this tilt the walker has rolled over
LEARNING_SEGMENTS = 2       # segments per actuator of the environment's walker
LEARNING_TIMESTEP = 1e-4    # s, its step, sized for the loaded system (see the module text)


@functools.lru_cache(maxsize=1)
def leg_design() -> dict:
    """hamr_leg.design() once per process (1.4 s; the same numbers every time)."""
    return design()


class HamrWalkEnv(SystemEnv):
    """HAMR-VI on a ground plane, walking under eight voltages (see the module text):
    ``control_interval`` and ``time_limit`` (s), the reward's ``speed_scale`` (m/s) and
    ``upright_weight``, the roll-over's ``rollover_deg``; the walker's ``mu`` (the feet's
    friction, 0.51), ``segments`` per actuator (LEARNING_SEGMENTS) and ``timestep`` (s,
    LEARNING_TIMESTEP; None: the actuators' own, the default model's); ``render_mode`` one of
    those that work here (:mod:`mjeap.envs.rendering`), ``width`` and ``height`` in pixels."""

    def __init__(self, control_interval: float = 5e-4, time_limit: float = 1.0, *, speed_scale: float = SPEED_SCALE,
                 upright_weight: float = UPRIGHT_WEIGHT, rollover_deg: float = ROLLOVER_DEG, mu: float = MU,
                 segments: int = LEARNING_SEGMENTS, timestep: Optional[float] = LEARNING_TIMESTEP,
                 render_mode: Optional[str] = None, width: int = 480, height: int = 480):
        check_render_mode(render_mode)          # before the robot is built
        self.speed_scale = check_range("speed_scale", speed_scale, 1e-6, 10.0, "m/s")
        self.upright_weight = check_range("upright_weight", upright_weight, 0.0, 100.0)
        self.rollover_deg = check_range("rollover_deg", rollover_deg, 0.0, 180.0, "deg", lo_open=True)
        system = build(mu, segments, d={k: dict(v) for k, v in leg_design().items()}, timestep=timestep)
        m = system.model
        self._G = ground_rotation(system)
        self._joints = [f"{leg}/{dof}" for leg in LEGS for dof in ("swing", "lift")]
        self._qadr = [int(m.jnt_qposadr[m.joint(j).id]) for j in self._joints]
        self._dadr = [int(m.jnt_dofadr[m.joint(j).id]) for j in self._joints]
        root = m.joint("root").id
        self._root_q, self._root_d = int(m.jnt_qposadr[root]), int(m.jnt_dofadr[root])
        camera = mujoco.MjvCamera()
        camera.type = mujoco.mjtCamera.mjCAMERA_TRACKING
        camera.trackbodyid = m.body("body").id
        camera.distance, camera.elevation, camera.azimuth = 80.0, -25.0, 135.0
        super().__init__(system, control_interval, time_limit, render_mode, width, height, camera)
        self._x_before = self._forward_position()

    @property
    def actuator_names(self) -> list:
        """The actions' order: the actuators' prefixes."""
        return [a.prefix.rstrip("/") for a in self.driven]

    @property
    def observation_names(self) -> list:
        """The observation's entries, with their units."""
        return (["height_m", "qw", "qx", "qy", "qz", "vx_m_s", "vy_m_s", "vz_m_s", "wx_rad_s", "wy_rad_s", "wz_rad_s"]
                + [f"{j}_rad" for j in self._joints] + [f"{j}_rad_s" for j in self._joints])

    # -- read-outs ---------------------------------------------------------------------
    def _forward_position(self) -> float:
        return float(body_position(self.system) @ self._G[:, 0])

    def tilt_deg(self) -> float:
        """The body's tilt (deg): its z axis from the ground's normal."""
        c = float(np.clip(body_rotation(self.system)[:, 2] @ self._G[:, 2], -1.0, 1.0))
        return float(np.degrees(np.arccos(c)))

    def _observe(self) -> np.ndarray:
        sy, d, u = self.system, self.system.data, self.system.units
        q, dq = self._root_q, self._root_d
        height = float(body_position(sy) @ self._G[:, 2])
        return np.concatenate([[height], d.qpos[q + 3:q + 7], d.qvel[dq:dq + 3] * u.length / u.time,
                               d.qvel[dq + 3:dq + 6] / u.time, d.qpos[self._qadr], d.qvel[self._dadr] / u.time])

    def _episode_start(self) -> None:
        self._x_before = self._forward_position()

    def _reward(self) -> float:
        x = self._forward_position()
        speed = (x - self._x_before) / self.control_timestep
        self._x_before = x
        return speed / self.speed_scale + self.upright_weight * np.cos(np.radians(self.tilt_deg()))

    def _terminated(self) -> str:
        tilt = self.tilt_deg()
        return f"rolled over: tilt {tilt:.1f} deg > {self.rollover_deg:g} deg" if tilt > self.rollover_deg else ""


def trot_policy(env: HamrWalkEnv, frequency: float, amplitude: Optional[float] = None,
                lift_amplitude: Optional[float] = None):
    """The walker's open-loop trot (:func:`mjeap.robots.hamr_walk.trot_voltages`: diagonal
    pairs in phase, lifts 90 deg ahead, amplitude ramped over 2 cycles) as a policy:
    ``policy(t)`` returns the action for the control step starting at ``t`` s, the
    waveforms sampled at the step's middle. ``amplitude`` and ``lift_amplitude`` (V) None:
    the robot's trot drive (:func:`mjeap.robots.hamr_walk.trot_drive`); an ``amplitude``
    alone drives the lifts with it too."""
    if amplitude is None:
        drive = trot_drive(env.unwrapped.system, frequency)
        amplitude = drive["amplitude"]
        lift_amplitude = drive["lift_amplitude"] if lift_amplitude is None else lift_amplitude
    waves = trot_voltages(frequency, amplitude, lift_amplitude=lift_amplitude)
    order = [waves[name] for name in env.unwrapped.actuator_names]
    half = 0.5 * env.unwrapped.control_timestep

    def policy(t: float) -> np.ndarray:
        return np.array([float(w(t + half)) for w in order], dtype=np.float32)
    return policy


def run_trot(env: HamrWalkEnv, frequency: float, amplitude: Optional[float] = None,
             lift_amplitude: Optional[float] = None, settle: Optional[float] = None,
             measure: Optional[float] = None, seed: Optional[int] = 0) -> dict:
    """The scripted baseline: :func:`trot_policy` through ``env`` for the walker's settle
    and measuring windows (:func:`mjeap.robots.hamr_walk.trot_durations`, whole cycles),
    measured as :func:`mjeap.robots.hamr_walk.walk_metrics` measures the walker: the body's
    forward speed (m/s) between the window's ends. Returns speed_m_s, the episode's return,
    the largest tilt (deg), whether it ended early and the times (s)."""
    e = env.unwrapped
    settle, measure = trot_durations(frequency, settle, measure)
    policy = trot_policy(e, frequency, amplitude, lift_amplitude)
    e.reset(seed=seed)
    n_settle = int(round(settle / e.control_timestep))
    n = int(round((settle + measure) / e.control_timestep))
    total, max_tilt, ended, x0, t0 = 0.0, 0.0, "", None, None
    for k in range(n):
        if k == n_settle:
            x0, t0 = e._forward_position(), e.time
        _, r, terminated, truncated, info = e.step(policy(e.time))
        total += r
        max_tilt = max(max_tilt, e.tilt_deg())
        if terminated or truncated:
            ended = info.get("ended") or info.get("divergence") or "truncated at time_limit"
            break
    speed = (e._forward_position() - x0) / (e.time - t0) if x0 is not None and e.time > t0 else float("nan")
    return {"frequency_hz": float(frequency), "speed_m_s": float(speed), "return": float(total),
            "max_tilt_deg": max_tilt, "ended": ended, "settle_s": float(settle), "measure_s": float(e.time - (t0 or 0.0)),
            "control_timestep_s": e.control_timestep}
