"""see scripts/bench.py"""
from __future__ import annotations

import time
from pathlib import Path

import numpy as np



def bench_metric_map(masses=(20, 40, 60, 70, 74, 78, 82, 100), amplitudes=(0.25, 1.0, 1.5), rounds=2, wide=(12, 8)):
    """The stability map (pedot-micro standing, 30 s points) at accuracy 1e-2 on its metrics
    (returns, peak_to_peak: mjeap.simulation.metric_accuracy, relaxed steps) against the
    default model on the same points, serial and on 2 workers, interleaved in ``rounds``
    rounds (the machine is shared), each run from cold (the scenes' shared analyses cleared):
    points per second, their ratio, returns agreement, the
    largest peak-to-peak deviation from the default, the simulated edges; a wider map
    (``wide``: masses x amplitudes) on 2 workers, once each; and where the time of an
    accuracy point goes (its runs)."""
    import tempfile
    from mjeap.studies.stability_map import MAP_BASE, simulated_edges
    from mjeap.simulation.scene import clear_build_caches
    from mjeap.studies.sweep import grid, read_results, run_sweep
    pts = grid(payload_mass=[m * 1e-6 for m in masses], amplitude=list(amplitudes))
    out = {"case": f"stability map points ({len(pts)}: {', '.join(map(str, masses))} mg x {amplitudes} V; the "
                   "relaxed column load 76 mg between 74 and 78), pedot-micro standing, 30 s, square 0.1 Hz",
           "rounds": rounds}
    walls = {}
    rows = {}
    with tempfile.TemporaryDirectory() as d:
        for k in range(rounds):
            for executor, workers in (("serial", 1), ("processes", 2)):
                for label, extra in (("default", {}), ("accuracy_1e-2", {"accuracy": 1e-2})):
                    key = f"{executor}_{workers}_{label}"
                    path = Path(d) / f"{key}_{k}.csv"
                    clear_build_caches()    # each run from cold: no analysis or layout from the one before
                    res = run_sweep(pts, path, metrics=("returns", "peak_to_peak"), base={**MAP_BASE, **extra},
                                    executor=executor, workers=workers, progress=False)
                    walls.setdefault(key, []).append(res.wall_s)
                    rows[key] = read_results(path)
    for executor, workers in (("serial", 1), ("processes", 2)):
        d_key, a_key = f"{executor}_{workers}_default", f"{executor}_{workers}_accuracy_1e-2"
        rate_d = len(pts) / min(walls[d_key])
        rate_a = len(pts) / min(walls[a_key])
        ref = {(r["payload_mass"], r["amplitude"]): r for r in rows[d_key]}
        dev = [abs(float(r["peak_to_peak"]) / float(ref[(r["payload_mass"], r["amplitude"])]["peak_to_peak"]) - 1)
               for r in rows[a_key]]
        same = [r["returns"] == ref[(r["payload_mass"], r["amplitude"])]["returns"] for r in rows[a_key]]
        out[f"{executor}_{workers}_workers"] = {
            "default_points_per_s": rate_d, "accuracy_points_per_s": rate_a, "ratio": rate_a / rate_d,
            "returns_equal": f"{sum(same)} of {len(same)}", "max_peak_to_peak_deviation": max(dev),
            "failed": sum(bool(r["error"]) for r in rows[a_key])}
    for label in ("default", "accuracy_1e-2"):
        rs = rows[f"serial_1_{label}"]
        m = np.array([float(r["payload_mass"]) for r in rs]) * 1e6
        v = np.array([float(r["amplitude"]) for r in rs])
        ok = np.array([r["returns"] == "True" for r in rs])
        out[f"edges_mg_{label}"] = {f"{a:g} V": e for a, e in simulated_edges(m, v, ok).items()}
    # a wider map on 2 workers, once each: the fixed costs (a pool, the costliest point's tail)
    # spread over more points
    wide_pts = grid(payload_mass=[float(m) * 1e-6 for m in np.linspace(10, 110, wide[0])],
                    amplitude=[float(a) for a in np.linspace(0.25, 1.5, wide[1])])
    wide_rows = {}
    with tempfile.TemporaryDirectory() as d:
        for label, extra in (("default", {}), ("accuracy_1e-2", {"accuracy": 1e-2})):
            clear_build_caches()
            res = run_sweep(wide_pts, Path(d) / f"wide_{label}.csv", metrics=("returns", "peak_to_peak"),
                            base={**MAP_BASE, **extra}, executor="processes", workers=2, progress=False)
            wide_rows[label] = (len(wide_pts) / res.wall_s, read_results(Path(d) / f"wide_{label}.csv"))
    ref = {(r["payload_mass"], r["amplitude"]): r for r in wide_rows["default"][1]}
    acc = wide_rows["accuracy_1e-2"][1]
    out["wide_map_2_workers"] = {
        "points": f"{len(wide_pts)} ({wide[0]} masses 10-110 mg x {wide[1]} amplitudes 0.25-1.5 V)",
        "default_points_per_s": wide_rows["default"][0], "accuracy_points_per_s": wide_rows["accuracy_1e-2"][0],
        "ratio": wide_rows["accuracy_1e-2"][0] / wide_rows["default"][0],
        "returns_equal": f"{sum(r['returns'] == ref[(r['payload_mass'], r['amplitude'])]['returns'] for r in acc)} "
                         f"of {len(acc)}",
        "max_peak_to_peak_deviation": max(abs(float(r["peak_to_peak"]) / float(
            ref[(r["payload_mass"], r["amplitude"])]["peak_to_peak"]) - 1) for r in acc)}
    from mjeap import Scene, rollout
    s = Scene("pedot-micro", orientation="up", payload="76mg@6.27mm")
    t0 = time.perf_counter()
    r = rollout(s, "square:1.0V@0.1Hz", 30.0, progress=False, accuracy=1e-2, metrics=("returns", "peak_to_peak"))
    a = r.meta["accuracy"]
    out["one_point_76mg_1V"] = {"wall_s": time.perf_counter() - t0, "model": a["model"],
                                "runs": [{k: x[k] for k in ("role", "segments", "timestep", "wall_time_s")}
                                         for x in a["runs"]],
                                "damped_modes": a["damped_modes"], "estimated_error": {
                                    k: x["estimated_error"] for k, x in a["metrics"].items()}}
    return out


def run(args) -> dict:
    """The benchmark's section of the JSON."""
    return bench_metric_map()
