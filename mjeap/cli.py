"""The ``mjeap`` command line."""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import Callable, List, Optional

import numpy as np

from .errors import MjeapError, ParameterError


def _fmt(v: float) -> str:
    return f"{v:.4g}"


def cmd_list(args) -> int:
    from .model.catalog import CATALOG
    width = max(len(k) for k in CATALOG)
    for a in CATALOG.values():
        print(f"{a.id:<{width}}  {a.title}  [{a.document}]")
    return 0


def describe(name: str) -> dict:
    """Every parameter of a catalog actuator with unit and provenance, plus derived values."""
    from .model import analytical
    from .model.catalog import get_actuator
    from .simulation.scene import Scene
    a = get_actuator(name)
    layers = []
    for l in a.layers:
        layers.append({
            "name": l.name, "material": l.material,
            "thickness": (l.thickness, "m", l.provenance("thickness")),
            "width": (l.width if l.width is not None else "planform", "m", l.provenance("width")),
            "youngs_modulus": (l.youngs_modulus, "Pa", l.provenance("youngs_modulus")),
            "poisson_ratio": (l.poisson_ratio, "-", l.provenance("poisson_ratio")),
            "density": (l.density, "kg/m^3", l.provenance("density")),
        })
    p = a.planform
    sec = a.section_at(0.0)
    EI0 = float(a.flexural_rigidity_at(0.0)[0])
    mu = a.total_mass() / a.length
    uniform = p.base_width == p.tip_width
    f1_formula = float(analytical.natural_frequencies(a.length, EI0, mu, n=1)[0]) if uniform else None
    scene = Scene(a)
    c = scene.choice
    return {
        "id": a.id, "title": a.title, "document": a.document, "layers": layers,
        "planform": {"length": (p.length, "m", p.source), "base_width": (p.base_width, "m", p.source),
                     "tip_width": (p.tip_width, "m", p.source),
                     "extension_length": (p.extension_length, "m", p.extension_source),
                     "extension_mass": (p.extension_mass, "kg", p.extension_source),
                     "residual_tip_mass": (p.residual_tip_mass, "kg", p.residual_source)},
        "overrides": {k: (getattr(a, k).value, getattr(a, k).unit, getattr(a, k).source)
                      for k in ("flexural_rigidity", "mass") if getattr(a, k) is not None},
        "damping_ratio": (a.damping_ratio.value, "-", a.damping_ratio.source),
        "voltage_range": (list(a.voltage_range), "V", a.voltage_source),
        "plane_strain": (a.plane_strain, "-", a.plane_strain_source),
        "derived": {
            "flexural_rigidity_clamp": (EI0, "N m^2", "identified" if a.flexural_rigidity else "multilayer_section"),
            "flexural_rigidity_tip": (float(a.flexural_rigidity_at(a.length)[0]), "N m^2", ""),
            "neutral_axis": (sec.neutral_axis, "m from the bottom face", "multilayer_section"),
            "thickness": (a.thickness, "m", ""),
            "mass": (a.total_mass(), "kg", "measured" if a.mass else "layers x planform"),
            "first_frequency_uniform_beam": (f1_formula, "Hz", "Euler-Bernoulli" if uniform else "tapered: n/a"),
            "first_frequency_model": (c.first_frequency, "Hz", f"MuJoCo hinge chain, {scene.layout.segments} segments"),
            "highest_frequency_model": (c.highest_frequency, "Hz", "highest discrete mode"),
            "stability_limit": (c.stability_limit, "s", f"{c.integrator}, Rayleigh beta = {c.rayleigh_beta:.3g} s"),
            "default_timestep": (c.timestep, "s", c.reason),
        },
    }


def cmd_show(args) -> int:
    d = describe(args.name)
    if args.json:
        print(json.dumps(d, indent=2, default=str))
        return 0
    print(f"{d['id']}: {d['title']}\n  source: {d['document']}\n\nlayers (bottom to top):")
    for l in d["layers"]:
        print(f"  {l['name']} ({l['material']})")
        for k in ("thickness", "width", "youngs_modulus", "poisson_ratio", "density"):
            v, u, s = l[k]
            print(f"    {k:<16} {v if isinstance(v, str) else _fmt(v):>12} {u:<7} {s}")

    def block(title, items):
        print(f"\n{title}:")
        for k, (v, u, s) in items.items():
            vs = "-" if v is None else (_fmt(v) if isinstance(v, float) else str(v))
            print(f"  {k:<30} {vs:>12} {u:<8} {s}")

    block("planform", d["planform"])
    if d["overrides"]:
        block("identified values (override the layers)", d["overrides"])
    block("model parameters", {k: d[k] for k in ("damping_ratio", "voltage_range", "plane_strain")})
    block("derived", d["derived"])
    return 0


def _scene_from_args(args):
    from .model.discretize import Payload
    from .simulation.scene import Scene
    payload = Payload.parse(args.payload) if args.payload else None
    return Scene(args.name, representation=args.representation, segments=args.segments,
                 orientation=args.orientation, payload=payload, timestep=args.timestep,
                 integrator=args.integrator)


def cmd_mjcf(args) -> int:
    scene = _scene_from_args(args)
    xml = scene.to_xml()
    if args.output in (None, "-"):
        sys.stdout.write(xml)
    else:
        from .io.outputs import replacing
        with replacing(args.output, "--output") as tmp:
            tmp.write_text(xml)
        c = scene.choice
        print(f"wrote {args.output}: {scene.representation}, {scene.layout.segments} segments, "
              f"timestep {c.timestep:.3g} s ({c.reason})", file=sys.stderr)
    return 0


def _params(pairs) -> dict:
    params = {}
    for kv in pairs or []:
        k, sep, v = kv.partition("=")
        if not sep or not k.strip() or not v.strip():
            raise ParameterError("--param", kv, "NAME=VALUE, e.g. --param gain=63")
        try:
            params[k] = json.loads(v)
        except json.JSONDecodeError:
            params[k] = v
    return params


def cmd_rollout(args) -> int:
    from .simulation.rollout import rollout
    from .simulation.accuracy import check_accuracy
    if args.accuracy is not None:
        check_accuracy(args.accuracy)
        for flag, given in (("--timestep", args.timestep), ("--estimate-error", args.estimate_error or None)):
            if given is not None:
                raise ParameterError(flag, given, f"no {flag} with --accuracy (the target chooses the model and "
                                     "estimates its error)")
    scene = _scene_from_args(args)
    params = _params(args.param)
    r = rollout(scene, args.voltage, args.duration, drive=args.drive, drive_params=params,
                initial_curvature=args.initial_curvature, rrd=args.rrd, csv_path=args.csv,
                progress=None if not args.quiet else False, engine=args.engine, max_steps=args.max_steps,
                accuracy=args.accuracy, estimate_error=args.estimate_error)
    summary = {"actuator": scene.actuator.id, "drive": r.meta["drive"], "engine": r.meta["engine"],
               "engine_reason": r.meta.get("engine_reason", ""),
               "voltage": args.voltage,
               "duration_s": args.duration, "segments": r.meta["scene"]["segments"],
               "integrator": r.meta["scene"]["integrator"], "timestep_s": r.meta["scene"]["timestep"],
               "steps": r.meta["steps"],
               "wall_time_s": round(r.meta["wall_time_s"], 3),
               "tip_curvature_final_per_m": float(r.tip_curvature[-1]),
               "tip_curvature_peak_to_peak_per_m": r.peak_to_peak(),
               "tip_deflection_final_m": float(r.tip_position[-1, 1]),
               "rrd": args.rrd, "csv": args.csv}
    if "accuracy" in r.meta:
        a = r.meta["accuracy"]
        summary["accuracy"] = {"quantity": a["quantity"], "target": a["target"],
                               "estimated_error": a["estimated_error"], "estimate": a["estimate"]}
        if a["target"] is not None:
            summary["accuracy"].update(predicted_error=a["predicted_error"], runs=len(a["runs"]),
                                       wall_time_all_runs_s=round(a["wall_time_s"], 3))
    if r.meta.get("warnings"):
        summary["warnings"] = r.meta["warnings"]
        for w in r.meta["warnings"]:
            print(f"mjeap: warning: {w}", file=sys.stderr)
    print(json.dumps(summary, indent=2))
    return 0


def cmd_validate(args) -> int:
    from .validation import report, run_validation
    exps = run_validation(args.experiments, out=args.out, quick=args.quick, progress=not args.quiet)
    print(report.console_table(exps))
    checks = [c for e in exps for c in e.checks]
    failed = [c for c in checks if c.verdict == "FAIL"]
    tol = sum(c.tolerance is not None for c in checks)
    print(f"\n{len(checks)} rows, {tol} with a tolerance: {tol - len(failed)} pass, {len(failed)} fail"
          + (f"; report in {args.out}" if args.out else ""))
    for c in failed:
        print(f"FAIL {c.experiment}: {c.quantity}: {c.simulated:.6g} vs {c.reference:.6g} {c.unit} ({c.source})")
    return 1 if failed else 0


def cmd_identify_step(args) -> int:
    from .analysis.identify import fit_step_response, read_columns
    d = read_columns(args.file, [args.time_column, args.curvature_column])
    fit = fit_step_response(d[args.time_column], d[args.curvature_column], args.voltage, args.t_step)
    out = {"fit": "kappa(t) = A + B exp(-p t) + C exp(-a t)", "A_per_m": fit.A, "B_per_m": fit.B, "C_per_m": fit.C,
           "transfer_function": f"K/V = {fit.gain:.4g} (s + {fit.zero:.4g}) / ((s + {fit.pole_mechanical:.4g})"
                                f"(s + {fit.pole_electrical:.4g}))",
           "initial_curvature_per_m": fit.initial_curvature, "rms_residual_per_m": fit.rms_residual,
           "drive": "rc-relaxation", "drive_parameters": fit.drive_parameters(),
           "use": "mjeap rollout ACTUATOR --drive rc-relaxation " +
                  " ".join(f"--param {k}={v:.6g}" for k, v in fit.drive_parameters().items())}
    print(json.dumps(out, indent=2))
    return 0


def cmd_identify_hinges(args) -> int:
    from .analysis.identify import fit_hinge_parameters, read_columns
    scene = _scene_from_args(args)
    d = read_columns(args.file, [args.time_column, args.tip_column])
    fit = fit_hinge_parameters(scene, d[args.time_column], d[args.tip_column], args.voltage, drive=args.drive,
                               drive_params=_params(args.param))
    print(json.dumps({"stiffness_N_m_per_rad": fit.stiffness, "stiffness_std": fit.stiffness_std,
                      "damping_N_m_s_per_rad": fit.damping, "damping_std": fit.damping_std,
                      "rms_residual_m": fit.rms_residual, "simulations": fit.evaluations,
                      "segments": scene.layout.segments}, indent=2))
    return 0


def add_scene_args(p: argparse.ArgumentParser) -> None:
    from .model.mjcf import REPRESENTATIONS
    from .model.discretize import ORIENTATIONS
    from .simulation.scene import DEFAULT_SEGMENTS, INTEGRATORS
    p.add_argument("name", help="catalog id (see `mjeap list`)")
    p.add_argument("--segments", type=int, default=DEFAULT_SEGMENTS, help="number of segments (>= 2)")
    p.add_argument("--representation", choices=REPRESENTATIONS, default="hinge")
    p.add_argument("--payload", help="tip payload MASS@POSITION[,point|,r=RADIUS|,I=INERTIA], e.g. 12.6mg@6.27mm "
                   "(NdFeB sphere) or 12.6mg@6.27mm,point (no rotary inertia)")
    p.add_argument("--orientation", choices=ORIENTATIONS, default="horizontal")
    p.add_argument("--timestep", type=float, help="timestep in s (default: chosen from the model)")
    p.add_argument("--integrator", choices=list(INTEGRATORS), default=None,
                   help="default: the representation's own (implicitfast; the rod: discrete)")


def _value(text: str):
    """A number if it parses as one, else the text (actuator ids, orientations, ...)."""
    try:
        return float(text)
    except ValueError:
        return text


def _sweep_values(spec: str, random: bool):
    """NAME=a,b,c (list) | NAME=lo:hi:n (n values, linspace) | NAME=lo..hi (random range)."""
    name, sep, rhs = spec.partition("=")
    if not sep or not rhs:
        raise ParameterError("--vary", spec, "NAME=a,b,c or NAME=lo:hi:n (grid) or NAME=lo..hi (with --random)")
    name = name.strip()
    form = "NAME=a,b,c or NAME=lo:hi:n (grid) or NAME=lo..hi (with --random)"
    try:
        if ".." in rhs:
            if not random:
                raise ParameterError("--vary", spec, "a range lo..hi only with --random N")
            lo, hi = (float(x) for x in rhs.split(".."))
            return name, (lo, hi)
        if ":" in rhs:
            lo, hi, n = rhs.split(":")
            if int(n) < 1:
                raise ValueError("n < 1")
            return name, [float(x) for x in np.linspace(float(lo), float(hi), int(n))]
    except ValueError as e:
        if isinstance(e, ParameterError):
            raise
        raise ParameterError("--vary", spec, form + " with numbers (n a positive integer)") from None
    return name, [_value(v) for v in rhs.split(",")]


def cmd_sweep(args) -> int:
    from . import sweep
    values = dict(_sweep_values(v, args.random is not None) for v in (args.vary or []))
    if not values:
        raise ParameterError("--vary", None, "at least one NAME=VALUES")
    points = sweep.random_design(args.random, args.seed, **values) if args.random is not None else \
        sweep.grid(**values)
    base = {k: _value(v) for k, v in (kv.partition("=")[::2] for kv in (args.set or []))}
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


def cmd_robot(args) -> int:
    from .robots import get
    return get(args.name).main(args.options) or 0


def build_parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(prog="mjeap", description=__doc__)
    sub = ap.add_subparsers(dest="command", required=True)
    sub.add_parser("list", help="list the catalog").set_defaults(func=cmd_list)
    p = sub.add_parser("show", help="parameters, provenance and derived values of an actuator")
    p.add_argument("name")
    p.add_argument("--json", action="store_true")
    p.set_defaults(func=cmd_show)
    p = sub.add_parser("mjcf", help="write the MJCF model of an actuator")
    add_scene_args(p)
    p.add_argument("-o", "--output", help="output file (default: stdout)")
    p.set_defaults(func=cmd_mjcf)
    p = sub.add_parser("rollout", help="run an actuator with its drive and record it")
    add_scene_args(p)
    p.add_argument("--voltage", required=True,
                   help="waveform, e.g. step:3V, square:1.5V@0.1Hz, sine:50V@100Hz,offset=100V, csv:FILE")
    p.add_argument("--duration", type=float, required=True, help="simulated time (s)")
    p.add_argument("--drive", help="drive name (default: the actuator's own)")
    p.add_argument("--param", action="append", metavar="KEY=VALUE", help="drive parameter (repeatable)")
    p.add_argument("--initial-curvature", type=float, default=0.0, help="start as a uniform arc (1/m)")
    p.add_argument("--rrd", help="write a Rerun recording here")
    p.add_argument("--csv", help="write the time series here")
    from .engines import ENGINES
    p.add_argument("--max-steps", type=int, default=None,
                   help="refuse runs of more steps than this (default 20,000,000: minutes of work)")
    p.add_argument("--engine", choices=ENGINES, default="auto",
                   help="'loop' (Python lockstep), 'threaded' (mujoco.rollout; open-loop drives only) or "
                        "'auto' (threaded where it applies; default)")
    p.add_argument("--accuracy", type=float, default=None,
                   help="largest error of the tip curvature relative to its swing (1e-5 to 0.2): segments, "
                        "integrator and timestep are chosen for it and the error is estimated (mjeap.accuracy)")
    p.add_argument("--estimate-error", action="store_true",
                   help="without --accuracy: estimate this model's error with a coarser companion run")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(func=cmd_rollout)
    p = sub.add_parser("robot",
                       help="run a robot's experiment (mjeap.robots): gripper, hamr-leg, hamr-walk, robobee-wing",
                       description="Run a registered robot's experiment; its options follow the name "
                                   "(mjeap robot NAME --help).")
    p.add_argument("name", help="a registered robot (mjeap.robots.names())")
    p.add_argument("options", nargs=argparse.REMAINDER, help="the robot experiment's own options")
    p.set_defaults(func=cmd_robot)
    p = sub.add_parser("validate", help="run the validation experiments; report, figures and recordings")
    p.add_argument("experiments", nargs="*", help="experiment names or prefixes (default: all)")
    p.add_argument("--out", default="out/validation", help="report folder (default: out/validation)")
    p.add_argument("--quick", action="store_true", help="fewer bisection steps and representations")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(func=cmd_validate)
    p = sub.add_parser("sweep", help="parameter study: rollouts reduced to metrics, streamed to CSV, resumable")
    p.add_argument("--vary", action="append", metavar="NAME=VALUES",
                   help="a,b,c | lo:hi:n (grid) | lo..hi (with --random); NAME is a point parameter "
                        "(actuator, payload_mass, amplitude, frequency, segments, ...) or drive.NAME (repeatable)")
    p.add_argument("--set", action="append", metavar="NAME=VALUE", help="fixed parameter for every point (repeatable)")
    p.add_argument("--random", type=int, metavar="N", help="N random points instead of the full grid")
    p.add_argument("--seed", type=int, default=0, help="seed of the random design")
    p.add_argument("--metrics", default="peak_to_peak,returns",
                   help="comma list: peak_to_peak, returns, settling_time, max_stress_proxy, max_tip_deflection")
    p.add_argument("--out", default="out/sweep.csv", help="results CSV (appended; finished points are skipped)")
    from .sweep import EXECUTORS
    p.add_argument("--executor", choices=EXECUTORS, default="processes")
    p.add_argument("--workers", type=int, default=2, help="worker processes (local pool or Dask LocalCluster)")
    p.add_argument("--scheduler", help="Dask scheduler address (tcp://host:8786); default: a LocalCluster")
    p.add_argument("--record", help="comma list of point indices that also write a .rrd")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(func=cmd_sweep)
    p = sub.add_parser("identify", help="fit the papers' models to measured data (CSV with a header)")
    isub = p.add_subparsers(dest="what", required=True)
    q = isub.add_parser("step", help="seed 000: transfer function from a curvature step response")
    q.add_argument("file")
    q.add_argument("--voltage", type=float, required=True, help="step amplitude (V)")
    q.add_argument("--t-step", type=float, default=0.0, help="time of the step (s)")
    q.add_argument("--time-column", default="time")
    q.add_argument("--curvature-column", default="tip_curvature")
    q.set_defaults(func=cmd_identify_step)
    q = isub.add_parser("hinges", help="seed 001: joint stiffness and damping from a tip trajectory")
    add_scene_args(q)
    q.add_argument("file")
    q.add_argument("--voltage", required=True, help="the waveform applied during the measurement")
    q.add_argument("--drive", help="drive name (default: the actuator's own)")
    q.add_argument("--param", action="append", metavar="KEY=VALUE", help="drive parameter (repeatable)")
    q.add_argument("--time-column", default="time")
    q.add_argument("--tip-column", default="tip_y", help="tip deflection column (m)")
    q.set_defaults(func=cmd_identify_hinges)
    return ap


# ---------------------------------------------------------------- running a command
#: exit codes of an interrupted command: 128 + the signal's number, as a shell reports it
EXIT_CTRL_C, EXIT_SIGTERM = 130, 143


def run_command(call: Callable[[], Optional[int]], prog: str = "mjeap") -> int:
    """Run ``call()`` as a command and return its exit code (None: 0). mjeap's own errors
    print one line, ``PROG: error: ...``, and exit 2. Ctrl-C or SIGTERM, anywhere in the
    command (:class:`~mjeap.errors.sigterm_as_interrupt`), print one line and exit 130 /
    143, without a traceback; what was written stays (a rollout writes its recording and
    CSV on its way out, a sweep has its finished rows)."""
    from .errors import Terminated, sigterm_as_interrupt
    try:
        with sigterm_as_interrupt():
            code = call()
    except MjeapError as e:
        print(f"{prog}: error: {e}", file=sys.stderr)
        for note in getattr(e, "__notes__", ()):      # e.g. an output that could not be written too
            print(f"{prog}: error: {note}", file=sys.stderr)
        return 2
    except KeyboardInterrupt as e:
        term = isinstance(e, Terminated)
        print(f"{prog}: interrupted ({'SIGTERM' if term else 'Ctrl-C'}); stopped, outputs written so far are kept",
              file=sys.stderr)
        for note in getattr(e, "__notes__", ()):
            print(f"{prog}: error: {note}", file=sys.stderr)
        return EXIT_SIGTERM if term else EXIT_CTRL_C
    return 0 if code is None else int(code)


def run_script(main: Callable[[Optional[List[str]]], Optional[int]], argv: Optional[List[str]] = None) -> int:
    """A script's ``main(argv)`` as a command (:func:`run_command`), named after the script:
    ``sys.exit(run_script(main))``."""
    return run_command(lambda: main(argv), Path(sys.argv[0]).name or "mjeap")


# ---------------------------------------------------------------- argparse checks for scripts
def _argument_type(check: Callable[[str], object]) -> Callable[[str], object]:
    """An argparse ``type=``: ``check(text)``, its ParameterError told the argparse way
    (usage, ``argument --NAME: 'TEXT' is not accepted: expected ...``, exit 2), at parse
    time, so before any work."""
    def convert(text: str):
        try:
            return check(text)
        except ParameterError as e:
            raise argparse.ArgumentTypeError(f"{text!r} is not accepted: expected {e.accepted}"
                                             + (f" ({e.why})" if e.why else "")) from None
    convert.__name__ = getattr(check, "__name__", "value")
    return convert


def arg_integer(lo: int, hi: Optional[int] = None, why: str = ""):
    """argparse ``type=``: an integer in [lo, hi] (:func:`mjeap.errors.check_integer`)."""
    from .errors import check_integer
    return _argument_type(lambda text: check_integer("", text, lo, hi, why))


def arg_number(lo: float, hi: float, unit: str = "", lo_open: bool = False, hi_open: bool = False):
    """argparse ``type=``: a number in the interval (:func:`mjeap.errors.check_range`)."""
    from .errors import check_range
    return _argument_type(lambda text: check_range("", text, lo, hi, unit, lo_open, hi_open))


def arg_output(inside: Optional[str] = None):
    """argparse ``type=``: an output path that can be written (its folder made now), or,
    with ``inside``, a folder in which the file ``inside`` can be written
    (:func:`mjeap.rollout.check_outputs`). Returns the text."""
    from .io.outputs import check_outputs

    def check(text: str) -> str:
        check_outputs(out=Path(text) / inside if inside else text)
        return text
    return _argument_type(check)


def parse_args(ap: argparse.ArgumentParser, argv: Optional[List[str]] = None,
               check: Optional[Callable[[argparse.Namespace], None]] = None) -> argparse.Namespace:
    """``ap.parse_args(argv)``, then ``check(args)``: checks across arguments that raise
    ParameterError, refused as argparse refuses a bad argument (usage, one line, exit 2)."""
    args = ap.parse_args(argv)
    if check is not None:
        try:
            check(args)
        except ParameterError as e:
            ap.error(str(e))
    return args


def main(argv: Optional[List[str]] = None) -> int:
    def command() -> int:
        args = build_parser().parse_args(argv)
        return args.func(args)
    return run_command(command)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
