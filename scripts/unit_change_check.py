"""Proof that the internal time unit (ms -> s) moves results by float rounding only: every
catalog actuator in every representation this MuJoCo builds, its golden scenario
(mjeap.validation.golden.SCENARIOS), run with the old units (mm, mg, ms) and the new
(mm, mg, s) on the lockstep loop and, where the drive compiles in, the native engine;
prints max |difference| / swing of the tip curvature per run (models with equality
constraints, the rod, also with the solver run to convergence, opt.tolerance = 0; runs that
move by more than 1e-10 of the swing also against the old units nudged by 1e-15, the run's own
sensitivity to float rounding) and the conditioning of each
model (smallest body mass and inertia, largest joint stiffness and damping, timestep and
gravity, internal units) as JSON.

    python scripts/unit_change_check.py [--out FILE] [--duration-scale 0.25]
"""
import argparse
import sys
import json

import numpy as np

from mjeap.assets import iter_assets
from mjeap.model.mjcf import BUILDERS
from mjeap.simulation.rollout import rollout
from mjeap.simulation.scene import Scene
from mjeap.units import UnitSystem
from mjeap.validation.golden import SCENARIOS
from mjeap.versions import MUJOCO_VERSION

OLD = UnitSystem(1e-3, 1e-6, 1e-3)
NEW = UnitSystem(1e-3, 1e-6, 1.0)
#: the old units with the time unit one part in 1e15 off: the same physics, other roundings;
#: how far this moves a run is the run's own sensitivity to float rounding (its baseline)
NUDGED = UnitSystem(1e-3, 1e-6, 1e-3 * (1 + 1e-15))
#: runs that move by more than this (of the swing) also get the rounding baseline
BASELINE_ABOVE = 1e-10


def conditioning(scene: Scene) -> dict:
    """The model's magnitudes in its internal units (what MuJoCo's absolute floors see)."""
    m = scene.model
    body = m.body_mass[1:] > 0
    stiff = m.jnt_stiffness[m.jnt_stiffness > 0]
    damp = m.dof_damping[m.dof_damping > 0]
    return {"min_body_mass": float(m.body_mass[1:][body].min()),
            "min_body_inertia": float(m.body_inertia[1:][body][m.body_inertia[1:][body] > 0].min()),
            "max_joint_stiffness": float(stiff.max()) if stiff.size else 0.0,
            "max_dof_damping": float(damp.max()) if damp.size else 0.0,
            "timestep": float(m.opt.timestep), "gravity": float(np.linalg.norm(m.opt.gravity)),
            # from a finite-difference stiffness (cable, rod): its rounding / eps differs per units
            "rayleigh_beta_s": float(scene.choice.rayleigh_beta),
            "solver_tolerance": float(m.opt.tolerance)}


def run(aid, rep, units, engine, scale, converged=False):
    kw, wave, duration, k0, params = SCENARIOS[aid]
    kw = dict(kw)
    if rep != "hinge":
        kw.pop("segments", None)
    s = Scene(aid, representation=rep, units=units, **kw)
    d = duration * scale
    if converged:       # the solver to convergence: its stopping rule is not unit-free (below)
        s.model.opt.tolerance = 0.0
    r = rollout(s, wave, d, drive_params=params, initial_curvature=k0, progress=False,
                sample_interval=d / 200, engine=engine)
    return s, r.tip_curvature


def main(argv=None):
    from mjeap.io.commandline import arg_output
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=None, type=arg_output(), help="also write the results here (JSON)")
    ap.add_argument("--duration-scale", type=float, default=1.0)
    ap.add_argument("--only", nargs="*", help="ACTUATOR:REPRESENTATION pairs (default: all)")
    a = ap.parse_args(argv)
    rows = []
    for aid, rep in iter_assets():
        if BUILDERS[rep].unavailable_reason() is not None or (a.only and f"{aid}:{rep}" not in a.only):
            continue
        for engine in ("loop", "native"):
            try:
                so, ko = run(aid, rep, OLD, engine, a.duration_scale)
            except Exception as e:      # the native engine refuses drives without a native form
                if engine == "native":
                    continue
                raise
            sn, kn = run(aid, rep, NEW, engine, a.duration_scale)
            swing = float(np.ptp(ko))
            dev = float(np.max(np.abs(kn - ko)))
            beta_change = sn.choice.rayleigh_beta / so.choice.rayleigh_beta - 1
            row = {"actuator": aid, "rayleigh_beta_relative_change": float(beta_change), "representation": rep, "engine": engine, "swing_1_m": swing,
                   "max_difference_1_m": dev, "difference_over_swing": dev / swing if swing else dev,
                   "old": conditioning(so), "new": conditioning(sn)}
            if row["difference_over_swing"] > BASELINE_ABOVE:
                _, kb = run(aid, rep, NUDGED, engine, a.duration_scale)
                row["rounding_baseline_over_swing"] = float(np.max(np.abs(kb - ko))) / swing
            if engine == "loop" and so.model.neq:
                # MuJoCo stops its solver on improvement < tol (an acceleration squared) or
                # gradient < tol (an acceleration): no one tolerance keeps both across units
                _, kc_old = run(aid, rep, OLD, engine, a.duration_scale, converged=True)
                _, kc_new = run(aid, rep, NEW, engine, a.duration_scale, converged=True)
                row["difference_over_swing_solver_converged"] = float(np.max(np.abs(kc_new - kc_old))) / swing
            rows.append(row)
            conv = row.get("difference_over_swing_solver_converged")
            base = row.get("rounding_baseline_over_swing")
            print(f"{aid:16s} {rep:6s} {engine:6s} swing {swing:.4g} 1/m, max diff/swing {row['difference_over_swing']:.3g}"
                  + ("" if base is None else f" (old units nudged by 1e-15: {base:.3g})")
                  + ("" if conv is None else f" (solver converged: {conv:.3g})")
                  + (f" (Rayleigh beta moved {beta_change:.2g})" if beta_change else ""), flush=True)
    out = {"mujoco": MUJOCO_VERSION, "duration_scale": a.duration_scale, "runs": rows,
           "worst_difference_over_swing": max(r["difference_over_swing"] for r in rows)}
    if a.out:
        from mjeap.io.outputs import write_text
        write_text(a.out, json.dumps(out, indent=1), "--out")
    print("worst", out["worst_difference_over_swing"])


if __name__ == "__main__":
    from mjeap.io.commandline import run_script
    sys.exit(run_script(main))
