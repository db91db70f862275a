"""HAMR-VI walks (Jayaram et al. 2018, section 6.2): a free-floating 1.43 g, 4.51 cm quadruped,
four legs of two pzt-hamr-small actuators each, trotting on a ground plane open loop at the
paper's 200 V bias.

    mjeap robot hamr-walk [--out out/hamr_walk.rrd] [--frequencies 5 10 20 40 65 80 100]
        [--record-frequency 10] [--amplitude 100] [--drive robot|full] [--settle 0.3] [--measure 0.2]
        [--timestep S] [--mu 0.51] [--segments 4] [--quick]
        [--loop-frequency 80] [--loop-amplitude 20] [--loop-cycles 40] [--loop-out ...] [--no-closed-loop]

Prints JSON: per frequency the forward speed, the no-slip kinematic estimate, foot slip,
body roll and pitch, duty factor and landings per cycle (also gathered in
duty_factor_by_frequency), penetration, the chassis's and legs' lowest points and wall
time; the speed at 65 Hz beside the paper's 0.5 m/s; the contact's sizing (contact); the
rest check (rest: no drive, the feet's normal forces against the weight at every step), the
segment check and the steepest incline climbed at --record-frequency (not with --quick);
the closed_loop section (the eight phase loops against the open loop at
--loop-frequency, --loop-amplitude). Writes a recording of the --record-frequency run and
one of the closed loop (:mod:`mjeap.robots.hamr_walk.experiments`: the studies).
"""
from __future__ import annotations

import argparse
import json
import sys

import numpy as np

from ...io.commandline import arg_integer, arg_number, arg_output, parse_args
from ...io.outputs import run_guard
from ..registry import summary
from .experiments import (AMPLITUDE, FREQUENCIES, LOOP_AMPLITUDE, LOOP_CYCLES, LOOP_FREQUENCY, OPEN_LOOP_CYCLES,
                          RECORD_FREQUENCY, closed_loop_section, max_incline, segment_effect, stand, trot_drive, walk)
from .metrics import walk_metrics
from .model import (BIAS, FREQUENCY_RANGE, MAX_TIMESTEP, MU, PAPER_FREQUENCY, PAPER_SPEED, SEGMENTS, build,
                    contact_sizing, design, model_summary)
from .recording import write_recording

__all__ = ["main"]


def _check_outputs(a) -> None:
    """The recordings are two distinct files (a shared path would overwrite the first)."""
    from ...io.outputs import check_outputs
    check_outputs(**{"--out": a.out, "--loop-out": None if a.no_closed_loop else a.loop_out})


def main(argv=None):
    ap = argparse.ArgumentParser(description=summary(__doc__))
    ap.add_argument("--out", default="out/hamr_walk.rrd", type=arg_output(), help="recording (.rrd)")
    ap.add_argument("--frequencies", nargs="+", type=arg_number(*FREQUENCY_RANGE, "Hz"), default=list(FREQUENCIES),
                    help=f"trot frequencies (Hz, {FREQUENCY_RANGE[0]:g} to {FREQUENCY_RANGE[1]:g})")
    ap.add_argument("--record-frequency", type=arg_number(*FREQUENCY_RANGE, "Hz"), default=RECORD_FREQUENCY,
                    help="the frequency of the recorded run (Hz)")
    ap.add_argument("--amplitude", type=arg_number(0.0, AMPLITUDE, "V", lo_open=True), default=AMPLITUDE,
                    help=f"drive amplitude about V_bias / 2 (V; {AMPLITUDE:g}: full, the signal swings 0..{BIAS:g} V)")
    ap.add_argument("--drive", choices=("robot", "full"), default="robot",
                    help="robot: per frequency the swing at --amplitude within its actuator's travel and the lift at "
                         "the largest amplitude at which the stance pair cannot throw the body (trot_drive); full: "
                         "--amplitude on every actuator")
    ap.add_argument("--timestep", type=arg_number(1e-7, MAX_TIMESTEP, "s"), default=None,
                    help="a step sized for the loaded system (s; default: the actuators' own, 4.51 us)")
    ap.add_argument("--settle", type=arg_number(0.0, 10.0, "s"), default=0.3,
                    help="settling before each trot's measuring window (s; the issue's bands: 0.3)")
    ap.add_argument("--measure", type=arg_number(0.0, 10.0, "s", lo_open=True), default=0.2,
                    help="each trot's measuring window (s)")
    ap.add_argument("--mu", type=arg_number(0.0, 10.0), default=MU, help="foot-ground friction coefficient")
    ap.add_argument("--segments", type=arg_integer(1, 40), default=SEGMENTS, help="segments per actuator")
    ap.add_argument("--loop-frequency", type=arg_number(*FREQUENCY_RANGE, "Hz"), default=LOOP_FREQUENCY,
                    help="the closed-loop trot's frequency (Hz)")
    ap.add_argument("--loop-amplitude", type=arg_number(0.0, AMPLITUDE, "V", lo_open=True), default=LOOP_AMPLITUDE,
                    help="the closed-loop trot's drive amplitude about V_bias / 2 (V)")
    ap.add_argument("--loop-cycles", type=arg_integer(OPEN_LOOP_CYCLES + 2, 10_000), default=LOOP_CYCLES,
                    help=f"cycles of the closed-loop trot, its {OPEN_LOOP_CYCLES} open-loop ones included")
    ap.add_argument("--loop-out", default="out/hamr_walk_loop.rrd", type=arg_output(),
                    help="recording of the closed-loop trot (.rrd)")
    ap.add_argument("--no-closed-loop", action="store_true", help="skip the closed-loop trot")
    ap.add_argument("--quick", action="store_true",
                    help="skip the rest check, the segment check and the incline search (at --record-frequency)")
    a = parse_args(ap, argv, _check_outputs)
    # the recordings locked before any work (a second run on them is refused); each study's
    # recording is written as soon as it is done, so Ctrl-C or SIGTERM keeps it
    with run_guard(**{"--out": a.out, "--loop-out": None if a.no_closed_loop else a.loop_out}):
        return _experiments(a)


def _drive(a, system, f: float) -> dict:
    """walk's amplitude and lift_amplitude (V) at ``f`` Hz: the robot's (trot_drive) or --amplitude on every actuator."""
    return trot_drive(system, f, a.amplitude) if a.drive == "robot" else {"amplitude": a.amplitude,
                                                                            "lift_amplitude": a.amplitude}


def _experiments(a) -> None:
    """The command line's studies (:func:`main`), its outputs already held."""
    d = design()
    system = build(a.mu, a.segments, d=d, timestep=a.timestep)
    out = {"model": model_summary(system), "amplitude_v": a.amplitude, "drive": a.drive,
           "bias_v": BIAS, "mu": a.mu, "timestep_s": system.timestep, "runs": []}
    freqs = sorted(set(a.frequencies) | {a.record_frequency})
    for f in freqs:
        run = walk(system, f, settle=a.settle, measure=a.measure, **_drive(a, system, f))
        m = walk_metrics(run)
        out["runs"].append(m)
        if f == a.record_frequency and a.out:
            write_recording(a.out, system, run)
        print(f"{f:g} Hz (swing {m['amplitude_v']:.3g} V, lift {m['lift_amplitude_v']:.3g} V): {m['speed_m_s']:.4g} m/s (no-slip "
              f"{m['kinematic_speed_m_s'] or float('nan'):.4g}), slip {m['slip_fraction']:.2f}, roll/pitch "
              f"{m['max_abs_roll_deg']:.1f}/{m['max_abs_pitch_deg']:.1f} deg, {m['wall_s_per_simulated_s']:.1f} s wall "
              "per s", file=sys.stderr)
    out.update(_bands(a, system, out["runs"]))
    out["contact"] = contact_sizing(system)
    if not a.no_closed_loop:
        out["closed_loop"] = closed_loop_section(system, a.loop_frequency, a.loop_amplitude, a.loop_cycles, a.loop_out)
    if not a.quick:
        out["rest"] = stand(system)         # no drive: the feet carry the weight at every step, no creep
        out["segment_effect"] = segment_effect()
        out["incline"] = max_incline(a.record_frequency, a.amplitude, a.mu, a.segments)
    out["recording"] = a.out
    print(json.dumps(out, indent=1, default=float))


def _bands(a, system, runs: list) -> dict:
    """The issue's checks on the runs: the 65 Hz speed beside the paper's 0.5 m/s (and, with
    the no-flight lift, the same swing with the lift at the full amplitude too: the flights),
    upright at every frequency of 10-65 Hz, the no-slip check and the contact read-outs per
    frequency."""
    out = {}
    at = {r["frequency_hz"]: r for r in runs}
    if PAPER_FREQUENCY in at:
        v, up = at[PAPER_FREQUENCY]["speed_m_s"], at[PAPER_FREQUENCY]["upright"]
        out["speed_at_65hz_m_s"], out["paper_speed_m_s"], out["upright_at_65hz"] = v, PAPER_SPEED, up
        # a robot that rolled over has no speed to compare
        out["speed_over_paper"] = v / PAPER_SPEED if up else None
        # the check: upright and forward within a factor of 2 of the paper's 0.5 m/s
        out["speed_at_65hz_within_2x_of_paper"] = bool(up and 0.5 * PAPER_SPEED <= v <= 2.0 * PAPER_SPEED)
        if a.drive == "robot":     # the same frequency at the full drive: the flights
            m = walk_metrics(walk(system, PAPER_FREQUENCY, a.amplitude, settle=a.settle, measure=a.measure))
            out["at_65hz_full_drive"] = {
                "amplitude_v": a.amplitude, "speed_m_s": m["speed_m_s"], "upright": m["upright"],
                "max_abs_roll_deg": m["max_abs_roll_deg"], "max_abs_pitch_deg": m["max_abs_pitch_deg"],
                "body_height_range_m": m["body_height_range_m"],
                "cause": "the lift's full stroke pushes the stance pair past the weight (no_flight_lift) and the "
                         "actuators past their travel: the body flies and lands tilted (docs/robots/hamr-walk.md)"}
    band = [r for r in runs if 10.0 <= r["frequency_hz"] <= PAPER_FREQUENCY]
    out["upright_10_to_65_hz"] = {f"{r['frequency_hz']:g}": r["upright"] for r in band}
    out["upright_at_every_frequency_10_to_65_hz"] = bool(band) and all(r["upright"] for r in band)
    low = at[min(at)]
    k = low["kinematic_speed_m_s"]
    out["kinematic_check"] = {"frequency_hz": low["frequency_hz"], "speed_m_s": low["speed_m_s"],
                              "no_slip_estimate_m_s": k, "relative_error": None if not k else low["speed_m_s"] / k - 1.0}
    out["wall_s_per_simulated_s"] = float(np.mean([r["wall_s_per_simulated_s"] for r in runs]))
    # per frequency: the contact read-outs (at the samples' instants, the issue's; over each interval) and landings
    keys = ("lift_amplitude_v", "duty_factor", "contact_duty_factor_sampled", "contact_when_near_sampled",
            "contact_touchdowns_per_cycle_sampled", "contact_duty_factor", "contact_when_near",
            "contact_touchdowns_per_cycle", "step_touchdowns_per_cycle", "force_balance_error",
            "time_with_a_foot_down", "touchdowns_per_cycle", "upright")
    out["duty_factor_by_frequency"] = {f"{r['frequency_hz']:g}": {k_: r[k_] for k_ in keys} for r in runs}
    return out
