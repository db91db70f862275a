"""Stopping a periodically driven run once its outcome is decided: when the last drive
period repeats the one before it, the rest of the run would repeat it too (a time-periodic
system on its periodic orbit), so the run stops there and says so.

:class:`PeriodicStop` is checked at every sample (:class:`mjeap.engines.frame.Samples`);
at each period boundary from the third on it compares the last period with the one before
(the earlier one interpolated at the same phase), and the one before with its own
predecessor: the tip curvature relative to its range and every centreline point relative to
the beam's length. Where the last change is within the tolerance and the changes, shrinking
as they did, add up to no more than it, it raises :class:`Decided`, which every engine turns into a run that ends
at that sample (the scene left there); :func:`mjeap.rollout` records it in
``meta['stopped_early']``. A run still drifting (relaxing, creeping, collapsing slowly)
differs by more than the tolerance and runs on.
"""
from __future__ import annotations

import numpy as np

from ..engines.frame import Decided
from ..errors import ParameterError, check_range
from ..model.analytical import arc_curvature

__all__ = ["Decided", "PeriodicStop", "check_periodic_stop", "PERIODIC_KINDS", "MIN_SAMPLES_PER_PERIOD"]


#: the waveforms that repeat with their frequency (from t = 0, without a delay)
PERIODIC_KINDS = ("sine", "square", "triangle")
#: a run that may stop is sampled at least this often a period
MIN_SAMPLES_PER_PERIOD = 8


def check_periodic_stop(tolerance, wave, duration: float, sample_interval: float):
    """The tolerance (relative, 1e-6 to 0.2) and the period (s) of a periodic stop, checked
    with the run before any work: the waveform must repeat from the start (a sine, square or
    triangle wave without a delay), the run last at least four periods and be sampled at
    least 8 times a period. Returns (tolerance, period)."""
    tol = check_range("stop_when_periodic", tolerance, 1e-6, 0.2)
    kind = getattr(wave, "kind", None)
    if kind not in PERIODIC_KINDS or float(getattr(wave, "delay", 0.0) or 0.0) != 0.0 or \
            not float(getattr(wave, "frequency", 0.0) or 0.0) > 0:
        raise ParameterError("stop_when_periodic", tolerance, "None for this waveform: a periodic stop needs a drive "
                             f"that repeats from the start ({', '.join(PERIODIC_KINDS)} without a delay; got "
                             f"{getattr(wave, 'text', None) or wave!s})")
    period = 1.0 / float(wave.frequency)
    if duration < 4 * period:
        raise ParameterError("stop_when_periodic", tolerance, f"None for a run of {duration:g} s: it can stop only "
                             f"after three periods and before its end (at least 4 periods, {4 * period:g} s)")
    if sample_interval > period / MIN_SAMPLES_PER_PERIOD:
        raise ParameterError("sample_interval", sample_interval, f"at most {period / MIN_SAMPLES_PER_PERIOD:g} s "
                             f"({MIN_SAMPLES_PER_PERIOD} samples a period) with stop_when_periodic")
    return tol, period


class PeriodicStop:
    """Raises :class:`Decided` at the first period boundary (from the third) where the last
    period repeats the one before within ``tolerance`` and the drift, shrinking from period to
    period as it did over the last two (ratio rho < 1), adds up to at most ``tolerance`` over
    all later periods (d rho / (1 - rho)): the rest of the run then stays within the tolerance
    of the last period. Quantities: the tip curvature relative to its range over the last
    three periods and every centreline point relative to ``length`` (m); ``period`` in s."""

    # Where both changes lie within twice what the samples resolve (:meth:`_floor`), the run
    # counts as settled if that resolution is within the tolerance (finer sampling resolves
    # more; a drift below the resolution is not seen).

    def __init__(self, period: float, tolerance: float, length: float):
        self.period, self.tolerance, self.length = float(period), float(tolerance), float(length)
        self._next = 3 * self.period                # first boundary with three periods behind it

    def _decided(self, d_last: float, d_before: float, floor: float):
        """(decided, rho, tail) of one quantity's period-to-period differences; ``floor``:
        the difference the samples cannot resolve (:meth:`_floor`)."""
        tol = self.tolerance
        if max(d_last, d_before) <= 1e-3 * tol:     # repeats to far below the tolerance
            return True, 0.0, 0.0
        if max(d_last, d_before) <= 2.0 * floor:    # settled, as far as the samples tell:
            return d_last <= tol and 2.0 * floor <= tol, 0.0, 0.0    # a stop only if they resolve the tolerance
        rho = d_last / d_before if d_before > 0 else np.inf
        tail = d_last * rho / (1.0 - rho) if rho < 1 else np.inf
        return d_last <= tol and tail <= tol, rho, tail

    @staticmethod
    def _floor(x: np.ndarray, h: float, dt: float) -> float:
        """The period-to-period difference a periodic run still shows in samples ``x`` taken
        every ``h`` s by a model stepping ``dt`` s: linear interpolation between samples
        (max |second difference| / 8) and the step's phase, which moves by a fraction of dt
        each period when the period is no whole number of steps (max |first difference| x
        dt / h)."""
        d1 = np.abs(np.diff(x))
        return float(d1.max() * min(dt / h, 1.0) + np.abs(np.diff(x, 2)).max() / 8.0) if len(x) > 2 else np.inf

    def __call__(self, samples) -> None:
        n = samples.n
        t = samples.t[:n]
        T = self.period
        eps = 1e-9 * T
        if t[-1] < self._next - eps:
            return
        self._next = (int(round(t[-1] / T)) + 1) * T
        use = t >= t[-1] - 3 * T - 1.5 * (t[-1] - t[-2])          # three periods and a sample before them
        pts, _ = samples.clamp_frame(np.nonzero(use)[0])
        tu = t[use]
        tip = pts[:, samples.part.layout.segments + 1]              # clamp, hinges, tip[, payload]
        kappa = arc_curvature(tip[:, 0], tip[:, 1])
        span = max(float(np.ptp(kappa)), 1e-300)
        shape = pts[:, :, :2].reshape(len(tu), -1)

        def drift(i):           # largest change from the period before, over period i (0: the last)
            sel = (tu >= tu[-1] - (i + 1) * T - eps) & (tu <= tu[-1] - i * T + eps)
            back = tu[sel] - T
            dk = np.max(np.abs(kappa[sel] - np.interp(back, tu, kappa))) / span
            ds = max(np.max(np.abs(shape[sel, j] - np.interp(back, tu, shape[:, j]))) for j in range(shape.shape[1]))
            return float(dk), float(ds) / self.length

        (k2, s2), (k1, s1) = drift(0), drift(1)
        h, dt = float(np.median(np.diff(tu))), samples.part.timestep
        floor_k = self._floor(kappa, h, dt) / span
        floor_s = max(self._floor(shape[:, j], h, dt) for j in range(shape.shape[1])) / self.length
        ok_k, rho_k, tail_k = self._decided(k2, k1, floor_k)
        ok_s, rho_s, tail_s = self._decided(s2, s1, floor_s)
        if ok_k and ok_s:
            raise Decided(f"stopped at {t[-1]:.6g} s: periodic (the last period repeats the one before within "
                          f"{self.tolerance:g}: tip curvature {k2:.2g} of its range, centreline {s2:.2g} of the "
                          f"length; " + (f"the drift shrinks {rho_k:.2g}x a period, at most {tail_k:.2g} still to "
                                         "come)" if rho_k else f"at the samples' resolution, {floor_k:.2g})"),
                          float(t[-1]))
