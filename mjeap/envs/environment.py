"""The dm_env environment: curvature tracking with one bending actuator, on MuJoCo 3.17 and 4.x.

:func:`make_environment` is the entry point (``mjeap.make_environment``). It returns a
``dm_env.Environment`` posed by :class:`CurvatureTrackingTask` on a :class:`BeamPhysics`
(a :class:`mjeap.Scene`'s model and data whose ``step`` runs the drive in lockstep with
MuJoCo: one drive update per MuJoCo step, the voltage held over the control interval):

* ``backend="dm_control"``: dm_control's ``control.Environment`` with the task and physics
  as dm_control's ``Task`` and ``Physics`` (:mod:`mjeap.envs.dm_control_env`), where
  dm-control's ``Physics`` loads the model (MuJoCo 3.x);
* ``backend="dm_env"``: :class:`TrackingEnvironment`, the same episode, step and time limit
  written on ``dm_env.Environment`` directly (no dm_control), which runs everywhere;
* ``backend="auto"`` (default): dm_control where it can run, else dm_env: on MuJoCo 4.0
  dm-control 1.0.50's ``Physics`` reads ``MjModel.flex_vertedge``, which 4.0 no longer has
  (:func:`mjeap.versions.dm_control_problem`).

Both give the same trajectories for the same seed and actions (tests/envs/test_environment.py).
The task, the physics and the dm_env environment are :mod:`mjeap.envs.dm_tracking`'s (no
dm_control). :class:`CurvatureTrackingTask` gives the action (drive voltage, V, inside the drive's safe
range), the observations (SI) and a configurable tracking reward, and randomises payload
mass and initial curvature per episode from its seeded generator.

The payload is randomised in place (``model.body_mass`` and its inertia, then
``mj_setConst``): timestep and Rayleigh damping stay those chosen for the scene's nominal
payload, so the first mode's damping ratio drifts with the mass (zeta ~ omega_1). Keep the
mass range below the actuator's stability limit (``mjeap validate`` reports it).
"""
from __future__ import annotations

import argparse
from typing import Callable, Optional, Tuple

import dm_env
import numpy as np

from ..io.commandline import arg_integer, arg_number, arg_output, parse_args
from ..model.discretize import Payload
from ..drives import make_drive
from ..errors import ParameterError, check_range
from ..io.outputs import guarded, provenance
from ..simulation.scene import Scene
from .dm_tracking import BeamPhysics, CurvatureTrackingTask, TrackingEnvironment, check_dm_control
from .tracking import check_curvature_range, check_mass_range, default_reference, warn_heavy_range
from ..versions import dm_control_problem

__all__ = ["make_environment", "run_episode", "BeamPhysics", "CurvatureTrackingTask", "TrackingEnvironment",
           "BACKENDS", "main"]

#: make_environment's backends: dm_control's control.Environment, or dm_env's interface directly
BACKENDS = ("auto", "dm_control", "dm_env")


def make_environment(actuator: str = "pedot-micro", reference: Optional[Callable[[float], float]] = None,
                     *, orientation: str = "up", payload: Optional[Payload] = Payload(12.6e-6, 6.27e-3),
                     payload_mass_range: Optional[Tuple[float, float]] = None,
                     initial_curvature_range: Tuple[float, float] = (0.0, 0.0), control_interval: float = 1e-2,
                     time_limit: float = 20.0, seed=None, drive: Optional[str] = None, drive_params=None,
                     reward_margin: float = 5.0, segments: int = 20, backend: str = "auto") -> dm_env.Environment:
    """A dm_env environment tracking ``reference(t)`` (1/m; default: a 0.05 Hz sine of 50
    1/m, Dadras et al. 2021's closed-loop case) with ``actuator``. The agent acts every
    ``control_interval`` s (rounded to whole MuJoCo steps) for ``time_limit`` s. ``backend``
    (:data:`BACKENDS`): 'dm_control' (``control.Environment``, MuJoCo 3.x; refused naming the
    versions where dm_control's Physics cannot run), 'dm_env' (:class:`TrackingEnvironment`,
    any MuJoCo) or 'auto' (the first where it runs, else the second). Either has
    ``physics`` (``scene``, ``drive``, ``voltage``, ``model``, ``data``, ``time()``), ``task``
    and ``control_timestep()``."""
    if backend not in BACKENDS:
        raise ParameterError("backend", backend, f"one of {', '.join(map(repr, BACKENDS))}")
    use_dm_control = backend == "dm_control" or (backend == "auto" and not dm_control_problem())
    if use_dm_control:
        check_dm_control()
    reference = default_reference if reference is None else reference
    scene = Scene(actuator, orientation=orientation, payload=payload, segments=segments)
    warn_heavy_range(check_mass_range(payload_mass_range), scene, 3)     # the Scene's unit check, on the draws
    check_curvature_range(initial_curvature_range, scene.layout.length)
    drv = make_drive(drive, scene, **(drive_params or {}))
    check_range("control_interval", control_interval, scene.timestep, time_limit, "s")
    n_sub = max(1, int(round(control_interval / scene.timestep)))
    if use_dm_control:
        from .dm_control_env import make_dm_control_environment
        return make_dm_control_environment(scene, drv, reference, payload_mass_range=payload_mass_range,
                                           initial_curvature_range=initial_curvature_range,
                                           reward_margin=reward_margin, seed=seed, time_limit=time_limit, n_sub=n_sub)
    task = CurvatureTrackingTask(reference, payload_mass_range, initial_curvature_range, reward_margin, random=seed)
    return TrackingEnvironment(BeamPhysics.from_scene(scene, drv), task, time_limit=time_limit, n_sub_steps=n_sub)


@guarded("rrd")
def run_episode(env: dm_env.Environment, policy: Callable, rrd=None):
    """Run one episode of ``env`` with ``policy(time_step) -> action`` and return it as a
    :class:`mjeap.RolloutResult` sampled at every agent step (the reward and the action as
    signals), written to ``rrd`` if given (also when the episode fails or is stopped, by
    Ctrl-C or SIGTERM; a second writer of it is refused, :func:`mjeap.io.outputs.guarded`)."""
    from ..model.analytical import arc_curvature
    from ..io.recording import write_recording
    from ..engines.result import RolloutResult
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
