"""see scripts/bench.py"""
from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from mjeap import Scene


def bench_warp(map_points=4, duration=1.0, batch=16, batch_duration=0.6):
    """The warp engine against the native one on this machine (Warp's CPU device unless a GPU
    is found; the device is in the output): a batch of Dadras et al. 2021's standing run with 16
    amplitudes, and a small stability map (``map_points`` points of ``duration`` s, serial)."""
    import tempfile
    from mjeap import Payload, rollout_batch
    from mjeap.studies.stability_map import MAP_BASE
    from mjeap.drives import make_drive
    from mjeap.engines import get_engine
    from mjeap.studies.sweep import grid, run_sweep
    s = Scene("pedot-micro", orientation="up", payload=Payload(12.6e-6, 6.27e-3))
    why = get_engine("warp").why_not(s, make_drive(None, s))
    if why is not None:
        return {"skipped": why}
    volts = [f"square:{a:.4g}V@0.1Hz" for a in np.linspace(0.25, 1.5, batch)]
    out = {"case": f"pedot-micro, 12.6 mg @ 6.27 mm, up, square 0.1 Hz, {batch} amplitudes, {batch_duration} s"}
    for engine in ("native", "warp", "warp"):       # warp twice: the second without the compile and captures
        t0 = time.perf_counter()
        r = rollout_batch(s, volts, batch_duration, initial_curvatures=-303.0, engine=engine)
        key = f"batch_{engine}_s" if f"batch_{engine}_s" not in out else f"batch_{engine}_again_s"
        out[key] = time.perf_counter() - t0
    out["device"] = r[0].meta["warp"]["device"]
    out["steps"] = r[0].meta["steps"]
    pts = grid(payload_mass=list(np.linspace(15e-6, 120e-6, max(map_points // 2, 1))), amplitude=[0.5, 1.5])
    with tempfile.TemporaryDirectory() as d:
        for engine in ("native", "warp"):
            res = run_sweep(pts, Path(d) / f"{engine}.csv", base={**MAP_BASE, "duration": duration, "engine": engine},
                            executor="serial", progress=False)
            out[f"map_{engine}_rollouts_per_s"] = res.throughput
            out[f"map_{engine}_failed"] = res.failed
    out["map"] = f"{len(pts)} points of {duration} s, serial"
    return out


def run(args) -> dict:
    """The benchmark's section of the JSON."""
    return bench_warp()
