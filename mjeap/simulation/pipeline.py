"""One run pipeline for a :class:`~mjeap.Scene` and a :class:`~mjeap.System`: plan, run,
finish. :func:`mjeap.rollout`, :func:`mjeap.rollout_batch` and :meth:`mjeap.System.rollout`
are front ends of it; what differs between them is the target and its stepping.

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

import time as _time
from dataclasses import dataclass
from typing import Callable, List, Optional, Sequence, Union

import numpy as np

from ..engines.base import Engine
from ..engines.frame import SCENE_TIMESTEP, Decided, Samples, check_work, sample_steps, voltage_steps
from ..engines.result import RolloutResult
from ..io.outputs import provenance, write_outputs

__all__ = ["Plan", "plan", "execute", "write_run"]


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
         dt: float, sample_interval: Optional[float], meta: dict, *, max_steps: Optional[int] = None,
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
