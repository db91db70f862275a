"""Rerun recordings of rollouts (``.rrd``), written headless.

Entity paths (SI: metres, seconds, volts):

* ``/beam/centreline`` LineStrips3D: clamp, hinges and tip (clamp frame, gravity-aware
  world frame of the scene), ``/beam/tip`` and ``/beam/payload`` Points3D,
  ``/beam/clamp`` Boxes3D (static)
* ``/plots/voltage`` applied voltage (V)
* ``/plots/tip_curvature/simulated`` and ``/plots/tip_curvature/reference`` (1/m):
  the arc through clamp and tip, and the analytical prediction where the drive has one
* ``/plots/tip_position/x``, ``/plots/tip_position/y`` (m), ``/plots/tip_angle`` (rad)
* ``/plots/drive/<signal>`` every drive signal (charge, moment, current, ...)
* ``/log`` TextLog: warnings and, for a failed run, the error; ``/meta`` the run's
  parameters as text (static)

Timeline ``time`` is simulated time. A default blueprint lays the 3D view beside the
time series.
"""
from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np

MAX_FRAMES = 2000


def _slug(name: str) -> str:
    return re.sub(r"[^a-z0-9_]+", "_", name.split(" (")[0].lower()).strip("_")


def blueprint():
    import rerun.blueprint as rrb
    return rrb.Blueprint(
        rrb.Horizontal(
            rrb.Spatial3DView(origin="/beam", name="beam"),
            rrb.Vertical(
                rrb.TimeSeriesView(origin="/plots/tip_curvature", name="tip curvature (1/m)"),
                rrb.TimeSeriesView(origin="/plots/voltage", name="voltage (V)"),
                rrb.TimeSeriesView(origin="/plots/drive", name="drive"),
                rrb.TimeSeriesView(origin="/plots/tip_position", name="tip position (m)"),
            ),
            column_shares=[2, 3],
        ),
        rrb.BlueprintPanel(state="collapsed"), rrb.SelectionPanel(state="collapsed"),
    )


def write_recording(path, result, scene, extra=None, views=()) -> Path:
    """Write ``result`` of a rollout of ``scene`` to ``path`` (.rrd); the file is flushed
    and closed before returning, also for a failed (partial) run. ``extra(rec)`` may log
    more entities to the open ``rerun.RecordingStream``; ``views`` (rerun blueprint views)
    are added to the default layout for them."""
    import rerun as rr
    import rerun.blueprint as rrb
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    rec = rr.RecordingStream("mjeap", recording_id=f"{scene.actuator.id}-{result.meta.get('drive', '')}")
    bp = blueprint()
    if views:
        bp = rrb.Blueprint(rrb.Vertical(bp.root_container, rrb.Horizontal(*views)),
                           rrb.BlueprintPanel(state="collapsed"), rrb.SelectionPanel(state="collapsed"))
    rec.save(str(path), default_blueprint=bp)
    try:
        t = result.time
        R = scene.rotation  # clamp frame -> world
        rec.log("meta", rr.TextDocument(json.dumps(result.meta, indent=1, default=str), media_type="text/markdown"),
                static=True)
        L = scene.layout.length
        w = float(scene.actuator.width_at(0.0))
        rec.log("beam/clamp", rr.Boxes3D(centers=[R @ [-0.04 * L, 0, 0]], half_sizes=[[0.04 * L, 0.02 * L, 0.6 * w]],
                                         colors=[[90, 90, 90]]), static=True)
        n = len(t)
        if n:
            cols = [("plots/voltage", result.voltage, "voltage (V)"),
                    ("plots/tip_curvature/simulated", result.tip_curvature, "simulated (mjeap)"),
                    ("plots/tip_position/x", result.tip_position[:, 0], "tip x (m)"),
                    ("plots/tip_position/y", result.tip_position[:, 1], "tip y (m)"),
                    ("plots/tip_angle", result.tip_angle, "tip angle (rad)")]
            if result.reference_curvature is not None:
                cols.append(("plots/tip_curvature/reference", result.reference_curvature,
                             "reference (analytical)"))
            for k, v in result.signals.items():
                cols.append((f"plots/drive/{_slug(k)}", v, k))
            for ent, y, label in cols:
                rec.log(ent, rr.SeriesLines(names=label), static=True)
                rec.send_columns(ent, indexes=[rr.TimeColumn("time", duration=t)],
                                 columns=rr.Scalars.columns(scalars=np.asarray(y, dtype=float)))
            # 3D frames, decimated to at most MAX_FRAMES, sent as columns (one batch)
            idx = np.arange(0, n, max(1, n // MAX_FRAMES))
            tf = rr.TimeColumn("time", duration=t[idx])
            pts = result.centreline[idx] @ R.T                       # (f, N + 2, 3)
            rec.send_columns("beam/centreline", indexes=[tf],
                             columns=rr.LineStrips3D.columns(strips=list(pts)).partition([1] * len(idx)))
            rec.log("beam/centreline", rr.LineStrips3D.from_fields(colors=[[50, 115, 205]]), static=True)
            rec.send_columns("beam/tip", indexes=[tf],
                             columns=rr.Points3D.columns(positions=pts[:, -1]))
            rec.log("beam/tip", rr.Points3D.from_fields(radii=[0.01 * L], colors=[[255, 80, 30]]), static=True)
            if result.payload_position is not None:
                rec.send_columns("beam/payload", indexes=[tf],
                                 columns=rr.Points3D.columns(positions=result.payload_position[idx] @ R.T))
                rec.log("beam/payload", rr.Points3D.from_fields(radii=[scene.payload.sphere_radius],
                                                                colors=[[190, 50, 50]]), static=True)
        for w in result.meta.get("warnings", []):
            if n:
                rec.set_time("time", duration=float(t[-1]))
            rec.log("log", rr.TextLog(w, level="WARN"))
        if "error" in result.meta:
            if n:
                rec.set_time("time", duration=float(t[-1]))
            rec.log("log", rr.TextLog(result.meta["error"], level="ERROR"))
        if extra is not None:
            extra(rec)
    finally:
        rec.flush()
        rec.disconnect()
    return path


def read_recording(path) -> dict:
    """Read a recording back: entity path -> list of pyarrow record batches."""
    from rerun.chunk import RrdReader
    out: dict = {}
    for chunk in RrdReader(str(path)).stream():
        out.setdefault(chunk.entity_path, []).append(chunk.to_record_batch())
    return out
