"""Runs at a stated accuracy: the cheapest hinge-chain model (segments, integrator, timestep)
whose error stays below a target, and an a-posteriori estimate of the error it made.

The quantity: the tip curvature kappa (1/m, the arc through clamp and tip, as Dadras et al. 2021
measures it). A run's error is max over its samples of |kappa - kappa_converged| divided by
the swing (peak to peak) of kappa over the run: ``accuracy=1e-3`` asks for 0.1 % of the swing.

A priori, the error of N segments stepped at h is modelled as

    e(N, h) = sqrt((a / N^2)^2 + (b h)^2)

* a / N^2: the midpoint-rule chain converges in segments with order 2 (measured 2.00,
  tests/test_convergence.py). ``a`` is measured on the run itself by two pilot runs of
  PILOT_SEGMENTS (6 and 12) at one coarse step: their difference is a (1/6^2 - 1/12^2), the
  step's error (about the same in both) cancelling (pilots of 4 and 8 segments gave
  estimates above 3 x the true error on 2 of 24 seeded cases, 6 and 12 on 1 of 24). It holds
  the geometry (a chord of a bent segment is shorter than its arc: (kappa L / N)^2 / 24) and
  the discretised gravity and payload loads.
* b h: the semi-implicit (and under 'discrete' backward) Euler step with the drive's moment
  held over it (zero-order hold) is first order in h (measured on Dadras et al. 2021-002's beams; the
  beam follows its drive about a step late). ``b`` is measured by a third pilot of 6
  segments at h / 2: its difference from the first is b h / 2 (the segments' error
  cancelling).

The two are combined in quadrature, not added: the chord error is largest where the beam is
most bent, the lag where it moves fastest, at different instants (on Dadras et al. 2021's heaviest run
the sum overstates the default model's error 1.9 x, the root sum of squares 1.3 x).
The cheapest (N, h) with e(N, h) <= target / SAFETY is taken, a step costing about
COST_PER_STEP = c0 + c1 N (measured, ``scripts/bench.py``): under ``implicitfast`` where 4 h
is within its default share of the stability limit (cheaper per step), else under
``discrete`` (no stability limit on the hinge chain; above the Rayleigh beta the step's own
damping h K exceeds the beam's, which shows in the estimate).

A posteriori: the chosen run F = (N, h) and two companions of the same N at 2 h and 4 h. The
step's observed order is 1 to 2 (1 for a beam following its drive, 2 for the phase of a
lightly damped mode), so the rate is measured, not assumed: with d1 = max|F - F_2h| and
d2 = max|F_2h - F_4h| over the swing, r = d2 / d1 and Richardson's extrapolation gives the
step's error d1 / (r - 1) (r clipped to RATIO_RANGE). The segments' error is a / N^2 with the
pilots' a (order 2 is established); the estimate combines both in quadrature.

Where that exceeds the target, the model's constants are scaled by estimate / e(F) and a
finer F is run with its own companions (at most MAX_REFINEMENTS times; a target not met then
is said in the result's warnings). A run, its companions and the pilots share their
integrator: 'implicitfast' where 4 h stays within the default step, else 'discrete'. All runs
sample the same instants (every timestep divides the sample interval), so their curvatures
are compared sample by sample.

Given an error model (``error_model``: the constants of an earlier, similar question, a
sweep's first point) the pilots are skipped; a and b then only choose the model, and the
segments' error of the estimate is measured on the question itself: a companion of about
N / sqrt 2 segments at 2 h against the 2 h companion (Richardson, order 2; the step's error,
about the same in both, cancels), so the estimate is the run's own. An optimistic prior
costs a refinement (its constants then each from its measured part); a pessimistic one
over-resolves (nothing coarsens a model that met its target), and one that would exceed the
step budget falls back to the question's own pilots. A batch (``rollout_batch``) runs its
pilots on its first member alone and measures every member the same way (``pilot_run``). The shared path's estimate leans low
where Richardson's step part does (pre-asymptotic rates under 'discrete'): measured 0.38 to
1.3 x the true error on the test's question, against 0.93 to 3.9 x with pilots, whose a
carries some of the step's error. On the 11 seeded cases below, each from priors 4 x off
its own constants either way: true error below the target in all 22 runs, the estimate
0.82 to 5.5 x the true error (within 3 x in 19).

Measured on 24 seeded cases (``mjeap.validation.accuracy_claim``, seed 23: four actuators
with their drives, targets 1e-4 .. 1e-2): the true error is below the target in all (at most
0.57 x it), the estimate 0.93 to 3.9 x the true error, within 3 x in 23 of 24.
"""
from __future__ import annotations

import math
import time as _time
from dataclasses import dataclass, asdict
from typing import List, Optional

import numpy as np

from ..errors import ParameterError
from ..model.mjcf import HINGE_CHAIN_ERROR

__all__ = ["QUANTITY", "ACCURACY_RANGE", "Model", "ErrorModel", "check_accuracy", "target_for", "relative_difference",
           "calibrate", "choose_model", "check_targetable", "run_at_accuracy", "estimate_error", "as_error_model", "fewer_segments",
           "spatial_error", "half_step_error", "estimate_system_error"]

QUANTITY = ("tip curvature: max over the samples of |kappa - kappa_converged| / swing, the swing being the "
            "peak-to-peak tip curvature of the run")
#: targets accepted (relative to the swing): below 1e-5 the converged reference itself is
#: in doubt (round-off of the arc read-out); above 0.2 the answer is not a simulation
ACCURACY_RANGE = (1e-5, 0.2)
PILOT_SEGMENTS = (6, 12)
#: the pilots step at PILOT_STEP x the Rayleigh beta (about the default step), within the cap
PILOT_STEP = 2.0
MIN_SEGMENTS, MAX_SEGMENTS = 4, 200
#: the companions of a run (N, h): the same N at 2 h and at 4 h
COMPANION_STEPS = (2, 4)
#: the model is chosen for target / SAFETY (the a-priori model is good to about 2x, the
#: refinement catches the rest)
SAFETY = 1.5
MAX_REFINEMENTS = 2
#: cost of a native step, c0 + c1 N (us, this 2-core machine, Dadras et al. 2021's beam; only the
#: ratio matters) and the extra of 'discrete' over 'implicitfast' per step
COST_PER_STEP = (3.0, 0.6)
DISCRETE_COST = 1.15
#: samples of an accuracy run when no sample_interval is given (the grid all runs share)
GRID_SAMPLES = 2000
#: at most this fraction of the first mode's period, and of the waveform's, per step
STEPS_PER_PERIOD_MIN = 8


def target_for(scene, accuracy: Optional[float]) -> Optional[float]:
    """The target a run of ``scene`` works to: ``accuracy`` if given, else the scene's own
    (none for a model already chosen for one, :meth:`Scene.variant`)."""
    if accuracy is not None:
        return accuracy
    return None if scene.chosen_model else scene.accuracy


def check_accuracy(value) -> float:
    """``value`` as a target relative to the swing, refused outside ACCURACY_RANGE."""
    lo, hi = ACCURACY_RANGE
    try:
        v = float(value)
    except (TypeError, ValueError):
        v = float("nan")
    if isinstance(value, bool) or not (lo <= v <= hi):
        raise ParameterError("accuracy", value, f"a number in [{lo:g}, {hi:g}]: the largest error of the tip "
                             "curvature relative to its swing (1e-3 = 0.1 %)")
    return v


@dataclass(frozen=True)
class Model:
    """A discretisation: ``segments`` hinges stepped at ``timestep`` (s) under ``integrator``."""
    segments: int
    timestep: float
    integrator: str

    def describe(self) -> str:
        return f"{self.segments} segments, {self.integrator}, h = {self.timestep:.4g} s"


@dataclass(frozen=True)
class ErrorModel:
    """e(N, h) = sqrt((spatial / N^2)^2 + (temporal h)^2), relative to the swing (temporal
    in 1/s)."""
    spatial: float
    temporal: float

    def predict(self, model: Model) -> float:
        return math.hypot(self.spatial / model.segments ** 2, self.temporal * model.timestep)

    def scaled(self, factor: float) -> "ErrorModel":
        return ErrorModel(self.spatial * factor, self.temporal * factor)


def _shared(a, b):
    """Indices (i, j) of the instants a.time[i] == b.time[j] both runs sampled."""
    _, i, j = np.intersect1d(np.round(a.time, 9), np.round(b.time, 9), return_indices=True)
    if not len(i):
        raise ValueError("the two runs share no sample instant")
    return i, j


def relative_difference(a, b) -> float:
    """max |kappa_a - kappa_b| over the instants both sampled, over a's swing."""
    i, j = _shared(a, b)
    swing = float(np.ptp(a.tip_curvature))
    d = float(np.max(np.abs(a.tip_curvature[i] - b.tip_curvature[j])))
    return d / swing if swing > 0 else (0.0 if d == 0 else math.inf)


def _grid(duration: float, sample_interval: Optional[float]) -> float:
    return sample_interval if sample_interval else duration / GRID_SAMPLES


def _on_grid(h: float, grid: float) -> float:
    """The largest grid / m (m a whole number) not above h."""
    return grid / max(1, math.ceil(grid / h * (1 - 1e-12)))


def _step_cap(scene, wave, grid: float) -> float:
    """The largest step any model may take: the sample interval, 1/STEPS_PER_PERIOD_MIN of the
    first mode's period and of the waveform's shortest period."""
    cap = min(grid, 1.0 / (STEPS_PER_PERIOD_MIN * scene.choice.first_frequency))
    f = getattr(wave, "max_frequency", 0.0) or 0.0
    if f > 0:
        cap = min(cap, 1.0 / (STEPS_PER_PERIOD_MIN * f))
    return cap


def _integrator_for(scene, h: float) -> str:
    """'implicitfast' where h and the companions' 4 h are within its default share of the
    stability limit (about the Rayleigh beta: the default step), else 'discrete': a run and
    its companions always share their integrator (its error's form)."""
    return "implicitfast" if COMPANION_STEPS[-1] * h <= scene.choice.rayleigh_beta else "discrete"


def _cost(model: Model, duration: float) -> float:
    c0, c1 = COST_PER_STEP
    return duration / model.timestep * (c0 + c1 * model.segments) * \
        (DISCRETE_COST if model.integrator == "discrete" else 1.0)


def choose_model(scene, error_model: ErrorModel, target: float, duration: float, grid: float,
                 h_cap: float, *, widest: int = COMPANION_STEPS[-1], cost=None, integrator=None) -> Model:
    """The cheapest model with predicted error <= target / SAFETY (h on the sample grid /
    ``widest``, the widest companion's step factor, so that every companion's step divides
    the grid); ``cost(model, duration)`` and ``integrator(scene, h)``: this module's
    unless given."""
    cost, integrator = cost or _cost, integrator or _integrator_for
    tau = target / SAFETY
    best = None
    for n in range(MIN_SEGMENTS, MAX_SEGMENTS + 1):
        e_n = error_model.spatial / n ** 2
        if e_n >= tau:
            continue
        room = math.sqrt(tau ** 2 - e_n ** 2)
        h = h_cap if error_model.temporal <= 0 else min(h_cap, room / error_model.temporal)
        h = _on_grid(h, grid / widest)
        m = Model(n, h, integrator(scene, h))
        if best is None or cost(m, duration) < cost(best, duration):
            best = m
    if best is None:         # even MAX_SEGMENTS are predicted too coarse: the finest there is
        h = _on_grid(min(h_cap, 0.5 * tau / max(error_model.temporal, 1e-300)), grid / widest)
        best = Model(MAX_SEGMENTS, h, integrator(scene, h))
    return best


def _check_work(model: Model, duration: float, target: float, em: ErrorModel, source: str = "pilots") -> None:
    from ..engines.frame import MAX_STEPS
    n = duration / model.timestep
    if n > MAX_STEPS:
        raise ParameterError("accuracy", target, "a target this run can reach within "
                             f"{MAX_STEPS:,} steps", f"{model.describe()} would take {n:,.0f} steps; the step's error "
                             f"constant b = {em.temporal:.3g} 1/s ({source})")


class _Runner:
    """Runs ``model``s of one scene and question, keeping every run's record."""

    def __init__(self, scene, run, grid: float):
        self.scene, self.run_fn, self.grid = scene, run, grid
        self.runs: List[dict] = []

    def __call__(self, model: Model, role: str, run=None):
        try:
            s = self.scene.variant(model.segments, model.timestep, model.integrator)
        except ParameterError:
            if model.integrator != "implicitfast":
                raise
            model = Model(model.segments, model.timestep, "discrete")     # beyond its stability limit
            s = self.scene.variant(model.segments, model.timestep, model.integrator)
        t0 = _time.perf_counter()
        out = (run or self.run_fn)(s, self.grid)
        self.runs.append({"role": role, **asdict(model), "wall_time_s": _time.perf_counter() - t0})
        return s, model, out


def _each(results) -> list:
    return results if isinstance(results, list) else [results]


def calibrate(runner: _Runner, h_pilot: float, run=None) -> ErrorModel:
    """The constants from three pilots: a from PILOT_SEGMENTS at one step h (the step's error
    cancels), b from the coarser at h and h / 2 (the segments' error cancels); ``run``: the
    pilots' own run function (a batch's first member), else the runner's."""
    n1, n2 = PILOT_SEGMENTS
    integ = _integrator_for(runner.scene, h_pilot / 2)
    _, _, coarse = runner(Model(n1, h_pilot, integ), "pilot", run)
    _, _, fine = runner(Model(n2, h_pilot, integ), "pilot", run)
    _, _, half = runner(Model(n1, _on_grid(h_pilot / 2, runner.grid), integ), "pilot", run)
    a = max([relative_difference(f, c) for f, c in zip(_each(fine), _each(coarse))]) / (n1 ** -2 - n2 ** -2)
    h_half = runner.runs[-1]["timestep"]
    b = max([relative_difference(f, c) for f, c in zip(_each(half), _each(coarse))]) / (h_pilot - h_half)
    return ErrorModel(a, b)


def _companions(model: Model) -> List[Model]:
    """The same segments and integrator at 2 h and 4 h."""
    return [Model(model.segments, k * model.timestep, model.integrator) for k in COMPANION_STEPS]


#: the observed ratio of successive step differences is clipped to 2^0.9 .. 2^2.1: the
#: step's order lies between 1 and 2 (semi-implicit and backward Euler: 1; their phase error
#: on a lightly damped mode: 2); outside, the differences are not yet asymptotic or cancel
RATIO_RANGE = (2 ** 0.9, 2 ** 2.1)


def _estimate(fine, mid, coarse, spatial) -> List[tuple]:
    """The step's error by Richardson with the observed rate (d1 = |F - T2h|, d2 = |T2h -
    T4h|, max over shared samples relative to F's swing; r = d2 / d1, e_h = d1 / (r - 1)),
    and the segments' error ``spatial`` (a / N^2 from the pilots, or one value per member
    measured by a companion of fewer segments): per member the pair (step, segments)."""
    out = []
    members = _each(fine)
    e_s = list(spatial) if isinstance(spatial, (list, tuple)) else [spatial] * len(members)
    for f, m, c, e in zip(members, _each(mid), _each(coarse), e_s):
        d1 = relative_difference(f, m)
        d2 = relative_difference(m, c) * float(np.ptp(m.tip_curvature)) / max(float(np.ptp(f.tip_curvature)), 1e-300)
        r = min(max(d2 / d1, RATIO_RANGE[0]), RATIO_RANGE[1]) if d1 > 0 else RATIO_RANGE[1]
        out.append((d1 / (r - 1), e))
    return out


def _combined(parts) -> List[float]:
    """Each member's (step, segments) errors combined in quadrature."""
    return [math.hypot(*p) for p in parts]


def fewer_segments(segments: int) -> int:
    """The segments of the spatial companion of a run of ``segments``: about N / sqrt 2 (its
    error twice the run's at order 2), at least 2 and at most N - 1."""
    return int(min(segments - 1, max(2, round(segments / math.sqrt(2)))))


def spatial_error(result, fewer, segments: int, n_fewer: int) -> float:
    """The segments' error of ``result`` (N segments) by Richardson against ``fewer`` (the
    same step, n_fewer segments), order 2: max |kappa_N - kappa_n| / swing / ((N/n)^2 - 1)."""
    return relative_difference(result, fewer) / ((segments / n_fewer) ** 2 - 1)


def _run_with_companions(runner, model: Model, role: str, spatial: float, measure_spatial: bool = False):
    """Run ``model`` and its step companions; the segments' error is a / N^2 with the pilots'
    ``spatial`` (a), or with ``measure_spatial`` measured on the run against a companion of
    :func:`fewer_segments` at the 2 h companion's step (when a came from another question)."""
    chosen, model, result = runner(model, role)
    comps = _companions(model)
    mid, coarse = [runner(c, "companion")[2] for c in comps]
    if measure_spatial:     # against the 2 h companion: the step's error, about the same in both, cancels
        n_s = fewer_segments(model.segments)
        fewer = _each(runner(Model(n_s, comps[0].timestep, model.integrator), "spatial companion")[2])
        e_s = [spatial_error(r, f, model.segments, n_s) for r, f in zip(_each(mid), fewer)]
    else:
        e_s = spatial / model.segments ** 2
    return chosen, model, result, _estimate(result, mid, coarse, e_s)


def as_error_model(value) -> ErrorModel:
    """``value`` (an ErrorModel, a pair (a, b) or a report's ``error_model`` dict) as an
    ErrorModel, refused unless both constants are finite and non-negative."""
    if isinstance(value, ErrorModel):
        a, b = value.spatial, value.temporal
    elif isinstance(value, dict):
        a, b = value.get("spatial_a"), value.get("temporal_b_per_s")
    else:
        try:
            a, b = value
        except (TypeError, ValueError):
            a = b = None
    try:
        a, b = float(a), float(b)
    except (TypeError, ValueError):
        a = b = float("nan")
    if not (math.isfinite(a) and math.isfinite(b) and a >= 0 and b >= 0):
        raise ParameterError("error_model", value, "an ErrorModel or a pair (a, b) of finite numbers >= 0: the "
                             "segments' constant a and the step's b (1/s) of e = sqrt((a / N^2)^2 + (b h)^2)")
    return ErrorModel(a, b)


def check_targetable(scene, accuracy) -> None:
    """Refuse an accuracy target on a scene whose model the error model does not describe
    (the hinge chain's, order 2 in segments), naming what the model is instead."""
    lack = scene.builder.lacks(HINGE_CHAIN_ERROR)
    if lack is not None:
        raise ParameterError("accuracy", accuracy, f"no target on a '{scene.representation}' scene (give segments "
                             "and timestep): the accuracy model is the hinge chain's (order 2 in segments)", lack)


def run_at_accuracy(scene, run, *, accuracy: float, duration: float, wave=None,
                    sample_interval: Optional[float] = None, error_model=None, pilot_run=None):
    """Choose, run and check a model of ``scene`` for ``accuracy``. ``run(scene, interval)``
    runs one model sampled every ``interval`` s and returns a RolloutResult (or a list of
    them, a batch: the model then serves its worst member). ``error_model`` (an ErrorModel
    or (a, b), e.g. another question's ``meta['accuracy']['error_model']``: a sweep's
    earlier point) replaces the pilots; the segments' error is then measured on the run
    (:func:`fewer_segments`), not taken from a. ``pilot_run`` (a batch: ``run`` for its
    first member only) runs the pilots on that member alone, the others then measured as
    with a given error model. Returns (result(s), scene of the chosen
    model, report dict), the report also put in each result's ``meta['accuracy']``; the
    chosen scene is shared (:meth:`mjeap.Scene.variant`): a later run of the same model in
    this thread resets its state."""
    target = check_accuracy(accuracy)
    given = None if error_model is None else as_error_model(error_model)
    check_targetable(scene, accuracy)
    t0 = _time.perf_counter()
    grid = _grid(duration, sample_interval)
    h_cap = _step_cap(scene, wave, grid)
    runner = _Runner(scene, run, grid)
    h_pilot = _on_grid(min(h_cap, PILOT_STEP * scene.choice.rayleigh_beta), grid)
    em = calibrate(runner, h_pilot, pilot_run) if given is None else given
    measure = given is not None or pilot_run is not None
    model = choose_model(scene, em, target, duration, grid, h_cap)
    if given is not None:
        try:
            _check_work(model, duration, target, em, "given")
        except ParameterError:      # a prior too pessimistic for this question: its own pilots decide
            given, em = None, calibrate(runner, h_pilot, pilot_run)
            measure = pilot_run is not None
            model = choose_model(scene, em, target, duration, grid, h_cap)
    if given is None:
        _check_work(model, duration, target, em, "pilots of this question")
    chosen, model, result, parts = _run_with_companions(runner, model, "chosen", em.spatial, measure)
    estimates = _combined(parts)
    refinements = 0
    while max(estimates) > target and refinements < MAX_REFINEMENTS:
        refinements += 1
        if measure:         # both parts measured on the run: each constant from its own
            em = ErrorModel(max(p[1] for p in parts) * model.segments ** 2,
                            max(p[0] for p in parts) / model.timestep)
        else:
            em = em.scaled(max(estimates) / em.predict(model))
        prev_model = model
        model = choose_model(scene, em, target, duration, grid, h_cap)
        if em.predict(model) >= 0.7 * em.predict(prev_model):          # no finer model predicted
            break
        _check_work(model, duration, target, em, "measured on this question")
        chosen, model, result, parts = _run_with_companions(runner, model, "refined", em.spatial, measure)
        estimates = _combined(parts)
    met = max(estimates) <= target
    spatial_how = (f"segments: {fewer_segments(model.segments)} against {model.segments} segments at 2 h (order 2)"
                   if measure else
                   f"segments: a / N^2 = {em.spatial / model.segments ** 2:.3g} (pilots)")
    pilots = (f"given (a = {given.spatial:.4g}, b = {given.temporal:.4g} 1/s), not calibrated on this run"
              if given is not None else f"{PILOT_SEGMENTS[0]} and {PILOT_SEGMENTS[1]} segments at {h_pilot:.4g} s, "
              f"{PILOT_SEGMENTS[0]} at half that" + (", on the batch's first member" if pilot_run is not None else ""))
    report = {"quantity": QUANTITY, "target": target, "model": asdict(model),
              "predicted_error": em.predict(model), "estimated_error": max(estimates), "met": met,
              "estimate": "step: Richardson with the observed rate against companions of "
                          + " and ".join(c.describe() for c in _companions(model))
                          + f"; {spatial_how}; in quadrature",
              "error_model": {"spatial_a": em.spatial, "temporal_b_per_s": em.temporal,
                              "form": "e = sqrt((a / N^2)^2 + (b h)^2)", "pilots": pilots},
              "refinements": refinements, "runs": runner.runs, "wall_time_s": _time.perf_counter() - t0}
    for r, e in zip(_each(result), estimates):
        r.meta["accuracy"] = {**report, "estimated_error": e}
        if not met:
            r.meta.setdefault("warnings", []).append(
                f"accuracy target {target:g} not met: estimated error {e:.3g} of the swing with {model.describe()} "
                f"after {refinements} refinements")
    return result, chosen, report


#: the step's order assumed where only one finer companion is run (between 1 and 2: the
#: error of a run is then d (2^p) / (2^p - 1), within 1.23 x for any order in that range)
ASSUMED_ORDER = 1.5


def half_step_error(result, finer) -> float:
    """The step's error of ``result`` from one companion at half its step: d 2^p / (2^p - 1),
    d = max |kappa_h - kappa_h/2| over the swing, p = ASSUMED_ORDER."""
    g = 2 ** ASSUMED_ORDER
    return relative_difference(result, finer) * g / (g - 1)


def estimate_error(scene, run, result, *, duration: float, sample_interval: Optional[float]) -> dict:
    """The error of ``result``, a run of ``scene`` as built (no target), estimated as
    :func:`run_at_accuracy` does: the step's by companions at 2 h and 4 h, the segments' by
    a companion of N / sqrt 2 segments at h (order 2). Under 'implicitfast' at its default
    step, 2 h and 4 h lie beyond its stability limit (and 'discrete' there is in another
    regime: its own damping h K exceeds the beam's): the step's error is then taken from one
    finer companion at h / 2, d = max |kappa_h - kappa_h/2|, as d 2^p / (2^p - 1) with
    p = ASSUMED_ORDER. Costs about 1.4 x the run (2.7 x with the finer companion)."""
    model = Model(scene.layout.segments, scene.timestep, scene.integrator)
    comps = _companions(model)
    finer = model.integrator == "implicitfast" and comps[-1].timestep > scene.choice.rayleigh_beta
    step_every = (result.time[1] - result.time[0]) if len(result.time) > 1 else duration
    if finer:
        comps, interval = [Model(model.segments, model.timestep / 2, model.integrator)], step_every
    else:
        interval = COMPANION_STEPS[-1] * (sample_interval or step_every)
    n_s = fewer_segments(model.segments)
    runs = [run(scene.variant(c.segments, c.timestep, c.integrator), interval)
            for c in comps + [Model(n_s, model.timestep, model.integrator)]]
    spatial = spatial_error(result, runs.pop(), model.segments, n_s)
    if finer:
        e = math.hypot(half_step_error(result, runs[0]), spatial)
        how = (f"step: against {comps[0].describe()} (order {ASSUMED_ORDER} assumed: implicitfast's stability "
               "limit keeps it from 2 h)")
    else:
        e = _combined(_estimate(result, *runs, spatial))[0]
        how = "step: Richardson with the observed rate against companions of " + " and ".join(
            c.describe() for c in comps)
    report = {"quantity": QUANTITY, "target": None, "model": asdict(model), "estimated_error": e,
              "estimate": how + f"; segments: against {n_s} segments (order 2): {spatial:.3g}; in quadrature"}
    result.meta["accuracy"] = report
    return report


def estimate_system_error(system, result, run) -> dict:
    """Each actuator's tip-curvature error in ``result``, a run of ``system`` (a
    :class:`~mjeap.simulation.system.System`), from its timestep: ``run(companion,
    interval)`` runs :meth:`System.half_step` sampled every ``interval`` s, and the error is
    :func:`half_step_error` (as :func:`estimate_error` under 'implicitfast'). The segments' error is not estimated: a
    System does not rebuild its actuators (build it with other ``segments=`` to compare).
    Where contact is on, its time constant (2 steps) halves with the step, so the estimate
    includes how much the contact model's own stiffness moves the result. Writes each
    actuator result's ``meta['accuracy']`` and ``result.meta['accuracy']`` (by prefix)."""
    t = result.time
    interval = float(t[1] - t[0]) if len(t) > 1 else None
    companion = system.half_step()
    other = run(companion, interval)
    out = {}
    for a in system.actuators:
        name = a.prefix.rstrip("/")
        r = result.actuators[name]
        e = half_step_error(r, other.actuators[name])
        rep = {"quantity": QUANTITY, "target": None,
               "model": asdict(Model(a.twin.layout.segments, system.timestep, system.integrator)),
               "estimated_error": e,
               "estimate": f"step only: against the system at h / 2 = {companion.timestep:.4g} s (order "
                           f"{ASSUMED_ORDER} assumed); segments: not estimated (a System does not rebuild its "
                           "actuators)"}
        r.meta["accuracy"] = rep
        out[name] = rep
    result.meta["accuracy"] = out
    return out
