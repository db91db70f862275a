"""HAMR-VI walks (issue 25; Jayaram et al. 2018, section 6.2): a free-floating 1.43 g, 4.51 cm
quadruped, four legs of two pzt-hamr-small actuators each (the legs of
mjeap.robots.hamr_leg), trotting on a ground plane open loop at the paper's 200 V bias.

    mjeap robot hamr-walk [--out out/hamr_walk.rrd] [--frequencies 5 10 20 40 65 80 100]
        [--record-frequency 10] [--amplitude 100] [--mu 0.51] [--segments 4] [--quick]
        [--loop-frequency 80] [--loop-amplitude 20] [--loop-cycles 40] [--loop-out ...] [--no-closed-loop]

Prints JSON: per frequency the forward speed, the no-slip kinematic estimate, foot slip,
body roll and pitch, duty factor and landings per cycle (also gathered in
duty_factor_by_frequency), penetration, the chassis's and legs' lowest points and wall
time; the speed at 65 Hz beside the paper's 0.5 m/s; the contact's sizing (contact); the
rest check (rest: no drive, the feet's normal forces against the weight at every step), the
segment check and the steepest incline climbed at --record-frequency (not with --quick);
the closed_loop section (the eight phase loops against the open loop at
--loop-frequency, --loop-amplitude). Writes a recording of the --record-frequency run and
one of the closed loop. Written against mjeap's public
component API (attach, System, ContactParameters, add_transmission) and plain MjSpec.

Gait (trot): per actuator V = V_bias/2 + a sin(omega t + phi), a = AMPLITUDE = 100 V by
default (full: the signal swings 0..200 V); the diagonal pairs (front-left + rear-right,
front-right + rear-left) in phase, the pairs 180 degrees apart, each lift 90 degrees ahead of
its swing (the foot ellipse of Jayaram et al. 2018's ref. [50]: with foot x ~ sin and z ~ cos the foot
is down while it moves backward). The amplitude is ramped over the first 2 cycles
(:class:`SoftStart`, as Doshi's simulations ramp theirs): a lift 90 degrees ahead would
otherwise start with a 100 V step. Open loop: near the transmission resonances each foot
lags its drive (the single leg's sweeps), which is what the paper's phase loop corrects.

Read-outs (SI): forward speed (the body's displacement along the ground's x over whole
cycles after the ramp and 2 more cycles, at least 0.1 s, divided by their duration); roll
and pitch relative to the ground; stance: a foot within STANCE_GAP = 10 um of the ground
(MuJoCo's contact list flickers at zero depth); foot slip: the fraction of stance samples
whose tangential foot speed exceeds SLIDE_FRACTION = 10 % of the mean stance speed relative
to the body; penetration; the no-slip kinematic estimate: the mean over time of the stance
feet's backward speed relative to the body (foot path in the body frame), i.e. what the
body would move if no stance foot slid; also the stance stroke, duty factor (the share of
the samples with a foot in stance, per foot), stroke x f / duty, the landings per foot and
cycle (stance onsets: ~1 a trot, more a foot bouncing, < 1 a body in flight), the lowest
point of the chassis and of the legs over the run (:func:`clearances`). :func:`stand`: the
robot with no drive, every step's normal forces against the weight, and its creep.

Findings (4 segments, mu 0.51, MuJoCo 4.0, 2 shared cores: 11-19 s wall per simulated
second, up to 29 beside another run), with :func:`walk` and :func:`walk_metrics` at their
default windows. The motion is chaotic (a small change of mu or segments moves these
numbers): single runs, not converged values. Re-measured with the contact of
:func:`~mjeap.robots.hamr_walk.model.contact_parameters` (issue: the walker's contact);
"before" is the 2-step contact under 'implicitfast', after hamr_leg's stage centre-of-mass fix (commit 41b82c0).
- Issue 46 (docs/robots/hamr-walk.md, hamr-walk-gait.md; 0.3 s settling, 0.2 s measured): the
  solver at SOLVER_TOLERANCE and the actuators' travel within ACTUATOR_RANGE. The contact
  forces (sensors, every step) balance the robot's momentum within 2e-5 under either
  integrator (+5.9 % under 'discrete' at MuJoCo's tolerance 1e-8). Full drive: 10 Hz 0.097 m/s
  upright (12 deg), 20 Hz 0.062 m/s upright (26 deg; rolled over before), 30-65 Hz tilted to
  33-67 deg (65 Hz 0.017 m/s; rolled onto its back before): the feet's 3.2-3.6 mm stroke
  accelerates them at more than g above 9 Hz and throws the body into flights (its top at
  18-24 mm), landing tilted; under 5 x gravity the 20 Hz trot runs upright at 2.4 deg. At
  10 Hz the contact duty factor (sample intervals with a load) is 0.38, every sample with a
  foot within STANCE_GAP has it loaded over its interval (at the instant alone 0.30), 2.65
  touch-downs per foot and cycle (444 at the step's resolution: a sliding foot's load comes
  in impulses, study.sliding_contact). The table below is from before issue 46.
- At rest (:func:`stand`, no drive, 1 s): after 0.5 s the feet's normal forces add up to the
  weight within 6e-8 at every step, all four feet down at every step; the body moves along
  the ground at 1e-10 m/s, each foot 0.12 um/s (the legs splay under the weight: 0.21 of
  it sideways on each foot, held by the soft friction) and the body sinks 0.11 um/s with
  them. Before: no foot touched in 40 % of the steps after 2.5 s, force spikes of 44-74 x
  the weight, the body bounced 7.8 um peak to peak and crept 67 um. The cause was the
  integrator, not the contact alone: under 'implicitfast' the 2-step contact chattered
  (softer contacts, 5-100 steps, too: 9-24 % of the steps with no foot down), impratio 1
  stilled it only after 0.45 s of chatter; under 'discrete' the 2-, 10- and 22-step
  contacts all rest within 3e-6.
- Rolled over: the chassis (and legs) now collide. Full drive at 20 / 65 / 100 Hz the robot
  lands on its back: the chassis's lowest corner 0.3 / 9.7 / 0.1 um into the ground (before:
  20 mm through it at 65 Hz, 2.5 at 80, 17.5 at 100); the legs 50 um (65 Hz) and 196 um
  (100 Hz: legs flailing at the swing resonance, v tau / e at ~12 m/s) into it.
- Full amplitude (the paper's drive): the feet move T x delta(200 V) = 3.5 mm (swing) and
  3.2 mm (lift) quasi-statically on a 10 mm leg, 6.1 and 9.4 mm at 65 Hz (dynamic gains 1.7
  and 2.9):

      f (Hz)  upright  speed (m/s)  no-slip est.  max |roll|,|pitch|  sliding  duty   landings
        5      yes       0.087         0.066          10, 11            74 %    0.34    2.4
       10      yes       0.093         0.074          12, 11            86 %    0.33    1.9
       20      no       (-0.16)                      108, 77 (rolled over)
       40      no       (0.045)                       62, 70
       65      no        --                          180, 43 (on its back)
     80, 100   no        --                          180, 67-86 (on its back)

  (duty: the share of the time each foot is in stance; landings: stance onsets per foot
  and cycle.) Before: upright also at 40 Hz (0.156 m/s) and at 20 Hz rocking to 33 deg
  (0.051 m/s); 5 and 10 Hz 0.081, 0.084. It trots upright at 5-10 Hz, a foot down 75-86 %
  of the time (the body rocking on its diagonal support and hopping on its legs' lift
  compliance, k_foot = m_foot (2 pi 80 Hz)^2 = 9 N/m: it bounces at 18 Hz on two feet, 25
  Hz on four, damped to zeta ~0.01); from 20 Hz up it rolls over: no speed at 65 Hz to set
  beside the paper's 0.5 m/s (mjeap.robots.hamr_walk.study: whatever single model parameter
  is changed; the lift amplitude decides it: full swing with a 20 V lift upright, 0.196 m/s;
  30 V: 0.183 m/s; 50 V 0.068 m/s at 20 / 16 deg; the full 100 V rolls over, the lift
  transmission amplifying 2.9x at 65 Hz). Speed-frequency with full swing, lift 20 V:

      f (Hz)             5      10      20      40      65      80      100
      speed (m/s)      0.067   0.149   0.292   0.159   0.196   0.347   rolls over
      no-slip est.     0.022   0.099   0.265   0.360   1.14   -0.18
      upright           yes     yes     yes     yes     yes   no (42)
      duty factor      0.82    0.61    0.51    0.21    0.035   0.012    0
      a foot down      100 %   100 %   100 %    71 %    14 %     5 %    0
      landings/cycle   0.6     1.6     1.3     2.2     0.44    0.19

  (before: 0.067, 0.146, 0.282, 0.251, 0.256 m/s to 65 Hz; 80 and 100 Hz rolled over). A
  walking trot to 20 Hz (duty factor above 0.5, a foot always down), a running trot at 40
  Hz, and from 65 Hz a hopping gait: the body in flight 86-95 % of the time.
- Why the trot hops (hamr_walk.study.contact_study): the gait, not the contact. At 80 Hz,
  20 V (the lifts at their resonance, gain 1 / (2 zeta) = 10: a free foot would move +-6.4 mm
  against the legs' static sag under the weight on two feet, W / (2 k_foot) = 0.78 mm) each
  foot lands once every 4-8 cycles (0.13, 0.23, 0.25 landings per cycle with the time
  constant at 2, 10, 50 steps; 0.17, 0.27, 0.20 under implicitfast) and the body flies 3-9
  mm above its standing height between: the time constant changes only how long a landing
  lasts (duty 0.0025, 0.0047, 0.016) and how deep it goes (2, 29, 191 um). Within a stance
  the feet do not stay on the ground either: at 40 Hz (lift 20 V) each foot touches 4-60
  times per cycle for 9-27 us (sampled every 2 steps), with the time constant at 2, 10 or
  50 steps, under either cone, impratio 1 or 10, a stiffer transmission equality (solref 2
  steps, solimp 0.99) and mu 0.1; frictionless (mu 0) they stay down for 0.1-7 ms at a time. MuJoCo's soft friction does
  this: it resolves a sliding contact's normal and friction in one cost, and a sliding
  contact is pushed apart (a 0.5 mm sphere on slide joints, driven to slide at 0.06-0.3 m/s
  on this contact, touches in under 1 % of the steps, hovering 2-60 um up; at mu 0, 98 %).
  The feet slide through most of their stance (74-91 % of the stance samples at full drive,
  21-97 % at 20-30 V), so they hover microns above the ground: the stance is read from the
  clearance (STANCE_GAP), not from MuJoCo's contact list.
- Literature: Doshi et al. 2019 (arXiv 1901.08715; its abstract, read on ar5iv) track leg
  trajectories closed loop "across a wide range of stride frequencies (10 Hz to 50 Hz)",
  find the robot's natural dynamics give "poor open-loop locomotion" at 10-30 Hz, and reach
  "minimal leg slippage (10 %)" (the sign before it lost in that rendering) and a cost of
  transport of 3.33 with trajectories designed to reduce slip. This open-loop sine trot
  slides through 74-91 % of its stance samples at full drive, 21-27 % at 20-30 V and 20 Hz.
  Goldberg, Doshi, Jayaram and Wood 2017 (Bioinspir. Biomim., HAMR's gaits, speeds and body
  natural frequencies over stride frequency) was not readable here: not compared.
- Reduced amplitude: at 30 V (feet 1.0 mm quasi-static) 20 Hz: 0.095 m/s, no-slip estimate
  0.086 (+9.96 %: within the tested 10 %, barely; before, +9 %), roll and pitch below 3
  deg, 27 % of the stance samples sliding, a foot always down, duty 0.51; 65 Hz: 0.175 m/s (0.35 x the paper; no-slip
  estimate 0.40), roll and pitch 9 and 11 deg, duty 0.024. At 20 V: 20, 40, 65, 80 Hz:
  0.053, 0.101, 0.149, 0.266 m/s (no-slip estimate 0.045, 0.109, 0.29, 0.36), duty 0.63,
  0.45, 0.035, 0.005; upright to 65 Hz, at 80 Hz pitching to 33 deg in its hops (before:
  0.053, 0.099, 0.232, 0.291, upright).
- Contact forces: a landing foot is stopped within the contact's time constant, F ~ m_eff
  v / tau; the recording pictured (10 Hz) peaks at 0.22 N (16 x the weight; before, 0.4 N),
  the 40 Hz trot's landings reach 210 x the weight over 10-20 us. The units are right
  (mj_contactForce in mg mm / ms^2 = 1 mN); the plot samples the force every 2 ms.
- Closed loop (:func:`walk_closed_loop`: the single leg's phase loops on all eight
  actuators, each reading only its own drive current through the estimator calibrated on
  the free actuator at 200 V and 4 segments; gains from phase_loop_gains at the trot
  frequency; the transmissions' sweep on the 4-segment leg at 200 V fits 99.8 Hz and 79.8
  Hz, zeta 0.052, the model's 100 / 80 Hz, 0.05), at 20 V, 80 Hz (the lifts' resonance,
  where their open-loop lag is largest: the second-order model's 90 deg, the swings' 12.5),
  40 cycles closed after 6: see tests/robots/test_hamr_walk_loops.py for the lags and errors. At
  80 Hz, 20 V the robot hops (above): a foot down 5 % (open loop) and 1.4-8 % (closed, two
  runs, the self-sensing controllers changed between them) of the time, duty 0.013 and
  0.003-0.021, and in its flights it tilts past UPRIGHT_DEG (open loop pitch 32 deg; closed
  roll 37 in one run, 17 / 24 in the other) without rolling over; the open loop +0.41 m/s,
  the closed +0.18-0.19 m/s (before: +0.35 and +0.30, upright): the loops correct the
  feet's phase, not the speed. Each foot's true error over cycles 16-39 averages
  -2.5..+4.0 deg, scattering 7-30 deg from cycle to cycle (the landings move the foot
  relative to the body); the sensed error follows the true one on average within 1.9 deg.
- Incline (the ground tilted, gravity along -z): full amplitude at 10 Hz climbs 8 deg
  (0.007 m/s), not 12 (-0.12 m/s); 30 V at 20 Hz and the 20 V lift at 65 Hz: 8 deg (the
  paper: nearly 22 deg); friction-limited (hamr_walk.study.incline_study).

The robot itself (builder, contact, read-outs, and the model's numbers) is
:mod:`mjeap.robots.hamr_walk.model`; the one-parameter studies of why it rolls over are
:mod:`mjeap.robots.hamr_walk.study`.
"""
from __future__ import annotations

import argparse
import json
import sys
from typing import Optional, Sequence

import mujoco
import numpy as np

from ...drives.waveforms import parse_waveform
from ...errors import check_integer, check_range
from ...io.commandline import arg_integer, arg_number, arg_output, parse_args
from ...io.outputs import run_guard
from ...simulation.system import System
from .. import hamr_leg
from ..registry import summary
from .model import (BIAS, CONTACT_WIDTH_FRACTION, FOOT_RADIUS, FREQUENCY_RANGE, LEGS, MU,
                    SEGMENTS, body_position, body_rotation, build, clearances, contact_sizing, design, feet,
                    foot_forces, ground_force, ground_rotation, GroundImpulses, metering, model_summary,
                    roll_pitch)

AMPLITUDE = 0.5 * BIAS          # V, full amplitude: the signal swings 0..V_bias
PAPER_SPEED, PAPER_FREQUENCY = 0.5, 65.0      # m/s at Hz, Jayaram et al. 2018
#: V: a lift amplitude at which the full-swing 65 Hz trot stays upright (hamr_walk.study: 20 and
#: 30 V upright, 40 V and full roll over), run beside the full drive where that rolls over
LIMITED_LIFT = 20.0
PAPER_INCLINE = 22.0                          # deg, Jayaram et al. 2018 ("inclines nearing 22 deg")
FREQUENCIES = (5.0, 10.0, 20.0, 40.0, 65.0, 80.0, 100.0)
RECORD_FREQUENCY = 10.0                       # Hz: the recorded run (at full amplitude it trots upright there)
SETTLE = 0.1                    # s at least, and SETTLE_CYCLES cycles, before measuring
SETTLE_CYCLES, MEASURE_CYCLES, MEASURE_MIN = 2, 4, 0.2      # cycles, cycles, s
SAMPLES_PER_CYCLE = 50
RAMP_CYCLES = 2                 # the drive's amplitude grows over these (SoftStart)
STANCE_GAP = 10e-6              # m, a foot this close to the ground is in stance (2 % of its radius)
UPRIGHT_DEG = 30.0              # deg: a body within this roll and pitch is upright
GRID = 5e-3                     # m, the recording's ground grid
SLIDE_FRACTION = 0.1            # a contact foot slides above this fraction of its stance speed


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


def force_balance(run: dict) -> dict:
    """Momentum along the ground's normal over a :func:`walk`'s measuring window: the mean of
    the ground's contact force on the robot (N, from the impulses of every step,
    ``ground_force_mean``) against what Newton's second law requires of it, the weight's
    normal share plus the change of the robot's normal momentum over the window divided by
    its duration; their ratio - 1. Beside it the mean of the forces at the samples alone
    (``sampled_force_balance_error``: a landing's force lasts a few steps, so the samples
    miss or catch it)."""
    t, up = run["time"], run["ground"][:, 2]
    k0 = int(np.argmax(t >= run["t0"] - 1e-12))
    T = t[-1] - t[k0]
    steps = np.asarray(run["interval_steps"][k0 + 1:], dtype=float)
    mean = float((run["ground_force_mean"][k0 + 1:] @ up) @ steps / steps.sum())
    fz = run["ground_force"][k0:] @ up
    sampled = float(np.sum(0.5 * (fz[1:] + fz[:-1]) * np.diff(t[k0:])) / T)
    p = run["momentum"][k0:] @ up
    need = float(run["weight_n"] * up[2] + (p[-1] - p[0]) / T)
    return {"mean_normal_force_n": mean, "momentum_normal_force_n": need, "weight_n": run["weight_n"],
            "force_balance_error": mean / need - 1.0, "sampled_force_balance_error": sampled / need - 1.0}


def walk_metrics(run: dict) -> dict:
    """The read-outs of a :func:`walk` over its measuring window (see the module text), with
    ``upright`` (:func:`upright`)."""
    t, f, G = run["time"], run["frequency"], run["ground"]
    k = t >= run["t0"] - 1e-12
    tw = t[k]
    fwd, up = G[:, 0], G[:, 2]
    p = run["body"][k]
    duration = tw[-1] - tw[0]
    speed = float((p[-1] - p[0]) @ fwd / duration)
    lateral = float((p[-1] - p[0]) @ G[:, 1] / duration)
    rp = np.degrees(np.array([roll_pitch(R, G) for R in run["R"][k]]))
    # the feet in the body frame: their fore-aft speed relative to the body
    rel = np.einsum("nji,nkj->nki", run["R"], run["feet"] - run["body"][:, None, :])     # R^T (foot - body)
    v_rel = np.gradient(rel[..., 0], t, axis=0)[k]                                        # (n, 4) m/s
    gap = run["feet"] @ up - FOOT_RADIUS                  # the feet's clearance (the plane passes the origin)
    c = (gap < STANCE_GAP)[k]                             # in stance (MuJoCo's contact flickers at zero depth)
    any_c = c.any(axis=1)
    stance_back = np.where(c, -v_rel, 0.0)
    v_est = np.where(any_c, stance_back.sum(axis=1) / np.maximum(c.sum(axis=1), 1), np.nan)
    dt = np.gradient(tw)
    stroke = float((stance_back * dt[:, None]).sum() / 4 / (duration * f))      # per foot per cycle
    duty = float(c.mean())
    stance_speed = float(np.abs(v_rel[c]).mean()) if c.any() else 0.0
    vf = run["feet_velocity"][k]
    v_t = np.linalg.norm(vf - (vf @ up)[..., None] * up, axis=-1)
    threshold = max(SLIDE_FRACTION * stance_speed, 1e-4)
    slides = (v_t > threshold) & c
    # contact: the ground's normal force on a foot, at the sample (instantaneous) and over
    # every step of the interval before it (its impulse; the steps with a positive force)
    touch_now = (run["foot_force"] @ up)[k] > 0.0                       # (n, 4)
    ki = np.flatnonzero(k)[1:]                                           # the intervals inside the window
    touch = (run["foot_force_mean"] @ up)[ki] > 0.0
    loaded = np.asarray(run["loaded_steps"])[ki]
    steps = np.asarray(run["interval_steps"])[ki]
    near = (gap < STANCE_GAP)[ki]
    out = {
        "frequency_hz": f, "amplitude_v": run["amplitude"], "lift_amplitude_v": run.get("lift_amplitude"),
        "speed_m_s": speed, "lateral_drift_m_s": lateral,
        "kinematic_speed_m_s": float(np.nanmean(v_est)) if any_c.any() else None,    # None: no foot ever down
        "stance_stroke_m": stroke, "duty_factor": duty,
        "stroke_f_over_duty_m_s": stroke * f / duty if duty > 0 else None,
        "time_with_a_foot_down": float(any_c.mean()),
        "slip_fraction": float(slides.sum() / max(c.sum(), 1)), "slide_threshold_m_s": threshold,
        "max_abs_roll_deg": float(np.abs(rp[:, 0]).max()), "max_abs_pitch_deg": float(np.abs(rp[:, 1]).max()),
        "mean_roll_deg": float(rp[:, 0].mean()), "mean_pitch_deg": float(rp[:, 1].mean()),
        "body_height_range_m": [float((p @ up).min()), float((p @ up).max())],
        "max_penetration_m": float(run["penetration"].max()),
        "contact_tolerance_m": CONTACT_WIDTH_FRACTION * FOOT_RADIUS,
        # the fastest a foot moved (m/s): a critically damped contact of time constant tau
        # stops a body landing at v within v tau / e (contact_sizing)
        "max_foot_speed_m_s": float(np.linalg.norm(run["feet_velocity"], axis=-1).max()),
        # stance onsets per foot per cycle: ~1 a trot, several a foot bouncing, < 1 a body in flight
        "touchdowns_per_cycle": float(((~c[:-1]) & c[1:]).sum() / 4 / (duration * f)),
        # the same read from the normal force: the share of the sample intervals in which a foot
        # carried load (a positive normal impulse; and of every step, and at the samples alone),
        # the onsets of those intervals per foot and cycle, and of the samples with a foot within
        # STANCE_GAP of the ground the share whose interval it carried load in (1: a stance
        # foot is in contact; and at the sample's instant alone)
        "contact_duty_factor": float(touch.mean()),                              # intervals with a load
        "loaded_step_fraction": float(loaded.sum() / (4 * steps.sum())),        # every step with a load
        "contact_duty_factor_sampled": float(touch_now.mean()),                  # at the samples alone
        "contact_touchdowns_per_cycle": float(((~touch[:-1]) & touch[1:]).sum() / 4 / (duration * f)),
        "contact_when_near": float(touch[near].mean()) if near.any() else None,
        "contact_when_near_sampled": float(touch_now[1:][near].mean()) if near.any() else None,
        # the load's onsets at the step's resolution (a flickering contact: many per cycle)
        "step_touchdowns_per_cycle": float(np.asarray(run["onsets"])[ki].sum() / 4 / (duration * f)),
        # momentum: the mean of the feet's vertical (ground-normal) forces over the window against
        # the weight plus the change of the robot's momentum along the normal (force_balance)
        **force_balance(run),
        # over the whole run (a roll-over may come before the window): below 0, through the ground
        "min_chassis_clearance_m": float(np.min(run["chassis_clearance"])),
        "min_leg_clearance_m": float(np.min(run["leg_clearance"])),
        "measured_s": float(duration), "simulated_s": float(t[-1]),
        "wall_time_s": float(run["result"].meta["wall_time_s"]),
        "wall_s_per_simulated_s": float(run["result"].meta["wall_time_s"] / t[-1]),
    }
    out["upright"] = upright(out)
    return out


# ---- closed loop: the single leg's two phase loops on all eight actuators (issue 25) ----
LOOP_FREQUENCY, LOOP_AMPLITUDE = 80.0, 20.0     # Hz, V: the lifts' resonance: open loop they lag most (~70-75 deg)
OPEN_LOOP_CYCLES = RAMP_CYCLES + 4              # cycles before the loops close (the soft start, then 4)
LOOP_CYCLES = 40                                # cycles of a closed-loop walk, the open-loop ones included
LOOP_MEASURE_CYCLES = 16                        # the walk metrics of a closed-loop walk: its last cycles
PHASE_TOL_DEG = 5.0                             # deg, Jayaram et al. 2018's "within 5 degrees"
#: Hz, the free actuator's calibration sweep (as the single leg's free_estimator)
ESTIMATOR_FREQUENCIES = (100.0, 1000.0, 1500.0, 1750.0, 2000.0)
FOOT_AXIS = {"swing": 0, "lift": 2}             # the foot's body-frame coordinate: fore-aft x, normal z


def desired_phases() -> dict:
    """Per actuator prefix the desired phase (rad, against sin(omega t)) of its foot's
    coordinate relative to the body (fore-aft for a swing, normal for a lift): the trot's,
    as :func:`trot_voltages` drives it (each transmission moves its foot +x or +z for a
    positive drive on either side)."""
    return {f"{leg}_{dof}": phase + lead for leg, (_, _, phase) in LEGS.items()
            for dof, lead in (("swing", 0.0), ("lift", 0.5 * np.pi))}


def walker_estimator(system: System):
    """Eqs. 7-9 calibrated once on the free pzt-hamr-small (no leg, no robot) at the
    walker's bias and segments, as the single leg's free_estimator (its sweep frequencies,
    ESTIMATOR_FREQUENCIES); not changed for the legs or the ground."""
    from ...controllers.hamr_leg import free_actuator
    from ...controllers.self_sensing import calibrate_on_free_actuator
    a = system.actuators[0]
    return calibrate_on_free_actuator(free_actuator(), a.drive.params["bias"], ESTIMATOR_FREQUENCIES, gravity=False,
                                      segments=system.parts[0].layout.segments)


def walk_loop_gains(frequency: float) -> dict:
    """Per degree of freedom the phase loop's (kp, ki, kd) per cycle at the trot
    ``frequency`` (Hz): controllers.hamr_leg.phase_loop_gains on the transmission's
    second-order model (resonance 100 Hz swing, 80 Hz lift, damping ratio hamr_leg.ZETA)."""
    from ...controllers.hamr_leg import phase_loop_gains
    frequency = check_range("frequency", frequency, *FREQUENCY_RANGE, "Hz")
    return {dof: phase_loop_gains(hamr_leg.ZETA, tr.resonance, frequency) for dof, tr in hamr_leg.DOFS.items()}


class TrotPhaseControllers(hamr_leg.LegControllers):
    """The eight phase loops as one system controller: per actuator a
    controllers.hamr_leg.LegPhaseController (the single leg's) driving V_bias/2 + a sin(omega t
    + phi), phi starting at the trot's phase (:func:`desired_phases`), the amplitude ramped
    over RAMP_CYCLES as the open-loop trot's; after ``open_loop_cycles`` phi moves once per
    cycle by the PI on the sensed foot phase error. Each loop reads only its own actuator's
    drive current (a drive observer stepped with the voltage it holds) through its own copy
    of ``estimator`` (:func:`walker_estimator` if None); nothing else of the simulator. Stepped
    as the single leg's (hamr_leg.LegControllers.__call__)."""

    name = "eight foot phase PIs on the self-sensed currents"

    def __init__(self, system: System, frequency: float, amplitude: float = LOOP_AMPLITUDE,
                 open_loop_cycles: int = OPEN_LOOP_CYCLES, estimator=None, gains: Optional[dict] = None):
        import copy
        from ...controllers.hamr_leg import LegPhaseController
        bias = system.actuators[0].drive.params["bias"]
        frequency = check_range("frequency", frequency, *FREQUENCY_RANGE, "Hz")
        amplitude = check_range("amplitude", amplitude, 0.0, 0.5 * bias, "V", lo_open=True)
        open_loop_cycles = check_integer("open_loop_cycles", open_loop_cycles, RAMP_CYCLES, 10_000)
        est = walker_estimator(system) if estimator is None else estimator
        gains = walk_loop_gains(frequency) if gains is None else gains
        self.frequency, self.open_loop_cycles, self.dt = frequency, open_loop_cycles, system.timestep
        self.ctrls, self.obs = {}, {}
        for prefix, phase in desired_phases().items():
            c = LegPhaseController(copy.deepcopy(est), frequency, amplitude, phase, gains[prefix.split("_")[1]],
                                   open_loop_cycles, initial_phase=phase, ramp=RAMP_CYCLES / frequency)
            self.obs[prefix] = system.drive_observer(prefix)
            c.reset(system, self.obs[prefix])
            self.ctrls[prefix] = c


def foot_phase_errors(run: dict, cycles: int) -> dict:
    """Per actuator prefix the true phase error (deg) of its foot per drive cycle, for the
    first ``cycles`` cycles of a :func:`walk`: the foot's simulated 3D position relative to
    the body, in the body frame (fore-aft x for a swing, normal z for a lift), against
    :func:`desired_phases` (controllers.hamr_leg.phase_errors_per_cycle, a lock-in per cycle)."""
    from ...controllers.hamr_leg import phase_errors_per_cycle
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


def upright(metrics: dict) -> bool:
    """|roll| and |pitch| stayed below UPRIGHT_DEG over the measuring window."""
    return bool(metrics["max_abs_roll_deg"] < UPRIGHT_DEG and metrics["max_abs_pitch_deg"] < UPRIGHT_DEG)


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


def _check_outputs(a) -> None:
    """The recordings are two distinct files (a shared path would overwrite the first)."""
    from ...io.outputs import check_outputs
    check_outputs(**{"--out": a.out, "--loop-out": None if a.no_closed_loop else a.loop_out})


def main(argv=None):
    ap = argparse.ArgumentParser(description=summary(__doc__))
    ap.add_argument("--out", default="out/hamr_walk.rrd", type=arg_output(), help="recording (.rrd)")
    ap.add_argument("--frequencies", nargs="+", type=arg_number(*FREQUENCY_RANGE, "Hz"), default=list(FREQUENCIES),
                    help=f"trot frequencies (Hz, {FREQUENCY_RANGE[0]:g} to {FREQUENCY_RANGE[1]:g})")
    ap.add_argument("--record-frequency", type=arg_number(*FREQUENCY_RANGE, "Hz"), default=RECORD_FREQUENCY,
                    help="the frequency of the recorded run (Hz)")
    ap.add_argument("--amplitude", type=arg_number(0.0, AMPLITUDE, "V", lo_open=True), default=AMPLITUDE,
                    help=f"drive amplitude about V_bias / 2 (V; {AMPLITUDE:g}: full, the signal swings 0..{BIAS:g} V)")
    ap.add_argument("--mu", type=arg_number(0.0, 10.0), default=MU, help="foot-ground friction coefficient")
    ap.add_argument("--segments", type=arg_integer(1, 40), default=SEGMENTS, help="segments per actuator")
    ap.add_argument("--loop-frequency", type=arg_number(*FREQUENCY_RANGE, "Hz"), default=LOOP_FREQUENCY,
                    help="the closed-loop trot's frequency (Hz)")
    ap.add_argument("--loop-amplitude", type=arg_number(0.0, AMPLITUDE, "V", lo_open=True), default=LOOP_AMPLITUDE,
                    help="the closed-loop trot's drive amplitude about V_bias / 2 (V)")
    ap.add_argument("--loop-cycles", type=arg_integer(OPEN_LOOP_CYCLES + 2, 10_000), default=LOOP_CYCLES,
                    help=f"cycles of the closed-loop trot, its {OPEN_LOOP_CYCLES} open-loop ones included")
    ap.add_argument("--loop-out", default="out/hamr_walk_loop.rrd", type=arg_output(),
                    help="recording of the closed-loop trot (.rrd)")
    ap.add_argument("--no-closed-loop", action="store_true", help="skip the closed-loop trot")
    ap.add_argument("--quick", action="store_true",
                    help="skip the rest check, the segment check and the incline search (at --record-frequency)")
    a = parse_args(ap, argv, _check_outputs)
    # the recordings locked before any work (a second run on them is refused); each study's
    # recording is written as soon as it is done, so Ctrl-C or SIGTERM keeps it
    with run_guard(**{"--out": a.out, "--loop-out": None if a.no_closed_loop else a.loop_out}):
        return _experiments(a)


def _experiments(a) -> None:
    """The command line's studies (:func:`main`), its outputs already held."""
    d = design()
    system = build(a.mu, a.segments, d=d)
    out = {"model": model_summary(system), "amplitude_v": a.amplitude, "bias_v": BIAS, "mu": a.mu, "runs": []}
    freqs = sorted(set(a.frequencies) | {a.record_frequency})
    for f in freqs:
        run = walk(system, f, a.amplitude)
        m = walk_metrics(run)
        out["runs"].append(m)
        if f == a.record_frequency and a.out:
            write_recording(a.out, system, run)
        print(f"{f:g} Hz: {m['speed_m_s']:.4g} m/s (no-slip {m['kinematic_speed_m_s'] or float('nan'):.4g}), slip "
              f"{m['slip_fraction']:.2f}, roll/pitch {m['max_abs_roll_deg']:.1f}/{m['max_abs_pitch_deg']:.1f} deg, "
              f"{m['wall_s_per_simulated_s']:.1f} s wall per s", file=sys.stderr)
    at = {r["frequency_hz"]: r for r in out["runs"]}
    if PAPER_FREQUENCY in at:
        v, up = at[PAPER_FREQUENCY]["speed_m_s"], at[PAPER_FREQUENCY]["upright"]
        out["speed_at_65hz_m_s"], out["paper_speed_m_s"], out["upright_at_65hz"] = v, PAPER_SPEED, up
        # a robot that rolled over has no speed to compare
        out["speed_over_paper"] = v / PAPER_SPEED if up else None
        # the check: upright and forward within a factor of 2 of the paper's 0.5 m/s
        out["speed_at_65hz_within_2x_of_paper"] = bool(up and 0.5 * PAPER_SPEED <= v <= 2.0 * PAPER_SPEED)
        if not up:      # the cause, shown: the same swing with the lift at LIMITED_LIFT (hamr_walk.study)
            m = walk_metrics(walk(system, PAPER_FREQUENCY, a.amplitude, lift_amplitude=LIMITED_LIFT))
            out["at_65hz_lift_limited"] = {
                "lift_amplitude_v": LIMITED_LIFT, "speed_m_s": m["speed_m_s"], "upright": m["upright"],
                "speed_over_paper": m["speed_m_s"] / PAPER_SPEED if m["upright"] else None,
                "max_abs_roll_deg": m["max_abs_roll_deg"], "max_abs_pitch_deg": m["max_abs_pitch_deg"],
                "cause": "at full drive the feet's stroke (3.2-3.6 mm, A omega^2 = 60 g at 65 Hz) throws the 1.43 g "
                         "body into flights it lands from tilted (docs/robots/hamr-walk.md; "
                         "mjeap.robots.hamr_walk.study)"}
    # the check: the full-drive trot upright at every frequency of 10-65 Hz run here
    band = [r for r in out["runs"] if 10.0 <= r["frequency_hz"] <= PAPER_FREQUENCY]
    out["upright_10_to_65_hz"] = {f"{r['frequency_hz']:g}": r["upright"] for r in band}
    out["upright_at_every_frequency_10_to_65_hz"] = bool(band) and all(r["upright"] for r in band)
    low = at[min(at)]
    k = low["kinematic_speed_m_s"]
    out["kinematic_check"] = {"frequency_hz": low["frequency_hz"], "speed_m_s": low["speed_m_s"],
                              "no_slip_estimate_m_s": k, "relative_error": None if not k else low["speed_m_s"] / k - 1.0}
    out["wall_s_per_simulated_s"] = float(np.mean([r["wall_s_per_simulated_s"] for r in out["runs"]]))
    # per frequency: the share of the time a foot is down (per foot), a foot at all, the landings per cycle
    out["duty_factor_by_frequency"] = {f"{r['frequency_hz']:g}": {
        "duty_factor": r["duty_factor"], "contact_duty_factor": r["contact_duty_factor"],
        "contact_when_near": r["contact_when_near"], "contact_touchdowns_per_cycle": r["contact_touchdowns_per_cycle"],
        "force_balance_error": r["force_balance_error"], "time_with_a_foot_down": r["time_with_a_foot_down"],
        "touchdowns_per_cycle": r["touchdowns_per_cycle"], "upright": r["upright"]} for r in out["runs"]}
    out["contact"] = contact_sizing(system)
    if not a.no_closed_loop:
        out["closed_loop"] = closed_loop_section(system, a.loop_frequency, a.loop_amplitude, a.loop_cycles, a.loop_out)
    if not a.quick:
        out["rest"] = stand(system)         # no drive: the feet carry the weight at every step, no creep
        out["segment_effect"] = segment_effect()
        out["incline"] = max_incline(a.record_frequency, a.amplitude, a.mu, a.segments)
    out["recording"] = a.out
    print(json.dumps(out, indent=1, default=float))
