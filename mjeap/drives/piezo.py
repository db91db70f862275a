"""PZT-5H bending bimorph under unipolar simultaneous drive (Jayaram et al. 2018).

A constant bias V_bias sits across the outer electrodes and the drive signal V_sig in
[0, V_bias] on the centre layer, so the two plates see V_bias - V_sig and V_sig, and the
bending follows V_eff = V_sig - V_bias / 2.

Moment per volt, derived three ways (they agree; the factor was 1/2 before issue 22):

1. Plate forces (Wood et al. 2005, Jafferis et al. 2015): a plate at voltage V_i carries the
   effective stress f31 V_i / t_p, a force per width f31 V_i, at (t_p + t_cf) / 2 from the
   symmetric bimorph's mid-plane. The plates bend oppositely, so at a section of width w

       M = f31 w (t_p + t_cf) (V_sig - (V_bias - V_sig)) / 2 = f31 w (t_p + t_cf) V_eff.

   Harvard's HAMR actuator model (PZTBender2.m) writes the same as forces Ft - Fb that are
   proportional to the plates' voltage difference V = 2 V_sig - V_bias, which is the V of
   the closed forms in ``mjeap.model.analytical`` (V_bias at full drive).
2. Jayaram et al. 2018 eq. (13): I_mech = 2 A f31 d(eps_1)/dt, eps_1 the bending strain of one plate,
   kappa (t_p + t_cf) / 2 at its mid-plane. Over a hinge j of width w_j and rotation theta_j
   (A eps_1 summed as w_j l_j kappa_j (t_p + t_cf)/2 = w_j theta_j (t_p + t_cf) / 2):
   I_mech = sum_j Gamma_j dtheta_j/dt with Gamma_j = f31 w_j (t_p + t_cf).
3. Reciprocity: the motional current's coefficient is dM_j/dV_sig (the electromechanical
   energy balance; ``tests/drives/test_piezo_moment.py`` checks it over a driven cycle).

So Gamma_j = f31 w_j (t_p + t_cf) N m/V per hinge and M_j = Gamma_j V_eff: the curvature
M / (D w) = f31 (t_p + t_cf) V_eff / D is uniform even on the trapezoidal planform.

Actuator current, eq. (1): I = (2 V_sig - V_bias) / (2 R) + C dV_sig/dt + I_mech, with
I_mech = sum_j Gamma_j dtheta_j/dt (the seed writes it as K(V_bias) v).

The instant of I_mech. A step holds V_k from t_k; MuJoCo's step (implicit damping, explicit
springs) is the leapfrog q_{k+1} = q_k + h v_{k+1}, whose velocity v_{k+1} = (q_{k+1} - q_k)/h
belongs to t_k + h/2: paired with V_k it leads by half a step, and V_k I_mech then carries a
relative power error of (h / 2 beta)(r^2 - 1), r = f / f_1 (-39 % at f_1/2 with h = beta, the
PZT default; trust issue, section 1). The rate at the held voltage's instant is the central
difference (q_{k+1} - q_{k-1}) / 2h = (v_k + v_{k+1}) / 2: with it the step map's electrical
work balances exactly what its dampers dissipate (multiply the step's equation by
(q_{k+1} - q_{k-1}) / 2: the mass and spring terms telescope over a period). So I_mech is
sum_j Gamma_j (v_j,k + v_j,k+1) / 2, the rates before and after the step the voltage was held
over; every engine reads it so (the threaded and native ones replay the step from the state
before it). ``tests/drives/test_piezo_power.py`` checks power and phase at 0.3 .. 2 f_1 against
converged runs and the per-cycle energy balance.

The instant of C dV/dt. The capacitive current belongs to the same instant t_k as V_k and
I_mech: the causal second-order difference (3 V_k - 4 V_{k-1} + V_{k-2}) / 2h, the slope at
t_k of the parabola through the last three voltages (its phase error is (omega h)^3 / 4, its
magnitude error (omega h)^2 / 3). The backward difference (V_k - V_{k-1}) / h is the slope at
t_k - h/2: beside I_mech at t_k it lagged by omega h / 2 (5.6 deg at 2 kHz on the RoboBee
actuator's 15.6 us step), which shows wherever the motional current is a small part of the
total: the fitted blocking factor of eq. 8 moved with the step (pzt-robobee's sweep to 2 f_1:
1.033 at h, 1.049 at h/4, 1.056 at h/16; now 1.0589 and 1.0593 at h and h/4) and a blocked
actuator's self-sensed stroke with it. Its real part omega^2 h / 2 also made the capacitor
do work over a cycle, 24 % of the motional power at f_1 / 2 on pzt-hamr-small (now 3e-4:
the second-order difference's real part is omega^4 h^3 / 4). Before the first step the first voltage is taken as
held (no current). The charge of a voltage step, sum_k h I_C,k = C (3/2 - 1/2) Delta V, is
C Delta V as with the backward difference, delivered over two steps (3/2 then -1/2 of it:
the parabola's slope overshoots a jump; tests/drives/test_piezo_power.py). A self-sensing
estimator must difference its own voltage samples the same way
(:mod:`mjeap.controllers.self_sensing`) for beta C_fit = C to cancel the dielectric current.
"""
from __future__ import annotations

from typing import Dict

import mujoco
import numpy as np

from ..model import analytical as an
from .base import Drive, NativeForm, OpenLoop, register_drive

_J = "Jafferis et al. 2015: f31 ~ 32 Pa m/V free (24 blocked)"
_C = ("estimate: Jayaram et al. 2018 measures about half the 16 nF datasheet value for a fixed HAMR actuator; "
      "8 nF scaled with the PZT area (Table 1)")
_R = "illustrative: the extracted fits of eq. 4a are unreliable (actuator reference); refit before use"


def _params(area_mm2: float):
    return {"bias": (200.0, "V", "Jayaram et al. 2018: 25-200 V tested"),
            "f31": (32.0, "Pa m/V", _J),
            "capacitance": (8e-9 * area_mm2 / 32.2, "F", _C),
            "resistance": (1e9, "ohm", _R)}


class LinearPiezo(OpenLoop, NativeForm, Drive):
    """What the piezo drives share (this module's text): moments linear in the held voltage,
    M_j = Gamma_j (V - V_0) at hinge j (or Gamma_j V + M0_j where the rest voltage differs
    from hinge to hinge), and the current of the voltage held over the last step at that
    voltage's instant: resistive, capacitive (C times the causal second-order difference)
    and motional (sum_j Gamma_j times the hinges' central rate). A subclass calls
    :meth:`_couple` from its ``__init__`` and gives :meth:`resistive_current`."""

    #: the voltage the drive's input is (its small-signal response is per volt of it)
    VOLTAGE_NAME = "V"

    def _couple(self, gamma, v0: float, m0=None, capacitance: float = 0.0) -> None:
        """Gamma_j (N m/V per hinge), the rest voltage V_0 (V), per-hinge offsets M0_j (N m;
        None: M_j = Gamma_j (V - V_0)) and the dielectric capacitance (F)."""
        n = self.scene.layout.segments
        self.gamma = np.asarray(gamma, float)
        self._v0, self._m0, self._capacitance = float(v0), None if m0 is None else np.asarray(m0, float), \
            float(capacitance)
        self._v_prev = self._v_prev2 = None     # the voltages held over the last two steps, V
        self._v = self._dv = 0.0
        self._m = np.zeros(n)
        self._rates = np.zeros(n)
        self._rates_before = np.zeros(n)
        self._i_before = None                   # whether _rates_before holds the rates before the last step

    def rest_voltage(self) -> float:
        """The voltage at which the drive applies no moment (V_0)."""
        return self._v0

    def reset(self, initial_curvature: float = 0.0) -> None:
        self._v_prev = self._v_prev2 = None
        self._v = self.rest_voltage()
        self._dv = 0.0
        self.part.set_internal_moments(0.0)
        self._m[:] = 0.0                        # per-hinge moment, N m, written in place
        self._i_before = None

    def step(self, voltage: float, dt: float) -> None:
        part = self.part
        if self._m0 is None:
            np.multiply(self.gamma, voltage - self._v0, out=self._m)
        else:
            np.multiply(self.gamma, voltage, out=self._m)
            np.add(self._m, self._m0, out=self._m)
        part.set_internal_moments(self._m)
        # dV/dt at the held voltage's instant t_k (module text): before the first step the
        # first voltage is taken as held
        v1 = self._v_prev
        if v1 is None:
            self._dv, self._v_prev2 = 0.0, voltage
        else:
            vpp = self._v_prev2
            self._dv = (1.5 * voltage - 2.0 * v1 + 0.5 * (v1 if vpp is None else vpp)) / dt
            self._v_prev2 = v1
        self._v = self._v_prev = voltage
        # the rates the held voltage starts from (internal units), half of the motional
        # current's central rate: copied here, summed only when a current is read
        np.copyto(self._rates_before, part.view.rates())
        self._i_before = True

    def closed_loop_reason(self):
        return None

    # -- native form: a fixed-gain actuator on the bending tendon -------------------------
    def native_reason(self):
        if self._m0 is not None:
            return ("its rest voltage differs from hinge to hinge (layers of their own widths move the neutral "
                    "axis along the beam), which one actuator on the bending tendon cannot apply")
        if not np.all(self.gamma != 0):
            return "its moment per volt is zero at some hinge"
        return None

    def add_native(self, spec, joints, parent):
        """M_j = Gamma_j (V - V_0): tendon coefficients Gamma_j / Gamma_0 (the width
        ratios), gain Gamma_0 and bias -Gamma_0 V_0; a tendon-velocity sensor
        ``bend_rate`` gives the motional current Gamma_0 x its reading (the custom numeric
        ``mjeap_coupling`` holds Gamma_0 in N m/V, i.e. A s)."""
        from . import native
        u = self.scene.units
        g0 = float(self.gamma[0])
        native.add_bending_tendon(spec, joints, self.gamma / g0)
        native.add_drive_actuator(spec, g0 / u.moment, self.voltage_range(), bias=-g0 * self.rest_voltage() / u.moment)
        spec.add_sensor(name="bend_rate", type=mujoco.mjtSensor.mjSENS_TENDONVEL, objtype=mujoco.mjtObj.mjOBJ_TENDON,
                        objname=native.TENDON)
        spec.add_numeric(name="mjeap_coupling", data=[g0])
        return native.NativeHandles(sensors={"motional_rate": "bend_rate"})

    def _moment_history(self, v):
        if self._m0 is None:
            return np.multiply.outer(v - self._v0, self.gamma)
        return np.multiply.outer(v, self.gamma) + self._m0

    def _restore_before(self, k: int) -> None:
        self._v_prev = None if k == 0 else float(self._v_history[k - 1])
        self._v_prev2 = None if k == 0 else float(self._v_history[max(k - 2, 0)])

    def resistive_current(self, v: float) -> float:
        """The leakage current (A) at the held voltage ``v`` (V)."""
        raise NotImplementedError

    def currents(self):
        """(resistive, capacitive, motional) current of eq. (1), A, of the voltage held over
        the last step, all at that voltage's instant t_k: the voltage, C times its causal
        second-order difference (3 V_k - 4 V_{k-1} + V_{k-2}) / 2h, and the hinges' central
        rate, the mean of their rates before and after the step (module text; before any
        step, the rates now)."""
        now = float(np.dot(self.gamma, self.part.hinge_rates(self._rates)))
        before = float(np.dot(self.gamma, self._rates_before)) / self.part.units.time
        i_mech = now if self._i_before is None else 0.5 * (before + now)
        return self.resistive_current(self._v), self._capacitance * self._dv, i_mech

    def signals(self) -> Dict[str, float]:
        i_r, i_c, i_m = self.currents()
        return {"current (A)": i_r + i_c + i_m, "current_resistive (A)": i_r,
                "current_capacitive (A)": i_c, "current_motional (A)": i_m,
                "drive_moment_root (N m)": float(self._m[0])}

    def small_signal(self, operating_voltage: float):
        """Linear in the drive's voltage at any operating point: moment per volt Gamma_j per
        hinge, the resistive current's conductance per volt (its slope, the leakage being
        affine in the voltage), the dielectric capacitance and the motional coupling Gamma_j
        (the same coefficient by reciprocity, module text)."""
        from .small_signal import SmallSignal
        v0 = self._operating_voltage(operating_voltage)
        g = np.array(self.gamma, dtype=float)
        return SmallSignal(v0, self.VOLTAGE_NAME, g, conductance=self.resistive_current(v0 + 1.0) -
                           self.resistive_current(v0), capacitance=self._capacitance, coupling=g,
                           notes="Gamma_j N m/V per hinge; I = G V + C dV/dt + sum_j Gamma_j dtheta_j/dt per volt "
                                 f"of {self.VOLTAGE_NAME}")

    # -- the laminate: fields, stresses and capacitances (mjeap.model.laminate) -------------
    def laminate(self):
        """The actuator's layer stack wired as this drive wires it
        (:class:`mjeap.model.laminate.Laminate`)."""
        raise NotImplementedError

    def capacitances(self) -> Dict[str, object]:
        """{'free': (F, how), 'blocked': (F, how)}: the free capacitance the signal terminal
        sees and the dielectric (blocked) term of the current."""
        raise NotImplementedError

    def warn_fields(self) -> None:
        """Warn (:class:`mjeap.model.laminate.FieldWarning`) of each layer the voltage range
        drives past its material's recommended field or coercive field, naming the layer."""
        import warnings
        from ..model.laminate import FieldWarning
        act = self.scene.actuator
        for text in self.laminate().field_warnings(self.voltage_range()):
            warnings.warn(f"{act.source_file or act.id}: {text}", FieldWarning, stacklevel=3)


@register_drive
class PiezoBimorphDrive(LinearPiezo):
    name = "piezo-bimorph"
    VOLTAGE_NAME = "V_sig"
    actuators = ("pzt-hamr-large", "pzt-hamr-small", "pzt-robobee")
    model_used = "unipolar simultaneous drive, Wood/Jafferis effective stress"
    #: a core with a piezo layer of equal thickness either side (:meth:`stack_reason`);
    #: the catalog bimorphs' parameters are in their actuator files
    ROLES = {"piezo": 2, "core": 1}
    GENERIC_PARAMETERS = _params(32.2)
    RANGES = {"bias": (0.0, 200.0 + 1e-9), "f31": (0.0, np.inf), "capacitance": (0.0, np.inf),
              "resistance": (0.0, np.inf)}

    def __init__(self, scene, **params):
        super().__init__(scene, **params)
        act = scene.actuator
        self.t_p, self.t_cf = self.stack(act)
        w = scene.layout.hinge_width
        # N m / V per hinge (module text); under plane strain the plates' stress per field
        # is f31 / (1 - nu) (mjeap.model.laminate)
        self._couple(self._f31() * w * (self.t_p + self.t_cf), 0.5 * float(self.params["bias"]),
                     capacitance=self.params["capacitance"])
        self.warn_fields()

    def _plane_strain_factor(self) -> float:
        """1, or 1 / (1 - nu_p) where the section is in plane strain (mjeap.model.laminate)."""
        act = self.scene.actuator
        if not act.section_at(0.0).plane_strain:
            return 1.0
        return 1.0 / (1.0 - act.layers[[l.role for l in act.layers].index("piezo")].poisson_ratio)

    @staticmethod
    def stack(actuator):
        """(t_p, t_cf) (m): a piezo layer's and the core's thickness of a symmetric bimorph."""
        roles = [l.role for l in actuator.layers]
        return actuator.layers[roles.index("piezo")].thickness, actuator.layers[roles.index("core")].thickness

    @classmethod
    def stack_reason(cls, actuator):
        """The bimorph's stack: exactly one 'core' layer with one 'piezo' layer of equal
        thickness either side of it (the moment per volt and the closed forms assume it)."""
        why = super().stack_reason(actuator)
        if why is not None:
            return why
        roles = [l.role for l in actuator.layers]
        core = [i for i, r in enumerate(roles) if r == "core"]
        piezo = [i for i, r in enumerate(roles) if r == "piezo"]
        layers = ", ".join(f"{l.name} ({l.role or 'no role'})" for l in actuator.layers)
        if len(core) != 1 or len(piezo) != 2 or not piezo[0] < core[0] < piezo[1]:
            return (f"it needs one 'core' layer between two 'piezo' layers; {actuator.id} has {layers} "
                    "(drive = \"piezo\" takes any stack)")
        t1, t2 = (actuator.layers[i].thickness for i in piezo)
        if abs(t1 - t2) > 1e-9 * max(t1, t2):
            return (f"its two 'piezo' layers must be equally thick (a symmetric bimorph); they are {t1:g} and {t2:g} m "
                    "(drive = \"piezo\" takes unequal plates)")
        return None

    def voltage_range(self):
        return (0.0, float(self.params["bias"]))

    def resistive_current(self, v: float) -> float:
        """(2 V_sig - V_bias) / (2 R), eq. (1)."""
        return (2 * v - self.params["bias"]) / (2 * self.params["resistance"])

    def laminate(self):
        """The bimorph as a laminate of the general drive's kind: each plate's d31 the
        equivalent -f31 / Y_p (its stress per field f31), the bottom plate on the signal
        (V_sig), the top one on the complement (V_bias - V_sig), both poled up; no
        permittivity (the file gives a capacitance instead)."""
        from ..model.laminate import Laminate, PiezoLayer
        if getattr(self, "_laminate", None) is None:
            act = self.scene.actuator
            idx = [i for i, l in enumerate(act.layers) if l.role == "piezo"]
            src = {"d31": "equivalent: -f31 / youngs_modulus (piezo-bimorph's effective stress per field)"}
            layers = [PiezoLayer(i, act.layers[i].name, -self.params["f31"] / act.layers[i].youngs_modulus, None,
                                 "signal" if k == 0 else "complement", "up", src, act.layers[i].material_key)
                      for k, i in enumerate(idx)]
            self._laminate = Laminate(act, layers, self.params["bias"])
        return self._laminate

    def capacitances(self):
        """Free: the model's low-frequency charge per volt C + Gamma^2 int dx / EI (the file
        has no permittivity); blocked: C, the dielectric term of the current."""
        c = float(self.params["capacitance"])
        return {"free": (c + self.laminate().bending_charge_per_volt(),
                         "model's low-frequency charge per volt, C + Gamma^2 int dx/EI (no permittivity in the file)"),
                "blocked": (c, "the capacitance parameter: the dielectric (blocked) term of the current")}

    # ---- Wood / Jafferis closed forms (mjeap.model.analytical), at this drive's V_eff -------------
    def bending_stiffness_per_width(self) -> float:
        sec = self.scene.actuator.section_at(0.0)
        return sec.flexural_rigidity / float(self.scene.actuator.width_at(0.0))

    def _closed_form_geometry(self):
        p = self.scene.actuator.planform
        wn = 0.5 * (p.base_width + p.tip_width)
        return p.length, wn, p.base_width / wn, p.extension_length / p.length

    def free_deflection(self, v_eff: float) -> float:
        """Free deflection (m) at the tip block's end for V_eff = V_sig - V_bias/2 (V): the
        Wood/Jafferis closed form with its plate-voltage difference V = 2 V_eff."""
        L, _, _, lr = self._closed_form_geometry()
        return an.bimorph_free_deflection(self._f31(), 2.0 * v_eff, self.t_p, self.t_cf, L, lr,
                                          self.bending_stiffness_per_width())

    def blocked_force(self, v_eff: float) -> float:
        """Blocked force (N) at the tip block's end for V_eff (V): the Wood/Jafferis closed
        form with V = 2 V_eff and the trapezoid's geometry factor G_F."""
        L, wn, wr, lr = self._closed_form_geometry()
        return an.bimorph_blocked_force(self._f31(), 2.0 * v_eff, self.t_p, self.t_cf, L, wn, wr, lr)

    def reference_curvature(self, t, v, initial_curvature=0.0):
        """Quasi-static uniform curvature of the free bimorph, M / (D w)."""
        return self._f31() * (self.t_p + self.t_cf) * (np.asarray(v) - 0.5 * self.params["bias"]) / \
            self.bending_stiffness_per_width()

    def _f31(self) -> float:
        """The plates' stress per field (Pa m/V): f31, over (1 - nu_p) under plane strain."""
        return self.params["f31"] * self._plane_strain_factor()
