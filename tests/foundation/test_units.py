"""SI answers do not depend on the internal unit system."""
import numpy as np
import pytest

from mjeap import ParameterError, Payload, Scene, UnitSystem

SYSTEMS = [UnitSystem(1e-3, 1e-6, 1e-3), UnitSystem(1e-3, 1e-6, 1.0), UnitSystem(1e-4, 1e-9, 1e-4),
           UnitSystem(1e-2, 1e-5, 1e-2)]


# Agreement is limited by float round-off only: 1e-9 L for the hinge chain; the cable's
# in-plane/out-of-plane stiffness ratio (w/t)^2 ~ 1.5e3 amplifies round-off, 1e-7 L.
@pytest.mark.parametrize("representation,tol", [("hinge", 1e-9), ("cable", 1e-7)])
def test_static_and_dynamic_answers_are_unit_independent(representation, tol):
    outs = []
    for u in SYSTEMS:
        s = Scene("pedot-micro", representation=representation, orientation="up",
                  payload=Payload(6.3e-6, 6.7e-3), units=u)
        s.set_tip_force(2e-5)
        traj = []
        for _ in range(40):
            s.step(5)
            traj.append(s.tip_position())
        outs.append((s.choice.timestep, s.choice.first_frequency, np.array(traj), s.centreline()))
    ref = outs[0]
    for o in outs[1:]:
        assert o[0] == pytest.approx(ref[0], rel=1e-9)
        assert o[1] == pytest.approx(ref[1], rel=1e-6)
        np.testing.assert_allclose(o[2], ref[2], rtol=0, atol=tol * 6e-3)
        np.testing.assert_allclose(o[3], ref[3], rtol=0, atol=tol * 6e-3)


def test_si_internal_units_are_refused_with_a_reason():
    """In SI the 35 um beam's segment inertias fall below MuJoCo's 1e-15 floor."""
    with pytest.raises(ParameterError, match="units=.*1e-15"):
        Scene("pedot-micro", units=UnitSystem(1.0, 1.0, 1.0))
