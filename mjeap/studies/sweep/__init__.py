"""Parameter sweeps: a design of points, each a rollout reduced to named metrics, run on
local processes or on Dask, streamed to CSV as they complete and resumable.

A point is a dict of :data:`PARAMETERS` (scene, waveform and rollout settings, SI) plus
``drive.NAME`` entries for drive parameters and ``actuator.X`` entries for the actuator's
geometry and materials (:mod:`mjeap.model.variants` builds the point's actuator from the base one).
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

The package's three modules, each on the one below: :mod:`mjeap.studies.sweep.points` (the points:
their parameters, designs, keys and the checks before any point runs),
:mod:`mjeap.studies.sweep.metrics` (the metrics and their registry) and :mod:`mjeap.studies.sweep.runner`
(one point's row, many points to CSV, the executors). Their public names are here.
"""
from .points import (MAX_POINTS, PARAMETERS, SWEEP_WAVEFORMS, check_design_size, check_settings, grid, point_id,
                     random_design, settings)
from .points import point_scene, wave_text  # a point's Scene and waveform text, as the runner makes them
from .metrics import (END_METRICS, METRIC_UNITS, METRICS, OWN_SCENE_METRICS, STATIC_METRICS, STEP_METRICS,
                      check_metric_settings, metric_value, register_metric)
from .runner import (EXECUTORS, SweepSummary, evaluate, read_results, run_sweep, stop_workers, worker_signals)

__all__ = ["point_scene", "wave_text", "EXECUTORS", "MAX_POINTS", "PARAMETERS", "SWEEP_WAVEFORMS", "METRICS",
           "METRIC_UNITS", "STATIC_METRICS",
           "END_METRICS", "STEP_METRICS", "OWN_SCENE_METRICS", "SweepSummary", "check_design_size",
           "check_metric_settings", "check_settings", "evaluate", "grid", "metric_value", "point_id",
           "random_design", "read_results", "register_metric", "run_sweep", "settings", "stop_workers",
           "worker_signals"]
