"""Parameter sweeps: a design of points, each a rollout reduced to named metrics, run on
local processes or on Dask, streamed to CSV as they complete and resumable.

A point is a dict of :data:`PARAMETERS` (scene, waveform and rollout settings, SI) plus
``drive.NAME`` entries for drive parameters. :func:`grid` and :func:`random_design` make
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
import itertools
import json
import os
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
from .errors import DivergenceError, MjeapError, ParameterError, UnknownNameError, check_integer, sigterm_as_interrupt
from .io.outputs import hold

EXECUTORS = ("processes", "serial", "dask")

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


METRICS: Dict[str, Callable] = {
    "estimated_error": metric_estimated_error, "stopped_early": metric_stopped_early,
    "peak_to_peak": metric_peak_to_peak, "returns": metric_returns, "settling_time": metric_settling_time,
    "max_stress_proxy": metric_max_stress_proxy, "max_tip_deflection": metric_max_tip_deflection,
}


def register_metric(name: str, fn: Callable) -> None:
    """Add ``fn(result, point, scene) -> number`` as metric ``name`` (in every worker
    process, register it at import time of a module the workers import)."""
    METRICS[name] = fn


# ---------------------------------------------------------------- designs
def _check_names(names: Iterable[str]) -> None:
    for n in names:
        if n not in PARAMETERS and not n.startswith("drive."):
            raise ParameterError("sweep parameter", n, f"one of {', '.join(PARAMETERS)} or drive.NAME")


def grid(**values: Sequence) -> List[dict]:
    """Full factorial design: every combination of the given values."""
    _check_names(values)
    names = list(values)
    return [dict(zip(names, combo)) for combo in itertools.product(*(list(values[n]) for n in names))]


def random_design(n: int, seed: int = 0, **ranges) -> List[dict]:
    """``n`` points, each parameter drawn uniformly from a (low, high) range or a list of
    choices, with numpy's generator seeded by ``seed``."""
    _check_names(ranges)
    if int(n) < 1:
        raise ParameterError("n", n, "a positive number of points")
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
    return hashlib.sha1(json.dumps(key, sort_keys=True, default=float).encode()).hexdigest()[:12]


def check_settings(points: Sequence[dict], base: Optional[dict]) -> None:
    """Every name in ``base`` is a sweep parameter, and every ``drive.NAME`` (in base or the
    points) a parameter of the actuator's drive; else UnknownNameError with the closest."""
    from .drives import default_drive_name, get_drive_class
    base = base or {}
    for n in base:
        if n not in PARAMETERS and not n.startswith("drive."):
            raise UnknownNameError("fixed sweep setting (--set / base)", n,
                                   [*PARAMETERS, "drive.NAME"])
    for p in points:
        full = {**PARAMETERS, **base, **p}
        if full["stop_when_periodic"] not in (None, ""):      # refused once, not in every row
            _check_stop(full)
        names = [k[6:] for k in full if k.startswith("drive.")]
        if not names:
            continue
        act = str(full["actuator"])
        try:
            cls = get_drive_class(default_drive_name(act))
        except MjeapError:
            continue              # a user actuator or an unknown one: the point reports it
        known = list(cls.PARAMETERS.get(act, cls.GENERIC_PARAMETERS)) + list(cls.extra_parameters(None))
        for n in names:
            if n not in known:
                raise UnknownNameError(f"{cls.name} drive parameter (drive.NAME)", n, known)


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
    from .model.discretize import Payload
    from .simulation.rollout import rollout
    from .simulation.scene import Scene

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
        payload = None
        if p["payload_mass"]:
            pos = p["payload_position"]
            if pos is None:
                raise ParameterError("payload_position", None, "a position in m when payload_mass > 0")
            payload = Payload(float(p["payload_mass"]), float(pos))
        scene = Scene(p["actuator"], representation=p["representation"], segments=int(p["segments"]),
                      orientation=p["orientation"], payload=payload, damping_ratio=p["damping_ratio"],
                      accuracy=None if p["accuracy"] in (None, "") else float(p["accuracy"]))
        wave = _wave_text(p)
        drive_params = {k[6:]: v for k, v in p.items() if k.startswith("drive.")}
        rrd = None if rrd_dir is None else Path(rrd_dir) / f"point-{row['point_id']}.rrd"
        r = rollout(scene, wave, _duration(p), drive_params=drive_params, initial_curvature=float(p["initial_curvature"]),
                    progress=False, rrd=rrd, engine=p["engine"],
                    error_model=error_model if scene.accuracy is not None else None,
                    stop_when_periodic=None if p["stop_when_periodic"] in (None, "") else
                    float(p["stop_when_periodic"]))
        if "accuracy" in r.meta:
            e = r.meta["accuracy"].get("error_model")
            row["_error_model"] = None if e is None else (e["spatial_a"], e["temporal_b_per_s"])
        for m in metrics:
            row[m] = METRICS[m](r, p, scene)
    except MjeapError as e:
        row["error"] = f"{type(e).__name__}: {e}"
        if "returns" in metrics and isinstance(e, DivergenceError):
            row["returns"] = False
    except Exception as e:  # a bug or a library error: keep the sweep going, keep the trace
        row["error"] = f"{type(e).__name__}: {e} | {traceback.format_exc(limit=3)!r}"
    row["wall_s"] = time.perf_counter() - t0
    return row


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


def read_results(path) -> List[dict]:
    """Rows of a sweep CSV (strings, as given: the quote that keeps a spreadsheet from
    running a text cell as a formula is dropped, :mod:`mjeap.io.csvio`; the header names the
    columns)."""
    with open(path, newline="") as fh:
        return [{plain_cell(k): plain_cell(v) for k, v in row.items()} for row in csv.DictReader(fh)]


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
    for p in points:
        _check_names(p)
    if isinstance(record, (str, bytes, int)):
        raise ParameterError("record", record, "a list of point indices, e.g. [0, 5]")
    n = len(points)
    record = [check_integer("record", i, 0, n - 1, f"indices of the sweep's {n} point{'s' * (n != 1)}")
              for i in record]
    check_settings(points, base)
    path.parent.mkdir(parents=True, exist_ok=True)
    # the CSV's lock for the whole sweep (PATH.lock): a second sweep on it, or a run writing it,
    # is refused (it would compute every point twice and duplicate rows)
    with hold(path, "path", holder="mjeap sweep"):
        return _run_locked(points, path, metrics, base, executor, workers, scheduler, record, rrd_dir, progress,
                           bool(share_error_models))


def _run_locked(points, path, metrics, base, executor, workers, scheduler, record, rrd_dir, progress, share=True):
    _drop_torn_row(path)
    done_ids = set()
    if path.exists() and path.stat().st_size > 0:
        done_ids = {row["point_id"] for row in read_results(path)}
    rrd_dir = str(rrd_dir or path.parent / (path.stem + "-rrd"))
    record = set(int(i) for i in record)
    jobs = [(p, tuple(metrics), base, rrd_dir if i in record else None) for i, p in enumerate(points)
            if point_id(p, base, metrics) not in done_ids]
    skipped = len(points) - len(jobs)
    columns = ["point_id", *sorted({k for p in points for k in p}), *metrics, "error", "wall_s", "settings"]
    path.parent.mkdir(parents=True, exist_ok=True)
    new_file = not path.exists() or path.stat().st_size == 0
    if not new_file:
        with open(path, newline="") as fh:
            header = [plain_cell(c) for c in next(csv.reader(fh))]
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
        return _write_rows(path, columns, new_file, executor, workers, scheduler, jobs, bar, skipped, t0, share)


def _write_rows(path, columns, new_file, executor, workers, scheduler, jobs, bar, skipped, t0, share=True):
    failed, done = 0, 0
    with open(path, "a", newline="") as fh:
        w = csvio.writer(fh)
        if new_file:
            w.writerow(columns)
            fh.flush()
        try:
            rows = _with_shared_error_models if share else _submit_all
            for row in rows(executor, int(workers), scheduler, jobs):
                w.writerow([row.get(k, "") for k in columns])
                fh.flush()
                os.fsync(fh.fileno())
                done += 1
                failed += bool(row["error"])
                if bar is not None:
                    bar.update(1)
        finally:
            if bar is not None:
                bar.close()
    return SweepSummary(path, done, skipped, failed, time.perf_counter() - t0)
