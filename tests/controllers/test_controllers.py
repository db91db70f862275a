"""mjeap.controllers: closed-loop rollouts through the public API (issue 5, first part)."""
import numpy as np
import pytest

from mjeap.controllers.curvature_tracking import CurvatureTracker
from mjeap import DivergenceError, Payload, Scene, rollout

AMP, F_REF, T = 50.0, 0.05, 40.0


def ref(t):
    return AMP * np.sin(2 * np.pi * F_REF * np.asarray(t))


def track(mass, **kw):
    scene = Scene("pedot-micro", orientation="up", payload=Payload(mass, 6.27e-3) if mass else None)
    r = rollout(scene, None, T, controller=CurvatureTracker(ref, T, **kw), progress=False)
    late = r.time >= T / 2   # the second period, after the start-up transient
    return float(np.sqrt(np.mean((r.tip_curvature[late] - ref(r.time[late])) ** 2))) / AMP, r


@pytest.mark.slow
def test_tracks_050_hz_sine_with_12_6_mg_inverted_within_5_percent():
    """Dadras et al. 2021's heaviest payload standing up, 50 1/m at 0.05 Hz: RMS error of the second
    period below 5 % of the amplitude with feedforward + PI, within the +-1.5 V safe range;
    feedback improves on the feedforward alone (which misses the payload's extra gain)."""
    e_both, r = track(12.6e-6)
    e_ff, _ = track(12.6e-6, feedback=False)
    assert e_both < 0.05
    assert e_ff > 3 * e_both
    assert np.abs(r.voltage).max() <= 1.5 and r.meta["saturated_updates"] == 0
    assert "controller_error (1/m)" in r.signals


@pytest.mark.parametrize("mass", [0.0, 3.15e-6, 40e-6, 70e-6])
@pytest.mark.slow
def test_same_controller_stable_below_the_static_stability_limit(mass):
    """Every payload below the relaxed column load (76 mg, mjeap validate's
    dadras2021-stability): finite, and the tracking error stays below 10 % of the amplitude."""
    e, r = track(mass)
    assert np.all(np.isfinite(r.tip_curvature)) and e < 0.10


@pytest.mark.slow
def test_unreachable_reference_saturates_with_a_warning(tmp_path):
    """A reference of 400 1/m is beyond the catalog's safe range (+-3 V): the command is clipped
    to it and the recording carries a warning, the run goes on."""
    big = lambda t: 8 * ref(t)  # noqa: E731
    scene = Scene("pedot-micro")
    r = rollout(scene, None, 10.0, controller=CurvatureTracker(big, 10.0), progress=False, rrd=tmp_path / "sat.rrd")
    assert r.meta["saturated_updates"] > 0 and "clipped" in r.meta["warnings"][0]
    assert np.abs(r.voltage).max() == pytest.approx(max(abs(v) for v in scene.actuator.voltage_range))
    from mjeap.io.recording import read_recording
    assert "/log" in read_recording(tmp_path / "sat.rrd")


@pytest.mark.slow
def test_unstable_gains_are_reported_with_the_controller_named():
    """A destabilising (negative) proportional gain with a huge magnitude diverges or rails;
    any divergence error names the controller."""
    scene = Scene("pedot-micro", timestep=None)
    ctrl = CurvatureTracker(ref, 5.0, kp=-50.0, ki=0.0, feedforward=False)
    try:
        r = rollout(scene, None, 5.0, controller=ctrl, progress=False)
    except DivergenceError as e:
        assert "curvature-tracker" in str(e)
    else:
        assert r.meta["saturated_updates"] > 0
