"""Design optimisation: maximise or minimise one metric of :mod:`mjeap.sweep` over bounded
actuator, drive and payload parameters, subject to constraints on other metrics, with
scipy's optimisers (``mjeap optimize``, :func:`optimize`).

An evaluation is one sweep point (:func:`mjeap.sweep.evaluate`): a Scene of the point's
actuator (:mod:`mjeap.design` builds it from the base actuator and the ``actuator.X``
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
"""
from __future__ import annotations

import dataclasses
import json
import math
import re
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Dict, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np

from .errors import MjeapError, ParameterError, UnknownNameError, check_integer, check_range, sigterm_as_interrupt

__all__ = ["optimize", "Constraint", "OptimizeResult", "parse_constraint", "parse_bounds", "METHODS"]

METHODS = ("slsqp", "differential-evolution")
#: sweep parameters an optimisation may vary besides actuator.X and drive.NAME: (unit, low, high,
#: low open) - the range a bound must lie in
VARIABLE = {"payload_mass": ("kg", 0.0, math.inf, False), "payload_position": ("m", 0.0, math.inf, True),
            "amplitude": ("V", -math.inf, math.inf, False), "offset": ("V", -math.inf, math.inf, False),
            "frequency": ("Hz", 0.0, math.inf, True), "initial_curvature": ("1/m", -math.inf, math.inf, False),
            "damping_ratio": ("-", 0.0, 10.0, True)}
#: the files an optimisation writes in its folder
RESULT, EVALUATIONS, OPTIMUM = "result.json", "evaluations.csv", "optimum.toml"
#: the actuator file of an optimisation that found no feasible point: its least infeasible point,
#: never named optimum; BASE: an Actuator object given as the base, written for the evaluations
LEAST_INFEASIBLE, BASE = "least-infeasible.toml", "base.toml"
_CONSTRAINT = re.compile(r"^\s*([A-Za-z0-9_-]+)\s*(>=|<=)\s*(.+?)\s*$")


@dataclass(frozen=True)
class Constraint:
    """``metric >= bound`` or ``metric <= bound`` (SI)."""

    metric: str
    sense: str
    bound: float

    @property
    def expression(self) -> str:
        return f"{self.metric}{self.sense}{self.bound:g}"

    def margin(self, value: float) -> float:
        """How far ``value`` lies on the feasible side, relative to the bound (>= 0: met)."""
        scale = abs(self.bound) if self.bound != 0 else 1.0
        return (value - self.bound) / scale if self.sense == ">=" else (self.bound - value) / scale


def parse_constraint(text: Union[str, Constraint, tuple]) -> Constraint:
    """``"NAME>=VALUE"`` or ``"NAME<=VALUE"`` (VALUE SI or with the metric's unit, e.g.
    ``first_frequency>=0.8kHz``), a (name, sense, value) tuple or a Constraint."""
    from .model.quantity import to_si
    from .sweep import METRIC_UNITS, METRICS
    if isinstance(text, Constraint):
        c = text
    else:
        if isinstance(text, tuple) and len(text) == 3:
            name, sense, value = text
        else:
            m = _CONSTRAINT.match(str(text))
            if m is None:
                raise ParameterError("--subject-to", text, "NAME>=VALUE or NAME<=VALUE, e.g. first_frequency>=800")
            name, sense, value = m.groups()
        if name not in METRICS:
            raise UnknownNameError("metric (--subject-to)", str(name), METRICS)
        if sense not in (">=", "<="):
            raise ParameterError("--subject-to", text, "NAME>=VALUE or NAME<=VALUE")
        unit = METRIC_UNITS.get(name, "-")
        c = Constraint(str(name), sense, to_si(value if isinstance(value, str) else float(value), unit,
                                               f"--subject-to {name}"))
    return c


def parse_bounds(name: str, value, actuator=None) -> Tuple[float, float]:
    """(low, high) SI of a varied parameter from (low, high) numbers or texts with units, or
    text ``"LOW:HIGH"`` (``"5mm:15mm"``): low < high, both in the parameter's range
    (:func:`mjeap.design.check_design_value` for actuator.X, the drive's RANGES for
    drive.NAME, :data:`VARIABLE` for the others). Raises ParameterError naming it."""
    from . import design
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
    lo, hi = (design.to_value(name, v, actuator) for v in (lo, hi))
    for v in (lo, hi):
        if isinstance(v, str) or isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
            raise ParameterError("--vary", f"{name}={value!r}", accepted, f"{v!r} is not a finite number")
    lo, hi = float(lo), float(hi)
    if not lo < hi:
        raise ParameterError("--vary", f"{name}={lo:g}:{hi:g}", accepted)
    if design.is_design_parameter(name):
        for v in (lo, hi):
            design.check_design_value(name, v, actuator)
    elif name.startswith("drive."):
        from .drives import default_drive_name, get_drive_class
        cls = get_drive_class(default_drive_name(design.get_base(actuator)))
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
                                   design.design_parameter_names(actuator) if actuator is not None else []))
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
    feasible: bool = True                   # False: no point met the constraints (the least infeasible is reported)

    def as_dict(self) -> dict:
        d = {k: getattr(self, k) for k in ("optimum", "metrics", "objective", "constraints", "evaluations",
                                          "evaluations_run", "evaluations_cached", "success", "message",
                                          "method", "wall_s", "runs", "files")}
        d["wall_s"] = round(self.wall_s, 3)
        return d


class _Budget(MjeapError):
    """The evaluation budget is spent."""


class _Failed(MjeapError):
    """An evaluation failed (its row's error): the start that asked for it stops."""


def _number(v) -> float:
    """A metric's value (a row's, live or read back from the CSV) as a float."""
    if isinstance(v, (bool, np.bool_)):
        return float(v)
    if isinstance(v, str):
        if v in ("True", "False"):
            return float(v == "True")
        if v == "":
            return math.nan
        return float(v)
    return float(v)


class _Evaluations:
    """The evaluations of one optimisation: points by their u in [0, 1]^n, each evaluated
    once (:func:`mjeap.sweep.evaluate`, serial, in this process) or read from the CSV,
    appended to it as they finish."""

    def __init__(self, names, lo, hi, metrics, base, cached, out, columns, max_evaluations, bar,
                 objective, sign, constraints, feasibility):
        self.names, self.lo, self.hi = names, np.asarray(lo, float), np.asarray(hi, float)
        self.metrics, self.base, self.cached, self.out, self.columns = metrics, base, cached, out, columns
        self.max_evaluations, self.bar = max_evaluations, bar
        self.objective, self.sign, self.constraints, self.feasibility = objective, sign, constraints, feasibility
        self.rows: Dict[str, dict] = {}
        self.order: List[str] = []
        self._us: List[np.ndarray] = []                        # u of self.order's points
        self.run = self.read = 0
        self.scale = 1.0
        self.best: Optional[Tuple[float, str]] = None         # (signed objective, point id) of the best feasible
        self.least: Optional[Tuple[float, str]] = None        # (violation, point id): the least infeasible

    def point(self, u) -> dict:
        u = np.clip(np.asarray(u, float), 0.0, 1.0)
        x = self.lo + u * (self.hi - self.lo)
        return {n: float(v) for n, v in zip(self.names, x)}

    #: points closer than this (in the box scaled to [0, 1]) are the same design: the nearest
    #: evaluated one answers (a line search shrinking its step below it stops there instead of
    #: spending the budget on designs no one could tell apart)
    RESOLUTION = 1e-9

    def __call__(self, u) -> dict:
        from .sweep import evaluate, point_id
        p = self.point(u)
        pid = point_id(p, self.base, self.metrics)
        row = self.rows.get(pid)
        if row is not None:
            return row
        if self._us:
            uu = np.clip(np.asarray(u, float), 0.0, 1.0)
            d = np.max(np.abs(np.asarray(self._us) - uu), axis=1)
            k = int(np.argmin(d))
            if d[k] < self.RESOLUTION:
                return self.rows[self.order[k]]
        if len(self.rows) >= self.max_evaluations:
            raise _Budget(f"the budget of {self.max_evaluations} evaluations is spent")
        if pid in self.cached:
            row = dict(self.cached[pid])
            self.read += 1
        else:
            row = evaluate(p, self.metrics, self.base)
            row.pop("_error_model", None)
            if self.out is not None:
                self.out.write([row.get(k, "") for k in self.columns], len(self.cached) + self.run)
            self.run += 1
            row = {**row, **{m: _readback(row[m]) for m in self.metrics}}
        row["_point"] = p
        self.rows[pid] = row
        self.order.append(pid)
        self._us.append(np.clip(np.asarray(u, float), 0.0, 1.0))
        self._rank(pid, row)
        if self.bar is not None:
            self.bar.update(1)
            if self.best is not None:
                self.bar.set_postfix_str(f"best {self.objective} {self.sign * self.best[0]:.5g}", refresh=False)
        return row

    def _rank(self, pid, row):
        if row.get("error"):
            return
        try:
            f = self.sign * _number(row[self.objective])
            margins = [c.margin(_number(row[c.metric])) for c in self.constraints]
        except (TypeError, ValueError):
            return
        if not math.isfinite(f) or not all(math.isfinite(m) for m in margins):
            return
        violation = sum(max(0.0, -m) for m in margins)
        if violation <= self.feasibility:
            if self.best is None or f > self.best[0]:
                self.best = (f, pid)
        elif self.least is None or violation < self.least[0]:
            self.least = (violation, pid)

    def values(self, u) -> Tuple[float, np.ndarray]:
        """(scaled objective to minimise, scaled constraint margins >= 0) at u; a failed point
        raises _Failed."""
        row = self(u)
        if row.get("error"):
            raise _Failed(f"{row['error'].split(' | ')[0]} (at {row['_point']})")
        f = -self.sign * _number(row[self.objective]) / self.scale
        g = np.array([c.margin(_number(row[c.metric])) for c in self.constraints])
        if not math.isfinite(f) or not np.all(np.isfinite(g)):
            raise _Failed(f"a metric is not a number at {row['_point']}")
        return f, g


def _readback(v):
    """A metric's value as the CSV gives it back (so a rerun from the cache is the same)."""
    from .io.csvio import plain_cell
    if isinstance(v, (float, np.floating)):
        return float(repr(float(v)))
    return plain_cell(v)


def _fd(ev: _Evaluations, u: np.ndarray, h: float):
    """(objective, margins, their gradients) at u by forward differences of h (backward at
    the upper bound)."""
    f0, g0 = ev.values(u)
    n = u.size
    df, dg = np.zeros(n), np.zeros((g0.size, n))
    for i in range(n):
        step = h if u[i] + h <= 1.0 else -h
        v = u.copy()
        v[i] += step
        f1, g1 = ev.values(v)
        df[i], dg[:, i] = (f1 - f0) / step, (g1 - g0) / step
    return f0, g0, df, dg


def _slsqp(ev: _Evaluations, u0, fd_step, tol, maxiter):
    from scipy.optimize import minimize
    n = len(u0)
    cons = []
    for j in range(len(ev.constraints)):
        cons.append({"type": "ineq", "fun": lambda u, j=j: ev.values(u)[1][j],
                     "jac": lambda u, j=j: _fd(ev, np.asarray(u, float), fd_step)[3][j]})
    res = minimize(lambda u: ev.values(u)[0], np.asarray(u0, float),
                   jac=lambda u: _fd(ev, np.asarray(u, float), fd_step)[2], method="SLSQP",
                   bounds=[(0.0, 1.0)] * n, constraints=cons, options={"maxiter": maxiter, "ftol": tol})
    return res


def _differential_evolution(ev: _Evaluations, seed, tol, budget, popsize):
    """scipy's differential_evolution on [0, 1]^n (Latin hypercube, seeded), no polish (SLSQP
    polishes after it), at most ``budget`` evaluations; ``tol`` its convergence tolerance
    (the population's spread of the objective relative to its mean)."""
    from scipy.optimize import NonlinearConstraint, differential_evolution
    n = len(ev.names)
    big = 1e30

    def f(u):
        try:
            return ev.values(u)[0]
        except _Failed:
            return big

    def g(u):
        try:
            return ev.values(u)[1]
        except _Failed:
            return np.full(len(ev.constraints), -big)

    kw = {}
    if ev.constraints:
        kw["constraints"] = NonlinearConstraint(g, 0.0, np.inf)
    gens = max(1, budget // (popsize * n) - 1)
    return differential_evolution(f, [(0.0, 1.0)] * n, seed=seed, maxiter=gens, popsize=popsize, tol=tol,
                                  init="latinhypercube", polish=False, updating="immediate", **kw)


def _base_actuator(actuator, folder: Optional[Path]):
    """The study's ``actuator`` setting: a catalog id or a file's path as given; an Actuator
    object is written as an actuator file (in the output folder, else a temporary one)."""
    from .model.actuator import Actuator
    if isinstance(actuator, Path):
        return str(actuator), None
    if isinstance(actuator, Actuator):
        from .model.actuator_file import actuator_toml, write_actuator
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
        return str(path), tmp
    if not isinstance(actuator, str):
        raise ParameterError("actuator", actuator, "a catalog id, an actuator file's path or an Actuator")
    return actuator, None


def _wave_settings(voltage) -> dict:
    """The sweep's waveform settings of a waveform text (step, square, sine or triangle)."""
    from .drives.waveforms import parse_waveform
    from .sweep import SWEEP_WAVEFORMS
    w = parse_waveform(voltage)
    if w.kind not in SWEEP_WAVEFORMS or w.phase or w.delay or (w.kind == "square" and w.duty != 0.5):
        raise ParameterError("voltage", voltage, f"a waveform of {', '.join(SWEEP_WAVEFORMS)}: "
                             "KIND:AMPLITUDE[@FREQUENCY][,offset=OFFSET] (no duty, phase or delay)")
    out = {"waveform": w.kind, "amplitude": float(w.amplitude), "offset": float(w.offset)}
    if w.kind != "step":
        out["frequency"] = float(w.frequency)
    return out


def optimize(actuator, vary: Mapping[str, object], maximize: Optional[str] = None, minimize: Optional[str] = None,
             subject_to: Sequence = (), voltage: Optional[str] = None, duration: Optional[float] = None,
             base: Optional[dict] = None, metrics: Sequence[str] = (), method: str = "slsqp", starts: int = 3,
             seed: int = 0, max_evaluations: int = 400, out=None, progress: Optional[bool] = None,
             tol: float = 1e-7, fd_step: float = 1e-3, feasibility: float = 1e-6, active: float = 1e-3,
             maxiter: int = 100, popsize: int = 10, de_tol: float = 1e-2) -> OptimizeResult:
    """Maximise (``maximize``) or minimise (``minimize``) one metric of :mod:`mjeap.sweep`
    over the box ``vary`` (name -> (low, high), SI numbers or texts with units, or
    ``"LOW:HIGH"``; names ``actuator.X`` of :mod:`mjeap.design`, ``drive.NAME``,
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
    constraint active). Evaluations run one at a time in this process."""
    from . import design
    from .io.outputs import check_outputs, hold, replacing
    from .model.actuator_file import actuator_toml, is_actuator_file
    from .sweep import METRICS, STATIC_METRICS, check_metric_settings, check_settings
    from .sweep.design import _check_names
    from .sweep.runner import _drop_torn_row, _read_sweep_csv, _RowFile

    t0 = time.perf_counter()
    # ---- the question, checked before any work
    if (maximize is None) == (minimize is None):
        raise ParameterError("maximize/minimize", f"maximize={maximize!r}, minimize={minimize!r}",
                             "exactly one metric to maximise or to minimise")
    objective, sign = (maximize, 1.0) if maximize is not None else (minimize, -1.0)
    if objective not in METRICS:
        raise UnknownNameError("metric (--maximize/--minimize)", str(objective), METRICS)
    constraints = [parse_constraint(c) for c in ([subject_to] if isinstance(subject_to, str) else subject_to)]
    extra = list(metrics.split(",")) if isinstance(metrics, str) else list(metrics)
    for m in extra:
        if m not in METRICS:
            raise UnknownNameError("metric (--metrics)", m, METRICS)
    wanted = list(dict.fromkeys([objective, *(c.metric for c in constraints), *extra]))
    method = str(method).strip().lower().replace("_", "-")
    if method not in METHODS:
        raise ParameterError("method", method, f"one of {', '.join(METHODS)}")
    starts = check_integer("starts", starts, 1, 100)
    seed = check_integer("seed", seed, 0)
    max_evaluations = check_integer("max_evaluations", max_evaluations, 2)
    popsize = check_integer("popsize", popsize, 4, 1000)
    maxiter = check_integer("maxiter", maxiter, 1)
    fd_step = check_range("fd_step", fd_step, 0.0, 0.1, "(of the box)", lo_open=True)
    tol = check_range("tol", tol, 0.0, 0.1, lo_open=True)
    de_tol = check_range("de_tol", de_tol, 0.0, 1.0, lo_open=True)
    feasibility = check_range("feasibility", feasibility, 0.0, 0.1)
    active = check_range("active", active, 0.0, 1.0)
    if not isinstance(vary, Mapping) or not vary:
        raise ParameterError("vary", vary, "at least one parameter with its bounds: {'actuator.length': "
                             "('5mm', '15mm')} (--vary NAME=LOW:HIGH)")
    folder = Path(out) if out is not None else None
    files = {}
    if folder is not None:
        if folder.exists() and not folder.is_dir():
            raise ParameterError("--out", str(folder), "a folder for result.json, evaluations.csv and optimum.toml",
                                 "it is a file")
        files = {k: folder / v for k, v in (("result", RESULT), ("evaluations", EVALUATIONS), ("optimum", OPTIMUM),
                                            ("least_infeasible", LEAST_INFEASIBLE))}
        named = {f"--out ({p.name})": p for p in files.values()}
        if not isinstance(actuator, (str, Path)):
            named[f"--out ({BASE})"] = folder / BASE
        # names mjeap picks: regular files or none, never a link, never the base actuator's file
        check_outputs(inputs=[("base actuator file", actuator if isinstance(actuator, (str, Path)) and
                               is_actuator_file(actuator) else None)], picked=named, **named)
    base_name, tmp = _base_actuator(actuator, folder)
    try:
        fixed = dict(base or {})
        if "actuator" in fixed:
            raise ParameterError("base", "actuator", "the actuator as optimize's first argument, not in base/--set")
        _check_names(fixed)
        fixed["actuator"] = base_name
        act0 = design.get_base(base_name)
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
            design.design_actuator(base_name, c)
        columns = ["point_id", *names, *wanted, "error", "wall_s", "settings"]
        # ---- the run
        from threadpoolctl import threadpool_limits
        with sigterm_as_interrupt(), threadpool_limits(1):
            if folder is None:
                return _run(names, lo, hi, wanted, fixed, {}, None, columns, max_evaluations, progress, objective,
                            sign, constraints, feasibility, method, starts, seed, tol, fd_step, maxiter, popsize,
                            active, base_name, t0, files, act0, de_tol)
            csv_path = files["evaluations"]
            with hold(csv_path, "--out (evaluations.csv)", holder="mjeap optimize", picked=True):
                _drop_torn_row(csv_path)
                cached, delimiter = {}, ","
                if csv_path.exists() and csv_path.stat().st_size > 0:
                    header, rows, delimiter = _read_sweep_csv(csv_path)
                    if header != columns:
                        raise ParameterError("--out", str(csv_path), f"the evaluations of this optimisation (columns "
                                             f"{columns}); it has {header}: choose another --out")
                    cached = {r["point_id"]: r for r in rows}
                writer = _RowFile(csv_path, delimiter, "--out (evaluations.csv)")
                try:
                    if not cached:
                        writer.write(columns, 0)
                    result = _run(names, lo, hi, wanted, fixed, cached, writer, columns, max_evaluations, progress,
                                  objective, sign, constraints, feasibility, method, starts, seed, tol, fd_step,
                                  maxiter, popsize, active, base_name, t0, files, act0, de_tol)
                finally:
                    writer.close()
            # the point's actuator file: named optimum only where the point is feasible
            which = "optimum" if result.feasible else "least_infeasible"
            result.files = {k: v for k, v in result.files.items()
                            if k not in ("optimum", "least_infeasible") or (k == which and result.actuator is not None)}
            if result.actuator is not None:
                with replacing(files[which], f"--out ({files[which].name})", picked=True) as t:
                    Path(t).write_text(actuator_toml(result.actuator), encoding="utf-8")
            text = json.dumps(result.as_dict(), indent=2, default=float)
            with replacing(files["result"], "--out (result.json)", picked=True) as t:
                Path(t).write_text(text + "\n", encoding="utf-8")
            return result
    finally:
        if tmp is not None:
            tmp.cleanup()


def _run(names, lo, hi, wanted, fixed, cached, writer, columns, max_evaluations, progress, objective, sign,
         constraints, feasibility, method, starts, seed, tol, fd_step, maxiter, popsize, active, base_name, t0,
         files, act0, de_tol=1e-2) -> OptimizeResult:
    bar = None
    if progress or (progress is None and sys.stderr.isatty()):
        try:
            from tqdm import tqdm
            bar = tqdm(total=max_evaluations, unit="eval", desc=f"optimize {objective}")
        except ImportError:  # pragma: no cover
            bar = None
    ev = _Evaluations(names, lo, hi, wanted, fixed, cached, writer, columns, max_evaluations, bar, objective, sign,
                      constraints, feasibility)
    n = len(names)
    runs, messages = [], []
    try:
        centre = np.full(n, 0.5)
        try:                               # the objective's scale: its magnitude at the box's centre
            f_c = _number(ev(centre)[objective]) if not ev(centre).get("error") else math.nan
        except _Budget:
            f_c = math.nan
        ev.scale = abs(f_c) if math.isfinite(f_c) and f_c != 0 else 1.0
        if method == "slsqp":
            rng = np.random.default_rng(seed)
            u_starts = [centre] + [rng.uniform(0.0, 1.0, n) for _ in range(starts - 1)]
        else:
            u_starts = [None]
        for k, u0 in enumerate(u_starts):
            before = len(ev.rows)
            info = {"start": "centre" if (u0 is not None and k == 0) else (
                "differential evolution" if u0 is None else f"seeded {k}")}
            try:
                if u0 is None:
                    de = _differential_evolution(ev, seed, de_tol, int(0.8 * max_evaluations), popsize)
                    info.update(evolution=str(de.message), generations=int(de.nit))
                    u0 = np.asarray(de.x, float)
                    info["polish"] = True
                if u0 is not None:
                    info["from"] = ev.point(u0)
                    res = _slsqp(ev, u0, fd_step, tol, maxiter)
                    info.update(message=str(res.message), success=bool(res.success), iterations=int(res.nit),
                                to=ev.point(res.x))
                    ev(res.x)
            except _Budget as e:
                info.update(message=str(e), success=False)
                messages.append(str(e))
                info["evaluations"] = len(ev.rows) - before
                runs.append(info)
                break
            except _Failed as e:
                info.update(message=f"stopped: an evaluation failed: {e}", success=False)
            info["evaluations"] = len(ev.rows) - before
            runs.append(info)
            messages.append(info["message"])
    finally:
        if bar is not None:
            bar.close()
    pick = ev.best or ev.least
    if pick is None:
        errors = [ev.rows[p]["error"].split(" | ")[0] for p in ev.order if ev.rows[p].get("error")]
        raise ParameterError("optimisation", objective, "a box where some evaluation succeeds",
                             f"all {len(ev.rows)} evaluations failed: {errors[0] if errors else 'no values'}")
    row = ev.rows[pick[1]]
    point = row["_point"]
    values = {m: _clean(row[m]) for m in wanted}
    cons = []
    for c in constraints:
        v = _number(row[c.metric])
        cons.append({"expression": c.expression, "metric": c.metric, "bound": c.bound, "value": v,
                     "margin": c.margin(v), "met": c.margin(v) >= -feasibility, "active": abs(c.margin(v)) <= active})
    feasible = ev.best is not None
    act = None
    try:
        from .design import design_actuator
        act = design_actuator(base_name, {**fixed, **point})     # fixed actuator.X (--set) too
        drive_set = {k[6:]: v for k, v in {**fixed, **point}.items() if k.startswith("drive.")}
        if drive_set:
            act = dataclasses.replace(act, drive_parameters={
                **act.drive_parameters, **{k: (float(v), "", "set by mjeap optimize") for k, v in drive_set.items()}})
        sense = "maximise" if sign > 0 else "minimise"
        act = dataclasses.replace(
            act, id=f"{act0.id}-optimum" if feasible else f"{act0.id}-least-infeasible",
            title=f"{act0.title}, optimised ({sense} {objective})" if feasible else
            f"{act0.title}, least infeasible point ({sense} {objective}: no point met the constraints)",
            notes=(act0.notes + "\n" if act0.notes else "") + f"mjeap optimize: {sense} {objective}"
            + (f" subject to {', '.join(c.expression for c in constraints)}" if constraints else "")
            + f" over {', '.join(f'{n} in [{a:g}, {b:g}]' for n, a, b in zip(names, lo, hi))}; optimum "
            + ", ".join(f"{k} = {v:.6g}" for k, v in point.items()))
    except MjeapError:
        act = None
    return OptimizeResult(
        optimum=dict(point), metrics=values,
        objective={"metric": objective, "sense": "maximize" if sign > 0 else "minimize", "value": values[objective]},
        constraints=cons, evaluations=len(ev.rows), evaluations_run=ev.run, evaluations_cached=ev.read,
        success=feasible and any(r.get("success") for r in runs),
        message="; ".join(dict.fromkeys(messages)) + ("" if feasible else "; no feasible point found: the least "
                                                       "infeasible is reported"),
        method=method, wall_s=time.perf_counter() - t0, runs=runs, actuator=act,
        files={k: str(v) for k, v in files.items()}, feasible=feasible)


def _clean(v):
    try:
        return _number(v)
    except (TypeError, ValueError):
        return v
