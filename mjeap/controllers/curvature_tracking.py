"""Tip-curvature tracking for the loaded PEDOT actuator (Dadras et al. 2021), written against mjeap's
public API only.

Feedforward: the inverse of the identified transfer function (eq. 8, or any
:class:`mjeap.analysis.identify.StepFit`), made proper by a first-order filter 1/(tau s + 1) and
run on the sampled reference with scipy.signal.lsim. Feedback: PI on the measured tip
curvature (arc through clamp and tip), with conditional integration as anti-windup.
The rollout clips the command to the drive's safe voltage range and reports it.
"""
from __future__ import annotations

from typing import Callable, Dict

import numpy as np
from ..lazy import lazy_module

#: imported at its first use (mjeap.lazy)
signal = lazy_module("scipy.signal")


class CurvatureTracker:
    """u = V_ff(t) + kp e + ki int e, e = kappa_ref - kappa (1/m); u in V.

    ``plant``: (num, den) of K/V in 1/(m V) (default eq. 8); ``reference``: kappa_ref(t),
    vectorised, 1/m; ``kp`` (V m), ``ki`` (V m / s); ``tau`` (s) the feedforward filter;
    ``interval`` (s) the control period; ``feedforward``/``feedback`` switch the two parts."""

    name = "curvature-tracker (inverse-model feedforward + PI)"

    def __init__(self, reference: Callable, duration: float, *, plant=((63.0, 63.0 * 0.52), (1.0, 2.1, 0.54)),
                 kp: float = 0.02, ki: float = 0.1, tau: float = 0.05, interval: float = 1e-3,
                 feedforward: bool = True, feedback: bool = True):
        self.reference, self.kp, self.ki, self.interval = reference, kp, ki, interval
        self.use_ff, self.use_fb = feedforward, feedback
        num, den = plant
        # inverse plant times 1/(tau s + 1): den(s) / (num(s) (tau s + 1)), proper for relative degree 1
        inv = signal.TransferFunction(den, np.polymul(num, [tau, 1.0]))
        self._t = np.arange(0.0, duration + 2 * interval, interval)
        self._ff = signal.lsim(inv, reference(self._t), self._t)[1] if feedforward else np.zeros_like(self._t)

    def reset(self, scene, drive) -> None:
        self._lo, self._hi = drive.voltage_range()
        self._int = 0.0
        self._e = self._ref = self._u = 0.0

    def __call__(self, t: float, scene) -> float:
        self._ref = float(self.reference(t))
        self._e = self._ref - scene.tip_curvature()
        ff = float(np.interp(t, self._t, self._ff))
        u = ff + (self.kp * self._e + self.ki * self._int if self.use_fb else 0.0)
        # conditional integration: integrate unless saturated and the error pushes further out
        if self.use_fb and not ((u >= self._hi and self._e > 0) or (u <= self._lo and self._e < 0)):
            self._int += self._e * self.interval
        self._u = u
        return u

    def signals(self) -> Dict[str, float]:
        return {"reference (1/m)": self._ref, "error (1/m)": self._e, "command (V)": self._u}
