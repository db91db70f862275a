"""Regression on tip curvature: one representative rollout per catalog actuator against the
golden trajectory stored in tests/golden/ (regenerate after an intentional physics change with
``python scripts/regenerate_golden.py`` and review ``git diff tests/golden``).

Tolerance: RTOL = 1e-5 of the trajectory's range. MuJoCo and the drives are deterministic:
reruns on this machine agree to the last bit, and reordered floating point (other BLAS,
other CPUs) moves these smooth, non-chaotic trajectories by ~1e-12 relative. A physics change
of 0.1 % in one parameter moves them by ~1e-3 of the range (checked below), 100x the tolerance.
"""
from pathlib import Path

import numpy as np
import pytest

from mjeap.drives.electrostrictive import STRAIN_COEFFICIENT

from mjeap.simulation.rollout import rollout
from mjeap.simulation.scene import Scene
from mjeap.validation import golden

FOLDER = Path(__file__).resolve().parents[1] / "golden"


@pytest.mark.parametrize("actuator_id", list(golden.SCENARIOS))
def test_tip_curvature_matches_golden(actuator_id):
    t_ref, k_ref = golden.read(FOLDER, actuator_id)
    t, k = golden.simulate(actuator_id)
    assert len(t) == len(t_ref) and np.allclose(t, t_ref, rtol=0, atol=1e-12)
    dev = np.max(np.abs(k - k_ref)) / np.ptp(k_ref)
    assert dev <= golden.RTOL, f"{actuator_id}: largest deviation {dev:.3g} of the range (tolerance {golden.RTOL:g})"


def test_golden_tolerance_catches_a_small_physics_change():
    """A 0.1 % change of the terpolymer's strain coefficient (moment +0.1 %) must fail the check."""
    kw, wave, duration, k0, params = golden.SCENARIOS["pvdf-60"]
    t_ref, k_ref = golden.read(FOLDER, "pvdf-60")
    r = rollout(Scene("pvdf-60", **kw), wave, duration, drive_params={**params, "strain_coefficient": 1.001 * STRAIN_COEFFICIENT},
                progress=False, sample_interval=duration / golden.SAMPLES)
    dev = np.max(np.abs(r.tip_curvature - k_ref)) / np.ptp(k_ref)
    assert dev > 10 * golden.RTOL
