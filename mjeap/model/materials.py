"""The materials library: the materials of the four sources and their companions, each
property with its value, unit, source and the range a layer's value is checked against.

A layer of an actuator file (:mod:`mjeap.model.actuator_file`) may name a material here; its
own values override the material's. A value outside the material's range is a warning
naming the file, key and range, one 1000 x outside it an error (:func:`check_value`). The
ranges span what the literature reports for the material class (grades, processing, the
effective values a source fitted), not a tolerance: a value outside is not impossible, but
worth a second look (a unit slip is usually orders of magnitude off).

A piezoelectric material also carries its datasheet constants (:class:`PiezoProperties`):
d31, the relative permittivity eps33^T / eps0, the coercive field, a recommended maximum
field and the tensile strength, each with its source. A ``role = "piezo"`` layer of a
``drive = "piezo"`` file takes d31 and the permittivity from its material where it gives none
(:mod:`mjeap.model.laminate`).

``mjeap materials`` lists them.
"""
from __future__ import annotations

import warnings
from dataclasses import dataclass
from typing import Dict, Optional, Tuple

from ..errors import ParameterError, UnknownNameError

__all__ = ["Property", "Material", "PiezoProperties", "MATERIALS", "get_material", "material_names", "check_value",
           "PROPERTIES", "PIEZO_PROPERTIES", "RangeWarning"]

#: the properties a layer takes from a material, with their SI units
PROPERTIES = {"youngs_modulus": "Pa", "density": "kg/m^3", "poisson_ratio": "-"}
#: a piezoelectric material's datasheet constants, with their SI units (the first two a
#: piezo layer takes from its material)
PIEZO_PROPERTIES = {"d31": "m/V", "relative_permittivity": "-", "coercive_field": "V/m", "max_field": "V/m",
                    "tensile_strength": "Pa"}

#: beyond this factor outside its material's range a value is an error, not a warning
HARD_FACTOR = 1000.0


class RangeWarning(UserWarning):
    """A layer's value lies outside its material's range (within HARD_FACTOR of it)."""


@dataclass(frozen=True)
class Property:
    """A value (SI, ``unit``) with its source and the range (low, high) values are checked against."""

    value: float
    unit: str
    source: str
    range: Tuple[float, float]


@dataclass(frozen=True)
class PiezoProperties:
    """A piezoelectric material's datasheet constants (:data:`PIEZO_PROPERTIES`): d31 (m/V,
    negative for a ceramic: it contracts in-plane under a field along its poling), the
    relative permittivity eps33^T / eps0 at constant stress (the free value a datasheet
    gives), the coercive field (V/m: a field this strong against the poling depolarises
    it), a recommended maximum field along the poling (V/m) and the tensile strength (Pa)."""

    d31: Property
    relative_permittivity: Property
    coercive_field: Property
    max_field: Property
    tensile_strength: Property


@dataclass(frozen=True)
class Material:
    """A material: its title and properties (:data:`PROPERTIES` keys; a piezoelectric one's
    datasheet constants in ``piezo``)."""

    name: str
    title: str
    youngs_modulus: Property
    density: Property
    poisson_ratio: Property
    notes: str = ""
    piezo: Optional[PiezoProperties] = None

    def property(self, key: str) -> Property:
        if key in PIEZO_PROPERTIES:
            if self.piezo is None:
                raise KeyError(f"{self.name} is not piezoelectric: it has no {key}")
            return getattr(self.piezo, key)
        return getattr(self, key)


_SEED_000 = "Dadras et al. 2021"
_SEED_001 = "Mutlu, Alici, Li 2013"
_SEED_002 = "Metello 2020, MSc thesis"
_SEED_003 = "Jayaram et al. 2018"
_HAMR = "Jafferis et al. 2015, as used by Harvard's HAMR actuator model (PZTBender2.m)"
_NU_POLY = Property(0.35, "-", "literature default for polymers", (0.25, 0.499))


def _m(name, title, E, rho, nu, notes="", piezo=None):
    """A Material from (value, source, range) triples of E (Pa), density (kg/m^3) and nu, and
    for a piezoelectric one a dict of such triples of :data:`PIEZO_PROPERTIES`."""
    nu = nu if isinstance(nu, Property) else Property(nu[0], "-", nu[1], nu[2])
    pz = None if piezo is None else PiezoProperties(
        **{k: Property(v[0], PIEZO_PROPERTIES[k], v[1], v[2]) for k, v in piezo.items()})
    return Material(name, title, Property(E[0], "Pa", E[1], E[2]), Property(rho[0], "kg/m^3", rho[1], rho[2]), nu,
                    notes, pz)


#: PZT-5H's datasheet, as Jayaram et al. 2018 used it (its permittivity gives their "about 16 nF")
_PSI_5H = ("Piezo Systems (piezo.com) Piezo Material Properties Data Sheet (2020), PZT-5H (CTS 3203HD prints the same "
           "K3T, d31 and Ec)")
_PSI_5A = ("Piezo Systems (piezo.com) Piezo Material Properties Data Sheet (2020), PZT-5A (CTS 3195HD: K3T 1900, "
           "d31 -190 pm/V, Ec 12 kV/cm)")
_PSI_STRENGTH = ("Piezo Systems' ceramic material properties: ultimate strength in tension 7.6e7 Pa static (2.1e7 Pa "
                 "dynamic, peak) for its PZT-5A and PZT-5H")
_MAX_FIELD_PZT = ("estimate: unipolar drive along the poling of soft PZT bending actuators reaches 1.5-2 V/um "
                  "(the Jayaram et al. 2018 bimorphs: 200 V on 135 um plates, 1.48 V/um); 2 V/um recommended")
_MSI = "Measurement Specialties, Piezo Film Sensors Technical Manual (1999), typical properties of PVDF film"


MATERIALS: Dict[str, Material] = {m.name: m for m in (
    _m("pzt-5h", "PZT-5H piezoceramic",
       (40e9, f"effective average modulus under drive, 40 GPa ({_HAMR}); small-signal Y11E is 62 GPa "
              "(manufacturer data)", (30e9, 80e9)),
       (7500.0, "manufacturer data (7500-7800 kg/m^3)", (7000.0, 8200.0)),
       (0.31, "manufacturer data", (0.25, 0.40)),
       "the moduli a bimorph's closed forms use are the effective large-signal ones (Wood 2005, Jafferis 2015)",
       piezo={"d31": (-320e-12, f"{_PSI_5H}: -320 pm/V (Erturk and Inman 2011, appendix E: -274 pm/V); the range "
                             "reaches the large-signal effective -800 pm/V of Jafferis et al. 2015's f31 = 32 Pa m/V on "
                             "40 GPa", (-900e-12, -150e-12)),
              "relative_permittivity": (3800.0, f"{_PSI_5H}: K3T = 3800 (Erturk and Inman 2011: 3400)",
                                        (2500.0, 5000.0)),
              "coercive_field": (0.8e6, f"{_PSI_5H}: Ec = 8 kV/cm", (0.4e6, 1.5e6)),
              "max_field": (2.0e6, _MAX_FIELD_PZT, (0.5e6, 3e6)),
              "tensile_strength": (76e6, _PSI_STRENGTH, (20e6, 150e6))}),
    _m("pzt-5a", "PZT-5A piezoceramic (small-signal datasheet values)",
       (66e9, f"{_PSI_5A}: Y11E = 6.6e10 Pa", (50e9, 80e9)),
       (7950.0, f"{_PSI_5A}: 7.95 g/cm^3 (Erturk and Inman 2011: 7750 kg/m^3)", (7500.0, 8100.0)),
       (0.31, f"{_PSI_5A}", (0.25, 0.40)),
       piezo={"d31": (-190e-12, f"{_PSI_5A}: -190 pm/V (Erturk and Inman 2011, appendix E: -171 pm/V)",
                      (-250e-12, -100e-12)),
              "relative_permittivity": (1800.0, f"{_PSI_5A}: K3T = 1800 (Erturk and Inman 2011: 1700)",
                                        (1200.0, 2500.0)),
              "coercive_field": (1.2e6, f"{_PSI_5A}: Ec = 12 kV/cm", (0.6e6, 2e6)),
              "max_field": (2.0e6, _MAX_FIELD_PZT, (0.5e6, 3e6)),
              "tensile_strength": (76e6, _PSI_STRENGTH, (20e6, 150e6))}),
    _m("pvdf-film", "poled PVDF piezo film (uniaxially drawn)",
       (3e9, f"{_MSI}: Young's modulus 2-4 GPa", (1e9, 5e9)),
       (1780.0, f"{_MSI}", (1700.0, 1900.0)),
       (0.35, "literature default for polymers", (0.25, 0.499)),
       "d31 along the draw direction; d32 is about a tenth of it (uniaxial film)",
       piezo={"d31": (23e-12, f"{_MSI}: d31 = 23e-12 m/V (positive for PVDF)", (5e-12, 40e-12)),
              "relative_permittivity": (12.0, f"{_MSI}: 12-13", (8.0, 16.0)),
              "coercive_field": (50e6, "literature: PVDF's coercive field ~ 50 MV/m", (30e6, 120e6)),
              "max_field": (30e6, f"{_MSI}: maximum operating field 30 V/um", (5e6, 80e6)),
              "tensile_strength": (160e6, f"{_MSI}: tensile strength 160-330 MPa (transverse-machine direction)",
                                   (50e6, 400e6))}),
    _m("stainless-steel", "stainless steel (unimorph substrates, shims)",
       (193e9, "handbook value (AISI 304: 193 GPa)", (180e9, 210e9)),
       (8000.0, "handbook value", (7700.0, 8100.0)),
       (0.29, "handbook value", (0.26, 0.31))),
    _m("brass", "brass (bender shims)",
       (100e9, "handbook value (97-110 GPa)", (80e9, 125e9)),
       (8500.0, "handbook value", (8300.0, 8800.0)),
       (0.34, "handbook value", (0.31, 0.36))),
    _m("carbon-fibre", "ultra-high-modulus carbon-fibre laminate (bimorph core)",
       (340e9, f"high-modulus carbon fibre ({_HAMR})", (50e9, 600e9)),
       (1550.0, "literature default for carbon-fibre/epoxy", (1400.0, 2000.0)),
       (0.3, "literature default", (0.2, 0.4))),
    _m("alumina", "alumina (Al2O3), bimorph tip blocks",
       (370e9, "literature: 300-400 GPa for 96-99.5 % alumina", (200e9, 450e9)),
       (3900.0, "literature default (3700-3980 kg/m^3)", (3500.0, 4100.0)),
       (0.22, "literature default", (0.18, 0.27))),
    _m("pedot-trilayer", "PEDOT:PSS/PEO | NBR-PEO IPN + EMImTFSI | PEDOT:PSS/PEO, whole stack (effective)",
       (4.19e9, f"effective: 12 EI / (w t^3) of {_SEED_000}'s identified EI on 1374 x 35 um", (0.1e9, 10e9)),
       (2409.0, f"effective: measured mass 0.695 mg / volume ({_SEED_000}, section IV)", (900.0, 3000.0)),
       _NU_POLY, "an effective layer: the source gives the whole stack only"),
    _m("polypyrrole", "polypyrrole (PPy), TFSI doped, electrolyte-soaked",
       (80e6, "literature default: E_PPy ~ 80 MPa (Sens. Actuators A 163 (2010) 240)", (10e6, 3e9)),
       (1400.0, "estimate: soaked density ~ 1.4 g/cm^3 (not in Mutlu et al. 2013)", (1000.0, 1700.0)),
       (0.3, "literature default (0.3)", (0.2, 0.45))),
    _m("pvdf-membrane", "porous PVDF membrane with LiTFSI/PC (PPy trilayer core)",
       (440e6, "literature default: E_PVDF membrane ~ 440 MPa (Alici's papers, unverified)", (50e6, 3e9)),
       (1400.0, "estimate: soaked density ~ 1.4 g/cm^3", (700.0, 1800.0)),
       (0.3, "literature default (0.3)", (0.2, 0.45))),
    _m("terpolymer", "P(VDF-TrFE-CTFE) relaxor terpolymer",
       (99.5e6, f"{_SEED_002}, Table 3.4 (9.95e7 Pa)", (30e6, 1e9)),
       (1780.0, f"{_SEED_002}, Table 5.2 (1.78 g/cm^3; Table 3.4 prints 1.7)", (1600.0, 1950.0)),
       (0.33, f"{_SEED_002}, Table 3.4", (0.25, 0.45))),
    _m("aluminium-foil", "aluminium foil electrode, as bonded in Metello 2020's unimorphs (effective)",
       (1.82e9, f"{_SEED_002}, Table 3.4 (1.82e9 Pa: the bonded foil's effective modulus; bulk aluminium is "
                "69 GPa)", (0.5e9, 75e9)),
       (2700.0, f"{_SEED_002}, Table 3.4", (2600.0, 2800.0)),
       (0.33, f"{_SEED_002}, Table 3.4", (0.3, 0.36))),
    _m("aluminium", "aluminium (bulk)",
       (69e9, "handbook value (68-71 GPa)", (60e9, 75e9)),
       (2700.0, "handbook value", (2600.0, 2800.0)),
       (0.33, "handbook value", (0.3, 0.36))),
    _m("kapton-tape", "Kapton polyimide tape, as in Metello 2020's unimorphs",
       (8.46e8, f"{_SEED_002}, Table 3.4 (8.46e8 Pa, the tape with its adhesive)", (0.3e9, 4e9)),
       (1420.0, f"{_SEED_002}, Table 3.4", (1300.0, 1500.0)),
       (0.34, f"{_SEED_002}, Table 3.4", (0.3, 0.4))),
    _m("kapton", "Kapton polyimide film",
       (2.5e9, "DuPont Kapton HN data sheet (2.5 GPa)", (1.5e9, 4e9)),
       (1420.0, "DuPont Kapton HN data sheet", (1380.0, 1450.0)),
       (0.34, "DuPont Kapton HN data sheet", (0.3, 0.4))),
    _m("pe-tape", "polyethylene adhesive tape",
       (4.66e8, f"{_SEED_002}, Table 3.4", (0.1e9, 2e9)),
       (920.0, f"{_SEED_002}, Table 3.4", (880.0, 980.0)),
       (0.46, f"{_SEED_002}, Table 3.4", (0.35, 0.49))),
    _m("gold", "gold (sputtered electrodes)",
       (79e9, "handbook value (bulk 79 GPa; thin films 50-80 GPa)", (40e9, 90e9)),
       (19300.0, "handbook value", (18000.0, 19400.0)),
       (0.42, "handbook value", (0.38, 0.45))),
)}


def material_names():
    return list(MATERIALS)


def get_material(name: str) -> Material:
    """The library's material ``name``; an unknown name suggests the closest."""
    try:
        return MATERIALS[name]
    except KeyError:
        raise UnknownNameError("material", str(name), MATERIALS) from None


def check_value(material: Optional[Material], key: str, value: float, where: str) -> None:
    """``value`` (SI) of ``key`` against ``material``'s range: outside it a
    :class:`RangeWarning`, more than :data:`HARD_FACTOR` outside it a ParameterError, both
    naming ``where`` (file and key) and the range. No material: nothing to check against.
    A piezoelectric constant is checked where the material has one; d31 by its magnitude,
    a sign opposite to the material's a warning (poling ``down`` is how a layer flips it)."""
    if material is None or (key not in PROPERTIES and not (key in PIEZO_PROPERTIES and material.piezo)):
        return
    p = material.property(key)
    lo, hi = p.range
    if key == "d31":
        if value * p.value < 0:
            warnings.warn(f"{where}={value:g} m/V has the opposite sign to {material.name}'s d31 "
                          f"({p.value:g} m/V, {p.source}); a layer poled the other way says poling = \"down\"",
                          RangeWarning, stacklevel=3)
        given, value, (lo, hi) = value, abs(value), sorted((abs(lo), abs(hi)))
    else:
        given = value
    if lo <= value <= hi:
        return
    far = value < lo / HARD_FACTOR or value > hi * HARD_FACTOR if key != "poisson_ratio" else \
        not (-1.0 < value < 0.5)
    text = (f"{where}={given:g} {p.unit} lies outside {material.name}'s range{' (magnitude)' if key == 'd31' else ''} "
            f"[{lo:g}, {hi:g}] {p.unit} "
            f"({p.source})")
    if far:
        raise ParameterError(where, value, f"a {key} near {material.name}'s range [{lo:g}, {hi:g}] {p.unit}",
                             f"more than {HARD_FACTOR:g} x outside it: check the unit" if key != "poisson_ratio"
                             else "a Poisson ratio lies in (-1, 0.5)")
    warnings.warn(text, RangeWarning, stacklevel=3)
