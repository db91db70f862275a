"""The metrics an accuracy target may be put on (:mod:`mjeap.simulation.metric_accuracy`),
the number behind each in a run and the scale its error is relative to (:data:`METRIC_SCALES`):

* ``peak_to_peak`` (last drive period): the swing of the run (peak-to-peak tip curvature
  over the whole run), as the trajectory's target is;
* ``max_stress_proxy``, ``max_tip_deflection``: their own value;
* ``settling_time``: the drive period (the run's duration without one);
* ``returns`` (a boolean: the tip curvature changes sign in the last period): its margin,
  min(max kappa, -min kappa) over the last period relative to the swing (> 0: returns).
"""
from __future__ import annotations

import math
from typing import Optional, Sequence

import numpy as np

from ..errors import ParameterError

__all__ = ["METRIC_SCALES", "LAST_PERIOD_METRICS", "BOOKKEEPING", "check_metrics", "answerable", "last_period",
           "peak_to_peak", "returns_margin", "metric_quantity", "metric_scale", "relative", "reported_value"]

#: the metrics a target may be put on, and the scale each one's error is relative to
METRIC_SCALES = {"peak_to_peak": "swing", "returns": "margin", "max_stress_proxy": "value",
                 "max_tip_deflection": "value", "settling_time": "period"}
#: metrics read on the last drive period: slow questions where the drive is (time-scale
#: separation); the others (a maximum over the run, a settling time) read the release
#: transient and keep the trajectory's step bound
LAST_PERIOD_METRICS = ("peak_to_peak", "returns")
#: bookkeeping columns of a sweep: not quantities, ignored where a target's metrics are read
BOOKKEEPING = ("estimated_error", "stopped_early")


def check_metrics(metrics) -> tuple:
    """``metrics`` as a tuple of names of :data:`METRIC_SCALES`, refused otherwise."""
    if isinstance(metrics, str):
        metrics = (metrics,)
    try:
        names = tuple(str(m) for m in metrics)
    except TypeError:
        names = ()
    bad = [m for m in names if m not in METRIC_SCALES] if names else [metrics]
    if bad:
        raise ParameterError("metrics", bad[0], f"names among {', '.join(METRIC_SCALES)} (a target on the "
                             "trajectory: leave metrics out)")
    return names


def answerable(metrics: Sequence[str]) -> bool:
    """Whether a target on ``metrics`` (a sweep's, bookkeeping columns aside) is one this
    module answers: all of them tip-curvature metrics of :data:`METRIC_SCALES`."""
    names = [m for m in metrics if m not in BOOKKEEPING]
    return bool(names) and all(m in METRIC_SCALES for m in names)


def last_period(time: np.ndarray, period: Optional[float]) -> np.ndarray:
    """Mask of the samples in the last drive period (``period`` s; the second half of the
    run without one, or where the run is not longer than it)."""
    t_end = time[-1]
    t0 = t_end - period if period and period < t_end else 0.5 * t_end
    return time >= t0 - 1e-9 * t_end           # the sample at the period's start (round-off) included


def peak_to_peak(time, kappa, period) -> float:
    """Peak-to-peak tip curvature (1/m) over the last drive period."""
    return float(np.ptp(kappa[last_period(time, period)]))


def returns_margin(time, kappa, period) -> float:
    """min(max kappa, -min kappa) over the last drive period (1/m): > 0 where the tip
    curvature changes sign there (Dadras et al. 2021's criterion), its distance from deciding else."""
    k = kappa[last_period(time, period)]
    return float(min(k.max(), -k.min()))


def _settling_time(r) -> float:
    k = r.tip_curvature
    band = 0.02 * max(abs(k[-1] - k[0]), 1e-300)
    outside = np.nonzero(np.abs(k - k[-1]) > band)[0]
    return float(r.time[outside[-1] + 1]) if outside.size and outside[-1] + 1 < k.size else 0.0


def metric_quantity(name: str, r, period: Optional[float]) -> float:
    """The number behind metric ``name`` in run ``r`` (its margin for ``returns``)."""
    if name == "peak_to_peak":
        return peak_to_peak(r.time, r.tip_curvature, period)
    if name == "returns":
        return returns_margin(r.time, r.tip_curvature, period)
    if name == "max_stress_proxy":
        return float(np.abs(r.tip_curvature).max())
    if name == "max_tip_deflection":
        return float(np.abs(r.tip_position[:, 1]).max())
    return _settling_time(r)


def metric_scale(name: str, r, value: float, period: Optional[float], duration: float) -> float:
    """The scale of metric ``name``'s error in run ``r`` (:data:`METRIC_SCALES`)."""
    kind = METRIC_SCALES[name]
    if kind in ("swing", "margin"):
        return float(np.ptp(r.tip_curvature))
    if kind == "period":
        return period or duration
    return abs(value)


def relative(x: float, scale: float) -> float:
    """``x`` relative to ``scale`` (0 for 0 on a zero scale, inf else)."""
    return x / scale if scale > 0 else (0.0 if x == 0 else math.inf)


def reported_value(result, name: str, period: Optional[float]) -> float:
    """The value of metric ``name`` a run at a target on metrics reports (its margin for
    ``returns``): ``meta['accuracy']['metrics'][name]['value']`` where the target was on
    it (extrapolated where the report says so), else read from the run's samples."""
    found = result.meta.get("accuracy", {}).get("metrics", {}).get(name)
    return float(found["value"]) if found and "value" in found else metric_quantity(name, result, period)
