"""Seed 002 (Metello 2020): the P(VDF-TrFE-CTFE) five-layer unimorphs, as the thesis tests them.

References: closed forms for the simulated beam (3 EI/L^3, 3 M/(2L), M L^2/(2 EI)) as
tolerance checks; the thesis's measured tables (4.1-4.4, 4.6, 6.1), its beam model and its
COMSOL results (5.3) as comparisons, with the disagreement stated.
"""
from __future__ import annotations

import numpy as np

from ..drives import make_drive
from ..drives.electrostrictive import FIELDS, SLOPES, maxwell_stress_model
from ..scene import Scene
from .core import Experiment, experiment

THESIS = "Metello 2020 (seed 002)"
SAMPLES = ("pvdf-60", "pvdf-60-half", "pvdf-130")
#: thesis 'Model' slope (N/mm), Tables 4.1-4.3
MODEL_SLOPE = {"pvdf-60": 5.00e-4, "pvdf-60-half": 2.90e-4, "pvdf-130": 8.60e-4}
#: Table 4.6 measured maximum tip displacement (m) at 8.33 / 11.67 / 15 MV/m
TABLE_4_6 = {"pvdf-60": (0.676e-3, 0.704e-3, 0.738e-3), "pvdf-60-half": (0.461e-3, 0.606e-3, 0.727e-3),
             "pvdf-130": (1.221e-3, 1.277e-3, 1.752e-3)}
#: Table 5.3 COMSOL stationary tip displacement (m)
TABLE_5_3 = {"pvdf-60": (0.0569e-3, 0.1160e-3, 0.2019e-3), "pvdf-60-half": (0.1122e-3, 0.2283e-3, 0.2533e-3),
             "pvdf-130": (0.0446e-3, 0.0914e-3, 0.1605e-3)}
#: Table 6.1 measured blocking force range (N)
TABLE_6_1 = {"pvdf-60": (9.07e-4, 9.17e-4), "pvdf-60-half": (8.35e-4, 9.22e-4), "pvdf-130": (5.26e-3, 7.98e-3)}
PUSH = np.arange(0.5e-3, 4.01e-3, 0.5e-3)   # m, the thesis's 0.5 mm steps up to 4 mm


def held(scene, voltage: float):
    """The electrostrictive drive holding ``voltage`` (static drive: one step sets its moment
    and field stiffening)."""
    drv = make_drive("electrostrictive", scene)
    scene.reset()
    drv.reset()
    drv.step(voltage, scene.timestep)
    return drv


def settle_tip(scene, force: float) -> float:
    scene.set_tip_force(force)
    scene.settle(tol=1e-9)
    return float(scene.tip_position()[1])


def load_displacement(scene, voltage: float, EI: float):
    """Tip pushed 0.5-4 mm from its rest position under the held voltage; returns (push (m),
    force (N), slope N/m, the drive's field-stiffening factor). Force-controlled points on the
    predicted compliance, then the force at each push by interpolation; the slope is the
    least-squares line through zero."""
    drv = held(scene, voltage)
    y0 = settle_tip(scene, 0.0)
    factor = drv.stiffness_factor(voltage / drv.t_active)
    k_guess = 3 * EI * factor / scene.layout.length**3
    forces = k_guess * np.linspace(0.25e-3, 4.5e-3, 6)
    pushes = np.array([settle_tip(scene, F) - y0 for F in forces])
    F_at = np.interp(PUSH, pushes, forces)
    slope = float(np.sum(F_at * PUSH) / np.sum(PUSH**2))
    return PUSH, F_at, slope, factor


@experiment("metello2020")
def metello(quick: bool = False) -> Experiment:
    ex = Experiment("metello2020", "P(VDF-TrFE-CTFE) unimorphs: load-displacement, blocked force, tip displacement per field")
    for act_id in SAMPLES:
        scene = Scene(act_id)
        act = scene.actuator
        L = scene.layout.length
        EI = float(act.flexural_rigidity_at(0.0)[0])
        t_a = next(l for l in act.layers if l.name == "terpolymer").thickness
        # load-displacement: 0 V (prediction) and the three fields (stiffening from the tables)
        slopes = []
        for i, E in enumerate(FIELDS):
            push, F, k, f = load_displacement(scene, E * t_a, EI)
            slopes.append(k)
            meas = SLOPES[act_id][i] * 1e3
            tag = "0 V" if E == 0 else f"{E / 1e6:.2f} MV/m"
            if E == 0:
                ex.check(f"{act_id} {tag}: load-displacement slope", "N/m", k, 3 * EI / L**3,
                         "3 EI/L^3, EI of eqs. 3.1-3.6", tolerance=0.02)
                ex.check(f"{act_id} {tag}: slope vs thesis model", "N/m", k, MODEL_SLOPE[act_id] * 1e3,
                         f"{THESIS} Tables 4.1-4.3, 'Model'")
            else:
                ex.check(f"{act_id} {tag}: load-displacement slope", "N/m", k, 3 * f * EI / L**3,
                         "3 f(E) EI/L^3, f = measured stiffening ratio (input)", tolerance=0.02)
            ex.check(f"{act_id} {tag}: slope vs measured", "N/m", k, meas, f"{THESIS} Tables 4.1-4.4, measured",
                     note="" if E == 0 else "field stiffening is an input taken from these tables (ratio to 0 V): "
                                            "this row shows the 0 V mismatch carried over, not a prediction")
            ex.curve(f"{act_id}: load-displacement", f"mjeap {tag}", push * 1e3, F * 1e3,
                     "tip push (mm)", "force (mN)", "o-")
        ex.curve(f"{act_id}: slopes", "mjeap", FIELDS / 1e6, np.array(slopes) * 1e-3, "field (MV/m)", "slope (N/mm)", "o-")
        ex.curve(f"{act_id}: slopes", f"{THESIS} measured", FIELDS / 1e6, SLOPES[act_id], "field (MV/m)",
                 "slope (N/mm)", "s--")
        # blocked force and free tip displacement per field (Maxwell model, as the thesis)
        free, blocked = [], []
        for j, E in enumerate(FIELDS[1:]):
            V = E * t_a
            drv = held(scene, V)
            M = drv.moment(V)
            f = drv.stiffness_factor(E)
            y_free = settle_tip(scene, 0.0)
            compliance = (settle_tip(scene, 1e-4) - y_free) / 1e-4
            Fb = -y_free / compliance
            y_check = settle_tip(scene, Fb)
            if j == len(FIELDS) - 2:
                settle_tip(scene, 0.0)
                ex.beam(f"{act_id}, {E / 1e6:.2f} MV/m, free", scene)
            free.append(y_free)
            blocked.append(-Fb)
            tag = f"{E / 1e6:.2f} MV/m"
            ex.check(f"{act_id} {tag}: blocked force", "N", -Fb, 1.5 * M / L, "3 M/(2L), uniform moment M",
                     tolerance=0.01, note=f"tip held at {abs(y_check) / abs(y_free):.1e} of the free deflection")
            lo, hi = TABLE_6_1[act_id]
            ex.check(f"{act_id} {tag}: blocked force vs measured", "N", -Fb, 0.5 * (lo + hi),
                     f"{THESIS} Table 6.1 (range {lo:.3g}-{hi:.3g} N, mid-range shown)")
            ex.check(f"{act_id} {tag}: blocked force vs thesis F_y = M/L", "N", -Fb,
                     maxwell_stress_model(act, V)["tip_force"], f"{THESIS} eq. 3.11")
            ex.check(f"{act_id} {tag}: free tip displacement", "m", y_free, M * L**2 / (2 * f * EI),
                     "M L^2 / (2 EI_field), small deflection", tolerance=0.02)
            ex.check(f"{act_id} {tag}: free tip displacement vs measured", "m", y_free, TABLE_4_6[act_id][j],
                     f"{THESIS} Table 4.6")
            ex.check(f"{act_id} {tag}: free tip displacement vs COMSOL", "m", y_free, TABLE_5_3[act_id][j],
                     f"{THESIS} Table 5.3 (COMSOL, stationary)")
        ex.curve(f"{act_id}: tip displacement", "mjeap (Maxwell model, stiffened)", FIELDS[1:] / 1e6,
                 np.array(free) * 1e3, "field (MV/m)", "tip displacement (mm)", "o-")
        ex.curve(f"{act_id}: tip displacement", f"{THESIS} Table 4.6 measured", FIELDS[1:] / 1e6,
                 np.array(TABLE_4_6[act_id]) * 1e3, "field (MV/m)", "tip displacement (mm)", "s--")
        ex.curve(f"{act_id}: tip displacement", f"{THESIS} Table 5.3 COMSOL", FIELDS[1:] / 1e6,
                 np.array(TABLE_5_3[act_id]) * 1e3, "field (MV/m)", "tip displacement (mm)", "^:")
    ex.notes += [
        "Model used: the thesis's Maxwell-stress chain (eqs. 3.7-3.11 as its Table 3.8 evaluates them, "
        "sigma = eps0 eps_r E^2) as a uniform internal moment, and field stiffening from the measured "
        "slopes (Tables 4.1-4.4) relative to 0 V. Tip forces are dead loads; no gravity in the bending plane.",
        "Load-displacement is run as the thesis does (push 0.5-4 mm in 0.5 mm steps, force read) by "
        "settling under prescribed forces and interpolating the force at each push; the slope is the "
        "least-squares line through the origin.",
        "The disagreement is the thesis's own: the free tip displacement of its beam model (simulated here) "
        "is 42-97 % below the measured Table 4.6 and -47 % to +127 % from its COMSOL Table 5.3, and the "
        "measured blocking forces are 1.7-26 times 3M/(2L). The blocked force of a uniform moment is "
        "3M/(2L), 1.5 times the thesis's F_y = M/L (eq. 3.11 takes the moment arm as L). The simulation reproduces the thesis's beam model (the "
        "tolerance rows) and says so; it cannot reproduce measurements its own model does not explain. "
        "The 0 V slope differs from the thesis 'Model' column because that column does not follow eq. 3.6 "
        "(see the mechanics-section experiment and tests/test_section.py).",
    ]
    return ex
