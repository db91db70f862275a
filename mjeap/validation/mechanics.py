"""Beam mechanics of the simulated chain, cable and rod against solutions by other methods (the
elastica by scipy solve_bvp, the exact arc, the characteristic equation of the cantilever with
tip mass, column buckling by shooting and by elliptic integrals) and the multilayer section
against the thesis's printed results."""
from __future__ import annotations

import numpy as np

from ..model import analytical as an
from ..model.discretize import Payload
from ..simulation.scene import Scene
from ..model.section import multilayer_section  # noqa: F401  (documented reference)
from .core import INDEPENDENT_SOLUTION, PUBLISHED_FORMULA, PUBLISHED_NUMBER, Experiment, experiment

ACT = "pedot-micro"
L, EI, M_BEAM = 6e-3, 1 / 4.86e7, 0.695e-6
G = 9.81


def settled(scene, force=0.0, moment=0.0):
    """Tip position (m, clamp frame) at static equilibrium under a dead tip force and couple."""
    scene.reset()
    scene.set_tip_force(force)
    scene.set_tip_moment(moment)
    scene.settle(tol=1e-9)
    return scene.tip_position()


def free_vibration_frequency(scene, periods: int = 12) -> float:
    """First frequency (Hz) from free vibration: released from the static shape of a small tip
    force, the mean spacing of upward zero crossings of the tip deflection."""
    scene.reset()
    scene.set_tip_force(1e-3 * scene.layout.length * an.lateral_stiffness(
        scene.layout.length, float(scene.actuator.flexural_rigidity_at(0)[0])))
    scene.settle(tol=1e-10)
    scene.set_tip_force(0.0)
    scene.data.time = 0.0
    n = int(periods / scene.choice.first_frequency / scene.timestep)
    t, y = np.empty(n), np.empty(n)
    for i in range(n):
        scene.step()
        t[i], y[i] = scene.time, scene.tip_position()[1]
    up = np.where((y[:-1] < 0) & (y[1:] >= 0))[0]
    tc = t[up] - y[up] * (t[up + 1] - t[up]) / (y[up + 1] - y[up])
    return 1.0 / np.mean(np.diff(tc))


def _representations():
    """The beam representations this MuJoCo offers (the cable: 3.x only, the rod: 4.x only;
    each builder says, mjeap.model.mjcf)."""
    from ..model.mjcf import BUILDERS
    return tuple(r for r, b in BUILDERS.items() if b.unavailable_reason() is None)


@experiment("mechanics-elastica")
def elastica(quick: bool = False) -> Experiment:
    ex = Experiment("mechanics-elastica", "Tip force and tip couple on the PEDOT beam (20 segments)")
    loads = [0.05, 0.5, 1.0, 2.0, 3.0]
    for rep in _representations():
        sc = Scene(ACT, representation=rep)
        ys, refs = [], []
        for a in loads:
            P = a * EI / L**2
            tip = settled(sc, force=P)
            ref = an.elastica_tip_force(P, L, EI)
            ys.append(tip[1])
            refs.append(ref.tip[1])
            if a == 3.0:
                ex.beam(f"{rep}: settled under P L^2/EI = 3", sc)
            if a in (0.05, 1.0, 3.0):
                ex.check(f"{rep}: tip deflection, P L^2/EI = {a:g}", "m", tip[1], ref.tip[1],
                         "elastica (scipy solve_bvp)", tolerance=0.01, kind=INDEPENDENT_SOLUTION)
        ex.curve("tip force", f"mjeap {rep}", loads, np.array(ys) / L, "P L^2 / EI (-)", "tip deflection / L (-)", "o")
        for kl in (0.3, 2.0):
            M = kl * EI / L
            settled(sc, moment=M)
            ex.check(f"{rep}: tip-couple arc curvature, kappa L = {kl:g}", "1/m", sc.tip_curvature(), kl / L,
                     "exact continuum solution: a tip couple bends the elastica into a circular arc, kappa = M / EI",
                     tolerance=0.005, kind=INDEPENDENT_SOLUTION)
    fine = np.linspace(0.02, 3.0, 25)
    ex.curve("tip force", "elastica (scipy solve_bvp)", fine,
             [an.elastica_tip_force(a * EI / L**2, L, EI).tip[1] / L for a in fine],
             "P L^2 / EI (-)", "tip deflection / L (-)")
    ex.curve("tip force", "Euler-Bernoulli P L^3 / 3EI", fine, fine / 3, "P L^2 / EI (-)", "tip deflection / L (-)", ":")
    # convergence of the hinge chain
    Ns = [4, 8, 16, 32]
    P = EI / L**2
    ref = an.elastica_tip_force(P, L, EI).tip[1]
    errs = [abs(settled(Scene(ACT, segments=N), force=P)[1] - ref) / ref for N in Ns]
    order = -np.polyfit(np.log(Ns), np.log(errs), 1)[0]
    ex.check("hinge chain: convergence order of the tip error", "-", order, 2.0,
             "order of the error against the elastica (scipy solve_bvp); 2 = the composite midpoint rule's",
             tolerance=0.15, kind=INDEPENDENT_SOLUTION,
             note="a chain converging to another limit than the elastica leaves a constant error: order near 0")
    ex.curve("convergence", "mjeap hinge chain", Ns, np.array(errs) * 100, "segments N", "tip deflection error (%)", "o-")
    ex.curve("convergence", "N^-2 through N = 4", Ns, errs[0] * 100 * (Ns[0] / np.array(Ns)) ** 2,
             "segments N", "tip deflection error (%)", "--")
    return ex


@experiment("mechanics-vibration")
def vibration(quick: bool = False) -> Experiment:
    ex = Experiment("mechanics-vibration", "First natural frequency with NdFeB tip masses (free vibration)")
    masses = [0.0, 3.15e-6, 12.6e-6]
    for rep in (("hinge",) if quick else _representations()):
        fs, refs = [], []
        for m in masses:
            pay = Payload(m, L) if m else None
            sc = Scene(ACT, representation=rep, payload=pay, damping_ratio=0.005)
            ref = an.natural_frequencies(L, EI, M_BEAM / L, tip_mass=m, tip_inertia=pay.inertia if pay else 0.0, n=1)[0]
            f = free_vibration_frequency(sc)
            if m == masses[-1]:
                ex.beam(f"{rep}: {m * 1e6:g} mg at the tip, end of the free vibration", sc)
            fs.append(f)
            refs.append(ref)
            ex.check(f"{rep}: f1 with {m * 1e6:g} mg at the tip", "Hz", f, ref,
                     "continuum cantilever with tip mass and rotary inertia: root of its characteristic equation "
                     "(Erturk & Inman 2011 eq. 3.16, brentq; equals the solve_bvp eigenproblem to 1e-11)",
                     tolerance=0.02, kind=INDEPENDENT_SOLUTION)
        ex.curve("f1", f"mjeap {rep}", np.array(masses) * 1e6, fs, "tip mass (mg)", "f1 (Hz)", "o")
    mm = np.linspace(0, 12.6e-6, 30)
    ex.curve("f1", "characteristic equation", mm * 1e6,
             [an.natural_frequencies(L, EI, M_BEAM / L, tip_mass=m, tip_inertia=Payload(m, L).inertia if m else 0.0,
                                     n=1)[0] for m in mm], "tip mass (mg)", "f1 (Hz)")
    return ex


@experiment("mechanics-buckling")
def buckling(quick: bool = False) -> Experiment:
    ex = Experiment("mechanics-buckling", "PEDOT beam standing up under a tip payload: buckling and post-buckling")
    P_cr = an.critical_tip_load(L, EI, M_BEAM * G / L)
    ex.notes.append(f"P_cr with the beam's own weight (scipy shooting) = {P_cr:.5g} N, "
                    f"{(P_cr / an.buckling_load(L, EI) - 1) * 100:+.2f} % from the weightless Euler load.")
    for factor in (0.97, 1.03, 1.10):
        sc = Scene(ACT, orientation="up", payload=Payload(factor * P_cr / G, L))
        sc.set_hinge_angles(np.full(sc.layout.segments, 1e-3 / sc.layout.segments))  # small push
        y0 = abs(sc.tip_position()[1])
        sc.settle(tol=1e-9)     # run to rest (first-mode damping raised to 0.3 while settling)
        tip = sc.tip_position()
        if factor < 1:
            ex.check(f"{factor:g} P_cr: lateral tip deflection at rest after a small push", "m", abs(tip[1]), 0.0,
                     "below P_cr of the column with its own weight (shooting: scipy solve_ivp + brentq) it returns "
                     "straight (tolerance: 1 % of the push)", tolerance=0.01 * y0,
                     error_kind="absolute", kind=INDEPENDENT_SOLUTION)
        else:
            ex.beam(f"{factor:g} P_cr: post-buckled, at rest", sc)
            x_ref, d_ref, _ = an.postbuckled_column(factor, L)
            ex.check(f"{factor:g} P_cr: post-buckled tip deflection", "m", abs(tip[1]), d_ref,
                     "post-buckled elastica (elliptic integrals, Timoshenko & Gere 1961 sec. 2.7)", tolerance=0.03,
                     kind=INDEPENDENT_SOLUTION)
            ex.curve("post-buckling", "mjeap hinge chain", [factor], [abs(tip[1]) / L],
                     "P / P_cr (-)", "tip deflection / L (-)", "o")
    ratios = np.linspace(1.0, 1.3, 30)
    ex.curve("post-buckling", "elastica (Timoshenko & Gere)", ratios,
             [an.postbuckled_column(r, L)[1] / L for r in ratios], "P / P_cr (-)", "tip deflection / L (-)")
    return ex


@experiment("mechanics-section")
def section(quick: bool = False) -> Experiment:
    from ..model.catalog import PVDF_60
    ex = Experiment("mechanics-section", "Multilayer cross-section of 60PVDF (thesis eqs. 3.1-3.6)")
    s = PVDF_60.section_at(0.0)
    ex.check("neutral axis z_c", "m", s.neutral_axis, 0.132e-3,
             "Metello 2020, Table 3.6: z_c = 0.132 mm (eqs. 3.1-3.3)", tolerance=0.01, kind=PUBLISHED_NUMBER)
    ex.check("flexural rigidity EI", "N m^2", s.flexural_rigidity, 2.703e-5,
             "Metello 2020, Table 3.7: EI = 2.703e7 Pa mm^4 (eqs. 3.4-3.5)", tolerance=0.01,
             kind=PUBLISHED_NUMBER)
    # the layer model's beam (the catalog's pvdf-60 takes its EI from the measured 0 V slope)
    from dataclasses import replace
    sc = Scene(replace(PVDF_60, flexural_rigidity=None), gravity=False)
    P = 1e-5
    tip = settled(sc, force=P)
    ex.beam("60PVDF (layer model) under a 10 uN tip force (deflection as computed)", sc)
    ex.check("simulated 52 mm beam, layer-model EI: tip compliance", "m/N", tip[1] / P,
             sc.layout.length**3 / (3 * 2.703e-5),
             "Metello 2020 eq. (3.12), z_m = W L^3 / (3 EI), with the EI of its Table 3.7 (2.703e-5 N m^2)",
             tolerance=0.01, kind=PUBLISHED_FORMULA)
    ex.notes.append("The catalog's pvdf-60 uses the EI identified from its measured 0 V slope (23 % below this "
                    "layer model, see metello2020); this experiment checks the layer model itself.")
    return ex
