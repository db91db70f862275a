"""Headless rollouts: a scene, a drive and a voltage waveform, stepped in lockstep.

Two engines give the same trajectory (tested to round-off):

* ``loop``: the drive, then ``mj_step``, once per step from Python. It serves every drive
  and closed-loop controllers. Why not MuJoCo's ``mjcb_control`` hook: that callback is
  one global per process (two scenes, or a scene and a dm_control environment, would
  fight over it) and costs a C-to-Python call per step anyway.
* ``threaded``: MuJoCo's native ``mujoco.rollout`` (:mod:`mjeap.threaded`), no Python per
  step, many rollouts over a thread pool. It applies where the drive is open-loop: its
  moments follow from the voltage alone, so their whole history is computed up front
  (piezo bimorph; blocking force without a stiffness table; electrostrictive without
  field stiffening), there is no controller and no tip load.

``engine="auto"`` (the default) takes ``threaded`` where it applies. The waveform is
evaluated for all steps up front (vectorised).
"""
from __future__ import annotations

import math
import os
import sys
import time as _time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Dict, List, Optional, Sequence, Tuple, Union

import mujoco
import numpy as np

from . import csvio
from .analytical import arc_curvature
from .errors import DivergenceError, ParameterError, check_integer, check_positive, check_range
from .outputs import deferred_signals, guarded, replacing
from .accuracy import target_for
from .scene import Scene
from .waveforms import Waveform, parse_waveform

try:  # progress bars are optional
    from tqdm import tqdm
except ImportError:  # pragma: no cover
    tqdm = None

#: at most this many samples are kept per rollout unless sample_interval is given
DEFAULT_SAMPLES = 5000
#: runs of more steps than this show a progress bar (when progress is None)
PROGRESS_STEPS = 200_000
ENGINES = ("auto", "loop", "threaded", "native")


@dataclass
class RolloutResult:
    """Sampled SI arrays of a rollout. Positions are in the clamp frame (x along the
    undeformed beam, y the deflection, z out of the bending plane). Sample i is the state
    after step k; its voltage is the one held over that step (zero-order hold), the same
    instant the drive signals describe."""

    time: np.ndarray                 # (n,) s
    voltage: np.ndarray              # (n,) V
    tip_position: np.ndarray         # (n, 3) m
    tip_angle: np.ndarray            # (n,) rad
    tip_curvature: np.ndarray        # (n,) 1/m, arc through clamp and tip (seed 000)
    centreline: np.ndarray           # (n, N + 2, 3) m
    payload_position: Optional[np.ndarray]
    signals: Dict[str, np.ndarray]   # drive quantities, 'name (unit)'
    reference_curvature: Optional[np.ndarray]
    meta: dict = field(default_factory=dict)

    def peak_to_peak(self, key: str = "tip_curvature", t_from: float = 0.0) -> float:
        y = getattr(self, key) if hasattr(self, key) else self.signals[key]
        sel = self.time >= t_from
        return float(np.max(y[sel]) - np.min(y[sel]))

    def to_csv(self, path: Union[str, Path]) -> None:
        """Time series (no centreline) as CSV with SI units in the header, written whole
        (:func:`mjeap.outputs.replacing`) and spreadsheet-safe (:class:`mjeap.csvio.writer`)."""
        cols = {"time (s)": self.time, "voltage (V)": self.voltage,
                "tip_x (m)": self.tip_position[:, 0], "tip_y (m)": self.tip_position[:, 1],
                "tip_z (m)": self.tip_position[:, 2], "tip_angle (rad)": self.tip_angle,
                "tip_curvature (1/m)": self.tip_curvature, **self.signals}
        if self.reference_curvature is not None:
            cols["reference_curvature (1/m)"] = self.reference_curvature
        with replacing(path, "csv_path") as tmp, open(tmp, "w", newline="") as fh:
            w = csvio.writer(fh)
            w.writerow(cols)
            w.writerows(np.column_stack([np.asarray(c, dtype=float) for c in cols.values()]))


class _Samples:
    """Preallocated sample arrays of one rollout of one actuator (an
    :class:`~mjeap.component.ActuatorPart`). A sample copies MuJoCo's raw world positions
    (clamp, links, payload, tip site), the tip's orientation (and the clamp's, where the
    clamp can move) and the drive's signals; the clamp-frame SI read-outs (the part's
    clamp_frame and in_plane_angle, as its own read-outs use) are computed for all samples
    at once at the end, so a sample costs a few copies."""

    def __init__(self, part, ns: int):
        self.part, self.ns = part, ns
        N = part.layout.segments
        # raw world points per sample: clamp, the N link origins, the tip site, the payload
        self._bodies = np.r_[part.clamp_id, part.link_ids].astype(np.intp)
        self._raw = np.empty((ns, N + 2 + (part.payload_id >= 0), 3))
        self._xmat = np.empty((ns, 9))
        self._moving = part._fixed_rotation is None
        self._clamp_xmat = np.empty((ns, 9)) if self._moving else None
        self.t, self.v = np.empty(ns), np.empty(ns)
        self.sig: Dict[str, np.ndarray] = {}
        self.n = 0                                  # samples taken

    def _put(self, key, i, value):
        if key not in self.sig:
            self.sig[key] = np.full(self.ns, np.nan)
        self.sig[key][i] = value

    def take(self, t: float, v: float, signals: Dict[str, float], controller=None) -> None:
        """Sample the state after the step that ended at ``t`` s (kinematics up to date),
        ``v`` the voltage held over that step (the first sample: the first step's), the
        instant the drive's ``signals`` describe."""
        p, i = self.part, self.n
        d = p.data
        self.t[i], self.v[i] = t, v
        raw, N = self._raw[i], p.layout.segments
        np.take(d.xpos, self._bodies, axis=0, out=raw[:N + 1], mode="clip")
        raw[N + 1] = d.site_xpos[p.tip_site_id]
        if p.payload_id >= 0:
            raw[N + 2] = d.xpos[p.payload_id]
        self._xmat[i] = d.xmat[p.tip_body_id]
        if self._moving:
            self._clamp_xmat[i] = d.xmat[p.clamp_id]
        for k, x in signals.items():
            self._put(k, i, x)
        if controller is not None and hasattr(controller, "signals"):
            for k, x in controller.signals().items():
                self._put(f"controller_{k}", i, x)
        self.n += 1

    def _to_clamp(self, raw: np.ndarray, xmat: np.ndarray):
        """Clamp-frame points (m) and tip angles (rad) of raw samples."""
        p = self.part
        if not self._moving:
            return p.clamp_frame(raw), p.in_plane_angle(xmat)
        R = self._clamp_xmat[:len(raw)].reshape(-1, 3, 3)
        pts = np.einsum("n...j,njk->n...k", raw, R) * p.units.length
        rel = np.einsum("nji,njk->nik", R, xmat.reshape(-1, 3, 3))
        return pts, np.arctan2(rel[:, 1, 0], rel[:, 0, 0])

    def result(self, drive, initial_curvature: float, meta: dict) -> RolloutResult:
        """The SI result; called once, at the end (it works on the raw arrays in place)."""
        n, p = self.n, self.part
        N = p.layout.segments
        raw = self._raw[:n]
        raw -= raw[:, :1].copy()                    # relative to the clamp (in place)
        pts, ang = self._to_clamp(raw, self._xmat[:n])
        cl = pts[:, :N + 2]                         # clamp, hinges, tip
        tip = cl[:, -1].copy()                      # the centreline ends at the tip point
        kap = arc_curvature(tip[:, 0], tip[:, 1])
        pay = pts[:, N + 2] if p.payload_id >= 0 else None
        ref = drive.reference_curvature(self.t[:n], self.v[:n], initial_curvature) \
            if (n > 1 and drive is not None) else None
        return RolloutResult(self.t[:n], self.v[:n], tip, ang, kap, cl, pay,
                             {k: x[:n] for k, x in self.sig.items()}, ref, meta)


#: runs of more steps are refused unless ``max_steps`` is raised (the voltage history alone
#: takes 8 bytes a step; at ~10-30 us a step this is minutes of work)
MAX_STEPS = 20_000_000
#: a waveform whose energy above the step's Nyquist frequency exceeds this fraction is refused
ALIASED_ENERGY = 1e-3


def check_work(duration: float, dt: float, max_steps: Optional[int] = None) -> int:
    """The number of steps of a run, refused before any work where the duration is shorter
    than one timestep or the steps exceed ``max_steps`` (default MAX_STEPS)."""
    limit = MAX_STEPS if max_steps is None else int(max_steps)
    if duration < dt:
        raise ParameterError("duration", f"{duration:g} s", f"at least one timestep ({dt:.4g} s)")
    n = int(round(duration / dt))
    if n > limit:
        raise ParameterError("duration", f"{duration:g} s", f"at most {limit:,} steps of {dt:.4g} s "
                             f"({limit * dt:.4g} s); this run needs {n:,} steps and {8 * n / 2**20:.0f} MiB for its "
                             "voltage history alone. Raise max_steps (--max-steps) to run it")
    return n


def check_sampling(wave, dt: float) -> None:
    """Refuse a waveform whose content the step cannot represent: a frequency at or above
    the Nyquist frequency 1/(2 dt) (a sine of 13 kHz at dt = 77 us runs as an aliased
    38 Hz one), or csv samples with more than ALIASED_ENERGY of their energy above it."""
    if not isinstance(wave, Waveform):
        return
    f_n = 0.5 / dt
    above = wave.content_above(f_n)
    if above > (ALIASED_ENERGY if wave.kind == "csv" else 0.0):
        what = (f"{above:.1%} of the csv signal's energy lies above" if wave.kind == "csv"
                else f"frequency {wave.max_frequency:g} Hz is at or above")
        raise ParameterError("voltage", getattr(wave, "text", str(wave)),
                             f"content below the Nyquist frequency {f_n:.4g} Hz of the timestep {dt:.4g} s "
                             f"({what} it and would alias)", "pass a smaller timestep to the Scene")


def check_outputs(**paths) -> Dict[str, Path]:
    """The outputs a run will write (name -> path or None), checked before any work: distinct
    files, not directories, in a folder that exists or can be made and is writable."""
    out, seen = {}, {}
    for name, p in paths.items():
        if p is None:
            continue
        p = Path(p)
        key = p.resolve()
        if key in seen:
            raise ParameterError(name, str(p), f"a file other than the {seen[key]} output's")
        seen[key] = name
        if p.is_dir():
            raise ParameterError(name, str(p), "a file path (it is a directory)")
        parent = p.parent
        try:
            parent.mkdir(parents=True, exist_ok=True)
        except OSError as e:
            raise ParameterError(name, str(p), "a path in a folder that exists or can be made",
                                 f"cannot write {p}: {e.strerror or e}") from None
        if not os.access(parent, os.W_OK) or (p.exists() and not os.access(p, os.W_OK)):
            raise ParameterError(name, str(p), "a writable path", f"cannot write {p}: permission denied")
        out[name] = p
    return out


def write_outputs(writers, error: Optional[BaseException], result=None) -> None:
    """Run each ``(path, write)`` on its own: one failing write does not stop the others.
    The run's own error stays the error raised (the write failures are added to its notes);
    without one, the failures raise :class:`OutputError` carrying the result. Ctrl-C and
    SIGTERM wait until all are written."""
    from .errors import OutputError
    failures = []
    with deferred_signals():
        for path, write in writers:
            try:
                write()
            except Exception as e:                   # noqa: BLE001 - reported, never masks the run's error
                failures.append((path, f"{type(e).__name__}: {e}"))
    if not failures:
        return
    if error is not None:
        notes = getattr(error, "__notes__", None)
        if notes is None:
            notes = error.__notes__ = []
        notes.extend(f"cannot write {p}: {why}" for p, why in failures)
        return
    raise OutputError(failures, result)


def _voltage_steps(wave, duration: float, dt: float, drive, max_steps: Optional[int] = None) -> np.ndarray:
    n_steps = check_work(duration, dt, max_steps)
    check_sampling(wave, dt)
    t_steps = np.arange(n_steps) * dt
    v = np.zeros(n_steps) if wave is None else np.asarray(wave(t_steps), dtype=float) * np.ones(n_steps)
    drive.check_voltage(v)
    return v


def _waveform(voltage, duration: float):
    """A waveform from text, a :class:`Waveform`, a number (a constant voltage, V) or a
    callable v(t); anything else is refused naming what is accepted."""
    if isinstance(voltage, bool) or voltage is None:
        raise ParameterError("voltage", voltage, "a waveform ('step:1V', 'sine:1V@2Hz', ...), a number of volts "
                             "or a callable v(t); None only with a controller")
    if isinstance(voltage, (int, float, np.number)):
        v = float(voltage)
        if not math.isfinite(v):
            raise ParameterError("voltage", voltage, "a finite number of volts")
        voltage = Waveform("step", amplitude=v, text=f"constant {v:g} V")
    if not isinstance(voltage, (str, Waveform)) and not callable(voltage):
        raise ParameterError("voltage", voltage, "a waveform text, a Waveform, a number of volts or a callable v(t)")
    wave = parse_waveform(voltage) if isinstance(voltage, str) else voltage
    return wave.with_duration(duration) if isinstance(wave, Waveform) else wave


def one_voltage(value, name: str, where: str = "") -> float:
    """A policy's or controller's command for one actuator as a voltage (V): a finite real
    number or a one-element array (shape (1,), a dm_env action). Text, None, a bool, more
    values (two for one actuator, never cut to the first), none or NaN/inf are refused
    naming ``name``, the shape expected and ``where`` (the controller and time). The one
    check of every command path (:func:`rollout`'s loop, :class:`mjeap.system.System`,
    the dm_env environment)."""
    try:
        a = None if isinstance(value, (str, bytes, bool, type(None))) else np.asarray(value)
    except (TypeError, ValueError):          # ragged nesting
        a = None
    ok = a is not None and a.size == 1 and a.dtype.kind in "iuf"
    v = float(a.reshape(-1)[0]) if ok else math.nan
    if not math.isfinite(v):
        shown = value if ok or a is None or a.ndim == 0 else f"{type(value).__name__} of shape {a.shape}"
        raise ParameterError(name, shown, "one number, a finite voltage in V for one actuator (a number or an "
                             "array of shape (1,))", where)
    return v


#: the largest initial bend accepted: a uniform arc closing into a full circle
MAX_INITIAL_BEND = 2 * np.pi


def check_initial_curvature(kappa, length: float, name: str = "initial_curvature") -> float:
    """A finite initial curvature (1/m) whose arc bends at most MAX_INITIAL_BEND over the
    beam (|kappa| L <= 2 pi: a full circle; more wraps the beam around itself)."""
    return check_range(name, kappa, -MAX_INITIAL_BEND / length, MAX_INITIAL_BEND / length, "1/m")


def _sample_steps(n_steps: int, dt: float, sample_interval: Optional[float]) -> np.ndarray:
    """The steps after which a sample is taken: every ``sample_interval`` (rounded to whole
    steps) or, by default, every ceil(n / DEFAULT_SAMPLES) steps: at most DEFAULT_SAMPLES + 1
    samples with the initial state, evenly spaced (the analytical references integrate on
    them), the last within one interval of the end (the scene holds the final state)."""
    every = max(1, int(round(sample_interval / dt))) if sample_interval else max(1, -(-n_steps // DEFAULT_SAMPLES))
    return np.arange(0, n_steps + 1, every)


def _meta(scene, drv, wave, duration, initial_curvature, n_steps, engine) -> dict:
    from .outputs import provenance
    return {**provenance(), "actuator": scene.actuator.id, "drive": drv.describe(),
            "voltage": "closed loop" if wave is None else getattr(wave, "text", str(wave)),
            "duration_s": duration, "initial_curvature_per_m": initial_curvature, "steps": n_steps,
            "engine": engine, "scene": scene.summary(),
            "drive_parameters": {k: [v, drv.sources.get(k, "")] for k, v in drv.params.items()}}


def _choose_engine(engine: str, scene, drv, controller) -> Tuple[str, str]:
    """The engine for this run and why: 'native' where the drive has a native form,
    else 'threaded' where it is open-loop, else 'loop' (``auto``); a named engine that does
    not apply is refused with the reason."""
    from . import native, threaded
    if engine not in ENGINES:
        raise ParameterError("engine", engine, f"one of {', '.join(ENGINES)}")
    if engine == "loop":
        return "loop", "asked for"
    why = {"native": native.why_not(scene, drv, controller), "threaded": threaded.why_not(scene, drv, controller)}
    if engine != "auto":
        if why[engine] is not None:
            raise ParameterError("engine", engine, f"'loop' or 'auto' for this run: {why[engine]}")
        return engine, "asked for"
    for i, e in enumerate(why):
        if why[e] is None:
            return e, "; ".join(["auto"] + [f"not {x}: {why[x]}" for x in list(why)[:i]])
    return "loop", "; ".join(["auto"] + [f"not {x}: {w}" for x, w in why.items()])


@guarded("rrd", "csv_path")
def rollout(scene: Scene, voltage: Union[str, Waveform, callable], duration: float,
            drive: Union[str, "object", None] = None, drive_params: Optional[dict] = None,
            initial_curvature: float = 0.0, rrd: Union[str, Path, None] = None,
            csv_path: Union[str, Path, None] = None, sample_interval: Optional[float] = None,
            progress: Optional[bool] = None, check_every: int = 100, controller=None,
            engine: str = "auto", max_steps: Optional[int] = None, accuracy: Optional[float] = None,
            estimate_error: bool = False) -> RolloutResult:
    """Run ``scene`` driven by ``drive`` (name, instance or None for the actuator's own)
    with ``voltage`` (waveform text, :class:`Waveform` or callable v(t)) for ``duration`` s.

    The beam starts at rest as a uniform arc of ``initial_curvature`` (1/m). Returns SI
    arrays sampled every ``sample_interval`` s (default: at most 5001 evenly spaced samples, the
    initial state included; the scene is left in the final state). With
    ``rrd`` a Rerun recording is written (also when the run fails or is stopped by Ctrl-C or
    SIGTERM: it then ends with the error), with ``csv_path`` the time series as CSV; a
    second writer of either is refused (:func:`mjeap.outputs.guarded`). A diverging run raises
    :class:`DivergenceError` naming the step, the drive and the timestep. ``engine``:
    'loop', 'threaded' (open-loop drives only, see the module) or 'auto'. Refused before
    any work: a duration shorter than a step, more than ``max_steps`` steps (default
    MAX_STEPS), a waveform above the step's Nyquist frequency.

    ``accuracy`` (default: the scene's own, if any): the largest error of the tip curvature
    relative to its swing; the run then chooses its segments, integrator and timestep
    (:mod:`mjeap.accuracy`; ``scene`` is left as it was) and ``meta['accuracy']`` carries the
    model and its estimated error. Without one the scene's model runs; ``estimate_error``
    then estimates its error with a coarser companion run (about 0.35 x the cost).
    """
    from .drives import make_drive
    from . import recording, threaded

    duration = check_positive("duration", duration, "s")
    initial_curvature = check_initial_curvature(initial_curvature, scene.layout.length)
    wave = None if controller is not None else _waveform(voltage, duration)
    drv = drive if (drive is not None and not isinstance(drive, str)) else \
        make_drive(drive, scene, **(drive_params or {}))
    target = target_for(scene, accuracy)
    if target is not None or estimate_error:
        return _rollout_at_accuracy(scene, voltage, duration, drv, initial_curvature, rrd, csv_path, sample_interval,
                                    check_every, controller, engine, max_steps, target, wave)
    engine, engine_reason = _choose_engine(engine, scene, drv, controller)
    dt = scene.timestep
    v_steps = _voltage_steps(wave, duration, dt, drv, max_steps)
    n_steps = len(v_steps)
    sample_steps = _sample_steps(n_steps, dt, sample_interval)
    nat = scene.native_model(drv) if engine == "native" else None
    samples = _Samples(scene.part if nat is None else nat.part, len(sample_steps))
    meta = _meta(scene, drv, wave, duration, initial_curvature, n_steps, engine)
    meta["engine_reason"] = engine_reason
    if scene.choice.buckled:
        meta.setdefault("warnings", []).append(
            f"{scene.actuator.id}: the straight beam is unstable under gravity (the payload is above the column "
            "load): the run starts from that unstable equilibrium and only a disturbance (an initial curvature, a "
            "voltage) makes it buckle; a result near zero here is not a stable beam")
    if controller is not None:
        meta["controller"] = getattr(controller, "name", type(controller).__name__)
    error = None
    wall0 = _time.perf_counter()
    try:
        if engine == "threaded":
            threaded.run(scene, [drv], [v_steps], [initial_curvature], sample_steps, [samples], nthread=0)
        elif engine == "native":
            threaded.run_native(scene, nat, [drv], [v_steps], [initial_curvature], sample_steps, [samples],
                                nthread=0)
        else:
            _run_loop(scene, drv, v_steps, initial_curvature, sample_steps, samples, progress, check_every,
                      controller, meta)
    except BaseException as e:  # record what was simulated, then re-raise
        error = e
        raise
    finally:
        meta["wall_time_s"] = _time.perf_counter() - wall0
        result = samples.result(drv, initial_curvature, meta)
        if error is not None:
            meta["error"] = f"{type(error).__name__}: {error}"
        writers = []
        if rrd is not None:
            writers.append((rrd, lambda: recording.write_recording(rrd, result, scene)))
        if csv_path is not None and samples.n > 0:
            writers.append((csv_path, lambda: result.to_csv(csv_path)))
        write_outputs(writers, error, result)
    return result


def _rollout_at_accuracy(scene, voltage, duration, drv, initial_curvature, rrd, csv_path, sample_interval,
                         check_every, controller, engine, max_steps, target, wave) -> RolloutResult:
    """:func:`rollout` at an accuracy target (or, without one, with its error estimated): the
    runs of :mod:`mjeap.accuracy`, each with the drive ``drv`` names and its parameters;
    the outputs hold the chosen run, whose meta says how it was chosen."""
    from . import accuracy as acc, recording
    from .drives import make_drive
    params = dict(drv.params)

    def run(s, interval):
        return rollout(s, voltage, duration, drive=make_drive(drv.name, s, **params),
                       initial_curvature=initial_curvature, sample_interval=interval, progress=False,
                       check_every=check_every, controller=controller, engine=engine, max_steps=max_steps)

    if target is None:
        chosen = scene
        result = run(scene, sample_interval)
        acc.estimate_error(scene, run, result, duration=duration, sample_interval=sample_interval)
    else:
        result, chosen, _ = acc.run_at_accuracy(scene, run, accuracy=target, duration=duration, wave=wave,
                                                sample_interval=sample_interval)
    writers = []
    if rrd is not None:
        writers.append((rrd, lambda: recording.write_recording(rrd, result, chosen)))
    if csv_path is not None:
        writers.append((csv_path, lambda: result.to_csv(csv_path)))
    write_outputs(writers, None, result)
    return result


def divergence_error(scene, drv, voltage: float, step: int, who: str = "") -> DivergenceError:
    """The error of a lockstep run of ``scene`` and ``drv`` that blew up by ``step`` (the
    last with ``voltage`` V held): a drive whose own moment is not finite is named as the
    cause, else the scene's error (timestep against its stability limit) with the drive and
    voltage, and ``who`` (a controller) added."""
    d = scene.data
    bad = d.qfrc_applied[~np.isfinite(d.qfrc_applied)]
    if bad.size:                 # the drive's own output, not the timestep
        return DivergenceError(
            f"the drive {drv.describe()} applied a non-finite moment ({bad[0]}) by t = "
            f"{step * scene.timestep:.6g} s (step {step}), voltage {voltage:.4g} V; the beam was finite "
            "until then: check the drive, not the timestep")
    return DivergenceError(f"{scene.divergence_error()} Drive: {drv.describe()}, voltage {voltage:.4g} V.{who}")


def _run_loop(scene, drv, v_steps, initial_curvature, sample_steps, samples, progress, check_every,
              controller, meta) -> None:
    """The lockstep engine: drive, then mj_step, once per step."""
    dt, n_steps, ns = scene.timestep, len(v_steps), len(sample_steps)
    scene.reset(curvature=initial_curvature)
    drv.reset(initial_curvature)
    ctrl_every, v_lo, v_hi, saturated, v_hold = n_steps + 1, *drv.voltage_range(), 0, 0.0
    if controller is not None:
        controller.reset(scene, drv)
        ctrl_every = max(1, int(round(getattr(controller, "interval", dt) / dt)))
        ctrl_name = meta["controller"]
    show = (n_steps > PROGRESS_STEPS and sys.stderr.isatty()) if progress is None else progress
    bar = tqdm(total=n_steps, unit="step", desc=f"{scene.actuator.id} {drv.name}", disable=not show,
               leave=False) if tqdm else None
    every = int(sample_steps[1] - sample_steps[0]) if ns > 1 else n_steps
    m, d = scene.model, scene.data
    step_fn = mujoco.mj_step

    def sample(step):
        scene.update_kinematics()
        samples.take(step * dt, v_hold if controller is not None else v_steps[max(step - 1, 0)], drv.signals(),
                     controller)

    try:
        sample(0)
        i_sample = 1
        nxt = sample_steps[1] if ns > 1 else n_steps + 1
        for k in range(n_steps):
            if controller is not None:
                if k % ctrl_every == 0:
                    scene.update_kinematics()
                    u = controller(k * dt, scene)
                    if not isinstance(u, float) or not math.isfinite(u):
                        u = one_voltage(u, "controller command", f"{ctrl_name} at t = {k * dt:.6g} s")
                    v_hold = min(max(u, v_lo), v_hi)
                    saturated += v_hold != u
                v_steps[k] = v_hold
            drv.step(v_steps[k], dt)
            step_fn(m, d)
            if (k + 1) % check_every == 0 or k + 1 == nxt:
                try:
                    scene._step_count = k + 1
                    scene.check_finite()
                except DivergenceError:
                    who = f" Controller: {ctrl_name} (check its gains)." if controller is not None else ""
                    raise divergence_error(scene, drv, v_steps[k], k + 1, who) from None
            if k + 1 == nxt:
                sample(k + 1)
                i_sample += 1
                nxt = sample_steps[i_sample] if i_sample < ns else n_steps + 1
                if bar is not None:
                    bar.update(every)
    finally:
        if bar is not None:
            bar.close()
        if controller is not None:
            meta["saturated_updates"] = int(saturated)
            if saturated:
                meta.setdefault("warnings", []).append(
                    f"{ctrl_name}: {saturated} voltage commands clipped to the safe range [{v_lo:g}, {v_hi:g}] V "
                    "(reference beyond reach or gains too high)")


def free_vibration(scene: Scene, curvature: float, duration: float, **kw) -> RolloutResult:
    """Release the beam, bent to a uniform arc of ``curvature`` (1/m), with no drive holding
    it, and follow it for ``duration`` s: a free vibration under its elasticity, damping,
    gravity and loads (the ``none`` drive). Keywords as :func:`rollout`."""
    return rollout(scene, "step:0V", duration, drive="none", initial_curvature=curvature, **kw)


def rollout_batch(scene: Scene, voltages: Sequence[Union[str, Waveform, callable]], duration: float,
                  drive: Optional[str] = None, drive_params: Optional[dict] = None,
                  initial_curvatures: Union[float, Sequence[float]] = 0.0,
                  sample_interval: Optional[float] = None, nthread: Optional[int] = None,
                  engine: str = "auto", accuracy: Optional[float] = None) -> List[RolloutResult]:
    """Many rollouts of one scene, one per entry of ``voltages`` (and of
    ``initial_curvatures``, 1/m, a scalar for all; a single waveform runs once per initial
    curvature, or once), on MuJoCo's threaded rollout with ``nthread`` threads (1 to the
    number of CPUs; default: one per CPU): the drive compiled into the model (``native``)
    or its moment history as applied forces (``threaded``); ``auto`` takes the first that
    applies. Same results as :func:`rollout` run one by one with that
    engine; raises ParameterError where neither applies. ``accuracy`` (default: the
    scene's own): one model is chosen for the whole batch, for its worst member
    (:mod:`mjeap.accuracy`), and each result carries its own estimated error."""
    from .drives import make_drive
    from . import threaded

    duration = check_positive("duration", duration, "s")
    if np.ndim(initial_curvatures) == 0:
        kappa0 = None
    else:
        kappa0 = list(np.ravel(initial_curvatures)) if np.ndim(initial_curvatures) == 1 else []
    if isinstance(voltages, (str, int, float, Waveform)) or callable(voltages):   # one waveform, not its characters
        voltages = [voltages] * (len(kappa0) if kappa0 else 1)
    voltages = list(voltages)
    if not voltages:
        raise ParameterError("voltages", voltages, "at least one waveform")
    cpus = os.cpu_count() or 1
    nthread = cpus if nthread is None else check_integer("nthread", nthread, 1, cpus,
                                                         f"{cpus} CPUs here: more threads only contend")
    if kappa0 is None:
        kappa0 = [initial_curvatures] * len(voltages)
    elif np.ndim(initial_curvatures) != 1 or len(kappa0) != len(voltages):
        raise ParameterError("initial_curvatures", f"{len(kappa0)} values" if np.ndim(initial_curvatures) == 1 else
                             f"an array of shape {np.shape(initial_curvatures)}",
                             f"one number (1/m) for all or one per voltage ({len(voltages)})")
    kappa0 = [check_initial_curvature(k, scene.layout.length, "initial_curvatures") for k in kappa0]
    target = target_for(scene, accuracy)
    if target is not None:
        from .accuracy import run_at_accuracy
        waves = [_waveform(v, duration) for v in voltages]
        fastest = max(waves, key=lambda w: getattr(w, "max_frequency", 0.0) or 0.0)
        make_drive(drive, scene, **(drive_params or {}))          # the drive's parameters, checked first

        def run(s, interval):
            return rollout_batch(s, voltages, duration, drive=drive, drive_params=drive_params,
                                 initial_curvatures=kappa0, sample_interval=interval, nthread=nthread, engine=engine)
        return run_at_accuracy(scene, run, accuracy=target, duration=duration, wave=fastest,
                               sample_interval=sample_interval)[0]
    drives = [make_drive(drive, scene, **(drive_params or {})) for _ in voltages]
    engine, _ = _choose_engine(engine, scene, drives[0], None)
    if engine == "loop":
        _choose_engine("threaded", scene, drives[0], None)      # raises, with the reason
    dt = scene.timestep
    waves = [_waveform(v, duration) for v in voltages]
    v_steps = [_voltage_steps(w, duration, dt, d) for w, d in zip(waves, drives)]
    sample_steps = _sample_steps(len(v_steps[0]), dt, sample_interval)
    nat = scene.native_model(drives[0]) if engine == "native" else None
    samples = [_Samples(scene.part if nat is None else nat.part, len(sample_steps)) for _ in voltages]
    wall0 = _time.perf_counter()
    if nat is None:
        threaded.run(scene, drives, v_steps, list(kappa0), sample_steps, samples, nthread=nthread)
    else:
        threaded.run_native(scene, nat, drives, v_steps, list(kappa0), sample_steps, samples, nthread=nthread)
    wall = _time.perf_counter() - wall0
    out = []
    for w, d, k0, smp in zip(waves, drives, kappa0, samples):
        meta = _meta(scene, d, w, duration, float(k0), len(v_steps[0]), engine)
        meta.update(wall_time_s=wall, batch=len(voltages), nthread=nthread)
        out.append(smp.result(d, float(k0), meta))
    return out
