"""mjeap.analysis.identify on simulated data with known truth (with noise) and on bad data files."""
import json

import numpy as np
import pytest
from scipy import signal

from mjeap import ParameterError, Scene
from mjeap.cli import main
from mjeap.analysis.identify import fit_hinge_parameters, fit_step_response, read_columns, simulate_tip

TRUTH = dict(gain=63.0, zero=0.52, pole_mechanical=0.3, pole_electrical=1.8)   # Dadras et al. 2021, eq. 8


def step_data(noise, k0=-174.0, dt=0.01, T=20.0, seed=0):
    """Exact response of eq. (8) to a 3 V step from kappa(0-) = k0 (zero-input on the 0.3 pole)."""
    t = np.arange(0, T, dt)
    tf = signal.TransferFunction([63.0, 63.0 * 0.52], np.polymul([1, 0.3], [1, 1.8]))
    _, y, _ = signal.lsim(tf, 3.0 * np.ones_like(t), t)
    y = y + k0 * np.exp(-0.3 * t)
    rng = np.random.default_rng(seed)
    return t, y + rng.normal(0, noise * np.ptp(y), len(t))


def test_step_fit_recovers_eq8_without_noise():
    t, k = step_data(0.0)
    fit = fit_step_response(t, k, 3.0)
    for name, v in TRUTH.items():
        assert getattr(fit, name) == pytest.approx(v, rel=1e-4), name
    assert fit.initial_curvature == pytest.approx(-174.0, rel=1e-4)


def test_step_fit_with_noise_within_its_own_uncertainty_scale():
    """0.5 % white noise on 2000 samples: parameters within 5 % (the electrical pole is the
    least determined: its transient lasts ~2 s of the 20 s record); the fitted curve
    leaves the noise (RMS residual within 10 % of the noise level)."""
    t, k = step_data(0.005)
    fit = fit_step_response(t, k, 3.0)
    for name, v in TRUTH.items():
        assert getattr(fit, name) == pytest.approx(v, rel=0.05), name
    assert fit.rms_residual == pytest.approx(0.005 * np.ptp(k), rel=0.1)


@pytest.mark.slow
def test_step_fit_drive_runs_and_reproduces_the_data():
    """The fitted drive in a rollout reproduces the data it was fitted to (2 % of the swing)."""
    from mjeap import rollout
    t, k = step_data(0.0, T=15.0)
    fit = fit_step_response(t, k, 3.0)
    scene = Scene("pedot-micro")
    r = rollout(scene, "step:3V", 15.0, drive=fit.make_drive(scene), initial_curvature=fit.initial_curvature,
                progress=False)
    ref = np.interp(r.time, t, k)
    assert np.sqrt(np.mean((r.tip_curvature - ref) ** 2)) < 0.02 * np.ptp(ref)


@pytest.mark.slow
def test_hinge_fit_recovers_stiffness_and_damping_with_noise():
    """Mutlu et al. 2013's identification: 1 % noise, truth k = 1.3 k0, b = 10 b0; both within 2 %."""
    s = Scene("ppy-trilayer", segments=16)
    k0, b0 = float(s.hinge_stiffness()[0]), float(s.hinge_damping()[0])
    t = np.arange(0.001, 0.3, 0.001)
    dp = {"time_constant": 0.01}
    y = simulate_tip(s, 1.3 * k0, 10 * b0, "step:1V", 0.3, t, drive_params=dp)
    y = y + np.random.default_rng(1).normal(0, 0.01 * np.ptp(y), len(t))
    fit = fit_hinge_parameters(s, t, y, "step:1V", drive_params=dp, initial=(k0, b0))
    assert fit.stiffness == pytest.approx(1.3 * k0, rel=0.02)
    assert fit.damping == pytest.approx(10 * b0, rel=0.02)
    assert fit.stiffness_std < 0.02 * fit.stiffness


def write(tmp_path, text, name="data.csv"):
    p = tmp_path / name
    p.write_text(text)
    return p


def good_csv(tmp_path, n=50):
    t, k = step_data(0.0, dt=0.4)
    lines = ["time (s),tip_curvature (1/m)"] + [f"{a},{b}" for a, b in zip(t[:n], k[:n])]
    return write(tmp_path, "\n".join(lines))


@pytest.mark.parametrize("mutate,match", [
    (lambda L: [L[0].replace("tip_curvature", "kappa")] + L[1:], "column.*tip_curvature"),
    (lambda L: L[:10] + [L[12], L[11]] + L[13:], "strictly increasing"),
    (lambda L: L[:5] + ["1.6,nan"] + L[6:], "NaN"),
    (lambda L: L[:8], "at least 20 samples"),
    (lambda L: L[:5] + ["1.6,abc"] + L[6:], "numbers"),
])
def test_bad_data_files_get_clear_errors(tmp_path, mutate, match):
    lines = good_csv(tmp_path).read_text().splitlines()
    p = write(tmp_path, "\n".join(mutate(lines)), "bad.csv")
    with pytest.raises(ParameterError, match=match):
        read_columns(p, ["time", "tip_curvature"])


def test_missing_file_is_named(tmp_path):
    with pytest.raises(ParameterError, match="data file"):
        read_columns(tmp_path / "nope.csv", ["time"])


def test_cli_identify_step(tmp_path, capsys):
    t, k = step_data(0.0)
    p = write(tmp_path, "time (s),tip_curvature (1/m)\n" + "\n".join(f"{a},{b}" for a, b in zip(t, k)))
    assert main(["identify", "step", str(p), "--voltage", "3"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["drive_parameters"]["gain"] == pytest.approx(63.0, rel=1e-3)
    # bad data: exit code 2 and the reason on stderr
    bad = write(tmp_path, "time,x\n1,2\n", "bad.csv")
    assert main(["identify", "step", str(bad), "--voltage", "3"]) == 2
    assert "tip_curvature" in capsys.readouterr().err


def test_bad_hinge_parameters_change_nothing():
    """Refused values leave the hinges, and the scene's derivability, as they were."""
    from mjeap import Scene
    from mjeap.errors import ParameterError
    s = Scene("pedot-micro", segments=6)
    k0 = s.part.hinge_stiffness().copy()
    for kw in (dict(stiffness=-1.0), dict(stiffness=2 * k0, damping=-1.0)):
        with pytest.raises(ParameterError):
            s.set_hinge_parameters(**kw)
        np.testing.assert_array_equal(s.part.hinge_stiffness(), k0)
        assert s.part.revision == 0
