"""The validation report: a console table, JSON, Markdown with figures (matplotlib, optional)
and one Rerun recording per experiment (curves as time series or 2D line strips, the checks
as a table, the simulated beams of the experiment's runs as 3D line strips under /beams)."""
from __future__ import annotations

import json
import re
from pathlib import Path
from typing import List, Optional, Sequence

import numpy as np

from ..io.outputs import replacing
from .core import REFERENCE_KINDS, Experiment

#: beam frames per simulated run in an experiment's recording
MAX_BEAM_FRAMES = 300
COLUMNS = ("experiment", "quantity", "simulated", "reference", "kind", "source", "error", "tolerance", "verdict")


def _fmt(x: float) -> str:
    return "nan" if not np.isfinite(x) else f"{x:.4g}"


def _err(c) -> str:
    if not np.isfinite(c.error):
        return "inf"
    return f"{c.error * 100:+.2f} %" if c.error_kind == "relative" else f"{c.error:+.3g} {c.unit}"


def _tol(c) -> str:
    if c.tolerance is None:
        return "-"
    return f"{c.tolerance * 100:g} %" if c.error_kind == "relative" else f"{c.tolerance:g} {c.unit}"


def rows(experiments: List[Experiment]) -> List[List[str]]:
    return [[c.experiment, c.quantity, f"{_fmt(c.simulated)} {c.unit}", f"{_fmt(c.reference)} {c.unit}",
             c.kind or "-", c.source, _err(c), _tol(c), c.verdict] for ex in experiments for c in ex.checks]


def console_table(experiments: List[Experiment], width: int = 60) -> str:
    def cut(s):
        return s if len(s) <= width else s[: width - 1] + "~"
    body = [[cut(x) for x in r] for r in rows(experiments)]
    w = [max(len(h), *(len(r[i]) for r in body)) if body else len(h) for i, h in enumerate(COLUMNS)]
    line = lambda r: "  ".join(x.ljust(w[i]) for i, x in enumerate(r))  # noqa: E731
    return "\n".join([line(COLUMNS), line(["-" * x for x in w])] + [line(r) for r in body])


def _slug(s: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", s).strip("_")


def write_json(experiments: List[Experiment], path: Path, pending: Sequence[str] = ()) -> None:
    """``validation.json``: ``complete`` is false and ``passed`` false while experiments are
    ``pending`` (not run yet, or never: an interrupted run), named in ``not_run``."""
    doc = {"complete": not pending, "passed": not pending and all(e.passed for e in experiments),
           "not_run": list(pending),
           "experiments": [{"name": e.name, "title": e.title, "seconds": round(e.seconds, 2), "passed": e.passed,
                            "notes": e.notes, "checks": [c.as_dict() for c in e.checks]} for e in experiments]}
    with replacing(path, f"--out ({Path(path).name})", picked=True) as tmp:
        tmp.write_text(json.dumps(doc, indent=1, default=float))


def have_matplotlib() -> bool:
    """Figures need the optional ``report`` extra."""
    import importlib.util
    return importlib.util.find_spec("matplotlib") is not None


def write_figure(ex: Experiment, path: Path) -> None:
    """One PNG per experiment with curves, a panel per curve group, axis labels with units and
    a legend naming each curve's source. Needs matplotlib (:func:`have_matplotlib`)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    panels = list(dict.fromkeys(c.panel for c in ex.curves))
    if not panels:
        return
    ncol = min(3, len(panels))
    nrow = int(np.ceil(len(panels) / ncol))
    fig, axes = plt.subplots(nrow, ncol, figsize=(5.2 * ncol, 3.6 * nrow), squeeze=False)
    for ax, panel in zip(axes.flat, panels):
        for c in (c for c in ex.curves if c.panel == panel):
            ax.plot(c.x, c.y, c.style, label=c.source, ms=4)
            ax.set_xlabel(c.xlabel)
            ax.set_ylabel(c.ylabel)
        ax.set_title(panel, fontsize=10)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
    for ax in list(axes.flat)[len(panels):]:
        ax.set_visible(False)
    fig.suptitle(ex.title, fontsize=11)
    fig.tight_layout()
    with replacing(path, f"--out ({Path(path).name})", picked=True) as tmp:
        fig.savefig(tmp, dpi=110, format=Path(path).suffix[1:] or "png")
    plt.close(fig)


def write_recording(ex: Experiment, path: Path, figure: Optional[Path] = None) -> None:
    """The experiment as a Rerun recording laid out for review: the checks (verdict first),
    curves against time as time series with fitted y axes, the report's figure as an image
    (``figure``: its PNG; curves against other quantities are best read there, with axes and
    units), without matplotlib those curves as a table, and the simulated beams in 3D.
    Written whole (:func:`mjeap.io.outputs.replacing`)."""
    with replacing(path, f"--out ({Path(path).name})", picked=True) as tmp:
        _write_recording(ex, tmp, figure)


def _write_recording(ex: Experiment, path: Path, figure: Optional[Path]) -> None:
    import rerun as rr
    import rerun.blueprint as rrb
    from ..io.recording import deformation_scale, y_axis
    panels = list(dict.fromkeys(c.panel for c in ex.curves))
    timed = [p for p in panels if any(c.xlabel.startswith("time") for c in ex.curves if c.panel == p)]
    untimed = [p for p in panels if p not in timed]
    views = [rrb.TimeSeriesView(origin=f"/{_slug(p)}", name=f"{p} ({_unit_of(ex, p)})",
                                axis_y=y_axis(*[c.y for c in ex.curves if c.panel == p])) for p in timed]
    have_figure = figure is not None and Path(figure).is_file()
    if have_figure:
        views.append(rrb.Spatial2DView(origin="/figure", name="report figure (axes, units, sources)"))
    elif untimed:
        views.append(rrb.TextDocumentView(origin="/curves", name="curves (x, y)"))
    beams = [(label, r, rotation) for label, r, rotation in ex.rollouts]
    scale = 1.0
    if beams:
        # tiny motions (the piezo bimorphs) magnified as in the rollout recordings, and said so
        scale = min(deformation_scale(r, float(np.linalg.norm(r.centreline[0, -1]))) for _, r, _ in beams)
        views.append(rrb.Spatial3DView(origin="/beams",
                                       name="simulated beams (m)" + ("" if scale == 1 else
                                                                     f", deformation shown x{scale:g}"),
                                       line_grid=rrb.archetypes.LineGrid3D(visible=True)))
    checks = rrb.TextDocumentView(origin="/checks", name="checks")
    root = rrb.Horizontal(checks, rrb.Grid(*views), column_shares=[2, 3]) if views else checks
    bp = rrb.Blueprint(root, rrb.BlueprintPanel(state="collapsed"), rrb.SelectionPanel(state="collapsed"),
                       rrb.TimePanel(state="collapsed", timeline="time", play_state="paused"))
    rec = rr.RecordingStream(f"mjeap validate {ex.name}", recording_id=ex.name)
    from ..io.recording import rrd_file
    with rrd_file(rec, path, bp):
        rec.log("checks", rr.TextDocument(markdown_section(ex, figures=False), media_type="text/markdown"), static=True)
        if have_figure:
            rec.log("figure", rr.EncodedImage(path=figure), static=True)
        palette = [[31, 119, 180], [255, 127, 14], [44, 160, 44], [214, 39, 40], [148, 103, 189], [140, 86, 75]]
        table = []
        for i, c in enumerate(ex.curves):
            color = palette[i % len(palette)]
            if c.panel in timed:
                ent = f"{_slug(c.panel)}/{_slug(c.source)}"
                rec.log(ent, rr.SeriesLines(names=f"{c.source} ({c.ylabel})", colors=[color],
                                            widths=[3.0 if "mjeap" not in c.source else 1.5]), static=True)
                rec.send_columns(ent, indexes=[rr.TimeColumn("time", duration=c.x)],
                                 columns=rr.Scalars.columns(scalars=c.y))
            elif not have_figure:
                table += [f"**{c.panel}: {c.source}**", "", f"| {c.xlabel} | {c.ylabel} |", "|---|---|"]
                table += [f"| {_fmt(x)} | {_fmt(y)} |" for x, y in zip(c.x, c.y)] + [""]
        if table:
            rec.log("curves", rr.TextDocument("\n".join(table), media_type="text/markdown"), static=True)
        for i, (label, r, rotation) in enumerate(beams):
            R = np.eye(3) if rotation is None else np.asarray(rotation)
            idx = np.arange(0, len(r.time), max(1, len(r.time) // MAX_BEAM_FRAMES))
            shown = r.centreline[idx].copy()
            shown[..., 1:] *= scale
            pts = shown @ R.T
            ent = f"beams/{_slug(label)}"
            rec.log(ent, rr.LineStrips3D.from_fields(colors=[palette[i % len(palette)]], labels=[label]), static=True)
            if len(idx) == 1:                      # a settled shape: no timeline
                rec.log(ent, rr.LineStrips3D(list(pts)), static=True)
                continue
            rec.send_columns(ent, indexes=[rr.TimeColumn("time", duration=r.time[idx])],
                             columns=rr.LineStrips3D.columns(strips=list(pts)).partition([1] * len(idx)))


def _unit_of(ex: Experiment, panel: str) -> str:
    labels = {c.ylabel for c in ex.curves if c.panel == panel}
    return ", ".join(sorted(labels))


def markdown_section(ex: Experiment, figures: bool = True) -> str:
    out = [f"## {ex.title}", "", f"`{ex.name}` ({ex.seconds:.1f} s)", ""]
    # the verdict first and the (long) source last: a narrow view shows what matters
    out += ["| verdict | quantity | simulated | reference | error | tolerance | reference kind | source |",
            "|---|---|---|---|---|---|---|---|"]
    for r in rows([ex]):
        quantity, sim, ref, kind, src, err, tol, verdict = r[1:]
        out.append("| " + " | ".join(x.replace("|", "/") for x in (verdict, quantity, sim, ref, err, tol, kind, src))
                   + " |")
    if ex.notes:
        out += [""] + [f"- {n}" for n in ex.notes]
    if figures and ex.curves:
        out += ["", f"![{ex.name}]({ex.name}.png)"]
    return "\n".join(out) + "\n"


def write_markdown(experiments: List[Experiment], path: Path, figures: bool, pending: Sequence[str] = ()) -> None:
    """``report.md``; while experiments are ``pending`` (an interrupted run) it opens by
    saying it is incomplete and which have not run."""
    n = sum(len(e.checks) for e in experiments)
    failed = [c for e in experiments for c in e.checks if c.verdict == "FAIL"]
    toleranced = sum(c.tolerance is not None for e in experiments for c in e.checks)
    kinds = {k: sum(c.tolerance is not None and c.kind == k for e in experiments for c in e.checks)
             for k in REFERENCE_KINDS}
    head = ["# mjeap validation report", ""]
    if pending:
        head += [f"**INCOMPLETE: {len(experiments)} of {len(experiments) + len(pending)} experiments ran; not run: "
                 f"{', '.join(pending)}.** The counts below are of those that ran.", ""]
    head += [f"{n} rows, {toleranced} with a tolerance, {len(failed)} failed. "
            "'compare' rows set the simulation beside a published number or a model it is not "
            "expected to match within a tolerance; their notes say why they differ.", "",
            "Every toleranced row is against a reference independent of the code: "
            + ", ".join(f"{v} against {'an' if k[0] in 'aeiou' else 'a'} {k}" for k, v in kinds.items())
            + " (a published number is printed in a source, named by its table or section; a published formula is "
            "transcribed with its equation; an independent solution is computed by a different method: a BVP, an "
            "eigenproblem, shooting, elliptic integrals, the exact continuum solution). 'compare' rows include "
            "checks of a quantity against the number it was fitted to and round trips of the identification tool.",
            ""]
    if not figures:
        head += ["(Figures need matplotlib: `pip install -e '.[report]'`.)", ""]
    with replacing(path, f"--out ({Path(path).name})", picked=True) as tmp:
        tmp.write_text("\n".join(head) + "\n" + "\n".join(markdown_section(e, figures) for e in experiments))
