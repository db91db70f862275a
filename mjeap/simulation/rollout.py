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

from . import pipeline
from .accuracy import GRID_SAMPLES, target_for
from ..engines import ENGINES
from .periodic import check_periodic_stop
from ..engines.frame import (DEFAULT_SAMPLES, MAX_INITIAL_BEND, MAX_STEPS, check_controller, check_initial_curvature,
                             check_sampling, check_work, one_voltage, to_waveform)
from ..engines.result import RolloutResult
from ..errors import ParameterError, check_integer, check_positive
from ..io.outputs import check_outputs, guarded, write_outputs
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


def _inputs(args: dict) -> list:
    """A rollout's input files (its actuator file, its waveform's CSV): no output may be one."""
    v = args.get("voltage")
    return input_files([args["scene"]], v if isinstance(v, (list, tuple)) else [v])


@guarded("rrd", "csv_path", inputs=_inputs)
def rollout(scene: Union[Scene, str, Path], voltage: Union[str, Waveform, callable], duration: float, *,
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
        from .metric_scales import check_metrics
        metrics = check_metrics(metrics)
    if error_model is not None and target is None:      # its values are checked by the choice, before any run
        raise ParameterError("error_model", error_model, "None without an accuracy target (it chooses the model for "
                             "one)")
    if stop_when_periodic is not None:         # checked before any work, on the sampling the run will have
        check_stop(stop_when_periodic, wave, duration, sample_interval, target is not None or estimate_error)
    if target is not None or estimate_error:
        scene.part.check_derivable()
    params = dict(drv.params)
    return pipeline.run(pipeline.Job(
        scene, (wave,), (drv,), duration, (initial_curvature,), make_drives=lambda s: (type(drv)(s, **params),),
        sample_interval=sample_interval, engine=engine, controller=controller, controller_name=ctrl_name,
        max_steps=max_steps, progress=progress, check_every=check_every, stop_when_periodic=stop_when_periodic,
        accuracy=target, metrics=metrics, error_model=error_model, estimate_error=estimate_error, rrd=rrd,
        csv_path=csv_path))


def free_vibration(scene: Union[Scene, str, Path], curvature: float, duration: float, **kw) -> RolloutResult:
    """Release the beam, bent to a uniform arc of ``curvature`` (1/m), with no drive holding
    it, and follow it for ``duration`` s: a free vibration under its elasticity, damping,
    gravity and loads (the ``none`` drive). Keywords as :func:`rollout`."""
    return rollout(scene, "step:0V", duration, drive="none", initial_curvature=curvature, **kw)


def rollout_batch(scene: Union[Scene, str, Path], voltages: Sequence[Union[str, Waveform, callable]], duration: float,
                  *,
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
        from .metric_scales import check_metrics
        metrics = check_metrics(metrics)
    if target is not None:
        scene.part.check_derivable()
    waves = tuple(to_waveform(v, duration) for v in voltages)
    params = drive_params or {}
    drives = tuple(make_drive(drive, scene, **params) for _ in voltages)     # the drive's parameters, checked first
    return pipeline.run(pipeline.Job(
        scene, waves, drives, duration, tuple(kappa0),
        make_drives=lambda s: tuple(make_drive(drive, s, **params) for _ in voltages), sample_interval=sample_interval,
        engine=engine, batch=True, nthread=nthread, accuracy=target, metrics=metrics if target is not None else None))
