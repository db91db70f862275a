"""runs at a stated accuracy (mjeap.simulation.accuracy) against the default model, side by
side: Dadras et al. 2021's heaviest run at 1e-2 and 1e-3 (wall, estimated and true error), a
batch of 16 at 1e-2 on 2 threads against the loop one by one, the stability map's points at
1e-2, where the native step's time goes (MuJoCo's timers) and the accuracy claim on seeded
cases."""
from __future__ import annotations

import time
from pathlib import Path

import mujoco
import numpy as np

from mjeap import Scene


def _step_phases(model, data, n=20000) -> dict:
    """Where mj_step's time goes (MuJoCo's own timers, us per step and share)."""
    mujoco.set_mjcb_time(lambda: time.perf_counter() * 1e6)
    try:
        mujoco.mj_step(model, data, nstep=n)
    finally:
        mujoco.set_mjcb_time(None)
    total = data.timer[mujoco.mjtTimer.mjTIMER_STEP].duration
    out = {}
    for t in mujoco.mjtTimer.__members__.values():
        if int(t) < len(data.timer) and data.timer[t].number:
            out[t.name[len("mjTIMER_"):].lower()] = {"us": data.timer[t].duration / data.timer[t].number,
                                                      "share": data.timer[t].duration / total}
    return out


def bench_accuracy(claim_cases=12):
    """Runs at a stated accuracy (mjeap.simulation.accuracy) against today's default model, side by side:
    Dadras et al. 2021's heaviest run (wall of all runs, estimated and true error against 40 segments
    at 1/60 of the 10 ms sample grid under discrete), a batch of 16 at 1e-2 on 2 threads
    against the loop one by one, the stability map's points at 1e-2, where the native
    step's time goes, and the accuracy claim on seeded cases."""
    from mjeap import rollout, rollout_batch
    from mjeap.simulation.accuracy import relative_difference
    from mjeap.drives import make_drive
    from mjeap.studies.stability_map import MAP_BASE
    from mjeap.studies.sweep import grid, read_results, run_sweep
    from mjeap.validation.accuracy_claim import check_case, draw_cases, summarise
    wave, args = "square:1.5V@0.1Hz", dict(initial_curvature=-303.0, progress=False)
    s = Scene("pedot-micro", orientation="up", payload="12.6mg@6.27mm")
    out = {"case": "pedot-micro, 12.6 mg @ 6.27 mm, up, square 3 Vpp 0.1 Hz, 20 s, from -303 1/m"}
    ref_scene = s.variant(40, 0.01 / 60, "discrete")
    ref = rollout(ref_scene, wave, 20.0, drive=make_drive(None, ref_scene), sample_interval=0.01, **args)
    t0 = time.perf_counter()
    r = rollout(s, wave, 20.0, sample_interval=s.timestep, **args)
    wall = time.perf_counter() - t0
    y = np.interp(ref.time, r.time, r.tip_curvature)
    out["default"] = {"model": f"{s.layout.segments} segments, {s.integrator}, h = {s.timestep:.4g} s",
                      "wall_s": wall, "true_error": float(np.max(np.abs(y - ref.tip_curvature)) / np.ptp(ref.tip_curvature))}
    r = rollout(s, wave, 20.0, estimate_error=True, **args)
    out["default"]["estimated_error"] = r.meta["accuracy"]["estimated_error"]
    for target in (1e-2, 1e-3):
        t0 = time.perf_counter()
        r = rollout(s, wave, 20.0, accuracy=target, **args)
        wall = time.perf_counter() - t0
        a = r.meta["accuracy"]
        out[f"accuracy_{target:g}"] = {"model": a["model"], "wall_s": wall, "runs": [x["role"] for x in a["runs"]],
                                       "estimated_error": a["estimated_error"],
                                       "true_error": relative_difference(ref, r),
                                       "speedup_vs_default": out["default"]["wall_s"] / wall}
    volts = [f"square:{v:.4g}V@0.1Hz" for v in np.linspace(0.5, 1.5, 16)]
    t0 = time.perf_counter()
    for v in volts:
        rollout(s, v, 20.0, engine="loop", **args)
    loop = time.perf_counter() - t0
    t0 = time.perf_counter()
    rs = rollout_batch(s, volts, 20.0, initial_curvatures=-303.0, nthread=2, accuracy=1e-2)
    batch = time.perf_counter() - t0
    out["batch16"] = {"loop_one_by_one_default_s": loop, "batch_2threads_accuracy_1e-2_s": batch,
                      "throughput_ratio": loop / batch, "model": rs[0].meta["accuracy"]["model"],
                      "largest_estimated_error": max(x.meta["accuracy"]["estimated_error"] for x in rs)}
    pts = grid(payload_mass=list(np.linspace(15e-6, 120e-6, 4)), amplitude=[0.5, 1.5])
    import tempfile
    with tempfile.TemporaryDirectory() as d:
        for label, extra, share in (("default", {}, True), ("accuracy_1e-2_pilots_per_point", {"accuracy": 1e-2}, False),
                                    ("accuracy_1e-2", {"accuracy": 1e-2}, True)):
            res = run_sweep(pts, Path(d) / f"{label}.csv", metrics=("returns", "peak_to_peak"),
                            base={**MAP_BASE, **extra}, workers=2, progress=False, share_error_models=share)
            rows = read_results(Path(d) / f"{label}.csv")
            out[f"stability_map_{label}_points_per_s"] = res.throughput
            out[f"stability_map_{label}_returns"] = {f"{float(r['payload_mass']) * 1e6:.1f} mg, {r['amplitude']} V":
                                                     r["returns"] for r in rows}
    nat = s.native_model(make_drive(None, s))
    nat.reset(-303.0)
    out["native_step_phases"] = {"nv": nat.model.nv, "nbody": nat.model.nbody, **_step_phases(nat.model, nat.data)}
    rows = [check_case(c) for c in draw_cases(seed=23, n=claim_cases)]
    out["claim"] = {**summarise(rows), "seed": 23,
                    "rows": [{k: r[k] for k in ("case", "model", "true_error", "estimated_error", "wall_s")} for r in rows]}
    return out


def run(args) -> dict:
    """The benchmark's section of the JSON."""
    return bench_accuracy()
