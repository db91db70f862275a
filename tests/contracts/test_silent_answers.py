"""Inputs that used to give a silent wrong answer: each now gives the right one or is refused
before any work, naming the parameter (or flag) and what is accepted.

References: the equivalent one-actuator Scene (an attached beam moves as it does, round-off
apart: tests/simulation/test_system.py), the first mode's damping ratio of the step map
(mjeap.model.modes.first_mode_damping: the catalog's 0.05), and rollout's own bounds."""
import mujoco
import numpy as np
import pytest

from mjeap import Scene, load_mjcf, rollout, rollout_batch
from mjeap.errors import MjeapError, ParameterError
from mjeap.model.fields import read_units
from mjeap.simulation.system import System, attach

G = "0 0 -0.00980665"      # standard gravity in mm / ms^2
VERTICAL = '<site name="mount" quat="0.7071068 0.7071068 0 0"/>'   # deflection along z: gravity bends it
UP = '<site name="mount" quat="0.7071068 0 -0.7071068 0"/>'         # beam along z: gravity loads it axially


def host(body: str = '<site name="mount"/>', option: str = "", gravity: str = G) -> mujoco.MjSpec:
    return mujoco.MjSpec.from_string(
        f'<mujoco><option gravity="{gravity}">{option}</option><worldbody>{body}</worldbody></mujoco>')


def close(got, want, tol=1e-6):
    return np.max(np.abs(got - want)) <= tol * np.ptp(want)


# 1 ------------------------------------------------------------------------------------------
@pytest.mark.parametrize("payload,option", [("5mg@6mm", ""), ("12.6mg@6.27mm", ""),
                                            ("5mg@6mm", '<flag filterparent="disable"/>')])
def test_payload_does_not_touch_its_own_beam(payload, option):
    """With contact (attach's default) the payload sphere overlapped its own beam's links
    (5 mg at 6 mm by 92 um) and the contact pushed the beam 0.5-0.8 % of its swing off the
    Scene's trajectory; with the host's filterparent flag off, neighbouring links touched
    too. The beam's own parts are excluded pairs: the Scene's trajectory to 1e-6."""
    spec = host(option=option)
    a = attach(spec, "pedot-micro", site="mount", prefix="p", payload=payload)
    r = System(spec, [a]).rollout(["square:1V@5Hz"], 0.15).actuators["p"]
    ref = rollout(Scene("pedot-micro", orientation=a.twin.rotation, payload=payload, integrator="discrete"),
                  "square:1V@5Hz", 0.15)
    assert close(r.tip_curvature, ref.tip_curvature)


# 2 ------------------------------------------------------------------------------------------
def test_discrete_user_timestep_is_bounded_by_damping_and_accuracy():
    """Under 'discrete' the joints carry (beta - h) K: at h >= beta their damping was 0 while
    choice.damping_ratio still said 0.05 (and the hinge chain has no stability limit to stop
    it). A user timestep above beta / 2, or above T_1 / 50 where beta is 0, is refused with the
    limit; one below it is taken."""
    s = Scene("pedot-micro", integrator="discrete")
    with pytest.raises(ParameterError, match=r"timestep=0.01 .*<= 3.83\d*e-05 s .*beta / 2"):
        Scene("pedot-micro", integrator="discrete", timestep=1e-2)
    with pytest.raises(ParameterError, match=r"timestep.*<= 9.64\d*e-05 s .*accuracy.*50 steps per period"):
        Scene("pedot-micro", integrator="discrete", damping_ratio=0.0, timestep=1e-3)
    Scene("pedot-micro", integrator="discrete", timestep=s.choice.accuracy_limit)       # the limit itself: taken
    spec = host()
    a = attach(spec, "pedot-micro", site="mount", prefix="a", contact=True)
    with pytest.raises(ParameterError, match=r"timestep=0.01 .*<= .* s .*beta / 2"):
        System(spec, [a], timestep=1e-2)


def test_system_timestep_below_the_twins_keeps_the_damping_ratio():
    """A System stepped finer than its discrete twin gives the joints beta - h of its own h:
    the first mode of the step map keeps the catalog's 0.05 (it had beta - h_twin + h_system:
    0.036 at half the twin's step)."""
    from mjeap.model.modes import first_mode_damping, linearize
    spec = host(VERTICAL)
    a = attach(spec, "pedot-micro", site="mount", prefix="a", passive=True, integrator="discrete", contact=False)
    s = System(spec, [a], timestep=a.twin.timestep / 2)
    _, zeta = first_mode_damping(linearize(s.model), s.model.dof_damping, s.model.opt.timestep, "discrete")
    assert zeta == pytest.approx(0.05, rel=0.02)
    again = System(spec, [a])                # the same host at the twin's own step: the twin's damping again
    assert np.array_equal(again.model.dof_damping, a.twin.model.dof_damping)


# 3 ------------------------------------------------------------------------------------------
def test_host_without_gravity_sizes_its_actuators_without_it():
    """<flag gravity="disable"/>: the twin was sized with gravity (a standing beam with a
    payload: its first mode and with it the damping and timestep off). Now as
    Scene(gravity=False): same choice, same trajectory."""
    spec = host(UP, '<flag gravity="disable"/>')
    a = attach(spec, "pedot-micro", site="mount", prefix="a", payload="12.6mg@6.27mm", contact=False)
    ref_scene = Scene("pedot-micro", orientation=a.twin.rotation, payload="12.6mg@6.27mm", gravity=False)
    assert a.twin.choice == ref_scene.choice
    r = System(spec, [a]).rollout(["square:1V@5Hz"], 0.1).actuators["a"]
    assert close(r.tip_curvature, rollout(ref_scene, "square:1V@5Hz", 0.1).tip_curvature)


@pytest.mark.parametrize("flag", ["actuation", "spring", "damper"])
def test_host_flags_that_switch_off_part_of_a_beam_are_refused(flag):
    """actuation off recorded 3 V while nothing was driven; springs or dampers off made the
    beam diverge with the timestep blamed. Refused at attach, and at System when set after."""
    with pytest.raises(ParameterError, match=rf"<flag {flag}>='disable'.*'enable'"):
        attach(host(option=f'<flag {flag}="disable"/>'), "pedot-micro", site="mount", prefix="a")
    spec = host()
    a = attach(spec, "pedot-micro", site="mount", prefix="a")
    spec.option.disableflags |= int(getattr(mujoco.mjtDisableBit, f"mjDSBL_{flag.upper()}"))
    with pytest.raises(ParameterError, match=rf"<flag {flag}>"):
        System(spec, [a])


def test_passive_beam_in_a_host_without_actuation_and_gravity_changed_after_attach():
    spec = host(option='<flag actuation="disable"/>')
    attach(spec, "pedot-micro", site="mount", prefix="a", passive=True, contact=False)   # nothing to drive: taken
    spec = host(VERTICAL)
    a = attach(spec, "pedot-micro", site="mount", prefix="a", contact=False)
    spec.option.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_GRAVITY)
    with pytest.raises(ParameterError, match=r"spec.option.gravity.*attached under"):
        System(spec, [a])


# 4 ------------------------------------------------------------------------------------------
@pytest.mark.parametrize("bounds", [(-1e5, 1e5), (float("nan"), 1.0), (0.0, float("inf"))])
def test_environment_initial_curvatures_within_rollouts_bounds(bounds):
    """(-1e5, 1e5) 1/m started episodes 60 turns round; NaN overflowed. rollout's bounds
    (finite, at most a full circle) apply, refused when the environment is made."""
    from mjeap.envs.environment import make_environment
    with pytest.raises(ParameterError, match=r"initial_curvature_range.*\[-1047.2, 1047.2\] 1/m"):
        make_environment(initial_curvature_range=bounds)


# 5 ------------------------------------------------------------------------------------------
def _numerics_model(*numerics) -> mujoco.MjModel:
    custom = "".join(f'<numeric name="{n}" data="{d}"/>' for n, d in numerics)
    return mujoco.MjModel.from_xml_string(
        f'<mujoco><custom>{custom}</custom><worldbody><body><joint type="hinge"/><joint type="hinge" axis="1 0 0"/>'
        '<geom size="1" mass="1"/></body></worldbody></mujoco>')


@pytest.mark.filterwarnings("ignore:MuJoCo. XML contains a 'NaN'")
@pytest.mark.parametrize("data", ["nan 1", "1 -1", "1 inf"])
def test_load_mjcf_refuses_bad_dof_damping(tmp_path, data):
    path = tmp_path / "m.xml"
    path.write_text('<mujoco><custom><numeric name="mjeap_dof_damping" data="' + data + '"/></custom><worldbody><body>'
                    '<joint type="hinge"/><joint type="hinge" axis="1 0 0"/><geom size="1" mass="1"/></body>'
                    '</worldbody></mujoco>')
    with pytest.raises(ParameterError, match=r"mjeap_dof_damping=.* finite values >= 0"):
        load_mjcf(path)


@pytest.mark.filterwarnings("ignore:MuJoCo. XML contains a 'NaN'")
def test_read_units_reads_its_own_field_only():
    """A short mjeap_units was read on into the next numeric (MuJoCo keeps them in one array)."""
    m = _numerics_model(("mjeap_units", "0.001 1e-6"), ("other", "5"))
    with pytest.raises(ParameterError, match=r"mjeap_units='2 values'.*3 values"):
        read_units(m)
    with pytest.raises(ParameterError, match=r"mjeap_units=.*nan.*> 0"):
        read_units(_numerics_model(("mjeap_units", "0.001 nan 0.001")))
    assert read_units(_numerics_model(("mjeap_units", "0.001 1e-6 0.001"), ("other", "5"))).time == 1e-3


# 6 ------------------------------------------------------------------------------------------
def test_policy_with_two_values_for_one_actuator_is_refused():
    from mjeap.envs.environment import make_environment
    env = make_environment(time_limit=0.05, payload=None, orientation="horizontal")
    env.reset()
    env.step([0.5])
    with pytest.raises(ParameterError, match=r"action=.*shape \(2,\).*shape \(1,\)"):
        env.step([0.5, 0.7])


def test_controllers_with_two_values_for_one_actuator_are_refused():
    s = Scene("pedot-micro")

    class Two:
        interval = 1e-3

        def reset(self, scene, drive):
            pass

        def __call__(self, t, scene):
            return np.array([0.1, 0.2])

    with pytest.raises(ParameterError, match=r"controller command.*shape \(2,\).*shape \(1,\)"):
        rollout(s, None, 0.01, controller=Two())
    spec = host()
    sys_ = System(spec, [attach(spec, "pedot-micro", site="mount", prefix="a", contact=False)])
    with pytest.raises(ParameterError, match=r"controller voltage of 'a'.*shape \(2,\)"):
        sys_.rollout(None, 0.01, controller=lambda t, system: [[0.1, 0.2]])


def test_bare_waveform_text_is_one_waveform():
    """A bare text was split into its characters (one 'waveform' per character). One
    actuator or one run takes it whole; several actuators refuse it, naming the choices."""
    spec = host('<site name="a"/><site name="b" pos="0 30 0"/>')
    one = System(spec, [attach(spec, "pedot-micro", site="a", prefix="a", contact=False)])
    r = one.rollout("step:1V", 0.02).actuators["a"].tip_curvature
    assert np.array_equal(r, one.rollout(["step:1V"], 0.02).actuators["a"].tip_curvature)
    spec = host('<site name="a"/><site name="b" pos="0 30 0"/>')
    two = System(spec, [attach(spec, "pedot-micro", site=n, prefix=n, contact=False) for n in "ab"])
    with pytest.raises(ParameterError, match=r"one per actuator \(2: a, b\).*system of one actuator only"):
        two.rollout("step:1V", 0.02)
    s = Scene("pedot-micro")
    runs = rollout_batch(s, "step:1V", 0.02, nthread=1)
    assert len(runs) == 1
    assert np.array_equal(runs[0].tip_curvature, rollout_batch(s, ["step:1V"], 0.02, nthread=1)[0].tip_curvature)
    runs = rollout_batch(s, "step:1V", 0.02, initial_curvatures=[0.0, 20.0], nthread=1)
    assert len(runs) == 2 and runs[1].tip_curvature[0] != runs[0].tip_curvature[0]
    with pytest.raises(ParameterError, match=r"initial_curvatures.*one per voltage \(3\)"):
        rollout_batch(s, ["step:1V"] * 3, 0.02, initial_curvatures=[0.0, 20.0])


# 7 ------------------------------------------------------------------------------------------
@pytest.mark.cable
@pytest.mark.parametrize("contact", [False, True])
def test_cable_keeps_its_per_dof_damping_in_a_system(contact):
    """The cable's per-dof damping (stiff in-plane and twist directions) travels as
    PREFIX/mjeap_dof_damping and is applied when the System compiles: released from a bent
    arc it follows its Scene (it diverged by step 7 with one scalar damping per ball joint;
    with contact, attach failed on the cable's geom names)."""
    spec = host()
    a = attach(spec, "pedot-micro", site="mount", prefix="c", representation="cable", passive=True, contact=contact)
    s = System(spec, [a])
    r = s.rollout([None], 0.004, initial_curvatures=[50.0]).actuators["c"]
    ref = rollout(Scene("pedot-micro", representation="cable", integrator=a.twin.integrator), "step:0V", 0.004,
                  drive="none", initial_curvature=50.0)
    assert close(r.tip_curvature, ref.tip_curvature)
