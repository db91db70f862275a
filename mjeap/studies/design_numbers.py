"""A design's first numbers (``mjeap show``): first frequency, free deflection and blocked
force over the drive's voltage range, free and blocked capacitance, energy density and mass,
from closed forms and the linearised model, no rollout (:func:`design_numbers`)."""
from __future__ import annotations

import warnings
from typing import Dict, Optional

from ..drives import make_drive
from ..drives.piezo import LinearPiezo
from ..errors import ParameterError
from ..model.variants import get_base
from ..simulation.scene import DEFAULT_SEGMENTS, Scene

__all__ = ["design_numbers", "PHYSICAL_SET_F1_GAP", "F1_NOTE", "MASS_NOTE"]

#: how far the catalog bimorphs' physical parameter set (their files without the fitted
#: residual tip mass) resonates above the f_r Jayaram et al. 2018 measured (Table 1), the
#: linearised model's f1 / f_r - 1 (tests/drives/test_piezo_laminate.py recomputes it)
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
