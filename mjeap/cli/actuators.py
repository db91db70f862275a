"""The actuator commands: ``mjeap list``, ``show`` (every number with its unit and source, the
design's first numbers), ``materials``, ``mjcf`` and ``examples``."""
from __future__ import annotations

import json
import sys
from pathlib import Path


from ..errors import ParameterError
from .common import (ACTUATOR_HELP, actuator_file_of, add_scene_args, fmt, printable_tree, scene_from_args,
                     told_actuator)


def cmd_list(args) -> int:
    from ..model.catalog import CATALOG
    width = max(len(k) for k in CATALOG)
    for a in CATALOG.values():
        print(f"{a.id:<{width}}  {a.title}  [{a.document}]")
    return 0


def drive_rows(a) -> dict:
    """The actuator's own drive and each of its parameters as (value, unit, source, origin):
    origin 'file' (the actuator's [drive.parameters]), 'generic' (the drive's default: the
    file gives none) or 'missing' (no default: a run must give it)."""
    from ..drives import default_drive_name, get_drive_class
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
    from ..studies.design_numbers import design_numbers
    from ..model import analytical
    from ..model.laminate import piezo_layers
    from ..simulation.scene import Scene
    a = told_actuator(name)
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
        "id": a.id, "title": a.title, "document": a.document, "file": actuator_file_of(a), "layers": layers,
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


def cmd_show(args) -> int:
    d = describe(args.name)
    if args.json:                      # JSON escapes control characters itself (and all non-ASCII)
        print(json.dumps(d, indent=2, default=str))
        return 0
    d = printable_tree(d)             # every string from the user's file, safe on a terminal
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
            print(f"    {k:<21} {v if isinstance(v, str) else fmt(v):>12} {u:<7} {s}")

    def block(title, items):
        print(f"\n{title}:")
        for k, (v, u, s) in items.items():
            vs = "-" if v is None else (fmt(v) if isinstance(v, float) else str(v))
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
        vs = "-" if v is None else (fmt(v) if isinstance(v, (int, float)) and not isinstance(v, bool) else str(v))
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
    from ..model import materials as mat
    names = [mat.get_material(args.name).name] if args.name else mat.material_names()
    if args.json:
        print(json.dumps({n: material_record(mat.get_material(n)) for n in names}, indent=2))
        return 0
    if args.name:
        m = mat.get_material(args.name)
        print(f"{m.name}: {m.title}" + (f"\n  {m.notes}" if m.notes else ""))
        for k in (*mat.PROPERTIES, *(mat.PIEZO_PROPERTIES if m.piezo else ())):
            p = m.property(k)
            rng = f"[{fmt(p.range[0])}, {fmt(p.range[1])}]"
            print(f"  {k:<21} {fmt(p.value):>9} {p.unit:<7} range {rng}  {p.source}")
        return 0
    keys = ("youngs_modulus", "density", "poisson_ratio")
    rows = [["material", "E (Pa)", "range", "density (kg/m^3)", "range", "nu", "range", "title"]]
    for n in names:
        m = mat.get_material(n)
        ps = [m.property(k) for k in keys]
        rows.append([m.name, *[c for p in ps for c in (fmt(p.value), f"[{fmt(p.range[0])}, {fmt(p.range[1])}]")],
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
    from ..model.materials import PIEZO_PROPERTIES, PROPERTIES
    return {"title": m.title, "notes": m.notes,
            **{k: {"value": m.property(k).value, "unit": m.property(k).unit, "range": list(m.property(k).range),
                   "source": m.property(k).source} for k in (*PROPERTIES, *(PIEZO_PROPERTIES if m.piezo else ()))}}


def cmd_mjcf(args) -> int:
    """The driven model file (mm, mg, s; actuator 'drive' in V where the drive compiles in)."""
    from ..io.outputs import check_outputs
    from ..simulation.model_file import model_file
    from ..simulation.scene import input_files
    from ..units import REAL_TIME_UNITS
    to_file = args.output not in (None, "-")
    if to_file:                                    # before any work: never a link, never the actuator file
        check_outputs(inputs=input_files([args.name]), **{"--output": args.output})
    scene = scene_from_args(args, REAL_TIME_UNITS)
    f = model_file(scene)
    xml = f"<!-- {scene.actuator.id}: {f.note} Units: {scene.units.describe()}. -->\n" + f.spec.to_xml()
    if not to_file:
        sys.stdout.write(xml)
    else:
        from ..io.outputs import replacing
        with replacing(args.output, "--output") as tmp:
            tmp.write_text(xml)
        c = scene.choice
        print(f"wrote {args.output}: {scene.representation}, {scene.layout.segments} segments, "
              f"timestep {c.timestep:.3g} s ({c.reason})", file=sys.stderr)
    return 0


def examples_dir() -> Path:
    """The examples as installed with the wheel (the package ``mjeap.examples_files``, mapped
    to the repository's ``examples`` by pyproject.toml), else the repository's folder."""
    here = Path(__file__).resolve().parents[1]            # the package mjeap
    installed = here / "examples_files"
    return installed if installed.is_dir() else here.parent / "examples"


def cmd_examples(args) -> int:
    """Copy the examples (actuator files, the design study) into a folder, through mjeap's
    writer: a file there that differs is refused before anything is copied, never replaced."""
    from ..io.outputs import check_outputs, replacing
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


def add_parsers(sub) -> None:
    """This module's commands on the command line (``sub``: its subparsers)."""
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
