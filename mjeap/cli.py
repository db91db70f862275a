"""The ``mjeap`` command line."""
from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path
from typing import List, Optional

import numpy as np

from .errors import ParameterError, printable
from .io.commandline import arg_number, run_command


def _fmt(v: float) -> str:
    return f"{v:.4g}"


def cmd_list(args) -> int:
    from .model.catalog import CATALOG
    width = max(len(k) for k in CATALOG)
    for a in CATALOG.values():
        print(f"{a.id:<{width}}  {a.title}  [{a.document}]")
    return 0


def _actuator(name):
    """The actuator a command names (catalog id or file), read before any work; a layer value
    outside its material's range (RangeWarning) or a size outside a plausible one
    (GeometryWarning) is told as one line, ``mjeap: warning: ...``."""
    import warnings
    from .model.actuator import GeometryWarning
    from .model.catalog import get_actuator
    from .model.materials import RangeWarning
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        act = get_actuator(name)
    for w in caught:
        if issubclass(w.category, (RangeWarning, GeometryWarning)):
            print(f"mjeap: warning: {printable(w.message)}", file=sys.stderr)
        else:
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
    return act


def _actuator_file_of(a) -> str:
    """Where ``a`` comes from: its file, or the catalog's file of a catalog id."""
    from .model.catalog import CATALOG_DIR
    return a.source_file or f"{CATALOG_DIR / (a.id + '.toml')} (catalog)"


def drive_rows(a) -> dict:
    """The actuator's own drive and each of its parameters as (value, unit, source, origin):
    origin 'file' (the actuator's [drive.parameters]), 'generic' (the drive's default: the
    file gives none) or 'missing' (no default: a run must give it)."""
    from .drives import default_drive_name, get_drive_class
    name = default_drive_name(a)
    cls = get_drive_class(name)
    units, defaults = cls.parameter_units(), cls.defaults_for(a)
    own = a.drive_parameters if a.drive == name else {}
    rows = {}
    for k in dict.fromkeys([*defaults, *units]):
        if k in own:
            rows[k] = (own[k][0], units.get(k, "-"), own[k][2], "file")
        elif k in defaults:
            rows[k] = (defaults[k][0], defaults[k][1], defaults[k][2], "generic")
        else:
            rows[k] = (None, units[k], "no value: give it in the file's [drive.parameters] or drive_params", "missing")
    return {"name": name, "model": cls.model_used, "parameters": rows}


#: the designer's first numbers `mjeap show` prints (and --json keys), in this order
DESIGN_KEYS = ("first_frequency", "free_deflection", "blocked_force", "capacitance", "blocked_capacitance",
               "energy_density", "mass")
#: which capacitance a datasheet gives, and what Jayaram et al. 2018 measured (section 3)
CAPACITANCE_NOTE = ("a datasheet's permittivity eps33^T (constant stress) gives the free capacitance; Jayaram et al. "
                    "2018 measured the fixed (blocked) capacitance of Type II at less than half the 16 nF that value "
                    "gives (section 3)")


def describe(name: str) -> dict:
    """Every parameter of an actuator (catalog id or file) with unit and provenance, its
    drive's parameters with theirs, derived values and the designer's first numbers
    (:data:`DESIGN_KEYS`, :func:`mjeap.studies.design_numbers.design_numbers`)."""
    from .studies.design_numbers import design_numbers
    from .model import analytical
    from .model.laminate import piezo_layers
    from .simulation.scene import Scene
    a = _actuator(name)
    piezo = {p.index: p for p in piezo_layers(a)}
    layers = []
    for i, l in enumerate(a.layers):
        layers.append({
            "name": l.name, "material": l.material,
            "thickness": (l.thickness, "m", l.provenance("thickness")),
            "width": (l.width if l.width is not None else "planform", "m",
                      l.provenance("width") if l.width is not None else "the planform's width"),
            "youngs_modulus": (l.youngs_modulus, "Pa", l.provenance("youngs_modulus")),
            "poisson_ratio": (l.poisson_ratio, "-", l.provenance("poisson_ratio")),
            "density": (l.density, "kg/m^3", l.provenance("density")),
        })
        pz = piezo.get(i)
        if pz is not None and a.drive == "piezo":
            layers[-1].update({
                "d31": (pz.d31, "m/V", pz.sources.get("d31", "none given")),
                "relative_permittivity": (pz.relative_permittivity, "-", pz.sources.get("relative_permittivity",
                                                                                         "none given")),
                "electrode": (pz.electrode, "-", "signal: V; complement: bias - V"),
                "poling": (pz.poling, "-", "the sign of the free strain d31 V / t")})
    p = a.planform
    sec = a.section_at(0.0)
    EI0 = float(a.flexural_rigidity_at(0.0)[0])
    mu = a.total_mass() / a.length
    uniform = p.base_width == p.tip_width
    f1_formula = float(analytical.natural_frequencies(a.length, EI0, mu, n=1)[0]) if uniform else None
    scene = Scene(a)
    c = scene.choice
    numbers = design_numbers(a)
    return {
        **{k: numbers[k] for k in DESIGN_KEYS}, "warnings": numbers["warnings"],
        "id": a.id, "title": a.title, "document": a.document, "file": _actuator_file_of(a), "layers": layers,
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
        "drive": drive_rows(a),
        "derived": {
            "flexural_rigidity_clamp": (EI0, "N m^2", "identified" if a.flexural_rigidity else "multilayer_section"),
            "flexural_rigidity_tip": (float(a.flexural_rigidity_at(a.length)[0]), "N m^2", ""),
            "neutral_axis": (sec.neutral_axis, "m from the bottom face", "multilayer_section"),
            "thickness": (a.thickness, "m", ""),
            "mass": (numbers["mass"][0], "kg", ("measured beam" if a.mass else "layers x planform")
                     + " and the rigid tip block (as the mass metric and mass above)"),
            "first_frequency_uniform_beam": (f1_formula, "Hz", "Euler-Bernoulli" if uniform else "tapered: n/a"),
            "first_frequency_model": (c.first_frequency, "Hz", f"MuJoCo hinge chain, {scene.layout.segments} segments"),
            "highest_frequency_model": (c.highest_frequency, "Hz", "highest discrete mode"),
            "stability_limit": (c.stability_limit, "s", f"{c.integrator}, Rayleigh beta = {c.rayleigh_beta:.3g} s"),
            "default_timestep": (c.timestep, "s", c.reason),
        },
    }


def _printable_tree(x):
    """``x`` (dicts, lists, tuples of values) with every string :func:`~mjeap.errors.printable`."""
    if isinstance(x, str):
        return printable(x)
    if isinstance(x, dict):
        return {printable(k): _printable_tree(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return type(x)(_printable_tree(v) for v in x)
    return x


def cmd_show(args) -> int:
    d = describe(args.name)
    if args.json:                      # JSON escapes control characters itself (and all non-ASCII)
        print(json.dumps(d, indent=2, default=str))
        return 0
    d = _printable_tree(d)             # every string from the user's file, safe on a terminal
    for w in d["warnings"]:
        print(f"mjeap: warning: {w}", file=sys.stderr)
    print(f"{d['id']}: {d['title']}\n  source: {d['document']}\n  file: {d['file']}\n\nlayers (bottom to top):")
    for l in d["layers"]:
        print(f"  {l['name']} ({l['material']})")
        for k in ("thickness", "width", "youngs_modulus", "poisson_ratio", "density", "d31",
                  "relative_permittivity", "electrode", "poling"):
            if k not in l:
                continue
            v, u, s = l[k]
            v = "-" if v is None else v
            print(f"    {k:<21} {v if isinstance(v, str) else _fmt(v):>12} {u:<7} {s}")

    def block(title, items):
        print(f"\n{title}:")
        for k, (v, u, s) in items.items():
            vs = "-" if v is None else (_fmt(v) if isinstance(v, float) else str(v))
            print(f"  {k:<30} {vs:>12} {u:<8} {s}")

    block("at the voltage range (closed forms, no rollout)", {k: d[k] for k in DESIGN_KEYS})
    if d["capacitance"][0] is not None:
        print(f"  ({CAPACITANCE_NOTE})")
    block("planform", d["planform"])
    if d["overrides"]:
        block("identified values (override the layers)", d["overrides"])
    block("model parameters", {k: d[k] for k in ("damping_ratio", "voltage_range", "plane_strain")})
    _print_drive(d["drive"])
    block("derived", d["derived"])
    return 0


def _print_drive(drv: dict) -> None:
    """The drive's parameters, those not in the file marked (the drive's generic values)."""
    print(f"\ndrive {drv['name']} ({drv['model']}):" if drv["model"] else f"\ndrive {drv['name']}:")
    marks = {"file": "  ", "generic": "* ", "missing": "! "}
    for k, (v, u, s, origin) in drv["parameters"].items():
        vs = "-" if v is None else (_fmt(v) if isinstance(v, (int, float)) and not isinstance(v, bool) else str(v))
        print(f"{marks[origin]}{k:<30} {vs:>12} {u:<8} {s}")
    origins = {r[3] for r in drv["parameters"].values()}
    if "generic" in origins:
        print("  * the drive's generic value: the actuator's file gives none")
    if "missing" in origins:
        print("  ! no value: a run must give it (the file's [drive.parameters] or --param)")
    if not drv["parameters"]:
        print("  (no parameters)")


def cmd_materials(args) -> int:
    """The materials library: a table, one material in full, or JSON."""
    from .model import materials as mat
    names = [mat.get_material(args.name).name] if args.name else mat.material_names()
    if args.json:
        print(json.dumps({n: material_record(mat.get_material(n)) for n in names}, indent=2))
        return 0
    if args.name:
        m = mat.get_material(args.name)
        print(f"{m.name}: {m.title}" + (f"\n  {m.notes}" if m.notes else ""))
        for k in (*mat.PROPERTIES, *(mat.PIEZO_PROPERTIES if m.piezo else ())):
            p = m.property(k)
            rng = f"[{_fmt(p.range[0])}, {_fmt(p.range[1])}]"
            print(f"  {k:<21} {_fmt(p.value):>9} {p.unit:<7} range {rng}  {p.source}")
        return 0
    keys = ("youngs_modulus", "density", "poisson_ratio")
    rows = [["material", "E (Pa)", "range", "density (kg/m^3)", "range", "nu", "range", "title"]]
    for n in names:
        m = mat.get_material(n)
        ps = [m.property(k) for k in keys]
        rows.append([m.name, *[c for p in ps for c in (_fmt(p.value), f"[{_fmt(p.range[0])}, {_fmt(p.range[1])}]")],
                     m.title])
    widths = [max(len(r[i]) for r in rows) for i in range(len(rows[0]) - 1)]
    for r in rows:
        print("  ".join(c.rjust(w) if i in (1, 3, 5) else c.ljust(w) for i, (c, w) in enumerate(zip(r, widths)))
              + "  " + r[-1])
    piezo = [n for n in names if mat.get_material(n).piezo]
    if piezo:
        print(f"\npiezoelectric (d31, permittivity, coercive field, recommended field, tensile strength): "
              f"{', '.join(piezo)}")
    print("\nsources: mjeap materials NAME (or --json); a layer names one with material = \"NAME\" in an actuator file")
    return 0


def material_record(m) -> dict:
    """A material as JSON: title, notes, each property's value, unit, range and source."""
    from .model.materials import PIEZO_PROPERTIES, PROPERTIES
    return {"title": m.title, "notes": m.notes,
            **{k: {"value": m.property(k).value, "unit": m.property(k).unit, "range": list(m.property(k).range),
                   "source": m.property(k).source} for k in (*PROPERTIES, *(PIEZO_PROPERTIES if m.piezo else ()))}}


def _scene_from_args(args, units=None):
    from .model.discretize import Payload
    from .simulation.scene import Scene
    payload = Payload.parse(args.payload) if args.payload else None
    from .simulation.scene import DEFAULT_SEGMENTS
    return Scene(_actuator(args.name), representation=args.representation,
                 segments=DEFAULT_SEGMENTS if args.segments is None else args.segments,
                 orientation=args.orientation, payload=payload, timestep=args.timestep,
                 integrator=args.integrator, units=units)


def cmd_mjcf(args) -> int:
    """The driven model file (mm, mg, s; actuator 'drive' in V where the drive compiles in)."""
    from .io.outputs import check_outputs
    from .simulation.model_file import model_file
    from .simulation.scene import input_files
    from .units import REAL_TIME_UNITS
    to_file = args.output not in (None, "-")
    if to_file:                                    # before any work: never a link, never the actuator file
        check_outputs(inputs=input_files([args.name]), **{"--output": args.output})
    scene = _scene_from_args(args, REAL_TIME_UNITS)
    f = model_file(scene)
    xml = f"<!-- {scene.actuator.id}: {f.note} Units: {scene.units.describe()}. -->\n" + f.spec.to_xml()
    if not to_file:
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
        # the target chooses segments, integrator and timestep: each given alongside it is refused alike
        for flag, given in (("--segments", args.segments), ("--integrator", args.integrator),
                            ("--timestep", args.timestep), ("--estimate-error", args.estimate_error or None)):
            if given is not None:
                raise ParameterError(flag, given, f"no {flag} with --accuracy (the target chooses the model and "
                                     "estimates its error)")
    from .io.outputs import check_outputs
    from .simulation.scene import input_files
    # before any work (the scene's build too): never a link, never the actuator file or the waveform's CSV
    check_outputs(inputs=input_files([args.name], [args.voltage]), rrd=args.rrd, csv_path=args.csv)
    scene = _scene_from_args(args)
    params = _params(args.param)
    r = rollout(scene, args.voltage, args.duration, drive=args.drive, drive_params=params,
                initial_curvature=args.initial_curvature, rrd=args.rrd, csv_path=args.csv,
                progress=False if args.quiet else ("lines" if args.progress else None), engine=args.engine,
                max_steps=args.max_steps,
                accuracy=args.accuracy, estimate_error=args.estimate_error)
    summary = {"actuator": scene.actuator.id, "actuator_file": scene.actuator.source_file,
               "drive": r.meta["drive"], "engine": r.meta["engine"],
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


#: where mjeap frf writes frf.csv, frf.json and frf.png unless told (--out)
FRF_OUT = "out/frf"


def _report_extra() -> bool:
    import importlib.util
    return importlib.util.find_spec("matplotlib") is not None


def cmd_frf(args) -> int:
    """Small-signal frequency response: frf.csv, frf.json (what was computed, how) and, with
    the report extra, frf.png, all in --out; checked before any work."""
    from .analysis import frf
    from .io.outputs import check_outputs, replacing
    f0, f1, n = frf.check_sweep(args.start, args.stop, args.points)
    folder = Path(args.out or FRF_OUT)
    if folder.exists() and not folder.is_dir():
        raise ParameterError("--out", str(folder), "a folder for frf.csv, frf.json and frf.png", "it is a file")
    paths = {"--out (frf.csv)": folder / "frf.csv", "--out (frf.json)": folder / "frf.json"}
    plot = _report_extra()
    if plot:
        paths["--out (frf.png)"] = folder / "frf.png"
    from .model.actuator_file import is_actuator_file
    # names mjeap picks in --out: regular files or none, never a link, never the actuator file
    check_outputs(inputs={"actuator file": args.name if is_actuator_file(args.name) else None}, picked=paths, **paths)
    scene = _scene_from_args(args)
    r = frf.frequency_response(scene, f0, f1, n, offset=args.offset, drive=args.drive, drive_params=_params(args.param))
    out = r.summary()
    out["files"] = {"csv": str(paths["--out (frf.csv)"]), "json": str(paths["--out (frf.json)"]),
                    "png": str(folder / "frf.png") if plot else "not written: the report extra (matplotlib) is not "
                                                                 "installed (pip install 'mjeap[report]')"}
    frf.write_frf(r, paths["--out (frf.csv)"])
    with replacing(paths["--out (frf.json)"], "--out (frf.json)", picked=True) as tmp:
        tmp.write_text(json.dumps(out, indent=2, default=float), encoding="utf-8")
    if plot:
        frf.plot_frf(r, folder / "frf.png")
    if r.admittance is None:
        print(f"mjeap frf: admittance columns left empty: {r.admittance_reason}", file=sys.stderr)
    print(json.dumps(out, indent=2, default=float))
    return 0


#: where mjeap identify writes the identified actuator file unless told (--out)
IDENTIFIED = "out/identified.toml"


def _identified_out(args, act, stack, data=()) -> str:
    """The identified file's path (--out, default IDENTIFIED: a name mjeap picks), checked and
    locked for the run before any work (``stack``: an ExitStack holding the lock): a
    writable path other than the run's inputs, the actuator file it comes from (a
    hand-written file's comments and units would be lost) and the data file (the
    measurements, ``data``: (name, path) pairs). A second identify on the same --out is
    refused at once."""
    from .io.outputs import run_guard
    out = args.out or IDENTIFIED
    inputs = [("actuator file", act.source_file if act is not None else None), *data]
    stack.enter_context(run_guard(inputs=inputs, picked=() if args.out else ("--out",), **{"--out": out}))
    return out


def _write_identified(act, out: str) -> str:
    """Write ``act`` to ``out`` whole or not at all (mjeap.io.outputs.replacing), once its
    drive was built on it (an identified value the drive refuses is never written) and its
    text read back as an actuator file (what cannot be read back is never put in place)."""
    from .drives import make_drive
    from .io.outputs import replacing
    from .model.actuator_file import actuator_toml
    from .simulation.scene import Scene
    from .model.actuator_file import read_actuator
    make_drive(None, Scene(act, segments=2, gravity=False))
    text = actuator_toml(act)
    with replacing(out, "--out", picked=out == IDENTIFIED) as tmp:
        tmp.write_text(text, encoding="utf-8")
        read_actuator(tmp.with_name(tmp.name))   # what is written reads back, or it is not put in place
    return out


def cmd_identify_step(args) -> int:
    from contextlib import ExitStack
    with ExitStack() as stack:
        return _identify_step(args, stack)


def _identify_step(args, stack) -> int:
    from .analysis.identify import fit_step_response, given_rows, read_columns, step_actuator, step_rows
    from .analysis.identify import check_identification
    act = given = None
    if args.actuator is not None:       # the file to put the fit in: checked before any work
        act = _actuator(args.actuator)
        check_identification(act, "step")
        given = given_rows(_params(args.param), "mjeap identify step")
        step_rows(act, given)
        out_path = _identified_out(args, act, stack, [("data file", args.file)])
    else:
        for flag, v in (("--out", args.out), ("--param", args.param)):
            if v is not None:
                raise ParameterError(flag, v if flag == "--out" else " ".join(v),
                                     f"{flag} only with --actuator (the actuator file the identified parameters go in)")
    d = read_columns(args.file, [args.time_column, args.curvature_column],
                     units={args.time_column: "s", args.curvature_column: "1/m"})
    fit = fit_step_response(d[args.time_column], d[args.curvature_column], args.voltage, args.t_step)
    from .analysis.file_fit import check_residual
    warning = check_residual(fit.rms_residual, float(np.ptp(d[args.curvature_column])), "identify step",
                             "nothing written" if act is None else f"nothing written to {out_path}")
    out = {"fit": "kappa(t) = A + B exp(-p t) + C exp(-a t)", "A_per_m": fit.A, "B_per_m": fit.B, "C_per_m": fit.C,
           "transfer_function": f"K/V = {fit.gain:.4g} (s + {fit.zero:.4g}) / ((s + {fit.pole_mechanical:.4g})"
                                f"(s + {fit.pole_electrical:.4g}))",
           "initial_curvature_per_m": fit.initial_curvature, "rms_residual_per_m": fit.rms_residual,
           "drive": "rc-relaxation", "drive_parameters": fit.drive_parameters(),
           "use": "mjeap rollout ACTUATOR --drive rc-relaxation " +
                  " ".join(f"--param {k}={v:.6g}" for k, v in fit.drive_parameters().items())}
    if warning:
        out["warning"] = warning
        print(f"mjeap: warning: {warning}", file=sys.stderr)
    if act is not None:
        out["actuator_file"] = _write_identified(step_actuator(act, fit, args.file, given), out_path)
        out["use"] = f"mjeap rollout {out_path} --voltage step:{args.voltage:g}V --duration ..."
    print(json.dumps(out, indent=2))
    return 0


def cmd_identify_hinges(args) -> int:
    """The beam's stiffness scale (EI(x) kept proportional to the file's), mass scale and
    damping ratio fitted to a tip trajectory with the file's own model
    (:mod:`mjeap.analysis.file_fit`); the identified file is the model that was fitted."""
    from contextlib import ExitStack
    with ExitStack() as stack:
        return _identify_hinges(args, stack)


def _identify_hinges(args, stack) -> int:
    from .analysis import file_fit, identify as ident
    scene = _scene_from_args(args)
    params = _params(args.param)
    given = ident.given_rows(params, "mjeap identify hinges")
    ident.file_drive_rows(scene.actuator, args.drive, given)        # checked before the fit, as is --out
    out_path = _identified_out(args, scene.actuator, stack, [("data file", args.file)])
    d = ident.read_columns(args.file, [args.time_column, args.tip_column],
                           units={args.time_column: "s", args.tip_column: "m"})
    t, y = d[args.time_column], d[args.tip_column]
    fit = file_fit.fit_tip_trajectory(scene, t, y, args.voltage, drive=args.drive, drive_params=params)
    act = file_fit.trajectory_actuator(scene, fit, args.file, drive=args.drive, given=given)
    EI = act.flexural_rigidity_at([0.0, act.length])
    out = {**fit.as_dict(), "rms_residual_m": fit.rms_residual, "residual_fraction": fit.rms_residual / fit.swing,
           "simulations": fit.evaluations, "segments": scene.layout.segments,
           "flexural_rigidity_clamp_N_m2": float(EI[0]), "flexural_rigidity_tip_N_m2": float(EI[1]),
           "mass_kg": act.total_mass(), "first_frequency_hz": file_fit_f1(scene, act)}
    warning = file_fit.check_residual(fit.rms_residual, fit.swing, "identified actuator",
                                      f"nothing written to {out_path}")
    out["identified_file_rms_m"] = fit.rms_residual
    if warning:
        out["warning"] = warning
        print(f"mjeap: warning: {warning}", file=sys.stderr)
    out["actuator_file"] = _write_identified(act, out_path)
    print(json.dumps(out, indent=2, default=float))
    return 0


def file_fit_f1(scene, act) -> float:
    """The first mode (Hz) of ``act`` built as ``scene`` is."""
    from .analysis.identify import _scene_like
    return float(_scene_like(scene, act).choice.first_frequency)


def cmd_identify_piezo(args) -> int:
    """A piezo bender's coupling, stiffness or tip mass, damping ratio, capacitance and
    resistance fitted to stroke, tip-FRF and impedance data (or a published resonance) with
    the file's own small-signal model (:mod:`mjeap.analysis.piezo_fit`)."""
    from contextlib import ExitStack
    with ExitStack() as stack:
        return _identify_piezo(args, stack)


def _identify_piezo(args, stack) -> int:
    from .analysis import file_fit, identify as ident, piezo_fit as pf
    from .analysis.frf import parse_frequency
    if not any((args.stroke, args.frf, args.impedance, args.resonance)):
        raise ParameterError("identify piezo", "no measurement", "at least one of --stroke, --frf, --impedance "
                             "(CSV files) or --resonance (a published first resonance, e.g. 1750Hz)")
    resonance = None if args.resonance is None else parse_frequency(args.resonance, "--resonance")
    scene = _scene_from_args(args)
    ident.check_identification(scene.actuator, "piezo")
    given = ident.given_rows(_params(args.param), "mjeap identify piezo")
    ident.file_drive_rows(scene.actuator, None, given)
    out_path = _identified_out(args, scene.actuator, stack, [(f"--{k} file", getattr(args, k))
                                                             for k in ("stroke", "frf", "impedance")])
    data = pf.PiezoData(
        stroke=None if args.stroke is None else pf.read_stroke(args.stroke, args.voltage_column, args.stroke_column),
        frf=None if args.frf is None else pf.read_frf(args.frf),
        impedance=None if args.impedance is None else (*pf.read_impedance(args.impedance), args.impedance_state),
        resonance=resonance,
        sources={"stroke": args.stroke, "frf": args.frf,
                 "impedance": f"{args.impedance} ({args.impedance_state} actuator)" if args.impedance else None,
                 "resonance": f"{args.resonance} (given: --resonance)"})
    fit = pf.fit_piezo(scene, data, drive_params=_params(args.param))
    act = pf.piezo_actuator(scene, fit, data, given)
    out = {"identified": {k: {"factor" if k != "damping_ratio" else "value": v, "std": fit.std[k]}
                          for k, v in fit.values.items()},
           "held": fit.held, "rms_residuals": fit.residuals, "derived": fit.derived, "evaluations": fit.evaluations}
    name = pf.COUPLING_PARAMETER[act.drive]
    out["file"] = {k: {"value": r[0], "source": r[2]} for k, r in act.drive_parameters.items()
                   if k in (name, "capacitance", "resistance")}
    out["file"].update({"damping_ratio": {"value": act.damping_ratio.value, "source": act.damping_ratio.source},
                        "tip_block_mass_kg": {"value": act.planform.tip_block_mass,
                                              "source": act.planform.residual_source},
                        "flexural_rigidity_clamp_N_m2": {"value": float(act.flexural_rigidity_at(0.0)[0]),
                                                         "source": act.layers[0].provenance("youngs_modulus")}})
    worst = max(fit.residuals, key=fit.residuals.get)
    warning = file_fit.check_residual(fit.residuals[worst], None, f"identify piezo ({worst})",
                                      f"nothing written to {out_path}")
    if warning:
        out["warning"] = f"{worst}: {warning}"
        print(f"mjeap: warning: {worst}: {warning}", file=sys.stderr)
    for k, why in fit.held.items():
        if k in ("stiffness", "tip_mass") and any(q in fit.values for q in ("stiffness", "tip_mass")):
            print(f"mjeap identify piezo: f1 fitted by the {'tip block mass' if k == 'stiffness' else 'modulus scale'}:"
                  f" {k} {why}", file=sys.stderr)
    out["actuator_file"] = _write_identified(act, out_path)
    print(json.dumps(out, indent=2, default=float))
    return 0


#: how a command's actuator argument reads
ACTUATOR_HELP = ("catalog id (mjeap list) or actuator file: a name ending in .toml or holding a path separator "
                 "is a file (./NAME for a file named like an id)")


def add_scene_args(p: argparse.ArgumentParser) -> None:
    from .model.mjcf import REPRESENTATIONS
    from .model.discretize import ORIENTATIONS
    from .simulation.scene import DEFAULT_SEGMENTS, INTEGRATORS
    p.add_argument("name", help=ACTUATOR_HELP)
    p.add_argument("--segments", type=int, default=None,
                   help=f"number of segments (>= 2; default {DEFAULT_SEGMENTS}; chosen by --accuracy where given)")
    p.add_argument("--representation", choices=REPRESENTATIONS, default="hinge")
    p.add_argument("--payload", help="tip payload MASS@POSITION[,point|,r=RADIUS|,I=INERTIA], e.g. 12.6mg@6.27mm "
                   "(NdFeB sphere) or 12.6mg@6.27mm,point (no rotary inertia); gravity loads it in the bending "
                   "plane only with --orientation up or down")
    p.add_argument("--orientation", choices=ORIENTATIONS, default="horizontal",
                   help="horizontal (default: the bending plane horizontal, gravity across the width, out of the "
                        "bending plane), up (the beam against gravity) or down (hanging along it)")
    p.add_argument("--timestep", type=float, help="timestep in s (default: chosen from the model)")
    p.add_argument("--integrator", choices=list(INTEGRATORS), default=None,
                   help="default: the representation's own (implicitfast; the rod: discrete)")


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
    from .studies.parameters import to_value
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
            from .studies.sweep import check_design_size       # the count, checked before the values are made
            check_design_size(int(n), "--vary", f"{spec}: {int(n):,} values of {name}")
            return name, [float(x) for x in np.linspace(num(lo), num(hi), int(n))]
    except ValueError as e:
        if isinstance(e, ParameterError):
            raise
        raise ParameterError("--vary", spec, form + " with numbers (n a positive integer)") from None
    return name, [to_value(name, v.strip(), actuator) for v in rhs.split(",")]


def _once(flag: str, specs, form: str = "NAME=VALUE") -> dict:
    """``NAME=VALUE`` options (``--set``, ``--vary``) as name -> value text, before any work:
    each NAME once (a repeated one would silently keep the last), none empty."""
    out = {}
    for spec in specs or []:
        name, sep, rhs = spec.partition("=")
        name = name.strip()
        if not sep or not name:
            raise ParameterError(flag, spec, form)
        if name in out:
            raise ParameterError(flag, spec, f"each NAME once ({name} is given twice: {flag} {name}={out[name]} "
                                 f"and {flag} {spec})")
        out[name] = rhs.strip()
    return out


def _distinct(vary: dict, fixed: dict) -> None:
    """A name varied (--vary) is not also fixed (--set)."""
    both = [n for n in vary if n in fixed]
    if both:
        raise ParameterError("--set", f"{both[0]}={fixed[both[0]]}", f"a setting that is not also varied "
                             f"(--vary {both[0]}=...)")


def cmd_sweep(args) -> int:
    from .studies import sweep
    from .studies.parameters import to_value
    raw = _once("--set", args.set)
    _distinct(_once("--vary", args.vary, "NAME=a,b,c or NAME=lo:hi:n (grid) or NAME=lo..hi (with --random)"), raw)
    actuator = raw.get("actuator", sweep.PARAMETERS["actuator"])
    values = dict(_sweep_values(v, args.random is not None, actuator) for v in (args.vary or []))
    if not values:
        raise ParameterError("--vary", None, "at least one NAME=VALUES")
    points = sweep.random_design(args.random, args.seed, **values) if args.random is not None else \
        sweep.grid(**values)
    base = {k: to_value(k, v, actuator) for k, v in raw.items()}
    if args.accuracy is not None:
        from .simulation.accuracy import check_accuracy
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
    from .studies.optimize import optimize
    from .studies.parameters import to_value
    vary = _once("--vary", args.vary, "NAME=LOW:HIGH, e.g. actuator.length=5mm:15mm")
    for name, rhs in vary.items():
        if not rhs:
            raise ParameterError("--vary", f"{name}=", "NAME=LOW:HIGH, e.g. actuator.length=5mm:15mm")
    raw = _once("--set", args.set)
    _distinct(vary, raw)
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


def cmd_view(args) -> int:
    """MuJoCo's viewer on an actuator (catalog id or .toml file) or an MJCF file."""
    from .simulation import viewer
    why = viewer.window_reason()                  # before any work
    if why is not None:
        raise viewer.NoDisplayError(f"mjeap view needs a display: {why}. Write the model instead: "
                                    f"mjeap mjcf {args.name} -o FILE, or use mjeap.assets.path(NAME)")
    from .robots import names as robot_names
    if args.name.lower().endswith(".xml"):
        vm = viewer.file_view_model(args.name, args.voltage)
    elif args.name in robot_names():
        from .robots import load
        vm = viewer.system_view_model(load(args.name), f"robot {args.name}")
    else:
        from .units import REAL_TIME_UNITS
        scene = _scene_from_args(args, REAL_TIME_UNITS)
        vm = viewer.view_model(scene, args.drive, _params(args.param), args.voltage)
        f1 = scene.choice.first_frequency
        if f1 / args.slow_motion > 20:
            print(f"mjeap view: a period of the first bending mode ({f1:.3g} Hz) lasts {args.slow_motion / f1:.2g} s "
                  f"on screen; --slow-motion {10 ** math.ceil(math.log10(f1 / 2)):g} shows it in ~0.5 s",
                  file=sys.stderr)
    print(f"mjeap view: {vm.note}; timestep {vm.timestep:.3g} s, {args.slow_motion:g}x slow motion", file=sys.stderr)
    out = viewer.view(vm, args.slow_motion)
    print(f"mjeap view: {out['simulated_s']:.4g} s simulated in {out['wall_s']:.4g} s"
          + (f", up to {out['max_lag_s']:.3g} s behind (raise --slow-motion)" if out["max_lag_s"] > 0.1 else ""),
          file=sys.stderr)
    return 0


def examples_dir() -> Path:
    """The examples as installed with the wheel (the package ``mjeap.examples_files``, mapped
    to the repository's ``examples`` by pyproject.toml), else the repository's folder."""
    here = Path(__file__).resolve().parent
    installed = here / "examples_files"
    return installed if installed.is_dir() else here.parent / "examples"


def cmd_examples(args) -> int:
    """Copy the examples (actuator files, the design study) into a folder, through mjeap's
    writer: a file there that differs is refused before anything is copied, never replaced."""
    from .io.outputs import check_outputs, replacing
    src = examples_dir()
    files = sorted(p.relative_to(src) for p in src.rglob("*") if p.is_file() and p.suffix in (".py", ".toml", ".csv")
                   and "__pycache__" not in p.parts)
    if not files:
        raise ParameterError("examples", str(src), "the examples installed with mjeap", "none found")
    dest = Path(args.dir)
    named = {f"DIR ({f})": dest / f for f in files}
    check_outputs(picked=named, **named)
    for f in files:
        t = dest / f
        if t.is_file() and t.read_bytes() != (src / f).read_bytes():
            raise ParameterError(f"DIR ({f})", str(t), "a folder without changed copies of the examples",
                                 "a file of that name there differs (yours?): refused, nothing copied; choose "
                                 "another folder or move it")
    for f in files:
        t = dest / f
        if t.is_file():
            print(f"{t}: already there", file=sys.stderr)
            continue
        with replacing(t, f"DIR ({f})", picked=True) as tmp:
            tmp.write_bytes((src / f).read_bytes())
        print(f"{t}", file=sys.stderr)
    print(f"mjeap examples: {len(files)} files in {dest}; try: python {dest / 'design_study.py'} --help",
          file=sys.stderr)
    return 0


def cmd_robot(args) -> int:
    from .robots import get
    return get(args.name).main(args.options) or 0


def build_parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(prog="mjeap", description=__doc__)
    sub = ap.add_subparsers(dest="command", required=True)
    sub.add_parser("list", help="list the catalog").set_defaults(func=cmd_list)
    p = sub.add_parser("show", help="parameters, provenance and derived values of an actuator (catalog id or file)")
    p.add_argument("name", help=ACTUATOR_HELP)
    p.add_argument("--json", action="store_true")
    p.set_defaults(func=cmd_show)
    p = sub.add_parser("examples", help="copy the examples (actuator files written by hand, a worked design study) "
                       "into a folder")
    p.add_argument("dir", help="the folder to copy them into (made if missing; a changed copy there is never replaced)")
    p.set_defaults(func=cmd_examples)
    p = sub.add_parser("materials", help="the materials library an actuator file's layers name (mjeap.model.materials)")
    p.add_argument("name", nargs="?", help="one material in full: each property's value, unit, range and source")
    p.add_argument("--json", action="store_true", help="every property with value, unit, range and source as JSON")
    p.set_defaults(func=cmd_materials)
    p = sub.add_parser("mjcf", help="write the driven MJCF model of an actuator (mm, mg, s; actuator 'drive' in V)")
    add_scene_args(p)
    p.add_argument("-o", "--output", help="output file (default: stdout)")
    p.set_defaults(func=cmd_mjcf)
    p = sub.add_parser("view", help="MuJoCo's viewer on an actuator (or an MJCF file) in real time, the drive "
                       "voltage on a slider")
    add_scene_args(p)
    p.add_argument("--slow-motion", type=arg_number(1e-3, 1e9), default=1.0,
                   help="wall seconds per simulated second (default 1: real time; ~100 for a 100 Hz piezo)")
    p.add_argument("--voltage", help="play a waveform instead of the slider (needed where the drive has no "
                   "native form), e.g. square:1V@0.5Hz")
    p.add_argument("--drive", help="drive name (default: the actuator's own)")
    p.add_argument("--param", action="append", metavar="KEY=VALUE", help="drive parameter (repeatable)")
    p.set_defaults(func=cmd_view)
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
                   help="'native' (the drive compiled into the model, on mujoco.rollout), 'threaded' "
                        "(mujoco.rollout, the drive's moments precomputed: open-loop drives only), 'loop' (Python "
                        "lockstep, any drive), 'warp' (MuJoCo Warp, a GPU) or 'auto' (default: the first of "
                        "native, threaded, loop that applies; the summary's engine_reason says why)")
    p.add_argument("--accuracy", type=float, default=None,
                   help="largest error of the tip curvature relative to its swing (1e-5 to 0.2): segments, "
                        "integrator and timestep are chosen for it and the error is estimated (mjeap.simulation.accuracy)")
    p.add_argument("--estimate-error", action="store_true",
                   help="without --accuracy: estimate this model's error with a coarser companion run")
    shown = p.add_mutually_exclusive_group()
    shown.add_argument("--quiet", action="store_true", help="no progress (default: a bar on a terminal once the run "
                       "has lasted 2 s)")
    shown.add_argument("--progress", action="store_true", help="one line per 10 %% of the simulated time on stderr "
                       "(for logs and batch jobs)")
    p.set_defaults(func=cmd_rollout)
    from .robots import names as robot_names
    p = sub.add_parser("robot", help=f"run a robot's experiment (mjeap.robots): {', '.join(robot_names())}",
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
    from .studies.sweep import EXECUTORS
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
    from .studies.optimize import METHODS
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
    p = sub.add_parser("frf", help="small-signal frequency response (tip deflection and admittance per volt) from "
                       "the linearised model; resonance, antiresonance, effective coupling")
    add_scene_args(p)
    p.add_argument("--from", dest="start", required=True, help="lowest frequency, Hz or with a unit: 200Hz, 0.2kHz")
    p.add_argument("--to", dest="stop", required=True, help="highest frequency (Hz or with a unit), up to the model's "
                   "highest resolved mode and its step's Nyquist limit")
    p.add_argument("--points", default=200, help="log-spaced frequencies (>= 2; default 200)")
    p.add_argument("--offset", type=float, default=None, help="operating voltage of the drive's input (V; default the "
                   "drive's rest voltage, V_bias/2 for piezo-bimorph)")
    p.add_argument("--drive", help="drive name (default: the actuator's own)")
    p.add_argument("--param", action="append", metavar="KEY=VALUE", help="drive parameter (repeatable)")
    p.add_argument("--out", help=f"folder for frf.csv, frf.json and frf.png (default {FRF_OUT})")
    p.set_defaults(func=cmd_frf)
    p = sub.add_parser("identify", help="fit the papers' models to measured data (CSV with a header)")
    isub = p.add_subparsers(dest="what", required=True)
    q = isub.add_parser("step", help="Dadras et al. 2021: transfer function from a curvature step response")
    q.add_argument("file")
    q.add_argument("--voltage", type=float, required=True, help="step amplitude (V)")
    q.add_argument("--t-step", type=float, default=0.0, help="time of the step (s; within the data's time span)")
    q.add_argument("--time-column", default="time")
    q.add_argument("--curvature-column", default="tip_curvature")
    q.add_argument("--actuator", help="catalog id or actuator file (.toml) to put the identified rc-relaxation "
                   f"parameters in, written to --out (default {IDENTIFIED})")
    q.add_argument("--param", action="append", metavar="KEY=VALUE",
                   help="with --actuator: an rc-relaxation parameter the step does not identify (capacitance)")
    q.add_argument("--out", help=f"with --actuator: the identified actuator file (default {IDENTIFIED})")
    q.set_defaults(func=cmd_identify_step)
    q = isub.add_parser("hinges", help="Mutlu et al. 2013: joint stiffness and damping from a tip trajectory")
    add_scene_args(q)
    q.add_argument("file")
    q.add_argument("--voltage", required=True, help="the waveform applied during the measurement")
    q.add_argument("--drive", help="drive name (default: the actuator's own)")
    q.add_argument("--param", action="append", metavar="KEY=VALUE", help="drive parameter (repeatable)")
    q.add_argument("--time-column", default="time")
    q.add_argument("--tip-column", default="tip_y", help="tip deflection column (m)")
    q.add_argument("--out", help=f"the identified actuator file: the actuator with EI = k L/N and the damping ratio "
                   f"of the fitted joints (default {IDENTIFIED})")
    q.set_defaults(func=cmd_identify_hinges)
    q = isub.add_parser("piezo", help="a piezo bender's coupling (f31), stiffness or tip mass, damping ratio, "
                        "capacitance and resistance from stroke, tip-FRF and impedance data")
    add_scene_args(q)
    q.add_argument("--stroke", help="CSV of stroke against voltage: columns voltage (V_sig) and stroke (tip "
                   "deflection), units in the headers")
    q.add_argument("--voltage-column", default="voltage")
    q.add_argument("--stroke-column", default="stroke")
    q.add_argument("--frf", help="CSV of the tip's frequency response per volt: frequency, tip_per_volt [, tip_phase "
                   "(deg)], as mjeap frf writes them")
    q.add_argument("--impedance", help="CSV of an impedance sweep: frequency and admittance [, admittance_phase], "
                   "impedance [, impedance_phase] or capacitance [, resistance]")
    q.add_argument("--impedance-state", choices=("free", "fixed"), default="free",
                   help="free: the actuator could move (the motional current is in the data); fixed: blocked, as "
                        "Jayaram et al. 2018 fixed theirs in epoxy (the data hold C and R only)")
    q.add_argument("--resonance", help="a published first resonance (Hz or with a unit), where no sweep is at hand")
    q.add_argument("--param", action="append", metavar="KEY=VALUE", help="drive parameter kept as given (repeatable)")
    q.add_argument("--out", help=f"the identified actuator file (default {IDENTIFIED})")
    q.set_defaults(func=cmd_identify_piezo)
    return ap


def _told(func):
    """Run ``func`` with a material's range warnings (a layer's value, a field past its
    limit: :class:`mjeap.model.materials.RangeWarning`) told as one line each,
    ``mjeap: warning: ...``, once per text; other warnings as Python tells them."""
    import warnings
    from .model.materials import RangeWarning
    told, plain = set(), warnings.showwarning

    def show(message, category, filename, lineno, file=None, line=None):
        if not issubclass(category, RangeWarning):
            return plain(message, category, filename, lineno, file, line)
        if str(message) not in told:
            told.add(str(message))
            print(f"mjeap: warning: {message}", file=sys.stderr)

    with warnings.catch_warnings():
        warnings.showwarning = show
        return func()


def main(argv: Optional[List[str]] = None) -> int:
    def command() -> int:
        args = build_parser().parse_args(argv)
        return _told(lambda: args.func(args))
    return run_command(command)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
