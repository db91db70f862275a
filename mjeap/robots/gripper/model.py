"""The PEDOT micro-gripper's model (:mod:`mjeap.robots.gripper`): its builder and read-out.

Scene (host in mm, mg, ms): a base on a vertical slide, raised by a position servo (a mocap
body moved by the script has no velocity, and friction, which MuJoCo imposes on velocities,
would not carry the bead), carries the two clamps; the fingers' faces stand GAP from a steel
bead (radius 0.75 mm, 13.9 mg) whose centre is A = 5 mm along them; the bead rests on a table
until the base lifts. Gravity is along the fingers' hinge axes, so the planar chains carry the
bead's weight by friction only (mu = 0.5, mjeap's contact default).

Soft-finger contact (an assumption, and why it is needed). A bent finger meets the bead
with its face tilted by its slope theta = y'(a) (3.1 deg at the lift threshold, 4-6 deg at
2 V): the two contact normals form a V and the line through the two contacts passes
R sin(theta) beside the bead's centre. Point contacts with Coulomb friction (MuJoCo's
condim 3, a "hard finger") resist no moment about that line, so the bead's weight rolls it
down between the fingers with both contacts sticking, at any grip force: two hard-finger
contacts are not force closure (grasping theory: Murray, Li & Sastry 1994, ch. 5). The
simulation shows it (``hard_finger``: the bead stays on the table and turns about the
gripping axis while the fingers rise past it, its contact points rolling up with them:
(turn) R sin(theta) = 1.05 x the fingers' rise, the 5 % slip at the contacts). Held beads
are held through contact patches, which resist that moment: MuJoCo's soft-finger contact
(condim 4) with a torsional friction of MU_TORSION = 0.1 mm, the moment per newton of
normal force of a patch of radius 16 mu_t / (3 pi mu) = 0.34 mm under Hertz pressure: a compliant fingertip,
not the film's own Hertz patch (about 1 um). Holding needs mu_t >= mu R sin(theta) (20 um at
the threshold, reported as measured); with 0.1 mm the moment takes 1-2 % of the elliptic
friction cone, so the closed form's 2 mu F >= m g stays the lift condition to that.
``impratio`` cuts the soft friction's creep in proportion (ContactParameters): under the
bead's weight 13 um/s with 10, 1.3 um/s with the 100 used here (measured).
"""
from __future__ import annotations

from dataclasses import replace

import mujoco
import numpy as np

from ...simulation.system import ContactParameters, System, attach

BEAD_RADIUS = 0.75e-3         # m
BEAD_DENSITY = 7850.0         # kg/m^3, steel
BEAD_MASS = BEAD_DENSITY * 4 / 3 * np.pi * BEAD_RADIUS**3     # kg, 13.9 mg
GAP = 0.05e-3                 # m, each finger's face to the bead
A = 5e-3                      # m, bead centre from the clamps
THICKNESS = 35e-6             # m, the finger (pedot-micro)
MU = ContactParameters().friction[0]   # sliding friction coefficient (mjeap's default)
MU_TORSION = 1e-4             # m, soft-finger torsional friction (assumption, see above)
CONTACT = replace(ContactParameters(), friction=(MU, MU_TORSION, ContactParameters().friction[2]), impratio=100.0)
BASE_MASS = 5e-3              # kg, the base on its slide (its weight compensated)
LIFT_SERVO_HZ = 10.0          # Hz, the slide's position servo (critically damped): it smooths
#                               the target, updated every sample (10 ms), into a ramp; the
#                               bead's weight sags it by m g / kp = 7 um
G = 9.80665


def build(soft_finger: bool = True) -> System:
    """The gripper as a System (host in mjeap's default units: mm, mg, ms); the bead's
    contacts are soft-finger (condim 4), or hard-finger (condim 3) for the check."""
    R, y = BEAD_RADIUS * 1e3, (BEAD_RADIUS + GAP + THICKNESS / 2) * 1e3
    host = mujoco.MjSpec.from_string(f"""<mujoco>
  <option gravity="0 0 {-G * 1e-3}"/>
  <worldbody>
    <body name="base" gravcomp="1">
      <joint name="lift" type="slide" axis="0 0 1"/>
      <inertial pos="0 0 0" mass="{BASE_MASS * 1e6}" diaginertia="1 1 1"/>
      <site name="left" pos="0 {-y} 0"/>
      <site name="right" pos="0 {y} 0" quat="0 1 0 0"/>
      <geom name="palm" type="box" size="0.3 {y + 0.3} 0.8" pos="-0.3 0 0" rgba="0.4 0.4 0.45 1"
            contype="0" conaffinity="0"/>
    </body>
    <geom name="table" type="box" size="10 10 0.1" pos="5 0 {-R - 0.1}" rgba="0.85 0.85 0.8 1"/>
    <body name="bead" pos="{A * 1e3} 0 0">
      <freejoint/>
      <geom name="bead" type="sphere" size="{R}" mass="{BEAD_MASS * 1e6}" condim="{4 if soft_finger else 3}"
            rgba="0.7 0.7 0.75 1"/>
    </body>
  </worldbody>
  <actuator><position name="lift" joint="lift" kp="{BASE_MASS * 1e6 * (2 * np.pi * LIFT_SERVO_HZ * 1e-3) ** 2}"
    dampratio="1"/></actuator>
</mujoco>""")
    fingers = [attach(host, "pedot-micro", site=s, prefix=s) for s in ("left", "right")]
    return System(host, fingers, contact=CONTACT)


def bead_position(system: System) -> np.ndarray:
    """The bead's centre in the world (m)."""
    return system.data.body("bead").xpos * system.units.length


#: the robot's read-outs (SI): name -> f(system)
READOUTS = {"bead_position": bead_position}
