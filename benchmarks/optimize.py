"""the cost of a design optimisation beside a plain sweep of the same resolution. The issue's
question on a uniform PZT-5H bimorph file (mjeap optimize: maximise free_deflection over
actuator.length 5-15 mm subject to first_frequency >= 800 Hz, step:200V for 0.05 s, 20
segments), whose optimum is known in closed form (L* from beta_1,
tests/studies/test_optimize.py): SLSQP (3 starts) and differential evolution, evaluations,
wall and their error against L*; beside them the grid sweep of the same two metrics whose
spacing is the 1 % the test asks of the optimiser (2 workers), its best feasible point's
error and wall, and the number of grid points a sweep would need to match each optimiser's
own error. Beside them, an optimisation on a file actuator and on the same actuator by its
catalog id (pzt-hamr-small: maximise first_frequency over its length, the linearised model
alone, 12 evaluations, cold caches each): the file is resolved once at the study's edge and
hits every cache the id hits, so the two walls match (issue 44)."""
from __future__ import annotations

import time
from pathlib import Path

import numpy as np



#: the optimisation bench's actuator: a uniform bimorph (tests/studies/test_optimize.py's closed form)
BENCH_BIMORPH = (Path(__file__).resolve().parents[1] / "examples" / "actuators" / "uniform-bimorph.toml").read_text()


def bench_optimize(f_min=800.0, box=(5e-3, 15e-3), resolution=0.01):
    """The optimisation against a grid sweep of the same question (module text)."""
    import math
    import tempfile
    import mjeap
    from mjeap.studies.sweep import grid, read_results, run_sweep
    # the closed form: L* = beta_1 sqrt(1 / (2 pi f_min)) (EI / mu)^(1/4), EI and mu from the layers
    E, t, rho = np.array([40e9, 340e9, 40e9]), np.array([127e-6, 60e-6, 127e-6]), np.array([7500.0, 1550.0, 7500.0])
    z = np.cumsum(t) - t / 2
    zn = np.sum(E * t * z) / np.sum(E * t)
    EI, mu = 3e-3 * float(np.sum(E * (t**3 / 12 + t * (z - zn) ** 2))), 3e-3 * float(np.sum(rho * t))
    l_star = 1.8751040687 * math.sqrt(1 / (2 * math.pi * f_min)) * (EI / mu) ** 0.25
    question = dict(maximize="free_deflection", subject_to=[f"first_frequency>={f_min:g}"], voltage="step:200V",
                    duration=0.05, base={"segments": 20})
    out = {"case": f"uniform PZT-5H bimorph, maximise free_deflection over actuator.length {box[0] * 1e3:g}-"
                   f"{box[1] * 1e3:g} mm at first_frequency >= {f_min:g} Hz, step:200V for 0.05 s, 20 segments",
           "L_star_closed_form_m": l_star}
    with tempfile.TemporaryDirectory() as d:
        act = Path(d) / "bimorph.toml"
        act.write_text(BENCH_BIMORPH)
        for method in ("slsqp", "differential-evolution"):
            r = mjeap.optimize(str(act), {"actuator.length": box}, method=method, out=Path(d) / method,
                               progress=False, **question)
            err = abs(r.optimum["actuator.length"] / l_star - 1)
            out[method] = {"evaluations": r.evaluations, "wall_s": r.wall_s,
                           "evaluations_per_s": r.evaluations / r.wall_s, "L_m": r.optimum["actuator.length"],
                           "error_vs_L_star": err, "constraint_active": r.constraints[0]["active"],
                           "grid_points_for_this_error": math.ceil((box[1] - box[0]) / (2 * err * l_star)) + 1}
        n = math.ceil((box[1] - box[0]) / (resolution * l_star)) + 1
        pts = grid(**{"actuator.length": list(np.linspace(box[0], box[1], n))})
        t0 = time.perf_counter()
        res = run_sweep(pts, Path(d) / "grid.csv", metrics=("free_deflection", "first_frequency"),
                        base={"actuator": str(act), "waveform": "step", "amplitude": 200.0, "duration": 0.05,
                              "segments": 20}, workers=2, progress=False)
        wall = time.perf_counter() - t0
        rows = [r for r in read_results(res.path) if not r["error"] and float(r["first_frequency"]) >= f_min]
        best = max(rows, key=lambda r: float(r["free_deflection"]))
        out["grid_sweep"] = {"points": n, "spacing_m": (box[1] - box[0]) / (n - 1), "workers": 2, "wall_s": wall,
                             "sum_of_point_walls_s": sum(float(r["wall_s"]) for r in read_results(res.path)),
                             "failed": res.failed, "L_m": float(best["actuator.length"]),
                             "error_vs_L_star": abs(float(best["actuator.length"]) / l_star - 1)}
    return out


def bench_file_actuator(evaluations: int = 12, repeats: int = 2) -> dict:
    """An optimisation on a file actuator beside the same on its catalog id (module text)."""
    import tempfile
    import mjeap
    from mjeap.caching import clear_caches
    from mjeap.model.catalog import CATALOG_DIR
    out = {}
    with tempfile.TemporaryDirectory() as d:
        f = Path(d) / "pzt-hamr-small-copy.toml"
        f.write_bytes((CATALOG_DIR / "pzt-hamr-small.toml").read_bytes())
        for label, actuator in (("catalog_id", "pzt-hamr-small"), ("file", str(f))):
            walls = []
            for _ in range(repeats):
                clear_caches()
                t0 = time.perf_counter()
                r = mjeap.optimize(actuator, {"actuator.length": ("6mm", "12mm")}, maximize="first_frequency",
                                   max_evaluations=evaluations, progress=False)
                walls.append(time.perf_counter() - t0)
            out[label] = {"wall_s": min(walls), "evaluations": r.evaluations,
                          "first_frequency_hz": r.metrics["first_frequency"]}
    out["file_over_id"] = out["file"]["wall_s"] / out["catalog_id"]["wall_s"]
    return out


def run(args) -> dict:
    """The benchmark's section of the JSON."""
    return {**bench_optimize(), "file_actuator": bench_file_actuator()}
