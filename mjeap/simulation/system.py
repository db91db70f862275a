"""Actuators as MuJoCo components: attach them to any model and run several in one system
with other bodies and contact.

:func:`attach` places a catalog (or user) actuator, with its drive compiled in
(:mod:`mjeap.drives.native`), into a user's ``MjSpec`` at a site, body or frame, under a prefix.
Its beam is discretised, damped and given a timestep exactly as a one-actuator
:class:`~mjeap.Scene` in the same orientation (its *twin*, built with the mount's world
rotation at the host's ``qpos0``), so an attached actuator moves as its Scene does.

:class:`System` compiles the host with its attached actuators: the timestep is the
smallest of the actuators' own choices (each already below its stability limit), contact
parameters are set for micro scale (:class:`ContactParameters`), and the model declares its
units in ``mjeap_units``. Each actuator is an :class:`~mjeap.simulation.part.ActuatorPart` with
SI read-outs in its own clamp frame; rollouts take one voltage per actuator.

Units: the host is written in the internal units the caller declares (``units``, default
mjeap's mm, mg, ms); a host in SI is refused where a beam's segments would fall below
MuJoCo's 1e-15 floors, with the part named and a unit system that works.
"""
from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Dict, List, Optional, Sequence, Union

import mujoco
import numpy as np

from ..drives.native import NativeHandles
from .part import ActuatorPart
from ..errors import DivergenceError, ParameterError, UnknownNameError, check_positive
from ..io.outputs import guarded
from ..versions import newton_sparse_broken
from ..engines.frame import check_work, one_voltage
from ..engines.result import SystemResult
from ..engines.native import why_not as native_why_not
from ..model.fields import UNITS_FIELD, add_units, apply_dof_damping
from .scene import DEFAULT_SEGMENTS, INTEGRATORS, Scene, diverged, input_files
from ..units import DEFAULT_UNITS, UnitSystem

_PREFIX = re.compile(r"^[A-Za-z][A-Za-z0-9_-]*$")
#: what to change when a voltage is above a system's Nyquist frequency: the system's step
#: (its actuators' twin Scenes do not set it)
SYSTEM_TIMESTEP = "pass a smaller timestep to the System (System(spec, actuators, timestep=...))"


def check_spec(spec) -> mujoco.MjSpec:
    """``spec`` if it is a ``mujoco.MjSpec``; XML text, a path or anything else is refused
    naming how to make one."""
    if not isinstance(spec, mujoco.MjSpec):
        shown = (spec if len(spec) <= 60 else spec[:57] + "...") if isinstance(spec, str) else type(spec).__name__
        raise ParameterError("spec", shown, "a mujoco.MjSpec: mujoco.MjSpec.from_string(xml) for XML text, "
                             "mujoco.MjSpec.from_file(path) for a file")
    return spec


_CONES = {"elliptic": mujoco.mjtCone.mjCONE_ELLIPTIC, "pyramidal": mujoco.mjtCone.mjCONE_PYRAMIDAL}


@dataclass(frozen=True)
class ContactParameters:
    """Contact for micro-scale systems, applied to every contact of the system (MuJoCo's
    ``override`` flag), internal units derived from the timestep h.

    * ``solref`` = (``timeconst_steps`` x h, ``dampratio``): the stiffest contact MuJoCo
      integrates stably is a time constant of 2 h (it raises smaller ones to 2 h);
      critically damped, so a beam closing on a body does not bounce.
    * ``solimp`` = (0.99, 0.999, ``width_fraction`` x the thinnest beam, 0.5, 2): impedance
      near 1 makes the contact nearly rigid. At rest the penetration is
      F (1 - d) (timeconst)^2 / m_eff for a force F on an effective mass m_eff; for the
      actuators here that is far below their thickness (tested: a beam pressing on a block).
    * ``margin`` 0, ``friction`` = (sliding coefficient, torsional m, rolling m) =
      (0.5, 5 um, 0.1 um), an elliptic cone (``cone``). The torsional and rolling
      coefficients are lengths (the moment they resist per newton of normal force) and act
      only where a geom asks for them (condim 4 or 6; the beams' geoms are condim 3).
    * ``impratio``: the friction rows' regularisation is the normal row's divided by it.
      MuJoCo's friction is soft: under a steady tangential load f a sticking contact creeps
      at about f R / b (R its regulariser, b = 1 / h its damping); impratio > 1 cuts the
      creep by that factor (elliptic cones only).

    Sizing a contact from its physics (the defaults suit a beam closing on a part, the
    gripper's and the rod's tests; a system whose contacts carry a body may need others:
    mjeap.robots.hamr_walk sizes the walker's feet this way). With dampratio 1 a contact's
    penetration r obeys r'' + (2 / tau) r' + r / tau^2 = 0 (MuJoCo's reference
    acceleration; b = 2 / (dmax tau), k = 1 / (dmax tau dampratio)^2), for any mass:

    * tau well above the step: at 2 h (MuJoCo's floor) the normal and friction rows are
      deadbeat from one step to the next and a contact that carries a body through other
      stiff constraints can chatter; ~10 steps resolve the response.
    * tau well below the contact's physical time scales: the critically damped response
      settles in about 5 tau, which should be a small share of the shortest contact event
      (a stance); a body landing at speed v penetrates at most v tau / e (critical damping),
      to be kept within the solimp width (the penetration the model tolerates).
    * At rest a contact carrying a force F on an effective mass m (1 / its diagonal of
      J M^-1 J^T) penetrates about (1 - d) / d^2 x tau^2 F / m (d = dmin at a shallow depth):
      the impedance d sets how rigid it is beside tau; and a sticking contact under a
      tangential force f creeps at about (1 - d) / d x (f / m) x dmax tau / (2 impratio):
      longer time constants creep more, impratio cuts it.
    * Under 'implicitfast' MuJoCo sizes contact impulses for M alone while the step
      integrates M + hD: a contact coupled to a damped beam (through a transmission, say)
      is then mis-sized and can chatter however the contact is set; 'discrete' solves it in
      the step's own metric (:func:`attach`'s ``integrator``).
    """

    timeconst_steps: float = 2.0
    dampratio: float = 1.0
    impedance: tuple = (0.99, 0.999)
    width_fraction: float = 0.1
    friction: tuple = (0.5, 5e-6, 1e-7)
    margin: float = 0.0
    cone: str = "elliptic"
    impratio: float = 1.0

    def __post_init__(self):
        if len(self.friction) != 3 or not all(np.isfinite(f) and f >= 0 for f in self.friction):
            raise ParameterError("friction", self.friction, "(sliding >= 0, torsional >= 0 m, rolling >= 0 m)")
        if self.cone not in _CONES:
            raise ParameterError("cone", self.cone, " or ".join(f"'{c}'" for c in _CONES))
        if not (np.isfinite(self.impratio) and self.impratio >= 1.0):
            raise ParameterError("impratio", self.impratio, "a ratio >= 1")

    def apply(self, spec: mujoco.MjSpec, h: float, thickness: float, length: float) -> None:
        """Set the host's contact override: ``h`` and ``thickness`` internal, ``length`` the
        SI size (m) of one internal length unit."""
        o = spec.option
        o.disableflags &= ~int(mujoco.mjtDisableBit.mjDSBL_CONTACT)
        o.enableflags |= int(mujoco.mjtEnableBit.mjENBL_OVERRIDE)
        o.o_solref = [self.timeconst_steps * h, self.dampratio]
        o.o_solimp = [self.impedance[0], self.impedance[1], self.width_fraction * thickness, 0.5, 2.0]
        o.o_margin = self.margin
        mu, torsion, rolling = self.friction[0], self.friction[1] / length, self.friction[2] / length
        o.o_friction = [mu, mu, torsion, rolling, rolling]
        o.cone = _CONES[self.cone]
        o.impratio = self.impratio


@dataclass
class AttachedActuator:
    """What :func:`attach` placed into a host spec. Names in the compiled model are
    ``prefix`` + the Scene's names (``clamp``, ``link<j>``, ``hinge<j>``, ``tip``) and, for
    the drive, ``drive`` (actuator; ctrl in volts), ``bend`` (tendon)."""

    prefix: str                      # with its trailing '/'
    twin: Scene                      # the equivalent one-actuator Scene (layout, damping, timestep)
    drive: Optional[object]          # the drive (its native form is in the model), None if passive
    native: Optional[NativeHandles]
    contact: bool

    def name(self, element: str) -> str:
        return self.prefix + element

    @property
    def actuator_name(self) -> Optional[str]:
        return None if self.native is None else self.prefix + self.native.actuator

    @property
    def tip_site(self) -> str:
        return self.prefix + self.twin.handles.tip_site

    @property
    def joints(self) -> List[str]:
        return [self.prefix + j for j in self.twin.handles.joints]

    @property
    def tendon(self) -> Optional[str]:
        return None if self.native is None else self.prefix + self.native.tendon


def _mount(spec: mujoco.MjSpec, site, body, frame):
    given = [(k, v) for k, v in (("site", site), ("body", body), ("frame", frame)) if v is not None]
    if len(given) != 1:
        raise ParameterError("site/body/frame", ", ".join(k for k, _ in given) or "none",
                             "exactly one of site=, body= or frame= naming where the clamp goes")
    kind, name = given[0]
    el = getattr(spec, kind)(name)
    if el is None:
        known = [x.name for x in getattr(spec, {"site": "sites", "body": "bodies", "frame": "frames"}[kind]) if x.name]
        raise UnknownNameError(kind, str(name), known)
    return kind, name, el


#: host flags that would switch off part of what an attached beam is: (bit, flag, why)
_BEAM_FLAGS = (
    (mujoco.mjtDisableBit.mjDSBL_SPRING, "spring",
     "the beam's bending stiffness is its joints' springs (and the cable plugin's forces): it would fall limp"),
    (mujoco.mjtDisableBit.mjDSBL_DAMPER, "damper",
     "the beam's Rayleigh damping is its joints' dampers, and its timestep is chosen with them: without them it "
     "rings or diverges"),
)
_DRIVE_FLAGS = (
    (mujoco.mjtDisableBit.mjDSBL_ACTUATION, "actuation",
     "a drive is a MuJoCo actuator: nothing would be driven while its voltage is recorded (attach the beam "
     "with passive=True to run it without a drive)"),
)


def host_gravity(option, driven: bool) -> np.ndarray:
    """The gravity (internal units) the host's ``option`` applies: zero under its
    ``<flag gravity="disable"/>``. Flags that would switch off part of an attached beam
    (springs, dampers; actuation where a beam is ``driven``) are refused with the flag named."""
    flags = int(option.disableflags)
    for bit, flag, why in _BEAM_FLAGS + (_DRIVE_FLAGS if driven else ()):
        if flags & int(bit):
            raise ParameterError(f"<flag {flag}>", "disable", "'enable' (the default) in a host with mjeap actuators",
                                 why)
    if flags & int(mujoco.mjtDisableBit.mjDSBL_GRAVITY):
        return np.zeros(3)
    return np.array(option.gravity, dtype=float)




#: compiled arrays a host's elements must hold finite: (MuJoCo object, array, what it is)
_FINITE = (("body", "body_pos", "pos"), ("body", "body_quat", "quat"), ("body", "body_ipos", "inertial pos"),
           ("body", "body_iquat", "inertial quat"), ("body", "body_mass", "mass"), ("body", "body_inertia", "inertia"),
           ("site", "site_pos", "pos"), ("site", "site_quat", "quat"), ("site", "site_size", "size"),
           ("geom", "geom_pos", "pos"), ("geom", "geom_quat", "quat"), ("geom", "geom_size", "size"),
           ("joint", "jnt_pos", "pos"), ("joint", "jnt_axis", "axis"), ("equality", "eq_data", "data"))


def check_finite_model(model: mujoco.MjModel, what: str = "spec") -> None:
    """Refuse a compiled host whose bodies, sites, geoms, joints or equalities hold a
    non-finite position, orientation, size or mass, naming the element (MuJoCo compiles
    them; the first step then diverges, which would be blamed on the timestep)."""
    for kind, array, label in _FINITE:
        a = np.asarray(getattr(model, array))
        if not a.size:
            continue
        a = a.reshape(a.shape[0], -1)
        bad = np.nonzero(~np.isfinite(a).all(axis=1))[0]
        if bad.size:
            i = int(bad[0])
            obj = getattr(mujoco.mjtObj, f"mjOBJ_{'EQUALITY' if kind == 'equality' else kind.upper()}")
            name = mujoco.mj_id2name(model, obj, i) or f"#{i} (unnamed)"
            raise ParameterError(f"{what}: {kind} '{name}' {label}", a[i].tolist(), "finite numbers",
                                 "a NaN or inf in the host model, not a timestep problem")


def _mount_rotation(spec: mujoco.MjSpec, kind: str, name: str, el) -> np.ndarray:
    """World rotation of the mount at the host's qpos0; a host with non-finite positions
    is refused (:func:`check_finite_model`)."""
    m = spec.copy().compile()
    check_finite_model(m)
    d = mujoco.MjData(m)
    mujoco.mj_kinematics(m, d)
    if kind == "site":
        R = d.site_xmat[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, name)].reshape(3, 3)
    else:
        parent = el.name if kind == "body" else el.parent.name
        R = d.xmat[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, parent)].reshape(3, 3)
        if kind == "frame":
            q = np.zeros(9)
            mujoco.mju_quat2Mat(q, np.asarray(el.quat, dtype=float) / np.linalg.norm(el.quat))
            R = R @ q.reshape(3, 3)
    return R.copy()


def attach(spec: mujoco.MjSpec, actuator, *, prefix: str, site: Optional[str] = None, body: Optional[str] = None,
           frame: Optional[str] = None, drive: Optional[str] = None, drive_params: Optional[dict] = None,
           payload=None, representation: str = "hinge", segments: int = DEFAULT_SEGMENTS,
           units: Optional[UnitSystem] = None, damping_ratio: Optional[float] = None, contact: bool = True,
           passive: bool = False, integrator: Optional[str] = None) -> AttachedActuator:
    """Place ``actuator`` (catalog id or :class:`mjeap.Actuator`) into the host ``spec`` at a
    ``site``, ``body`` or ``frame`` (exactly one, by name): its clamp frame is the mount's
    (x along the beam, y the deflection, z the hinge axis). ``prefix`` (letters, digits,
    '_', '-'; unique in the spec) is prepended as ``prefix/`` to every name. ``drive``
    (default: the actuator's own) is compiled in (:mod:`mjeap.drives.native`); ``passive=True``
    attaches the bare beam (the cable representation has no native drive). ``contact``
    lets the beam's geoms touch other bodies. ``units``: the host's internal units.
    ``integrator`` defaults to 'discrete' with contact (MuJoCo solves contacts in the
    metric of its implicit update there; under 'implicitfast' contact impulses are sized
    for M alone and kick the heavily damped short modes of a beam: tested) and
    'implicitfast' without; the timestep and damping follow from it (:mod:`mjeap.simulation.scene`).
    The host's flags are read: under ``<flag gravity="disable"/>`` the beam is sized without
    gravity; springs or dampers switched off (and actuation, for a driven beam) are refused.
    With ``contact`` the beam's own parts (its payload, neighbouring links) never touch."""
    check_spec(spec)
    units = units or DEFAULT_UNITS
    from ..model.mjcf import get_builder
    from ..model.mjcf import ATTACHED_WHOLE
    why = get_builder(representation).lacks(ATTACHED_WHOLE)
    if why is not None:
        raise ParameterError("representation", representation, "'hinge' (or 'cable' on MuJoCo 3.x) for attach: a "
                             "beam that MjSpec.attach carries whole with its clamp body", why)
    integrator = integrator or ("discrete" if contact else "implicitfast")
    if not isinstance(prefix, str) or not _PREFIX.match(prefix):
        raise ParameterError("prefix", prefix, "a name of letters, digits, '_' or '-', starting with a letter")
    if spec.body(prefix + "/clamp") is not None:
        raise ParameterError("prefix", prefix, "a prefix not used yet in this model (an actuator is attached "
                             f"under '{prefix}/' already)")
    kind, name, el = _mount(spec, site, body, frame)
    g = host_gravity(spec.option, driven=not passive)
    gs = g * units.acceleration
    if np.any(g) and not np.allclose(gs, [0, 0, -9.80665], rtol=2e-3):
        raise ParameterError("spec.option.gravity", f"{gs} m/s^2 (in the declared units {units.describe()})",
                             f"standard gravity along -z, 0 0 {-9.80665 / units.acceleration:.9g} in these units "
                             "(9.81 m/s^2), or none: the actuator's damping and timestep are chosen for it "
                             "(a host in other units: declare them with units=)")
    R = _mount_rotation(spec, kind, name, el)
    twin = Scene(actuator, representation=representation, segments=segments, orientation=R, payload=payload,
                 units=units, damping_ratio=damping_ratio, gravity=bool(np.any(g)), integrator=integrator)
    drv, nat = None, None
    if passive:
        child = twin.spec.copy()
    else:
        from ..drives import make_drive
        drv = make_drive(drive, twin, **(drive_params or {}))
        why = native_why_not(twin, drv)
        if why is not None:
            raise ParameterError("drive", drv.name, "a drive with a native form, or passive=True", why)
        nm = twin.native_model(drv)
        child, nat = nm.spec.copy(), nm.handles
    for n in list(child.numerics):
        if n.name == UNITS_FIELD:
            child.delete(n)
    if contact:
        for b in twin.handles.link_bodies:              # the hinge chain's links, the cable's segments
            for g_ in child.body(b).geoms:
                g_.contype, g_.conaffinity, g_.condim = 1, 1, 3
        if twin.payload is not None:
            child.geom("payload").contype, child.geom("payload").conaffinity = 1, 1
    o, co = spec.option, child.option         # the host's options rule; say so to MjSpec
    co.timestep, co.integrator, co.gravity = o.timestep, o.integrator, o.gravity
    child.memory = spec.memory
    clamp = child.body(twin.handles.clamp_body)
    clamp.pos, clamp.quat = [0, 0, 0], [1, 0, 0, 0]       # the mount's frame is the clamp frame
    target = el if kind != "body" else el.add_frame()
    target.attach_body(clamp, prefix + "/", "")
    if contact:
        _exclude_own_contacts(spec, twin.handles, prefix + "/")
    return AttachedActuator(prefix + "/", twin, drv, nat, contact)


def _exclude_own_contacts(spec: mujoco.MjSpec, handles, prefix: str) -> None:
    """A beam's own parts never touch each other: its payload sphere (it overlaps the links
    it is mounted beside) and its neighbouring links (MuJoCo filters parent and child only
    while the host keeps its filterparent flag) are excluded pairs."""
    links = [prefix + b for b in handles.link_bodies]
    for b1, b2 in zip(links[:-1], links[1:]):
        spec.add_exclude(bodyname1=b1, bodyname2=b2)
    if handles.payload_body:
        for b in links:
            spec.add_exclude(bodyname1=prefix + handles.payload_body, bodyname2=b)


def add_transmission(spec: mujoco.MjSpec, actuator: AttachedActuator, joint: str, ratio: float) -> None:
    """Couple the host's hinge ``joint`` to an attached ``actuator``'s tip: joint angle (rad)
    = ``ratio`` (rad/m, signed) x the tip's deflection linearised in the hinge angles (m),
    the small-motion transmission Jayaram et al. 2018 states (RoboBee T_eff, HAMR T / leg length). A
    fixed tendon '<prefix>tip_deflection' sums the actuator's hinges with coefficients
    x_tip - x_j, a tendon '<prefix>transmission' reads the joint, and a tendon equality
    holds one at ``ratio`` times the other."""
    if not np.isfinite(ratio) or ratio == 0:
        raise ParameterError("ratio", ratio, "a finite, non-zero transmission ratio in rad/m")
    if spec.joint(joint) is None:
        raise UnknownNameError("joint", joint, [j.name for j in spec.joints])
    lay, u = actuator.twin.layout, actuator.twin.units
    tip = spec.add_tendon(name=actuator.name("tip_deflection"))
    for j, x in zip(actuator.joints, lay.hinge_x):
        tip.wrap_joint(j, (lay.tip_x - x) / u.length)
    spec.add_tendon(name=actuator.name("transmission")).wrap_joint(joint, 1.0)
    eq = spec.add_equality(type=mujoco.mjtEq.mjEQ_TENDON, name1=actuator.name("transmission"),
                           name2=actuator.name("tip_deflection"))
    eq.data[:5] = [0.0, ratio * u.length, 0.0, 0.0, 0.0]


class System:
    """A compiled MuJoCo system: a host ``spec`` with ``actuators`` attached by
    :func:`attach` (all in ``units``), other bodies, joints, constraints and contact.
    ``timestep`` (s) defaults to the smallest of the actuators' own choices; one beyond an
    actuator's limits (:meth:`~mjeap.Scene.check_timestep`: stability, and under 'discrete'
    accuracy and beta / 2) is refused with the limit; under 'discrete' the hinges' damping
    is (beta - h) k of the system's h. The host's flags and gravity must still be those the
    actuators were attached under. The integrator is the actuators' (they were attached for one:
    'discrete' with contact, see :func:`attach`); ``integrator`` is needed only without
    actuators. ``contact``: :class:`ContactParameters` (None: the host's own). ``loaded``: the
    actuators drive heavy host parts (a transmission and a leg on each tip), so their loaded
    modes, not the free beam's, set the dynamics: a given ``timestep`` is then checked only
    against each actuator's stability limit (none under 'discrete', which takes the beam's
    springs implicitly), not against the free beam's accuracy (T_1 / 50) and damping (beta /
    2) limits, and the caller sizes it for the loaded system and checks it (e.g. against a
    run at half the step: :meth:`half_step`). Above beta the step's own damping h K
    exceeds the beam's Rayleigh damping (the joints then carry none)."""

    def __init__(self, spec: mujoco.MjSpec, actuators: Sequence[AttachedActuator], units: Optional[UnitSystem] = None,
                 timestep: Optional[float] = None, integrator: Optional[str] = None,
                 contact: Optional[ContactParameters] = ContactParameters(), *, loaded: bool = False):
        check_spec(spec)
        self.units = units = units or DEFAULT_UNITS
        self.actuators = list(actuators)
        prefixes = [a.prefix for a in self.actuators]
        if len(set(prefixes)) != len(prefixes):
            raise ParameterError("actuators", prefixes, "actuators with distinct prefixes")
        for a in self.actuators:
            if a.twin.units != units:
                raise ParameterError("units", units.describe(), f"the units actuator '{a.prefix}' was attached in "
                                     f"({a.twin.units.describe()}): pass the same units= to attach and System")
        used = {a.twin.integrator for a in self.actuators}
        if len(used) > 1 or (integrator is not None and used and used != {integrator}):
            raise ParameterError("integrator", integrator or sorted(used), "one integrator for every actuator "
                                 f"(attached with {', '.join(f'{a.prefix} {a.twin.integrator}' for a in self.actuators)}): "
                                 "pass the same integrator= (or contact=) to attach")
        integrator = integrator or (used.pop() if used else "implicitfast")
        if integrator not in INTEGRATORS:
            raise ParameterError("integrator", integrator, f"one of {', '.join(INTEGRATORS)}")
        self.integrator = integrator
        if self.actuators:
            # the host's flags and gravity now, against those each twin was sized for at attach
            g = host_gravity(spec.option, driven=any(a.drive is not None for a in self.actuators))
            for a in self.actuators:
                g_twin = a.twin.model.opt.gravity * units.acceleration
                if not np.allclose(g * units.acceleration, g_twin, rtol=2e-3):
                    raise ParameterError(
                        "spec.option.gravity", f"{g * units.acceleration} m/s^2 (with its gravity flag)",
                        f"the gravity actuator '{a.prefix.rstrip('/')}' was attached under, {g_twin} m/s^2",
                        "its damping and timestep were chosen for that gravity: set the host's gravity and its flag "
                        "before attach")
        self.loaded = bool(loaded)
        if timestep is None:
            if not self.actuators:
                raise ParameterError("timestep", None, "a timestep in s for a system without actuators")
            h = min(a.twin.timestep for a in self.actuators)
            self.timestep_reason = "the smallest of the actuators' own timesteps"
        else:
            h = check_positive("timestep", timestep, "s")
            for a in self.actuators:          # stability; accuracy and the joints' damping under discrete
                if not loaded:
                    a.twin.check_timestep(timestep)
                elif timestep > a.twin.choice.stability_limit:
                    raise ParameterError("timestep", timestep, f"a timestep <= {a.twin.choice.stability_limit:.4g} s",
                                         f"the stability limit of actuator '{a.prefix.rstrip('/')}'")
            self.timestep_reason = "given by the user" + (" for the loaded system (stability checked)" if loaded else "")
        self.spec = spec
        for a in self.actuators:
            if a.twin.builder.implicit_stiffness(a.twin.integrator):
                # discrete damps the beam by h K itself: the joints carry beta - h of the system's h
                for name, b in zip(a.joints, a.twin.joint_damping(h)):
                    spec.joint(name).damping = [float(b), 0.0, 0.0]
        spec.option.timestep = h / units.time
        spec.option.integrator = INTEGRATORS[integrator]
        spec.option.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_AUTORESET)
        if newton_sparse_broken():          # MuJoCo 4.0.0's sparse Cholesky bug (mjeap.versions)
            spec.option.jacobian = mujoco.mjtJacobian.mjJAC_DENSE
        if contact is not None and any(a.contact for a in self.actuators):
            t_min = min(a.twin.layout.thickness for a in self.actuators if a.contact) / units.length
            contact.apply(spec, h / units.time, t_min, units.length)
        self.contact = contact
        add_units(spec, units)
        try:
            model = spec.compile()
        except ValueError as e:
            raise ParameterError("spec", spec.modelname, "a host model that compiles with its actuators",
                                 str(e).splitlines()[0]) from None
        self.model = apply_dof_damping(model)         # a cable's per-dof damping (PREFIX/mjeap_dof_damping)
        check_finite_model(self.model)
        self.data = mujoco.MjData(self.model)
        m = self.model
        self.parts: List[ActuatorPart] = []
        self.actuator_ids: List[int] = []
        for a in self.actuators:
            tw = a.twin
            clamp = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, a.prefix + tw.handles.clamp_body)
            fixed = m.body_weldid[clamp] == 0          # welded to the world: a constant clamp frame
            part = ActuatorPart(m, tw.handles, tw.layout, tw.actuator, units, tw.representation, payload=tw.payload,
                                prefix=a.prefix, rotation=None)
            part.bind(self.data)
            if fixed:
                mujoco.mj_kinematics(m, self.data)
                part.fix_rotation(self.data.xmat[clamp].reshape(3, 3))
            self.parts.append(part)
            self.actuator_ids.append(-1 if a.actuator_name is None else
                                     mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_ACTUATOR, a.actuator_name))
        #: steps since the last reset (the engines that step the system advance it)
        self.step_count = 0
        self.reset()

    # ------------------------------------------------------------------ access
    def __len__(self) -> int:
        return len(self.actuators)

    def index(self, prefix: str) -> int:
        names = [a.prefix.rstrip("/") for a in self.actuators]
        p = prefix.rstrip("/")
        if p not in names:
            raise UnknownNameError("actuator prefix", p, names)
        return names.index(p)

    def part(self, prefix: str) -> ActuatorPart:
        """The actuator attached under ``prefix``: SI read-outs in its clamp frame."""
        return self.parts[self.index(prefix)]

    @property
    def timestep(self) -> float:
        return self.model.opt.timestep * self.units.time

    @property
    def time(self) -> float:
        return self.data.time * self.units.time

    def drive_observer(self, prefix: str):
        """A copy of the drive of the actuator under ``prefix`` that reads this system's beam
        and never acts on it (the native model drives it): call its ``step(v, dt)`` with the
        voltage (V) held over each step, in lockstep with :meth:`step`, and its
        ``signals()`` (the drive current, A, ...) read what a lockstep loop would, e.g. for
        a controller that senses the actuator's own current."""
        from ..drives import make_drive
        from ..drives.base import ReadOnlyPart
        i = self.index(prefix)
        a = self.actuators[i]
        if a.drive is None:
            raise ParameterError("prefix", prefix, "an actuator attached with a drive (this one is passive)")
        obs = make_drive(a.drive.name, a.twin, **a.drive.params)
        obs.part = ReadOnlyPart(self.parts[i])
        obs.reset()
        return obs

    # ------------------------------------------------------------------ state
    def reset(self, initial_curvatures: Union[float, Sequence[float]] = 0.0) -> None:
        """Reset to the host's qpos0 with each beam a uniform arc of its initial curvature
        (1/m), the drives at rest there (relaxation holding the shape, no charge)."""
        k0 = self._per_actuator("initial_curvatures", initial_curvatures)
        m, d = self.model, self.data
        mujoco.mj_resetData(m, d)
        mujoco.mj_kinematics(m, d)           # the clamp frames, the tip moments' axes
        from ..engines.frame import check_initial_curvature
        for p, k in zip(self.parts, k0):
            p.after_data_reset()
            k = check_initial_curvature(k, p.layout.length, "initial_curvatures")
            if k:
                p.set_hinge_angles(np.full(p.layout.segments, float(k) * p.layout.ds), forward=False)
        mujoco.mj_forward(m, d)
        for a, p in zip(self.actuators, self.parts):
            if a.drive is not None:
                a.drive.native_reset(p, a.native, a.prefix)
        for a, i in zip(self.actuators, self.actuator_ids):
            if i >= 0:
                d.ctrl[i] = a.drive.rest_voltage()
        self.step_count = 0

    def _per_actuator(self, name: str, values) -> list:
        """One value per actuator from a list, a dict by prefix or one value for all; a bare
        text (a waveform) is one actuator's, so only a system of one takes it."""
        if isinstance(values, str):
            if len(self) == 1:
                return [values]
            raise ParameterError(name, values, f"one per actuator ({len(self)}: "
                                 f"{', '.join(a.prefix.rstrip('/') for a in self.actuators)}) as a list or a dict "
                                 "by prefix: a single text is taken for a system of one actuator only")
        if np.ndim(values) == 0 and not isinstance(values, dict):
            return [values] * len(self)
        if isinstance(values, dict):
            out = [None] * len(self)
            for k, v in values.items():
                out[self.index(k)] = v
            return out
        values = list(values)
        if len(values) != len(self):
            raise ParameterError(name, f"{len(values)} values", f"one per actuator ({len(self)}: "
                                 f"{', '.join(a.prefix.rstrip('/') for a in self.actuators)}) or a dict by prefix")
        return values

    def set_voltages(self, voltages: Sequence[float]) -> None:
        """Hold these voltages (V), one per actuator, from now on (the actuators' ctrl)."""
        for a, i, v in zip(self.actuators, self.actuator_ids, self._per_actuator("voltages", voltages)):
            if i < 0 or v is None:
                continue
            v = one_voltage(v, f"voltage of '{a.prefix.rstrip('/')}'")
            a.drive.check_voltage(np.asarray([v], dtype=float))
            self.data.ctrl[i] = v

    def step(self, n: int = 1) -> None:
        """Advance ``n`` steps; raises :class:`DivergenceError` if the state blows up."""
        mujoco.mj_step(self.model, self.data, nstep=n)
        self.step_count += n
        self.check_finite()
        mujoco.mj_kinematics(self.model, self.data)

    def check_finite(self) -> None:
        if diverged(self.data):
            raise DivergenceError(
                f"system of {len(self)} actuators diverged by step {self.step_count} (t = {self.time:.6g} s): "
                f"timestep {self.timestep:.4g} s ({self.timestep_reason}); check the host's bodies, joints and "
                "contacts (a stiff or light part may need a smaller timestep)")

    # ------------------------------------------------------------------ contact
    def contact_forces(self) -> np.ndarray:
        """Net contact force (N, world frame) on every body at the present state, (nbody, 3)."""
        m, d = self.model, self.data
        out = np.zeros((m.nbody, 3))
        f6 = np.zeros(6)
        for i in range(d.ncon):
            c = d.contact[i]
            mujoco.mj_contactForce(m, d, i, f6)
            fw = c.frame.reshape(3, 3).T @ f6[:3]        # force of geom1 on geom2, world
            out[m.geom_bodyid[c.geom2]] += fw
            out[m.geom_bodyid[c.geom1]] -= fw
        return out * self.units.force

    def penetration(self) -> float:
        """Deepest penetration (m) among the present contacts (0 if none)."""
        d = self.data
        dist = [d.contact[i].dist for i in range(d.ncon)]
        return max(0.0, -min(dist, default=0.0)) * self.units.length

    def hold_voltages(self, voltages, v_steps, k: int, who: str) -> None:
        """Hold a controller's ``voltages`` (V) from step ``k`` on, each checked first: one
        number per actuator (or one for all, or a dict by prefix; None: unchanged)."""
        t = self.time
        try:
            if isinstance(voltages, (str, bytes)):
                raise ValueError
            listed = isinstance(voltages, (list, tuple)) and len(voltages) == len(self)    # checked one by one
            values = list(voltages) if listed else self._per_actuator("controller voltages", voltages)
        except (ParameterError, ValueError, TypeError):      # text, a wrong length, ragged
            shown = voltages if isinstance(voltages, (str, bytes)) else \
                f"{len(voltages)} values" if hasattr(voltages, "__len__") else type(voltages).__name__
            raise ParameterError("controller voltages", shown, f"one number (V) for all or one per actuator "
                                 f"({len(self)}: {', '.join(a.prefix.rstrip('/') for a in self.actuators)}), "
                                 "or a dict by prefix", f"{who} at t = {t:.6g} s") from None
        for a, vs, v in zip(self.actuators, v_steps, values):
            if vs is None:
                continue
            if v is None:
                if k:
                    vs[k] = vs[k - 1]
                continue
            v = one_voltage(v, f"controller voltage of '{a.prefix.rstrip('/')}'", f"{who} at t = {t:.6g} s")
            lo, hi = a.drive.voltage_range()
            if not (lo - 1e-12 <= v <= hi + 1e-12):
                raise ParameterError(f"controller voltage of '{a.prefix.rstrip('/')}'", f"{v:.6g} V at t = {self.time:.6g} s",
                                     f"a voltage in the safe range [{lo:g}, {hi:g}] V of {a.twin.actuator.id}")
            vs[k] = v

    # ------------------------------------------------------------------ rollout
    @guarded("rrd", inputs=lambda a: input_files(
        [x.twin for x in a["self"].actuators],
        list(a["voltages"].values()) if isinstance(a["voltages"], dict) else
        (a["voltages"] if isinstance(a["voltages"], (list, tuple)) else [a["voltages"]])))
    def rollout(self, voltages, duration: float, *, initial_curvatures: Union[float, Sequence[float]] = 0.0,
                sample_interval: Optional[float] = None, rrd: Union[str, Path, None] = None,
                on_sample=None, controller=None, engine: str = "auto", estimate_error: bool = False) -> SystemResult:
        """Run for ``duration`` s with one voltage per actuator (waveform text,
        :class:`~mjeap.Waveform`, callable v(t) or None for its rest voltage; a list or a dict
        by prefix). Returns a :class:`SystemResult`; with ``rrd`` a Rerun recording (written
        also when the run fails or is stopped by Ctrl-C or SIGTERM: it then ends with the
        error; a second writer is refused, :func:`mjeap.io.outputs.guarded`). ``on_sample(system)``
        is called at every sample (e.g. to move a mocap body). ``controller(t, system)``
        (``voltages`` then None; a plain function or an object, the one contract of
        :func:`mjeap.rollout`, :func:`mjeap.engines.frame.check_controller`: its ``reset(system,
        None)``, ``interval`` and ``name`` are used when present) is called before every step
        (every ``interval``) and returns the voltages (V) to hold until its next call, one per
        actuator or a dict by prefix (None: unchanged); each is checked against its drive's
        safe range. It may read the system's state; a controller that
        senses an actuator's current steps a :meth:`drive_observer` with them. ``engine``: one
        that runs systems (:func:`mjeap.engines.choose_system`; 'auto': the loop engine).
        ``estimate_error``: each actuator's tip-curvature error from the timestep, against the
        system at half the step (:func:`mjeap.simulation.accuracy.estimate_system_error`; 2 x
        the cost; open loop without ``on_sample``), in ``meta['accuracy']``."""
        from ..engines.frame import check_controller, to_waveform
        from . import pipeline
        duration = check_positive("duration", duration, "s")
        ctrl_name = None if controller is None else check_controller(controller)
        if estimate_error and (controller is not None or on_sample is not None):
            raise ParameterError("estimate_error", estimate_error, "False with a controller or on_sample: the "
                                 "companion run at half the step would call them again (they may keep state or "
                                 "move the model)")
        if estimate_error:
            for p in self.parts:
                p.check_derivable()
        if controller is not None:
            if voltages is not None and any(v is not None for v in self._per_actuator("voltages", voltages)):
                raise ParameterError("voltages", voltages, "None when a controller sets the voltages")
            voltages = None
        waves = [None if w is None else to_waveform(w, duration) for w in self._per_actuator("voltages", voltages)]
        check_work(duration, self.timestep)
        for a, w in zip(self.actuators, waves):
            if a.drive is None and w is not None:
                raise ParameterError("voltages", getattr(w, "text", w), f"None for the passive actuator '{a.prefix}'")
        # a waveform is checked against the drive's safe range (the plan); the rest voltage (None) is in it
        return pipeline.run(pipeline.Job(
            self, tuple(waves), tuple(a.drive for a in self.actuators), duration, initial_curvatures,
            sample_interval=sample_interval, engine=engine, controller=controller, controller_name=ctrl_name,
            on_sample=on_sample, estimate_error=estimate_error, remedy=SYSTEM_TIMESTEP, rrd=rrd))

    def describe_run(self, waves, controller, ctrl_name: Optional[str], duration: float) -> dict:
        """What a run of this system describes in its meta (:func:`mjeap.simulation.pipeline.plan`
        adds the provenance, steps and engine)."""
        return {"actuators": {a.prefix.rstrip("/"): {"actuator": a.twin.actuator.id,
                                                     "drive": None if a.drive is None else a.drive.describe(),
                                                     "voltage": (f"controller: {ctrl_name}" if controller is not None
                                                                 and a.drive is not None else
                                                                 None if w is None else getattr(w, "text", str(w)))}
                              for a, w in zip(self.actuators, waves)},
                "duration_s": duration, "timestep_s": self.timestep, "timestep_reason": self.timestep_reason,
                "units": self.units.describe()}

    def half_step(self) -> "System":
        """This system at half its timestep: a copy of its spec with the same actuators,
        integrator and contact parameters (contact's time constant, in steps, halves with it),
        and the tip loads set on its actuators."""
        for p in self.parts:
            p.check_derivable()
        half = System(self.spec.copy(), self.actuators, self.units, timestep=self.timestep / 2,
                      integrator=self.integrator, contact=self.contact, loaded=self.loaded)
        for p, q in zip(self.parts, half.parts):
            p.carry_loads(q)
        return half
