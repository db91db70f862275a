"""the stability map's points at 30 s, and at 60 s run to the end and stopped once periodic
(stop_when_periodic=1e-2): points per second and where each stopped."""
from __future__ import annotations

from pathlib import Path

import numpy as np



def bench_early_stop(map_points=8):
    """The stability map's bench points (as in native and accuracy) at the map's 30 s (three
    periods: too short for a stop, which needs four) and at 60 s, run to the end and with
    stop_when_periodic=1e-2 (mjeap.simulation.periodic), 2 workers: points per second, where
    each stopped, and the returns."""
    import tempfile
    from mjeap.studies.stability_map import MAP_BASE
    from mjeap.studies.sweep import grid, read_results, run_sweep
    pts = grid(payload_mass=list(np.linspace(15e-6, 120e-6, map_points // 2)), amplitude=[0.5, 1.5])
    out = {"case": f"stability map bench points ({len(pts)}), 2 workers, default model"}
    with tempfile.TemporaryDirectory() as d:
        for duration, stops in ((30.0, (None,)), (60.0, (None, 1e-2))):    # a stop needs 4 periods
            for stop in stops:
                label = f"{duration:g}s" + ("" if stop is None else f"_stop_{stop:g}")
                base = {**MAP_BASE, "duration": duration, **({} if stop is None else {"stop_when_periodic": stop})}
                res = run_sweep(pts, Path(d) / f"{label}.csv", metrics=("returns", "stopped_early"), base=base,
                                workers=2, progress=False)
                rows = read_results(Path(d) / f"{label}.csv")
                out[label] = {"points_per_s": res.throughput, "failed": res.failed,
                              "sum_of_point_walls_s": sum(float(r["wall_s"]) for r in rows), "points": {
                    f"{float(r['payload_mass']) * 1e6:.1f} mg, {r['amplitude']} V":
                        {"returns": r["returns"], "stopped_at_s": (float(r["stopped_early"].split()[2])
                                                                   if r["stopped_early"] else None)}
                    for r in rows}}
    return out


def run(args) -> dict:
    """The benchmark's section of the JSON."""
    return bench_early_stop()
