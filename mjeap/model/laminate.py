"""Piezoelectric laminates from datasheet constants: a layer stack with one or more piezo
layers anywhere in it (a unimorph, an asymmetric bimorph, a multilayer), wired to one drive
voltage V (SI throughout).

Each ``role = "piezo"`` layer j has d31 (m/V) and a relative permittivity eps33^T / eps0
(its own, :class:`~mjeap.model.actuator.Layer`, else its material's,
:mod:`mjeap.model.materials`), an electrode and a poling:

* ``electrode = "signal"`` (default): the layer's voltage is V_j = V; ``"complement"``:
  V_j = bias - V. A positive V_j drives the field V_j / t_j along +z (up the stack).
* ``poling = "up"`` (default) or ``"down"`` (p_j = +1 or -1): the field along the poling is
  p_j V_j / t_j; a negative one is a reverse field (the depolarisation risk).
* the layer's free in-plane strain is S_j = d31 p_j V_j / t_j (a ceramic's d31 < 0: it
  contracts under a field along its poling).

The beam (Euler-Bernoulli, perfect bonding, the transformed section of
:mod:`mjeap.model.section`): about the modulus-weighted neutral axis z_n, the free strains
bend the beam with the moment

    M(x, V) = sum_i Y_i w_i t_i S*_i (zbar_i - z_n)        (Timoshenko 1925 for a bimetal,
                                                            any stack; zbar_i a layer's mid-plane)

and stretch it with N = sum_i Y_i w_i t_i S*_i, which an inextensible beam does not carry.
Y_i is the stiffness's modulus: E / (1 - nu^2) under plane strain, else E. Plane strain
scales the free-strain stress too: a poled ceramic's in-plane free strain is equibiaxial
(d32 = d31), and with the width held (eps_2 = 0) the axial stress of a free strain S is
E S / (1 - nu) = Y (1 + nu) S, so S*_i = (1 + nu_i) S_i under plane strain and S_i
otherwise (the thin-film e31,f = d31 / (s11 + s12)). Both piezo drives do the same.

Electrically (charge per volt seen by the signal terminal; A_j the electrode area):

* free capacitance: sum_j eps0 eps_r A_j / t_j over the piezo layers (a stress-free layer,
  the datasheet's permittivity);
* clamped (dielectric) capacitance: sum_j (eps33^T - d31 e_j) A_j / t_j with e_j the
  layer's stress per field, d31 Y (uniaxial stress) or, under plane strain, twice
  d31 E / (1 - nu) (both in-plane directions held): the permittivity a layer bonded in a
  laminate sees at zero strain (Erturk and Inman 2011, eq. 3.55's eps33^S = eps33^T -
  d31^2 / s11^E for a beam). The motional current, Gamma dtheta/dt with Gamma = dM/dV,
  carries the direct effect, so a drive's dielectric term must be this one, not the free one.

A model's low-frequency charge per volt of the free actuator is then the clamped value plus
the bending charge sum_j Gamma_j^2 / k_j (the hinges' compliance); a real free laminate adds
the stretching charge (dN/dV)^2 / (sum Y w t) per length, which the inextensible beam lacks;
neither reaches the free value, since a bonded layer never strains freely
(:meth:`Laminate.charge_per_volt`).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Dict, List, Optional, Sequence, Tuple

import numpy as np

from . import materials as mat

__all__ = ["EPS0", "PiezoLayer", "piezo_layers", "laminate_reason", "Laminate", "FieldWarning"]

class FieldWarning(mat.RangeWarning):
    """A piezo layer is driven past its material's recommended field, or against its poling
    past its coercive field, somewhere in the voltage range (:meth:`Laminate.field_warnings`)."""


#: vacuum permittivity (F/m), CODATA 2018
EPS0 = 8.8541878128e-12
#: Gauss-Legendre nodes and weights on [-1, 1] for integrals along the beam
_GAUSS = np.polynomial.legendre.leggauss(24)


@dataclass(frozen=True)
class PiezoLayer:
    """One piezo layer of a stack, resolved: its index in the actuator's layers, d31 (m/V),
    relative permittivity (None: unknown), electrode ('signal' or 'complement'), poling
    ('up' or 'down'), where each constant comes from, and its material (for its limits)."""

    index: int
    name: str
    d31: Optional[float]
    relative_permittivity: Optional[float]
    electrode: str = "signal"
    poling: str = "up"
    sources: Dict[str, str] = field(default_factory=dict)
    material: Optional[str] = None

    @property
    def sign(self) -> float:
        """dV_j/dV: +1 for a signal layer, -1 for a complement one."""
        return 1.0 if self.electrode == "signal" else -1.0

    @property
    def polarity(self) -> float:
        """+1 poled up, -1 poled down."""
        return 1.0 if self.poling == "up" else -1.0

    def limit(self, key: str) -> Optional[Tuple[float, str]]:
        """(value, source) of its material's ``coercive_field``, ``max_field`` or
        ``tensile_strength``; None where the material gives none."""
        if self.material is None:
            return None
        m = mat.get_material(self.material)
        if m.piezo is None:
            return None
        p = m.property(key)
        return p.value, f"material {m.name}: {p.source}"


def piezo_layers(actuator) -> List[PiezoLayer]:
    """The actuator's ``role = "piezo"`` layers, bottom to top, each constant its own where
    the file gives one, else its material's (None where neither does)."""
    out = []
    for i, l in enumerate(actuator.layers):
        if l.role != "piezo":
            continue
        m = mat.get_material(l.material_key) if l.material_key else None
        pz = m.piezo if m is not None else None
        src = {}
        vals = {}
        for k in ("d31", "relative_permittivity"):
            v = getattr(l, k)
            if v is not None:
                vals[k], src[k] = v, l.provenance(k)
            elif pz is not None:
                p = getattr(pz, k)
                vals[k], src[k] = p.value, f"material {m.name}: {p.source}"
            else:
                vals[k] = None
        out.append(PiezoLayer(i, l.name, vals["d31"], vals["relative_permittivity"], l.electrode or "signal",
                              l.poling or "up", src, m.name if pz is not None else None))
    return out


def laminate_reason(actuator, bias: Optional[float], *, permittivity: bool = True,
                    need_bias: bool = True) -> Optional[str]:
    """Why ``actuator``'s stack is no piezo laminate a drive can run (None: it is): no piezo
    layer, a piezo layer without d31 (or, where ``permittivity``, without a relative
    permittivity) from the file or its material, a complement layer without a ``bias``
    (where ``need_bias``: the bias is known), or a coupling d31^2 Y >= eps33^T (no positive
    clamped permittivity). Each names the key."""
    layers = piezo_layers(actuator)
    if not layers:
        return (f"it needs at least one 'piezo' layer (role = \"piezo\"); {actuator.id} has "
                + ", ".join(f"{l.name} ({l.role or 'no role'})" for l in actuator.layers))
    lib = ", ".join(n for n in mat.material_names() if mat.get_material(n).piezo is not None)
    for p in layers:
        if p.d31 is None:
            return (f"layers.{p.name}.d31 is missing: give d31 (e.g. \"-320 pm/V\") or e31 (C/m^2), or a piezo "
                    f"material that has them ({lib})")
        if permittivity and p.relative_permittivity is None:
            return (f"layers.{p.name}.relative_permittivity is missing: give eps33^T / eps0 (e.g. 3800), or a piezo "
                    f"material that has it ({lib})")
        if p.electrode == "complement" and bias is None and need_bias:
            return (f"layers.{p.name}.electrode is \"complement\" (it sees bias - V) but no bias is given: set bias "
                    "under [drive.parameters]")
        if permittivity:
            layer = actuator.layers[p.index]
            k2 = p.d31 ** 2 * layer.youngs_modulus / (EPS0 * p.relative_permittivity)
            if not k2 < 1.0:
                return (f"layers.{p.name}: d31^2 Y / eps33^T = {k2:.3g} >= 1 (d31 {p.d31:g} m/V, Y "
                        f"{layer.youngs_modulus:g} Pa, eps_r {p.relative_permittivity:g}): no positive clamped "
                        "permittivity; check the units of d31 (pm/V) and the permittivity (relative)")
    return None


class Laminate:
    """A layer stack with its piezo layers wired to the drive voltage V (module text):
    moments, stretching, fields, stresses and capacitances, in closed form.

    ``layers``: the piezo layers (:func:`piezo_layers`, or a drive's equivalent ones);
    ``bias``: the complement layers' bias (V)."""

    def __init__(self, actuator, layers: Sequence[PiezoLayer], bias: Optional[float] = None):
        self.actuator = actuator
        self.piezo = list(layers)
        self.bias = 0.0 if bias is None else float(bias)
        n = len(actuator.layers)
        t = np.array([l.thickness for l in actuator.layers])
        # every layer's free strain S_i = a_i V + b_i (zero in the passive ones)
        self.strain_per_volt, self.strain_offset = np.zeros(n), np.zeros(n)
        for p in self.piezo:
            k = p.d31 * p.polarity / t[p.index]
            self.strain_per_volt[p.index] = k * p.sign
            self.strain_offset[p.index] = k * (self.bias if p.electrode == "complement" else 0.0)
        self._nu = np.array([l.poisson_ratio for l in actuator.layers])
        self._sections = {}

    # ---------------------------------------------------------------- mechanics
    def _section(self, x: float):
        x = float(x)
        if x not in self._sections:
            self._sections[x] = self.actuator.section_at(x)
        return self._sections[x]

    def _weights(self, x: float):
        """(section, Y_i w_i t_i S*_i / S_i per layer, mid-plane heights above z_n) at x."""
        sec = self._section(x)
        z = np.asarray(sec.interfaces)
        t = np.diff(z)
        factor = (1.0 + self._nu) if sec.plane_strain else 1.0
        ywt = np.asarray(sec.layer_moduli) * np.asarray(sec.layer_widths) * t * factor
        return sec, ywt, 0.5 * (z[:-1] + z[1:]) - sec.neutral_axis

    def moment(self, x: float) -> Tuple[float, float]:
        """(dM/dV (N m/V), M at V = 0 (N m)) of the section at ``x`` (m from the clamp):
        M = sum_i Y_i w_i t_i S*_i (zbar_i - z_n) (module text)."""
        _, ywt, arm = self._weights(x)
        k = ywt * arm
        return float(k @ self.strain_per_volt), float(k @ self.strain_offset)

    def stretch(self, x: float) -> Tuple[float, float]:
        """(dN/dV (N/V), N at V = 0 (N)): the axial force the free strains would exert on a
        beam held at zero strain, sum_i Y_i w_i t_i S*_i (an inextensible beam does not
        carry it; a free one stretches by N / sum Y w t)."""
        _, ywt, _ = self._weights(x)
        return float(ywt @ self.strain_per_volt), float(ywt @ self.strain_offset)

    def layer_voltages(self, v) -> np.ndarray:
        """(piezo layers, len(v)) voltage V_j (V) of each piezo layer at drive voltages ``v``."""
        v = np.atleast_1d(np.asarray(v, float))
        return np.array([p.sign * v + (self.bias if p.electrode == "complement" else 0.0) for p in self.piezo])

    def fields_along_poling(self, v) -> np.ndarray:
        """(piezo layers, len(v)) field along each layer's poling (V/m): p_j V_j / t_j
        (negative: a reverse field)."""
        t = np.array([self.actuator.layers[p.index].thickness for p in self.piezo])
        pol = np.array([p.polarity for p in self.piezo])
        return self.layer_voltages(v) * (pol / t)[:, None]

    def max_field(self, v) -> Tuple[float, str]:
        """(largest |field| (V/m) in any piezo layer over the voltages ``v``, that layer's name)."""
        f = np.abs(self.fields_along_poling(v)).max(axis=1)
        j = int(np.argmax(f))
        return float(f[j]), self.piezo[j].name

    def max_reverse_field(self, v) -> Tuple[float, str]:
        """(largest field against the poling (V/m, >= 0) over the voltages ``v``, its layer)."""
        f = np.maximum(-self.fields_along_poling(v), 0.0).max(axis=1)
        j = int(np.argmax(f))
        return float(f[j]), self.piezo[j].name

    def field_warnings(self, v_range) -> List[str]:
        """The fields past a layer's limits over the voltages ``v_range`` (V), as texts naming
        the layer and the field: along the poling beyond its material's recommended maximum
        field, against it beyond the coercive field (where the material gives them)."""
        out = []
        v_range = np.asarray(v_range, float)
        f = self.fields_along_poling(v_range)
        where = f"over the voltage range [{v_range.min():g}, {v_range.max():g}] V"
        for j, p in enumerate(self.piezo):
            top, rev = float(np.abs(f[j]).max()), float(np.maximum(-f[j], 0.0).max())
            lim = p.limit("max_field")
            if lim is not None and top > lim[0] * (1 + 1e-9):
                out.append(f"layer {p.name} sees {top / 1e6:.3g} V/um {where}, past its recommended "
                           f"{lim[0] / 1e6:.3g} V/um ({lim[1]})")
            ec = p.limit("coercive_field")
            if ec is not None and rev > ec[0] * (1 + 1e-9):
                out.append(f"layer {p.name} sees {rev / 1e6:.3g} V/um against its poling {where}, past its "
                           f"coercive field {ec[0] / 1e6:.3g} V/um: it depolarises ({ec[1]})")
        return out

    def stress_coefficients(self, x: float) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(d sigma / d kappa, d sigma / dV, sigma at kappa = V = 0), each (layers, 2): the axial
        stress (Pa) at each layer's bottom and top fibre of the section at ``x``, for a
        curvature kappa (1/m, + bending towards +y) and drive voltage V, the beam free to
        stretch: sigma = Y_i (eps_0 + kappa (z - z_n)) - Y_i S*_i / S_i x S_i, with the stretch
        eps_0 = N / sum Y w t that leaves no axial force."""
        sec, ywt, _ = self._weights(x)
        z = np.asarray(sec.interfaces)
        Y = np.asarray(sec.layer_moduli)
        factor = (1.0 + self._nu) if sec.plane_strain else 1.0
        axial = float(np.sum(np.asarray(sec.layer_moduli) * np.asarray(sec.layer_widths) * np.diff(z)))
        faces = np.stack([z[:-1], z[1:]], axis=1) - sec.neutral_axis
        dk = Y[:, None] * faces
        dv = Y * (float(ywt @ self.strain_per_volt) / axial - factor * self.strain_per_volt)
        c0 = Y * (float(ywt @ self.strain_offset) / axial - factor * self.strain_offset)
        return dk, np.repeat(dv[:, None], 2, axis=1), np.repeat(c0[:, None], 2, axis=1)

    # ---------------------------------------------------------------- the beam's closed forms
    def _along(self):
        """Gauss nodes x (m) and weights on [0, L]."""
        L = self.actuator.length
        xg, wg = _GAUSS
        return 0.5 * L * (xg + 1.0), 0.5 * L * wg

    def free_deflection(self, v: float) -> float:
        """Quasi-static tip deflection (m, small deflections) at the tip block's end for the
        drive voltage ``v`` (V), from the straight beam: the unit-load integral
        int_0^L kappa(x) (L + l_e - x) dx with kappa = M(x, V) / EI(x)."""
        x, w = self._along()
        tip = self.actuator.length + self.actuator.planform.extension_length
        kappa = np.array([(g * v + m0) for g, m0 in (self.moment(xi) for xi in x)]) / \
            self.actuator.flexural_rigidity_at(x)
        return float(np.sum(w * kappa * (tip - x)))

    def tip_compliance(self) -> float:
        """Tip deflection per tip force (m/N) at the tip block's end: int_0^L (L + l_e - x)^2 /
        EI(x) dx (the unit-load method)."""
        x, w = self._along()
        tip = self.actuator.length + self.actuator.planform.extension_length
        return float(np.sum(w * (tip - x) ** 2 / self.actuator.flexural_rigidity_at(x)))

    def blocked_force(self, v: float) -> float:
        """Force (N) at the tip block's end that holds the tip at zero deflection under
        ``v`` (V): free deflection / tip compliance, the sign of the free deflection."""
        return self.free_deflection(v) / self.tip_compliance()

    # ---------------------------------------------------------------- electrical
    def electrode_areas(self, weight=None) -> np.ndarray:
        """Each piezo layer's electrode area (m^2), int w_j(x) dx; ``weight(x, j)`` multiplies
        the integrand."""
        x, w = self._along()
        out = []
        for j, p in enumerate(self.piezo):
            layer = self.actuator.layers[p.index]
            width = np.full_like(x, layer.width) if layer.width is not None else self.actuator.width_at(x)
            k = 1.0 if weight is None else np.array([weight(xi, j) for xi in x])
            out.append(float(np.sum(w * width * k)))
        return np.array(out)

    def free_capacitance(self) -> float:
        """Charge per volt (F) of the piezo layers the signal terminal drives, each at its
        free (constant-stress) permittivity: sum_j eps0 eps_r A_j / t_j."""
        t = np.array([self.actuator.layers[p.index].thickness for p in self.piezo])
        eps = np.array([EPS0 * p.relative_permittivity for p in self.piezo])
        return float(np.sum(eps * self.electrode_areas() / t))

    def clamped_capacitance(self) -> float:
        """Charge per volt (F) with the laminate held at zero strain: sum_j (eps33^T - d31 e_j)
        A_j / t_j (module text); e_j = d31 Y uniaxially, 2 d31 E / (1 - nu) under plane strain."""
        def eps_clamped(x, j):
            p = self.piezo[j]
            layer = self.actuator.layers[p.index]
            if self._section(x).plane_strain:
                coupling = 2.0 * p.d31 ** 2 * layer.youngs_modulus / (1.0 - layer.poisson_ratio)
            else:
                coupling = p.d31 ** 2 * layer.youngs_modulus
            return EPS0 * p.relative_permittivity - coupling
        t = np.array([self.actuator.layers[p.index].thickness for p in self.piezo])
        return float(np.sum(self.electrode_areas(eps_clamped) / t))

    def charge_per_volt(self) -> Dict[str, float]:
        """The low-frequency charge per volt (F) of the free actuator, four ways: ``clamped``
        (:meth:`clamped_capacitance`), ``beam`` (clamped + int (dM/dV)^2 / EI dx, what the
        inextensible beam model gives), ``laminate`` (beam + int (dN/dV)^2 / (sum Y w t) dx:
        free to stretch too) and ``free`` (:meth:`free_capacitance`)."""
        x, w = self._along()
        n = np.array([self.stretch(xi)[0] for xi in x])
        ea = np.array([float(np.sum(np.asarray(s.layer_moduli) * np.asarray(s.layer_widths)
                                    * np.diff(np.asarray(s.interfaces)))) for s in map(self._section, x)])
        clamped = self.clamped_capacitance()
        beam = clamped + self.bending_charge_per_volt()
        return {"clamped": clamped, "beam": beam, "laminate": beam + float(np.sum(w * n ** 2 / ea)),
                "free": self.free_capacitance()}

    def bending_charge_per_volt(self) -> float:
        """The motional charge per volt (F) of the free beam at rest under a static voltage:
        int (dM/dV)^2 / EI dx (reciprocity: the charge Gamma theta of the rotation Gamma V / k)."""
        x, w = self._along()
        g = np.array([self.moment(xi)[0] for xi in x])
        return float(np.sum(w * g ** 2 / self.actuator.flexural_rigidity_at(x)))
