"""HAMR leg phase control from the self-sensed current (Jayaram et al. 2018, section 6.2)."""
import numpy as np
import pytest

from mjeap.controllers.hamr_leg import SWING, leg_scene, pid_gains, run_leg
from mjeap.io.recording import read_recording
from mjeap.validation.mechanics import free_vibration_frequency

#: Jayaram et al. 2018: within 5 degrees in under 25 cycles (250 ms) at 100 Hz
PHASE_TOL_DEG, MAX_CYCLES = 5.0, 25


@pytest.fixture(scope="module")
def swing(tmp_path_factory):
    path = tmp_path_factory.mktemp("leg") / "hamr-leg.rrd"
    return run_leg(SWING, cycles=40, open_loop_cycles=10, rrd=path), path


def test_leg_scene_rings_at_the_swing_resonance():
    """The reflected leg mass is sized on the linearised scene; the free ring-down of the
    nonlinear MuJoCo scene must agree within 1 % (the damped frequency is 0.13 % lower at
    zeta = 0.05)."""
    sc = leg_scene(SWING)
    assert free_vibration_frequency(sc) == pytest.approx(SWING.resonance, rel=0.01)


def test_phase_error_within_5_degrees_in_25_cycles(swing):
    run, _ = swing
    n_open = run.open_loop_cycles
    # starts from the open-loop lag: at resonance the foot lags the drive by ~90 degrees
    assert run.true_error_deg[n_open - 1] > 45.0
    for which in ("true", "sensed"):
        n = run.cycles_to_within(PHASE_TOL_DEG, which)
        assert n is not None and n <= MAX_CYCLES, (which, n)


def _sensed_bias(run):
    """Sensed minus true foot phase error (deg) over the last three open-loop cycles."""
    n_open = run.open_loop_cycles
    return run.sensed_error_deg[n_open - 3:n_open] - run.true_error_deg[n_open - 3:n_open]


def test_sensed_phase_follows_the_true_phase(swing):
    """The estimator is calibrated on the free actuator and not changed for the leg (as in
    the paper); the leg's inertial tip force bends the actuator differently from the drive's
    uniform moment, so the sensed phase carries a small bias (measured 0.9 / 0.7 / 0.6
    degrees over the last three open-loop cycles; 6.7 / 6.5 / 6.3 when the controller's
    lock-in dated the current read after a step, which belongs to the step's start, at the
    step's end: omega h = 5.7 deg at the leg's 159 us step)."""
    run, _ = swing
    assert np.abs(_sensed_bias(run)).max() < PHASE_TOL_DEG


def test_sensed_phase_bias_converges_with_the_step(swing):
    """The same open loop at a quarter of the leg's step: the sensed-vs-true bias within
    0.1 degree of the default step's (measured 0.02; 4.3 degrees apart, 6.6 against 2.3,
    with the lock-in a step late)."""
    run, _ = swing
    quarter = run_leg(SWING, cycles=run.open_loop_cycles + 1, open_loop_cycles=run.open_loop_cycles,
                      timestep=run.result.meta["scene"]["timestep"] / 4)
    assert quarter.result.meta["scene"]["timestep"] < run.result.meta["scene"]["timestep"] / 3.9
    np.testing.assert_allclose(_sensed_bias(quarter), _sensed_bias(run), atol=0.1)


def test_gains_from_the_plant_put_both_poles_at_one_half():
    kp, ki, kd = pid_gains(0.05, 100.0, 100.0)
    a = np.exp(-0.05 * 2 * np.pi)
    assert kp / (kp + ki) == pytest.approx(a) and (kp + ki) * (1 - a) == pytest.approx(0.25) and kd == 0


def test_recording_holds_the_foot_before_and_after(swing):
    _, path = swing
    ents = read_recording(path)
    for e in ("/leg/foot_path/open_loop", "/leg/foot_path/closed_loop", "/leg/phase_error/true",
              "/leg/phase_error/sensed", "/leg/foot/swing/simulated", "/beam/centreline"):
        assert e in ents, e
