"""The run commands: ``mjeap rollout``, ``view``, ``frf``, ``robot`` and ``validate``."""
from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path


from ..errors import ParameterError
from ..io.commandline import arg_number
from .common import add_scene_args, drive_params_from, report_extra, scene_from_args


def cmd_rollout(args) -> int:
    from ..simulation.rollout import rollout
    from ..simulation.accuracy import check_accuracy
    if args.accuracy is not None:
        check_accuracy(args.accuracy)
        # the target chooses segments, integrator and timestep: each given alongside it is refused alike
        for flag, given in (("--segments", args.segments), ("--integrator", args.integrator),
                            ("--timestep", args.timestep), ("--estimate-error", args.estimate_error or None)):
            if given is not None:
                raise ParameterError(flag, given, f"no {flag} with --accuracy (the target chooses the model and "
                                     "estimates its error)")
    from ..io.outputs import check_outputs
    from ..simulation.scene import input_files
    # before any work (the scene's build too): never a link, never the actuator file or the waveform's CSV
    check_outputs(inputs=input_files([args.name], [args.voltage]), rrd=args.rrd, csv_path=args.csv)
    scene = scene_from_args(args)
    params = drive_params_from(args.param)
    r = rollout(scene, args.voltage, args.duration, drive=args.drive, drive_params=params,
                initial_curvature=args.initial_curvature, rrd=args.rrd, csv_path=args.csv,
                progress=False if args.quiet else ("lines" if args.progress else None), engine=args.engine,
                max_steps=args.max_steps,
                accuracy=args.accuracy, estimate_error=args.estimate_error)
    summary = {"actuator": scene.actuator.id, "actuator_file": scene.actuator.source_file,
               "drive": r.meta["drive"], "engine": r.meta["engine"],
               "engine_reason": r.meta.get("engine_reason", ""),
               "voltage": args.voltage,
               "duration_s": args.duration, "segments": r.meta["scene"]["segments"],
               "integrator": r.meta["scene"]["integrator"], "timestep_s": r.meta["scene"]["timestep"],
               "steps": r.meta["steps"],
               "wall_time_s": round(r.meta["wall_time_s"], 3),
               "tip_curvature_final_per_m": float(r.tip_curvature[-1]),
               "tip_curvature_peak_to_peak_per_m": r.peak_to_peak(),
               "tip_deflection_final_m": float(r.tip_position[-1, 1]),
               "rrd": args.rrd, "csv": args.csv}
    if "accuracy" in r.meta:
        a = r.meta["accuracy"]
        summary["accuracy"] = {"quantity": a["quantity"], "target": a["target"],
                               "estimated_error": a["estimated_error"], "estimate": a["estimate"]}
        if a["target"] is not None:
            summary["accuracy"].update(predicted_error=a["predicted_error"], runs=len(a["runs"]),
                                       wall_time_all_runs_s=round(a["wall_time_s"], 3))
    if r.meta.get("warnings"):
        summary["warnings"] = r.meta["warnings"]
        for w in r.meta["warnings"]:
            print(f"mjeap: warning: {w}", file=sys.stderr)
    print(json.dumps(summary, indent=2))
    return 0


def cmd_validate(args) -> int:
    from ..validation import report, run_validation
    exps = run_validation(args.experiments, out=args.out, quick=args.quick, progress=not args.quiet)
    print(report.console_table(exps))
    checks = [c for e in exps for c in e.checks]
    failed = [c for c in checks if c.verdict == "FAIL"]
    tol = sum(c.tolerance is not None for c in checks)
    print(f"\n{len(checks)} rows, {tol} with a tolerance: {tol - len(failed)} pass, {len(failed)} fail"
          + (f"; report in {args.out}" if args.out else ""))
    for c in failed:
        print(f"FAIL {c.experiment}: {c.quantity}: {c.simulated:.6g} vs {c.reference:.6g} {c.unit} ({c.source})")
    return 1 if failed else 0


#: where mjeap frf writes frf.csv, frf.json and frf.png unless told (--out)
FRF_OUT = "out/frf"


def cmd_frf(args) -> int:
    """Small-signal frequency response: frf.csv, frf.json (what was computed, how) and, with
    the report extra, frf.png, all in --out; checked before any work."""
    from ..analysis import frf
    from ..io.outputs import check_outputs, replacing
    f0, f1, n = frf.check_sweep(args.start, args.stop, args.points)
    folder = Path(args.out or FRF_OUT)
    if folder.exists() and not folder.is_dir():
        raise ParameterError("--out", str(folder), "a folder for frf.csv, frf.json and frf.png", "it is a file")
    paths = {"--out (frf.csv)": folder / "frf.csv", "--out (frf.json)": folder / "frf.json"}
    plot = report_extra()
    if plot:
        paths["--out (frf.png)"] = folder / "frf.png"
    from ..model.actuator_file import is_actuator_file
    # names mjeap picks in --out: regular files or none, never a link, never the actuator file
    check_outputs(inputs={"actuator file": args.name if is_actuator_file(args.name) else None}, picked=paths, **paths)
    scene = scene_from_args(args)
    r = frf.frequency_response(scene, f0, f1, n, offset=args.offset, drive=args.drive,
                               drive_params=drive_params_from(args.param))
    out = r.summary()
    out["files"] = {"csv": str(paths["--out (frf.csv)"]), "json": str(paths["--out (frf.json)"]),
                    "png": str(folder / "frf.png") if plot else "not written: the report extra (matplotlib) is not "
                                                                 "installed (pip install 'mjeap[report]')"}
    frf.write_frf(r, paths["--out (frf.csv)"])
    with replacing(paths["--out (frf.json)"], "--out (frf.json)", picked=True) as tmp:
        tmp.write_text(json.dumps(out, indent=2, default=float), encoding="utf-8")
    if plot:
        frf.plot_frf(r, folder / "frf.png")
    if r.admittance is None:
        print(f"mjeap frf: admittance columns left empty: {r.admittance_reason}", file=sys.stderr)
    print(json.dumps(out, indent=2, default=float))
    return 0


def cmd_view(args) -> int:
    """MuJoCo's viewer on an actuator (catalog id or .toml file) or an MJCF file."""
    from ..simulation import viewer
    why = viewer.window_reason()                  # before any work
    if why is not None:
        raise viewer.NoDisplayError(f"mjeap view needs a display: {why}. Write the model instead: "
                                    f"mjeap mjcf {args.name} -o FILE, or use mjeap.assets.path(NAME)")
    from ..robots import names as robot_names
    if args.name.lower().endswith(".xml"):
        vm = viewer.file_view_model(args.name, args.voltage)
    elif args.name in robot_names():
        from ..robots import load
        vm = viewer.system_view_model(load(args.name), f"robot {args.name}")
    else:
        from ..units import REAL_TIME_UNITS
        scene = scene_from_args(args, REAL_TIME_UNITS)
        vm = viewer.view_model(scene, args.drive, drive_params_from(args.param), args.voltage)
        f1 = scene.choice.first_frequency
        if f1 / args.slow_motion > 20:
            print(f"mjeap view: a period of the first bending mode ({f1:.3g} Hz) lasts {args.slow_motion / f1:.2g} s "
                  f"on screen; --slow-motion {10 ** math.ceil(math.log10(f1 / 2)):g} shows it in ~0.5 s",
                  file=sys.stderr)
    print(f"mjeap view: {vm.note}; timestep {vm.timestep:.3g} s, {args.slow_motion:g}x slow motion", file=sys.stderr)
    out = viewer.view(vm, args.slow_motion)
    print(f"mjeap view: {out['simulated_s']:.4g} s simulated in {out['wall_s']:.4g} s"
          + (f", up to {out['max_lag_s']:.3g} s behind (raise --slow-motion)" if out["max_lag_s"] > 0.1 else ""),
          file=sys.stderr)
    return 0


def cmd_robot(args) -> int:
    from ..robots import get
    return get(args.name).main(args.options) or 0


def add_parsers(sub) -> None:
    """This module's commands on the command line (``sub``: its subparsers)."""
    p = sub.add_parser("view", help="MuJoCo's viewer on an actuator (or an MJCF file) in real time, the drive "
                       "voltage on a slider")
    add_scene_args(p)
    p.add_argument("--slow-motion", type=arg_number(1e-3, 1e9), default=1.0,
                   help="wall seconds per simulated second (default 1: real time; ~100 for a 100 Hz piezo)")
    p.add_argument("--voltage", help="play a waveform instead of the slider (needed where the drive has no "
                   "native form), e.g. square:1V@0.5Hz")
    p.add_argument("--drive", help="drive name (default: the actuator's own)")
    p.add_argument("--param", action="append", metavar="KEY=VALUE", help="drive parameter (repeatable)")
    p.set_defaults(func=cmd_view)
    p = sub.add_parser("rollout", help="run an actuator with its drive and record it")
    add_scene_args(p)
    p.add_argument("--voltage", required=True,
                   help="waveform, e.g. step:3V, square:1.5V@0.1Hz, sine:50V@100Hz,offset=100V, csv:FILE")
    p.add_argument("--duration", type=float, required=True, help="simulated time (s)")
    p.add_argument("--drive", help="drive name (default: the actuator's own)")
    p.add_argument("--param", action="append", metavar="KEY=VALUE", help="drive parameter (repeatable)")
    p.add_argument("--initial-curvature", type=float, default=0.0, help="start as a uniform arc (1/m)")
    p.add_argument("--rrd", help="write a Rerun recording here")
    p.add_argument("--csv", help="write the time series here")
    from ..engines import ENGINES
    p.add_argument("--max-steps", type=int, default=None,
                   help="refuse runs of more steps than this (default 20,000,000: minutes of work)")
    p.add_argument("--engine", choices=ENGINES, default="auto",
                   help="'native' (the drive compiled into the model, on mujoco.rollout), 'threaded' "
                        "(mujoco.rollout, the drive's moments precomputed: open-loop drives only), 'loop' (Python "
                        "lockstep, any drive), 'warp' (MuJoCo Warp, a GPU) or 'auto' (default: the first of "
                        "native, threaded, loop that applies; the summary's engine_reason says why)")
    p.add_argument("--accuracy", type=float, default=None,
                   help="largest error of the tip curvature relative to its swing (1e-5 to 0.2): segments, "
                        "integrator and timestep are chosen for it and the error is estimated (mjeap.simulation.accuracy)")
    p.add_argument("--estimate-error", action="store_true",
                   help="without --accuracy: estimate this model's error with a coarser companion run")
    shown = p.add_mutually_exclusive_group()
    shown.add_argument("--quiet", action="store_true", help="no progress (default: a bar on a terminal once the run "
                       "has lasted 2 s)")
    shown.add_argument("--progress", action="store_true", help="one line per 10 %% of the simulated time on stderr "
                       "(for logs and batch jobs)")
    p.set_defaults(func=cmd_rollout)
    p = sub.add_parser("robot", help="run a robot's experiment (mjeap.robots: gripper, hamr-leg, hamr-walk, "
                       "robobee-wing, and any registered; a wrong name lists them)",
                       description="Run a registered robot's experiment; its options follow the name "
                                   "(mjeap robot NAME --help).")
    p.add_argument("name", help="a registered robot (mjeap.robots.names())")
    p.add_argument("options", nargs=argparse.REMAINDER, help="the robot experiment's own options")
    p.set_defaults(func=cmd_robot)
    p = sub.add_parser("validate", help="run the validation experiments; report, figures and recordings")
    p.add_argument("experiments", nargs="*", help="experiment names or prefixes (default: all)")
    p.add_argument("--out", default="out/validation", help="report folder (default: out/validation)")
    p.add_argument("--quick", action="store_true", help="fewer bisection steps and representations")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(func=cmd_validate)
    p = sub.add_parser("frf", help="small-signal frequency response (tip deflection and admittance per volt) from "
                       "the linearised model; resonance, antiresonance, effective coupling")
    add_scene_args(p)
    p.add_argument("--from", dest="start", required=True, help="lowest frequency, Hz or with a unit: 200Hz, 0.2kHz")
    p.add_argument("--to", dest="stop", required=True, help="highest frequency (Hz or with a unit), up to the model's "
                   "highest resolved mode and its step's Nyquist limit")
    p.add_argument("--points", default=200, help="log-spaced frequencies (>= 2; default 200)")
    p.add_argument("--offset", type=float, default=None, help="operating voltage of the drive's input (V; default the "
                   "drive's rest voltage, V_bias/2 for piezo-bimorph)")
    p.add_argument("--drive", help="drive name (default: the actuator's own)")
    p.add_argument("--param", action="append", metavar="KEY=VALUE", help="drive parameter (repeatable)")
    p.add_argument("--out", help=f"folder for frf.csv, frf.json and frf.png (default {FRF_OUT})")
    p.set_defaults(func=cmd_frf)
