"""mjeap.model.lti.lsim against scipy.signal.lsim (the per-sample reference it replaces)."""
import numpy as np
import pytest
from scipy import signal

from mjeap.model.lti import lsim

SYSTEMS = [signal.TransferFunction([63.0, 63.0 * 0.52], np.polymul([1.0, 0.3], [1.0, 1.8])),  # Dadras et al. 2021 eq. 8
           signal.TransferFunction([2.0], [0.01, 1.0]),                                          # fast first order
           signal.TransferFunction([3.0, 0.9], [1.0, 0.52])]                                     # proper (D != 0)


@pytest.mark.parametrize("interp", [True, False])
@pytest.mark.parametrize("k", range(len(SYSTEMS)))
def test_lsim_equals_scipy(k, interp):
    """Same output as scipy's lsim from rest, to 1e-9 of its swing, on a square wave with
    noise starting at a nonzero value (the first-order hold's initial state)."""
    rng = np.random.default_rng(k)
    t = 0.3 + 0.004 * np.arange(3000)
    u = 1.5 * np.sign(np.sin(2 * np.pi * 0.1 * t + 0.2)) + 0.1 * rng.standard_normal(len(t))
    ref = signal.lsim(SYSTEMS[k], u, t, interp=interp)[1]
    assert np.max(np.abs(lsim(SYSTEMS[k], u, t, interp) - ref)) < 1e-9 * np.ptp(ref)


def test_lsim_nonuniform_grid_falls_back_to_scipy():
    t = np.r_[0.0, 0.01, 0.03, 0.04]
    u = np.ones(4)
    with pytest.raises(ValueError):            # scipy refuses a non-uniform grid, and so do we
        lsim(SYSTEMS[0], u, t)


@pytest.mark.parametrize("n", [2, 3])
@pytest.mark.parametrize("interp", [True, False])
def test_lsim_on_the_shortest_grids_equals_scipy(n, interp):
    """A rollout sampled only at its start and end gives two samples: still scipy's answer."""
    t, u = np.linspace(0.0, 0.05, n), np.linspace(1.0, 2.0, n)
    for system in SYSTEMS:
        ref = signal.lsim(system, u, t, interp=interp)[1]
        assert np.max(np.abs(lsim(system, u, t, interp) - ref)) < 1e-12 * max(np.ptp(ref), 1.0)
