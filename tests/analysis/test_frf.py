"""The small-signal frequency response (mjeap.analysis.frf, mjeap frf) against independent
references.

- A uniform bimorph (Harvard's stack, widths equal, no tip block): the Euler-Bernoulli
  cantilever's beta_1 L = 1.8751 and beta_2 L = 4.6941 with EI from Jafferis 2015's layer
  formula D and mu from the layers' densities; the quasi-static tip per volt Gamma L^2 / (2 EI)
  of a uniform moment Gamma = f31 w (t_p + t_cf) per volt of V_sig (Wood 2005 / Jafferis 2015,
  the free deflection with V = 2 V_eff, l_r = 0); the admittance below resonance
  omega (C + Gamma^2 L / EI), the dielectric capacitance plus the motional charge per volt of a
  uniform moment (the rotation of the tip, Gamma L / EI, times Gamma).
- Time-domain sine runs of the tapered catalog bimorph (a different method: MuJoCo stepping
  the drive), steady state over whole periods, below, at and above resonance.
- The ionic drive against seed 000's eq. (8) and its RC admittance; the blocking-force drive
  against its first-order force.
"""
import dataclasses
import json

import numpy as np
import pytest

from mjeap import Scene
from mjeap.analysis.frf import SmallSignalModel, frequency_response, sweep_limit
from mjeap.analysis.frequency import sine_sweep
from mjeap.errors import ParameterError
from mjeap.model import analytical as an
from mjeap.model.catalog import get_actuator

from harvard import F31, stack

#: Euler-Bernoulli cantilever eigenvalues beta_n L (Erturk & Inman 2011, Table 3.1)
BETA_L = (1.87510407, 4.69409113)


def uniform_bimorph(width=3.5e-3):
    """pzt-hamr-small's stack on a uniform planform without a tip block."""
    base = get_actuator("pzt-hamr-small")
    p = dataclasses.replace(base.planform, base_width=width, tip_width=width, extension_length=0.0,
                            extension_mass=0.0, residual_tip_mass=0.0)
    return dataclasses.replace(base, id="uniform-bimorph", planform=p)


def closed_forms(act):
    """(EI N m^2, mu kg/m, Gamma N m/V) of the uniform bimorph from Harvard's formulas."""
    t_p, t_cf, E_p, E_cf = stack(act)
    w = act.planform.base_width
    EI = an.bimorph_stiffness_per_width(E_p, t_p, E_cf, t_cf) * w
    mu = w * sum(l.thickness * l.density for l in act.layers)
    return EI, mu, F31 * w * (t_p + t_cf)


def eb_frequency(n, act):
    EI, mu, _ = closed_forms(act)
    return BETA_L[n] ** 2 / (2 * np.pi) * np.sqrt(EI / (mu * act.length ** 4))


@pytest.fixture(scope="module")
def uniform_model():
    act = uniform_bimorph()
    return act, SmallSignalModel(Scene(act, segments=40, gravity=False, damping_ratio=0.001))


def test_resonances_of_a_uniform_bimorph_against_beta_1_and_beta_2(uniform_model):
    """The admittance's first and second maxima against beta_1 and beta_2 (0.5 %; measured
    -0.01 % and -0.15 %, the latter the chain's rotary inertia). Damping 0.1 % on the first
    mode: the maximum of |Y| sits below the mode by an amount growing with the mode's damping
    ratio, zeta_2 = zeta_1 f_2 / f_1 under Rayleigh damping (-1.0 % at zeta_1 = 0.5 %)."""
    act, m = uniform_model
    f1, f2 = eb_frequency(0, act), eb_frequency(1, act)
    fr1, fa1, _ = m.resonances(0.5 * f1, 2 * f1)
    fr2, _, _ = m.resonances(0.7 * f2, 1.3 * f2)
    assert fr1 == pytest.approx(f1, rel=0.005)
    assert fr2 == pytest.approx(f2, rel=0.005)
    assert fr1 < fa1 < f2


def test_quasi_static_tip_and_admittance_of_a_uniform_bimorph(uniform_model):
    """At f_1 / 100: tip per volt of V_sig within 1 % of Gamma L^2 / (2 EI) (measured 9e-5, the
    dynamic amplification (1/100)^2), the admittance within 2 % of omega (C + Gamma^2 L / EI)
    (measured 3e-5) and its phase 90 deg (a capacitance; R = 1 GOhm)."""
    act, m = uniform_model
    EI, _, gamma = closed_forms(act)
    C, L = m.small_signal.capacitance, act.length
    f = eb_frequency(0, act) / 100
    tip, y = m.respond([f])
    assert abs(tip[0]) == pytest.approx(gamma * L ** 2 / (2 * EI), rel=0.01)
    assert abs(y[0]) == pytest.approx(2 * np.pi * f * (C + gamma ** 2 * L / EI), rel=0.02)
    assert np.degrees(np.angle(y[0])) == pytest.approx(90.0, abs=0.5)
    # the same closed form's free deflection (Wood / Jafferis, V = 2 V_eff per volt of V_sig)
    t_p, t_cf, E_p, E_cf = stack(act)
    D = an.bimorph_stiffness_per_width(E_p, t_p, E_cf, t_cf)
    assert abs(tip[0]) == pytest.approx(an.bimorph_free_deflection(F31, 2.0, t_p, t_cf, L, 0.0, D), rel=0.01)


@pytest.mark.slow
def test_against_time_domain_sine_runs_below_at_and_above_resonance():
    """pzt-hamr-small (tapered, tip block) driven by 20 V sines about V_bias/2 at 0.3, 0.8, 1,
    1.2 and 2 f_1: the tip's and the current's phasors over 10 whole periods after 5 time
    constants, per volt, against the small-signal model. The sample's deflection is the one
    after the step its voltage was held over: its phasor is taken back one step. The runs
    converge on the model with the step: at h/4 within 1 % and 1 deg (measured 0.7 %, 0.6 deg
    at resonance), each quantity's largest error at h/4 under half its largest at h (measured
    3 %, 2.3 deg at h)."""
    errors = []
    for div in (1, 4):
        s0 = Scene("pzt-hamr-small")
        s = Scene("pzt-hamr-small", timestep=s0.timestep / div)
        model = SmallSignalModel(s)
        fs = np.array([0.3, 0.8, 1.0, 1.2, 2.0]) * s.choice.first_frequency
        sw = sine_sweep(s, fs, offset=100.0, amplitude=20.0, cycles=10)
        tip, y = model.respond(fs)
        ht = sw.response("tip_deflection") * np.exp(-2j * np.pi * fs * s.timestep) / tip
        hy = sw.response("current (A)") / y
        errors.append(np.array([np.abs(np.abs(ht) - 1), np.abs(np.degrees(np.angle(ht))),
                                np.abs(np.abs(hy) - 1), np.abs(np.degrees(np.angle(hy)))]))
    coarse, fine = errors
    assert np.all(fine[[0, 2]] < 0.01), fine
    assert np.all(fine[[1, 3]] < 1.0), fine
    assert np.all(fine.max(axis=1) < 0.5 * coarse.max(axis=1)), (coarse, fine)


def test_ionic_drive_against_seed_000_eq_8_and_its_rc_admittance():
    """pedot-micro (rc-relaxation: RC charging and the back-relaxation inside the beam) at
    0.05-2 Hz, far below its first mode: tip per volt against eq. (8)'s curvature per volt times
    the arc's L^2 / 2 (2 %: the arc's small-deflection tip), the admittance against the double
    layer's C p s / (s + p) (1e-9)."""
    s = Scene("pedot-micro", gravity=False)
    m = SmallSignalModel(s)
    p = m.drive.params
    fs = np.array([0.05, 0.3, 2.0])
    assert fs.max() < s.choice.first_frequency / 20
    tip, y = m.respond(fs)
    w = 2j * np.pi * fs
    kappa = p["gain"] * (w + p["zero"]) / ((w + p["pole_mechanical"]) * (w + p["pole_electrical"]))
    np.testing.assert_allclose(np.abs(tip), np.abs(kappa) * s.length ** 2 / 2, rtol=0.02)
    np.testing.assert_allclose(np.angle(tip), np.angle(kappa), atol=0.02)
    ref = p["capacitance"] * p["pole_electrical"] * w / (w + p["pole_electrical"])
    np.testing.assert_allclose(y, ref, rtol=1e-9)
    fr, fa, why = m.resonances(0.01, 5.0)
    assert fr is None and "no maximum" in why


def test_a_drive_without_current_leaves_the_admittance_empty_and_says_why(tmp_path):
    """blocking-force: the tip follows (2/3) F_1 L / (1 + i omega tau) as a uniform moment
    (quasi-static: the arc's tip M L^2 / (2 EI), 2 %); frf.csv's admittance cells are empty
    and frf.json and the command's stderr say why."""
    from mjeap.cli import main
    r = frequency_response("ppy-trilayer", 0.01, 0.5, 5, gravity=False)
    drv = SmallSignalModel(Scene("ppy-trilayer", gravity=False)).drive
    F1, tau, L = drv.params["blocking_force_per_volt"], drv.params["time_constant"], drv.L
    EI = float(drv.scene.actuator.flexural_rigidity_at(0.0)[0])
    ref = 2 / 3 * F1 * L / (1 + 2j * np.pi * r.frequency * tau) * L ** 2 / (2 * EI)
    np.testing.assert_allclose(np.abs(r.tip_per_volt), np.abs(ref), rtol=0.02)
    assert r.admittance is None and "models no current" in r.admittance_reason
    out = tmp_path / "frf"
    assert main(["frf", "ppy-trilayer", "--from", "10mHz", "--to", "0.5Hz", "--points", "5", "--out", str(out)]) == 0
    rows = (out / "frf.csv").read_text().splitlines()
    assert rows[0] == "frequency (Hz),tip_per_volt (m/V),tip_phase (deg),admittance (S),admittance_phase (deg)"
    assert all(r.endswith(",,") for r in rows[1:]) and len(rows) == 6
    assert "models no current" in json.loads((out / "frf.json").read_text())["admittance"]


@pytest.mark.slow
def test_mjeap_frf_writes_the_csv_the_json_and_the_bode_plot(tmp_path):
    """The command's files: frf.csv with the issue's columns, 2 kHz = 2000 Hz, the resonance
    in frf.json equal to the Python API's, frf.png (the report extra)."""
    from mjeap.cli import main
    pytest.importorskip("matplotlib")
    out = tmp_path / "o"
    assert main(["frf", "pzt-hamr-small", "--from", "200Hz", "--to", "4kHz", "--points", "50", "--out", str(out)]) == 0
    data = np.genfromtxt(out / "frf.csv", delimiter=",", names=True)
    assert len(data) == 50 and data["frequency_Hz"][-1] == pytest.approx(4000.0)
    summary = json.loads((out / "frf.json").read_text())
    r = frequency_response("pzt-hamr-small", "200Hz", "4kHz", 50)
    assert summary["resonance_frequency_hz"] == pytest.approx(r.resonance_frequency, rel=1e-9)
    assert summary["coupling_factor"] == pytest.approx(np.sqrt(1 - (r.resonance_frequency / r.antiresonance_frequency) ** 2))
    assert (out / "frf.png").read_bytes()[:4] == b"\x89PNG"


@pytest.mark.parametrize("args, name", [
    (("2kHz", "1kHz", 10), "--from"), (("1kHz", "1kHz", 10), "--from"), (("100Hz", "1kHz", 1), "--points"),
    (("100Hz", "1kHz", "2.5"), "--points"), (("-1Hz", "1kHz", 10), "--from"), (("1V", "1kHz", 10), "--from"),
    (("100Hz", "1MHz", 10), "--to")])
def test_bad_sweeps_are_refused_naming_the_parameter(args, name):
    with pytest.raises(ParameterError) as e:
        frequency_response("pzt-hamr-small", *args)
    assert e.value.name == name


def test_the_limit_names_the_nyquist_frequency_or_the_highest_mode():
    """Above 1 / (2 dt) (or the chain's highest mode, with few segments and a small step) is
    refused with that limit in the message."""
    s = Scene("pzt-hamr-small")
    limit, why = sweep_limit(s)
    assert limit == pytest.approx(0.5 / s.timestep) and "Nyquist" in why
    with pytest.raises(ParameterError, match="Nyquist"):
        frequency_response(s, 100.0, 1.01 * limit, 10)
    s2 = Scene("pzt-hamr-small", segments=3, timestep=1e-7)
    limit2, why2 = sweep_limit(s2)
    assert limit2 == pytest.approx(s2.choice.highest_frequency) and "highest resolved mode" in why2


def test_an_operating_point_without_gain_is_refused():
    """The electrostrictive moment is quadratic in V: about 0 V it has no small-signal gain
    (refused, naming the offset); about 500 V the quasi-static tip per volt is 2 M(500 V) / 500
    over the stiffness of a uniform moment (2 %)."""
    with pytest.raises(ParameterError, match="moment per volt is zero"):
        frequency_response("pvdf-60", 0.1, 1.0, 5)
    s = Scene("pvdf-60", gravity=False)
    r = frequency_response(s, 0.01, 0.1, 3, offset=500.0)
    m = SmallSignalModel(s, operating_voltage=500.0).drive.moment(500.0)
    EI = float(s.actuator.flexural_rigidity_at(0.0)[0])
    assert abs(r.tip_per_volt[0]) == pytest.approx(2 * m / 500.0 * s.length ** 2 / (2 * EI), rel=0.02)
    assert r.admittance is None


def test_the_sweep_metrics_are_the_frequency_responses():
    """resonance_frequency, antiresonance_frequency, coupling_factor, tip_per_volt_at: the same
    numbers as frequency_response, with no rollout; refused with the reason where the drive
    draws no current."""
    from mjeap.studies.sweep import STATIC_METRICS, evaluate
    names = ["resonance_frequency", "antiresonance_frequency", "coupling_factor", "tip_per_volt_at"]
    assert set(names) <= STATIC_METRICS
    row = evaluate({"actuator": "pzt-hamr-small", "frequency": 500.0, "offset": 100.0}, names)
    assert row["error"] == ""
    r = frequency_response("pzt-hamr-small", 500.0, 4000.0, 2)
    assert row["resonance_frequency"] == pytest.approx(r.resonance_frequency, rel=1e-6)
    assert row["antiresonance_frequency"] == pytest.approx(r.antiresonance_frequency, rel=1e-6)
    assert row["coupling_factor"] == pytest.approx(r.coupling_factor, rel=1e-5)
    assert row["tip_per_volt_at"] == pytest.approx(abs(r.tip_per_volt[0]), rel=1e-9)
    bad = evaluate({"actuator": "ppy-trilayer", "frequency": 0.5}, ["resonance_frequency"])
    assert "models no current" in bad["error"]


def test_the_rod_is_refused_with_the_reason():
    from mjeap.model.mjcf import BUILDERS
    if BUILDERS["rod"].unavailable_reason():
        pytest.skip(BUILDERS["rod"].unavailable_reason())
    with pytest.raises(ParameterError, match="rod"):
        frequency_response("pzt-hamr-small", 100.0, 1000.0, 5, representation="rod")


def test_a_drive_of_ones_own_plugs_in_and_a_bad_model_is_named():
    """A user drive that states a uniform moment per volt is answered like the built-in ones
    (the quasi-static tip of a uniform moment, Gamma L^2 / (2 EI), 1 %); one whose
    small_signal returns something else is refused naming the drive; one without is refused
    naming it too."""
    from mjeap.drives import Drive, SmallSignal, register_drive, DRIVES

    class Plain(Drive):
        name = "test-plain-moment"
        GENERIC_PARAMETERS = {"gain": (1e-6, "N m/V", "test")}

        def step(self, voltage, dt):
            self.part.set_internal_moments(self.params["gain"] * voltage)

        def small_signal(self, operating_voltage):
            return SmallSignal(operating_voltage, "V", np.full(self.scene.layout.segments, self.params["gain"]),
                               current=False, no_current="test drive")

    class Broken(Plain):
        name = "test-broken-moment"

        def small_signal(self, operating_voltage):
            return {"moment_per_volt": 1.0}

    class Silent(Plain):
        name = "test-silent-moment"
        small_signal = Drive.small_signal

    try:
        for cls in (Plain, Broken, Silent):
            register_drive(cls)
        act = uniform_bimorph()
        s = Scene(act, gravity=False)
        EI, _, _ = closed_forms(act)
        r = frequency_response(s, 1.0, 2.0, 2, drive="test-plain-moment")
        assert abs(r.tip_per_volt[0]) == pytest.approx(1e-6 * act.length ** 2 / (2 * EI), rel=0.01)
        with pytest.raises(ParameterError, match="test-broken-moment"):
            frequency_response(s, 1.0, 2.0, 2, drive="test-broken-moment")
        with pytest.raises(ParameterError, match="test-silent-moment.*states none"):
            frequency_response(s, 1.0, 2.0, 2, drive="test-silent-moment")
    finally:
        for name in ("test-plain-moment", "test-broken-moment", "test-silent-moment"):
            DRIVES.pop(name, None)
