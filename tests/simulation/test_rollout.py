"""Rollouts: recordings, user drives, waveforms, bad input, divergence."""
import numpy as np
import pytest

from mjeap import (DRIVES, DivergenceError, Drive, ParameterError, Scene, UnknownNameError, parse_waveform, register_drive, rollout)
from mjeap.cli import main
from mjeap.io.recording import read_recording


def scalars(rec, entity):
    import pyarrow as pa
    batches = [b for b in rec[entity] if "Scalars:scalars" in b.schema.names]
    col = pa.concat_arrays([b.column(b.schema.names.index("Scalars:scalars")) for b in batches])
    return np.array([x[0] for x in col.to_pylist()])


def test_recording_holds_beam_series_and_reference(tmp_path):
    path = tmp_path / "run.rrd"
    r = rollout(Scene("pedot-micro"), "square:1V@0.5Hz", 2.0, rrd=path, progress=False)
    rec = read_recording(path)
    for ent in ("/beam/centreline", "/beam/clamp", "/beam/tip", "/plots/voltage", "/plots/tip_curvature/simulated",
                "/plots/tip_curvature/reference", "/plots/drive/charge", "/plots/drive/drive_moment",
                "/plots/tip_position/y", "/meta"):
        assert ent in rec, ent
    np.testing.assert_allclose(scalars(rec, "/plots/voltage"), r.voltage)
    np.testing.assert_allclose(scalars(rec, "/plots/tip_curvature/simulated"), r.tip_curvature)
    np.testing.assert_allclose(scalars(rec, "/plots/tip_curvature/reference"), r.reference_curvature)
    strips = [b for b in rec["/beam/centreline"] if "LineStrips3D:strips" in b.schema.names]
    assert sum(b.num_rows for b in strips) > 100


def test_user_drive_registers_and_runs():
    """A drive written outside the package: a constant moment per volt, 2nd-order free."""

    @register_drive
    class MomentPerVolt(Drive):
        name = "test-moment-per-volt"

        def step(self, voltage, dt):
            self.scene.set_internal_moments(1e-7 * voltage)

        def signals(self):
            return {"moment (N m)": 0.0}

    try:
        s = Scene("pedot-micro")
        r = rollout(s, "step:2V", 0.2, drive="test-moment-per-volt", progress=False)
        EI = 1 / 4.86e7
        assert r.tip_curvature[-1] == pytest.approx(2e-7 / EI, rel=0.01)
    finally:
        DRIVES.pop("test-moment-per-volt")


def test_waveform_shapes():
    t = np.array([0.0, 2.5, 5.0, 7.5])
    np.testing.assert_allclose(parse_waveform("square:1.5V@0.1Hz")(t), [1.5, 1.5, -1.5, -1.5])
    np.testing.assert_allclose(parse_waveform("square:1V@0.1Hz,duty=0.25,offset=1V")(t), [2, 0, 0, 0])
    np.testing.assert_allclose(parse_waveform("sine:2V@0.1Hz")(t), [0, 2, 0, -2], atol=1e-12)
    np.testing.assert_allclose(parse_waveform("triangle:1V@0.1Hz")(t), [0, 1, 0, -1], atol=1e-12)
    np.testing.assert_allclose(parse_waveform("step:3V,delay=1s")(t), [0, 3, 3, 3])
    ch = parse_waveform("chirp:1V@1Hz..3Hz").with_duration(2.0)
    assert abs(ch(np.array([0.25]))[0] - np.sin(2 * np.pi * (0.25 + 0.5 * 0.0625))) < 1e-12


def test_csv_waveform_and_its_errors(tmp_path):
    good = tmp_path / "v.csv"
    good.write_text("time,voltage\n0,0\n1,2\n2,2\n")
    np.testing.assert_allclose(parse_waveform(f"csv:{good}")(np.array([0.5, 1.5, 5.0])), [1, 2, 2])
    cases = {"nan.csv": ("time,voltage\n0,0\n1,nan\n", "NaN"),
             "cols.csv": ("t_ms,volts2\n0,0\n1,1\n", "columns"),
             "order.csv": ("time,voltage\n0,0\n0,1\n", "increasing"),
             "short.csv": ("time,voltage\n0,0\n", "at least 2")}
    for name, (text, msg) in cases.items():
        p = tmp_path / name
        p.write_text(text)
        with pytest.raises(ParameterError, match=msg):
            parse_waveform(f"csv:{p}")


@pytest.mark.parametrize("actuator,voltage,match", [
    ("pedot-micro", "step:3.5V", r"\[-3, 3\] V"),            # electrolysis above ~3 V
    ("pzt-hamr-small", "sine:150V@100Hz,offset=100V", r"\[0, 200\] V"),  # beyond [0, V_bias]
])
def test_voltage_outside_safe_range(actuator, voltage, match):
    with pytest.raises(ParameterError, match=match):
        rollout(Scene(actuator), voltage, 0.01, progress=False)


def test_unknown_drive_and_waveform():
    with pytest.raises(UnknownNameError, match="rc-relaxation"):
        rollout(Scene("pedot-micro"), "step:1V", 0.1, drive="rc-relax")
    with pytest.raises(UnknownNameError, match="square"):
        rollout(Scene("pedot-micro"), "sqare:1V@1Hz", 0.1)


def test_divergence_stops_with_reason_and_recording_is_closed(tmp_path):
    """A drive that blows the beam up with a NaN moment: the error names the drive, the time
    and the step (not the timestep: the drive's output was not finite); the recording
    written so far opens and ends with the error."""

    @register_drive
    class Exploding(Drive):
        name = "test-exploding"

        def step(self, voltage, dt):
            t = self.scene.time
            self.scene.set_internal_moments(np.nan if t > 0.01 else 1e-7)

    path = tmp_path / "boom.rrd"
    try:
        with pytest.raises(DivergenceError, match=r"test-exploding applied a non-finite moment.*\(step \d+\)"):
            rollout(Scene("pedot-micro"), "step:1V", 0.1, drive="test-exploding", rrd=path, progress=False)
    finally:
        DRIVES.pop("test-exploding")
    rec = read_recording(path)
    assert "/log" in rec and "/plots/voltage" in rec
    texts = [x for b in rec["/log"] for x in b.column(b.schema.names.index("TextLog:text")).to_pylist()]
    assert any("DivergenceError" in str(t) for t in texts)


def test_cli_rollout_writes_recording_and_csv(tmp_path, capsys):
    rrd, csv = tmp_path / "r.rrd", tmp_path / "r.csv"
    assert main(["rollout", "ppy-trilayer", "--voltage", "step:1V", "--duration", "1", "--rrd", str(rrd),
                 "--csv", str(csv), "--quiet"]) == 0
    assert rrd.stat().st_size > 0
    lines = csv.read_text().splitlines()
    assert lines[0].startswith("time (s),voltage (V)") and len(lines) > 100
    assert main(["rollout", "pedot-micro", "--voltage", "step:5V", "--duration", "1"]) == 2
    assert "safe range" in capsys.readouterr().err


@pytest.mark.parametrize("engine", ["loop", "native"])
def test_tip_force_acts_as_a_dead_load_through_rollouts(engine):
    """A tip force set on the scene survives the rollout's reset and stays a dead load at
    the tip point (massless tip-load body): the settled tip under P L^2/EI = 1 with a drive
    at 0 V (no moment) matches the elastica within 0.5 % (20 hinges: -0.07 %), the same as
    Scene.run, on the loop and on the native engine (the load as xfrc_applied controls).
    Before the load body, the rollout lost the load at reset."""
    from mjeap import analytical as an
    s = Scene("ppy-trilayer", gravity=False, damping_ratio=0.7)
    L, EI = s.layout.length, float(s.actuator.flexural_rigidity_at(0.0)[0])
    P = EI / L**2
    s.set_tip_force(P)
    r = rollout(s, "step:0V", 40 / s.choice.first_frequency, engine=engine)
    ref = an.elastica_tip_force(P, L, EI).tip
    assert r.meta["engine"] == engine
    assert r.tip_position[-1, 1] == pytest.approx(ref[1], rel=5e-3)
    assert r.tip_position[-1, 0] == pytest.approx(ref[0], abs=5e-3 * L)


@pytest.mark.parametrize("representation", ["hinge", "cable"])
def test_samples_equal_the_scene_read_outs(representation):
    """Samples store raw MuJoCo positions and are converted at the end: the last sample
    equals the scene's own SI read-outs at the final state (rotated clamp, payload)."""
    from mjeap import Payload
    s = Scene("pedot-micro", representation=representation, orientation="up", payload=Payload(5e-6, 4e-3))
    r = rollout(s, "sine:1V@2Hz", 0.3, initial_curvature=-50.0)
    np.testing.assert_allclose(r.centreline[-1], s.centreline(), rtol=0, atol=1e-15)
    np.testing.assert_allclose(r.tip_position[-1], s.tip_position(), rtol=0, atol=1e-15)
    np.testing.assert_allclose(r.payload_position[-1], s.payload_position(), rtol=0, atol=1e-15)
    assert r.tip_angle[-1] == pytest.approx(s.tip_angle(), abs=1e-13)
    assert r.tip_curvature[-1] == pytest.approx(s.tip_curvature(), rel=1e-12)
