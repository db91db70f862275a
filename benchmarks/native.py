"""Dadras et al. 2021's drive compiled into the model (mjeap.drives.native) against the
lockstep loop, side by side: the heaviest experiment as one rollout, a batch of 16 on 2
threads against the loop one by one, mj_step of the native model against the bare beam, and
the stability map's 30 s points per second on 2 workers with either engine."""
from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from mjeap import Scene
from benchmarks.common import time_steps


def bench_native(repeats=2, map_points=8):
    from mjeap import Payload, rollout, rollout_batch
    from mjeap.drives import make_drive
    from mjeap.studies.stability_map import MAP_BASE
    from mjeap.studies.sweep import grid, run_sweep
    s = Scene("pedot-micro", orientation="up", payload=Payload(12.6e-6, 6.27e-3))
    args = dict(duration=20.0, initial_curvature=-303.0, progress=False)
    out = {"case": "pedot-micro, 12.6 mg @ 6.27 mm, up, square 3 Vpp 0.1 Hz, 20 s, from -303 1/m",
           "timestep_s": s.timestep}
    for engine in ("loop", "native"):
        best = np.inf
        for _ in range(repeats):
            t0 = time.perf_counter()
            r = rollout(s, "square:1.5V@0.1Hz", engine=engine, **args)
            best = min(best, time.perf_counter() - t0)
        out[f"single_{engine}_s"] = best
        out[f"single_{engine}_us_per_step"] = best / r.meta["steps"] * 1e6
    out["steps"] = r.meta["steps"]
    out["single_speedup_native_vs_loop"] = out["single_loop_s"] / out["single_native_s"]
    volts = [f"square:{a:.4g}V@0.1Hz" for a in np.linspace(0.5, 1.5, 16)]
    t0 = time.perf_counter()
    for v in volts:
        rollout(s, v, engine="loop", **args)
    out["batch16_loop_s"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    rollout_batch(s, volts, 20.0, initial_curvatures=-303.0, nthread=2, engine="native")
    out["batch16_native_2threads_s"] = time.perf_counter() - t0
    out["batch16_throughput_native_vs_loop"] = out["batch16_loop_s"] / out["batch16_native_2threads_s"]
    native = s.native_model(make_drive(None, s))
    s.reset(curvature=-303.0)
    out["mj_step_bare_us"] = 1e6 / time_steps(s.model, s.data)
    native.reset(-303.0)
    out["mj_step_native_us"] = 1e6 / time_steps(native.model, native.data)
    out["native_step_cost_vs_bare"] = out["mj_step_native_us"] / out["mj_step_bare_us"]
    out["native_nv"], out["bare_nv"] = native.model.nv, s.model.nv
    pts = grid(payload_mass=list(np.linspace(15e-6, 120e-6, map_points // 2)), amplitude=[0.5, 1.5])
    import tempfile
    with tempfile.TemporaryDirectory() as d:
        for engine in ("loop", "native"):
            res = run_sweep(pts, Path(d) / f"{engine}.csv", base={**MAP_BASE, "engine": engine}, workers=2,
                            progress=False)
            out[f"stability_map_{engine}_rollouts_per_s"] = res.throughput
    out["stability_map_points"] = len(pts)
    return out


def run(args) -> dict:
    """The benchmark's section of the JSON."""
    return bench_native()
