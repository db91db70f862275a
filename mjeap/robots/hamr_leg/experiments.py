"""HAMR single leg (Jayaram et al. 2018, section 6.2): two pzt-hamr-small actuators drive a rigid leg
through its swing and lift transmissions; resonances from sine sweeps, then the foot
ellipse at 100 Hz open loop and with both phase loops closed on the self-sensed currents.

    mjeap robot hamr-leg [--out out/hamr_leg.rrd] [--cycles 40] [--open-loop-cycles 10]

Prints JSON with swing_resonance_hz, lift_resonance_hz, cycles_to_5deg_swing and
cycles_to_5deg_lift (closed-loop cycles until the true foot phase error stays within 5
degrees), and writes the recording. Written against mjeap's public component API (attach,
System, System.drive_observer) and plain MjSpec.

Control: V = V_bias/2 + a sin(omega t + phi) per actuator, phi moved once per cycle by the
self-sensed phase PID of mjeap.controllers.hamr_leg (each actuator's drive current through its
own estimator, calibrated on the free actuator; no simulator state), its gains from each
transmission's second-order model (phase_loop_gains: the swing at resonance, the lift 20 Hz
above its own). Desired foot motion:
swing sin(omega t), lift 90 degrees ahead: the ellipse of Jayaram et al. 2018's ref. [50].

The leg itself (design, builder, read-out) is :mod:`mjeap.robots.hamr_leg.model`.
"""
from __future__ import annotations

import argparse
import json

import numpy as np

from ...analysis.frequency import phasor
from ...controllers.hamr_leg import (LegPhaseController, PhaseControllers, cycles_to_within, free_estimator,
                                     phase_errors_per_cycle, phase_loop_gains)
from ...errors import check_integer
from ...io.commandline import arg_integer, arg_output, parse_args
from ...io.outputs import run_guard
from ...simulation.system import System
from ..registry import summary
from .model import BIAS, DOFS, FOOT_COORD, LEG_LENGTH, ZETA, build, design, foot
from ...lazy import lazy_module

#: imported at its first use (mjeap.lazy)
optimize = lazy_module("scipy.optimize")

AMPLITUDE, FREQUENCY = 20.0, 100.0            # V (40 Vpp), Hz
SWEEP = np.array([40, 50, 60, 70, 75, 80, 85, 90, 95, 100, 105, 110, 120, 130, 140.0])   # Hz, Fig. 8(a)-(b)
SWEEP_CYCLES, SWEEP_LAST = 24, 6


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


class LegControllers(PhaseControllers):
    """Both phase controllers as one system controller (controllers.hamr_leg.PhaseControllers:
    each reads only its actuator's drive current and its own commands)."""

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
    from ...io.recording import write_system_recording

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
