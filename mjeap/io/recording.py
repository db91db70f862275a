"""Rerun recordings of rollouts (``.rrd``), written headless, laid out for review.

Entity paths (SI: metres, seconds, volts):

* ``/beam/centreline`` LineStrips3D: clamp, hinges and tip (clamp frame, gravity-aware
  world frame of the scene), drawn with the displayed deformation scale (see below);
  ``/beam/tip`` and ``/beam/payload`` Points3D, ``/beam/clamp`` Boxes3D and
  ``/beam/scale_bar`` (static)
* ``/plots/voltage`` applied voltage (V)
* ``/plots/tip_curvature/simulated`` and ``/plots/tip_curvature/reference`` (1/m):
  the arc through clamp and tip, and the analytical prediction where the drive has one
  (thicker, orange, under the simulation: agreement shows as a blue line on orange)
* ``/plots/tip_position/x``, ``/plots/tip_position/y`` (m, each in its own view),
  ``/plots/tip_angle`` (rad)
* ``/plots/drive/<signal>`` every drive signal, one view per unit (charge, currents,
  moments, ...)
* ``/log`` TextLog: warnings and, for a failed run, the error; ``/meta`` the run's
  parameters with their sources (static, in the layout)

Timeline ``time`` is simulated time; the viewer opens paused. Deformation scale: where the
largest deflection is below 1 % of L (piezo bimorphs: +-72 um on 9.2 mm), the 3D view
shows the deflection magnified (x 2, 5, 10, ...) and says so in its title, as finite-element
post-processors do; the time series are always true values.
"""
from __future__ import annotations

import re
from collections import OrderedDict
from contextlib import contextmanager
from pathlib import Path

import mujoco
import numpy as np

from .outputs import replacing

MAX_FRAMES = 2000
#: deflection / L below which the 3D view magnifies the deformation
SMALL_DEFLECTION = 0.01
#: the magnified largest deflection, as a fraction of L
SHOWN_DEFLECTION = 0.2
SIMULATED = [40, 110, 220]
REFERENCE = [255, 150, 30]


def _slug(name: str) -> str:
    return re.sub(r"[^a-z0-9_]+", "_", name.split(" (")[0].lower()).strip("_")


def _unit(name: str) -> str:
    m = re.search(r"\(([^)]*)\)\s*$", name)
    return m.group(1) if m else "-"


def deformation_scale(result, length: float) -> float:
    """Displayed deformation scale of the 3D view: 1, or a 1-2-5 step that shows the largest
    deflection at about SHOWN_DEFLECTION x L where it is below SMALL_DEFLECTION x L."""
    if result.centreline is None or not len(result.time):
        return 1.0
    dev = np.abs(result.centreline[..., 1:]).max()
    if not np.isfinite(dev) or dev <= 0 or dev >= SMALL_DEFLECTION * length:
        return 1.0
    want = SHOWN_DEFLECTION * length / dev
    steps = np.array([1, 2, 5]) * 10.0 ** np.floor(np.log10(want))
    return float(steps[steps <= want].max())


def scale_bar_length(length: float) -> float:
    """A 1-2-5 length (m) near a fifth of the beam, for the 3D view's scale bar."""
    e = 10.0 ** np.floor(np.log10(0.2 * length))
    return float(max(x for x in (e, 2 * e, 5 * e) if x <= 0.2 * length * 1.0001))


def _drive_units(signals) -> "OrderedDict[str, list]":
    groups: "OrderedDict[str, list]" = OrderedDict()
    for k in signals:
        groups.setdefault(_unit(k), []).append(k)
    return groups


def y_axis(*series):
    """A fixed y range around the data (5 % margin), so a view is readable as it opens."""
    import rerun.blueprint as rrb
    y = np.concatenate([np.asarray(v, dtype=float).ravel() for v in series if v is not None] or [np.zeros(1)])
    y = y[np.isfinite(y)]
    if not y.size:
        return None
    lo, hi = float(y.min()), float(y.max())
    pad = 0.05 * (hi - lo) if hi > lo else max(abs(hi), 1e-300) * 0.05 or 1.0
    return rrb.ScalarAxis(range=(lo - pad, hi + pad))


def x_axis(time):
    """The whole run on the time axis (``time`` in s), not the viewer's default window
    around the cursor, which shows a long run's first half only."""
    import rerun.blueprint as rrb
    if time is None or not len(time):
        return None
    start, end = float(time[0]), float(time[-1])
    return rrb.TimeAxis(view_range=rrb.TimeRange(start=rrb.TimeRangeBoundary.absolute(seconds=start),
                                                 end=rrb.TimeRangeBoundary.absolute(seconds=max(end, start + 1e-9))))


def _ts(origin: str, name: str, *series, contents=None, time=None):
    import rerun.blueprint as rrb
    kw = {} if contents is None else {"contents": contents}
    return rrb.TimeSeriesView(origin=origin, name=name, axis_y=y_axis(*series), axis_x=x_axis(time), **kw)


def blueprint(result=None, scale: float = 1.0, grid_spacing: float = 1e-3, extra_views=()):
    """The layout: the 3D beam (with a grid and the deformation scale in its title) over the
    run's parameters, beside a grid of time series, one quantity (one unit) per view, each
    with its y range fitted to the data."""
    import rerun.blueprint as rrb
    r = result
    signals = {} if r is None else r.signals
    t = None if r is None else r.time
    drive_views = [_ts("/plots/drive", f"drive ({unit})", *[signals[k] for k in keys],
                       contents=[f"/plots/drive/{_slug(k)}" for k in keys], time=t)
                   for unit, keys in _drive_units(signals).items()]
    title = "beam (m)" + ("" if scale == 1 else f", deformation shown x{scale:g}")
    tip = (None, None) if r is None else (r.tip_position[:, 0], r.tip_position[:, 1])
    # two rows of two, tall enough for labelled y ticks; the less central quantities as tabs
    series = [_ts("/plots/tip_curvature", "tip curvature (1/m)", *(() if r is None else
                                                                   (r.tip_curvature, r.reference_curvature)), time=t),
              _ts("/plots/voltage", "voltage (V)", None if r is None else r.voltage, time=t),
              _ts("/plots/tip_position/y", "tip deflection y (m)", tip[1], time=t),
              rrb.Tabs(*drive_views, _ts("/plots/tip_angle", "tip angle (rad)", None if r is None else r.tip_angle, time=t),
                       _ts("/plots/tip_position/x", "tip axial x (m)", tip[0], time=t), name="drive and tip")]
    # Rerun's own camera frames the beam; an explicit EyeControls3D position was tried and
    # rendered off target (headless, Rerun 0.41)
    left = rrb.Vertical(rrb.Spatial3DView(origin="/beam", name=title,
                                          line_grid=rrb.archetypes.LineGrid3D(visible=True, spacing=grid_spacing)),
                        rrb.TextDocumentView(origin="/meta", name="run parameters and sources"),
                        row_shares=[3, 2])
    right = rrb.Grid(*series, grid_columns=2)
    root = rrb.Horizontal(left, right, column_shares=[2, 3])
    if extra_views:
        root = rrb.Vertical(root, rrb.Horizontal(*extra_views), row_shares=[3, 1])
    return rrb.Blueprint(root, rrb.BlueprintPanel(state="collapsed"), rrb.SelectionPanel(state="collapsed"),
                         rrb.TimePanel(state="collapsed", timeline="time", play_state="paused"))


def _meta_markdown(meta: dict) -> str:
    lines = ["| parameter | value |", "|---|---|"]
    a = meta.get("accuracy")
    if a:       # first, where the panel opens: how far this run can be trusted
        m = a["model"]
        target = "no target" if a.get("target") is None else f"target {a['target']:g}"
        lines.append(f"| estimated error (tip curvature / swing) | {a['estimated_error']:.2g} ({target}; "
                     f"{m['segments']} segments, {m['integrator']}, h = {m['timestep']:.4g} s) |")
    for k, v in meta.items():
        if isinstance(v, dict):
            continue
        lines.append(f"| {k} | {v} |")
    def cell(x):
        if isinstance(x, dict):
            return ", ".join(f"{a}: {_short(b)}" for a, b in x.items())
        return _short(x)

    for k, v in meta.items():
        if isinstance(v, dict):
            lines += ["", f"**{k}**", "", "| name | value |", "|---|---|"]
            tables = {kk: vv for kk, vv in v.items() if isinstance(vv, list) and vv and isinstance(vv[0], dict)}
            lines += [f"| {kk} | {cell(vv)} |" for kk, vv in v.items() if kk not in tables]
            for kk, rows in tables.items():          # e.g. the runs an accuracy target made
                cols = list(rows[0])
                lines += ["", f"*{k}: {kk}*", "", "| " + " | ".join(cols) + " |", "|" + "---|" * len(cols)]
                lines += ["| " + " | ".join(cell(r.get(c, "")) for c in cols) + " |" for r in rows]
    return "\n".join(lines)


def _short(x) -> str:
    """A number to 4 significant figures, anything else as it prints."""
    if isinstance(x, float):
        return f"{x:.4g}"
    return str(x)


def _log_outcome(rec, meta: dict, t, extra) -> None:
    """The run's warnings and error (at its last sample's time) as text logs, then the
    caller's ``extra(rec)`` entities."""
    import rerun as rr
    for level, texts in (("WARN", meta.get("warnings", [])), ("ERROR", [meta["error"]] if "error" in meta else [])):
        for text in texts:
            if len(t):
                rec.set_time("time", duration=float(t[-1]))
            rec.log("log", rr.TextLog(text, level=level))
    if extra is not None:
        extra(rec)


@contextmanager
def rrd_file(rec, path, blueprint=None):
    """Log to the recording stream ``rec`` within the block; when it ends, its bytes (with
    ``blueprint`` as the default layout) are written to ``path`` by Python's own file I/O,
    so that a full disk or a closed stream raises. Rerun's file sink (``rec.save``) only
    logs such an error and leaves a torn file that fails ``rerun rrd verify``. Nothing is
    written when the block raises."""
    stream = rec.binary_stream()
    if blueprint is not None:
        rec.send_blueprint(blueprint, make_active=False, make_default=True)
    try:
        yield rec
        rec.flush()
        data = stream.read(flush=True) or b""
    finally:
        rec.disconnect()
    with open(path, "wb") as fh:
        fh.write(data)
        fh.flush()


def write_recording(path, result, scene, extra=None, views=(), deformation: float = None) -> Path:
    """Write ``result`` of a rollout of ``scene`` to ``path`` (.rrd); the file is flushed,
    closed and renamed into place whole (:func:`mjeap.io.outputs.replacing`) before returning,
    also for a failed (partial) run. ``extra(rec)`` may log
    more entities to the open ``rerun.RecordingStream``; ``views`` (rerun blueprint views)
    are added to the default layout for them. ``deformation``: displayed deformation scale
    of the 3D view (default: automatic, see the module)."""
    with replacing(path, "rrd") as tmp:
        _write_recording(tmp, result, scene, extra, views, deformation)
    return Path(path)


def _write_recording(path, result, scene, extra, views, deformation) -> None:
    import rerun as rr
    L = scene.layout.length
    scale = deformation_scale(result, L) if deformation is None else float(deformation)
    bar = scale_bar_length(L)
    # an application per actuator and drive: Rerun keeps one blueprint per application, and
    # the default layout here is fitted to this run's data
    drive_name = str(result.meta.get("drive", "")).split(" (")[0]
    rec = rr.RecordingStream(f"mjeap {scene.actuator.id} {drive_name}".strip(),
                             recording_id=f"{scene.actuator.id}-{result.meta.get('drive', '')}")
    shown = None
    if len(result.time):
        idx = np.arange(0, len(result.time), max(1, len(result.time) // MAX_FRAMES))
        shown = result.centreline[idx].copy()
        shown[..., 1:] *= scale                                      # magnified deflection
        shown = shown @ scene.rotation.T                             # (f, N + 2, 3), world axes
    with rrd_file(rec, path, blueprint(result, scale, bar, views)):
        t = result.time
        R = scene.rotation  # clamp frame -> world
        rec.log("meta", rr.TextDocument(_meta_markdown({**result.meta, "deformation_shown": f"x{scale:g}"}),
                                        media_type="text/markdown"), static=True)
        w = float(scene.actuator.width_at(0.0))
        thick = scene.layout.thickness
        rec.log("beam/clamp", rr.Boxes3D(centers=[R @ [-0.05 * L, 0, 0]],
                                         half_sizes=[[0.05 * L, max(4 * thick, 0.02 * L), 0.55 * w]],
                                         colors=[[90, 90, 90]], fill_mode="solid"), static=True)
        # scale bar: along the beam axis, beside the clamp, labelled with its length
        p0 = np.array([0.0, -0.15 * L, 0.0])
        rec.log("beam/scale_bar", rr.LineStrips3D([[R @ p0, R @ (p0 + [bar, 0, 0])]], colors=[[230, 230, 230]],
                                                  labels=[f"{bar * 1e3:g} mm"]), static=True)
        n = len(t)
        if n:
            cols = [("plots/voltage", result.voltage, "voltage (V)", SIMULATED, 1.5),
                    ("plots/tip_curvature/simulated", result.tip_curvature, "simulated, mjeap (1/m)", SIMULATED, 1.5),
                    ("plots/tip_position/x", result.tip_position[:, 0], "tip x, axial (m)", SIMULATED, 1.5),
                    ("plots/tip_position/y", result.tip_position[:, 1], "tip y, deflection (m)", SIMULATED, 1.5),
                    ("plots/tip_angle", result.tip_angle, "tip angle (rad)", SIMULATED, 1.5)]
            if result.reference_curvature is not None:
                cols.insert(1, ("plots/tip_curvature/reference", result.reference_curvature,
                                f"reference: {result.meta.get('reference', 'analytical model of the drive')} (1/m)",
                                REFERENCE, 5.0))
            palette = [[40, 110, 220], [220, 60, 60], [40, 160, 80], [150, 80, 200], [200, 140, 20], [20, 170, 170]]
            for i, (k, v) in enumerate(result.signals.items()):
                cols.append((f"plots/drive/{_slug(k)}", v, k, palette[i % len(palette)], 1.5))
            for ent, y, label, color, width in cols:
                rec.log(ent, rr.SeriesLines(names=label, colors=[color], widths=[width]), static=True)
                rec.send_columns(ent, indexes=[rr.TimeColumn("time", duration=t)],
                                 columns=rr.Scalars.columns(scalars=np.asarray(y, dtype=float)))
            # 3D frames, decimated to at most MAX_FRAMES, sent as columns (one batch)
            tf = rr.TimeColumn("time", duration=t[idx])
            pts = shown
            rec.send_columns("beam/centreline", indexes=[tf],
                             columns=rr.LineStrips3D.columns(strips=list(pts)).partition([1] * len(idx)))
            rec.log("beam/centreline", rr.LineStrips3D.from_fields(colors=[SIMULATED], radii=[max(thick, 0.004 * L)]),
                    static=True)
            rec.send_columns("beam/tip", indexes=[tf], columns=rr.Points3D.columns(positions=pts[:, -1]))
            pay_r = scene.payload.sphere_radius if result.payload_position is not None else 0.0
            rec.log("beam/tip", rr.Points3D.from_fields(radii=[max(0.015 * L, 1.1 * pay_r)], colors=[[255, 80, 30, 160]],
                                                        labels=["tip"]), static=True)
            if result.payload_position is not None:
                pp = result.payload_position[idx].copy()
                pp[:, 1:] *= scale
                rec.send_columns("beam/payload", indexes=[tf], columns=rr.Points3D.columns(positions=pp @ R.T))
                rec.log("beam/payload", rr.Points3D.from_fields(radii=[pay_r], colors=[[190, 50, 50]]), static=True)
        _log_outcome(rec, result.meta, t, extra)


def read_recording(path) -> dict:
    """Read a recording back: entity path -> list of pyarrow record batches."""
    from rerun.chunk import RrdReader
    out: dict = {}
    for chunk in RrdReader(str(path)).stream():
        out.setdefault(chunk.entity_path, []).append(chunk.to_record_batch())
    return out


def read_blueprint(path) -> list:
    """The default layout's views of a recording: dicts with 'kind' (e.g. 'TimeSeries',
    '3D', '2D', 'TextDocument'), 'name' and 'origin' (entity path)."""
    from rerun.chunk import RrdReader
    reader = RrdReader(str(path))
    views = []
    for entry in reader.blueprints():
        for chunk in reader.store(store=entry).stream():
            if not (chunk.entity_path.startswith("/view/") and chunk.entity_path.count("/") == 2):
                continue
            b = chunk.to_record_batch()
            col = {n: b.column(b.schema.names.index(n)).to_pylist() for n in b.schema.names
                   if n.startswith("ViewBlueprint:")}
            for kind, name, origin in zip(col.get("ViewBlueprint:class_identifier", []),
                                          col.get("ViewBlueprint:display_name", []),
                                          col.get("ViewBlueprint:space_origin", [])):
                first = (lambda v: v[0] if isinstance(v, list) and v else v)
                views.append({"kind": first(kind), "name": first(name), "origin": first(origin)})
    return views


def _geom_archetype(rr, model, g: int, length: float, color):
    """A Rerun archetype drawing geom ``g`` in its body's frame (SI), or None."""
    T = mujoco.mjtGeom
    t, size = model.geom_type[g], model.geom_size[g] * length
    pos = model.geom_pos[g] * length
    q = model.geom_quat[g]
    rot = rr.Quaternion(xyzw=[q[1], q[2], q[3], q[0]])
    if t == T.mjGEOM_BOX:
        return rr.Boxes3D(half_sizes=[size], centers=[pos], quaternions=[rot], colors=[color], fill_mode="solid")
    if t == T.mjGEOM_SPHERE:
        return rr.Ellipsoids3D(half_sizes=[[size[0]] * 3], centers=[pos], colors=[color], fill_mode="solid")
    if t == T.mjGEOM_ELLIPSOID:
        return rr.Ellipsoids3D(half_sizes=[size], centers=[pos], quaternions=[rot], colors=[color], fill_mode="solid")
    if t == T.mjGEOM_CAPSULE:
        # MuJoCo: along the local z axis, half-length size[1], centred; Rerun: from the origin along +z
        start = pos - _quat_mat(q)[:, 2] * size[1]
        return rr.Capsules3D(lengths=[2 * size[1]], radii=[size[0]], translations=[start], quaternions=[rot],
                             colors=[color])
    if t == T.mjGEOM_CYLINDER:
        return rr.Cylinders3D(lengths=[2 * size[1]], radii=[size[0]], centers=[pos], quaternions=[rot], colors=[color],
                              fill_mode="solid")
    return None


def write_system_recording(path, result, system, extra=None, views=(), actuator_views: bool = True) -> Path:
    """Write a :class:`mjeap.simulation.system.SystemResult` to ``path`` (.rrd): every beam's
    centreline and tip (world frame, m), every other body's geoms (boxes, spheres,
    ellipsoids, capsules, cylinders) moving with their bodies, and per actuator its voltage
    and tip curvature; the net contact force on every body that touches something.
    ``extra(rec)`` may log more entities to the open ``rerun.RecordingStream``; ``views``
    (rerun blueprint views) are placed first in the plots' column for them.
    ``actuator_views=False`` logs each actuator's plots but leaves their views out of the
    layout (a system of many actuators: the column keeps ``views`` readable). Written whole
    (:func:`mjeap.io.outputs.replacing`)."""
    with replacing(path, "rrd") as tmp:
        _write_system_recording(tmp, result, system, extra, views, actuator_views)
    return Path(path)


def _write_system_recording(path, result, system, extra, views, actuator_views=True) -> None:
    import rerun as rr
    import rerun.blueprint as rrb
    m, L = system.model, system.units.length
    names = [a.prefix.rstrip("/") for a in system.actuators]
    res = result.actuators
    t = result.time
    groups = [rrb.Vertical(_ts(f"/plots/{n}/tip_curvature", f"{n}: tip curvature (1/m)", res[n].tip_curvature, time=t),
                           _ts(f"/plots/{n}/voltage", f"{n}: voltage (V)", res[n].voltage, time=t), name=n)
              for n in names] if actuator_views else []
    touched = [b for b in range(m.nbody) if len(result.time) and np.abs(result.contact_force[:, b]).max() > 0]
    if touched:
        groups.append(_ts("/plots/contact", "contact force (N)",
                          *[np.linalg.norm(result.contact_force[:, b], axis=1) for b in touched], time=t))
    left = rrb.Vertical(rrb.Spatial3DView(origin="/world", name="system (m)",
                                          line_grid=rrb.archetypes.LineGrid3D(visible=True)),
                        rrb.TextDocumentView(origin="/meta", name="run parameters"), row_shares=[3, 1])
    bp = rrb.Blueprint(rrb.Horizontal(left, rrb.Vertical(*views, *groups), column_shares=[3, 2]),
                       rrb.BlueprintPanel(state="collapsed"), rrb.SelectionPanel(state="collapsed"),
                       rrb.TimePanel(state="collapsed", timeline="time", play_state="paused"))
    rec = rr.RecordingStream("mjeap", recording_id=f"system-{'-'.join(names)}")
    with rrd_file(rec, path, bp):
        rec.log("meta", rr.TextDocument(_meta_markdown(result.meta), media_type="text/markdown"), static=True)
        t = result.time
        n = len(t)
        beam_bodies = set()
        for p in system.parts:
            beam_bodies.update(int(b) for b in p.link_ids)
            beam_bodies.update({p.tip_load_id, p.clamp_id})
        idx = np.arange(0, n, max(1, n // MAX_FRAMES)) if n else np.zeros(0, int)
        tf = rr.TimeColumn("time", duration=t[idx]) if n else None
        # rigid bodies other than the beams (the world's own geoms too): their geoms, posed
        # per frame; each actuator's clamp drawn as its model has it
        for b in range(0, m.nbody):
            if (b in beam_bodies and not any(b == p.clamp_id for p in system.parts)) or m.body_geomnum[b] == 0:
                continue
            ent = f"world/bodies/{result.body_names[b] if b else 'world'}"
            for g in range(m.body_geomadr[b], m.body_geomadr[b] + m.body_geomnum[b]):
                rgba = (np.clip(m.geom_rgba[g], 0, 1) * 255).astype(np.uint8)
                arch = _geom_archetype(rr, m, g, L, rgba)
                if arch is not None:
                    rec.log(f"{ent}/geom{g - m.body_geomadr[b]}", arch, static=True)
            if b and n:
                q = result.body_quat[idx, b]
                rec.send_columns(ent, indexes=[tf], columns=rr.Transform3D.columns(
                    translation=result.body_position[idx, b], quaternion=q[:, [1, 2, 3, 0]]))
        for name, p, a in zip(names, system.parts, system.actuators):
            r = result.actuators[name]
            if not n:
                continue
            # the centreline back in the world: clamp position + clamp rotation x clamp-frame points
            R = None if p.clamp_moves else p.rotation
            clamp = result.body_position[idx, p.clamp_id]
            pts = r.centreline[idx]
            if R is not None:
                world = clamp[:, None, :] + pts @ R.T
            else:
                Rs = np.array([_quat_mat(q) for q in result.body_quat[idx, p.clamp_id]])
                world = clamp[:, None, :] + np.einsum("nij,nkj->nki", Rs, pts)
            rec.send_columns(f"world/{name}/centreline", indexes=[tf],
                             columns=rr.LineStrips3D.columns(strips=list(world)).partition([1] * len(idx)))
            rec.log(f"world/{name}/centreline", rr.LineStrips3D.from_fields(
                colors=[SIMULATED], radii=[max(0.5 * p.layout.thickness, 0.004 * p.layout.length)]), static=True)
            rec.send_columns(f"world/{name}/tip", indexes=[tf], columns=rr.Points3D.columns(positions=world[:, -1]))
            rec.log(f"world/{name}/tip", rr.Points3D.from_fields(radii=[0.01 * p.layout.length],
                                                                colors=[[255, 80, 30]]), static=True)
            cols = [(f"plots/{name}/tip_curvature", r.tip_curvature, f"{name}: tip curvature (1/m)")]
            if a.drive is not None:
                cols.append((f"plots/{name}/voltage", r.voltage, f"{name}: voltage (V)"))
            for ent, y, label in cols:
                rec.log(ent, rr.SeriesLines(names=label), static=True)
                rec.send_columns(ent, indexes=[rr.TimeColumn("time", duration=t)],
                                 columns=rr.Scalars.columns(scalars=np.asarray(y, dtype=float)))
        for b in touched:
            ent = f"plots/contact/{result.body_names[b].replace('/', '_')}"
            rec.log(ent, rr.SeriesLines(names=f"{result.body_names[b]}: |contact force| (N)"), static=True)
            rec.send_columns(ent, indexes=[rr.TimeColumn("time", duration=t)],
                             columns=rr.Scalars.columns(scalars=np.linalg.norm(result.contact_force[:, b], axis=1)))
        _log_outcome(rec, result.meta, t, extra)


def _quat_mat(q) -> np.ndarray:
    R = np.zeros(9)
    mujoco.mju_quat2Mat(R, np.asarray(q, dtype=float))
    return R.reshape(3, 3)
