"""The drive callbacks run once per MuJoCo step: they must not allocate arrays per step.

Measured with tracemalloc (which sees NumPy's data buffers) as the peak of traced memory
above its level before the steps. On a 100-hinge beam one per-hinge temporary costs
800 B of data plus the array object, so a budget of 600 B separates 'no per-step array'
from 'one or more' while leaving room for the interpreter's small float objects. The
voltage changes every step (a sine sample), the worst case for drives that cache on it.
"""
import tracemalloc

import numpy as np
import pytest

from mjeap import Scene
from mjeap.drives import make_drive

SEGMENTS = 100
BUDGET_BYTES = 600


def _peak_growth(fn, n=300):
    for k in range(20):   # warm up caches and lazily built state
        fn(k)
    tracemalloc.start()
    try:
        tracemalloc.reset_peak()
        before = tracemalloc.get_traced_memory()[0]
        for k in range(n):
            fn(k)
        return tracemalloc.get_traced_memory()[1] - before
    finally:
        tracemalloc.stop()


@pytest.mark.parametrize("actuator,representation", [
    ("pedot-micro", "hinge"), ("pedot-micro", "cable"), ("ppy-trilayer", "hinge"),
    ("pvdf-60", "hinge"), ("pzt-hamr-small", "hinge")])
@pytest.mark.slow
def test_drive_step_allocates_no_array(actuator, representation):
    scene = Scene(actuator, representation=representation, segments=SEGMENTS)
    drive = make_drive(None, scene)
    drive.reset(0.0)
    lo, hi = drive.voltage_range()
    v = 0.5 * (lo + hi) + 0.3 * (hi - lo) * np.sin(0.1 * np.arange(400))
    dt = scene.timestep
    grown = _peak_growth(lambda k: drive.step(float(v[k]), dt))
    assert grown < BUDGET_BYTES, f"{drive.name} on {actuator} ({representation}): {grown} B per 300 steps"


def test_budget_detects_one_temporary_per_step():
    """The measurement can fail: a step making one per-hinge temporary exceeds the budget."""
    x = np.zeros(SEGMENTS)
    grown = _peak_growth(lambda k: np.multiply(x, 0.5))   # a fresh array each call
    assert grown >= BUDGET_BYTES
