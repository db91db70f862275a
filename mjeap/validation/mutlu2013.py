"""Seed 001 (Mutlu, Alici, Li 2013): the PPy trilayer as a 16-link compliant chain.

References: the continuum beam with the same EI under the drive's uniform moment
(2/3) F_B L (exact arc), and, for the identification tool, the known truth of a simulated,
noisy tip trajectory.
"""
from __future__ import annotations

import numpy as np

from .. import analytical as an
from ..identify import fit_hinge_parameters, simulate_tip
from ..rollout import rollout
from ..scene import Scene
from .core import Experiment, experiment

PAPER = "Mutlu et al. 2013 (seed 001)"


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
    for v in (0.25, 0.5, 0.75, 1.0):
        r = rollout(scene, f"step:{v}V", 12.0, progress=False)
        M = r.signals["drive_moment (N m)"][-1]
        kappa = M / EI
        cl = r.centreline[-1][:, :2]
        ref = arc_points(s_nodes, kappa)
        dev = np.max(np.linalg.norm(cl - ref, axis=1))
        ex.check(f"{v:g} V, settled: largest node distance from the arc / L", "-", dev / L, 0.0,
                 "continuum beam, same EI, uniform moment (2/3) F_B L: exact arc", tolerance=0.005,
                 error_kind="absolute")
        x, y, _ = an.arc_tip_moment(M, L, EI)
        ex.check(f"{v:g} V, settled: tip deflection", "m", r.tip_position[-1, 1], y, "exact arc, kappa = M/EI",
                 tolerance=0.005)
        # tip path: distance of every sampled tip position from the arc-tip locus
        kk = np.linspace(0, 1.05 * kappa, 400)
        locus = np.array([an.arc_tip_moment(k * EI, L, EI)[:2] for k in kk])
        d = np.min(np.linalg.norm(r.tip_position[:, None, :2] - locus[None], axis=2), axis=1)
        ex.check(f"{v:g} V: tip path, largest distance from the arc-tip locus / L", "-", d.max() / L, 0.0,
                 "quasi-static continuum (tau = 2 s >> 1/f1)", tolerance=0.005, error_kind="absolute")
        ex.curve("shapes", f"mjeap 16 links, {v:g} V", cl[:, 0] * 1e3, cl[:, 1] * 1e3, "x (mm)", "y (mm)", "o")
        fine = arc_points(np.linspace(0, L, 100), kappa)
        ex.curve("shapes", f"continuum arc, {v:g} V", fine[:, 0] * 1e3, fine[:, 1] * 1e3, "x (mm)", "y (mm)")
        ex.curve("tip paths", f"mjeap tip, {v:g} V", r.tip_position[::25, 0] * 1e3, r.tip_position[::25, 1] * 1e3,
                 "tip x (mm)", "tip y (mm)", ".")
        ex.rollouts.append((f"{v:g} V step", r, scene.rotation))
    ex.curve("tip paths", "continuum arc-tip locus", locus[:, 0] * 1e3, locus[:, 1] * 1e3, "tip x (mm)", "tip y (mm)")
    ex.notes.append(
        f"Drive: blocking force {scene.actuator.id} 0.5 mN/V with a 2 s time constant (estimates, see the "
        "catalog) as a uniform moment (2/3) F_B L at every joint, as seed 001's model reads once its "
        "garbled eqs. 12-14 are made mechanically consistent. Horizontal bending plane (no gravity in it).")
    return ex


@experiment("mutlu2013-identify")
def identify(quick: bool = False) -> Experiment:
    ex = Experiment("mutlu2013-identify", "Seed 001's identification as a tool: joint stiffness and damping from a noisy tip trajectory")
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
    ex.check("joint stiffness k", "N m/rad", fit.stiffness, truth[0], "known truth of the simulated data", tolerance=0.02)
    ex.check("joint damping b", "N m s/rad", fit.damping, truth[1], "known truth of the simulated data", tolerance=0.02)
    ex.check("RMS residual / noise level", "-", fit.rms_residual / (0.01 * np.ptp(clean)), 1.0,
             "white noise of 1 % of the swing: a good fit leaves the noise", tolerance=0.1)
    ex.curve("tip deflection", "simulated measurement (truth + 1 % noise)", t, noisy * 1e3, "time (s)", "tip deflection (mm)", ".")
    ex.curve("tip deflection", "mjeap with the fitted k, b", t, fitted * 1e3, "time (s)", "tip deflection (mm)")
    ex.notes += [
        f"Truth: k = 1.3 x the catalog hinge ({truth[0]:.4g} N m/rad), b = {truth[1]:.4g} N m s/rad "
        "(damping ratio near 0.5, so the mechanical transient is visible); a 1 V step with a fast "
        "(10 ms) blocking-force rise, sampled at 1 kHz for 0.3 s with Gaussian noise of 1 % of the swing. "
        f"Start from the catalog values; {fit.evaluations} simulations; 1-sigma from the Jacobian: "
        f"k +- {fit.stiffness_std / fit.stiffness * 100:.2f} %, b +- {fit.damping_std / fit.damping * 100:.2f} %.",
        "With the catalog's slow (2 s) blocking force the damping is not identifiable (b/k << 2 s): the "
        "trajectory is quasi-static. Measured data must excite the mechanical transient to fit b.",
    ]
    return ex
