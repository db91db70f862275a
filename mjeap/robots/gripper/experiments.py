"""PEDOT micro-gripper (Dadras et al. 2021's actuator, built for micromanipulation): two pedot-micro
fingers close on a steel bead resting on a table, hold it and lift it.

    mjeap robot gripper [--out out/gripper.rrd] [--voltage 1] [--hold 60] [--quick]

Prints JSON: the grip force at a held voltage against its closed form, at contact and after
the back-relaxation; the smallest voltage that lifts the bead, from the closed form and by
bisection on simulated lifts; the hard-finger check (the model's soft-finger contact). Writes a recording of the held
run (both fingers, the bead, the grip force against its closed form, the lift at the end).
Written against mjeap's public component API (attach, System, ContactParameters).

Closed form (mjeap.model.analytical.DadrasModel.grip_force): the finger is a cantilever under the
drive's uniform moment; once it has closed the gap it presses on a stop at a with
F = (3/a^3) E * d/dt max(y_free - gap, 0), E the back-relaxation's modulus; its limits are
F = 3M/(2a) - 3 EI gap / a^3 (instantaneous EI) and, long after, the relaxed EI p/z. The
bead lifts when 2 mu F >= m g at the moment the base starts to rise (at a held voltage the
force only grows after that).

The gripper itself (builder, read-out, and why its contacts are soft-finger) is
:mod:`mjeap.robots.gripper.model`.
"""
from __future__ import annotations

import argparse
import json
import shutil
import tempfile
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path
from typing import Optional

import numpy as np

from ...errors import ParameterError, check_range
from ...io.commandline import arg_number, arg_output, parse_args
from ...io.outputs import replacing, run_guard
from ...model.analytical import DadrasModel
from ...simulation.system import System
from ...studies.sweep import stop_workers, worker_signals
from ..registry import summary
from .model import A, BEAD_MASS, BEAD_RADIUS, G, GAP, MU, MU_TORSION, build
from ...lazy import lazy_module

#: imported at its first use (mjeap.lazy)
optimize = lazy_module("scipy.optimize")

LIFT = 1e-3                   # m, how far the base rises
LIFT_TIME = 0.5               # s, over which it rises (constant speed)
LIFT_AT = 1.0                 # s, when the base starts to rise in the lift tries
LIFT_HOLD = 10.0              # s, how long a lifted bead must stay held
DROPPED = 0.1 * LIFT          # m, a bead that lags the base by more has been dropped


@dataclass
class GripRun:
    """One run: time (s), the left finger's grip force (N, normal to the bead, positive
    pressing), the bead's height above its start and the base's (the slide's), the bead's x
    (m), the contact normal's tilt from the gripping axis (rad); ``dropped``: the run was
    stopped when the bead fell behind the base."""

    voltage: float
    time: np.ndarray
    force: np.ndarray
    bead_rise: np.ndarray
    base_rise: np.ndarray
    bead_x: np.ndarray
    tilt: np.ndarray
    penetration: float
    dropped: bool = False
    result: object = None
    meta: dict = field(default_factory=dict)

    @property
    def lifted(self) -> bool:
        """The base has lifted and the bead has stayed with it (within DROPPED)."""
        return bool(not self.dropped and self.base_rise[-1] > 0.98 * LIFT
                    and self.base_rise[-1] - self.bead_rise[-1] < DROPPED)


class _Dropped(Exception):
    pass


def grip(voltage: float, duration: float, lift_at: Optional[float] = None, sample_interval: float = 0.01,
         system: Optional[System] = None, stop_when_dropped: bool = False) -> GripRun:
    """Hold ``voltage`` (V) on both fingers from rest for ``duration`` s; from ``lift_at`` s
    the base rises by LIFT over LIFT_TIME. ``stop_when_dropped``: end the run once the
    bead lags the base by DROPPED."""
    s = system or build()
    m, d = s.model, s.data
    servo = m.actuator("lift").id
    slide = m.jnt_qposadr[m.joint("lift").id]
    bead = m.body("bead").id
    left = set(int(b) for b in s.parts[0].link_ids)
    z0 = m.body_pos[bead][2]
    t, force, bead_z, base_z, bead_x, tilt = [], [], [], [], [], []
    deepest = [0.0]

    def on_sample(sy):
        now = sy.time
        rise = 0.0 if lift_at is None else float(np.clip((now - lift_at) / LIFT_TIME, 0.0, 1.0)) * LIFT
        d.ctrl[servo] = rise / sy.units.length
        fc = sy.contact_forces()
        t.append(now)
        force.append(-float(np.sum([fc[b] for b in left], axis=0)[1]))   # the bead pushes the left finger to -y
        bead_z.append((d.xpos[bead][2] - z0) * sy.units.length)
        base_z.append(float(d.qpos[slide]) * sy.units.length)
        bead_x.append(d.xpos[bead][0] * sy.units.length)
        th = np.nan
        for c in d.contact[:d.ncon]:
            if m.geom_bodyid[c.geom[1]] in left or m.geom_bodyid[c.geom[0]] in left:
                th = float(np.arctan2(abs(c.frame[0]), abs(c.frame[1])))
        tilt.append(th)
        deepest[0] = max(deepest[0], sy.penetration())
        if stop_when_dropped and base_z[-1] - bead_z[-1] > DROPPED:
            raise _Dropped

    dropped = False
    try:
        r = s.rollout([f"step:{voltage}V"] * 2, duration, sample_interval=sample_interval, on_sample=on_sample)
    except _Dropped:
        dropped, r = True, None
    n = len(t)
    return GripRun(voltage, np.array(t), np.array(force), np.array(bead_z[:n]), np.array(base_z[:n]),
                   np.array(bead_x[:n]), np.array(tilt[:n]), deepest[0], dropped, r,
                   {} if r is None else r.meta)


def lift_try(voltage: float, hold: float = LIFT_HOLD, lift_at: float = LIFT_AT) -> GripRun:
    """Grip at ``voltage`` (V), lift at ``lift_at`` s, hold for ``hold`` s; stops early if dropped."""
    return grip(voltage, lift_at + LIFT_TIME + hold, lift_at=lift_at, stop_when_dropped=True)


def closed_form_force(t: np.ndarray, voltage: float) -> np.ndarray:
    """Grip force (N) at the times ``t`` (uniform, from 0) for ``voltage`` held from t = 0."""
    return DadrasModel().grip_force(t, np.full(len(t), voltage), A, GAP)


def closed_form_min_lift_voltage(lift_at: float = LIFT_AT) -> float:
    """Smallest voltage (V) with 2 mu F(lift_at) = m g (brentq on the closed form)."""
    t = np.linspace(0.0, lift_at, 2001)

    def margin(v):
        return 2 * MU * closed_form_force(t, v)[-1] - BEAD_MASS * G

    return float(optimize.brentq(margin, 0.05, 3.0, xtol=1e-6))


def min_lift_voltage(low: float, high: float, rtol: float = 0.02, hold: float = LIFT_HOLD) -> dict:
    """Bisection on the held voltage between ``low`` (must drop the bead) and ``high`` (must
    lift it) until the bracket is narrower than ``rtol`` of its top: the bracket's midpoint
    (V) and every try, with its contact tilt when the base starts to rise."""
    tries = []

    def lifts(v):
        r = lift_try(v, hold)
        tries.append({"voltage_v": v, "lifted": r.lifted, "bead_rise_m": float(r.bead_rise[-1]),
                      "stopped_at_s": float(r.time[-1]),
                      "contact_tilt_at_lift_deg": float(np.degrees(r.tilt[np.searchsorted(r.time, LIFT_AT)]))})
        return r.lifted

    if lifts(low) or not lifts(high):
        return {"voltage_v": None, "tries": tries,
                "note": f"the bracket {low:.3g}-{high:.3g} V does not hold the threshold"}
    while high - low > rtol * high:
        mid = 0.5 * (low + high)
        if lifts(mid):
            high = mid
        else:
            low = mid
    return {"voltage_v": 0.5 * (low + high), "bracket_v": [low, high], "tries": tries}


def hard_finger_check(voltage: float = 2.0, duration: float = 1.2, lift_at: float = 0.4) -> dict:
    """Hard-finger contacts (condim 3): the base lifts at ``lift_at``; the bead stays put and
    rolls so that its contact points rise with the fingers. Over the middle 60 % of the rise:
    the bead's turn about y (from its orientation, sample to sample) times R sin(theta), theta
    the contact's tilt at that sample, against the slide's rise (``rolling_over_lift``, 1 for
    pure rolling), and the bead's own rise."""
    from scipy.spatial.transform import Rotation

    r = grip(voltage, duration, lift_at=lift_at, system=build(soft_finger=False))
    k0, k1 = np.searchsorted(r.time, [lift_at + 0.2 * LIFT_TIME, lift_at + 0.8 * LIFT_TIME])
    b = r.result.body("bead")
    q = Rotation.from_quat(r.result.body_quat[k0:k1 + 1, b], scalar_first=True)
    steps = (q[1:] * q[:-1].inv()).as_rotvec()              # sample to sample (each < pi), world
    turn = np.sum(steps, axis=0)
    tilt = r.tilt[k0:k1 + 1]
    theta = float(np.median(tilt))
    rolled = np.sum(np.abs(steps[:, 1]) * BEAD_RADIUS * np.sin(0.5 * (tilt[1:] + tilt[:-1])))  # the tilt grows
    lift = r.base_rise[k1] - r.base_rise[k0]
    return {"voltage_v": voltage,
            "two_mu_f_over_mg": float(2 * MU * np.median(r.force[k0:k1 + 1]) / (BEAD_MASS * G)),
            "bead_rise_m": float(r.bead_rise[-1]), "base_rise_m": float(r.base_rise[-1]),
            "tilt_deg": float(np.degrees(theta)), "bead_turn_deg": float(np.degrees(np.linalg.norm(turn))),
            "turn_axis": (turn / np.linalg.norm(turn)).tolist(),
            "rolling_over_lift": float(rolled / lift),
            "bead_rise_over_lift": float((r.bead_rise[k1] - r.bead_rise[k0]) / lift)}


def write_recording(path, system: System, run: GripRun, reference: np.ndarray) -> None:
    """The held run in 3D (fingers, bead, table), the grip force simulated and closed form,
    the bead's and the base's rise."""
    import rerun as rr
    import rerun.blueprint as rrb
    from ...io.recording import write_system_recording, x_axis, y_axis

    def extra(rec):
        tc = [rr.TimeColumn("time", duration=run.time)]
        for ent, label, colour, values in (
                ("gripper/force/simulated", "simulated: left finger's contact force (N)", [40, 110, 220], run.force),
                ("gripper/force/closed_form", "closed form: DadrasModel.grip_force (N)", [230, 150, 40], reference),
                ("gripper/rise/base", "base (m)", [150, 150, 150], run.base_rise),
                ("gripper/rise/bead", "bead (m)", [40, 170, 60], run.bead_rise)):
            rec.log(ent, rr.SeriesLines(names=label, colors=[colour]), static=True)
            rec.send_columns(ent, indexes=tc, columns=rr.Scalars.columns(scalars=values))

    views = (rrb.TimeSeriesView(origin="/gripper/force", name="grip force (N): simulated vs closed form",
                                axis_y=y_axis(run.force, reference), axis_x=x_axis(run.time)),
             rrb.TimeSeriesView(origin="/gripper/rise", name="rise above start (m): base and bead",
                                axis_y=y_axis(run.base_rise, run.bead_rise), axis_x=x_axis(run.time)))
    write_system_recording(path, run.result, system, extra=extra, views=views)


def held_run(voltage: float, hold: float, out: Optional[str]) -> dict:
    """Grip force over ``hold`` s at ``voltage`` against the closed form; then the base
    lifts (LIFT over LIFT_TIME) and holds 1 s. Recorded to ``out``."""
    s = build()
    run = grip(voltage, hold + LIFT_TIME + 1.0, lift_at=hold, system=s)
    ref = closed_form_force(run.time, voltage)
    if out:
        write_recording(out, s, run, ref)
    k_end = int(np.searchsorted(run.time, hold)) - 1
    k_contact = int(np.argmax(run.force > 0))
    k_early = min(k_contact + int(round(1.0 / (run.time[1] - run.time[0]))), k_end)   # 1 s after contact
    dm = DadrasModel()
    EI = 1.0 / dm.mechanical_gain
    gamma = dm.k_tf * EI / dm.electrical_pole
    settled = (run.time >= run.time[k_contact] + 0.2) & (run.time <= run.time[k_end])   # impact transient left out
    return {
        "voltage_v": voltage, "hold_s": hold, "contact_time_s": float(run.time[k_contact]),
        "grip_force_early_n": float(run.force[k_early]), "grip_force_early_closed_form_n": float(ref[k_early]),
        "early_time_s": float(run.time[k_early]),
        "grip_force_n": float(run.force[k_end]), "grip_force_closed_form_n": float(ref[k_end]),
        "grip_force_instantaneous_ei_n": 3 * gamma * voltage / (2 * A) - 3 * EI * GAP / A**3,
        "grip_force_relaxed_ei_n": 3 * gamma * voltage / (2 * A) - 3 * EI * dm.pole / dm.zero * GAP / A**3,
        "max_force_error_after_contact": float(np.max(np.abs(run.force[settled] - ref[settled])) / np.max(ref[:k_end])),
        "bead_drift_toward_clamps_m": float(A - run.bead_x[k_end]),
        "contact_tilt_deg": float(np.degrees(run.tilt[k_end])),
        "max_penetration_m": run.penetration,
        "bead_lifted_at_the_end": run.lifted,
        "wall_time_s": run.meta.get("wall_time_s"), "recording": out,
    }


#: --hold (s): the early grip force is read 1 s after contact; at most 600 s (the held run,
#: hold + 1.5 s, stays within the rollout's 20 million steps of the gripper's 38 us)
HOLD_RANGE = (1.0, 600.0)


def contact_voltage(hold: float) -> float:
    """The smallest held voltage (V) at which the fingers reach the bead within ``hold`` s
    (closed form: the free deflection at A, linear in the voltage, reaches GAP)."""
    t = np.linspace(0.0, hold, 4001)
    y = DadrasModel().free_curvature(t, np.ones_like(t)) * A**2 / 2      # at 1 V
    return GAP / float(np.max(y))


def _check_voltage(a) -> None:
    """The held voltage: within pedot-micro's safe range, and enough to reach the bead."""
    from ...model.catalog import get_actuator
    hold = 10.0 if a.quick else a.hold
    lo, hi = contact_voltage(hold), get_actuator("pedot-micro").voltage_range[1]
    try:
        check_range("--voltage", a.voltage, lo, hi, "V", lo_open=True)
    except ParameterError as e:
        raise ParameterError("--voltage", a.voltage, e.accepted,
                             f"at {lo:.3g} V the fingers just reach the bead in the {hold:g} s hold (closed form); "
                             f"{hi:g} V is pedot-micro's safe limit") from None


def main(argv=None):
    ap = argparse.ArgumentParser(description=summary(__doc__))
    ap.add_argument("--out", default="out/gripper.rrd", type=arg_output(), help="recording (.rrd)")
    ap.add_argument("--voltage", type=float, default=1.0,
                    help="held voltage for the grip force (V): above the fingers' contact voltage for the hold "
                         "(0.066 V for 60 s), up to pedot-micro's 3 V")
    ap.add_argument("--hold", type=arg_number(*HOLD_RANGE, "s"), default=60.0,
                    help=f"how long the voltage is held ({HOLD_RANGE[0]:g} to {HOLD_RANGE[1]:g} s)")
    ap.add_argument("--quick", action="store_true", help="10 s hold, 2 s lift hold, 5 %% bisection")
    a = parse_args(ap, argv, _check_voltage)
    hold, lift_hold, rtol = (10.0, 2.0, 0.05) if a.quick else (a.hold, LIFT_HOLD, 0.02)

    v_cf = closed_form_min_lift_voltage()
    # the long held run beside the bisection; stopped at once if the script is. The output
    # is locked here before any work; the worker records into a private temporary file,
    # put in place here once the held run is done (the lock is this process's)
    pool = ProcessPoolExecutor(max_workers=2, initializer=worker_signals)
    with run_guard(**{"--out": a.out}), tempfile.TemporaryDirectory(prefix="mjeap-gripper-") as folder:
        held_rrd = None if not a.out else str(Path(folder) / "held.rrd")
        try:
            held = pool.submit(held_run, a.voltage, hold, held_rrd)
            lift = min_lift_voltage(0.8 * v_cf, 1.25 * v_cf, rtol, lift_hold)
            hard = hard_finger_check()
            held = held.result()
        except BaseException:
            stop_workers(pool)
            raise
        pool.shutdown()
        if held_rrd is not None:
            with replacing(a.out, "--out") as tmp:
                shutil.copyfile(held_rrd, tmp)
    v_sim = lift["voltage_v"]
    # the torsional friction the soft-finger grasp needs at the threshold, mu R sin(theta):
    # theta when the base starts to rise in the lowest try that lifted (the bracket's top)
    held_tries = [tr for tr in lift["tries"] if tr["lifted"]]
    theta = np.radians(min(held_tries, key=lambda tr: tr["voltage_v"])["contact_tilt_at_lift_deg"]) if held_tries else np.nan
    out = {
        **{k: held[k] for k in ("grip_force_n", "grip_force_closed_form_n")},
        "min_lift_voltage_v": v_sim, "min_lift_voltage_closed_form_v": v_cf,
        "min_lift_voltage_error": None if v_sim is None else v_sim / v_cf - 1.0,
        "bead_mass_kg": BEAD_MASS, "bead_radius_m": BEAD_RADIUS, "friction": MU, "torsional_friction_m": MU_TORSION,
        "gap_m": GAP, "stop_distance_m": A, "lift_m": LIFT, "lift_at_s": LIFT_AT, "lift_hold_s": lift_hold,
        "held": held, "lift": lift,
        "threshold_contact_tilt_deg": float(np.degrees(theta)),
        "torsional_friction_needed_m": float(MU * BEAD_RADIUS * np.sin(theta)),
        "hard_finger": hard,
    }
    print(json.dumps(out, indent=1, default=float))
