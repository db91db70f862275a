"""Dadras et al. 2021: the PEDOT actuator's RC + back-relaxation drive against eqs. (7) and (8)."""
import json

import numpy as np
import pytest
from scipy import signal

from mjeap import Payload, Scene, rollout

TF8 = signal.TransferFunction([63.0, 63.0 * 0.52], np.polymul([1, 0.3], [1, 1.8]))  # eq. (8)


def test_step_response_follows_eq7():
    """3 V step from kappa(0-) = -174 1/m: within 2 % RMS of the swing over 0-15 s of
    eq. (7), kappa(t) = 181 - 90 exp(-1.8 t) - 265 exp(-0.3 t) (the paper's fitted curve)."""
    r = rollout(Scene("pedot-micro"), "step:3V", 15.0, initial_curvature=-174.0, progress=False)
    ref = 181 - 90 * np.exp(-1.8 * r.time) - 265 * np.exp(-0.3 * r.time)
    swing = ref.max() - ref.min()
    assert np.sqrt(np.mean((r.tip_curvature - ref) ** 2)) < 0.02 * swing
    assert r.tip_curvature[0] == pytest.approx(-174.0, abs=0.5)


@pytest.mark.parametrize("vpp", [2.0, 3.0])
@pytest.mark.slow
def test_square_wave_matches_transfer_function(vpp):
    """0.1 Hz square wave from rest: peak-to-peak tip curvature over the second period
    within 2 % of scipy.signal.lsim of eq. (8); the whole trajectory within 2 % RMS."""
    r = rollout(Scene("pedot-micro"), f"square:{vpp / 2}V@0.1Hz", 20.0, progress=False)
    _, ref, _ = signal.lsim(TF8, r.voltage, r.time)
    late = r.time >= 10.0
    p2p_sim = np.ptp(r.tip_curvature[late])
    p2p_ref = np.ptp(ref[late])
    assert p2p_sim == pytest.approx(p2p_ref, rel=0.02)
    assert np.sqrt(np.mean((r.tip_curvature - ref) ** 2)) < 0.02 * p2p_ref


# Table II of Dadras et al. 2021: payload (kg), l_e (m), initial curvature at 2 and 3 Vpp (1/m)
TABLE_II = [(3.15e-6, 6.20e-3, -133.0, -132.0), (6.30e-6, 6.70e-3, -156.0, -241.0),
            (12.60e-6, 6.27e-3, -209.0, -303.0)]


def payload_runs():
    out = []
    for m, le, k2, k3 in TABLE_II:
        for vpp, k0 in ((2.0, k2), (3.0, k3)):
            s = Scene("pedot-micro", orientation="up", payload=Payload(m, le))
            r = rollout(s, f"square:{vpp / 2}V@0.1Hz", 20.0, initial_curvature=k0, progress=False)
            out.append((m, le, vpp, k0, r))
    return out


@pytest.mark.slow
def test_payloads_inverted_stay_finite_and_increase_the_swing(capsys):
    """Each Table II payload, actuator standing up, 0.1 Hz square wave of 2 and 3 Vpp from
    the table's initial curvature: finite, and a larger peak-to-peak tip curvature in the
    second period than the unloaded actuator at the same voltage (the payload's weight is
    positive feedback). The numbers are printed for the validation issue."""
    unloaded = {vpp: np.ptp(rollout(Scene("pedot-micro", orientation="up"), f"square:{vpp / 2}V@0.1Hz", 20.0,
                                    progress=False).tip_curvature[-2000:]) for vpp in (2.0, 3.0)}
    rows = []
    for m, le, vpp, k0, r in payload_runs():
        assert np.all(np.isfinite(r.tip_curvature))
        late = r.time >= 10.0
        p2p = float(np.ptp(r.tip_curvature[late]))
        rows.append({"payload_mg": m * 1e6, "l_e_mm": le * 1e3, "vpp": vpp, "kappa0": k0,
                     "p2p_per_m": round(p2p, 1), "unloaded_p2p_per_m": round(float(unloaded[vpp]), 1)})
        assert p2p > 1.02 * unloaded[vpp]
    with capsys.disabled():
        print("\nDadras et al. 2021 payload runs (second period):\n" + json.dumps(rows, indent=1))


def test_direct_step_is_the_general_step(monkeypatch):
    """Dadras et al. 2021's drive writes its moments straight into the hinge chain's qfrc_applied
    (Part.direct_bending); the general path (set_internal_moments and the state vector) must
    give the same run: curvature, tip and every signal, with gravity, a payload and a
    square wave, to rounding."""
    from mjeap.simulation.part import ActuatorPart

    def run():
        s = Scene("pedot-micro", orientation="up", payload=Payload(40e-6, 6.27e-3), segments=8)
        r = rollout(s, "square:1.5V@0.5Hz", 2.0, engine="loop", initial_curvature=-100.0, progress=False)
        return s, r

    s, direct = run()
    assert s.part.direct_bending() is not None
    monkeypatch.setattr(ActuatorPart, "direct_bending", lambda self: None)
    _, general = run()
    swing = np.ptp(general.tip_curvature)
    assert np.max(np.abs(direct.tip_curvature - general.tip_curvature)) < 1e-9 * swing
    assert np.allclose(direct.tip_position, general.tip_position, rtol=0, atol=1e-12)
    for k, g in general.signals.items():
        assert np.allclose(direct.signals[k], g, rtol=1e-9, atol=1e-12 * np.max(np.abs(g))), k


@pytest.mark.parametrize("representation", ["cable", "rod"])   # cable on MuJoCo 3.x, rod on 4.x
def test_direct_step_only_where_the_moments_are_the_joints_own(representation):
    """The cable's and the rod's bending is not a hinge joint's own dof and stiffness (their
    moments follow the geometry): no direct path there (the general one runs)."""
    assert Scene("pedot-micro", representation=representation, segments=8).part.direct_bending() is None


def test_direct_step_follows_the_stiffness_a_native_run_leaves():
    """A loop run, new hinge stiffness, a native run (which leaves the loop drive in its
    state), then steps from Python (an environment's advance): the direct path must use the
    new stiffness, as the general path does."""
    import mujoco
    from mjeap.engines.loop import advance
    from mjeap.drives import make_drive
    s = Scene("pedot-micro", segments=6)
    d = make_drive("rc-relaxation", s)
    rollout(s, "square:1V@0.5Hz", 0.5, drive=d, engine="loop", progress=False)
    s.part.set_hinge_parameters(stiffness=2 * s.part.hinge_stiffness())
    rollout(s, "square:1V@0.5Hz", 0.5, drive=d, engine="native", progress=False)
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    state = np.empty(mujoco.mj_stateSize(s.model, spec))
    mujoco.mj_getState(s.model, s.data, state, spec)
    saved_s, saved_k, direct = d._s.copy(), d._k.copy(), d._direct
    assert direct is not None
    out = []
    for path in (direct, None):
        mujoco.mj_setState(s.model, s.data, state, spec)
        d._s[:], d._k = saved_s, saved_k.copy()
        d._apply()
        d._direct = path
        advance(s.model, s.data, d, 1.0, s.timestep, 2000)
        s.update_kinematics()
        out.append(s.part.tip_curvature())
    assert out[0] == pytest.approx(out[1], rel=1e-9)


def test_signals_after_a_rebind_are_the_general_paths():
    """Direct steps, then the scene's data replaced (the general path takes over): the
    relaxation moment must come from the general path, not from the old data's forces."""
    import mujoco
    from mjeap.drives import make_drive
    s = Scene("pedot-micro", segments=8)

    def go(rebind):
        s.reset()
        d = make_drive("rc-relaxation", s)
        d.reset(0.0)
        for _ in range(50):
            d.step(1.0, s.timestep)
            mujoco.mj_step(s.model, s.data)
        if rebind:
            new = mujoco.MjData(s.model)
            mujoco.mj_copyData(new, s.model, s.data)
            s.data = new
        for _ in range(50):
            d.step(1.0, s.timestep)
            mujoco.mj_step(s.model, s.data)
        return d.signals()

    a, b = go(False), go(True)
    for k in a:
        assert b[k] == pytest.approx(a[k], rel=1e-6, abs=1e-18), k
