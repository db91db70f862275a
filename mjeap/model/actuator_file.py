"""Actuator files: a TOML file describes an actuator completely (geometry, layers, drive and
its parameters, damping, safe voltage range) and where each number comes from.

A bare number is SI; a string carries its unit (``"10 mm"``, ``"40 GPa"``,
:mod:`mjeap.model.quantity`). The keys (optional ones in brackets)::

    id = "long-bimorph"                  # letters, digits, '-', '_'
    title = "A longer tapered PZT-5H bimorph"
    [document]                           # the source the actuator comes from (text)
    drive = "piezo-bimorph"              # a registered drive (mjeap.drives), or "none"; with
                                         # [drive.parameters]: drive.name = "piezo-bimorph" (TOML)
    damping_ratio = 0.05                 # first-mode modal damping ratio, (0, 1)
    voltage_range = ["0 V", "200 V"]     # safe drive voltage, low < high
    [plane_strain = false]               # default: the width >= 5 thickness rule
    [flexural_rigidity = {value = "2.06e-8 N m^2", source = "..."}]   # measured overrides
    [mass = {value = "0.695 mg", source = "..."}]
    [notes = "..."]
    [sources]                            # where top-level numbers come from
    damping_ratio = "assumed"   voltage_range = "..."   plane_strain = "..."
    [planform]
    length = "10 mm"   base_width = "2.5 mm"   [tip_width = base_width]   [source = "..."]
    [extension_length = "1 mm"   extension_mass = "2 mg"   extension_source = "..."]
    [residual_tip_mass = "..."   residual_source = "..."]
    [[layers]]                           # bottom to top
    name = "pzt-bottom"   role = "piezo"   [material = "pzt-5h"]   [description = "PZT-5H"]
    thickness = "135 um"   [width = ...]  youngs_modulus, density, poisson_ratio (from the material
    where left out)   [source = "..."]   [sources = {youngs_modulus = "..."}]
    [drive.parameters]                   # the drive's own names, as `mjeap show` prints them
    bias = "200 V"
    [drive.sources]
    bias = "..."

The file is read by :mod:`tomllib` alone (strict TOML: ``drive = "NAME"`` and a
``[drive.parameters]`` table cannot both stand; ``drive.name = "NAME"`` can). Everything is
checked on load, before any work: an error names the file, the key and what is
accepted (a missing layer, a negative thickness, an unknown material or drive, a drive whose
layer roles are missing, a unit that does not parse); a layer value outside its material's
range is a :class:`~mjeap.model.materials.RangeWarning`, 1000 x outside it an error.
"""
from __future__ import annotations

import math
import re
import sys
from pathlib import Path
from typing import Dict, Optional, Tuple

from ..errors import ParameterError, UnknownNameError
from . import materials as mat
from .actuator import Actuator, Layer, Planform, Sourced, validate_actuator
from .quantity import to_si

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10
    import tomli as tomllib

__all__ = ["read_actuator", "write_actuator", "actuator_toml", "is_actuator_file", "TOP_KEYS", "PLANFORM_KEYS",
           "LAYER_KEYS", "DriveInfo", "set_drive_info", "drive_info"]


class DriveInfo:
    """What a file's drive section is checked against, from the drive layer above
    (:func:`set_drive_info`; mjeap.drives installs it): ``units(name)`` the drive's parameter
    units by name (an unknown drive raises UnknownNameError), ``extra(name)`` parameter names
    without a unit (tables), ``stack_reason(name, actuator)`` why the drive cannot take the
    layer stack (None: it can), ``default(actuator)`` the actuator's own drive's name."""

    def __init__(self, units, extra, stack_reason, default):
        self.units, self.extra, self.stack_reason, self.default = units, extra, stack_reason, default


_drive_info: Optional[DriveInfo] = None


def drive_info() -> Optional[DriveInfo]:
    """The drive layer's answers (:class:`DriveInfo`), None before mjeap.drives installed them."""
    return _drive_info


def set_drive_info(info: DriveInfo) -> None:
    """Install the drive layer's answers (:class:`DriveInfo`): the model layer does not
    import the drives above it."""
    global _drive_info
    _drive_info = info

TOP_KEYS = ("id", "title", "document", "drive", "damping_ratio", "voltage_range", "plane_strain",
            "flexural_rigidity", "mass", "notes", "sources", "planform", "layers")
PLANFORM_KEYS = ("length", "base_width", "tip_width", "extension_length", "extension_mass", "residual_tip_mass",
                 "source", "extension_source", "residual_source")
LAYER_KEYS = ("name", "role", "material", "description", "thickness", "width", "youngs_modulus", "density",
              "poisson_ratio", "source", "sources", *("d31", "e31", "relative_permittivity", "electrode", "poling"))
#: the keys only a piezo layer (role = "piezo") takes, and the choices of the two texts
PIEZO_KEYS = ("d31", "e31", "relative_permittivity", "electrode", "poling")
ELECTRODES, POLINGS = ("signal", "complement"), ("up", "down")
_ID = re.compile(r"[A-Za-z0-9_-]+")
_UNITS = {"length": "m", "base_width": "m", "tip_width": "m", "extension_length": "m", "extension_mass": "kg",
          "residual_tip_mass": "kg", "thickness": "m", "width": "m", "youngs_modulus": "Pa", "density": "kg/m^3",
          "poisson_ratio": "-", "flexural_rigidity": "N m^2", "mass": "kg"}


def is_actuator_file(name) -> bool:
    """Whether ``name`` names a file rather than a registered actuator: it ends in ``.toml``
    or holds a path separator (a :class:`pathlib.Path` always does)."""
    if isinstance(name, Path):
        return True
    return isinstance(name, str) and (name.endswith(".toml") or "/" in name or (sys.platform == "win32" and "\\" in name))


class _Reader:
    """Reads one file's table with errors naming the file and key."""

    def __init__(self, path: Path):
        self.path = path

    def where(self, key: str) -> str:
        return f"{self.path}: {key}"

    def error(self, key, value, accepted, why=""):
        return ParameterError(self.where(key), value, accepted, why)

    def unknown(self, table: dict, allowed, prefix: str) -> None:
        extra = [k for k in table if k not in allowed]
        if extra:
            raise self.error(f"{prefix}{extra[0]}", table[extra[0]], f"one of the keys {', '.join(allowed)}")

    def text(self, table: dict, key: str, prefix: str = "", default=None, required=False) -> Optional[str]:
        if key not in table:
            if required:
                raise self.error(prefix + key, "missing", "a value (it is required)")
            return default
        v = table[key]
        if not isinstance(v, str):
            raise self.error(prefix + key, v, "text in quotes")
        return v

    def number(self, table: dict, key: str, unit: str, prefix: str = "", positive=True, default=None,
               required=False):
        if key not in table:
            if required:
                raise self.error(prefix + key, "missing", f"a quantity in {unit} (it is required)")
            return default
        v = to_si(table[key], unit, self.where(prefix + key))
        if positive and not v > 0:
            raise self.error(prefix + key, table[key], f"a positive quantity in {unit}")
        if not positive and v < 0:
            raise self.error(prefix + key, table[key], f"a non-negative quantity in {unit}")
        return v


def read_actuator(path):
    """The :class:`~mjeap.model.catalog.Actuator` a TOML file describes, checked (module
    text); its ``source_file`` is the file."""
    path = Path(path)
    r = _Reader(path)
    if not path.is_file():
        raise ParameterError("actuator", str(path), "an existing actuator file (.toml)",
                             "no such file" if not path.exists() else "not a regular file")
    doc = _parse(path)
    r.unknown(doc, (*TOP_KEYS, "drive"), "")
    drive_table = doc.get("drive") if isinstance(doc.get("drive"), dict) else None
    aid = r.text(doc, "id", required=True)
    if not _ID.fullmatch(aid):
        raise r.error("id", aid, "letters, digits, '-' and '_'")
    src = doc.get("sources", {})
    if not isinstance(src, dict):
        raise r.error("sources", src, "a table of sources: key = \"where the number comes from\"")
    drive = _drive_name(r, doc, drive_table)
    planform = _planform(r, doc)
    layers_doc = doc.get("layers")
    if not isinstance(layers_doc, list) or not layers_doc:
        raise r.error("layers", layers_doc if layers_doc is not None else "missing",
                      "at least one [[layers]] table, bottom to top")
    layers, names = [], set()
    for i, ld in enumerate(layers_doc):
        layers.append(_layer(r, i, ld, names))
    overrides = _overrides(r, doc, src)
    zeta = r.number(doc, "damping_ratio", "-", required=True)
    if not zeta < 1.0:
        raise r.error("damping_ratio", doc["damping_ratio"], "a damping ratio in (0, 1)")
    lo, hi = _voltage_range(r, doc)
    plane = doc.get("plane_strain")
    if plane is not None and not isinstance(plane, bool):
        raise r.error("plane_strain", plane, "true or false")
    drive_params = _drive_parameters(r, drive, drive_table)
    act = Actuator(
        id=aid, title=r.text(doc, "title", default=aid), document=r.text(doc, "document", default=str(path)),
        layers=tuple(layers), planform=planform,
        damping_ratio=Sourced(zeta, "-", src.get("damping_ratio", "given in the file")),
        voltage_range=(lo, hi), voltage_source=src.get("voltage_range", "given in the file"),
        plane_strain=plane,
        plane_strain_source=src.get("plane_strain", "thesis eq. 3.1 rule (width >= 5 x thickness)"
                                    if plane is None else "given in the file"),
        notes=r.text(doc, "notes", default=""), drive=drive, drive_parameters=drive_params,
        source_file=str(path), **overrides)
    bad = set(src) - {"damping_ratio", "voltage_range", "plane_strain", "flexural_rigidity", "mass"}
    if bad:
        raise r.error(f"sources.{sorted(bad)[0]}", src[sorted(bad)[0]],
                      "a source for damping_ratio, voltage_range, plane_strain, flexural_rigidity or mass")
    try:
        validate_actuator(act, where=r.where(""))
    except ParameterError as e:
        raise ParameterError(e.name if e.name.startswith(r.where("")) else r.where(e.name), e.value, e.accepted,
                             e.why) from None
    why = None if _drive_info is None else _drive_info.stack_reason(drive, act)
    if why is not None:
        raise r.error("layers", [f"{l.name} ({l.role or 'no role'})" for l in act.layers],
                      f"a layer stack the {drive} drive can take", why)
    return act


def _drive_name(r: _Reader, doc: dict, drive_table: Optional[dict]) -> str:
    """The file's drive: a name, or a table with name, parameters and sources; known to the
    drive layer where it has told its drives."""
    if drive_table is not None:
        r.unknown(drive_table, ("name", "parameters", "sources"), "drive.")
        drive = r.text(drive_table, "name", "drive.", required=True)
    else:
        drive = r.text(doc, "drive", required=True)
    if _drive_info is not None:
        try:
            _drive_info.units(drive)
        except UnknownNameError as e:
            raise _unknown(r.where("drive"), "drive", drive, e.known) from None
    return drive


def _planform(r: _Reader, doc: dict) -> Planform:
    """The [planform] table."""
    pf = doc.get("planform")
    if not isinstance(pf, dict):
        raise r.error("planform", pf if pf is not None else "missing", "a [planform] table with length and base_width")
    r.unknown(pf, PLANFORM_KEYS, "planform.")
    num = lambda k, **kw: r.number(pf, k, _UNITS[k], "planform.", **kw)  # noqa: E731
    length, base = num("length", required=True), num("base_width", required=True)
    planform = Planform(length=length, base_width=base, tip_width=num("tip_width", default=base),
                        source=r.text(pf, "source", "planform.", default="given in the file"),
                        extension_length=num("extension_length", positive=False, default=0.0),
                        extension_mass=num("extension_mass", positive=False, default=0.0),
                        extension_source=r.text(pf, "extension_source", "planform.", default="none"),
                        residual_tip_mass=num("residual_tip_mass", positive=False, default=0.0),
                        residual_source=r.text(pf, "residual_source", "planform.", default="none"))
    if planform.extension_mass > 0 and planform.extension_length == 0:
        raise r.error("planform.extension_length", 0, "a positive length where extension_mass is given")
    return planform


def _layer(r: _Reader, i: int, ld, names: set) -> Layer:
    """The ``i``-th [[layers]] table (its name added to ``names``, which no other may take):
    its numbers given or taken from its material, each with its source."""
    pre = f"layers[{i}]."
    if not isinstance(ld, dict):
        raise r.error(f"layers[{i}]", ld, "a [[layers]] table")
    r.unknown(ld, LAYER_KEYS, pre)
    name = r.text(ld, "name", pre, required=True)
    if name in names:
        raise r.error(pre + "name", name, "a name no other layer has")
    names.add(name)
    pre = f"layers.{name}."
    m = None
    if "material" in ld:
        key = r.text(ld, "material", pre)
        try:
            m = mat.get_material(key)
        except UnknownNameError:
            raise _unknown(r.where(pre + "material"), "material", key, mat.MATERIALS) from None
    values = {}
    for k in ("youngs_modulus", "density", "poisson_ratio"):
        if k in ld:
            v = r.number(ld, k, _UNITS[k], pre, positive=k != "poisson_ratio")
            if k == "poisson_ratio" and not -1.0 < v < 0.5:
                raise r.error(pre + k, ld[k], "a Poisson ratio in (-1, 0.5)")
            mat.check_value(m, k, v, r.where(pre + k))
            values[k] = v
        elif m is not None:
            values[k] = m.property(k).value
        else:
            raise r.error(pre + k, "missing", f"a value in {_UNITS[k]}, or a material from the library "
                          f"({', '.join(mat.material_names())}) to take it from")
    sources = ld.get("sources", {})
    if not isinstance(sources, dict) or not all(isinstance(v, str) for v in sources.values()):
        raise r.error(pre + "sources", sources, "a table of texts: field = \"source\"")
    if m is not None:       # what the layer takes from the material carries its source
        sources = {**{k: f"material {m.name}: {m.property(k).source}" for k in values if k not in ld}, **sources}
    piezo = _piezo_keys(r, ld, pre, values["youngs_modulus"], m)
    if "e31" in ld and "d31" not in ld and "d31" not in sources:   # d31 carries e31's source
        sources = {**sources, "d31": f"e31 = {ld['e31']} / youngs_modulus; e31: "
                   + sources.get("e31", r.text(ld, "source", pre, default="not given"))}
    return Layer(name=name, material=r.text(ld, "description", pre, default=m.title if m else name),
                 thickness=r.number(ld, "thickness", "m", pre, required=True),
                 width=r.number(ld, "width", "m", pre, default=None), source=r.text(
                     ld, "source", pre, default="given in the file"),
                 sources=dict(sources), role=r.text(ld, "role", pre, default=""),
                 material_key=m.name if m else None, **values, **piezo)


def _overrides(r: _Reader, doc: dict, src: dict) -> dict:
    """The measured overrides (flexural_rigidity, mass), each a number or a table with its
    value and source."""
    overrides = {}
    for k in ("flexural_rigidity", "mass"):
        if k not in doc:
            continue
        v = doc[k]
        if isinstance(v, dict):
            r.unknown(v, ("value", "source"), f"{k}.")
            val = r.number(v, "value", _UNITS[k], f"{k}.", required=True)
            s = r.text(v, "source", f"{k}.", default=src.get(k, "given in the file"))
        else:
            val = r.number(doc, k, _UNITS[k])
            s = src.get(k, "given in the file")
        overrides[k] = Sourced(val, _UNITS[k], s)
    return overrides


def _voltage_range(r: _Reader, doc: dict) -> Tuple[float, float]:
    """``voltage_range = [low, high]`` in V, low < high."""
    vr = doc.get("voltage_range")
    if not isinstance(vr, list) or len(vr) != 2:
        raise r.error("voltage_range", vr if vr is not None else "missing",
                      "[low, high] in V, e.g. [\"0 V\", \"200 V\"]")
    lo, hi = (to_si(v, "V", r.where(f"voltage_range[{i}]")) for i, v in enumerate(vr))
    if not lo < hi:
        raise r.error("voltage_range", vr, "[low, high] with low < high")
    return lo, hi


def _piezo_keys(r: _Reader, ld: dict, pre: str, youngs_modulus: float, material) -> dict:
    """A layer's piezo keys (:data:`PIEZO_KEYS`, a role = "piezo" layer only) as Layer
    fields: d31 (m/V) from ``d31`` or from ``e31`` (C/m^2) / the layer's Young's modulus (the
    beam's uniaxial-stress model: e31 = d31 Y), both given only where they agree;
    ``relative_permittivity`` (> 0); ``electrode`` and ``poling`` among their choices."""
    given = [k for k in PIEZO_KEYS if k in ld]
    if not given:
        return {}
    if ld.get("role") != "piezo":
        raise r.error(pre + given[0], ld[given[0]], "a piezo constant only on a layer with role = \"piezo\"")
    out = {}
    d31 = None if "d31" not in ld else to_si(ld["d31"], "m/V", r.where(pre + "d31"))
    if "e31" in ld:
        from_e = to_si(ld["e31"], "C/m^2", r.where(pre + "e31")) / youngs_modulus
        if d31 is not None and not math.isclose(d31, from_e, rel_tol=1e-6):
            raise r.error(pre + "e31", ld["e31"], f"e31 = d31 x youngs_modulus = {d31 * youngs_modulus:.6g} C/m^2 "
                          "(this beam's uniaxial-stress model), or only one of d31 and e31",
                          f"d31 = {d31:g} m/V and e31 disagree")
        d31 = from_e if d31 is None else d31
    for k, v in (("d31", d31),):
        if v is not None:
            if not (math.isfinite(v) and v != 0):
                raise r.error(pre + k, ld.get(k, ld.get("e31")), "a finite, non-zero piezoelectric constant")
            mat.check_value(material, "d31", v, r.where(pre + ("d31" if "d31" in ld else "e31 / youngs_modulus")))
            out["d31"] = v
    if "relative_permittivity" in ld:
        eps = r.number(ld, "relative_permittivity", "-", pre)
        mat.check_value(material, "relative_permittivity", eps, r.where(pre + "relative_permittivity"))
        out["relative_permittivity"] = eps
    for k, choices in (("electrode", ELECTRODES), ("poling", POLINGS)):
        if k in ld:
            v = r.text(ld, k, pre)
            if v not in choices:
                raise r.error(pre + k, v, " or ".join(f'"{c}"' for c in choices))
            out[k] = v
    return out


def _unknown(where: str, kind: str, name: str, known) -> UnknownNameError:
    """UnknownNameError for ``kind`` ``name``, its message led by ``where`` (file: key)."""
    e = UnknownNameError(kind, name, known)
    e.args = (f"{where}: {e.args[0]}",)
    return e


#: the largest actuator file read (bytes): a description, not a data set
MAX_FILE_BYTES = 1 << 20


def _parse(path: Path) -> dict:
    """The file's TOML document, read by :mod:`tomllib` alone; what it cannot read (not
    TOML, not UTF-8, nested too deep, a number too long, too large a file) is one
    ParameterError naming the file."""
    def refuse(why):
        return ParameterError("actuator", str(path), "a TOML actuator file (docs/actuators/files.md)", why)
    try:
        with open(path, "rb") as fh:
            data = fh.read(MAX_FILE_BYTES + 1)
    except OSError as e:
        raise refuse(f"cannot read it: {e.strerror or e}") from None
    if len(data) > MAX_FILE_BYTES:
        raise refuse(f"it is larger than {MAX_FILE_BYTES // 1024} KiB: an actuator file describes one actuator")
    try:
        return tomllib.loads(data.decode("utf-8"))
    except UnicodeDecodeError as e:
        raise refuse(f"it is not UTF-8 text ({e.reason} at byte {e.start})") from None
    except tomllib.TOMLDecodeError as e:
        hint = ("; a drive with parameters is a table: write drive.name = \"NAME\" (or name = \"NAME\" under "
                "[drive]) instead of drive = \"NAME\" beside [drive.parameters]") if "overwrite" in str(e) else ""
        raise refuse(f"it does not parse: {e}{hint}") from None
    except RecursionError:
        raise refuse("its arrays or tables are nested too deep to read") from None
    except (ValueError, OverflowError, MemoryError) as e:     # an integer of thousands of digits
        raise refuse(f"it does not parse: {e}") from None


def _drive_parameters(r: _Reader, drive: str, table) -> Dict[str, tuple]:
    """The file's drive parameters as rows (value SI, '', source): a value with a unit is
    converted by the drive's own unit for it (the unit stays the drive's to say); names the
    drive does not take are refused."""
    if table is None:
        return {}
    params, sources = table.get("parameters", {}), table.get("sources", {})
    if not isinstance(params, dict) or not isinstance(sources, dict):
        raise r.error("drive.parameters", params, "a [drive.parameters] table of the drive's parameters")
    info = _drive_info
    known = {} if info is None else info.units(drive)
    extra = set() if info is None else set(info.extra(drive))
    out = {}
    for k, v in params.items():
        if info is not None and k not in known and k not in extra:
            raise r.error(f"drive.parameters.{k}", v, f"one of the {drive} drive's parameters: "
                          f"{', '.join(sorted((*known, *extra))) or 'none'}")
        unit = known.get(k, "-")
        if isinstance(v, (bool, list)) or (isinstance(v, str) and unit == "-" and not _looks_numeric(v)):
            value = v                         # a choice ('maxwell'), a switch or a table
        else:
            value = to_si(v, unit, r.where(f"drive.parameters.{k}"))
        out[k] = (value, "", sources.get(k, "given in the file"))     # the unit is the drive's
    stray = set(sources) - set(params)
    if stray:
        k = sorted(stray)[0]
        raise r.error(f"drive.sources.{k}", sources[k], "a source of a parameter given in [drive.parameters]")
    return out


def _looks_numeric(text: str) -> bool:
    try:
        float(text)
        return True
    except ValueError:
        return False


# ---------------------------------------------------------------- writing
def _fmt(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, (int, float)):
        x = float(v)
        if math.isnan(x):
            return "nan"
        if math.isinf(x):
            return "inf" if x > 0 else "-inf"
        return repr(x)
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n") + '"'
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_fmt(x) for x in v) + "]"
    raise TypeError(type(v))


def _inline(d: dict) -> str:
    return "{" + ", ".join(f"{_key(k)} = {_fmt(v)}" for k, v in d.items()) + "}"


def _key(k: str) -> str:
    return k if re.fullmatch(r"[A-Za-z0-9_-]+", k) else _fmt(k)


def actuator_toml(act) -> str:
    """The TOML text of ``act`` (numbers in SI, floats written exactly: a round trip through
    :func:`read_actuator` gives the same actuator)."""
    out = [f"# {act.title}", f"id = {_fmt(act.id)}", f"title = {_fmt(act.title)}", f"document = {_fmt(act.document)}"]
    drive = act.drive or (None if _drive_info is None else _drive_info.default(act))
    if drive is None:
        raise ParameterError("actuator.drive", None, "the name of the drive that moves the actuator")
    out += [f"damping_ratio = {_fmt(act.damping_ratio.value)}", f"voltage_range = {_fmt(list(act.voltage_range))}"]
    if act.plane_strain is not None:
        out.append(f"plane_strain = {_fmt(act.plane_strain)}")
    for k in ("flexural_rigidity", "mass"):
        o = getattr(act, k)
        if o is not None:
            out.append(f"{k} = {_inline({'value': o.value, 'source': o.source})}")
    if act.notes:
        out.append(f"notes = {_fmt(act.notes)}")
    out += ["", "[sources]", f"damping_ratio = {_fmt(act.damping_ratio.source)}",
            f"voltage_range = {_fmt(act.voltage_source)}"]
    if act.plane_strain is not None:
        out.append(f"plane_strain = {_fmt(act.plane_strain_source)}")
    p = act.planform
    out += ["", "[planform]", f"length = {_fmt(p.length)}", f"base_width = {_fmt(p.base_width)}",
            f"tip_width = {_fmt(p.tip_width)}", f"source = {_fmt(p.source)}"]
    if p.extension_length or p.extension_mass:
        out += [f"extension_length = {_fmt(p.extension_length)}", f"extension_mass = {_fmt(p.extension_mass)}",
                f"extension_source = {_fmt(p.extension_source)}"]
    if p.residual_tip_mass:
        out += [f"residual_tip_mass = {_fmt(p.residual_tip_mass)}", f"residual_source = {_fmt(p.residual_source)}"]
    for l in act.layers:
        out += ["", "[[layers]]", f"name = {_fmt(l.name)}", f"role = {_fmt(l.role)}"]
        if l.material_key:
            out.append(f"material = {_fmt(l.material_key)}")
        out += [f"description = {_fmt(l.material)}", f"thickness = {_fmt(l.thickness)}"]
        if l.width is not None:
            out.append(f"width = {_fmt(l.width)}")
        out += [f"youngs_modulus = {_fmt(l.youngs_modulus)}", f"density = {_fmt(l.density)}",
                f"poisson_ratio = {_fmt(l.poisson_ratio)}", f"source = {_fmt(l.source)}"]
        out += [f"{k} = {_fmt(getattr(l, k))}" for k in ("d31", "relative_permittivity", "electrode", "poling")
                if getattr(l, k) is not None]
        if l.sources:
            out.append(f"sources = {_inline(l.sources)}")
    out += ["", "[drive]", f"name = {_fmt(drive)}"]
    if act.drive_parameters:
        out += ["", "[drive.parameters]"] + [f"{_key(k)} = {_fmt(v[0])}" for k, v in act.drive_parameters.items()]
        out += ["", "[drive.sources]"] + [f"{_key(k)} = {_fmt(v[2])}" for k, v in act.drive_parameters.items()]
    return "\n".join(out) + "\n"


def write_actuator(act, path) -> Path:
    """Write ``act`` as an actuator file (whole or not at all, :mod:`mjeap.io.outputs`)."""
    from ..io.outputs import replacing
    text = actuator_toml(act)
    with replacing(path, "path") as tmp:
        Path(tmp).write_text(text, encoding="utf-8")
    return Path(path)


# Actuator.from_file / actuator.to_file: the file form, provided here (the dataclass module
# does not import its reader)
def _from_file(cls, path) -> Actuator:
    """The actuator a TOML file describes, checked (:func:`read_actuator`)."""
    return read_actuator(path)


Actuator.from_file = classmethod(_from_file)
Actuator.to_file = write_actuator
