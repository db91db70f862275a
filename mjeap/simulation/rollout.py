"""Headless rollouts: a scene, a drive and a voltage waveform, on one of the engines of
:mod:`mjeap.engines` (``auto``: native where the drive has a native form, else threaded
where it is open-loop, else the Python loop; all give the same trajectory, tested to
round-off). The waveform is evaluated for all steps up front (vectorised). :func:`rollout`
and :func:`rollout_batch` are front ends of the one run pipeline,
:mod:`mjeap.simulation.pipeline` (as is :meth:`mjeap.System.rollout`).
"""
from __future__ import annotations

import os
from pathlib import Path
from typing import List, Optional, Sequence, Union

import numpy as np

from .accuracy import GRID_SAMPLES, target_for
from ..engines import ENGINES, choose, run_checked
from .periodic import MIN_SAMPLES_PER_PERIOD, PeriodicStop, check_periodic_stop
from ..engines.frame import (DEFAULT_SAMPLES, MAX_INITIAL_BEND, MAX_STEPS, check_controller, check_initial_curvature,
                             check_sampling, check_work, one_voltage, to_waveform)
from ..engines.result import RolloutResult
from ..errors import ParameterError, check_integer, check_positive
from ..io.outputs import check_outputs, guarded, write_outputs
from .pipeline import execute, plan, write_run
from .scene import Scene, as_scene, input_files
from ..drives.waveforms import Waveform

__all__ = ["rollout", "rollout_batch", "free_vibration", "RolloutResult", "ENGINES", "MAX_STEPS", "DEFAULT_SAMPLES",
           "MAX_INITIAL_BEND", "check_work", "check_sampling", "check_outputs", "write_outputs", "one_voltage",
           "check_initial_curvature"]


def check_stop(stop_when_periodic, wave, duration: float, sample_interval: Optional[float] = None,
               at_accuracy: bool = False):
    """:func:`mjeap.simulation.periodic.check_periodic_stop` on the sampling the rollout will
    have (``sample_interval``, else its default: DEFAULT_SAMPLES over the run, GRID_SAMPLES at
    an accuracy target or with an error estimate): (tolerance, period s)."""
    return check_periodic_stop(stop_when_periodic, wave, duration, sample_interval or
                               duration / (GRID_SAMPLES if at_accuracy else DEFAULT_SAMPLES))


def _meta(scene, drv, wave, duration, initial_curvature) -> dict:
    """What a scene's run describes in its meta (:func:`mjeap.simulation.pipeline.plan` adds
    the provenance, steps and engine)."""
    return {"actuator": scene.actuator.id, "drive": drv.describe(),
            "voltage": "closed loop" if wave is None else getattr(wave, "text", str(wave)),
            "duration_s": duration, "initial_curvature_per_m": initial_curvature, "scene": scene.summary(),
            "drive_parameters": {k: [v, drv.sources.get(k, "")] for k, v in drv.params.items()}}


def _inputs(args: dict) -> list:
    """A rollout's input files (its actuator file, its waveform's CSV): no output may be one."""
    v = args.get("voltage")
    return input_files([args["scene"]], v if isinstance(v, (list, tuple)) else [v])


@guarded("rrd", "csv_path", inputs=_inputs)
def rollout(scene: Union[Scene, str, Path],  voltage: Union[str, Waveform, callable], duration: float,
            drive: Union[str, "object", None] = None, drive_params: Optional[dict] = None,
            initial_curvature: float = 0.0, rrd: Union[str, Path, None] = None,
            csv_path: Union[str, Path, None] = None, sample_interval: Optional[float] = None,
            progress: Union[bool, str, None] = None, check_every: int = 100, controller=None,
            engine: str = "auto", max_steps: Optional[int] = None, accuracy: Optional[float] = None,
            estimate_error: bool = False, error_model=None,
            stop_when_periodic: Optional[float] = None, metrics: Optional[Sequence[str]] = None) -> RolloutResult:
    """Run ``scene`` (a Scene, or a catalog id or actuator file's path: its default Scene,
    :func:`mjeap.simulation.scene.as_scene`) driven by ``drive`` (name, instance or None for the actuator's own)
    with ``voltage`` (waveform text, :class:`Waveform` or callable v(t)) for ``duration`` s,
    or closed loop under ``controller`` (``voltage`` then None): a callable
    ``controller(t, scene) -> V``, a plain function or an object, with optional ``reset``,
    ``interval``, ``name`` and ``signals`` (the one contract of rollout and System.rollout,
    :func:`mjeap.engines.frame.check_controller`).

    The beam starts at rest as a uniform arc of ``initial_curvature`` (1/m). Returns SI
    arrays sampled every ``sample_interval`` s (default: at most 5001 evenly spaced samples, the
    initial state included; the scene is left in the final state). With
    ``rrd`` a Rerun recording is written (also when the run fails or is stopped by Ctrl-C or
    SIGTERM: it then ends with the error), with ``csv_path`` the time series as CSV; a
    second writer of either is refused (:func:`mjeap.io.outputs.guarded`). A diverging run raises
    :class:`DivergenceError` naming the step, the drive and the timestep. ``engine``:
    'loop', 'threaded' (open-loop drives only, see the module) or 'auto'. Refused before
    any work: a duration shorter than a step, more than ``max_steps`` steps (default
    MAX_STEPS), a waveform above the step's Nyquist frequency.

    ``accuracy`` (default: the scene's own, if any): the largest error of the tip curvature
    relative to its swing; the run then chooses its segments, integrator and timestep
    (:mod:`mjeap.simulation.accuracy`; ``scene`` is left as it was) and ``meta['accuracy']`` carries the
    model and its estimated error. Without one the scene's model runs; ``estimate_error``
    then estimates its error with a coarser companion run (about 0.35 x the cost).
    ``error_model`` (with a target): the constants (a, b) of a similar question's run, its
    ``meta['accuracy']['error_model']``, in place of this run's pilots
    (:func:`mjeap.simulation.accuracy.run_at_accuracy`). ``metrics`` (with a target): the
    target applies to these metrics of the run (peak_to_peak, returns, ...), each relative
    to its own scale, not to the trajectory; slow questions then take steps far beyond the
    modes' resolution (:mod:`mjeap.simulation.metric_accuracy`).

    ``progress``: None (default: a bar on a terminal once the run has lasted 2 s), True, False
    or ``"lines"`` (one line per 10 % of the simulated time, for logs; :mod:`mjeap.engines.progress`).

    ``stop_when_periodic`` (relative tolerance, periodic waveforms): the run stops at the
    first period boundary, from the third, where its last period repeats the one before
    within the tolerance and the shrinking change still to come stays within it (tip
    curvature of its range, centreline of the length; :mod:`mjeap.simulation.periodic`); ``meta['stopped_early']`` then says where and why and
    the result ends there (at an accuracy target every run of the choice stops on its own).
    """
    from ..drives import make_drive

    scene = as_scene(scene)
    duration = check_positive("duration", duration, "s")
    ctrl_name = None if controller is None else check_controller(controller, voltage)
    initial_curvature = check_initial_curvature(initial_curvature, scene.layout.length)
    wave = None if controller is not None else to_waveform(voltage, duration)
    drv = drive if (drive is not None and not isinstance(drive, str)) else \
        make_drive(drive, scene, **(drive_params or {}))
    target = target_for(scene, accuracy)
    if metrics is not None:
        from .metric_accuracy import check_metrics
        metrics = check_metrics(metrics)
    if error_model is not None:         # its values are checked by run_at_accuracy, before any run
        if target is None:
            raise ParameterError("error_model", error_model, "None without an accuracy target (it chooses the model "
                                 "for one)")
    if stop_when_periodic is not None:         # checked before any work, on the sampling the run will have
        stop_tol, period = check_stop(stop_when_periodic, wave, duration, sample_interval,
                                      target is not None or estimate_error)
    if target is not None or estimate_error:
        scene.part.check_derivable()
        return _rollout_at_accuracy(scene, voltage, duration, drv, initial_curvature, rrd, csv_path, sample_interval,
                                    check_every, controller, engine, max_steps, target, wave, error_model,
                                    stop_when_periodic, metrics)
    eng, engine_reason = choose(engine, scene, drv, controller)
    p = plan(eng, engine_reason, [wave], [drv], lambda: [eng.part(scene, drv)], duration, scene.timestep,
             sample_interval, _meta(scene, drv, wave, duration, initial_curvature), max_steps=max_steps)
    (samples,) = p.samples
    if stop_when_periodic is not None:
        samples.stop = PeriodicStop(period, stop_tol, scene.layout.length)
    if scene.choice.buckled:
        p.meta.setdefault("warnings", []).append(scene.buckled_warning())
    if controller is not None:
        p.meta["controller"] = ctrl_name
    return execute(p.meta, lambda: run_checked(eng, scene, [drv], p.v_steps, [initial_curvature], p.sample_steps,
                                               p.samples, progress=progress, check_every=check_every,
                                               controller=controller, meta=p.meta),
                   lambda error: samples.result(drv, initial_curvature, p.meta),
                   lambda result, error: write_run(result, scene, rrd, csv_path, error))


def _rollout_at_accuracy(scene, voltage, duration, drv, initial_curvature, rrd, csv_path, sample_interval,
                         check_every, controller, engine, max_steps, target, wave, error_model=None,
                         stop_when_periodic=None, metrics=None) -> RolloutResult:
    """:func:`rollout` at an accuracy target (or, without one, with its error estimated): the
    runs of :mod:`mjeap.simulation.accuracy`, each with the drive ``drv`` names and its parameters;
    the outputs hold the chosen run, whose meta says how it was chosen."""
    from . import accuracy as acc
    params = dict(drv.params)

    def run(s, interval):
        # each run stops on its own where its sampling allows (the estimate compares the runs
        # over the instants they share); a companion sampled coarser runs to the end
        stop = stop_when_periodic if stop_when_periodic is not None and \
            (interval or duration / DEFAULT_SAMPLES) * wave.frequency <= 1.0 / MIN_SAMPLES_PER_PERIOD else None
        return rollout(s, voltage, duration, drive=type(drv)(s, **params),
                       initial_curvature=initial_curvature, sample_interval=interval, progress=False,
                       check_every=check_every, controller=controller, engine=engine, max_steps=max_steps,
                       stop_when_periodic=stop)

    if target is not None and metrics:
        from .metric_accuracy import run_from_states, run_metrics_at_accuracy
        every_step = None       # each run sampled every step, read from its states where that applies
        if controller is None and engine in ("auto", "native") and stop_when_periodic is None and max_steps is None:
            def every_step(s, tip_only=False):
                return run_from_states(s, type(drv)(s, **params), wave, duration, initial_curvature, tip_only)
        result, chosen, _ = run_metrics_at_accuracy(scene, run, metrics=metrics, accuracy=target, duration=duration,
                                                    drive=drv, wave=wave, sample_interval=sample_interval,
                                                    error_model=error_model, every_step=every_step)
    elif target is None:
        chosen = scene
        result = run(scene, sample_interval)
        acc.estimate_error(scene, run, result, duration=duration, sample_interval=sample_interval)
    else:
        result, chosen, _ = acc.run_at_accuracy(scene, run, accuracy=target, duration=duration, wave=wave,
                                                sample_interval=sample_interval, error_model=error_model)
    write_run(result, chosen, rrd, csv_path)
    return result


def free_vibration(scene: Union[Scene, str, Path], curvature: float, duration: float, **kw) -> RolloutResult:
    """Release the beam, bent to a uniform arc of ``curvature`` (1/m), with no drive holding
    it, and follow it for ``duration`` s: a free vibration under its elasticity, damping,
    gravity and loads (the ``none`` drive). Keywords as :func:`rollout`."""
    return rollout(scene, "step:0V", duration, drive="none", initial_curvature=curvature, **kw)


def rollout_batch(scene: Union[Scene, str, Path], voltages: Sequence[Union[str, Waveform, callable]], duration: float,
                  drive: Optional[str] = None, drive_params: Optional[dict] = None,
                  initial_curvatures: Union[float, Sequence[float]] = 0.0,
                  sample_interval: Optional[float] = None, nthread: Optional[int] = None,
                  engine: str = "auto", accuracy: Optional[float] = None,
                  metrics: Optional[Sequence[str]] = None) -> List[RolloutResult]:
    """Many rollouts of one scene, one per entry of ``voltages`` (and of
    ``initial_curvatures``, 1/m, a scalar for all; a single waveform runs once per initial
    curvature, or once), on MuJoCo's threaded rollout with ``nthread`` threads (1 to the
    number of CPUs; default: one per CPU): the drive compiled into the model (``native``)
    or its moment history as applied forces (``threaded``); ``auto`` takes the first that
    applies. Same results as :func:`rollout` run one by one with that
    engine; raises ParameterError where neither applies. ``accuracy`` (default: the
    scene's own): one model is chosen for the whole batch, from the pilots of its first
    member and then for its worst member (:mod:`mjeap.simulation.accuracy`: each member's
    error is measured on it, segments and step), and each result carries its own estimated
    error. ``metrics`` (with a target): the target is on these metrics of each member, each
    member choosing its own model as :func:`rollout` does (one by one)."""
    from ..drives import make_drive
    scene = as_scene(scene)
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
    if metrics is not None:
        from .metric_accuracy import check_metrics
        metrics = check_metrics(metrics)
    if target is not None and metrics is not None:       # each member's own model for its answer
        return [rollout(scene, v, duration, drive=drive, drive_params=drive_params, initial_curvature=k,
                        sample_interval=sample_interval, progress=False, engine=engine, accuracy=target,
                        metrics=metrics) for v, k in zip(voltages, kappa0)]
    if target is not None:
        from .accuracy import run_at_accuracy
        scene.part.check_derivable()
        waves = [to_waveform(v, duration) for v in voltages]
        fastest = max(waves, key=lambda w: getattr(w, "max_frequency", 0.0) or 0.0)
        make_drive(drive, scene, **(drive_params or {}))          # the drive's parameters, checked first

        def run(s, interval, members=slice(None)):
            return rollout_batch(s, voltages[members], duration, drive=drive, drive_params=drive_params,
                                 initial_curvatures=kappa0[members], sample_interval=interval, nthread=nthread,
                                 engine=engine)
        return run_at_accuracy(scene, run, accuracy=target, duration=duration, wave=fastest,
                               sample_interval=sample_interval,
                               pilot_run=(lambda s, i: run(s, i, slice(1))) if len(voltages) > 1 else None)[0]
    drives = [make_drive(drive, scene, **(drive_params or {})) for _ in voltages]
    eng, engine_reason = choose(engine, scene, drives[0], None, batched=True)
    waves = [to_waveform(v, duration) for v in voltages]
    engine_meta: dict = {}              # what the engine says of its run (the warp engine's settings)
    p = plan(eng, engine_reason, waves, drives, lambda: [eng.part(scene, drives[0])] * len(voltages), duration,
             scene.timestep, sample_interval, {"batch": len(voltages), "nthread": nthread})
    return execute(p.meta, lambda: run_checked(eng, scene, drives, p.v_steps, list(kappa0), p.sample_steps,
                                               p.samples, nthread=nthread, meta=engine_meta),
                   lambda error: None if error is not None else
                   [smp.result(d, float(k0), {**p.meta, **_meta(scene, d, w, duration, float(k0)), **engine_meta})
                    for w, d, k0, smp in zip(waves, drives, kappa0, p.samples)])
