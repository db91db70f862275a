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
import re
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Dict, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np

from .parameters import to_value
from ..errors import MjeapError, ParameterError, UnknownNameError, check_integer, check_range, sigterm_as_interrupt

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
FIGURE, PARETO, PARETO_FIGURE = "optimize.png", "pareto.csv", "pareto.png"
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
    from ..model.quantity import to_si
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
    once (:func:`mjeap.studies.sweep.evaluate`, serial, in this process) or read from the CSV,
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

    def aim(self, objective: str, sign: float, constraints) -> None:
        """Ask another question of the same evaluations (a Pareto front's next point): the
        best and least infeasible ranked again over every row so far."""
        self.objective, self.sign, self.constraints = objective, sign, list(constraints)
        self.best = self.least = None
        for pid in self.order:
            self._rank(pid, self.rows[pid])

    def u_of(self, point: dict) -> np.ndarray:
        """The scaled u in [0, 1]^n of a point (SI)."""
        return (np.array([point[n] for n in self.names]) - self.lo) / (self.hi - self.lo)

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
    from ..io.csvio import plain_cell
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
    from ..model.actuator import Actuator
    if isinstance(actuator, Path):
        return str(actuator), None
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
        return str(path), tmp
    if not isinstance(actuator, str):
        raise ParameterError("actuator", actuator, "a catalog id, an actuator file's path or an Actuator")
    return actuator, None


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


def optimize(actuator, vary: Mapping[str, object], maximize: Optional[str] = None, minimize: Optional[str] = None,
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
    from ..model import variants
    from ..io.outputs import check_outputs, hold, replacing
    from ..model.actuator_file import actuator_toml, is_actuator_file
    from .sweep import METRICS, STATIC_METRICS, check_metric_settings, check_settings
    from .sweep.points import check_names
    from .store import RowFile, drop_torn_row, read_study_csv

    t0 = time.perf_counter()
    # ---- the question, checked before any work
    front = None if pareto is None else _parse_pareto(pareto)
    if front is not None:
        if maximize is not None or minimize is not None:
            raise ParameterError("pareto", pareto, "either a front (--pareto M1,M2) or one metric to maximise or "
                                 "minimise, not both")
        pareto_points = check_integer("pareto_points", pareto_points, 3, 100)
        (maximize, minimize) = (front[0][0], None) if front[0][1] > 0 else (None, front[0][0])
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
    wanted = list(dict.fromkeys([objective, *(c.metric for c in constraints), *extra,
                                 *([] if front is None else [front[1][0]])]))
    method = str(method).strip().lower().replace("_", "-")
    if method not in METHODS:
        raise ParameterError("method", method, f"one of {', '.join(METHODS)}")
    starts = check_integer("starts", starts, 1, 100)
    seed = check_integer("seed", seed, 0)
    max_evaluations = check_integer("max_evaluations", max_evaluations, 2)
    popsize = check_integer("popsize", popsize, 4, 1000)
    slice_points = check_integer("slice_points", slice_points, 0, 1000)
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
                                            ("figure", FIGURE), ("least_infeasible", LEAST_INFEASIBLE))}
        if front is not None:
            files.update(pareto=folder / PARETO, pareto_figure=folder / PARETO_FIGURE)
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
        check_names(fixed)
        fixed["actuator"] = base_name
        act0 = variants.get_base(base_name)
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
        _check_fields(base_name, fixed, corners, constraints)
        columns = ["point_id", *names, *wanted, "error", "wall_s", "settings"]
        # ---- the run
        from threadpoolctl import threadpool_limits
        with sigterm_as_interrupt(), threadpool_limits(1):
            if folder is None:
                return _run(names, lo, hi, wanted, fixed, {}, None, columns, max_evaluations, progress, objective,
                            sign, constraints, feasibility, method, starts, seed, tol, fd_step, maxiter, popsize,
                            active, base_name, t0, files, act0, de_tol, front, pareto_points, slice_points)
            csv_path = files["evaluations"]
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
                    result = _run(names, lo, hi, wanted, fixed, cached, writer, columns, max_evaluations, progress,
                                  objective, sign, constraints, feasibility, method, starts, seed, tol, fd_step,
                                  maxiter, popsize, active, base_name, t0, files, act0, de_tol, front, pareto_points, slice_points)
                finally:
                    writer.close()
            # the point's actuator file: named optimum only where the point is feasible
            which = "optimum" if result.feasible else "least_infeasible"
            result.files = {k: v for k, v in result.files.items()
                            if k not in ("optimum", "least_infeasible") or (k == which and result.actuator is not None)}
            if result.actuator is not None:
                with replacing(files[which], f"--out ({files[which].name})", picked=True) as t:
                    Path(t).write_text(actuator_toml(result.actuator), encoding="utf-8")
            if front is not None:
                _write_front(files["pareto"], result.pareto, front, names, base_name)
            drawn = _draw(result, files, names, lo, hi, constraints, front, base_name)
            if drawn:
                result.message += f"; {drawn}"
                for k in ("figure", "pareto_figure"):
                    result.files.pop(k, None)
            text = json.dumps(result.as_dict(), indent=2, default=float)
            with replacing(files["result"], "--out (result.json)", picked=True) as t:
                Path(t).write_text(text + "\n", encoding="utf-8")
            return result
    finally:
        if tmp is not None:
            tmp.cleanup()


def _search(ev: _Evaluations, method, starts, seed, tol, fd_step, maxiter, popsize, de_tol, max_evaluations,
            first=None) -> Tuple[List[dict], List[str]]:
    """One question's search over ``ev`` (aimed at it): SLSQP from ``first`` (a u) or the
    box's centre and ``starts - 1`` seeded points, or differential evolution polished by
    SLSQP. Returns the starts' reports and messages; the budget spent ends it."""
    n = len(ev.names)
    runs, messages = [], []
    centre = np.full(n, 0.5)
    try:                               # the objective's scale: its magnitude at the box's centre
        f_c = _number(ev(centre)[ev.objective]) if not ev(centre).get("error") else math.nan
    except _Budget:
        f_c = math.nan
    except (TypeError, ValueError):
        f_c = math.nan
    ev.scale = abs(f_c) if math.isfinite(f_c) and f_c != 0 else 1.0
    if first is not None:
        u_starts = [np.asarray(first, float)]
    elif method == "slsqp":
        rng = np.random.default_rng(seed)
        u_starts = [centre] + [rng.uniform(0.0, 1.0, n) for _ in range(starts - 1)]
    else:
        u_starts = [None]
    for k, u0 in enumerate(u_starts):
        before = len(ev.rows)
        info = {"start": "previous optimum" if first is not None else "centre" if (u0 is not None and k == 0) else (
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
    return runs, messages


def _run(names, lo, hi, wanted, fixed, cached, writer, columns, max_evaluations, progress, objective, sign,
         constraints, feasibility, method, starts, seed, tol, fd_step, maxiter, popsize, active, base_name, t0,
         files, act0, de_tol=1e-2, pareto=None, pareto_points=7, slice_points=11) -> OptimizeResult:
    bar = None
    if progress or (progress is None and sys.stderr.isatty()):
        try:
            from tqdm import tqdm
            bar = tqdm(total=max_evaluations, unit="eval", desc=f"optimize {objective}")
        except ImportError:  # pragma: no cover
            bar = None
    ev = _Evaluations(names, lo, hi, wanted, fixed, cached, writer, columns, max_evaluations, bar, objective, sign,
                      constraints, feasibility)
    search = dict(method=method, starts=starts, seed=seed, tol=tol, fd_step=fd_step, maxiter=maxiter,
                  popsize=popsize, de_tol=de_tol, max_evaluations=max_evaluations)
    front = None
    try:
        runs, messages = _search(ev, **search)
        if pareto is not None:
            front = _trace_front(ev, pareto, constraints, pareto_points, search, runs)
            ev.aim(objective, sign, constraints)            # back to the first metric's question
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
    sensitivities = _sensitivities(ev, row, constraints, active, fd_step, base_name) if feasible else []
    slices = _slices(ev, ev.u_of(point), slice_points)
    act = None
    try:
        from ..model.variants import design_actuator
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
    evaluated = [(ev.rows[p]["_point"], {m: _clean(ev.rows[p].get(m, "")) for m in wanted}, ev.rows[p].get("error", ""))
                 for p in ev.order]
    return OptimizeResult(
        optimum=dict(point), metrics=values,
        objective={"metric": objective, "sense": "maximize" if sign > 0 else "minimize", "value": values[objective]},
        constraints=cons, evaluations=len(ev.rows), evaluations_run=ev.run, evaluations_cached=ev.read,
        success=feasible and any(r.get("success") for r in runs),
        message="; ".join(dict.fromkeys(messages)) + ("" if feasible else "; no feasible point found: the least "
                                                       "infeasible is reported"),
        method=method, wall_s=time.perf_counter() - t0, runs=runs, actuator=act,
        files={k: str(v) for k, v in files.items()}, sensitivities=sensitivities, pareto=front, evaluated=evaluated,
        slices=slices, feasible=feasible)


def _slices(ev: _Evaluations, u: np.ndarray, points: int) -> Dict[str, List[tuple]]:
    """Each variable swept over its range through the optimum (the others held there):
    name -> [(point, {metric: value}, error)]; where the budget runs out, what was reached."""
    out: Dict[str, List[tuple]] = {}
    if points < 2:
        return out
    for i, name in enumerate(ev.names):
        rows = []
        for ui in np.linspace(0.0, 1.0, points):
            v = u.copy()
            v[i] = ui
            try:
                r = ev(v)
            except _Budget:
                break
            rows.append((r["_point"], {m: _clean(r.get(m, "")) for m in ev.metrics}, r.get("error", "")))
        out[name] = rows
    return out


def _trace_front(ev: _Evaluations, pareto, constraints, points: int, search: dict, runs: List[dict]) -> List[dict]:
    """The Pareto front between ``pareto`` ((M1, sign), (M2, sign)) by the epsilon-constraint
    method (module text), ``ev`` holding the best M1 already; each level starts from the
    previous optimum. Returns the front's points, sorted along M2."""
    (m1, s1), (m2, s2) = pareto
    found = []

    def take(kind):
        pick = ev.best
        if pick is None:
            found.append({"kind": kind, "feasible": False})
            return None
        row = ev.rows[pick[1]]
        found.append({"kind": kind, "feasible": True, m1: _number(row[m1]), m2: _number(row[m2]), **row["_point"]})
        return ev.u_of(row["_point"])

    u_a = take(f"best {m1}")
    ev.aim(m2, s2, constraints)
    more, _ = _search(ev, **{**search, "starts": 1}, first=u_a)
    runs.extend({**r, "question": f"best {m2}"} for r in more)
    if ev.best is not None:      # the best M2 that is not dominated: the best M1 at (nearly) that M2
        best2 = s2 * ev.best[0]
        c = Constraint(m2, ">=" if s2 > 0 else "<=", best2 - s2 * 1e-3 * abs(best2))
        ev.aim(m1, s1, [*constraints, c])
        more, _ = _search(ev, **{**search, "starts": 1}, first=ev.u_of(ev.rows[ev.best[1]]["_point"])
                          if ev.best is not None else None)
        runs.extend({**r, "question": f"best {m1} at {c.expression}"} for r in more)
    u_b = take(f"best {m2}")
    if u_a is not None and u_b is not None:
        a, b = found[0][m2], found[1][m2]
        u_prev = u_a
        for eps in np.linspace(a, b, points)[1:-1]:
            c = Constraint(m2, ">=" if s2 > 0 else "<=", float(eps))
            ev.aim(m1, s1, [*constraints, c])
            more, _ = _search(ev, **{**search, "starts": 1}, first=u_prev)
            runs.extend({**r, "question": f"best {m1} at {c.expression}"} for r in more)
            u_prev = take(f"{m2} {c.sense} {eps:.6g}") if ev.best is not None else u_prev
    front = [f for f in found if f["feasible"]]
    return sorted(front, key=lambda f: f[m2]) + [f for f in found if not f["feasible"]]


def _sensitivities(ev: _Evaluations, row: dict, constraints, active: float, fd_step: float, actuator) -> List[dict]:
    """The objective's sensitivity to each active constraint's bound and each variable at a
    bound (module text): KKT multipliers by least squares from forward differences at the
    optimum (steps into the box)."""
    from .parameters import parameter_unit
    from .sweep import METRIC_UNITS
    x = row["_point"]
    u = ev.u_of(x)
    act_c = [c for c in constraints if abs(c.margin(_number(row[c.metric]))) <= active]
    bounds = [(i, "lower" if u[i] <= active else "upper") for i in range(u.size) if u[i] <= active or u[i] >= 1 - active]
    if not act_c and not bounds:
        return []
    span = ev.hi - ev.lo
    f0 = _number(row[ev.objective])
    c0 = np.array([_number(row[c.metric]) for c in act_c])
    df, dc = np.zeros(u.size), np.zeros((len(act_c), u.size))
    try:
        for i in range(u.size):
            h = fd_step if u[i] + fd_step <= 1.0 else -fd_step
            v = u.copy()
            v[i] += h
            r1 = ev(v)
            if r1.get("error"):
                raise _Failed(r1["error"].split(" | ")[0])
            df[i] = (_number(r1[ev.objective]) - f0) / (h * span[i])
            dc[:, i] = (np.array([_number(r1[c.metric]) for c in act_c]) - c0) / (h * span[i])
    except (_Budget, _Failed) as e:
        return [{"note": f"not computed: {e}"}]
    A = np.column_stack([*dc, *[np.eye(u.size)[i] for i, _ in bounds]]) if (act_c or bounds) else np.zeros((u.size, 0))
    lam, *_ = np.linalg.lstsq(A, df, rcond=None)
    residual = float(np.linalg.norm(A @ lam - df) / max(np.linalg.norm(df), 1e-300))
    unit = METRIC_UNITS.get(ev.objective, "-")
    out = []
    for c, mu in zip(act_c, lam):
        out.append({"kind": "constraint", "bound": c.expression, "sensitivity": float(mu),
                    "unit": f"{unit} per {METRIC_UNITS.get(c.metric, '-')}",
                    "meaning": f"d {ev.objective} / d bound: the optimum's change per unit change of the bound"})
    for (i, side), nu in zip(bounds, lam[len(act_c):]):
        name = ev.names[i]
        vunit = parameter_unit(name, actuator) or VARIABLE.get(name, ("-",))[0]
        out.append({"kind": f"{side} bound", "bound": f"{name} {'>=' if side == 'lower' else '<='} "
                    f"{(ev.lo if side == 'lower' else ev.hi)[i]:g}", "sensitivity": float(nu),
                    "unit": f"{unit} per {vunit}",
                    "meaning": f"d {ev.objective} / d bound: the optimum's change per unit change of the bound"})
    for o in out:
        o["kkt_residual"] = residual
    return out


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
    if any(c.metric in ("max_field", "max_reverse_field") for c in constraints):
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


def _write_front(path, front: List[dict], pareto, names, actuator) -> None:
    """``pareto.csv``: the front's points, its two metrics and the variables, units in the
    header (mjeap.io.csvio's writer, whole or not at all)."""
    from .parameters import parameter_unit
    from ..io import csvio
    from ..io.outputs import replacing
    from .sweep import METRIC_UNITS
    (m1, _), (m2, _) = pareto
    unit = lambda n: METRIC_UNITS.get(n) or parameter_unit(n, actuator) or VARIABLE.get(n, ("-",))[0]  # noqa: E731
    keys = [m1, m2, *names]
    with replacing(path, "--out (pareto.csv)") as tmp, open(tmp, "w", newline="") as fh:
        w = csvio.writer(fh)
        w.writerow([f"{k} ({unit(k)})" for k in keys] + ["point"])
        for f in front:
            if f["feasible"]:
                w.writerow([f[k] for k in keys] + [f["kind"]])


def _draw(result: OptimizeResult, files, names, lo, hi, constraints, front, actuator) -> str:
    """Draw ``optimize.png`` (and ``pareto.png``) where matplotlib is installed; '' when
    drawn, else why not."""
    try:
        import matplotlib
    except ImportError:
        return "figures skipped: pip install -e '.[report]' for matplotlib"
    matplotlib.use("Agg")
    _draw_search(files["figure"], result, names, lo, hi, constraints, actuator)
    if front is not None:
        _draw_front(files["pareto_figure"], result, front, constraints)
    return ""


def _unit(name: str, actuator) -> str:
    from .parameters import parameter_unit
    from .sweep import METRIC_UNITS
    return METRIC_UNITS.get(name) or parameter_unit(name, actuator) or VARIABLE.get(name, ("-",))[0]


def _axis(ax, which: str, unit: str) -> None:
    from matplotlib.ticker import EngFormatter
    if unit not in ("-", ""):
        (ax.xaxis if which == "x" else ax.yaxis).set_major_formatter(EngFormatter(unit=unit.replace("^", "")))


def _draw_search(path, result: OptimizeResult, names, lo, hi, constraints, actuator) -> None:
    """optimize.png: a column per variable, a row for the objective and one per constrained
    metric; every evaluation (feasible filled, infeasible hollow), the optimum starred, each
    constraint's bound dashed (red where active), a variable's active bound a vertical line."""
    import matplotlib.pyplot as plt
    obj = result.objective["metric"]
    rows = list(dict.fromkeys([obj, *(c.metric for c in constraints)]))
    ok = [(p, m) for p, m, e in result.evaluated if not e]
    feas = [all(c.margin(_number(m[c.metric])) >= -1e-6 for c in constraints) for _, m in ok]
    fig, axes = plt.subplots(len(rows), len(names), figsize=(4.4 * len(names) + 0.6, 2.9 * len(rows) + 0.9),
                             squeeze=False, sharex="col")
    for j, name in enumerate(names):
        x = np.array([p[name] for p, _ in ok])
        for i, metric in enumerate(rows):
            ax = axes[i, j]
            y = np.array([_number(m[metric]) for _, m in ok])
            f = np.array(feas, bool)
            ax.scatter(x[f], y[f], s=12, color="0.55", label="search: feasible")
            ax.scatter(x[~f], y[~f], s=12, facecolors="none", edgecolors="0.6", label="search: infeasible")
            cut = [(p[name], _number(m[metric])) for p, m, e in result.slices.get(name, ()) if not e]
            if cut:
                ax.plot(*np.array(cut).T, "-", color="C0", lw=1.6,
                        label="through the optimum" if len(names) > 1 else "over the range")
            ax.plot([result.optimum[name]], [_number(result.metrics[metric])], "*", color="C3", ms=14,
                    label="optimum")
            for c, info in zip(constraints, result.constraints):
                if c.metric == metric:
                    ax.axhline(c.bound, ls="--", color="C3" if info["active"] else "0.5",
                               label=_pretty(c) + (" (active)" if info["active"] else ""))
            for side, b in (("lower", lo[j]), ("upper", hi[j])):
                if abs(result.optimum[name] - b) <= 1e-3 * (hi[j] - lo[j]):
                    ax.axvline(b, color="C2", lw=2, label=f"{side} bound of {name} (active)")
            _axis(ax, "y", _unit(metric, actuator))
            ax.set_ylabel(f"{metric}")
            if i == len(rows) - 1:
                from matplotlib.ticker import MaxNLocator
                _axis(ax, "x", _unit(name, actuator))
                ax.xaxis.set_major_locator(MaxNLocator(5))
                ax.set_xlabel(name)
            ax.grid(alpha=0.3)
            ax.legend(fontsize=7, loc="best")
    import textwrap
    sense = result.objective["sense"]
    title = f"mjeap optimize: {sense} {obj}" + (f" subject to {', '.join(_pretty(c) for c in constraints)}"
                                                if constraints else "")
    fig.suptitle(textwrap.fill(title, 90) + f"\nevery evaluation of the search ({len(result.evaluated)})", fontsize=9)
    fig.tight_layout()
    _save(fig, path, "--out (optimize.png)")


def _margins(metrics: dict, constraints) -> List[dict]:
    return [{"met": c.margin(_number(metrics[c.metric])) >= -1e-6} for c in constraints]


def _pretty(c: "Constraint") -> str:
    """A constraint with its bound in engineering notation and its metric's unit."""
    from matplotlib.ticker import EngFormatter
    unit = _unit(c.metric, None)
    bound = EngFormatter(unit=unit.replace("^", "") if unit not in ("-", "") else "", sep="\u00a0")(c.bound)
    return f"{c.metric} {'>=' if c.sense == '>=' else '<='} {bound}"


def _draw_front(path, result: OptimizeResult, pareto, constraints=()) -> None:
    """pareto.png: every evaluation (hollow where it violates a constraint) and the traced
    front between the two metrics."""
    import matplotlib.pyplot as plt
    (m1, s1), (m2, s2) = pareto
    fig, ax = plt.subplots(figsize=(6.4, 4.8))
    for feasible in (True, False):
        a = np.array([[_number(m[m1]), _number(m[m2])] for _, m, e in result.evaluated
                      if not e and all(c["met"] for c in _margins(m, constraints)) == feasible]).reshape(-1, 2)
        if feasible:
            ax.scatter(a[:, 1], a[:, 0], s=10, color="0.55", label="evaluations meeting the constraints")
        elif a.size:
            ax.scatter(a[:, 1], a[:, 0], s=10, facecolors="none", edgecolors="0.7", label="evaluations violating one")
    front = [f for f in result.pareto if f["feasible"]]
    ax.plot([f[m2] for f in front], [f[m1] for f in front], "o-", color="C3", label="Pareto front (epsilon-constraint)")
    for k, f in enumerate(front):
        if f["kind"].startswith("best"):
            last = k == len(front) - 1
            ax.annotate(f["kind"], (f[m2], f[m1]), textcoords="offset points", xytext=(-8 if last else 8, 8),
                        ha="right" if last else "left", fontsize=8)
    ax.margins(0.08)
    _axis(ax, "x", _unit(m2, None))
    _axis(ax, "y", _unit(m1, None))
    ax.set_xlabel(f"{m2} ({'maximised' if s2 > 0 else 'minimised'})")
    ax.set_ylabel(f"{m1} ({'maximised' if s1 > 0 else 'minimised'})")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title(f"mjeap optimize --pareto {m1},{m2}: {len(front)} points"
                 + (f"\nsubject to {', '.join(_pretty(c) for c in constraints)}" if constraints else ""), fontsize=10)
    fig.tight_layout()
    _save(fig, path, "--out (pareto.png)")


def _save(fig, path, name: str) -> None:
    import matplotlib.pyplot as plt
    from ..io.outputs import replacing
    try:
        with replacing(path, name) as tmp:
            fig.savefig(tmp, dpi=110, format="png")
    finally:
        plt.close(fig)


def _clean(v):
    try:
        return _number(v)
    except (TypeError, ValueError):
        return v
