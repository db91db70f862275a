"""HAMR-VI walks (Jayaram et al. 2018, section 6.2): a free-floating 1.43 g, 4.51 cm quadruped,
four legs of two pzt-hamr-small actuators each, trotting on a ground plane open loop at the
paper's 200 V bias.

    mjeap robot hamr-walk [--out out/hamr_walk.rrd] [--frequencies 5 10 20 40 65 80 100]
        [--record-frequency 10] [--amplitude 100] [--mu 0.51] [--segments 4] [--quick]
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
from .experiments import (AMPLITUDE, FREQUENCIES, LIMITED_LIFT, LOOP_AMPLITUDE, LOOP_CYCLES, LOOP_FREQUENCY,
                          OPEN_LOOP_CYCLES, RECORD_FREQUENCY, closed_loop_section, max_incline, segment_effect, stand,
                          walk)
from .metrics import walk_metrics
from .model import (BIAS, FREQUENCY_RANGE, MU, PAPER_FREQUENCY, PAPER_SPEED, SEGMENTS, build, contact_sizing, design,
                    model_summary)
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


def _experiments(a) -> None:
    """The command line's studies (:func:`main`), its outputs already held."""
    d = design()
    system = build(a.mu, a.segments, d=d)
    out = {"model": model_summary(system), "amplitude_v": a.amplitude, "bias_v": BIAS, "mu": a.mu, "runs": []}
    freqs = sorted(set(a.frequencies) | {a.record_frequency})
    for f in freqs:
        run = walk(system, f, a.amplitude)
        m = walk_metrics(run)
        out["runs"].append(m)
        if f == a.record_frequency and a.out:
            write_recording(a.out, system, run)
        print(f"{f:g} Hz: {m['speed_m_s']:.4g} m/s (no-slip {m['kinematic_speed_m_s'] or float('nan'):.4g}), slip "
              f"{m['slip_fraction']:.2f}, roll/pitch {m['max_abs_roll_deg']:.1f}/{m['max_abs_pitch_deg']:.1f} deg, "
              f"{m['wall_s_per_simulated_s']:.1f} s wall per s", file=sys.stderr)
    at = {r["frequency_hz"]: r for r in out["runs"]}
    if PAPER_FREQUENCY in at:
        v, up = at[PAPER_FREQUENCY]["speed_m_s"], at[PAPER_FREQUENCY]["upright"]
        out["speed_at_65hz_m_s"], out["paper_speed_m_s"], out["upright_at_65hz"] = v, PAPER_SPEED, up
        # a robot that rolled over has no speed to compare
        out["speed_over_paper"] = v / PAPER_SPEED if up else None
        # the check: upright and forward within a factor of 2 of the paper's 0.5 m/s
        out["speed_at_65hz_within_2x_of_paper"] = bool(up and 0.5 * PAPER_SPEED <= v <= 2.0 * PAPER_SPEED)
        if not up:      # the cause, shown: the same swing with the lift at LIMITED_LIFT (hamr_walk.study)
            m = walk_metrics(walk(system, PAPER_FREQUENCY, a.amplitude, lift_amplitude=LIMITED_LIFT))
            out["at_65hz_lift_limited"] = {
                "lift_amplitude_v": LIMITED_LIFT, "speed_m_s": m["speed_m_s"], "upright": m["upright"],
                "speed_over_paper": m["speed_m_s"] / PAPER_SPEED if m["upright"] else None,
                "max_abs_roll_deg": m["max_abs_roll_deg"], "max_abs_pitch_deg": m["max_abs_pitch_deg"],
                "cause": "at full drive the feet's stroke (3.2-3.6 mm, A omega^2 = 60 g at 65 Hz) throws the 1.43 g "
                         "body into flights it lands from tilted (docs/robots/hamr-walk.md; "
                         "mjeap.robots.hamr_walk.study)"}
    # the check: the full-drive trot upright at every frequency of 10-65 Hz run here
    band = [r for r in out["runs"] if 10.0 <= r["frequency_hz"] <= PAPER_FREQUENCY]
    out["upright_10_to_65_hz"] = {f"{r['frequency_hz']:g}": r["upright"] for r in band}
    out["upright_at_every_frequency_10_to_65_hz"] = bool(band) and all(r["upright"] for r in band)
    low = at[min(at)]
    k = low["kinematic_speed_m_s"]
    out["kinematic_check"] = {"frequency_hz": low["frequency_hz"], "speed_m_s": low["speed_m_s"],
                              "no_slip_estimate_m_s": k, "relative_error": None if not k else low["speed_m_s"] / k - 1.0}
    out["wall_s_per_simulated_s"] = float(np.mean([r["wall_s_per_simulated_s"] for r in out["runs"]]))
    # per frequency: the share of the time a foot is down (per foot), a foot at all, the landings per cycle
    out["duty_factor_by_frequency"] = {f"{r['frequency_hz']:g}": {
        "duty_factor": r["duty_factor"], "contact_duty_factor": r["contact_duty_factor"],
        "contact_when_near": r["contact_when_near"], "contact_touchdowns_per_cycle": r["contact_touchdowns_per_cycle"],
        "force_balance_error": r["force_balance_error"], "time_with_a_foot_down": r["time_with_a_foot_down"],
        "touchdowns_per_cycle": r["touchdowns_per_cycle"], "upright": r["upright"]} for r in out["runs"]}
    out["contact"] = contact_sizing(system)
    if not a.no_closed_loop:
        out["closed_loop"] = closed_loop_section(system, a.loop_frequency, a.loop_amplitude, a.loop_cycles, a.loop_out)
    if not a.quick:
        out["rest"] = stand(system)         # no drive: the feet carry the weight at every step, no creep
        out["segment_effect"] = segment_effect()
        out["incline"] = max_incline(a.record_frequency, a.amplitude, a.mu, a.segments)
    out["recording"] = a.out
    print(json.dumps(out, indent=1, default=float))
