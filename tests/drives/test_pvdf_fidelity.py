"""Metello 2020's unimorphs against the thesis's measurements: the eigenstrain coefficient fitted
on one sample predicts the others; field stiffening is off by default; the Maxwell chain uses
the thesis's layer-sum moment of inertia."""
import numpy as np
import pytest

from mjeap import Scene, get_actuator
from mjeap.drives import make_drive
from mjeap.drives.electrostrictive import (FIELDS, SLOPES, STRAIN_COEFFICIENT, maxwell_stress_model, section_moment_of_inertia)
from mjeap.validation.metello2020 import (FIT_SAMPLE, SAMPLES, TABLE_4_6, active_share_of_ei, fit_strain_coefficient, load_displacement, held, settle_tip)


def test_layer_sum_moment_of_inertia_is_the_thesis_table_3_7():
    """60PVDF: sum of I_i about the neutral axis = 2.633e-2 mm^4 (Table 3.7, 1.092e-2 +
    3.680e-3 + 3.561e-4 + 1.947e-3 + 9.429e-3), 1 %; w h^3 / 12 is 0.9 % larger."""
    I = section_moment_of_inertia(get_actuator("pvdf-60"))
    assert I == pytest.approx(2.6332e-14, rel=0.01)
    assert 15e-3 * 0.277e-3**3 / 12 / I - 1 == pytest.approx(0.009, abs=0.003)
    # the thesis's Table 3.8 moment with it: 1.080e-5 N m at 700 V, 0.5 %
    assert maxwell_stress_model(get_actuator("pvdf-60"), 700.0)["moment"] == pytest.approx(1.080e-5, rel=0.005)


def test_strain_coefficient_is_fitted_on_one_sample_and_consistent_across_all():
    """The drive's default Q is the least-squares fit on 60PVDF's Table 4.6 (0.5 %); fitted on
    each of the other samples alone it comes out within 5 % of that (the data's consistency,
    measured: -3.8 % and -1.5 %)."""
    q = fit_strain_coefficient(FIT_SAMPLE)
    assert STRAIN_COEFFICIENT == pytest.approx(q, rel=0.005)
    for a in SAMPLES:
        assert fit_strain_coefficient(a) == pytest.approx(q, rel=0.05)


@pytest.mark.parametrize("actuator", [a for a in SAMPLES if a != FIT_SAMPLE])
def test_fitted_coefficient_predicts_the_other_samples_free_deflection(actuator):
    """Held-out samples: the simulated free tip displacement with the 60PVDF coefficient is
    within 50 % of Table 4.6 at every field and within 25 % at 11.67 and 15 MV/m (measured:
    -41/-12/+21 % and -49/-5/+15 %; one Q cannot follow the measured E^0.6-0.8 growth, so the
    lowest field is the worst), and the error changes sign across the fields (no bias that a
    different Q would remove)."""
    scene = Scene(actuator)
    t_a = next(l for l in scene.actuator.layers if l.name == "terpolymer").thickness
    err = []
    for j, E in enumerate(FIELDS[1:]):
        held(scene, E * t_a)
        err.append(settle_tip(scene, 0.0) / TABLE_4_6[actuator][j] - 1)
    err = np.array(err)
    assert np.all(np.abs(err) < 0.5) and np.all(np.abs(err[1:]) < 0.25)
    assert err.min() < 0 < err.max()


def test_field_stiffening_is_off_by_default_and_cannot_be_material():
    """Default drive: stiffness factor 1 at every field (the beam's slope under 15 MV/m is the
    0 V one within 2 %, the large-deflection geometry aside). The terpolymer carries 0.15 % of
    60PVDF's and 0.6 % of 130PVDF's EI (layer model), so a 100-fold modulus rise would change
    EI by at most 15 % / 61 %, while the thesis's slopes rise 2.5 x / 8.2 x."""
    s = Scene("pvdf-60")
    drv = make_drive(None, s)
    assert drv.factors is None and drv.stiffness_factor(15e6) == 1.0
    EI = float(s.actuator.flexural_rigidity_at(0.0)[0])
    _, _, k15, _ = load_displacement(s, 15e6 * 60e-6, EI)
    assert k15 == pytest.approx(3 * EI / s.layout.length**3, rel=0.02)
    assert active_share_of_ei("pvdf-60") == pytest.approx(0.0015, rel=0.1)
    assert active_share_of_ei("pvdf-130") == pytest.approx(0.0062, rel=0.1)
    for a in ("pvdf-60", "pvdf-130"):
        assert 1 + 99 * active_share_of_ei(a) < SLOPES[a][-1] / SLOPES[a][0]
    assert make_drive(None, Scene("pvdf-60"), stiffening=True).stiffness_factor(15e6) == pytest.approx(1.16 / 0.47)


def test_catalog_stiffness_is_the_measured_0v_slope():
    """EI of each sample = (measured 0 V slope) L^3 / 3, Tables 4.1-4.3, to the digit."""
    for a in SAMPLES:
        act = get_actuator(a)
        assert 3 * act.flexural_rigidity_at(0.0)[0] / act.length**3 == pytest.approx(SLOPES[a][0] * 1e3, rel=1e-12)
