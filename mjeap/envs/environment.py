"""A dm_env environment through dm_control: ``control.Environment`` with a :class:`Task`.

:class:`BeamPhysics` is a dm_control ``Physics`` on a :class:`mjeap.Scene`'s model and data
whose ``step`` runs the drive in lockstep with MuJoCo (one drive update per MuJoCo step,
the voltage held over the control interval), so ``control.Environment``'s sub-steps keep the
drive exact. :class:`CurvatureTrackingTask` gives the action (drive voltage, V, inside the
drive's safe range), the observations (SI) and a configurable tracking reward, and
randomises payload mass and initial curvature per episode from its seeded generator.

The payload is randomised in place (``model.body_mass`` and its inertia, then
``mj_setConst``): timestep and Rayleigh damping stay those chosen for the scene's nominal
payload, so the first mode's damping ratio drifts with the mass (zeta ~ omega_1). Keep the
mass range below the actuator's stability limit (``mjeap validate`` reports it).
"""
from __future__ import annotations

import argparse
from typing import Callable, Optional, Tuple

import numpy as np
from dm_control.mujoco import engine, wrapper
from dm_control.rl import control
from dm_control.suite import base
from dm_env import specs

from ..errors import install_mujoco_warnings
from ..io.commandline import arg_integer, arg_number, arg_output, parse_args
from ..model.discretize import Payload
from ..drives import make_drive
from ..errors import MjeapError, check_positive, check_range
from ..io.outputs import guarded, provenance
from ..simulation.scene import Scene
from .tracking import (check_curvature_range, check_mass_range, default_reference, draw_episode, observe, step_lockstep, tracking_reward, VoltageLimiter, warn_heavy_range)
from ..versions import dm_control_problem

install_mujoco_warnings()         # dm_control's import installed its own MuJoCo warning handler


class BeamPhysics(engine.Physics):
    """dm_control Physics sharing a Scene's MjModel and MjData; stepping also steps the drive."""

    @classmethod
    def from_scene(cls, scene: Scene, drive) -> "BeamPhysics":
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


class CurvatureTrackingTask(base.Task):
    """Track ``reference(t)`` (1/m) with the tip curvature. Reward per step:
    ``reward_fn(kappa, kappa_ref)``, default a Gaussian of the error with width
    ``reward_margin`` (1/m), 1 on target (dm_control.utils.rewards.tolerance).

    Randomised at every reset (``random``: seed or numpy Generator/RandomState): the payload
    mass uniformly in ``payload_mass_range`` (kg, needs a scene with a payload), the initial
    curvature uniformly in ``initial_curvature_range`` (1/m, both bounds within rollout's:
    finite, at most a full circle over the beam). An action is one voltage (shape (1,));
    more values are refused, not cut. Actions outside the safe range
    are clipped, counted in ``saturated_steps`` and warned about once per episode."""

    def __init__(self, reference: Callable[[float], float], payload_mass_range: Optional[Tuple[float, float]] = None,
                 initial_curvature_range: Tuple[float, float] = (0.0, 0.0), reward_margin: float = 5.0,
                 reward_fn: Optional[Callable[[float, float], float]] = None, random=None):
        super().__init__(random=random)
        self.reference = reference
        self.payload_mass_range = check_mass_range(payload_mass_range)
        self.initial_curvature_range = check_curvature_range(initial_curvature_range, None)   # bounds: per beam
        self.reward_margin = check_positive("reward_margin", reward_margin, "1/m")
        self.reward_fn = reward_fn
        self.limiter = VoltageLimiter("the action_spec")
        self.episode = {}

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
        sc._step_count = 0
        physics.drive.reset(kappa0)
        physics.voltage = physics.drive.rest_voltage()
        self.limiter.reset()
        self._signal_names = list(physics.drive.signals())

    def action_spec(self, physics: BeamPhysics):
        lo, hi = physics.drive.voltage_range()
        return specs.BoundedArray((1,), np.float64, lo, hi, name="voltage (V)")

    def before_step(self, action, physics: BeamPhysics) -> None:
        physics.voltage = self.limiter(action, physics.drive)

    # -- read-outs ---------------------------------------------------------------------
    def get_observation(self, physics: BeamPhysics):
        """tip_curvature (1/m), reference (1/m), tip_position (m, clamp frame), drive_state
        (SI, see drive_state_names) and current (A) where the drive reports one."""
        return observe(physics.scene, physics.drive, self.reference, self._signal_names)

    @property
    def drive_state_names(self):
        return list(self._signal_names)

    def get_reward(self, physics: BeamPhysics) -> float:
        sc = physics.scene
        k, ref = sc.tip_curvature(), float(self.reference(sc.time))
        if self.reward_fn is not None:
            return float(self.reward_fn(k, ref))
        return tracking_reward(k, ref, self.reward_margin)


def check_dm_control() -> None:
    """Refuse, naming the versions, where dm_control's Physics cannot run on this MuJoCo."""
    why = dm_control_problem()
    if why:
        raise MjeapError(f"no dm_env environment here: {why}")


def make_environment(actuator: str = "pedot-micro", reference: Optional[Callable[[float], float]] = None,
                     orientation: str = "up", payload: Optional[Payload] = Payload(12.6e-6, 6.27e-3),
                     payload_mass_range: Optional[Tuple[float, float]] = None,
                     initial_curvature_range: Tuple[float, float] = (0.0, 0.0), control_interval: float = 1e-2,
                     time_limit: float = 20.0, seed=None, drive: Optional[str] = None, drive_params=None,
                     reward_margin: float = 5.0, segments: int = 20) -> control.Environment:
    """A ``dm_control.rl.control.Environment`` tracking ``reference(t)`` (1/m; default: a
    0.05 Hz sine of 50 1/m, seed 000's closed-loop case) with ``actuator``. The agent acts
    every ``control_interval`` s (rounded to whole MuJoCo steps) for ``time_limit`` s."""
    check_dm_control()
    reference = default_reference if reference is None else reference
    scene = Scene(actuator, orientation=orientation, payload=payload, segments=segments)
    warn_heavy_range(check_mass_range(payload_mass_range), scene, 3)     # the Scene's unit check, on the draws
    check_curvature_range(initial_curvature_range, scene.layout.length)
    drv = make_drive(drive, scene, **(drive_params or {}))
    check_range("control_interval", control_interval, scene.timestep, time_limit, "s")
    physics = BeamPhysics.from_scene(scene, drv)
    task = CurvatureTrackingTask(reference, payload_mass_range, initial_curvature_range, reward_margin,
                                 random=seed)
    n_sub = max(1, int(round(control_interval / scene.timestep)))
    return control.Environment(physics, task, time_limit=time_limit, n_sub_steps=n_sub)


@guarded("rrd")
def run_episode(env: control.Environment, policy: Callable, rrd=None):
    """Run one episode of ``env`` with ``policy(time_step) -> action`` and return it as a
    :class:`mjeap.RolloutResult` sampled at every agent step (the reward and the action as
    signals), written to ``rrd`` if given (also when the episode fails or is stopped, by
    Ctrl-C or SIGTERM; a second writer of it is refused, :func:`mjeap.io.outputs.guarded`)."""
    from ..model.analytical import arc_curvature
    from ..io.recording import write_recording
    from ..engines.frame import RolloutResult
    from ..io.outputs import write_outputs

    physics, task = env.physics, env.task
    sc = physics.scene
    rows, error = [], None

    def sample(ts):
        p = sc.tip_position()
        sig = dict(physics.drive.signals())
        sig["reward (-)"] = np.nan if ts.reward is None else float(ts.reward)
        sig["reference_curvature (1/m)"] = float(task.reference(sc.time))
        rows.append((sc.time, physics.voltage, p, sc.tip_angle(), arc_curvature(p[0], p[1]), sc.centreline(),
                     sc.payload_position(), sig))

    try:
        ts = env.reset()
        sample(ts)
        while not ts.last():
            action = policy(ts)
            ts = env.step(action)
            sample(ts)
    except BaseException as e:
        error = e
        raise
    finally:
        t, v, p, a, k, cl, pay, sig = zip(*rows) if rows else ([],) * 8
        keys = list(sig[0]) if rows else []
        meta = {**provenance(), "actuator": sc.actuator.id, "drive": physics.drive.describe(), "voltage": "agent",
                "episode": dict(task.episode), "saturated_steps": task.saturated_steps,
                "control_interval_s": env.control_timestep(), "scene": sc.summary()}
        if task.saturated_steps:
            meta["warnings"] = [f"{task.saturated_steps} actions clipped to the safe range "
                                f"{physics.drive.voltage_range()} V"]
        if error is not None:
            meta["error"] = f"{type(error).__name__}: {error}"
        result = RolloutResult(np.array(t), np.array(v), np.array(p), np.array(a), np.array(k), np.array(cl),
                               None if (not rows or pay[0] is None) else np.array(pay),
                               {kk: np.array([s[kk] for s in sig]) for kk in keys}, None, meta)
        if rrd is not None and rows:
            write_outputs([(rrd, lambda: write_recording(rrd, result, sc))], error, result)
    return result


# ---------------------------------------------------------------- the example episode
def reference(t):
    """The episode's reference curvature (1/m) at ``t`` (s): 50 1/m at 0.05 Hz."""
    return 50.0 * np.sin(2 * np.pi * 0.05 * np.asarray(t))


def main(argv=None):
    """One recorded episode under the curvature tracker: ``python scripts/env_episode.py --help``."""
    ap = argparse.ArgumentParser(description="One episode of the dm_env curvature-tracking environment, recorded.")
    ap.add_argument("--seed", type=arg_integer(0), default=0)
    ap.add_argument("--duration", type=arg_number(0.01, 600.0, "s"), default=20.0,
                    help="simulated time of the episode (s): from one agent step (10 ms) to 600 s")
    ap.add_argument("--out", default="out/env-episode.rrd", type=arg_output(), help="recording (.rrd)")
    a = parse_args(ap, argv)
    from ..controllers.curvature_tracking import CurvatureTracker
    env = make_environment("pedot-micro", reference, payload_mass_range=(1e-6, 12.6e-6),
                           initial_curvature_range=(-20.0, 20.0), time_limit=a.duration, seed=a.seed)
    tracker = CurvatureTracker(reference, a.duration + 1.0, interval=env.control_timestep())
    physics = env.physics

    def policy(time_step):
        if time_step.first():
            tracker.reset(physics.scene, physics.drive)
        return np.array([tracker(physics.time(), physics.scene)])

    r = run_episode(env, policy, rrd=a.out)
    err = r.tip_curvature - r.signals["reference_curvature (1/m)"]
    second_half = r.time >= a.duration / 2
    print(f"episode: {env.task.episode}")
    print(f"{len(r.time) - 1} agent steps of {env.control_timestep() * 1e3:.3g} ms; mean reward "
          f"{np.nanmean(r.signals['reward (-)']):.3f}; RMS error over the second half "
          f"{np.sqrt(np.mean(err[second_half] ** 2)):.3g} 1/m; clipped actions {env.task.saturated_steps}")
    print(f"wrote {a.out}")
