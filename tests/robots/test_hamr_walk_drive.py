"""HAMR-VI's trot drive and the step sized for the loaded system (mjeap.robots.hamr_walk;
issue 46), each against a physical reference:

- the no-flight lift is sized on the diagonal pair's sag, W T^2 / (2 k_tip): the robot's
  simulated sag at rest (four legs, half of it) against that closed form;
- at the no-flight lift the trot keeps a foot on the ground all the time and the body within
  a millimetre of its standing height; at the full lift (100 V) the same trot flies;
- the robot's drive trots upright at 10, 20, 40 and 65 Hz, and at 65 Hz within 2 x of the
  robot's 0.5 m/s (Jayaram et al. 2018);
- a step sized for the loaded system (System's ``loaded``) is checked against a run at half
  that step, and the learning environment's model against the default one (within 5 %).
"""
import numpy as np
import pytest

from mjeap.errors import ParameterError
from mjeap.robots import hamr_walk as hw
from mjeap.robots.hamr_leg.model import DOFS


@pytest.fixture(scope="module")
def system():
    return hw.build()


def _sag_closed_form(system, legs: int) -> float:
    """W T_lift^2 / (legs k_tip): the feet's sag under the weight the lifts carry
    (hamr_walk.sprung_weight) on ``legs`` legs, the lift actuator's tip stiffness (the
    laminate's closed form) seen through the transmission."""
    lam = system.actuators[0].drive.laminate()
    return hw.sprung_weight(system) * DOFS["lift"].ratio ** 2 * lam.tip_compliance() / legs


@pytest.mark.slow
def test_the_robot_sags_on_its_legs_as_the_lift_actuators_compliance_says(system):
    """At rest (no drive, 0.3 s) the body stands lower than its rigid-leg height (the feet
    FOOT_DROP + FOOT_RADIUS below the hips) by the sag on four legs, W T^2 / (4 k_tip) = 0.30
    mm (W the weight the lifts carry, 1.09 of the 1.43 g), the quantity the no-flight lift is
    sized on (twice it on a diagonal pair): within 10 % (measured -3.4 %; the legs' lateral
    splay under the load and the 4-segment beams move it)."""
    rest = hw.stand(system, duration=0.3, after=0.2, window=0.02)
    sag = hw.FOOT_DROP + hw.FOOT_RADIUS - rest["body_height_m"]
    assert sag == pytest.approx(_sag_closed_form(system, 4), rel=0.10)


def test_the_robots_drive_keeps_its_actuators_within_their_travel_and_its_lift_below_flight(system):
    """trot_drive: below 20 Hz the full swing (100 V) and the no-flight lift; at 65 Hz the swing
    at the amplitude that reaches its travel (0.3 mm x its second-order gain, 64 V), the lift
    there at 6.3 V; each lift's foot stroke (quasi-static x its gain) the pair's sag."""
    lam = system.actuators[0].drive.laminate()
    per_volt = (lam.free_deflection(200.0) - lam.free_deflection(0.0)) / 200.0
    for f in (10.0, 20.0, 40.0, 65.0):
        d = hw.trot_drive(system, f)
        r = f / DOFS["lift"].resonance
        gain = 1.0 / np.hypot(1 - r * r, 2 * 0.05 * r)
        stroke = d["lift_amplitude"] * per_volt * DOFS["lift"].ratio * gain
        assert stroke == pytest.approx(_sag_closed_form(system, 2), rel=1e-6), f
        rs = f / DOFS["swing"].resonance
        tip = d["amplitude"] * per_volt / np.hypot(1 - rs * rs, 2 * 0.05 * rs)
        assert tip <= hw.ACTUATOR_RANGE * (1 + 1e-9), f
    assert hw.trot_drive(system, 10.0)["amplitude"] == hw.AMPLITUDE
    assert hw.trot_drive(system, 65.0)["amplitude"] == pytest.approx(64.2, abs=0.5)
    with pytest.raises(ParameterError, match="frequency"):
        hw.trot_drive(system, 150.0)
    with pytest.raises(ParameterError, match="timestep"):
        hw.build(timestep=1e-3)


@pytest.fixture(scope="module")
def robot_trots():
    """The robot's drive at 10, 20, 40 and 65 Hz on the default model (0.3 s settling, 0.2 s
    measured: the issue's window)."""
    s = hw.build()
    return {f: hw.walk_metrics(hw.walk(s, f, settle=0.3, measure=0.2, **hw.trot_drive(s, f)))
            for f in (10.0, 20.0, 40.0, 65.0)}


@pytest.mark.slow
def test_the_robots_trot_is_upright_at_10_to_65_hz_and_near_the_robots_speed_at_65(robot_trots):
    """|roll| and |pitch| below 30 deg over the whole window at 10-65 Hz (measured below 3.3
    deg), and at 65 Hz forward within 2 x of the robot's 0.5 m/s (measured 0.47 m/s)."""
    for f, m in robot_trots.items():
        assert m["upright"], (f, m["max_abs_roll_deg"], m["max_abs_pitch_deg"])
    v = robot_trots[65.0]["speed_m_s"]
    assert 0.5 * hw.PAPER_SPEED <= v <= 2.0 * hw.PAPER_SPEED


@pytest.mark.slow
def test_the_robots_trot_keeps_a_foot_down_at_10_and_20_hz(robot_trots):
    """No flight at 10 and 20 Hz, the no-flight lift's claim: a foot within STANCE_GAP of the
    ground at every sample and the body's height within 1 mm over the window (the reference:
    the stance pair's force never unloads when its feet push down by at most its sag). The
    trot's stance read at the samples' instants is reported, not asserted (issue 46's bands,
    docs/robots/hamr-walk.md: each foot down 0.67 and 0.58 of the cycle, 1.5-1.7 touch-downs
    per cycle within STANCE_GAP)."""
    for f in (10.0, 20.0):
        m = robot_trots[f]
        assert m["time_with_a_foot_down"] == 1.0, f
        assert np.ptp(m["body_height_range_m"]) < 1e-3, f


@pytest.mark.slow
def test_at_the_full_lift_the_same_trot_flies():
    """The reference of the no-flight lift: at 20 Hz the same swing with the lifts at 100 V
    (4.5 x the no-flight amplitude) throws the body off its feet: no foot within STANCE_GAP
    in some samples and the body more than 2 mm above its lowest point."""
    s = hw.build()
    m = hw.walk_metrics(hw.walk(s, 20.0, settle=0.3, measure=0.2))
    assert m["time_with_a_foot_down"] < 1.0
    assert np.ptp(m["body_height_range_m"]) > 2e-3


@pytest.mark.slow
def test_a_step_sized_for_the_loaded_system_agrees_with_half_of_it():
    """The 20 Hz trot (the robot's drive) at the learning environment's 50 us step and at
    25 us (half; System.half_step) on the same 4-segment model and contact: speeds within 2 %
    (measured 0.3 %), both upright, no warning from MuJoCo (an unstable run resets itself
    and only warns)."""
    s = hw.build(timestep=50e-6)
    half = s.half_step()
    speeds = []
    for sy in (s, half):
        m = hw.walk_metrics(hw.walk(sy, 20.0, settle=0.3, measure=0.2, **hw.trot_drive(sy, 20.0)))
        assert m["upright"]
        assert not any(w.number for w in sy.data.warning)
        speeds.append(m["speed_m_s"])
    assert speeds[0] == pytest.approx(speeds[1], rel=0.02)
