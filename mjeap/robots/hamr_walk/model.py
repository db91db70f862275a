"""The HAMR-VI walker's model (:mod:`mjeap.robots.hamr_walk`): its builder, its contact and
its read-outs.

Model (host in mm, mg, ms; gravity along -z; x forward, y left, z up):
- Body: a free body (freejoint), BODY_LENGTH = 45.1 mm long, the whole robot TOTAL_MASS =
  1.43 g (Jayaram et al. 2018: "a 4.51 cm long, 1.43 g quadrupedal microrobot"); width 15 mm and height
  4 mm ASSUMED; the body's own mass (a uniform box, 0.49 g) is what the eight actuators
  (0.48 g) and the four legs (0.46 g) leave.
- Legs: mjeap.robots.hamr_leg.add_leg with the single leg's design (hamr_leg.design():
  joint inertias that put the loaded actuators at the transmission resonances, 100 Hz swing
  and 80 Hz lift, zeta 0.05; T_swing = 13, T_lift = 12, Jayaram et al. 2018 from its ref. [51];
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
  rear legs' backward; ``contact=False`` (the beams lie inside the chassis). SEGMENTS = 4 per
  actuator: against 20, the single leg's foot gain moves by -0.05 % (swing) and -0.1 %
  (lift) at 20 Hz, -0.4 % and -1.7 % at 65 Hz (2 segments: -1.2 % and -3.6 % at 65 Hz;
  :func:`~mjeap.robots.hamr_walk.experiments.segment_effect`, on the single leg). Integrator
  'discrete' (INTEGRATOR): the feet's contact forces reach the beams through the
  transmissions, and under 'implicitfast' MuJoCo sizes contact impulses for M while the step
  integrates M + hD (see mjeap.simulation.system.attach): with it the robot never came to
  rest (:mod:`mjeap.robots.hamr_walk.experiments`). The step is then the discrete
  integrator's beta / 2 = 4.51 us (beta = 2 zeta_1 / omega_1, the actuator's first mode;
  10.4 us under implicitfast), 2-3 x the wall time.
- Ground contact: the feet (spheres of FOOT_RADIUS = 0.5 mm, ASSUMED), the chassis box and
  the legs' rods and shanks touch the ground plane (nothing else touches anything): a robot
  that rolls over lands on its chassis or legs. Coulomb friction MU = 0.51 (the value of
  Doshi's HAMR trot simulations; a parameter), elliptic cone, impratio 10. MuJoCo's soft
  contact sized from the robot's physics in :func:`contact_parameters`: time constant
  CONTACT_TIMECONST = 100 us (a landing penetrates as a Hertz contact of the 0.5 mm foot on a
  polymer or paper ground at the trot's landing speeds; v tau / e, 37 um per m/s), critically
  damped, solimp (0.99, 0.999, 50 um): at rest each foot sinks nanometres and creeps under
  the legs' splay (tested below 1 um/s). The solimp width, 0.1 x FOOT_RADIUS = 50 um, is the
  contact tolerance of the penetration checks.
- Travel: each actuator's tip deflection is held within +-ACTUATOR_RANGE = 0.3 mm (the range
  of the actuator joints in N. Doshi's HAMR-VI model, HAMR_scaledV2.urdf), a stop as stiff as
  the ground contact: the feet reach T x 0.3 mm = 3.9 mm (swing) and 3.6 mm (lift). The full
  drive moves them 3.5 and 3.2 mm quasi-statically, within it; near the transmissions'
  resonances (65 Hz: lift x 2.9, swing x 1.7) the free model swung the feet +-9.4 mm, which no
  HAMR transmission reaches.
- Solver: the constraint solver's tolerance SOLVER_TOLERANCE = 1e-12. At MuJoCo's 1e-8 the
  Newton solve of the 'discrete' step stopped with its contact forces off the motion it
  integrated: over every step of a 30 V, 20 Hz trot they read +5.9 % (1e-10: +0.08 %) against
  the robot's momentum; at 1e-12 they balance it within 2e-5 (1.6 -> 2.4 iterations a step).
- Read-outs of the contact: MuJoCo contact sensors ``<leg>/ground_force`` (the ground on each
  foot) and ``ground_force`` (on the whole robot), world frame, computed with each step's
  solve; :class:`GroundImpulses` adds them up at every step (:func:`metering`), so a walk
  reports each sample interval's impulse, not only the force at the sample's instant.
"""
from __future__ import annotations

from contextlib import contextmanager
from typing import Optional

import mujoco
import numpy as np

from ...errors import ParameterError, check_integer, check_range
from ...simulation.system import ContactParameters, System, attach
from ..hamr_leg.model import ACTUATOR, LEG_LENGTH, add_leg, design

TOTAL_MASS = 1.43e-3            # kg, Jayaram et al. 2018
PAPER_SPEED, PAPER_FREQUENCY = 0.5, 65.0      # m/s at Hz, Jayaram et al. 2018 ("approximately 0.5 m/s ... 65 Hz")
PAPER_INCLINE = 22.0                          # deg, Jayaram et al. 2018 ("inclines nearing 22 deg")
BODY_LENGTH = 45.1e-3           # m, Jayaram et al. 2018
BODY_WIDTH = 15e-3              # m, assumed
BODY_HEIGHT = 4e-3              # m, assumed
HIP_X = 14e-3                   # m, assumed (hips 28 mm apart fore-aft)
FOOT_DROP = 11.35e-3            # m, the foot below its leg frame in Doshi's HAMR model (see the module text)
FOOT_RADIUS = 0.5e-3            # m, assumed
MU = 0.51                       # sliding friction, as Doshi's HAMR trot simulations (see the module text)
CONTACT_WIDTH_FRACTION = 0.1    # solimp width as a fraction of FOOT_RADIUS: the penetration tolerance
IMPRATIO = 10.0                 # the friction rows' regulariser / 10: a sticking foot creeps 10 x less
#: s, the feet's contact time constant: a landing of the foot (about 0.1 g effective) penetrates
#: as a Hertz contact of its 0.5 mm sphere on a polymer or paper ground (E* 0.5-1 GPa) at the
#: trot's landing speeds, 0.2-1 m/s (contact_parameters)
CONTACT_TIMECONST = 100e-6
#: the same in the actuators' own steps (4.51 us at 4 segments)
CONTACT_STEPS = 22.0
#: the actuators' integrator: the feet's contact forces reach the beams through the
#: transmissions, and 'implicitfast' sizes them for M alone (the feet chatter at rest)
INTEGRATOR = "discrete"
BIAS = 200.0                    # V, HAMR's drive bias (the brief's "paper's 200 V")
#: m, each actuator's tip travel either way: the range of HAMR-VI's actuator joints in N. Doshi's
#: model (HAMR_scaledV2.urdf, its prismatic joints FLqsact ... RRqlact, limits +-0.3 mm); the
#: feet's stroke T x 0.3 mm = 3.9 mm (swing) and 3.6 mm (lift) is the transmissions' reach
ACTUATOR_RANGE = 0.3e-3
#: the constraint solver's tolerance: at MuJoCo's 1e-8 the Newton solve of the 'discrete' step
#: stops before its contact forces match the motion (the walker's read +5.9 % against its
#: momentum at 30 V, 20 Hz; 1e-10: +0.08 %; 1e-12: 0.000 %, 1.6 -> 2.4 iterations a step)
SOLVER_TOLERANCE = 1e-12
SEGMENTS = 4
FREQUENCY_RANGE = (1.0, 100.0)                # Hz, the trot frequencies the contact is sized for
#: MuJoCo's contact sensor parameters: data 'force' (bit 1), reduce 'netforce' (3), one result
CONTACT_SENSOR = [2, 3, 1]
#: leg name -> (fore +1 / aft -1, side +1 left / -1 right, trot phase of its pair)
LEGS = {"FL": (1, 1, 0.0), "FR": (1, -1, np.pi), "RL": (-1, 1, np.pi), "RR": (-1, -1, 0.0)}


def build(mu: float = MU, segments: int = SEGMENTS, *, bias: float = BIAS, incline_deg: float = 0.0,
          d: Optional[dict] = None, armature_fraction: float = 0.0, foot_drop: float = FOOT_DROP,
          body_width: float = BODY_WIDTH, timeconst_steps: Optional[float] = None,
          upside_down: bool = False, integrator: str = INTEGRATOR, actuator_range: float = ACTUATOR_RANGE,
          timestep: Optional[float] = None) -> System:
    """The robot as a System (host in mm, mg, ms) standing on a ground plane tilted by
    ``incline_deg`` about y (uphill along +x); ``d``: hamr_leg.design() (computed if None).

    For the roll-over study (mjeap.robots.hamr_walk.study), each a model parameter whose
    true value is not published: ``armature_fraction`` of each leg joint's design inertia
    is carried as joint armature (a rotor on the joint: it enters that joint's own inertia
    only, so the transmission resonances stay, but it exchanges no momentum with the body)
    instead of by the leg's moving masses, whose masses scale by 1 - armature_fraction (the
    body's own mass takes up the rest: the robot still weighs TOTAL_MASS); ``foot_drop`` (m):
    the foot below the leg rod's end (its lateral motion per radian of lift); ``body_width``
    (m): the chassis width, the hips at its sides; ``timeconst_steps``: the contact's time
    constant in the actuators' own steps (None: CONTACT_TIMECONST, see :func:`contact_parameters`).
    ``upside_down``: the body starts turned 180 degrees about x, its chassis 20 um above the
    ground (the rolled-over robot). ``integrator``: the actuators' ('discrete', INTEGRATOR:
    the feet's contacts reach the beams through the transmissions, see the module text).
    ``actuator_range`` (m): each actuator's tip travel either way (ACTUATOR_RANGE, a stop as
    stiff as the ground contact). ``timestep`` (s): None, the actuators' own step (beta / 2 of
    the free beam, 4.51 us at 4 segments); a larger one is sized for the loaded system
    (:func:`loaded_timestep`, System's ``loaded``): the contact keeps its time constant in
    seconds (at least 2 steps, MuJoCo's floor) and the legs' joint damping gives back what the
    step's own damping h K adds to the transmissions' modes (:func:`leg_damping_at_step`)."""
    mu = check_range("mu", mu, 0.0, 10.0)
    segments = check_integer("segments", segments, 1, 40)
    incline = np.radians(check_range("incline_deg", incline_deg, -45.0, 45.0, "deg"))
    armature_fraction = check_range("armature_fraction", armature_fraction, 0.0, 1.0, hi_open=True)
    foot_drop = check_range("foot_drop", foot_drop, 0.0, 0.05, "m")
    body_width = check_range("body_width", body_width, 6e-3, 0.1, "m")
    if timeconst_steps is not None:
        timeconst_steps = check_range("timeconst_steps", timeconst_steps, 2.0, 100.0)
    if integrator not in ("discrete", "implicitfast"):
        raise ParameterError("integrator", integrator, "'discrete' or 'implicitfast'")
    d = design() if d is None else d
    actuator_range = check_range("actuator_range", actuator_range, 0.0, 1e-3, "m", lo_open=True)
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
    q_body = np.array(q_ground)
    if upside_down:             # turned about x: the chassis (its top down) 20 um above the ground
        hip_height = H + 0.02
        mujoco.mju_mulQuat(q_body, np.array(q_ground), np.array([0.0, 1.0, 0.0, 0.0]))
    body = wb.add_body(name="body", pos=(R_ground.reshape(3, 3) @ [0, 0, hip_height]).tolist(), quat=q_body.tolist())
    body.add_freejoint(name="root")
    # the chassis touches the ground (contype 1; the ground's conaffinity 1), nothing else: a
    # robot that rolls over lands on it
    box = body.add_geom(name="chassis", type=mujoco.mjtGeom.mjGEOM_BOX, size=[L / 2, W / 2, H / 2], pos=[0, 0, H / 2],
                        mass=TOTAL_MASS * 1e6 / 2, rgba=[0.25, 0.3, 0.4, 0.5], contype=1, conaffinity=0,
                        condim=3)
    acts = {}
    for leg, (fore, side, _) in LEGS.items():
        for k, dof in enumerate(("swing", "lift")):
            # clamps 2 mm either side of the middle, the beams running toward their hips
            site = body.add_site(name=f"{leg}_{dof}_mount", pos=[fore * 2.0, side * (2.5 + 3.0 * k), H - 1.0 - 2.0 * k],
                                 quat=[1, 0, 0, 0] if fore > 0 else [0, 0, 0, 1])
            acts[f"{leg}_{dof}"] = attach(spec, ACTUATOR, site=site.name, prefix=f"{leg}_{dof}", contact=False,
                                          drive_params={"bias": bias}, segments=segments, integrator=integrator)
    for leg, (fore, side, _) in LEGS.items():
        add_leg(spec, body, {dof: acts[f"{leg}_{dof}"] for dof in ("swing", "lift")}, d, prefix=f"{leg}/",
                pos=[fore * HIP_X * mm, side * W / 2, 0.0], side=side, mass_radius=LEG_LENGTH * mm,
                foot_drop=foot_drop * mm, foot_radius=FOOT_RADIUS * mm, foot_contact=True)
        # the leg rod and the shank touch the ground too (a robot on its side lies on them)
        for part in ("leg", "shank"):
            g = spec.geom(f"{leg}/{part}")
            if g is not None:
                g.contype, g.conaffinity, g.condim = 1, 0, 3
        if armature_fraction:
            u0 = acts[f"{leg}_swing"].twin.units
            for dof in ("swing", "lift"):
                full = d[dof]["joint_inertia_kg_m2"] / (1.0 - armature_fraction)
                spec.joint(f"{leg}/{dof}").armature = armature_fraction * full / (u0.mass * u0.length**2)
    # each actuator's travel: its tip deflection (the transmission's tendon) within +-actuator_range
    for a in acts.values():
        t = spec.tendon(a.name("tip_deflection"))
        t.limited = mujoco.mjtLimited.mjLIMITED_TRUE
        t.range = [-actuator_range * mm, actuator_range * mm]
    # the ground's contact force on each foot and on the whole robot (MuJoCo's contact sensors:
    # the net force of the matching contacts, world frame; computed with every step's solve)
    for leg in LEGS:
        spec.add_sensor(name=f"{leg}/ground_force", type=mujoco.mjtSensor.mjSENS_CONTACT,
                        objtype=mujoco.mjtObj.mjOBJ_GEOM, objname="ground", reftype=mujoco.mjtObj.mjOBJ_GEOM,
                        refname=f"{leg}/foot", intprm=CONTACT_SENSOR)
    spec.add_sensor(name="ground_force", type=mujoco.mjtSensor.mjSENS_CONTACT, objtype=mujoco.mjtObj.mjOBJ_GEOM,
                    objname="ground", reftype=mujoco.mjtObj.mjOBJ_XBODY, refname="body", intprm=CONTACT_SENSOR)
    # the body's own mass: what the actuators and legs leave of TOTAL_MASS
    m = spec.copy().compile()
    bid = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, "body")
    others = m.body_subtreemass[bid] - box.mass
    own = TOTAL_MASS * 1e6 - others
    if own <= 0:
        raise ParameterError("TOTAL_MASS", TOTAL_MASS, f"more than the actuators and legs ({others * 1e-6:.4g} kg)")
    box.mass = own
    return _system(spec, list(acts.values()), d, mu, timeconst_steps, timestep)


def _system(spec: mujoco.MjSpec, acts_list: list, d: dict, mu: float, timeconst_steps: Optional[float],
            timestep: Optional[float]) -> System:
    """The walker's System from its spec (:func:`build`): the ground contact, the travel stops
    and the solver's tolerance, at the actuators' own step or at ``timestep`` sized for the
    loaded system (the legs' joint damping less the step's own)."""
    u = acts_list[0].twin.units
    h0 = min(a.twin.timestep for a in acts_list)         # the actuators' own step: the contact is sized on it
    h = h0 if timestep is None else check_range("timestep", timestep, 0.0, MAX_TIMESTEP, "s", lo_open=True)
    tau = CONTACT_TIMECONST if timeconst_steps is None else timeconst_steps * h0
    tau = max(tau, 2.0 * h)                                # s: the contact's time constant, MuJoCo's floor 2 h
    contact = contact_parameters(h, mu, tau / h)
    # System applies contact parameters only for actuators with contact: here the feet's
    contact.apply(spec, h / u.time, FOOT_RADIUS / u.length, u.length)
    spec.option.tolerance = SOLVER_TOLERANCE
    for a in acts_list:             # the stops as stiff as the ground contact (its time constant)
        spec.tendon(a.name("tip_deflection")).solref_limit = [tau / u.time, 1.0]
    if timestep is None:
        return System(spec, acts_list, contact=contact)
    beta = acts_list[0].twin.choice.rayleigh_beta
    for leg in LEGS:                # the step damps the transmissions by h K: the legs carry the rest of ZETA
        for dof, c in leg_damping_at_step(d, h, beta).items():
            spec.joint(f"{leg}/{dof}").damping = [c / (u.mass * u.length ** 2 / u.time), 0.0, 0.0]
    return System(spec, acts_list, timestep=h, contact=contact, loaded=True)


#: s, the largest step :func:`build` takes: 1/50 of the period of the fastest transmission mode (100 Hz)
MAX_TIMESTEP = 2e-4


def leg_damping_at_step(d: dict, h: float, beta: float) -> dict:
    """Per degree of freedom the leg joint's damping (N m s) that keeps each transmission mode
    at hamr_leg.ZETA when the system steps at ``h`` (s): under 'discrete' the beam's hinges are
    damped by max(beta, h) K (their Rayleigh beta, or the step's own h K where that is larger),
    which damps the loaded mode at omega by max(beta, h) omega / 2; the joint carries the rest,
    2 (ZETA - max(beta, h) omega / 2) omega I (hamr_leg.design: the same with beta)."""
    from ..hamr_leg.model import DOFS, ZETA
    out = {}
    for dof, tr in DOFS.items():
        w = 2 * np.pi * tr.resonance
        share = 0.5 * max(beta, h) * w
        if share >= ZETA:
            raise ParameterError("timestep", h, f"a step whose own damping h omega / 2 stays below ZETA = {ZETA:g} "
                                 f"at the {dof} resonance ({tr.resonance:g} Hz): h < {2 * ZETA / w:.3g} s")
        out[dof] = 2 * (ZETA - share) * w * d[dof]["joint_inertia_kg_m2"]
    return out


def contact_parameters(h: float, mu: float = MU, timeconst_steps: Optional[float] = None) -> ContactParameters:
    """The feet's (and the chassis's) contact with the ground for a timestep ``h`` (s), sized
    from the robot's physics (:func:`contact_sizing` gives its numbers for a built robot;
    ``timeconst_steps`` other than None, the time constant in steps of ``h``, are for studies,
    hamr_walk.study.contact_study).

    solref = (tau, 1), tau = CONTACT_TIMECONST = 100 us, critically damped: a landing foot does
    not rebound off the contact itself (its penetration obeys r'' + 2 r' / tau + r / tau^2 = 0)
    and penetrates at most v tau / e, 37 um per m/s. Sized from the foot's real contact: a
    sphere of FOOT_RADIUS with the foot's effective mass (about 0.1 g: a dropped robot's feet
    stop 0.094 g each) landing at v on a surface of reduced modulus E* penetrates (Hertz)
    (15 m v^2 / (16 E* sqrt(R)))^(2/5): on a polymer or paper ground (E* 0.5-1 GPa) at the
    trot's landing speeds (0.2-1 m/s) 8-36 um, the depth of a critically damped contact of
    tau = 75-135 us (E* 3 GPa: 48-66 us). The window it keeps: at least 2 steps (MuJoCo's
    floor; 22 at the actuators' own 4.51 us, 2 at a 50 us step sized for the loaded system)
    and 5 tau = 0.5 ms, 7 % of the 65 Hz trot's half cycle; a landing within the solimp width
    (the contact tolerance, 50 um = 0.1 x the foot radius) up to 1.4 m/s.
    solimp (dmin 0.99, dmax 0.999, width 50 um): at rest a foot carrying a quarter of the
    weight (3.5 mN) on its effective mass (156 mg, MuJoCo's diagonal of the contact's
    inverse inertia) sinks (1 - d) / d^2 x tau^2 F / m = 2.3 nm. Friction: mu, elliptic cone,
    impratio IMPRATIO: a sticking foot under a tangential force f creeps at about
    (1 - d) / d x (f / m) x dmax tau / (2 impratio) (the legs splay under the weight, 0.21 of
    it sideways on each foot; impratio 1 would make it 10 x more). MuJoCo's convex contact
    starts a slip only with some motion along the normal: a sliding contact is pushed apart
    (hamr_walk.study.sliding_contact)."""
    steps = CONTACT_TIMECONST / h if timeconst_steps is None else timeconst_steps
    steps = check_range("timeconst_steps", steps, 2.0, 100.0)
    return ContactParameters(friction=(mu, 5e-6, 1e-7), impratio=IMPRATIO, width_fraction=CONTACT_WIDTH_FRACTION,
                             timeconst_steps=steps)


def contact_sizing(system: System) -> dict:
    """The numbers behind :func:`contact_parameters` for a built ``system`` (SI): the step,
    the time constant (s and steps), 5 tau against the shortest stance (half a cycle at
    FREQUENCY_RANGE's top), the penetration per m/s of landing speed (tau / e) against the
    contact tolerance, and the landing speed at which they meet."""
    o = system.model.opt
    u = system.units
    tau = float(o.o_solref[0]) * u.time
    stance = 0.5 / FREQUENCY_RANGE[1]
    tol = CONTACT_WIDTH_FRACTION * FOOT_RADIUS
    return {"timestep_s": system.timestep, "timeconst_s": tau, "timeconst_steps": tau / system.timestep,
            "dampratio": float(o.o_solref[1]), "solimp": [float(x) for x in o.o_solimp[:3]] + [float(o.o_solimp[3]),
                                                                                             float(o.o_solimp[4])],
            "shortest_stance_s": stance, "settling_5tau_over_stance": 5 * tau / stance,
            "landing_penetration_m_per_m_s": tau / np.e, "contact_tolerance_m": tol,
            "landing_speed_at_tolerance_m_s": tol * np.e / tau, "impratio": float(o.impratio)}


def body_position(system: System) -> np.ndarray:
    """The body's world position (m)."""
    return system.data.body("body").xpos * system.units.length


def body_rotation(system: System) -> np.ndarray:
    """The body's world rotation (3 x 3)."""
    return system.data.body("body").xmat.reshape(3, 3).copy()


def feet(system: System) -> np.ndarray:
    """The four feet's world positions (m), in LEGS order."""
    return np.array([system.data.site(f"{leg}/foot").xpos for leg in LEGS]) * system.units.length


def foot_forces(system: System, foot_geoms: Optional[list] = None) -> np.ndarray:
    """The ground's contact force on each foot (N, world frame, (4, 3) in LEGS order) at the
    present state, as the step's constraint solve found it (mj_contactForce); ``foot_geoms``:
    the feet's geom ids (looked up if None)."""
    m, d = system.model, system.data
    fid = foot_geoms if foot_geoms is not None else \
        [mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, f"{leg}/foot") for leg in LEGS]
    ground = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, "ground")
    out = np.zeros((len(fid), 3))
    f6 = np.zeros(6)
    for i in range(d.ncon):
        c = d.contact[i]
        if ground not in (c.geom1, c.geom2):
            continue
        other, sign = (c.geom2, 1.0) if c.geom1 == ground else (c.geom1, -1.0)
        if other in fid:
            mujoco.mj_contactForce(m, d, i, f6)
            out[fid.index(other)] += sign * (c.frame.reshape(3, 3).T @ f6[:3])     # geom1 on geom2, world
    return out * system.units.force


def ground_force(system: System) -> np.ndarray:
    """The ground's total contact force on the robot (N, world frame) at the present state:
    its feet, and its chassis or legs where they touch (mj_contactForce)."""
    m, d = system.model, system.data
    ground = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, "ground")
    out = np.zeros(3)
    f6 = np.zeros(6)
    for i in range(d.ncon):
        c = d.contact[i]
        if ground in (c.geom1, c.geom2):
            mujoco.mj_contactForce(m, d, i, f6)
            out += (1.0 if c.geom1 == ground else -1.0) * (c.frame.reshape(3, 3).T @ f6[:3])
    return out * system.units.force


class GroundImpulses:
    """The ground's contact impulses on the robot added up step by step (N s, world): on each
    foot (LEGS order) and in all (feet, chassis, legs); per foot the steps it carried load
    (a positive normal force) and the steps its load began (touch-downs at the step's
    resolution). :func:`metering` has MuJoCo call it at every step: it reads the contact
    sensors of the step just taken (before the next solve replaces them; each step once, an
    mj_forward at a state already counted is skipped). :meth:`take`
    returns what was added since the last take. A foot's load in MuJoCo's time-stepping can
    change from one step to the next (a sliding contact is pushed apart between steps,
    :func:`mjeap.robots.hamr_walk.study.sliding_contact`): its impulse over an interval is
    the load carried in it, where one step's force is not."""

    def __init__(self, system: System):
        m = system.model
        self.system = system
        names = [f"{leg}/ground_force" for leg in LEGS] + ["ground_force"]
        adr = [int(m.sensor_adr[m.sensor(name).id]) for name in names]
        self._idx = (np.array(adr)[:, None] + np.arange(3)).ravel()           # the feet's, then the total
        mujoco.mj_kinematics(m, system.data)
        self._normal = ground_rotation(system)[:, 2]
        self._scale = m.opt.timestep * system.units.time * system.units.force       # internal force x step -> N s
        self._t_last, self._armed = -np.inf, False
        self._was_loaded = np.zeros(len(LEGS), dtype=bool)
        self.reset()

    def reset(self) -> None:
        """Start the sums again."""
        self._sum = np.zeros(3 * len(LEGS) + 3)
        self.loaded_steps = np.zeros(len(LEGS), dtype=int)
        self.onsets = np.zeros(len(LEGS), dtype=int)
        self.steps = 0

    def step_hook(self, data) -> None:
        """MuJoCo's control callback for this system's data (:func:`metering`): before each
        step's (or mj_forward's) own solve, the forces of the last solve are the step just
        taken. A state already counted (the same time) is skipped; an earlier one (a reset)
        starts the sums again."""
        t = data.time
        if t < self._t_last:
            self.reset()
            self._armed, self._was_loaded[:] = False, False
        elif t == self._t_last:
            return
        self._t_last = t
        if self._armed:
            self.add()
        self._armed = True

    def add(self) -> None:
        """Add the impulse of the step just taken: the last solve's contact forces (the
        sensors ``<leg>/ground_force`` and ``ground_force``) times the step."""
        v = self.system.data.sensordata[self._idx]
        self._sum += v
        loaded = v[:-3].reshape(-1, 3) @ self._normal > 0
        self.loaded_steps += loaded
        self.onsets += loaded > self._was_loaded
        self._was_loaded = loaded
        self.steps += 1

    def take(self) -> dict:
        """What was added since the last take: the impulses (N s), the steps, and per foot the
        steps it carried load and the touch-downs; then starts again."""
        out = {"foot": self._sum[:-3].reshape(-1, 3) * self._scale, "total": self._sum[-3:] * self._scale,
               "steps": self.steps,
               "loaded_steps": self.loaded_steps.copy(), "onsets": self.onsets.copy()}
        self.reset()
        return out


@contextmanager
def metering(meter: GroundImpulses):
    """While inside, MuJoCo calls ``meter`` (:meth:`GroundImpulses.step_hook`) at every step
    of its system (through its process-wide control callback, mjcb_control; a callback set
    before is chained for other data and set back on leaving). One metered run at a time."""
    before = mujoco.get_mjcb_control()
    data = meter.system.data

    def hook(m, d):
        if d is data:
            meter.step_hook(d)
        elif before is not None:
            before(m, d)
    mujoco.set_mjcb_control(hook)
    try:
        yield meter
    finally:
        mujoco.set_mjcb_control(before)


def ground_rotation(system: System) -> np.ndarray:
    """The ground plane's world rotation: its x uphill (forward), z its normal."""
    return system.data.geom("ground").xmat.reshape(3, 3).copy()


def clearances(system: System) -> tuple:
    """The lowest point (m) above the ground plane of the chassis (its box's corners) and of
    the legs (their rods' and shanks' capsules): negative where it is below the ground."""
    m, d = system.model, system.data
    g = d.geom("ground")
    up, origin = g.xmat.reshape(3, 3)[:, 2], g.xpos
    c = d.geom("chassis")
    size = m.geom("chassis").size
    corners = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]) * size
    chassis = float(((c.xpos + corners @ c.xmat.reshape(3, 3).T - origin) @ up).min())
    legs = np.inf
    for leg in LEGS:
        for part in ("leg", "shank"):
            gid = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, f"{leg}/{part}")
            if gid < 0:
                continue
            r, half = m.geom_size[gid, 0], m.geom_size[gid, 1]
            axis = d.geom_xmat[gid].reshape(3, 3)[:, 2]
            ends = d.geom_xpos[gid] + np.outer([-half, half], axis)
            legs = min(legs, float(((ends - origin) @ up).min() - r))
    u = system.units.length
    return chassis * u, legs * u


def roll_pitch(R: np.ndarray, G: np.ndarray) -> tuple:
    """Roll and pitch (rad) of a body rotation ``R`` relative to the ground's ``G``."""
    Rr = G.T @ R
    return float(np.arctan2(Rr[2, 1], Rr[2, 2])), float(np.arcsin(np.clip(-Rr[2, 0], -1, 1)))


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
            "cited": {"total mass, body length, 0.5 m/s at 65 Hz, 22 deg": "Jayaram et al. 2018 section 6.2 (Jayaram 2018)",
                      "T_swing 13, T_lift 12, resonances 100 / 80 Hz": "Jayaram et al. 2018 section 6.2 (its refs [51], [19])",
                      "foot 11.35 mm below its leg frame, mu 0.51, drive ramped over 2 cycles":
                          "N. Doshi's HAMR Drake simulation scripts (HamrRBM FOOT_POS, trot sweeps MU)"},
            "assumed": ["body width and height", "hip spacing", "leg length (hamr_leg)", "foot radius",
                        "the legs' mass radius (= leg length)",
                        "contact: MuJoCo soft, elliptic cone, impratio 10, sized by contact_parameters"]}


#: the robot's read-outs (SI): name -> f(system)
READOUTS = {"body_position": body_position, "feet": feet,
            "roll_pitch": lambda s: np.array(roll_pitch(body_rotation(s), ground_rotation(s)))}
