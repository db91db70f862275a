"""mjeap identify piezo (mjeap.analysis.piezo_fit): a piezo bender identified from stroke,
tip-FRF and impedance data, each a different measurement of a known truth.

The stroke is measured the way a bench does it, by settled time-domain runs at several
voltages (not the small-signal model); the FRF and the admittance come from `mjeap frf` of
the truth file, rewritten in other units (kHz, um/V, mS). The Type II run on Jayaram et al.
2018's published numbers is checked against the catalog's tip-mass calibration (scipy brentq
on the scene's first mode: a different method) and Table 2's capacitance.
"""
import dataclasses
import json

import numpy as np
import pytest

from mjeap import Scene, rollout
from mjeap.cli import main
from mjeap.errors import ParameterError
from mjeap.model.actuator import Actuator, Sourced
from mjeap.model.catalog import get_actuator
from mjeap.analysis.file_fit import scaled_actuator
from mjeap.analysis.frf import frequency_response
from mjeap.analysis.piezo_fit import PiezoData, fit_piezo

from pathlib import Path

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "jayaram2018"


def truth():
    return dataclasses.replace(get_actuator("pzt-hamr-small"), damping_ratio=Sourced(0.03, "-", "test truth"))


def perturbed(act):
    """f31 x 0.8, moduli x 0.9, residual tip mass x 1.5, damping ratio 0.05, C x 1.3."""
    dp = dict(act.drive_parameters)
    w = scaled_actuator(act, stiffness=0.9, damping_ratio=0.05)
    return dataclasses.replace(w, planform=dataclasses.replace(w.planform,
                                                               residual_tip_mass=1.5 * w.planform.residual_tip_mass),
                               drive_parameters={**dp, "f31": (0.8 * dp["f31"][0], "", "guess"),
                                                 "capacitance": (1.3 * dp["capacitance"][0], "", "guess")})


def stroke_by_settled_runs(act, volts=(40.0, 80.0, 120.0, 160.0)):
    out = []
    for v in volts:
        s = Scene(act)
        rollout(s, f"step:{v}V", 10 / s.choice.first_frequency, progress=False)
        s.settle(tol=1e-11)
        out.append(float(s.tip_position()[1]))
    return np.array(volts), np.array(out)


@pytest.mark.slow
def test_stroke_frf_and_impedance_identify_the_truth(tmp_path, capsys):
    """All three measurements: f31, EI(x), the tip block's mass, the damping ratio and the
    capacitance of the truth within 1 % (measured within 0.1 %), each with its source; the
    identified file's own f1 and stroke per volt within 1 % of the truth's."""
    t = truth()
    v, d = stroke_by_settled_runs(t)
    stroke = tmp_path / "stroke.csv"
    stroke.write_text("voltage (V),stroke (um)\n" + "\n".join(f"{float(a)!r},{float(b) * 1e6!r}" for a, b in zip(v, d)))
    tf = tmp_path / "truth.toml"
    t.to_file(tf)
    assert main(["frf", str(tf), "--from", "300Hz", "--to", "5kHz", "--points", "60", "--out", str(tmp_path / "f")]) == 0
    rows = np.genfromtxt(tmp_path / "f" / "frf.csv", delimiter=",", skip_header=1)
    sweep = tmp_path / "sweep.csv"
    sweep.write_text("frequency (kHz),tip_per_volt (um/V),tip_phase (deg),admittance (mS),admittance_phase (deg)\n" +
                     "\n".join(",".join(repr(float(x)) for x in (r[0] / 1e3, r[1] * 1e6, r[2], r[3] * 1e3, r[4]))
                               for r in rows))
    mine = tmp_path / "mine.toml"
    perturbed(t).to_file(mine)
    out = tmp_path / "identified.toml"
    capsys.readouterr()
    assert main(["identify", "piezo", str(mine), "--stroke", str(stroke), "--frf", str(sweep), "--impedance", str(sweep),
                 "--out", str(out)]) == 0
    report = json.loads(capsys.readouterr().out)
    assert set(report["identified"]) == {"coupling", "stiffness", "tip_mass", "damping_ratio", "capacitance"}
    ident = Actuator.from_file(out)
    for k in ("f31", "capacitance"):
        assert ident.drive_parameters[k][0] == pytest.approx(t.drive_parameters[k][0], rel=0.01), k
        assert ident.drive_parameters[k][2].startswith("identified from stroke"), k
    x = np.linspace(0, t.length, 5)
    np.testing.assert_allclose(ident.flexural_rigidity_at(x), t.flexural_rigidity_at(x), rtol=0.01)
    assert ident.planform.tip_block_mass == pytest.approx(t.planform.tip_block_mass, rel=0.01)
    assert ident.damping_ratio.value == pytest.approx(0.03, rel=0.01)
    a, b = Scene(ident), Scene(t)
    assert a.choice.first_frequency == pytest.approx(b.choice.first_frequency, rel=0.01)
    ra, rb = frequency_response(a, 10.0, 20.0, 2), frequency_response(b, 10.0, 20.0, 2)
    assert abs(ra.tip_per_volt[0]) == pytest.approx(abs(rb.tip_per_volt[0]), rel=0.01)


def test_what_the_data_can_tell_apart():
    """An FRF through resonance with 1 % noise (magnitude) and 0.5 deg (phase) tells a modulus
    scale from a tip mass: the quasi-static gain is Gamma / EI, f1 ~ sqrt(EI / m) and the mass
    line above resonance ~ Gamma / m; each comes back within 5 % and 2.5 of its reported 1-sigma
    (measured: the tip mass 3.6 % off, 1.2 sigma; the coupling and the stiffness 1.1 %). A stroke
    and a resonance alone (Gamma / EI and EI / m) cannot: the stiffness is held with the reason,
    f1 is fitted by the tip mass (0.1 %) and the stroke per volt by the coupling (1 %)."""
    t = truth()
    f1 = Scene(t).choice.first_frequency
    r = frequency_response(Scene(t), 300.0, 3000.0, 80)
    rng = np.random.default_rng(0)
    h = r.tip_per_volt * (1 + 0.01 * rng.normal(size=80)) * np.exp(1j * np.radians(0.5) * rng.normal(size=80))
    fit = fit_piezo(Scene(perturbed(t)), PiezoData(frf=(r.frequency, h, True)))
    want = {"stiffness": 1 / 0.9, "coupling": 1 / 0.8, "damping_ratio": 0.03,
            "tip_mass": t.planform.tip_block_mass / perturbed(t).planform.tip_block_mass}
    for k, w in want.items():
        assert fit.values[k] == pytest.approx(w, rel=0.05), k
        assert abs(fit.values[k] - w) < 2.5 * fit.std[k], k       # the reported 1-sigma covers the error
    v = np.array([40.0, 80.0, 120.0, 160.0])
    fit = fit_piezo(Scene(perturbed(t)), PiezoData(stroke=(v, abs(r.tip_per_volt[0]) * (v - 100.0)), resonance=f1))
    assert "stiffness" not in fit.values and "modulus scale" in fit.held["stiffness"]
    assert fit.derived["first_frequency_hz"] == pytest.approx(f1, rel=0.001)
    assert fit.derived["quasi_static_tip_per_volt_m_per_v"] == pytest.approx(abs(r.tip_per_volt[0]), rel=0.01)


def test_jayaram_type_ii_published_numbers(tmp_path, capsys):
    """Table 1's 1750 Hz and section 3's fixed capacitance (Table 2's K_C1 times Table 1's
    area, 7.76 nF) on the physical set: the capacitance comes out as the paper's (1e-9), the
    tip block's mass as the catalog's calibration of the same resonance by brentq on the
    scene's first mode (0.2 %), the modulus held with the reason (one resonance cannot tell it
    from a tip mass), and the identified file resonates at 1750 Hz (0.2 %)."""
    from mjeap.analysis.calibration import calibrate_tip_mass
    out = tmp_path / "type2.toml"
    assert main(["identify", "piezo", str(EXAMPLES / "type2-physical.toml"), "--resonance", "1750Hz", "--impedance",
                 str(EXAMPLES / "type2-fixed-capacitance.csv"), "--impedance-state", "fixed", "--out", str(out)]) == 0
    captured = capsys.readouterr()
    report = json.loads(captured.out)
    assert "f1 fitted by the tip block mass" in captured.err
    assert set(report["identified"]) == {"tip_mass", "capacitance"} and "stiffness" in report["held"]
    ident = Actuator.from_file(out)
    assert ident.drive_parameters["capacitance"][0] == pytest.approx(2.41e5 * 1e-9 * 32.2e-6, rel=1e-3)
    cal = calibrate_tip_mass(Actuator.from_file(EXAMPLES / "type2-physical.toml"), 1750.0)
    assert ident.planform.tip_block_mass == pytest.approx(cal.actuator.planform.tip_block_mass, rel=0.002)
    assert Scene(ident).choice.first_frequency == pytest.approx(1750.0, rel=0.002)


def test_refusals_before_any_work(tmp_path, capsys):
    """No measurement; a drive it does not fit (an ionic file: identify step); an unknown unit
    in a column; each exit code 2 with the reason, nothing written."""
    out = tmp_path / "x.toml"
    assert main(["identify", "piezo", "pzt-hamr-small", "--out", str(out)]) == 2
    assert "at least one of --stroke, --frf, --impedance" in capsys.readouterr().err
    assert main(["identify", "piezo", "pedot-micro", "--resonance", "3Hz", "--out", str(out)]) == 2
    assert "use mjeap identify step" in capsys.readouterr().err
    bad = tmp_path / "s.csv"
    bad.write_text("voltage (V),stroke (furlongs)\n0,0\n100,1\n")
    assert main(["identify", "piezo", "pzt-hamr-small", "--stroke", str(bad), "--out", str(out)]) == 2
    assert "column 'stroke (furlongs)'" in capsys.readouterr().err
    assert not out.exists()
    with pytest.raises(ParameterError, match="at least one"):
        fit_piezo(Scene("pzt-hamr-small"), PiezoData())


def test_a_coupling_given_on_the_command_line_is_kept():
    """--param f31=... keeps f31 as given: the coupling is not fitted, the FRF then fits the
    stiffness to the quasi-static gain (Gamma / EI with Gamma as given)."""
    t = truth()
    r = frequency_response(Scene(t), 300.0, 3000.0, 40)
    fit = fit_piezo(Scene(perturbed(t)), PiezoData(frf=(r.frequency, r.tip_per_volt, True)),
                    drive_params={"f31": 32.0})
    assert "coupling" not in fit.values and "given on the command line" in fit.held["coupling"]
    assert fit.values["stiffness"] == pytest.approx(1 / 0.9, rel=0.01)


@pytest.mark.slow
def test_a_laminates_coupling_is_identified_as_its_layers_d31(tmp_path, capsys):
    """drive = "piezo": the stroke of a unimorph whose d31 is 1.2 x its file's, measured by
    settled runs (not the small-signal model), identifies every piezo layer's d31 x 1.2; the
    written file reproduces the stroke."""
    src = Path(__file__).resolve().parents[2] / "examples" / "actuators" / "pzt-unimorph.toml"
    mine = tmp_path / "uni.toml"
    mine.write_text(src.read_text())
    base = get_actuator(str(mine))
    layers = [dataclasses.replace(l, d31=1.2 * (l.d31 if l.d31 is not None else -190e-12)) if l.role == "piezo"
              else l for l in base.layers]
    truth_act = dataclasses.replace(base, layers=tuple(layers), source_file=None)
    v, d = stroke_by_settled_runs(truth_act, volts=(20.0, 40.0, 60.0, 80.0))
    stroke = tmp_path / "stroke.csv"
    stroke.write_text("voltage (V),stroke (um)\n" + "".join(f"{a},{b * 1e6}\n" for a, b in zip(v, d)))
    out = tmp_path / "id.toml"
    assert main(["identify", "piezo", str(mine), "--stroke", str(stroke), "--out", str(out)]) == 0
    found = get_actuator(str(out))
    ratio = [a.d31 / (b.d31 if b.d31 is not None else -190e-12) for a, b in zip(found.layers, base.layers)
             if a.role == "piezo"]
    assert ratio and all(r == pytest.approx(1.2, rel=1e-2) for r in ratio)
