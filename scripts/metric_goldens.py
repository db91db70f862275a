"""The converged answers of the metric-accuracy claim's cases (mjeap.validation.metric_claim):
REFERENCE_SEGMENTS segments at half each scene's default step, with their uncertainty,
written to tests/golden/metric_accuracy.json (tests/simulation/test_metric_accuracy.py reads them).

    python scripts/metric_goldens.py [--seed 36] [--cases 40] [--out tests/golden/metric_accuracy.json]
    python scripts/metric_goldens.py --geometry [--out tests/golden/metric_accuracy_geometry.json]
    python scripts/metric_goldens.py --column-band [--out tests/golden/metric_accuracy_column.json]

With --geometry: the converged peak_to_peak of a file actuator's length sweep
(mjeap.validation.metric_claim.GEOMETRY) instead; with --column-band: the stability map's
cases about the instantaneous column load (mjeap.validation.metric_claim.COLUMN_BAND).
"""
import argparse
import json
import sys
from pathlib import Path


def main(argv=None):
    from mjeap.io.commandline import arg_integer, arg_output, parse_args
    from mjeap.validation.metric_claim import column_band_cases, converged, draw_cases, geometry_goldens
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--seed", type=arg_integer(0), default=36)
    ap.add_argument("--cases", type=arg_integer(1, 1000), default=40)
    ap.add_argument("--geometry", action="store_true", help="the length sweep's goldens instead of the cases'")
    ap.add_argument("--column-band", action="store_true", help="the column band's goldens instead of the cases'")
    ap.add_argument("--out", default=None, type=arg_output(),
                    help="default: tests/golden/metric_accuracy[_geometry|_column].json")
    a = parse_args(ap, argv)
    from mjeap.io.outputs import write_text
    root = Path(__file__).resolve().parents[1]
    if a.column_band:
        out = a.out or str(root / "tests/golden/metric_accuracy_column.json")
        goldens = []
        for case in column_band_cases():
            goldens.append(converged(case))
            print(case.describe(), flush=True)
        write_text(out, json.dumps({"cases": goldens}, indent=1, default=float) + "\n", "--out")
        print(f"wrote {out}")
        return
    if a.geometry:
        out = a.out or str(root / "tests/golden/metric_accuracy_geometry.json")
        write_text(out, json.dumps(geometry_goldens(root), indent=1, default=float) + "\n", "--out")
        print(f"wrote {out}")
        return
    a.out = a.out or str(root / "tests/golden/metric_accuracy.json")
    goldens = []
    for i, case in enumerate(draw_cases(a.seed, a.cases)):
        goldens.append(converged(case))
        print(f"{i + 1}/{a.cases} {case.describe()}", flush=True)
    write_text(a.out, json.dumps({"seed": a.seed, "cases": goldens}, indent=1, default=float) + "\n", "--out")
    print(f"wrote {a.out}")


if __name__ == "__main__":
    from mjeap.io.commandline import run_script
    sys.exit(run_script(main))
