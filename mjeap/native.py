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
* seed 000's standard-linear-solid back-relaxation is one Maxwell arm per hinge (see
  :func:`add_maxwell_arms`).

Conventions every generated model follows: the custom numeric ``mjeap_units`` holds
"L M T", the SI size of one internal length, mass and time unit; the beam's names are as
a :class:`mjeap.Scene` builds them (``clamp`` body, ``tip`` site, ``hinge<j>`` joints),
prefixed per actuator when several share a model. A representation without bending joints
to sum has no native form (its builder's ``native_reason``: the cable's ball joints, the
rod's vertices) and runs on the loop (or threaded) engine.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Dict, List, Optional

import mujoco
import numpy as np

from .errors import ParameterError
from .units import UnitSystem

UNITS_FIELD = "mjeap_units"
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


def add_units(spec: mujoco.MjSpec, units: UnitSystem) -> None:
    """Declare the internal units in the file: custom numeric ``mjeap_units`` = L M T (SI)."""
    for n in spec.numerics:
        if n.name == UNITS_FIELD:
            n.data = [units.length, units.mass, units.time]
            return
    spec.add_numeric(name=UNITS_FIELD, data=[units.length, units.mass, units.time])


def read_numeric(model: mujoco.MjModel, name: str, size: int, accepted: str,
                 positive: bool = False) -> Optional[np.ndarray]:
    """The values of the custom numeric ``name`` (None if the model has none), refused
    unless there are exactly ``size`` of them, finite and >= 0 (> 0 if ``positive``):
    MuJoCo keeps every numeric in one array, so a short field read at its length would
    run into the next one. ``accepted`` says what they are, for the message."""
    i = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_NUMERIC, name)
    if i < 0:
        return None
    a, n = int(model.numeric_adr[i]), int(model.numeric_size[i])
    v = np.array(model.numeric_data[a:a + n], dtype=float)
    if n != size:
        raise ParameterError(name, f"{n} values", f"{size} values: {accepted}")
    bad = ~np.isfinite(v) | ((v <= 0) if positive else (v < 0))
    if bad.any():
        j = int(np.argmax(bad))
        raise ParameterError(name, f"{float(v[j])!r} at index {j}",
                             f"finite values {'> 0' if positive else '>= 0'}: {accepted}")
    return v


def read_units(model: mujoco.MjModel) -> Optional[UnitSystem]:
    """The unit system a model declares in ``mjeap_units`` (None if it declares none)."""
    v = read_numeric(model, UNITS_FIELD, 3, "L M T, the SI size of one internal length (m), mass (kg) "
                     "and time (s) unit", positive=True)
    return None if v is None else UnitSystem(*map(float, v))


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
    gravity) relaxes, as seed 000's mechanical block (s + z)/(s + p) says. The damper is
    implicit under ``implicitfast``; the relaxation dof's armature is RELAXATION_INERTIA x
    (timestep x damping), so the arm is first order to 1e-3 of a step; its body (on the
    hinge axis, under ``parent``) weighs RELAXATION_BODY_MASS x ``link_mass``.
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


def why_not(scene, drive, controller=None) -> Optional[str]:
    """None where the native engine applies to this run of ``scene``; else why not."""
    if controller is not None:
        return "a controller closes the loop (its voltage depends on the state)"
    if scene.builder.native_reason is not None:
        return scene.builder.native_reason
    reason = drive.native_reason()
    if reason is not None:
        return f"the {drive.name} drive has no native form: {reason}"
    return None


class NativeModel:
    """A scene's beam with its drive compiled in (internal units, the scene's timestep,
    damping and present hinge parameters): ``model``, ``data``, the actuator's ``part``
    (the scene's names, so the same read-outs) and the drive's ``handles``."""

    def __init__(self, scene, drive, check_stability: bool = True):
        from .component import ActuatorPart
        from .errors import ParameterError
        from .scene import apply_dof_damping
        why = why_not(scene, drive)
        if why is not None:
            raise ParameterError("engine", "native", f"'loop' or 'auto' for this run: {why}")
        spec = scene.spec.copy()
        m0 = scene.model
        for name, j in zip(scene.handles.joints, scene.part.joint_ids):   # present values (identify may set them)
            spec.joint(name).stiffness = [float(m0.jnt_stiffness[j]), 0.0, 0.0]
            spec.joint(name).damping = [float(m0.dof_damping[m0.jnt_dofadr[j]]), 0.0, 0.0]
        self.handles = drive.add_native(spec, scene.handles.joints, scene.handles.clamp_body)
        add_units(spec, scene.units)
        self.spec, self.drive, self.scene = spec, drive, scene
        self.model = apply_dof_damping(spec.compile())
        if check_stability:
            self.check_stability()
        self.data = mujoco.MjData(self.model)
        self.part = ActuatorPart(self.model, scene.handles, scene.layout, scene.actuator, scene.units,
                                 scene.representation, scene.payload, rotation=scene.rotation)
        self.part.bind(self.data)
        self.actuator_id = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_ACTUATOR, self.handles.actuator)

    def check_stability(self) -> None:
        """The scene chose its timestep for the bare beam; the drive's elements (Maxwell arms)
        must not make the linearised step map unstable at that timestep."""
        from .errors import ParameterError
        from .modes import linearize, spectral_radius
        lin = linearize(self.model)
        rho = spectral_radius(lin, self.model.dof_damping, self.model.opt.timestep, self.scene.integrator)
        if rho > 1.0 + 1e-9:
            raise ParameterError("timestep", self.scene.timestep, "a timestep at which the native drive is stable",
                                 f"spectral radius {rho:.6g} of the native model's step map")

    def reset(self, initial_curvature: float = 0.0) -> None:
        """Rest at a uniform arc of ``initial_curvature`` (1/m), the drive state at rest there;
        the scene's tip loads act here too."""
        mujoco.mj_resetData(self.model, self.data)
        src = self.scene.part
        self.part._tip_force_world, self.part._tip_moment = src._tip_force_world.copy(), src._tip_moment
        self.part.apply_loads()
        lay = self.scene.layout
        if initial_curvature:
            self.part.set_hinge_angles(np.full(lay.segments, initial_curvature * lay.ds), forward=False)
        mujoco.mj_forward(self.model, self.data)
        self.drive.native_reset(self.part, self.handles)
