"""Why HAMR-VI (:mod:`mjeap.robots.hamr_walk`) rolls over at 65 Hz at the paper's full drive
(issue 25): one-parameter studies of the 65 Hz trot, each against the default model.

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

from ...errors import ParameterError
from . import experiments as hw
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
    ("contact 5x softer (timeconst_steps 50)", {"timeconst_steps": 50.0}, {}),
    ("lift 20 V", {}, {"lift_amplitude": 20.0}),
    ("lift 30 V", {}, {"lift_amplitude": 30.0}),
    ("lift 50 V", {}, {"lift_amplitude": 50.0}),
)


def study_run(frequency: float = hw.PAPER_FREQUENCY, build: Optional[dict] = None, walk: Optional[dict] = None,
              d: Optional[dict] = None, **walk_kw) -> dict:
    """One trot: hamr_walk.build(**build) walked at ``frequency`` (walk options ``walk``);
    its walk_metrics."""
    return hw.walk_metrics(hw.walk(model.build(d=d, **(build or {})), frequency, **(walk or {}), **walk_kw))


def rolling_study(variants: Sequence = VARIANTS, frequency: float = hw.PAPER_FREQUENCY) -> list:
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
