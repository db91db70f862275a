"""Design optimisation: maximise or minimise one metric of :mod:`mjeap.studies.sweep` over bounded
actuator, drive and payload parameters, subject to constraints on other metrics, with
scipy's optimisers (``mjeap optimize``, :func:`optimize`).

An evaluation is one sweep point (:func:`mjeap.studies.sweep.evaluate`): a Scene of the point's
actuator (:mod:`mjeap.model.variants` builds it from the base actuator and the ``actuator.X``
values) and, only where a metric needs one, a rollout; ``first_frequency`` and ``mass``
read the linearised model alone. Every evaluation is appended to a CSV in the sweep's own
format as it finishes; a rerun with the same CSV reads it as a cache (the same points get
the same numbers, so the optimiser retraces its path and ends at the same optimum without
simulating them again).

The search runs on the box scaled to [0, 1]^n (x = low + u (high - low)), the objective
divided by its magnitude at the box's centre and each constraint by its bound:

* ``slsqp`` (default): scipy's SLSQP, bounded and constrained, its gradients by forward
  differences of ``fd_step`` in u (one evaluation per parameter and iteration), started from
  the box's centre and ``starts - 1`` seeded points (numpy's generator seeded by ``seed``);
* ``differential-evolution``: scipy's differential_evolution (a global search, Latin
  hypercube start, seeded) under the same constraints, then polished by SLSQP from its best.

The optimum is the best feasible evaluation (every constraint within ``feasibility`` of its
bound, relative); a constraint is *active* there where its metric lies within ``active`` of
its bound (relative). ``max_evaluations`` bounds the points simulated or read back, over all
starts together.

At the optimum, ``result.json`` reports the objective's sensitivity to each active bound and
constraint: the Lagrange multipliers of the Karush-Kuhn-Tucker conditions, grad f = sum_k
mu_k grad c_k + sum_i nu_i e_i over the active constraints c_k and the variables i at a
bound, solved by least squares from forward differences at the optimum (the same steps as
SLSQP's gradients, so mostly read back): mu_k = d f* / d b_k, the objective's change per unit
change of constraint k's bound, and nu_i = d f* / d (bound of variable i).

``pareto=(M1, M2)`` traces the front between two metrics (each maximised, or minimised with a
``min:`` prefix) by the epsilon-constraint method: the best M1, the best M2, and the best M1
with M2 held at ``pareto_points - 2`` levels between them (each started from the previous
optimum), under the same constraints and budget; it is written to ``pareto.csv`` and, with
the ``report`` extra, ``pareto.png``. With the ``report`` extra every optimisation draws
``optimize.png``: the objective and each constraint's metric over each variable, swept through
the optimum (``slice_points`` evaluations each, the other variables held) over every
evaluation of the search, the optimum, the constraints' bounds and the active bounds marked.
"""
from __future__ import annotations

import dataclasses
import json
import math
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Dict, List, Mapping, Optional, Sequence, Tuple

import numpy as np

from .constraints import Constraint, parse_constraint
from .optimize_figures import draw, write_front
from .parameters import VARIABLE, to_value
from .search import Box, Evaluations, Goal, SearchSettings, clean, number, search, sensitivities, slices, trace_front
from ..errors import MjeapError, ParameterError, UnknownNameError, check_integer, check_range, sigterm_as_interrupt

__all__ = ["optimize", "Constraint", "OptimizeResult", "parse_constraint", "parse_bounds", "METHODS"]

METHODS = ("slsqp", "differential-evolution")
#: the files an optimisation writes in its folder
RESULT, EVALUATIONS, OPTIMUM = "result.json", "evaluations.csv", "optimum.toml"
FIGURE, PARETO, PARETO_FIGURE = "optimize.png", "pareto.csv", "pareto.png"
#: the actuator file of an optimisation that found no feasible point: its least infeasible point,
#: never named optimum; BASE: an Actuator object given as the base, written for the evaluations
LEAST_INFEASIBLE, BASE = "least-infeasible.toml", "base.toml"


def parse_bounds(name: str, value, actuator=None) -> Tuple[float, float]:
    """(low, high) SI of a varied parameter from (low, high) numbers or texts with units, or
    text ``"LOW:HIGH"`` (``"5mm:15mm"``): low < high, both in the parameter's range
    (:func:`mjeap.variants.check_design_value` for actuator.X, the drive's RANGES for
    drive.NAME, :data:`VARIABLE` for the others). Raises ParameterError naming it."""
    from ..model import variants
    accepted = f"{name}=LOW:HIGH with LOW < HIGH (SI, or with a unit: 5mm:15mm)"
    if isinstance(value, str):
        parts = value.split(":")
        if len(parts) != 2 or not all(p.strip() for p in parts):
            raise ParameterError("--vary", f"{name}={value}", accepted)
        value = tuple(p.strip() for p in parts)
    try:
        lo, hi = value
    except (TypeError, ValueError):
        raise ParameterError("--vary", f"{name}={value!r}", accepted) from None
    lo, hi = (to_value(name, v, actuator) for v in (lo, hi))
    for v in (lo, hi):
        if isinstance(v, str) or isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
            raise ParameterError("--vary", f"{name}={value!r}", accepted, f"{v!r} is not a finite number")
    lo, hi = float(lo), float(hi)
    if not lo < hi:
        raise ParameterError("--vary", f"{name}={lo:g}:{hi:g}", accepted)
    if variants.is_design_parameter(name):
        for v in (lo, hi):
            variants.check_design_value(name, v, actuator)
    elif name.startswith("drive."):
        from ..drives import default_drive_name, get_drive_class
        cls = get_drive_class(default_drive_name(variants.get_base(actuator)))
        known = list(cls.parameter_units())
        if name[6:] not in known:
            raise UnknownNameError(f"{cls.name} drive parameter (drive.NAME)", name[6:], known)
        r_lo, r_hi = cls.RANGES.get(name[6:], (-math.inf, math.inf))
        if not (r_lo < lo and hi < r_hi):
            raise ParameterError(name, f"{lo:g}:{hi:g}", f"bounds within the {cls.name} drive's range "
                                 f"({r_lo:g}, {r_hi:g}) {cls.parameter_units()[name[6:]]}")
    elif name in VARIABLE:
        unit, r_lo, r_hi, lo_open = VARIABLE[name]
        if not ((r_lo < lo if lo_open else r_lo <= lo) and hi <= r_hi):
            raise ParameterError(name, f"{lo:g}:{hi:g}", f"bounds in {'(' if lo_open else '['}{r_lo:g}, {r_hi:g}] "
                                 f"{unit}")
    else:
        raise UnknownNameError("optimisation parameter (--vary)", name,
                               [*VARIABLE, "actuator.NAME", "drive.NAME"] + (
                                   variants.design_parameter_names(actuator) if actuator is not None else []))
    return lo, hi


@dataclass
class OptimizeResult:
    """An optimisation's answer: the optimum (SI), its metrics, the constraints there, how
    many evaluations it took and where its files are."""

    optimum: Dict[str, float]
    metrics: Dict[str, object]
    objective: Dict[str, object]
    constraints: List[dict]
    evaluations: int
    evaluations_run: int
    evaluations_cached: int
    success: bool
    message: str
    method: str
    wall_s: float
    runs: List[dict] = field(default_factory=list)
    actuator: object = None                 # the optimum's Actuator (the least infeasible point's: feasible False)
    files: Dict[str, str] = field(default_factory=dict)
    #: the objective's sensitivity to each active bound and constraint (module text)
    sensitivities: List[dict] = field(default_factory=list)
    #: the traced front (``pareto``): one dict per point, the two metrics and the variables
    pareto: Optional[List[dict]] = None
    #: every evaluation: (point, {metric: value}, error) for the figures
    evaluated: List[tuple] = field(default_factory=list, repr=False)
    #: each variable swept through the optimum, the others held: name -> evaluations as above
    slices: Dict[str, List[tuple]] = field(default_factory=dict, repr=False)
    feasible: bool = True                   # False: no point met the constraints (the least infeasible is reported)

    def as_dict(self) -> dict:
        d = {k: getattr(self, k) for k in ("optimum", "metrics", "objective", "constraints", "sensitivities",
                                          "evaluations", "evaluations_run", "evaluations_cached", "success",
                                          "message", "method", "wall_s", "runs", "files")}
        if self.pareto is not None:
            d["pareto"] = self.pareto
        d["wall_s"] = round(self.wall_s, 3)
        return d


def _base_actuator(actuator, folder: Optional[Path]):
    """The study's ``actuator`` setting, resolved once at its edge (an
    :class:`~mjeap.model.catalog.ActuatorRef`: its points never read a file again): a catalog
    id or a file's path as given; an Actuator object is written as an actuator file (in the
    output folder, else a temporary one: the record of the base its points name) and resolved
    from it. Returns (the setting, the temporary folder or None)."""
    from ..model.actuator import Actuator
    from ..model.catalog import resolve_actuator
    if isinstance(actuator, Path):
        return resolve_actuator(str(actuator)), None
    if isinstance(actuator, Actuator):
        from ..model.actuator_file import actuator_toml, write_actuator
        tmp = None
        if folder is None:
            tmp = tempfile.TemporaryDirectory(prefix="mjeap-optimize-")
            folder = Path(tmp.name)
        path = folder / BASE
        text = actuator_toml(actuator)
        if path.is_file() and path.read_text(encoding="utf-8", errors="replace") != text:
            raise ParameterError("--out", str(folder), f"a folder whose {BASE} is this base actuator, or none",
                                 f"{path} exists and holds another file: refused, not replaced; choose another "
                                 "folder or remove it")
        if not path.is_file():
            write_actuator(actuator, path)
        return resolve_actuator(str(path)), tmp
    if not isinstance(actuator, str):
        raise ParameterError("actuator", actuator, "a catalog id, an actuator file's path or an Actuator")
    return resolve_actuator(actuator), None


def _wave_settings(voltage) -> dict:
    """The sweep's waveform settings of a waveform text (step, square, sine or triangle)."""
    from ..drives.waveforms import parse_waveform
    from .sweep import SWEEP_WAVEFORMS
    w = parse_waveform(voltage)
    if w.kind not in SWEEP_WAVEFORMS or w.phase or w.delay or (w.kind == "square" and w.duty != 0.5):
        raise ParameterError("voltage", voltage, f"a waveform of {', '.join(SWEEP_WAVEFORMS)}: "
                             "KIND:AMPLITUDE[@FREQUENCY][,offset=OFFSET] (no duty, phase or delay)")
    out = {"waveform": w.kind, "amplitude": float(w.amplitude), "offset": float(w.offset)}
    if w.kind != "step":
        out["frequency"] = float(w.frequency)
    return out


def optimize(actuator, vary: Mapping[str, object], *, maximize: Optional[str] = None, minimize: Optional[str] = None,
             subject_to: Sequence = (), voltage: Optional[str] = None, duration: Optional[float] = None,
             base: Optional[dict] = None, metrics: Sequence[str] = (), method: str = "slsqp", starts: int = 3,
             seed: int = 0, max_evaluations: int = 400, out=None, progress: Optional[bool] = None,
             tol: float = 1e-7, fd_step: float = 1e-3, feasibility: float = 1e-6, active: float = 1e-3,
             maxiter: int = 100, popsize: int = 10, de_tol: float = 1e-2, pareto=None,
             pareto_points: int = 7, slice_points: int = 11) -> OptimizeResult:
    """Maximise (``maximize``) or minimise (``minimize``) one metric of :mod:`mjeap.studies.sweep`
    over the box ``vary`` (name -> (low, high), SI numbers or texts with units, or
    ``"LOW:HIGH"``; names ``actuator.X`` of :mod:`mjeap.model.variants`, ``drive.NAME``,
    ``payload_mass``, ``payload_position``, ``amplitude``, ``offset``, ``frequency``, ...),
    subject to ``subject_to`` (``"first_frequency>=800"``, :func:`parse_constraint`).

    ``actuator``: the base actuator (catalog id, file path or Actuator); ``voltage``: the
    waveform (``step:200V``, ``sine:50V@100Hz,offset=100V``) and ``duration`` (s) of the
    rollouts the metrics need; ``base``: other fixed sweep settings (``segments``,
    ``orientation``, ``payload_mass``, ...); ``metrics``: more metrics to record at every
    evaluation. ``method``: ``"slsqp"`` (``starts`` starts: the box's centre and seeded
    points) or ``"differential-evolution"`` (module text). ``out``: a folder for
    ``result.json``, ``evaluations.csv`` (the evaluations, read back as a cache by a rerun)
    and ``optimum.toml`` (the optimum's actuator file); paths checked before any work.
    Everything is checked before any work (ParameterError naming the parameter and range).

    Tuning: ``max_evaluations`` (all starts together), ``tol`` (SLSQP's ftol on the scaled
    objective), ``fd_step`` (the finite-difference step, a fraction of each range),
    ``maxiter`` (SLSQP iterations per start), ``popsize`` and ``de_tol`` (differential
    evolution), ``feasibility`` and ``active`` (relative tolerances: a constraint met, a
    constraint active). Evaluations run one at a time in this process.

    ``pareto``: ``"M1,M2"`` or (M1, M2), each maximised or, prefixed ``min:``, minimised,
    instead of ``maximize``/``minimize``: the front between them at ``pareto_points`` points
    (module text), in ``pareto.csv`` and ``pareto.png``; the optimum reported is the best M1.
    With the ``report`` extra (matplotlib) ``optimize.png`` shows the search (module text).
    ``slice_points``: evaluations of each variable swept through the optimum, the others
    held (the figure's lines; 0: none), within the budget and written as the others are."""
    t0 = time.perf_counter()
    # ---- the question and the search's settings, checked before any work
    front = None if pareto is None else _parse_pareto(pareto)
    if front is not None:
        if maximize is not None or minimize is not None:
            raise ParameterError("pareto", pareto, "either a front (--pareto M1,M2) or one metric to maximise or "
                                 "minimise, not both")
        pareto_points = check_integer("pareto_points", pareto_points, 3, 100)
        (maximize, minimize) = (front[0][0], None) if front[0][1] > 0 else (None, front[0][0])
    goal = _goal(maximize, minimize, subject_to, feasibility, active)
    wanted = _wanted(goal, metrics, front)
    settings = _search_settings(method=method, starts=starts, seed=seed, tol=tol, fd_step=fd_step, maxiter=maxiter,
                                popsize=popsize, de_tol=de_tol, max_evaluations=max_evaluations)
    slice_points = check_integer("slice_points", slice_points, 0, 1000)
    if not isinstance(vary, Mapping) or not vary:
        raise ParameterError("vary", vary, "at least one parameter with its bounds: {'actuator.length': "
                             "('5mm', '15mm')} (--vary NAME=LOW:HIGH)")
    folder = Path(out) if out is not None else None
    files = _files(folder, actuator, front)
    base_name, tmp = _base_actuator(actuator, folder)
    try:
        box, fixed = _box(base_name, vary, base, voltage, duration, goal, wanted)
        columns = ["point_id", *box.names, *wanted, "error", "wall_s", "settings"]
        study = _Study(box, goal, settings, wanted, fixed, columns, base_name, front, pareto_points, slice_points)
        # ---- the run
        from threadpoolctl import threadpool_limits
        with sigterm_as_interrupt(), threadpool_limits(1):
            if folder is None:
                return _run(study, cached={}, writer=None, progress=progress, t0=t0, files=files)
            result = _run_stored(study, files, progress=progress, t0=t0)
            _write_result(result, study, files)
            return result
    finally:
        if tmp is not None:
            tmp.cleanup()


@dataclass(frozen=True)
class _Study:
    """An optimisation checked and ready to run: its box, goal and search settings, the
    metrics each point reads, the points' fixed settings, the CSV's columns, the base
    actuator's name, the Pareto front asked for (and its points) and the slices' points."""

    box: Box
    goal: Goal
    settings: SearchSettings
    wanted: List[str]
    fixed: dict
    columns: List[str]
    base_name: str
    front: Optional[tuple]
    pareto_points: int
    slice_points: int


def _goal(maximize, minimize, subject_to, feasibility: float, active: float) -> Goal:
    """The question: one metric maximised or minimised, the constraints, the tolerances."""
    from .sweep import METRICS
    if (maximize is None) == (minimize is None):
        raise ParameterError("maximize/minimize", f"maximize={maximize!r}, minimize={minimize!r}",
                             "exactly one metric to maximise or to minimise")
    objective, sign = (maximize, 1.0) if maximize is not None else (minimize, -1.0)
    if objective not in METRICS:
        raise UnknownNameError("metric (--maximize/--minimize)", str(objective), METRICS)
    constraints = tuple(parse_constraint(c) for c in ([subject_to] if isinstance(subject_to, str) else subject_to))
    return Goal(objective, sign, constraints, check_range("feasibility", feasibility, 0.0, 0.1),
                check_range("active", active, 0.0, 1.0))


def _wanted(goal: Goal, metrics, front) -> List[str]:
    """Every metric a point reads: the objective, the constrained ones, ``metrics``, the
    front's second."""
    from .sweep import METRICS
    extra = list(metrics.split(",")) if isinstance(metrics, str) else list(metrics)
    for m in extra:
        if m not in METRICS:
            raise UnknownNameError("metric (--metrics)", m, METRICS)
    return list(dict.fromkeys([goal.objective, *(c.metric for c in goal.constraints), *extra,
                               *([] if front is None else [front[1][0]])]))


def _search_settings(*, method, starts, seed, tol, fd_step, maxiter, popsize, de_tol, max_evaluations) -> SearchSettings:
    """The search's settings, each checked against its range."""
    method = str(method).strip().lower().replace("_", "-")
    if method not in METHODS:
        raise ParameterError("method", method, f"one of {', '.join(METHODS)}")
    return SearchSettings(method=method, starts=check_integer("starts", starts, 1, 100),
                          seed=check_integer("seed", seed, 0),
                          tol=check_range("tol", tol, 0.0, 0.1, lo_open=True),
                          fd_step=check_range("fd_step", fd_step, 0.0, 0.1, "(of the box)", lo_open=True),
                          maxiter=check_integer("maxiter", maxiter, 1),
                          popsize=check_integer("popsize", popsize, 4, 1000),
                          de_tol=check_range("de_tol", de_tol, 0.0, 1.0, lo_open=True),
                          max_evaluations=check_integer("max_evaluations", max_evaluations, 2))


def _files(folder: Optional[Path], actuator, front) -> Dict[str, Path]:
    """The files an optimisation writes in ``folder`` (none without one), checked before any
    work: names mjeap picks, regular files or none, never a link, never the base actuator's
    file."""
    from ..io.outputs import check_outputs
    from ..model.actuator_file import is_actuator_file
    if folder is None:
        return {}
    if folder.exists() and not folder.is_dir():
        raise ParameterError("--out", str(folder), "a folder for result.json, evaluations.csv and optimum.toml",
                             "it is a file")
    files = {k: folder / v for k, v in (("result", RESULT), ("evaluations", EVALUATIONS), ("optimum", OPTIMUM),
                                        ("figure", FIGURE), ("least_infeasible", LEAST_INFEASIBLE))}
    if front is not None:
        files.update(pareto=folder / PARETO, pareto_figure=folder / PARETO_FIGURE)
    named = {f"--out ({p.name})": p for p in files.values()}
    if not isinstance(actuator, (str, Path)):
        named[f"--out ({BASE})"] = folder / BASE
    check_outputs(inputs=[("base actuator file", actuator if isinstance(actuator, (str, Path)) and
                           is_actuator_file(actuator) else None)], picked=named, **named)
    return files


def _box(base_name: str, vary: Mapping, base: Optional[dict], voltage, duration, goal: Goal,
         wanted: List[str]) -> Tuple[Box, dict]:
    """The box (its bounds checked, its corners built and checked as sweep points) and the
    points' fixed settings (``base``, the waveform of ``voltage``, ``duration``)."""
    from ..model import variants
    from .sweep import STATIC_METRICS, check_metric_settings, check_settings
    from .sweep.points import check_names
    fixed = dict(base or {})
    if "actuator" in fixed:
        raise ParameterError("base", "actuator", "the actuator as optimize's first argument, not in base/--set")
    check_names(fixed)
    fixed["actuator"] = base_name
    names = sorted(vary)
    bounds = [parse_bounds(n, vary[n], base_name) for n in names]
    clash = [n for n in names if n in fixed]
    if clash:
        raise ParameterError("--set", clash[0], "a setting that is not also varied (--vary)")
    needs_run = any(m not in STATIC_METRICS for m in wanted)
    if voltage is not None:
        fixed.update(_wave_settings(voltage))
    elif needs_run and "waveform" not in fixed:
        raise ParameterError("voltage", None, "a waveform for the rollouts of "
                             f"{', '.join(m for m in wanted if m not in STATIC_METRICS)}: e.g. --voltage step:200V")
    if duration is not None:
        fixed["duration"] = float(duration)
    if needs_run and fixed.get("waveform") == "step" and fixed.get("duration") in (None, ""):
        raise ParameterError("duration", None, "a duration in s for a step (--duration)")
    lo, hi = np.array([b[0] for b in bounds]), np.array([b[1] for b in bounds])
    corners = [{n: float(v) for n, v in zip(names, x)} for x in (lo, hi, 0.5 * (lo + hi))]
    check_settings(corners, fixed)
    check_metric_settings(corners, fixed, wanted)
    for c in corners:                       # the box's corners build (a stack the drive takes)
        variants.design_actuator(base_name, c)
    _check_fields(base_name, fixed, corners, goal.constraints)
    return Box(tuple(names), lo, hi), fixed


def _run_stored(study: _Study, files: Dict[str, Path], *, progress, t0: float) -> OptimizeResult:
    """:func:`_run` with its evaluations appended to ``evaluations.csv`` (held for the run),
    those already there read back as a cache."""
    from ..io.outputs import hold
    from .store import RowFile, drop_torn_row, read_study_csv
    csv_path, columns = files["evaluations"], study.columns
    with hold(csv_path, "--out (evaluations.csv)", holder="mjeap optimize", picked=True):
        drop_torn_row(csv_path)
        cached, delimiter = {}, ","
        if csv_path.exists() and csv_path.stat().st_size > 0:
            header, rows, delimiter = read_study_csv(csv_path)
            if header != columns:
                raise ParameterError("--out", str(csv_path), f"the evaluations of this optimisation (columns "
                                     f"{columns}); it has {header}: choose another --out")
            cached = {r["point_id"]: r for r in rows}
        writer = RowFile(csv_path, delimiter, "--out (evaluations.csv)")
        try:
            if not cached:
                writer.write(columns, 0)
            return _run(study, cached=cached, writer=writer, progress=progress, t0=t0, files=files)
        finally:
            writer.close()


def _write_result(result: OptimizeResult, study: _Study, files: Dict[str, Path]) -> None:
    """The point's actuator file (named optimum only where it is feasible), the front, the
    figures and result.json, each whole or not at all."""
    from ..io.outputs import replacing
    from ..model.actuator_file import actuator_toml
    which = "optimum" if result.feasible else "least_infeasible"
    result.files = {k: v for k, v in result.files.items()
                    if k not in ("optimum", "least_infeasible") or (k == which and result.actuator is not None)}
    if result.actuator is not None:
        with replacing(files[which], f"--out ({files[which].name})", picked=True) as t:
            Path(t).write_text(actuator_toml(result.actuator), encoding="utf-8")
    box = study.box
    if study.front is not None:
        write_front(files["pareto"], result.pareto, study.front, list(box.names), study.base_name)
    drawn = draw(result, files, list(box.names), box.lo, box.hi, list(study.goal.constraints), study.front,
                 study.base_name)
    if drawn:
        result.message += f"; {drawn}"
        for k in ("figure", "pareto_figure"):
            result.files.pop(k, None)
    text = json.dumps(result.as_dict(), indent=2, default=float)
    with replacing(files["result"], "--out (result.json)", picked=True) as t:
        Path(t).write_text(text + "\n", encoding="utf-8")


def _run(study: _Study, *, cached: dict, writer, progress, t0: float, files: Dict[str, Path]) -> OptimizeResult:
    """The search of ``study`` (and its front), then the result at the best point."""
    goal, settings = study.goal, study.settings
    bar = None
    if progress or (progress is None and sys.stderr.isatty()):
        try:
            from tqdm import tqdm
            bar = tqdm(total=settings.max_evaluations, unit="eval", desc=f"optimize {goal.objective}")
        except ImportError:  # pragma: no cover
            bar = None
    ev = Evaluations(study.box, goal, metrics=study.wanted, base=study.fixed, cached=cached, out=writer,
                     columns=study.columns, max_evaluations=settings.max_evaluations, bar=bar)
    front = None
    try:
        runs, messages = search(ev, settings)
        if study.front is not None:
            front = trace_front(ev, study.front, list(goal.constraints), study.pareto_points, settings, runs)
            ev.aim(goal.objective, goal.sign, goal.constraints)     # back to the first metric's question
    finally:
        if bar is not None:
            bar.close()
    pick = ev.best or ev.least
    if pick is None:
        errors = [ev.rows[p]["error"].split(" | ")[0] for p in ev.order if ev.rows[p].get("error")]
        raise ParameterError("optimisation", goal.objective, "a box where some evaluation succeeds",
                             f"all {len(ev.rows)} evaluations failed: {errors[0] if errors else 'no values'}")
    return _result(study, ev, ev.rows[pick[1]], runs=runs, messages=messages, front=front, t0=t0, files=files)


def _result(study: _Study, ev: Evaluations, row: dict, *, runs, messages, front, t0: float,
            files: Dict[str, Path]) -> OptimizeResult:
    """The optimisation's answer at ``row`` (the best feasible point, else the least
    infeasible): its metrics, constraints, sensitivities, slices and actuator."""
    goal, wanted = study.goal, study.wanted
    point = row["_point"]
    values = {m: clean(row[m]) for m in wanted}
    cons = []
    for c in goal.constraints:
        v = number(row[c.metric])
        cons.append({"expression": c.expression, "metric": c.metric, "bound": c.bound, "value": v,
                     "margin": c.margin(v), "met": c.margin(v) >= -goal.feasibility,
                     "active": abs(c.margin(v)) <= goal.active})
    feasible = ev.best is not None
    sens = sensitivities(ev, row, list(goal.constraints), goal.active, study.settings.fd_step, study.base_name) \
        if feasible else []
    swept = slices(ev, ev.u_of(point), study.slice_points)
    evaluated = [(ev.rows[p]["_point"], {m: clean(ev.rows[p].get(m, "")) for m in wanted}, ev.rows[p].get("error", ""))
                 for p in ev.order]
    return OptimizeResult(
        optimum=dict(point), metrics=values,
        objective={"metric": goal.objective, "sense": "maximize" if goal.sign > 0 else "minimize",
                   "value": values[goal.objective]},
        constraints=cons, evaluations=len(ev.rows), evaluations_run=ev.run, evaluations_cached=ev.read,
        success=feasible and any(r.get("success") for r in runs),
        message="; ".join(dict.fromkeys(messages)) + ("" if feasible else "; no feasible point found: the least "
                                                       "infeasible is reported"),
        method=study.settings.method, wall_s=time.perf_counter() - t0, runs=runs,
        actuator=_point_actuator(study, point, feasible),
        files={k: str(v) for k, v in files.items()}, sensitivities=sens, pareto=front, evaluated=evaluated,
        slices=swept, feasible=feasible)


def _point_actuator(study: _Study, point: dict, feasible: bool):
    """The actuator of ``point`` (the fixed actuator.X and drive.NAME settings too), named and
    noted as the optimum or the least infeasible point; None where it does not build."""
    from ..model.variants import design_actuator, get_base
    goal, fixed, box = study.goal, study.fixed, study.box
    try:
        act0 = get_base(study.base_name)
        act = design_actuator(study.base_name, {**fixed, **point})     # fixed actuator.X (--set) too
        drive_set = {k[6:]: v for k, v in {**fixed, **point}.items() if k.startswith("drive.")}
        if drive_set:
            act = dataclasses.replace(act, drive_parameters={
                **act.drive_parameters, **{k: (float(v), "", "set by mjeap optimize") for k, v in drive_set.items()}})
        sense = "maximise" if goal.sign > 0 else "minimise"
        return dataclasses.replace(
            act, id=f"{act0.id}-optimum" if feasible else f"{act0.id}-least-infeasible",
            title=f"{act0.title}, optimised ({sense} {goal.objective})" if feasible else
            f"{act0.title}, least infeasible point ({sense} {goal.objective}: no point met the constraints)",
            notes=(act0.notes + "\n" if act0.notes else "") + f"mjeap optimize: {sense} {goal.objective}"
            + (f" subject to {', '.join(c.expression for c in goal.constraints)}" if goal.constraints else "")
            + f" over {', '.join(f'{n} in [{a:g}, {b:g}]' for n, a, b in zip(box.names, box.lo, box.hi))}; optimum "
            + ", ".join(f"{k} = {v:.6g}" for k, v in point.items()))
    except MjeapError:
        return None


def _check_fields(actuator, fixed: dict, corners: List[dict], constraints) -> None:
    """One warning (:class:`mjeap.model.laminate.FieldWarning`) where a corner of the box
    drives a piezo layer past its material's limits and no constraint on ``max_field`` bounds
    the answer (the points' own drives are quiet: a study's field is its metric)."""
    import warnings
    from ..model.variants import design_actuator
    from ..drives import make_drive
    from ..drives.piezo import LinearPiezo
    from ..model.laminate import FieldWarning
    from ..simulation.scene import Scene
    from .sweep.metrics import FIELD_METRICS
    if any(c.metric in FIELD_METRICS for c in constraints):
        return
    texts = []
    for c in corners:
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                act = design_actuator(actuator, {**fixed, **c})
                drv = make_drive(None, Scene(act, segments=2),
                                 **{k[6:]: v for k, v in {**fixed, **c}.items() if k.startswith("drive.")})
        except MjeapError:
            return                                 # the points report it
        if not isinstance(drv, LinearPiezo):
            return
        texts += drv.laminate().field_warnings(drv.voltage_range())
    if texts:
        warnings.warn(f"the box reaches fields past a layer's limit ({texts[0]}); a constraint such as "
                      "--subject-to max_field<=2V/um keeps the optimum within it", FieldWarning, stacklevel=3)


def _parse_pareto(pareto) -> Tuple[Tuple[str, float], Tuple[str, float]]:
    """((M1, sign), (M2, sign)) of ``"M1,M2"`` or (M1, M2), a ``min:`` prefix minimising (sign
    -1), ``max:`` or none maximising; two different known metrics, else refused."""
    from .sweep import METRICS
    parts = pareto.split(",") if isinstance(pareto, str) else list(pareto)
    if len(parts) != 2:
        raise ParameterError("--pareto", pareto, "two metrics M1,M2 (each maximised; min:NAME minimises), e.g. "
                             "stroke,blocked_force or free_deflection,min:mass")
    out = []
    for part in parts:
        part = str(part).strip()
        sense, _, name = part.rpartition(":")
        if sense not in ("", "max", "min"):
            raise ParameterError("--pareto", pareto, "METRIC, max:METRIC or min:METRIC")
        if name not in METRICS:
            raise UnknownNameError("metric (--pareto)", name, METRICS)
        out.append((name, -1.0 if sense == "min" else 1.0))
    if out[0][0] == out[1][0]:
        raise ParameterError("--pareto", pareto, "two different metrics")
    return out[0], out[1]


