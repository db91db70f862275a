"""The stability map of Dadras et al. 2021's inverted actuator under a payload: a sweep of
payload mass x drive amplitude (:mod:`mjeap.studies.sweep`), judged by the paper's criterion
(the tip curvature still changes sign in the third period of the square wave), with the
theory boundaries drawn over it (:func:`column_limits`) and the simulated edge read off the
sweep (:func:`simulated_edges`); as a command line (:func:`main`, ``python
scripts/stability_map.py``) it writes results.csv (resumable), stability_map.png, report.md
and stability_map.rrd.

The beam stands up (clamp below), the payload sits at l_e past the clamp on a rigid arm
beyond the beam's end (L = 6 mm, l_e = 6.27 mm). Theory is amplitude independent: the
Euler column with the payload on the arm (k a tan(kL) = 1, :func:`analytical.critical_load_with_arm`)
with the instantaneous EI of eq. 8 and with its relaxed (DC) EI, x pole/zero = 0.3/0.52,
and the paper's own Region 3 model's marginal mass."""
from __future__ import annotations

import argparse
from pathlib import Path
from typing import Dict, Sequence

import numpy as np

from ..io.commandline import arg_integer, arg_output, parse_args
from ..io.outputs import check_outputs, replacing
from ..io.recording import rrd_file
from ..model import analytical as an
from ..engines import ENGINES
from .sweep import EXECUTORS, grid, read_results, run_sweep

__all__ = ["MAP_BASE", "column_limits", "simulated_edges", "main"]

#: the sweep base of Dadras et al. 2021's map: standing up, payload at l_e, 0.1 Hz square wave, 30 s
#: (three periods)
MAP_BASE = dict(actuator="pedot-micro", orientation="up", payload_position=6.27e-3, waveform="square",
                frequency=0.1, duration=30.0)


def column_limits(l_e: float = 6.27e-3, length: float = 6e-3) -> Dict[str, float]:
    """Payload masses (kg) of the theory boundaries, by name."""
    model = an.DadrasModel()
    ei, g = 1.0 / model.mechanical_gain, model.gravity
    p_arm = an.critical_load_with_arm(length, ei, l_e - length)
    return {"column, instantaneous EI": p_arm / g,
            "column, relaxed EI (static limit)": model.pole / model.zero * p_arm / g,
            "paper's Region 3 model (marginal)": model.marginal_mass(l_e)}


def simulated_edges(mass: Sequence[float], amplitude: Sequence[float], returns: Sequence[bool]) -> Dict[float, float]:
    """Per amplitude: the mass midway between the heaviest returning point and the lightest
    heavier one that does not return (NaN where the sweep does not bracket the edge)."""
    m, v, ok = np.asarray(mass, float), np.asarray(amplitude, float), np.asarray(returns, bool)
    edges = {}
    for amp in np.unique(v):
        sel = v == amp
        good, bad = m[sel & ok], m[sel & ~ok]
        above = bad[bad > good.max()] if good.size else bad
        edges[float(amp)] = 0.5 * (good.max() + above.min()) if good.size and above.size else float("nan")
    return edges


MAP_DESCRIPTION = ("Stability map of the PEDOT micro trilayer standing up (Dadras et al. 2021): payload mass x drive "
                   "amplitude.")


def main(argv=None):
    """The map's command line: ``python scripts/stability_map.py --help``."""
    a = parse_args(_parser(), argv)
    if a.accuracy is not None:
        from ..simulation.accuracy import check_accuracy
        check_accuracy(a.accuracy)
    out = Path(a.out)
    # the files it names itself, checked before any work: regular files or none, never a link
    named = {f"--out ({n})": out / n for n in ("stability_map.png", "report.md", "stability_map.rrd")}
    check_outputs(picked=named, **named)
    masses = np.linspace(0.0, 150e-6, a.masses)[1:]
    amps = np.linspace(0.25, 1.5, a.amplitudes)
    points = grid(payload_mass=[float(m) for m in masses], amplitude=[float(v) for v in amps])
    # at a target the map asks for its answer, read on the last period (relaxed steps,
    # mjeap.simulation.metric_accuracy); the stress proxy reads the release transient
    metrics = (("returns", "peak_to_peak", "estimated_error") if a.accuracy else
               ("returns", "peak_to_peak", "max_stress_proxy")) + \
        (("stopped_early",) if a.stop_when_periodic else ())
    base = {**MAP_BASE, "engine": a.engine, "duration": a.periods * (1.0 / MAP_BASE["frequency"]),
            **({"accuracy": a.accuracy} if a.accuracy else {}),
            **({"stop_when_periodic": a.stop_when_periodic} if a.stop_when_periodic else {})}
    s = run_sweep(points, out / "results.csv", metrics=metrics, base=base,
                  executor=a.executor, workers=a.workers)
    print(f"{s.done} rollouts in {s.wall_s:.1f} s ({s.throughput:.2f}/s), {s.skipped} already done, {s.failed} failed")
    rows = read_results(out / "results.csv")
    m = np.array([float(r["payload_mass"]) for r in rows]) * 1e6
    v = np.array([float(r["amplitude"]) for r in rows])
    ok = np.array([r["returns"] == "True" for r in rows])
    bounds = {k: b * 1e6 for k, b in column_limits().items()}
    sim_edge = simulated_edges(m, v, ok)
    lines = ["# Stability map: pedot-micro standing up, payload at l_e = 6.27 mm, 0.1 Hz square wave", "",
             f"{len(rows)} points of {a.periods} periods; criterion: tip curvature changes sign in the last period "
             "(Dadras et al. 2021: the third)"
             + (f"; stopped once periodic within {a.stop_when_periodic:g} (stopped_early)"
                if a.stop_when_periodic else "") + ".", "",
             "| amplitude (V) | simulated limit (mg) |", "|---|---|"]
    lines += [f"| {amp:.3g} | {edge:.1f} |" for amp, edge in sim_edge.items()]
    lines += ["", "| theory (amplitude independent) | mass (mg) |", "|---|---|"]
    lines += [f"| {k} | {b:.1f} |" for k, b in bounds.items()]
    lines += ["", "Below the relaxed column load the beam holds any amplitude; above it, the drive's own moment "
              "pushes the column back through straight each half period, so the drive-following limit rises "
              "with amplitude (validation: 99.7 mg at 1.5 V), up to the instantaneous column load."]
    _figure(out, m, v, ok, bounds, lines)
    with replacing(out / "report.md", "--out (report.md)", picked=True) as tmp:
        tmp.write_text("\n".join(lines) + "\n")

    _recording(out, m, v, ok, lines)
    print("\n".join(lines))
    print(f"wrote {out / 'report.md'}, {out / 'stability_map.rrd'}")


def _parser() -> argparse.ArgumentParser:
    """The map's options."""
    ap = argparse.ArgumentParser(description=MAP_DESCRIPTION)
    ap.add_argument("--out", default="out/stability", type=arg_output(inside="results.csv"),
                    help="folder of results.csv, stability_map.png, report.md and stability_map.rrd")
    ap.add_argument("--workers", type=arg_integer(1), default=2)
    ap.add_argument("--executor", default="processes", choices=EXECUTORS)
    ap.add_argument("--engine", default="auto", choices=ENGINES,
                    help="the engine every point runs on (warp: MuJoCo Warp, the optional 'warp' extra)")
    ap.add_argument("--masses", type=arg_integer(2, 1000), default=11,
                    help="payload masses from 0 to 150 mg, 0 left out (2 to 1000)")
    ap.add_argument("--amplitudes", type=arg_integer(1, 1000), default=6,
                    help="amplitudes from 0.25 to 1.5 V (1 to 1000); the map runs masses x amplitudes points")
    ap.add_argument("--accuracy", type=float, default=None,
                    help="error (1e-5 to 0.2) of each point's answer, returns and peak_to_peak (relative to the "
                         "swing; returns decided only beyond its estimated error, else refined): segments, integrator "
                         "and timestep chosen per point, steps far beyond the beam's modes where the drive is slow; "
                         "estimates in the estimated_error.METRIC columns (max_stress_proxy is then not reported)")
    ap.add_argument("--periods", type=arg_integer(1, 1000), default=3,
                    help="drive periods (10 s each) a point runs, the criterion read on the last (Dadras et al. 2021: "
                         "3)")
    ap.add_argument("--stop-when-periodic", type=float, default=None, metavar="TOL",
                    help="stop a point once its last drive period repeats the one before within TOL (1e-6 to 0.2, "
                         "of the tip curvature's range and of the length) and its shrinking change still to come "
                         "stays within it: its outcome is decided; the stopped_early column says where (from the "
                         "third period's end on: needs --periods 4 or more; refused before any point otherwise)")
    return ap


def _figure(out: Path, m, v, ok, bounds: dict, lines: list) -> None:
    """stability_map.png (the report extra), named in the report ``lines``; else the report
    says why not."""
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(figsize=(7, 5.5))
        ax.scatter(m[ok], v[ok], marker="o", c="tab:green", label="returns")
        ax.scatter(m[~ok], v[~ok], marker="x", c="tab:red", label="stays collapsed / diverges")
        for (k, b), ls in zip(bounds.items(), ("-", "--", ":")):
            ax.axvline(b, color="k", ls=ls, label=f"{k}: {b:.0f} mg")
        ax.set_xlabel("payload mass (mg)")
        ax.set_ylabel("square-wave amplitude (V)")
        ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.14), ncol=2)
        ax.set_title("pedot-micro standing up, l_e = 6.27 mm, 0.1 Hz")
        fig.tight_layout()
        with replacing(out / "stability_map.png", "--out (stability_map.png)", picked=True) as tmp:
            fig.savefig(tmp, dpi=120, format="png")
        lines.insert(2, "![stability map](stability_map.png)\n")
    except ImportError:
        lines.append("\n(figure skipped: pip install -e '.[report]' for matplotlib)")


def _recording(out: Path, m, v, ok, lines: list) -> None:
    """stability_map.rrd: the report beside the map as a figure (axes, units, legend); without
    matplotlib the report's tables alone."""
    import rerun as rr
    import rerun.blueprint as rrb
    figure = out / "stability_map.png"
    views = [rrb.TextDocumentView(origin="/report", name="stability map: report")]
    if figure.exists():
        views.append(rrb.Spatial2DView(origin="/figure", name="payload mass (mg) x amplitude (V)"))
    rec = rr.RecordingStream("mjeap stability map")
    bp = rrb.Blueprint(rrb.Horizontal(*views, column_shares=[2, 3][:len(views)]), rrb.BlueprintPanel(state="collapsed"),
                       rrb.SelectionPanel(state="collapsed"), rrb.TimePanel(state="collapsed"))
    with replacing(out / "stability_map.rrd", "--out (stability_map.rrd)", picked=True) as tmp, \
            rrd_file(rec, tmp, bp):
        if figure.exists():
            rec.log("figure", rr.EncodedImage(path=figure), static=True)
        table = ["", "| payload (mg) | amplitude (V) | returns |", "|---|---|---|"]
        table += [f"| {mm:.1f} | {vv:.3g} | {'yes' if o else 'no'} |" for mm, vv, o in zip(m, v, ok)]
        rec.log("report", rr.TextDocument("\n".join([x for x in lines if not x.startswith("![")] + table),
                                          media_type="text/markdown"), static=True)
