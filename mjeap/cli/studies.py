"""The study commands: ``mjeap sweep`` and ``optimize``."""
from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

from ..errors import ParameterError
from .common import distinct, once


def _value(text: str):
    """A number if it parses as one, else the text (actuator ids, orientations, ...)."""
    try:
        return float(text)
    except ValueError:
        return text


def _sweep_values(spec: str, random: bool, actuator=None):
    """NAME=a,b,c (list) | NAME=lo:hi:n (n values, linspace) | NAME=lo..hi (random range);
    values SI or with the parameter's unit (``actuator.length=8mm:16mm:5``,
    :func:`mjeap.studies.parameters.to_value`; ``actuator`` resolves drive.NAME's units)."""
    from ..studies.parameters import to_value
    name, sep, rhs = spec.partition("=")
    if not sep or not rhs:
        raise ParameterError("--vary", spec, "NAME=a,b,c or NAME=lo:hi:n (grid) or NAME=lo..hi (with --random)")
    name = name.strip()
    form = "NAME=a,b,c or NAME=lo:hi:n (grid) or NAME=lo..hi (with --random)"
    num = lambda x: float(to_value(name, x.strip(), actuator))       # noqa: E731
    try:
        if ".." in rhs:
            if not random:
                raise ParameterError("--vary", spec, "a range lo..hi only with --random N")
            lo, hi = (num(x) for x in rhs.split(".."))
            return name, (lo, hi)
        if ":" in rhs:
            lo, hi, n = rhs.split(":")
            if int(n) < 1:
                raise ValueError("n < 1")
            from ..studies.sweep import check_design_size       # the count, checked before the values are made
            check_design_size(int(n), "--vary", f"{spec}: {int(n):,} values of {name}")
            return name, [float(x) for x in np.linspace(num(lo), num(hi), int(n))]
    except ValueError as e:
        if isinstance(e, ParameterError):
            raise
        raise ParameterError("--vary", spec, form + " with numbers (n a positive integer)") from None
    return name, [to_value(name, v.strip(), actuator) for v in rhs.split(",")]


def cmd_sweep(args) -> int:
    from ..studies import sweep
    from ..studies.parameters import to_value
    raw = once("--set", args.set)
    distinct(once("--vary", args.vary, "NAME=a,b,c or NAME=lo:hi:n (grid) or NAME=lo..hi (with --random)"), raw)
    actuator = raw.get("actuator", sweep.PARAMETERS["actuator"])
    values = dict(_sweep_values(v, args.random is not None, actuator) for v in (args.vary or []))
    if not values:
        raise ParameterError("--vary", None, "at least one NAME=VALUES")
    points = sweep.random_design(args.random, args.seed, **values) if args.random is not None else \
        sweep.grid(**values)
    base = {k: to_value(k, v, actuator) for k, v in raw.items()}
    if args.accuracy is not None:
        from ..simulation.accuracy import check_accuracy
        if "accuracy" in raw:
            raise ParameterError("--accuracy", args.accuracy, "either --accuracy or --set accuracy=..., not both")
        base["accuracy"] = check_accuracy(args.accuracy)
    try:
        record = [int(i) for i in args.record.split(",")] if args.record else []
    except ValueError:
        raise ParameterError("--record", args.record, "comma-separated point indices, e.g. --record 0,5") from None
    if Path(args.out).is_dir():
        raise ParameterError("--out", args.out, "a CSV file path (it is a directory)")
    s = sweep.run_sweep(points, args.out, metrics=args.metrics.split(","), base=base, executor=args.executor,
                        workers=args.workers, scheduler=args.scheduler, record=record,
                        progress=False if args.quiet else None)
    print(json.dumps({"results": str(s.path), "points": len(points), "ran": s.done, "skipped (already in the file)":
                      s.skipped, "failed": s.failed, "wall_s": round(s.wall_s, 3),
                      "rollouts_per_s": round(s.throughput, 3) if s.done else None}, indent=2))
    if s.done and s.failed == s.done:
        errors = {}
        for row in sweep.read_results(s.path):
            if row.get("error"):
                errors[row["error"].split(" | ")[0]] = errors.get(row["error"].split(" | ")[0], 0) + 1
        print(f"mjeap sweep: every point that ran failed ({s.failed}):", file=sys.stderr)
        for e, n in sorted(errors.items(), key=lambda x: -x[1])[:5]:
            print(f"  {n} x {e}", file=sys.stderr)
        return 1
    return 0


def cmd_optimize(args) -> int:
    from ..studies.optimize import optimize
    from ..studies.parameters import to_value
    vary = once("--vary", args.vary, "NAME=LOW:HIGH, e.g. actuator.length=5mm:15mm")
    for name, rhs in vary.items():
        if not rhs:
            raise ParameterError("--vary", f"{name}=", "NAME=LOW:HIGH, e.g. actuator.length=5mm:15mm")
    raw = once("--set", args.set)
    distinct(vary, raw)
    base = {k: to_value(k, v, args.name) for k, v in raw.items()}
    r = optimize(args.name, vary, maximize=args.maximize, minimize=args.minimize, subject_to=args.subject_to or (),
                 voltage=args.voltage, duration=args.duration, base=base,
                 metrics=[m for m in (args.metrics or "").split(",") if m], method=args.method, starts=args.starts,
                 seed=args.seed, max_evaluations=args.max_evaluations, out=args.out,
                 progress=False if args.quiet else None, pareto=args.pareto, pareto_points=args.pareto_points)
    print(json.dumps(r.as_dict(), indent=2, default=float))
    if not r.success:
        print(f"mjeap optimize: {r.message}", file=sys.stderr)
    return 0 if r.success else 1


def add_parsers(sub) -> None:
    """This module's commands on the command line (``sub``: its subparsers)."""
    p = sub.add_parser("sweep", help="parameter study: rollouts reduced to metrics, streamed to CSV, resumable")
    p.add_argument("--vary", action="append", metavar="NAME=VALUES",
                   help="a,b,c | lo:hi:n (grid) | lo..hi (with --random), SI or with a unit (8mm:16mm:5); NAME is a "
                        "point parameter (actuator, payload_mass, amplitude, frequency, segments, ...), drive.NAME or "
                        "actuator.NAME (actuator.length, actuator.layers.LAYER.thickness, ...; repeatable)")
    p.add_argument("--set", action="append", metavar="NAME=VALUE", help="fixed parameter for every point (repeatable)")
    p.add_argument("--accuracy", type=float, default=None,
                   help="error target of every point's metrics (1e-5 to 0.2, as --set accuracy=...): on "
                        "peak_to_peak, returns, ... each relative to its scale, estimates in estimated_error.METRIC "
                        "columns (docs/concepts/accuracy.md)")
    p.add_argument("--random", type=int, metavar="N", help="N random points instead of the full grid")
    p.add_argument("--seed", type=int, default=0, help="seed of the random design")
    p.add_argument("--metrics", default="peak_to_peak,returns",
                   help="comma list: peak_to_peak, returns, settling_time, max_stress_proxy, max_tip_deflection, "
                        "first_frequency, mass, free_deflection, blocked_force, energy_density (a step's), stroke (a "
                        "periodic drive's), peak_power, energy_per_cycle, max_field, max_reverse_field, max_stress, "
                        "capacitance (piezo drives), resonance_frequency, antiresonance_frequency, coupling_factor, "
                        "tip_per_volt_at")
    p.add_argument("--out", default="out/sweep.csv", help="results CSV (appended; finished points are skipped)")
    from ..studies.sweep import EXECUTORS
    p.add_argument("--executor", choices=EXECUTORS, default="processes")
    p.add_argument("--workers", type=int, default=2, help="worker processes (local pool or Dask LocalCluster)")
    p.add_argument("--scheduler", help="Dask scheduler address (tcp://host:8786); default: a LocalCluster")
    p.add_argument("--record", help="comma list of point indices that also write a .rrd")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(func=cmd_sweep)
    p = sub.add_parser("optimize", help="design optimisation: maximise or minimise a metric over bounded actuator, "
                       "drive and payload parameters, subject to constraints (scipy)")
    p.add_argument("name", help="the base actuator: catalog id or actuator file (.toml)")
    p.add_argument("--vary", action="append", metavar="NAME=LOW:HIGH", required=True,
                   help="a bounded parameter, SI or with a unit: actuator.length=5mm:15mm, "
                        "actuator.roles.piezo.thickness=100um:150um, drive.bias=100:200, payload_mass=0:5mg (repeatable)")
    goal = p.add_mutually_exclusive_group(required=True)
    goal.add_argument("--maximize", metavar="METRIC", help="the metric to maximise (free_deflection, blocked_force, "
                      "energy_density, stroke, first_frequency, ...)")
    goal.add_argument("--minimize", metavar="METRIC", help="the metric to minimise (mass, peak_power, max_field, ...)")
    goal.add_argument("--pareto", metavar="M1,M2", help="trace the front between two metrics (each maximised; "
                      "min:NAME minimises), e.g. free_deflection,blocked_force: pareto.csv and pareto.png")
    p.add_argument("--pareto-points", type=int, default=7, help="points of the front (default 7)")
    p.add_argument("--subject-to", action="append", metavar="EXPR",
                   help='a constraint "METRIC>=VALUE" or "METRIC<=VALUE", SI or with the metric\'s unit: '
                        '"first_frequency>=800Hz", "max_field<=1V/um" (repeatable)')
    p.add_argument("--voltage", help="waveform of the rollouts the metrics need: step:200V, sine:50V@100Hz,offset=100V")
    p.add_argument("--duration", type=float, help="simulated time of each rollout (s; a step needs one)")
    p.add_argument("--set", action="append", metavar="NAME=VALUE",
                   help="a fixed sweep setting (segments, orientation, payload_mass, ...; repeatable)")
    p.add_argument("--metrics", help="more metrics to record at every evaluation (comma list)")
    from ..studies.optimize import METHODS
    p.add_argument("--method", choices=METHODS, default="slsqp",
                   help="slsqp (local, from the box's centre and --starts - 1 seeded points; default) or "
                        "differential-evolution (global, then polished by SLSQP)")
    p.add_argument("--starts", type=int, default=3, help="SLSQP starts: the centre and seeded points (default 3)")
    p.add_argument("--seed", type=int, default=0, help="seed of the starts / the evolution")
    p.add_argument("--max-evaluations", type=int, default=400, help="at most this many evaluations (default 400)")
    p.add_argument("--out", default="out/optimize",
                   help="folder for result.json, evaluations.csv (a rerun reads it as a cache), optimum.toml "
                        "(least-infeasible.toml where no point meets the constraints) and, with the report extra, "
                        "optimize.png (and pareto.csv, pareto.png)")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(func=cmd_optimize)
