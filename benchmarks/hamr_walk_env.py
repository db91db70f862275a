"""mjeap/HamrWalk-v0's env steps per second and real-time factor on one core, the default model
(4 segments per actuator) beside the fewest segments (2), and the wall hours of a 10^6-step
learning run."""
from __future__ import annotations

import time

import mujoco

from benchmarks.common import time_steps


def bench_hamr_walk_env(simulated=0.05, segments=(4, 2), frequency=10.0):
    """``mjeap/HamrWalk-v0`` on one core, side by side: the default model (4 segments per
    actuator) and the fewest segments the actuators take (2; each its own 4.4-4.5 us step,
    the beam's unloaded first mode's beta / 2 under 'discrete'): env steps per second over
    ``simulated`` s of the scripted trot at ``frequency`` Hz after the soft start, simulated
    seconds per wall second (the real-time factor), the bare mj_step's share, and what a
    learning run of 10^6 env steps (0.5 ms each, 500 simulated s) costs in wall hours."""
    from mjeap.envs.hamr_walk import HamrWalkEnv, trot_policy
    out = {"case": f"HamrWalk-v0, scripted trot at {frequency:g} Hz full drive, {simulated:g} s after "
                   "the ramp, one thread"}
    for n in segments:
        env = HamrWalkEnv(segments=n, time_limit=10.0)
        env.reset(seed=0)
        policy = trot_policy(env, frequency)
        for _ in range(int(round(2.0 / frequency / env.control_timestep))):      # the soft start
            env.step(policy(env.time))
        k = int(round(simulated / env.control_timestep))
        t0 = time.perf_counter()
        for _ in range(k):
            env.step(policy(env.time))
        wall = time.perf_counter() - t0
        m, d = env.system.model, env.system.data
        step_rate = time_steps(m, mujoco.MjData(m), min_seconds=0.3)
        rate = k / wall
        out[f"segments_{n}"] = {
            "timestep_s": env.system.timestep, "mujoco_steps_per_env_step": env._n_sub,
            "env_steps_per_s": rate, "realtime_factor": rate * env.control_timestep,
            "bare_mj_step_per_s": step_rate, "bare_mj_step_realtime_factor": step_rate * env.system.timestep,
            "hours_per_1e6_env_steps": 1e6 / rate / 3600.0}
    return out


def run(args) -> dict:
    """The benchmark's section of the JSON."""
    return bench_hamr_walk_env()
