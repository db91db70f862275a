"""One episode of the dm_env curvature-tracking environment, driven by the controller of
``controllers/curvature_tracking.py``, recorded to a Rerun file.

    python scripts/env_episode.py [--seed 0] [--duration 20] [--out out/env-episode.rrd]

pedot-micro standing up with a payload at 6.27 mm whose mass is drawn per episode from
1-12.6 mg, initial curvature from -20..20 1/m; reference: 50 1/m at 0.05 Hz.
"""
import argparse
import sys

import numpy as np

from controllers.curvature_tracking import CurvatureTracker
from mjeap.cli import arg_integer, arg_number, arg_output, parse_args, run_script
from mjeap.environment import make_environment, run_episode


def reference(t):
    return 50.0 * np.sin(2 * np.pi * 0.05 * np.asarray(t))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seed", type=arg_integer(0), default=0)
    ap.add_argument("--duration", type=arg_number(0.01, 600.0, "s"), default=20.0,
                    help="simulated time of the episode (s): from one agent step (10 ms) to 600 s")
    ap.add_argument("--out", default="out/env-episode.rrd", type=arg_output(), help="recording (.rrd)")
    a = parse_args(ap, argv)
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


if __name__ == "__main__":
    sys.exit(run_script(main))
