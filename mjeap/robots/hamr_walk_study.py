"""Why HAMR-VI (mjeap.robots.hamr_walk) rolls over at 65 Hz at the paper's full drive
(issue 25): one-parameter studies of the 65 Hz trot, each against the default model.

:func:`rolling_study` runs ``hamr_walk.walk(system, 65.0)`` and ``walk_metrics`` for the
default model and for one changed parameter at a time (build options of hamr_walk and the
lift amplitude of the trot) and reports for each: upright (|roll|, |pitch| < 30 deg), speed,
the largest roll and pitch, the body's height range.

Findings (4 segments, MuJoCo 4.0, 2 shared cores, about 1.5 s wall per run; after the
fix of hamr_leg.add_leg's stage centre of mass, commit 41b82c0):
- A bug, not a parameter, was the first cause: MuJoCo's compiler put each swing stage's
  explicit inertial at twice the hip offset, so the robot's swing joints carried twice the
  design inertia (3.93e-9 against 1.96e-9 kg m^2, swing resonance 71 Hz instead of 100)
  and swung an 8 mg eccentric 16 mm off their axes. Before the fix, full swing with a 10 V
  lift rolled over at 65 Hz (the probe that cleared the lift measured this); after it, the
  same drive trots upright (0.24 m/s, roll/pitch 7/9 deg).
- At the full drive (swing and lift 100 V) the trot still rolls over (roll 72 deg, pitch 61,
  the body thrown to 39 mm, its standing height 12 mm), and no single model parameter
  tried keeps it upright: the legs' moving mass (armature_fraction 0.5 and 0.9: the legs
  0.23 and 0.046 g, the resonances kept) rolls 180 and 60 deg; mu 0.2 and 1.0 roll over;
  no shank (foot_drop 0: no lateral foot motion) 62 deg; a 30 mm wide body 43 deg; a
  5x softer contact (timeconst_steps 10) rolls over.
- The lift amplitude decides it (full swing, default model): lift 20 V upright (0.256
  m/s, 11/8 deg), 30 V upright (0.186 m/s, 9/13 deg), 40 V 60 deg roll, 50 V 29/22 deg
  (marginal), 70 V rolls over. Cause: at 65 Hz the lift transmission (80 Hz, zeta 0.05)
  amplifies its quasi-static 3.2 mm by 1 / (1 - (65/80)^2) = 2.9: the foot moves +-9.4 mm
  at 100 V, its peak vertical speed 2 pi 65 Hz x 9.4 mm = 3.8 m/s, against a standing
  height of 12 mm; the stance pair pushes the 1.43 g body off the ground (it flies to 3x its
  standing height) and lands it on one diagonal. A lift of 20-30 V (+-1.9-2.8 mm at the
  foot) keeps it on its feet. The trot is chaotic: lift 30 V at mu 0.50 pitches to 35 deg,
  at mu 0.52 it runs at 0.49 m/s.
- The true lift amplitude of HAMR-VI's foot at 65 Hz is not published here (the paper's
  phase loop, seed 003, and a loaded leg's damping would both change it); the defaults are
  kept, and the 65 Hz speed within a factor of 2 of the paper's 0.5 m/s is reached only
  with the lift at 20-30 V (0.19-0.49 m/s).

:func:`incline_study`: the steepest incline climbed (hamr_walk.max_incline, 4 deg steps)
against the feet's friction. Measured (full drive at 10 Hz, where it trots upright on
level ground): mu 0.51: 8 deg (MuJoCo 4.0; 4 on 3.17: the trot is chaotic); 0.8: 12 deg;
1.2: 16 deg (3.17; failing at the next step each time, still upright: it slides back). Far below the static friction angle
(atan mu = 27, 39, 50 deg): the trot's feet slide through most of their stance (slip
fraction 0.5-0.9 on level ground), so the climb is set by sliding friction during the
stride, and it grows with mu. At 65 Hz with the lift at 20 V it climbs 8 deg at mu 0.51 and
rolls over at mu 1.2. The paper's ~22 deg is not reached with these friction values; the
surface of its incline tests is not in the sources here.
"""
from __future__ import annotations

from typing import Optional, Sequence

from ..errors import ParameterError
from . import hamr_walk as hw

#: (label, build options, walk options): one parameter changed per row
VARIANTS = (
    ("default", {}, {}),
    ("legs' moving mass x 0.5 (armature_fraction 0.5)", {"armature_fraction": 0.5}, {}),
    ("legs' moving mass x 0.1 (armature_fraction 0.9)", {"armature_fraction": 0.9}, {}),
    ("mu 0.2", {"mu": 0.2}, {}),
    ("mu 1.0", {"mu": 1.0}, {}),
    ("no shank (foot_drop 0)", {"foot_drop": 0.0}, {}),
    ("body 30 mm wide", {"body_width": 0.03}, {}),
    ("contact 5x softer (timeconst_steps 10)", {"timeconst_steps": 10.0}, {}),
    ("lift 20 V", {}, {"lift_amplitude": 20.0}),
    ("lift 30 V", {}, {"lift_amplitude": 30.0}),
    ("lift 50 V", {}, {"lift_amplitude": 50.0}),
)


def study_run(frequency: float = hw.PAPER_FREQUENCY, build: Optional[dict] = None, walk: Optional[dict] = None,
              d: Optional[dict] = None, **walk_kw) -> dict:
    """One trot: hamr_walk.build(**build) walked at ``frequency`` (walk options ``walk``);
    its walk_metrics."""
    return hw.walk_metrics(hw.walk(hw.build(d=d, **(build or {})), frequency, **(walk or {}), **walk_kw))


def rolling_study(variants: Sequence = VARIANTS, frequency: float = hw.PAPER_FREQUENCY) -> list:
    """Each of ``variants`` ((label, build options, walk options)) at ``frequency``: label,
    upright, speed (m/s), max |roll| and |pitch| (deg), the body's height range (m)."""
    if not len(variants):
        raise ParameterError("variants", variants, "at least one (label, build options, walk options)")
    d = hw.design()
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
    d = hw.design()
    rows = []
    for f in frequencies:
        m = study_run(float(f), build, walk, d=d)
        rows.append({k: m[k] for k in ("frequency_hz", "upright", "speed_m_s", "kinematic_speed_m_s",
                                       "max_abs_roll_deg", "max_abs_pitch_deg")})
    return rows


def incline_study(mus: Sequence[float] = (hw.MU, 0.8, 1.2), frequency: float = hw.RECORD_FREQUENCY,
                  **kw) -> list:
    """The steepest incline climbed (hamr_walk.max_incline, options ``kw``) for each foot
    friction coefficient in ``mus``, at ``frequency``."""
    if not len(mus):
        raise ParameterError("mus", mus, "at least one friction coefficient")
    return [{"mu": float(mu), **hw.max_incline(frequency, mu=float(mu), **kw)} for mu in mus]
