"""Dadras et al. 2021's heaviest experiment (pedot-micro, 12.6 mg at 6.27 mm, standing up, 3
Vpp square wave at 0.1 Hz, 20 s) with the drive and the recording on: wall time and real-
time factor, the drive's own cost per step, and the peak-to-peak tip curvature against a run
at half the timestep and twice the segments."""
from __future__ import annotations

import time
from pathlib import Path

import mujoco
import numpy as np

from mjeap import Scene


def bench_rollout(tmpdir):
    from mjeap import Payload, rollout
    from mjeap.drives import make_drive

    def scene(**kw):
        return Scene("pedot-micro", orientation="up", payload=Payload(12.6e-6, 6.27e-3), **kw)

    args = dict(voltage="square:1.5V@0.1Hz", duration=20.0, initial_curvature=-303.0, progress=False)
    s = scene()
    t0 = time.perf_counter()
    r = rollout(s, rrd=Path(tmpdir) / "bench.rrd", **args)
    wall = time.perf_counter() - t0
    # the drive alone, per step, on the settled scene
    drv = make_drive(None, s)
    drv.reset(0.0)
    n = 20000
    t1 = time.perf_counter()
    for _ in range(n):
        drv.step(1.5, s.timestep)
    drive_us = (time.perf_counter() - t1) / n * 1e6
    t2 = time.perf_counter()
    mujoco.mj_step(s.model, s.data, nstep=n)
    mj_us = (time.perf_counter() - t2) / n * 1e6
    fine = scene(segments=2 * s.layout.segments, timestep=s.timestep / 2)
    rf = rollout(fine, **args)
    late, late_f = r.time >= 10, rf.time >= 10
    p2p, p2p_f = float(np.ptp(r.tip_curvature[late])), float(np.ptp(rf.tip_curvature[late_f]))
    return {"case": "pedot-micro, 12.6 mg @ 6.27 mm, up, square 3 Vpp 0.1 Hz, 20 s, recording on",
            "timestep_s": s.timestep, "segments": s.layout.segments, "steps": r.meta["steps"],
            "wall_time_s": wall, "real_time_factor": 20.0 / wall,
            "drive_step_us": drive_us, "mj_step_us": mj_us,
            "loop_us_per_step": r.meta["wall_time_s"] / r.meta["steps"] * 1e6,
            "p2p_curvature_per_m": p2p, "p2p_curvature_fine_per_m": p2p_f,
            "p2p_relative_difference": p2p / p2p_f - 1,
            "fine": {"timestep_s": fine.timestep, "segments": fine.layout.segments}}


def run(args) -> dict:
    """The benchmark's section of the JSON."""
    import tempfile
    with tempfile.TemporaryDirectory() as d:
        return bench_rollout(d)
