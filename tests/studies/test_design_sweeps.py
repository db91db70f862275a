"""Geometry and materials in studies (own-actuator issue, deliverable 3): ``actuator.X``
sweep parameters build each point's actuator from the base file (mjeap.model.variants), and the
designers' metrics against references derived here from the file's layer stack, not from
mjeap's code.

The references (small deflections, Euler-Bernoulli; the stack by the transformed section,
z_n = sum E_i t_i z_i / sum E_i t_i, D = sum E_i (t_i^3 / 12 + t_i (z_i - z_n)^2), plane
stress as the file asks):
- the bimorph's plate couple: each plate at field V_i / t_p carries the effective stress
  f31 V_i / t_p (Wood et al. 2005, Jafferis et al. 2015), so M = f31 w (t_p + t_cf) V / 2 for
  the plates' voltage difference V = 2 V_eff = 2 (V_sig - V_bias / 2); kappa = M / (D w) is
  uniform and bends the beam into an arc: free deflection (1 - cos kappa L) / kappa;
- blocked force: the tip force that cancels it, F_b = kappa L^2 / 2 / (L^3 / (3 D w)) =
  3 D w kappa / (2 L). The hinge chain's tip compliance is sum_j ds (L - x_j)^2 / EI with
  hinges at x_j = (j - 1/2) ds, L^3 / (3 EI) (1 - 1 / (4 N^2)): F_b reads 1 / (4 N^2) high
  (0.06 % at 20 segments), inside the 0.2 % asked;
- mass: w L (2 rho_p t_p + rho_cf t_cf) (library densities 7500, 1550 kg/m^3);
- first frequency with a tip mass m: beta_1 of 1 + cos b cosh b + (m / (mu L)) b (cos b sinh b -
  sin b cosh b) = 0, f_1 = beta_1^2 / (2 pi L^2) sqrt(EI / mu) (Blevins). The sweep's payload is
  an NdFeB sphere: its rotary inertia J = 0.4 m r^2 (tau = J / (mu L^3) < 4e-4 here) lowers f_1
  by a few 1e-4, inside the 0.3 % asked; hanging down, the payload's weight stiffens by
  m g L^2 / EI ~ 1e-5;
- energy per cycle (V x the total current over the last period, sine about V_bias / 2 at a
  whole number of steps a period): in steady state the electrical work of a cycle is what the
  hinge dampers dissipate, h sum_k sum_j b_j v_j,k^2 (v from the centreline's hinge angles,
  b_j the scene's hinge damping) plus the drive's resistance, h sum_k V_k (2 V_k - V_b) / (2 R);
  the capacitor's charge returns within C a^2 (1 - cos omega h)^2 / 2 a step; the piezo
  drive's docstring shows the step map balances exactly (measured 0.25 % at f_1, 0.03 % at f_1 / 2).
"""

import numpy as np
import pytest
from pathlib import Path
from scipy import optimize as so

from mjeap import rollout
from mjeap.model import variants as design
from mjeap.studies import sweep
from mjeap.cli import main
from mjeap.errors import ParameterError, UnknownNameError
from mjeap.model.catalog import CATALOG
from mjeap.model.materials import RangeWarning

#: a uniform PZT-5H bimorph, 12 x 3 mm (its closed forms are written in these tests)
BIMORPH = (Path(__file__).resolve().parents[2] / "examples" / "actuators" / "uniform-bimorph.toml").read_text()
E_P, E_CF, RHO_P, RHO_CF, T_P, T_CF, W, F31 = 40e9, 340e9, 7500.0, 1550.0, 127e-6, 60e-6, 3e-3, 32.0


@pytest.fixture
def bimorph(tmp_path):
    p = tmp_path / "bimorph.toml"
    p.write_text(BIMORPH)
    return str(p)


def _stiffness_per_width(t_p=T_P):
    E = np.array([E_P, E_CF, E_P])
    t = np.array([t_p, T_CF, t_p])
    z = np.cumsum(t) - t / 2
    zn = np.sum(E * t * z) / np.sum(E * t)
    return float(np.sum(E * (t**3 / 12 + t * (z - zn) ** 2)))


# ---------------------------------------------------------------- the design helper
def test_design_actuator_replaces_planform_layers_and_roles(bimorph):
    a = design.design_actuator(bimorph, {"actuator.length": 0.008, "actuator.roles.piezo.thickness": 1e-4,
                                         "actuator.layers.core.youngs_modulus": 3e11, "amplitude": 5.0})
    assert a.planform.length == 0.008 and a.planform.base_width == 3e-3
    assert [l.thickness for l in a.layers] == [1e-4, pytest.approx(60e-6), 1e-4]
    assert a.layers[1].youngs_modulus == 3e11 and a.layers[1].sources["youngs_modulus"] == design.DESIGN_SOURCE
    assert "length" in a.planform.source and a.source_file is None
    w = design.design_actuator(bimorph, {"actuator.width": 5e-3})
    assert (w.planform.base_width, w.planform.tip_width) == (5e-3, 5e-3)
    assert design.design_actuator(bimorph, {}) == design.get_base(bimorph)


def test_identified_overrides_follow_their_layered_values():
    """pedot-micro's EI and mass are measured: a wider beam scales both by the layered
    ratio (x 2), a longer one keeps EI and scales the mass (x 1.5)."""
    base = CATALOG["pedot-micro"]
    wide = design.design_actuator("pedot-micro", {"actuator.width": 2 * base.planform.base_width})
    assert wide.flexural_rigidity.value == pytest.approx(2 * base.flexural_rigidity.value, rel=1e-12)
    assert wide.total_mass() == pytest.approx(2 * base.total_mass(), rel=1e-12)
    long = design.design_actuator("pedot-micro", {"actuator.length": 1.5 * base.length})
    assert long.flexural_rigidity.value == base.flexural_rigidity.value
    assert long.total_mass() == pytest.approx(1.5 * base.total_mass(), rel=1e-12)


BAD = [
    ({"actuator.length": -8e-3}, ParameterError, r"actuator.length=-0.008 .*positive quantity in m"),
    ({"actuator.extension_mass": -1e-6}, ParameterError, r"actuator.extension_mass.*non-negative"),
    ({"actuator.layers.core.poisson_ratio": 0.7}, ParameterError, r"poisson_ratio.*\(-1, 0.5\)"),
    ({"actuator.damping_ratio": 1.5}, ParameterError, r"damping_ratio.*\(0, 1\)"),
    ({"actuator.layers.core.youngs_modulus": 340.0}, ParameterError, r"youngs_modulus.*carbon-fibre's range"),
    ({"actuator.layers.pzt-top.thickness": 1e-4}, ParameterError, r"pzt-top.thickness.*roles.piezo.thickness"
                                                                  r".*equally thick"),
    ({"actuator.extension_mass": 1e-6}, ParameterError, r"extension_length > 0"),
    ({"actuator.lenght": 1e-2}, UnknownNameError, r"'actuator.lenght'; did you mean 'actuator.length'"),
    ({"actuator.layers.cor.thickness": 1e-4}, UnknownNameError, r"did you mean 'actuator.layers.core.thickness'"),
]


@pytest.mark.parametrize("params,error,match", BAD, ids=[next(iter(b[0])) + "" for b in BAD])
def test_a_bad_design_value_is_refused_naming_the_parameter_and_range(bimorph, params, error, match):
    with pytest.raises(error, match=match):
        design.design_actuator(bimorph, params)


def test_a_sweep_refuses_bad_design_values_before_any_point_runs(bimorph, tmp_path, monkeypatch):
    monkeypatch.setattr(sweep.runner, "evaluate", lambda *a, **k: pytest.fail("a point ran"))
    with pytest.raises(ParameterError, match=r"actuator.length=-0.004"):
        sweep.run_sweep(sweep.grid(**{"actuator.length": [8e-3, -4e-3]}), tmp_path / "s.csv",
                        metrics=("mass",), base={"actuator": bimorph}, executor="serial", progress=False)
    with pytest.raises(ParameterError, match=r"blocked_force.*without an accuracy target"):
        sweep.run_sweep(sweep.grid(**{"actuator.length": [8e-3]}), tmp_path / "s.csv", metrics=("blocked_force",),
                        base={"actuator": bimorph, "accuracy": 0.01}, executor="serial", progress=False)
    with pytest.raises(ParameterError, match=r"peak_power.*periodic waveform"):
        sweep.run_sweep(sweep.grid(**{"actuator.length": [8e-3]}), tmp_path / "s.csv", metrics=("peak_power",),
                        base={"actuator": bimorph, "waveform": "step"}, executor="serial", progress=False)
    with pytest.warns(RangeWarning, match=r"actuator.roles.piezo.youngs_modulus=5e\+09 Pa lies outside pzt-5h's"):
        sweep.check_settings(sweep.grid(**{"actuator.roles.piezo.youngs_modulus": [5e9, 40e9]}), {"actuator": bimorph})


# ---------------------------------------------------------------- the metrics against references
def test_static_metrics_run_no_rollout_and_match_beta_1_with_a_tip_mass(bimorph, monkeypatch):
    monkeypatch.setattr(sweep.runner, "_run_point", lambda *a, **k: pytest.fail("a rollout ran"))
    D = _stiffness_per_width()
    EI, mu = D * W, W * (2 * RHO_P * T_P + RHO_CF * T_CF)
    for L, m in ((0.010, 0.0), (0.010, 5e-6), (0.014, 20e-6)):
        point = {"actuator.length": L, **({"payload_mass": m, "payload_position": L} if m else {})}
        row = sweep.evaluate(point, ("first_frequency", "mass"), {"actuator": bimorph, "orientation": "down"})
        assert row["error"] == ""
        eta = m / (mu * L)
        beta = so.brentq(lambda b: 1 + np.cos(b) * np.cosh(b)
                         + eta * b * (np.cos(b) * np.sinh(b) - np.sin(b) * np.cosh(b)), 0.3, 1.8752)
        assert row["first_frequency"] == pytest.approx(beta**2 / (2 * np.pi * L**2) * np.sqrt(EI / mu), rel=3e-3)
        assert row["mass"] == pytest.approx(mu * L, rel=1e-12)


@pytest.mark.parametrize("L,t_p", [(0.008, 127e-6), (0.012, 100e-6)])
def test_free_deflection_blocked_force_energy_density_against_the_plate_couple(bimorph, L, t_p):
    """Full drive (V_sig = V_bias = 200 V, V = 200 V), a file bimorph with its length and
    plates varied by the study; run 0.05 s (40+ decay times of the first mode)."""
    base = {"actuator": bimorph, "segments": 20, "orientation": "down", "waveform": "step", "amplitude": 200.0,
            "duration": 0.05}
    row = sweep.evaluate({"actuator.length": L, "actuator.roles.piezo.thickness": t_p},
                         ("free_deflection", "blocked_force", "energy_density", "mass"), base)
    assert row["error"] == ""
    D = _stiffness_per_width(t_p)
    kappa = F31 * 200.0 * (t_p + T_CF) / 2 / D
    free = (1 - np.cos(kappa * L)) / kappa
    blocked = 3 * D * W * kappa / (2 * L)
    mass = W * L * (2 * RHO_P * t_p + RHO_CF * T_CF)
    assert row["free_deflection"] == pytest.approx(free, rel=1e-3)
    assert row["blocked_force"] == pytest.approx(blocked, rel=2e-3)
    assert row["energy_density"] == pytest.approx(blocked * free / (2 * mass), rel=3e-3)


@pytest.mark.parametrize("ratio,fraction", [(1.0, 0.0), (0.5, 0.0), (0.5, 0.4)])
def test_energy_per_cycle_is_what_the_dampers_and_the_resistance_dissipate(bimorph, ratio, fraction):
    """At f_1 and f_1 / 2, the period a whole number of steps and (0.4 step over) not: there
    the reference averages the dissipation over the last 10 periods (its leakage is a step of
    the dissipated power over 10 periods, against the metric's fit to the last period)."""
    base = {"actuator": bimorph, "segments": 10, "orientation": "down"}
    p = {**sweep.PARAMETERS, **base, "actuator.length": 0.010}
    scene = sweep.point_scene(p)
    dt, f1 = scene.timestep, scene.choice.first_frequency
    n = int(round(1 / (ratio * f1 * dt))) + fraction       # steps a period
    f = 1 / (n * dt)
    duration = (int(np.ceil(12 / (0.05 * 2 * np.pi * f1) * f)) + 10) / f     # 12 decay times, then 10 periods
    wave = {"waveform": "sine", "amplitude": 20.0, "offset": 100.0, "frequency": f, "duration": duration}
    row = sweep.evaluate({"actuator.length": 0.010}, ("energy_per_cycle", "peak_power"), {**base, **wave})
    assert row["error"] == ""
    s = sweep.point_scene({**p, **wave})
    r = rollout(s, sweep.wave_text({**p, **wave}), duration, sample_interval=dt, progress=False)
    d = np.diff(r.centreline[:, :, :2], axis=1)               # clamp, link origins, tip: segment directions
    theta = np.diff(np.arctan2(d[..., 1], d[..., 0]), axis=1)   # the hinges' angles
    assert np.allclose(theta[-1], s.hinge_angles(), atol=1e-12)
    v = np.diff(theta, axis=0) / dt
    k = int(round(n)) if fraction == 0 else int(10 * n)      # one whole period, or the last 10 periods' steps
    cycles = k / n
    dampers = dt * np.sum(v[-k:] ** 2 @ s.hinge_damping()) / cycles
    V = r.voltage[-k:]
    resistance = dt * np.sum(V * (2 * V - 200.0) / (2 * 1e9)) / cycles
    assert row["energy_per_cycle"] == pytest.approx(dampers + resistance, rel=1e-2)
    m = int(round(n))
    assert row["peak_power"] == pytest.approx(np.max(np.abs(r.voltage[-m:] * r.signals["current (A)"][-m:])),
                                              rel=1e-12)
    assert row["peak_power"] >= row["energy_per_cycle"] * f


# ---------------------------------------------------------------- sweeps of designs
def test_sweep_of_designs_streams_resumes_and_agrees_across_executors(bimorph, tmp_path):
    points = sweep.grid(**{"actuator.length": [8e-3, 12e-3], "actuator.roles.piezo.thickness": [100e-6, 127e-6]})
    base = {"actuator": bimorph, "segments": 8}
    a = sweep.run_sweep(points, tmp_path / "a.csv", metrics=("first_frequency", "mass"), base=base,
                        executor="serial", progress=False)
    b = sweep.run_sweep(points, tmp_path / "b.csv", metrics=("first_frequency", "mass"), base=base,
                        executor="processes", workers=2, progress=False)
    assert a.failed == b.failed == 0 and a.done == b.done == 4
    rows_a = {r["point_id"]: r["first_frequency"] for r in sweep.read_results(a.path)}
    assert rows_a == {r["point_id"]: r["first_frequency"] for r in sweep.read_results(b.path)}
    again = sweep.run_sweep(points, tmp_path / "a.csv", metrics=("first_frequency", "mass"), base=base,
                            executor="serial", progress=False)
    assert (again.done, again.skipped) == (0, 4)
    # the file's content is part of each point's key: an edited file computes its points again
    (tmp_path / "bimorph.toml").write_text(BIMORPH.replace('"3 mm"', '"4 mm"'))
    edited = sweep.run_sweep(points, tmp_path / "a.csv", metrics=("first_frequency", "mass"), base=base,
                             executor="serial", progress=False)
    assert (edited.done, edited.skipped) == (4, 0)


def test_cli_sweep_takes_design_parameters_with_units(bimorph, tmp_path, capsys):
    out = tmp_path / "s.csv"
    assert main(["sweep", "--vary", "actuator.length=8mm:16mm:3", "--set", f"actuator={bimorph}",
                 "--set", "segments=8", "--metrics", "first_frequency,mass", "--out", str(out),
                 "--executor", "serial", "--quiet"]) == 0
    rows = sweep.read_results(out)
    assert sorted(float(r["actuator.length"]) for r in rows) == [0.008, 0.012, 0.016]
    mu = W * (2 * RHO_P * T_P + RHO_CF * T_CF)
    assert all(float(r["mass"]) == pytest.approx(mu * float(r["actuator.length"]), rel=1e-12) for r in rows)
    capsys.readouterr()
    assert main(["sweep", "--vary", "actuator.lenght=8mm:16mm:3", "--set", f"actuator={bimorph}",
                 "--out", str(tmp_path / "t.csv")]) == 2
    assert "did you mean 'actuator.length'" in capsys.readouterr().err


@pytest.mark.slow
def test_dask_runs_design_points_as_the_local_processes_do(bimorph, tmp_path):
    pytest.importorskip("distributed")
    points = sweep.grid(**{"actuator.length": [8e-3, 12e-3]})
    base = {"actuator": bimorph, "segments": 6, "waveform": "step", "amplitude": 200.0, "duration": 0.01}
    metrics = ("first_frequency", "free_deflection")
    a = sweep.run_sweep(points, tmp_path / "a.csv", metrics=metrics, base=base, executor="serial", progress=False)
    d = sweep.run_sweep(points, tmp_path / "d.csv", metrics=metrics, base=base, executor="dask", workers=1,
                        progress=False)
    assert a.failed == d.failed == 0
    key = lambda rows: {r["point_id"]: (r["first_frequency"], r["free_deflection"]) for r in rows}   # noqa: E731
    assert key(sweep.read_results(a.path)) == key(sweep.read_results(d.path))


def test_a_registered_scene_metric_runs_no_rollout(bimorph, monkeypatch):
    monkeypatch.setattr(sweep.metrics, "METRICS", dict(sweep.METRICS))
    monkeypatch.setattr(sweep.metrics, "STATIC_METRICS", set(sweep.STATIC_METRICS))
    sweep.register_metric("segments_used", lambda r, p, scene: scene.layout.segments, rollout=False)
    monkeypatch.setattr(sweep.runner, "_run_point", lambda *a, **k: pytest.fail("a rollout ran"))
    row = sweep.evaluate({"actuator.length": 9e-3}, ("segments_used", "mass"), {"actuator": bimorph, "segments": 7})
    assert row["error"] == "" and row["segments_used"] == 7


def test_a_drive_parameter_of_a_file_actuator_is_checked_before_any_point(bimorph, tmp_path):
    with pytest.raises(UnknownNameError, match="piezo-bimorph drive parameter.*'d31'"):
        sweep.run_sweep(sweep.grid(**{"actuator.length": [8e-3]}), tmp_path / "s.csv", metrics=("mass",),
                        base={"actuator": bimorph, "drive.d31": 1.0}, executor="serial", progress=False)
