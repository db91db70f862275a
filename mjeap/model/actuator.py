"""An actuator in SI, with the source of every number: its layers (bottom to top), planform,
damping, safe voltage range, measured overrides and its drive with that drive's parameters.
Derived quantities (neutral axis, EI, mass per length) come from
:func:`mjeap.model.section.multilayer_section` only."""
from __future__ import annotations

import weakref
from dataclasses import dataclass, field
from typing import Dict, Optional, Tuple

import numpy as np

from ..errors import ParameterError, check_positive
from .section import SectionLayer, SectionProperties, multilayer_section

__all__ = ["Layer", "Planform", "Sourced", "Actuator", "validate_actuator", "check_geometry", "GeometryWarning",
           "PLAUSIBLE", "MIN_SLENDERNESS"]

#: 8-point Gauss-Legendre nodes and weights on [-1, 1] (the layered mass's quadrature)
_GAUSS_8 = np.polynomial.legendre.leggauss(8)


@dataclass(frozen=True)
class Layer:
    """One layer, bottom to top. SI: thickness m, width m (None: follows the planform), E Pa,
    density kg/m^3. ``source`` applies to every number unless ``sources`` overrides a field."""

    name: str
    material: str
    thickness: float
    width: Optional[float]
    youngs_modulus: float
    poisson_ratio: float
    density: float
    source: str
    sources: Dict[str, str] = field(default_factory=dict)
    #: what a drive needs of the layer (piezo, core, terpolymer, electrode, ...; '' none)
    role: str = ""
    #: the materials library entry (mjeap.model.materials) it was made from, if any
    material_key: Optional[str] = None
    #: a piezo layer's own datasheet constants (None: its material's, mjeap.model.laminate):
    #: d31 (m/V) and the relative permittivity eps33^T / eps0
    d31: Optional[float] = None
    relative_permittivity: Optional[float] = None
    #: which voltage a piezo layer sees: 'signal' (the drive's V) or 'complement' (bias - V);
    #: None: 'signal'
    electrode: Optional[str] = None
    #: a piezo layer's poling, 'up' or 'down' (flips the sign of its free strain); None: 'up'
    poling: Optional[str] = None

    def provenance(self, field_name: str) -> str:
        return self.sources.get(field_name, self.source)


@dataclass(frozen=True)
class Planform:
    """Outline of the free (unclamped) beam, SI. Width varies linearly from ``base_width`` at
    the clamp to ``tip_width`` at ``length``; an inactive rigid extension of
    ``extension_length`` (mass ``extension_mass``) may continue past the active tip."""

    length: float
    base_width: float
    tip_width: float
    source: str
    extension_length: float = 0.0
    extension_mass: float = 0.0
    extension_source: str = "none"
    #: labelled residual: mass (kg) added to the tip block at fixed length, calibrated to a
    #: measured resonance (mjeap.analysis.calibration.calibrate_tip_mass); 0 = none
    residual_tip_mass: float = 0.0
    residual_source: str = "none"

    @property
    def tip_block_mass(self) -> float:
        """Mass of the rigid tip block (kg): its material and the calibrated residual."""
        return self.extension_mass + self.residual_tip_mass

    def width_at(self, x):
        """Planform width (m) at distance x (m) from the clamp."""
        return self.base_width + (self.tip_width - self.base_width) * np.asarray(x) / self.length


@dataclass(frozen=True)
class Sourced:
    """A number with its unit and where it comes from."""

    value: float
    unit: str
    source: str


@dataclass(frozen=True)
class Actuator:
    """An actuator. ``layers`` bottom to top; overrides replace derived values where a source
    identified them directly (e.g. the PEDOT beam's EI from its step response).
    ``Actuator.from_file(path)`` reads one from an actuator file and ``actuator.to_file(path)``
    writes it (:mod:`mjeap.model.actuator_file`, which provides both)."""

    id: str
    title: str
    document: str
    layers: Tuple[Layer, ...]
    planform: Planform
    damping_ratio: Sourced                 # first-mode modal damping ratio (-)
    voltage_range: Tuple[float, float]     # safe drive voltage (V), see voltage_source
    voltage_source: str
    flexural_rigidity: Optional[Sourced] = None   # overrides the layered EI (N m^2)
    mass: Optional[Sourced] = None                # overrides the layered mass (kg)
    plane_strain: Optional[bool] = None           # None: thesis rule width >= 5 thickness
    plane_strain_source: str = "thesis eq. 3.1 rule (width >= 5 x thickness)"
    notes: str = ""
    #: the drive that moves it (a registered drive's name; None: the drive whose source
    #: document describes it) and that drive's parameters: name -> (value SI, '', source)
    #: (the unit is the drive's own, :meth:`mjeap.drives.Drive.parameter_units`)
    drive: Optional[str] = None
    drive_parameters: Dict[str, tuple] = field(default_factory=dict)
    #: the actuator file it was read from (None: built in Python)
    source_file: Optional[str] = None

    # ---- derived quantities -------------------------------------------------------------
    def section_at(self, x: float) -> SectionProperties:
        """Layered cross-section at distance ``x`` (m) from the clamp."""
        w_plan = float(self.planform.width_at(x))
        return multilayer_section(
            [SectionLayer(l.thickness, w_plan if l.width is None else l.width,
                          l.youngs_modulus, l.poisson_ratio, l.density) for l in self.layers],
            plane_strain=self.plane_strain)

    @property
    def thickness(self) -> float:
        return float(sum(l.thickness for l in self.layers))

    @property
    def length(self) -> float:
        return self.planform.length

    def width_at(self, x):
        return self.planform.width_at(x)

    def flexural_rigidity_at(self, x) -> np.ndarray:
        """EI (N m^2) at x (m); the identified value where the source gives one."""
        x = np.atleast_1d(np.asarray(x, dtype=float))
        if self.flexural_rigidity is not None:
            return np.full_like(x, self.flexural_rigidity.value)
        return np.array([self.section_at(xi).flexural_rigidity for xi in x])

    def mass_per_length_at(self, x) -> np.ndarray:
        """Mass per length (kg/m) at x (m); scaled to the measured mass where one is given."""
        x = np.atleast_1d(np.asarray(x, dtype=float))
        mu = np.array([self.section_at(xi).mass_per_length for xi in x])
        if self.mass is not None:
            mu = mu * self.mass.value / self._layered_mass()
        return mu

    def _layered_mass(self) -> float:
        xg, wg = _GAUSS_8
        x = 0.5 * self.length * (xg + 1.0)
        return float(0.5 * self.length * np.sum(wg * [self.section_at(v).mass_per_length for v in x]))

    def total_mass(self) -> float:
        """Mass of the free length (kg), without the tip extension."""
        return self.mass.value if self.mass is not None else self._layered_mass()

    def actuator_mass(self) -> float:
        """The actuator's mass (kg): its free length and its rigid tip block (extension and
        residual mass). The one mass mjeap reports (the ``mass`` metric, ``mjeap show``)."""
        return self.total_mass() + self.planform.tip_block_mass


class GeometryWarning(UserWarning):
    """A size of an actuator lies outside the range mjeap's actuators plausibly have (its
    key named): a unit slip (a bare 60 is 60 m) or a design beyond the beam model."""


#: plausible sizes (SI, m) of the actuators mjeap models: outside them a GeometryWarning
PLAUSIBLE = {"length": (10e-6, 1.0), "width": (1e-6, 1.0), "thickness": (10e-9, 5e-3)}
#: the slenderness (length / total thickness) below which a GeometryWarning says the beam model
#: strains: under a tip force shear adds E h^2 / (4 kappa G L^2) ~ 0.8 (h/L)^2 to Euler-Bernoulli's
#: deflection (rectangle, kappa = 5/6, E/G = 2.6): 3 % at L/h = 5
MIN_SLENDERNESS = 5.0


#: the actuators whose implausible sizes were told (by id; the entry goes with the actuator)
_WARNED: "weakref.WeakValueDictionary" = weakref.WeakValueDictionary()


def check_geometry(act: "Actuator", where: Optional[str] = None) -> None:
    """The sizes of ``act`` against each other and against physics (``where``: the prefix
    of the keys named, e.g. the file): a ParameterError where the shape is no beam at all
    (a layer as thick as the beam is long or as it is wide, the stack as thick as the beam
    is long); a :class:`GeometryWarning` naming the key outside a plausible range
    (:data:`PLAUSIBLE`, :data:`MIN_SLENDERNESS`; a beam thicker than wide)."""
    import warnings
    p = act.planform
    pre = f"{act.id}." if where is None else where
    total = sum(l.thickness for l in act.layers)
    narrow = min(p.base_width, p.tip_width)
    for l in act.layers:
        key = f"{pre}layers.{l.name}.thickness"
        width = l.width if l.width is not None else narrow
        if l.thickness >= p.length:
            raise ParameterError(key, l.thickness, f"a thickness (m) below the beam's length {p.length:.4g} m",
                                 "a layer as thick as the beam is long is no beam; a bare number is SI (60 is 60 m, "
                                 "'60 um' is 60 um)")
        if l.thickness >= width:
            raise ParameterError(key, l.thickness, f"a thickness (m) below the layer's width {width:.4g} m",
                                 "a layer thicker than it is wide is no bending strip; a bare number is SI")
    if total >= p.length:
        raise ParameterError(f"{pre}layers (total thickness)", total, f"a stack thinner than the beam's length "
                             f"{p.length:.4g} m", "a bare number is SI")

    if _WARNED.get(id(act)) is act:          # told once per actuator (a file read, then its Scene built)
        return
    _WARNED[id(act)] = act

    def warn(key, value, text):
        warnings.warn(f"{key} = {value:.4g} m {text}", GeometryWarning, stacklevel=4)

    for key, value, kind in ([(f"{pre}planform.length", p.length, "length"),
                              (f"{pre}planform.base_width", p.base_width, "width"),
                              (f"{pre}planform.tip_width", p.tip_width, "width")]
                             + [(f"{pre}layers.{l.name}.thickness", l.thickness, "thickness") for l in act.layers]
                             + [(f"{pre}layers.{l.name}.width", l.width, "width") for l in act.layers
                                if l.width is not None]):
        lo, hi = PLAUSIBLE[kind]
        if not lo <= value <= hi:
            warn(key, value, f"lies outside the plausible {kind} of a bending actuator, [{lo:g}, {hi:g}] m: "
                             "a unit slip? (a bare number is SI)")
    if p.length / total < MIN_SLENDERNESS:
        warn(f"{pre}planform.length", p.length, f"is {p.length / total:.3g} x the stack's thickness ({total:.4g} m): "
             f"below {MIN_SLENDERNESS:g} a thick beam, whose shear deformation (~0.8 (h/L)^2 of the deflection "
             "under a tip force) the Euler-Bernoulli model leaves out")
    if narrow < total:
        warn(f"{pre}planform.{'tip_width' if p.tip_width < p.base_width else 'base_width'}", narrow,
             f"is narrower than the stack is thick ({total:.4g} m): the strip bends more easily sideways, out "
             "of the plane mjeap models")


def validate_actuator(act: Actuator, where: Optional[str] = None) -> Actuator:
    """Raise ParameterError naming the first non-positive size or property of ``act``, or a
    shape that is no beam (:func:`check_geometry`, which warns of implausible sizes)."""
    check_positive(f"{act.id}.planform.length", act.planform.length, "m")
    check_positive(f"{act.id}.planform.base_width", act.planform.base_width, "m")
    check_positive(f"{act.id}.planform.tip_width", act.planform.tip_width, "m")
    for l in act.layers:
        for f, unit in (("thickness", "m"), ("youngs_modulus", "Pa"), ("density", "kg/m^3")):
            check_positive(f"{act.id}.{l.name}.{f}", getattr(l, f), unit)
        if l.width is not None:
            check_positive(f"{act.id}.{l.name}.width", l.width, "m")
    if act.planform.extension_mass < 0 or act.planform.residual_tip_mass < 0:
        raise ParameterError(f"{act.id}.planform.extension_mass", act.planform.extension_mass,
                             "a non-negative tip-block mass (kg) and residual")
    for o in ("flexural_rigidity", "mass"):
        if getattr(act, o) is not None:
            check_positive(f"{act.id}.{o}", getattr(act, o).value, getattr(act, o).unit)
    check_geometry(act, where)
    return act
