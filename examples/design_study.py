#!/usr/bin/env python
"""A worked design study: how long and how thick should a PZT-5H bimorph leg actuator be for
the largest stroke, when its first resonance must stay above a bandwidth floor?

The actuator is examples/actuators/long-bimorph.toml (a tapered bimorph with an alumina tip
block). A grid sweep varies its length and its plates' thickness (both plates together:
``actuator.roles.piezo.thickness``) and reads two metrics per point: ``free_deflection`` (m,
simulated at full drive, 200 V) and ``first_frequency`` (Hz, the linearised model). The
picture draws the stroke over the grid with the floor's contour; ``mjeap.optimize`` then finds
the longest-stroke design on the floor, drawn as a star. Writes out/design-study/ (the sweep's
CSV, the optimisation's files and design-study.png; ``--png`` puts the figure elsewhere).

    python examples/design_study.py                 # about 10 s on 2 cores (7 s measured)

The figure needs matplotlib, mjeap's ``report`` extra (``pip install "mjeap[report]"``);
without it the study runs and says so, and only the figure is left out (``--png`` without it is
refused before any work).
"""
import argparse
import importlib.util
import sys
from pathlib import Path

import numpy as np

import mjeap
from mjeap.studies.sweep import grid, read_results, run_sweep

HERE = Path(__file__).resolve().parent
ACTUATOR = HERE / "actuators" / "long-bimorph.toml"
FLOOR_HZ = 600.0                 # the bandwidth floor: first resonance at least this (Hz)
LENGTHS = np.linspace(8e-3, 20e-3, 7)            # m
THICKNESSES = np.linspace(80e-6, 200e-6, 7)      # m, each plate
RUN = {"waveform": "step", "amplitude": 200.0, "duration": 0.03, "segments": 10, "orientation": "down"}


def main(argv=None):
    from mjeap.io.commandline import arg_integer, arg_output
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="out/design-study", help="folder of the sweep's and optimisation's files")
    ap.add_argument("--png", default=None, type=arg_output(), help="the figure (default: OUT/design-study.png)")
    ap.add_argument("--workers", type=arg_integer(1), default=2)
    a = ap.parse_args(argv)
    out = Path(a.out)
    figure = importlib.util.find_spec("matplotlib") is not None
    if not figure:                      # said before the work, not after it
        if a.png:                       # a file asked for by name is never silently left out
            ap.error("--png: the figure needs matplotlib, which is not installed (pip install \"mjeap[report]\")")
        print("design_study: matplotlib is not installed: the figure is left out (pip install \"mjeap[report]\" "
              "for it); the sweep and the optimisation run", file=sys.stderr)
    points = grid(**{"actuator.length": [float(x) for x in LENGTHS],
                     "actuator.roles.piezo.thickness": [float(x) for x in THICKNESSES]})
    run_sweep(points, out / "grid.csv", metrics=("free_deflection", "first_frequency"),
              base={"actuator": str(ACTUATOR), **RUN}, workers=a.workers)
    rows = read_results(out / "grid.csv")
    L = np.array([float(r["actuator.length"]) for r in rows])
    t = np.array([float(r["actuator.roles.piezo.thickness"]) for r in rows])
    stroke = np.array([float(r["free_deflection"]) for r in rows])
    f1 = np.array([float(r["first_frequency"]) for r in rows])
    best = mjeap.optimize(str(ACTUATOR), {"actuator.length": (LENGTHS[0], LENGTHS[-1]),
                                          "actuator.roles.piezo.thickness": (THICKNESSES[0], THICKNESSES[-1])},
                          maximize="free_deflection", subject_to=[f"first_frequency>={FLOOR_HZ:g}"],
                          voltage="step:200V", duration=RUN["duration"],
                          base={"segments": RUN["segments"], "orientation": RUN["orientation"]}, out=out / "optimum")
    if figure:
        plot(L, t, stroke, f1, best, Path(a.png) if a.png else out / "design-study.png")
    print(f"optimum: length {best.optimum['actuator.length'] * 1e3:.2f} mm, plates "
          f"{best.optimum['actuator.roles.piezo.thickness'] * 1e6:.1f} um: stroke "
          f"{best.metrics['free_deflection'] * 1e6:.1f} um, first resonance {best.metrics['first_frequency']:.0f} Hz "
          f"({best.evaluations} evaluations); written {out}")


def plot(L, t, stroke, f1, best, png: Path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    n = len(np.unique(L))
    order = np.lexsort((t, L))
    X, Y = L[order].reshape(n, -1) * 1e3, t[order].reshape(n, -1) * 1e6
    S, F = stroke[order].reshape(n, -1) * 1e6, f1[order].reshape(n, -1)
    fig, ax = plt.subplots(figsize=(7, 5.2))
    cs = ax.contourf(X, Y, S, levels=14, cmap="viridis")
    fig.colorbar(cs, ax=ax, label="free deflection at 200 V (um), simulated (mjeap sweep)")
    c = ax.contour(X, Y, F, levels=[FLOOR_HZ], colors="w", linewidths=2)
    ax.clabel(c, fmt=lambda v: f"f1 = {v:.0f} Hz floor", fontsize=8)
    ax.contourf(X, Y, F, levels=[0, FLOOR_HZ], colors="none", hatches=["//"])
    ax.plot(best.optimum["actuator.length"] * 1e3, best.optimum["actuator.roles.piezo.thickness"] * 1e6, "r*",
            ms=16, label=f"optimum (mjeap.optimize, SLSQP): {best.metrics['free_deflection'] * 1e6:.0f} um, "
                         f"{best.metrics['first_frequency']:.0f} Hz")
    ax.set_xlabel("active length L (mm)")
    ax.set_ylabel("PZT plate thickness t_p (um), each of two")
    ax.set_title("long-bimorph.toml: stroke against length and plate thickness\n"
                 f"hatched: first resonance below {FLOOR_HZ:.0f} Hz (linearised model)", fontsize=10)
    ax.legend(loc="upper left", fontsize=8)
    fig.tight_layout()
    from mjeap.io.outputs import replacing
    with replacing(png, "--png") as tmp:              # mjeap's one writer: whole, never through a link
        fig.savefig(tmp, dpi=110, format="png")
    plt.close(fig)


if __name__ == "__main__":
    from mjeap.io.commandline import run_script
    sys.exit(run_script(main))
