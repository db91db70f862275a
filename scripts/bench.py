#!/usr/bin/env python
"""Benchmarks, printed as JSON (and written with --json FILE).

models: every shipped model file this MuJoCo loads (mjeap.assets.path: assets/mjcf, in seconds),
as a user plays it (mjeap.load_mjcf, MuJoCo's own stepping loop, one thread, its drive held off
rest): steps per second and simulated seconds per wall second (the real-time factor).

rollout: Dadras et al. 2021's heaviest experiment (pedot-micro, 12.6 mg at 6.27 mm, standing up,
3 Vpp square wave at 0.1 Hz, 20 s) with the drive and the recording on: wall time and
real-time factor, the drive's own cost per step, and the peak-to-peak tip curvature
against a run at half the timestep and twice the segments.

drives: cost of one drive step (us) for every drive on its actuator's 20-hinge beam.

threaded: the lockstep loop against MuJoCo's native threaded rollout (open-loop piezo
drive): one rollout, and a batch of 16 on 1 and 2 threads.

elastica: the pedot-micro cantilever under a dead tip force with P L^2/EI = 1, damped
(first-mode damping ratio 0.7 in both codes) and settled over 0.05 s simulated, in mjeap
and in PyElastica 1.0 (optional, benchmark only: pip install -e ".[bench]"), with the tip
error against the elastica (scipy solve_bvp) and the wall-time ratio; also with the
drive callback running every step, and with the model mjeap chooses for PyElastica's tip
error as its accuracy target.

sweep: rollouts per second of a 16-point sweep on 1 and 2 local worker processes, and the
memory of one rollout.

native: Dadras et al. 2021's drive compiled into the model (mjeap.drives.native) against the lockstep loop,
side by side: the heaviest experiment as one rollout, a batch of 16 on 2 threads against the
loop one by one, mj_step of the native model against the bare beam, and the stability
map's 30 s points per second on 2 workers with either engine.

accuracy: runs at a stated accuracy (mjeap.simulation.accuracy) against the default model, side by
side: Dadras et al. 2021's heaviest run at 1e-2 and 1e-3 (wall, estimated and true error), a batch of
16 at 1e-2 on 2 threads against the loop one by one, the stability map's points at 1e-2,
where the native step's time goes (MuJoCo's timers) and the accuracy claim on seeded cases.

early_stop: the stability map's points at 30 s, and at 60 s run to the end and stopped once
periodic (stop_when_periodic=1e-2): points per second and where each stopped.

hamr_walk_env: mjeap/HamrWalk-v0's env steps per second and real-time factor on one core:
its learning model (2 segments per actuator, a 100 us step sized for the loaded system)
beside the default walker model (4 segments, 4.51 us), and the wall hours of a 10^6-step
learning run.

optimize: the cost of a design optimisation beside a plain sweep of the same resolution. The
issue's question on a uniform PZT-5H bimorph file (mjeap optimize: maximise free_deflection
over actuator.length 5-15 mm subject to first_frequency >= 800 Hz, step:200V for 0.05 s, 20
segments), whose optimum is known in closed form (L* from beta_1, tests/studies/test_optimize.py):
SLSQP (3 starts) and differential evolution, evaluations, wall and their error against L*;
beside them the grid sweep of the same two metrics whose spacing is the 1 % the test asks of
the optimiser (2 workers), its best feasible point's error and wall, and the number of grid
points a sweep would need to match each optimiser's own error.

show: mjeap show's time per file (the catalog and examples/actuators): the first describe()
of each file in one process (the designer's first numbers from closed forms and the
linearised model, the scene built) and the best of three more; and the whole command in a
fresh process, beside importing the package alone (what a cold start costs).
"""
import argparse
import json
import os
import platform
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
os.environ.setdefault("MUJOCO_GL", "disable")

import mujoco  # noqa: E402
import numpy as np  # noqa: E402

from mjeap import Scene  # noqa: E402


def time_steps(model, data, min_seconds=0.5):
    """Steps per second of mj_step on one thread, measured over at least ``min_seconds``."""
    n = 1000
    while True:
        t0 = time.perf_counter()
        mujoco.mj_step(model, data, nstep=n)
        dt = time.perf_counter() - t0
        if dt >= min_seconds:
            return n / dt
        n = int(n * max(2.0, 1.2 * min_seconds / max(dt, 1e-6)))


def bench_models(min_seconds):
    """Every shipped model file this MuJoCo loads (mjeap.assets.path), as a user plays it
    (mjeap.load_mjcf: MuJoCo's own stepping loop, one thread), its drive held a tenth of its
    range off rest so that the beam moves: simulated seconds per wall second (the
    real-time factor; below 1 the file plays slower than real time in MuJoCo's viewer)."""
    from mjeap import load_mjcf
    from mjeap.assets import iter_assets, path
    from mjeap.errors import ParameterError
    from mjeap.model.fields import read_units
    rows = []
    for aid, rep in iter_assets():          # every shipped file ...
        try:
            f = path(aid, rep)              # ... that this MuJoCo loads
        except ParameterError:
            continue
        m = load_mjcf(f)
        d = mujoco.MjData(m)
        rest = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_KEY, "rest")
        if rest >= 0:
            mujoco.mj_resetDataKeyframe(m, d, rest)
        if m.nu:
            lo, hi = m.actuator_ctrlrange[:, 0], m.actuator_ctrlrange[:, 1]
            d.ctrl[:] = np.clip(d.ctrl + 0.1 * (hi - lo), lo, hi)
        sps = time_steps(m, d, min_seconds)
        dt = m.opt.timestep * read_units(m).time
        rows.append({"file": f.name, "actuator": aid, "representation": rep, "nv": m.nv, "timestep_s": dt,
                     "steps_per_s": sps, "real_time_factor": sps * dt})
    return rows


def bench_rollout(tmpdir):
    from mjeap import Payload, rollout
    from mjeap.drives import make_drive

    def scene(**kw):
        return Scene("pedot-micro", orientation="up", payload=Payload(12.6e-6, 6.27e-3), **kw)

    args = dict(voltage="square:1.5V@0.1Hz", duration=20.0, initial_curvature=-303.0, progress=False)
    s = scene()
    t0 = time.perf_counter()
    r = rollout(s, rrd=Path(tmpdir) / "bench.rrd", **args)
    wall = time.perf_counter() - t0
    # the drive alone, per step, on the settled scene
    drv = make_drive(None, s)
    drv.reset(0.0)
    n = 20000
    t1 = time.perf_counter()
    for _ in range(n):
        drv.step(1.5, s.timestep)
    drive_us = (time.perf_counter() - t1) / n * 1e6
    t2 = time.perf_counter()
    mujoco.mj_step(s.model, s.data, nstep=n)
    mj_us = (time.perf_counter() - t2) / n * 1e6
    fine = scene(segments=2 * s.layout.segments, timestep=s.timestep / 2)
    rf = rollout(fine, **args)
    late, late_f = r.time >= 10, rf.time >= 10
    p2p, p2p_f = float(np.ptp(r.tip_curvature[late])), float(np.ptp(rf.tip_curvature[late_f]))
    return {"case": "pedot-micro, 12.6 mg @ 6.27 mm, up, square 3 Vpp 0.1 Hz, 20 s, recording on",
            "timestep_s": s.timestep, "segments": s.layout.segments, "steps": r.meta["steps"],
            "wall_time_s": wall, "real_time_factor": 20.0 / wall,
            "drive_step_us": drive_us, "mj_step_us": mj_us,
            "loop_us_per_step": r.meta["wall_time_s"] / r.meta["steps"] * 1e6,
            "p2p_curvature_per_m": p2p, "p2p_curvature_fine_per_m": p2p_f,
            "p2p_relative_difference": p2p / p2p_f - 1,
            "fine": {"timestep_s": fine.timestep, "segments": fine.layout.segments}}


#: drives no catalog actuator uses, timed on an example file
EXAMPLE_ACTUATORS = {"piezo": "examples/actuators/laminate/pzt-hamr-small.toml"}


def bench_drives(n=20000):
    """Drive step cost (us), 20 hinges, the voltage alternating every step (worst case for
    drives that cache on it)."""
    from mjeap.drives import DRIVES, make_drive
    rows = []
    for name, cls in DRIVES.items():
        example = EXAMPLE_ACTUATORS.get(name)
        if not cls.actuators and example is None:   # a drive no actuator uses ('none'): nothing to time
            continue
        s = Scene(cls.actuators[0] if cls.actuators else str(Path(__file__).resolve().parent.parent / example))
        drv = make_drive(name, s)
        drv.reset(0.0)
        lo, hi = drv.voltage_range()
        v = (0.5 * (lo + hi) + 0.3 * (hi - lo), 0.5 * (lo + hi) + 0.2 * (hi - lo))
        for k in range(100):
            drv.step(v[k % 2], s.timestep)
        t0 = time.perf_counter()
        for k in range(n):
            drv.step(v[k % 2], s.timestep)
        rows.append({"drive": name, "actuator": s.actuator.id, "segments": s.layout.segments,
                     "step_us": (time.perf_counter() - t0) / n * 1e6,
                     "open_loop": drv.closed_loop_reason() is None})
    return rows


def bench_show(repeats=3):
    """mjeap show per file (module text): seconds of describe() first and warm, and of the
    command in a fresh process beside the import alone."""
    import subprocess
    from mjeap.cli import describe
    from mjeap.model.catalog import CATALOG
    root = Path(__file__).resolve().parent.parent
    files = list(CATALOG) + sorted(str(p.relative_to(root)) for p in (root / "examples" / "actuators").rglob("*.toml"))
    rows = []
    for f in files:
        t0 = time.perf_counter()
        describe(str(root / f) if f.endswith(".toml") else f)
        first = time.perf_counter() - t0
        again = []
        for _ in range(repeats):
            t0 = time.perf_counter()
            describe(str(root / f) if f.endswith(".toml") else f)
            again.append(time.perf_counter() - t0)
        rows.append({"file": f, "first_s": first, "again_s": min(again)})
    cold = {}
    for what, argv in (("import_s", [sys.executable, "-c", "import mjeap.cli"]),
                       ("command_s", [sys.executable, "-m", "mjeap.cli", "show", "pzt-hamr-small"])):
        best = []
        for _ in range(repeats):
            t0 = time.perf_counter()
            subprocess.run(argv, cwd=root, check=True, capture_output=True)
            best.append(time.perf_counter() - t0)
        cold[what] = min(best)
    return {"files": rows, "fresh_process": {"file": "pzt-hamr-small", **cold}}


def bench_threaded():
    """Loop vs mujoco.rollout on the HAMR bimorph (open-loop piezo drive), 0.2 s of a
    100 V-biased sine, samples every 1 ms."""
    from mjeap.simulation.rollout import rollout, rollout_batch
    s = Scene("pzt-hamr-small")
    volts = [f"sine:20V@{f:g}Hz,offset=100V" for f in np.linspace(100, 1000, 16)]
    kw = dict(sample_interval=1e-3)
    out = {"case": "pzt-hamr-small, 0.2 s, sine 20 V about 100 V, samples every 1 ms", "timestep_s": s.timestep}
    for engine in ("loop", "threaded"):
        t0 = time.perf_counter()
        r = rollout(s, volts[0], 0.2, engine=engine, **kw)
        out[f"single_{engine}_s"] = time.perf_counter() - t0
    out["steps"] = r.meta["steps"]
    t0 = time.perf_counter()
    for v in volts:
        rollout(s, v, 0.2, engine="loop", **kw)
    out["batch16_loop_s"] = time.perf_counter() - t0
    for nt in (1, 2):
        t0 = time.perf_counter()
        rollout_batch(s, volts, 0.2, nthread=nt, **kw)
        out[f"batch16_threaded_{nt}thread_s"] = time.perf_counter() - t0
    out["batch16_speedup_2threads_vs_loop"] = out["batch16_loop_s"] / out["batch16_threaded_2thread_s"]
    return out


# ------------------------------------------------------------------ elastica benchmark
ELASTICA_ZETA = 0.7      # first-mode damping ratio in both codes: settled well within 0.05 s


def _beam_numbers():
    s = Scene("pedot-micro", gravity=False)
    act = s.actuator
    sec = act.section_at(0.0)
    # the bending stiffness the scene simulates (plane-strain modulus of the wide strip)
    L, w, t, EI = act.length, float(act.width_at(0.0)), sec.thickness, float(act.flexural_rigidity_at(0.0)[0])
    return {"L": L, "w": w, "t": t, "EI": EI, "rho": act.layers[0].density, "E": EI / (w * t**3 / 12),
            "f1": float(s.choice.first_frequency)}


def _mjeap_cantilever(b, T, P, segments, drive=None, repeats=3, engine="loop"):
    """Best-of-``repeats`` wall time of T s simulated; tip at the end (m)."""
    from mjeap import rollout
    s = Scene("pedot-micro", gravity=False, damping_ratio=ELASTICA_ZETA, segments=segments)
    s.set_tip_force(P)
    best = np.inf
    for _ in range(repeats):
        s.reset()
        t0 = time.perf_counter()
        if drive is None:
            s.run(T)
        else:
            rollout(s, "step:0V", T, drive=drive, sample_interval=T, engine=engine)
        best = min(best, time.perf_counter() - t0)
    tip = s.tip_position()
    s.run(0.1 * T)
    moved = float(np.linalg.norm(s.tip_position() - tip) / b["L"])
    return {"segments": segments, "engine": engine if drive else "scene.run", "timestep_s": s.timestep,
            "steps": int(round(T / s.timestep)),
            "integrator": s.integrator, "wall_s": best, "tip_m": tip[:2].tolist(),
            "tip_moved_over_next_10pct_per_L": moved}


def _mjeap_at_accuracy(T, P, target, ref, repeats=3):
    """The same cantilever with Dadras et al. 2021's drive running, mjeap choosing its model for
    ``target`` (mjeap.simulation.accuracy, its quantity sampled at the end only: the settled tip arc's
    curvature against a converged model, relative to its change). The chosen model is then
    built once (as the rod is) and its run timed as the others; its tip is checked against
    the elastica ``ref`` without the drive (an independent reference) and, with the drive,
    against a converged run (40 segments at a quarter of the default step)."""
    from mjeap import rollout
    s = Scene("pedot-micro", gravity=False, damping_ratio=ELASTICA_ZETA)
    s.set_tip_force(P)
    drive = "rc-relaxation"
    t0 = time.perf_counter()
    r = rollout(s, "step:0V", T, drive=drive, sample_interval=T, accuracy=target)
    whole = time.perf_counter() - t0
    a = r.meta["accuracy"]
    m = a["model"]
    v = s.variant(m["segments"], m["timestep"], m["integrator"])
    best = np.inf
    for _ in range(repeats):
        v.reset()
        t0 = time.perf_counter()
        rollout(v, "step:0V", T, drive=drive, sample_interval=T, engine="loop")
        best = min(best, time.perf_counter() - t0)
    tip_drive = v.tip_position()
    v.reset()
    v.run(T)
    tip_bare = v.tip_position()
    conv = s.variant(40, s.timestep / 4, "implicitfast")
    rollout(conv, "step:0V", T, drive=drive, sample_interval=T, engine="loop")
    tip_conv = conv.tip_position()
    return {"target": target, "model": m, "steps": int(round(T / m["timestep"])),
            "estimated_error": a["estimated_error"], "wall_s": best,
            "whole_call_s": whole, "whole_call_runs": [(x["role"], x["segments"], x["timestep"]) for x in a["runs"]],
            "tip_deflection_error": float(tip_bare[1] / ref[1] - 1),
            "tip_deflection_error_with_drive_vs_converged": float((tip_drive[1] - tip_conv[1]) / tip_conv[1]),
            "tip_m_with_drive": tip_drive[:2].tolist(), "converged_tip_m_with_drive": tip_conv[:2].tolist()}


def _pyelastica_cantilever(b, T, P, n, shifted):
    """PyElastica 1.0 Cosserat rod of the same beam: rectangular section (bending and mass
    second moments of the w x t strip; area equal), G = E/3 (nu = 1/2), clamp by
    OneEndFixedBC, dead end force, AnalyticalLinearDamper with a uniform rate 2 zeta omega_1
    (mass-proportional: first-mode damping ratio zeta). Timestep 0.9 x 2/omega_sr, the
    Position-Verlet limit of the fastest mode, the shear-rotation of an element about the
    thin axis, omega_sr^2 = alpha G A / (rho I_2) (independent of the element length).
    ``shifted``: the rod starts half an element behind the clamp, so that the clamped first
    element's centre sits at x = 0 (free length L)."""
    import elastica as ea
    L, w, t, E, rho = b["L"], b["w"], b["t"], b["E"], b["rho"]
    G, A = E / 3.0, w * t
    I0 = A * A / (4 * np.pi)                     # what straight_rod assumes (disk)
    I1, I2, J = t * w**3 / 12, w * t**3 / 12, w * t**3 / 3
    alpha = 4.0 / 3.0                            # PyElastica's shear coefficient
    omega_sr = np.sqrt(alpha * G * A / (rho * I2))
    dt = 0.9 * 2.0 / omega_sr

    class Sim(ea.BaseSystemCollection, ea.Constraints, ea.Forcing, ea.Damping):
        pass

    def build():
        sim = Sim()
        length = L + (0.5 * L / (n - 0.5) if shifted else 0.0)
        rod = ea.CosseratRod.straight_rod(n, np.array([L - length, 0.0, 0.0]), np.array([1.0, 0, 0]),
                                          np.array([0, 1.0, 0]), length, np.sqrt(A / np.pi), rho,
                                          youngs_modulus=E, shear_modulus=G)
        # directors d1 = y (deflection), d2 = z (width), d3 = x: bending in the x-y plane is
        # about d2, the thin axis
        for k, (I, Idisk) in enumerate(((I1, I0), (I2, I0), (J, 2 * I0))):
            rod.bend_matrix[k, k, :] *= I / Idisk
        for k, (I, Idisk) in enumerate(((I1, I0), (I2, I0), (I1 + I2, 2 * I0))):
            rod.mass_second_moment_of_inertia[k, k, :] *= I / Idisk
        for i in range(n):
            rod.inv_mass_second_moment_of_inertia[..., i] = np.linalg.inv(rod.mass_second_moment_of_inertia[..., i])
        sim.append(rod)
        sim.constrain(rod).using(ea.OneEndFixedBC, constrained_position_idx=(0,), constrained_director_idx=(0,))
        sim.add_forcing_to(rod).using(ea.EndpointForces, np.zeros(3), np.array([0.0, P, 0.0]), ramp_up_time=1e-6)
        sim.dampen(rod).using(ea.AnalyticalLinearDamper,
                              uniform_damping_constant=2 * ELASTICA_ZETA * 2 * np.pi * b["f1"], time_step=dt)
        sim.finalize()
        return sim, rod

    import logging
    logging.getLogger().setLevel(logging.ERROR)  # its 'mass moment of inertia below tolerance' notice
    sim, rod = build()                           # warm-up: numba compiles on the first steps
    ea.integrate(ea.PositionVerlet(), sim, 200 * dt, 200, progress_bar=False)
    sim, rod = build()
    steps = int(round(T / dt))
    t0 = time.perf_counter()
    ea.integrate(ea.PositionVerlet(), sim, steps * dt, steps, progress_bar=False)
    wall = time.perf_counter() - t0
    tip = rod.position_collection[:2, -1]
    return {"elements": n, "clamp": "shifted by half an element" if shifted else "stock (node 0)",
            "timestep_s": dt, "stability_limit_s": 2.0 / omega_sr, "steps": steps, "wall_s": wall,
            "tip_m": tip.tolist(), "finite": bool(np.isfinite(rod.position_collection).all())}


def bench_elastica(T=0.05, elements=20, with_pyelastica=True):
    from mjeap import analytical as an
    b = _beam_numbers()
    P = b["EI"] / b["L"] ** 2
    ref = an.elastica_tip_force(P, b["L"], b["EI"]).tip

    def err(row):
        x, y = row["tip_m"]
        row["tip_deflection_error"] = y / ref[1] - 1
        row["tip_axial_error_per_L"] = (x - ref[0]) / b["L"]
        return row

    out = {"case": f"pedot-micro beam (L {b['L']:.4g} m, EI {b['EI']:.4g} N m^2), dead tip force with "
                   f"P L^2/EI = 1, gravity off, first-mode damping ratio {ELASTICA_ZETA}, {T} s simulated",
           "elastica_tip_m": [float(ref[0]), float(ref[1])], "simulated_s": T,
           "mjeap": [err(_mjeap_cantilever(b, T, P, n)) for n in (20, 50)],
           "mjeap_with_drive_callback": [err(_mjeap_cantilever(b, T, P, 20, drive=d))
                                         for d in ("blocking-force", "rc-relaxation")],
           "mjeap_with_native_drive": err(_mjeap_cantilever(b, T, P, 20, drive="rc-relaxation", engine="native"))}
    out["mjeap_with_drive_callback"][0]["drive"] = "blocking-force at 0 V (no moment): the callback's cost alone"
    out["mjeap_with_drive_callback"][1]["drive"] = ("rc-relaxation at 0 V: Dadras et al. 2021's drive; its back-relaxation "
                                                    "creeps the beam, so the tip is not the elastic one")
    out["mjeap_with_native_drive"]["drive"] = ("rc-relaxation compiled into the model (mjeap.drives.native, Maxwell arms), "
                                               "on mujoco.rollout")
    if not with_pyelastica:
        return out
    try:
        import elastica  # noqa: F401
    except ImportError:
        out["pyelastica"] = "not installed (pip install -e '.[bench]')"
        return out
    out["pyelastica"] = [err(_pyelastica_cantilever(b, T, P, elements, shifted)) for shifted in (True, False)]
    pe = out["pyelastica"][0]
    target = abs(pe["tip_deflection_error"])
    out["mjeap_at_pyelastica_accuracy"] = _mjeap_at_accuracy(T, P, target, ref)
    base = out["mjeap"][0]
    out["ratio"] = {
        "pyelastica_shifted_over_mjeap_20": pe["wall_s"] / base["wall_s"],
        "pyelastica_shifted_over_mjeap_20_with_rc_relaxation_callback":
            pe["wall_s"] / out["mjeap_with_drive_callback"][1]["wall_s"],
        "pyelastica_shifted_over_mjeap_20_with_blocking_force_callback":
            pe["wall_s"] / out["mjeap_with_drive_callback"][0]["wall_s"],
        "pyelastica_shifted_over_mjeap_20_with_native_rc_relaxation":
            pe["wall_s"] / out["mjeap_with_native_drive"]["wall_s"],
        "pyelastica_shifted_over_mjeap_with_rc_relaxation_at_its_accuracy":
            pe["wall_s"] / out["mjeap_at_pyelastica_accuracy"]["wall_s"],
        "pyelastica_shifted_over_mjeap_whole_accuracy_call":
            pe["wall_s"] / out["mjeap_at_pyelastica_accuracy"]["whole_call_s"],
        "note": "equal accuracy: both tip errors below 0.1 % (PyElastica needs the half-element clamp shift; "
                "its stock clamp is off by several % at this resolution and would need many more elements). "
                "at_its_accuracy: the model mjeap chooses for PyElastica's tip error as its target, built "
                "once and timed as the rest (the whole call adds the pilots, the companions and the "
                "builds of the six models that choose it and estimate its error)"}
    return out


def bench_sweep(points=16, duration=2.0):
    """Rollouts per second of the same sweep on 1 and 2 worker processes (pool start
    included), and the memory of one rollout (tracemalloc peak, which sees NumPy's
    buffers, plus the MjModel and MjData)."""
    import tempfile
    import tracemalloc
    from mjeap import rollout
    from mjeap.studies.sweep import grid, run_sweep
    pts = grid(payload_mass=list(np.linspace(1e-6, 12.6e-6, points // 2)), amplitude=[0.5, 1.0])
    base = {"actuator": "pedot-micro", "orientation": "up", "waveform": "square", "frequency": 0.5,
            "duration": duration, "payload_position": 6.27e-3}
    out = {"case": f"pedot-micro up, payload x amplitude grid, {len(pts)} points of {duration} s"}
    with tempfile.TemporaryDirectory() as d:
        for workers in (1, 2):
            res = run_sweep(pts, Path(d) / f"w{workers}.csv", base=base, workers=workers, progress=False)
            out[f"workers_{workers}"] = {"rollouts_per_s": res.throughput, "wall_s": res.wall_s,
                                         "failed": res.failed}
    out["speedup_2_vs_1"] = out["workers_2"]["rollouts_per_s"] / out["workers_1"]["rollouts_per_s"]
    from mjeap import Payload
    s = Scene("pedot-micro", orientation="up", payload=Payload(12.6e-6, 6.27e-3))
    rollout(s, "square:1V@0.5Hz", 0.1)                        # warm caches
    tracemalloc.start()
    r = rollout(s, "square:1V@0.5Hz", duration)
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    result_bytes = sum(a.nbytes for a in (r.time, r.voltage, r.tip_position, r.tip_angle, r.tip_curvature,
                                          r.centreline)) + sum(a.nbytes for a in r.signals.values())
    out["memory_per_rollout"] = {"python_peak_bytes": peak, "result_arrays_bytes": result_bytes,
                                 "samples": len(r.time), "mjmodel_bytes": int(s.model.nbuffer),
                                 "mjdata_bytes": int(s.data.nbuffer + s.data.narena)}
    return out


def bench_native(repeats=2, map_points=8):
    from mjeap import Payload, rollout, rollout_batch
    from mjeap.drives import make_drive
    from mjeap.studies.stability_map import MAP_BASE
    from mjeap.studies.sweep import grid, run_sweep
    s = Scene("pedot-micro", orientation="up", payload=Payload(12.6e-6, 6.27e-3))
    args = dict(duration=20.0, initial_curvature=-303.0, progress=False)
    out = {"case": "pedot-micro, 12.6 mg @ 6.27 mm, up, square 3 Vpp 0.1 Hz, 20 s, from -303 1/m",
           "timestep_s": s.timestep}
    for engine in ("loop", "native"):
        best = np.inf
        for _ in range(repeats):
            t0 = time.perf_counter()
            r = rollout(s, "square:1.5V@0.1Hz", engine=engine, **args)
            best = min(best, time.perf_counter() - t0)
        out[f"single_{engine}_s"] = best
        out[f"single_{engine}_us_per_step"] = best / r.meta["steps"] * 1e6
    out["steps"] = r.meta["steps"]
    out["single_speedup_native_vs_loop"] = out["single_loop_s"] / out["single_native_s"]
    volts = [f"square:{a:.4g}V@0.1Hz" for a in np.linspace(0.5, 1.5, 16)]
    t0 = time.perf_counter()
    for v in volts:
        rollout(s, v, engine="loop", **args)
    out["batch16_loop_s"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    rollout_batch(s, volts, 20.0, initial_curvatures=-303.0, nthread=2, engine="native")
    out["batch16_native_2threads_s"] = time.perf_counter() - t0
    out["batch16_throughput_native_vs_loop"] = out["batch16_loop_s"] / out["batch16_native_2threads_s"]
    native = s.native_model(make_drive(None, s))
    s.reset(curvature=-303.0)
    out["mj_step_bare_us"] = 1e6 / time_steps(s.model, s.data)
    native.reset(-303.0)
    out["mj_step_native_us"] = 1e6 / time_steps(native.model, native.data)
    out["native_step_cost_vs_bare"] = out["mj_step_native_us"] / out["mj_step_bare_us"]
    out["native_nv"], out["bare_nv"] = native.model.nv, s.model.nv
    pts = grid(payload_mass=list(np.linspace(15e-6, 120e-6, map_points // 2)), amplitude=[0.5, 1.5])
    import tempfile
    with tempfile.TemporaryDirectory() as d:
        for engine in ("loop", "native"):
            res = run_sweep(pts, Path(d) / f"{engine}.csv", base={**MAP_BASE, "engine": engine}, workers=2,
                            progress=False)
            out[f"stability_map_{engine}_rollouts_per_s"] = res.throughput
    out["stability_map_points"] = len(pts)
    return out


def _step_phases(model, data, n=20000) -> dict:
    """Where mj_step's time goes (MuJoCo's own timers, us per step and share)."""
    mujoco.set_mjcb_time(lambda: time.perf_counter() * 1e6)
    try:
        mujoco.mj_step(model, data, nstep=n)
    finally:
        mujoco.set_mjcb_time(None)
    total = data.timer[mujoco.mjtTimer.mjTIMER_STEP].duration
    out = {}
    for t in mujoco.mjtTimer.__members__.values():
        if int(t) < len(data.timer) and data.timer[t].number:
            out[t.name[len("mjTIMER_"):].lower()] = {"us": data.timer[t].duration / data.timer[t].number,
                                                      "share": data.timer[t].duration / total}
    return out


def bench_accuracy(claim_cases=12):
    """Runs at a stated accuracy (mjeap.simulation.accuracy) against today's default model, side by side:
    Dadras et al. 2021's heaviest run (wall of all runs, estimated and true error against 40 segments
    at 1/60 of the 10 ms sample grid under discrete), a batch of 16 at 1e-2 on 2 threads
    against the loop one by one, the stability map's points at 1e-2, where the native
    step's time goes, and the accuracy claim on seeded cases."""
    from mjeap import rollout, rollout_batch
    from mjeap.simulation.accuracy import relative_difference
    from mjeap.drives import make_drive
    from mjeap.studies.stability_map import MAP_BASE
    from mjeap.studies.sweep import grid, read_results, run_sweep
    from mjeap.validation.accuracy_claim import check_case, draw_cases, summarise
    wave, args = "square:1.5V@0.1Hz", dict(initial_curvature=-303.0, progress=False)
    s = Scene("pedot-micro", orientation="up", payload="12.6mg@6.27mm")
    out = {"case": "pedot-micro, 12.6 mg @ 6.27 mm, up, square 3 Vpp 0.1 Hz, 20 s, from -303 1/m"}
    ref_scene = s.variant(40, 0.01 / 60, "discrete")
    ref = rollout(ref_scene, wave, 20.0, drive=make_drive(None, ref_scene), sample_interval=0.01, **args)
    t0 = time.perf_counter()
    r = rollout(s, wave, 20.0, sample_interval=s.timestep, **args)
    wall = time.perf_counter() - t0
    y = np.interp(ref.time, r.time, r.tip_curvature)
    out["default"] = {"model": f"{s.layout.segments} segments, {s.integrator}, h = {s.timestep:.4g} s",
                      "wall_s": wall, "true_error": float(np.max(np.abs(y - ref.tip_curvature)) / np.ptp(ref.tip_curvature))}
    r = rollout(s, wave, 20.0, estimate_error=True, **args)
    out["default"]["estimated_error"] = r.meta["accuracy"]["estimated_error"]
    for target in (1e-2, 1e-3):
        t0 = time.perf_counter()
        r = rollout(s, wave, 20.0, accuracy=target, **args)
        wall = time.perf_counter() - t0
        a = r.meta["accuracy"]
        out[f"accuracy_{target:g}"] = {"model": a["model"], "wall_s": wall, "runs": [x["role"] for x in a["runs"]],
                                       "estimated_error": a["estimated_error"],
                                       "true_error": relative_difference(ref, r),
                                       "speedup_vs_default": out["default"]["wall_s"] / wall}
    volts = [f"square:{v:.4g}V@0.1Hz" for v in np.linspace(0.5, 1.5, 16)]
    t0 = time.perf_counter()
    for v in volts:
        rollout(s, v, 20.0, engine="loop", **args)
    loop = time.perf_counter() - t0
    t0 = time.perf_counter()
    rs = rollout_batch(s, volts, 20.0, initial_curvatures=-303.0, nthread=2, accuracy=1e-2)
    batch = time.perf_counter() - t0
    out["batch16"] = {"loop_one_by_one_default_s": loop, "batch_2threads_accuracy_1e-2_s": batch,
                      "throughput_ratio": loop / batch, "model": rs[0].meta["accuracy"]["model"],
                      "largest_estimated_error": max(x.meta["accuracy"]["estimated_error"] for x in rs)}
    pts = grid(payload_mass=list(np.linspace(15e-6, 120e-6, 4)), amplitude=[0.5, 1.5])
    import tempfile
    with tempfile.TemporaryDirectory() as d:
        for label, extra, share in (("default", {}, True), ("accuracy_1e-2_pilots_per_point", {"accuracy": 1e-2}, False),
                                    ("accuracy_1e-2", {"accuracy": 1e-2}, True)):
            res = run_sweep(pts, Path(d) / f"{label}.csv", metrics=("returns", "peak_to_peak"),
                            base={**MAP_BASE, **extra}, workers=2, progress=False, share_error_models=share)
            rows = read_results(Path(d) / f"{label}.csv")
            out[f"stability_map_{label}_points_per_s"] = res.throughput
            out[f"stability_map_{label}_returns"] = {f"{float(r['payload_mass']) * 1e6:.1f} mg, {r['amplitude']} V":
                                                     r["returns"] for r in rows}
    nat = s.native_model(make_drive(None, s))
    nat.reset(-303.0)
    out["native_step_phases"] = {"nv": nat.model.nv, "nbody": nat.model.nbody, **_step_phases(nat.model, nat.data)}
    rows = [check_case(c) for c in draw_cases(seed=23, n=claim_cases)]
    out["claim"] = {**summarise(rows), "seed": 23,
                    "rows": [{k: r[k] for k in ("case", "model", "true_error", "estimated_error", "wall_s")} for r in rows]}
    return out


def bench_metric_map(masses=(20, 40, 60, 70, 74, 78, 82, 100), amplitudes=(0.25, 1.0, 1.5), rounds=2, wide=(12, 8)):
    """The stability map (pedot-micro standing, 30 s points) at accuracy 1e-2 on its metrics
    (returns, peak_to_peak: mjeap.simulation.metric_accuracy, relaxed steps) against the
    default model on the same points, serial and on 2 workers, interleaved in ``rounds``
    rounds (the machine is shared), each run from cold (the scenes' shared analyses cleared):
    points per second, their ratio, returns agreement, the
    largest peak-to-peak deviation from the default, the simulated edges; a wider map
    (``wide``: masses x amplitudes) on 2 workers, once each; and where the time of an
    accuracy point goes (its runs)."""
    import tempfile
    from mjeap.studies.stability_map import MAP_BASE, simulated_edges
    from mjeap.simulation.scene import clear_build_caches
    from mjeap.studies.sweep import grid, read_results, run_sweep
    pts = grid(payload_mass=[m * 1e-6 for m in masses], amplitude=list(amplitudes))
    out = {"case": f"stability map points ({len(pts)}: {', '.join(map(str, masses))} mg x {amplitudes} V; the "
                   "relaxed column load 76 mg between 74 and 78), pedot-micro standing, 30 s, square 0.1 Hz",
           "rounds": rounds}
    walls = {}
    rows = {}
    with tempfile.TemporaryDirectory() as d:
        for k in range(rounds):
            for executor, workers in (("serial", 1), ("processes", 2)):
                for label, extra in (("default", {}), ("accuracy_1e-2", {"accuracy": 1e-2})):
                    key = f"{executor}_{workers}_{label}"
                    path = Path(d) / f"{key}_{k}.csv"
                    clear_build_caches()    # each run from cold: no analysis or layout from the one before
                    res = run_sweep(pts, path, metrics=("returns", "peak_to_peak"), base={**MAP_BASE, **extra},
                                    executor=executor, workers=workers, progress=False)
                    walls.setdefault(key, []).append(res.wall_s)
                    rows[key] = read_results(path)
    for executor, workers in (("serial", 1), ("processes", 2)):
        d_key, a_key = f"{executor}_{workers}_default", f"{executor}_{workers}_accuracy_1e-2"
        rate_d = len(pts) / min(walls[d_key])
        rate_a = len(pts) / min(walls[a_key])
        ref = {(r["payload_mass"], r["amplitude"]): r for r in rows[d_key]}
        dev = [abs(float(r["peak_to_peak"]) / float(ref[(r["payload_mass"], r["amplitude"])]["peak_to_peak"]) - 1)
               for r in rows[a_key]]
        same = [r["returns"] == ref[(r["payload_mass"], r["amplitude"])]["returns"] for r in rows[a_key]]
        out[f"{executor}_{workers}_workers"] = {
            "default_points_per_s": rate_d, "accuracy_points_per_s": rate_a, "ratio": rate_a / rate_d,
            "returns_equal": f"{sum(same)} of {len(same)}", "max_peak_to_peak_deviation": max(dev),
            "failed": sum(bool(r["error"]) for r in rows[a_key])}
    for label in ("default", "accuracy_1e-2"):
        rs = rows[f"serial_1_{label}"]
        m = np.array([float(r["payload_mass"]) for r in rs]) * 1e6
        v = np.array([float(r["amplitude"]) for r in rs])
        ok = np.array([r["returns"] == "True" for r in rs])
        out[f"edges_mg_{label}"] = {f"{a:g} V": e for a, e in simulated_edges(m, v, ok).items()}
    # a wider map on 2 workers, once each: the fixed costs (a pool, the costliest point's tail)
    # spread over more points
    wide_pts = grid(payload_mass=[float(m) * 1e-6 for m in np.linspace(10, 110, wide[0])],
                    amplitude=[float(a) for a in np.linspace(0.25, 1.5, wide[1])])
    wide_rows = {}
    with tempfile.TemporaryDirectory() as d:
        for label, extra in (("default", {}), ("accuracy_1e-2", {"accuracy": 1e-2})):
            clear_build_caches()
            res = run_sweep(wide_pts, Path(d) / f"wide_{label}.csv", metrics=("returns", "peak_to_peak"),
                            base={**MAP_BASE, **extra}, executor="processes", workers=2, progress=False)
            wide_rows[label] = (len(wide_pts) / res.wall_s, read_results(Path(d) / f"wide_{label}.csv"))
    ref = {(r["payload_mass"], r["amplitude"]): r for r in wide_rows["default"][1]}
    acc = wide_rows["accuracy_1e-2"][1]
    out["wide_map_2_workers"] = {
        "points": f"{len(wide_pts)} ({wide[0]} masses 10-110 mg x {wide[1]} amplitudes 0.25-1.5 V)",
        "default_points_per_s": wide_rows["default"][0], "accuracy_points_per_s": wide_rows["accuracy_1e-2"][0],
        "ratio": wide_rows["accuracy_1e-2"][0] / wide_rows["default"][0],
        "returns_equal": f"{sum(r['returns'] == ref[(r['payload_mass'], r['amplitude'])]['returns'] for r in acc)} "
                         f"of {len(acc)}",
        "max_peak_to_peak_deviation": max(abs(float(r["peak_to_peak"]) / float(
            ref[(r["payload_mass"], r["amplitude"])]["peak_to_peak"]) - 1) for r in acc)}
    from mjeap import Scene, rollout
    s = Scene("pedot-micro", orientation="up", payload="76mg@6.27mm")
    t0 = time.perf_counter()
    r = rollout(s, "square:1.0V@0.1Hz", 30.0, progress=False, accuracy=1e-2, metrics=("returns", "peak_to_peak"))
    a = r.meta["accuracy"]
    out["one_point_76mg_1V"] = {"wall_s": time.perf_counter() - t0, "model": a["model"],
                                "runs": [{k: x[k] for k in ("role", "segments", "timestep", "wall_time_s")}
                                         for x in a["runs"]],
                                "damped_modes": a["damped_modes"], "estimated_error": {
                                    k: x["estimated_error"] for k, x in a["metrics"].items()}}
    return out


def bench_early_stop(map_points=8):
    """The stability map's bench points (as in native and accuracy) at the map's 30 s (three
    periods: too short for a stop, which needs four) and at 60 s, run to the end and with
    stop_when_periodic=1e-2 (mjeap.simulation.periodic), 2 workers: points per second, where
    each stopped, and the returns."""
    import tempfile
    from mjeap.studies.stability_map import MAP_BASE
    from mjeap.studies.sweep import grid, read_results, run_sweep
    pts = grid(payload_mass=list(np.linspace(15e-6, 120e-6, map_points // 2)), amplitude=[0.5, 1.5])
    out = {"case": f"stability map bench points ({len(pts)}), 2 workers, default model"}
    with tempfile.TemporaryDirectory() as d:
        for duration, stops in ((30.0, (None,)), (60.0, (None, 1e-2))):    # a stop needs 4 periods
            for stop in stops:
                label = f"{duration:g}s" + ("" if stop is None else f"_stop_{stop:g}")
                base = {**MAP_BASE, "duration": duration, **({} if stop is None else {"stop_when_periodic": stop})}
                res = run_sweep(pts, Path(d) / f"{label}.csv", metrics=("returns", "stopped_early"), base=base,
                                workers=2, progress=False)
                rows = read_results(Path(d) / f"{label}.csv")
                out[label] = {"points_per_s": res.throughput, "failed": res.failed,
                              "sum_of_point_walls_s": sum(float(r["wall_s"]) for r in rows), "points": {
                    f"{float(r['payload_mass']) * 1e6:.1f} mg, {r['amplitude']} V":
                        {"returns": r["returns"], "stopped_at_s": (float(r["stopped_early"].split()[2])
                                                                   if r["stopped_early"] else None)}
                    for r in rows}}
    return out


#: the optimisation bench's actuator: a uniform bimorph (tests/studies/test_optimize.py's closed form)
BENCH_BIMORPH = (Path(__file__).resolve().parents[1] / "examples" / "actuators" / "uniform-bimorph.toml").read_text()


def bench_optimize(f_min=800.0, box=(5e-3, 15e-3), resolution=0.01):
    """The optimisation against a grid sweep of the same question (module text)."""
    import math
    import tempfile
    import mjeap
    from mjeap.studies.sweep import grid, read_results, run_sweep
    # the closed form: L* = beta_1 sqrt(1 / (2 pi f_min)) (EI / mu)^(1/4), EI and mu from the layers
    E, t, rho = np.array([40e9, 340e9, 40e9]), np.array([127e-6, 60e-6, 127e-6]), np.array([7500.0, 1550.0, 7500.0])
    z = np.cumsum(t) - t / 2
    zn = np.sum(E * t * z) / np.sum(E * t)
    EI, mu = 3e-3 * float(np.sum(E * (t**3 / 12 + t * (z - zn) ** 2))), 3e-3 * float(np.sum(rho * t))
    l_star = 1.8751040687 * math.sqrt(1 / (2 * math.pi * f_min)) * (EI / mu) ** 0.25
    question = dict(maximize="free_deflection", subject_to=[f"first_frequency>={f_min:g}"], voltage="step:200V",
                    duration=0.05, base={"segments": 20})
    out = {"case": f"uniform PZT-5H bimorph, maximise free_deflection over actuator.length {box[0] * 1e3:g}-"
                   f"{box[1] * 1e3:g} mm at first_frequency >= {f_min:g} Hz, step:200V for 0.05 s, 20 segments",
           "L_star_closed_form_m": l_star}
    with tempfile.TemporaryDirectory() as d:
        act = Path(d) / "bimorph.toml"
        act.write_text(BENCH_BIMORPH)
        for method in ("slsqp", "differential-evolution"):
            r = mjeap.optimize(str(act), {"actuator.length": box}, method=method, out=Path(d) / method,
                               progress=False, **question)
            err = abs(r.optimum["actuator.length"] / l_star - 1)
            out[method] = {"evaluations": r.evaluations, "wall_s": r.wall_s,
                           "evaluations_per_s": r.evaluations / r.wall_s, "L_m": r.optimum["actuator.length"],
                           "error_vs_L_star": err, "constraint_active": r.constraints[0]["active"],
                           "grid_points_for_this_error": math.ceil((box[1] - box[0]) / (2 * err * l_star)) + 1}
        n = math.ceil((box[1] - box[0]) / (resolution * l_star)) + 1
        pts = grid(**{"actuator.length": list(np.linspace(box[0], box[1], n))})
        t0 = time.perf_counter()
        res = run_sweep(pts, Path(d) / "grid.csv", metrics=("free_deflection", "first_frequency"),
                        base={"actuator": str(act), "waveform": "step", "amplitude": 200.0, "duration": 0.05,
                              "segments": 20}, workers=2, progress=False)
        wall = time.perf_counter() - t0
        rows = [r for r in read_results(res.path) if not r["error"] and float(r["first_frequency"]) >= f_min]
        best = max(rows, key=lambda r: float(r["free_deflection"]))
        out["grid_sweep"] = {"points": n, "spacing_m": (box[1] - box[0]) / (n - 1), "workers": 2, "wall_s": wall,
                             "sum_of_point_walls_s": sum(float(r["wall_s"]) for r in read_results(res.path)),
                             "failed": res.failed, "L_m": float(best["actuator.length"]),
                             "error_vs_L_star": abs(float(best["actuator.length"]) / l_star - 1)}
    return out


def bench_warp(map_points=4, duration=1.0, batch=16, batch_duration=0.6):
    """The warp engine against the native one on this machine (Warp's CPU device unless a GPU
    is found; the device is in the output): a batch of Dadras et al. 2021's standing run with 16
    amplitudes, and a small stability map (``map_points`` points of ``duration`` s, serial)."""
    import tempfile
    from mjeap import Payload, rollout_batch
    from mjeap.studies.stability_map import MAP_BASE
    from mjeap.drives import make_drive
    from mjeap.engines import get_engine
    from mjeap.studies.sweep import grid, run_sweep
    s = Scene("pedot-micro", orientation="up", payload=Payload(12.6e-6, 6.27e-3))
    why = get_engine("warp").why_not(s, make_drive(None, s))
    if why is not None:
        return {"skipped": why}
    volts = [f"square:{a:.4g}V@0.1Hz" for a in np.linspace(0.25, 1.5, batch)]
    out = {"case": f"pedot-micro, 12.6 mg @ 6.27 mm, up, square 0.1 Hz, {batch} amplitudes, {batch_duration} s"}
    for engine in ("native", "warp", "warp"):       # warp twice: the second without the compile and captures
        t0 = time.perf_counter()
        r = rollout_batch(s, volts, batch_duration, initial_curvatures=-303.0, engine=engine)
        key = f"batch_{engine}_s" if f"batch_{engine}_s" not in out else f"batch_{engine}_again_s"
        out[key] = time.perf_counter() - t0
    out["device"] = r[0].meta["warp"]["device"]
    out["steps"] = r[0].meta["steps"]
    pts = grid(payload_mass=list(np.linspace(15e-6, 120e-6, max(map_points // 2, 1))), amplitude=[0.5, 1.5])
    with tempfile.TemporaryDirectory() as d:
        for engine in ("native", "warp"):
            res = run_sweep(pts, Path(d) / f"{engine}.csv", base={**MAP_BASE, "duration": duration, "engine": engine},
                            executor="serial", progress=False)
            out[f"map_{engine}_rollouts_per_s"] = res.throughput
            out[f"map_{engine}_failed"] = res.failed
    out["map"] = f"{len(pts)} points of {duration} s, serial"
    return out


def bench_hamr_walk_env(simulated=0.2, frequency=10.0):
    """``mjeap/HamrWalk-v0`` on one core, side by side: its learning model (2 segments per
    actuator at a 50 us step sized for the loaded system, the id's default) and the default
    walker model (4 segments, each actuator's own 4.51 us step): env steps per second over
    ``simulated`` s of the scripted trot (the robot's drive, its actions computed beforehand:
    the environment's cost, not the policy's) at ``frequency`` Hz after the soft start,
    simulated seconds per wall second (the real-time factor; and per CPU second of the
    process, what one core costs on a shared machine), the bare mj_step's rate
    and what a learning run of 10^6 env steps (0.5 ms each, 500 simulated s) costs in wall
    hours. One thread: OMP and MKL at 1 (set before numpy loads: run with
    OMP_NUM_THREADS=1 MKL_NUM_THREADS=1)."""
    from mjeap.envs.hamr_walk import LEARNING_SEGMENTS, LEARNING_TIMESTEP, HamrWalkEnv, trot_policy
    out = {"case": f"HamrWalk-v0, scripted trot at {frequency:g} Hz (the robot's drive), {simulated:g} s after "
                   "the ramp, one thread", "omp_num_threads": os.environ.get("OMP_NUM_THREADS"),
           "mkl_num_threads": os.environ.get("MKL_NUM_THREADS")}
    for label, segments, step in (("learning", LEARNING_SEGMENTS, LEARNING_TIMESTEP), ("default_model", 4, None)):
        env = HamrWalkEnv(segments=segments, timestep=step, time_limit=10.0)
        env.reset(seed=0)
        policy = trot_policy(env, frequency)
        for _ in range(int(round(2.0 / frequency / env.control_timestep))):      # the soft start
            env.step(policy(env.time))
        k = int(round(simulated / env.control_timestep))
        actions = [policy(env.time + i * env.control_timestep) for i in range(k)]   # the policy's cost apart
        t0, c0 = time.perf_counter(), time.process_time()
        for a in actions:
            env.step(a)
        wall, cpu = time.perf_counter() - t0, time.process_time() - c0
        m, d = env.system.model, env.system.data
        step_rate = time_steps(m, mujoco.MjData(m), min_seconds=0.3)
        rate = k / wall
        out[label] = {
            "segments": segments, "timestep_s": env.system.timestep, "mujoco_steps_per_env_step": env._n_sub,
            "env_steps_per_s": rate, "realtime_factor": rate * env.control_timestep,
            "cpu_realtime_factor": k * env.control_timestep / cpu,
            "bare_mj_step_per_s": step_rate, "bare_mj_step_realtime_factor": step_rate * env.system.timestep,
            "hours_per_1e6_env_steps": 1e6 / rate / 3600.0}
    return out


BENCHMARKS = ("models", "rollout", "drives", "threaded", "elastica", "sweep", "native", "accuracy", "metric_map",
              "early_stop", "optimize", "warp", "show", "hamr_walk_env")


def main(argv=None):
    from mjeap.io.commandline import arg_number, arg_output, parse_args
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--json", type=arg_output(), help="also write the results to this file")
    ap.add_argument("--min-seconds", type=arg_number(0.0, float("inf"), "s", True, True), default=0.5,
                    help="timing window per measurement (s)")
    ap.add_argument("--only", choices=BENCHMARKS, action="append", help="run these benchmarks (repeatable)")
    ap.add_argument("--elastica-time", type=arg_number(0.0, float("inf"), "s", True, True), default=0.05,
                    help="simulated time of the elastica benchmark (s); PyElastica takes ~1 min per 0.05 s")
    ap.add_argument("--no-pyelastica", action="store_true", help="mjeap side of the elastica benchmark only")
    args = parse_args(ap, argv)
    only = args.only or BENCHMARKS
    out = {"machine": {"python": platform.python_version(), "mujoco": mujoco.__version__,
                       "processor": platform.processor() or platform.machine(), "cpus": os.cpu_count()}}

    def emit():
        text = json.dumps(out, indent=2)
        if args.json:    # written after every benchmark: nothing measured is lost (mjeap's one writer)
            from mjeap.io.outputs import write_text
            write_text(args.json, text, "--json")
        return text

    for name in BENCHMARKS:
        if name not in only:
            continue
        if name == "models":
            out["models"] = bench_models(args.min_seconds)
        elif name == "rollout":
            import tempfile
            with tempfile.TemporaryDirectory() as d:
                out["rollout"] = bench_rollout(d)
        elif name == "drives":
            out["drives"] = bench_drives()
        elif name == "threaded":
            out["threaded"] = bench_threaded()
        elif name == "elastica":
            out["elastica"] = bench_elastica(args.elastica_time, with_pyelastica=not args.no_pyelastica)
        elif name == "sweep":
            out["sweep"] = bench_sweep()
        elif name == "native":
            out["native"] = bench_native()
        elif name == "accuracy":
            out["accuracy"] = bench_accuracy()
        elif name == "metric_map":
            out["metric_map"] = bench_metric_map()
        elif name == "early_stop":
            out["early_stop"] = bench_early_stop()
        elif name == "optimize":
            out["optimize"] = bench_optimize()
        elif name == "warp":
            out["warp"] = bench_warp()
        elif name == "show":
            out["show"] = bench_show()
        elif name == "hamr_walk_env":
            out["hamr_walk_env"] = bench_hamr_walk_env()
        emit()
    print(emit())


if __name__ == "__main__":
    from mjeap.io.commandline import run_script
    sys.exit(run_script(main))
