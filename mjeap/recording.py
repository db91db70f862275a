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


def _geom_archetype(rr, model, g: int, length: float, color):
    """A Rerun archetype drawing geom ``g`` in its body's frame (SI), or None."""
    T = mujoco_types()
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
    if t in (T.mjGEOM_CAPSULE, T.mjGEOM_CYLINDER):
        # MuJoCo: along the local z axis, half-length size[1], centred; Rerun: from the origin along +z
        R = np.zeros(9)
        import mujoco
        mujoco.mju_quat2Mat(R, q)
        start = pos - R.reshape(3, 3)[:, 2] * size[1]
        cls = rr.Capsules3D if t == T.mjGEOM_CAPSULE else rr.Cylinders3D
        if cls is rr.Capsules3D:
            return cls(lengths=[2 * size[1]], radii=[size[0]], translations=[start], quaternions=[rot], colors=[color])
        return cls(lengths=[2 * size[1]], radii=[size[0]], centers=[pos], rotations=[rot], colors=[color])
    return None


def mujoco_types():
    import mujoco
    return mujoco.mjtGeom


def write_system_recording(path, result, system) -> Path:
    """Write a :class:`mjeap.system.SystemResult` to ``path`` (.rrd): every beam's
    centreline and tip (world frame, m), every other body's geoms (boxes, spheres,
    ellipsoids, capsules, cylinders) moving with their bodies, and per actuator its voltage
    and tip curvature; the net contact force on every body that touches something."""
    import rerun as rr
    import rerun.blueprint as rrb
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    m, L = system.model, system.units.length
    names = [a.prefix.rstrip("/") for a in system.actuators]
    groups = [rrb.Vertical(rrb.TimeSeriesView(origin=f"/plots/{n}/tip_curvature", name=f"{n}: tip curvature (1/m)"),
                           rrb.TimeSeriesView(origin=f"/plots/{n}/voltage", name=f"{n}: voltage (V)"), name=n)
              for n in names]
    touched = [b for b in range(m.nbody) if len(result.time) and np.abs(result.contact_force[:, b]).max() > 0]
    if touched:
        groups.append(rrb.TimeSeriesView(origin="/plots/contact", name="contact force (N)"))
    bp = rrb.Blueprint(rrb.Horizontal(rrb.Spatial3DView(origin="/world", name="system (m)"), rrb.Vertical(*groups),
                                      column_shares=[3, 2]),
                       rrb.BlueprintPanel(state="collapsed"), rrb.SelectionPanel(state="collapsed"))
    rec = rr.RecordingStream("mjeap", recording_id=f"system-{'-'.join(names)}")
    rec.save(str(path), default_blueprint=bp)
    try:
        rec.log("meta", rr.TextDocument(json.dumps(result.meta, indent=1, default=str), media_type="text/markdown"),
                static=True)
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
            R = p.rotation if p._fixed_rotation is not None else None
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
                colors=[[50, 115, 205]], radii=[0.5 * p.layout.thickness]), static=True)
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
        if "error" in result.meta:
            if n:
                rec.set_time("time", duration=float(t[-1]))
            rec.log("log", rr.TextLog(result.meta["error"], level="ERROR"))
    finally:
        rec.flush()
        rec.disconnect()
    return path


def _quat_mat(q) -> np.ndarray:
    import mujoco
    R = np.zeros(9)
    mujoco.mju_quat2Mat(R, np.asarray(q, dtype=float))
    return R.reshape(3, 3)
