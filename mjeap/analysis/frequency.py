"""Frequency-domain read-outs of rollouts: the phasor of a sampled sinusoid, and sine sweeps.

A phasor is the complex amplitude ``A`` of ``y(t) = offset + Re(A exp(i 2 pi f t))``,
fitted by linear least squares (numpy.linalg.lstsq) on the chosen window, so the window
need not hold a whole number of periods. The frequency response of y to the input u at f
is then ``phasor(y) / phasor(u)``. Phases are in radians, SI amplitudes.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Dict, Sequence

import numpy as np

from ..errors import ParameterError, check_positive


def phasor(t: np.ndarray, y: np.ndarray, frequency: float) -> complex:
    """Complex amplitude of the component of ``y(t)`` at ``frequency`` (Hz), with a constant
    offset fitted alongside it."""
    t, y = np.asarray(t, float), np.asarray(y, float)
    if t.shape != y.shape or t.size < 4:
        raise ParameterError("y", f"{y.shape} samples at {t.shape} times", "matching arrays of >= 4 samples")
    w = 2 * np.pi * check_positive("frequency", frequency, "Hz")
    basis = np.column_stack([np.cos(w * t), -np.sin(w * t), np.ones_like(t)])
    (a, b, _), *_ = np.linalg.lstsq(basis, y, rcond=None)
    return complex(a, b)


@dataclass
class SineSweep:
    """Steady-state phasors of a sine sweep: per frequency (Hz), the applied voltage's, the
    tip deflection's (m), the tip velocity's (m/s) and every drive signal's.

    The tip velocity is the backward difference of the sampled deflection over one timestep,
    (1 - exp(-i omega dt)) / dt times its phasor: what MuJoCo's velocities are (its
    semi-implicit step sets q+ = q + h v+) and what the drives' rates see; i omega would
    lead them by omega dt / 2 (3.3 degrees at 2 kHz with dt = 9 us)."""

    frequency: np.ndarray
    voltage: np.ndarray
    tip_deflection: np.ndarray
    signals: Dict[str, np.ndarray] = field(default_factory=dict)
    meta: dict = field(default_factory=dict)

    @property
    def derivative(self) -> np.ndarray:
        """The sampled backward difference d/dt as a frequency response, 1/s."""
        dt = self.meta["timestep_s"]
        return (1 - np.exp(-2j * np.pi * self.frequency * dt)) / dt

    @property
    def tip_velocity(self) -> np.ndarray:
        return self.derivative * self.tip_deflection

    def response(self, key: str = "tip_velocity") -> np.ndarray:
        """Frequency response of ``key`` (tip_deflection, tip_velocity or a signal name) to
        the voltage."""
        y = getattr(self, key) if key in ("tip_deflection", "tip_velocity") else self.signals[key]
        return y / self.voltage


def sine_sweep(scene, frequencies: Sequence[float], offset: float, amplitude: float,
               drive=None, drive_params=None, settle_time: float = None, cycles: int = 4) -> SineSweep:
    """Drive ``scene`` with ``offset + amplitude sin(2 pi f t)`` V at each frequency (Hz) and
    fit the phasors of the last ``cycles`` periods (at least 2 ms), sampled every timestep.

    ``settle_time`` (s): transient allowed before the window, default five time constants
    of the first mode, 5 / (zeta omega_1).
    """
    from ..simulation.rollout import rollout

    f = np.asarray(frequencies, float)
    if f.ndim != 1 or f.size == 0 or np.any(f <= 0):
        raise ParameterError("frequencies", frequencies, "a non-empty list of positive frequencies in Hz")
    ch = scene.choice
    if settle_time is None:
        settle_time = 5.0 / (ch.damping_ratio * 2 * np.pi * ch.first_frequency)
    dt = scene.timestep
    if np.any(f > 0.25 / dt):
        raise ParameterError("frequencies", float(f.max()), f"frequencies below a quarter of 1/timestep = "
                             f"{0.25 / dt:.4g} Hz for this scene")
    V, Y, S = [], [], {}
    for fk in f:
        window = max(cycles / fk, 2e-3)
        r = rollout(scene, f"sine:{float(amplitude)!r}V@{float(fk)!r}Hz,offset={float(offset)!r}V", settle_time + window, drive=drive,
                    drive_params=drive_params, sample_interval=dt, progress=False)
        sel = r.time >= r.time[-1] - window
        t = r.time[sel]
        V.append(phasor(t, r.voltage[sel], fk))
        Y.append(phasor(t, r.tip_position[sel, 1], fk))
        for k, y in r.signals.items():
            S.setdefault(k, []).append(phasor(t, y[sel], fk))
    return SineSweep(f, np.array(V), np.array(Y), {k: np.array(v) for k, v in S.items()},
                     {"actuator": scene.actuator.id, "offset_V": offset, "amplitude_V": amplitude,
                      "settle_time_s": settle_time, "cycles": cycles, "timestep_s": dt})
