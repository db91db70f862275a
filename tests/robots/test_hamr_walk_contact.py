"""HAMR-VI's ground contact read out (mjeap.robots.hamr_walk; issue: HAMR-VI runs like the
robot): the contact forces the walk reports against the robot's momentum, and why a stance
foot's contact flickers.

References: Newton's second law. Over a window the ground's mean force on the robot along
the ground's normal equals the weight plus the change of the robot's normal momentum over
the window divided by its duration; the momentum is read from the bodies' velocities
(mj_subtreeVel), the forces from MuJoCo's contact sensors at every step, two independent
read-outs. A body at rest on a contact carries its weight there at every step; one sliding
on it carries its weight on average (its mean vertical acceleration is zero)."""
import numpy as np
import pytest

from mjeap.robots import hamr_walk as hw
from mjeap.robots.hamr_walk import study as st

BALANCE_TOL = 0.01              # of the momentum's force (the 1 %)


def _short_trot(system):
    """30 V at 20 Hz (the issue's case: +5.4 % under 'discrete' before), 0.1 s settling and 0.1 s measured."""
    return hw.walk_metrics(hw.walk(system, 20.0, 30.0, settle=0.1, measure=0.1))


@pytest.mark.slow
@pytest.mark.parametrize("integrator", ["discrete", "implicitfast"])
def test_the_contact_forces_balance_the_momentum(integrator):
    """Under either integrator the mean ground force over the window (the impulses of every
    step) matches weight + change of momentum / duration within 1 % (measured -2e-5 under
    'discrete', -1.5e-7 under 'implicitfast'); the same forces read at the samples alone miss
    or catch the landings' few steps (+35 %, +28 % here: reported, not held)."""
    m = _short_trot(hw.build(integrator=integrator))
    assert abs(m["force_balance_error"]) < BALANCE_TOL, m["force_balance_error"]
    assert m["mean_normal_force_n"] == pytest.approx(m["momentum_normal_force_n"], rel=BALANCE_TOL)


@pytest.mark.slow
def test_at_mujocos_default_tolerance_the_discrete_step_reads_forces_off_its_motion():
    """The cause of the +5 % the issue measured: at MuJoCo's solver tolerance (1e-8) the
    Newton solve of the 'discrete' step stops before its contact forces match the motion it
    integrates; the same run then reads more than 1 % off the momentum (measured +6.8 % here,
    +5.9 % over 0.15 s of plain mj_step). SOLVER_TOLERANCE (1e-12) is what the walker runs at."""
    system = hw.build()
    system.model.opt.tolerance = 1e-8
    m = _short_trot(system)
    assert m["force_balance_error"] > BALANCE_TOL, m["force_balance_error"]
    assert hw.SOLVER_TOLERANCE < 1e-8


@pytest.mark.slow
def test_at_rest_every_foot_carries_load_at_every_step_and_none_touches_down():
    """No drive (amplitude 0) after 0.3 s: each foot is loaded at every step (contact duty
    factor 1 at every step and every interval), no foot touches down again, and the feet's
    mean normal forces add up to the weight within 1 % (Newton, a body at rest)."""
    run = hw.walk(hw.build(), 10.0, 0.0, settle=0.3, measure=0.1)
    m = hw.walk_metrics(run)
    assert m["loaded_step_fraction"] == 1.0 and m["contact_duty_factor"] == 1.0
    assert m["contact_touchdowns_per_cycle"] == 0.0 and m["step_touchdowns_per_cycle"] == 0.0
    k = run["time"] > run["t0"]
    fn = (run["foot_force_mean"][k] @ run["ground"][:, 2]).sum(axis=1)
    assert np.abs(fn / run["weight_n"] - 1.0).max() < BALANCE_TOL


def test_a_sliding_foot_is_pushed_apart_yet_carries_its_load():
    """The flicker's cause, on one foot alone (study.sliding_contact: a 0.5 mm sphere
    carrying a quarter of the weight on the walker's contact): at rest, and sliding
    without friction, it is loaded at every step; sliding at 0.03-0.1 m/s with mu 0.51 it
    is loaded in under 5 % of the steps (measured 1.6 % and 0.5 %; MuJoCo resolves normal
    and friction forces in one cost, which pushes a sliding contact apart) while its mean
    normal force stays its load within 3 % (measured +2.7 %, +0.1 %)."""
    rest, slow, fast = st.sliding_contact((0.0, 0.03, 0.1))
    assert rest["loaded_step_share"] == 1.0
    for r in (slow, fast):
        assert r["loaded_step_share"] < 0.05, r
        assert r["mean_normal_force_over_load"] == pytest.approx(1.0, abs=0.03), r
    (frictionless,) = st.sliding_contact((0.1,), contact={"o_friction": np.zeros(5)})
    assert frictionless["loaded_step_share"] == 1.0
