"""First natural frequency from free vibration against the characteristic equation."""
import numpy as np
import pytest

from mjeap import Payload, Scene, analytical as an
from mjeap.validation.mechanics import free_vibration_frequency as measured_frequency


@pytest.mark.parametrize("representation", ["hinge", "cable"])
@pytest.mark.parametrize("tip_mass", [0.0, 3.15e-6, 12.6e-6])
def test_first_frequency_within_2_percent(representation, tip_mass):
    """PEDOT beam, unloaded and with seed 000's payload masses at the tip (NdFeB sphere,
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
    does per step, integrator included; mjeap.modes.first_mode_damping) is the catalog's
    zeta_1 = 0.05 within 2 %, unloaded horizontal. Under 'discrete' backward Euler adds
    zeta = omega h / 2 of its own (Rayleigh beta = h): the joints carry beta - h."""
    from mjeap.modes import first_mode_damping, linearize
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
    from mjeap.modes import first_mode_damping, linearize
    s = Scene("pedot-micro", orientation=orientation, payload="100mg@6mm", integrator=integrator)
    w, zeta = first_mode_damping(linearize(s.model), s.model.dof_damping, s.model.opt.timestep, integrator)
    assert zeta == pytest.approx(0.05, rel=0.02)
    assert w / s.units.time / (2 * np.pi) == pytest.approx(s.choice.first_frequency, rel=0.01)
