"""Design optimisation (own-actuator issue, deliverable 4): ``mjeap optimize`` and
``mjeap.optimize`` find an optimum known in closed form, rerun from their CSV as a cache,
write the optimum as an actuator file and refuse bad questions before any work.

The closed form. A uniform bimorph without a tip block (EI and mu from its layers, below)
has f_1 = beta_1^2 / (2 pi L^2) sqrt(EI / mu), beta_1 = 1.8751 (the root of
1 + cos b cosh b = 0), falling as 1 / L^2, and under a fixed voltage a uniform curvature
kappa (the plate couple over EI, independent of L), so a free deflection
(1 - cos kappa L) / kappa ~ kappa L^2 / 2 growing with L. Maximising the free deflection at a
first-frequency floor f_1 >= f_min therefore drives L up until the floor stops it: the
constraint is active and f_1(L*) = f_min, i.e.

    L* = beta_1 sqrt(1 / (2 pi f_min)) (EI / mu)^(1/4).

For the bimorph below (E 40 / 340 GPa, rho 7500 / 1550 kg/m^3, plates 127 um, core 60 um,
3 mm wide, plane stress) and f_min = 800 Hz, L* = 12.77 mm, inside the box 5-15 mm. The
hinge chain's f_1 at 10 segments is 0.2 % above Euler-Bernoulli's (L* then 0.1 % long), well
inside the 1 % asked. The mass of a uniform beam, mu L, also grows with L: maximising it at
the same floor has the same L* and needs no rollout (the first-frequency-only formulation).
"""
import json

import numpy as np
import pytest

import mjeap
from mjeap import Actuator
from mjeap.studies import sweep
from mjeap.cli import main
from mjeap.errors import ParameterError, UnknownNameError

from test_design_sweeps import BIMORPH, E_CF, E_P, RHO_CF, RHO_P, T_CF, T_P, W

F_MIN = 800.0


def _l_star(f_min=F_MIN):
    E = np.array([E_P, E_CF, E_P])
    t = np.array([T_P, T_CF, T_P])
    z = np.cumsum(t) - t / 2
    zn = np.sum(E * t * z) / np.sum(E * t)
    EI = W * float(np.sum(E * (t**3 / 12 + t * (z - zn) ** 2)))
    mu = W * (2 * RHO_P * T_P + RHO_CF * T_CF)
    beta1 = 1.8751040687
    return beta1 * np.sqrt(1 / (2 * np.pi * f_min)) * (EI / mu) ** 0.25


@pytest.fixture
def bimorph(tmp_path):
    p = tmp_path / "my.toml"
    p.write_text(BIMORPH)
    return str(p)


@pytest.mark.slow
def test_the_cli_finds_the_closed_form_optimum_and_reruns_from_its_cache(bimorph, tmp_path, capsys):
    """The issue's command (10 segments, one start, to stay cheap): L within 1 % of L*, the
    floor active; result.json, evaluations.csv and optimum.toml written; a rerun reads
    every evaluation from the CSV and gives the same optimum."""
    out = tmp_path / "opt"
    argv = ["optimize", bimorph, "--vary", "actuator.length=5mm:15mm", "--maximize", "free_deflection",
            "--subject-to", "first_frequency>=800", "--voltage", "step:200V", "--duration", "0.05",
            "--out", str(out), "--set", "segments=10", "--starts", "1", "--quiet"]
    assert main(argv) == 0
    printed = json.loads(capsys.readouterr().out)
    result = json.loads((out / "result.json").read_text())
    assert printed["optimum"] == result["optimum"]
    L = result["optimum"]["actuator.length"]
    assert L == pytest.approx(_l_star(), rel=0.01)
    assert set(result["metrics"]) == {"free_deflection", "first_frequency"}
    [c] = result["constraints"]
    assert c["expression"] == "first_frequency>=800" and c["active"] is True
    assert c["value"] == pytest.approx(F_MIN, rel=1e-4)
    assert result["evaluations"] == result["evaluations_run"] > 3
    rows = sweep.read_results(out / "evaluations.csv")
    assert len(rows) == result["evaluations"] and all(r["error"] == "" for r in rows)
    best = Actuator.from_file(out / "optimum.toml")
    assert best.planform.length == L and best.id == "uniform-bimorph-optimum"
    # the rerun: the same optimum, nothing simulated
    assert main(argv) == 0
    again = json.loads((out / "result.json").read_text())
    assert again["optimum"] == result["optimum"] and again["metrics"] == result["metrics"]
    assert (again["evaluations_run"], again["evaluations_cached"]) == (0, result["evaluations"])


@pytest.mark.slow
def test_differential_evolution_on_the_linearised_model_alone(bimorph, monkeypatch):
    """Maximise the mass at the floor: the same L*, by the global search then SLSQP's polish,
    every evaluation a linearised model (no rollout); a second parameter, the width, leaves
    f_1 alone and raises the mass, so it goes to its bound."""
    monkeypatch.setattr(sweep.runner, "_run_point", lambda *a, **k: pytest.fail("a rollout ran"))
    r = mjeap.optimize(bimorph, {"actuator.length": ("5mm", "15mm")}, maximize="mass",
                       subject_to=["first_frequency>=0.8kHz"], base={"segments": 10},
                       method="differential-evolution", progress=False)
    assert r.success and r.optimum["actuator.length"] == pytest.approx(_l_star(), rel=0.01)
    assert r.constraints[0]["active"]
    two = mjeap.optimize(bimorph, {"actuator.length": ("5mm", "15mm"), "actuator.width": (2e-3, 4e-3)},
                         maximize="mass", subject_to=["first_frequency>=800"], base={"segments": 10},
                         starts=2, progress=False)
    assert two.optimum["actuator.length"] == pytest.approx(_l_star(), rel=0.01)
    assert two.optimum["actuator.width"] == pytest.approx(4e-3, rel=1e-6)


def test_a_drive_parameter_goes_into_the_optimum_file(bimorph, tmp_path):
    """Free deflection grows with f31: the optimum sits on its upper bound, and the optimum
    file carries it as the drive's parameter."""
    r = mjeap.optimize(bimorph, {"drive.f31": (20.0, 30.0)}, maximize="free_deflection", voltage="step:200V",
                       duration=0.02, base={"segments": 6, "actuator.length": 8e-3}, starts=1, out=tmp_path / "o",
                       progress=False)
    assert r.optimum["drive.f31"] == pytest.approx(30.0, rel=1e-6)
    act = Actuator.from_file(tmp_path / "o" / "optimum.toml")
    assert act.drive_parameters["f31"][0] == pytest.approx(30.0, rel=1e-6) and act.planform.length == 8e-3


BAD = [
    (dict(vary={"actuator.length": ("15mm", "5mm")}), ParameterError, "LOW < HIGH"),
    (dict(vary={"actuator.length": ("-5mm", "15mm")}), ParameterError, "actuator.length.*positive"),
    (dict(vary={"actuator.lenght": ("5mm", "15mm")}), UnknownNameError, "did you mean 'actuator.length'"),
    (dict(vary={"drive.bias": (100.0, 300.0)}), ParameterError, r"drive.bias.*piezo-bimorph drive's range"),
    (dict(vary={"payload_mass": (-1e-6, 1e-6)}), ParameterError, r"payload_mass.*\[0, inf\]"),
    (dict(maximize="wobble"), UnknownNameError, "metric"),
    (dict(minimize="mass"), ParameterError, "exactly one metric"),
    (dict(subject_to=["first_frequency=800"]), ParameterError, "NAME>=VALUE"),
    (dict(subject_to=["first_frequency>=800mm"]), ParameterError, "first_frequency.*Hz"),
    (dict(voltage=None), ParameterError, "voltage.*free_deflection"),
    (dict(voltage="chirp:1V@1Hz..2Hz"), ParameterError, "step, square, sine, triangle"),
    (dict(duration=None), ParameterError, "duration"),
    (dict(method="nelder-mead"), ParameterError, "slsqp, differential-evolution"),
]


@pytest.mark.parametrize("change,error,match", BAD, ids=[str(b[0])[:40] for b in BAD])
def test_a_bad_question_is_refused_before_any_work(bimorph, tmp_path, monkeypatch, change, error, match):
    monkeypatch.setattr(sweep, "evaluate", lambda *a, **k: pytest.fail("an evaluation ran"))
    kw = dict(vary={"actuator.length": ("5mm", "15mm")}, maximize="free_deflection",
              subject_to=["first_frequency>=800"], voltage="step:200V", duration=0.05, out=tmp_path / "o")
    kw.update(change)
    with pytest.raises(error, match=match):
        mjeap.optimize(bimorph, **kw)
    assert not (tmp_path / "o" / "result.json").exists()


def test_an_out_folder_that_is_a_file_is_refused(bimorph, tmp_path, capsys):
    (tmp_path / "o").write_text("mine")
    assert main(["optimize", bimorph, "--vary", "actuator.length=5mm:15mm", "--maximize", "mass",
                 "--out", str(tmp_path / "o")]) == 2
    assert "it is a file" in capsys.readouterr().err and (tmp_path / "o").read_text() == "mine"


def test_an_optimisations_actuator_is_read_once_at_its_edge(tmp_path, monkeypatch):
    """The trace of an optimisation's actuator (issue 44): resolved once at the study's edge
    (one read of the file's bytes, one parse), then carried down as an object by every
    evaluation, its scene, variants and point ids: the file is never read again, and every
    evaluation's scene is built from that one Actuator object."""
    import pathlib
    import pickle
    from mjeap.model import catalog
    from mjeap.model.catalog import ActuatorRef
    from mjeap.simulation import scene as scene_module
    f = tmp_path / "bimorph.toml"
    f.write_text(BIMORPH)
    reads, parses, built = [], [], []
    real_bytes, real_read, real_init = pathlib.Path.read_bytes, catalog.read_actuator, scene_module.Scene.__init__

    def read_bytes(self):
        if self.name == f.name:
            reads.append(str(self))
        return real_bytes(self)

    def read_actuator(path):
        parses.append(str(path))
        return real_read(path)

    def init(self, actuator, **kw):
        built.append(actuator)
        real_init(self, actuator, **kw)
    monkeypatch.setattr(pathlib.Path, "read_bytes", read_bytes)
    monkeypatch.setattr(catalog, "read_actuator", read_actuator)
    monkeypatch.setattr(scene_module.Scene, "__init__", init)
    from mjeap.caching import clear_caches
    clear_caches()                          # a cold start: the file parsed here, at the edge
    r = mjeap.optimize(str(f), {"actuator.length": ("5mm", "15mm")}, maximize="first_frequency",
                       max_evaluations=8, progress=False)
    assert r.evaluations >= 3
    assert len(reads) == 1 and len(parses) == 1, (reads, parses)     # the edge's one read and one parse
    bases = {id(a) for a in built if getattr(a, "source_file", None) == str(f)}
    assert len(bases) <= 1                  # the base object, where a scene was built from it unchanged
    ref = catalog.resolve_actuator(str(f))
    assert isinstance(ref, ActuatorRef) and str(ref) == str(f) and ref.actuator is catalog.get_actuator(ref)
    back = pickle.loads(pickle.dumps(ref))          # what a worker process receives
    assert isinstance(back, ActuatorRef) and back == ref and back.actuator == ref.actuator
