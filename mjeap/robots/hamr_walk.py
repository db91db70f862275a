"""HAMR-VI walks (issue 25; seed 003, section 6.2): a free-floating 1.43 g, 4.51 cm
quadruped, four legs of two pzt-hamr-small actuators each (the legs of
mjeap.robots.hamr_leg), trotting on a ground plane open loop at the paper's 200 V bias.

    mjeap robot hamr-walk [--out out/hamr_walk.rrd] [--frequencies 5 10 20 40 65 80 100]
        [--record-frequency 10] [--amplitude 100] [--mu 0.51] [--segments 4] [--quick]
        [--loop-frequency 80] [--loop-amplitude 20] [--loop-cycles 40] [--loop-out ...] [--no-closed-loop]

Prints JSON: per frequency the forward speed, the no-slip kinematic estimate, foot slip,
body roll and pitch, penetration and wall time; the speed at 65 Hz beside the paper's
0.5 m/s; the segment check and the steepest incline climbed at --record-frequency (not with
--quick); the closed_loop section (the eight phase loops against the open loop at
--loop-frequency, --loop-amplitude). Writes a recording of the --record-frequency run and
one of the closed loop. Written against mjeap's public
component API (attach, System, ContactParameters, add_transmission) and plain MjSpec.

Model (host in mm, mg, ms; gravity along -z; x forward, y left, z up):
- Body: a free body (freejoint), BODY_LENGTH = 45.1 mm long, the whole robot TOTAL_MASS =
  1.43 g (seed 003: "a 4.51 cm long, 1.43 g quadrupedal microrobot"); width 15 mm and height
  4 mm ASSUMED; the body's own mass (a uniform box, 0.49 g) is what the eight actuators
  (0.48 g) and the four legs (0.46 g) leave.
- Legs: mjeap.robots.hamr_leg.add_leg with the single leg's design (hamr_leg.design():
  joint inertias that put the loaded actuators at the transmission resonances, 100 Hz swing
  and 80 Hz lift, zeta 0.05; T_swing = 13, T_lift = 12, seed 003 from its ref. [51];
  LEG_LENGTH 10 mm, ASSUMED there), one per corner: hips at x = +-HIP_X (14 mm, ASSUMED),
  y = +-7.5 mm (the body's sides), the rod outward along +-y, the foot FOOT_DROP = 11.35 mm
  below its end on a massless shank (the foot's offset below its leg frame in N. Doshi's
  HAMR-VI simulation model, HamrRBM.FOOT_POS, public Drake/MATLAB code; the shank leaves the
  foot's fore-aft and normal motion per joint angle as the single leg's and adds a lateral
  one, 11.35 mm per radian of lift). Mass radius LEG_LENGTH (the single leg's 2 mm would
  make each leg weigh 1.8 g): each leg carries the single leg's inertias with 0.12 g.
- Actuators: eight pzt-hamr-small (piezo-bimorph drive, bias 200 V), clamped on the body
  (mount sites on it: the clamps ride with it), along x in the body's horizontal plane (their
  bending plane; gravity along their hinge axes), the front legs' pointing forward, the
  rear legs' backward; ``contact=False``: only the feet touch the ground. SEGMENTS = 4 per
  actuator: against 20, the single leg's foot gain moves by -0.05 % (swing) and -0.1 %
  (lift) at 20 Hz, -0.4 % and -1.7 % at 65 Hz (2 segments: -1.2 % and -3.6 % at 65 Hz;
  :func:`segment_effect`); the timestep (10.4 us) is set by the first mode either way.
- Feet: spheres of FOOT_RADIUS = 0.5 mm (ASSUMED) on a ground plane, Coulomb friction
  MU = 0.51 (the value of Doshi's HAMR trot simulations; a parameter), MuJoCo soft contact
  from mjeap.simulation.system.ContactParameters (time constant 2 timesteps, critically damped,
  elliptic cone, impratio 10 against creep); the solimp width, 0.1 x FOOT_RADIUS = 50 um,
  is the contact tolerance of the penetration check.

Gait (trot): per actuator V = V_bias/2 + a sin(omega t + phi), a = AMPLITUDE = 100 V by
default (full: the signal swings 0..200 V); the diagonal pairs (front-left + rear-right,
front-right + rear-left) in phase, the pairs 180 degrees apart, each lift 90 degrees ahead of
its swing (the foot ellipse of seed 003's ref. [50]: with foot x ~ sin and z ~ cos the foot
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
body would move if no stance foot slid; also the stance stroke, duty factor, stroke x f /
duty.

Findings (4 segments, mu 0.51, MuJoCo 4.0; wall time 3.5-7 s per simulated second on 2
shared cores). Re-measured after the fix of hamr_leg.add_leg's swing-stage and lift-lever
centres of mass (commit 41b82c0: before it the robot's swing joints carried twice the
design inertia, swing resonance 71 Hz, not 100), with :func:`walk` and :func:`walk_metrics`
at their default windows; the motion is chaotic (a small change of mu or segments moves
these numbers), so they are single runs, not converged values:
- Full amplitude (the paper's drive): the feet move T x delta(200 V) = 3.5 mm (swing) and
  3.2 mm (lift) quasi-statically on a 10 mm leg, 6.1 and 9.4 mm at 65 Hz (dynamic gains 1.7
  and 2.9). After the fix:

      f (Hz)   upright   speed (m/s)   no-slip est.   max |roll|, |pitch| (deg)   sliding
        5       yes        0.081          0.069             7,  8                  75 %
       10       yes        0.084          0.086            13, 11                  84 %
       20       no         0.051          0.078            33, 13                  86 %
       40       yes        0.156          0.232            24, 15                  89 %
       65       no        (-0.13)         --               72, 61 (rolled over; body to 39 mm)
     80, 100    no          --            --              180, 86 (on its back)

  It trots upright at 5-10 Hz (the body rocking on its diagonal support and hopping on its
  legs' lift compliance: k_foot = m_foot (2 pi 80 Hz)^2 = 9 N/m, the body bounces at 18 Hz
  on two feet, 25 Hz on four, damped to zeta ~0.01) and, just, at 40 Hz; at 20 Hz it rocks
  past UPRIGHT_DEG (33 deg) while still moving forward; from 65 Hz up it rolls over: no
  speed at 65 Hz to set beside the paper's 0.5 m/s (mjeap.robots.hamr_walk_study: whatever
  single model parameter is changed; the lift amplitude decides it: full swing with a 20 V
  lift upright, 0.256 m/s; 30 V: 0.186 m/s; 40 V and up: thrown off its feet, the lift
  transmission amplifying 2.9x at 65 Hz. Speed-frequency with full swing, lift 20 V: 5, 10,
  20, 40, 65 Hz: 0.067, 0.146, 0.282, 0.251, 0.256 m/s, no-slip estimate 0.063, 0.135,
  0.311, 0.392, 0.963; 80 and 100 Hz roll over). Before the fix: transmission damping
  zeta 0.15 or 0.3 still rolled over at 65 Hz (not re-measured).
- Reduced amplitude, after the fix: at 30 V (feet 1.0 mm quasi-static) 20 Hz: 0.093 m/s,
  no-slip estimate 0.086 (9 % below; tested within 10 %), roll and pitch below 3 deg, 36 %
  of the stance samples sliding; 65 Hz: 0.217 m/s (0.43 x the paper; no-slip estimate
  0.331), roll and pitch 7 and 5 deg, a bounding gait (the body 13.4-15.6 mm high against
  11.6-12.0 mm at 20 Hz). At 20 V the speed rises with frequency and stays upright: 20, 40,
  65, 80 Hz: 0.053, 0.099, 0.232, 0.291 m/s (no-slip estimate 0.047, 0.100, 0.301, 0.331).
  Before the fix the 20 V trot walked backward at 80 Hz (-0.30 m/s: the swing, at 71 Hz,
  lagged past the lift); after it, it does not (see Closed loop).
- The contact-force plot's spikes (measured before the fix: 18 N on FL's leg at t = 0.735 s
  in the 10 Hz run, 1300x the weight): a foot striking the ground at 0.59 m/s (the body
  rocking onto it), stopped within the contact's time constant (2 timesteps, 21 us): F ~
  m_eff v / tau. The units are right (mj_contactForce in mg mm / ms^2 = 1 mN); the peak is
  set by the numerical time constant, not a physical stiffness, and the plot samples the
  instantaneous force every 2 ms, so it shows such a 20 us impact only when a sample falls
  in it.
- Closed loop (:func:`walk_closed_loop`: the single leg's phase loops on all eight
  actuators, each reading only its own drive current through the estimator calibrated on
  the free actuator at 200 V and 4 segments; gains from phase_loop_gains at the trot
  frequency; the transmissions' sweep on the 4-segment leg at 200 V fits 99.8 Hz and 79.8
  Hz, zeta 0.052, the model's 100 / 80 Hz, 0.05), at 20 V, 80 Hz (the lifts' resonance,
  where their open-loop lag is largest: the second-order model's 90 deg, the swings' 12.5),
  after the fix, 40 cycles closed after 6: open loop (cycles 4-39) the lifts lag 70.5-75.6
  deg (less than 90: stance adds the ground's stiffness to the lift) and the swings
  15.3-21.3 deg, each with a per-cycle scatter of 8-15 deg sd; closed, each foot's true
  error over cycles 16-39 averages -0.9..+4.4 deg (standard error of that mean 1.6-3.2
  deg), but scatters 8-15 deg sd from cycle to cycle (the stance impacts and the body's
  bounce move the foot relative to the body): no foot holds 5 deg every cycle (four come
  within it only over the last cycles). The sensed
  error follows the true one on average within 2.6 deg. The open loop walks forward here
  (+0.35 m/s over the last 16 cycles, upright), faster than the closed loop (+0.30 m/s,
  upright): the loops correct the feet's phase, not the speed. Before the fix the open loop
  walked backward (-0.48 m/s) and the loop turned it forward; after it no drive near the
  lift resonance shows that: at 85 and 90 Hz (lifts lagging 102-110 and 118-128 deg) the
  open loop walks forward too (+0.30, +0.55 m/s), and the closed loop leaves the lifts' mean
  error at 5-10 and 13-33 deg. 80 Hz stays the demonstration: the largest lift lag whose
  loop settles.
- Incline (the ground tilted, gravity along -z), after the fix: full amplitude at 10 Hz
  climbs 8 deg (0.005 m/s), not 12 (-0.13 m/s); 30 V at 20 Hz climbs 8 deg (0.066 m/s), not
  12 (-0.063 m/s) (the paper: nearly 22 deg).
"""
from __future__ import annotations

import argparse
import json
import sys
from typing import Optional, Sequence

import mujoco
import numpy as np

from ..cli import arg_integer, arg_number, arg_output, parse_args, run_script
from ..drives.waveforms import parse_waveform
from ..errors import ParameterError, check_integer, check_range
from ..simulation.system import ContactParameters, System, attach
from . import hamr_leg
from .hamr_leg import ACTUATOR, LEG_LENGTH, add_leg, design
from .registry import Robot, register, summary

TOTAL_MASS = 1.43e-3            # kg, seed 003
BODY_LENGTH = 45.1e-3           # m, seed 003
BODY_WIDTH = 15e-3              # m, assumed
BODY_HEIGHT = 4e-3              # m, assumed
HIP_X = 14e-3                   # m, assumed (hips 28 mm apart fore-aft)
FOOT_DROP = 11.35e-3            # m, the foot below its leg frame in Doshi's HAMR model (see the module text)
FOOT_RADIUS = 0.5e-3            # m, assumed
MU = 0.51                       # sliding friction, as Doshi's HAMR trot simulations (see the module text)
CONTACT_WIDTH_FRACTION = 0.1    # solimp width as a fraction of FOOT_RADIUS: the penetration tolerance
IMPRATIO = 10.0
BIAS = 200.0                    # V, HAMR's drive bias (the brief's "paper's 200 V")
AMPLITUDE = 0.5 * BIAS          # V, full amplitude: the signal swings 0..V_bias
SEGMENTS = 4
PAPER_SPEED, PAPER_FREQUENCY = 0.5, 65.0      # m/s at Hz, seed 003
#: V: a lift amplitude at which the full-swing 65 Hz trot stays upright (hamr_walk_study: 20 and
#: 30 V upright, 40 V and full roll over), run beside the full drive where that rolls over
LIMITED_LIFT = 20.0
PAPER_INCLINE = 22.0                          # deg, seed 003 ("inclines nearing 22 deg")
FREQUENCIES = (5.0, 10.0, 20.0, 40.0, 65.0, 80.0, 100.0)
FREQUENCY_RANGE = (1.0, 100.0)                # Hz
RECORD_FREQUENCY = 10.0                       # Hz: the recorded run (at full amplitude it trots upright there)
#: leg name -> (fore +1 / aft -1, side +1 left / -1 right, trot phase of its pair)
LEGS = {"FL": (1, 1, 0.0), "FR": (1, -1, np.pi), "RL": (-1, 1, np.pi), "RR": (-1, -1, 0.0)}
SETTLE = 0.1                    # s at least, and SETTLE_CYCLES cycles, before measuring
SETTLE_CYCLES, MEASURE_CYCLES, MEASURE_MIN = 2, 4, 0.2      # cycles, cycles, s
SAMPLES_PER_CYCLE = 50
RAMP_CYCLES = 2                 # the drive's amplitude grows over these (SoftStart)
STANCE_GAP = 10e-6              # m, a foot this close to the ground is in stance (2 % of its radius)
UPRIGHT_DEG = 30.0              # deg: a body within this roll and pitch is upright
GRID = 5e-3                     # m, the recording's ground grid
SLIDE_FRACTION = 0.1            # a contact foot slides above this fraction of its stance speed


def build(mu: float = MU, segments: int = SEGMENTS, bias: float = BIAS, incline_deg: float = 0.0,
          d: Optional[dict] = None, armature_fraction: float = 0.0, foot_drop: float = FOOT_DROP,
          body_width: float = BODY_WIDTH, timeconst_steps: float = 2.0) -> System:
    """The robot as a System (host in mm, mg, ms) standing on a ground plane tilted by
    ``incline_deg`` about y (uphill along +x); ``d``: hamr_leg.design() (computed if None).

    For the roll-over study (mjeap.robots.hamr_walk_study), each a model parameter whose
    true value is not published: ``armature_fraction`` of each leg joint's design inertia
    is carried as joint armature (a rotor on the joint: it enters that joint's own inertia
    only, so the transmission resonances stay, but it exchanges no momentum with the body)
    instead of by the leg's moving masses, whose masses scale by 1 - armature_fraction (the
    body's own mass takes up the rest: the robot still weighs TOTAL_MASS); ``foot_drop`` (m):
    the foot below the leg rod's end (its lateral motion per radian of lift); ``body_width``
    (m): the chassis width, the hips at its sides; ``timeconst_steps``: the contact's time
    constant in timesteps (ContactParameters)."""
    mu = check_range("mu", mu, 0.0, 10.0)
    segments = check_integer("segments", segments, 1, 40)
    incline = np.radians(check_range("incline_deg", incline_deg, -45.0, 45.0, "deg"))
    armature_fraction = check_range("armature_fraction", armature_fraction, 0.0, 1.0, hi_open=True)
    foot_drop = check_range("foot_drop", foot_drop, 0.0, 0.05, "m")
    body_width = check_range("body_width", body_width, 6e-3, 0.1, "m")
    timeconst_steps = check_range("timeconst_steps", timeconst_steps, 2.0, 100.0)
    d = design() if d is None else d
    if armature_fraction:
        d = {n: {**v, "joint_inertia_kg_m2": v["joint_inertia_kg_m2"] * (1.0 - armature_fraction)}
             for n, v in d.items()}
    spec = mujoco.MjSpec.from_string('<mujoco><option gravity="0 0 -9.80665e-3"/><worldbody/></mujoco>')
    wb = spec.worldbody
    # the ground: a plane turned about y by -incline (its +x rises), the robot on it
    q_ground = [np.cos(-incline / 2), 0.0, np.sin(-incline / 2), 0.0]
    wb.add_geom(name="ground", type=mujoco.mjtGeom.mjGEOM_PLANE, size=[200.0, 200.0, 1.0], quat=q_ground,
                rgba=[0.85, 0.85, 0.8, 1], contype=0, conaffinity=1, condim=3)
    mm = 1e3
    L, W, H = BODY_LENGTH * mm, body_width * mm, BODY_HEIGHT * mm
    hip_height = (foot_drop + FOOT_RADIUS) * mm + 0.02          # feet 20 um above the ground at the start
    R_ground = np.zeros(9)
    mujoco.mju_quat2Mat(R_ground, np.array(q_ground))
    body = wb.add_body(name="body", pos=(R_ground.reshape(3, 3) @ [0, 0, hip_height]).tolist(), quat=q_ground)
    body.add_freejoint(name="root")
    box = body.add_geom(name="chassis", type=mujoco.mjtGeom.mjGEOM_BOX, size=[L / 2, W / 2, H / 2], pos=[0, 0, H / 2],
                        mass=TOTAL_MASS * 1e6 / 2, rgba=[0.25, 0.3, 0.4, 0.5], contype=0, conaffinity=0)
    acts = {}
    for leg, (fore, side, _) in LEGS.items():
        for k, dof in enumerate(("swing", "lift")):
            # clamps 2 mm either side of the middle, the beams running toward their hips
            site = body.add_site(name=f"{leg}_{dof}_mount", pos=[fore * 2.0, side * (2.5 + 3.0 * k), H - 1.0 - 2.0 * k],
                                 quat=[1, 0, 0, 0] if fore > 0 else [0, 0, 0, 1])
            acts[f"{leg}_{dof}"] = attach(spec, ACTUATOR, site=site.name, prefix=f"{leg}_{dof}", contact=False,
                                          drive_params={"bias": bias}, segments=segments)
    for leg, (fore, side, _) in LEGS.items():
        add_leg(spec, body, {dof: acts[f"{leg}_{dof}"] for dof in ("swing", "lift")}, d, prefix=f"{leg}/",
                pos=[fore * HIP_X * mm, side * W / 2, 0.0], side=side, mass_radius=LEG_LENGTH * mm,
                foot_drop=foot_drop * mm, foot_radius=FOOT_RADIUS * mm, foot_contact=True)
        if armature_fraction:
            u0 = acts[f"{leg}_swing"].twin.units
            for dof in ("swing", "lift"):
                full = d[dof]["joint_inertia_kg_m2"] / (1.0 - armature_fraction)
                spec.joint(f"{leg}/{dof}").armature = armature_fraction * full / (u0.mass * u0.length**2)
    # the body's own mass: what the actuators and legs leave of TOTAL_MASS
    m = spec.copy().compile()
    bid = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, "body")
    others = m.body_subtreemass[bid] - box.mass
    own = TOTAL_MASS * 1e6 - others
    if own <= 0:
        raise ParameterError("TOTAL_MASS", TOTAL_MASS, f"more than the actuators and legs ({others * 1e-6:.4g} kg)")
    box.mass = own
    acts_list = list(acts.values())
    u = acts_list[0].twin.units
    h = min(a.twin.timestep for a in acts_list)
    contact = ContactParameters(friction=(mu, 5e-6, 1e-7), impratio=IMPRATIO, width_fraction=CONTACT_WIDTH_FRACTION,
                                timeconst_steps=timeconst_steps)
    # System applies contact parameters only for actuators with contact: here the feet's
    contact.apply(spec, h / u.time, FOOT_RADIUS / u.length, u.length)
    return System(spec, acts_list, contact=contact)


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


def body_position(system: System) -> np.ndarray:
    """The body's world position (m)."""
    return system.data.body("body").xpos * system.units.length


def body_rotation(system: System) -> np.ndarray:
    """The body's world rotation (3 x 3)."""
    return system.data.body("body").xmat.reshape(3, 3).copy()


def feet(system: System) -> np.ndarray:
    """The four feet's world positions (m), in LEGS order."""
    return np.array([system.data.site(f"{leg}/foot").xpos for leg in LEGS]) * system.units.length


def ground_rotation(system: System) -> np.ndarray:
    """The ground plane's world rotation: its x uphill (forward), z its normal."""
    return system.data.geom("ground").xmat.reshape(3, 3).copy()


def roll_pitch(R: np.ndarray, G: np.ndarray) -> tuple:
    """Roll and pitch (rad) of a body rotation ``R`` relative to the ground's ``G``."""
    Rr = G.T @ R
    return float(np.arctan2(Rr[2, 1], Rr[2, 2])), float(np.arcsin(np.clip(-Rr[2, 0], -1, 1)))


def _durations(frequency: float, settle: Optional[float], measure: Optional[float]) -> tuple:
    """(settle, measure) in s, each whole cycles."""
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
    deepest penetration; the rollout's result; the measuring window's start ``t0``."""
    bias = system.actuators[0].drive.params["bias"]
    settle, measure = _durations(frequency, settle, measure)
    fid = [mujoco.mj_name2id(system.model, mujoco.mjtObj.mjOBJ_GEOM, f"{leg}/foot") for leg in LEGS]
    sid = [mujoco.mj_name2id(system.model, mujoco.mjtObj.mjOBJ_SITE, f"{leg}/foot") for leg in LEGS]
    rows = {k: [] for k in ("body", "R", "feet", "feet_velocity", "contact", "penetration")}
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
        rows["penetration"].append(sy.penetration())

    volts = None if controller is not None else trot_voltages(frequency, amplitude, bias, lift_amplitude=lift_amplitude)
    res = system.rollout(volts, settle + measure, sample_interval=1.0 / (samples_per_cycle * frequency),
                         on_sample=on_sample, controller=controller)
    run = {k: np.array(v) for k, v in rows.items()}
    run.update(time=res.time[:len(rows["body"])], result=res, frequency=float(frequency), amplitude=float(amplitude),
               lift_amplitude=float(amplitude if lift_amplitude is None else lift_amplitude),
               t0=float(settle), ground=ground_rotation(system))
    return run


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
PHASE_TOL_DEG = 5.0                             # deg, seed 003's "within 5 degrees"
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
    from ..controllers.hamr_leg import free_actuator
    from ..controllers.self_sensing import calibrate_on_free_actuator
    a = system.actuators[0]
    return calibrate_on_free_actuator(free_actuator(), a.drive.params["bias"], ESTIMATOR_FREQUENCIES, gravity=False,
                                      segments=system.parts[0].layout.segments)


def walk_loop_gains(frequency: float) -> dict:
    """Per degree of freedom the phase loop's (kp, ki, kd) per cycle at the trot
    ``frequency`` (Hz): controllers.hamr_leg.phase_loop_gains on the transmission's
    second-order model (resonance 100 Hz swing, 80 Hz lift, damping ratio hamr_leg.ZETA)."""
    from ..controllers.hamr_leg import phase_loop_gains
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
        from ..controllers.hamr_leg import LegPhaseController
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
    from ..controllers.hamr_leg import phase_errors_per_cycle
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
    from ..controllers.hamr_leg import cycles_to_within
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
    speed (instantaneous, per cycle, the paper's 0.5 m/s at 65 Hz), its roll and pitch and
    the feet's clearance."""
    import rerun as rr
    import rerun.blueprint as rrb
    from ..io.recording import write_system_recording, x_axis, y_axis

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
                for i, leg in enumerate(LEGS)):
            rec.log(ent, rr.SeriesLines(names=label, colors=[colour]), static=True)
            rec.send_columns(ent, indexes=[rr.TimeColumn("time", duration=ts)] if ts is not t else tc,
                             columns=rr.Scalars.columns(scalars=np.asarray(values, dtype=float)))

    views = (rrb.TimeSeriesView(origin="/walk/speed", name=f"forward speed (m/s) at {f:g} Hz",
                                axis_y=y_axis(v_cyc, [0.0, PAPER_SPEED]), axis_x=x_axis(t)),
             rrb.TimeSeriesView(origin="/walk/attitude", name="roll and pitch (deg)", axis_y=y_axis(rp),
                                axis_x=x_axis(t)),
             rrb.TimeSeriesView(origin="/walk/clearance", name="foot clearance above the ground (m)",
                                axis_y=y_axis(clearance), axis_x=x_axis(t)))
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


def model_summary(system: System) -> dict:
    """Masses and dimensions of the built robot (SI), with what is cited and what assumed."""
    m = system.model
    u = system.units
    mass = {}
    for b in range(1, m.nbody):
        name = mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_BODY, b)
        key = "body" if name == "body" else "actuators" if "_swing/" in name or "_lift/" in name else "legs"
        mass[key] = mass.get(key, 0.0) + float(m.body_mass[b]) * u.mass
    return {"total_mass_kg": float(m.body_subtreemass[1] * u.mass), "mass_kg": mass,
            "body_length_m": BODY_LENGTH, "body_width_m": BODY_WIDTH, "body_height_m": BODY_HEIGHT,
            "hip_x_m": HIP_X, "leg_length_m": LEG_LENGTH, "foot_drop_m": FOOT_DROP, "foot_radius_m": FOOT_RADIUS,
            "timestep_s": system.timestep, "segments": system.parts[0].layout.segments,
            "cited": {"total mass, body length, 0.5 m/s at 65 Hz, 22 deg": "seed 003 section 6.2 (Jayaram 2018)",
                      "T_swing 13, T_lift 12, resonances 100 / 80 Hz": "seed 003 section 6.2 (its refs [51], [19])",
                      "foot 11.35 mm below its leg frame, mu 0.51, drive ramped over 2 cycles":
                          "N. Doshi's HAMR Drake simulation scripts (HamrRBM FOOT_POS, trot sweeps MU)"},
            "assumed": ["body width and height", "hip spacing", "leg length (hamr_leg)", "foot radius",
                        "the legs' mass radius (= leg length)", "contact: MuJoCo soft, elliptic cone, impratio 10"]}


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
                    help="skip the segment check and the incline search (at --record-frequency)")
    a = parse_args(ap, argv)
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
        if not up:      # the cause, shown: the same swing with the lift at LIMITED_LIFT (hamr_walk_study)
            m = walk_metrics(walk(system, PAPER_FREQUENCY, a.amplitude, lift_amplitude=LIMITED_LIFT))
            out["at_65hz_lift_limited"] = {
                "lift_amplitude_v": LIMITED_LIFT, "speed_m_s": m["speed_m_s"], "upright": m["upright"],
                "speed_over_paper": m["speed_m_s"] / PAPER_SPEED if m["upright"] else None,
                "max_abs_roll_deg": m["max_abs_roll_deg"], "max_abs_pitch_deg": m["max_abs_pitch_deg"],
                "cause": "at 65 Hz the lift transmission (80 Hz) amplifies its drive ~2.9 x: the feet throw the "
                         "body off the ground at full lift (mjeap.robots.hamr_walk_study)"}
    low = at[min(at)]
    k = low["kinematic_speed_m_s"]
    out["kinematic_check"] = {"frequency_hz": low["frequency_hz"], "speed_m_s": low["speed_m_s"],
                              "no_slip_estimate_m_s": k, "relative_error": None if not k else low["speed_m_s"] / k - 1.0}
    out["wall_s_per_simulated_s"] = float(np.mean([r["wall_s_per_simulated_s"] for r in out["runs"]]))
    if not a.no_closed_loop:
        out["closed_loop"] = closed_loop_section(system, a.loop_frequency, a.loop_amplitude, a.loop_cycles, a.loop_out)
    if not a.quick:
        out["segment_effect"] = segment_effect()
        out["incline"] = max_incline(a.record_frequency, a.amplitude, a.mu, a.segments)
    out["recording"] = a.out
    print(json.dumps(out, indent=1, default=float))


register(Robot("hamr-walk", summary(__doc__), build, main,
               {"body_position": body_position, "feet": feet,
                "roll_pitch": lambda s: np.array(roll_pitch(body_rotation(s), ground_rotation(s)))},
               ("hamr", "piezo", "transmission", "legged", "contact")))

if __name__ == "__main__":
    sys.exit(run_script(main))
