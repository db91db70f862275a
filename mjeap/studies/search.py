"""An optimisation's search (:mod:`mjeap.studies.optimize`): its evaluations of points in the
box scaled to [0, 1]^n (:class:`Evaluations`: each point once, read back from the CSV or run
as a sweep point), scipy's SLSQP and differential evolution on them (:func:`search`), the
variables swept through the optimum (:func:`slices`), the Pareto front by the
epsilon-constraint method (:func:`trace_front`) and the optimum's sensitivities, KKT
multipliers from forward differences (:func:`sensitivities`)."""
from __future__ import annotations

import dataclasses

import math
from typing import Dict, List, Optional, Tuple

import numpy as np

from ..errors import MjeapError

from .constraints import Constraint
from .parameters import VARIABLE

__all__ = ["Box", "Goal", "SearchSettings", "Evaluations", "Budget", "Failed", "number", "readback", "clean", "search", "slices", "trace_front",
           "sensitivities"]

@dataclasses.dataclass(frozen=True)
class Box:
    """The varied parameters (sorted by name) and their bounds ``lo``, ``hi`` (SI)."""

    names: Tuple[str, ...]
    lo: np.ndarray
    hi: np.ndarray


@dataclasses.dataclass(frozen=True)
class Goal:
    """What an optimisation asks: maximise (``sign`` 1) or minimise (-1) ``objective`` subject
    to ``constraints``; ``feasibility``: the relative violation a met constraint may have;
    ``active``: how near its bound an active one lies (relative)."""

    objective: str
    sign: float
    constraints: Tuple[Constraint, ...]
    feasibility: float
    active: float


@dataclasses.dataclass(frozen=True)
class SearchSettings:
    """How the search runs (module :mod:`mjeap.studies.optimize`'s text): ``method``, its
    ``starts`` and ``seed``, SLSQP's ``tol``, ``fd_step`` and ``maxiter``, differential
    evolution's ``popsize`` and ``de_tol``, and ``max_evaluations`` over all starts."""

    method: str
    starts: int
    seed: int
    tol: float
    fd_step: float
    maxiter: int
    popsize: int
    de_tol: float
    max_evaluations: int


class Budget(MjeapError):
    """The evaluation budget is spent."""


class Failed(MjeapError):
    """An evaluation failed (its row's error): the start that asked for it stops."""


def number(v) -> float:
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


class Evaluations:
    """The evaluations of one optimisation: points by their u in [0, 1]^n, each evaluated
    once (:func:`mjeap.studies.sweep.evaluate`, serial, in this process) or read from the CSV,
    appended to it as they finish."""

    def __init__(self, box: Box, goal: Goal, *, metrics, base, cached, out, columns, max_evaluations: int, bar):
        self.names, self.lo, self.hi = list(box.names), np.asarray(box.lo, float), np.asarray(box.hi, float)
        self.metrics, self.base, self.cached, self.out, self.columns = metrics, base, cached, out, columns
        self.max_evaluations, self.bar = max_evaluations, bar
        self.objective, self.sign, self.constraints = goal.objective, goal.sign, list(goal.constraints)
        self.feasibility = goal.feasibility
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
            raise Budget(f"the budget of {self.max_evaluations} evaluations is spent")
        if pid in self.cached:
            row = dict(self.cached[pid])
            self.read += 1
        else:
            row = evaluate(p, self.metrics, self.base)
            row.pop("_error_model", None)
            row.pop("_field", None)                  # the box's fields are optimize's own check
            if self.out is not None:
                self.out.write([row.get(k, "") for k in self.columns], len(self.cached) + self.run)
            self.run += 1
            row = {**row, **{m: readback(row[m]) for m in self.metrics}}
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
            f = self.sign * number(row[self.objective])
            margins = [c.margin(number(row[c.metric])) for c in self.constraints]
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
        raises Failed."""
        row = self(u)
        if row.get("error"):
            raise Failed(f"{row['error'].split(' | ')[0]} (at {row['_point']})")
        f = -self.sign * number(row[self.objective]) / self.scale
        g = np.array([c.margin(number(row[c.metric])) for c in self.constraints])
        if not math.isfinite(f) or not np.all(np.isfinite(g)):
            raise Failed(f"a metric is not a number at {row['_point']}")
        return f, g


def readback(v):
    """A metric's value as the CSV gives it back (so a rerun from the cache is the same)."""
    from ..io.csvio import plain_cell
    if isinstance(v, (float, np.floating)):
        return float(repr(float(v)))
    return plain_cell(v)


def _fd(ev: Evaluations, u: np.ndarray, h: float):
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


def _slsqp(ev: Evaluations, u0, fd_step, tol, maxiter):
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


def _differential_evolution(ev: Evaluations, seed, tol, budget, popsize):
    """scipy's differential_evolution on [0, 1]^n (Latin hypercube, seeded), no polish (SLSQP
    polishes after it), at most ``budget`` evaluations; ``tol`` its convergence tolerance
    (the population's spread of the objective relative to its mean)."""
    from scipy.optimize import NonlinearConstraint, differential_evolution
    n = len(ev.names)
    big = 1e30

    def f(u):
        try:
            return ev.values(u)[0]
        except Failed:
            return big

    def g(u):
        try:
            return ev.values(u)[1]
        except Failed:
            return np.full(len(ev.constraints), -big)

    kw = {}
    if ev.constraints:
        kw["constraints"] = NonlinearConstraint(g, 0.0, np.inf)
    gens = max(1, budget // (popsize * n) - 1)
    return differential_evolution(f, [(0.0, 1.0)] * n, seed=seed, maxiter=gens, popsize=popsize, tol=tol,
                                  init="latinhypercube", polish=False, updating="immediate", **kw)


def search(ev: Evaluations, settings: SearchSettings, first=None) -> Tuple[List[dict], List[str]]:
    """One question's search over ``ev`` (aimed at it): SLSQP from ``first`` (a u) or the
    box's centre and ``starts - 1`` seeded points, or differential evolution polished by
    SLSQP (``settings``). Returns the starts' reports and messages; the budget spent ends it."""
    method, starts, seed, tol, fd_step = settings.method, settings.starts, settings.seed, settings.tol, settings.fd_step
    maxiter, popsize, de_tol, max_evaluations = settings.maxiter, settings.popsize, settings.de_tol, \
        settings.max_evaluations
    n = len(ev.names)
    runs, messages = [], []
    centre = np.full(n, 0.5)
    try:                               # the objective's scale: its magnitude at the box's centre
        f_c = number(ev(centre)[ev.objective]) if not ev(centre).get("error") else math.nan
    except Budget:
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
        except Budget as e:
            info.update(message=str(e), success=False)
            messages.append(str(e))
            info["evaluations"] = len(ev.rows) - before
            runs.append(info)
            break
        except Failed as e:
            info.update(message=f"stopped: an evaluation failed: {e}", success=False)
        info["evaluations"] = len(ev.rows) - before
        runs.append(info)
        messages.append(info["message"])
    return runs, messages


def slices(ev: Evaluations, u: np.ndarray, points: int) -> Dict[str, List[tuple]]:
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
            except Budget:
                break
            rows.append((r["_point"], {m: clean(r.get(m, "")) for m in ev.metrics}, r.get("error", "")))
        out[name] = rows
    return out


def trace_front(ev: Evaluations, pareto, constraints, points: int, settings: SearchSettings,
                runs: List[dict]) -> List[dict]:
    """The Pareto front between ``pareto`` ((M1, sign), (M2, sign)) by the epsilon-constraint
    method (module text), ``ev`` holding the best M1 already; each level starts from the
    previous optimum. Returns the front's points, sorted along M2."""
    (m1, s1), (m2, s2) = pareto
    one = dataclasses.replace(settings, starts=1)
    found = []

    def take(kind):
        pick = ev.best
        if pick is None:
            found.append({"kind": kind, "feasible": False})
            return None
        row = ev.rows[pick[1]]
        found.append({"kind": kind, "feasible": True, m1: number(row[m1]), m2: number(row[m2]), **row["_point"]})
        return ev.u_of(row["_point"])

    u_a = take(f"best {m1}")
    ev.aim(m2, s2, constraints)
    more, _ = search(ev, one, first=u_a)
    runs.extend({**r, "question": f"best {m2}"} for r in more)
    if ev.best is not None:      # the best M2 that is not dominated: the best M1 at (nearly) that M2
        best2 = s2 * ev.best[0]
        c = Constraint(m2, ">=" if s2 > 0 else "<=", best2 - s2 * 1e-3 * abs(best2))
        ev.aim(m1, s1, [*constraints, c])
        more, _ = search(ev, one, first=ev.u_of(ev.rows[ev.best[1]]["_point"])
                          if ev.best is not None else None)
        runs.extend({**r, "question": f"best {m1} at {c.expression}"} for r in more)
    u_b = take(f"best {m2}")
    if u_a is not None and u_b is not None:
        a, b = found[0][m2], found[1][m2]
        u_prev = u_a
        for eps in np.linspace(a, b, points)[1:-1]:
            c = Constraint(m2, ">=" if s2 > 0 else "<=", float(eps))
            ev.aim(m1, s1, [*constraints, c])
            more, _ = search(ev, one, first=u_prev)
            runs.extend({**r, "question": f"best {m1} at {c.expression}"} for r in more)
            u_prev = take(f"{m2} {c.sense} {eps:.6g}") if ev.best is not None else u_prev
    front = [f for f in found if f["feasible"]]
    return sorted(front, key=lambda f: f[m2]) + [f for f in found if not f["feasible"]]


def sensitivities(ev: Evaluations, row: dict, constraints, active: float, fd_step: float, actuator) -> List[dict]:
    """The objective's sensitivity to each active constraint's bound and each variable at a
    bound (module text): KKT multipliers by least squares from forward differences at the
    optimum (steps into the box)."""
    from .parameters import parameter_unit
    from .sweep import METRIC_UNITS
    x = row["_point"]
    u = ev.u_of(x)
    act_c = [c for c in constraints if abs(c.margin(number(row[c.metric]))) <= active]
    bounds = [(i, "lower" if u[i] <= active else "upper") for i in range(u.size) if u[i] <= active or u[i] >= 1 - active]
    if not act_c and not bounds:
        return []
    span = ev.hi - ev.lo
    f0 = number(row[ev.objective])
    c0 = np.array([number(row[c.metric]) for c in act_c])
    df, dc = np.zeros(u.size), np.zeros((len(act_c), u.size))
    try:
        for i in range(u.size):
            h = fd_step if u[i] + fd_step <= 1.0 else -fd_step
            v = u.copy()
            v[i] += h
            r1 = ev(v)
            if r1.get("error"):
                raise Failed(r1["error"].split(" | ")[0])
            df[i] = (number(r1[ev.objective]) - f0) / (h * span[i])
            dc[:, i] = (np.array([number(r1[c.metric]) for c in act_c]) - c0) / (h * span[i])
    except (Budget, Failed) as e:
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


def clean(v):
    try:
        return number(v)
    except (TypeError, ValueError):
        return v
