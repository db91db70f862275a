"""Static tip loads on the simulated beams against the elastica and the exact arc."""
import numpy as np
import pytest

from mjeap import Scene, analytical as an
from mjeap.validation.mechanics import settled as settled_tip

ACT = "pedot-micro"
L, EI = 6e-3, 1 / 4.86e7


@pytest.fixture(scope="module", params=["hinge", "cable", "rod"])
def scene(request):
    return Scene(ACT, representation=request.param)


@pytest.mark.parametrize("load", [0.05, 0.5, 1.0, 2.0, 3.0])
def test_tip_force_matches_elastica_within_1_percent(scene, load):
    """P L^2 / EI from 0.05 to 3 at the default 20 segments: tip position within 1 % of
    the elastica (deflection relative to itself, axial shortening relative to L)."""
    P = load * EI / L**2
    tip = settled_tip(scene, force=P)
    ref = an.elastica_tip_force(P, L, EI)
    assert tip[1] == pytest.approx(ref.tip[1], rel=0.01)
    assert abs(tip[0] - ref.tip[0]) < 0.01 * L
    assert scene.tip_angle() == pytest.approx(ref.tip_angle, rel=0.01)


@pytest.mark.parametrize("kl", [0.3, 1.2, 2.0])
def test_tip_moment_bends_exact_arc(scene, kl):
    """A tip couple M gives curvature M/EI; tip within 0.5 % of the exact arc (the rod:
    -0.25 % at kappa L = 2, its 2 tan(theta/2) curvature; the hinge chain +0.08 %)."""
    M = kl * EI / L
    tip = settled_tip(scene, moment=M)
    x, y, th = an.arc_tip_moment(M, L, EI)
    assert np.hypot(tip[0] - x, tip[1] - y) < 0.005 * np.hypot(x, y)
    assert scene.tip_curvature() == pytest.approx(kl / L, rel=0.005)


@pytest.mark.parametrize("representation", ["hinge", "cable", "rod"])
def test_convergence_is_second_order(representation):
    """Tip deflection error against the elastica (P L^2/EI = 1) falls as N^-2 (measured:
    hinge 2.001, rod 2.003)."""
    P = EI / L**2
    ref = an.elastica_tip_force(P, L, EI).tip[1]
    Ns = [4, 8, 16, 32]
    errs = [abs(settled_tip(Scene(ACT, representation=representation, segments=N), force=P)[1] - ref) / ref
            for N in Ns]
    order = -np.polyfit(np.log(Ns), np.log(errs), 1)[0]
    assert errs[-1] < errs[0] / 50
    assert 1.8 < order < 2.3, (errs, order)


def test_tapered_bimorph_matches_nonuniform_beam_theory():
    """Trapezoidal PZT bimorph (EI linear in x) with its rigid tip block: small force at the
    block's end, deflection there against P int_0^L (L + l_ext - x)^2 / EI(x) dx (Castigliano),
    quadrature by scipy."""
    from scipy.integrate import quad
    s = Scene("pzt-hamr-large")
    act = s.actuator
    P = 1e-3
    end = act.length + act.planform.extension_length
    ref = P * quad(lambda x: (end - x) ** 2 / act.flexural_rigidity_at(x)[0], 0, act.length)[0]
    tip = settled_tip(s, force=P)
    assert tip[1] == pytest.approx(ref, rel=0.005)
