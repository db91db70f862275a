"""A study's parameters as text (the command line's ``--vary``, ``--set``, bounds): their SI
unit and their value. ``actuator.X`` takes its field's unit (:mod:`mjeap.model.variants`),
``drive.NAME`` the drive's own, the sweep's parameters theirs (:data:`SWEEP_UNITS`)."""
from __future__ import annotations

import math
from typing import Optional

from ..model.variants import design_unit, get_base, is_design_parameter, parse_design_name

__all__ = ["SWEEP_UNITS", "VARIABLE", "parameter_unit", "to_value"]

#: units of the sweep's own numeric parameters (mjeap.studies.sweep.PARAMETERS)
SWEEP_UNITS = {"payload_mass": "kg", "payload_position": "m", "amplitude": "V", "frequency": "Hz", "offset": "V",
               "duration": "s", "initial_curvature": "1/m", "damping_ratio": "-", "accuracy": "-",
               "stop_when_periodic": "-"}

#: the sweep parameters an optimisation (mjeap.studies.optimize) may vary besides actuator.X and drive.NAME: (unit, low, high,
#: low open) - the range a bound must lie in
VARIABLE = {"payload_mass": ("kg", 0.0, math.inf, False), "payload_position": ("m", 0.0, math.inf, True),
            "amplitude": ("V", -math.inf, math.inf, False), "offset": ("V", -math.inf, math.inf, False),
            "frequency": ("Hz", 0.0, math.inf, True), "initial_curvature": ("1/m", -math.inf, math.inf, False),
            "damping_ratio": ("-", 0.0, 10.0, True)}


def parameter_unit(name: str, actuator=None) -> Optional[str]:
    """The SI unit of a study parameter: ``actuator.X`` (from its field), ``drive.NAME`` (the
    drive's own unit, where ``actuator`` names one) or a sweep parameter; None where it has
    none (text parameters, a drive parameter of an unknown drive)."""
    if is_design_parameter(name):
        return design_unit(name)
    if name.startswith("drive."):
        if actuator is None:
            return None
        try:
            from ..drives import default_drive_name, get_drive_class
            return get_drive_class(default_drive_name(get_base(actuator))).parameter_units().get(name[6:])
        except Exception:          # noqa: BLE001 - an unknown actuator or drive: the point reports it
            return None
    return SWEEP_UNITS.get(name)


def to_value(name: str, text, actuator=None):
    """A study parameter's value from text: SI for a parameter with a unit (``"8mm"`` ->
    0.008, a bare number SI); the number or the text itself for the others."""
    if not isinstance(text, str):
        return text
    unit = parameter_unit(name, actuator)
    if unit is None and is_design_parameter(name):
        parse_design_name(name, get_base(actuator if actuator is not None else "pedot-micro"))   # unknown: named
    if unit is not None:
        try:
            float(text)
        except ValueError:
            from ..model.quantity import to_si
            return to_si(text.strip(), unit, name)
    try:
        return float(text)
    except ValueError:
        return text
