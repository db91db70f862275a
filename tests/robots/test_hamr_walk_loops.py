"""HAMR-VI's eight phase loops on the self-sensed currents (mjeap.robots.hamr_walk; issue 25,
Jayaram et al. 2018 section 6.2), at 20 V, 80 Hz: the lift transmissions' resonance, where open loop
each lift lags its drive most (the single leg's second-order model: 90 degrees) and the
swings (100 Hz) little (12.5 degrees).

Reference: each foot's simulated 3D position relative to the body, in the body frame
(fore-aft for a swing, normal for a lift), locked in per drive cycle; independent of the
current estimator. Measured with the walker's contact sized from its physics
(hamr_walk.contact_parameters: 10-step time constant, the 'discrete' integrator; MuJoCo
4.0, 4 segments, 40 cycles): open loop (its cycles 4-39, circular mean) the lifts lag
72.7-84.5 degrees (less than the model's 90: stance adds the ground's stiffness to the
lift) and the swings 14.5-21.6 degrees (model 12.5). Closed loop (closed after 6 cycles;
two runs, the self-sensing controllers edited between them): each foot's true error over
cycles 16-39 averages -2.5..+4.0 degrees (lifts 0.4-4.0, swings -2.5..+3.4), standard error
of that mean 1.5-6.3 degrees (sd 7-30 degrees, 23 cycles): the
landings move the foot relative to the body from cycle to cycle, which a once-per-cycle
loop cannot take out; no foot holds 5 degrees every cycle. The sensed error follows the
true one on average within 1.9 degrees.
At 80 Hz, 20 V the trot is a hopping gait (the lifts at their resonance throw the body: a
foot down 5 % of the time open loop, 1.4-8 % closed, each foot landing once every 2.5-6
cycles, hamr_walk's module text): open loop +0.41 m/s, closed +0.18-0.19 m/s, both forward;
in its flights the body tilts past hamr_walk.UPRIGHT_DEG (open loop pitch 32 degrees;
closed roll 37 in one run, roll 17 and pitch 24 in the other) without rolling over. With
the earlier contact (2 steps, 'implicitfast', whose feet chattered at rest) it had stayed
within 30 degrees (+0.35, +0.30 m/s); that claim was dropped with it, and what holds is
tested: forward, not rolled over (|roll|, |pitch| below 90 degrees), landings within the
contact tolerance. The motion is chaotic."""
import numpy as np
import pytest

from mjeap.errors import ParameterError
from mjeap.robots import hamr_walk as hw

FREQUENCY, AMPLITUDE, CYCLES = 80.0, 20.0, 40
SETTLED = hw.OPEN_LOOP_CYCLES + 10        # cycles: the loops closed 10 cycles before
OPEN_FROM = hw.RAMP_CYCLES + 2            # cycles: the open loop's lag is averaged from here on
SENSED_MEAN_TOL_DEG = 5.0                 # |mean sensed - true| (measured <= 1.9; 2.6 with the earlier contact)


class _NoState:
    """Stands in for the system handed to the controller: any read fails the test."""

    def __getattr__(self, name):
        raise AssertionError(f"the controller read system.{name}")


@pytest.fixture(scope="module")
def system():
    return hw.build()


_SYSTEM = None


@pytest.fixture(scope="module")
def runs(system):
    global _SYSTEM
    _SYSTEM = system
    """The closed loop (the controller handed no system: it can read only its observers) and
    the open loop over the same cycles and window."""
    call = hw.TrotPhaseControllers.__call__
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(hw.TrotPhaseControllers, "__call__", lambda self, t, s: call(self, t, _NoState()))
        closed = hw.walk_closed_loop(system, FREQUENCY, AMPLITUDE, CYCLES)
    T = 1.0 / FREQUENCY
    open_ = hw.walk(system, FREQUENCY, AMPLITUDE, settle=(CYCLES - hw.LOOP_MEASURE_CYCLES) * T,
                    measure=hw.LOOP_MEASURE_CYCLES * T)
    return closed, open_, hw.loop_summary(closed, open_)


def _wrap(deg):
    return np.degrees(np.angle(np.exp(1j * np.radians(deg))))


@pytest.mark.slow
def test_each_loop_reads_only_its_own_actuator_current(system, runs):
    """Besides the run above (the controller handed an object that fails on any read), each
    loop's drive is the read-only observer of its own actuator's beam."""
    ctrl = runs[0]["controller"]
    assert set(ctrl.ctrls) == {a.prefix.rstrip("/") for a in system.actuators}
    for p, c in ctrl.ctrls.items():
        assert c.drive is ctrl.obs[p]
        assert c.drive.part._part is system.parts[system.index(p)]
        assert type(c.drive.part).__name__ == "ReadOnlyPart"


def _model_lag_deg(dof):
    """The single leg's transmission (hamr_leg's design: resonance 100 Hz swing, 80 Hz lift,
    damping ratio ZETA) as a second-order system: its phase lag at FREQUENCY (deg)."""
    from mjeap.robots.hamr_leg import DOFS, ZETA
    r = FREQUENCY / DOFS[dof].resonance
    return float(np.degrees(np.arctan2(2.0 * ZETA * r, 1.0 - r * r)))


def _open_lags(runs):
    """Per actuator the open-loop run's true error (deg), circular mean over cycles OPEN_FROM.."""
    _, open_, _ = runs
    errors = hw.foot_phase_errors(open_, CYCLES - 1)
    return {p: float(np.degrees(np.angle(np.exp(1j * np.radians(np.asarray(e)[OPEN_FROM:])).mean())))
            for p, e in errors.items()}


@pytest.mark.slow
def test_open_loop_lifts_lag_at_their_resonance(runs):
    """Open loop each foot lags as its transmission's second-order model says, to within
    what tells a lift from a swing: each foot's mean lag is nearer its own model lag (lift
    90, swing 12.5 degrees at 80 Hz) than the other's, i.e. lifts above and swings below
    the midpoint, 51 degrees (measured: lifts 72.7-84.5, swings 14.5-21.6). The open loop
    walks forward (measured +0.41 m/s), does not roll over (pitch 32 degrees at most, in its
    hops) and its landings stay within the contact tolerance: its failure is the lag, not
    the walk."""
    lift, swing = _model_lag_deg("lift"), _model_lag_deg("swing")
    assert lift == pytest.approx(90.0) and swing == pytest.approx(12.5, abs=0.1)
    mid = 0.5 * (lift + swing)
    for p, lag in _open_lags(runs).items():
        if p.endswith("_lift"):
            assert mid < lag < 180.0, (p, lag)
        else:
            assert 0.0 < lag < mid, (p, lag)
    m = runs[2]["open_loop"]
    assert m["speed_m_s"] > 0
    assert max(m["max_abs_roll_deg"], m["max_abs_pitch_deg"]) < 90.0
    _landings_obey_the_contact_law(m)


def _landings_obey_the_contact_law(m):
    """The deepest landing is within the critically damped contact's v tau / e of the
    fastest foot (5 %: the impedance, 0.99, and sampling), and the hops' fastest feet are
    what takes it near the contact tolerance (80 Hz, 20 V: the lifts at resonance move a
    free foot +-6.4 mm, 3.2 m/s; the tolerance is reached at 3 m/s: 51.6 um measured on
    MuJoCo 3.17, under 50 um on 4.0, so the tolerance itself is not the bound)."""
    from mjeap.robots.hamr_walk import build, contact_sizing
    per = contact_sizing(_SYSTEM or build())["landing_penetration_m_per_m_s"]
    assert m["max_penetration_m"] < 1.05 * per * m["max_foot_speed_m_s"], (m["max_penetration_m"], per,
                                                                             m["max_foot_speed_m_s"])


@pytest.mark.slow
def test_closed_loop_removes_the_mean_lag(runs):
    """The loops remove each foot's mean lag: over cycles SETTLED..CYCLES-1 the true error's
    mean lies more than two standard errors (of the per-cycle scatter) closer to zero than
    the open-loop lag, i.e. |mean| + 2 sem < open-loop lag (measured: swings <= 12.1 against
    14.5-21.6, lifts <= 13.1 against 72.7-84.5); the lifts, whose lag is large against the
    scatter, to within a quarter of it (measured |mean| <= 4.0 against 72.7-84.5). The
    robot moves forward (measured +0.18-0.19 m/s), does not roll over (roll 37 degrees at
    most, in its hops) and its landings stay within the contact tolerance."""
    closed, _, s = runs
    open_lag = _open_lags(runs)
    for p, e in closed["errors"].items():
        tail = np.asarray(e["true_deg"])[SETTLED:]
        mean, sem = tail.mean(), tail.std(ddof=1) / np.sqrt(tail.size)
        assert abs(mean) + 2.0 * sem < open_lag[p], (p, mean, sem, open_lag[p])
        if p.endswith("_lift"):
            assert abs(mean) < 0.25 * open_lag[p], (p, mean, open_lag[p])
    m = s["closed_loop"]
    assert m["speed_m_s"] > 0.05
    assert max(m["max_abs_roll_deg"], m["max_abs_pitch_deg"]) < 90.0
    _landings_obey_the_contact_law(m)


@pytest.mark.slow
def test_sensed_phase_follows_the_foot(runs):
    """Mean over the cycles after the soft start of sensed - true within SENSED_MEAN_TOL_DEG,
    per actuator; the reference is the foot's simulated position, not the estimator."""
    closed, _, _ = runs
    for p, e in closed["errors"].items():
        d = _wrap(e["sensed_deg"] - e["true_deg"])[hw.RAMP_CYCLES:]
        assert abs(d.mean()) < SENSED_MEAN_TOL_DEG, p


def test_the_loop_gains_are_stable_at_the_walking_frequencies():
    from mjeap.controllers.hamr_leg import phase_loop_characteristic
    from mjeap.robots.hamr_leg import DOFS, ZETA
    for f in (10.0, 20.0, 40.0, 65.0, 80.0):
        for dof, (kp, ki, _) in hw.walk_loop_gains(f).items():
            poly = phase_loop_characteristic(kp, ki, ZETA, DOFS[dof].resonance, f)
            assert np.abs(np.roots(poly)).max() < 0.8, (f, dof)


def test_bad_loop_parameters_are_refused(system):
    with pytest.raises(ParameterError, match="open_loop_cycles"):
        hw.walk_closed_loop(system, FREQUENCY, AMPLITUDE, cycles=10, open_loop_cycles=1)
    with pytest.raises(ParameterError, match="amplitude"):
        hw.TrotPhaseControllers(system, FREQUENCY, 150.0, estimator=object())
    with pytest.raises(ParameterError, match="frequency"):
        hw.walk_loop_gains(150.0)
