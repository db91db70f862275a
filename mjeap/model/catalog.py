"""Catalog of the actuators of the four source documents, in SI, with the source of every number.

The data lives in plain dataclasses below (one block per actuator) so that it can be read
and reviewed without the builders. ``SEED_000`` etc. name the documents in
``shared/seeds``; "literature default" marks numbers the sources do not give.
Derived quantities (neutral axis, EI, mass per length) come from
:func:`mjeap.section.multilayer_section` only.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Dict, Optional, Tuple

import numpy as np

from ..errors import ParameterError, UnknownNameError, check_positive
from .section import SectionLayer, SectionProperties, multilayer_section

SEED_000 = "Dadras et al. 2021, IEEE JMEMS 30(3) (seed 000)"
SEED_001 = "Mutlu, Alici, Li 2013, IEEE/ASME AIM (seed 001)"
SEED_002 = "Metello 2020, MSc thesis (seed 002)"
SEED_003 = "Jayaram et al. 2018, Smart Mater. Struct. 27 065028 (seed 003)"


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
    #: measured resonance (mjeap.calibration.calibrate_tip_mass); 0 = none
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
    """A catalog actuator. ``layers`` bottom to top; overrides replace derived values where a
    source identified them directly (e.g. the PEDOT beam's EI from its step response)."""

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
        xg, wg = np.polynomial.legendre.leggauss(8)
        x = 0.5 * self.length * (xg + 1.0)
        return float(0.5 * self.length * np.sum(wg * [self.section_at(v).mass_per_length for v in x]))

    def total_mass(self) -> float:
        """Mass of the free length (kg), without the tip extension."""
        return self.mass.value if self.mass is not None else self._layered_mass()


def validate_actuator(act: Actuator) -> Actuator:
    """Raise ParameterError naming the first non-positive size or property of ``act``."""
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
    return act


# =========================================================================================
# Seed 000: PEDOT:PSS/PEO micro trilayer
# =========================================================================================
_PEDOT_IDENTIFIED_EI = 1.0 / 4.86e7
PEDOT_MICRO = Actuator(
    id="pedot-micro",
    title="PEDOT:PSS/PEO micro trilayer, 6000 x 1374 x 35 um",
    document=SEED_000,
    layers=(
        # The paper gives the whole stack only (no layer thicknesses or moduli); one
        # effective layer carries the geometry, EI and mass come from the paper below.
        Layer("trilayer", "PEDOT:PSS/PEO | NBR-PEO IPN + EMImTFSI | PEDOT:PSS/PEO",
              thickness=35e-6, width=None,
              youngs_modulus=12 * _PEDOT_IDENTIFIED_EI / (1374e-6 * 35e-6**3), poisson_ratio=0.35,
              density=0.695e-6 / (6000e-6 * 1374e-6 * 35e-6),
              source=SEED_000 + ", section IV (6000 x 1374 x 35 um)",
              sources={"youngs_modulus": "effective: 12 EI / (w t^3) from the identified EI (seed 000 eq. 8 gain)",
                       "poisson_ratio": "literature default for soft polymers (0.35); enters only the cable's twist",
                       "density": "effective: measured mass 0.695 mg / volume (seed 000, section IV)"}),
    ),
    planform=Planform(length=6000e-6, base_width=1374e-6, tip_width=1374e-6,
                      source=SEED_000 + ", section IV"),
    flexural_rigidity=Sourced(_PEDOT_IDENTIFIED_EI, "N m^2",
                              SEED_000 + ": identified mechanical gain 1/EI = 4.86e7 1/(N m^2)"),
    mass=Sourced(0.695e-6, "kg", SEED_000 + ", section IV: 0.695 +- 0.004 mg"),
    damping_ratio=Sourced(0.05, "-", "assumed (no value in the source)"),
    voltage_range=(-3.0, 3.0),
    voltage_source=SEED_000 + ", section I: operating voltages typically <= 3 V (citing its ref. [26])",
)

# =========================================================================================
# Seed 001: PPy trilayer, 16-link model
# =========================================================================================
_PPY_E = "literature default: E_PPy ~ 80 MPa (Sens. Actuators A 163 (2010) 240)"
_PPY_RHO = "estimate: soaked density ~ 1.4 g/cm^3 (not in the source)"
_PPY_NU = "literature default (0.3; not in the source)"
PPY_TRILAYER = Actuator(
    id="ppy-trilayer",
    title="PPy / porous PVDF / PPy trilayer, 20 x 3 x 0.17 mm",
    document=SEED_001,
    layers=(
        Layer("ppy-bottom", "polypyrrole (TFSI doped)", 30e-6, None, 80e6, 0.3, 1400.0,
              source=SEED_001 + ", section II (~30 um PPy each side)",
              sources={"youngs_modulus": _PPY_E, "density": _PPY_RHO, "poisson_ratio": _PPY_NU}),
        Layer("pvdf-membrane", "porous PVDF + LiTFSI/PC", 110e-6, None, 440e6, 0.3, 1400.0,
              source=SEED_001 + ", section II (110 um PVDF membrane)",
              sources={"youngs_modulus": "literature default: E_PVDF membrane ~ 440 MPa (Alici's papers, unverified)",
                       "density": _PPY_RHO, "poisson_ratio": _PPY_NU}),
        Layer("ppy-top", "polypyrrole (TFSI doped)", 30e-6, None, 80e6, 0.3, 1400.0,
              source=SEED_001 + ", section II (~30 um PPy each side)",
              sources={"youngs_modulus": _PPY_E, "density": _PPY_RHO, "poisson_ratio": _PPY_NU}),
    ),
    planform=Planform(length=20e-3, base_width=3e-3, tip_width=3e-3,
                      source=SEED_001 + ", section V (20 x 3 x 0.17 mm)"),
    damping_ratio=Sourced(0.05, "-", "assumed (the source identifies joint damping per voltage, Fig. 3, values not extractable)"),
    voltage_range=(-1.0, 1.0),
    voltage_source=SEED_001 + ", section V: inputs 0.25-1.00 V",
)

# =========================================================================================
# Seed 002: P(VDF-TrFE-CTFE) five-layer unimorphs
# =========================================================================================


def _pvdf(id_: str, title: str, t_active: float, w_full: float, w_el: float, slope_0v: float, table: str) -> Actuator:
    """``slope_0v``: the sample's measured tip stiffness at 0 V (N/m), which sets its EI =
    k L^3 / 3 (the layer model misses it by +23 / +7 / +95 %: adhesive layers and the clamp)."""
    src = SEED_002 + ", Tables 3.1, 3.3, 3.4"
    L = 52e-3
    return Actuator(
        id=id_, title=title, document=SEED_002,
        layers=(
            Layer("kapton", "Kapton tape", 57e-6, w_full, 8.46e8, 0.34, 1420.0, source=src),
            Layer("electrode-bottom", "aluminium foil", 55e-6, w_el, 1.82e9, 0.33, 2700.0, source=src),
            Layer("terpolymer", "P(VDF-TrFE-CTFE)", t_active, w_full, 9.95e7, 0.33, 1780.0, source=src,
                  sources={"density": SEED_002 + ", Table 5.2 (1.78 g/cm^3; Table 3.4 prints 1.7)"}),
            Layer("electrode-top", "aluminium foil", 55e-6, w_el, 1.82e9, 0.33, 2700.0, source=src),
            Layer("pe-tape", "PE adhesive tape", 50e-6, w_full, 4.66e8, 0.46, 920.0, source=src),
        ),
        planform=Planform(length=52e-3, base_width=w_full, tip_width=w_full,
                          source=SEED_002 + ", Table 3.4 (free length 52 mm; 10 mm more in the clamp)"),
        flexural_rigidity=Sourced(slope_0v * L**3 / 3, "N m^2",
                                  f"identified: 3 EI / L^3 = the measured 0 V load-displacement slope "
                                  f"{slope_0v * 1e-3:.3g} N/mm ({SEED_002}, {table}); the layer model (eqs. 3.1-3.6) "
                                  f"stays available as section_at()"),
        damping_ratio=Sourced(0.05, "-", "assumed (no value in the source)"),
        voltage_range=(-15e6 * t_active, 15e6 * t_active),
        voltage_source=SEED_002 + ": fields up to 15 MV/m tested (Table 4.6); electrostriction is even in V",
    )


PVDF_60 = _pvdf("pvdf-60", "60PVDF five-layer unimorph, 52 x 15 mm, 60 um terpolymer", 60e-6, 15e-3, 14e-3,
                0.470, "Table 4.1")
PVDF_60_HALF = _pvdf("pvdf-60-half", "60PVDFHalf five-layer unimorph, 52 x 8 mm, 60 um terpolymer", 60e-6, 8e-3, 7e-3,
                     0.280, "Table 4.2")
PVDF_130 = _pvdf("pvdf-130", "130PVDF five-layer unimorph, 52 x 15 mm, 130 um terpolymer", 130e-6, 15e-3, 14e-3,
                 0.600, "Table 4.3")

# =========================================================================================
# Seed 003: PZT-5H bimorphs (HAMR, RoboBee)
# =========================================================================================
# Physical parameter set. Table 1's f_r are unloaded clamped-free resonances, so nothing but
# the actuator itself is modelled. Moduli: the effective (large-signal average) values that
# Harvard's own HAMR actuator model uses for these bimorphs, not PZT-5H's small-signal 62 GPa.
_HAMR_MODEL = ("Jafferis et al. 2015, Smart Mater. Struct. 24 065023, as used by Harvard's HAMR actuator "
               "model (HarvardAgileRoboticsLab/drake, examples/HAMR-URDF/dev/Actuator/PZTBender2.m)")
_PZT_E = f"effective average modulus under drive, 40 GPa ({_HAMR_MODEL}; small-signal Y11E is 62 GPa)"
_PZT_RHO = "literature default: PZT-5H 7500 kg/m^3 (manufacturer data)"
_CF_E = f"high-modulus carbon fibre 340 GPa ({_HAMR_MODEL})"
_CF_RHO = "literature default: carbon-fibre/epoxy ~ 1550 kg/m^3"
_T1 = SEED_003 + ", Table 1 caption (total 320 um, each PZT layer 135 um)"
#: alumina density, literature default (kg/m^3)
ALUMINA_DENSITY = 3900.0
_ALUMINA = f"alumina, {ALUMINA_DENSITY:g} kg/m^3 (literature default), tip width x full thickness"
_TIP_HAMR = f"1.0 mm alumina tip ({_HAMR_MODEL}: lext = 1 mm on the 9.2 mm HAMR actuator)"
_TIP_HAMR_LARGE = _TIP_HAMR + "; assumed the same for Type I (no published value)"
_TIP_ROBOBEE = ("2.25 mm alumina tip: extension ratio 0.25 on the 9 mm RoboBee actuator (Jafferis et al. 2015 "
                "design rules, as in public design code with Table 1's Type III widths; secondary source)")
#: calibrated residual per type: tip-block mass at fixed length that brings the first mode to
#: Table 1's f_r (mjeap.calibration.calibrate_tip_mass; tests/test_pzt_fidelity.py re-fits it)
_RESIDUAL_SRC = ("calibrated residual: extra tip-block mass at fixed block length fitted to the Table 1 "
                 "resonance (mjeap.calibration.calibrate_tip_mass); leaves the static gains unchanged")


def _pzt(id_: str, title: str, w_tip: float, w_base: float, length: float, row: str, tip_length: float,
         tip_source: str, residual_mass: float) -> Actuator:
    pzt = dict(youngs_modulus=40e9, poisson_ratio=0.31, density=7500.0, source=_T1,
               sources={"youngs_modulus": _PZT_E, "density": _PZT_RHO,
                        "poisson_ratio": "literature default (0.31, manufacturer data)"})
    block = ALUMINA_DENSITY * w_tip * 320e-6 * tip_length
    return Actuator(
        id=id_, title=title, document=SEED_003,
        layers=(
            Layer("pzt-bottom", "PZT-5H", 135e-6, None, **pzt),
            Layer("carbon-fibre", "carbon fibre (UHM)", 50e-6, None, 340e9, 0.3, 1550.0,
                  source=_T1 + "; thickness = 320 - 2 x 135 um",
                  sources={"youngs_modulus": _CF_E, "density": _CF_RHO,
                           "poisson_ratio": "literature default (0.3)"}),
            Layer("pzt-top", "PZT-5H", 135e-6, None, **pzt),
        ),
        planform=Planform(length=length, base_width=w_base, tip_width=w_tip,
                          source=SEED_003 + f", Table 1 ({row})",
                          extension_length=tip_length, extension_mass=block,
                          extension_source=f"{tip_source}; mass: {_ALUMINA}",
                          residual_tip_mass=residual_mass, residual_source=_RESIDUAL_SRC),
        damping_ratio=Sourced(0.05, "-", "assumed (no value in the source)"),
        voltage_range=(0.0, 200.0),
        voltage_source=SEED_003 + ": unipolar drive, V_sig in [0, V_bias], bias 25-200 V",
        plane_strain=False,
        plane_strain_source="Wood 2005 / Jafferis 2015 bimorph formulas use Y11 directly",
    )


PZT_HAMR_LARGE = _pzt("pzt-hamr-large", "PZT-5H bimorph Type I (HAMR, large)", 1.35e-3, 7.75e-3, 10e-3, "Type I",
                      1.0e-3, _TIP_HAMR_LARGE, 10.18e-6)
PZT_HAMR_SMALL = _pzt("pzt-hamr-small", "PZT-5H bimorph Type II (HAMR, small)", 1.75e-3, 5.25e-3, 9.2e-3, "Type II",
                      1.0e-3, _TIP_HAMR, 1.835e-6)
PZT_ROBOBEE = _pzt("pzt-robobee", "PZT-5H bimorph Type III (RoboBee)", 0.5e-3, 1.75e-3, 9e-3, "Type III",
                   2.25e-3, _TIP_ROBOBEE, 7.111e-6)

CATALOG: Dict[str, Actuator] = {a.id: validate_actuator(a) for a in (
    PEDOT_MICRO, PPY_TRILAYER, PVDF_60, PVDF_60_HALF, PVDF_130,
    PZT_HAMR_LARGE, PZT_HAMR_SMALL, PZT_ROBOBEE)}


def get_actuator(name: str) -> Actuator:
    """Catalog entry by id; an unknown id raises with the closest ids suggested."""
    if isinstance(name, Actuator):
        return validate_actuator(name)
    try:
        return CATALOG[name]
    except KeyError:
        raise UnknownNameError("actuator", str(name), CATALOG) from None


def actuator_ids() -> list:
    return list(CATALOG)
