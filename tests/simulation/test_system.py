"""Actuators as MuJoCo components (mjeap.simulation.system): attached to a host model written here, several
in one system, with contact.

References: the equivalent one-actuator Scene (the same beam, damping and timestep; round-off
apart the same trajectory), and for contact the discrete chain's own blocked force (the
hinge chain's closed form, below) and the Euler-Bernoulli 3 M / (2 a)."""
import mujoco
import numpy as np
import pytest

from mjeap import Scene, UnitSystem, rollout
from mjeap.errors import ParameterError, UnknownNameError
from mjeap.simulation.system import ContactParameters, System, attach

from hosts import GRIP, host


TILTED = '<body name="base" pos="1 -2 3" quat="0.9 0.2 -0.1 0.3"><site name="mount" pos="0.5 0 0" quat="0.8 0.1 0.3 0.2"/></body>'


@pytest.mark.parametrize("contact,integrator", [(False, "implicitfast"), (True, "discrete")])
def test_attached_at_a_tilted_site_moves_as_its_scene(contact, integrator):
    """At a site tilted in 3D (gravity then loads the beam in and out of its plane): the SI
    tip curvature in the clamp frame equals the equivalent Scene's (same orientation
    relative to gravity, same integrator) to 1e-6 of its largest value."""
    spec = host(TILTED)
    a = attach(spec, "pedot-micro", site="mount", prefix="left", payload="3.15mg@6.2mm", contact=contact)
    s = System(spec, [a])
    assert s.integrator == integrator
    r = s.rollout(["square:1V@2Hz"], 0.5, initial_curvatures=[-50.0])
    ref = rollout(Scene("pedot-micro", orientation=a.twin.rotation, payload="3.15mg@6.2mm", integrator=integrator),
                  "square:1V@2Hz", 0.5, initial_curvature=-50.0)
    k, k_ref = r.actuators["left"].tip_curvature, ref.tip_curvature
    assert s.timestep == a.twin.timestep
    assert np.max(np.abs(k - k_ref)) <= 1e-6 * np.abs(k_ref).max()
    np.testing.assert_allclose(r.actuators["left"].tip_position, ref.tip_position, rtol=0,
                               atol=1e-6 * np.abs(ref.tip_position).max())


def _native_actuators():
    from mjeap.engines.native import why_not
    from mjeap.model.catalog import actuator_ids
    from mjeap.drives import make_drive
    return [a for a in actuator_ids() if why_not(Scene(a), make_drive(None, Scene(a))) is None]


@pytest.mark.parametrize("actuator", _native_actuators())
def test_every_native_drive_attached_moves_and_reads_as_its_scene(actuator):
    """Each catalog actuator's own drive, attached alone and stepped by the system: tip
    curvature and every drive signal equal the Scene's native rollout's to 1e-6 of their
    largest values. (The drive's signals are replayed beside the native model; a replay that
    wrote its moments into the system's beam doubled a piezo bimorph's deflection.)"""
    spec = host('<site name="mount"/>')
    a = attach(spec, actuator, site="mount", prefix="act", contact=False)
    s = System(spec, [a])
    lo, hi = a.drive.voltage_range()
    v = f"step:{lo + 0.75 * (hi - lo)}V"
    duration = 300 * s.timestep
    r = s.rollout([v], duration).actuators["act"]
    ref = rollout(Scene(actuator, orientation=a.twin.rotation), v, duration, engine="native", progress=False)
    for got, want in [(r.tip_curvature, ref.tip_curvature)] + [(r.signals[k], ref.signals[k]) for k in ref.signals]:
        assert np.max(np.abs(got - want)) <= 1e-6 * max(np.abs(want).max(), 1e-300)


TWO = ('<body name="base"><site name="a" pos="0 0 0" quat="0.7071068 0.7071068 0 0"/>'
       '<site name="b" pos="0 30 0" quat="0.7071068 0.7071068 0 0"/></body>')


@pytest.mark.slow
def test_two_actuators_not_touching_each_move_as_alone():
    """Two actuators whose bending planes are vertical (gravity bends them): one driven, one
    at 0 V (sagging and creeping under its own weight). Each equals its one-actuator run
    to 1e-9 of its swing."""
    spec = host(TWO)
    a = attach(spec, "pedot-micro", site="a", prefix="driven")
    b = attach(spec, "pedot-micro", site="b", prefix="idle")
    s = System(spec, [a, b])
    r = s.rollout({"driven": "square:1V@2Hz", "idle": None}, 0.5)
    for name, att, wave in (("driven", a, "square:1V@2Hz"), ("idle", b, "step:0V")):
        alone = rollout(Scene("pedot-micro", orientation=att.twin.rotation, integrator="discrete"), wave, 0.5)
        k = r.actuators[name].tip_curvature
        assert np.ptp(alone.tip_curvature) > 0
        assert np.max(np.abs(k - alone.tip_curvature)) <= 1e-9 * np.ptp(alone.tip_curvature), name


def chain_blocked_force(part, moments, a: float) -> float:
    """The hinge chain's blocked force (N) at distance a (m) from the clamp, zero gap: hinge j
    at x_j < a turns by (M_j - F (a - x_j)) / k_j, and the point at a does not move:
    F = sum M_j (a - x_j) / k_j / sum (a - x_j)^2 / k_j."""
    x = part.layout.hinge_x
    k = part.hinge_stiffness()
    arm = np.clip(a - x, 0.0, None)
    return float(np.sum(moments * arm / k) / np.sum(arm**2 / k))


def test_beam_pressing_on_a_block_gives_its_blocked_force():
    """pedot-micro, horizontal, a fixed rod (capsule along the hinge axis) touching the beam's
    +y face at a = 5 mm; 3 V. The contact force follows the chain's blocked force for the
    drive's moment Gamma v_c (v_c the actuator's activation) within 1 %, and the
    Euler-Bernoulli 3 M / (2 a) within 2 % (the 20-hinge chain's discretisation). The
    penetration stays below 1 % of the beam's 35 um."""
    t, r, a_mm = 35e-3, 0.2, 5.0
    rod = f'<geom name="rod" type="capsule" size="{r} 1" pos="{a_mm} {t / 2 + r} 0" rgba="0.6 0.6 0.6 1"/>'
    spec = host('<site name="mount"/>' + rod)
    act = attach(spec, "pedot-micro", site="mount", prefix="beam")
    s = System(spec, [act])
    s.set_voltages([3.0])
    s.step(int(round(0.3 / s.timestep)))
    mujoco.mj_forward(s.model, s.data)
    part, drv = s.parts[0], act.drive
    vc = s.data.act[s.model.actuator_actadr[s.actuator_ids[0]]]
    M = drv.gamma * vc
    F = np.linalg.norm(s.contact_forces()[0])                      # on the world body (the rod)
    assert F == pytest.approx(chain_blocked_force(part, M, a_mm * 1e-3), rel=0.01)
    assert F == pytest.approx(1.5 * M / (a_mm * 1e-3), rel=0.02)
    assert s.penetration() < 0.01 * t * 1e-3


def test_two_actuators_close_on_a_free_body():
    """Two pedot-micro fingers facing each other close on a 2.25 mg bead resting on a floor:
    contact forces appear on the bead from both sides, each above 10 x its weight, equal
    and opposite to 2 %, the bead stays centred (within 20 um) and nothing diverges;
    penetration below 2 % of the beam thickness."""
    spec = host(GRIP)
    fingers = [attach(spec, "pedot-micro", site=n, prefix=n) for n in ("left", "right")]
    s = System(spec, fingers)
    r = s.rollout(["step:3V", "step:3V"], 0.6, sample_interval=0.01)
    bead = r.body("bead")
    f = r.contact_force[:, bead]
    assert np.all(np.isfinite(r.body_position))
    assert abs(r.body_position[-1, bead, 1]) < 20e-6
    # squeezed from both sides: the fingers' forces along y cancel, each well above the weight
    weight = 2.25e-6 * 9.80665
    finger_forces = [np.sum([s.contact_forces()[b] for b in part.link_ids], axis=0) for part in s.parts]
    assert abs(finger_forces[0][1]) > 10 * weight
    assert finger_forces[0][1] == pytest.approx(-finger_forces[1][1], rel=0.02)
    assert abs(f[-1, 1]) < 0.02 * abs(finger_forces[0][1])
    assert s.penetration() < 0.02 * 35e-6


def test_contact_friction_lengths_are_si_and_bad_values_are_named():
    """The torsional and rolling coefficients are lengths given in m: in a host in mm they
    compile as mm (x 1e3); the sliding one is a ratio; impratio is passed on. Negative or
    missing coefficients, an unknown cone and impratio < 1 are refused, named."""
    spec = host(GRIP)
    fingers = [attach(spec, "pedot-micro", site=n, prefix=n) for n in ("left", "right")]
    s = System(spec, fingers, contact=ContactParameters(friction=(0.4, 2e-5, 3e-7), impratio=5.0))
    assert list(s.model.opt.o_friction) == pytest.approx([0.4, 0.4, 2e-2, 3e-4, 3e-4])
    assert s.model.opt.impratio == 5.0
    for kw, name in (({"friction": (0.5, -1e-6, 0.0)}, "friction"), ({"friction": (0.5, 1e-6)}, "friction"),
                     ({"cone": "round"}, "cone"), ({"impratio": 0.5}, "impratio")):
        with pytest.raises(ParameterError, match=name):
            ContactParameters(**kw)


def test_bad_attachments_are_named():
    spec = host(TILTED)
    with pytest.raises(UnknownNameError, match="site 'mnt'.*mount"):
        attach(spec, "pedot-micro", site="mnt", prefix="a")
    with pytest.raises(UnknownNameError, match="body"):
        attach(spec, "pedot-micro", body="nobody", prefix="a")
    with pytest.raises(ParameterError, match="site/body/frame"):
        attach(spec, "pedot-micro", site="mount", body="base", prefix="a")
    a = attach(spec, "pedot-micro", site="mount", prefix="a")
    with pytest.raises(ParameterError, match="prefix"):
        attach(spec, "pedot-micro", site="mount", prefix="a")
    with pytest.raises(ParameterError, match="prefix"):
        attach(spec, "pedot-micro", site="mount", prefix="a/b")
    s = System(spec, [a])
    with pytest.raises(ParameterError, match="voltages.*one per actuator"):
        s.rollout(["step:1V", "step:1V"], 0.01)
    with pytest.raises(ParameterError, match="voltage"):
        s.rollout(["step:9V"], 0.01)
    with pytest.raises(ParameterError, match="drive"):
        attach(host(TILTED), "pvdf-60", site="mount", prefix="p")


def test_si_host_with_micro_parts_is_refused_with_a_unit_system_that_works():
    spec = host('<site name="mount"/>', gravity="0 0 -9.80665")
    with pytest.raises(ParameterError, match=r"units.*1e-15.*mm, mg, ms"):
        attach(spec, "pedot-micro", site="mount", prefix="a", units=UnitSystem(1.0, 1.0, 1.0))


def test_host_gravity_in_other_units_is_refused():
    with pytest.raises(ParameterError, match="gravity.*-0.00980665"):
        attach(host('<site name="mount"/>', gravity="0 0 -9.81"), "pedot-micro", site="mount", prefix="a")


def test_a_controller_drives_the_system_as_the_waveform_it_returns():
    """A controller returning the square wave's value before every step gives the same run
    as the waveform (to round-off); one returning a voltage outside the drive's safe range
    stops the run with the actuator, the voltage and the range named."""
    from mjeap.drives.waveforms import parse_waveform
    spec = host('<site name="mount"/>')
    a = attach(spec, "pedot-micro", site="mount", prefix="act", contact=False)
    s = System(spec, [a])
    w = parse_waveform("square:1V@5Hz")
    ref = s.rollout(["square:1V@5Hz"], 0.2).actuators["act"]
    got = s.rollout(None, 0.2, controller=lambda t, sy: [float(w(np.array([t]))[0])]).actuators["act"]
    np.testing.assert_allclose(got.tip_curvature, ref.tip_curvature, rtol=0, atol=1e-9 * np.abs(ref.tip_curvature).max())
    np.testing.assert_allclose(got.voltage, ref.voltage, atol=1e-12)
    with pytest.raises(ParameterError, match="controller voltage of 'act'.*safe range"):
        s.rollout(None, 0.2, controller=lambda t, sy: [5.0])
    with pytest.raises(ParameterError, match="voltages"):
        s.rollout(["step:1V"], 0.2, controller=lambda t, sy: [1.0])


def test_transmission_inputs_are_named():
    """add_transmission refuses a zero or non-finite ratio and an unknown joint, naming them."""
    from mjeap.simulation.system import add_transmission
    spec = host('<site name="mount"/><body name="arm"><joint name="stroke" type="hinge"/>'
                '<geom type="sphere" size="1" contype="0" conaffinity="0"/></body>')
    a = attach(spec, "pzt-robobee", site="mount", prefix="act", contact=False)
    for bad in (0.0, float("nan")):
        with pytest.raises(ParameterError, match="ratio"):
            add_transmission(spec, a, "stroke", bad)
    with pytest.raises(UnknownNameError, match="nope"):
        add_transmission(spec, a, "nope", 4000.0)


@pytest.mark.slow
@pytest.mark.parametrize("wave,duration", [("square:1V@2Hz", 0.5), ("sine:1V@20Hz", 0.2)])
def test_a_system_estimates_its_step_error(wave, duration):
    """estimate_error: each actuator's tip-curvature error from the timestep, against the
    system at h / 2 (order 1.5 assumed). Reference: the same system at h / 16 (its own step
    error 1/16 of the run's at order 1). The estimate within 3 x of the true step error
    (measured: 1.5 x and 0.82 x)."""
    from mjeap.simulation.accuracy import relative_difference
    spec = host('<site name="a"/>')
    a = attach(spec, "pedot-micro", site="a", prefix="driven", contact=False)
    s = System(spec, [a])
    r = s.rollout({"driven": wave}, duration, estimate_error=True)
    rep = r.meta["accuracy"]["driven"]
    assert r.actuators["driven"].meta["accuracy"] is rep and "segments: not estimated" in rep["estimate"]
    ref = System(s.spec.copy(), s.actuators, s.units, timestep=s.timestep / 16, integrator=s.integrator,
                 contact=s.contact).rollout({"driven": wave}, duration, sample_interval=float(r.time[1] - r.time[0]))
    true = relative_difference(ref.actuators["driven"], r.actuators["driven"])
    assert true > 0
    assert 1 / 3 <= rep["estimated_error"] / true <= 3


def test_a_system_refuses_an_estimate_beside_a_controller():
    spec = host('<site name="a"/>')
    s = System(spec, [attach(spec, "pedot-micro", site="a", prefix="d", contact=False)])
    with pytest.raises(ParameterError, match="estimate_error"):
        s.rollout(None, 0.01, controller=lambda t, sy: [0.5], estimate_error=True)


def test_the_half_step_companion_carries_the_tip_loads_and_hand_set_hinges_are_refused():
    """The estimate's companion (System.half_step) is the same system: its actuators carry
    the tip loads set on the system's parts (they once ran unloaded). Hinge parameters set
    by hand are refused up front, before the run."""
    spec = host('<site name="a"/>')
    s = System(spec, [attach(spec, "pedot-micro", site="a", prefix="d", contact=False)])
    s.part("d").set_tip_force(1e-6)
    s.part("d").set_tip_moment(2e-9)
    half = s.half_step()
    f, m = half.part("d").tip_loads()
    np.testing.assert_allclose(f, [0.0, 1e-6, 0.0], atol=1e-18)
    assert m == pytest.approx(2e-9)
    s.part("d").set_hinge_parameters(stiffness=s.part("d").layout.hinge_stiffness)
    with pytest.raises(ParameterError, match="set_hinge_parameters"):
        s.rollout({"d": "step:0.5V"}, 0.01, estimate_error=True)
    assert s.time == 0.0


ARM = ('<body name="arm"><joint name="swing" type="hinge" axis="0 0 1"/>'
       '<geom type="sphere" size="0.1" mass="1" contype="0" conaffinity="0"/>'
       '<site name="mount" pos="2 0 0"/></body>')


def test_on_a_moving_clamp_the_companion_and_a_reset_keep_the_tip_loads_in_the_world():
    """A clamp on a swinging arm: the force set stays the force in the world after the arm
    turns (the half-step companion starts from qpos0 and must not re-express it in its own
    clamp frame), and a reset re-applies the moment about the hinge axis (it had been written
    before the clamp's frame was known, as zero)."""
    spec = host(ARM, gravity="0 0 0")
    s = System(spec, [attach(spec, "pedot-micro", site="mount", prefix="d", contact=False)])
    p = s.part("d")
    p.set_tip_force(1e-6)
    p.set_tip_moment(2e-9)
    world = s.data.xfrc_applied[p.tip_load_id].copy()
    assert world[3:].any()
    s.data.qpos[s.model.joint("swing").qposadr[0]] = 0.7
    mujoco.mj_forward(s.model, s.data)
    half = s.half_step()
    np.testing.assert_allclose(half.data.xfrc_applied[half.part("d").tip_load_id], world, rtol=1e-12, atol=0)
    s.reset()
    np.testing.assert_allclose(s.data.xfrc_applied[p.tip_load_id], world, rtol=1e-12, atol=0)
