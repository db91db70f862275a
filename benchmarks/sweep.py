"""rollouts per second of a 16-point sweep on 1 and 2 local worker processes, and the memory of
one rollout."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from mjeap import Scene


def bench_sweep(points=16, duration=2.0):
    """Rollouts per second of the same sweep on 1 and 2 worker processes (pool start
    included), and the memory of one rollout (tracemalloc peak, which sees NumPy's
    buffers, plus the MjModel and MjData)."""
    import tempfile
    import tracemalloc
    from mjeap import rollout
    from mjeap.studies.sweep import grid, run_sweep
    pts = grid(payload_mass=list(np.linspace(1e-6, 12.6e-6, points // 2)), amplitude=[0.5, 1.0])
    base = {"actuator": "pedot-micro", "orientation": "up", "waveform": "square", "frequency": 0.5,
            "duration": duration, "payload_position": 6.27e-3}
    out = {"case": f"pedot-micro up, payload x amplitude grid, {len(pts)} points of {duration} s"}
    with tempfile.TemporaryDirectory() as d:
        for workers in (1, 2):
            res = run_sweep(pts, Path(d) / f"w{workers}.csv", base=base, workers=workers, progress=False)
            out[f"workers_{workers}"] = {"rollouts_per_s": res.throughput, "wall_s": res.wall_s,
                                         "failed": res.failed}
    out["speedup_2_vs_1"] = out["workers_2"]["rollouts_per_s"] / out["workers_1"]["rollouts_per_s"]
    from mjeap import Payload
    s = Scene("pedot-micro", orientation="up", payload=Payload(12.6e-6, 6.27e-3))
    rollout(s, "square:1V@0.5Hz", 0.1)                        # warm caches
    tracemalloc.start()
    r = rollout(s, "square:1V@0.5Hz", duration)
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    result_bytes = sum(a.nbytes for a in (r.time, r.voltage, r.tip_position, r.tip_angle, r.tip_curvature,
                                          r.centreline)) + sum(a.nbytes for a in r.signals.values())
    out["memory_per_rollout"] = {"python_peak_bytes": peak, "result_arrays_bytes": result_bytes,
                                 "samples": len(r.time), "mjmodel_bytes": int(s.model.nbuffer),
                                 "mjdata_bytes": int(s.data.nbuffer + s.data.narena)}
    return out


def run(args) -> dict:
    """The benchmark's section of the JSON."""
    return bench_sweep()
