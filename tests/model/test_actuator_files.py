"""Actuator files (own-actuator issue, deliverable 1): the catalog as files, round trips,
every bad file refused naming file, key and range before any work, and file actuators of
our own against closed forms derived here from their layer stacks, not from mjeap's code.

The closed forms (small deflections, Euler-Bernoulli):
- bending stiffness per width of a layered strip by the transformed section (Gere &
  Timoshenko, Mechanics of Materials, composite beams): neutral axis z_n = sum E_i t_i z_i /
  sum E_i t_i (z_i each layer's mid-plane), D = sum E_i (t_i^3 / 12 + t_i (z_i - z_n)^2): the
  parallel-axis theorem, not the code's eqs. 3.3-3.6 form;
- a tip force P on a cantilever: delta = P L^3 / (3 E I); on a tapered one
  delta = P int_0^L (L - x)^2 / (E I(x)) dx (unit-load method), by quadrature;
- a uniform couple bends the beam into an arc: delta = (1 - cos(kappa L)) / kappa, and a rigid
  extension l_e adds sin(kappa L) l_e;
- the bimorph's couple per width: each plate at field V_i / t_p carries the effective stress
  f31 V_i / t_p (Wood et al. 2005, Jafferis et al. 2015), resultant f31 V_i at its mid-plane
  (t_p + t_cf) / 2 from the centre: m = f31 V (t_p + t_cf) / 2 for the plates' voltage
  difference V = 2 V_eff;
- an eigenstrain S in one layer of a free strip (the layer would stretch by S; bonded, it
  pulls the stack): the force E_a w t_a S at the layer's mid-plane, about the neutral axis,
  kappa = E_a t_a S (z_a - z_n) / D (Timoshenko 1925, bimetal thermostats, generalised);
- the first frequency of a uniform cantilever with a tip mass m: beta_1 of
  1 + cos b cosh b + (m / (mu L)) b (cos b sinh b - sin b cosh b) = 0,
  f_1 = beta_1^2 / (2 pi L^2) sqrt(EI / mu) (e.g. Blevins, Formulas for natural frequency).
"""
import dataclasses
import json
import re
import warnings
from pathlib import Path

import numpy as np
import pytest
from scipy import integrate, optimize

from mjeap import Actuator, Scene, rollout
from mjeap.drives import make_drive
from mjeap.errors import ParameterError, UnknownNameError
from mjeap.model.catalog import CATALOG, CATALOG_DIR, get_actuator
from mjeap.model.materials import RangeWarning

#: the sources are named by author and year since issue 42, where the golden still says "seed 00N":
#: the golden's texts pass through the same renaming (the numbers are the golden's own)
_AUTHORS = {"0": ("Dadras et al. 2021", "Dadras"), "1": ("Mutlu et al. 2013", "Mutlu"),
            "2": ("Metello 2020", "Metello"), "3": ("Jayaram et al. 2018", "Jayaram")}


def _author_year(text: str) -> str:
    # 'Seed 002 (Metello 2020)' -> 'Metello 2020'
    text = re.sub(r"[Ss]eed 00([0-3]) \(([^()]*\d{4})\)", r"\2", text)

    def paren(m):
        name, surname = _AUTHORS[m.group(1)]
        start = m.start()
        line_start = text.rfind("\n", 0, start) + 1
        near = surname in text[max(line_start, start - 160):start]
        rest = m.group(2)                                # ', section 6.2' or ''
        if near:
            return f" ({rest[2:]})" if rest else ""
        return f" ({name}{rest})"

    text = re.sub(r" ?\(seed 00([0-3])((?:, [^()]*)?)\)", paren, text)
    text = re.sub(r"\b[Ss]eed 00([0-3])", lambda m: _AUTHORS[m.group(1)][0], text)
    return text


def _renamed(x):
    if isinstance(x, str):
        return _author_year(x)
    if isinstance(x, dict):
        return {k: _renamed(v) for k, v in x.items()}
    if isinstance(x, list):
        return [_renamed(v) for v in x]
    return x


GOLDEN = _renamed(json.loads((Path(__file__).resolve().parents[1] / "golden" / "catalog_eaac59e.json").read_text())["actuators"])


# ---------------------------------------------------------------- the catalog as files
def test_the_catalog_files_hold_todays_numbers_and_sources():
    """Every field of the eight actuators, read from their files, equals the catalog as it
    was compiled into catalog.py at eaac59e, and their drives' parameters (value, unit,
    source) the drive classes' tables then."""
    assert sorted(CATALOG) == sorted(GOLDEN) and len(list(CATALOG_DIR.glob("*.toml"))) == 8
    for k, act in CATALOG.items():
        d = json.loads(json.dumps(dataclasses.asdict(act), default=float))
        old = GOLDEN[k]
        for f in old:
            if f in ("drive", "drive_parameters"):
                continue
            if f == "layers":
                for lo, ln in zip(old[f], d[f]):
                    assert {x: ln[x] for x in lo} == lo, (k, lo["name"])
            else:
                assert d[f] == old[f], (k, f)
        assert act.drive == old["drive"]
        drv = make_drive(None, Scene(k, segments=4))
        for p, (value, unit, source) in old["drive_parameters"].items():
            assert drv.params[p] == value and drv.sources[p] == f"{unit}; {source}", (k, p)


@pytest.mark.parametrize("aid", list(GOLDEN))
def test_round_trip_through_a_file(tmp_path, aid):
    act = CATALOG[aid]
    act.to_file(tmp_path / f"{aid}.toml")
    back = Actuator.from_file(tmp_path / f"{aid}.toml")
    assert dataclasses.replace(back, source_file=None) == act


def test_a_file_actuator_runs_bit_for_bit_as_its_catalog_twin(tmp_path):
    CATALOG["pzt-hamr-small"].to_file(tmp_path / "twin.toml")
    a = rollout(Scene("pzt-hamr-small"), "sine:50V@200Hz,offset=100V", 0.005, progress=False)
    b = rollout(Scene(str(tmp_path / "twin.toml")), "sine:50V@200Hz,offset=100V", 0.005, progress=False)
    assert np.array_equal(a.tip_curvature, b.tip_curvature)
    assert np.array_equal(a.signals["current (A)"], b.signals["current (A)"])


def test_a_name_that_is_also_a_file_here_is_refused_naming_both(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "pedot-micro").write_text("x")
    with pytest.raises(ParameterError, match="pedot-micro.*catalog actuator.*file here.*./pedot-micro"):
        get_actuator("pedot-micro")


# ---------------------------------------------------------------- files of our own
#: a uniform PZT-5H bimorph, 12 x 3 mm: examples/actuators/uniform-bimorph.toml
BIMORPH = (Path(__file__).resolve().parents[2] / "examples" / "actuators" / "uniform-bimorph.toml").read_text()


def _file(tmp_path, text, name="a.toml"):
    p = tmp_path / name
    p.write_text(text)
    return p


def _transformed(layers):
    """(z_n, D per width) of [(E, t), ...] bottom to top: the transformed section."""
    E = np.array([e for e, _ in layers])
    t = np.array([t for _, t in layers])
    z = np.cumsum(t) - t / 2
    zn = float(np.sum(E * t * z) / np.sum(E * t))
    return zn, float(np.sum(E * (t**3 / 12 + t * (z - zn) ** 2)))


def _settled_tip(scene, voltage, drive_params=None, duration=None):
    duration = duration or 30 / scene.choice.first_frequency
    rollout(scene, voltage, duration, drive_params=drive_params, progress=False)
    scene.settle(tol=1e-11)
    return float(scene.tip_position()[1])


def test_uniform_bimorph_free_deflection_against_the_plate_couple(tmp_path):
    s = Scene(str(_file(tmp_path, BIMORPH)), gravity=False)
    E_p, E_cf, t_p, t_cf, L = 40e9, 340e9, 127e-6, 60e-6, 12e-3
    _, D = _transformed([(E_p, t_p), (E_cf, t_cf), (E_p, t_p)])
    kappa = 32.0 * 200.0 * (t_p + t_cf) / 2 / D          # full drive: V_sig = V_bias, V = 200 V
    ref = (1 - np.cos(kappa * L)) / kappa
    assert _settled_tip(s, "step:200V") == pytest.approx(ref, rel=2e-3)


def test_tapered_bimorph_with_a_tip_block_free_deflection_and_blocked_force(tmp_path):
    text = BIMORPH.replace('base_width = "3 mm"', 'base_width = "4 mm"\ntip_width = "1.5 mm"\n'
                           'extension_length = "1 mm"\nextension_mass = "1 mg"')
    s = Scene(str(_file(tmp_path, text)), gravity=False)
    E_p, E_cf, t_p, t_cf, L, le = 40e9, 340e9, 127e-6, 60e-6, 12e-3, 1e-3
    _, D = _transformed([(E_p, t_p), (E_cf, t_cf), (E_p, t_p)])
    kappa = 32.0 * 200.0 * (t_p + t_cf) / 2 / D          # the couple scales with width: uniform kappa
    free = (1 - np.cos(kappa * L)) / kappa + np.sin(kappa * L) * le
    assert _settled_tip(s, "step:200V") == pytest.approx(free, rel=2e-3)
    # a tip force's compliance by the unit-load integral over the taper (the block rigid)
    w = lambda x: 4e-3 + (1.5e-3 - 4e-3) * x / L                  # noqa: E731
    c = integrate.quad(lambda x: (L + le - x) ** 2 / (D * w(x)), 0, L)[0]
    s2 = Scene(str(tmp_path / "a.toml"), gravity=False)
    s2.set_tip_force(1e-4)
    s2.settle(tol=1e-12)
    assert float(s2.tip_position()[1]) == pytest.approx(1e-4 * c, rel=3e-3)


TRILAYER = """
id = "my-trilayer"
title = "A thicker PPy trilayer, its own eq. (8) parameters"
drive.name = "rc-relaxation"
damping_ratio = 0.05
voltage_range = ["-1 V", "1 V"]
plane_strain = false
[planform]
length = "15 mm"
base_width = "4 mm"
[[layers]]
name = "ppy-bottom"
role = "electrode"
material = "polypyrrole"
thickness = "40 um"
[[layers]]
name = "membrane"
role = "electrolyte"
material = "pvdf-membrane"
thickness = "150 um"
[[layers]]
name = "ppy-top"
role = "electrode"
material = "polypyrrole"
thickness = "40 um"
[drive.parameters]
gain = 20.0
zero = "0.6 1/s"
pole_mechanical = "0.3 1/s"
pole_electrical = "2 1/s"
capacitance = "1 mF"
[drive.sources]
gain = "made up for the test"
"""


@pytest.mark.slow
def test_trilayer_with_rc_relaxation_settles_at_eq_8s_dc_gain_and_bends_by_its_stack(tmp_path):
    """The step's final curvature is eq. (8)'s DC gain k z / (p_m p_e) x V (Dadras et al. 2021; the
    drive's moment is the one that gives it on the file's own EI), and a tip force bends
    the stack by P L^3 / (3 D w) with D from its layers."""
    path = _file(tmp_path, TRILAYER)
    s = Scene(str(path), gravity=False)
    r = rollout(s, "step:0.5V", 40.0, progress=False)
    assert r.tip_curvature[-1] == pytest.approx(20.0 * 0.6 / (0.3 * 2.0) * 0.5, rel=5e-3)
    _, D = _transformed([(80e6, 40e-6), (440e6, 150e-6), (80e6, 40e-6)])
    s2 = Scene(str(path), gravity=False)
    s2.set_tip_force(1e-6)
    s2.settle(tol=1e-13)
    assert float(s2.tip_position()[1]) == pytest.approx(1e-6 * 15e-3**3 / (3 * D * 4e-3), rel=3e-3)


UNIMORPH = """
id = "my-unimorph"
title = "A terpolymer unimorph on a Kapton film"
drive.name = "electrostrictive"
damping_ratio = 0.05
voltage_range = ["-1500 V", "1500 V"]
plane_strain = false
[planform]
length = "30 mm"
base_width = "10 mm"
[[layers]]
name = "kapton"
role = "substrate"
material = "kapton"
thickness = "25 um"
[[layers]]
name = "terpolymer"
role = "terpolymer"
material = "terpolymer"
thickness = "80 um"
[drive.parameters]
model = "eigenstrain"
"""


def test_terpolymer_unimorph_bends_by_its_eigenstrain_about_the_neutral_axis(tmp_path):
    """S = Q E^2 in the active layer (Metello 2020; Q the drive's generic 6.92e-17 m^2/V^2),
    E = V / t_a; kappa = E_a t_a S (z_a - z_n) / D. The sign: the active layer lies above
    the neutral axis and stretches, so the strip curls towards -y."""
    s = Scene(str(_file(tmp_path, UNIMORPH)), gravity=False)
    Q, V, t_a = 6.92e-17, 250.0, 80e-6         # kappa L ~ 0.28: the chain resolves the arc
    S = Q * (V / t_a) ** 2
    layers = [(2.5e9, 25e-6), (99.5e6, 80e-6)]
    zn, D = _transformed(layers)
    z_a = 25e-6 + 40e-6
    kappa = 99.5e6 * t_a * S * (z_a - zn) / D
    ref = (1 - np.cos(kappa * 30e-3)) / kappa
    assert abs(_settled_tip(s, f"step:{V}V")) == pytest.approx(ref, rel=3e-3)


PASSIVE = """
id = "passive-stack"
title = "An unsymmetric passive stack: gold on Kapton under parylene-free PE tape"
drive = "none"
damping_ratio = 0.05
voltage_range = ["0 V", "1 V"]
plane_strain = false
[planform]
length = "8 mm"
base_width = "2 mm"
[[layers]]
name = "kapton"
material = "kapton"
thickness = "50 um"
[[layers]]
name = "gold"
material = "gold"
thickness = "2 um"
[[layers]]
name = "tape"
material = "pe-tape"
thickness = "30 um"
"""


def test_unsymmetric_passive_stack_tip_compliance_and_first_frequency_with_a_tip_mass(tmp_path):
    path = _file(tmp_path, PASSIVE)
    layers = [(2.5e9, 50e-6), (79e9, 2e-6), (4.66e8, 30e-6)]
    _, D = _transformed(layers)
    EI, L, w = D * 2e-3, 8e-3, 2e-3
    s = Scene(str(path), gravity=False)
    s.set_tip_force(1e-6)
    s.settle(tol=1e-14)
    assert float(s.tip_position()[1]) == pytest.approx(1e-6 * L**3 / (3 * EI), rel=3e-3)
    mu = w * (1420.0 * 50e-6 + 19300.0 * 2e-6 + 920.0 * 30e-6)
    m = 0.5 * mu * L
    beta = optimize.brentq(lambda b: 1 + np.cos(b) * np.cosh(b)
                           + m / (mu * L) * b * (np.cos(b) * np.sinh(b) - np.sin(b) * np.cosh(b)), 0.5, 1.875)
    f1 = beta**2 / (2 * np.pi * L**2) * np.sqrt(EI / mu)
    s2 = Scene(str(path), gravity=False, payload=f"{m}@{L},point")
    assert s2.choice.first_frequency == pytest.approx(f1, rel=3e-3)


# ---------------------------------------------------------------- bad files, before any work
BAD = [
    ("no layers", lambda t: t.split("[[layers]]")[0], "layers", "at least one"),
    ("negative thickness", lambda t: t.replace('thickness = "60 um"', 'thickness = "-60 um"'),
     r"layers.core.thickness", "positive"),
    ("unknown material", lambda t: t.replace('"carbon-fibre"', '"carbon-fiber"'), r"layers.core.material",
     "carbon-fibre"),
    ("unknown drive", lambda t: t.replace('"piezo-bimorph"', '"piezo-bimorf"'), "drive", "piezo-bimorph"),
    ("role missing", lambda t: t.replace('role = "core"', 'role = "substrate"'), "layers",
     "core.*between two 'piezo'|'core'"),
    ("asymmetric bimorph", lambda t: t.replace('thickness = "127 um"', 'thickness = "100 um"', 1),
     "layers", "equally thick"),
    ("unit does not parse", lambda t: t.replace('"12 mm"', '"12 furlongs"'), r"planform.length",
     "does not parse"),
    ("wrong dimension", lambda t: t.replace('"12 mm"', '"12 mg"'), r"planform.length", "another dimension"),
    ("1000 x outside", lambda t: t.replace('thickness = "60 um"', 'thickness = "60 um"\nyoungs_modulus = "340 Pa"'),
     r"layers.core.youngs_modulus", "check the unit"),
    ("unknown key", lambda t: t.replace("damping_ratio", "damping"), "damping", "one of the keys"),
    ("bad id", lambda t: t.replace('id = "uniform-bimorph"', 'id = "uniform bimorph!"'), "id", "letters, digits"),
    ("reversed voltage range", lambda t: t.replace('["0 V", "200 V"]', '["200 V", "0 V"]'), "voltage_range",
     "low < high"),
    ("unknown drive parameter", lambda t: t.replace("f31 =", "d31 ="), r"drive.parameters.d31", "f31"),
    ("missing property", lambda t: t.replace('material = "carbon-fibre"\n', ""), r"layers.core.youngs_modulus",
     "material from the library"),
]


@pytest.mark.parametrize("what,edit,key,why", BAD, ids=[b[0] for b in BAD])
def test_a_bad_file_is_refused_naming_file_key_and_range(tmp_path, what, edit, key, why):
    path = _file(tmp_path, edit(BIMORPH))
    with pytest.raises((ParameterError, UnknownNameError)) as e:
        Actuator.from_file(path)
    msg = str(e.value)
    assert str(path) in msg and (key in msg or __import__("re").search(key, msg)), msg
    assert __import__("re").search(why, msg), msg


def test_a_value_outside_its_materials_range_warns_naming_file_key_and_range(tmp_path):
    path = _file(tmp_path, BIMORPH.replace('thickness = "60 um"', 'thickness = "60 um"\nyoungs_modulus = "30 GPa"'))
    with pytest.warns(RangeWarning, match=r"a.toml: layers.core.youngs_modulus=3e\+10 Pa lies outside carbon-fibre's "
                                          r"range \[5e\+10, 6e\+11\] Pa"):
        act = Actuator.from_file(path)
    assert act.layers[1].youngs_modulus == 30e9


def test_the_catalog_files_load_without_warnings():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for p in CATALOG_DIR.glob("*.toml"):
            Actuator.from_file(p)


def test_a_file_is_refused_before_any_work(tmp_path, monkeypatch):
    """mjeap.Scene with a bad file raises before anything is built."""
    import mjeap.simulation.scene as sc
    monkeypatch.setattr(sc, "build_spec", lambda *a, **k: (_ for _ in ()).throw(AssertionError("work started")))
    with pytest.raises(ParameterError, match="planform.length"):
        Scene(str(_file(tmp_path, BIMORPH.replace('"12 mm"', '"-12 mm"'))))
