"""Why HAMR-VI (:mod:`mjeap.robots.hamr_walk`) rolls over at 65 Hz at the paper's full drive
(issue 25): one-parameter studies of the 65 Hz trot, each against the default model; why a
stance foot's contact flickers (:func:`sliding_contact`) and the trot's speed per frequency
beside the robot's (:func:`gait_study`, :func:`gait_main`; issue 46, whose findings are in
docs/robots/hamr-walk.md: the findings below predate its solver tolerance and actuator travel).

:func:`rolling_study` runs ``hamr_walk.walk(system, 65.0)`` and ``walk_metrics`` for the
default model and for one changed parameter at a time (build options of hamr_walk and the
lift amplitude of the trot) and reports for each: upright (|roll|, |pitch| < 30 deg), speed,
the largest roll and pitch, the body's height range.

Findings (4 segments, MuJoCo 4.0, 2 shared cores, 5-10 s wall per run), with the
walker's contact sized from its physics (hamr_walk.contact_parameters: 10-step time
constant, 'discrete' integrator, the chassis and legs colliding); "before": the 2-step
contact under 'implicitfast', after the fix of hamr_leg.add_leg's stage centre of mass
(commit 41b82c0):
- A bug, not a parameter, was the first cause: MuJoCo's compiler put each swing stage's
  explicit inertial at twice the hip offset, so the robot's swing joints carried twice the
  design inertia (3.93e-9 against 1.96e-9 kg m^2, swing resonance 71 Hz instead of 100)
  and swung an 8 mg eccentric 16 mm off their axes. Before that fix, full swing with a 10 V
  lift rolled over at 65 Hz; after it, the same drive trots upright.
- At the full drive (swing and lift 100 V) the trot rolls over (roll 180 deg, pitch 43, the
  body thrown to 25 mm, its standing height 11.6 mm), and no single model parameter tried
  keeps it upright: the legs' moving mass (armature_fraction 0.5 and 0.9: the legs 0.23 and
  0.046 g, the resonances kept) rolls 180 and 180 deg; mu 0.2 and 1.0 roll over; no shank
  (foot_drop 0: no lateral foot motion) 126 deg; a 30 mm wide body 180; a 5x softer contact
  (timeconst_steps 50) rolls over.
- The lift amplitude decides it (full swing, default model): lift 20 V upright (0.196 m/s,
  10/10 deg), 30 V upright (0.183 m/s, 8/10 deg), 50 V upright but tilting 20/16 deg (0.068
  m/s; before: 29/22, marginal), 100 V rolls over (70 V rolled over before; not re-run).
  Cause: at 65 Hz the lift transmission (80 Hz, zeta 0.05) amplifies its quasi-static 3.2
  mm by 1 / (1 - (65/80)^2) = 2.9: the foot moves +-9.4 mm at 100 V, its peak vertical
  speed 2 pi 65 Hz x 9.4 mm = 3.8 m/s, against a standing height of 12 mm; the stance pair
  pushes the 1.43 g body off the ground and lands it on one diagonal. A lift of 20-30 V
  (+-1.9-2.8 mm at the foot) keeps it on its feet, though even then it hops (a foot down
  14 % of the time at 20 V). The trot is chaotic: before, lift 30 V at mu 0.50 pitched to
  35 deg, at mu 0.52 it ran at 0.49 m/s.
- The true lift amplitude of HAMR-VI's foot at 65 Hz is not published here (the paper's
  phase loop, Jayaram et al. 2018, and a loaded leg's damping would both change it); the defaults are
  kept, and the 65 Hz speed comes within a factor of 2.6 of the paper's 0.5 m/s only with
  the lift at 20-30 V (0.18-0.20 m/s; before 0.19-0.49).

:func:`contact_study`: does the contact or the gait make the feet bounce? At 80 Hz, 20 V
(the lifts at their resonance) each foot lands 0.13, 0.23 and 0.25 times per cycle with the
contact's time constant at 2, 10 and 50 steps (0.17, 0.27, 0.20 under implicitfast) and the
body flies 3-9 mm above its standing height between landings: the gait. The time constant
sets only how long a landing lasts (duty factor 0.0025, 0.0047, 0.016) and how deep it goes
(2, 29, 191 um). At 40 Hz, full swing, lift 20 V: 1.3, 2.2 and 2.2 landings per cycle, duty
0.105, 0.21, 0.29 (time with a foot down 0.41, 0.71, 0.83): the feet slide and MuJoCo's
soft friction lifts a sliding contact off (hamr_walk's module text), so the sampled stance
depends on how long each touch lasts.

:func:`incline_study`: the steepest incline climbed (hamr_walk.max_incline, 4 deg steps)
against the feet's friction. Measured (full drive at 10 Hz, where it trots upright on
level ground): mu 0.51: 8 deg; 0.8: 8 deg (at 12 deg -0.004 m/s); 1.2: 20 deg (at 24 it
slides back, tipping past 30 deg; before: 4 / 12 / 16 deg on 3.17, 8 on 4.0 at mu 0.51). Far below the
static friction angle (atan mu = 27, 39, 50 deg): the trot's feet slide through most of
their stance (slip fraction 0.7-0.9 on level ground), so the climb is set by sliding
friction during the stride, and it grows with mu. At 65 Hz with the lift at 20 V it climbs
8 deg at mu 0.51. The paper's ~22 deg is not reached at mu 0.51; the surface of its incline
tests is not in the sources here.
"""
from __future__ import annotations

from typing import Optional, Sequence

import mujoco
import numpy as np

from ...errors import ParameterError
from . import experiments as hw
from .metrics import UPRIGHT_DEG
from .model import PAPER_FREQUENCY
from . import model

#: (label, build options, walk options): one parameter changed per row
VARIANTS = (
    ("default", {}, {}),
    ("legs' moving mass x 0.5 (armature_fraction 0.5)", {"armature_fraction": 0.5}, {}),
    ("legs' moving mass x 0.1 (armature_fraction 0.9)", {"armature_fraction": 0.9}, {}),
    ("mu 0.2", {"mu": 0.2}, {}),
    ("mu 1.0", {"mu": 1.0}, {}),
    ("no shank (foot_drop 0)", {"foot_drop": 0.0}, {}),
    ("body 30 mm wide", {"body_width": 0.03}, {}),
    ("contact 2.2x softer (timeconst_steps 50)", {"timeconst_steps": 50.0}, {}),
    ("lift 20 V", {}, {"lift_amplitude": 20.0}),
    ("lift 30 V", {}, {"lift_amplitude": 30.0}),
    ("lift 50 V", {}, {"lift_amplitude": 50.0}),
)


def study_run(frequency: float = PAPER_FREQUENCY, build: Optional[dict] = None, walk: Optional[dict] = None,
              d: Optional[dict] = None, **walk_kw) -> dict:
    """One trot: hamr_walk.build(**build) walked at ``frequency`` (walk options ``walk``);
    its walk_metrics."""
    return hw.walk_metrics(hw.walk(model.build(d=d, **(build or {})), frequency, **(walk or {}), **walk_kw))


def rolling_study(variants: Sequence = VARIANTS, frequency: float = PAPER_FREQUENCY) -> list:
    """Each of ``variants`` ((label, build options, walk options)) at ``frequency``: label,
    upright, speed (m/s), max |roll| and |pitch| (deg), the body's height range (m)."""
    if not len(variants):
        raise ParameterError("variants", variants, "at least one (label, build options, walk options)")
    d = model.design()
    out = []
    for label, b, w in variants:
        m = study_run(frequency, b, w, d=d)
        out.append({"label": label, "build": dict(b), "walk": dict(w), "upright": m["upright"],
                    "speed_m_s": m["speed_m_s"], "max_abs_roll_deg": m["max_abs_roll_deg"],
                    "max_abs_pitch_deg": m["max_abs_pitch_deg"], "body_height_range_m": m["body_height_range_m"]})
    return out


def frequency_sweep(frequencies: Sequence[float] = hw.FREQUENCIES, build: Optional[dict] = None,
                    walk: Optional[dict] = None) -> list:
    """The speed-frequency curve of one variant: per frequency upright, speed, no-slip
    estimate, roll and pitch."""
    d = model.design()
    rows = []
    for f in frequencies:
        m = study_run(float(f), build, walk, d=d)
        rows.append({k: m[k] for k in ("frequency_hz", "upright", "speed_m_s", "kinematic_speed_m_s",
                                       "max_abs_roll_deg", "max_abs_pitch_deg")})
    return rows


def contact_study(frequency: float = hw.LOOP_FREQUENCY, amplitude: float = hw.LOOP_AMPLITUDE,
                  steps: Sequence[float] = (2.0, model.CONTACT_STEPS, 50.0), lift_amplitude: Optional[float] = None,
                  integrators: Sequence[str] = (model.INTEGRATOR,)) -> list:
    """Does the contact or the gait make the feet bounce? The same trot (``frequency``,
    ``amplitude``, ``lift_amplitude``) with the contact's time constant at each of ``steps``
    timesteps (and under each of ``integrators``): per run the duty factor, the time with a
    foot down, the landings per foot and cycle, the deepest penetration, speed, roll and
    pitch. A contact that made the feet bounce would change the landings with its time
    constant; a gait that throws the body keeps them and only the contact time per landing
    (a few time constants) moves."""
    d = model.design()
    rows = []
    for integ in integrators:
        for n in steps:
            m = study_run(frequency, {"timeconst_steps": float(n), "integrator": integ},
                          {"amplitude": amplitude, "lift_amplitude": lift_amplitude}, d=d)
            rows.append({"integrator": integ, "timeconst_steps": float(n), **{k: m[k] for k in (
                "duty_factor", "time_with_a_foot_down", "touchdowns_per_cycle", "max_penetration_m", "speed_m_s",
                "max_abs_roll_deg", "max_abs_pitch_deg", "upright", "body_height_range_m")}})
    return rows


def incline_study(mus: Sequence[float] = (model.MU, 0.8, 1.2), frequency: float = hw.RECORD_FREQUENCY,
                  **kw) -> list:
    """The steepest incline climbed (hamr_walk.max_incline, options ``kw``) for each foot
    friction coefficient in ``mus``, at ``frequency``."""
    if not len(mus):
        raise ParameterError("mus", mus, "at least one friction coefficient")
    return [{"mu": float(mu), **hw.max_incline(frequency, mu=float(mu), **kw)} for mu in mus]


# ---- why a stance foot flickers, and the speed per frequency (issue: HAMR-VI runs like the robot) ----
#: m/s: the sliding speeds of the walker's stance feet (10 Hz full drive: 0.05-0.15 m/s)
SLIDE_SPEEDS = (0.0, 0.03, 0.1, 0.3)


def sliding_contact(speeds: Sequence[float] = SLIDE_SPEEDS, duration: float = 0.02, load: float = 0.25,
                    contact: Optional[dict] = None) -> list:
    """A stance foot on the walker's ground contact, alone: a FOOT_RADIUS sphere carrying
    ``load`` of the robot's weight (its mass), driven to slide at each of ``speeds`` (m/s,
    a stiff velocity servo on a slide joint; the height free), stepped as the walker is
    (its timestep, 'discrete', contact_parameters; ``contact``: options of MuJoCo's own to
    change, e.g. {'cone': 'pyramidal'}, {'noslip_iterations': 20}, {'impratio': 1}). After
    a quarter of ``duration`` settling, per speed: the share of the steps with the sphere
    loaded (a positive normal force), its mean height above the ground (m) and the mean
    normal force against the load (Newton: 1 whatever the steps). MuJoCo resolves a
    contact's normal and friction forces in one cost: a sliding contact is pushed apart
    (tested), so its load comes as impulses a few steps apart."""
    from ...simulation.system import ContactParameters
    ref = model.build()
    h, u = ref.timestep, ref.units
    c = model.contact_parameters(h)
    opts = dict(contact or {})
    cone = opts.pop("cone", c.cone)
    mass = load * model.TOTAL_MASS / u.mass
    xml = f"""<mujoco><option gravity="0 0 -9.80665e-3" integrator="discrete"/>
    <worldbody><geom name="ground" type="plane" size="1000 1000 1"/>
    <body pos="0 0 {model.FOOT_RADIUS / u.length}"><joint name="x" type="slide" axis="1 0 0" damping="0"/>
    <joint name="z" type="slide" axis="0 0 1"/>
    <geom name="foot" type="sphere" size="{model.FOOT_RADIUS / u.length}" mass="{mass}"/></body></worldbody>
    <actuator><velocity joint="x" kv="{1e3 * mass / (h / u.time)}"/></actuator></mujoco>"""
    spec = mujoco.MjSpec.from_string(xml)
    ContactParameters(**{**c.__dict__, "cone": cone}).apply(spec, h / u.time, model.FOOT_RADIUS / u.length,
                                                           u.length)
    spec.option.timestep = h / u.time
    spec.option.tolerance = model.SOLVER_TOLERANCE
    m = spec.compile()
    for k, v in opts.items():
        setattr(m.opt, k, v)
    rows = []
    f6 = np.zeros(6)
    for v in speeds:
        d = mujoco.MjData(m)
        d.ctrl[0] = v * u.time / u.length
        n = int(round(duration / h))
        fn, z = np.zeros(n), np.zeros(n)
        for k in range(n):
            mujoco.mj_step(m, d)
            total = 0.0
            for i in range(d.ncon):
                mujoco.mj_contactForce(m, d, i, f6)
                total += f6[0]
            fn[k], z[k] = total, d.qpos[1]
        keep = slice(n // 4, n)
        w = mass * 9.80665e-3
        rows.append({"speed_m_s": float(v), "loaded_step_share": float((fn[keep] > 0).mean()),
                     "mean_height_m": float(z[keep].mean() * u.length),
                     "mean_normal_force_over_load": float(fn[keep].mean() / w)})
    return rows


#: Hz, the gait study's trot frequencies
GAIT_FREQUENCIES = (10.0, 20.0, 30.0, 40.0, 50.0, 65.0)
#: the gait study's drives: (label, swing amplitude V, robot): the robot's trot drive
#: (hamr_walk.trot_drive: the swing within its travel, the no-flight lift) at the full and at
#: half the amplitude, and the full drive (100 V on every actuator)
GAIT_DRIVES = (("robot drive, full swing", hw.AMPLITUDE, True), ("robot drive, half swing", 0.5 * hw.AMPLITUDE, True),
               ("full drive, 100 V on every actuator", hw.AMPLITUDE, False))
#: mm per cycle and m/s the robot is published at (see docs/robots/hamr-walk.md, Gait study)
PUBLISHED = (
    {"source": "Jayaram et al. 2018 (section 6.2)", "frequency_hz": 65.0, "speed_m_s": 0.5,
     "what": "maximum forward velocity, 'approximately 0.5 m/s at a pre-resonant drive frequency of 65 Hz'"},
    {"source": "Doshi et al. 2019, arXiv 1901.09065 (abstract)", "frequency_hz": None, "mm_per_cycle": 10.87,
     "what": "fastest planned gait, 'a maximum of 10.87 mm/cycle, 15 % faster than previously measured'"},
    {"source": "Doshi et al. 2019, arXiv 1901.09065 (abstract)", "frequency_hz": None, "mm_per_cycle": 10.87 / 1.15,
     "what": "the previously measured best, 10.87 / 1.15 = 9.45 mm/cycle"},
    {"source": "Goldberg, Doshi and Wood 2017, ICRA (abstract)", "frequency_hz": None, "speed_m_s": 0.294,
     "what": "trajectory control with gaits at 2-45 Hz, 'speeds up to 6.5 BL/s (29.4 cm/s)'"},
)


def gait_study(frequencies: Sequence[float] = GAIT_FREQUENCIES, drives: Sequence[tuple] = GAIT_DRIVES,
               settle: float = 0.3, measure: float = 0.2, on_row=None) -> list:
    """The trot's speed per frequency and drive: per (frequency, drive of ``drives``: label,
    amplitude V, robot) a walk of the default model over ``measure`` s after ``settle`` s (the
    issue's bands: after 0.3 s), the robot's drive (hamr_walk.trot_drive at that amplitude)
    or the amplitude on every actuator, with speed (m/s and mm per cycle), upright, the
    largest roll and pitch over the whole run, the contact read-outs and the body's highest
    point (its hops). ``on_row(row)`` is called after each run (to write as it goes)."""
    if not len(frequencies) or not len(drives):
        raise ParameterError("frequencies, drives", (frequencies, drives), "at least one of each")
    d = model.design()
    rows = []
    for label, a, robot in drives:
        for f in frequencies:
            system = model.build(d=d)
            drive = hw.trot_drive(system, float(f), float(a)) if robot else {"amplitude": float(a),
                                                                             "lift_amplitude": float(a)}
            run = hw.walk(system, float(f), settle=settle, measure=measure, **drive)
            m = hw.walk_metrics(run)
            rp = np.degrees(np.abs(np.array([model.roll_pitch(R, run["ground"]) for R in run["R"]])))
            row = {"frequency_hz": float(f), "drive": label, "amplitude_v": drive["amplitude"],
                   "lift_amplitude_v": drive["lift_amplitude"], "speed_m_s": m["speed_m_s"],
                   "mm_per_cycle": m["speed_m_s"] / f * 1e3,
                   "upright_whole_run": bool(rp.max() < UPRIGHT_DEG),
                   "max_abs_roll_deg_whole_run": float(rp[:, 0].max()),
                   "max_abs_pitch_deg_whole_run": float(rp[:, 1].max()),
                   "body_height_min_m": m["body_height_range_m"][0], "body_height_max_m": m["body_height_range_m"][1],
                   "wall_s": m["wall_time_s"],
                   **{k: m[k] for k in ("kinematic_speed_m_s", "duty_factor", "touchdowns_per_cycle",
                                        "time_with_a_foot_down", "contact_duty_factor_sampled",
                                        "contact_when_near_sampled", "contact_touchdowns_per_cycle_sampled",
                                        "contact_duty_factor", "loaded_step_fraction", "contact_touchdowns_per_cycle",
                                        "step_touchdowns_per_cycle", "contact_when_near", "force_balance_error",
                                        "slip_fraction")}}
            rows.append(row)
            if on_row is not None:
                on_row(row)
    return rows


def gait_figure(rows: Sequence[dict], path) -> None:
    """The gait study's figure (PNG at ``path``): mm per cycle and m/s against frequency per
    drive (filled: upright over the whole run; open: tilted past UPRIGHT_DEG),
    beside the published HAMR-VI numbers (PUBLISHED). Needs matplotlib (the report extra)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from ...io.outputs import replacing
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.6))
    drives = list(dict.fromkeys(r["drive"] for r in rows))
    colours = dict(zip(drives, ("tab:blue", "tab:orange", "tab:red", "tab:purple", "tab:brown")))
    for ax, key, unit in ((axes[0], "mm_per_cycle", "mm per cycle"), (axes[1], "speed_m_s", "m/s")):
        for dr in drives:
            rs = sorted((r for r in rows if r["drive"] == dr), key=lambda r: r["frequency_hz"])
            f = np.array([r["frequency_hz"] for r in rs])
            y = np.array([r[key] for r in rs])
            up = np.array([r["upright_whole_run"] for r in rs])
            ax.plot(f, y, "-", color=colours[dr], lw=1, alpha=0.6)
            if up.any():
                ax.plot(f[up], y[up], "o", color=colours[dr], label=f"mjeap, {dr}: upright")
            if (~up).any():
                ax.plot(f[~up], y[~up], "o", mfc="none", color=colours[dr],
                        label=f"mjeap, {dr}: tilted past {UPRIGHT_DEG:g} deg")
        ax.axhline(0.0, color="0.6", lw=0.8)
        ax.set_xlabel("stride frequency (Hz)")
        ax.set_ylabel(f"forward speed ({unit})")
    for p in PUBLISHED:
        if p.get("frequency_hz") and "speed_m_s" in p:
            axes[1].plot(p["frequency_hz"], p["speed_m_s"], "*", ms=14, color="k", label=f"{p['source']}: 0.5 m/s")
            axes[0].plot(p["frequency_hz"], p["speed_m_s"] / p["frequency_hz"] * 1e3, "*", ms=14, color="k",
                         label=f"{p['source']}: {p['speed_m_s'] / p['frequency_hz'] * 1e3:.2f} mm/cycle")
        elif "speed_m_s" in p:
            axes[1].axhline(p["speed_m_s"], color="k", ls="-.", lw=1,
                            label=f"{p['source']}: {p['speed_m_s']:g} m/s (gaits at 2-45 Hz)")
        elif "mm_per_cycle" in p:
            ax = axes[0]
            ax.axhline(p["mm_per_cycle"], color="k", ls="--" if p["mm_per_cycle"] > 10 else ":", lw=1,
                       label=f"{p['source']}: {p['mm_per_cycle']:.2f} mm/cycle (frequency not stated)")
    axes[0].set_title("per cycle")
    axes[1].set_title("per second")
    handles, labels = axes[0].get_legend_handles_labels()
    for h, lab in zip(*axes[1].get_legend_handles_labels()):
        if lab not in labels and "mm/cycle" not in lab and ": 0.5 m/s" not in lab:
            handles.append(h)
            labels.append(lab)
    fig.legend(handles, labels, fontsize=7, loc="lower center", ncol=2, bbox_to_anchor=(0.5, -0.02))
    fig.suptitle("HAMR-VI open-loop trot: mjeap (hamr_walk, 0.3 s settling, 0.2 s measured) and the robot")
    fig.tight_layout(rect=(0, 0.2, 1, 0.95))
    with replacing(path, "--figure") as tmp:
        fig.savefig(tmp, dpi=110, format="png")
    plt.close(fig)


def gait_main(argv=None):
    """The gait study's command line (scripts/hamr_walk_gait.py): JSON of :func:`gait_study`
    beside PUBLISHED, and its figure (:func:`gait_figure`)."""
    import argparse
    import json
    import sys
    from ...io.commandline import arg_number, arg_output, parse_args
    from ...io.outputs import replacing, run_guard
    ap = argparse.ArgumentParser(description="HAMR-VI's trot speed per frequency and drive beside the robot's")
    ap.add_argument("--out", default="out/hamr_walk_gait.json", type=arg_output(), help="results (.json)")
    ap.add_argument("--figure", default="out/hamr_walk_gait.png", type=arg_output(), help="figure (.png)")
    ap.add_argument("--frequencies", nargs="+", type=arg_number(*model.FREQUENCY_RANGE, "Hz"),
                    default=list(GAIT_FREQUENCIES), help="trot frequencies (Hz)")
    ap.add_argument("--settle", type=arg_number(0.0, 10.0, "s"), default=0.3, help="settling before the window (s)")
    ap.add_argument("--measure", type=arg_number(0.0, 10.0, "s", True), default=0.2, help="the window (s)")
    ap.add_argument("--from-json", type=str, default=None,
                    help="draw the figure from this JSON of an earlier run instead of simulating")
    a = parse_args(ap, argv)
    with run_guard(**{"--out": None if a.from_json else a.out, "--figure": a.figure}):
        if a.from_json:
            with open(a.from_json) as fh:
                rows = json.load(fh)["runs"]
        else:
            rows = []

            def write(row):
                rows.append(row)
                print(f"{row['frequency_hz']:g} Hz, {row['drive']} (swing {row['amplitude_v']:.3g} V, lift "
                      f"{row['lift_amplitude_v']:.3g} V): {row['speed_m_s']:.3f} m/s "
                      f"({row['mm_per_cycle']:.2f} mm/cycle), upright {row['upright_whole_run']}", file=sys.stderr)
                with replacing(a.out, "--out") as tmp:
                    tmp.write_text(json.dumps({"runs": rows, "published": list(PUBLISHED)}, indent=1, default=float))
            gait_study(a.frequencies, GAIT_DRIVES, a.settle, a.measure, on_row=write)
        try:
            gait_figure(rows, a.figure)
        except ImportError:
            print("figure skipped: pip install -e '.[report]' for matplotlib", file=sys.stderr)
    return 0
