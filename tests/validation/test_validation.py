"""The validation machinery (mjeap validate) and the analytical references it adds."""
import json

import numpy as np
import pytest
from scipy import signal

from mjeap import analytical as an
from mjeap.cli import main
from mjeap.validation import REGISTRY, Experiment, run_validation
from mjeap.validation.core import PUBLISHED_NUMBER, REFERENCE_KINDS

EQ8 = signal.TransferFunction([63.0, 63.0 * 0.52], np.polymul([1, 0.3], [1, 1.8]))


def test_dadras_model_unloaded_is_eq8():
    """Without payload the piecewise model is eq. (8): a square wave from rest equals
    scipy lsim to 1e-6 (both exact ZOH), and the 3 V step from -174 1/m is eq. (7) within
    its rounding (1 1/m)."""
    m = an.DadrasModel()
    t = np.arange(0, 20, 1e-3)
    v = 1.5 * np.where((0.1 * t) % 1 < 0.5, 1.0, -1.0)
    k, regions = m.response(t, v)
    _, ref, _ = signal.lsim(EQ8, v, t, interp=False)
    assert np.max(np.abs(k - ref)) < 1e-6 * np.ptp(ref)
    k7, _ = m.response(t, 3 * np.ones_like(t), kappa0=-174.0)
    assert np.max(np.abs(k7 - (181 - 90 * np.exp(-1.8 * t) - 265 * np.exp(-0.3 * t)))) < 1.0


def test_dadras_model_switches_regions_with_continuous_curvature():
    """12.6 mg, 3 Vpp from -303 1/m starts in Region 1 (kappa l_e < -1.05... here -1.9) and
    passes through 2, 3, 4; the curvature carries over at every switch (no jump larger than
    the largest step-to-step change inside a region)."""
    m = an.DadrasModel()
    t = np.arange(0, 20, 1e-3)
    v = 1.5 * np.where((0.1 * t) % 1 < 0.5, 1.0, -1.0)
    k, regions = m.response(t, v, 12.6e-6, 6.27e-3, -303.0)
    assert regions[0] == 1 and {1, 2, 3, 4} <= set(regions)
    dk = np.abs(np.diff(k))
    switch = np.flatnonzero(np.diff(regions) != 0)
    edges = np.flatnonzero(np.diff(v) != 0)
    inside = np.setdiff1d(np.arange(len(dk)), np.concatenate([switch, edges]))
    assert dk[switch].max() <= dk[inside].max()


def test_region3_pole_is_the_closed_loop_pole():
    """Closed loop of g (s + z)/(s + p) with positive feedback f: its pole from numpy.roots
    of (s + p) - g f (s + z) equals DadrasModel.region3_pole; it reaches 0 at marginal_mass."""
    m = an.DadrasModel()
    for mass in (3.15e-6, 12.6e-6, 40e-6):
        f, _ = m.region_coefficients(mass, 6.27e-3, 3)
        g = m.mechanical_gain
        root = np.roots([1 - g * f, m.pole - g * f * m.zero])[0]
        assert m.region3_pole(mass, 6.27e-3) == pytest.approx(root, rel=1e-12)
    assert m.region3_pole(m.marginal_mass(6.27e-3), 6.27e-3) == pytest.approx(0.0, abs=1e-12)


def test_critical_load_with_arm_between_the_two_euler_loads():
    L, EI = 6e-3, 1 / 4.86e7
    assert an.critical_load_with_arm(L, EI, 0.0) == pytest.approx(an.buckling_load(L, EI))
    P = an.critical_load_with_arm(L, EI, 1e-3)
    assert an.buckling_load(L + 1e-3, EI) < P < an.buckling_load(L, EI)
    k = np.sqrt(P / EI)
    assert k * 1e-3 * np.tan(k * L) == pytest.approx(1.0, rel=1e-9)


def test_variable_section_frequency_matches_uniform_closed_form():
    L, EI, m = 6e-3, 1 / 4.86e7, 0.695e-6
    f = an.first_frequency_variable(L, lambda x: EI + 0 * x, lambda x: m / L + 0 * x, 150.0)
    assert f == pytest.approx(an.natural_frequencies(L, EI, m / L, n=1)[0], rel=1e-6)


def test_run_validation_writes_report_json_figures_and_recordings(tmp_path):
    exps = run_validation(["mechanics-section", "mutlu2013-identify"], out=tmp_path, progress=False)
    assert all(e.passed for e in exps)
    doc = json.loads((tmp_path / "validation.json").read_text())
    assert doc["passed"] and [e["name"] for e in doc["experiments"]] == ["mechanics-section", "mutlu2013-identify"]
    assert all(c["source"] for e in doc["experiments"] for c in e["checks"])
    assert all(c["kind"] in REFERENCE_KINDS for e in doc["experiments"] for c in e["checks"] if c["tolerance"] is not None)
    md = (tmp_path / "report.md").read_text()
    assert "joint stiffness k" in md
    for e in exps:
        assert (tmp_path / f"{e.name}.rrd").stat().st_size > 0
    from mjeap.io.recording import read_recording
    ents = read_recording(tmp_path / "mutlu2013-identify.rrd")
    assert "/checks" in ents and any(k.startswith("/tip_deflection") for k in ents)


def test_report_links_a_figure_for_every_experiment_with_curves(tmp_path):
    """An experiment without curves (mechanics-section) must not switch the figures off for
    the ones after it."""
    pytest.importorskip("matplotlib")
    run_validation(["mechanics-section", "mutlu2013-identify"], out=tmp_path, progress=False)
    md = (tmp_path / "report.md").read_text()
    assert "![mutlu2013-identify](mutlu2013-identify.png)" in md and "need matplotlib" not in md
    assert (tmp_path / "mutlu2013-identify.png").is_file() and not (tmp_path / "mechanics-section.png").exists()


def test_validate_exits_nonzero_when_a_toleranced_check_fails(tmp_path, capsys):
    def broken(quick=False):
        ex = Experiment("zz-broken", "a check that must fail")
        ex.check("answer", "-", 41.0, 42.0, "Adams 1979", tolerance=0.01, kind=PUBLISHED_NUMBER)
        ex.check("comparison only", "-", 1.0, 2.0, "a paper")
        return ex
    REGISTRY["zz-broken"] = broken
    try:
        assert main(["validate", "zz-broken", "--out", str(tmp_path), "--quiet"]) == 1
        out = capsys.readouterr().out
        assert "FAIL zz-broken: answer" in out and "1 fail" in out
    finally:
        del REGISTRY["zz-broken"]


def test_a_toleranced_check_names_its_reference_kind():
    """Issue 22: a row with a tolerance says what its reference is (a published number, a
    published formula or an independent solution); without it, or with another word, the
    row is refused. A comparison row needs none."""
    ex = Experiment("zz-kinds", "kinds")
    with pytest.raises(ValueError, match="kind"):
        ex.check("answer", "-", 41.0, 42.0, "Adams 1979", tolerance=0.01)
    with pytest.raises(ValueError, match="kind"):
        ex.check("answer", "-", 41.0, 42.0, "Adams 1979", tolerance=0.01, kind="restated derivation")
    assert ex.check("answer", "-", 41.0, 42.0, "Adams 1979", tolerance=0.01, kind=PUBLISHED_NUMBER).kind == PUBLISHED_NUMBER
    assert ex.check("comparison only", "-", 1.0, 2.0, "a paper").verdict == "compare"


def test_unknown_experiment_is_named(capsys):
    assert main(["validate", "nonsense", "--quiet"]) == 2
    assert "experiment" in capsys.readouterr().err
