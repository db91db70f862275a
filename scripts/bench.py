#!/usr/bin/env python
"""Benchmarks, printed as JSON (and written with --json FILE).

models: steps per second and real-time factor of every catalog actuator at its default
discretisation, both representations, unforced (MuJoCo's own stepping loop, one thread).
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


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--json", help="also write the results to this file")
    ap.add_argument("--min-seconds", type=float, default=0.5, help="timing window per measurement")
    args = ap.parse_args()
    out = {"machine": {"python": platform.python_version(), "mujoco": mujoco.__version__,
                       "processor": platform.processor() or platform.machine(), "cpus": os.cpu_count()},
           "models": bench_models(args.min_seconds)}
    text = json.dumps(out, indent=2)
    print(text)
    if args.json:
        Path(args.json).write_text(text)


if __name__ == "__main__":
    main()
