"""Drives compiled into MJCF (mjeap.drives.native) against the lockstep loop, the reference.

Tolerance: 1e-3 of the tip-curvature swing (the component issue's 0.1 %). The native
rc-relaxation drive integrates its Maxwell arms with MuJoCo's semi-implicit step where the
loop steps the relaxation exactly (zero-order hold): both are first order in h z
(z = 0.52 1/s, h < 1 ms), so they differ by ~1e-4 of the swing; the open-loop drives
apply the same moments through a tendon and agree to round-off (checked at 1e-9)."""
import subprocess
import sys
import textwrap

import mujoco
import numpy as np
import pytest

from mjeap import Scene, rollout, rollout_batch
from mjeap.assets import ASSET_DIR
from mjeap.drives import make_drive
from mjeap.errors import ParameterError
from mjeap.model.fields import read_units
from mjeap.validation import golden

CASES = [  # actuator, scene kwargs, waveform, duration s, initial curvature 1/m, tolerance (of the swing)
    ("pedot-micro", {"orientation": "up", "payload": "12.6mg@6.27mm"}, "square:1.5V@0.1Hz", 20.0, -303.0, 1e-3),
    pytest.param("pedot-micro", {}, "step:3V", 5.0, 0.0, 1e-3, marks=pytest.mark.slow),
    ("pzt-hamr-small", {}, "sine:20V@500Hz,offset=100V", 0.01, 0.0, 1e-9),
    ("ppy-trilayer", {}, "square:0.5V@0.5Hz", 3.0, 0.0, 1e-9),
]


@pytest.mark.parametrize("actuator,kw,wave,duration,k0,tol", CASES)
def test_native_follows_the_loop(actuator, kw, wave, duration, k0, tol):
    s = Scene(actuator, **kw)
    a = rollout(s, wave, duration, initial_curvature=k0, engine="loop")
    final_loop, qfrc_loop = s.tip_curvature(), s.data.qfrc_applied.copy()
    b = rollout(s, wave, duration, initial_curvature=k0, engine="native")
    assert b.meta["engine"] == "native"
    np.testing.assert_array_equal(a.time, b.time)
    swing = np.ptp(a.tip_curvature)
    assert np.max(np.abs(a.tip_curvature - b.tip_curvature)) <= tol * swing
    assert set(a.signals) == set(b.signals)
    for k in a.signals:   # the drive's own signals too (currents, charge, moments)
        x, y = a.signals[k], b.signals[k]
        assert np.max(np.abs(x - y)) <= max(tol, 2e-3) * (np.ptp(x) + np.abs(x).max()) + 1e-300, k
    # the scene is left in the run's final state (its beam dofs) with the last step's
    # moments applied, as the loop leaves it
    assert abs(s.tip_curvature() - final_loop) <= tol * swing
    np.testing.assert_allclose(s.data.qfrc_applied, qfrc_loop, rtol=max(tol, 1e-3), atol=0)


@pytest.mark.parametrize("actuator_id", ["pedot-micro", "ppy-trilayer", "pzt-hamr-small"])
def test_native_matches_the_golden_trajectories(actuator_id):
    """The loop engine's golden trajectories (tests/golden), on the native engine, within
    the native criterion (1e-3 of the range, see the module docstring)."""
    t_ref, k_ref = golden.read(golden.FOLDER, actuator_id)
    t, k = golden.simulate(actuator_id, engine="native")
    assert np.max(np.abs(k - k_ref)) <= 1e-3 * np.ptp(k_ref)


@pytest.mark.cable
def test_auto_picks_native_and_says_why_not_otherwise():
    r = rollout(Scene("pedot-micro"), "step:1V", 0.05)
    assert r.meta["engine"] == "native"
    r = rollout(Scene("pedot-micro", representation="cable"), "step:1V", 0.02)
    assert r.meta["engine"] == "loop" and "fixed tendon" in r.meta["engine_reason"]
    r = rollout(Scene("pvdf-60"), "step:300V", 0.01, drive_params={"stiffening": False})
    assert r.meta["engine"] == "threaded" and "quadratic" in r.meta["engine_reason"]


@pytest.mark.parametrize("actuator,kw,params,words", [
    ("pedot-micro", {"representation": "cable"}, {}, "fixed tendon"),
    ("pvdf-60", {}, {"stiffening": False}, "quadratic"),
    ("ppy-trilayer", {}, {"stiffness_table": [(0.0, 1.0), (1.0, 1.5)]}, "stiffness table")])
def test_native_is_refused_with_the_reason(actuator, kw, params, words):
    s = Scene(actuator, **kw)
    with pytest.raises(ParameterError, match=words):
        rollout(s, "step:0.1V", 0.01, drive_params=params, engine="native")


def test_native_batch_on_two_threads_equals_one_by_one():
    s = Scene("pedot-micro", orientation="up", payload="6.3mg@6.7mm")
    waves = ["square:1V@0.5Hz", "square:1.5V@0.5Hz", "sine:1V@1Hz"]
    batch = rollout_batch(s, waves, 2.0, initial_curvatures=[-100.0, 0.0, 50.0], nthread=2)
    assert all(r.meta["engine"] == "native" for r in batch)
    for w, k0, r in zip(waves, [-100.0, 0.0, 50.0], batch):
        one = rollout(s, w, 2.0, initial_curvature=k0, engine="native")
        np.testing.assert_array_equal(one.tip_curvature, r.tip_curvature)


@pytest.mark.cable
def test_generated_models_carry_units_and_the_drive():
    m = mujoco.MjModel.from_xml_path(str(ASSET_DIR / "pedot-micro_hinge.xml"))
    u = read_units(m)
    assert (u.length, u.mass, u.time) == (1e-3, 1e-6, 1.0)        # seconds: the viewer's real time
    a = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_ACTUATOR, "drive")
    assert a >= 0 and tuple(m.actuator_ctrlrange[a]) == (-3.0, 3.0)
    assert m.actuator_dyntype[a] == mujoco.mjtDyn.mjDYN_FILTEREXACT
    assert m.actuator_dynprm[a, 0] * u.time == pytest.approx(1 / 1.8)          # 1 / p_elec, s
    cable = mujoco.MjModel.from_xml_path(str(ASSET_DIR / "pedot-micro_cable.xml"))
    assert read_units(cable) is not None and cable.nu == 0                     # no native form


PLAIN_MUJOCO = textwrap.dedent('''
    # no mjeap here: MuJoCo, numpy and scipy only
    import sys, mujoco, numpy as np
    from scipy import signal
    m = mujoco.MjModel.from_xml_path(sys.argv[1])
    i = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_NUMERIC, "mjeap_units")
    L, M, T = m.numeric_data[m.numeric_adr[i]:m.numeric_adr[i] + 3]
    d = mujoco.MjData(m)
    clamp = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, "clamp")
    tip = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, "tip")
    d.ctrl[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_ACTUATOR, "drive")] = 3.0     # volts
    every = max(1, int(round(0.01 / (m.opt.timestep * T))))
    t, kappa = [], []
    while d.time * T < 15.0:
        mujoco.mj_step(m, d, nstep=every)
        mujoco.mj_kinematics(m, d)
        R = d.xmat[clamp].reshape(3, 3)
        x, y, _ = R.T @ (d.site_xpos[tip] - d.xpos[clamp]) * L                  # clamp frame, m
        t.append(d.time * T)
        kappa.append(2 * y / (x * x + y * y))                                     # arc through clamp and tip
    t, kappa = np.array(t), np.array(kappa)
    # Dadras et al. 2021, eq. (8): K/V = 63 (s + 0.52) / ((s + 0.3)(s + 1.8)), 3 V step from rest
    _, ref = signal.step(signal.TransferFunction([63.0, 63.0 * 0.52], np.polymul([1, 0.3], [1, 1.8])), T=t)
    ref = 3.0 * ref
    print(np.sqrt(np.mean((kappa - ref) ** 2)) / np.ptp(ref))
''')


@pytest.mark.slow
def test_plain_mujoco_moves_the_generated_file_as_eq8_says(tmp_path):
    """The generated pedot-micro file in plain MuJoCo (a subprocess that imports no mjeap):
    ctrl = 3 V for 15 s; the curvature of the arc through clamp and tip follows eq. (8)'s
    step response within 1 % RMS of the swing."""
    script = tmp_path / "plain.py"
    script.write_text(PLAIN_MUJOCO)
    out = subprocess.run([sys.executable, "-I", str(script), str(ASSET_DIR / "pedot-micro_hinge.xml")],
                         capture_output=True, text=True, check=True, cwd=tmp_path)
    assert float(out.stdout.strip()) < 0.01


def test_native_model_is_checked_for_stability():
    """The Maxwell arms' explicit tendon springs must not destabilise the scene's timestep:
    the spectral radius of the native step map is checked when it is built."""
    s = Scene("pedot-micro", orientation="up", payload="12.6mg@6.27mm")
    nat = s.native_model(make_drive(None, s))
    from mjeap.model.modes import linearize, spectral_radius
    rho = spectral_radius(linearize(nat.model), nat.model.dof_damping, nat.model.opt.timestep, "implicitfast")
    assert rho <= 1.0
    assert nat.model.nv == 2 * s.layout.segments and nat.model.nu == 1


def test_tip_loads_ride_along_in_the_native_engine():
    """A dead tip force on the scene acts in the native model too (xfrc_applied goes with the
    controls of mujoco.rollout): the same settling under P L^2/EI = 0.5 as the loop."""
    s = Scene("pedot-micro", gravity=False, damping_ratio=0.7)
    s.set_tip_force(0.5 * 2.058e-8 / 6e-3**2)
    a = rollout(s, "step:0.5V", 0.05, engine="loop")
    b = rollout(s, "step:0.5V", 0.05, engine="native")
    assert b.meta["engine"] == "native" and np.ptp(a.tip_curvature) > 0
    assert np.max(np.abs(a.tip_curvature - b.tip_curvature)) <= 1e-3 * np.ptp(a.tip_curvature)


def test_the_native_form_follows_hand_set_hinges_and_not_a_leftover_stiffness_scale():
    """The native model starts from the hinges as built or identified: Dadras et al. 2021's drive once
    rebuilt its springs and Maxwell arms from the catalog (an identified stiffness did nothing
    on the native engine), and a stiffness scale a loop run left behind (Mutlu et al. 2013's
    stiffness table) was compiled into the cached native model. Reference: the loop engine,
    the Python drive on the scene's own model."""
    from mjeap import Scene, rollout
    s = Scene("pedot-micro", segments=8)
    s.set_hinge_parameters(stiffness=2 * s.layout.hinge_stiffness)
    loop = rollout(s, "step:1V", 0.5, engine="loop")
    native = rollout(s, "step:1V", 0.5, engine="native")
    swing = np.ptp(loop.tip_curvature)
    assert np.max(np.abs(native.tip_curvature - loop.tip_curvature)) < 1e-3 * swing
    p = Scene("ppy-trilayer", segments=8)
    rollout(p, "step:1V", 0.2, engine="loop", drive_params={"stiffness_table": [(0, 1), (1, 2)]})
    loop = rollout(p, "step:1V", 0.2, engine="loop")
    native = rollout(p, "step:1V", 0.2, engine="native")
    swing = np.ptp(loop.tip_curvature)
    assert np.max(np.abs(native.tip_curvature - loop.tip_curvature)) < 1e-3 * swing
