"""Vertical payloads: lateral stiffness hanging and inverted, and buckling when inverted."""
import numpy as np
import pytest

from mjeap import Payload, Scene, analytical as an

L, EI, M_BEAM = 6e-3, 1 / 4.86e7, 0.695e-6
G = 9.80665
P_E = an.buckling_load(L, EI)


def lateral_stiffness_sim(orientation, payload_mass, representation="hinge"):
    s = Scene("pedot-micro", representation=representation, orientation=orientation,
              payload=Payload(payload_mass, L))
    F = 1e-3 * L * 3 * EI / L**3
    s.settle(tol=1e-10)
    y0 = s.tip_position()[1]
    s.set_tip_force(F)
    s.settle(tol=1e-10)
    return F / (s.tip_position()[1] - y0)


@pytest.mark.parametrize("orientation,sign", [("down", +1), ("up", -1)])
def test_lateral_stiffness_with_vertical_payload(orientation, sign):
    """Payload weight 0.5 x the Euler load at the tip: hanging is stiffer, inverted softer,
    both within 2 % of the column BVP with the beam's own weight included."""
    mass = 0.5 * P_E / G
    k = lateral_stiffness_sim(orientation, mass)
    ref = an.lateral_stiffness_column(L, EI, sign * mass * G, sign * M_BEAM * G / L)
    assert k == pytest.approx(ref, rel=0.02)
    k0 = 3 * EI / L**3
    assert (k > 1.3 * k0) if sign > 0 else (k < 0.75 * k0)


def test_inverted_beam_buckles_at_euler_load():
    """pi^2 EI / (4 L^2) within 3 %: at 0.97 x the critical payload weight the inverted beam
    oscillates about straight after a push, never leaving the push's amplitude (its first
    mode, 0.8 Hz, decays with zeta_1 = 0.05); at 1.03 x it buckles and settles on the
    post-buckled elastica (tip deflection within 3 % of the exact solution). The modal
    analysis agrees."""
    P_cr = an.critical_tip_load(L, EI, M_BEAM * G / L)
    assert P_cr == pytest.approx(P_E, rel=0.03)
    for factor, should_buckle in ((0.97, False), (1.03, True)):
        s = Scene("pedot-micro", orientation="up", payload=Payload(factor * P_cr / G, L))
        assert s.choice.buckled is should_buckle
        s.set_hinge_angles(np.full(20, 1e-3 / 20))  # small push
        y0 = abs(s.tip_position()[1])
        y = []
        for _ in range(30):
            s.run(0.1)
            y.append(s.tip_position()[1])
        tip = s.tip_position()
        if should_buckle:
            x_ref, delta_ref, _ = an.postbuckled_column(factor, L)
            assert abs(tip[1]) == pytest.approx(delta_ref, rel=0.03)
            assert tip[0] == pytest.approx(x_ref, rel=0.03)
        else:
            assert np.max(np.abs(y)) <= 1.01 * y0
            assert np.min(y) < -0.3 * y0          # it swung through straight: a restoring mode


def test_damping_and_timestep_are_continuous_across_the_buckling_load():
    """Standing up, 0.99 / 0.999 / 1.001 / 1.01 x the critical payload: the first mode's rate
    (frequency below the load, the straight column's growth rate above it) goes to zero
    like sqrt|1 - P/P_cr| from both sides, and the Rayleigh coefficient and timestep with it:
    neighbours across the load differ by less than 2 x (they jumped ~100 x), and the
    timestep stays below 1/50 of the elastic period however close the load is."""
    P_cr = an.critical_tip_load(L, EI, M_BEAM * G / L)
    choices = [Scene("pedot-micro", orientation="up", payload=Payload(f * P_cr / G, L)).choice
               for f in (0.99, 0.999, 1.001, 1.01)]
    assert [c.buckled for c in choices] == [False, False, True, True]
    below, near_below, near_above, above = choices
    assert near_below.first_frequency < 0.4 * below.first_frequency
    assert near_above.first_frequency < 0.4 * above.first_frequency
    ratio = near_above.rayleigh_beta / near_below.rayleigh_beta
    assert 0.5 < ratio < 2.0
    assert 0.5 < near_above.timestep / near_below.timestep < 2.0
    for c in choices:
        assert c.timestep <= c.accuracy_limit


def test_timestep_converges_near_the_buckling_load():
    """0.999 x the critical payload standing up: T_1 = 6.6 s, so T_1 / 50 would be 0.13 s
    and the answer unconverged. A push released for 1 s: the default timestep and a
    quarter of it give the same tip deflection within 0.5 % of the push's, every 0.1 s."""
    P_cr = an.critical_tip_load(L, EI, M_BEAM * G / L)
    payload = Payload(0.999 * P_cr / G, L)
    default = Scene("pedot-micro", orientation="up", payload=payload)
    fine = Scene("pedot-micro", orientation="up", payload=payload, timestep=default.timestep / 4)
    paths = []
    for s in (default, fine):
        s.set_hinge_angles(np.full(20, 1e-3 / 20))
        y0, y = s.tip_position()[1], []
        for _ in range(10):
            s.run(0.1)
            y.append(s.tip_position()[1])
        paths.append(np.array(y) / y0)
    assert np.all(paths[0] > 0.5) and paths[0][-1] < 0.7      # slow mode: ~cos(2 pi 0.15 Hz t)
    assert np.max(np.abs(paths[0] - paths[1])) < 0.005
