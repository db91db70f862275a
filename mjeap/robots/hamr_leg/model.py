"""The HAMR single leg's model (:mod:`mjeap.robots.hamr_leg`): its design, builder and
read-out.

Model (host in mm, mg, ms; gravity along -z):
- The hip at the origin; the leg a rigid rod of LEG_LENGTH along +y (lateral). The swing
  hinge (axis z) carries a swing stage; on it the lift hinge (axis x, turning with the
  stage) carries the leg and the lift lever. Swing moves the foot fore-aft (x), lift up and
  down (z): the foot's position is the 3D kinematics of these joints.
- Each transmission (mjeap.simulation.system.add_transmission): a tendon equality that turns the leg
  joint by T d / LEG_LENGTH, d the actuator's tip deflection linearised in its hinge angles,
  so that the foot moves T x the tip for small motion (T_swing = 13, T_lift = 12, Jayaram et al. 2018
  from its ref. [51]).
- Inertia: for each degree of freedom, the tip mass that puts the loaded actuator's first
  mode at the paper's transmission resonance (100 Hz swing, 80 Hz lift: the point-mass leg
  of mjeap.controllers.hamr_leg, scipy brentq on the scene's modes) is reflected to the joint,
  I = m (LEG_LENGTH / T)^2. The leg rod carries LEG_SHARE of the smaller of the two; the
  swing stage (about z only) and the lift lever (about x only) carry the rest of each.
- Damping: each leg joint damps its transmission mode to ZETA (less the actuator's own
  stiffness-proportional share at that frequency, zeta_act f / f_free), as the point-mass
  scene's damping is set on its loaded mode.
- LEG_LENGTH = 10 mm is ASSUMED (a quarter of HAMR-VI's 4.51 cm body, Jayaram et al. 2018); with the
  ratios fixed it sets only the joint angles, i.e. the kinematic nonlinearity.
"""
from __future__ import annotations

from typing import Optional

import mujoco
import numpy as np

from ...controllers.hamr_leg import LIFT, SWING, leg_scene
from ...simulation.scene import DEFAULT_SEGMENTS, Scene
from ...simulation.system import System, add_transmission, attach

ACTUATOR = "pzt-hamr-small"
LEG_LENGTH = 10e-3            # m, assumed (see the module text)
LEG_SHARE = 0.8               # of the smaller joint inertia carried by the leg rod
ZETA = 0.05                   # damping ratio of each transmission mode, as the point-mass leg's
BIAS = 100.0                  # V
DOFS = {"swing": SWING, "lift": LIFT}
AXES = {"swing": (0.0, 0.0, 1.0), "lift": (1.0, 0.0, 0.0)}
FOOT_COORD = {"swing": 0, "lift": 2}                  # foot x (fore-aft), z (normal)


def design() -> dict:
    """Per degree of freedom: the reflected tip mass (kg) that puts the loaded actuator at
    its resonance, the joint inertia (kg m^2) it needs, and the joint damping (N m s)."""
    out = {}
    for name, tr in DOFS.items():
        sc = leg_scene(tr)
        m = sc.payload.mass
        inertia = m * (LEG_LENGTH / tr.ratio) ** 2
        free = Scene(sc.actuator, gravity=False)
        zeta_act = free.choice.damping_ratio * tr.resonance / free.choice.first_frequency
        damping = 2 * (ZETA - zeta_act) * 2 * np.pi * tr.resonance * inertia
        out[name] = {"reflected_mass_kg": m, "joint_inertia_kg_m2": inertia, "joint_damping_N_m_s": damping,
                     "zeta_actuator_share": zeta_act, "point_mass_resonance_hz": sc.choice.first_frequency}
    return out


def build(d: Optional[dict] = None, bias: float = BIAS, segments: int = DEFAULT_SEGMENTS) -> System:
    """The leg system (host in mm, mg, ms) from :func:`design` (computed when ``d`` is None);
    ``segments`` per actuator (:func:`mjeap.simulation.system.attach`)."""
    d = design() if d is None else d
    spec = mujoco.MjSpec.from_string('<mujoco><option gravity="0 0 -9.80665e-3"/><worldbody/></mujoco>')
    wb = spec.worldbody
    acts = {}
    for k, (name, z) in enumerate((("swing", 0.0), ("lift", -4.0))):
        site = wb.add_site(name=f"{name}_mount", pos=[-14.0, -3.0 - 3.0 * k, z])
        acts[name] = attach(spec, ACTUATOR, site=site.name, prefix=name, contact=False, drive_params={"bias": bias},
                            segments=segments)
    add_leg(spec, wb, acts, d)
    return System(spec, [acts["swing"], acts["lift"]])


def add_leg(spec: mujoco.MjSpec, parent, acts: dict, d: dict, *, prefix: str = "", pos=(0.0, 0.0, 0.0),
            side: float = 1.0, mass_radius: float = 2.0, foot_drop: float = 0.0, foot_radius: float = 0.5,
            foot_contact: bool = False):
    """One leg on ``parent`` (a body of ``spec``) at its hip ``pos`` (internal units), driven
    by ``acts`` ({'swing': ..., 'lift': ...}, attached actuators) through their
    transmissions, with the joint inertias and damping of ``d`` (:func:`design`). Names are
    ``prefix`` + swing_stage, swing, leg, lift, lift_lever, foot (site and geom).

    ``side``: +1, the leg along +y (as :func:`build`), or -1, mirrored along -y; the
    transmission signs follow, so that on either side a positive tip deflection moves the
    foot +x (swing) and +z (lift). ``mass_radius`` (internal length): the radius at which
    the stage's and the lever's masses sit (their masses are inertia / radius^2, so a larger
    radius carries the same inertia with less mass). ``foot_drop``: the foot hangs this far
    below the end of the leg rod on a massless shank, which leaves the foot's fore-aft (swing)
    and normal (lift) motion per joint angle unchanged (adds a lateral one of foot_drop per
    radian of lift). ``foot_contact``: the foot's sphere (``foot_radius``) touches geoms
    with conaffinity 1 (condim 3); it never touches another foot. Returns the leg body."""
    u = acts["swing"].twin.units
    to_I = u.mass * u.length**2
    ell = LEG_LENGTH / u.length
    y = side * ell
    I_s, I_l = (d[n]["joint_inertia_kg_m2"] / to_I for n in ("swing", "lift"))
    I_leg = LEG_SHARE * min(I_s, I_l)
    m_leg = 3 * I_leg / ell**2                                 # a thin rod about its end
    r = mass_radius                                            # the stage's and the lever's mass radius
    stage = parent.add_body(name=f"{prefix}swing_stage", pos=list(pos))
    stage.add_joint(name=f"{prefix}swing", type=mujoco.mjtJoint.mjJNT_HINGE, axis=AXES["swing"],
                    damping=d["swing"]["joint_damping_N_m_s"] / (to_I / u.time))
    # the stage turns about z only: a disc's inertia (its x and y values meet no joint)
    stage.add_geom(name=f"{prefix}stage", type=mujoco.mjtGeom.mjGEOM_CYLINDER, size=[1.0, 0.2, 0], mass=0,
                   rgba=[0.6, 0.6, 0.65, 1], contype=0, conaffinity=0)
    stage.mass, stage.inertia = 2 * (I_s - I_leg) / r**2, [(I_s - I_leg) / 2, (I_s - I_leg) / 2, I_s - I_leg]
    # its centre of mass on the swing axis, stated: left unset, MuJoCo's compiler puts an
    # explicit inertial at the body's pos again (the hip's offset twice: at HAMR-VI's hips
    # that doubled the swing joint's inertia and swung 8 mg on a 16 mm eccentric)
    stage.ipos, stage.explicitinertial = [0, 0, 0], True
    leg = stage.add_body(name=f"{prefix}leg")
    leg.add_joint(name=f"{prefix}lift", type=mujoco.mjtJoint.mjJNT_HINGE, axis=AXES["lift"],
                  damping=d["lift"]["joint_damping_N_m_s"] / (to_I / u.time))
    leg.add_geom(name=f"{prefix}leg", type=mujoco.mjtGeom.mjGEOM_CAPSULE, fromto=[0, 0, 0, 0, y, 0], size=[0.25, 0, 0],
                 mass=0, rgba=[0.85, 0.65, 0.3, 1], contype=0, conaffinity=0)
    # a thin rod's inertia, stated (a capsule's caps would add 1.7 % about the hip)
    leg.mass, leg.ipos, leg.explicitinertial = m_leg, [0, y / 2, 0], True
    leg.inertia = [m_leg * ell**2 / 12, 1e-6 * m_leg * ell**2, m_leg * ell**2 / 12]
    # the lift lever: a rod along z centred on the lift axis, inertia about x (and y, which
    # no joint sees), none about z, so the swing does not see it
    lever = leg.add_body(name=f"{prefix}lift_lever")
    lever.add_geom(name=f"{prefix}lever", type=mujoco.mjtGeom.mjGEOM_CAPSULE, fromto=[0, 0, 1.5, 0, 0, -1.5],
                   size=[0.2, 0, 0], mass=0, rgba=[0.6, 0.6, 0.65, 1], contype=0, conaffinity=0)
    lever.mass, lever.inertia = 3 * (I_l - I_leg) / r**2, [I_l - I_leg, I_l - I_leg, 1e-6 * (I_l - I_leg)]
    lever.ipos, lever.explicitinertial = [0, 0, 0], True
    foot = [0, y, -foot_drop]
    if foot_drop:
        leg.add_geom(name=f"{prefix}shank", type=mujoco.mjtGeom.mjGEOM_CAPSULE, fromto=[0, y, 0, *foot],
                     size=[0.2, 0, 0], mass=0, rgba=[0.85, 0.65, 0.3, 1], contype=0, conaffinity=0)
    leg.add_site(name=f"{prefix}foot", pos=foot)
    leg.add_geom(name=f"{prefix}foot", type=mujoco.mjtGeom.mjGEOM_SPHERE, size=[foot_radius, 0, 0], pos=foot, mass=0,
                 rgba=[0.9, 0.3, 0.2, 1], contype=int(foot_contact), conaffinity=0, condim=3)
    # transmissions: joint angle = sign x T d / LEG_LENGTH, the foot moving +T d along x / z
    # (about z a +y leg moves its foot -x; about x, +z; a -y leg the other way)
    sign = {"swing": -side, "lift": side}
    for name, tr in DOFS.items():
        add_transmission(spec, acts[name], f"{prefix}{name}", sign[name] * tr.ratio / LEG_LENGTH)
    return leg


def foot(system: System) -> np.ndarray:
    """The foot's world position (m)."""
    return system.data.site("foot").xpos * system.units.length


#: the robot's read-outs (SI): name -> f(system)
READOUTS = {"foot": foot}
