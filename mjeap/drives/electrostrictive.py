"""Electrostrictive terpolymer unimorph (Metello 2020).

Two models, chosen with ``model=``:

* ``eigenstrain`` (default): the active layer's free in-plane strain S = Q E^2, Q the
  electrostrictive field coefficient ``strain_coefficient`` (m^2/V^2), turned into a bending
  moment by the layer stack, M = E_a w_a S [(z_1 - z_c)^2 - (z_0 - z_c)^2] / 2. Q is a labelled,
  fitted parameter: least squares on 60PVDF's free tip displacements (Table 4.6, with its
  measured 0 V stiffness), then *predicting* 60PVDFHalf and 130PVDF
  (:func:`mjeap.validation.metello2020.fit_strain_coefficient` and the cross-validation
  rows of ``mjeap validate``).
* ``maxwell`` (thesis eqs. 3.7-3.11, as the thesis evaluates them in Table 3.8):
  strain S_m = eps0 eps_r E^2 / Y, stress sigma = Y S_m, axial force F_x = sigma L t_a,
  moment M = sigma I / z_c with I the layers' moments of inertia about the neutral axis
  summed (eq. 3.4, Table 3.7), tip force F_y = M / L. The textbook Maxwell stress is
  eps0 eps_r E^2 / 2; the thesis's Table 3.8 numbers (S_m = 0.0545 % at 11.67 MV/m) need the
  form without the 1/2, which is reproduced here. In the beam, M acts as a uniform internal
  moment.

E = V / t_active; the response is even in V (electrostriction). With ``stiffening=True``
(off by default) the hinge stiffness follows the measured load-displacement slopes (Tables
4.1-4.4) relative to 0 V, linearly interpolated in |E|: the thesis's empirical slopes, not
physics (the terpolymer carries 0.15 % / 0.6 % of the laminate's EI, so no change of its
modulus can double the beam's stiffness).
"""
from __future__ import annotations

from typing import Dict

import numpy as np

from ..errors import ParameterError
from .base import Drive, OpenLoop, register_drive

EPS0 = 8.8541878128e-12
_T = "Metello 2020"
#: measured tip stiffness (N/mm) at 0, 8.33, 11.67, 15 MV/m, Tables 4.1-4.4
SLOPES = {"pvdf-60": (4.70e-4, 1.01e-3, 1.19e-3, 1.16e-3),
          "pvdf-60-half": (2.80e-4, 5.70e-4, 6.00e-4, 6.20e-4),
          "pvdf-130": (6.00e-4, 3.57e-3, 4.53e-3, 4.92e-3)}
FIELDS = np.array([0.0, 8.33e6, 11.67e6, 15e6])
#: electrostrictive field coefficient Q (m^2/V^2) fitted on 60PVDF (Table 4.6, least squares
#: with its measured 0 V stiffness; re-fitted by tests/drives/test_pvdf_fidelity.py)
STRAIN_COEFFICIENT = 6.92e-17
_Q = (f"fitted: least squares on 60PVDF's free tip displacements ({_T}, Table 4.6) with its measured 0 V "
      "stiffness; predicts 60PVDFHalf and 130PVDF (mjeap validate, metello2020). About 50-100 x the "
      "in-plane coefficient the terpolymer literature implies (strains of a few % at ~150 MV/m)")


def section_moment_of_inertia(actuator) -> float:
    """Sum of the layers' second moments of area about the stack's neutral axis (m^4), each
    with its own width (thesis eq. 3.4, Table 3.7)."""
    return float(sum(actuator.section_at(0.0).layer_inertias))


def maxwell_stress_model(actuator, voltage: float, relative_permittivity: float = 45.0) -> Dict[str, float]:
    """The thesis's Maxwell-stress chain (eqs. 3.7-3.11) for a catalog unimorph, SI."""
    act = actuator
    active = act.layers[active_layer(act)]
    E = voltage / active.thickness
    S = EPS0 * relative_permittivity * E**2 / active.youngs_modulus
    sigma = active.youngs_modulus * S
    sec = act.section_at(0.0)
    M = sigma * section_moment_of_inertia(act) / sec.neutral_axis
    return {"field": E, "strain": S, "stress": sigma, "axial_force": sigma * act.length * active.thickness,
            "moment": M, "tip_force": M / act.length,
            "tip_deflection_thesis": (M / act.length) * act.length**3 / (3 * sec.flexural_rigidity)}


def eigenstrain_moment(actuator, strain: float) -> float:
    """Moment (N m) of a free in-plane strain of the active layer, multilayer beam."""
    sec = actuator.section_at(0.0)
    i = active_layer(actuator)
    z0, z1 = sec.interfaces[i] - sec.neutral_axis, sec.interfaces[i + 1] - sec.neutral_axis
    return sec.layer_moduli[i] * sec.layer_widths[i] * strain * (z1**2 - z0**2) / 2


def active_layer(actuator) -> int:
    """Index of the terpolymer layer in the stack."""
    return next(k for k, l in enumerate(actuator.layers) if l.role == "terpolymer")


@register_drive
class ElectrostrictiveDrive(OpenLoop, Drive):
    name = "electrostrictive"
    actuators = ("pvdf-60", "pvdf-60-half", "pvdf-130")
    ROLES = {"terpolymer": 1}
    GENERIC_PARAMETERS = {"strain_coefficient": (STRAIN_COEFFICIENT, "m^2/V^2", _Q),
                          "relative_permittivity": (45.0, "-", f"{_T}, Table 5.2 (terpolymer dielectric constant)"),
                          "model": ("eigenstrain", "-", "electrostrictive eigenstrain S = Q E^2"),
                          "stiffening": (False, "-", "no measured slopes for this actuator")}

    RANGES = {"relative_permittivity": (0.0, np.inf), "strain_coefficient": (0.0, np.inf)}

    def __init__(self, scene, **params):
        super().__init__(scene, **params)
        if self.params["model"] not in ("maxwell", "eigenstrain"):
            raise ParameterError("model", self.params["model"], "'maxwell' or 'eigenstrain'")
        self.model_used = {"maxwell": "thesis Maxwell-stress model, eqs. 3.7-3.11",
                           "eigenstrain": "electrostrictive eigenstrain S = Q E^2 in the layer stack"}[self.params["model"]]
        act = scene.actuator
        self.t_active = act.layers[active_layer(act)].thickness
        slopes = SLOPES.get(act.id)
        if self.params["stiffening"] and slopes is None:
            raise ParameterError("stiffening", True, "False for an actuator without measured slopes",
                                 f"{act.id} has none (only {', '.join(SLOPES)})")
        self.factors = None if (slopes is None or not self.params["stiffening"]) else np.array(slopes) / slopes[0]
        self._E = self._M = 0.0
        # both models are quadratic in V (Maxwell stress ~ E^2; eigenstrain ~ strain ~ E^2)
        self._M_per_V2 = self.moment(1.0)

    def strain(self, voltage: float) -> float:
        """Free in-plane strain of the active layer (-) at ``voltage`` (V)."""
        E = voltage / self.t_active
        if self.params["model"] == "maxwell":
            return maxwell_stress_model(self.scene.actuator, voltage, self.params["relative_permittivity"])["strain"]
        return float(self.params["strain_coefficient"]) * E * E

    def moment(self, voltage: float) -> float:
        """Drive moment (N m) at ``voltage`` (V)."""
        act = self.scene.actuator
        if self.params["model"] == "maxwell":
            return maxwell_stress_model(act, voltage, self.params["relative_permittivity"])["moment"]
        return eigenstrain_moment(act, self.strain(voltage))

    def stiffness_factor(self, field: float) -> float:
        return 1.0 if self.factors is None else float(np.interp(abs(field), FIELDS, self.factors))

    def reset(self, initial_curvature: float = 0.0) -> None:
        self.part.set_bending_stiffness_scale(1.0)
        self.part.set_internal_moments(0.0)
        self._v_last = None
        self._E = self._M = 0.0

    def closed_loop_reason(self):
        return None if self.factors is None else "field stiffening changes the beam's stiffness with the voltage"

    def native_reason(self):
        return ("its moment is quadratic in the voltage and a MuJoCo actuator's force is linear in ctrl: a native "
                "form would need ctrl = V^2 and break the convention that ctrl is the voltage in volts (the "
                "threaded engine runs it in C without Python per step)")

    def _moment_history(self, v):
        return np.repeat((self._M_per_V2 * v ** 2)[:, None], self.scene.layout.segments, axis=1)

    def step(self, voltage: float, dt: float) -> None:
        if voltage != self._v_last:  # the drive is static in V: recompute only on change
            self._E = voltage / self.t_active
            self._M = self._M_per_V2 * voltage * voltage
            self._f = self.stiffness_factor(self._E)
            self._v_last = voltage
        self.part.set_bending_stiffness_scale(self._f)
        self.part.set_internal_moments(self._M)

    def signals(self) -> Dict[str, float]:
        return {"field (V/m)": float(self._E), "drive_moment (N m)": float(self._M),
                "stiffness_factor (-)": float(self.part.stiffness_scale)}

    def small_signal(self, operating_voltage: float):
        """Quadratic in V, so linear about V0 with dM/dV = 2 M(1 V) V0 on every hinge (zero
        about 0 V). Its model draws no current. Field stiffening is refused (the beam's
        stiffness would follow the voltage)."""
        from .small_signal import SmallSignal
        v0 = self._operating_voltage(operating_voltage)
        if self.factors is not None:
            raise ParameterError("drive_params", "stiffening", "False for a small-signal model",
                                 "field stiffening makes the beam's stiffness a function of the voltage; run sine "
                                 "sweeps instead (mjeap.analysis.frequency.sine_sweep)")
        n = self.scene.layout.segments
        return SmallSignal(v0, "V", np.full(n, 2.0 * self._M_per_V2 * v0), current=False,
                           no_current="the electrostrictive drive (Metello 2020) models no current: its moment is "
                                      "the field's alone, with no charge or motional coupling in the model",
                           notes=f"dM/dV = 2 M(1 V) V0 = {2.0 * self._M_per_V2 * v0:.4g} N m/V at V0 = {v0:g} V")

    def reference_curvature(self, t, v, initial_curvature=0.0):
        """Quasi-static uniform curvature M(V) / (f(E) EI) of the continuum beam."""
        EI = float(self.scene.actuator.flexural_rigidity_at(0.0)[0])
        return np.array([self.moment(x) / (self.stiffness_factor(x / self.t_active) * EI) for x in v])
