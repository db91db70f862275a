"""The analytical references against published numbers and against each other."""
import numpy as np
import pytest

from mjeap import analytical as an

L, EI = 6e-3, 2.0576e-8


def test_elastica_matches_bisshopp_drucker_and_small_deflection():
    # Bisshopp & Drucker (1945), P L^2 / EI = 1: vertical tip deflection 0.3017 L,
    # horizontal 0.0564 L; tip angle 26.4 degrees
    e = an.elastica_tip_force(EI / L**2, L, EI)
    assert e.tip[1] / L == pytest.approx(0.3017, abs=2e-4)
    assert 1 - e.tip[0] / L == pytest.approx(0.0564, abs=2e-4)
    assert np.degrees(e.tip_angle) == pytest.approx(26.4, abs=0.1)
    # small load: Euler-Bernoulli
    P = 1e-4 * EI / L**2
    assert an.elastica_tip_force(P, L, EI).tip[1] == pytest.approx(an.tip_force_deflection(P, L, EI)[0], rel=1e-4)


def test_elastica_with_tip_moment_only_is_the_arc():
    M = 1.2 * EI / L
    e = an.elastica_tip_force(0.0, L, EI, tip_moment=M)
    x, y, th = an.arc_tip_moment(M, L, EI)
    assert e.tip == pytest.approx((x, y), rel=1e-7)
    assert e.tip_angle == pytest.approx(th, rel=1e-7)


def test_natural_frequencies_uniform_and_tip_mass():
    mu = 1e-4
    f = an.natural_frequencies(L, EI, mu, n=3)
    lam = np.sqrt(f * 2 * np.pi / np.sqrt(EI / (mu * L**4)))
    assert lam == pytest.approx([1.87510407, 4.69409113, 7.85475744], rel=1e-7)
    # heavy tip mass: single-degree-of-freedom limit with Rayleigh's 33/140 effective beam mass
    Mt = 100 * mu * L
    f1 = an.natural_frequencies(L, EI, mu, tip_mass=Mt, n=1)[0]
    f_sdof = np.sqrt(3 * EI / L**3 / (Mt + 33 / 140 * mu * L)) / (2 * np.pi)
    assert f1 == pytest.approx(f_sdof, rel=1e-4)


def test_lateral_stiffness_formula_and_bvp_agree():
    Pe = an.buckling_load(L, EI)
    for axial in (0.7 * Pe, 0.0, -0.5 * Pe, -0.9 * Pe):
        assert an.lateral_stiffness_column(L, EI, axial) == pytest.approx(an.lateral_stiffness(L, EI, axial), rel=1e-6)
    assert an.lateral_stiffness(L, EI, 0.3 * Pe) > 3 * EI / L**3 > an.lateral_stiffness(L, EI, -0.3 * Pe)


def test_critical_load_weightless_and_with_self_weight():
    assert an.critical_tip_load(L, EI) == pytest.approx(np.pi**2 * EI / (4 * L**2), rel=1e-9)
    # classical result (Timoshenko & Gere): a column's own weight counts ~0.3 of its total
    q = 0.05 * an.buckling_load(L, EI) / L
    assert an.critical_tip_load(L, EI, q) == pytest.approx(an.buckling_load(L, EI) - 0.3 * q * L, rel=2e-3)


def test_arc_curvature_recovers_a_circle():
    k = 150.0
    x, y, _ = an.arc_tip_moment(k * EI, L, EI)
    assert an.arc_curvature(x, y) == pytest.approx(k, rel=1e-12)


def test_grip_force_closed_form_has_the_elastic_and_relaxed_limits():
    """DadrasModel.grip_force (the hereditary integral of the back-relaxation) against its two
    limits, from closed forms: with the relaxation switched off (zero = pole) it is
    3 M(t)/(2a) - 3 EI gap / a^3 once in contact, M(t) = Gamma V (1 - exp(-p_e t)), to 1e-6;
    held for 60 s it is 3 Gamma V/(2a) - 3 (EI p/z) gap / a^3 to 1e-6; before contact 0."""
    from dataclasses import replace
    dm = an.DadrasModel()
    EI, a, gap, V = 1 / dm.mechanical_gain, 5e-3, 0.05e-3, 1.0
    gamma = dm.k_tf * EI / dm.electrical_pole
    t = np.linspace(0, 60, 60001)
    F = dm.grip_force(t, np.full(t.size, V), a, gap)
    assert F[-1] == pytest.approx(3 * gamma * V / (2 * a) - 3 * EI * dm.pole / dm.zero * gap / a**3, rel=1e-6)
    elastic = replace(dm, zero=dm.pole)
    Fe = elastic.grip_force(t[:5001], np.full(5001, V), a, gap)
    M = gamma * V * (1 - np.exp(-dm.electrical_pole * t[:5001]))
    ref = np.clip(3 * M / (2 * a) - 3 * EI * gap / a**3, 0, None)
    assert np.max(np.abs(Fe - ref)) < 1e-6 * ref.max()
    assert F[0] == 0 and np.all(F >= -1e-12)
