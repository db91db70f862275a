"""HAMR swing leg at 100 Hz: 10 cycles open loop, then the self-sensed phase PID.

    python scripts/hamr_leg.py [--out out/hamr-leg.rrd] [--cycles 40]

Prints the foot phase error per cycle (sensed and true) and writes the recording with the
foot path before and after the loop closes.
"""
import argparse
import json

from controllers.hamr_leg import SWING, run_leg


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="out/hamr-leg.rrd")
    ap.add_argument("--cycles", type=int, default=40)
    ap.add_argument("--open-loop-cycles", type=int, default=10)
    a = ap.parse_args(argv)
    run = run_leg(SWING, cycles=a.cycles, open_loop_cycles=a.open_loop_cycles, rrd=a.out)
    print("cycle  sensed error (deg)  true error (deg)")
    for n, (s, t) in enumerate(zip(run.sensed_error_deg, run.true_error_deg)):
        mark = "  open loop" if n < run.open_loop_cycles else ""
        print(f"{n + 1:5d}  {s:18.2f}  {t:16.2f}{mark}")
    print(f"closed-loop cycles to within 5 deg: true {run.cycles_to_within(5.0)}, "
          f"sensed {run.cycles_to_within(5.0, 'sensed')}")
    print(json.dumps(run.meta, indent=1, default=float))
    print(f"wrote {a.out}")


if __name__ == "__main__":
    main()
