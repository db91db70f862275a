"""Self-sensing tip velocity of a piezoelectric bimorph from its own drive current
(Jayaram et al. 2018, eqs. 7-9), written against mjeap's public API only.

    I_sen = I_act - (2 V - V_bias) / (2 R_fit) - beta C_fit dV/dt      (eq. 7)
    v_sen = alpha I_sen                                                (eq. 9)

R_fit and C_fit are the dielectric resistance and capacitance the user measured (Jayaram et al. 2018:
on a fixed actuator) or took from a datasheet. The blocking factor beta corrects C_fit to
the free actuator's capacitance and is fitted once (eq. 8): the value that minimises the
squared phase difference between the measured tip velocity and I_sen over a frequency
sweep. The velocity scale alpha (m/(A s)) is then the geometric-mean magnitude ratio.

In this model I_mech is exactly sum_j Gamma_j dtheta_j/dt (the reciprocal of the drive
moment), so eqs. (7)-(9) hold up to the change of mode shape with frequency; the paper's
10 % / 10 degree errors on real actuators come from what the model leaves out (R and C that
vary with frequency and voltage, measurement noise).

dV/dt is taken at the instant of the sample's voltage and current, as the drive reports them
(:mod:`mjeap.drives.piezo`: the capacitive and motional currents of a sample both belong to
its voltage's instant): the causal second-order difference (3 V_k - 4 V_{k-1} + V_{k-2}) / 2h
of the voltage samples (the slope at t_k of the parabola through the last three; on uneven
samples its general form). The dielectric current then cancels for beta C_fit = C whatever
the sample interval Delta against the simulator's step h, to (omega max(h, Delta))^2 / 3.
Where the motional current is a small part of the total (a blocked actuator) the estimate's
error is that of the dielectric term times the dielectric/motional ratio; the backward
difference, the slope half a sample before the sample's instant, left omega (Delta - h) / 2
of it uncancelled, which grew as the step shrank (the RoboBee wing at 270 Hz, sampled every
37 us, with the drive's capacitive current half a step early too and eq. 8's beta moving
with it: +13 % at the default step, +22 % at a quarter of it; now +8.4 % and +8.8 %).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Optional

import numpy as np

from mjeap.errors import ParameterError, check_positive
from mjeap.analysis.frequency import SineSweep
from ..lazy import lazy_module

#: imported at its first use (mjeap.lazy)
optimize = lazy_module("scipy.optimize")


@dataclass
class SelfSensingEstimator:
    """Eqs. (7) and (9). ``bias`` (V), ``r_fit`` (ohm), ``c_fit`` (F), ``beta`` (-),
    ``alpha`` (m/(A s))."""

    bias: float
    r_fit: float
    c_fit: float
    beta: float = 1.0
    alpha: float = 1.0
    fit: dict = field(default_factory=dict)

    def __post_init__(self):
        for name in ("bias", "r_fit", "c_fit", "beta", "alpha"):
            check_positive(name, getattr(self, name))
        self.reset()

    # ---- time domain -----------------------------------------------------------------
    def sensor_current(self, time, voltage, current) -> np.ndarray:
        """I_sen (A) of sampled V (V) and I_act (A) at ``time`` (s), eq. (7). dV/dt as
        :meth:`update` takes it from the third sample on (module text); the samples are a
        window of a longer record, so the first two take the second-order one-sided and
        central differences (what the online form, which cannot look ahead, does not)."""
        t, v, i = (np.asarray(a, float) for a in (time, voltage, current))
        if not (t.shape == v.shape == i.shape) or t.ndim != 1 or t.size < 2:
            raise ParameterError("time, voltage, current", f"shapes {t.shape}, {v.shape}, {i.shape}",
                                 "three 1-D arrays of the same length >= 2")
        return i - (2 * v - self.bias) / (2 * self.r_fit) - self.beta * self.c_fit * sampled_derivative(t, v)

    def velocity(self, time, voltage, current) -> np.ndarray:
        """v_sen (m/s), eq. (9)."""
        return self.alpha * self.sensor_current(time, voltage, current)

    def reset(self) -> None:
        self._v_prev: Optional[float] = None
        self._v_prev2: Optional[float] = None
        self._dt_prev = 0.0

    def update(self, voltage: float, current: float, dt: float) -> float:
        """One sample of v_sen (m/s) online, from V (V) and I_act (A) of one instant and the
        interval ``dt`` (s) since the last sample. dV/dt is the causal second-order
        difference (module text); before the first sample the first voltage is taken as
        held (as the drive takes it), so the first sample has none."""
        if self._v_prev is None:
            dv, vp = 0.0, voltage
        else:
            vp = self._v_prev
            vpp, h2 = (vp, dt) if self._v_prev2 is None else (self._v_prev2, self._dt_prev)
            dv = _bdf2(voltage, vp, vpp, dt, h2)
        self._v_prev2, self._v_prev, self._dt_prev = vp, voltage, dt
        return self.alpha * (current - (2 * voltage - self.bias) / (2 * self.r_fit) - self.beta * self.c_fit * dv)

    # ---- frequency domain ------------------------------------------------------------
    def sensor_current_response(self, sweep: SineSweep, beta: Optional[float] = None) -> np.ndarray:
        """I_sen / V (A/V) per sweep frequency; the resistive term of an AC voltage about the
        bias midpoint is V / R."""
        beta = self.beta if beta is None else beta
        return sweep.response("current (A)") - 1.0 / self.r_fit - beta * self.c_fit * sweep.derivative

    def velocity_response(self, sweep: SineSweep) -> np.ndarray:
        """v_sen / V ((m/s)/V) per sweep frequency."""
        return self.alpha * self.sensor_current_response(sweep)

    def errors(self, sweep: SineSweep):
        """(magnitude error (fraction), phase error (degrees)) of v_sen against the
        simulated tip velocity, per sweep frequency."""
        ratio = self.velocity_response(sweep) / sweep.response("tip_velocity")
        return np.abs(ratio) - 1.0, np.degrees(np.angle(ratio))


def _bdf2(v0, v1, v2, h1, h2):
    """The slope at the last of three samples v2, v1, v0 (v0 the latest, h1 after v1, which
    is h2 after v2) of the parabola through them: (3 v0 - 4 v1 + v2) / 2h on even samples."""
    return (v0 * (2 * h1 + h2) / (h1 * (h1 + h2)) - v1 * (h1 + h2) / (h1 * h2) + v2 * h1 / (h2 * (h1 + h2)))


def sampled_derivative(t: np.ndarray, v: np.ndarray) -> np.ndarray:
    """dv/dt at each sample of ``v`` at times ``t`` (1-D, >= 2 samples): the causal
    second-order difference (:meth:`SelfSensingEstimator.update`) from the third sample on,
    the second-order central and forward differences at the second and first (first order
    with two samples)."""
    t, v = np.asarray(t, float), np.asarray(v, float)
    dv = np.empty_like(v)
    h = np.diff(t)
    if v.size < 3:
        dv[:] = (v[1] - v[0]) / h[0]
        return dv
    h1, h2 = h[1:], h[:-1]                  # before sample k: t_k - t_{k-1}, t_{k-1} - t_{k-2}
    dv[2:] = _bdf2(v[2:], v[1:-1], v[:-2], h1, h2)
    a, b = h[0], h[1]
    dv[1] = (-v[0] * b / (a * (a + b)) + v[1] * (b - a) / (a * b) + v[2] * a / (b * (a + b)))
    dv[0] = (-v[0] * (2 * a + b) / (a * (a + b)) + v[1] * (a + b) / (a * b) - v[2] * a / (b * (a + b)))
    return dv


def calibrate(sweep: SineSweep, bias: float, r_fit: float, c_fit: float,
              beta_range=(0.05, 20.0)) -> SelfSensingEstimator:
    """Fit beta by eq. (8), the least-squares phase match of I_sen to the measured tip
    velocity over the sweep, then alpha as the geometric-mean magnitude ratio. The fit's
    residuals are in ``estimator.fit``."""
    est = SelfSensingEstimator(bias, r_fit, c_fit)
    v = sweep.response("tip_velocity")

    def phase_cost(beta):
        return float(np.sum(np.angle(v / est.sensor_current_response(sweep, beta)) ** 2))

    res = optimize.minimize_scalar(phase_cost, bounds=beta_range, method="bounded", options={"xatol": 1e-6})
    est.beta = float(res.x)
    if min(abs(est.beta - beta_range[0]), abs(est.beta - beta_range[1])) < 1e-3 * est.beta:
        raise ParameterError("beta", est.beta, f"a blocking factor inside {beta_range}: the fit ran to the "
                             "bound; check c_fit (F) and that the sweep covers frequencies where the motional "
                             "current is a sizeable part of the total")
    est.alpha = float(np.exp(np.mean(np.log(np.abs(v) / np.abs(est.sensor_current_response(sweep))))))
    mag, ph = est.errors(sweep)
    est.fit = {"frequencies_hz": sweep.frequency.tolist(), "rms_phase_error_deg": float(np.sqrt(np.mean(ph**2))),
               "max_magnitude_error": float(np.abs(mag).max()), "beta": est.beta, "alpha_m_per_As": est.alpha}
    return est


def calibrate_on_free_actuator(actuator, bias: float, frequencies, **scene_kw) -> SelfSensingEstimator:
    """Eqs. 7-9 calibrated once on the free (unloaded) ``actuator``'s sine sweep at ``bias``
    (V) over ``frequencies`` (Hz), as Jayaram et al. 2018 calibrates on the bench, not on the robot:
    the drive's own resistance and capacitance stand in for the user's fixed-actuator
    measurement (Table 2's extracted fits are unreliable), beta by eq. 8. ``scene_kw`` go to
    the free actuator's :class:`mjeap.Scene`."""
    from mjeap.simulation.scene import Scene
    from mjeap.drives import make_drive
    from mjeap.analysis.frequency import sine_sweep
    free = Scene(actuator, **scene_kw)
    p = make_drive("piezo-bimorph", free, bias=bias).params
    sweep = sine_sweep(free, tuple(frequencies), bias / 2, bias / 4, drive_params={"bias": bias})
    return calibrate(sweep, bias, p["resistance"], p["capacitance"])


def quasi_static_alpha(length: float, extension: float, area: float, f31: float, t_p: float, t_cf: float) -> float:
    """alpha (m/(A s)) of the uniform-curvature bimorph: the tip velocity (L/2 + l_ext) L kappa'
    over the motional current of Jayaram et al. 2018's eq. (13), 2 A f31 eps_1' with the plate's mid-plane
    strain eps_1 = kappa (t_p + t_cf)/2 over the PZT area A; the counterpart of the paper's
    eq. (17b), which averages 1/y over the plate instead and leaves out the tip block."""
    return length * (0.5 * length + extension) / (f31 * (t_p + t_cf) * area)
