"""RoboBee wing (seed 003, section 6.1): one pzt-robobee actuator flaps a rigid wing through
its transmission, in air; stroke amplitude against frequency, and the self-sensing estimate.

    python scripts/robobee_wing.py [--out out/robobee_wing.rrd] [--quick]

Prints JSON with resonance_hz, peak_stroke_deg_100V, peak_stroke_deg_200V and
max_estimate_error (fraction), and writes a recording of the 150 Hz run at 200 V. Written
against mjeap's public component API (attach, System) and plain MjSpec.

Model (host in mm, mg, ms):
- the actuator attached without contact (its own damping and timestep);
- the wing: a rigid plate on a stroke hinge, MuJoCo's ellipsoid fluid model in air
  (1.2 kg/m^3, 1.8e-5 Pa s);
- the transmission: a fixed tendon with coefficients x_tip - x_j over the actuator's hinges
  (its linearised tip deflection) and a tendon equality stroke = T_eff x that deflection,
  T_eff = 4000 rad/m (seed 003, from its ref. [48]): the small-motion transmission the paper
  uses to turn the actuator's motion into a stroke angle.
- Wing: 15 mm long (seed 003's 3.5 cm wingspan less the thorax), 4 mm chord and 0.5 mg.
  ASSUMED: the chord and mass are not in the sources here; the resonance scales with
  1/sqrt(wing inertia).

Self-sensing: the estimator of controllers/self_sensing.py (eqs. 7-9), calibrated on the
free actuator's sine sweep at the same bias (as the paper calibrates on the bench), turns
the simulated drive current into tip velocity; integrated and times T_eff, it is the
estimated stroke angle.
"""
from __future__ import annotations

import argparse
import json
from pathlib import Path

import mujoco
import numpy as np

from controllers.self_sensing import calibrate
from mjeap import Scene
from mjeap.drives import make_drive
from mjeap.frequency import sine_sweep
from mjeap.system import System, attach

T_EFF = 4000.0                                  # rad/m, seed 003 section 6.1
SPAN, CHORD, THICKNESS = 15e-3, 4e-3, 20e-6     # m (chord and thickness assumed)
WING_MASS = 0.5e-6                              # kg (assumed)
HINGE_OFFSET = 1e-3                             # m, wing root from the stroke axis
AIR_DENSITY, AIR_VISCOSITY = 1.2, 1.8e-5        # kg/m^3, Pa s
FREQUENCIES = np.arange(30.0, 271.0, 30.0)      # Hz, the paper's 30-270 Hz
VOLTAGES = (100.0, 200.0)                       # V, bias; the signal swings 0..bias
CYCLES, LAST = 30, 4                            # cycles per frequency; the last ones are measured


def build() -> System:
    """The actuator and wing as a System (host in mm, mg, ms)."""
    s, c, t, o = SPAN * 1e3, CHORD * 1e3, THICKNESS * 1e3, HINGE_OFFSET * 1e3
    spec = mujoco.MjSpec.from_string(f"""<mujoco>
  <option gravity="0 0 -9.80665e-3" density="{AIR_DENSITY * 1e-3}" viscosity="{AIR_VISCOSITY}"/>
  <worldbody>
    <site name="mount"/>
    <body name="wing" pos="-5 0 0">
      <joint name="stroke" type="hinge" axis="0 0 1"/>
      <geom name="wing" type="box" size="{s / 2} {t / 2} {c / 2}" pos="{-s / 2 - o} 0 0" mass="{WING_MASS * 1e6}"
            fluidshape="ellipsoid" contype="0" conaffinity="0" rgba="0.75 0.8 1 0.6"/>
    </body>
  </worldbody>
</mujoco>""")
    act = attach(spec, "pzt-robobee", site="mount", prefix="act", contact=False)
    lay, u = act.twin.layout, act.twin.units
    tip = spec.add_tendon(name="tip_deflection")
    for j, x in zip(act.joints, lay.hinge_x):
        tip.wrap_joint(j, (lay.tip_x - x) / u.length)
    spec.add_tendon(name="stroke_angle").wrap_joint("stroke", 1.0)
    eq = spec.add_equality(type=mujoco.mjtEq.mjEQ_TENDON, name1="stroke_angle", name2="tip_deflection")
    eq.data[:5] = [0.0, T_EFF * u.length, 0.0, 0.0, 0.0]
    return System(spec, [act])


def estimator(bias: float):
    """Eqs. 7-9 calibrated on the free actuator's sweep at ``bias`` (C_fit: the datasheet's
    2 x the free capacitance, as the paper's bench)."""
    free = Scene("pzt-robobee")
    c = make_drive("piezo-bimorph", free).params["capacitance"]
    sw = sine_sweep(free, (30.0, 100.0, 300.0, 1000.0, 2000.0), bias / 2, bias / 4, drive_params={"bias": bias})
    return calibrate(sw, bias, 1e9, 2 * c)


def flap(system: System, bias: float, frequency: float, est, rrd=None) -> dict:
    """Sine drive 0..bias at ``frequency`` for CYCLES cycles: stroke amplitudes (deg) over
    the last LAST cycles, simulated and self-sensed, and their steady-state check (the
    amplitude of the cycles before, relative)."""
    q = system.model.joint("stroke").qposadr[0]
    angle = []

    def on_sample(sy):
        angle.append(sy.data.qpos[q])

    r = system.rollout([f"sine:{bias / 2}V@{frequency}Hz,offset={bias / 2}V"], CYCLES / frequency,
                       sample_interval=1 / (frequency * 100), on_sample=on_sample, rrd=rrd)
    a = r.actuators["act"]
    angle = np.array(angle)
    v = est.velocity(a.time, a.voltage, a.signals["current (A)"])
    y = np.concatenate([[0.0], np.cumsum(0.5 * (v[1:] + v[:-1]) * np.diff(a.time))])
    late = a.time > (CYCLES - LAST) / frequency
    before = (a.time > (CYCLES - 2 * LAST) / frequency) & ~late
    amp = np.degrees(0.5 * np.ptp(angle[late]))
    return {"frequency_hz": frequency, "stroke_deg": float(amp),
            "estimated_deg": float(np.degrees(0.5 * np.ptp(T_EFF * y[late]))),
            "steady": float(abs(np.degrees(0.5 * np.ptp(angle[before])) / amp - 1))}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="out/robobee_wing.rrd")
    ap.add_argument("--quick", action="store_true", help="60, 120, 180, 240 Hz only")
    a = ap.parse_args(argv)
    Path(a.out).parent.mkdir(parents=True, exist_ok=True)
    freqs = FREQUENCIES[1::2] if a.quick else FREQUENCIES
    system = build()
    out = {"t_eff_rad_per_m": T_EFF, "wing_span_m": SPAN, "wing_chord_m": CHORD, "wing_mass_kg": WING_MASS,
           "assumed": "wing chord and mass", "sweeps": {}}
    errors = []
    for bias in VOLTAGES:
        est = estimator(bias)
        rows = [flap(system, bias, f, est) for f in freqs]
        out["sweeps"][f"{bias:g}V"] = rows
        peak = max(rows, key=lambda r: r["stroke_deg"])
        out[f"peak_stroke_deg_{bias:g}V"] = peak["stroke_deg"]
        out[f"resonance_hz_{bias:g}V"] = peak["frequency_hz"]
        errors += [abs(r["estimated_deg"] / r["stroke_deg"] - 1) for r in rows]
    out["resonance_hz"] = out[f"resonance_hz_{VOLTAGES[0]:g}V"]
    out["max_estimate_error"] = float(max(errors))
    out["max_unsteadiness"] = float(max(r["steady"] for s in out["sweeps"].values() for r in s))
    flap(system, 200.0, 150.0, estimator(200.0), rrd=a.out)
    out["recording"] = a.out
    print(json.dumps(out, indent=1, default=float))


if __name__ == "__main__":
    main()
