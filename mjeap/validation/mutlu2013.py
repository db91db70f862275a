"""Mutlu, Alici, Li 2013: the PPy trilayer as a 16-link compliant chain.

References: the blocked tip force against the blocking force the drive is given (Dadras et al. 2021
eq. 6: the uniform moment (2/3) F_B L and the tip force F_B give the same tip deflection), a
published formula that checks the drive's moment; the continuum beam with the same EI under
the drive's moment (the exact arc, an independent solution) for the chain's shape. The
identification tool's recovery of the known truth of a simulated, noisy tip trajectory is
shown as comparison rows: the data come from the same simulator, a round trip, not a
reference (tests/analysis/test_identify.py tests the tool).
"""
from __future__ import annotations

import numpy as np

from ..model import analytical as an
from ..analysis.identify import fit_hinge_parameters, simulate_tip
from ..simulation.rollout import rollout
from ..simulation.scene import Scene
from .core import INDEPENDENT_SOLUTION, PUBLISHED_FORMULA, Experiment, experiment

PAPER = "Mutlu et al. 2013"


def arc_points(s, kappa):
    """Points at arc length s of a clamped arc of curvature kappa (clamp frame)."""
    s = np.asarray(s, float)
    if abs(kappa) < 1e-12:
        return np.column_stack([s, np.zeros_like(s)])
    return np.column_stack([np.sin(kappa * s) / kappa, (1 - np.cos(kappa * s)) / kappa])


@experiment("mutlu2013-chain")
def chain(quick: bool = False) -> Experiment:
    ex = Experiment("mutlu2013-chain", "PPy trilayer: 16-link chain against the continuum beam (0.25-1.00 V)")
    scene = Scene("ppy-trilayer", segments=16)
    L, EI = scene.layout.length, float(scene.actuator.flexural_rigidity_at(0.0)[0])
    lay = scene.layout
    s_nodes = np.concatenate([[0.0], (np.arange(lay.segments) + 0.5) * lay.ds, [L]])
    from ..drives import make_drive
    p = make_drive(None, scene).params
    F1, tau = float(p["blocking_force_per_volt"]), float(p["time_constant"])
    arc = "exact continuum solution, same EI: a uniform moment M bends the elastica into a circular arc, kappa = M/EI"
    duration = 12.0
    for v in (0.25, 0.5, 0.75, 1.0):
        r = rollout(scene, f"step:{v}V", duration, progress=False)
        M = r.signals["drive_moment (N m)"][-1]
        kappa = M / EI
        cl = r.centreline[-1][:, :2]
        ref = arc_points(s_nodes, kappa)
        dev = np.max(np.linalg.norm(cl - ref, axis=1))
        ex.check(f"{v:g} V, settled: largest node distance from the arc of the drive's moment / L", "-", dev / L, 0.0,
                 arc, tolerance=0.005, error_kind="absolute", kind=INDEPENDENT_SOLUTION,
                 note="M is the drive's moment signal (an input here); the blocked-force row checks M")
        x, y, _ = an.arc_tip_moment(M, L, EI)
        ex.check(f"{v:g} V, settled: tip deflection under the drive's moment", "m", r.tip_position[-1, 1], y, arc,
                 tolerance=0.005, kind=INDEPENDENT_SOLUTION)
        # the drive's moment, checked: the blocked tip pushes with the blocking force the drive is given
        F_B = F1 * v * (1 - np.exp(-duration / tau))
        side = np.sign(r.tip_position[-1, 1])
        ys = []
        for F in (F_B, 1.05 * F_B):
            scene.set_tip_force(-side * F)
            ys.append(side * rollout(scene, f"step:{v}V", duration, progress=False).tip_position[-1, 1])
        scene.set_tip_force(0.0)
        F_blocked = F_B - ys[0] * 0.05 * F_B / (ys[1] - ys[0])
        ex.check(f"{v:g} V, settled: blocked tip force", "N", F_blocked, F_B,
                 "Dadras et al. 2021 eq. (6), M_e = (2/3) l_e F_e: the uniform moment (2/3) F_B L and the tip force F_B give the "
                 "same tip deflection, so the blocked tip pushes with the blocking force F_B(t, V) that Mutlu et al. 2013's "
                 f"model (its eqs. 12-14) is given; here F_1 V (1 - e^(-t/tau)), the catalog's F_1 = {F1 * 1e3:g} mN/V, "
                 f"tau = {tau:g} s (estimates), at t = {duration:g} s", tolerance=0.01, kind=PUBLISHED_FORMULA,
                 note="the tip force that holds the tip at 0, interpolated between two runs; the 16 links (about "
                      "+0.1 %) and the exact elastica (+0.16 % over 3 M/(2L) at 1 V, scipy solve_bvp) put it "
                      "slightly above F_B")
        # tip path: distance of every sampled tip position from the arc-tip locus
        kk = np.linspace(0, 1.05 * kappa, 400)
        locus = np.array([an.arc_tip_moment(k * EI, L, EI)[:2] for k in kk])
        d = np.min(np.linalg.norm(r.tip_position[:, None, :2] - locus[None], axis=2), axis=1)
        ex.check(f"{v:g} V: tip path, largest distance from the arc-tip locus / L", "-", d.max() / L, 0.0,
                 "tips of the exact continuum arcs (circular, kappa from 0 to 1.05 x the settled one): the quasi-static "
                 "path (tau = 2 s >> 1/f1)", tolerance=0.005, error_kind="absolute", kind=INDEPENDENT_SOLUTION)
        ex.curve("shapes", f"mjeap 16 links, {v:g} V", cl[:, 0] * 1e3, cl[:, 1] * 1e3, "x (mm)", "y (mm)", "o")
        fine = arc_points(np.linspace(0, L, 100), kappa)
        ex.curve("shapes", f"continuum arc, {v:g} V", fine[:, 0] * 1e3, fine[:, 1] * 1e3, "x (mm)", "y (mm)")
        ex.curve("tip paths", f"mjeap tip, {v:g} V", r.tip_position[::25, 0] * 1e3, r.tip_position[::25, 1] * 1e3,
                 "tip x (mm)", "tip y (mm)", ".")
        ex.rollouts.append((f"{v:g} V step", r, scene.rotation))
    ex.curve("tip paths", "continuum arc-tip locus", locus[:, 0] * 1e3, locus[:, 1] * 1e3, "tip x (mm)", "tip y (mm)")
    ex.notes.append(
        f"Drive: blocking force {scene.actuator.id} 0.5 mN/V with a 2 s time constant (estimates, see the "
        "catalog) as a uniform moment (2/3) F_B L at every joint, as Mutlu et al. 2013's model reads once its "
        "garbled eqs. 12-14 are made mechanically consistent. Horizontal bending plane (no gravity in it).")
    return ex


@experiment("mutlu2013-identify")
def identify(quick: bool = False) -> Experiment:
    ex = Experiment("mutlu2013-identify", "Mutlu et al. 2013's identification as a tool: joint stiffness and damping from a noisy tip trajectory")
    scene = Scene("ppy-trilayer", segments=16)
    k0, b0 = float(scene.hinge_stiffness()[0]), float(scene.hinge_damping()[0])
    truth = (1.3 * k0, 10.0 * b0)
    drive_params = {"time_constant": 0.01}
    t = np.arange(0.001, 0.3, 0.001)
    clean = simulate_tip(scene, *truth, "step:1V", 0.3, t, drive_params=drive_params)
    rng = np.random.default_rng(2013)
    noisy = clean + rng.normal(0.0, 0.01 * np.ptp(clean), len(t))
    fit = fit_hinge_parameters(scene, t, noisy, "step:1V", drive_params=drive_params, initial=(k0, b0))
    fitted = simulate_tip(scene, fit.stiffness, fit.damping, "step:1V", 0.3, t, drive_params=drive_params)
    round_trip = ("a round trip, not a reference: the data are simulated by the model that is fitted (the tool is "
                  "tested in tests/analysis/test_identify.py)")
    ex.check("joint stiffness k", "N m/rad", fit.stiffness, truth[0], "known truth of the simulated data",
             note=round_trip)
    ex.check("joint damping b", "N m s/rad", fit.damping, truth[1], "known truth of the simulated data",
             note=round_trip)
    ex.check("RMS residual / noise level", "-", fit.rms_residual / (0.01 * np.ptp(clean)), 1.0,
             "white noise of 1 % of the swing: a good fit leaves the noise", note=round_trip)
    ex.curve("tip deflection", "simulated measurement (truth + 1 % noise)", t, noisy * 1e3, "time (s)", "tip deflection (mm)", ".")
    ex.curve("tip deflection", "mjeap with the fitted k, b", t, fitted * 1e3, "time (s)", "tip deflection (mm)")
    ex.notes += [
        f"Truth: k = 1.3 x the catalog hinge ({truth[0]:.4g} N m/rad), b = {truth[1]:.4g} N m s/rad "
        "(damping ratio near 0.5, so the mechanical transient is visible); a 1 V step with a fast "
        "(10 ms) blocking-force rise, sampled at 1 kHz for 0.3 s with Gaussian noise of 1 % of the swing. "
        f"Start from the catalog values; {fit.evaluations} simulations; 1-sigma from the Jacobian (the "
        "residual's correlation counted, mjeap.analysis.identify.covariance): "
        f"k +- {fit.stiffness_std / fit.stiffness * 100:.2f} %, b +- {fit.damping_std / fit.damping * 100:.2f} %.",
        "With the catalog's slow (2 s) blocking force the damping is not identifiable (b/k << 2 s): the "
        "trajectory is quasi-static. Measured data must excite the mechanical transient to fit b.",
    ]
    return ex
