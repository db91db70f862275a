"""The HAMR-VI walk's recording (:mod:`mjeap.robots.hamr_walk`): the run in 3D at true scale
and its plots (speed, attitude, clearance, the ground's force on each foot), written with
mjeap's recording writer (:func:`mjeap.io.recording.write_system_recording`)."""
from __future__ import annotations

import numpy as np

from ...simulation.system import System
from .model import FOOT_RADIUS, LEGS, PAPER_FREQUENCY, PAPER_SPEED, roll_pitch

__all__ = ["write_recording"]

GRID = 5e-3                     # m, the recording's ground grid


def write_recording(path, system: System, run: dict) -> None:
    """The run in 3D at true scale (the body, the eight actuators, the legs, the feet) over a
    5 mm ground grid, each foot's trail and the body's path; plots of the body's forward
    speed (instantaneous, per cycle, the paper's 0.5 m/s at 65 Hz), its roll and pitch, the
    feet's clearance and the ground's normal force on each foot over each sample interval
    (from every step's contact sensors) beside the weight."""
    import rerun as rr
    import rerun.blueprint as rrb
    from ...io.recording import write_system_recording, x_axis, y_axis

    t, f, G = run["time"], run["frequency"], run["ground"]
    fwd, up = G[:, 0], G[:, 2]
    x_body = run["body"] @ fwd
    v_inst = np.gradient(x_body, t)
    n_cyc = int(np.floor(t[-1] * f + 1e-9))
    t_cyc = (np.arange(n_cyc) + 1) / f
    x_cyc = np.interp(np.arange(n_cyc + 1) / f, t, x_body)
    v_cyc = np.diff(x_cyc) * f
    rp = np.degrees(np.array([roll_pitch(R, G) for R in run["R"]]))
    clearance = run["feet"] @ up - FOOT_RADIUS
    load = run["foot_force_mean"] @ up          # each interval's mean (the impulses of every step)
    colours = {"FL": [230, 80, 60], "FR": [60, 120, 230], "RL": [240, 170, 40], "RR": [60, 180, 90]}

    def extra(rec):
        lo = min(run["feet"][..., 0].min(), run["body"][:, 0].min()) - 0.02
        hi = max(run["feet"][..., 0].max(), run["body"][:, 0].max()) + 0.02
        xs = np.arange(np.floor(lo / GRID) * GRID, hi + GRID, GRID)
        ys = np.arange(-0.03, 0.03 + 1e-9, GRID)
        lines = [[G @ [x, ys[0], 0], G @ [x, ys[-1], 0]] for x in xs] + \
                [[G @ [xs[0], y, 0], G @ [xs[-1], y, 0]] for y in ys]
        rec.log("world/ground_grid", rr.LineStrips3D(lines, colors=[[150, 150, 150]], radii=[2e-5]), static=True)
        for i, leg in enumerate(LEGS):
            rec.log(f"world/foot_trails/{leg}", rr.LineStrips3D([run["feet"][:, i]], colors=[colours[leg]],
                                                                 radii=[6e-5], labels=[f"{leg} foot"]), static=True)
        rec.log("world/body_path", rr.LineStrips3D([run["body"]], colors=[[40, 40, 40]], radii=[6e-5],
                                                   labels=["body"]), static=True)
        tc = [rr.TimeColumn("time", duration=t)]
        for ent, label, colour, ts, values in (
                ("walk/speed/instantaneous", "body forward speed (m/s)", [150, 150, 150], t, v_inst),
                ("walk/speed/per_cycle", "per cycle (m/s)", [40, 110, 220], t_cyc, v_cyc),
                ("walk/speed/paper", f"paper: {PAPER_SPEED} m/s at {PAPER_FREQUENCY:g} Hz", [230, 150, 40], t,
                 np.full(len(t), PAPER_SPEED)),
                ("walk/attitude/roll", "roll (deg)", [220, 60, 60], t, rp[:, 0]),
                ("walk/attitude/pitch", "pitch (deg)", [40, 110, 220], t, rp[:, 1])) + tuple(
                (f"walk/clearance/{leg}", f"{leg} foot clearance (m)", colours[leg], t, clearance[:, i])
                for i, leg in enumerate(LEGS)) + tuple(
                (f"walk/ground_force/{leg}", f"{leg}: ground's normal force, interval mean (N)", colours[leg], t,
                 load[:, i]) for i, leg in enumerate(LEGS)) + (
                ("walk/ground_force/total", "all feet (N)", [40, 40, 40], t, load.sum(axis=1)),
                ("walk/ground_force/weight", f"weight ({run['weight_n'] * 1e3:.3g} mN)", [150, 150, 150], t,
                 np.full(len(t), run["weight_n"]))):
            rec.log(ent, rr.SeriesLines(names=label, colors=[colour]), static=True)
            rec.send_columns(ent, indexes=[rr.TimeColumn("time", duration=ts)] if ts is not t else tc,
                             columns=rr.Scalars.columns(scalars=np.asarray(values, dtype=float)))

    views = (rrb.TimeSeriesView(origin="/walk/speed", name=f"forward speed (m/s) at {f:g} Hz",
                                axis_y=y_axis(v_cyc, [0.0, PAPER_SPEED]), axis_x=x_axis(t)),
             rrb.TimeSeriesView(origin="/walk/attitude", name="roll and pitch (deg)", axis_y=y_axis(rp),
                                axis_x=x_axis(t)),
             rrb.TimeSeriesView(origin="/walk/clearance", name="foot clearance above the ground (m)",
                                axis_y=y_axis(clearance), axis_x=x_axis(t)),
             rrb.TimeSeriesView(origin="/walk/ground_force", name="the ground's normal force on each foot, mean "
                                "over each sample interval (N; its mean over the window balances the momentum)",
                                axis_y=y_axis(load), axis_x=x_axis(t)))
    if "errors" in run:                          # a walk_closed_loop: its phase errors per cycle
        extra, views = _with_phase_plots(run, extra, views)
    write_system_recording(path, run["result"], system, extra=extra, views=views, actuator_views=False)


def _with_phase_plots(run: dict, extra, views) -> tuple:
    """``extra`` and ``views`` of :func:`write_recording` with a closed-loop walk's phase
    errors per cycle (deg): per actuator true (foot position) and sensed (own current)."""
    import rerun as rr
    import rerun.blueprint as rrb
    f = run["frequency"]

    def more(rec):
        extra(rec)
        for p, e in run["errors"].items():
            t_cycle = (np.arange(len(e["true_deg"])) + 1) / f
            for kind in ("true", "sensed"):
                ent = f"walk/phase_error/{p}/{kind}"
                rec.log(ent, rr.SeriesPoints(names=f"{p} {kind} phase error (deg)",
                                             markers=["circle" if kind == "true" else "cross"]), static=True)
                rec.send_columns(ent, indexes=[rr.TimeColumn("time", duration=t_cycle)],
                                 columns=rr.Scalars.columns(scalars=np.asarray(e[f"{kind}_deg"], dtype=float)))

    return more, views + (rrb.TimeSeriesView(origin="/walk/phase_error", name="foot phase error per cycle (deg): "
                                             f"true (foot) and sensed (current), loops closed after "
                                             f"{run['open_loop_cycles']} cycles"),)
