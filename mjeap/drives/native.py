"""Drives compiled into MJCF ("native" drives): the model moves in plain MuJoCo.

A native drive is built from MuJoCo elements only, so the generated file runs in MuJoCo's
viewer (the voltage is a slider), in ``mujoco.rollout`` and in batched engines:

* the voltage is the ``ctrl`` (V) of one actuator named ``drive``, ``ctrlrange`` the
  drive's safe range;
* the actuator acts on a fixed tendon ``bend`` over the bending hinges; a fixed tendon
  applies ``coef_j x`` its force to hinge j, so a uniform moment is coefficients 1 and the
  piezo bimorph's width-proportional moment is coefficients w_j / w_0;
* first-order electrical dynamics are the actuator's activation (``dyntype="filterexact"``:
  exact for a voltage held over the step, as the loop drives step it);
* Dadras et al. 2021's standard-linear-solid back-relaxation is one Maxwell arm per hinge (see
  :func:`add_maxwell_arms`).

Conventions every generated model follows: the custom numeric ``mjeap_units`` holds
"L M T", the SI size of one internal length, mass and time unit; the beam's names are as
a :class:`mjeap.Scene` builds them (``clamp`` body, ``tip`` site, ``hinge<j>`` joints),
prefixed per actuator when several share a model. A representation without bending joints
to sum has no native form (its builder lacks ``HINGE_TENDON``, :mod:`mjeap.model.mjcf`: the cable's ball joints, the
rod's vertices) and runs on the loop (or threaded) engine.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Dict, List, Optional

import mujoco
import numpy as np


ACTUATOR = "drive"
TENDON = "bend"
#: armature of a relaxation dof as a fraction of (timestep x its damping): the arm's inertial
#: time constant is then 1e-3 of a step and the dof follows its first-order law
RELAXATION_INERTIA = 1e-3
#: mass (and rotary inertia) of a relaxation body as a fraction of the lightest beam link's:
#: MuJoCo needs some on a moving body; this little adds nothing measurable to a host
RELAXATION_BODY_MASS = 1e-9


@dataclass
class NativeHandles:
    """Names of what a native drive added (unprefixed)."""

    actuator: str = ACTUATOR
    tendon: str = TENDON
    relaxation_joints: List[str] = field(default_factory=list)
    sensors: Dict[str, str] = field(default_factory=dict)


def add_bending_tendon(spec: mujoco.MjSpec, joints, coefficients, name: str = TENDON):
    """A fixed tendon sum_j c_j theta_j over the bending hinges."""
    t = spec.add_tendon(name=name)
    for j, c in zip(joints, coefficients):
        t.wrap_joint(j, float(c))
    return t


def add_drive_actuator(spec: mujoco.MjSpec, gain: float, ctrlrange, time_constant: Optional[float] = None,
                       bias: float = 0.0, name: str = ACTUATOR, tendon: str = TENDON):
    """The voltage input: force = gain x (activation or ctrl) + bias on the bending tendon,
    internal units; ``time_constant`` (internal) makes it first order (filterexact)."""
    dyn = mujoco.mjtDyn.mjDYN_NONE if time_constant is None else mujoco.mjtDyn.mjDYN_FILTEREXACT
    return spec.add_actuator(
        name=name, target=tendon, trntype=mujoco.mjtTrn.mjTRN_TENDON, dyntype=dyn,
        dynprm=[time_constant or 0.0] + [0.0] * 9, gaintype=mujoco.mjtGain.mjGAIN_FIXED,
        gainprm=[gain] + [0.0] * 9, biastype=mujoco.mjtBias.mjBIAS_AFFINE if bias else mujoco.mjtBias.mjBIAS_NONE,
        biasprm=[bias] + [0.0] * 9, ctrllimited=True, ctrlrange=[float(ctrlrange[0]), float(ctrlrange[1])])


def add_maxwell_arms(spec: mujoco.MjSpec, joints, parent: str, k, zero: float, pole: float,
                     timestep: float, link_mass: float) -> List[str]:
    """Standard linear solid on every hinge, as MuJoCo elements (internal units).

    The hinge's spring keeps the relaxed stiffness k p/z; in parallel a Maxwell arm, a
    spring k (z - p)/z (a fixed tendon theta_j - r_j) in series with a damper
    k (z - p)/z^2 on a relaxation dof r_j. Instantaneous stiffness k, relaxed k p/z,
    relaxation rate z: the moment of every load the beam carries (drive, payload,
    gravity) relaxes, as Dadras et al. 2021's mechanical block (s + z)/(s + p) says. The damper is
    implicit under ``implicitfast``; the relaxation dof's armature is RELAXATION_INERTIA x
    (timestep x damping), so the arm is first order to 1e-3 of a step; its body (on the
    hinge axis, under ``parent``) weighs RELAXATION_BODY_MASS x ``link_mass``.

    Cost, measured on Dadras et al. 2021's 20-hinge beam (MuJoCo 3.17, this 2-core machine, mj_step):
    bare beam 5.5 us, with the drive's tendon and actuator 6.4, with the arms 9.2-9.5; of
    the arms, their 20 dofs take 2.4 us and their 20 tendons 0.7; their bodies nothing
    measurable (six arms' joints on one body: the same time). The tendon-free form, a second
    hinge on every link (a spring in series with a spring-damper), puts the 20 extra dofs
    into the chain (a dense 40-dof mass matrix): 13.1 us. MuJoCo keeps no per-joint state
    without a dof, so these arms are the cheapest exact form found.
    """
    k = np.asarray(k, dtype=float)
    k1 = k * (zero - pole) / zero
    c = k1 / zero
    body = spec.body(parent)
    names = []
    for j, name in enumerate(joints):
        spec.joint(name).stiffness = [float(k[j] * pole / zero), 0.0, 0.0]
        b = body.add_body(name=f"relax{j}")
        b.explicitinertial = True
        b.mass, b.ipos, b.inertia = RELAXATION_BODY_MASS * link_mass, [0, 0, 0], [RELAXATION_BODY_MASS * link_mass] * 3
        b.add_joint(name=f"relax{j}", type=mujoco.mjtJoint.mjJNT_HINGE, axis=[0, 0, 1], damping=float(c[j]),
                    armature=float(RELAXATION_INERTIA * timestep * c[j]))
        t = spec.add_tendon(name=f"maxwell{j}", stiffness=float(k1[j]), springlength=[0.0, 0.0])
        t.wrap_joint(name, 1.0)
        t.wrap_joint(f"relax{j}", -1.0)
        names.append(f"relax{j}")
    return names
