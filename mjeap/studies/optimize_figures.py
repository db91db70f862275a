"""What an optimisation draws and tabulates with its result (:mod:`mjeap.studies.optimize`):
``optimize.png`` (the objective and each constrained metric over every variable, swept
through the optimum), ``pareto.png`` and ``pareto.csv`` (the traced front)."""
from __future__ import annotations

from typing import List

import numpy as np


from .parameters import VARIABLE
from .search import number

__all__ = ["draw", "write_front"]

def write_front(path, front: List[dict], pareto, names, actuator) -> None:
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


def draw(result, files, names, lo, hi, constraints, front, actuator) -> str:
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


def _draw_search(path, result, names, lo, hi, constraints, actuator) -> None:
    """optimize.png: a column per variable, a row for the objective and one per constrained
    metric; every evaluation (feasible filled, infeasible hollow), the optimum starred, each
    constraint's bound dashed (red where active), a variable's active bound a vertical line."""
    import matplotlib.pyplot as plt
    obj = result.objective["metric"]
    rows = list(dict.fromkeys([obj, *(c.metric for c in constraints)]))
    ok = [(p, m) for p, m, e in result.evaluated if not e]
    feas = [all(c.margin(number(m[c.metric])) >= -1e-6 for c in constraints) for _, m in ok]
    fig, axes = plt.subplots(len(rows), len(names), figsize=(4.4 * len(names) + 0.6, 2.9 * len(rows) + 0.9),
                             squeeze=False, sharex="col")
    for j, name in enumerate(names):
        x = np.array([p[name] for p, _ in ok])
        for i, metric in enumerate(rows):
            ax = axes[i, j]
            y = np.array([number(m[metric]) for _, m in ok])
            f = np.array(feas, bool)
            ax.scatter(x[f], y[f], s=12, color="0.55", label="search: feasible")
            ax.scatter(x[~f], y[~f], s=12, facecolors="none", edgecolors="0.6", label="search: infeasible")
            cut = [(p[name], number(m[metric])) for p, m, e in result.slices.get(name, ()) if not e]
            if cut:
                ax.plot(*np.array(cut).T, "-", color="C0", lw=1.6,
                        label="through the optimum" if len(names) > 1 else "over the range")
            ax.plot([result.optimum[name]], [number(result.metrics[metric])], "*", color="C3", ms=14,
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
    return [{"met": c.margin(number(metrics[c.metric])) >= -1e-6} for c in constraints]


def _pretty(c) -> str:
    """A constraint with its bound in engineering notation and its metric's unit."""
    from matplotlib.ticker import EngFormatter
    unit = _unit(c.metric, None)
    bound = EngFormatter(unit=unit.replace("^", "") if unit not in ("-", "") else "", sep="\u00a0")(c.bound)
    return f"{c.metric} {'>=' if c.sense == '>=' else '<='} {bound}"


def _draw_front(path, result, pareto, constraints=()) -> None:
    """pareto.png: every evaluation (hollow where it violates a constraint) and the traced
    front between the two metrics."""
    import matplotlib.pyplot as plt
    (m1, s1), (m2, s2) = pareto
    fig, ax = plt.subplots(figsize=(6.4, 4.8))
    for feasible in (True, False):
        a = np.array([[number(m[m1]), number(m[m2])] for _, m, e in result.evaluated
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
