"""The metrics of a sweep: each reduces a point's rollout (or its scene alone) to a number,
a bool or a str. :data:`METRICS` holds them by name (:func:`register_metric` adds one); the
sets beside it say which need no rollout (:data:`STATIC_METRICS`: ``first_frequency``,
``mass`` and the small-signal ``resonance_frequency``, ``antiresonance_frequency``,
``coupling_factor``, ``tip_per_volt_at``), which read only the run's end or every step of its last period (how a point's
rollout is sampled) and which need the run's own scene; :func:`check_metric_settings`
refuses, before any point runs, a metric its points cannot give.

No metric is read at an arbitrary instant of a periodic run: under a periodic drive (square,
sine, triangle) a metric reads the last whole period (``peak_to_peak``, ``returns``,
``stroke``, ``peak_power``, ``energy_per_cycle``), the whole run (``max_*``) or no run at all
(``first_frequency``, ``mass``, ``capacitance``, the fields); ``free_deflection``,
``blocked_force``, ``energy_density`` and ``settling_time`` keep their step meaning and are
refused there (:data:`STEP_ONLY_METRICS`), ``stroke`` under a step
(:data:`PERIODIC_ONLY_METRICS`).

The piezo metrics (``stroke`` aside) read the point's laminate, the actuator's stack wired as
its drive wires it (:mod:`mjeap.model.laminate`; ``piezo`` and ``piezo-bimorph``):
``max_field``, ``max_reverse_field`` (V/m, from the waveform's extreme voltages: a field is
linear in V), ``max_stress`` (Pa, from every hinge's curvature and the voltage over the
run) and ``capacitance`` (F, the free capacitance the signal terminal sees).
"""
from __future__ import annotations

import json
import weakref
from typing import Callable, Dict, Optional, Sequence

import numpy as np

from ...errors import DivergenceError, ParameterError, check_registration
from ...simulation.metric_scales import peak_to_peak, reported_value
from .points import PARAMETERS


def _period(point) -> Optional[float]:
    f = float(point.get("frequency") or 0.0)
    return 1.0 / f if f > 0 else None


def metric_peak_to_peak(r, point, scene) -> float:
    """Peak-to-peak tip curvature (1/m) over the last drive period (the second half of the
    run without a frequency); at a target on it, the value the accuracy report gives
    (:func:`mjeap.simulation.metric_scales.reported_value`)."""
    return reported_value(r, "peak_to_peak", _period(point))


def metric_returns(r, point, scene) -> bool:
    """Dadras et al. 2021's stability criterion: the tip curvature still changes sign in the last
    drive period (the actuator follows the drive instead of staying collapsed); at a target on
    it, decided on the margin the accuracy report gives."""
    return reported_value(r, "returns", _period(point)) > 0


def metric_settling_time(r, point, scene) -> float:
    """Time (s) after which the tip curvature stays within 2 % of its final change (a step
    drive: refused under a periodic one, which has no final value)."""
    _step_only(point, "settling_time")
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
    if "metrics" in a:          # a target on the metrics (mjeap.simulation.metric_accuracy)
        how = "shared error model" if a["error_model"]["pilots"] == "given" else "no prior"
    else:
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
    return float(act.actuator_mass())


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
    gravity and payload act too: hanging or standing, along the beam). A step drive's:
    refused under a periodic one (read ``stroke``)."""
    _step_only(point, "free_deflection")
    return float(_end_tip(r, scene)[1])


def _periodic(point) -> bool:
    return str(point.get("waveform", "")).strip().lower() in PERIODIC_WAVEFORMS


def _step_only(point, name: str) -> None:
    """Refuse metric ``name`` (a step's) at a point with a periodic waveform."""
    if _periodic(point):
        raise ParameterError("metrics", name, STEP_ONLY_METRICS[name],
                             f"the point's waveform is {point.get('waveform')}: a periodic run has no final value")


def metric_stroke(r, point, scene) -> float:
    """Stroke (m): the peak-to-peak tip deflection (the clamp frame's y) over the last whole
    drive period of a periodic drive (square, sine or triangle); refused under a step (read
    ``free_deflection``)."""
    if not _periodic(point):
        raise ParameterError("metrics", "stroke", PERIODIC_ONLY_METRICS["stroke"],
                             f"the point's waveform is {point.get('waveform') or 'none'}")
    return float(peak_to_peak(r.time, r.tip_position[:, 1], _period(point)))


def _laminate(point, scene, name: str):
    """The point's laminate (its actuator wired as its drive wires it) and drive; a drive
    without one (not a piezo drive) is refused naming ``name``."""
    from ...drives import make_drive
    from ...drives.piezo import LinearPiezo
    drv = make_drive(None, scene, **{k[6:]: v for k, v in point.items() if k.startswith("drive.")})
    if not isinstance(drv, LinearPiezo):
        raise ParameterError("metrics", name, PIEZO_ONLY, f"{scene.actuator.id}'s drive is {drv.name}")
    return drv.laminate(), drv


def _voltage_extremes(point) -> np.ndarray:
    """The lowest and highest voltage (V) of the point's waveform over its run: a step's
    amplitude; a periodic waveform's offset -/+ amplitude where the run lasts a period, else
    the waveform sampled finely over the run."""
    from ...drives.waveforms import parse_waveform
    from .points import point_duration, wave_text
    wave = parse_waveform(wave_text(point))
    if wave.kind == "step":
        return np.array([wave.amplitude])
    duration = point_duration(point)
    if duration * wave.frequency >= 1.0:
        return wave.offset + np.array([-1.0, 1.0]) * abs(wave.amplitude)
    v = wave(np.linspace(0.0, duration, 20001))
    return np.array([v.min(), v.max()])


def metric_max_field(r, point, scene) -> float:
    """Largest |field| (V/m) in any piezo layer over the run: V_j / t_j at the waveform's
    extreme voltages (a field is linear in V); no rollout."""
    lam, _ = _laminate(point, scene, "max_field")
    return lam.max_field(_voltage_extremes(point))[0]


def metric_max_reverse_field(r, point, scene) -> float:
    """Largest field against a piezo layer's poling (V/m, 0 where none) over the run: the
    depolarisation risk; no rollout."""
    lam, _ = _laminate(point, scene, "max_reverse_field")
    return lam.max_reverse_field(_voltage_extremes(point))[0]


def metric_capacitance(r, point, scene) -> float:
    """Free capacitance (F) the signal terminal sees: eps0 eps33^T A / t summed over the
    piezo layers whose voltage follows V (signal and complement). For a piezo-bimorph file,
    which has no permittivity, the model's low-frequency charge per volt
    C + Gamma^2 int dx / EI instead (its C, the capacitance parameter, is the blocked term);
    no rollout."""
    _, drv = _laminate(point, scene, "capacitance")
    return float(drv.capacitances()["free"][0])


def metric_max_stress(r, point, scene) -> float:
    """Largest |axial stress| (Pa) in any layer over the run: at each hinge and sample, from
    the hinge's curvature (its rotation / the segment length), the free strains at the
    sample's voltage and the neutral axis, at every layer's outer fibres, the beam free to
    stretch (:meth:`mjeap.model.laminate.Laminate.stress_coefficients`)."""
    lam, _ = _laminate(point, scene, "max_stress")
    lay = scene.layout
    c = np.asarray(r.centreline, float)                    # (n, N + 2, 3): clamp, hinges, tip
    seg = np.diff(c[:, :, :2], axis=1)
    phi = np.unwrap(np.arctan2(seg[..., 1], seg[..., 0]), axis=1)
    kappa = np.diff(phi, axis=1) / lay.ds                  # (n, N): each hinge's rotation over its segment
    v = np.asarray(r.voltage, float)
    worst = 0.0
    for j, x in enumerate(lay.hinge_x):
        dk, dv, c0 = lam.stress_coefficients(x)
        sigma = kappa[:, j, None, None] * dk + v[:, None, None] * dv + c0
        worst = max(worst, float(np.abs(sigma).max()))
    return worst


#: the tip must come back to within this fraction of its free deflection for a blocked force
BLOCKED_TOL = 1e-6


def metric_blocked_force(r, point, scene) -> float:
    """Blocked force (N): the tip force that holds the tip at zero deflection under the
    voltage at the run's end, simulated. The scene, left in the run's final state with the
    drive's moments applied, settles statically (:meth:`Scene.settle`); a transverse tip force
    is then found by the secant method, each trial settled again, until the tip is back
    within BLOCKED_TOL of its free deflection (geometric nonlinearity included; 2-4
    settles). Reported as the force the actuator exerts on the block: the same sign as the
    free deflection. Needs the run's own scene: not at an accuracy target. A step drive's:
    refused under a periodic one (read ``stroke``)."""
    _step_only(point, "blocked_force")
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
    its tip block's (:func:`metric_mass`); a step drive's, as theirs."""
    _step_only(point, "energy_density")
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


# ---------------------------------------------------------------- small-signal metrics
#: the admittance's resonance is searched between these multiples of the first mode
RESONANCE_SEARCH = (0.25, 4.0)
_SMALL_SIGNAL = weakref.WeakKeyDictionary()


def _small_signal(point, scene):
    """The point's small-signal model (:class:`mjeap.analysis.frf.SmallSignalModel`) about its
    ``offset`` (V) with its ``drive.*`` parameters, and its resonances, kept per scene."""
    from ...analysis.frf import SmallSignalModel
    params = {k[6:]: v for k, v in point.items() if k.startswith("drive.")}
    key = (float(point.get("offset") or 0.0), json.dumps(params, sort_keys=True, default=str), scene.part.revision)
    cache = _SMALL_SIGNAL.setdefault(scene, {})
    if key not in cache:
        model = SmallSignalModel(scene, drive_params=params, operating_voltage=key[0])
        f1 = scene.choice.first_frequency
        lo, hi = RESONANCE_SEARCH
        cache.clear()
        cache[key] = (model, model.resonances(lo * f1, min(hi * f1, scene.choice.highest_frequency)))
    return cache[key]


def _resonance(point, scene, which: int, name: str) -> float:
    _, found = _small_signal(point, scene)
    if found[which] is None:
        raise ParameterError("metrics", name, "a drive whose admittance shows the first mode's resonance",
                             found[2])
    return float(found[which])


def metric_resonance_frequency(r, point, scene) -> float:
    """Resonance (Hz): the admittance's first maximum between RESONANCE_SEARCH x the first
    mode, from the small-signal model about the point's offset (:mod:`mjeap.analysis.frf`);
    no rollout. Refused for a drive whose model draws no current."""
    return _resonance(point, scene, 0, "resonance_frequency")


def metric_antiresonance_frequency(r, point, scene) -> float:
    """Antiresonance (Hz): the admittance's first minimum after the resonance; no rollout."""
    return _resonance(point, scene, 1, "antiresonance_frequency")


def metric_coupling_factor(r, point, scene) -> float:
    """Effective electromechanical coupling k_eff = sqrt(1 - (f_r / f_a)^2) (-) of the first
    mode, from the admittance's resonance and antiresonance; no rollout."""
    fr = _resonance(point, scene, 0, "coupling_factor")
    fa = _resonance(point, scene, 1, "coupling_factor")
    return float(np.sqrt(max(0.0, 1.0 - (fr / fa) ** 2)))


def metric_tip_per_volt_at(r, point, scene) -> float:
    """Tip deflection per volt (m/V) of the small-signal response at the point's
    ``frequency`` (Hz), about its ``offset`` (V), per volt of the drive's input; no rollout."""
    f = float(point.get("frequency") or 0.0)
    if not f > 0:
        raise ParameterError("frequency", point.get("frequency"), "a frequency > 0 Hz for tip_per_volt_at")
    model, _ = _small_signal(point, scene)
    return float(abs(model.tip([f])[0]))


METRICS: Dict[str, Callable] = {
    "estimated_error": metric_estimated_error, "stopped_early": metric_stopped_early,
    "peak_to_peak": metric_peak_to_peak, "returns": metric_returns, "settling_time": metric_settling_time,
    "max_stress_proxy": metric_max_stress_proxy, "max_tip_deflection": metric_max_tip_deflection,
    "first_frequency": metric_first_frequency, "mass": metric_mass, "free_deflection": metric_free_deflection,
    "blocked_force": metric_blocked_force, "energy_density": metric_energy_density,
    "peak_power": metric_peak_power, "energy_per_cycle": metric_energy_per_cycle, "stroke": metric_stroke,
    "max_field": metric_max_field, "max_reverse_field": metric_max_reverse_field, "max_stress": metric_max_stress,
    "capacitance": metric_capacitance,
    "resonance_frequency": metric_resonance_frequency, "antiresonance_frequency": metric_antiresonance_frequency,
    "coupling_factor": metric_coupling_factor, "tip_per_volt_at": metric_tip_per_volt_at,
}
#: metrics that need no rollout: the point's scene alone (``fn(None, point, scene)``)
STATIC_METRICS = {"first_frequency", "mass", "max_field", "max_reverse_field", "capacitance", "resonance_frequency",
                  "antiresonance_frequency", "coupling_factor", "tip_per_volt_at"}
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
                "energy_density": "J/kg", "peak_power": "W", "energy_per_cycle": "J", "stroke": "m",
                "max_field": "V/m", "max_reverse_field": "V/m", "max_stress": "Pa", "capacitance": "F",
                "resonance_frequency": "Hz", "antiresonance_frequency": "Hz", "coupling_factor": "-",
                "tip_per_volt_at": "m/V"}
#: the waveforms of a periodic drive (the others: a step)
PERIODIC_WAVEFORMS = ("square", "sine", "triangle")
#: metrics with a step's meaning, refused under a periodic drive: what to read instead
STEP_ONLY_METRICS = {
    "free_deflection": "a step drive (a periodic run has no final deflection: read stroke, the peak-to-peak tip "
                       "deflection over the last whole periods, or use --voltage step:V)",
    "blocked_force": "a step drive (a periodic run has no final state to block: read stroke under a periodic drive, or "
                     "use --voltage step:V)",
    "energy_density": "a step drive (blocked_force x free_deflection of a step: read stroke under a periodic drive, "
                      "or use --voltage step:V)",
    "settling_time": "a step drive (settling after a step: a periodic run has no final value; read peak_to_peak or "
                     "stroke)"}
#: metrics of a periodic drive, refused under a step: what to read instead
PERIODIC_ONLY_METRICS = {"stroke": "a periodic waveform (square, sine or triangle with a frequency > 0): under a step "
                                   "read free_deflection"}
#: metrics that read a piezo layer's field: a study that reads one says its fields in that column
FIELD_METRICS = ("max_field", "max_reverse_field")
#: metrics that read a piezo laminate (the piezo and piezo-bimorph drives)
PIEZO_METRICS = (*FIELD_METRICS, "max_stress", "capacitance")
PIEZO_ONLY = "an actuator with a piezo drive (piezo or piezo-bimorph: a laminate of piezo layers)"


#: a row's own columns, which no metric may be named
ROW_COLUMNS = ("point_id", "error", "wall_s", "settings", "_error_model", "_field")


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


def check_metric_settings(points: Sequence[dict], base: Optional[dict], metrics: Sequence[str]) -> None:
    """Metrics their points cannot give, refused before any work: a blocked force (and the
    energy density) at an accuracy target (it is simulated on the run's own scene), a step's
    metric under a periodic waveform and ``stroke`` under a step (:data:`STEP_ONLY_METRICS`,
    :data:`PERIODIC_ONLY_METRICS`), power metrics without a periodic waveform, a piezo metric
    of an actuator without a piezo drive."""
    base = base or {}
    _check_piezo_metrics(points, base, metrics)
    for p in points or [{}]:
        full = {**PARAMETERS, **base, **p}
        own = [m for m in metrics if m in OWN_SCENE_METRICS]
        if own and full["accuracy"] not in (None, ""):
            raise ParameterError("metrics", own[0], "a study without an accuracy target (the blocked force is "
                                 "simulated on the run's own scene, which a target replaces by the models it chooses)")
        wave = str(full["waveform"]).strip().lower()
        for m in metrics:
            if m in STEP_ONLY_METRICS and wave in PERIODIC_WAVEFORMS:
                raise ParameterError("metrics", m, STEP_ONLY_METRICS[m],
                                     f"the waveform is {wave}: refused before any work")
            if m in PERIODIC_ONLY_METRICS and wave not in PERIODIC_WAVEFORMS:
                raise ParameterError("metrics", m, PERIODIC_ONLY_METRICS[m], f"the waveform is {wave}")
        power = [m for m in metrics if m in STEP_METRICS]
        if power and (str(full["waveform"]).strip().lower() not in ("square", "sine", "triangle")
                      or not _positive(full["frequency"])):
            raise ParameterError("metrics", power[0], "a periodic waveform (square, sine or triangle with a frequency "
                                 "> 0) for peak_power and energy_per_cycle",
                                 f"a point has waveform={full['waveform']!r}, frequency={full['frequency']!r}")


def _check_piezo_metrics(points, base, metrics) -> None:
    """A piezo metric (:data:`PIEZO_METRICS`) of a point whose actuator's drive is no piezo
    drive, refused (once per actuator) before any work."""
    wanted = [m for m in metrics if m in PIEZO_METRICS]
    if not wanted:
        return
    from ...drives import default_drive_name, get_drive_class
    from ...drives.piezo import LinearPiezo
    from ...errors import MjeapError
    from ...model.catalog import get_actuator
    seen = set()
    for p in points or [{}]:
        act = {**PARAMETERS, **base, **p}["actuator"]
        key = act if isinstance(act, str) else id(act)
        if key in seen:
            continue
        seen.add(key)
        try:
            cls = get_drive_class(default_drive_name(get_actuator(act)))
        except MjeapError:
            continue                    # an unknown actuator: its points report it
        if not issubclass(cls, LinearPiezo):
            raise ParameterError("metrics", wanted[0], PIEZO_ONLY, f"the actuator's drive is {cls.name}")


def _positive(x) -> bool:
    try:
        return float(x) > 0
    except (TypeError, ValueError):
        return False
