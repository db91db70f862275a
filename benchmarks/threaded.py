"""the lockstep loop against MuJoCo's native threaded rollout (open-loop piezo drive): one
rollout, and a batch of 16 on 1 and 2 threads."""
from __future__ import annotations

import time

import numpy as np

from mjeap import Scene


def bench_threaded():
    """Loop vs mujoco.rollout on the HAMR bimorph (open-loop piezo drive), 0.2 s of a
    100 V-biased sine, samples every 1 ms."""
    from mjeap.simulation.rollout import rollout, rollout_batch
    s = Scene("pzt-hamr-small")
    volts = [f"sine:20V@{f:g}Hz,offset=100V" for f in np.linspace(100, 1000, 16)]
    kw = dict(sample_interval=1e-3)
    out = {"case": "pzt-hamr-small, 0.2 s, sine 20 V about 100 V, samples every 1 ms", "timestep_s": s.timestep}
    for engine in ("loop", "threaded"):
        t0 = time.perf_counter()
        r = rollout(s, volts[0], 0.2, engine=engine, **kw)
        out[f"single_{engine}_s"] = time.perf_counter() - t0
    out["steps"] = r.meta["steps"]
    t0 = time.perf_counter()
    for v in volts:
        rollout(s, v, 0.2, engine="loop", **kw)
    out["batch16_loop_s"] = time.perf_counter() - t0
    for nt in (1, 2):
        t0 = time.perf_counter()
        rollout_batch(s, volts, 0.2, nthread=nt, **kw)
        out[f"batch16_threaded_{nt}thread_s"] = time.perf_counter() - t0
    out["batch16_speedup_2threads_vs_loop"] = out["batch16_loop_s"] / out["batch16_threaded_2thread_s"]
    return out


def run(args) -> dict:
    """The benchmark's section of the JSON."""
    return bench_threaded()
