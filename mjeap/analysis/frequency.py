"""Frequency-domain read-outs of rollouts: the phasor of a sampled sinusoid, and sine sweeps.

A phasor is the complex amplitude ``A`` of ``y(t) = offset + Re(A exp(i 2 pi f t))``,
fitted by linear least squares (numpy.linalg.lstsq) on the chosen window, so the window
need not hold a whole number of periods. The frequency response of y to the input u at f
is then ``phasor(y) / phasor(u)``. Phases are in radians, SI amplitudes.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Dict, Optional, Sequence

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


def cycle_power(t: np.ndarray, v: np.ndarray, i: np.ndarray, frequency: float, cycles: int = 1) -> float:
    """Mean electrical power (W) into a port over the last ``cycles`` whole periods of a
    periodic drive at ``frequency`` (Hz): the mean of (v - its mean) i, the voltage (V)
    measured from its mean (the piezo bimorph's V_eff about V_bias / 2), i in A. The samples
    must be evenly spaced with a whole number of them per period (refused otherwise: a
    partial period biases the mean by up to the reactive power's share)."""
    t, v, i = (np.asarray(a, float) for a in (t, v, i))
    if not (t.shape == v.shape == i.shape) or t.ndim != 1 or t.size < 3:
        raise ParameterError("t, v, i", f"shapes {t.shape}, {v.shape}, {i.shape}", "three 1-D arrays of one length")
    dt = float(np.median(np.diff(t)))
    per = check_positive("frequency", frequency, "Hz") ** -1 / dt
    n = int(round(per))
    if abs(per - n) > 1e-6 * per or n < 4 or not np.allclose(np.diff(t), dt, rtol=1e-6, atol=0):
        raise ParameterError("frequency", frequency, f"a period of a whole number (>= 4) of evenly spaced samples "
                             f"(here {per:.6g} samples of {dt:.4g} s)")
    k = n * int(cycles)
    if k > t.size:
        raise ParameterError("cycles", cycles, f"at most {t.size // n} periods of {n} samples")
    vv, ii = v[-k:], i[-k:]
    return float(np.mean((vv - vv.mean()) * ii))


def phase_lag(t: np.ndarray, v: np.ndarray, rate: np.ndarray, frequency: float) -> float:
    """The lag (degrees, in (-90, 270)) of a rate's fundamental (a velocity, a motional
    current) behind the voltage's quadrature: 90 - arg(phasor(rate) / phasor(v)). For a
    mode driven below resonance it is the displacement's lag, 90 at resonance, towards 180
    above it."""
    z = phasor(t, rate, frequency) / phasor(t, v, frequency)
    lag = 90.0 - np.degrees(np.angle(z))
    return float(lag - 360.0 if lag > 270.0 else lag)


@dataclass
class SineSweep:
    """Steady-state phasors of a sine sweep: per frequency (Hz), the applied voltage's, the
    tip deflection's (m), the tip velocity's (m/s) and every drive signal's.

    The tip velocity is the one at the instant of the sample's voltage (the start of the step
    it was held over, one step before the deflection's): the central difference of the
    sampled deflection about it, (1 - exp(-2 i omega dt)) / (2 dt) times its phasor, as the
    drives' rates are read (:mod:`mjeap.drives.piezo`: the motional current uses the hinges'
    central rate there). MuJoCo's own velocity after a step, the backward difference
    (1 - exp(-i omega dt)) / dt, belongs half a step later (3.3 degrees at 2 kHz with
    dt = 9 us)."""

    frequency: np.ndarray
    voltage: np.ndarray
    tip_deflection: np.ndarray
    signals: Dict[str, np.ndarray] = field(default_factory=dict)
    meta: dict = field(default_factory=dict)

    @property
    def derivative(self) -> np.ndarray:
        """d/dt of the samples at their own instant as a frequency response, 1/s: the causal
        second-order difference (3 - 4 exp(-i omega dt) + exp(-2 i omega dt)) / (2 dt), what
        the piezo drive's capacitive current and the self-sensing estimator take of the
        voltage (:mod:`mjeap.drives.piezo`)."""
        dt = self.meta["timestep_s"]
        z = np.exp(-2j * np.pi * self.frequency * dt)
        return (3 - 4 * z + z**2) / (2 * dt)

    @property
    def central_derivative(self) -> np.ndarray:
        """d/dt at the voltage's instant as a frequency response, 1/s: the central difference
        over two steps about the step before the sample."""
        dt = self.meta["timestep_s"]
        return (1 - np.exp(-4j * np.pi * self.frequency * dt)) / (2 * dt)

    @property
    def tip_velocity(self) -> np.ndarray:
        return self.central_derivative * self.tip_deflection

    def response(self, key: str = "tip_velocity") -> np.ndarray:
        """Frequency response of ``key`` (tip_deflection, tip_velocity or a signal name) to
        the voltage."""
        y = getattr(self, key) if key in ("tip_deflection", "tip_velocity") else self.signals[key]
        return y / self.voltage


def driven_power(scene, frequency: float, amplitude: float, offset: float, cycles: int = 4,
                 settle_time: Optional[float] = None, current: str = "current_motional (A)", drive_params=None) -> dict:
    """Steady state of ``offset + amplitude sin(2 pi f t)`` V on ``scene``: the mean power
    (W) of (V - offset) x ``current`` over the last ``cycles`` periods and the lag (deg) of
    the current's fundamental behind the voltage's quadrature (:func:`cycle_power`,
    :func:`phase_lag`), sampled every step. A period must be a whole number of the scene's
    steps (choose ``frequency`` so). ``settle_time`` (s): default 12 / (zeta_1 omega_1),
    whole periods."""
    from ..simulation.rollout import rollout
    ch, dt = scene.choice, scene.timestep
    if settle_time is None:
        settle_time = 12.0 / (ch.damping_ratio * 2 * np.pi * ch.first_frequency)
    n_settle = int(np.ceil(settle_time * frequency))
    r = rollout(scene, f"sine:{float(amplitude)!r}V@{float(frequency)!r}Hz,offset={float(offset)!r}V",
                (n_settle + cycles) / frequency, drive_params=drive_params, sample_interval=dt, progress=False)
    k = int(round(cycles / (frequency * dt)))
    t, v, i = r.time[-k:], r.voltage[-k:], r.signals[current][-k:]
    return {"frequency_hz": float(frequency), "timestep_s": dt, "power_w": cycle_power(t, v, i, frequency, cycles),
            "lag_deg": phase_lag(t, v, i, frequency), "engine": r.meta.get("engine")}


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
