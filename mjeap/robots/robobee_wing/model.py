"""The RoboBee wing's model (:mod:`mjeap.robots.robobee_wing`): its builder and read-out.

Model (host in mm, mg, ms):
- the actuator attached without contact (its own damping and timestep);
- the wing: a rigid plate on a stroke hinge, MuJoCo's ellipsoid fluid model in air
  (1.2 kg/m^3, 1.8e-5 Pa s);
- the transmission (mjeap.simulation.system.add_transmission): a tendon equality stroke = T_eff x the
  actuator's tip deflection linearised in its hinge angles, T_eff = 4000 rad/m (Jayaram et al. 2018,
  from its ref. [48]): the small-motion transmission the paper uses to turn the actuator's
  motion into a stroke angle.
- Wing: 15 mm long, 5 mm mean chord, 0.51 mg. Not in the seeds; taken from a secondary
  source, the Harvard Microrobotics Lab's public RoboBee wing models (github.com/avikde/
  robobee3d, flapopt/Wing2DOF.py: R = 15 mm, m_wing = 0.51 mg; flapopt/wingopt.py: mean
  chord 5 mm). The length agrees with Jayaram et al. 2018's 3.5 cm wingspan (two wings and a ~5 mm
  thorax). Drawn as a 15 x 5 mm plate; MuJoCo's ellipsoid model sees the inscribed
  ellipse (pi/4 of the plate's area). The resonance scales with 1/sqrt(wing inertia).
"""
from __future__ import annotations

import mujoco

from ...simulation.system import System, add_transmission, attach

T_EFF = 4000.0                                  # rad/m, Jayaram et al. 2018 section 6.1
SPAN, CHORD, THICKNESS = 15e-3, 5e-3, 20e-6     # m (length, mean chord: secondary source; thickness drawn)
WING_MASS = 0.51e-6                             # kg (secondary source, see the module text)
HINGE_OFFSET = 1e-3                             # m, wing root beyond the stroke axis (drawn)
AIR_DENSITY, AIR_VISCOSITY = 1.2, 1.8e-5        # kg/m^3, Pa s


def wing_inertia() -> float:
    """The wing's moment of inertia about the stroke axis (kg m^2): a plate of SPAN x CHORD
    whose root is HINGE_OFFSET from the axis."""
    return WING_MASS * (SPAN**2 / 12 + (HINGE_OFFSET + SPAN / 2) ** 2 + THICKNESS**2 / 12)


def build(bias: float = 200.0, air: bool = True) -> System:
    """The actuator (drive biased at ``bias``, V) and the wing as a System (host in mm, mg,
    ms); ``air=False`` leaves the fluid out. The stroke hinge sits 1/T_eff beyond the actuator's tip, so the transmission reads
    as a lever of that length from the tip; the wing spans on from the hinge."""
    spec = mujoco.MjSpec.from_string(f"""<mujoco>
  <option gravity="0 0 -9.80665e-3" density="{AIR_DENSITY * 1e-3 * air}" viscosity="{AIR_VISCOSITY * air}"/>
  <worldbody><site name="mount"/></worldbody>
</mujoco>""")
    act = attach(spec, "pzt-robobee", site="mount", prefix="act", contact=False, drive_params={"bias": bias})
    lay, u = act.twin.layout, act.twin.units
    s, c, t, o = (v / u.length for v in (SPAN, CHORD, THICKNESS, HINGE_OFFSET))
    lever = 1 / (T_EFF * u.length)
    wing = spec.worldbody.add_body(name="wing", pos=[lay.tip_x / u.length + lever, 0, 0])
    wing.add_joint(name="stroke", type=mujoco.mjtJoint.mjJNT_HINGE, axis=[0, 0, 1])
    wing.add_geom(name="lever", type=mujoco.mjtGeom.mjGEOM_CAPSULE, fromto=[-lever, 0, 0, o, 0, 0],
                  size=[0.05, 0, 0], mass=0, contype=0, conaffinity=0, rgba=[0.3, 0.3, 0.3, 1])
    wing.add_geom(name="wing", type=mujoco.mjtGeom.mjGEOM_BOX, size=[s / 2, t / 2, c / 2], pos=[o + s / 2, 0, 0],
                  mass=WING_MASS / u.mass, fluid_ellipsoid=1,
                  contype=0, conaffinity=0, rgba=[0.75, 0.8, 1, 0.6])
    # the lever: the tip moving +y turns the wing the negative way about z
    add_transmission(spec, act, "stroke", -T_EFF)
    return System(spec, [act])


def stroke_angle(system: System) -> float:
    """The wing's stroke angle (rad)."""
    return float(system.data.joint("stroke").qpos[0])


#: the robot's read-outs (SI): name -> f(system)
READOUTS = {"stroke_angle": stroke_angle}
