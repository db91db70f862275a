"""HAMR-VI's studies (:mod:`mjeap.robots.hamr_walk`; Jayaram et al. 2018, section 6.2): the
open-loop trot (:func:`trot_voltages`, :func:`walk`), the robot at rest (:func:`stand`), the
eight phase loops closed on the self-sensed currents (:func:`walk_closed_loop`, the
controllers in :mod:`mjeap.controllers.hamr_walk`), the segment check and the steepest
incline. The read-outs are :mod:`~mjeap.robots.hamr_walk.metrics`, the recording
:mod:`~mjeap.robots.hamr_walk.recording`, the command line :mod:`~mjeap.robots.hamr_walk.cli`;
what they measured is in docs/robots/hamr-walk.md and hamr-walk-gait.md.

Gait (trot): per actuator V = V_bias/2 + a sin(omega t + phi), a = AMPLITUDE = 100 V by
default (full: the signal swings 0..200 V); the diagonal pairs (front-left + rear-right,
front-right + rear-left) in phase, the pairs 180 degrees apart, each lift 90 degrees ahead of
its swing (the foot ellipse of Jayaram et al. 2018's ref. [50]: with foot x ~ sin and z ~ cos
the foot is down while it moves backward). The amplitude is ramped over the first 2 cycles
(:class:`SoftStart`, as Doshi's simulations ramp theirs): a lift 90 degrees ahead would
otherwise start with a 100 V step. Open loop: near the transmission resonances each foot
lags its drive (the single leg's sweeps), which is what the paper's phase loop corrects.

The trot is chaotic (a small change of mu or segments moves its numbers by tens of percent):
single runs, not converged values.
"""
from __future__ import annotations

import sys
from typing import Optional, Sequence

import mujoco
import numpy as np

from ...controllers import hamr_walk as controllers
from ...controllers.hamr_leg import phase_errors_per_cycle
from ...controllers.hamr_walk import ESTIMATOR_FREQUENCIES, trot_loop_gains, walker_estimator  # noqa: F401
from ...drives.waveforms import parse_waveform
from ...errors import check_integer, check_range
from ...simulation.system import System
from .. import hamr_leg
from .metrics import walk_metrics
from .model import (ACTUATOR_RANGE, BIAS, FREQUENCY_RANGE, LEGS, MU, PAPER_INCLINE, SEGMENTS, GroundImpulses, body_position,
                    body_rotation, build, clearances, design, feet, foot_forces, ground_force, ground_rotation,
                    metering)
from .recording import write_recording

AMPLITUDE = 0.5 * BIAS          # V, full amplitude: the signal swings 0..V_bias
FREQUENCIES = (5.0, 10.0, 20.0, 40.0, 65.0, 80.0, 100.0)
RECORD_FREQUENCY = 10.0                       # Hz: the recorded run (at full amplitude it trots upright there)
SETTLE = 0.1                    # s at least, and SETTLE_CYCLES cycles, before measuring
SETTLE_CYCLES, MEASURE_CYCLES, MEASURE_MIN = 2, 4, 0.2      # cycles, cycles, s
SAMPLES_PER_CYCLE = 50
RAMP_CYCLES = 2                 # the drive's amplitude grows over these (SoftStart)



class SoftStart:
    """A waveform (mjeap's text) whose oscillation about its offset grows linearly from zero
    over ``ramp`` s, then runs as written: the run starts at the drive's rest voltage with
    no step (a lift actuator 90 degrees ahead would otherwise jump by V_bias/2 at t = 0 and
    kick the robot off the ground). Doshi's HAMR simulations ramp their drive the same way,
    over 2 cycles."""

    def __init__(self, text: str, ramp: float):
        self.wave = parse_waveform(text)
        self.ramp = float(ramp)
        self.text = f"{text}, amplitude ramped over {self.ramp:.4g} s"

    def __call__(self, t):
        t = np.asarray(t, dtype=float)
        off = self.wave.offset
        return off + np.clip(t / self.ramp, 0.0, 1.0) * (self.wave(t) - off)


def _transmission(system: System, dof: str, frequency: float) -> tuple:
    """(the foot's quasi-static stroke per volt (m/V), the actuator's blocked force per volt (N/V),
    the transmission's second-order gain |H(f)| at ``frequency``, its ratio) of one leg degree
    of freedom: the laminate's free deflection and tip compliance (the drive's closed forms),
    the transmission's resonance (hamr_leg.DOFS) and damping ratio (hamr_leg.ZETA)."""
    frequency = check_range("frequency", frequency, *FREQUENCY_RANGE, "Hz")
    drv = system.actuators[0].drive
    lam = drv.laminate()
    lo, hi = drv.voltage_range()
    free_per_volt = (lam.free_deflection(hi) - lam.free_deflection(lo)) / (hi - lo)
    tr = hamr_leg.DOFS[dof]
    r = frequency / tr.resonance
    return free_per_volt, free_per_volt / lam.tip_compliance(), 1.0 / np.hypot(1.0 - r * r, 2.0 * hamr_leg.ZETA * r), \
        tr.ratio


def no_flight_lift(system: System, frequency: float, amplitude: float = AMPLITUDE) -> float:
    """The lift amplitude (V, at most ``amplitude``) at which a trot's stance pair cannot throw
    the body off the ground at ``frequency`` (Hz): the pair's legs carry the weight W on the
    lift actuators' stiffness (k_tip / T_lift^2 at each foot, the static sag W T^2 / (2 k_tip)
    on two legs; W the weight the lift transmissions carry, :func:`sprung_weight`), and
    driving their feet down by A adds 2 k_tip A / T^2; for A beyond the sag the pair's force
    swings from 2 W to below zero and the body flies. A = the sag is the lift
    drive whose blocked force at the feet, 2 F_b' V / T_lift (F_b' the actuator's blocked force
    per volt: the laminate's free deflection / tip compliance), equals W, amplified by the lift
    transmission's second-order gain |H(f)| (80 Hz, hamr_leg.ZETA): V = W T_lift / (2 F_b'
    |H(f)|) (17.8 V at 10 Hz, 6.3 V at 65 Hz). N. Doshi's Vicon measurement of HAMR-VI set down
    from the air (HarvardAgileRoboticsLab/drake, GaitRecoveryTransition/SystemIDJbrn.m,
    2018-05-17) puts the robot's legs' sag at 0.5-0.7 mm on four legs (about 1.0-1.4 mm on a
    diagonal pair), against this model's 0.30 mm on four."""
    _, blocked_per_volt, gain, ratio = _transmission(system, "lift", frequency)
    return float(min(amplitude, sprung_weight(system) * ratio / (2.0 * blocked_per_volt * gain)))


def sprung_weight(system: System) -> float:
    """The weight (N) the four lift transmissions carry at the feet: the robot's, less what
    the parts turning with each lift (its leg rod and lever, on the lift axis) hang on their
    own axis: each such part's weight times 1 - its centre's lateral arm / the foot's (the rod's
    centre halfway out, the lever's on the axis). 1.09 of the robot's 1.43 g."""
    m, d = system.model, mujoco.MjData(system.model)
    mujoco.mj_kinematics(m, d)
    g = float(np.linalg.norm(m.opt.gravity))
    carried = float(m.body_subtreemass[m.body("body").id]) * g
    for leg in LEGS:
        hip, foot = d.body(f"{leg}/leg").xpos, d.site(f"{leg}/foot").xpos
        arm = abs(foot[1] - hip[1])
        for b in range(m.nbody):
            if m.body_rootid[b] == m.body_rootid[m.body("body").id] and _inside(m, b, m.body(f"{leg}/leg").id):
                carried -= float(m.body_mass[b]) * g * (1.0 - abs(d.xipos[b][1] - hip[1]) / arm)
    return carried * system.units.force


def _inside(m, b: int, root: int) -> bool:
    """Body ``b`` is ``root`` or below it in the kinematic tree."""
    while b > 0:
        if b == root:
            return True
        b = int(m.body_parentid[b])
    return False


def travel_amplitude(system: System, dof: str, frequency: float, travel: float = ACTUATOR_RANGE) -> float:
    """The drive amplitude (V) at which the ``dof`` actuator's tip reaches its ``travel`` (m,
    ACTUATOR_RANGE: the range of HAMR-VI's actuator joints in Doshi's model) at ``frequency``
    (Hz): travel / (free deflection per volt x |H(f)|). At 65 Hz the swing (100 Hz) takes
    64 V, the lift (80 Hz) 39 V; below 20 Hz both take the full 100 V."""
    free_per_volt, _, gain, _ = _transmission(system, dof, frequency)
    return float(travel / (free_per_volt * gain))


def trot_drive(system: System, frequency: float, amplitude: float = AMPLITUDE) -> dict:
    """The robot's trot at ``frequency`` (Hz), as :func:`walk`'s ``amplitude`` and
    ``lift_amplitude`` (V): the swing at ``amplitude`` (the full drive) or, where that would
    carry its actuator past its travel, the amplitude that reaches it
    (:func:`travel_amplitude`); the lift at :func:`no_flight_lift`, the largest at which the
    stance pair cannot throw the body."""
    amplitude = check_range("amplitude", amplitude, 0.0, AMPLITUDE, "V", lo_open=True)
    return {"amplitude": min(amplitude, travel_amplitude(system, "swing", frequency)),
            "lift_amplitude": min(no_flight_lift(system, frequency, amplitude),
                                  travel_amplitude(system, "lift", frequency))}


def trot_voltages(frequency: float, amplitude: float = AMPLITUDE, bias: float = BIAS,
                  ramp_cycles: float = RAMP_CYCLES, lift_amplitude: Optional[float] = None) -> dict:
    """The trot, one waveform per actuator prefix: sine of ``amplitude`` about V_bias / 2 at
    ``frequency`` (the lifts: ``lift_amplitude``, default the same); the diagonal pairs in
    phase, the pairs 180 degrees apart, each lift 90 degrees ahead of its swing (mjeap's
    'phase=' key, rad); amplitude ramped over ``ramp_cycles`` cycles (:class:`SoftStart`)."""
    frequency = check_range("frequency", frequency, *FREQUENCY_RANGE, "Hz")
    amplitude = check_range("amplitude", amplitude, 0.0, 0.5 * bias, "V")
    lift = amplitude if lift_amplitude is None else check_range("lift_amplitude", lift_amplitude, 0.0, 0.5 * bias,
                                                                "V")
    out = {}
    for leg, (_, _, phase) in LEGS.items():
        for dof, lead, a in (("swing", 0.0, amplitude), ("lift", 0.5 * np.pi, lift)):
            text = f"sine:{a:g}V@{frequency:g}Hz,offset={0.5 * bias:g}V,phase={phase + lead:.17g}"
            out[f"{leg}_{dof}"] = SoftStart(text, ramp_cycles / frequency)
    return out


def trot_durations(frequency: float, settle: Optional[float], measure: Optional[float]) -> tuple:
    """(settle, measure) in s of a trot at ``frequency`` (Hz), each whole cycles; None takes
    :func:`walk`'s defaults (RAMP_CYCLES + SETTLE_CYCLES cycles and at least SETTLE s;
    MEASURE_CYCLES cycles and at least MEASURE_MIN s)."""
    T = 1.0 / frequency
    s = settle if settle is not None else max((RAMP_CYCLES + SETTLE_CYCLES) * T, SETTLE)
    m = measure if measure is not None else max(MEASURE_CYCLES * T, MEASURE_MIN)
    return np.ceil(s / T - 1e-9) * T, np.ceil(m / T - 1e-9) * T


def walk(system: System, frequency: float, amplitude: float = AMPLITUDE, settle: Optional[float] = None,
         measure: Optional[float] = None, samples_per_cycle: int = SAMPLES_PER_CYCLE,
         lift_amplitude: Optional[float] = None, controller=None) -> dict:
    """Trot open loop at ``frequency`` (Hz) for ``settle`` + ``measure`` s (defaults: whole
    cycles, see SETTLE and MEASURE_*), or under ``controller`` (a system controller, e.g.
    :class:`TrotPhaseControllers`, see :func:`walk_closed_loop`). Returns the samples (SI,
    world): time, body position and rotation, the feet's positions and velocities, which feet touch the ground, the
    deepest penetration, the chassis's and the legs' lowest points above the ground
    (:func:`clearances`); the rollout's result; the measuring window's start ``t0``; and
    per sample the ground's force on each foot (``foot_force``, N, at the sample, as
    mj_contactForce reads it) and the mean over the interval since the previous sample
    (``foot_force_mean``; ``ground_force_mean`` in all, from the impulses of every step,
    model.GroundImpulses), per foot the steps it carried load and its touch-downs at the
    step's resolution (``loaded_steps``, ``onsets``; ``interval_steps``) and the robot's
    momentum (``momentum``, N s)."""
    bias = system.actuators[0].drive.params["bias"]
    settle, measure = trot_durations(frequency, settle, measure)
    fid = [mujoco.mj_name2id(system.model, mujoco.mjtObj.mjOBJ_GEOM, f"{leg}/foot") for leg in LEGS]
    sid = [mujoco.mj_name2id(system.model, mujoco.mjtObj.mjOBJ_SITE, f"{leg}/foot") for leg in LEGS]
    rows = {k: [] for k in ("body", "R", "feet", "feet_velocity", "contact", "foot_force", "ground_force",
                            "foot_force_mean", "ground_force_mean", "loaded_steps", "onsets", "interval_steps",
                            "momentum",
                            "penetration", "chassis_clearance", "leg_clearance")}
    meter = GroundImpulses(system)
    bid = mujoco.mj_name2id(system.model, mujoco.mjtObj.mjOBJ_BODY, "body")
    v6 = np.zeros(6)

    def on_sample(sy):
        m, d = sy.model, sy.data
        rows["body"].append(body_position(sy))
        rows["R"].append(body_rotation(sy))
        rows["feet"].append(feet(sy))
        vel = []
        for s_ in sid:
            mujoco.mj_objectVelocity(m, d, mujoco.mjtObj.mjOBJ_SITE, s_, v6, 0)
            vel.append(v6[3:].copy())
        rows["feet_velocity"].append(np.array(vel) * sy.units.length / sy.units.time)
        touching = {d.contact[i].geom1 for i in range(d.ncon)} | {d.contact[i].geom2 for i in range(d.ncon)}
        rows["contact"].append([g in touching for g in fid])
        rows["foot_force"].append(foot_forces(sy, fid))
        rows["ground_force"].append(ground_force(sy))
        got = meter.take()                      # the steps since the previous sample
        span = max(got["steps"], 1) * sy.timestep
        rows["foot_force_mean"].append(got["foot"] / span)
        rows["ground_force_mean"].append(got["total"] / span)
        rows["loaded_steps"].append(got["loaded_steps"])
        rows["onsets"].append(got["onsets"])
        rows["interval_steps"].append(got["steps"])
        mujoco.mj_subtreeVel(m, d)              # the robot's momentum (N s, world) at this state
        rows["momentum"].append(m.body_subtreemass[bid] * d.subtree_linvel[bid] * sy.units.mass * sy.units.length
                                / sy.units.time)
        rows["penetration"].append(sy.penetration())
        low = clearances(sy)
        rows["chassis_clearance"].append(low[0])
        rows["leg_clearance"].append(low[1])

    volts = None if controller is not None else trot_voltages(frequency, amplitude, bias, lift_amplitude=lift_amplitude)
    with metering(meter):
        res = system.rollout(volts, settle + measure, sample_interval=1.0 / (samples_per_cycle * frequency),
                             on_sample=on_sample, controller=controller)
    run = {k: np.array(v) for k, v in rows.items()}
    run.update(time=res.time[:len(rows["body"])], result=res, frequency=float(frequency), amplitude=float(amplitude),
               lift_amplitude=float(amplitude if lift_amplitude is None else lift_amplitude),
               t0=float(settle), ground=ground_rotation(system),
               weight_n=float(system.model.body_subtreemass[bid] * np.linalg.norm(system.model.opt.gravity)
                              * system.units.force))
    return run


def stand(system: System, duration: float = 1.0, after: float = 0.5, window: float = 0.1) -> dict:
    """No drive (every actuator held at its rest voltage) for ``duration`` s from the start
    (feet or, upside down, the chassis 20 um above the ground). At every step after
    ``after`` s: the sum of the normal forces of the ground's contacts against the robot's
    weight (relative error; the largest), the steps with no foot down. The creep: the mean
    positions over the first and last ``window`` s after ``after`` (at most a quarter of
    the checked time each), their horizontal
    distance over the time between (body and each foot, m/s), and the body's vertical
    drift. SI; stepped with mj_step (one step at a time, to read every step's forces)."""
    duration = check_range("duration", duration, 0.0, 10.0, "s", lo_open=True)
    after = check_range("after", after, 0.0, duration, "s", hi_open=True)
    window = min(check_range("window", window, 0.0, 10.0, "s", lo_open=True), 0.25 * (duration - after))
    m, d = system.model, system.data
    u = system.units
    system.reset()
    h = system.timestep
    n = int(round(duration / h))
    k0 = int(np.ceil(after / h - 1e-9))
    ground = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, "ground")
    fid = [mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, f"{leg}/foot") for leg in LEGS]
    sid = [mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, f"{leg}/foot") for leg in LEGS]
    bid = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, "body")
    weight = float(m.body_subtreemass[bid] * np.linalg.norm(m.opt.gravity)) * u.force
    fn = np.zeros(n - k0)
    down = np.zeros(n - k0, dtype=int)
    pos = np.zeros((n - k0, 5, 3))
    f6 = np.zeros(6)
    for k in range(n):
        mujoco.mj_step(m, d)
        if k < k0:
            continue
        i = k - k0
        total, feet_down = 0.0, set()
        for c in range(d.ncon):
            con = d.contact[c]
            if ground not in (con.geom1, con.geom2):
                continue
            mujoco.mj_contactForce(m, d, c, f6)
            total += f6[0]
            other = con.geom2 if con.geom1 == ground else con.geom1
            if other in fid and f6[0] > 0:
                feet_down.add(other)
        fn[i], down[i] = total * u.force, len(feet_down)
        pos[i, 0] = d.xpos[bid]
        pos[i, 1:] = d.site_xpos[sid]
    mujoco.mj_kinematics(m, d)
    t = (np.arange(k0, n) + 1) * h
    a, b = t < t[0] + window, t > t[-1] - window
    span = t[b].mean() - t[a].mean()
    drift = (pos[b].mean(axis=0) - pos[a].mean(axis=0)) * u.length / span          # (5, 3) m/s
    err = fn / weight - 1.0
    return {"weight_n": weight, "checked_from_s": float(t[0]), "steps_checked": int(n - k0),
            "max_force_error": float(np.abs(err).max()), "mean_force_error": float(err.mean()),
            "steps_with_no_foot_down": int((down == 0).sum()), "min_feet_down": int(down.min()),
            "body_creep_m_s": float(np.hypot(*drift[0, :2])), "body_vertical_drift_m_s": float(drift[0, 2]),
            "feet_creep_m_s": [float(np.hypot(*v[:2])) for v in drift[1:]],
            "body_height_m": float(pos[-1, 0, 2] * u.length),
            "body_height_range_m": float(np.ptp(pos[:, 0, 2]) * u.length)}


# ---- closed loop: the single leg's two phase loops on all eight actuators (issue 25) ----
LOOP_FREQUENCY, LOOP_AMPLITUDE = 80.0, 20.0     # Hz, V: the lifts' resonance: open loop they lag most (~70-75 deg)
OPEN_LOOP_CYCLES = RAMP_CYCLES + 4              # cycles before the loops close (the soft start, then 4)
LOOP_CYCLES = 40                                # cycles of a closed-loop walk, the open-loop ones included
LOOP_MEASURE_CYCLES = 16                        # the walk metrics of a closed-loop walk: its last cycles
PHASE_TOL_DEG = 5.0                             # deg, Jayaram et al. 2018's "within 5 degrees"
FOOT_AXIS = {"swing": 0, "lift": 2}             # the foot's body-frame coordinate: fore-aft x, normal z


def desired_phases() -> dict:
    """Per actuator prefix the desired phase (rad, against sin(omega t)) of its foot's
    coordinate relative to the body (fore-aft for a swing, normal for a lift): the trot's,
    as :func:`trot_voltages` drives it (each transmission moves its foot +x or +z for a
    positive drive on either side)."""
    return {f"{leg}_{dof}": phase + lead for leg, (_, _, phase) in LEGS.items()
            for dof, lead in (("swing", 0.0), ("lift", 0.5 * np.pi))}


def walk_loop_gains(frequency: float) -> dict:
    """Per degree of freedom the phase loop's (kp, ki, kd) per cycle at the trot
    ``frequency`` (Hz): :func:`mjeap.controllers.hamr_walk.trot_loop_gains` at the legs'
    damping ratio (hamr_leg.ZETA)."""
    frequency = check_range("frequency", frequency, *FREQUENCY_RANGE, "Hz")
    return trot_loop_gains(frequency, hamr_leg.ZETA)


class TrotPhaseControllers(controllers.TrotPhaseControllers):
    """:class:`mjeap.controllers.hamr_walk.TrotPhaseControllers` on this walker: its trot's
    phases (:func:`desired_phases`), gains at the trot frequency (:func:`walk_loop_gains`)
    and soft start (RAMP_CYCLES); ``amplitude`` (V), ``open_loop_cycles`` (at least the
    soft start's) and ``frequency`` checked before the estimator is calibrated."""

    def __init__(self, system: System, frequency: float, amplitude: float = LOOP_AMPLITUDE,
                 open_loop_cycles: int = OPEN_LOOP_CYCLES, estimator=None, gains: Optional[dict] = None):
        bias = system.actuators[0].drive.params["bias"]
        frequency = check_range("frequency", frequency, *FREQUENCY_RANGE, "Hz")
        amplitude = check_range("amplitude", amplitude, 0.0, 0.5 * bias, "V", lo_open=True)
        open_loop_cycles = check_integer("open_loop_cycles", open_loop_cycles, RAMP_CYCLES, 10_000)
        super().__init__(system, frequency, desired_phases(), walk_loop_gains(frequency) if gains is None else gains,
                         amplitude=amplitude, open_loop_cycles=open_loop_cycles, ramp=RAMP_CYCLES / frequency,
                         estimator=estimator, frequency_range=FREQUENCY_RANGE)


def foot_phase_errors(run: dict, cycles: int) -> dict:
    """Per actuator prefix the true phase error (deg) of its foot per drive cycle, for the
    first ``cycles`` cycles of a :func:`walk`: the foot's simulated 3D position relative to
    the body, in the body frame (fore-aft x for a swing, normal z for a lift), against
    :func:`desired_phases` (controllers.hamr_leg.phase_errors_per_cycle, a lock-in per cycle)."""
    rel = np.einsum("nji,nkj->nki", run["R"], run["feet"] - run["body"][:, None, :])     # R^T (foot - body)
    legs = list(LEGS)
    return {p: phase_errors_per_cycle(run["time"], rel[:, legs.index(p.split("_")[0]), FOOT_AXIS[p.split("_")[1]]],
                                      run["frequency"], ph, cycles)
            for p, ph in desired_phases().items()}


def walk_closed_loop(system: System, frequency: float = LOOP_FREQUENCY, amplitude: float = LOOP_AMPLITUDE,
                     cycles: int = LOOP_CYCLES, open_loop_cycles: int = OPEN_LOOP_CYCLES,
                     measure_cycles: int = LOOP_MEASURE_CYCLES, estimator=None, gains: Optional[dict] = None) -> dict:
    """Trot ``cycles`` cycles at ``frequency`` (Hz), ``amplitude`` (V) under
    :class:`TrotPhaseControllers` (closed after ``open_loop_cycles``). Returns :func:`walk`'s
    samples (its measuring window: the last ``measure_cycles``, for :func:`walk_metrics`) with
    ``errors``: per actuator prefix the sensed and the true (:func:`foot_phase_errors`) phase
    error per cycle (deg), the drive phase per cycle (deg) and the gains; and ``controller``."""
    cycles = check_integer("cycles", cycles, 3, 10_000)
    open_loop_cycles = check_integer("open_loop_cycles", open_loop_cycles, RAMP_CYCLES, cycles - 2,
                                     f"at most cycles {cycles} - 2, so that a closed-loop cycle is measured")
    measure_cycles = check_integer("measure_cycles", measure_cycles, 1, cycles - 1)
    ctrl = TrotPhaseControllers(system, frequency, amplitude, open_loop_cycles, estimator, gains)
    T = 1.0 / ctrl.frequency
    run = walk(system, ctrl.frequency, amplitude, settle=(cycles - measure_cycles) * T, measure=measure_cycles * T,
               controller=ctrl)
    n = min(len(c.errors) for c in ctrl.ctrls.values())
    true = foot_phase_errors(run, n)
    run["errors"] = {p: {"sensed_deg": np.degrees(c.errors[:n]), "true_deg": true[p],
                         "drive_phase_deg": np.degrees(c.commands[:n]), "gains": list(c.gains)}
                     for p, c in ctrl.ctrls.items()}
    run.update(controller=ctrl, open_loop_cycles=open_loop_cycles, closed_loop=True)
    return run


def loop_summary(run: dict, open_run: Optional[dict] = None, tol_deg: float = PHASE_TOL_DEG) -> dict:
    """The read-outs of a :func:`walk_closed_loop`: per actuator the true phase error (deg)
    in the last open-loop cycle and the last cycle, the cycles after closing until the true
    and the sensed error stay within ``tol_deg`` (None: never), the largest |sensed - true|
    (deg) over the cycles after the soft start and its mean; the true error's mean and rms
    from 10 cycles after closing (None if the run is shorter); the walk metrics; and those of ``open_run``
    (an open-loop :func:`walk` at the same drive) beside them."""
    from ...controllers.hamr_leg import cycles_to_within
    n_open = run["open_loop_cycles"]
    act = {}
    for p, e in run["errors"].items():
        diff = np.angle(np.exp(1j * np.radians(e["sensed_deg"] - e["true_deg"])))[RAMP_CYCLES:]
        tail = np.asarray(e["true_deg"])[n_open + 10:]          # from 10 cycles after the loops close
        act[p] = {"open_loop_error_deg": float(e["true_deg"][n_open - 1]), "final_error_deg": float(e["true_deg"][-1]),
                  "cycles_to_tol": cycles_to_within(e["true_deg"], n_open, tol_deg),
                  "cycles_to_tol_sensed": cycles_to_within(e["sensed_deg"], n_open, tol_deg),
                  "max_sensed_minus_true_deg": float(np.degrees(np.abs(diff).max())),
                  "mean_sensed_minus_true_deg": float(np.degrees(diff.mean())),
                  "settled_mean_error_deg": float(np.mean(tail)) if tail.size else None,
                  "settled_rms_error_deg": float(np.sqrt(np.mean(tail ** 2))) if tail.size else None,
                  "gains_kp_ki_kd": e["gains"],
                  "true_deg": [float(x) for x in e["true_deg"]], "sensed_deg": [float(x) for x in e["sensed_deg"]]}
    m = walk_metrics(run)
    out = {"frequency_hz": run["frequency"], "amplitude_v": run["amplitude"], "open_loop_cycles": n_open,
           "cycles": len(next(iter(run["errors"].values()))["true_deg"]) + 1, "tolerance_deg": tol_deg,
           "actuators": act, "closed_loop": m,
           "max_cycles_to_tol": None if any(a["cycles_to_tol"] is None for a in act.values())
           else max(a["cycles_to_tol"] for a in act.values())}
    if open_run is not None:
        out["open_loop"] = walk_metrics(open_run)
    return out


def closed_loop_section(system: System, frequency: float = LOOP_FREQUENCY, amplitude: float = LOOP_AMPLITUDE,
                        cycles: int = LOOP_CYCLES, out=None) -> dict:
    """The command line's closed_loop section: :func:`walk_closed_loop` and the open-loop
    :func:`walk` over the same cycles and window, :func:`loop_summary` of both, the
    estimator's calibration; the closed-loop run recorded to ``out`` (None: not)."""
    est = walker_estimator(system)
    run = walk_closed_loop(system, frequency, amplitude, cycles, estimator=est)
    T = 1.0 / frequency
    open_run = walk(system, frequency, amplitude, settle=(cycles - LOOP_MEASURE_CYCLES) * T,
                    measure=LOOP_MEASURE_CYCLES * T)
    res = loop_summary(run, open_run)
    res["estimator"] = dict(est.fit, bias_v=est.bias, calibrated_on="the free pzt-hamr-small (no leg), "
                            f"{system.parts[0].layout.segments} segments")
    if out:
        write_recording(out, system, run)
    res["recording"] = out
    c, o = res["closed_loop"], res["open_loop"]
    print(f"closed loop at {frequency:g} Hz, {amplitude:g} V: {c['speed_m_s']:.4g} m/s (open loop "
          f"{o['speed_m_s']:.4g}); cycles to {PHASE_TOL_DEG:g} deg: {res['max_cycles_to_tol']}", file=sys.stderr)
    return res

def segment_effect(segments: Sequence[int] = (2, SEGMENTS, 20), frequencies: Sequence[float] = (20.0, 65.0)) -> dict:
    """The single leg (hamr_leg.build, its design) with ``segments`` per actuator: each
    transmission's foot gain (m/V, hamr_leg.sweep) at ``frequencies``, and the foot
    amplitude (m) it gives at this robot's full AMPLITUDE. The design's inertias are sized
    on the 20-segment beam; fewer segments stiffen the chain (its static gain and first
    mode move by ~1/N^2), which moves the foot amplitude by what is reported here."""
    d = design()
    out = {}
    for n in segments:
        system = hamr_leg.build(d, segments=n)
        row = {"timestep_s": system.timestep}
        for dof in ("swing", "lift"):
            sw = hamr_leg.sweep(system, dof, np.asarray(frequencies, dtype=float))
            row[dof] = {f"{f:g}_hz": {"gain_m_per_v": g, "amplitude_m": g * AMPLITUDE}
                        for f, g in zip(sw["frequency_hz"], sw["magnitude_m_per_V"])}
        out[str(n)] = row
    ref = out[str(max(segments))]
    for n in segments:
        for dof in ("swing", "lift"):
            for key, v in out[str(n)][dof].items():
                v["relative_to_most_segments"] = v["gain_m_per_v"] / ref[dof][key]["gain_m_per_v"] - 1.0
    return out


def max_incline(frequency: float = RECORD_FREQUENCY, amplitude: float = AMPLITUDE, mu: float = MU,
                segments: int = SEGMENTS, step: float = 4.0, top: float = 32.0,
                lift_amplitude: Optional[float] = None) -> dict:
    """The steepest ground incline (deg, in ``step`` up to ``top``) on which the trot at
    ``frequency`` (the lifts at ``lift_amplitude``, default ``amplitude``) still climbs:
    forward speed along the slope > 0 with the body upright (|roll| and |pitch| below
    UPRIGHT_DEG) over the measuring window. The ground is tilted, gravity stays along -z
    (attach sizes the actuators for it)."""
    d = design()
    tried, best = [], None
    for angle in np.arange(0.0, top + 1e-9, step):
        m = walk_metrics(walk(build(mu, segments, incline_deg=float(angle), d=d), frequency, amplitude,
                              lift_amplitude=lift_amplitude))
        ok = m["speed_m_s"] > 0 and m["upright"]
        tried.append({"incline_deg": float(angle), "speed_m_s": m["speed_m_s"], "upright": m["upright"]})
        if not ok:
            break
        best = float(angle)
    return {"frequency_hz": frequency, "amplitude_v": amplitude,
            "lift_amplitude_v": amplitude if lift_amplitude is None else lift_amplitude, "max_incline_deg": best,
            "step_deg": step, "tried": tried, "paper_incline_deg": PAPER_INCLINE}
