"""HAMR single leg (seed 003, section 6.2): two pzt-hamr-small actuators drive a rigid leg
through its swing and lift transmissions; resonances from sine sweeps, then the foot
ellipse at 100 Hz open loop and with both phase loops closed on the self-sensed currents.

    mjeap robot hamr-leg [--out out/hamr_leg.rrd] [--cycles 40] [--open-loop-cycles 10]

Prints JSON with swing_resonance_hz, lift_resonance_hz, cycles_to_5deg_swing and
cycles_to_5deg_lift (closed-loop cycles until the true foot phase error stays within 5
degrees), and writes the recording. Written against mjeap's public component API (attach,
System, System.drive_observer) and plain MjSpec.

Model (host in mm, mg, ms; gravity along -z):
- The hip at the origin; the leg a rigid rod of LEG_LENGTH along +y (lateral). The swing
  hinge (axis z) carries a swing stage; on it the lift hinge (axis x, turning with the
  stage) carries the leg and the lift lever. Swing moves the foot fore-aft (x), lift up and
  down (z): the foot's position is the 3D kinematics of these joints.
- Each transmission (mjeap.system.add_transmission): a tendon equality that turns the leg
  joint by T d / LEG_LENGTH, d the actuator's tip deflection linearised in its hinge angles,
  so that the foot moves T x the tip for small motion (T_swing = 13, T_lift = 12, seed 003
  from its ref. [51]).
- Inertia: for each degree of freedom, the tip mass that puts the loaded actuator's first
  mode at the paper's transmission resonance (100 Hz swing, 80 Hz lift: the point-mass leg
  of controllers/hamr_leg.py, scipy brentq on the scene's modes) is reflected to the joint,
  I = m (LEG_LENGTH / T)^2. The leg rod carries LEG_SHARE of the smaller of the two; the
  swing stage (about z only) and the lift lever (about x only) carry the rest of each.
- Damping: each leg joint damps its transmission mode to ZETA (less the actuator's own
  stiffness-proportional share at that frequency, zeta_act f / f_free), as the point-mass
  scene's damping is set on its loaded mode.
- LEG_LENGTH = 10 mm is ASSUMED (a quarter of HAMR-VI's 4.51 cm body, seed 003); with the
  ratios fixed it sets only the joint angles, i.e. the kinematic nonlinearity.

Control: V = V_bias/2 + a sin(omega t + phi) per actuator, phi moved once per cycle by the
self-sensed phase PID of controllers/hamr_leg.py (each actuator's drive current through its
own estimator, calibrated on the free actuator; no simulator state), its gains from each
transmission's second-order model (phase_loop_gains: the swing at resonance, the lift 20 Hz
above its own). Desired foot motion:
swing sin(omega t), lift 90 degrees ahead: the ellipse of seed 003's ref. [50].
"""
from __future__ import annotations

import argparse
import json
import sys
from typing import Optional

import mujoco
import numpy as np
from scipy import optimize

from ..analysis.frequency import phasor
from ..cli import arg_integer, arg_output, parse_args, run_script
from ..io.outputs import run_guard
from ..controllers.hamr_leg import (LIFT, SWING, LegPhaseController, cycles_to_within, free_estimator, leg_scene,
                                    phase_errors_per_cycle, phase_loop_gains)
from ..errors import check_integer
from ..simulation.scene import DEFAULT_SEGMENTS, Scene
from ..simulation.system import System, add_transmission, attach
from .registry import Robot, register, summary

ACTUATOR = "pzt-hamr-small"
LEG_LENGTH = 10e-3            # m, assumed (see the module text)
LEG_SHARE = 0.8               # of the smaller joint inertia carried by the leg rod
ZETA = 0.05                   # damping ratio of each transmission mode, as the point-mass leg's
BIAS, AMPLITUDE, FREQUENCY = 100.0, 20.0, 100.0     # V, V (40 Vpp), Hz
SWEEP = np.array([40, 50, 60, 70, 75, 80, 85, 90, 95, 100, 105, 110, 120, 130, 140.0])   # Hz, Fig. 8(a)-(b)
SWEEP_CYCLES, SWEEP_LAST = 24, 6
DOFS = {"swing": SWING, "lift": LIFT}
AXES = {"swing": (0.0, 0.0, 1.0), "lift": (1.0, 0.0, 0.0)}
FOOT_COORD = {"swing": 0, "lift": 2}                  # foot x (fore-aft), z (normal)


def design() -> dict:
    """Per degree of freedom: the reflected tip mass (kg) that puts the loaded actuator at
    its resonance, the joint inertia (kg m^2) it needs, and the joint damping (N m s)."""
    out = {}
    for name, tr in DOFS.items():
        sc = leg_scene(tr)
        m = sc.payload.mass
        inertia = m * (LEG_LENGTH / tr.ratio) ** 2
        free = Scene(sc.actuator, gravity=False)
        zeta_act = free.choice.damping_ratio * tr.resonance / free.choice.first_frequency
        damping = 2 * (ZETA - zeta_act) * 2 * np.pi * tr.resonance * inertia
        out[name] = {"reflected_mass_kg": m, "joint_inertia_kg_m2": inertia, "joint_damping_N_m_s": damping,
                     "zeta_actuator_share": zeta_act, "point_mass_resonance_hz": sc.choice.first_frequency}
    return out


def build(d: Optional[dict] = None, bias: float = BIAS, segments: int = DEFAULT_SEGMENTS) -> System:
    """The leg system (host in mm, mg, ms) from :func:`design` (computed when ``d`` is None);
    ``segments`` per actuator (:func:`mjeap.system.attach`)."""
    d = design() if d is None else d
    spec = mujoco.MjSpec.from_string('<mujoco><option gravity="0 0 -9.80665e-3"/><worldbody/></mujoco>')
    wb = spec.worldbody
    acts = {}
    for k, (name, z) in enumerate((("swing", 0.0), ("lift", -4.0))):
        site = wb.add_site(name=f"{name}_mount", pos=[-14.0, -3.0 - 3.0 * k, z])
        acts[name] = attach(spec, ACTUATOR, site=site.name, prefix=name, contact=False, drive_params={"bias": bias},
                            segments=segments)
    add_leg(spec, wb, acts, d)
    return System(spec, [acts["swing"], acts["lift"]])


def add_leg(spec: mujoco.MjSpec, parent, acts: dict, d: dict, *, prefix: str = "", pos=(0.0, 0.0, 0.0),
            side: float = 1.0, mass_radius: float = 2.0, foot_drop: float = 0.0, foot_radius: float = 0.5,
            foot_contact: bool = False):
    """One leg on ``parent`` (a body of ``spec``) at its hip ``pos`` (internal units), driven
    by ``acts`` ({'swing': ..., 'lift': ...}, attached actuators) through their
    transmissions, with the joint inertias and damping of ``d`` (:func:`design`). Names are
    ``prefix`` + swing_stage, swing, leg, lift, lift_lever, foot (site and geom).

    ``side``: +1, the leg along +y (as :func:`build`), or -1, mirrored along -y; the
    transmission signs follow, so that on either side a positive tip deflection moves the
    foot +x (swing) and +z (lift). ``mass_radius`` (internal length): the radius at which
    the stage's and the lever's masses sit (their masses are inertia / radius^2, so a larger
    radius carries the same inertia with less mass). ``foot_drop``: the foot hangs this far
    below the end of the leg rod on a massless shank, which leaves the foot's fore-aft (swing)
    and normal (lift) motion per joint angle unchanged (adds a lateral one of foot_drop per
    radian of lift). ``foot_contact``: the foot's sphere (``foot_radius``) touches geoms
    with conaffinity 1 (condim 3); it never touches another foot. Returns the leg body."""
    u = acts["swing"].twin.units
    to_I = u.mass * u.length**2
    ell = LEG_LENGTH / u.length
    y = side * ell
    I_s, I_l = (d[n]["joint_inertia_kg_m2"] / to_I for n in ("swing", "lift"))
    I_leg = LEG_SHARE * min(I_s, I_l)
    m_leg = 3 * I_leg / ell**2                                 # a thin rod about its end
    r = mass_radius                                            # the stage's and the lever's mass radius
    stage = parent.add_body(name=f"{prefix}swing_stage", pos=list(pos))
    stage.add_joint(name=f"{prefix}swing", type=mujoco.mjtJoint.mjJNT_HINGE, axis=AXES["swing"],
                    damping=d["swing"]["joint_damping_N_m_s"] / (to_I / u.time))
    # the stage turns about z only: a disc's inertia (its x and y values meet no joint)
    stage.add_geom(name=f"{prefix}stage", type=mujoco.mjtGeom.mjGEOM_CYLINDER, size=[1.0, 0.2, 0], mass=0,
                   rgba=[0.6, 0.6, 0.65, 1], contype=0, conaffinity=0)
    stage.mass, stage.inertia = 2 * (I_s - I_leg) / r**2, [(I_s - I_leg) / 2, (I_s - I_leg) / 2, I_s - I_leg]
    # its centre of mass on the swing axis, stated: left unset, MuJoCo's compiler puts an
    # explicit inertial at the body's pos again (the hip's offset twice: at HAMR-VI's hips
    # that doubled the swing joint's inertia and swung 8 mg on a 16 mm eccentric)
    stage.ipos, stage.explicitinertial = [0, 0, 0], True
    leg = stage.add_body(name=f"{prefix}leg")
    leg.add_joint(name=f"{prefix}lift", type=mujoco.mjtJoint.mjJNT_HINGE, axis=AXES["lift"],
                  damping=d["lift"]["joint_damping_N_m_s"] / (to_I / u.time))
    leg.add_geom(name=f"{prefix}leg", type=mujoco.mjtGeom.mjGEOM_CAPSULE, fromto=[0, 0, 0, 0, y, 0], size=[0.25, 0, 0],
                 mass=0, rgba=[0.85, 0.65, 0.3, 1], contype=0, conaffinity=0)
    # a thin rod's inertia, stated (a capsule's caps would add 1.7 % about the hip)
    leg.mass, leg.ipos, leg.explicitinertial = m_leg, [0, y / 2, 0], True
    leg.inertia = [m_leg * ell**2 / 12, 1e-6 * m_leg * ell**2, m_leg * ell**2 / 12]
    # the lift lever: a rod along z centred on the lift axis, inertia about x (and y, which
    # no joint sees), none about z, so the swing does not see it
    lever = leg.add_body(name=f"{prefix}lift_lever")
    lever.add_geom(name=f"{prefix}lever", type=mujoco.mjtGeom.mjGEOM_CAPSULE, fromto=[0, 0, 1.5, 0, 0, -1.5],
                   size=[0.2, 0, 0], mass=0, rgba=[0.6, 0.6, 0.65, 1], contype=0, conaffinity=0)
    lever.mass, lever.inertia = 3 * (I_l - I_leg) / r**2, [I_l - I_leg, I_l - I_leg, 1e-6 * (I_l - I_leg)]
    lever.ipos, lever.explicitinertial = [0, 0, 0], True
    foot = [0, y, -foot_drop]
    if foot_drop:
        leg.add_geom(name=f"{prefix}shank", type=mujoco.mjtGeom.mjGEOM_CAPSULE, fromto=[0, y, 0, *foot],
                     size=[0.2, 0, 0], mass=0, rgba=[0.85, 0.65, 0.3, 1], contype=0, conaffinity=0)
    leg.add_site(name=f"{prefix}foot", pos=foot)
    leg.add_geom(name=f"{prefix}foot", type=mujoco.mjtGeom.mjGEOM_SPHERE, size=[foot_radius, 0, 0], pos=foot, mass=0,
                 rgba=[0.9, 0.3, 0.2, 1], contype=int(foot_contact), conaffinity=0, condim=3)
    # transmissions: joint angle = sign x T d / LEG_LENGTH, the foot moving +T d along x / z
    # (about z a +y leg moves its foot -x; about x, +z; a -y leg the other way)
    sign = {"swing": -side, "lift": side}
    for name, tr in DOFS.items():
        add_transmission(spec, acts[name], f"{prefix}{name}", sign[name] * tr.ratio / LEG_LENGTH)
    return leg


def foot(system: System) -> np.ndarray:
    """The foot's world position (m)."""
    return system.data.site("foot").xpos * system.units.length


def sweep(system: System, name: str, frequencies=SWEEP) -> dict:
    """Sine of AMPLITUDE (40 Vpp) about V_bias/2 on one actuator, the other at rest: the
    foot coordinate's response per frequency, magnitude (m/V) and phase (deg) against the
    drive, over the last SWEEP_LAST of SWEEP_CYCLES cycles."""
    mag, ph = [], []
    for f in frequencies:
        pos = []
        volts = {"swing": None, "lift": None, name: f"sine:{AMPLITUDE}V@{f}Hz,offset={BIAS / 2}V"}
        r = system.rollout(volts, SWEEP_CYCLES / f, sample_interval=1 / (40 * f),
                           on_sample=lambda s: pos.append(foot(s)[FOOT_COORD[name]]))
        t = r.time[:len(pos)]
        late = t >= (SWEEP_CYCLES - SWEEP_LAST) / f - 1e-12
        z = phasor(t[late], np.asarray(pos)[late], f) / AMPLITUDE     # its offset fitted alongside
        # the drive is sin(omega t): its phasor is -i; the response relative to it
        z = z / -1j
        mag.append(abs(z))
        ph.append(np.degrees(np.angle(z)))
    ph = np.degrees(np.unwrap(np.radians(ph)))
    return {"frequency_hz": list(map(float, frequencies)), "magnitude_m_per_V": mag, "phase_deg": list(ph)}


def second_order_fit(sw: dict) -> dict:
    """The swept response fitted by K / (1 - (f/f_n)^2 + 2 i zeta f/f_n) (scipy
    least_squares on the complex response, relative residuals): the transmission's
    resonance f_n (Hz), its damping ratio and static gain (m/V)."""
    f = np.asarray(sw["frequency_hz"])
    h = np.asarray(sw["magnitude_m_per_V"]) * np.exp(1j * np.radians(sw["phase_deg"]))

    def model(p):
        k, fn, z = p
        r = f / fn
        return k / (1 - r**2 + 2j * z * r)

    def resid(p):
        e = (model(p) - h) / np.abs(h)
        return np.concatenate([e.real, e.imag])

    i = int(np.argmax(np.abs(h)))
    fit = optimize.least_squares(resid, [abs(h[0]), f[i], 0.05], bounds=([0, f[0], 1e-4], [np.inf, f[-1], 1.0]))
    return {"resonance_hz": float(fit.x[1]), "damping_ratio": float(fit.x[2]), "static_gain_m_per_V": float(fit.x[0]),
            "rms_relative_residual": float(np.sqrt(np.mean(resid(fit.x) ** 2)))}


def phase_crossing(sw: dict) -> float:
    """The frequency (Hz) where the phase passes -90 degrees, interpolated linearly."""
    f, ph = np.asarray(sw["frequency_hz"]), np.asarray(sw["phase_deg"])
    i = int(np.nonzero((ph[:-1] > -90) & (ph[1:] <= -90))[0][0])
    return float(f[i] + (-90 - ph[i]) * (f[i + 1] - f[i]) / (ph[i + 1] - ph[i]))


class LegControllers:
    """Both phase controllers as one system controller: each reads only its actuator's drive
    current (a drive observer stepped with the voltage it holds) and its own commands."""

    name = "swing and lift phase PIDs on the self-sensed currents"

    def __init__(self, system: System, open_loop_cycles: int):
        self.ctrls, self.obs, self.dt = {}, {}, system.timestep
        for nm, tr in DOFS.items():
            gains = phase_loop_gains(ZETA, tr.resonance, FREQUENCY)
            c = LegPhaseController(free_estimator(BIAS), FREQUENCY, AMPLITUDE, tr.desired_phase, gains,
                                   open_loop_cycles)
            self.obs[nm] = system.drive_observer(nm)
            c.reset(system, self.obs[nm])
            self.ctrls[nm] = c

    def __call__(self, t: float, system: System) -> dict:
        out = {}
        for nm, c in self.ctrls.items():
            out[nm] = c(t, None)               # reads the current after the last step, nothing of the system
            self.obs[nm].step(out[nm], self.dt)
        return out


def run_closed_loop(system: System, cycles: int = 40, open_loop_cycles: int = 10, rrd=None) -> dict:
    """Both actuators under :class:`LegControllers`: ``open_loop_cycles`` open loop, then
    closed. Returns the rollout, the foot's trajectory (m) and per cycle the phase errors
    (deg): sensed, and true from the foot's 3D position."""
    ctrl = LegControllers(system, open_loop_cycles)
    feet = []
    res = system.rollout(None, cycles / FREQUENCY, sample_interval=1 / (FREQUENCY * 50), controller=ctrl,
                         on_sample=lambda s: feet.append(foot(s)))
    ts, feet = res.time[:len(feet)], np.array(feet)
    out = {"result": res, "time": ts, "foot": feet, "errors": {}, "open_loop_cycles": open_loop_cycles}
    for name, tr in DOFS.items():
        c = ctrl.ctrls[name]
        true = phase_errors_per_cycle(ts, feet[:, FOOT_COORD[name]], FREQUENCY, tr.desired_phase, len(c.errors))
        out["errors"][name] = {"sensed_deg": np.degrees(c.errors), "true_deg": true, "gains": list(c.gains)}
    if rrd is not None:
        write_recording(rrd, system, out)
    return out


def write_recording(path, system: System, run: dict) -> None:
    """The closed-loop run in 3D (actuators, stage, lever, leg), the foot's trail over the
    last open-loop cycle (grey) and the last closed-loop cycle (green) with the desired
    ellipse (white), the foot's swing and lift against time, and the phase errors per cycle."""
    import rerun as rr
    import rerun.blueprint as rrb
    from ..io.recording import write_system_recording

    ts, feet, n_open = run["time"], run["foot"], run["open_loop_cycles"]
    n_cyc = len(next(iter(run["errors"].values()))["true_deg"])
    t_cycle = (np.arange(n_cyc) + 1) / FREQUENCY
    centre = feet[ts >= (n_cyc - 1) / FREQUENCY].mean(axis=0)
    colours = {"swing": [40, 110, 220], "lift": [220, 60, 60]}

    def extra(rec):
        for label, c, colour in (("open loop", n_open - 1, [150, 150, 150]), ("closed loop", n_cyc - 1, [40, 170, 60])):
            sel = (ts >= c / FREQUENCY - 1e-12) & (ts <= (c + 1) / FREQUENCY + 1e-12)
            rec.log(f"world/foot_trail/{label.replace(' ', '_')}", rr.LineStrips3D([feet[sel]], colors=[colour],
                                                                                   radii=[4e-5], labels=[label]),
                    static=True)
        # the desired ellipse: the closed loop's amplitudes, swing sin(wt), lift 90 deg ahead
        sel = ts >= (n_cyc - 1) / FREQUENCY
        amp = 0.5 * np.ptp(feet[sel], axis=0)
        ph = np.linspace(0, 2 * np.pi, 100)
        ell = np.tile(centre, (100, 1))
        ell[:, 0] += amp[0] * np.sin(ph + DOFS["swing"].desired_phase)
        ell[:, 2] += amp[2] * np.sin(ph + DOFS["lift"].desired_phase)
        rec.log("world/foot_trail/desired", rr.LineStrips3D([ell], colors=[[230, 230, 230]], radii=[2e-5],
                                                            labels=["desired"]), static=True)
        for name in DOFS:
            ent = f"leg/foot/{name}"
            rec.log(ent, rr.SeriesLines(names=f"foot {name} ({'x' if name == 'swing' else 'z'}, m)",
                                        colors=[colours[name]]), static=True)
            rec.send_columns(ent, indexes=[rr.TimeColumn("time", duration=ts)],
                             columns=rr.Scalars.columns(scalars=feet[:, FOOT_COORD[name]] - centre[FOOT_COORD[name]]))
            for kind in ("true", "sensed"):
                ent = f"leg/phase_error/{name}/{kind}"
                rec.log(ent, rr.SeriesPoints(names=f"{name} {kind} (deg)", colors=[colours[name]],
                                             markers=["circle" if kind == "true" else "cross"]), static=True)
                rec.send_columns(ent, indexes=[rr.TimeColumn("time", duration=t_cycle)],
                                 columns=rr.Scalars.columns(scalars=run["errors"][name][f"{kind}_deg"]))

    views = (rrb.TimeSeriesView(origin="/leg/phase_error", name="foot phase error per cycle (deg), closed after "
                                f"{n_open} cycles"),
             rrb.TimeSeriesView(origin="/leg/foot", name="foot position about its mean (m)"))
    write_system_recording(path, run["result"], system, extra=extra, views=views)


#: the most cycles of the closed-loop run: 100 s at 100 Hz, 11 million steps of the leg's
#: 9.1 us timestep (the rollout's own bound is 20 million)
MAX_CYCLES = 10_000


def _check_cycles(a) -> None:
    """At least one closed-loop cycle measured after the open-loop ones (a run of n cycles
    measures the phase errors of its first n - 1)."""
    check_integer("--open-loop-cycles", a.open_loop_cycles, 1, a.cycles - 2,
                  f"at most --cycles {a.cycles} - 2, so that a closed-loop cycle is measured")


def main(argv=None):
    ap = argparse.ArgumentParser(description=summary(__doc__))
    ap.add_argument("--out", default="out/hamr_leg.rrd", type=arg_output(), help="recording (.rrd)")
    ap.add_argument("--cycles", type=arg_integer(3, MAX_CYCLES), default=40,
                    help=f"cycles of the closed-loop run at 100 Hz, open-loop ones included (3 to {MAX_CYCLES})")
    ap.add_argument("--open-loop-cycles", type=arg_integer(1), default=10,
                    help="cycles before the phase loops close (1 to --cycles - 2)")
    a = parse_args(ap, argv, _check_cycles)
    d = design()
    system = build(d)
    out = {"leg_length_m": LEG_LENGTH, "assumed": "leg length", "design": d}
    with run_guard(**{"--out": a.out}):           # locked before any work
        for name in DOFS:
            sw = sweep(system, name)
            out[f"{name}_sweep"] = sw
            fit = second_order_fit(sw)
            out[f"{name}_resonance_hz"] = fit["resonance_hz"]
            out[f"{name}_fit"] = fit
            out[f"{name}_phase_crossing_hz"] = phase_crossing(sw)
            out[f"{name}_point_mass_resonance_hz"] = d[name]["point_mass_resonance_hz"]
        run = run_closed_loop(system, a.cycles, a.open_loop_cycles, rrd=a.out)
    for name in DOFS:
        e = run["errors"][name]
        out[f"cycles_to_5deg_{name}"] = cycles_to_within(e["true_deg"], a.open_loop_cycles)
        out[f"cycles_to_5deg_{name}_sensed"] = cycles_to_within(e["sensed_deg"], a.open_loop_cycles)
        out[f"open_loop_error_deg_{name}"] = float(e["true_deg"][a.open_loop_cycles - 1])
        out[f"phase_error_deg_{name}"] = {k: list(map(float, v)) for k, v in e.items()}
    out["recording"] = a.out
    print(json.dumps(out, indent=1, default=float))


register(Robot("hamr-leg", summary(__doc__), build, main, {"foot": foot},
               ("hamr", "piezo", "transmission", "self-sensing")))

if __name__ == "__main__":
    sys.exit(run_script(main))
