"""Parameter sweeps: a design of points, each a rollout reduced to named metrics, run on
local processes or on Dask, streamed to CSV as they complete and resumable.

A point is a dict of :data:`PARAMETERS` (scene, waveform and rollout settings, SI) plus
``drive.NAME`` entries for drive parameters and ``actuator.X`` entries for the actuator's
geometry and materials (:mod:`mjeap.design` builds the point's actuator from the base one).
Metrics that read the scene alone (:data:`STATIC_METRICS`: ``first_frequency``, ``mass``) run
no rollout; the others run one, sampled as they need. :func:`grid` and :func:`random_design` make
designs; :func:`run_sweep` evaluates them. Every finished point is appended to the CSV
(and flushed) at once, keyed by a hash of its parameters, so an interrupted sweep keeps what
finished and a rerun with the same file skips it. A point that fails (bad input, divergence)
records its error in the ``error`` column instead of stopping the sweep.

Executors: ``"processes"`` (``concurrent.futures``, the default), ``"serial"``, and
``"dask"``: a ``distributed.Client`` on ``scheduler`` (an address such as
``tcp://host:8786``) or, without one, on a ``LocalCluster`` of ``workers`` processes. The
same code runs on all three; Dask is the optional ``sweep`` extra.
"""
from __future__ import annotations

import csv
import hashlib
import io
import itertools
import json
import math
import os
import stat
import sys
import time
import traceback
import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Dict, Iterable, List, Optional, Sequence

import numpy as np

from .io import csvio
from .io.csvio import plain_cell
from .errors import (DivergenceError, MjeapError, OutputError, ParameterError, UnknownNameError, check_integer,
                     check_registration, sigterm_as_interrupt)
from .io.outputs import hold

EXECUTORS = ("processes", "serial", "dask")
#: the most points one sweep design may have (each is a rollout, and the design is held in
#: memory): a larger design is refused before it is built, naming its count; split it into
#: several sweeps on the same CSV (each resumes past what is there)
MAX_POINTS = 1_000_000
#: the waveforms a sweep point runs: KIND:AMPLITUDE[@FREQUENCY],offset=OFFSET (a chirp needs two
#: frequencies, a csv: waveform a file: both are for mjeap rollout)
SWEEP_WAVEFORMS = ("step", "square", "sine", "triangle")

#: point parameters and their defaults (SI); ``drive.NAME`` entries go to the drive
PARAMETERS: Dict[str, object] = {
    "actuator": "pedot-micro", "representation": "hinge", "segments": 20, "orientation": "horizontal",
    "payload_mass": 0.0, "payload_position": None, "waveform": "square", "amplitude": 1.0, "frequency": 0.1,
    "offset": 0.0, "duration": None, "initial_curvature": 0.0, "damping_ratio": None, "engine": "auto",
    "accuracy": None, "stop_when_periodic": None,
}


def _last_period(r, point):
    f = point.get("frequency") or 0.0
    t_end = r.time[-1]
    t0 = t_end - 1.0 / f if f > 0 and 1.0 / f < t_end else 0.5 * t_end
    return r.time >= t0


def metric_peak_to_peak(r, point, scene) -> float:
    """Peak-to-peak tip curvature (1/m) over the last drive period (the second half of the
    run without a frequency)."""
    return float(np.ptp(r.tip_curvature[_last_period(r, point)]))


def metric_returns(r, point, scene) -> bool:
    """Seed 000's stability criterion: the tip curvature still changes sign in the last
    drive period (the actuator follows the drive instead of staying collapsed)."""
    k = r.tip_curvature[_last_period(r, point)]
    return bool(k.max() > 0 > k.min())


def metric_settling_time(r, point, scene) -> float:
    """Time (s) after which the tip curvature stays within 2 % of its final change."""
    k = r.tip_curvature
    band = 0.02 * max(abs(k[-1] - k[0]), 1e-300)
    outside = np.nonzero(np.abs(k - k[-1]) > band)[0]
    return float(r.time[outside[-1] + 1]) if outside.size and outside[-1] + 1 < k.size else 0.0


def metric_max_stress_proxy(r, point, scene) -> float:
    """Outer-fibre bending stress proxy (Pa): max |tip curvature| x (thickness / 2) x the
    stiffest layer's modulus (a uniform arc; not a stress analysis)."""
    act = scene.actuator
    e_max = max(layer.youngs_modulus for layer in act.layers)
    return float(np.abs(r.tip_curvature).max() * 0.5 * act.thickness * e_max)


def metric_max_tip_deflection(r, point, scene) -> float:
    """Largest transverse tip deflection (m)."""
    return float(np.abs(r.tip_position[:, 1]).max())


def metric_estimated_error(r, point, scene) -> str:
    """With an ``accuracy`` target: the estimated error of the tip curvature relative to its
    swing and the model chosen for it, e.g. '0.0031 (12 segments, discrete, h = 0.00333 s;
    pilots)' (:mod:`mjeap.simulation.accuracy`), 'shared error model' where the point started
    from its family's (:func:`run_sweep`); '' without one."""
    a = r.meta.get("accuracy")
    if not a:
        return ""
    m = a["model"]
    how = "shared error model" if any(x["role"] == "spatial companion" for x in a.get("runs", ())) else "pilots"
    return (f"{a['estimated_error']:.3g} ({m['segments']} segments, {m['integrator']}, h = {m['timestep']:.3g} s; "
            f"{how}, {a.get('refinements', 0)} refinements)")


def metric_stopped_early(r, point, scene) -> str:
    """Where and why the point stopped before its duration (``stop_when_periodic``: its
    last period repeated the one before; :mod:`mjeap.simulation.periodic`), '' where it ran
    to the end."""
    return r.meta.get("stopped_early", "")


# ---------------------------------------------------------------- design metrics
def metric_first_frequency(r, point, scene) -> float:
    """First bending frequency (Hz) of the point's scene from its linearised model
    (:attr:`Scene.choice`: payload, tip block and gravity included); no rollout."""
    return float(scene.choice.first_frequency)


def metric_mass(r, point, scene) -> float:
    """Mass (kg) of the beam (its free length) and its rigid tip block, without a payload;
    no rollout."""
    act = scene.actuator
    return float(act.total_mass() + act.planform.tip_block_mass)


def _end_tip(r, scene):
    """The tip point (m, clamp frame) at the run's end: the scene's final state (a rollout
    leaves it there), or at an accuracy target (which runs other models) the last sample;
    kept in the result's meta (the blocked force's settling moves the scene meanwhile)."""
    if "_end_tip" not in r.meta:
        r.meta["_end_tip"] = np.asarray(r.tip_position[-1] if "accuracy" in r.meta else scene.tip_position(), float)
    return r.meta["_end_tip"]


def metric_free_deflection(r, point, scene) -> float:
    """Free deflection (m): the tip's displacement normal to the undeformed beam (the clamp
    frame's y) at the run's end, under the run's voltage (signed: + towards +y; the scene's
    gravity and payload act too: hanging or standing, along the beam)."""
    return float(_end_tip(r, scene)[1])


#: the tip must come back to within this fraction of its free deflection for a blocked force
BLOCKED_TOL = 1e-6


def metric_blocked_force(r, point, scene) -> float:
    """Blocked force (N): the tip force that holds the tip at zero deflection under the
    voltage at the run's end, simulated. The scene, left in the run's final state with the
    drive's moments applied, settles statically (:meth:`Scene.settle`); a transverse tip force
    is then found by the secant method, each trial settled again, until the tip is back
    within BLOCKED_TOL of its free deflection (geometric nonlinearity included; 2-4
    settles). Reported as the force the actuator exerts on the block: the same sign as the
    free deflection. Needs the run's own scene: not at an accuracy target."""
    cached = r.meta.get("_blocked_force")
    if cached is not None:
        return cached
    if "accuracy" in r.meta:
        raise ParameterError("metrics", "blocked_force", "a point without an accuracy target (the blocked force is "
                             "simulated on the run's own scene, which a target replaces by the models it chooses)")
    _end_tip(r, scene)
    part = scene.part
    force0, moment0 = part.tip_loads()
    L = scene.length
    saved = (scene.data.qpos.copy(), scene.data.qvel.copy(), scene.data.act.copy(), scene.data.time)
    tol = 1e-12

    def settled(f):
        part.set_tip_force(np.asarray(force0) + np.array([0.0, f, 0.0]))
        scene.settle(tol=tol, max_periods=2000)
        return float(scene.tip_position()[1])

    try:
        y0 = settled(0.0)
        if y0 == 0.0:
            value = 0.0
        else:
            # first trial: the uniform cantilever's tip compliance L^3 / (3 EI(0))
            c = L**3 / (3.0 * float(scene.actuator.flexural_rigidity_at(0.0)[0]))
            f_prev, y_prev, f = 0.0, y0, -y0 / c
            y = settled(f)
            for _ in range(12):
                if abs(y) <= BLOCKED_TOL * abs(y0) or y == y_prev:
                    break
                f, f_prev, y_prev = f - y * (f - f_prev) / (y - y_prev), f, y
                y = settled(f)
            if abs(y) > 1e-3 * abs(y0):
                raise DivergenceError(f"{scene.actuator.id}: the blocked-force search did not hold the tip at zero "
                                      f"(tip still {y:.3g} m from the clamp line, free deflection {y0:.3g} m)")
            value = -f
    finally:                       # the scene back in the run's final state
        part.set_tip_force(force0)
        d = scene.data
        d.qpos[:], d.qvel[:], d.act[:], d.time = saved
        _forward(scene)
    r.meta["_blocked_force"] = value
    return value


def _forward(scene) -> None:
    import mujoco
    mujoco.mj_forward(scene.model, scene.data)


def metric_energy_density(r, point, scene) -> float:
    """Energy density (J/kg): blocked_force x free_deflection / (2 mass), mass the beam's and
    its tip block's (:func:`metric_mass`)."""
    return float(metric_blocked_force(r, point, scene) * metric_free_deflection(r, point, scene)
                 / (2.0 * metric_mass(r, point, scene)))


def _last_whole_period(r, point, name: str):
    """(V, I, sample spacing, T) over the last drive period: the samples within its T = 1 /
    frequency before the run's end (round(T / spacing) of them; a periodic waveform only), I
    the drive's total current."""
    wave = str(point.get("waveform", "")).strip().lower()
    f = float(point.get("frequency") or 0.0)
    if wave not in ("square", "sine", "triangle") or not f > 0:
        raise ParameterError("metrics", name, "a periodic waveform (square, sine or triangle with a frequency > 0)",
                             f"the point's waveform is {wave or 'none'}")
    if "current (A)" not in r.signals:
        raise ParameterError("metrics", name, "a drive that reports its current ('current (A)')",
                             f"the {r.meta.get('drive', 'drive')} drive reports {', '.join(r.signals) or 'no signals'}")
    dt = float(r.time[1] - r.time[0]) if r.time.size > 1 else 0.0
    n = int(round(1.0 / (f * dt))) if dt > 0 else 0
    if n < 4 or n > r.time.size - 1:
        raise ParameterError("metrics", name, "a run longer than one drive period with >= 4 samples in it",
                             f"{r.time.size} samples of {dt:.3g} s, period {1.0 / f:.3g} s")
    return r.voltage[-n:], r.signals["current (A)"][-n:], dt, 1.0 / f


def metric_peak_power(r, point, scene) -> float:
    """Peak electrical power (W): max |V x I| over the last whole drive period, V the drive
    voltage and I the drive's total current (periodic waveforms; sampled every step)."""
    v, i, _, _ = _last_whole_period(r, point, "peak_power")
    return float(np.max(np.abs(v * i)))


def metric_energy_per_cycle(r, point, scene) -> float:
    """Electrical energy (J) delivered over the last whole drive period, P = V x I (V the
    drive voltage, I the drive's total current, sampled every step): the sum of P dt over the
    period's samples where the period is a whole number of steps. Where it is not, the window
    of round(T / dt) samples is a fraction of a step off the period, and the reactive power
    (the capacitor's charge going in and out, often 100 x the mean) would leak into the sum by
    up to half a step of it; the mean power is then fitted by linear least squares with the
    period's first harmonics alongside (numpy.linalg.lstsq, as mjeap.analysis.frequency.phasor
    fits), which removes them whatever the window, and the energy is T x that mean. In steady
    state it is what the beam's dampers and the drive's resistance dissipate over the cycle
    (the capacitive part returns)."""
    v, i, dt, period = _last_whole_period(r, point, "energy_per_cycle")
    p = v * i
    n = p.size
    if abs(period / dt - n) <= 1e-9 * n:
        return float(np.sum(p) * dt)
    t = dt * np.arange(n)
    w = 2 * np.pi / period
    harmonics = min(10, (n - 2) // 3)
    basis = np.column_stack([np.ones(n)] + [f(k * w * t) for k in range(1, harmonics + 1) for f in (np.cos, np.sin)])
    mean = np.linalg.lstsq(basis, p, rcond=None)[0][0]
    return float(mean * period)


METRICS: Dict[str, Callable] = {
    "estimated_error": metric_estimated_error, "stopped_early": metric_stopped_early,
    "peak_to_peak": metric_peak_to_peak, "returns": metric_returns, "settling_time": metric_settling_time,
    "max_stress_proxy": metric_max_stress_proxy, "max_tip_deflection": metric_max_tip_deflection,
    "first_frequency": metric_first_frequency, "mass": metric_mass, "free_deflection": metric_free_deflection,
    "blocked_force": metric_blocked_force, "energy_density": metric_energy_density,
    "peak_power": metric_peak_power, "energy_per_cycle": metric_energy_per_cycle,
}
#: metrics that need no rollout: the point's scene alone (``fn(None, point, scene)``)
STATIC_METRICS = {"first_frequency", "mass"}
#: metrics that read only the run's end: their points sample sparsely (the scene holds the end)
END_METRICS = {"free_deflection", "blocked_force", "energy_density"}
#: metrics that read every step of the last period: their points sample every step
#: (every k steps where a run has more than MAX_STEP_SAMPLES steps)
STEP_METRICS = {"peak_power", "energy_per_cycle"}
MAX_STEP_SAMPLES = 200_000
#: metrics simulated on the run's own scene: refused at an accuracy target
OWN_SCENE_METRICS = {"blocked_force", "energy_density"}
#: SI units of the built-in metrics (constraints of mjeap.optimize may carry units)
METRIC_UNITS = {"peak_to_peak": "1/m", "settling_time": "s", "max_stress_proxy": "Pa", "max_tip_deflection": "m",
                "first_frequency": "Hz", "mass": "kg", "free_deflection": "m", "blocked_force": "N",
                "energy_density": "J/kg", "peak_power": "W", "energy_per_cycle": "J"}


#: a row's own columns, which no metric may be named
ROW_COLUMNS = ("point_id", "error", "wall_s", "settings", "_error_model")


def register_metric(name: str, fn: Callable, *, replace: bool = False, rollout: bool = True) -> None:
    """Add ``fn(result, point, scene) -> number`` (a finite number, a bool or a str: ''
    for no value; anything else fails the point naming the metric) as metric ``name``
    (letters, digits, '-', '_'; not a point parameter or a row column; a name taken is
    refused unless ``replace``). ``rollout=False``: the metric reads the point's scene alone
    (its result is None) and a point asking only for such metrics runs no rollout. In every
    worker process, register it at import time of a module the workers import."""
    check_registration("metric", METRICS, name, fn,
                       lacks=None if callable(fn) else "not callable",
                       expected="a callable fn(result, point, scene) returning a number, a bool or a str",
                       reserved=(*PARAMETERS, *ROW_COLUMNS), replace=replace, how="register_metric")
    METRICS[name] = fn
    if rollout:
        STATIC_METRICS.discard(name)
        END_METRICS.discard(name)
        STEP_METRICS.discard(name)
    else:
        STATIC_METRICS.add(name)


def metric_value(name: str, value):
    """``value``, what metric ``name`` returned, where it is a finite number, a bool or a
    str; else a ParameterError naming the metric."""
    if isinstance(value, (bool, np.bool_, str)):
        return value
    if isinstance(value, (int, float, np.integer, np.floating)) and np.isfinite(value):
        return value
    raise ParameterError("metric", name, "a metric that returns a finite number, a bool or a str ('' for no value)",
                         f"it returned {value!r}")


# ---------------------------------------------------------------- designs
def _check_names(names: Iterable[str]) -> None:
    for n in names:
        if n not in PARAMETERS and not n.startswith("drive.") and not n.startswith("actuator."):
            raise ParameterError("sweep parameter", n, f"one of {', '.join(PARAMETERS)}, drive.NAME or actuator.NAME "
                                 "(mjeap.design: actuator.length, actuator.layers.LAYER.thickness, ...)")


def check_design_size(count: int, name: str = "design", how: str = "") -> int:
    """``count`` points, refused beyond MAX_POINTS before any of them is built (a ParameterError
    naming the count and the limit; ``how`` says where the count comes from)."""
    if count > MAX_POINTS:
        raise ParameterError(name, f"{count:,} points", f"at most MAX_POINTS = {MAX_POINTS:,} points per sweep "
                             "(split the design into several sweeps on the same CSV)", how)
    return count


def grid(**values: Sequence) -> List[dict]:
    """Full factorial design: every combination of the given values (at most MAX_POINTS,
    refused before the combinations are built)."""
    _check_names(values)
    names = list(values)
    lists = [list(values[n]) for n in names]
    check_design_size(math.prod(map(len, lists)), "grid", " x ".join(f"{n}: {len(v)}" for n, v in zip(names, lists)))
    return [dict(zip(names, combo)) for combo in itertools.product(*lists)]


def random_design(n: int, seed: int = 0, **ranges) -> List[dict]:
    """``n`` points, each parameter drawn uniformly from a (low, high) range or a list of
    choices, with numpy's generator seeded by ``seed``."""
    _check_names(ranges)
    if int(n) < 1:
        raise ParameterError("n", n, "a positive number of points")
    check_design_size(int(n), "n", "random points")
    rng = np.random.default_rng(seed)
    cols = {}
    for k, v in ranges.items():
        if isinstance(v, tuple) and len(v) == 2 and all(isinstance(x, (int, float)) for x in v):
            cols[k] = rng.uniform(v[0], v[1], int(n)).tolist()
        else:
            choices = list(v)
            cols[k] = [choices[i] for i in rng.integers(0, len(choices), int(n))]
    return [{k: cols[k][i] for k in ranges} for i in range(int(n))]


def settings(base: Optional[dict] = None, metrics: Sequence[str] = ()) -> dict:
    """Everything besides a point's own parameters that changes its row: the fixed
    parameters (``base`` over the defaults), the metrics and the package version."""
    from .versions import MJEAP_VERSION
    return {"base": {**PARAMETERS, **(base or {})}, "metrics": sorted(metrics), "mjeap": MJEAP_VERSION}


def point_id(point: dict, base: Optional[dict] = None, metrics: Sequence[str] = ()) -> str:
    """Stable key of a point: hash of its parameters and of the sweep's :func:`settings`
    (JSON, sorted keys), so that a rerun with other fixed settings computes its points."""
    key = {"point": point, "settings": settings(base, metrics)}
    digest = _actuator_file_digest({**PARAMETERS, **(base or {}), **point}["actuator"])
    if digest is not None:              # a file's content, not only its name (catalog ids: as before)
        key["actuator_file"] = digest
    return hashlib.sha1(json.dumps(key, sort_keys=True, default=float).encode()).hexdigest()[:12]


_FILE_DIGESTS: Dict[tuple, str] = {}


def _actuator_file_digest(actuator) -> Optional[str]:
    """SHA-1 of an actuator file's bytes (None: a catalog id, an Actuator or no such file),
    so that a point of an edited file is computed again; cached by path, size and mtime."""
    from .model.actuator_file import is_actuator_file
    if not isinstance(actuator, (str, Path)) or not is_actuator_file(actuator):
        return None
    try:
        st = os.stat(actuator)
    except OSError:
        return None
    k = (os.path.realpath(actuator), st.st_size, st.st_mtime_ns)
    if k not in _FILE_DIGESTS:
        try:
            _FILE_DIGESTS[k] = hashlib.sha1(Path(actuator).read_bytes()).hexdigest()[:16]
        except OSError:
            return None
    return _FILE_DIGESTS[k]


def check_settings(points: Sequence[dict], base: Optional[dict]) -> None:
    """Every name in ``base`` is a sweep parameter, and every ``drive.NAME`` (in base or the
    points) a parameter of the actuator's drive; else UnknownNameError with the closest."""
    from .drives import default_drive_name, get_drive_class
    base = base or {}
    for n in base:
        if n not in PARAMETERS and not n.startswith("drive.") and not n.startswith("actuator."):
            raise UnknownNameError("fixed sweep setting (--set / base)", n,
                                   [*PARAMETERS, "drive.NAME", "actuator.NAME"])
    from .model.catalog import check_actuator_files      # a bad actuator file: refused before any point
    check_actuator_files({**PARAMETERS, **base, **p}["actuator"] for p in points or [{}])
    _check_designs(points, base)
    _check_fixed(points, base)
    for p in points:
        full = {**PARAMETERS, **base, **p}
        if full["stop_when_periodic"] not in (None, ""):      # refused once, not in every row
            _check_stop(full)
        names = [k[6:] for k in full if k.startswith("drive.")]
        if not names:
            continue
        act = str(full["actuator"])
        try:
            from .model.actuator_file import is_actuator_file
            from .model.catalog import get_actuator
            cls = get_drive_class(default_drive_name(get_actuator(act) if is_actuator_file(act) else act))
        except MjeapError:
            continue              # a user actuator or an unknown one: the point reports it
        known = list(cls.parameter_units()) + list(cls.extra_parameters(None))
        for n in names:
            if n not in known:
                raise UnknownNameError(f"{cls.name} drive parameter (drive.NAME)", n, known)


def check_metric_settings(points: Sequence[dict], base: Optional[dict], metrics: Sequence[str]) -> None:
    """Metrics their points cannot give, refused before any work: a blocked force (and the
    energy density) at an accuracy target (it is simulated on the run's own scene), power
    metrics without a periodic waveform."""
    base = base or {}
    for p in points or [{}]:
        full = {**PARAMETERS, **base, **p}
        own = [m for m in metrics if m in OWN_SCENE_METRICS]
        if own and full["accuracy"] not in (None, ""):
            raise ParameterError("metrics", own[0], "a study without an accuracy target (the blocked force is "
                                 "simulated on the run's own scene, which a target replaces by the models it chooses)")
        power = [m for m in metrics if m in STEP_METRICS]
        if power and (str(full["waveform"]).strip().lower() not in ("square", "sine", "triangle")
                      or not _positive(full["frequency"])):
            raise ParameterError("metrics", power[0], "a periodic waveform (square, sine or triangle with a frequency "
                                 "> 0) for peak_power and energy_per_cycle",
                                 f"a point has waveform={full['waveform']!r}, frequency={full['frequency']!r}")


def _positive(x) -> bool:
    try:
        return float(x) > 0
    except (TypeError, ValueError):
        return False


def _check_designs(points: Sequence[dict], base: dict) -> None:
    """The ``actuator.X`` parameters of a study (:mod:`mjeap.design`), checked before any
    point runs: each name against its point's base actuator, every value against its range,
    and the actuator of each base actuator's first point built (its sizes and its drive's
    layer stack)."""
    from . import design
    from .errors import MjeapError as _Error
    by_actuator: Dict[str, Dict[str, list]] = {}
    firsts: Dict[str, dict] = {}
    for p in points or [{}]:
        full = {**PARAMETERS, **base, **p}
        names = [k for k in full if design.is_design_parameter(k)]
        if not names:
            continue
        act = full["actuator"]
        key = act if isinstance(act, str) else repr(act)
        vals = by_actuator.setdefault(key, {})
        firsts.setdefault(key, {"actuator": act, **{k: full[k] for k in names}})
        for k in names:
            vals.setdefault(k, []).append(full[k])
    for key, vals in by_actuator.items():
        act = firsts[key]["actuator"]
        try:
            design.get_base(act)
        except _Error:
            continue                # an unknown actuator: each point reports it
        design.check_design(act, {name: list(dict.fromkeys(values)) for name, values in vals.items()})
        design.design_actuator(act, {k: v for k, v in firsts[key].items() if k != "actuator"})


def _check_fixed(points: Sequence[dict], base: dict) -> None:
    """The fixed settings (``base``, ``--set``) every point shares, checked once before any
    point runs, as each point would check them (each would fail the same way): ``accuracy``
    a target in the accepted range (or None), ``waveform`` one of SWEEP_WAVEFORMS,
    ``duration`` finite and > 0 s and, where no point varies it (and without an accuracy
    target, which chooses the step), at most MAX_STEPS steps of the first point's scene."""
    from .engines.frame import MAX_STEPS
    from .errors import check_positive
    from .simulation.accuracy import check_accuracy
    fixed = "a fixed sweep setting (--set / base): every point would fail with it"
    try:
        if base.get("accuracy") not in (None, ""):
            check_accuracy(base["accuracy"])
        if "waveform" in base and str(base["waveform"]).strip().lower() not in SWEEP_WAVEFORMS:
            raise ParameterError("waveform", base["waveform"], f"one of {', '.join(SWEEP_WAVEFORMS)} (a point's "
                                 "waveform is KIND:amplitude@frequency,offset=offset from its parameters; a csv: or "
                                 "chirp waveform is for mjeap rollout --voltage)")
        if base.get("duration") not in (None, ""):
            duration = check_positive("duration", base["duration"], "s")
            if points and not any("duration" in p for p in points) and \
                    {**PARAMETERS, **base, **points[0]}["accuracy"] in (None, ""):
                try:
                    scene = _scene({**PARAMETERS, **base, **points[0]})
                except MjeapError:
                    scene = None               # the point reports its own scene's error
                if scene is not None:
                    dt = scene.timestep
                    if not dt <= duration <= MAX_STEPS * dt:       # check_work's bounds, without --max-steps
                        raise ParameterError("duration", f"{duration:g} s", f"one step to {MAX_STEPS:,} steps of "
                                             f"{dt:.4g} s ({dt:.4g} s to {MAX_STEPS * dt:.4g} s) for the first "
                                             "point's scene", f"{duration / dt:,.0f} steps")
    except ParameterError as e:
        raise ParameterError(f"{e.name} (--set / base)", e.value, e.accepted,
                             f"{e.why}; {fixed}" if e.why else fixed) from None


def _scene(p: dict):
    """The Scene of a point's full parameters (``base`` and the defaults filled in)."""
    from .model.discretize import Payload
    from .simulation.scene import Scene
    payload = None
    if p["payload_mass"]:
        pos = p["payload_position"]
        if pos is None:
            raise ParameterError("payload_position", None, "a position in m when payload_mass > 0")
        payload = Payload(float(p["payload_mass"]), float(pos))
    from .design import design_actuator, is_design_parameter
    act = p["actuator"]
    if any(is_design_parameter(k) for k in p):
        act = design_actuator(act, p)
    return Scene(act, representation=p["representation"], segments=int(p["segments"]),
                 orientation=p["orientation"], payload=payload, damping_ratio=p["damping_ratio"],
                 accuracy=None if p["accuracy"] in (None, "") else float(p["accuracy"]))


def _wave_text(p: dict) -> str:
    """The waveform text of a point's parameters (mjeap.drives.waveforms)."""
    f, a = float(p["frequency"]), float(p["amplitude"])
    return f"step:{a!r}V" if p["waveform"] == "step" else \
        f"{p['waveform']}:{a!r}V@{f!r}Hz,offset={float(p['offset'])!r}V"


def _duration(p: dict) -> float:
    """A point's duration (s): its own, else two drive periods."""
    return float(p["duration"]) if p["duration"] not in (None, "") else 2.0 / float(p["frequency"])


def _check_stop(p: dict) -> None:
    """A point's periodic stop, as its rollout will check it (mjeap.simulation.rollout.check_stop)."""
    from .drives.waveforms import parse_waveform
    from .simulation.rollout import check_stop
    check_stop(float(p["stop_when_periodic"]), parse_waveform(_wave_text(p)), _duration(p),
               at_accuracy=p["accuracy"] not in (None, ""))


# ---------------------------------------------------------------- one point
def evaluate(point: dict, metrics: Sequence[str] = ("peak_to_peak", "returns"), base: Optional[dict] = None,
             rrd_dir: Optional[str] = None, error_model=None) -> dict:
    """Run one point (``base`` filled in under it) and return its row: the parameters, the
    metrics, ``error`` (empty when it ran), ``wall_s`` and ``point_id``. Never raises for a
    failing point. At an accuracy target, ``error_model`` (a, b) replaces the point's pilots
    (:func:`mjeap.simulation.accuracy.run_at_accuracy`) and the row's ``_error_model`` (not
    a CSV column) holds the constants the point ran with."""
    p = {**PARAMETERS, **(base or {}), **point}
    row = {"point_id": point_id(point, base, metrics), **point, "error": "", "wall_s": 0.0,
           "settings": json.dumps(settings(base, metrics), sort_keys=True, default=float)}
    for m in metrics:
        row[m] = ""
    t0 = time.perf_counter()
    try:
        unknown = [m for m in metrics if m not in METRICS]
        if unknown:
            raise UnknownNameError("metric", unknown[0], METRICS)
        scene = _scene(p)
        for m in metrics:                   # the scene's own metrics first: no rollout for them
            if m in STATIC_METRICS:
                row[m] = metric_value(m, METRICS[m](None, p, scene))
        dynamic = [m for m in metrics if m not in STATIC_METRICS]
        r = _run_point(p, scene, dynamic, rrd_dir, row["point_id"], error_model) if dynamic or rrd_dir else None
        if r is not None and "accuracy" in r.meta:
            e = r.meta["accuracy"].get("error_model")
            row["_error_model"] = None if e is None else (e["spatial_a"], e["temporal_b_per_s"])
        for m in dynamic:
            row[m] = metric_value(m, METRICS[m](r, p, scene))
    except MjeapError as e:
        row["error"] = f"{type(e).__name__}: {e}"
        if "returns" in metrics and isinstance(e, DivergenceError):
            row["returns"] = False
    except Exception as e:  # a bug or a library error: keep the sweep going, keep the trace
        row["error"] = f"{type(e).__name__}: {e} | {traceback.format_exc(limit=3)!r}"
    row["wall_s"] = time.perf_counter() - t0
    return row


def _run_point(p: dict, scene, metrics: Sequence[str], rrd_dir, pid: str, error_model=None):
    """The rollout of a point, sampled as its metrics need: every step (every k steps beyond
    MAX_STEP_SAMPLES) for STEP_METRICS, sparsely where every metric reads only the run's end
    (END_METRICS: the scene holds the end), else the rollout's default."""
    from .simulation.rollout import rollout
    wave = _wave_text(p)
    duration = _duration(p)
    drive_params = {k[6:]: v for k, v in p.items() if k.startswith("drive.")}
    rrd = None if rrd_dir is None else Path(rrd_dir) / f"point-{pid}.rrd"
    stop = None if p["stop_when_periodic"] in (None, "") else float(p["stop_when_periodic"])
    at_target = scene.accuracy is not None
    interval = None
    if any(m in STEP_METRICS for m in metrics):
        dt = scene.timestep
        interval = dt * max(1, -(-int(round(duration / dt)) // MAX_STEP_SAMPLES))
    elif metrics and all(m in END_METRICS for m in metrics) and not at_target and stop is None and rrd is None:
        interval = duration / 8.0
    return rollout(scene, wave, duration, drive_params=drive_params, initial_curvature=float(p["initial_curvature"]),
                   progress=False, rrd=rrd, engine=p["engine"], sample_interval=interval,
                   error_model=error_model if at_target else None, stop_when_periodic=stop)


# ---------------------------------------------------------------- many points
@dataclass
class SweepSummary:
    path: Path
    done: int
    skipped: int
    failed: int
    wall_s: float

    @property
    def throughput(self) -> float:
        """Rollouts per second of wall time (points run in this call)."""
        return self.done / self.wall_s if self.wall_s > 0 else float("nan")


def _drop_torn_row(path: Path) -> None:
    """A file cut mid-line (a killed writer) loses its partial last row, which would
    otherwise count as done and have the next row glued onto it; the point runs again."""
    if not path.exists() or path.stat().st_size == 0:
        return
    with open(path, "rb+") as fh:
        data = fh.read()
        if data.endswith(b"\n"):
            return
        cut = data.rfind(b"\n") + 1
        fh.truncate(cut)
    warnings.warn(f"{path}: dropped a partial last row ({len(data) - cut} bytes, cut mid-line); its point runs again",
                  stacklevel=3)


def _read_sweep_csv(path):
    """A sweep's CSV read as :mod:`mjeap.io.csvio` reads users' files (a UTF-8 BOM, ',', ';'
    or tab as the delimiter: a file re-saved by a spreadsheet): (header, rows as dicts,
    delimiter). Refused, naming the file, where its first row does not name ``point_id`` (the
    header was lost or replaced: the points done could not be told)."""
    rows, delimiter = csvio.read_table(path, "path")
    header = rows[0]
    if "point_id" not in header:
        shown = ", ".join(header[:3]) + (", ..." if len(header) > 3 else "")
        raise ParameterError("path", str(path), "a sweep CSV whose first row is the header mjeap wrote, naming "
                             "point_id (the key of each point done)", f"its first row is [{shown}]: the header row "
                             "was lost or changed (re-saved by a spreadsheet?); restore it, or start a new file")
    pad = [""] * len(header)
    return header, [dict(zip(header, r + pad[len(r):])) for r in rows[1:]], delimiter


def read_results(path) -> List[dict]:
    """Rows of a sweep CSV (strings, as given: the quote that keeps a spreadsheet from
    running a text cell as a formula is dropped; a BOM, ';' or tab delimiters of a file
    re-saved by a spreadsheet are read, :mod:`mjeap.io.csvio`; the header names the columns
    and must name ``point_id``, else a ParameterError names the file)."""
    if Path(path).is_file() and Path(path).stat().st_size == 0:
        return []
    return _read_sweep_csv(path)[1]


def _die_with_parent() -> None:
    """Linux: the kernel kills this worker when its parent dies (kill -9 of the sweep), so no
    orphan keeps running with the CSV's points."""
    try:
        import ctypes
        import signal
        ctypes.CDLL("libc.so.6", use_errno=True).prctl(1, signal.SIGKILL)   # PR_SET_PDEATHSIG
    except (OSError, AttributeError):   # pragma: no cover - not Linux
        pass


def worker_signals() -> None:
    """Process-pool initializer: the worker dies with its parent (:func:`_die_with_parent`),
    ignores Ctrl-C (the terminal sends it to the whole process group; the parent stops its
    workers) and takes SIGTERM's default action (a forked worker inherits the parent's
    :class:`~mjeap.errors.sigterm_as_interrupt` handler, which would print a traceback when
    the parent terminates it)."""
    import signal
    _die_with_parent()
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    sigterm_as_interrupt.in_pool_worker = True       # a run's guard inside the worker leaves SIGTERM alone


def stop_workers(executor) -> None:
    """Stop a ProcessPoolExecutor now: terminate its processes (the points in flight are
    not waited for) and shut it down without waiting."""
    for proc in list((getattr(executor, "_processes", None) or {}).values()):
        proc.terminate()
    executor.shutdown(wait=False, cancel_futures=True)


def _worker_init() -> None:
    worker_signals()
    _one_blas_thread()


def _one_blas_thread() -> None:
    """Process-pool initializer: one BLAS thread per worker. A point's linear algebra is on
    matrices of a few dozen rows, where OpenBLAS's threads only cost; with one pool of them
    per worker the workers also fight over the cores (measured, 32 points on 2 cores: 2
    workers gave 1.2x one worker with BLAS threads, 1.8x without). Dask's nanny does the
    same for its workers (OPENBLAS_NUM_THREADS=1)."""
    from threadpoolctl import threadpool_limits
    threadpool_limits(1)


#: parameters that change the size of a point's loads, not the kind of its question: points
#: that differ only in these share one accuracy error model (:func:`_with_shared_error_models`)
LOAD_SIZE = ("payload_mass", "amplitude", "offset", "initial_curvature")


def _family(job) -> Optional[str]:
    """The accuracy family of a job: its parameters less LOAD_SIZE, or None without a target."""
    p = {**PARAMETERS, **(job[2] or {}), **job[0]}
    if p["accuracy"] in (None, ""):
        return None
    return json.dumps({k: v for k, v in p.items() if k not in LOAD_SIZE}, sort_keys=True, default=float)


def _with_shared_error_models(executor: str, workers: int, scheduler: Optional[str], jobs):
    """Yield finished rows. At an accuracy target the first point of each family (the same
    question but for LOAD_SIZE) runs first with its own pilots; the family's other points
    start from its error model (a, b) instead of pilots of their own, their error still
    measured on each (:func:`mjeap.simulation.accuracy.run_at_accuracy`). Points of a
    family whose first point failed run their own pilots. Points without a target run
    beside the first points."""
    first, rest, seen, lead_family = [], [], set(), {}     # lead_family: a first point's id -> its family
    for job in jobs:
        key = _family(job)
        if key is not None and key in seen:
            rest.append((key, job))
            continue
        if key is not None:
            seen.add(key)
            lead_family[point_id(job[0], job[2], job[1])] = key
        first.append(job)
    if not lead_family:
        yield from _submit_all(executor, workers, scheduler, jobs)
        return
    models = {}
    for row in _submit_all(executor, workers, scheduler, first):
        if row["point_id"] in lead_family:
            models[lead_family[row["point_id"]]] = row.get("_error_model")
        yield row
    yield from _submit_all(executor, workers, scheduler,
                           [tuple(job[:4]) + (models.get(key),) for key, job in rest])


def _submit_all(executor: str, workers: int, scheduler: Optional[str], jobs):
    """Yield finished rows as they complete."""
    if executor == "serial":
        from threadpoolctl import threadpool_limits
        with threadpool_limits(1):
            for args in jobs:
                yield evaluate(*args)
        return
    if executor == "processes":
        yield from _run_processes(list(jobs), workers)
        return
    if executor == "dask":  # run_sweep has checked the name
        try:
            from distributed import Client, LocalCluster, as_completed
        except ImportError:
            raise ParameterError("executor", "dask", "an installed Dask: pip install -e '.[sweep]'") from None
        cluster = None
        if scheduler:
            client = Client(scheduler)
        else:
            cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                                   dashboard_address=None)
            client = Client(cluster)
        try:
            futures = [client.submit(evaluate, *args, pure=False) for args in jobs]
            for fut in as_completed(futures):
                yield fut.result()
        finally:
            client.close()
            if cluster is not None:
                cluster.close()


WORKER_DIED = ("worker process died while running this point (killed, e.g. by the out-of-memory killer, "
               "or crashed); run alone after the pool broke, it died again")


def _run_processes(jobs: list, workers: int):
    """Local worker processes, at most ``workers`` points in flight. A worker that dies
    breaks the pool: the points then in flight are run again one by one in a fresh
    single-worker pool (the one that kills its worker again is recorded as failed), and the
    sweep goes on in a fresh pool. Ctrl-C or SIGTERM cancels what has not started."""
    from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
    from concurrent.futures.process import BrokenProcessPool
    import multiprocessing as mp
    # fork where there is one (fast start, works from any __main__), spawn elsewhere
    ctx = mp.get_context("fork" if "fork" in mp.get_all_start_methods() else "spawn")

    def pool(n):
        return ProcessPoolExecutor(max_workers=n, mp_context=ctx, initializer=_worker_init)

    pending = list(jobs)
    while pending:
        suspects, ex = [], pool(workers)
        inflight = {}
        try:
            while pending or inflight:
                broken = False
                while pending and len(inflight) < workers:
                    try:                    # the pool may break between a finished point and this submit
                        fut = ex.submit(evaluate, *pending[0])
                    except BrokenProcessPool:
                        broken = True
                        break
                    inflight[fut] = pending.pop(0)
                done, _ = wait(inflight, return_when=FIRST_COMPLETED)
                for fut in done:
                    args = inflight.pop(fut)
                    try:
                        yield fut.result()
                    except BrokenProcessPool:
                        suspects.append(args)
                if suspects or broken:
                    suspects += list(inflight.values())
                    break
        except BaseException:               # Ctrl-C, SIGTERM, the caller closing: stop the workers now
            stop_workers(ex)
            raise
        else:
            ex.shutdown(wait=not suspects, cancel_futures=True)
        for args in suspects:                      # one by one: find the point that kills
            alone = pool(1)
            try:
                yield alone.submit(evaluate, *args).result()
            except BrokenProcessPool:
                point = args[0]
                yield {"point_id": point_id(point, args[2], args[1]), **point, "error": f"WorkerDied: {WORKER_DIED}",
                       "wall_s": 0.0, "settings": json.dumps(settings(args[2], args[1]), sort_keys=True, default=float)}
            finally:
                alone.shutdown(wait=False, cancel_futures=True)


def run_sweep(points: Sequence[dict], path, metrics: Sequence[str] = ("peak_to_peak", "returns"),
              base: Optional[dict] = None, executor: str = "processes", workers: int = 2,
              scheduler: Optional[str] = None, record: Sequence[int] = (), rrd_dir=None,
              progress: Optional[bool] = None, share_error_models: bool = True) -> SweepSummary:
    """Evaluate ``points`` and stream one CSV row per finished point to ``path``. Points
    already in the file (same ``point_id``) are skipped. ``record``: indices of points
    that also write a recording to ``rrd_dir`` (default: next to the CSV).
    ``share_error_models`` (at an accuracy target): points differing only in LOAD_SIZE
    start from their family's first point's error model instead of pilots of their own
    (:func:`_with_shared_error_models`); each point's error is measured on it either way."""
    path = Path(path)
    if executor not in EXECUTORS:
        raise ParameterError("executor", executor, f"one of {', '.join(EXECUTORS)}")
    if int(workers) < 1:
        raise ParameterError("workers", workers, "a positive number of worker processes")
    unknown = [m for m in metrics if m not in METRICS]
    if unknown:
        raise UnknownNameError("metric", unknown[0], METRICS)
    points = list(points)
    check_design_size(len(points), "points")
    for p in points:
        _check_names(p)
    if isinstance(record, (str, bytes, int)):
        raise ParameterError("record", record, "a list of point indices, e.g. [0, 5]")
    n = len(points)
    record = [check_integer("record", i, 0, n - 1, f"indices of the sweep's {n} point{'s' * (n != 1)}")
              for i in record]
    check_settings(points, base)
    check_metric_settings(points, base, metrics)
    path.parent.mkdir(parents=True, exist_ok=True)
    # the CSV's lock for the whole sweep (PATH.lock): a second sweep on it, or a run writing it,
    # is refused (it would compute every point twice and duplicate rows)
    with hold(path, "path", holder="mjeap sweep"):
        return _run_locked(points, path, metrics, base, executor, workers, scheduler, record, rrd_dir, progress,
                           bool(share_error_models))


def _run_locked(points, path, metrics, base, executor, workers, scheduler, record, rrd_dir, progress, share=True):
    _drop_torn_row(path)
    done_ids, header, delimiter = set(), None, ","
    if path.exists() and path.stat().st_size > 0:       # resumed: read as users' CSVs are, appended in its form
        header, rows, delimiter = _read_sweep_csv(path)
        done_ids = {row["point_id"] for row in rows}
    rrd_dir = str(rrd_dir or path.parent / (path.stem + "-rrd"))
    record = set(int(i) for i in record)
    jobs = [(p, tuple(metrics), base, rrd_dir if i in record else None) for i, p in enumerate(points)
            if point_id(p, base, metrics) not in done_ids]
    skipped = len(points) - len(jobs)
    columns = ["point_id", *sorted({k for p in points for k in p}), *metrics, "error", "wall_s", "settings"]
    path.parent.mkdir(parents=True, exist_ok=True)
    new_file = not path.exists() or path.stat().st_size == 0
    if not new_file:
        if header != columns:
            raise ParameterError("path", str(path), f"a CSV of this sweep (columns {columns}); it has {header}")
    bar = None
    if progress or (progress is None and sys.stderr.isatty()):      # no bar flooding a log file
        try:
            from tqdm import tqdm
            bar = tqdm(total=len(jobs), unit="point", desc="sweep")
        except ImportError:  # pragma: no cover
            bar = None
    t0 = time.perf_counter()
    with sigterm_as_interrupt():
        return _write_rows(path, columns, new_file, executor, workers, scheduler, jobs, bar, skipped, t0, share,
                           delimiter)


class _RowFile:
    """The sweep's CSV, appended one whole row at a time: a row is formatted first, then
    written and fsynced; a write that fails (a full disk) cuts the file back to its last
    whole row and raises :class:`OutputError` saying how many rows are kept, so that a rerun
    resumes from them (a stream, e.g. /dev/stdout, is written through)."""

    def __init__(self, path: Path, delimiter: str = ","):
        self.path = path
        self.fd = os.open(path, os.O_WRONLY | os.O_APPEND | os.O_CREAT | os.O_CLOEXEC, 0o666)
        self.regular = stat.S_ISREG(os.fstat(self.fd).st_mode)
        self.buf = io.StringIO()
        self.writer = csvio.writer(self.buf, delimiter=delimiter)

    def write(self, cells, kept: int) -> None:
        self.buf.seek(0)
        self.buf.truncate()
        self.writer.writerow(cells)
        data = memoryview(self.buf.getvalue().encode("utf-8"))
        end = os.lseek(self.fd, 0, os.SEEK_END) if self.regular else None
        try:
            while data:
                data = data[os.write(self.fd, data):]
            if self.regular:
                os.fsync(self.fd)
        except OSError as e:
            if self.regular:
                os.ftruncate(self.fd, end)
            raise OutputError([(str(self.path), f"{e.strerror or e}; the {kept} whole rows written so far are "
                                               "kept: rerun the same sweep to resume from them")]) from None

    def close(self) -> None:
        os.close(self.fd)


def _write_rows(path, columns, new_file, executor, workers, scheduler, jobs, bar, skipped, t0, share=True,
                delimiter=","):
    failed, done = 0, 0
    out = _RowFile(path, delimiter)
    try:
        if new_file:
            out.write(columns, 0)
        rows = _with_shared_error_models if share else _submit_all
        for row in rows(executor, int(workers), scheduler, jobs):
            out.write([row.get(k, "") for k in columns], done + skipped)
            done += 1
            failed += bool(row["error"])
            if bar is not None:
                bar.update(1)
    finally:
        out.close()
        if bar is not None:
            bar.close()
    return SweepSummary(path, done, skipped, failed, time.perf_counter() - t0)
