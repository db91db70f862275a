"""One run pipeline for a :class:`~mjeap.Scene` and a :class:`~mjeap.System`: a :class:`Job`
(what a front end asks for, checked before any work) goes in through :func:`run`, the one
entry of :func:`mjeap.rollout`, :func:`mjeap.rollout_batch`, :meth:`mjeap.System.rollout` and
the accuracy machinery (whose model runs, companions and pilots come back through it). The
engines step the target, a scene's or a system's alike (:mod:`mjeap.engines`); each run is

* **plan** (:func:`plan`), before any work: the voltage history of every actuator (its
  waveform checked against the step's Nyquist frequency and the drive's safe range, the
  run's length against ``max_steps``), the sample steps, a sample store per actuator part,
  and the meta data (provenance, the engine chosen and why, what the caller describes);
* **run** (:func:`execute`): the engine steps its target (a :class:`mjeap.engines.SceneTarget`
  or :class:`mjeap.engines.SystemTarget`), timed; a :class:`~mjeap.engines.frame.Decided`
  ends it early as a result (the meta says where and why), any other error is recorded in
  the meta and raised once the outputs are written from what was simulated;
* **finish**: the results (the caller's ``finish``, with its error estimate where asked) and
  the outputs, written by one writer for one or many parts (:func:`write_run`).
"""
from __future__ import annotations

import dataclasses
import time as _time
from dataclasses import dataclass
from typing import Any, Callable, List, Optional, Sequence, Tuple, Union

import numpy as np

from ..engines.base import Engine
from ..engines.frame import SCENE_TIMESTEP, Decided, Samples, check_work, sample_steps, voltage_steps
from ..engines.result import RolloutResult
from ..io.outputs import provenance, write_outputs

__all__ = ["Job", "run", "Plan", "plan", "execute", "write_run", "scene_meta"]


@dataclass
class Plan:
    """What a run will do, decided before any work: its ``engine``, ``n_steps``, the steps
    after which it samples, one voltage history (V per step; None: a passive actuator) and
    one sample store per actuator, and its ``meta``."""

    engine: Engine
    n_steps: int
    sample_steps: np.ndarray
    v_steps: List[Optional[np.ndarray]]
    samples: List[Samples]
    meta: dict


def plan(engine: Engine, engine_reason: str, waves: Sequence, drives: Sequence,
         parts: Union[Sequence, Callable[[], Sequence]], duration: float,
         dt: float, sample_interval: Optional[float], *, meta: dict, max_steps: Optional[int] = None,
         remedy: str = SCENE_TIMESTEP, rest: bool = False) -> Plan:
    """The plan of a run of ``duration`` s at steps of ``dt`` s on ``engine`` (chosen for
    ``engine_reason``): per drive (None: passive) its ``waves`` entry's voltage per step
    (None: zero volts, or with ``rest`` the drive's rest voltage), checked (``remedy``: what
    to change at the Nyquist frequency); the sample steps; a store per entry of ``parts`` (or
    of ``parts()``, called once the voltages passed: an engine's part may be a model it
    compiles); ``meta`` after the provenance, with the steps and the engine."""
    n_steps = check_work(duration, dt, max_steps)
    v_steps = [None if d is None else np.full(n_steps, d.rest_voltage()) if (w is None and rest) else
               voltage_steps(w, duration, dt, d, max_steps, remedy) for w, d in zip(waves, drives)]
    steps = sample_steps(n_steps, dt, sample_interval)
    meta = {**provenance(), **meta, "steps": n_steps, "engine": engine.name, "engine_reason": engine_reason}
    parts = parts() if callable(parts) else parts
    return Plan(engine, n_steps, steps, v_steps, [Samples(p, len(steps)) for p in parts], meta)


def execute(meta: dict, run: Callable[[], None], finish: Callable[[Optional[BaseException]], object],
            write: Callable[[object, Optional[BaseException]], None] = lambda result, error: None):
    """Run: ``run()`` timed into ``meta['wall_time_s']``. A :class:`Decided` ends the run
    early as a result (``meta['stopped_early']``, ``meta['steps_run']``); any other error is
    recorded (``meta['error']``) and raised after ``finish(error)`` built the result of what
    was simulated and ``write(result, error)`` wrote it (also on Ctrl-C or SIGTERM).
    Returns ``finish(None)``'s result."""
    error = None
    wall0 = _time.perf_counter()
    try:
        run()
    except Decided as stop:     # a finished run that ends early: its result, not an error
        meta["stopped_early"], meta["steps_run"] = stop.reason, stop.step
    except BaseException as e:  # record what was simulated, then re-raise
        error = e
        raise
    finally:
        meta["wall_time_s"] = _time.perf_counter() - wall0
        if error is not None:
            meta["error"] = f"{type(error).__name__}: {error}"
        result = finish(error)
        write(result, error)
    return result


def write_run(result, target, rrd=None, csv_path=None, error: Optional[BaseException] = None) -> None:
    """The one writer of a run's outputs, for one part or many: with ``rrd`` a Rerun
    recording (:func:`mjeap.io.recording.write_recording` for a scene's
    :class:`RolloutResult`, :func:`mjeap.io.recording.write_system_recording` for a system's),
    with ``csv_path`` the time series as CSV (where samples were taken); each write on its own
    (:func:`mjeap.io.outputs.write_outputs`: ``error``, the run's, stays the one raised)."""
    from ..io import recording
    writers = []
    if rrd is not None:
        record = recording.write_recording if isinstance(result, RolloutResult) else recording.write_system_recording
        writers.append((rrd, lambda: record(rrd, result, target)))
    if csv_path is not None and len(result.time):
        writers.append((csv_path, lambda: result.to_csv(csv_path)))
    if writers:
        write_outputs(writers, error, result)


# ---------------------------------------------------------------- the one entry
@dataclass(frozen=True)
class Job:
    """One run as a front end asks for it, checked before any work (SI). ``target``: a
    :class:`mjeap.Scene` (one run, or with ``batch`` one batched call of every member) or a
    :class:`mjeap.System`; per actuator (a scene's batch: per member) its waveform (None: the
    rest voltage, or a controller's) and drive; ``make_drives(target)`` the drives of the same
    question on another model of it (an accuracy target's variants and companions); the
    initial curvatures (1/m: one per run of a scene; a system's value or values); sampling,
    engine, controller, periodic stop and the outputs; ``accuracy``/``metrics``/
    ``error_model``/``estimate_error``: the run's model chosen and its error estimated
    (:mod:`mjeap.simulation.accuracy`, :mod:`mjeap.simulation.metric_accuracy`);
    ``read_states`` (a scene, sampled every step): read from the states ``mujoco.rollout``
    returns where the native engine can (its tip alone with ``tip_only``)."""

    target: Any
    waves: Tuple
    drives: Tuple
    duration: float
    initial_curvatures: Any = (0.0,)
    make_drives: Optional[Callable[[Any], Tuple]] = None
    sample_interval: Optional[float] = None
    engine: str = "auto"
    batch: bool = False
    nthread: int = 0
    controller: Any = None
    controller_name: Optional[str] = None
    on_sample: Any = None
    max_steps: Optional[int] = None
    progress: Optional[bool] = None
    check_every: int = 100
    stop_when_periodic: Optional[float] = None
    accuracy: Optional[float] = None
    metrics: Optional[Tuple[str, ...]] = None
    error_model: Any = None
    estimate_error: bool = False
    read_states: bool = False
    tip_only: bool = False
    remedy: str = SCENE_TIMESTEP
    rrd: Any = None
    csv_path: Any = None

    def on(self, target, interval: Optional[float], **changes) -> "Job":
        """The same question on another model ``target`` (an accuracy target's variant,
        companion or pilot) sampled every ``interval`` s: its own drives, no target, no
        estimate, no outputs, no progress bar."""
        drives = self.make_drives(target) if self.make_drives is not None else \
            tuple(a.drive for a in target.actuators)
        base = dict(target=target, drives=drives, sample_interval=interval, accuracy=None, metrics=None,
                    error_model=None, estimate_error=False, rrd=None, csv_path=None, progress=False)
        return dataclasses.replace(self, **{**base, **changes})

    def members(self, which: slice) -> "Job":
        """A batch's members ``which`` (a slice) as a batch of their own."""
        make = self.make_drives
        return dataclasses.replace(self, waves=self.waves[which], drives=self.drives[which],
                                   initial_curvatures=self.initial_curvatures[which],
                                   make_drives=None if make is None else (lambda target: make(target)[which]))


def run(job: Job):
    """Run ``job``: its result (a :class:`RolloutResult`; a list of them for a batch; a
    :class:`mjeap.engines.result.SystemResult` for a system; a
    :class:`mjeap.engines.result.TipPath` for a tip read from the states)."""
    if hasattr(job.target, "actuators"):
        return _run_system(job)
    if job.accuracy is not None or job.estimate_error:
        return _at_accuracy(job)
    return _run_batch(job) if job.batch else _run_scene(job)


def scene_meta(scene, drv, wave, duration, initial_curvature) -> dict:
    """What a scene's run describes in its meta (:func:`plan` adds the provenance, steps and
    engine)."""
    return {"actuator": scene.actuator.id, "drive": drv.describe(),
            "voltage": "closed loop" if wave is None else getattr(wave, "text", str(wave)),
            "duration_s": duration, "initial_curvature_per_m": initial_curvature, "scene": scene.summary(),
            "drive_parameters": {k: [v, drv.sources.get(k, "")] for k, v in drv.params.items()}}


def _states_read(job: Job):
    """``job`` (a scene's, sampled every step) read from its states by the native engine:
    the result (a TipPath with ``tip_only``), or None where that does not apply."""
    from ..engines import get_engine
    from ..engines.native import StatesUnread
    scene, (drv,), (wave,), (kappa0,) = job.target, job.drives, job.waves, job.initial_curvatures
    native = get_engine("native")
    if native.states_reason(scene, drv) is not None:
        return None
    t0 = _time.perf_counter()
    p = plan(native, "every step read from mujoco.rollout's states", [wave], [drv], lambda: [native.part(scene, drv)],
             job.duration, scene.timestep, scene.timestep, meta=scene_meta(scene, drv, wave, job.duration, kappa0))
    try:
        tip = native.read_states(scene, drv, p.v_steps[0], kappa0, p.samples[0], tip_only=job.tip_only)
    except StatesUnread:
        return None
    if tip is not None:
        return tip
    p.meta.update(engine="native (every step read from mujoco.rollout's states)", wall_time_s=_time.perf_counter() - t0)
    if scene.choice.buckled:
        p.meta["warnings"] = [scene.buckled_warning()]
    return p.samples[0].result(drv, kappa0, p.meta)


def _run_scene(job: Job):
    """One run of a scene (the plan, the engine's run, the result and its outputs)."""
    from ..engines import choose, run_checked
    from .periodic import PeriodicStop, check_periodic_stop
    if job.read_states:
        out = _states_read(job)
        if out is not None:
            return out
    scene, (drv,), (wave,), (kappa0,) = job.target, job.drives, job.waves, job.initial_curvatures
    eng, engine_reason = choose(job.engine, scene, drv, job.controller)
    p = plan(eng, engine_reason, [wave], [drv], lambda: [eng.part(scene, drv)], job.duration, scene.timestep,
             job.sample_interval, meta=scene_meta(scene, drv, wave, job.duration, kappa0), max_steps=job.max_steps)
    (samples,) = p.samples
    if job.stop_when_periodic is not None:     # on the sampling the run has (its default without one)
        from ..engines.frame import DEFAULT_SAMPLES
        tol, period = check_periodic_stop(job.stop_when_periodic, wave, job.duration,
                                          job.sample_interval or job.duration / DEFAULT_SAMPLES)
        samples.stop = PeriodicStop(period, tol, scene.layout.length)
    if scene.choice.buckled:
        p.meta.setdefault("warnings", []).append(scene.buckled_warning())
    if job.controller is not None:
        p.meta["controller"] = job.controller_name
    return execute(p.meta, lambda: run_checked(eng, scene, [drv], p.v_steps, [kappa0], p.sample_steps, p.samples,
                                               progress=job.progress, check_every=job.check_every,
                                               controller=job.controller, meta=p.meta),
                   lambda error: samples.result(drv, kappa0, p.meta),
                   lambda result, error: write_run(result, scene, job.rrd, job.csv_path, error))


def _run_batch(job: Job):
    """A scene's batch in one batched call of its engine (``mujoco.rollout`` over threads)."""
    from ..engines import choose, run_checked
    scene, drives, waves, kappa0 = job.target, list(job.drives), list(job.waves), list(job.initial_curvatures)
    eng, engine_reason = choose(job.engine, scene, drives[0], None, batched=True)
    engine_meta: dict = {}              # what the engine says of its run (the warp engine's settings)
    p = plan(eng, engine_reason, waves, drives, lambda: [eng.part(scene, drives[0])] * len(waves), job.duration,
             scene.timestep, job.sample_interval, meta={"batch": len(waves), "nthread": job.nthread})
    return execute(p.meta, lambda: run_checked(eng, scene, drives, p.v_steps, kappa0, p.sample_steps, p.samples,
                                               nthread=job.nthread, meta=engine_meta),
                   lambda error: None if error is not None else
                   [smp.result(d, float(k0), {**p.meta, **scene_meta(scene, d, w, job.duration, float(k0)),
                                              **engine_meta})
                    for w, d, k0, smp in zip(waves, drives, kappa0, p.samples)])


def _run_system(job: Job):
    """A run of a system, stepped by its engine (:class:`mjeap.engines.system_frame.SystemRun`),
    its error estimated against the system at half the step where asked."""
    from ..engines import choose_system
    from ..engines.system_frame import SystemRun
    system = job.target
    eng, engine_reason = choose_system(job.engine, system, job.controller, job.on_sample)
    p = plan(eng, engine_reason, job.waves, job.drives, system.parts, job.duration, system.timestep,
             job.sample_interval,
             meta=system.describe_run(job.waves, job.controller, job.controller_name, job.duration),
             remedy=job.remedy, rest=True)
    frame = SystemRun(system, p, job.initial_curvatures, on_sample=job.on_sample, controller=job.controller,
                      ctrl_name=job.controller_name)

    def finish(error):
        result = frame.result()
        if job.estimate_error and error is None:
            from .accuracy import estimate_system_error
            estimate_system_error(system, result, lambda companion, interval: run(job.on(companion, interval)))
        return result
    return execute(p.meta, frame.run, finish, lambda result, error: write_run(result, system, job.rrd, error=error))


def _at_accuracy(job: Job):
    """A scene's run at an accuracy target (or, without one, with its error estimated): the
    runs of :mod:`mjeap.simulation.accuracy` (a target on metrics: of
    :mod:`mjeap.simulation.metric_accuracy`, each member of a batch on its own), each back
    through :func:`run`; the outputs hold the chosen run, whose meta says how it was chosen."""
    from . import accuracy as acc
    from ..engines.frame import DEFAULT_SAMPLES
    from .periodic import MIN_SAMPLES_PER_PERIOD
    scene, wave, duration = job.target, job.waves[0], job.duration
    if job.batch and job.metrics:       # each member's own model for its answer
        return [run(dataclasses.replace(job.members(slice(i, i + 1)), batch=False)) for i in range(len(job.waves))]
    if job.batch:
        fastest = max(job.waves, key=lambda w: getattr(w, "max_frequency", 0.0) or 0.0)

        def run_batch(s, interval, members=slice(None)):
            return run(job.on(s, interval).members(members))
        return acc.run_at_accuracy(scene, run_batch, accuracy=job.accuracy, duration=duration, wave=fastest,
                                   sample_interval=job.sample_interval,
                                   pilot_run=(lambda s, i: run_batch(s, i, slice(1))) if len(job.waves) > 1
                                   else None)[0]
    states = job.controller is None and job.engine in ("auto", "native") and job.stop_when_periodic is None and \
        job.max_steps is None

    def one(s, interval, every_step: bool = False, tip_only: bool = False):
        # each run stops on its own where its sampling allows (the estimate compares the runs
        # over the instants they share); a companion sampled coarser runs to the end
        stop = job.stop_when_periodic if job.stop_when_periodic is not None and \
            (interval or duration / DEFAULT_SAMPLES) * wave.frequency <= 1.0 / MIN_SAMPLES_PER_PERIOD else None
        return run(job.on(s, interval, stop_when_periodic=stop, read_states=every_step and states, tip_only=tip_only))

    if job.accuracy is not None and job.metrics:
        from .metric_accuracy import run_metrics_at_accuracy
        result, chosen, _ = run_metrics_at_accuracy(scene, one, metrics=job.metrics, accuracy=job.accuracy,
                                                    duration=duration, drive=job.drives[0], wave=wave,
                                                    sample_interval=job.sample_interval, error_model=job.error_model)
    elif job.accuracy is None:
        chosen = scene
        result = one(scene, job.sample_interval)
        acc.estimate_error(scene, one, result, duration=duration, sample_interval=job.sample_interval)
    else:
        result, chosen, _ = acc.run_at_accuracy(scene, one, accuracy=job.accuracy, duration=duration, wave=wave,
                                                sample_interval=job.sample_interval, error_model=job.error_model)
    write_run(result, chosen, job.rrd, job.csv_path)
    return result
