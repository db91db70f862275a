"""Runs at a stated accuracy on the answer: a target on named metrics of the tip curvature
(a sweep's, a map's, an optimisation's), not on the whole trajectory
(:mod:`mjeap.simulation.accuracy`). Each metric's error is taken relative to its own scale
(:mod:`mjeap.simulation.metric_scales`). ``returns`` (a boolean) is *decided* only where
|margin| exceeds the margin's estimated error; else the run is refined, and a point still
undecided after MAX_REFINEMENTS, or whose next model would cost more than the scene's own (a
margin of 3e-4 of the swing asked for 137 segments at 0.16 ms, 2 minutes), is run on the
scene's own (default) model, which then decides it (``decided_by`` says so): no point is
left undecided. A boolean's target is its decision: the margin's estimated error is reported
(the row's ``estimated_error.returns``) but not held to the target (a decided answer is the
answer).

Time-scale separation. A question read on the last drive period (:data:`LAST_PERIOD_METRICS`)
whose drive is slow against the beam's modes (the drive's fastest time constant, 1 / its
fastest pole or zero or its ``time_constant``, at least SEPARATION / omega for each mode) is
answered with steps far beyond the modes' resolution under 'discrete': backward Euler damps
the fast modes (overdamped above f = 1 / (pi h), said in ``meta['accuracy']['damped_modes']``)
and keeps the slow path. A mode as slow as the drive (the first one near the instantaneous
column load, where it softens towards zero, or the buckled straight beam's growth) is followed
instead: the step resolves it, omega h <= RESOLVED_MODE (before, such points were not relaxed
and ran at beta / 2: 3.4 s against the default model's 1.5 s at 129 mg; now 0.1 s). The step
is chosen by the error model on the answer and bounded by the drive's fastest time constant /
STEPS_PER_TAU, the waveform's period / STEPS_PER_DRIVE_PERIOD and the sample interval, not by beta / 2 (the
refusal of such steps stays for trajectories and for user timesteps). Maxima over the whole
run (they read the release transient), drives without a time constant (the piezo bimorph,
the electrostrictive film) and electrical quantities (power, current, phase: not metrics of
this module; a sweep asking for them puts its target on the trajectory) keep the
trajectory's bound, 1/8 of the first mode's period, and beta / 2 (on pvdf-60's release
ringing a step of 1/8 period, damped by backward Euler in the run and its companions alike,
was 38 x off its estimate).

A posteriori, on the same quantities: the chosen run F = (N, h), a companion of the same N
at 2 h and one of :func:`~mjeap.simulation.accuracy.fewer_segments` at 2 h. The step's error
of each metric is |q(F) - q(F_2h)| / scale (order 1 assumed: backward Euler with the drive
held over the step; 3 x high where it is 2). With relaxed steps a third companion of the
same N at 4 h is run and the metric is extrapolated (Richardson, order 1 -> 2,
:func:`_extrapolate`): where the observed order log2((q_2h - q_4h) / (q - q_2h)) is within
EXTRAPOLATION_ORDERS of 1, the value reported is q + (q - q_2h) (``extrapolated``; the run's
own in ``run_value``, the trajectory returned is the run at h) and its step error
|(q + d1) - (q_2h + d2)| / 3, at least EXTRAPOLATION_FLOOR x the correction; outside the
window the run's own value stands and the next model halves the step (until the steps are
in the asymptotic range). The sweep's rows read the reported values
(:func:`reported_value`). Measured on nine of the map's points, 8 segments (against the
same segments at 0.5 and 1 ms, extrapolated; that reference's own spread up to 0.07 % of the
swing): at 25 ms the run's own peak-to-peak is 0.08-4.4 % of the swing off, the extrapolated
one 0.001-0.15 % (1.2 % at 100 mg, 1.5 V, where the order is outside the window). The
segments' error |q(F_2h) - q(S_2h)| / scale / ((N / n)^2 - 1) (order 2), and where F is
sampled coarser than its step (a user's interval) the sampling's, |q(F) - q(F every other
sample)| / 3, combined in quadrature. Each run is sampled every step otherwise: the drive
held over a step puts a square wave's peak one step after its switch, and a grid coarser
than the step reads the models' peaks unequally (on thick-trilayer's length sweep that hid
a 0.7 % error from the companions); such a run is read from the states ``mujoco.rollout``
returns for all its steps (the native engine's
:meth:`~mjeap.engines.native.NativeEngine.read_states`), not sampled from Python, and a
refinement reuses the runs already made (its 2 h companion is the last chosen run where it
halves the step). Where a metric's estimate exceeds the target (or a boolean is undecided), the
error model e = sqrt((a / N^2)^2 + (b h)^2) takes a and b from the measured parts and a finer
model is run. Measured numbers: docs/concepts/accuracy.md, scripts/bench.py.
"""
from __future__ import annotations

import math
import time as _time
from dataclasses import asdict
from typing import Dict, List, Optional, Sequence

import numpy as np

from ..engines.result import TipPath
from ..errors import ParameterError
from ..model.modes import modal_frequencies
from .metric_scales import LAST_PERIOD_METRICS, METRIC_SCALES, check_metrics, metric_quantity, metric_scale, relative
from .accuracy import (SAFETY, ErrorModel, Model, as_error_model, check_accuracy, check_targetable, choose_model,
                       fewer_segments)

__all__ = ["relaxed_step_cap", "run_metrics_at_accuracy"]

#: a relaxed step divides the drive period / SAMPLES_PER_PERIOD (the square wave's switching
#: instants on its grid)
SAMPLES_PER_PERIOD = 100
#: the drive's fastest time constant must be this many x the first mode's 1 / omega_1
SEPARATION = 10.0
#: a mode as slow as the drive (omega tau < SEPARATION) is resolved by a relaxed step:
#: omega h at most this (about 60 steps a period)
RESOLVED_MODE = 0.1
#: steps per drive time constant and per drive period, at most
STEPS_PER_TAU = 20
STEPS_PER_DRIVE_PERIOD = 100
#: the first model tried without an error model: segments (the step: the cap)
START_SEGMENTS = 8
#: the step's error of a metric from one companion at 2 h: d / (2^p - 1) with the order p =
#: 1 assumed (backward Euler with the drive held over the step: the beam follows a step
#: late; measured first order on thick-trilayer's length sweep, where p = 1.5 gave 0.56 x
#: the true error): 3 x high where the order is 2
STEP_RICHARDSON = 1.0
MAX_REFINEMENTS = 3
#: Richardson extrapolation of a relaxed run's metrics (order 1 -> 2, :func:`_extrapolate`):
#: where the observed order from the runs at h, 2 h and 4 h, log2(d2 / d1), lies in this window
EXTRAPOLATION_ORDERS = (0.7, 1.4)
#: the extrapolated value's step error is taken as at least this fraction of the correction
#: it made: three steps see the h^2 term, not where the relaxed branch's limit (its fast modes
#: overdamped) differs from the resolved solution (measured on the map's points near the
#: column load, 70-82 mg at 25 ms against runs at 0.5 and 1 ms: 0.06-0.075 of it)
EXTRAPOLATION_FLOOR = 0.1
#: cost of a run of a model: RUN_OVERHEAD + steps x (c0 + c1 N) (us; this 2-core machine,
#: the map's scene under 'discrete', read from its states (the native engine's read_states): building
#: a variant and its native model about 12 ms, a step of 8 segments 12-15 us, of 16 27-35 us)
RUN_OVERHEAD_US = 15_000.0
COST_PER_STEP = (1.0, 1.6)
#: a model is never chosen with more steps than this (a boolean at its edge falls back to
#: the scene's own model instead)
MAX_MODEL_STEPS = 2_000_000


def _drive_tau(drive) -> Optional[float]:
    """The drive's fastest time constant (s): 1 / its fastest pole or zero, else its
    ``time_constant`` parameter; None without either (an instantaneous drive)."""
    tf = getattr(drive, "transfer_function", None)
    if tf is None:
        tau = getattr(drive, "params", {}).get("time_constant")
        return float(tau) if tau else None
    try:
        f = tf()
        rates = [abs(complex(x)) for x in list(f.poles) + list(f.zeros)]
    except Exception:           # a drive without a linear form
        return None
    rates = [x for x in rates if x > 0]
    return 1.0 / max(rates) if rates else None


def relaxed_step_cap(scene, drive, wave, metrics: Sequence[str] = LAST_PERIOD_METRICS) -> tuple:
    """(h_cap s, why) for a target on ``metrics``: the drive's fastest time constant /
    STEPS_PER_TAU and the waveform's period / STEPS_PER_DRIVE_PERIOD where every metric reads
    the last period and the drive is slow against the beam's modes (time-scale separation),
    else (None, why not). A mode that is not (omega tau < SEPARATION: the first one near the
    column load, where it softens towards zero, or a buckled beam's growth rate) is followed
    instead of damped: the step then resolves it, omega h <= RESOLVED_MODE; where that leaves
    no step beyond beta / 2 the steps are not relaxed."""
    fast = [m for m in metrics if m not in LAST_PERIOD_METRICS]
    if fast:
        return None, f"{fast[0]} reads the whole run (its release transient is as fast as the beam's modes)"
    if wave is None or not getattr(wave, "frequency", 0):
        return None, "no drive period (the metrics' last period is the run's second half)"
    tau = _drive_tau(drive)
    if tau is None:
        return None, f"the {getattr(drive, 'name', 'drive')} drive has no time constant to bound the step"
    # the beam's rates (rad/s, gravity's load included; a negative eigenvalue: a growth rate)
    rates = np.sqrt(np.abs(modal_frequencies(scene.linearization))) / scene.units.time
    slow = rates[rates * tau < SEPARATION]
    cap = tau / STEPS_PER_TAU
    f = getattr(wave, "max_frequency", 0.0) or getattr(wave, "frequency", 0.0) or 0.0
    if f > 0:
        cap = min(cap, 1.0 / (STEPS_PER_DRIVE_PERIOD * f))
    why = (f"time-scale separation: the drive's fastest time constant {tau:.3g} s against the beam's modes; step at "
           f"most tau / {STEPS_PER_TAU}" + (f" and the drive period / {STEPS_PER_DRIVE_PERIOD}" if f > 0 else ""))
    if slow.size:
        w = float(slow.max())
        if w > 0:
            cap = min(cap, RESOLVED_MODE / w)
        if cap <= 0.5 * scene.choice.rayleigh_beta:
            return None, (f"the drive's fastest time constant {tau:.3g} s is not {SEPARATION:g} x slower than the "
                          f"beam's mode at {w / (2 * math.pi):.3g} Hz, nor can a relaxed step resolve it")
        why += (f"; {slow.size} mode(s) as slow as the drive (up to {w / (2 * math.pi):.3g} Hz) followed, not damped: "
                f"omega h <= {RESOLVED_MODE:g}")
    return cap, why


# ---------------------------------------------------------------- the choice
def _cost(model: Model, duration: float) -> float:
    c0, c1 = COST_PER_STEP
    return RUN_OVERHEAD_US + duration / model.timestep * (c0 + c1 * model.segments)


def _on_grid(h: float, grid: float) -> float:
    return grid / max(1, math.ceil(grid / h * (1 - 1e-12)))


def _integrator(scene, h: float) -> str:
    """'implicitfast' where h and the 2 h companion stay within the Rayleigh beta (about its
    stability limit), else 'discrete'."""
    return "implicitfast" if 2 * h <= scene.choice.rayleigh_beta else "discrete"


def _choose(scene, em: ErrorModel, target: float, duration: float, grid: float, h_cap: float,
            widest: int = 2) -> Model:
    """The cheapest model with predicted error <= target / SAFETY, h on the grid / ``widest``
    (the widest companion's step divides it: 2 h, or 4 h where it extrapolates), a run's
    overhead in its cost."""
    return choose_model(scene, em, target, duration, grid, h_cap, widest=widest, cost=_cost, integrator=_integrator)


class _EveryOther:
    """A run's samples, every other one (the sampling's own companion)."""

    def __init__(self, r):
        self.time, self.tip_curvature, self.tip_position = r.time[::2], r.tip_curvature[::2], r.tip_position[::2]


#: the sampling's error of a metric from its value on every other sample: d / (2^2 - 1), a
#: smooth extremum read between samples being off by O(interval^2)
SAMPLING_RICHARDSON = 3.0


def _extrapolate(q: float, q_2h: float, q_4h: float) -> Optional[tuple]:
    """(value, step error) of a metric from its values at h, 2 h and 4 h by Richardson's
    extrapolation at order 1 (backward Euler, the drive held over the step): d1 = q - q_2h,
    d2 = q_2h - q_4h; where the observed order log2(d2 / d1) is within
    EXTRAPOLATION_ORDERS the value is q + d1 (its first-order error removed) and its error
    |(q + d1) - (q_2h + d2)| / 3 (order 2) plus |d1| |1 - 1 / (2^p - 1)| (the order-p
    sequence's limit against order 1's), at least EXTRAPOLATION_FLOOR x |d1|; None outside
    the window (not in the asymptotic range: the run's own value stands)."""
    p = _observed_order(q, q_2h, q_4h)
    if p is None or not EXTRAPOLATION_ORDERS[0] <= p <= EXTRAPOLATION_ORDERS[1]:
        return None
    d1, d2 = q - q_2h, q_2h - q_4h
    # the h^2 remainder, and what assuming order 1 leaves where the observed order is p: the
    # limit of an order-p sequence is q + d1 / (2^p - 1)
    err = abs(2 * d1 - d2) / 3.0 + abs(d1) * abs(1.0 - 1.0 / (2.0 ** p - 1.0))
    return q + d1, max(err, EXTRAPOLATION_FLOOR * abs(d1))


def _observed_order(q: float, q_2h: float, q_4h: float) -> Optional[float]:
    """log2(d2 / d1) of :func:`_extrapolate` (None where d1 is 0 or the signs differ)."""
    d1, d2 = q - q_2h, q_2h - q_4h
    return math.log2(d2 / d1) if d1 != 0 and d2 / d1 > 0 else None


def _evaluate(metrics, runs, period, duration, step) -> Dict[str, dict]:
    """Each metric's value and its (step, segments, sampling) errors relative to its scale,
    from the runs (F, F_2h, S_2h, F_4h or None) and the segment counts (N, n): the value
    F's own, or extrapolated where F_4h was run and the step's order is observed to be 1
    (:func:`_extrapolate`; ``run_value`` then holds F's own); the sampling's error only
    where F was sampled coarser than its ``step``."""
    (f, mid, fewer, quad), (n_f, n_s) = runs
    coarse = len(f.time) > 1 and f.time[1] - f.time[0] > 1.5 * step      # sampled coarser than its step
    sparse = _EveryOther(f)
    out = {}
    for name in metrics:
        q = [metric_quantity(name, r, period) for r in (f, mid, fewer, sparse)]
        scale = metric_scale(name, f, q[0], period, duration)
        e_h = relative(abs(q[0] - q[1]), scale) / STEP_RICHARDSON
        e_s = relative(abs(q[1] - q[2]), scale) / ((n_f / n_s) ** 2 - 1)
        e_t = relative(abs(q[0] - q[3]), scale) / SAMPLING_RICHARDSON if coarse else 0.0
        q4 = None if quad is None or coarse else metric_quantity(name, quad, period)
        x = None if q4 is None else _extrapolate(q[0], q[1], q4)
        value = q[0]
        if x is not None:
            value, e_h = x[0], relative(x[1], scale)
        e = math.sqrt(e_h ** 2 + e_s ** 2 + e_t ** 2)
        row = {"value": value, "estimated_error": e, "step_error": e_h, "segments_error": e_s,
               "sampling_error": e_t, "scale": METRIC_SCALES[name], "extrapolated": x is not None}
        if q4 is not None:
            row["observed_step_order"] = _observed_order(q[0], q[1], q4)
        if x is not None:
            row["run_value"] = q[0]
        if name == "returns":       # decided beyond its error, and on the run's own side where extrapolated
            margin = relative(value, scale)
            row.update(margin=margin, decided=abs(margin) > e and (x is None or (value > 0) == (q[0] > 0)))
        out[name] = row
    return out


def _needs(metrics: Dict[str, dict], target: float) -> float:
    """The error the next model must reach: the target (for the metrics that are numbers),
    and below each undecided boolean's margin (a boolean's target is its decision); 0 where
    the run is good enough."""
    worst = max([m["estimated_error"] for m in metrics.values() if "decided" not in m] or [0.0])
    need = target if worst > target else math.inf
    for m in metrics.values():
        if "decided" in m and not m["decided"]:
            need = min(need, abs(m["margin"]) / 2)
    return 0.0 if need == math.inf else need


class _Choice:
    """One question's runs of ``scene`` (``run(scene, interval, every_step, tip_only)``): the
    steps it may take, every run made (kept, so an attempt reuses what an earlier one ran)
    and its log; :meth:`attempt` runs a model with its companions and evaluates the metrics."""

    def __init__(self, scene, run, names, duration: float, drive, wave, sample_interval: Optional[float]):
        self.scene, self.run, self.names, self.duration = scene, run, names, duration
        self.sample_interval = sample_interval
        self.period = 1.0 / wave.frequency if wave is not None and getattr(wave, "frequency", 0) else None
        self.relaxed, self.why = relaxed_step_cap(scene, drive, wave, names)
        # not relaxed: 1/8 of the first mode's period, and beta / 2 (the step's own damping under
        # 'discrete' at most half the beam's: a maximum over the release transient reads its
        # ringing, which a larger step damps in the run and its companions alike, unseen)
        trajectory_cap = min(1.0 / (8 * scene.choice.first_frequency), 0.5 * scene.choice.rayleigh_beta or math.inf)
        h_cap = self.relaxed if self.relaxed is not None else trajectory_cap
        # each run sampled every step (a peak one step after a switch, the drive held over the
        # step, is then each model's own); the relaxed step on a grid of the drive period
        self.own_grid = self.relaxed is not None and sample_interval is None
        self.grid = self.period / SAMPLES_PER_PERIOD if self.own_grid else (sample_interval or duration)
        self.h_cap = min(h_cap, self.grid)
        self.widest = 4 if self.relaxed is not None and self.own_grid else 2   # the widest companion's step factor
        self.log: List[dict] = []
        self.done: Dict[tuple, tuple] = {}      # (model, interval) -> (scene, result)

    def one(self, model: Model, role: str, interval=None, tip_only: bool = False):
        """The run of ``model`` sampled every ``interval`` s (a companion's: ``tip_only``,
        where it is read from its states: the tip alone, all its metrics read)."""
        key = (model, interval)
        if key in self.done and (tip_only or not isinstance(self.done[key][1], TipPath)):
            self.log.append({"role": role + " (reused)", **asdict(model), "wall_time_s": 0.0})
            return self.done[key]
        s = self.scene.variant(model.segments, model.timestep, model.integrator)
        t = _time.perf_counter()
        out = self.run(s, interval, every_step=interval == model.timestep, tip_only=tip_only)
        self.log.append({"role": role, **asdict(model), "wall_time_s": _time.perf_counter() - t})
        self.done[key] = s, out
        return s, out

    def extrapolating(self, model: Model) -> bool:
        """Whether an attempt at ``model`` adds the run at 4 h (:func:`_extrapolate`): relaxed
        steps under 'discrete', each run sampled every step, 4 h dividing the drive's grid."""
        k = self.grid / (4 * model.timestep)
        return self.relaxed is not None and self.own_grid and model.integrator == "discrete" and k >= 1 - 1e-9 and \
            abs(k - round(k)) <= 1e-9 * k

    def runs_of(self, model: Model) -> list:
        """The runs an attempt at ``model`` needs: it and its companions (2 h, fewer segments
        at 2 h, and 4 h where it extrapolates)."""
        h2, si = 2 * model.timestep, self.sample_interval
        out = [(model, si or model.timestep), (Model(model.segments, h2, model.integrator), si or h2),
               (Model(fewer_segments(model.segments), h2, model.integrator), si or h2)]
        if self.extrapolating(model):
            out.append((Model(model.segments, 2 * h2, model.integrator), 2 * h2))
        return out

    def new_cost(self, model: Model) -> float:
        """The cost of an attempt at ``model``, less the runs already done."""
        return sum(_cost(m, self.duration) for m, i in self.runs_of(model) if (m, i) not in self.done)

    def choose(self, em: ErrorModel, need: float, h_cap: float) -> Model:
        return _choose(self.scene, em, need, self.duration, self.grid, h_cap, self.widest)

    def refine(self, em: ErrorModel, need: float, last: Model, pre_asymptotic: bool) -> Model:
        """The cheapest next model by the error model: :func:`_choose`'s, or ``last``'s
        segments at an integer fraction of its step (its runs then serve as companions);
        where ``last``'s step was outside the asymptotic range (``pre_asymptotic``: a
        metric's observed order outside EXTRAPOLATION_ORDERS), half its step: at its
        segments where the error model's spatial part allows them (the runs at h and 2 h
        then serve as companions), else at the segments that part needs."""
        if pre_asymptotic:
            h = min(self.h_cap, last.timestep / 2)
            if em.spatial / last.segments ** 2 <= need / SAFETY:
                return Model(last.segments, h, _integrator(self.scene, h))
            return self.choose(ErrorModel(em.spatial, 0.0), need, h)
        best = self.choose(em, need, self.h_cap)
        for k in (2, 3, 4, 6, 8):
            m = Model(last.segments, last.timestep / k, last.integrator)
            if em.predict(m) <= need / SAFETY and _integrator(self.scene, m.timestep) == last.integrator and \
                    self.new_cost(m) < self.new_cost(best):
                best = m
        return best

    def attempt(self, model: Model, role: str):
        """(scene, result, metrics) of a run of ``model`` checked against its companions."""
        (m_f, i_f), (m_mid, i_mid), (m_s, i_s), *rest = self.runs_of(model)
        chosen, f = self.one(m_f, role, i_f)
        _, mid = self.one(m_mid, "companion", i_mid, tip_only=True)
        _, fewer = self.one(m_s, "spatial companion", i_s, tip_only=True)
        quad = self.one(rest[0][0], "extrapolation companion", rest[0][1], tip_only=True)[1] if rest else None
        return chosen, f, _evaluate(self.names, ((f, mid, fewer, quad), (model.segments, m_s.segments)), self.period,
                                    self.duration, model.timestep)

    def decide_by_default(self, found: Dict[str, dict]):
        """The scene's own (default) model run, deciding the booleans still undecided in
        ``found`` (updated); its result."""
        scene, t = self.scene, _time.perf_counter()
        result = self.run(scene, self.sample_interval)
        self.log.append({"role": "default model (undecided at the target)", "segments": scene.layout.segments,
                         "timestep": scene.timestep, "integrator": scene.integrator,
                         "wall_time_s": _time.perf_counter() - t})
        for k, m in found.items():
            if "decided" in m and not m["decided"]:
                value = metric_quantity(k, result, self.period)
                for gone in ("run_value", "observed_step_order"):
                    m.pop(gone, None)
                scale = metric_scale(k, result, value, self.period, self.duration)
                m.update(value=value, margin=relative(value, scale), extrapolated=False, decided=True,
                         decided_by=DEFAULT_DECIDES)
        return result


#: who decides a boolean the chosen model leaves undecided
DEFAULT_DECIDES = "the scene's own model: undecided by the chosen model's estimate"


def run_metrics_at_accuracy(scene, run, *, metrics: Sequence[str], accuracy: float, duration: float, drive,
                            wave=None, sample_interval: Optional[float] = None, error_model=None):
    """Choose, run and check a model of ``scene`` whose ``metrics`` (names of
    :data:`METRIC_SCALES`) are within ``accuracy`` of their scales. ``run(scene, interval,
    every_step=False, tip_only=False)`` runs one model sampled every ``interval`` s (None:
    every step) and returns a RolloutResult; with ``every_step`` (sampled every step) read
    from its states where the native engine can (:meth:`mjeap.engines.native.NativeEngine.read_states`;
    the companions ``tip_only``: a :class:`~mjeap.engines.result.TipPath`);
    ``drive`` (the question's drive) bounds the relaxed step. ``error_model``:
    (a, b) of a similar question (a sweep's earlier point) choosing the first model. Returns
    (result, scene of the chosen model, report), the report also in
    ``result.meta['accuracy']`` with one entry per metric under ``'metrics'``. The chosen
    scene is shared (:meth:`mjeap.Scene.variant`): a later run of the same model in this
    thread resets its state."""
    target = check_accuracy(accuracy)
    names = check_metrics(metrics)
    given = None if error_model is None else as_error_model(error_model)
    check_targetable(scene, accuracy)
    t0 = _time.perf_counter()
    c = _Choice(scene, run, names, duration, drive, wave, sample_interval)
    if given is not None:       # not below START_SEGMENTS: a family's first point (its lightest load, on the
        # map) predicts too few for the rest (from 4 segments 13 of the map's 23 other points were refined)
        model = c.choose(given, target, c.h_cap)
        model = Model(max(model.segments, START_SEGMENTS), model.timestep, model.integrator)
    else:
        h0 = _on_grid(c.h_cap, c.grid / c.widest)
        model = Model(START_SEGMENTS, h0, _integrator(scene, h0))
    chosen, result, found = c.attempt(model, "chosen")
    em = given or ErrorModel(0.0, 0.0)
    own_cost = _cost(Model(scene.layout.segments, scene.timestep, scene.integrator), duration)
    refinements, decided_by = 0, None
    need = _needs(found, target)
    while need > 0 and refinements < MAX_REFINEMENTS:
        # the metrics that ask for more: numbers beyond the target, undecided booleans
        short = [m for m in found.values() if (not m["decided"] if "decided" in m else m["estimated_error"] > target)]
        em = ErrorModel(max(max(m["segments_error"] for m in short) * model.segments ** 2, 1e-12),
                        max(max(m["step_error"] for m in short) / model.timestep, 1e-12))
        nxt = c.refine(em, need, model, any("observed_step_order" in m and not m["extrapolated"] for m in short))
        if duration / nxt.timestep > MAX_MODEL_STEPS or \
                (nxt.segments <= model.segments and nxt.timestep >= model.timestep):
            break
        if all("decided" in m for m in short) and c.new_cost(nxt) > own_cost:
            break       # only a boolean at its edge: the scene's own model decides it for less
        refinements += 1
        model = nxt
        chosen, result, found = c.attempt(model, "refined")
        need = _needs(found, target)
    if any("decided" in m and not m["decided"] for m in found.values()):    # a boolean at its edge
        result = c.decide_by_default(found)
        chosen, decided_by = scene, DEFAULT_DECIDES
    report = _report(c, found, model, em, given=given, target=target, refinements=refinements, decided_by=decided_by,
                     wall=_time.perf_counter() - t0)
    result.meta["accuracy"] = report
    if report["damped_modes"]:
        result.meta.setdefault("warnings", []).append(report["damped_modes"])
    if not report["met"]:
        result.meta.setdefault("warnings", []).append(
            f"accuracy target {target:g} on {', '.join(names)} not met: estimated error "
            f"{report['estimated_error']:.3g} with {Model(**report['model']).describe()} after {refinements} "
            "refinements")
    return result, chosen, report


def _report(c: _Choice, found: Dict[str, dict], model: Model, em: ErrorModel, *, given, target: float,
            refinements: int, decided_by: Optional[str], wall: float) -> dict:
    """What a choice reports (``meta['accuracy']``): the model, each metric, the error held
    to the target (the numbers': a boolean's target is its decision), the runs."""
    scene = c.scene
    numbers = [m["estimated_error"] for m in found.values() if "decided" not in m]
    worst = max(numbers or [m["estimated_error"] for m in found.values()])
    met = all(m["decided"] if "decided" in m else m["estimated_error"] <= target for m in found.values())
    h = model.timestep
    damped = None
    if h > scene.choice.rayleigh_beta and model.integrator == "discrete":
        damped = (f"modes above {1 / (math.pi * h):.3g} Hz overdamped by the step (backward Euler, h = {h:.3g} s; "
                  f"first mode {scene.choice.first_frequency:.3g} Hz, its damping ratio raised to about "
                  f"{math.pi * scene.choice.first_frequency * h:.2g}): the answer is the slow path")
    report = {"quantity": "metrics: " + ", ".join(f"{k} (relative to its {METRIC_SCALES[k]})" for k in c.names),
              "target": target, "model": asdict(model), "estimated_error": worst, "met": met,
              "metrics": found, "relaxed_step": c.why if c.relaxed is not None else None,
              "relaxed_step_refused": None if c.relaxed is not None else c.why, "damped_modes": damped,
              "decided_by": decided_by,
              "estimate": "each metric on the chosen run against companions of the same segments at 2 h (step, "
                          "order 1 assumed) and of fewer segments at 2 h (segments, order 2), in quadrature; with "
                          "relaxed steps also at 4 h: Richardson-extrapolated where the observed order is near 1",
              "values_from": ("the chosen model's runs (the numbers); the trajectory and the undecided booleans "
                              "from the scene's own model" if decided_by else "the chosen model's runs"),
              "error_model": {"spatial_a": em.spatial, "temporal_b_per_s": em.temporal,
                              "form": "e = sqrt((a / N^2)^2 + (b h)^2)",
                              "pilots": "given" if given is not None else "none: measured on the runs"},
              "refinements": refinements, "runs": c.log, "wall_time_s": wall}
    if refinements == 0 and given is None:      # the error model of this question, for the next
        report["error_model"].update(
            spatial_a=max(max(m["segments_error"] for m in found.values()) * model.segments ** 2, 1e-12),
            temporal_b_per_s=max(max(m["step_error"] for m in found.values()) / model.timestep, 1e-12))
    return report
