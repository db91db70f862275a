"""Stopping a periodically driven run once its outcome is decided: when the last drive
period repeats the one before it, the rest of the run would repeat it too (a time-periodic
system on its periodic orbit), so the run stops there and says so.

:class:`PeriodicStop` is checked at every sample (:class:`mjeap.engines.frame.Samples`);
at each period boundary from the second on it compares the last period with the one before
(the earlier one interpolated at the same phase): the tip curvature relative to its range
over both periods and every centreline point relative to the beam's length. Within the
tolerance on both it raises :class:`Decided`, which every engine turns into a run that ends
at that sample (the scene left there); :func:`mjeap.rollout` records it in
``meta['stopped_early']``. A run still drifting (relaxing, creeping, collapsing slowly)
differs by more than the tolerance and runs on.
"""
from __future__ import annotations

import numpy as np

from ..engines.frame import Decided
from ..errors import ParameterError, check_range
from ..model.analytical import arc_curvature

__all__ = ["Decided", "PeriodicStop", "check_periodic_stop"]


def check_periodic_stop(tolerance, wave, duration: float, sample_interval: float):
    """The tolerance (relative, 1e-6 to 0.2) of a periodic stop, checked with the run before
    any work: the waveform must be periodic (a frequency, not a chirp or step), the run at
    least three periods long and sampled at least 8 times a period. Returns the period (s)."""
    tol = check_range("stop_when_periodic", tolerance, 1e-6, 0.2)
    f = float(getattr(wave, "frequency", 0.0) or 0.0)
    f_end = float(getattr(wave, "frequency_end", 0.0) or 0.0)
    if f <= 0 or (f_end and f_end != f):
        raise ParameterError("stop_when_periodic", tolerance, "None for this waveform: a periodic stop needs a "
                             f"periodic drive (a frequency; got {getattr(wave, 'text', wave)!s})")
    period = 1.0 / f
    if duration < 3 * period:
        raise ParameterError("stop_when_periodic", tolerance, f"None for a run of {duration:g} s: it can stop only "
                             f"after two periods and before its end (at least 3 periods, {3 * period:g} s)")
    if sample_interval > period / 8:
        raise ParameterError("sample_interval", sample_interval, f"at most {period / 8:g} s (8 samples a period) "
                             "with stop_when_periodic")
    return tol, period


class PeriodicStop:
    """Raises :class:`Decided` at the first period boundary (from the second) where the last
    period repeats the one before within ``tolerance``; ``length`` is the beam's (m)."""

    def __init__(self, period: float, tolerance: float, length: float):
        self.period, self.tolerance, self.length = float(period), float(tolerance), float(length)
        self._next = 2 * self.period                # first boundary with two periods behind it
        self.checked = 0                            # boundaries compared

    def __call__(self, samples) -> None:
        n = samples.n
        t = samples.t[:n]
        eps = 1e-9 * self.period
        if t[-1] < self._next - eps:
            return
        k = int(round(t[-1] / self.period))
        self._next = (k + 1) * self.period
        self.checked += 1
        T = self.period
        use = t >= t[-1] - 2 * T - 1.5 * (t[-1] - t[-2])          # two periods and a sample before them
        pts, _ = samples.clamp_frame(np.nonzero(use)[0])
        tu = t[use]
        last = tu >= tu[-1] - T - eps
        kappa = arc_curvature(pts[:, -1, 0], pts[:, -1, 1])
        before = np.interp(tu[last] - T, tu, kappa)
        span = max(float(np.ptp(kappa)), 1e-300)
        d_kappa = float(np.max(np.abs(kappa[last] - before))) / span
        d_shape = 0.0
        for j in range(pts.shape[1]):
            for c in range(2):
                prev = np.interp(tu[last] - T, tu, pts[:, j, c])
                d_shape = max(d_shape, float(np.max(np.abs(pts[last, j, c] - prev))) / self.length)
        if d_kappa <= self.tolerance and d_shape <= self.tolerance:
            raise Decided(f"stopped at {t[-1]:.6g} s: periodic (the last period repeats the one before within "
                          f"{self.tolerance:g}: tip curvature {d_kappa:.2g} of its range, centreline {d_shape:.2g} "
                          "of the length)", float(t[-1]))
