"""mjeap/HamrWalk-v0's env steps per second and real-time factor on one core: its learning
model (2 segments per actuator, a 100 us step sized for the loaded system) beside the default
walker model (4 segments, 4.51 us), and the wall hours of a 10^6-step learning run."""
from __future__ import annotations

import os
import time

import mujoco

from benchmarks.common import time_steps


def bench_hamr_walk_env(simulated=0.2, frequency=10.0):
    """``mjeap/HamrWalk-v0`` on one core, side by side: its learning model (2 segments per
    actuator at a 50 us step sized for the loaded system, the id's default) and the default
    walker model (4 segments, each actuator's own 4.51 us step): env steps per second over
    ``simulated`` s of the scripted trot (the robot's drive, its actions computed beforehand:
    the environment's cost, not the policy's) at ``frequency`` Hz after the soft start,
    simulated seconds per wall second (the real-time factor; and per CPU second of the
    process, what one core costs on a shared machine), the bare mj_step's rate
    and what a learning run of 10^6 env steps (0.5 ms each, 500 simulated s) costs in wall
    hours. One thread: OMP and MKL at 1 (set before numpy loads: run with
    OMP_NUM_THREADS=1 MKL_NUM_THREADS=1)."""
    from mjeap.envs.hamr_walk import LEARNING_SEGMENTS, LEARNING_TIMESTEP, HamrWalkEnv, trot_policy
    out = {"case": f"HamrWalk-v0, scripted trot at {frequency:g} Hz (the robot's drive), {simulated:g} s after "
                   "the ramp, one thread", "omp_num_threads": os.environ.get("OMP_NUM_THREADS"),
           "mkl_num_threads": os.environ.get("MKL_NUM_THREADS")}
    for label, segments, step in (("learning", LEARNING_SEGMENTS, LEARNING_TIMESTEP), ("default_model", 4, None)):
        env = HamrWalkEnv(segments=segments, timestep=step, time_limit=10.0)
        env.reset(seed=0)
        policy = trot_policy(env, frequency)
        for _ in range(int(round(2.0 / frequency / env.control_timestep))):      # the soft start
            env.step(policy(env.time))
        k = int(round(simulated / env.control_timestep))
        actions = [policy(env.time + i * env.control_timestep) for i in range(k)]   # the policy's cost apart
        t0, c0 = time.perf_counter(), time.process_time()
        for a in actions:
            env.step(a)
        wall, cpu = time.perf_counter() - t0, time.process_time() - c0
        m, d = env.system.model, env.system.data
        step_rate = time_steps(m, mujoco.MjData(m), min_seconds=0.3)
        rate = k / wall
        out[label] = {
            "segments": segments, "timestep_s": env.system.timestep, "mujoco_steps_per_env_step": env._n_sub,
            "env_steps_per_s": rate, "realtime_factor": rate * env.control_timestep,
            "cpu_realtime_factor": k * env.control_timestep / cpu,
            "bare_mj_step_per_s": step_rate, "bare_mj_step_realtime_factor": step_rate * env.system.timestep,
            "hours_per_1e6_env_steps": 1e6 / rate / 3600.0}
    return out


def run(args) -> dict:
    """The benchmark's section of the JSON."""
    return bench_hamr_walk_env()
