"""drive = "piezo" (issue 42): any piezo laminate from datasheet constants, against closed
forms derived here, not from mjeap's code, within 1 %:

- the transformed section (Gere & Timoshenko, Mechanics of Materials, composite beams): with
  every layer as wide as the beam, z_n = sum E_i t_i z_i / sum E_i t_i (z_i each layer's
  mid-plane) and D = sum E_i (t_i^3 / 12 + t_i (z_i - z_n)^2) per width (the parallel-axis
  theorem, not the thesis's eqs. 3.3-3.6 that mjeap.model.section codes);
- free-strain moments about the neutral axis (Timoshenko 1925, the bimetal thermostat, for
  any stack): a layer whose free strain is S_i pulls with E_i t_i S_i at its mid-plane, so
  m = sum E_i t_i S_i (z_i - z_n) per width and the beam bends into an arc kappa = m / D;
  S_i = d31 p_i V_i / t_i (IEEE Std 176 with the field along the poling, p_i = +-1);
- a couple bends an inextensible cantilever into the arc delta = (1 - cos kappa L) / kappa;
  slowly driven (f << f1, the dynamic gain 1 / (1 - (f / f1)^2) ~ 1), the stroke is the
  difference of two such arcs;
- the first frequency of a uniform cantilever, f1 = 1.87510^2 / (2 pi L^2) sqrt(D w / mu)
  (Euler-Bernoulli, e.g. Blevins, Formulas for natural frequency, table 8-1);
- the parallel-plate capacitance eps0 eps_r A / t of each piezo layer, and at zero strain
  (eps33^T - d31^2 E) A / t (a uniaxially stressed layer: D3 = d31 sigma + eps33^T E3 with
  sigma = E (eps - d31 E3), Erturk and Inman 2011, section 3.2);
- the axial stress at a fibre z of a free laminate, sigma = E_i (eps_0 + kappa (z - z_n) - S_i)
  with the stretch eps_0 = sum E t S / sum E t that leaves no axial force;
- a field V_i / t_i.

Three stacks: a PZT-5A unimorph on brass, a PZT-5H bimorph with 100 um and 120 um plates on
carbon fibre (signal and complement), a four-layer stack with a steel shim (one layer poled
down). The catalog bimorphs written as drive = "piezo" files give piezo-bimorph's numbers to
rounding.
"""
import dataclasses
import warnings
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from mjeap import Scene, rollout
from mjeap.studies import sweep
from mjeap.drives import make_drive
from mjeap.model.laminate import FieldWarning
from mjeap.errors import ParameterError
from mjeap.model.actuator_file import read_actuator
from mjeap.model.catalog import CATALOG
from mjeap.studies.sweep import metrics as sweep_metrics

EPS0 = 8.8541878128e-12
BETA1 = 1.8751040687
EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "actuators"

#: (name, role, E, rho, t, d31, eps_r, electrode, poling) bottom to top
UNIMORPH = dict(L=20e-3, w=5e-3, bias=None, v=(0.0, 150.0), layers=[
    ("shim", "substrate", 100e9, 8500.0, 102e-6, None, None, None, None),
    ("pzt", "piezo", 66e9, 7800.0, 127e-6, -190e-12, 1800.0, "signal", "up")])
ASYMMETRIC = dict(L=10e-3, w=3e-3, bias=150.0, v=(0.0, 150.0), layers=[
    ("pzt-bottom", "piezo", 62e9, 7500.0, 100e-6, -320e-12, 3800.0, "signal", "up"),
    ("core", "core", 340e9, 1550.0, 50e-6, None, None, None, None),
    ("pzt-top", "piezo", 62e9, 7500.0, 120e-6, -320e-12, 3800.0, "complement", "up")])
STACK = dict(L=15e-3, w=4e-3, bias=40.0, v=(0.0, 40.0), layers=[
    ("pzt-1", "piezo", 62e9, 7500.0, 50e-6, -320e-12, 3800.0, "signal", "up"),
    ("pzt-2", "piezo", 62e9, 7500.0, 60e-6, -320e-12, 3800.0, "signal", "down"),
    ("shim", "substrate", 193e9, 8000.0, 30e-6, None, None, None, None),
    ("pzt-3", "piezo", 62e9, 7500.0, 50e-6, -320e-12, 3800.0, "complement", "up"),
    ("pzt-4", "piezo", 62e9, 7500.0, 60e-6, -320e-12, 3800.0, "complement", "up")])
CASES = {"unimorph": UNIMORPH, "asymmetric-bimorph": ASYMMETRIC, "four-piezo-layers": STACK}


def _toml(case, name="laminate", damping=0.05):
    out = [f'id = "{name}"', 'drive.name = "piezo"', f"damping_ratio = {damping}",
           f'voltage_range = ["{case["v"][0]} V", "{case["v"][1]} V"]', "plane_strain = false",
           "[planform]", f'length = {case["L"]}', f'base_width = {case["w"]}']
    for name_, role, E, rho, t, d31, eps, electrode, poling in case["layers"]:
        out += ["[[layers]]", f'name = "{name_}"', f'role = "{role}"', f"thickness = {t}", f"youngs_modulus = {E}",
                f"density = {rho}", "poisson_ratio = 0.3"]
        if role == "piezo":
            out += [f'd31 = "{d31 * 1e12} pm/V"', f"relative_permittivity = {eps}", f'electrode = "{electrode}"',
                    f'poling = "{poling}"']
    if case["bias"] is not None:
        out += ["[drive.parameters]", f'bias = "{case["bias"]} V"']
    return "\n".join(out) + "\n"


def _file(tmp_path, case, **kw):
    p = tmp_path / "laminate.toml"
    p.write_text(_toml(case, **kw))
    return str(p)


# ---------------------------------------------------------------- the closed forms
def _section(case):
    E = np.array([l[2] for l in case["layers"]])
    t = np.array([l[4] for l in case["layers"]])
    z = np.cumsum(t) - t / 2
    zn = float(np.sum(E * t * z) / np.sum(E * t))
    return E, t, z, zn, float(np.sum(E * (t**3 / 12 + t * (z - zn) ** 2)))


def _layer_voltages(case, v):
    return [None if l[1] != "piezo" else (v if l[7] == "signal" else case["bias"] - v) for l in case["layers"]]


def _strains(case, v):
    """Each layer's free strain d31 p V_i / t_i (0 in the passive ones)."""
    return np.array([0.0 if vi is None else l[5] * (1 if l[8] == "up" else -1) * vi / l[4]
                     for l, vi in zip(case["layers"], _layer_voltages(case, v))])


def _kappa(case, v):
    E, t, z, zn, D = _section(case)
    return float(np.sum(E * t * _strains(case, v) * (z - zn))) / D


def _arc(kappa, L):
    return (1 - np.cos(kappa * L)) / kappa if kappa else 0.0


def _f1(case):
    _, _, _, _, D = _section(case)
    mu = case["w"] * sum(l[3] * l[4] for l in case["layers"])
    return BETA1**2 / (2 * np.pi * case["L"] ** 2) * np.sqrt(D * case["w"] / mu)


def _capacitances(case):
    A = case["L"] * case["w"]
    free = sum(EPS0 * l[6] * A / l[4] for l in case["layers"] if l[1] == "piezo")
    clamped = sum((EPS0 * l[6] - l[5] ** 2 * l[2]) * A / l[4] for l in case["layers"] if l[1] == "piezo")
    return free, clamped


def _max_field(case, voltages):
    return max(abs(vi) / l[4] for v in voltages for l, vi in zip(case["layers"], _layer_voltages(case, v))
               if vi is not None)


def _settled_tip(scene, voltage):
    rollout(scene, voltage, 30 / scene.choice.first_frequency, progress=False)
    scene.settle(tol=1e-11)
    return float(scene.tip_position()[1])


# ---------------------------------------------------------------- the three stacks
@pytest.mark.parametrize("case", list(CASES))
def test_static_deflection_against_the_free_strain_moment(tmp_path, case):
    c = CASES[case]
    s = Scene(_file(tmp_path, c), gravity=False)
    v = c["v"][1] * 0.75
    assert _settled_tip(s, f"step:{v}V") == pytest.approx(_arc(_kappa(c, v), c["L"]), rel=1e-2)
    # and the drive's own quasi-static closed form (small deflections) at the same voltage
    assert make_drive(None, s).free_deflection(v) == pytest.approx(_kappa(c, v) * c["L"] ** 2 / 2, rel=1e-6)


@pytest.mark.parametrize("case", list(CASES))
def test_first_frequency_capacitance_and_fields_against_closed_forms(tmp_path, case):
    """No rollout: first_frequency (beta_1), capacitance (parallel plates, free), the
    drive's dielectric term (clamped), max_field and max_reverse_field at a sine's extremes."""
    c = CASES[case]
    path = _file(tmp_path, c)
    lo, hi = c["v"]
    base = {"actuator": path, "segments": 40, "waveform": "sine", "amplitude": 0.4 * (hi - lo),
            "offset": 0.5 * (lo + hi), "frequency": 50.0, "duration": 0.1}
    row = sweep.evaluate({}, ("first_frequency", "capacitance", "max_field", "max_reverse_field"), base)
    assert row["error"] == ""
    free, clamped = _capacitances(c)
    assert row["first_frequency"] == pytest.approx(_f1(c), rel=1e-2)
    assert row["capacitance"] == pytest.approx(free, rel=1e-6)
    assert make_drive(None, Scene(path)).capacitances()["blocked"][0] == pytest.approx(clamped, rel=1e-6)
    extremes = (base["offset"] - base["amplitude"], base["offset"] + base["amplitude"])
    assert row["max_field"] == pytest.approx(_max_field(c, extremes), rel=1e-9)
    down = [l for l in c["layers"] if l[8] == "down"]
    reverse = max([v / l[4] for l in down for v in extremes] + [0.0])        # signal layers poled down
    assert row["max_reverse_field"] == pytest.approx(reverse, rel=1e-9, abs=1e-9)


@pytest.mark.parametrize("case", ["unimorph", "asymmetric-bimorph"])
def test_stroke_of_a_slow_sine_is_the_quasi_static_stroke(tmp_path, case):
    """A sine at f1 / 40 from its offset, heavily damped (zeta 0.5, the start's ringing gone
    within the first period): stroke over the last period is the difference of the two arcs."""
    c = CASES[case]
    path = _file(tmp_path, c, damping=0.5)
    lo, hi = c["v"]
    amp, off = 0.45 * (hi - lo), 0.5 * (lo + hi)
    f = _f1(c) / 40
    base = {"actuator": path, "waveform": "sine", "amplitude": amp, "offset": off, "frequency": f,
            "duration": 3 / f}
    row = sweep.evaluate({}, ("stroke",), base)
    assert row["error"] == ""
    ref = abs(_arc(_kappa(c, off + amp), c["L"]) - _arc(_kappa(c, off - amp), c["L"]))
    assert row["stroke"] == pytest.approx(ref, rel=1e-2)


@pytest.mark.parametrize("case", list(CASES))
def test_max_stress_of_a_settled_beam_at_its_layers_outer_fibres(tmp_path, case):
    c = CASES[case]
    s = Scene(_file(tmp_path, c), gravity=False)
    v = c["v"][1] * 0.75
    rollout(s, f"step:{v}V", 30 / s.choice.first_frequency, progress=False)
    s.settle(tol=1e-11)
    lay = s.layout
    # the settled beam as one sample: clamp, hinges and tip from its hinge angles
    phi = np.concatenate([[0.0], np.cumsum(s.part.hinge_angles())])
    pts = [np.zeros(2), np.array([lay.ds / 2, 0.0])]
    for j in range(lay.segments):
        step = lay.ds if j < lay.segments - 1 else lay.ds / 2
        pts.append(pts[-1] + step * np.array([np.cos(phi[j + 1]), np.sin(phi[j + 1])]))
    centreline = np.array([[[p[0], p[1], 0.0] for p in pts]])
    got = sweep_metrics.metric_max_stress(SimpleNamespace(centreline=centreline, voltage=np.array([v])),
                                          {}, s)
    E, t, z, zn, _ = _section(c)
    S = _strains(c, v)
    eps0 = float(np.sum(E * t * S) / np.sum(E * t))
    kappa = _kappa(c, v)
    faces = np.stack([z - t / 2, z + t / 2], axis=1) - zn
    ref = np.abs(E[:, None] * (eps0 + kappa * faces - S[:, None])).max()
    assert got == pytest.approx(ref, rel=1e-2)


def test_plane_strain_scales_stiffness_by_1_minus_nu2_and_the_free_strain_stress_by_1_minus_nu(tmp_path):
    """A wide unimorph: D with E / (1 - nu^2), the free strain's stress E S / (1 - nu) (a
    ceramic's equibiaxial free strain with the width held)."""
    c = UNIMORPH
    path = _file(tmp_path, c)
    wide = Path(path).read_text().replace("plane_strain = false", "plane_strain = true")
    Path(path).write_text(wide)
    drv = make_drive(None, Scene(path, gravity=False))
    nu, v = 0.3, 100.0
    E, t, z, _, _ = _section(c)
    Eh = E / (1 - nu**2)
    zn = float(np.sum(Eh * t * z) / np.sum(Eh * t))
    D = float(np.sum(Eh * (t**3 / 12 + t * (z - zn) ** 2)))
    m = float(np.sum(E / (1 - nu) * t * _strains(c, v) * (z - zn)))
    assert drv.free_deflection(v) == pytest.approx(m / D * c["L"] ** 2 / 2, rel=1e-9)


# ---------------------------------------------------------------- free and clamped charge
def test_a_symmetric_bimorphs_charge_per_volt_is_1_minus_k2_over_4_of_the_free_value(tmp_path):
    """Two equal plates in parallel (both on the signal, poled opposite ways, no core): the
    bending charge 3/2 d31^2 E A / t recovers three quarters of what bonding took from the
    free value, so beam / free = 1 - k31^2 / 4, k31^2 = d31^2 E / eps33^T; a parallel
    bimorph does not stretch (laminate = beam)."""
    d31, E, eps, t = -190e-12, 66e9, 1800.0, 127e-6
    case = dict(L=20e-3, w=5e-3, bias=None, v=(0.0, 100.0), layers=[
        ("pzt-bottom", "piezo", E, 7800.0, t, d31, eps, "signal", "down"),
        ("pzt-top", "piezo", E, 7800.0, t, d31, eps, "signal", "up")])
    q = make_drive(None, Scene(_file(tmp_path, case))).laminate().charge_per_volt()
    k2 = d31**2 * E / (EPS0 * eps)
    assert q["beam"] / q["free"] == pytest.approx(1 - k2 / 4, rel=1e-9)
    assert q["laminate"] == pytest.approx(q["beam"], rel=1e-12)
    assert q["clamped"] / q["free"] == pytest.approx(1 - k2, rel=1e-9)


def test_a_unimorphs_charge_per_volt_lies_between_clamped_and_free(tmp_path):
    q = make_drive(None, Scene(_file(tmp_path, UNIMORPH))).laminate().charge_per_volt()
    assert q["clamped"] < q["beam"] < q["laminate"] < q["free"]


# ---------------------------------------------------------------- the catalog bimorphs as piezo files
@pytest.mark.parametrize("aid", ["pzt-hamr-large", "pzt-hamr-small", "pzt-robobee"])
def test_a_catalog_bimorph_as_a_piezo_file_gives_piezo_bimorphs_numbers(aid):
    """Moment per volt, the static deflection and blocked force (piezo-bimorph's Jafferis
    closed forms against the laminate's unit-load integrals), f1, and over a driven run the
    motional and total currents (the catalog capacitance given as the dielectric term)."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        a, b = Scene(aid), Scene(str(EXAMPLES / "laminate" / f"{aid}.toml"))
    da, db = make_drive(None, a), make_drive(None, b)
    assert db.name == "piezo" and da.name == "piezo-bimorph"
    assert np.allclose(db.gamma, da.gamma, rtol=1e-12, atol=0) and db.rest_voltage() == pytest.approx(100.0, rel=1e-12)
    assert db.free_deflection(200.0) == pytest.approx(da.free_deflection(100.0), rel=1e-9)
    assert db.blocked_force(200.0) == pytest.approx(da.blocked_force(100.0), rel=1e-9)
    assert b.choice.first_frequency == pytest.approx(a.choice.first_frequency, rel=1e-12)
    wave = f"sine:60V@{0.6 * a.choice.first_frequency:.6g}Hz,offset=100V"
    ra = rollout(a, wave, 0.004, progress=False)
    rb = rollout(b, wave, 0.004, progress=False)
    for k in ("current_motional (A)", "current_capacitive (A)", "current_resistive (A)", "current (A)"):
        assert np.allclose(rb.signals[k], ra.signals[k], rtol=1e-9, atol=1e-15), k
    assert np.allclose(rb.tip_position, ra.tip_position, rtol=1e-9, atol=1e-15)


def test_the_datasheet_permittivity_gives_jayaram_2018s_16_nF_for_type_ii():
    """Jayaram et al. 2018, section 3: 2 eps0 eps_r A / d from the datasheet permittivity is
    'about 16 nF' for Type II (A = 32.2 mm^2, d = 135 um); the file's free capacitance with
    K3T = 3800 gives it, and its dielectric term (the catalog's 8 nF) is under half of it, as
    their fixed actuators measured."""
    d = make_drive(None, Scene(str(EXAMPLES / "laminate" / "pzt-hamr-small.toml"))).capacitances()
    assert d["free"][0] == pytest.approx(16e-9, rel=1e-2)
    assert d["blocked"][0] <= 0.5 * d["free"][0]


# ---------------------------------------------------------------- bad files, before any work
GOOD = _toml(ASYMMETRIC)


def _edit(old, new, count=1):
    assert old in GOOD, old
    return GOOD.replace(old, new, count)


BAD = [
    (_edit('d31 = "-320.0 pm/V"\n', ""), r"layers.pzt-bottom.d31 is missing"),
    (_edit("relative_permittivity = 3800.0\n", ""), r"layers.pzt-bottom.relative_permittivity is missing"),
    (_edit('[drive.parameters]\nbias = "150.0 V"\n', ""), r"layers.pzt-top.electrode is \"complement\".*bias"),
    (_toml(dict(UNIMORPH, layers=UNIMORPH["layers"][:1])), r"at least one 'piezo' layer"),
    (_edit('d31 = "-320.0 pm/V"', 'd31 = "-320.0 pm/V"\ne31 = "-10 C/m^2"'), r"layers.pzt-bottom.e31"),
    (_edit('poling = "up"', 'poling = "sideways"'), r"layers.pzt-bottom.poling='sideways'.*\"up\" or \"down\""),
    (_edit('electrode = "signal"', 'electrode = "ground"'), r"layers.pzt-bottom.electrode='ground'"),
    (_edit('name = "core"\nrole = "core"', 'name = "core"\nrole = "core"\nd31 = "1 pm/V"'),
     r"layers.core.d31.*role = \"piezo\""),
    (_edit('d31 = "-320.0 pm/V"', 'd31 = "-320 V/m"'), r"layers.pzt-bottom.d31"),
    (_edit('d31 = "-320.0 pm/V"', 'd31 = "-320 nm/V"'), r"d31\^2 Y / eps33\^T"),
]


@pytest.mark.parametrize("text,match", BAD, ids=[m.split(".")[-1][:24] for _, m in BAD])
def test_a_bad_laminate_file_is_refused_naming_file_and_key(tmp_path, text, match):
    p = tmp_path / "bad.toml"
    p.write_text(text)
    with pytest.raises(ParameterError, match=match) as e:
        read_actuator(p)
    assert str(p) in str(e.value)


def test_e31_is_d31_times_the_layers_modulus(tmp_path):
    text = GOOD.replace('d31 = "-320.0 pm/V"', f'e31 = "{-320e-12 * 62e9} C/m^2"', 1)
    p = tmp_path / "e31.toml"
    p.write_text(text)
    assert read_actuator(p).layers[0].d31 == pytest.approx(-320e-12, rel=1e-12)
    p.write_text(text.replace('e31 =', 'd31 = "-320 pm/V"\ne31 =', 1))       # both, agreeing
    assert read_actuator(p).layers[0].d31 == pytest.approx(-320e-12, rel=1e-12)


def test_a_layer_takes_d31_and_permittivity_from_its_material(tmp_path):
    act = read_actuator(EXAMPLES / "pzt-unimorph.toml")
    drv = make_drive(None, Scene(act))
    pz = drv.laminate().piezo[0]
    assert (pz.d31, pz.relative_permittivity) == (-190e-12, 1800.0) and "material pzt-5a" in pz.sources["d31"]


def test_a_voltage_range_past_the_recommended_field_is_warned_naming_layer_and_field(tmp_path):
    text = _toml(UNIMORPH).replace('"150.0 V"]', '"300.0 V"]') + ""
    text = text.replace('role = "piezo"', 'role = "piezo"\nmaterial = "pzt-5a"')
    p = tmp_path / "hot.toml"
    p.write_text(text)
    with pytest.warns(FieldWarning, match=r"layer pzt sees 2.36 V/um .* past its recommended 2 V/um"):
        make_drive(None, Scene(str(p)))


def test_a_piezo_bimorph_thinned_past_the_field_limit_is_warned_too():
    """Issue 42's optimum: pzt-hamr-small's plates thinned to 75 um at 200 V, 2.7 V/um."""
    from mjeap.model import variants as design
    act = design.design_actuator("pzt-hamr-small", {"actuator.roles.piezo.thickness": 75e-6})
    with pytest.warns(FieldWarning, match=r"layer pzt-bottom sees 2.67 V/um .* past its recommended 2 V/um"):
        make_drive(None, Scene(act))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        make_drive(None, Scene("pzt-hamr-small"))          # 1.48 V/um: no warning


def test_the_physical_sets_f1_gap_the_docs_state():
    """mjeap.studies.design_numbers.PHYSICAL_SET_F1_GAP (show's and the docs' 8-75 %): the catalog files
    without their fitted residual tip mass against Jayaram et al. 2018's Table 1 f_r."""
    from mjeap.studies.design_numbers import PHYSICAL_SET_F1_GAP
    measured = {"pzt-hamr-large": 1400.0, "pzt-hamr-small": 1750.0, "pzt-robobee": 1020.0}
    for aid, fr in measured.items():
        a = CATALOG[aid]
        bare = dataclasses.replace(a, planform=dataclasses.replace(a.planform, residual_tip_mass=0.0))
        assert Scene(bare).choice.first_frequency / fr - 1 == pytest.approx(PHYSICAL_SET_F1_GAP[aid], abs=1e-3)


@pytest.mark.parametrize("name", ["pzt-unimorph", "asymmetric-bimorph", "multilayer-bender"])
def test_every_engine_runs_a_laminate_as_the_loop_does(name):
    """The drive's native form (one actuator on the bending tendon) and its open-loop form
    (the threaded engine) give the loop's tip and current; auto picks one of them."""
    runs = {}
    for engine in ("loop", "threaded", "native", "auto"):
        runs[engine] = rollout(Scene(str(EXAMPLES / f"{name}.toml")), "sine:30V@200Hz,offset=50V", 0.01,
                               engine=engine, progress=False)
    assert runs["auto"].meta["engine"] in ("native", "threaded")
    ref = runs["loop"]
    for engine in ("threaded", "native"):
        for a, b in ((runs[engine].tip_position[:, 1], ref.tip_position[:, 1]),
                     (runs[engine].signals["current (A)"], ref.signals["current (A)"])):
            assert np.max(np.abs(a - b)) <= 1e-9 * np.ptp(b), engine
