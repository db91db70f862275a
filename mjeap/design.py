"""Actuator designs in studies: ``actuator.X`` parameters of a sweep or an optimisation
mapped onto a modified :class:`~mjeap.Actuator` (one helper, :func:`design_actuator`).

A point's actuator is its base actuator (a catalog id or an actuator file, the study's
``actuator`` setting) with these replaced (``dataclasses.replace``), SI or, in text, with a
unit (``"8mm"``, :func:`mjeap.model.quantity.to_si`):

* planform: ``actuator.length``, ``actuator.base_width``, ``actuator.tip_width``,
  ``actuator.extension_length``, ``actuator.extension_mass``, ``actuator.residual_tip_mass``;
* ``actuator.width``: base and tip width together, the taper ratio kept (the mean width);
* one layer, named as in the actuator's file (``mjeap show``):
  ``actuator.layers.NAME.thickness``, ``.width``, ``.youngs_modulus``, ``.density``,
  ``.poisson_ratio``;
* every layer of a role at once (a bimorph's two plates stay equal):
  ``actuator.roles.ROLE.thickness`` etc.;
* ``actuator.damping_ratio`` (first mode).

An identified override of the actuator (a measured EI or mass, as the PEDOT beam has) scales
with the layered value it replaces: EI by the layered EI at the clamp, the mass by the
layered mass, so the identified correction is kept while the geometry moves. A drive's own
parameters (its gains) are not rescaled: vary them as ``drive.NAME``.

Every value is checked against its range (:func:`check_design_value`; an error names the
parameter and the range) and the modified actuator against the drive's layer stack (a
piezo bimorph's plates must stay equally thick), before any work.
"""
from __future__ import annotations

import dataclasses
import warnings
from typing import Dict, List, Mapping, Optional

from .errors import ParameterError, UnknownNameError

__all__ = ["PREFIX", "PLANFORM", "LAYER_FIELDS", "is_design_parameter", "design_parameter_names", "design_numbers",
           "check_design_value", "check_design", "design_actuator", "get_base", "parameter_unit", "to_value", "DESIGN_SOURCE"]

PREFIX = "actuator."
#: planform fields: unit, whether zero is allowed
PLANFORM = {"length": ("m", False), "base_width": ("m", False), "tip_width": ("m", False),
            "extension_length": ("m", True), "extension_mass": ("kg", True), "residual_tip_mass": ("kg", True)}
#: layer fields and their units
LAYER_FIELDS = {"thickness": "m", "width": "m", "youngs_modulus": "Pa", "density": "kg/m^3", "poisson_ratio": "-"}
#: what a value set by a study says of its source
DESIGN_SOURCE = "set by a design study (mjeap.design)"
#: units of the sweep's own numeric parameters (mjeap.sweep.PARAMETERS)
SWEEP_UNITS = {"payload_mass": "kg", "payload_position": "m", "amplitude": "V", "frequency": "Hz", "offset": "V",
               "duration": "s", "initial_curvature": "1/m", "damping_ratio": "-", "accuracy": "-",
               "stop_when_periodic": "-"}


def is_design_parameter(name: str) -> bool:
    return isinstance(name, str) and name.startswith(PREFIX)


def get_base(actuator):
    """The base actuator of a study: a catalog id, a file's path or an Actuator."""
    from .model.catalog import get_actuator
    return get_actuator(actuator)


def design_parameter_names(actuator) -> List[str]:
    """Every ``actuator.X`` name the actuator takes (its layers and roles by name)."""
    act = get_base(actuator)
    names = [PREFIX + k for k in PLANFORM] + [PREFIX + "width", PREFIX + "damping_ratio"]
    names += [f"{PREFIX}layers.{l.name}.{f}" for l in act.layers for f in LAYER_FIELDS]
    roles = sorted({l.role for l in act.layers if l.role})
    names += [f"{PREFIX}roles.{r}.{f}" for r in roles for f in LAYER_FIELDS]
    return names


def _parse(name: str, act):
    """(kind, key, field): ('planform', field, None), ('width', None, None), ('damping',
    None, None), ('layers', layer name, field) or ('roles', role, field); an unknown name
    raises UnknownNameError with the actuator's names."""
    rest = name[len(PREFIX):] if is_design_parameter(name) else None
    if rest in PLANFORM:
        return "planform", rest, None
    if rest == "width":
        return "width", None, None
    if rest == "damping_ratio":
        return "damping", None, None
    for kind in ("layers", "roles"):
        if rest is not None and rest.startswith(kind + ".") and rest.count(".") >= 2:
            key, _, fld = rest[len(kind) + 1:].rpartition(".")
            known = [l.name for l in act.layers] if kind == "layers" else [l.role for l in act.layers if l.role]
            if key in known and fld in LAYER_FIELDS:
                return kind, key, fld
    raise UnknownNameError(f"design parameter of {act.id} (actuator.X)", name, design_parameter_names(act))


def parameter_unit(name: str, actuator=None) -> Optional[str]:
    """The SI unit of a study parameter: ``actuator.X`` (from its field), ``drive.NAME`` (the
    drive's own unit, where ``actuator`` names one) or a sweep parameter; None where it has
    none (text parameters, a drive parameter of an unknown drive)."""
    if is_design_parameter(name):
        rest = name[len(PREFIX):]
        if rest in PLANFORM:
            return PLANFORM[rest][0]
        if rest == "width":
            return "m"
        if rest == "damping_ratio":
            return "-"
        fld = rest.rpartition(".")[2]
        return LAYER_FIELDS.get(fld)
    if name.startswith("drive."):
        if actuator is None:
            return None
        try:
            from .drives import default_drive_name, get_drive_class
            unit = get_drive_class(default_drive_name(get_base(actuator))).parameter_units().get(name[6:])
        except Exception:          # noqa: BLE001 - an unknown actuator or drive: the point reports it
            return None
        return unit
    return SWEEP_UNITS.get(name)


def to_value(name: str, text, actuator=None):
    """A study parameter's value from text: SI for a parameter with a unit (``"8mm"`` ->
    0.008, a bare number SI); the number or the text itself for the others."""
    if not isinstance(text, str):
        return text
    unit = parameter_unit(name, actuator)
    if unit is None and is_design_parameter(name):
        _parse(name, get_base(actuator if actuator is not None else "pedot-micro"))   # unknown: named, with the known
    if unit is not None:
        try:
            float(text)
        except ValueError:
            from .model.quantity import to_si
            return to_si(text.strip(), unit, name)
    try:
        return float(text)
    except ValueError:
        return text


def check_design_value(name: str, value, actuator=None) -> float:
    """``value`` (SI) of design parameter ``name`` for ``actuator``, checked: finite and in
    its range (lengths, moduli and densities > 0; tip-block masses and extension >= 0; a
    Poisson ratio in (-1, 0.5); a damping ratio in (0, 1)); a layer value of a library
    material more than 1000 x outside the material's range is refused (outside it, a
    RangeWarning). Raises ParameterError naming the parameter and the range."""
    from .model import materials as mat
    act = get_base(actuator) if actuator is not None else None
    kind, key, fld = _parse(name, act) if act is not None else (None, None, None)
    unit = parameter_unit(name) or ""
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ParameterError(name, value, f"a number in {unit} (SI) or text with a unit") from None
    if v != v or v in (float("inf"), float("-inf")):
        raise ParameterError(name, value, f"a finite number in {unit}")
    rest = name[len(PREFIX):]
    zero_ok = rest in PLANFORM and PLANFORM[rest][1]
    if rest == "damping_ratio":
        if not 0.0 < v < 1.0:
            raise ParameterError(name, value, "a first-mode damping ratio in (0, 1)")
    elif rest.endswith(".poisson_ratio"):
        if not -1.0 < v < 0.5:
            raise ParameterError(name, value, "a Poisson ratio in (-1, 0.5)")
    elif zero_ok:
        if v < 0:
            raise ParameterError(name, value, f"a non-negative quantity in {unit} (0: none)")
    elif not v > 0:
        raise ParameterError(name, value, f"a positive quantity in {unit}")
    if act is not None and kind in ("layers", "roles") and fld in mat.PROPERTIES:
        for l in act.layers:
            if (l.name if kind == "layers" else l.role) == key and l.material_key:
                mat.check_value(mat.get_material(l.material_key), fld, v, name)
    return v


def _layered_ei(act) -> float:
    return float(dataclasses.replace(act, flexural_rigidity=None).flexural_rigidity_at(0.0)[0])


def _layered_mass(act) -> float:
    return float(act._layered_mass())


def design_actuator(actuator, params: Mapping[str, object]):
    """The actuator ``actuator`` (a catalog id, a file's path or an Actuator) with the
    ``actuator.X`` entries of ``params`` applied (others are ignored), checked: each value
    (:func:`check_design_value`, material-range warnings left to the study's own check),
    the modified actuator's sizes and its drive's layer stack; a ParameterError names the
    parameter. Without design entries the base actuator itself is returned."""
    from .model.actuator import validate_actuator
    base = get_base(actuator)
    given = {k: v for k, v in params.items() if is_design_parameter(k)}
    if not given:
        return base
    planform, layers, top = {}, [dict() for _ in base.layers], {}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")          # material ranges: warned once by the study's check
        for name, value in given.items():
            kind, key, fld = _parse(name, base)
            v = check_design_value(name, value, base)
            if kind == "planform":
                planform[key] = v
            elif kind == "width":
                p = base.planform
                mean = 0.5 * (p.base_width + p.tip_width)
                planform.setdefault("base_width", p.base_width * v / mean)
                planform.setdefault("tip_width", p.tip_width * v / mean)
            elif kind == "damping":
                top["damping_ratio"] = v
            else:
                for i, l in enumerate(base.layers):
                    if (l.name if kind == "layers" else l.role) == key:
                        layers[i][fld] = v
    p = base.planform
    pf_changes = dict(planform)
    if pf_changes:
        moved = ", ".join(sorted(pf_changes))
        pf_changes["source"] = f"{p.source}; {moved}: {DESIGN_SOURCE}"
        if "extension_length" in planform or "extension_mass" in planform:
            pf_changes["extension_source"] = f"{p.extension_source}; {DESIGN_SOURCE}"
        if "residual_tip_mass" in planform:
            pf_changes["residual_source"] = f"{p.residual_source}; {DESIGN_SOURCE}"
    new_layers = tuple(dataclasses.replace(l, **ch, sources={**l.sources, **{f: DESIGN_SOURCE for f in ch}})
                       if ch else l for l, ch in zip(base.layers, layers))
    act = dataclasses.replace(base, planform=dataclasses.replace(p, **pf_changes), layers=new_layers,
                              source_file=None)
    if "damping_ratio" in top:
        act = dataclasses.replace(act, damping_ratio=dataclasses.replace(
            base.damping_ratio, value=top["damping_ratio"], source=DESIGN_SOURCE))
    # identified overrides follow their layered values (module text)
    geometry = bool(planform) or any(layers)
    if geometry and base.flexural_rigidity is not None:
        scale = _layered_ei(act) / _layered_ei(base)
        act = dataclasses.replace(act, flexural_rigidity=dataclasses.replace(
            base.flexural_rigidity, value=base.flexural_rigidity.value * scale,
            source=f"{base.flexural_rigidity.source}; x {scale:.6g} with the layered EI ({DESIGN_SOURCE})"))
    if geometry and base.mass is not None:
        scale = _layered_mass(act) / _layered_mass(base)
        act = dataclasses.replace(act, mass=dataclasses.replace(
            base.mass, value=base.mass.value * scale,
            source=f"{base.mass.source}; x {scale:.6g} with the layered mass ({DESIGN_SOURCE})"))
    names = ", ".join(sorted(given))
    try:
        validate_actuator(act)
    except ParameterError as e:
        raise ParameterError(names, e.value, e.accepted, f"{e.name} of the modified actuator"
                             + (f"; {e.why}" if e.why else "")) from None
    if act.planform.extension_mass > 0 and act.planform.extension_length == 0:
        raise ParameterError(names, 0.0, "actuator.extension_length > 0 where the tip block has a mass",
                             "a tip block needs a length")
    why = _stack_reason(act)
    if why is not None:
        raise ParameterError(names, given[names] if len(given) == 1 else {k: given[k] for k in sorted(given)},
                             "a layer stack the actuator's drive can "
                             "take (vary a bimorph's plates together: actuator.roles.piezo.thickness)", why)
    return act


def _stack_reason(act) -> Optional[str]:
    from .drives import default_drive_name, get_drive_class
    try:
        cls = get_drive_class(default_drive_name(act))
    except (UnknownNameError, ParameterError):
        return None
    return cls.stack_reason(act)


def check_design(actuator, values: Mapping[str, List[object]]) -> Dict[str, List[float]]:
    """Every value of every ``actuator.X`` parameter of a study (name -> its values), checked
    before any work (:func:`check_design_value`: names and ranges; a material range warned
    once per end of the values). Returns the SI values. (A point's combination is checked
    by building it, :func:`design_actuator`.)"""
    act = get_base(actuator)
    out = {}
    for name, vals in values.items():
        if not is_design_parameter(name):
            continue
        _parse(name, act)
        out[name] = [_quiet_check(name, v, act) for v in vals]
        if out[name]:                       # the range's ends: a material-range warning once each
            for end in {min(out[name]), max(out[name])}:
                check_design_value(name, end, act)
    return out


def _quiet_check(name, v, act):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return check_design_value(name, v, act)


# ---------------------------------------------------------------- a design's first numbers
#: how far the catalog bimorphs' physical parameter set (their files without the fitted
#: residual tip mass) resonates above the f_r Jayaram et al. 2018 measured (Table 1), the
#: linearised model's f1 / f_r - 1 (tests/test_piezo_laminate.py recomputes it)
PHYSICAL_SET_F1_GAP = {"pzt-hamr-small": 0.077, "pzt-hamr-large": 0.358, "pzt-robobee": 0.748}
F1_NOTE = ("from the physical parameter set, no residual tip mass fitted to a measurement: that set resonated "
           f"{min(PHYSICAL_SET_F1_GAP.values()):.0%} to {max(PHYSICAL_SET_F1_GAP.values()):.0%} above the three measured "
           "catalog types (Jayaram et al. 2018, Table 1; the catalog closes the gap with a fitted residual tip mass): "
           "expect the real part lower")
MASS_NOTE = "the beam's layers and its rigid tip block (extension and residual mass), as the mass metric"


def design_numbers(actuator, *, segments: Optional[int] = None) -> Dict[str, object]:
    """A designer's first numbers for ``actuator`` (catalog id, file or Actuator) at its
    drive's voltage range, from closed forms and the linearised model (no rollout), each
    (value SI, unit, how): ``first_frequency`` (the linearised model's, as the metric),
    ``free_deflection`` and ``blocked_force`` (their swings over the range: the quasi-static
    tip deflection and the force at the tip block's end that holds it, small deflections),
    ``capacitance`` (free) and ``blocked_capacitance`` (the dielectric term of the current),
    ``energy_density`` (blocked_force x free_deflection / (2 mass)) and ``mass`` (beam and tip
    block). The piezo numbers are None for a drive without a laminate; ``warnings`` lists the
    fields past a layer's limits."""
    from .drives import make_drive
    from .drives.piezo import LinearPiezo
    from .simulation.scene import DEFAULT_SEGMENTS, Scene
    act = get_base(actuator)
    scene = Scene(act, segments=segments or DEFAULT_SEGMENTS)
    why = ""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            drv = make_drive(None, scene)
        except ParameterError as e:       # a parameter a run must give: the mechanics still answer
            drv, why = None, f"n/a: the drive needs {e}"
    out: Dict[str, object] = {"warnings": [str(w.message) for w in caught]}
    p = act.planform
    piezo = isinstance(drv, LinearPiezo)
    how = f"linearised model, {scene.layout.segments} segments"
    if piezo and p.residual_tip_mass == 0:
        how += "; " + F1_NOTE
    out["first_frequency"] = (float(scene.choice.first_frequency), "Hz", how)
    mass = float(act.actuator_mass())
    out["mass"] = (mass, "kg", MASS_NOTE)
    if not piezo:
        none = why or f"n/a: the {drv.name} drive has no laminate closed form"
        for k, u in (("free_deflection", "m"), ("blocked_force", "N"), ("capacitance", "F"),
                     ("blocked_capacitance", "F"), ("energy_density", "J/kg")):
            out[k] = (None, u, none)
        return out
    lo, hi = drv.voltage_range()
    lam = drv.laminate()
    free = abs(lam.free_deflection(hi) - lam.free_deflection(lo))
    force = free / lam.tip_compliance()
    rng = f"over the voltage range [{lo:g}, {hi:g}] V"
    out["free_deflection"] = (free, "m", f"peak to peak {rng}: int kappa (L + l_e - x) dx, kappa = M(x, V) / EI(x)")
    out["blocked_force"] = (force, "N", f"peak to peak {rng} at the tip block's end: free deflection / tip compliance")
    caps = drv.capacitances()
    out["capacitance"] = (float(caps["free"][0]), "F", caps["free"][1])
    out["blocked_capacitance"] = (float(caps["blocked"][0]), "F", caps["blocked"][1])
    out["energy_density"] = (force * free / (2.0 * mass), "J/kg", "blocked_force x free_deflection / (2 mass), "
                             "the swings over the range")
    return out
