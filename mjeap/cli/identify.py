"""The identification commands: ``mjeap identify step``, ``hinges`` and ``piezo`` (the identified
actuator file locked, checked and read back)."""
from __future__ import annotations

import json
import sys

import numpy as np

from ..errors import ParameterError
from .common import add_scene_args, drive_params_from, scene_from_args, told_actuator


#: where mjeap identify writes the identified actuator file unless told (--out)
IDENTIFIED = "out/identified.toml"


def _identified_out(args, act, stack, data=()) -> str:
    """The identified file's path (--out, default IDENTIFIED: a name mjeap picks), checked and
    locked for the run before any work (``stack``: an ExitStack holding the lock): a
    writable path other than the run's inputs, the actuator file it comes from (a
    hand-written file's comments and units would be lost) and the data file (the
    measurements, ``data``: (name, path) pairs). A second identify on the same --out is
    refused at once."""
    from ..io.outputs import run_guard
    out = args.out or IDENTIFIED
    inputs = [("actuator file", act.source_file if act is not None else None), *data]
    stack.enter_context(run_guard(inputs=inputs, picked=() if args.out else ("--out",), **{"--out": out}))
    return out


def _write_identified(act, out: str) -> str:
    """Write ``act`` to ``out`` whole or not at all (mjeap.io.outputs.replacing), once its
    drive was built on it (an identified value the drive refuses is never written) and its
    text read back as an actuator file (what cannot be read back is never put in place)."""
    from ..drives import make_drive
    from ..io.outputs import replacing
    from ..model.actuator_file import actuator_toml
    from ..simulation.scene import Scene
    from ..model.actuator_file import read_actuator
    make_drive(None, Scene(act, segments=2, gravity=False))
    text = actuator_toml(act)
    with replacing(out, "--out", picked=out == IDENTIFIED) as tmp:
        tmp.write_text(text, encoding="utf-8")
        read_actuator(tmp.with_name(tmp.name))   # what is written reads back, or it is not put in place
    return out


def cmd_identify_step(args) -> int:
    from contextlib import ExitStack
    with ExitStack() as stack:
        return _identify_step(args, stack)


def _identify_step(args, stack) -> int:
    from ..analysis.identify import fit_step_response, given_rows, read_columns, step_actuator, step_rows
    from ..analysis.identify import check_identification
    act = given = None
    if args.actuator is not None:       # the file to put the fit in: checked before any work
        act = told_actuator(args.actuator)
        check_identification(act, "step")
        given = given_rows(drive_params_from(args.param), "mjeap identify step")
        step_rows(act, given)
        out_path = _identified_out(args, act, stack, [("data file", args.file)])
    else:
        for flag, v in (("--out", args.out), ("--param", args.param)):
            if v is not None:
                raise ParameterError(flag, v if flag == "--out" else " ".join(v),
                                     f"{flag} only with --actuator (the actuator file the identified parameters go in)")
    d = read_columns(args.file, [args.time_column, args.curvature_column],
                     units={args.time_column: "s", args.curvature_column: "1/m"})
    fit = fit_step_response(d[args.time_column], d[args.curvature_column], args.voltage, args.t_step)
    from ..analysis.file_fit import check_residual
    warning = check_residual(fit.rms_residual, float(np.ptp(d[args.curvature_column])), "identify step",
                             "nothing written" if act is None else f"nothing written to {out_path}")
    out = {"fit": "kappa(t) = A + B exp(-p t) + C exp(-a t)", "A_per_m": fit.A, "B_per_m": fit.B, "C_per_m": fit.C,
           "transfer_function": f"K/V = {fit.gain:.4g} (s + {fit.zero:.4g}) / ((s + {fit.pole_mechanical:.4g})"
                                f"(s + {fit.pole_electrical:.4g}))",
           "initial_curvature_per_m": fit.initial_curvature, "rms_residual_per_m": fit.rms_residual,
           "drive": "rc-relaxation", "drive_parameters": fit.drive_parameters(),
           "use": "mjeap rollout ACTUATOR --drive rc-relaxation " +
                  " ".join(f"--param {k}={v:.6g}" for k, v in fit.drive_parameters().items())}
    if warning:
        out["warning"] = warning
        print(f"mjeap: warning: {warning}", file=sys.stderr)
    if act is not None:
        out["actuator_file"] = _write_identified(step_actuator(act, fit, args.file, given), out_path)
        out["use"] = f"mjeap rollout {out_path} --voltage step:{args.voltage:g}V --duration ..."
    print(json.dumps(out, indent=2))
    return 0


def cmd_identify_hinges(args) -> int:
    """The beam's stiffness scale (EI(x) kept proportional to the file's), mass scale and
    damping ratio fitted to a tip trajectory with the file's own model
    (:mod:`mjeap.analysis.file_fit`); the identified file is the model that was fitted."""
    from contextlib import ExitStack
    with ExitStack() as stack:
        return _identify_hinges(args, stack)


def _identify_hinges(args, stack) -> int:
    from ..analysis import file_fit, identify as ident
    scene = scene_from_args(args)
    params = drive_params_from(args.param)
    given = ident.given_rows(params, "mjeap identify hinges")
    ident.file_drive_rows(scene.actuator, args.drive, given)        # checked before the fit, as is --out
    out_path = _identified_out(args, scene.actuator, stack, [("data file", args.file)])
    d = ident.read_columns(args.file, [args.time_column, args.tip_column],
                           units={args.time_column: "s", args.tip_column: "m"})
    t, y = d[args.time_column], d[args.tip_column]
    fit = file_fit.fit_tip_trajectory(scene, t, y, args.voltage, drive=args.drive, drive_params=params)
    act = file_fit.trajectory_actuator(scene, fit, args.file, drive=args.drive, given=given)
    EI = act.flexural_rigidity_at([0.0, act.length])
    out = {**fit.as_dict(), "rms_residual_m": fit.rms_residual, "residual_fraction": fit.rms_residual / fit.swing,
           "simulations": fit.evaluations, "segments": scene.layout.segments,
           "flexural_rigidity_clamp_N_m2": float(EI[0]), "flexural_rigidity_tip_N_m2": float(EI[1]),
           "mass_kg": act.total_mass(), "first_frequency_hz": file_fit_f1(scene, act)}
    warning = file_fit.check_residual(fit.rms_residual, fit.swing, "identified actuator",
                                      f"nothing written to {out_path}")
    out["identified_file_rms_m"] = fit.rms_residual
    if warning:
        out["warning"] = warning
        print(f"mjeap: warning: {warning}", file=sys.stderr)
    out["actuator_file"] = _write_identified(act, out_path)
    print(json.dumps(out, indent=2, default=float))
    return 0


def file_fit_f1(scene, act) -> float:
    """The first mode (Hz) of ``act`` built as ``scene`` is."""
    from ..analysis.identify import scene_like
    return float(scene_like(scene, act).choice.first_frequency)


def cmd_identify_piezo(args) -> int:
    """A piezo bender's coupling, stiffness or tip mass, damping ratio, capacitance and
    resistance fitted to stroke, tip-FRF and impedance data (or a published resonance) with
    the file's own small-signal model (:mod:`mjeap.analysis.piezo_fit`)."""
    from contextlib import ExitStack
    with ExitStack() as stack:
        return _identify_piezo(args, stack)


def _identify_piezo(args, stack) -> int:
    from ..analysis import file_fit, identify as ident, piezo_fit as pf
    from ..analysis.frf import parse_frequency
    if not any((args.stroke, args.frf, args.impedance, args.resonance)):
        raise ParameterError("identify piezo", "no measurement", "at least one of --stroke, --frf, --impedance "
                             "(CSV files) or --resonance (a published first resonance, e.g. 1750Hz)")
    resonance = None if args.resonance is None else parse_frequency(args.resonance, "--resonance")
    scene = scene_from_args(args)
    ident.check_identification(scene.actuator, "piezo")
    given = ident.given_rows(drive_params_from(args.param), "mjeap identify piezo")
    ident.file_drive_rows(scene.actuator, None, given)
    out_path = _identified_out(args, scene.actuator, stack, [(f"--{k} file", getattr(args, k))
                                                             for k in ("stroke", "frf", "impedance")])
    data = pf.PiezoData(
        stroke=None if args.stroke is None else pf.read_stroke(args.stroke, args.voltage_column, args.stroke_column),
        frf=None if args.frf is None else pf.read_frf(args.frf),
        impedance=None if args.impedance is None else (*pf.read_impedance(args.impedance), args.impedance_state),
        resonance=resonance,
        sources={"stroke": args.stroke, "frf": args.frf,
                 "impedance": f"{args.impedance} ({args.impedance_state} actuator)" if args.impedance else None,
                 "resonance": f"{args.resonance} (given: --resonance)"})
    fit = pf.fit_piezo(scene, data, drive_params=drive_params_from(args.param))
    act = pf.piezo_actuator(scene, fit, data, given)
    out = {"identified": {k: {"factor" if k != "damping_ratio" else "value": v, "std": fit.std[k]}
                          for k, v in fit.values.items()},
           "held": fit.held, "rms_residuals": fit.residuals, "derived": fit.derived, "evaluations": fit.evaluations}
    name = pf.COUPLING_PARAMETER[act.drive]
    out["file"] = {k: {"value": r[0], "source": r[2]} for k, r in act.drive_parameters.items()
                   if k in (name, "capacitance", "resistance")}
    out["file"].update({"damping_ratio": {"value": act.damping_ratio.value, "source": act.damping_ratio.source},
                        "tip_block_mass_kg": {"value": act.planform.tip_block_mass,
                                              "source": act.planform.residual_source},
                        "flexural_rigidity_clamp_N_m2": {"value": float(act.flexural_rigidity_at(0.0)[0]),
                                                         "source": act.layers[0].provenance("youngs_modulus")}})
    worst = max(fit.residuals, key=fit.residuals.get)
    warning = file_fit.check_residual(fit.residuals[worst], None, f"identify piezo ({worst})",
                                      f"nothing written to {out_path}")
    if warning:
        out["warning"] = f"{worst}: {warning}"
        print(f"mjeap: warning: {worst}: {warning}", file=sys.stderr)
    for k, why in fit.held.items():
        if k in ("stiffness", "tip_mass") and any(q in fit.values for q in ("stiffness", "tip_mass")):
            print(f"mjeap identify piezo: f1 fitted by the {'tip block mass' if k == 'stiffness' else 'modulus scale'}:"
                  f" {k} {why}", file=sys.stderr)
    out["actuator_file"] = _write_identified(act, out_path)
    print(json.dumps(out, indent=2, default=float))
    return 0


def add_parsers(sub) -> None:
    """This module's commands on the command line (``sub``: its subparsers)."""
    p = sub.add_parser("identify", help="fit the papers' models to measured data (CSV with a header)")
    isub = p.add_subparsers(dest="what", required=True)
    q = isub.add_parser("step", help="Dadras et al. 2021: transfer function from a curvature step response")
    q.add_argument("file")
    q.add_argument("--voltage", type=float, required=True, help="step amplitude (V)")
    q.add_argument("--t-step", type=float, default=0.0, help="time of the step (s; within the data's time span)")
    q.add_argument("--time-column", default="time")
    q.add_argument("--curvature-column", default="tip_curvature")
    q.add_argument("--actuator", help="catalog id or actuator file (.toml) to put the identified rc-relaxation "
                   f"parameters in, written to --out (default {IDENTIFIED})")
    q.add_argument("--param", action="append", metavar="KEY=VALUE",
                   help="with --actuator: an rc-relaxation parameter the step does not identify (capacitance)")
    q.add_argument("--out", help=f"with --actuator: the identified actuator file (default {IDENTIFIED})")
    q.set_defaults(func=cmd_identify_step)
    q = isub.add_parser("hinges", help="Mutlu et al. 2013: joint stiffness and damping from a tip trajectory")
    add_scene_args(q)
    q.add_argument("file")
    q.add_argument("--voltage", required=True, help="the waveform applied during the measurement")
    q.add_argument("--drive", help="drive name (default: the actuator's own)")
    q.add_argument("--param", action="append", metavar="KEY=VALUE", help="drive parameter (repeatable)")
    q.add_argument("--time-column", default="time")
    q.add_argument("--tip-column", default="tip_y", help="tip deflection column (m)")
    q.add_argument("--out", help=f"the identified actuator file: the actuator with EI = k L/N and the damping ratio "
                   f"of the fitted joints (default {IDENTIFIED})")
    q.set_defaults(func=cmd_identify_hinges)
    q = isub.add_parser("piezo", help="a piezo bender's coupling (f31), stiffness or tip mass, damping ratio, "
                        "capacitance and resistance from stroke, tip-FRF and impedance data")
    add_scene_args(q)
    q.add_argument("--stroke", help="CSV of stroke against voltage: columns voltage (V_sig) and stroke (tip "
                   "deflection), units in the headers")
    q.add_argument("--voltage-column", default="voltage")
    q.add_argument("--stroke-column", default="stroke")
    q.add_argument("--frf", help="CSV of the tip's frequency response per volt: frequency, tip_per_volt [, tip_phase "
                   "(deg)], as mjeap frf writes them")
    q.add_argument("--impedance", help="CSV of an impedance sweep: frequency and admittance [, admittance_phase], "
                   "impedance [, impedance_phase] or capacitance [, resistance]")
    q.add_argument("--impedance-state", choices=("free", "fixed"), default="free",
                   help="free: the actuator could move (the motional current is in the data); fixed: blocked, as "
                        "Jayaram et al. 2018 fixed theirs in epoxy (the data hold C and R only)")
    q.add_argument("--resonance", help="a published first resonance (Hz or with a unit), where no sweep is at hand")
    q.add_argument("--param", action="append", metavar="KEY=VALUE", help="drive parameter kept as given (repeatable)")
    q.add_argument("--out", help=f"the identified actuator file (default {IDENTIFIED})")
    q.set_defaults(func=cmd_identify_piezo)
