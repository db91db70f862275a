"""The RoboBee wing of scripts/robobee_wing.py, shortened (the 30-270 Hz sweeps are the
script's): the stroke rises to the transmission resonance and falls after, and the
self-sensing estimate follows the simulated stroke within the paper's 10 %."""
import importlib.util
import sys
from pathlib import Path

_spec = importlib.util.spec_from_file_location("robobee_wing", Path(__file__).parent.parent / "scripts" / "robobee_wing.py")
robobee = importlib.util.module_from_spec(_spec)
sys.modules["robobee_wing"] = robobee
_spec.loader.exec_module(robobee)


def test_stroke_peaks_between_30_and_270_hz_and_is_self_sensed():
    system = robobee.build()
    est = robobee.estimator(100.0)
    rows = {f: robobee.flap(system, 100.0, f, est) for f in (30.0, 90.0, 270.0)}
    assert rows[90.0]["stroke_deg"] > rows[30.0]["stroke_deg"] > rows[270.0]["stroke_deg"]
    for r in rows.values():
        assert r["steady"] < 0.01
        assert abs(r["estimated_deg"] / r["stroke_deg"] - 1) < 0.10
