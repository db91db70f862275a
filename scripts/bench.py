#!/usr/bin/env python
"""Benchmarks, printed as JSON (and written with --json FILE): one module each under
benchmarks/ (its docstring says what it measures; ``run(args)`` gives its section of the
JSON), run side by side in this one process, in the order of BENCHMARKS. ``--only NAME``
runs some. docs/bench.json (``--json docs/bench.json``) feeds the documentation's
performance tables (docs/hooks/bench_tables.py).
"""
import argparse
import importlib
import json
import os
import platform
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
os.environ.setdefault("MUJOCO_GL", "disable")

import mujoco  # noqa: E402

#: the benchmarks (modules of benchmarks/), in the order they run and the JSON lists them
BENCHMARKS = ("models", "rollout", "drives", "threaded", "elastica", "sweep", "native", "accuracy", "metric_map",
              "early_stop", "optimize", "warp", "show", "hamr_walk_env")


def describe() -> str:
    """Every benchmark's name and what it measures (its module's docstring)."""
    out = []
    for name in BENCHMARKS:
        doc = (importlib.import_module(f"benchmarks.{name}").__doc__ or "").strip()
        out.append(f"{name}: {doc}")
    return "\n\n".join(out)


def main(argv=None):
    from mjeap.io.commandline import arg_number, arg_output, parse_args
    ap = argparse.ArgumentParser(description=__doc__, epilog=describe(),
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
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
        if name in only:
            out[name] = importlib.import_module(f"benchmarks.{name}").run(args)
            emit()
    print(emit())


if __name__ == "__main__":
    from mjeap.io.commandline import run_script
    sys.exit(run_script(main))
