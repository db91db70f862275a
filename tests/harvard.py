"""Harvard's HAMR actuator model (PZTBender2.m, Jafferis et al. 2015) with its own variables,
for the tests: the plates' voltage difference V (V = V_bias at full drive, V_sig = V_bias),
the bending stiffness per width D from its layer formula, f31 its free value. None of it
is the drive's code."""
from mjeap import analytical as an
from mjeap.model.catalog import get_actuator

F31 = 32.0          # Pa m/V, Jafferis 2015 free value (PZTBender2's f31_eff_f)


def stack(act):
    """(t_p, t_cf, E_p, E_cf) of a catalog bimorph, m and Pa."""
    lay = {l.role: l for l in act.layers}             # the piezo layers are alike
    return (lay["piezo"].thickness, lay["core"].thickness, lay["piezo"].youngs_modulus, lay["core"].youngs_modulus)


def free_deflection(actuator: str, v: float) -> float:
    """(1/4)(1 + 2 l_r) f31 V (t_p + t_cf) L^2 / D (m) at the tip block's end for the plates'
    voltage difference ``v`` (V)."""
    act = get_actuator(actuator)
    t_p, t_cf, E_p, E_cf = stack(act)
    p = act.planform
    D = an.bimorph_stiffness_per_width(E_p, t_p, E_cf, t_cf)
    return an.bimorph_free_deflection(F31, v, t_p, t_cf, p.length, p.extension_length / p.length, D)
