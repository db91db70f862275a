"""What several benchmarks share: timing a model's steps."""
from __future__ import annotations

import time

import mujoco



def time_steps(model, data, min_seconds=0.5):
    """Steps per second of mj_step on one thread, measured over at least ``min_seconds``."""
    n = 1000
    while True:
        t0 = time.perf_counter()
        mujoco.mj_step(model, data, nstep=n)
        dt = time.perf_counter() - t0
        if dt >= min_seconds:
            return n / dt
        n = int(n * max(2.0, 1.2 * min_seconds / max(dt, 1e-6)))
