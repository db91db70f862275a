"""Actuators as MuJoCo components (:func:`attach`): a catalog (or user) actuator, with its
drive compiled in (:mod:`mjeap.drives.native`), placed into a user's ``MjSpec`` at a site,
body or frame, under a prefix. Its beam is discretised, damped and given a timestep exactly
as a one-actuator :class:`~mjeap.Scene` in the same orientation (its *twin*, built with the
mount's world rotation at the host's ``qpos0``), so an attached actuator moves as its Scene
does; :func:`add_transmission` couples its tip to a host joint. :class:`mjeap.System`
compiles the host with its attached actuators.
"""
from __future__ import annotations

import re
from dataclasses import dataclass
from typing import List, Optional

import mujoco
import numpy as np

from ..drives.native import NativeHandles
from ..engines.native import why_not as native_why_not
from ..errors import ParameterError, UnknownNameError
from ..model.fields import UNITS_FIELD
from .scene import DEFAULT_SEGMENTS, Scene
from ..units import DEFAULT_UNITS, UnitSystem

__all__ = ["attach", "add_transmission", "AttachedActuator", "check_spec", "host_gravity", "check_finite_model"]

_PREFIX = re.compile(r"^[A-Za-z][A-Za-z0-9_-]*$")


def check_spec(spec) -> mujoco.MjSpec:
    """``spec`` if it is a ``mujoco.MjSpec``; XML text, a path or anything else is refused
    naming how to make one."""
    if not isinstance(spec, mujoco.MjSpec):
        shown = (spec if len(spec) <= 60 else spec[:57] + "...") if isinstance(spec, str) else type(spec).__name__
        raise ParameterError("spec", shown, "a mujoco.MjSpec: mujoco.MjSpec.from_string(xml) for XML text, "
                             "mujoco.MjSpec.from_file(path) for a file")
    return spec


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
