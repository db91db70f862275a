#!/usr/bin/env python
"""Benchmarks, printed as JSON (and written with --json FILE).

models: steps per second and real-time factor of every catalog actuator at its default
discretisation, both representations, unforced (MuJoCo's own stepping loop, one thread).

rollout: seed 000's heaviest experiment (pedot-micro, 12.6 mg at 6.27 mm, standing up,
3 Vpp square wave at 0.1 Hz, 20 s) with the drive and the recording on: wall time and
real-time factor, the drive's own cost per step, and the peak-to-peak tip curvature
against a run at half the timestep and twice the segments.
"""
import argparse
import json
import os
import platform
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
os.environ.setdefault("MUJOCO_GL", "disable")

import mujoco  # noqa: E402
import numpy as np  # noqa: E402

from mjeap import CATALOG, REPRESENTATIONS, Scene  # noqa: E402


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


def bench_models(min_seconds):
    rows = []
    for aid in CATALOG:
        for rep in REPRESENTATIONS:
            s = Scene(aid, representation=rep)
            # small initial bend so that the beam actually moves
            s.reset(curvature=0.1 / s.layout.length)
            sps = time_steps(s.model, s.data, min_seconds)
            rows.append({"actuator": aid, "representation": rep, "segments": s.layout.segments,
                         "nv": s.model.nv, "timestep_s": s.timestep, "steps_per_s": sps,
                         "real_time_factor": sps * s.timestep})
    return rows


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


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--json", help="also write the results to this file")
    ap.add_argument("--min-seconds", type=float, default=0.5, help="timing window per measurement")
    ap.add_argument("--only", choices=["models", "rollout"], help="run one benchmark")
    args = ap.parse_args()
    out = {"machine": {"python": platform.python_version(), "mujoco": mujoco.__version__,
                       "processor": platform.processor() or platform.machine(), "cpus": os.cpu_count()}}
    if args.only in (None, "models"):
        out["models"] = bench_models(args.min_seconds)
    if args.only in (None, "rollout"):
        import tempfile
        with tempfile.TemporaryDirectory() as d:
            out["rollout"] = bench_rollout(d)
    text = json.dumps(out, indent=2)
    print(text)
    if args.json:
        Path(args.json).write_text(text)


if __name__ == "__main__":
    main()
