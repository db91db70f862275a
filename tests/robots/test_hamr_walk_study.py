"""The cause of HAMR-VI's roll-over at 65 Hz (mjeap.robots.hamr_walk.study), by controlled
one-parameter comparisons against the default model at the paper's full drive (swing and
lift 0..200 V): the lift amplitude decides it, the legs' moving mass does not."""
import pytest

from mjeap.errors import ParameterError
from mjeap.robots import hamr_walk as hw
from mjeap.robots.hamr_walk import study as st

SHORT = {"measure": 0.1}         # 2 ramp + 5 settling + 7 measured cycles at 65 Hz


@pytest.fixture(scope="module")
def d():
    return hw.design()


@pytest.mark.slow
def test_at_full_drive_the_65_hz_trot_rolls_over_and_with_a_20_v_lift_it_runs_upright(d):
    """The same model and swing (100 V): the full 100 V lift (foot +-9.4 mm at 65 Hz, the
    lift transmission's gain 2.9 below its 80 Hz resonance) throws the body off its feet
    (roll or pitch past 30 deg); a 20 V lift (+-1.9 mm) keeps it upright and running forward."""
    full = st.study_run(65.0, d=d, **SHORT)
    low = st.study_run(65.0, walk={"lift_amplitude": 20.0}, d=d, **SHORT)
    assert not full["upright"]
    assert low["upright"] and low["speed_m_s"] > 0.1


@pytest.mark.slow
def test_the_legs_moving_mass_is_not_the_cause(d):
    """A tenth of the legs' moving mass (armature_fraction 0.9: the rest of each joint's
    design inertia as armature, the resonances kept) still rolls over at full drive: at
    40 Hz (measured: roll 180 deg; at 65 Hz this trot, chaotic, stays within 20 deg over
    0.5 s, as the default model tilts to 45-67 deg there)."""
    m = st.study_run(40.0, build={"armature_fraction": 0.9}, d=d, settle=0.3, measure=0.2)
    assert not m["upright"]


@pytest.mark.slow
def test_the_climb_is_friction_limited(d):
    """On a 12 deg incline at 10 Hz and full drive (upright on level ground), one parameter
    changed: with the default mu 0.51 the robot slides back down (measured -0.12 m/s along
    the slope), with mu 1.2 it climbs (+0.09 m/s); upright in both."""
    low = st.study_run(10.0, build={"mu": hw.MU, "incline_deg": 12.0}, d=d)
    high = st.study_run(10.0, build={"mu": 1.2, "incline_deg": 12.0}, d=d)
    assert low["speed_m_s"] < 0 < high["speed_m_s"]
    assert low["upright"] and high["upright"]


@pytest.mark.slow
def test_at_80_hz_the_gait_not_the_contact_makes_the_body_hop(d):
    """At 80 Hz, 20 V (the lifts at their resonance) the body flies between landings whatever
    the contact's time constant (10 steps, the walker's, and 50, five times softer): each
    foot lands less than once every two cycles (measured 0.23 and 0.25 landings per cycle)
    and the body never comes down to its hips' height on unloaded legs over the window
    (FOOT_DROP + FOOT_RADIUS = 11.85 mm; at rest, loaded, 11.56 mm, hamr_walk.stand; its
    lowest here 15.3 mm). Only the time per landing follows the contact (duty factor 0.0047
    against 0.016, measured)."""
    rows = st.contact_study(80.0, 20.0, steps=(hw.CONTACT_STEPS, 4 * hw.CONTACT_STEPS))
    standing = hw.FOOT_DROP + hw.FOOT_RADIUS        # m, the hips' height on unloaded legs
    for r in rows:
        assert r["touchdowns_per_cycle"] < 0.5, r
        assert r["body_height_range_m"][0] > standing, r
    assert rows[0]["duty_factor"] < rows[1]["duty_factor"]


def test_the_study_options_refuse_bad_values():
    with pytest.raises(ParameterError, match="armature_fraction"):
        hw.build(armature_fraction=1.0)
    with pytest.raises(ParameterError, match="body_width"):
        hw.build(body_width=1e-3)
    with pytest.raises(ParameterError, match="variants"):
        st.rolling_study(())
    with pytest.raises(ParameterError, match="mus"):
        st.incline_study(())
