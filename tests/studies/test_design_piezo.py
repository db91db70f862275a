"""Design round 2 (issue 42): the numbers a designer reads at the operating point and at the
limits, and never a silent answer.

- The issue's command (free_deflection under a sine) is refused before any work, naming
  stroke; no metric is read at an arbitrary instant of a periodic run (each metric is
  classified here, so that a new one must be too).
- Constraints carry units; a unit that does not match, an unknown --pareto metric: refused.
- A field-limited optimum: maximising the free deflection of a bimorph at a fixed voltage
  thins its plates until the field V / t_p reaches the limit, t_p* = V / E_max (the free
  deflection falls with t_p here: checked on the closed form), found within 1 %; its
  sensitivity to the limit is d delta / d t_p x dt_p*/dE_max = -V / E_max^2 d delta / d t_p, by
  central differences of the drive's closed form.
- The Pareto front, optimize.png, and mjeap show's first numbers against the transformed
  section (tests/test_piezo_laminate.py's closed forms).
"""
import importlib.util
import json
import warnings
from pathlib import Path

import numpy as np
import pytest

import mjeap
from mjeap import Scene
from mjeap.model import variants as design
from mjeap.studies import sweep
from mjeap.cli import main
from mjeap.drives import make_drive
from mjeap.errors import ParameterError, UnknownNameError
from mjeap.studies.sweep import metrics as M

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "actuators"
HAMR = str(EXAMPLES / "laminate" / "pzt-hamr-small.toml")
EPS0 = 8.8541878128e-12

ISSUE_COMMAND = ["optimize", "pzt-hamr-small", "--vary", "actuator.length=6mm:12mm", "--maximize", "free_deflection",
                 "--voltage", "sine:50V@100Hz,offset=100V", "--duration", "0.05"]


def _no_work(monkeypatch):
    monkeypatch.setattr(sweep, "evaluate", lambda *a, **k: pytest.fail("an evaluation ran"))
    monkeypatch.setattr(sweep.runner, "evaluate", lambda *a, **k: pytest.fail("an evaluation ran"))


# ---------------------------------------------------------------- periodic runs have no final value
def test_the_issues_command_is_refused_before_any_work_naming_stroke(monkeypatch, tmp_path, capsys):
    _no_work(monkeypatch)
    assert main([*ISSUE_COMMAND, "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert "free_deflection" in err and "stroke" in err and "sine" in err
    assert not list((tmp_path / "o").glob("*")) if (tmp_path / "o").exists() else True


@pytest.mark.parametrize("metric,waveform,match", [
    ("blocked_force", "sine", "stroke"), ("energy_density", "square", "stroke"),
    ("settling_time", "triangle", "a step drive"), ("stroke", "step", "free_deflection")])
def test_a_metric_whose_drive_it_is_not_is_refused_before_any_point(monkeypatch, tmp_path, metric, waveform, match):
    _no_work(monkeypatch)
    base = {"actuator": HAMR, "waveform": waveform, "amplitude": 50.0, "offset": 100.0, "frequency": 100.0,
            "duration": 0.02}
    with pytest.raises(ParameterError, match=match):
        sweep.run_sweep(sweep.grid(amplitude=[40.0, 50.0]), tmp_path / "s.csv", metrics=(metric,), base=base,
                        executor="serial", progress=False)


#: every metric, by what it reads of a periodic run (the rule: never an arbitrary instant)
PERIODIC_READS = {
    "last whole period": {"peak_to_peak", "returns", "stroke", "peak_power", "energy_per_cycle"},
    "the whole run": {"max_stress_proxy", "max_tip_deflection", "max_stress"},
    "no run (the scene, the waveform's extremes)": {"first_frequency", "mass", "max_field", "max_reverse_field",
                                                     "capacitance"},
    "no run (the linearised model's frequency response)": {"resonance_frequency", "antiresonance_frequency",
                                                           "coupling_factor", "tip_per_volt_at"},
    "refused (a step's)": set(M.STEP_ONLY_METRICS),
    "bookkeeping text": {"estimated_error", "stopped_early"},
}


def test_every_metric_reads_a_periodic_run_over_whole_periods_the_whole_run_or_not_at_all():
    classified = set().union(*PERIODIC_READS.values())
    assert classified == set(M.METRICS), f"classify {set(M.METRICS) ^ classified} in PERIODIC_READS"
    assert M.STEP_ONLY_METRICS.keys() == {"free_deflection", "blocked_force", "energy_density", "settling_time"}


def test_a_piezo_metric_of_an_actuator_without_a_piezo_drive_is_refused(monkeypatch, tmp_path):
    _no_work(monkeypatch)
    with pytest.raises(ParameterError, match="max_field.*piezo drive.*blocking-force"):
        sweep.run_sweep(sweep.grid(amplitude=[1.0]), tmp_path / "s.csv", metrics=("max_field",),
                        base={"actuator": "ppy-trilayer"}, executor="serial", progress=False)


# ---------------------------------------------------------------- constraints with units, refusals
def test_constraints_take_units_and_a_wrong_unit_or_unknown_pareto_metric_is_refused(monkeypatch, tmp_path):
    from mjeap.studies.optimize import parse_constraint
    assert parse_constraint("max_field<=1V/um").bound == pytest.approx(1e6)
    assert parse_constraint("capacitance<=12nF").bound == pytest.approx(12e-9)
    _no_work(monkeypatch)
    kw = dict(vary={"actuator.roles.piezo.thickness": ("80um", "150um")}, voltage="step:200V", duration=0.02,
              out=tmp_path / "o")
    with pytest.raises(ParameterError, match=r"max_field.*V/m.*another dimension"):
        mjeap.optimize(HAMR, maximize="free_deflection", subject_to=["max_field<=1mm"], **kw)
    with pytest.raises(UnknownNameError, match=r"metric \(--pareto\) 'strok'.*did you mean 'stroke'"):
        mjeap.optimize(HAMR, pareto="strok,blocked_force", **kw)
    with pytest.raises(ParameterError, match="either a front"):
        mjeap.optimize(HAMR, pareto="free_deflection,blocked_force", maximize="mass", **kw)
    assert not (tmp_path / "o" / "result.json").exists()


# ---------------------------------------------------------------- a field-limited optimum
@pytest.mark.slow
def test_a_field_limited_optimum_is_the_thinnest_plate_the_limit_allows(tmp_path):
    V, e_max = 200.0, 2e6
    t_star = V / e_max

    def closed(t):
        act = design.design_actuator(HAMR, {"actuator.roles.piezo.thickness": t})
        return make_drive(None, Scene(act, segments=10)).free_deflection(V)

    ts = np.linspace(60e-6, 200e-6, 8)
    assert np.all(np.diff([closed(t) for t in ts]) < 0), "the free deflection falls with t_p: the limit binds"
    r = mjeap.optimize(HAMR, {"actuator.roles.piezo.thickness": ("60um", "200um")}, maximize="free_deflection",
                       subject_to=["max_field<=2V/um"], voltage=f"step:{V}V", duration=0.02,
                       base={"segments": 10}, starts=1, out=tmp_path / "o", progress=False)
    assert r.success and r.optimum["actuator.roles.piezo.thickness"] == pytest.approx(t_star, rel=1e-2)
    [c] = r.constraints
    assert c["active"] and c["value"] == pytest.approx(e_max, rel=1e-3)
    [s] = r.sensitivities
    h = 1e-7
    slope = (closed(t_star + h) - closed(t_star - h)) / (2 * h)
    assert s["kind"] == "constraint" and s["sensitivity"] == pytest.approx(-V / e_max**2 * slope, rel=0.05)
    files = json.loads((tmp_path / "o" / "result.json").read_text())["files"]
    if importlib.util.find_spec("matplotlib") is None:                # the optional 'report' extra
        assert "figure" not in files
    else:
        assert Path(files["figure"]).stat().st_size > 10_000


def test_a_box_past_the_field_limit_without_a_field_constraint_is_warned_once(monkeypatch, recwarn):
    """Issue 42: asked for the most stroke, the optimiser thins the plates past PZT-5H's
    field; the box's corners say so once, before any work, naming the layer and field."""
    from mjeap.model.laminate import FieldWarning
    _no_work(monkeypatch)
    with pytest.raises(pytest.fail.Exception):          # the first evaluation: the check came before it
        mjeap.optimize("pzt-hamr-small", {"actuator.roles.piezo.thickness": ("60um", "150um")},
                       maximize="free_deflection", voltage="step:200V", duration=0.02, progress=False)
    told = [w for w in recwarn if issubclass(w.category, FieldWarning)]
    assert len(told) == 1 and "layer pzt-bottom sees 3.33 V/um" in str(told[0].message)
    assert "max_field" in str(told[0].message)


@pytest.mark.slow
def test_a_pareto_front_between_free_deflection_and_blocked_force(tmp_path):
    """Thin plates deflect most, thick ones push hardest: the front runs from the lower bound
    to the upper one, free deflection falling as the blocked force rises; pareto.csv holds
    it with units, pareto.png draws it."""
    pytest.importorskip("matplotlib")
    r = mjeap.optimize(HAMR, {"actuator.roles.piezo.thickness": ("60um", "200um")},
                       pareto="free_deflection,blocked_force", pareto_points=4, voltage="step:200V", duration=0.02,
                       base={"segments": 8}, starts=1, out=tmp_path / "o", progress=False)
    front = [f for f in r.pareto if f["feasible"]]
    assert len(front) == 4
    t = [f["actuator.roles.piezo.thickness"] for f in front]
    # the best blocked force is taken at 0.1 % below its maximum, the best deflection there
    assert t[0] == pytest.approx(60e-6, rel=1e-6) and t[-1] == pytest.approx(200e-6, rel=5e-3)
    assert np.all(np.diff([f["blocked_force"] for f in front]) > 0)
    assert np.all(np.diff([f["free_deflection"] for f in front]) < 0)
    rows = (tmp_path / "o" / "pareto.csv").read_text().splitlines()
    assert rows[0].startswith("free_deflection (m),blocked_force (N),actuator.roles.piezo.thickness (m)")
    assert len(rows) == 5 and (tmp_path / "o" / "pareto.png").stat().st_size > 10_000


# ---------------------------------------------------------------- mjeap show
def test_show_gives_the_unimorphs_first_numbers_from_the_transformed_section(capsys):
    """The PZT-5A unimorph on brass (uniform, no tip block, plane strain by the width rule):
    free deflection over 0-150 V, kappa L^2 / 2; blocked force 3 EI delta / L^3; the free
    capacitance eps0 eps_r A / t; mass and energy density; f1 from the physical set, said so."""
    assert main(["show", str(EXAMPLES / "pzt-unimorph.toml"), "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    L, w, nu = 20e-3, 5e-3, (0.31, 0.34)
    E = np.array([66e9, 100e9]) / (1 - np.array(nu) ** 2)          # plane strain: w >= 5 h
    t = np.array([127e-6, 102e-6])
    z = np.cumsum(t) - t / 2
    zn = np.sum(E * t * z) / np.sum(E * t)
    D = float(np.sum(E * (t**3 / 12 + t * (z - zn) ** 2)))
    S = -190e-12 * 150.0 / 127e-6 * (1 + nu[0])                    # the free strain's stress factor (1 + nu) E_hat
    kappa = E[0] * t[0] * S * (z[0] - zn) / D
    free = kappa * L**2 / 2
    force = 3 * D * w * free / L**3
    mass = w * L * (7950 * 127e-6 + 8500 * 102e-6)
    assert d["free_deflection"][0] == pytest.approx(free, rel=1e-6) and d["free_deflection"][1] == "m"
    assert d["blocked_force"][0] == pytest.approx(force, rel=1e-6)
    assert d["capacitance"][0] == pytest.approx(EPS0 * 1800 * L * w / 127e-6, rel=1e-9)
    assert d["mass"][0] == pytest.approx(mass, rel=1e-9) and "tip block" in d["mass"][2]
    assert d["energy_density"][0] == pytest.approx(force * free / (2 * mass), rel=1e-6)
    assert "resonated 8% to 75% above" in d["first_frequency"][2]
    assert {"first_frequency", "free_deflection", "blocked_force", "capacitance", "blocked_capacitance",
            "energy_density", "mass"} <= set(d)


def test_show_of_a_catalog_bimorph_labels_its_capacitances_and_counts_the_tip_block(capsys):
    assert main(["show", "pzt-hamr-small", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    act = mjeap.Actuator.from_file(HAMR)
    assert d["blocked_capacitance"][0] == 8e-9
    assert "C + Gamma^2" in d["capacitance"][2] and d["capacitance"][0] > 2 * 8e-9
    assert d["mass"][0] == pytest.approx(act.total_mass() + act.planform.tip_block_mass, rel=1e-12)
    assert d["mass"][0] == d["derived"]["mass"][0]
    assert "resonated" not in d["first_frequency"][2]          # the catalog's f1 is fitted to the measurement
    text = capsys.readouterr().out
    assert main(["show", "pzt-hamr-small"]) == 0
    text = capsys.readouterr().out
    assert "Jayaram et al. 2018 measured the fixed (blocked) capacitance" in text


def test_show_warns_of_a_layer_driven_past_its_recommended_field(tmp_path, capsys):
    text = (EXAMPLES / "pzt-unimorph.toml").read_text().replace('"150 V"]', '"300 V"]')
    p = tmp_path / "hot.toml"
    p.write_text(text)
    assert main(["show", str(p)]) == 0
    assert "warning: " in (err := capsys.readouterr().err) and "layer pzt sees 2.36 V/um" in err


# ---------------------------------------------------------------- a sweep past the field limit
def test_a_sweep_says_once_which_points_drive_a_layer_past_its_limit(tmp_path):
    """Issue 42, never a silent answer: a sweep whose points thin the plates below V / E_max
    (200 V over 2 V/um: 100 um) warns once, counting those points; reading max_field, its
    column says it point by point and the sweep is quiet."""
    from mjeap.model.laminate import FieldWarning
    points = sweep.grid(**{"actuator.roles.piezo.thickness": [60e-6, 90e-6, 135e-6]})
    base = {"actuator": HAMR, "waveform": "step", "amplitude": 200.0, "duration": 0.002, "segments": 4}
    with pytest.warns(FieldWarning) as told:
        s = sweep.run_sweep(points, tmp_path / "a.csv", metrics=("free_deflection",), base=base, executor="serial",
                            progress=False)
    assert s.done == 3 and s.failed == 0
    [w] = [w for w in told if issubclass(w.category, FieldWarning)]
    assert str(w.message).startswith("2 of the 3 points run drive a layer past its limit") and "V/um" in str(w.message)
    with warnings.catch_warnings():
        warnings.simplefilter("error", FieldWarning)
        sweep.run_sweep(points, tmp_path / "b.csv", metrics=("max_field",), base=base, executor="serial",
                        progress=False)
    fields = [float(r["max_field"]) for r in sweep.read_results(tmp_path / "b.csv")]
    assert fields == pytest.approx([200 / 60e-6, 200 / 90e-6, 200 / 135e-6], rel=1e-9)
