"""HAMR-VI at rest and rolled over (mjeap.robots.hamr_walk): the ground contact sized from
the robot's physics (hamr_walk.contact_parameters: time constant 10 steps = 45 us,
critically damped, the actuators under the 'discrete' integrator).

References: Newton's laws. A robot at rest is not accelerating, so the ground's normal
forces add up to its weight, TOTAL_MASS x g (1.43 g, Jayaram et al. 2018), at every step; a body at
rest does not move (creep, the soft friction's slow slide, is held to 1 um/s). A robot on
its back lies on its chassis: the body's frame (the chassis's bottom face) then sits
BODY_HEIGHT above the ground. Before this contact (2-step time constant, 'implicitfast')
the robot never came to rest: no foot touched in 40 % of the steps, force spikes of 44-74 x
the weight, 67 um of creep over 2.5 s; and only the feet collided, so a rolled-over chassis
fell through the floor (20 / 2.5 / 17.5 mm below it at 65 / 80 / 100 Hz full drive)."""
import numpy as np
import pytest

from mjeap.robots import hamr_walk as hw

G0 = 9.80665                            # m/s^2, standard gravity (the model's)
FORCE_TOL = 0.01                        # of the weight, at every step (the 1 %)
CREEP_TOL = 1e-6                        # m/s
TOL = hw.CONTACT_WIDTH_FRACTION * hw.FOOT_RADIUS      # m, the contact tolerance (solimp width, 50 um)


@pytest.fixture(scope="module")
def rest():
    """1 s with no drive from the start (the feet 20 um above the ground); every step after
    0.5 s checked (measured: force error 6e-8, no creep above 0.13 um/s)."""
    return hw.stand(hw.build(), duration=1.0, after=0.5)


@pytest.mark.slow
def test_at_rest_the_feet_carry_the_weight_at_every_step(rest):
    """The sum of the feet's normal forces equals the weight within 1 % at every step after
    0.5 s, and every foot stays down (all four at every step)."""
    assert rest["weight_n"] == pytest.approx(hw.TOTAL_MASS * G0, rel=1e-9)
    assert rest["steps_checked"] > 1e5
    assert rest["max_force_error"] < FORCE_TOL
    assert rest["steps_with_no_foot_down"] == 0 and rest["min_feet_down"] == 4


@pytest.mark.slow
def test_at_rest_nothing_creeps(rest):
    """Neither the body nor any foot moves along the ground faster than 1 um/s (the feet,
    under the legs' splay, 0.12 um/s measured; the body 1e-10); the body sinks slower than
    1 um/s (0.11 measured, as the feet creep outward)."""
    assert rest["body_creep_m_s"] < CREEP_TOL
    assert max(rest["feet_creep_m_s"]) < CREEP_TOL
    assert abs(rest["body_vertical_drift_m_s"]) < CREEP_TOL


@pytest.mark.slow
def test_upside_down_the_robot_lies_on_its_chassis():
    """Dropped on its back from 20 um: it lies on the chassis, the body's frame BODY_HEIGHT
    above the ground within the contact tolerance, and the ground carries the weight within
    1 % at every step after 0.25 s (six decay times, 1 / (zeta omega) = 40 ms, of the legs'
    80 Hz lift mode, which the landing sets swinging)."""
    system = hw.build(upside_down=True)
    r = hw.stand(system, duration=0.35, after=0.25)
    assert r["body_height_m"] == pytest.approx(hw.BODY_HEIGHT, abs=TOL)
    assert r["max_force_error"] < FORCE_TOL
    chassis, legs = hw.clearances(system)
    assert -TOL < chassis < TOL and legs > 0


@pytest.mark.slow
def test_a_trot_that_rolls_over_lands_on_the_chassis_not_through_the_floor():
    """The full drive at 100 Hz throws the robot over (measured: roll 147 deg with the 100 us
    contact, 180 with the 45 us one); its chassis never sinks more than the contact tolerance
    into the ground, where it fell 17.5 mm through before the chassis collided (it lands on
    its side now, the chassis 5 mm up and a leg on the ground: lying on the chassis is the
    upside-down test's)."""
    m = hw.walk_metrics(hw.walk(hw.build(), 100.0))
    assert max(m["max_abs_roll_deg"], m["max_abs_pitch_deg"]) > 90.0
    assert m["min_chassis_clearance_m"] > -TOL
    assert min(m["min_chassis_clearance_m"], m["min_leg_clearance_m"]) < 1e-3


def test_the_contact_is_sized_inside_its_window():
    """contact_parameters' window, on the built robot, against its physical reference: a
    landing of the foot (0.094 g effective, the 0.5 mm sphere) at 0.4 m/s penetrates v tau / e
    (critically damped) within the depths of a Hertz contact on a polymer or paper ground,
    (15 m v^2 / (16 E* sqrt(R)))^(2/5) for E* 0.5-1 GPa (13-17 um; measured 14.7); the time
    constant at least 2 steps (MuJoCo's floor) and 5 tau within a tenth of the 65 Hz trot's
    half cycle; landings up to 1.3 m/s within the contact tolerance."""
    c = hw.contact_sizing(hw.build())
    m, v, R = 0.094e-3, 0.4, hw.FOOT_RADIUS          # kg, m/s, m
    hertz = [(15 * m * v * v / (16 * E * np.sqrt(R))) ** 0.4 for E in (1e9, 0.5e9)]
    assert hertz[0] <= v * c["landing_penetration_m_per_m_s"] <= hertz[1]
    assert c["timeconst_steps"] >= 2.0 - 1e-9
    assert 5 * c["timeconst_s"] <= 0.1 * 0.5 / 65.0
    assert c["dampratio"] == 1.0
    assert 1.3 * c["landing_penetration_m_per_m_s"] < c["contact_tolerance_m"]
