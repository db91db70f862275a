"""The rod representation (mjeap.rod, a 1D flexcomp rod: MuJoCo 4.x) against the same
analytical references as the hinge chain, within the hinge chain's tolerances (the checks
the two share are parametrised with the rod where they live: tests/model/test_statics.py,
tests/model/test_dynamics.py), and against the hinge chain on Dadras et al. 2021's heaviest run; what it
refuses, and why.

The PEDOT beam at the default 20 segments unless said otherwise. The rod is refused on
MuJoCo 3.x (tests/conftest.py skips these there with mjeap's reason)."""
import numpy as np
import pytest

from mjeap import Payload, Scene, analytical as an, rollout
from mjeap.errors import ParameterError
from mjeap.validation.mechanics import settled

pytestmark = pytest.mark.rod

ACT = "pedot-micro"
L, EI, M_BEAM = 6e-3, 1 / 4.86e7, 0.695e-6
G = 9.80665


@pytest.fixture(scope="module")
def rod():
    return Scene(ACT, representation="rod")


def test_rod_runs_under_discrete_with_its_own_damping(rod):
    """The scene takes 'discrete' (MuJoCo refuses rod elasticity under implicit and
    implicitfast), has no stability limit (the rod's elasticity is implicit), steps at
    beta / 2 (the step damps by h K itself) and damps the rod by its flex's own damping."""
    import mujoco
    c = rod.choice
    assert rod.integrator == "discrete" and rod.model.opt.integrator == mujoco.mjtIntegrator.mjINT_DISCRETE
    assert c.stability_limit == float("inf")
    assert c.timestep == pytest.approx(0.5 * c.rayleigh_beta, rel=2e-3)
    assert rod.model.flex_damping[0] > 0 and not rod.model.dof_damping.any()
    # hinge-equivalent damping of the bending: (beta - h) x its stiffness, as the hinge chain under discrete
    assert rod.hinge_damping() == pytest.approx((c.rayleigh_beta - c.timestep) * rod.hinge_stiffness(), rel=1e-9)


# ---------------------------------------------------------------------------- statics
# (the tip force to P L^2/EI = 3, the tip couple and the convergence order: tests/model/test_statics.py,
# parametrised with the rod; f1 with tip masses and the free vibration's damping ratio:
# tests/model/test_dynamics.py)
ALPHA_10_ROD_20 = pytest.mark.xfail(strict=True, reason=(
    "the rod at 20 segments is 0.20 % of L off axially and 0.21 % laterally at P L^2/EI = 10 (the hinge chain: "
    "0.022 % and 0.099 %): MuJoCo's discrete elastic rod measures the turn at a vertex as 2 tan(theta / 2), "
    "which stiffens it by theta^2 / 3 against the continuum (1.6 % at the clamp here, theta = 0.22 rad); a "
    "second-order error that 40 segments bring to 0.054 % (test below). Not fixable in mjeap: the flex's "
    "curvature measure is MuJoCo's"))


@pytest.mark.parametrize("representation,segments", [
    ("hinge", 20), pytest.param("rod", 20, marks=ALPHA_10_ROD_20),
    pytest.param("rod", 40, marks=pytest.mark.slow)])
def test_elastica_to_alpha_10_within_a_thousandth_of_L(representation, segments):
    """P L^2 / EI up to 10 (tip angle 82 degrees): the tip point within 0.1 % of L of the
    elastica (scipy solve_bvp), both coordinates."""
    s = Scene(ACT, representation=representation, segments=segments)
    for alpha in (1.0, 3.0, 10.0):
        P = alpha * EI / L**2
        tip = settled(s, force=P)
        ref = an.elastica_tip_force(P, L, EI)
        assert np.all(np.abs(tip[:2] - np.array(ref.tip)) < 1e-3 * L), (alpha, (tip[:2] - ref.tip) / L)


# ---------------------------------------------------------------------------- dynamics
@pytest.mark.slow
def test_buckling_load_within_1_percent():
    """Standing up under a tip payload: the modal analysis (in the hinge angles, gravity's
    geometric stiffness from the vertices' lever arms) calls the column straight at 0.99 x
    the critical load of the column with its own weight (scipy shooting) and buckled at
    1.01 x; pushed, it returns at 0.97 x (tests/model/test_axial.py's check) and, run to rest,
    settles on the post-buckled elastica at 1.03 x and 1.1 x (tip within 3 % of the
    elliptic-integral solution; measured -0.7 % and -1.2 %, the hinge chain +0.7 % and
    +0.1 %)."""
    P_cr = an.critical_tip_load(L, EI, M_BEAM * G / L)
    for factor in (0.99, 1.01):
        s = Scene(ACT, representation="rod", orientation="up", payload=Payload(factor * P_cr / G, L))
        assert s.choice.buckled is (factor > 1)
    for factor in (0.97, 1.03, 1.1):
        s = Scene(ACT, representation="rod", orientation="up", payload=Payload(factor * P_cr / G, L))
        s.set_hinge_angles(np.full(20, 1e-3 / 20))
        y0 = abs(s.tip_position()[1])
        if factor > 1:
            s.settle(tol=1e-9)
            tip = s.tip_position()
            x_ref, delta_ref, _ = an.postbuckled_column(factor, L)
            assert abs(tip[1]) == pytest.approx(delta_ref, rel=0.03)
            assert tip[0] == pytest.approx(x_ref, rel=0.03)
            continue
        y = []
        for _ in range(30):
            s.run(0.1)
            y.append(s.tip_position()[1])
        assert np.max(np.abs(y)) <= 1.01 * y0
        assert np.min(y) < -0.3 * y0


@pytest.mark.slow
def test_seed_000_heaviest_run_matches_the_hinge_chain_within_1_percent_of_the_swing():
    """Dadras et al. 2021's heaviest run (pedot-micro standing up, 12.6 mg NdFeB payload at 6.27 mm,
    square 3 Vpp at 0.1 Hz for 20 s from -303 1/m, its rc-relaxation drive): the rod's tip
    curvature within 1 % of the swing of the hinge chain's, each at its own default
    timestep (the rod's samples interpolated to the hinge chain's steps). Measured: 0.39 %,
    at the release transient."""
    out = {}
    for rep in ("hinge", "rod"):
        s = Scene(ACT, representation=rep, orientation="up", payload="12.6mg@6.27mm")
        out[rep] = rollout(s, "square:1.5V@0.1Hz", 20.0, initial_curvature=-303.0, progress=False,
                           sample_interval=(1 if rep == "hinge" else 2) * s.timestep)
    h, r = out["hinge"], out["rod"]
    assert r.meta["engine"] == "loop"
    rod_at_hinge = np.interp(h.time, r.time, r.tip_curvature)
    swing = np.ptp(h.tip_curvature)
    assert swing > 300
    assert np.max(np.abs(rod_at_hinge - h.tip_curvature)) < 0.01 * swing


# ---------------------------------------------------------------------------- read-outs and drives
def test_angles_rates_and_gravity_moments_read_the_vertices():
    """Bending angles written and read back; rates against the change of the angles over
    the step that ended with them; gravity's moments standing up against the hinge chain's (same
    layout, the rod lumps its masses on the vertices: within 2 %)."""
    s = Scene(ACT, representation="rod", orientation="up", payload="3mg@6mm")
    a = np.linspace(0.0, 0.03, 20)
    s.set_hinge_angles(a)
    assert s.hinge_angles() == pytest.approx(a, abs=1e-12)
    assert s.tip_angle() == pytest.approx(a.sum(), abs=1e-12)
    g_rod = s.gravity_moments()
    h = Scene(ACT, orientation="up", payload="3mg@6mm")
    h.set_hinge_angles(a)
    assert g_rod == pytest.approx(h.gravity_moments(), rel=0.02, abs=1e-3 * np.abs(g_rod).max())
    s.step(5)
    before = s.hinge_angles()
    s.step()        # 'discrete' moves the positions by h x the new velocities
    w = s.hinge_rates()
    assert (s.hinge_angles() - before) / s.timestep == pytest.approx(w, rel=1e-3, abs=1e-4 * np.abs(w).max())


def test_internal_moments_bend_the_rod_as_the_hinge_chain():
    """A drive's moments act as couples on the edges each vertex joins: a uniform moment M
    bends the arc of curvature M / EI (0.5 %); moments rising along the beam give the hinge
    chain's static tip within 0.5 % of its deflection."""
    s = Scene(ACT, representation="rod", gravity=False)
    M = 1.2 * EI / L
    s.set_internal_moments(M)
    s.settle(tol=1e-9)
    assert s.tip_curvature() == pytest.approx(1.2 / L, rel=0.005)
    ramp = np.linspace(0.2, 1.0, 20) * EI / L
    tips = []
    for sc in (s, Scene(ACT, gravity=False)):
        sc.reset()
        sc.set_internal_moments(ramp)
        sc.settle(tol=1e-9)
        tips.append(sc.tip_position())
    assert tips[0][:2] == pytest.approx(tips[1][:2], abs=5e-3 * abs(tips[1][1]))


def test_stiffness_scale_changes_the_flex_itself():
    """set_bending_stiffness_scale(2) halves a small static deflection (the flex's bending
    records are scaled, its damping follows), and 1 restores it."""
    s = Scene(ACT, representation="rod", gravity=False)
    P = 0.01 * EI / L**2
    y1 = settled(s, force=P)[1]
    s.reset()
    s.set_bending_stiffness_scale(2.0)
    s.set_tip_force(P)
    s.settle(tol=1e-10)
    assert s.tip_position()[1] == pytest.approx(y1 / 2, rel=1e-3)
    assert s.hinge_stiffness() == pytest.approx(2 * s.layout.hinge_stiffness)
    s.set_bending_stiffness_scale(1.0)
    s.settle(tol=1e-10)
    assert s.tip_position()[1] == pytest.approx(y1, rel=1e-6)


# ---------------------------------------------------------------------------- refusals
def test_implicit_integrators_are_refused_naming_the_reason():
    with pytest.raises(ParameterError, match=r"integrator='implicitfast'.*'discrete'.*MuJoCo 4.0 does not integrate"):
        Scene(ACT, representation="rod", integrator="implicitfast")


def test_native_and_threaded_engines_are_refused_naming_the_reason(rod):
    with pytest.raises(ParameterError, match=r"engine='native'.*no bending joints"):
        rollout(rod, "step:1V", 0.002, engine="native")
    with pytest.raises(ParameterError, match=r"engine='threaded'.*edge normals"):
        rollout(rod, "step:1V", 0.002, engine="threaded", drive="blocking-force")
    r = rollout(rod, "step:1V", 0.002)
    assert r.meta["engine"] == "loop" and "no bending joints" in r.meta["engine_reason"]


def test_accuracy_target_attach_and_hinge_parameters_are_refused(rod):
    import mujoco
    from mjeap.simulation.system import attach
    with pytest.raises(ParameterError, match=r"accuracy.*'rod' scene"):
        rollout(rod, "step:1V", 0.01, accuracy=1e-2)
    spec = mujoco.MjSpec.from_string('<mujoco><worldbody><site name="m"/></worldbody></mujoco>')
    with pytest.raises(ParameterError, match=r"representation='rod'.*twist bodies"):
        attach(spec, ACT, prefix="a", site="m", representation="rod", passive=True)
    with pytest.raises(ParameterError, match=r"representation='rod'.*hinge-chain notion"):
        rod.set_hinge_parameters(stiffness=1e-5)


def test_tapered_beams_and_payloads_inside_the_rod_are_refused():
    with pytest.raises(ParameterError, match=r"representation='rod'.*pzt-hamr-large: a flexcomp rod has one section"):
        Scene("pzt-hamr-large", representation="rod")
    with pytest.raises(ParameterError, match=r"payload.position.*do not rotate"):
        Scene(ACT, representation="rod", payload="3mg@3mm")
