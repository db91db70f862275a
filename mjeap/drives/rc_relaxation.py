"""Ionic actuator: RC charging and back-relaxation (Dadras et al. 2021, eqs. 1-8).

Identified whole-actuator model (eq. 8), K curvature (1/m), V volts:

    K(s)/V(s) = gain (s + zero) / ((s + p_mech)(s + p_elec))

split, as in the paper's block diagram, into
* electrical: the double-layer voltage v_c = q / C charges through R,
  v_c / V = p_elec / (s + p_elec), p_elec = 1/(RC);
* electromechanical: a moment M = Gamma v_c at every hinge (uniform curvature), with
  Gamma = gain EI / p_elec so that the product has the identified gain;
* mechanical: (1/EI)(s + zero)/(s + p_mech) from curvature to moment, realised inside the
  beam as a standard linear solid: each hinge carries an internal variable r,
  r' = -zero r + (zero - p_mech) theta, and the moment k r. It relaxes *every* moment the
  beam carries (drive, payload, gravity), which is the feedback inside the mechanical
  block of the paper. Instantaneous stiffness EI, relaxed stiffness EI p_mech / zero.
"""
from __future__ import annotations

from typing import Dict

import mujoco
import numpy as np

from ..lazy import lazy_module
from ..model import lti
from ..model.analytical import DadrasModel
from ..errors import ParameterError
from .base import Drive, NativeForm, register_drive, zoh_first_order

#: imported at its first use (mjeap.lazy)
signal = lazy_module("scipy.signal")

_SRC = "Dadras et al. 2021, eq. 8 (identified from a 3 V step)"
_EQ8 = DadrasModel()      # the identified numbers live there, once


@register_drive
class RCRelaxationDrive(NativeForm, Drive):
    name = "rc-relaxation"
    actuators = ("pedot-micro",)
    model_used = "lumped RC + standard-linear-solid back-relaxation"
    #: the eq. (8) parameters and their units; Dadras et al. 2021's identified values are in
    #: pedot-micro's actuator file (mjeap/model/actuators/pedot-micro.toml). No generic
    #: default: an actuator of one's own gives its own (identify them: mjeap identify step)
    UNITS = {"gain": "1/(m s)", "zero": "1/s", "pole_mechanical": "1/s", "pole_electrical": "1/s", "capacitance": "F"}

    RANGES = {"zero": (0.0, np.inf), "pole_mechanical": (0.0, np.inf), "pole_electrical": (0.0, np.inf),
              "capacitance": (0.0, np.inf)}

    def __init__(self, scene, **params):
        super().__init__(scene, **params)
        p = self.params
        if not p["zero"] > p["pole_mechanical"]:
            raise ParameterError(f"{self.name} parameter zero", p["zero"],
                                 f"a value above pole_mechanical = {p['pole_mechanical']:g} 1/s (a back-relaxation "
                                 "relaxes: relaxed stiffness EI p/z below the instantaneous EI)")
        self.EI = float(scene.actuator.flexural_rigidity_at(0.0)[0])
        self.gamma = p["gain"] * self.EI / p["pole_electrical"]   # N m per volt of v_c
        # state s = (r_1 .. r_N, v_c): the relaxation angle of every hinge and the
        # double-layer voltage, all first order and stepped exactly (zero-order hold) in
        # one vectorised update s+ = a s + b u with input u = (theta_1 .. theta_N, V)
        n, dt = scene.layout.segments, scene.timestep
        z, pm, pe = p["zero"], p["pole_mechanical"], p["pole_electrical"]
        a_r, b_r = zoh_first_order(z, z - pm, dt)
        a_e, b_e = zoh_first_order(pe, pe, dt)
        self._a = np.r_[np.full(n, a_r), a_e]
        self._b = np.r_[np.full(n, b_r), b_e]
        self._s, self._u, self._bu = np.zeros(n + 1), np.zeros(n + 1), np.empty(n + 1)
        self._r, self._theta = self._s[:n], self._u[:n]      # views
        self._m_relax, self._m_total = np.empty(n), np.empty(n)
        self._v = self._m_drive = 0.0
        # the same update as scalars (uniform over the hinges), for the direct path
        self._ar, self._br, self._ae, self._be = a_r, b_r, a_e, b_e
        self._direct, self._stale = None, False

    def reset(self, initial_curvature: float = 0.0) -> None:
        """Start at rest at the scene's current shape: the relaxation state holds it (zero
        elastic moment beyond what gravity needs), so a bent start decays on the mechanical
        pole alone, as the zero-input term of Dadras et al. 2021's eq. (7)."""
        sc = self.part
        # equilibrium at rest: k (theta - r) = gravity moment on each hinge
        self._r[:] = sc.hinge_angles() - sc.gravity_moments() / sc.hinge_stiffness()
        self._s[-1] = 0.0
        self._v = 0.0
        self._k = sc.hinge_stiffness()
        self._apply()
        self._bind_direct()

    def _bind_direct(self):
        """The direct path's views and constants for the present part, data and stiffness
        (Part.direct_bending), or None; after :meth:`_apply` (the moments it wrote are current)."""
        sc = self.part
        d = sc.direct_bending()
        if d is not None:       # moments in internal units straight into qfrc_applied
            theta, qfrc, scale = d
            self._direct = (sc.data, theta, qfrc, self._k * scale, self.gamma * scale, np.empty_like(self._r),
                            1.0 / scale)
        else:
            self._direct = None

    def _apply(self):
        """Moments over the coming step: k r (relaxation) + Gamma v_c (drive), N m."""
        self._m_drive = self.gamma * float(self._s[-1])
        np.multiply(self._k, self._r, out=self._m_relax)
        np.add(self._m_relax, self._m_drive, out=self._m_total)
        self.part.set_internal_moments(self._m_total)
        self._stale = False

    def step(self, voltage: float, dt: float) -> None:
        self._v = voltage
        if self._direct is not None and self._direct[0] is self.part.data:
            # :meth:`_apply` and the update below written into the model's own arrays
            # (Part.direct_bending): the same arithmetic in 5 array operations
            _, theta, qfrc, k, gamma, tmp, _ = self._direct
            r, s = self._r, self._s
            vc = float(s[-1])
            np.multiply(k, r, out=qfrc)
            qfrc += gamma * vc
            r *= self._ar
            np.multiply(theta, self._br, out=tmp)
            r += tmp
            s[-1] = self._ae * vc + self._be * voltage
            self._m_drive = self.gamma * vc
            self._stale = True
            return
        self._apply()
        self.part.hinge_angles(out=self._theta)
        self._u[-1] = voltage
        np.multiply(self._b, self._u, out=self._bu)
        self._s *= self._a
        self._s += self._bu

    def signals(self) -> Dict[str, float]:
        C = self.params["capacitance"]
        vc = float(self._s[-1])
        if self._stale:       # after direct steps: the relaxation moments that acted over the last one
            _, _, qfrc, _, _, _, newton_metre = self._direct
            np.multiply(qfrc, newton_metre, out=self._m_relax)
            self._m_relax -= self._m_drive
            self._stale = False
        return {"double_layer_voltage (V)": vc, "charge (C)": C * vc,
                "current (A)": C * self.params["pole_electrical"] * (self._v - vc),
                "drive_moment (N m)": float(self._m_drive),
                "relaxation_moment_mean (N m)": float(np.mean(self._m_relax))}

    # -- native form: filterexact actuator on the bending tendon + Maxwell arms ----------
    def native_reason(self):
        return None

    def _internal_rates(self):
        t = self.scene.units.time
        p = self.params
        return p["zero"] * t, p["pole_mechanical"] * t, p["pole_electrical"] * t

    def add_native(self, spec, joints, parent):
        from . import native
        u = self.scene.units
        z, pm, pe = self._internal_rates()
        native.add_bending_tendon(spec, joints, np.ones(len(joints)))
        native.add_drive_actuator(spec, self.gamma / u.moment, self.voltage_range(), time_constant=1.0 / pe)
        k, _ = self.scene.part.built_hinge_parameters()      # as built or identified (internal)
        relax = native.add_maxwell_arms(spec, joints, parent, k, z, pm, self.scene.timestep / u.time,
                                        float(self.scene.layout.link_mass.min() / u.mass))
        return native.NativeHandles(relaxation_joints=relax)

    def _relaxation_adr(self, part, handles, prefix):
        """(qpos addresses of the relaxation dofs, act address of the drive) in part's model."""
        m = part.model
        key = (id(m), prefix)
        if getattr(self, "_adr_key", None) != key:
            ids = [mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, prefix + j) for j in handles.relaxation_joints]
            a = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_ACTUATOR, prefix + handles.actuator)
            self._adr_key, self._adr = key, (m.jnt_qposadr[ids], int(m.actuator_actadr[a]))
        return self._adr

    def native_reset(self, part, handles, prefix=""):
        """The Maxwell arms hold the present shape at rest: k_inf theta + k1 (theta - r) = g
        on every hinge (g the gravity moment), the native twin of :meth:`reset`."""
        u = self.scene.units
        z, pm, _ = self._internal_rates()
        k = part.hinge_stiffness() / u.rotational_stiffness
        k1, k_inf = k * (z - pm) / z, k * pm / z
        theta = part.hinge_angles()
        g = part.gravity_moments() / u.moment
        qadr, _ = self._relaxation_adr(part, handles, prefix)
        part.data.qpos[qadr] = theta - (g - k_inf * theta) / k1
        mujoco.mj_forward(part.model, part.data)

    def native_prepare(self, v_steps, dt=None):
        self._v_native = np.asarray(v_steps, dtype=float)

    def native_signals(self, k, part, handles, prefix="", before=None):
        """From the native state: v_c is the activation, the relaxation moment k1 r_j of
        each arm (k r of the loop drive's internal variable), both after step k."""
        z, pm, _ = self._internal_rates()
        qadr, aadr = self._relaxation_adr(part, handles, prefix)
        self._s[-1] = part.data.act[aadr]
        self._v = float(self._v_native[max(k - 1, 0)]) if k else 0.0
        self._m_drive = self.gamma * float(self._s[-1])
        self._stale = False
        k1 = part.hinge_stiffness() * (z - pm) / z
        np.multiply(k1, part.data.qpos[qadr], out=self._m_relax)
        return self.signals()

    def native_signal_history(self, ks, states, part, handles, prefix=""):
        """:meth:`native_signals` for many samples at once, from the full-physics states."""
        m = part.model
        qadr, aadr = self._relaxation_adr(part, handles, prefix)
        S = mujoco.mjtState
        q0 = mujoco.mj_stateSize(m, S.mjSTATE_TIME)
        a0 = mujoco.mj_stateSize(m, S.mjSTATE_TIME | S.mjSTATE_QPOS | S.mjSTATE_QVEL)
        vc = states[:, a0 + aadr]
        z, pm, _ = self._internal_rates()
        k1 = part.hinge_stiffness() * (z - pm) / z
        ks = np.asarray(ks)
        v = np.where(ks > 0, self._v_native[np.maximum(ks - 1, 0)], 0.0)
        C = self.params["capacitance"]
        return {"double_layer_voltage (V)": vc, "charge (C)": C * vc,
                "current (A)": C * self.params["pole_electrical"] * (v - vc),
                "drive_moment (N m)": self.gamma * vc,
                "relaxation_moment_mean (N m)": states[:, q0 + qadr] @ k1 / len(k1)}

    def native_leave(self, k, part, handles, prefix="", before=None):
        """The loop drive's state from the native one (v_c, r = k1 r_native / k), its
        moments applied to the scene: a loop run can go on from here."""
        self.native_signals(k, part, handles, prefix)
        self._k = self.part.hinge_stiffness()
        np.divide(self._m_relax, self._k, out=self._r)
        self._apply()
        self._bind_direct()          # the stiffness may have changed since the last reset

    def closed_loop_reason(self):
        return "the back-relaxation acts on every moment the beam carries, so the moments follow the hinge angles"

    def small_signal(self, operating_voltage: float):
        """Linear at any operating point. States (r_1 .. r_N, v_c): r_j' = -z r_j + (z - p)
        theta_j, v_c' = p_elec (V - v_c); moments k_j r_j + Gamma v_c; current C p_elec (V -
        v_c), the double layer's charging (no motional current: the model has none)."""
        from .small_signal import SmallSignal
        v0 = self._operating_voltage(operating_voltage)
        p, n = self.params, self.scene.layout.segments
        z, pm, pe, C = p["zero"], p["pole_mechanical"], p["pole_electrical"], p["capacitance"]
        A = np.diag(np.r_[np.full(n, -z), -pe])
        B = np.r_[np.zeros(n), pe]
        F = np.vstack([(z - pm) * np.eye(n), np.zeros((1, n))])
        G = np.hstack([np.diag(self.part.hinge_stiffness()), np.full((n, 1), self.gamma)])
        h = np.r_[np.zeros(n), -C * pe]
        return SmallSignal(v0, "V", np.zeros(n), conductance=C * pe, state_matrix=A, state_input=B,
                           state_from_angles=F, moment_from_state=G, current_from_state=h,
                           notes="eq. (8) as the drive runs it: RC charging, Gamma v_c on every hinge, the "
                                 "standard-linear-solid back-relaxation k r inside the beam")

    def transfer_function(self) -> signal.TransferFunction:
        """Eq. (8): K(s)/V(s) in 1/(m V)."""
        p = self.params
        return signal.TransferFunction(p["gain"] * np.array([1.0, p["zero"]]),
                                       np.polymul([1.0, p["pole_mechanical"]], [1.0, p["pole_electrical"]]))

    def reference_curvature(self, t, v, initial_curvature=0.0):
        """Eq. (8) from rest (:func:`mjeap.model.lti.lsim`, as scipy.signal.lsim), plus the initial
        curvature decaying on the mechanical pole (the zero-input term of eq. 7). Unloaded beam."""
        y = lti.lsim(self.transfer_function(), v, t)
        return y + initial_curvature * np.exp(-self.params["pole_mechanical"] * (np.asarray(t) - t[0]))
