"""Running a sweep: :func:`evaluate` runs one point into its row, :func:`run_sweep` many,
on local processes or on Dask, streamed to CSV as they complete and resumable
(:func:`read_results` reads the CSV back).

Every finished point is appended to the CSV (and flushed) at once, keyed by a hash of its
parameters (:func:`mjeap.studies.sweep.points.point_id`), so an interrupted sweep keeps what finished
and a rerun with the same file skips it. A point that fails (bad input, divergence) records
its error in the ``error`` column instead of stopping the sweep.

Executors: ``"processes"`` (``concurrent.futures``, the default), ``"serial"``, and
``"dask"``: a ``distributed.Client`` on ``scheduler`` (an address such as
``tcp://host:8786``) or, without one, on a ``LocalCluster`` of ``workers`` processes. The
same code runs on all three; Dask is the optional ``sweep`` extra.
"""
from __future__ import annotations

import json
import os
import sys
import time
import traceback
import warnings
from collections import OrderedDict, deque
from concurrent.futures import FIRST_COMPLETED, wait
from concurrent.futures.process import BrokenProcessPool
from dataclasses import dataclass
from pathlib import Path
from typing import List, Optional, Sequence

from ...errors import DivergenceError, MjeapError, ParameterError, UnknownNameError, check_integer, sigterm_as_interrupt
from ...io.outputs import check_outputs, hold, output_kind
from ..store import RowFile, drop_torn_row, read_study_csv
from ...model.laminate import FieldWarning
from . import metrics as _metrics      # its registries, read where a point runs
from .points import (PARAMETERS, check_design_size, check_names, check_settings, point_duration, point_id, point_scene,
                     resolve_actuators, settings, wave_text)
from .metrics import check_metric_settings, metric_value

EXECUTORS = ("processes", "serial", "dask")


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
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", FieldWarning)
            try:
                _evaluate_into(row, p, metrics, rrd_dir, error_model)
            finally:
                _sort_warnings(row, caught)
    except MjeapError as e:
        row["error"] = f"{type(e).__name__}: {e}"
        if "returns" in metrics and isinstance(e, DivergenceError):
            row["returns"] = False
    except Exception as e:  # a bug or a library error: keep the sweep going, keep the trace
        row["error"] = f"{type(e).__name__}: {e} | {traceback.format_exc(limit=3)!r}"
    row["wall_s"] = time.perf_counter() - t0
    return row


def _sort_warnings(row: dict, caught: list) -> None:
    """A point's field warnings go into its row (``_field``, not a CSV column: the sweep says
    them once, :func:`_say_fields`); every other warning is shown as it came."""
    fields = [str(w.message) for w in caught if issubclass(w.category, FieldWarning)]
    row["_field"] = fields[0] if fields else ""
    for w in caught:
        if not issubclass(w.category, FieldWarning):
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)


def _say_fields(past: List[tuple], done: int, columns: Sequence[str]) -> None:
    """One :class:`~mjeap.model.laminate.FieldWarning` for the points whose drive takes a piezo
    layer past its material's limits, unless the sweep reads ``max_field`` (then its column
    says it, point by point)."""
    if past and not set(_metrics.FIELD_METRICS) & set(columns):
        warnings.warn(f"{len(past)} of the {done} points run drive a layer past its limit (point {past[0][0]}: "
                      f"{past[0][1]}); add max_field to the metrics for each point's field", FieldWarning,
                      stacklevel=5)


def _evaluate_into(row: dict, p: dict, metrics: Sequence[str], rrd_dir, error_model) -> None:
    """The work of :func:`evaluate`: the point's scene, rollout and metrics into ``row``."""
    unknown = [m for m in metrics if m not in _metrics.METRICS]
    if unknown:
        raise UnknownNameError("metric", unknown[0], _metrics.METRICS)
    scene = point_scene(p)
    for m in metrics:                   # the scene's own metrics first: no rollout for them
        if m in _metrics.STATIC_METRICS:
            row[m] = metric_value(m, _metrics.METRICS[m](None, p, scene))
    dynamic = [m for m in metrics if m not in _metrics.STATIC_METRICS]
    r = _run_point(p, scene, dynamic, rrd_dir, row["point_id"], error_model) if dynamic or rrd_dir else None
    if r is not None and "accuracy" in r.meta:
        e = r.meta["accuracy"].get("error_model")
        row["_error_model"] = None if e is None else (e["spatial_a"], e["temporal_b_per_s"])
    for m in dynamic:
        row[m] = metric_value(m, _metrics.METRICS[m](r, p, scene))
    for m, est in (r.meta.get("accuracy", {}).get("metrics", {}) if r is not None else {}).items():
        row[f"estimated_error.{m}"] = est["estimated_error"]


def _run_point(p: dict, scene, metrics: Sequence[str], rrd_dir, pid: str, error_model=None):
    """The rollout of a point, sampled as its metrics need: every step (every k steps beyond
    MAX_STEP_SAMPLES) for STEP_METRICS, sparsely where every metric reads only the run's end
    (END_METRICS: the scene holds the end), else the rollout's default."""
    from ...simulation.rollout import rollout
    wave = wave_text(p)
    duration = point_duration(p)
    drive_params = {k[6:]: v for k, v in p.items() if k.startswith("drive.")}
    rrd = None if rrd_dir is None else Path(rrd_dir) / f"point-{pid}.rrd"
    stop = None if p["stop_when_periodic"] in (None, "") else float(p["stop_when_periodic"])
    at_target = scene.accuracy is not None
    interval = None
    if any(m in _metrics.STEP_METRICS for m in metrics):
        dt = scene.timestep
        interval = dt * max(1, -(-int(round(duration / dt)) // _metrics.MAX_STEP_SAMPLES))
    elif metrics and all(m in _metrics.END_METRICS for m in metrics) and not at_target and stop is None and rrd is None:
        interval = duration / 8.0
    targeted = targeted_metrics(metrics) if at_target else ()
    return rollout(scene, wave, duration, drive_params=drive_params, initial_curvature=float(p["initial_curvature"]),
                   progress=False, rrd=rrd, engine=p["engine"], sample_interval=interval,
                   error_model=error_model if at_target else None, stop_when_periodic=stop,
                   metrics=targeted or None)


def targeted_metrics(metrics: Sequence[str]) -> tuple:
    """The metrics an accuracy target applies to (:mod:`mjeap.simulation.metric_accuracy`):
    all the point's rollout metrics where each is one it answers (bookkeeping columns
    aside), else none (the target is then on the trajectory)."""
    from ...simulation.metric_scales import BOOKKEEPING, answerable
    return tuple(m for m in metrics if m not in BOOKKEEPING) if answerable(metrics) else ()


def _at_target(points, base) -> bool:
    return any({**PARAMETERS, **(base or {}), **p}["accuracy"] not in (None, "") for p in points or [{}])


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


def read_results(path) -> List[dict]:
    """Rows of a sweep CSV (strings, as given: the quote that keeps a spreadsheet from
    running a text cell as a formula is dropped; a BOM, ';' or tab delimiters of a file
    re-saved by a spreadsheet are read, :mod:`mjeap.io.csvio`; the header names the columns
    and must name ``point_id``, else a ParameterError names the file)."""
    if Path(path).is_file() and Path(path).stat().st_size == 0:
        return []
    return read_study_csv(path)[1]


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
    """The accuracy family of a job: its parameters less LOAD_SIZE; None without a target,
    or with one on its metrics (:func:`targeted_metrics`: no pilots to share; each point
    starts from the same first model, and on the stability map the family's error model
    chose the same models as the points' own, while the family phase before the rest held
    2 workers back: 21.7-22.5 against 23.7 points/s)."""
    p = {**PARAMETERS, **(job[2] or {}), **job[0]}
    if p["accuracy"] in (None, "") or targeted_metrics([m for m in job[1] if m not in _metrics.STATIC_METRICS]):
        return None
    return json.dumps({k: v for k, v in p.items() if k not in LOAD_SIZE}, sort_keys=True, default=float)


def _with_shared_error_models(executor: str, workers: int, scheduler: Optional[str], jobs):
    """Yield finished rows. At an accuracy target the first point of each family (the same
    question but for LOAD_SIZE) runs first with its own pilots; the family's other points
    start from its error model (a, b) instead of pilots of their own, their error still
    measured on each (:func:`mjeap.simulation.accuracy.run_at_accuracy`). Points of a
    family whose first point failed run their own pilots. Points without a target, or with
    one on their metrics (no pilots to share, :func:`_family`), run beside the first points."""
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
    pools = _Pools(workers) if executor == "processes" else None     # one pool for both phases
    try:
        for row in _submit_all(executor, workers, scheduler, first, pools):
            if row["point_id"] in lead_family:
                models[lead_family[row["point_id"]]] = row.get("_error_model")
            yield row
        yield from _submit_all(executor, workers, scheduler,
                               [tuple(job[:4]) + (models.get(key),) for key, job in rest], pools)
    except BaseException:       # Ctrl-C, SIGTERM, the caller closing: stop the workers now
        if pools is not None:
            pools.stop()
        raise
    finally:
        if pools is not None:
            pools.close()


def _submit_all(executor: str, workers: int, scheduler: Optional[str], jobs, pools: "Optional[_Pools]" = None):
    """Yield finished rows as they complete (``pools``: the worker processes to run them in,
    kept by the caller)."""
    if executor == "serial":
        from threadpoolctl import threadpool_limits
        with threadpool_limits(1):
            for args in jobs:
                yield evaluate(*args)
        return
    if executor == "processes":
        yield from _run_processes(list(jobs), workers, pools)
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


class _SceneQueue:
    """Jobs grouped by their point's scene (:func:`mjeap.studies.sweep.points.scene_key`), in their
    order: a worker that just finished a point takes another of the same scene (built and
    kept in that process, :meth:`mjeap.Scene.shared`), else the first of a scene no running
    point holds, else the first (with one point in flight per worker, the job submitted
    after a point finishes goes to the worker that ran it)."""

    def __init__(self, jobs):
        from .points import scene_key
        self.groups: "OrderedDict[str, deque]" = OrderedDict()
        for job in jobs:
            self.groups.setdefault(scene_key({**PARAMETERS, **(job[2] or {}), **job[0]}), deque()).append(job)

    def __bool__(self) -> bool:
        return bool(self.groups)

    def take(self, prefer: Optional[str], busy) -> tuple:
        """(scene key, job): of scene ``prefer`` where one is left, else as the class says."""
        key = prefer if prefer in self.groups else next((k for k in self.groups if k not in busy),
                                                         next(iter(self.groups)))
        group = self.groups[key]
        job = group.popleft()
        if not group:
            del self.groups[key]
        return key, job

    def put_back(self, key: str, job) -> None:
        self.groups.setdefault(key, deque()).appendleft(job)
        self.groups.move_to_end(key, last=False)


def _new_pool(n: int):
    """A pool of ``n`` worker processes: forked where the platform can (fast start, works from
    any __main__), spawned elsewhere."""
    from concurrent.futures import ProcessPoolExecutor
    import multiprocessing as mp
    ctx = mp.get_context("fork" if "fork" in mp.get_all_start_methods() else "spawn")
    return ProcessPoolExecutor(max_workers=n, mp_context=ctx, initializer=_worker_init)


class _Pools:
    """A sweep's worker processes, kept from one phase to the next (a family's first points,
    then the rest: what the processes built, scenes and analyses, stays there); a new pool
    after a worker died."""

    def __init__(self, workers: int):
        self.workers, self.ex = workers, None

    def get(self):
        if self.ex is None:
            self.ex = _new_pool(self.workers)
        return self.ex

    def drop(self) -> None:
        """Leave a broken pool (its points in flight are run again by the caller)."""
        if self.ex is not None:
            self.ex.shutdown(wait=False, cancel_futures=True)
            self.ex = None

    def stop(self) -> None:
        """Stop the workers now (Ctrl-C, SIGTERM, the caller closing)."""
        if self.ex is not None:
            stop_workers(self.ex)
            self.ex = None

    def close(self) -> None:
        if self.ex is not None:
            self.ex.shutdown(wait=True, cancel_futures=True)
            self.ex = None


def _run_processes(jobs: list, workers: int, pools: Optional[_Pools] = None):
    """Local worker processes, at most ``workers`` points in flight, each worker kept on the
    points of one scene while there are any (:class:`_SceneQueue`). A worker that dies
    breaks the pool: the points then in flight are run again one by one in a fresh
    single-worker pool (the one that kills its worker again is recorded as failed), and the
    sweep goes on in a fresh pool. Ctrl-C or SIGTERM cancels what has not started."""
    own = pools is None
    pools = pools or _Pools(workers)
    try:
        yield from _run_in(pools, _SceneQueue(jobs), workers)
    finally:
        if own:
            pools.close()


def _run_in(pools: _Pools, pending: _SceneQueue, workers: int):
    """:func:`_run_processes`'s loop, in ``pools``."""
    while pending:
        suspects, ex, broken = [], pools.get(), False
        inflight, freed = {}, []            # freed: the scenes of the workers that just finished
        try:
            while pending or inflight:
                while pending and len(inflight) < workers:
                    key, args = pending.take(freed.pop(0) if freed else None, {k for _, k in inflight.values()})
                    try:                    # the pool may break between a finished point and this submit
                        fut = ex.submit(evaluate, *args)
                    except BrokenProcessPool:
                        pending.put_back(key, args)
                        broken = True
                        break
                    inflight[fut] = args, key
                freed.clear()
                done, _ = wait(inflight, return_when=FIRST_COMPLETED)
                for fut in done:
                    args, key = inflight.pop(fut)
                    freed.append(key)
                    try:
                        yield fut.result()
                    except BrokenProcessPool:
                        suspects.append(args)
                if suspects or broken:
                    suspects += [args for args, _ in inflight.values()]
                    break
        except BaseException:               # Ctrl-C, SIGTERM, the caller closing: stop the workers now
            pools.stop()
            raise
        if suspects or broken:
            pools.drop()
        for args in suspects:                      # one by one: find the point that kills
            alone = _new_pool(1)
            try:
                yield alone.submit(evaluate, *args).result()
            except BrokenProcessPool:
                point = args[0]
                yield {"point_id": point_id(point, args[2], args[1]), **point, "error": f"WorkerDied: {WORKER_DIED}",
                       "wall_s": 0.0, "settings": json.dumps(settings(args[2], args[1]), sort_keys=True, default=float)}
            finally:
                alone.shutdown(wait=False, cancel_futures=True)


def run_sweep(points: Sequence[dict], path, *, metrics: Sequence[str] = ("peak_to_peak", "returns"),
              base: Optional[dict] = None, executor: str = "processes", workers: int = 2,
              scheduler: Optional[str] = None, record: Sequence[int] = (), rrd_dir=None,
              progress: Optional[bool] = None, share_error_models: bool = True) -> SweepSummary:
    """Evaluate ``points`` and stream one CSV row per finished point to ``path``. Points
    already in the file (same ``point_id``) are skipped. ``record``: indices of points
    that also write a recording to ``rrd_dir`` (default: next to the CSV).
    ``share_error_models`` (at an accuracy target on the trajectory): points differing only
    in LOAD_SIZE start from their family's first point's error model instead of pilots of
    their own (:func:`_with_shared_error_models`); each point's error is measured on it
    either way."""
    path = Path(path)
    if executor not in EXECUTORS:
        raise ParameterError("executor", executor, f"one of {', '.join(EXECUTORS)}")
    if int(workers) < 1:
        raise ParameterError("workers", workers, "a positive number of worker processes")
    unknown = [m for m in metrics if m not in _metrics.METRICS]
    if unknown:
        raise UnknownNameError("metric", unknown[0], _metrics.METRICS)
    points = list(points)
    check_design_size(len(points), "points")
    points, base = resolve_actuators(points, base)      # the study's edge: each actuator read once
    for p in points:
        check_names(p)
    if isinstance(record, (str, bytes, int)):
        raise ParameterError("record", record, "a list of point indices, e.g. [0, 5]")
    n = len(points)
    record = [check_integer("record", i, 0, n - 1, f"indices of the sweep's {n} point{'s' * (n != 1)}")
              for i in record]
    check_settings(points, base)
    check_metric_settings(points, base, metrics)
    # every output before any work: the CSV, and the recordings it names itself (point-ID.rrd), none a
    # link or one of the sweep's actuator files
    folder = Path(rrd_dir) if rrd_dir is not None else path.parent / (path.stem + "-rrd")
    if record and rrd_dir is None and os.path.islink(folder):
        raise ParameterError("record", str(folder), "a folder for the recordings that is not a symbolic link",
                             "mjeap names it itself (next to the CSV): a planted link is never followed")
    recordings = {f"record (point {i})": folder / f"point-{point_id(points[i], base, metrics)}.rrd" for i in record}
    check_outputs(inputs=sweep_inputs(points, base), picked=recordings, path=path, **recordings)
    # the CSV's lock for the whole sweep (PATH.lock): a second sweep on it, or a run writing it,
    # is refused (it would compute every point twice and duplicate rows)
    with hold(path, "path", holder="mjeap sweep"):
        return _run_locked(points, path, metrics, base, executor=executor, workers=workers, scheduler=scheduler,
                           record=record, rrd_dir=rrd_dir, progress=progress, share=bool(share_error_models))


def sweep_inputs(points: Sequence[dict], base: Optional[dict] = None) -> list:
    """The files a study reads (the actuator files its points and settings name), as
    (name, path) pairs: none may be one of its outputs (:func:`mjeap.io.outputs.check_inputs`)."""
    from ...model.actuator_file import is_actuator_file
    files = dict.fromkeys(str(p["actuator"]) for p in [*points, base or {}]
                          if isinstance(p.get("actuator"), (str, Path)) and is_actuator_file(p["actuator"]))
    return [("actuator file", f) for f in files]


def _run_locked(points, path, metrics, base, *, executor, workers, scheduler, record, rrd_dir, progress, share=True):
    stream = output_kind(path) == "stream"             # /dev/stdout, a FIFO: written through, never read back
    if not stream:
        drop_torn_row(path)
    done_ids, header, delimiter = set(), None, ","
    # resumed: read as users' CSVs are, appended in its form
    if not stream and path.exists() and path.stat().st_size > 0:
        header, rows, delimiter = read_study_csv(path)
        done_ids = {row["point_id"] for row in rows}
    rrd_dir = str(rrd_dir or path.parent / (path.stem + "-rrd"))
    record = set(int(i) for i in record)
    jobs = [(p, tuple(metrics), base, rrd_dir if i in record else None) for i, p in enumerate(points)
            if point_id(p, base, metrics) not in done_ids]
    skipped = len(points) - len(jobs)
    estimates = [f"estimated_error.{m}" for m in targeted_metrics(metrics)] if _at_target(points, base) else []
    columns = ["point_id", *sorted({k for p in points for k in p}), *metrics, *estimates, "error", "wall_s", "settings"]
    new_file = stream or not path.exists() or path.stat().st_size == 0
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
        return _write_rows(path, columns, new_file, executor=executor, workers=workers, scheduler=scheduler, jobs=jobs,
                           bar=bar, skipped=skipped, t0=t0, share=share, delimiter=delimiter)


def _write_rows(path, columns, new_file, *, executor, workers, scheduler, jobs, bar, skipped, t0, share=True,
                delimiter=","):
    failed, done, past = 0, 0, []
    out = RowFile(path, delimiter)
    try:
        if new_file:
            out.write(columns, 0)
        rows = _with_shared_error_models if share else _submit_all
        for row in rows(executor, int(workers), scheduler, jobs):
            out.write([row.get(k, "") for k in columns], done + skipped)
            done += 1
            failed += bool(row["error"])
            if row.get("_field"):
                past.append((row["point_id"], row["_field"]))
            if bar is not None:
                bar.update(1)
    finally:
        out.close()
        if bar is not None:
            bar.close()
    _say_fields(past, done, columns)
    return SweepSummary(path, done, skipped, failed, time.perf_counter() - t0)
