"""First natural frequency from free vibration against the characteristic equation."""
import numpy as np
import pytest

from mjeap import Payload, Scene, analytical as an
from mjeap.validation.mechanics import free_vibration_frequency as measured_frequency


@pytest.mark.parametrize("representation", ["hinge", "cable", pytest.param("rod", marks=pytest.mark.slow)])
@pytest.mark.parametrize("tip_mass", [0.0, 3.15e-6, 12.6e-6])
def test_first_frequency_within_2_percent(representation, tip_mass):
    """PEDOT beam, unloaded and with Dadras et al. 2021's payload masses at the tip (NdFeB sphere,
    rotary inertia included in the reference). Light damping (zeta_1 = 0.005) so the
    measured damped frequency differs from the undamped one by < 0.002 %."""
    L, EI, m = 6e-3, 1 / 4.86e7, 0.695e-6
    payload = Payload(tip_mass, L) if tip_mass else None
    s = Scene("pedot-micro", representation=representation, payload=payload, damping_ratio=0.005)
    ref = an.natural_frequencies(L, EI, m / L, tip_mass=tip_mass,
                                 tip_inertia=payload.inertia if payload else 0.0, n=1)[0]
    assert measured_frequency(s) == pytest.approx(ref, rel=0.02)
    # the modal analysis used to pick the timestep agrees too
    assert s.choice.first_frequency == pytest.approx(ref, rel=0.02)


def test_discrete_integrator_runs_undamped_beyond_the_explicit_limit():
    """Under 'discrete' joint stiffness is implicit: an undamped chain is stable at a step
    20 x above the explicit (implicitfast) limit, and the first mode still oscillates at
    its frequency (within 2 %; numerical damping ~ omega h / 2)."""
    explicit = Scene("pedot-micro", damping_ratio=1e-4)
    s = Scene("pedot-micro", damping_ratio=0.0, integrator="discrete",
              timestep=20 * explicit.choice.stability_limit)
    assert s.choice.stability_limit == float("inf")
    L, EI, m = 6e-3, 1 / 4.86e7, 0.695e-6
    ref = an.natural_frequencies(L, EI, m / L, n=1)[0]
    s.data.qpos[:] = 0.0
    s.set_hinge_angles(np.full(20, 1e-3))
    s.data.time = 0.0
    n = int(6 / ref / s.timestep)
    y = np.empty(n)
    for i in range(n):
        s.step()
        y[i] = s.tip_position()[1]
    assert np.all(np.isfinite(y))
    spec = np.abs(np.fft.rfft(y - y.mean(), 64 * n))
    f = np.fft.rfftfreq(64 * n, s.timestep)[np.argmax(spec)]
    assert f == pytest.approx(ref, rel=0.02)


@pytest.mark.parametrize("integrator", ["implicitfast", "discrete"])
def test_first_mode_damping_ratio_is_the_catalogs_under_either_integrator(integrator):
    """The damping ratio of the first mode of the discrete step map (what the simulation
    does per step, integrator included; mjeap.model.modes.first_mode_damping) is the catalog's
    zeta_1 = 0.05 within 2 %, unloaded horizontal. Under 'discrete' backward Euler adds
    zeta = omega h / 2 of its own (Rayleigh beta = h): the joints carry beta - h."""
    from mjeap.model.modes import first_mode_damping, linearize
    s = Scene("pedot-micro", integrator=integrator)
    w, zeta = first_mode_damping(linearize(s.model), s.model.dof_damping, s.model.opt.timestep, integrator)
    assert zeta == pytest.approx(0.05, rel=0.02)
    assert w / s.units.time / (2 * np.pi) == pytest.approx(s.choice.first_frequency, rel=0.01)


@pytest.mark.parametrize("integrator", ["implicitfast", "discrete"])
@pytest.mark.parametrize("orientation", ["horizontal", "up", "down"])
def test_first_mode_damping_ratio_is_the_catalogs_under_gravity_loads(orientation, integrator):
    """With 100 mg at the tip (0.76 x the column load standing up) gravity's geometric
    stiffness moves omega_1 by a factor 0.55 (up) to 1.3 (down); the first mode of the step
    map still has the catalog's zeta_1 = 0.05 within 2 % (it had zeta (w_el / w_1)^2:
    0.16 up, 0.03 down, when beta was 2 zeta / w_1 on the elastic stiffness only)."""
    from mjeap.model.modes import first_mode_damping, linearize
    s = Scene("pedot-micro", orientation=orientation, payload="100mg@6mm", integrator=integrator)
    w, zeta = first_mode_damping(linearize(s.model), s.model.dof_damping, s.model.opt.timestep, integrator)
    assert zeta == pytest.approx(0.05, rel=0.02)
    assert w / s.units.time / (2 * np.pi) == pytest.approx(s.choice.first_frequency, rel=0.01)


@pytest.mark.parametrize("representation", ["hinge", "rod"])
def test_free_vibration_from_an_initial_curvature(representation):
    """mjeap.free_vibration releases the unloaded beam bent to a 10 1/m arc with no drive
    holding it: the tip swings through straight at the first natural frequency (within 2 %
    of the clamped-free frequency equation) and its peaks decay with the catalog's
    zeta_1 = 0.05 (logarithmic decrement over peaks 2-6, 5 %; measured 0.0498 hinge, 0.0499
    rod: the flex's damping coefficient (beta - h) t / w gives its weak axis (beta - h) k,
    MuJoCo damping a box section's weak axis by the coefficient x sqrt(k1 k2), and the
    discrete step adds h k)."""
    from scipy.signal import find_peaks
    from mjeap import free_vibration
    L, EI, m = 6e-3, 1 / 4.86e7, 0.695e-6
    f_ref = an.natural_frequencies(L, EI, m / L, n=1)[0]
    s = Scene("pedot-micro", representation=representation)
    r = free_vibration(s, 10.0, 8 / f_ref, sample_interval=s.timestep)
    assert r.meta["drive"].startswith("none")
    y = r.tip_position[:, 1]
    assert y.min() < -0.5 * y[0]                    # released: it swings to the other side
    k, _ = find_peaks(y)
    t, a = r.time[k][1:6], y[k][1:6]
    assert 1 / np.mean(np.diff(t)) == pytest.approx(f_ref, rel=0.02)
    d = np.mean(np.log(a[:-1] / a[1:]))
    assert d / np.sqrt(4 * np.pi**2 + d**2) == pytest.approx(0.05, rel=0.05)


def test_point_mass_and_given_inertia_payloads():
    """Payload.point (no rotary inertia) and a given inertia, from the API and the CLI text:
    the scene's first mode against the frequency equation with that tip inertia (2 %)."""
    from mjeap.errors import ParameterError
    L, EI, m = 6e-3, 1 / 4.86e7, 0.695e-6
    assert Payload.parse("12.6mg@6mm,point") == Payload.point(12.6e-6, 6e-3)
    assert Payload.parse("12.6mg@6mm,I=3e-12").inertia == 3e-12
    assert Payload.parse("12.6mg@6mm,r=1mm").inertia == pytest.approx(0.4 * 12.6e-6 * 1e-6)
    with pytest.raises(ParameterError, match="payload"):
        Payload.parse("12.6mg@6mm,spin")
    for text, J in (("12.6mg@6mm,point", 0.0), ("12.6mg@6mm,I=3e-11", 3e-11)):
        ref = an.natural_frequencies(L, EI, m / L, tip_mass=12.6e-6, tip_inertia=J, n=1)[0]
        assert Scene("pedot-micro", payload=text).choice.first_frequency == pytest.approx(ref, rel=0.02)
