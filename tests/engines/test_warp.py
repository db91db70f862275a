"""The warp engine (mjeap.engines.warp) on Warp's CPU device against the native engine, the
reference: the same native model, MuJoCo Warp in float32 against MuJoCo in float64.

Tolerance: 1e-3 of the tip-curvature swing (float32 round-off over the run; measured
1.2e-6 over 2204 steps). The 1.5 s pass step 1215, where MuJoCo Warp's own step went NaN on
this scene (its solver's float32 factor of the mass matrix alone; the engine steps without
the solver where no constraint row can arise, mjeap.engines.warp). Skipped only where mujoco-warp is not installed (the ``warp``
extra; CI installs it); the kernels compile once into Warp's kernel cache
(``WARP_CACHE_PATH``, ~50 s on 2 cores), later runs load them."""
from importlib.util import find_spec

import numpy as np
import pytest

from mjeap import Scene, rollout, rollout_batch
from mjeap.engines import get_engine
from mjeap.errors import ParameterError


def needs_warp():
    """Skip where mujoco-warp is not installed (the ``warp`` extra), and only there."""
    pytest.importorskip("mujoco_warp")

#: Dadras et al. 2021's main job (README), shortened: standing up, the 12.6 mg payload at 6.27 mm,
#: square 0.1 Hz from the measured initial curvature; 16 amplitudes as a map's axis
SCENE = {"orientation": "up", "payload": "12.6mg@6.27mm"}
AMPLITUDES = np.linspace(0.25, 1.5, 16)
DURATION, K0 = 1.5, -303.0


@pytest.mark.slow
def test_warp_batch_follows_the_native_engine():
    needs_warp()
    s = Scene("pedot-micro", **SCENE)
    volts = [f"square:{a:.6g}V@0.1Hz" for a in AMPLITUDES]
    ref = rollout_batch(s, volts, DURATION, initial_curvatures=K0, engine="native")
    got = rollout_batch(s, volts, DURATION, initial_curvatures=K0, engine="warp")
    assert got[0].meta["engine"] == "warp" and got[0].meta["warp"]["float"] == "float32"
    assert "mjDSBL_AUTORESET" in got[0].meta["warp"]["cleared"]
    worst = 0.0
    for a, b in zip(ref, got):
        np.testing.assert_array_equal(a.time, b.time)
        swing = np.ptp(a.tip_curvature)
        assert swing > 20.0                 # 1/m: the runs move (up to 165 1/m over 1.5 s)
        dev = np.max(np.abs(a.tip_curvature - b.tip_curvature))
        worst = max(worst, dev / swing)
        assert dev <= 1e-3 * swing
        assert set(a.signals) == set(b.signals)
        for k in a.signals:
            x, y = a.signals[k], b.signals[k]
            assert np.max(np.abs(x - y)) <= 1e-3 * (np.ptp(x) + np.abs(x).max()), k
    # the scene is left in the last run's final state, as the native engine leaves it
    assert abs(s.tip_curvature() - ref[-1].tip_curvature[-1]) <= 1e-3 * np.ptp(ref[-1].tip_curvature)
    print(f"warp vs native, 16 runs: worst deviation {worst:.3g} of the swing")


@pytest.mark.slow
def test_piezo_on_warp_follows_the_native_engine():
    """The piezo bimorph's native form on Warp: its motional current is read from the state
    before each sampled step (native_signals' ``before``), so the read-back of both states is
    checked too. Measured: 2.2e-7 of the swing, motional current within 6.2e-7 of its range."""
    needs_warp()
    s = Scene("pzt-hamr-small")
    a = rollout(s, "sine:20V@500Hz,offset=100V", 0.01, engine="native")
    b = rollout(s, "sine:20V@500Hz,offset=100V", 0.01, engine="warp")
    assert np.max(np.abs(a.tip_curvature - b.tip_curvature)) <= 1e-3 * np.ptp(a.tip_curvature)
    for k in ("current (A)", "current_motional (A)"):
        assert np.max(np.abs(a.signals[k] - b.signals[k])) <= 1e-3 * np.ptp(a.signals[k]), k


@pytest.mark.slow
def test_one_rollout_on_warp_says_what_it_cleared():
    needs_warp()
    s = Scene("pedot-micro")
    a = rollout(s, "step:3V", 0.05, engine="native")
    b = rollout(s, "step:3V", 0.05, engine="warp")
    assert b.meta["warp"]["cleared"]["mjDSBL_AUTORESET"]
    assert np.max(np.abs(a.tip_curvature - b.tip_curvature)) <= 1e-3 * np.ptp(a.tip_curvature)


@pytest.mark.rod
def test_warp_refuses_the_rod_before_any_work():
    """The rod's flex: refused in the engine's words, installed or not."""
    with pytest.raises(ParameterError, match="rod's flex under the discrete integrator"):
        rollout(Scene("pedot-micro", representation="rod"), "step:1V", 0.01, engine="warp")


def test_warp_refuses_what_it_cannot_run_before_any_work():
    """Refused by the engine's own words, before a step or a kernel, installed or not: a
    drive stepped from Python (PVDF's electrostrictive drive: no native form), a controller;
    without mujoco-warp, the extra to install."""
    with pytest.raises(ParameterError, match="electrostrictive drive is stepped from Python"):
        rollout_batch(Scene("pvdf-60"), ["sine:100V@1Hz"], 0.01, engine="warp")
    with pytest.raises(ParameterError, match="controller"):
        rollout(Scene("pedot-micro"), None, 0.01, engine="warp", controller=lambda t, s: 1.0)
    assert get_engine("warp").batched
    if find_spec("mujoco_warp") is None:
        with pytest.raises(ParameterError, match=r"pip install -e \".\[warp\]\""):
            rollout_batch(Scene("pedot-micro"), ["step:1V"], 0.01, engine="warp")
