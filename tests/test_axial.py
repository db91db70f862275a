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
    returns after a push; at 1.03 x it buckles and settles on the post-buckled elastica
    (tip deflection within 3 % of the exact solution). The modal analysis agrees."""
    P_cr = an.critical_tip_load(L, EI, M_BEAM * G / L)
    assert P_cr == pytest.approx(P_E, rel=0.03)
    for factor, should_buckle in ((0.97, False), (1.03, True)):
        s = Scene("pedot-micro", orientation="up", payload=Payload(factor * P_cr / G, L))
        assert s.choice.buckled is should_buckle
        s.set_hinge_angles(np.full(20, 1e-3 / 20))  # small push
        y0 = abs(s.tip_position()[1])
        s.run(3.0)
        tip = s.tip_position()
        if should_buckle:
            x_ref, delta_ref, _ = an.postbuckled_column(factor, L)
            assert abs(tip[1]) == pytest.approx(delta_ref, rel=0.03)
            assert tip[0] == pytest.approx(x_ref, rel=0.03)
        else:
            assert abs(tip[1]) < 0.01 * y0
