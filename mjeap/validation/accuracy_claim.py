"""The accuracy claim of :mod:`mjeap.simulation.accuracy`, checked against converged runs.

Cases are drawn by a seeded generator (actuators with their own drives, payloads,
orientations, waveforms as the sources drive them, targets log-uniform in 1e-4 .. 1e-2). Each case is run at its
target; its true error is measured against a converged run of the same question
(REFERENCE_SEGMENTS x the segments and 1/REFERENCE_STEP_DIVISOR of the step of the chosen
model, at least REFERENCE_MIN_SEGMENTS, under 'discrete'), a solution of the same equations
at a finer discretisation: its own error is about a quarter of the chosen run's, so the
true error is known to about 25 %. The claim: the true error is below the target in
at least 95 % of cases and never above 2 x; the estimate is within 3 x of the true error.
"""
from __future__ import annotations

import math
import time as _time
from dataclasses import dataclass, asdict
from typing import List, Optional

import numpy as np

from ..simulation.accuracy import relative_difference
from ..drives import make_drive
from ..simulation.rollout import rollout
from ..simulation.scene import Scene

__all__ = ["Case", "draw_cases", "check_case", "summarise"]

REFERENCE_SEGMENTS = 2.0
REFERENCE_STEP_DIVISOR = 4
REFERENCE_MIN_SEGMENTS = 24
#: a case runs at most this many periods of its first mode
MAX_FIRST_PERIODS = 30


@dataclass(frozen=True)
class Case:
    actuator: str
    orientation: str
    payload: Optional[str]
    voltage: str
    duration: float            # s
    target: float

    def describe(self) -> str:
        p = f" + {self.payload}" if self.payload else ""
        return f"{self.actuator} {self.orientation}{p}, {self.voltage}, {self.duration:.4g} s, target {self.target:.1e}"


def _waveform(rng, actuator: str, f1: float):
    """A waveform text and a duration: one period (a step: as long as a period would be) or
    MAX_FIRST_PERIODS of the first mode if shorter, as the sources drive them: the polymers
    by steps, squares and sines far below their first mode (f1 / 500 .. f1 / 50), the piezo
    bimorph by sines up to f1 / 20."""
    lo, hi = {"pedot-micro": (-3, 3), "ppy-trilayer": (-1, 1), "pvdf-60": (0, 900), "pzt-hamr-small": (0, 200)}[actuator]
    if lo < 0:
        amp, off = float(rng.uniform(0.3, 0.8)) * hi, ""
    else:
        amp, off = float(rng.uniform(0.3, 0.95)) * hi / 2, f",offset={hi / 2:.4g}V"
    if actuator.startswith("pzt"):
        kind, f = "sine", f1 / float(10 ** rng.uniform(np.log10(20), 2))
    else:
        kind, f = str(rng.choice(["step", "square", "sine"])), f1 / float(10 ** rng.uniform(np.log10(50), np.log10(500)))
    duration = min(1.0 / f, MAX_FIRST_PERIODS / f1)
    if kind == "step":
        return f"step:{amp:.3g}V{off}", duration
    return f"{kind}:{amp:.3g}V@{f:.4g}Hz{off}", duration


def draw_cases(seed: int, n: int) -> List[Case]:
    """``n`` cases from a seeded generator (numpy's default_rng(seed))."""
    rng = np.random.default_rng(seed)
    cases = []
    for _ in range(n):
        act = str(rng.choice(["pedot-micro", "ppy-trilayer", "pvdf-60", "pzt-hamr-small"]))
        orient = str(rng.choice(["horizontal", "up", "down"]))
        payload = None
        if act == "pedot-micro" and rng.uniform() < 0.5:
            payload = f"{rng.uniform(1.0, 8.0):.2f}mg@{rng.uniform(3.0, 6.0):.2f}mm"
        f1 = Scene(act, orientation=orient, payload=payload).choice.first_frequency
        voltage, duration = _waveform(rng, act, f1)
        target = float(10 ** rng.uniform(-4, -2))
        cases.append(Case(act, orient, payload, voltage, duration, target))
    return cases


def check_case(case: Case, error_model=None) -> dict:
    """Run ``case`` at its target (starting from ``error_model`` (a, b) instead of pilots, if
    given) and against a converged run: the true error, the estimate, the model and the
    walls."""
    scene = Scene(case.actuator, orientation=case.orientation, payload=case.payload)
    t0 = _time.perf_counter()
    r = rollout(scene, case.voltage, case.duration, accuracy=case.target, error_model=error_model)
    wall = _time.perf_counter() - t0
    a = r.meta["accuracy"]
    m = a["model"]
    n_ref = max(REFERENCE_MIN_SEGMENTS, int(math.ceil(REFERENCE_SEGMENTS * m["segments"])))
    h_ref = m["timestep"] / REFERENCE_STEP_DIVISOR
    ref_scene = scene.variant(n_ref, h_ref, "discrete")
    interval = float(r.time[1] - r.time[0])
    t1 = _time.perf_counter()
    ref = rollout(ref_scene, case.voltage, case.duration, drive=make_drive(None, ref_scene), sample_interval=interval)
    true = relative_difference(ref, r)
    return {"case": case.describe(), **asdict(case), "model": m, "estimated_error": a["estimated_error"],
            "error_model": (a["error_model"]["spatial_a"], a["error_model"]["temporal_b_per_s"]),
            "true_error": true, "below_target": true <= case.target, "within_2x": true <= 2 * case.target,
            "estimate_over_true": a["estimated_error"] / true if true > 0 else math.inf,
            "runs": len(a["runs"]), "wall_s": wall, "reference": f"{n_ref} segments at {h_ref:.4g} s",
            "reference_wall_s": _time.perf_counter() - t1}


def summarise(rows: List[dict]) -> dict:
    ratio = np.array([r["estimate_over_true"] for r in rows])
    return {"cases": len(rows), "below_target": float(np.mean([r["below_target"] for r in rows])),
            "worst_true_over_target": max(r["true_error"] / r["target"] for r in rows),
            "estimate_within_3x": float(np.mean((ratio >= 1 / 3) & (ratio <= 3))),
            "estimate_over_true_range": [float(ratio.min()), float(ratio.max())]}
