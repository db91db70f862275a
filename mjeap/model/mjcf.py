"""MJCF model building: a clamped beam, its payload and options, as a ``mujoco.MjSpec``.

Two representations sit behind one interface, :class:`BeamBuilder`:

* ``hinge``: a planar chain of rigid links joined by damped hinge springs (Mutlu et al. 2013's
  16-link model, any N), built with MjSpec.
* ``cable``: MuJoCo's ``composite type="cable"`` with the ``mujoco.elasticity.cable``
  plugin (3D: bending in both directions and twist). The composite is expanded by MuJoCo's
  parser; each segment's geom then carries its own stiffness (the plugin computes E*I from
  the geom's box section, divided by the distance to the previous body) and each body an
  explicit inertial.

* ``rod``: a 1D ``flexcomp`` rod (discrete elastic rod, MuJoCo's replacement of the cable),
  in its own module, :mod:`mjeap.model.rod`.

All place their hinges by the midpoint rule of :mod:`mjeap.model.discretize`. Body frames: the
origin of link j is hinge j, local x runs along the beam, local y is the deflection
(thickness) direction and local z the hinge (width) axis. Everything is written in the
internal units of a :class:`~mjeap.units.UnitSystem`.

A builder owns everything that differs between representations, so that the rest of mjeap
asks it and a new beam type is one module: what it builds, which integrators it runs under
and whether they integrate its stiffness implicitly, how it is damped and linearised, which
what its model is in model terms (:attr:`BeamBuilder.capabilities`: a fixed tendon can sum its
bending, its moments are fixed generalised forces, ...; each engine or feature above words
its own refusal from them), and, through its
:class:`~mjeap.model.views.BeamView`, how its bending is read, set and driven in a compiled
model.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Dict, List, Optional, Tuple

import mujoco
import numpy as np

from .discretize import BeamLayout, Payload, block_inertia, clamp_rotation
from ..errors import ParameterError, UnknownNameError, check_registration
from ..units import UnitSystem

GRAVITY = 9.80665  # m/s^2

# What a beam's model is, in model terms (BeamBuilder.capabilities); the layers above read
# them and word their own refusals (a new engine names what it needs, not a new attribute here)
#: one scalar joint per hinge carries its bending, so a fixed tendon sums the hinges (the
#: compiled drive moments of mjeap.drives.native)
HINGE_TENDON = "one tendon per hinge"
#: a hinge moment is a constant generalised force on its dof (qfrc_applied), whatever the
#: configuration
FIXED_BENDING_FORCES = "fixed generalised bending forces"
#: its discretisation error follows the hinge chain's (order 2 in segments; the accuracy model)
HINGE_CHAIN_ERROR = "the hinge chain's discretisation error"
#: MjSpec.attach of its clamp body carries the whole beam into a host
ATTACHED_WHOLE = "attached whole with its clamp body"
CAPABILITIES = (HINGE_TENDON, FIXED_BENDING_FORCES, HINGE_CHAIN_ERROR, ATTACHED_WHOLE)
BEAM_RGBA = [0.2, 0.45, 0.8, 1.0]


@dataclass
class BeamHandles:
    """Names of what a builder made, for the scene to look up after compiling."""

    representation: str
    link_bodies: List[str]               # body of link j (origin at hinge j)
    joints: List[str]                    # joint of hinge j
    tip_body: str
    tip_site: str = "tip"
    #: massless body at the tip point: xfrc_applied acts at a body's centre of mass, so tip
    #: loads go here and stay exact dead loads at the tip as the beam rotates
    tip_load_body: str = "tip_load"
    clamp_body: str = "clamp"
    payload_body: Optional[str] = None
    extra: Dict[str, str] = field(default_factory=dict)


class BeamBuilder:
    """Interface: add a discretised beam under the clamp body of a spec, and say how it is
    simulated, damped and read (see the module docstring)."""

    representation: str = ""
    #: generalised dofs per hinge (sizes the MjData arena)
    dofs_per_hinge: int = 1
    #: the integrators it runs under, and the one a Scene takes when none is named
    integrators: Tuple[str, ...] = ("implicitfast", "discrete")
    default_integrator: str = "implicitfast"
    #: per-dof damping travels in the custom numeric mjeap_dof_damping (mjeap.simulation.scene), applied
    #: after compiling: MJCF has one damping per joint (the cable's ball joints)
    stores_dof_damping: bool = False
    #: the stability limit is also checked bent (Scene's max_bend): stiffness that couples
    #: once bent (the cable)
    check_bent_stability: bool = False
    #: per-hinge stiffness and damping can be set (mjeap.analysis.identify)
    per_hinge_parameters: bool = False
    #: what the model is, in model terms (HINGE_TENDON, FIXED_BENDING_FORCES, ...): the hinge
    #: chain is all of them
    capabilities: frozenset = frozenset(CAPABILITIES)
    #: for a capability it lacks, what the model is instead (model terms)
    instead: Dict[str, str] = {}

    def has(self, capability: str) -> bool:
        """Whether the model is ``capability`` (one of :data:`CAPABILITIES`, or a name a
        layer above asks about: absent unless the builder states it)."""
        return capability in self.capabilities

    def lacks(self, capability: str) -> Optional[str]:
        """None where the model has ``capability``; else what it is instead, in words."""
        if self.has(capability):
            return None
        return self.instead.get(capability, f"the {self.representation} representation does not state "
                                            f"'{capability}'")

    def unavailable_reason(self) -> Optional[str]:
        """Why this MuJoCo cannot run the representation (None: it can)."""
        return None

    def layout_reason(self, layout: BeamLayout) -> Optional[str]:
        """Why this beam cannot be built in the representation (None: it can)."""
        return None

    def integrator_reason(self, integrator: str) -> Optional[str]:
        """Why ``integrator`` does not run the representation (None: it does)."""
        if integrator in self.integrators:
            return None
        return f"the {self.representation} representation runs under {' or '.join(map(repr, self.integrators))}"

    def implicit_stiffness(self, integrator: str) -> bool:
        """Whether ``integrator`` integrates the beam's bending stiffness implicitly (backward
        Euler: it then damps each mode by omega h / 2 itself, Rayleigh damping with beta = h,
        and has no stability limit of its own)."""
        return False

    def skeleton_xml(self, layout: BeamLayout, units: UnitSystem) -> str:
        """XML placed inside the clamp body before parsing (composites must be parsed)."""
        return ""

    def extensions_xml(self) -> str:
        return ""

    def build(self, spec: mujoco.MjSpec, layout: BeamLayout, units: UnitSystem) -> BeamHandles:
        raise NotImplementedError

    def payload_host(self, layout: BeamLayout, handles: BeamHandles, payload: Payload) -> str:
        """The body that carries ``payload`` (its frame's origin at link j's start)."""
        return handles.link_bodies[layout.link_containing(min(payload.position, layout.length))]

    def set_damping(self, spec: mujoco.MjSpec, handles: BeamHandles, beta: float, per_hinge: np.ndarray,
                    dof_damping: Optional[np.ndarray] = None) -> None:
        """Damp the beam (internal units): stiffness-proportional with coefficient ``beta``
        (time), ``per_hinge`` the damping of each hinge that gives; ``dof_damping`` the
        Rayleigh damping per dof of the whole model where the builder stores it."""
        for name, b in zip(handles.joints, per_hinge):
            spec.joint(name).damping = [b, 0, 0]

    def finish(self, spec: mujoco.MjSpec, handles: BeamHandles, timestep: float) -> None:
        """Last settings once the timestep (internal) is chosen."""

    def linearize(self, model: mujoco.MjModel, handles: BeamHandles, layout: BeamLayout, units: UnitSystem,
                  angles: Optional[np.ndarray] = None):
        """Mass and stiffness matrices (:class:`mjeap.model.modes.Linearization`) in the beam's own
        coordinates, at its reference configuration or bent by ``angles`` (rad per hinge)."""
        from .modes import linearize
        if angles is None:
            return linearize(model)
        q = model.qpos0.copy()
        self.view(model, handles, layout, units).write_angles(q, angles)
        return linearize(model, qpos=q)

    def view(self, model: mujoco.MjModel, handles: BeamHandles, layout: BeamLayout, units: UnitSystem,
             prefix: str = "", find=None):
        """The :class:`~mjeap.model.views.BeamView` of this beam in a compiled model (names
        prefixed by ``prefix``; ``find(kind, name)`` looks an element up, refusing a
        missing one)."""
        raise NotImplementedError


def element_finder(model, prefix, find):
    if find is not None:
        return find

    def look(kind, name):
        i = mujoco.mj_name2id(model, kind, prefix + name)
        if i < 0:
            raise UnknownNameError(kind.name[6:].lower(), prefix + name, [])
        return i
    return look


def _mat2quat(R: np.ndarray) -> np.ndarray:
    q = np.zeros(4)
    mujoco.mju_mat2Quat(q, np.ascontiguousarray(R, dtype=float).ravel())
    return q


def set_inertial(body, mass, com_local, inertia, units: UnitSystem):
    body.explicitinertial = True
    body.mass = mass / units.mass
    body.ipos = np.asarray(com_local, dtype=float) / units.length
    body.inertia = np.asarray(inertia, dtype=float) / units.inertia


class HingeChainBuilder(BeamBuilder):
    """Planar chain: N links, N hinge springs about the local z axis."""

    representation = "hinge"
    dofs_per_hinge = 1
    per_hinge_parameters = True

    def implicit_stiffness(self, integrator):
        # under 'discrete' the joint springs are implicit (backward Euler)
        return integrator == "discrete"

    def view(self, model, handles, layout, units, prefix="", find=None):
        from .views import HingeView
        look = element_finder(model, prefix, find)
        return HingeView(model, np.array([look(mujoco.mjtObj.mjOBJ_JOINT, n) for n in handles.joints], dtype=int))

    def build(self, spec, layout, units):
        parent = spec.body("clamp")
        t = layout.thickness / units.length
        bodies, joints = [], []
        prev_x = 0.0
        for j in range(layout.segments):
            x0, x1 = layout.link_start[j], layout.link_end[j]
            b = parent.add_body(name=f"link{j}", pos=[(x0 - prev_x) / units.length, 0, 0])
            b.add_joint(name=f"hinge{j}", type=mujoco.mjtJoint.mjJNT_HINGE, axis=[0, 0, 1],
                        stiffness=[layout.hinge_stiffness[j] / units.rotational_stiffness, 0, 0],
                        springref=0.0)
            half = 0.5 * (x1 - x0) / units.length
            b.add_geom(name=f"link{j}", type=mujoco.mjtGeom.mjGEOM_BOX,
                       size=[half, 0.5 * t, 0.5 * layout.link_width[j] / units.length],
                       pos=[half, 0, 0], rgba=BEAM_RGBA, contype=0, conaffinity=0)
            set_inertial(b, layout.link_mass[j], [layout.link_com[j] - x0, 0, 0],
                          layout.link_inertia[j], units)
            bodies.append(b.name)
            joints.append(f"hinge{j}")
            parent, prev_x = b, x0
        return BeamHandles("hinge", bodies, joints, tip_body=bodies[-1])


class CableBuilder(BeamBuilder):
    """MuJoCo composite cable with the elasticity plugin (3D bending and twist)."""

    representation = "cable"
    dofs_per_hinge = 3          # ball joints
    prefix = "cable"
    stores_dof_damping = True
    check_bent_stability = True
    capabilities = frozenset({FIXED_BENDING_FORCES, ATTACHED_WHOLE})
    instead = {HINGE_TENDON: "the cable representation's hinges are ball joints (three dofs each), which a fixed "
                             "tendon cannot sum",
               HINGE_CHAIN_ERROR: "the cable's discretisation error is not measured (the plugin's stiffness per "
                                  "segment is not the hinge chain's)"}

    def unavailable_reason(self):
        from ..versions import MUJOCO_VERSION, cable_available
        if cable_available():
            return None
        return (f"MuJoCo {MUJOCO_VERSION} removed the cable plugin and <composite>: use representation='rod' "
                "(a 1D flexcomp rod, their replacement, mjeap.model.rod) or 'hinge'; the cable runs on MuJoCo 3.17")

    def set_damping(self, spec, handles, beta, per_hinge, dof_damping=None):
        super().set_damping(spec, handles, beta, per_hinge)
        if dof_damping is not None:
            from .fields import DOF_DAMPING_FIELD
            spec.add_numeric(name=DOF_DAMPING_FIELD, data=list(dof_damping))

    def view(self, model, handles, layout, units, prefix="", find=None):
        from .views import CableView
        look = element_finder(model, prefix, find)
        return CableView(model, np.array([look(mujoco.mjtObj.mjOBJ_JOINT, n) for n in handles.joints], dtype=int))

    def extensions_xml(self) -> str:
        return '<extension><plugin plugin="mujoco.elasticity.cable"/></extension>'

    def _reference_modulus(self, layout: BeamLayout) -> float:
        # effective modulus of the section, SI: E_ref * w * t^3 / 12 = EI at the first hinge
        return 12 * layout.hinge_stiffness[0] * layout.ds / (layout.hinge_width[0] * layout.thickness**3)

    def skeleton_xml(self, layout, units):
        ds = layout.ds
        # vertices: -ds/2 (body fixed in the clamp), then the hinges, then the tip
        xs = np.concatenate([[-0.5 * ds], layout.hinge_x, [layout.length]]) / units.length
        vertex = " ".join(f"{x:.12g} 0 0" for x in xs)
        E = self._reference_modulus(layout)
        G = E / (2 * (1 + layout.poisson_ratio))
        t = layout.thickness / units.length
        w = layout.hinge_width[0] / units.length
        return (
            f'<composite prefix="{self.prefix}" type="cable" vertex="{vertex}" initial="none">'
            f'<plugin plugin="mujoco.elasticity.cable">'
            f'<config key="twist" value="{G / units.pressure:.12g}"/>'
            f'<config key="bend" value="{E / units.pressure:.12g}"/>'
            f'<config key="vmax" value="0"/></plugin>'
            f'<joint kind="main" damping="0"/>'
            f'<geom type="box" size="1 {0.5 * t:.12g} {0.5 * w:.12g}" rgba="{" ".join(map(str, BEAM_RGBA))}"'
            f' contype="0" conaffinity="0"/>'
            f'</composite>')

    def build(self, spec, layout, units):
        N = layout.segments
        names = [f"{self.prefix}B_{k}" for k in range(1, N)] + [f"{self.prefix}B_last"]
        E = self._reference_modulus(layout)
        t = layout.thickness
        for j, name in enumerate(names):
            b = spec.body(name)
            # per-segment stiffness: the plugin uses E_ref * w_eq * t^3 / 12 for bending
            # about local z, so the geom width carries EI(x_j)
            w_eq = 12 * layout.hinge_stiffness[j] * layout.ds / (E * t**3)
            g = b.geoms[0]
            g.size = [g.size[0], 0.5 * t / units.length, 0.5 * w_eq / units.length]
            set_inertial(b, layout.link_mass[j], [layout.link_com[j] - layout.link_start[j], 0, 0],
                          layout.link_inertia[j], units)
        spec.body(f"{self.prefix}B_first").geoms[0].mass = 0.0
        joints = [spec.body(n).joints[0].name for n in names]
        # the skin that the composite adds is only a visual for capsules; drop it
        for skin in list(spec.skins):
            spec.delete(skin)
        return BeamHandles("cable", names, joints, tip_body=names[-1],
                           extra={"fixed_segment": f"{self.prefix}B_first"})


BUILDERS: Dict[str, BeamBuilder] = {"hinge": HingeChainBuilder(), "cable": CableBuilder()}


def _builder_lacks(builder) -> Optional[str]:
    """Why ``builder`` cannot be registered (None: it can)."""
    if not isinstance(builder, BeamBuilder):
        return ("a class, not an instance: register(MyBuilder())" if isinstance(builder, type)
                and issubclass(builder, BeamBuilder) else "not a BeamBuilder")
    missing = [m for m in ("build", "view") if getattr(type(builder), m) is getattr(BeamBuilder, m)]
    if missing:
        return f"its {' and '.join(missing)} {'are' if len(missing) > 1 else 'is'} BeamBuilder's, which builds nothing"
    d = builder.dofs_per_hinge
    if isinstance(d, bool) or not isinstance(d, (int, np.integer)) or d < 1:
        return f"its dofs_per_hinge is {d!r}, not an integer >= 1"
    if builder.default_integrator not in builder.integrators:
        return f"its default_integrator {builder.default_integrator!r} is not one of its integrators"
    return None


def register(builder: BeamBuilder, *, replace: bool = False) -> BeamBuilder:
    """Add a representation (its builder: an instance of a :class:`BeamBuilder` subclass
    that implements ``build`` and ``view``) to :data:`BUILDERS` under its ``representation``
    (letters, digits, '-', '_'; and its name to :data:`REPRESENTATIONS`; ``mjeap.model``
    imports every builder's module before anyone reads it). A name taken is refused unless
    ``replace``."""
    global REPRESENTATIONS
    check_registration("beam builder", BUILDERS, getattr(builder, "representation", None), builder,
                       lacks=_builder_lacks(builder), expected="an instance of a mjeap.model.mjcf.BeamBuilder "
                       "subclass that implements build and view, with a representation", replace=replace,
                       how="mjeap.model.mjcf.register")
    BUILDERS[builder.representation] = builder
    REPRESENTATIONS = tuple(BUILDERS)
    return builder


#: the representations' names, in the order they were registered
REPRESENTATIONS = tuple(BUILDERS)


def get_builder(representation: str, layout: Optional[BeamLayout] = None) -> BeamBuilder:
    """The builder of ``representation``, refused where this MuJoCo cannot run it (or, given
    ``layout``, where that beam cannot be built in it), naming the alternative."""
    try:
        builder = BUILDERS[representation]
    except KeyError:
        raise UnknownNameError("representation", str(representation), BUILDERS) from None
    why = builder.unavailable_reason()
    if why is not None:
        from ..versions import MUJOCO_VERSION
        ok = [r for r, b in BUILDERS.items() if b.unavailable_reason() is None]
        raise ParameterError("representation", representation,
                             f"{' or '.join(map(repr, ok))} on MuJoCo {MUJOCO_VERSION}", why)
    if layout is not None:
        why = builder.layout_reason(layout)
        if why is not None:
            raise ParameterError("representation", representation,
                                 "'hinge' for this beam" if representation != "hinge" else "another representation",
                                 f"{layout.actuator_id}: {why}")
    return builder


def arena_bytes(nv: int) -> int:
    """MjData arena (bytes) for a beam of ``nv`` dofs: no contacts or constraints, so the
    largest need is the finite-difference linearisation (mjd_transitionFD, one (2 nv)^2
    matrix of doubles on the stack), taken twice, plus 1 MiB. MuJoCo's own default sizes
    for legacy contact buffers (about 14 MiB per MjData), which these scenes never use."""
    return (1 << 20) + 2 * 8 * (2 * nv) ** 2


def _check_handles(builder: BeamBuilder, spec, layout: BeamLayout, handles) -> None:
    """Refuse what a builder's ``build`` returned where it is not :class:`BeamHandles` of one
    link body per segment, naming bodies the spec holds, naming the builder."""
    fail = None
    if not isinstance(handles, BeamHandles):
        fail = f"its build returned {type(handles).__name__}, not BeamHandles"
    elif not isinstance(handles.link_bodies, (list, tuple)) or len(handles.link_bodies) != layout.segments:
        fail = f"its build named link bodies {handles.link_bodies!r} for {layout.segments} segments"
    else:
        names = [handles.clamp_body, *handles.link_bodies, handles.tip_body]
        missing = [n for n in names if not isinstance(n, str) or spec.body(n) is None]
        if missing:
            fail = f"its build named bodies the model lacks: {', '.join(map(repr, missing[:3]))}"
    if fail is not None:
        raise ParameterError("representation", builder.representation, "a beam builder whose build returns "
                             "BeamHandles naming one link body per segment and the tip body of the spec", fail)


def build_spec(layout: BeamLayout, representation: str = "hinge", orientation: str = "horizontal",
               payload: Optional[Payload] = None, units: Optional[UnitSystem] = None,
               gravity: bool = True, model_name: Optional[str] = None):
    """MjSpec of a clamped beam (internal units) and the handles of its parts.

    Damping, timestep and integrator are set later by :mod:`mjeap.simulation.scene`, which derives
    them from the compiled model.
    """
    units = units or UnitSystem()
    builder = get_builder(representation, layout)
    R = clamp_rotation(orientation)
    quat = " ".join(f"{v:.12g}" for v in _mat2quat(R))
    L = layout.length / units.length
    t = layout.thickness / units.length
    w0 = layout.hinge_width[0] / units.length
    g = GRAVITY / units.acceleration if gravity else 0.0
    name = model_name or f"{layout.actuator_id}-{representation}-{orientation}"
    xml = f"""<mujoco model="{name}">
  <compiler angle="radian" autolimits="true"/>
  <option gravity="0 0 {-g:.12g}" tolerance="{units.solver_tolerance:.12g}"><flag contact="disable"/></option>
  <visual><global elevation="-20"/></visual>
  <statistic center="{0.5 * L * R[0, 0]:.6g} {0.5 * L * R[1, 0]:.6g} {0.5 * L * R[2, 0]:.6g}" extent="{1.5 * L:.6g}"/>
  {builder.extensions_xml()}
  <worldbody>
    <light pos="0 0 {3 * L:.6g}" dir="0 0 -1"/>
    <body name="clamp" quat="{quat}">
      <geom name="clamp" type="box" size="{0.08 * L:.6g} {max(3 * t, 0.04 * L):.6g} {0.6 * w0 + 0.02 * L:.6g}"
            pos="{-0.08 * L:.6g} 0 0" rgba="0.35 0.35 0.35 1" contype="0" conaffinity="0" mass="0"/>
      {builder.skeleton_xml(layout, units)}
    </body>
  </worldbody>
</mujoco>"""
    spec = mujoco.MjSpec.from_string(xml)
    spec.memory = arena_bytes(layout.segments * builder.dofs_per_hinge)
    handles = builder.build(spec, layout, units)
    _check_handles(builder, spec, layout, handles)
    tip = spec.body(handles.tip_body)
    tip_local = (layout.tip_x - layout.link_start[-1]) / units.length
    tip.add_site(name="tip", pos=[tip_local, 0, 0], size=[0.01 * L, 0, 0], rgba=[1, 0.3, 0.1, 1])
    set_inertial(tip.add_body(name=handles.tip_load_body, pos=[tip_local, 0, 0]), 0.0, [0, 0, 0], [0, 0, 0], units)
    if layout.extension_length > 0:
        x0 = (layout.length - layout.link_start[-1]) / units.length
        ext = tip.add_body(name="extension", pos=[x0, 0, 0])
        half = 0.5 * layout.extension_length / units.length
        ext.add_geom(type=mujoco.mjtGeom.mjGEOM_BOX, size=[half, 0.5 * t, 0.5 * layout.link_width[-1] / units.length],
                     pos=[half, 0, 0], rgba=[0.9, 0.9, 0.85, 1], contype=0, conaffinity=0)
        m = max(layout.extension_mass, 1e-6 * layout.link_mass[-1])
        set_inertial(ext, m, [layout.extension_length / 2, 0, 0],
                      block_inertia(m, layout.extension_length, layout.thickness, layout.link_width[-1]), units)
    if payload is not None:
        j = layout.link_containing(min(payload.position, layout.length))
        host = spec.body(builder.payload_host(layout, handles, payload))
        r = payload.sphere_radius
        pb = host.add_body(name="payload", pos=[(payload.position - layout.link_start[j]) / units.length, 0, 0])
        pb.add_geom(name="payload", type=mujoco.mjtGeom.mjGEOM_SPHERE, size=[r / units.length, 0, 0],
                    rgba=[0.75, 0.2, 0.2, 1], contype=0, conaffinity=0)
        set_inertial(pb, payload.mass, [0, 0, 0], [payload.inertia] * 3, units)
        handles.payload_body = "payload"
    return spec, handles
