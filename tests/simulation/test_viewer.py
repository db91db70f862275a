"""mjeap view without its window: the refusal without a display, the model it would show
(the driven model in seconds, the slider's range in volts), the real-time pacing, and
mjeap mjcf's driven model file."""
import sys

import mujoco
import numpy as np
import pytest

from mjeap import Scene
from mjeap.assets import path
from mjeap.cli import main
from mjeap.drives import make_drive
from mjeap.errors import ParameterError
from mjeap.model.fields import read_units
from mjeap.simulation.viewer import (MAX_STEPS_PER_FRAME, NoDisplayError, display_reason, file_view_model, steps_due,
                                     system_view_model, view, view_model)
from mjeap.units import REAL_TIME_UNITS


def test_display_reason():
    """A display is what the viewer's GLFW window needs on Linux; MUJOCO_GL (the off-screen
    renderer's GL, 'disable' under mjeap) does not matter to it."""
    assert display_reason({"DISPLAY": ":0"}, "linux") is None
    assert display_reason({"WAYLAND_DISPLAY": "wayland-0", "MUJOCO_GL": "disable"}, "linux") is None
    assert "DISPLAY" in display_reason({}, "linux")
    assert display_reason({}, "darwin") is None


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="the display check is Linux's (X11 / Wayland)")
def test_view_refuses_without_a_display_before_any_work(capsys, monkeypatch):
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    assert main(["view", "no-such-actuator"]) == 2          # refused before the name is even read
    err = capsys.readouterr().err
    assert "mjeap view needs a display" in err and "neither DISPLAY nor WAYLAND_DISPLAY" in err
    assert "mjeap mjcf no-such-actuator -o FILE" in err
    s = Scene("pedot-micro", units=REAL_TIME_UNITS)
    with pytest.raises(NoDisplayError):
        view(view_model(s), slow_motion=100)


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="X11")
def test_view_refuses_a_display_that_does_not_open(capsys, monkeypatch):
    """DISPLAY set to a display that is not there: GLFW is tried first, and the command
    stops with its reason (MuJoCo's viewer would exit the process)."""
    monkeypatch.setenv("DISPLAY", ":97")
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    from mjeap.simulation.viewer import window_reason
    why = window_reason()
    if why is None:
        pytest.skip("an X server answers on :97 here")
    assert main(["view", "pedot-micro"]) == 2
    assert "needs a display" in capsys.readouterr().err


@pytest.mark.parametrize("actuator_id", ["pedot-micro", "pzt-robobee"])
def test_view_model_is_the_driven_model_in_seconds_with_a_slider_in_volts(actuator_id):
    """The slider is actuator 'drive', its range the drive's voltage range (V); the model
    is in seconds; a piezo starts at its rest voltage; full voltage bends the beam the way
    mjeap's own run does (same sign, 1e-9 of the swing: the same model)."""
    s = Scene(actuator_id, units=REAL_TIME_UNITS)
    drv = make_drive(None, s)
    vm = view_model(s)
    assert vm.units.time == 1.0 and read_units(vm.model).time == 1.0
    assert vm.voltage_range == drv.voltage_range()
    a = vm.model.actuator("drive")
    assert tuple(a.ctrlrange) == drv.voltage_range()
    assert vm.data.ctrl[a.id] == drv.rest_voltage()
    assert vm.timestep == pytest.approx(s.timestep, rel=1e-12)
    vm.data.ctrl[a.id] = drv.voltage_range()[1]
    vm.advance(200)
    assert vm.time == pytest.approx(200 * s.timestep, rel=1e-9)
    nat = s.native_model(drv)
    d = mujoco.MjData(nat.model)
    if drv.rest_voltage():
        mujoco.mj_resetDataKeyframe(nat.model, d, 0) if nat.model.nkey else None
    d.ctrl[0] = drv.voltage_range()[1]
    mujoco.mj_step(nat.model, d, nstep=200)
    assert np.allclose(vm.data.qpos, d.qpos, rtol=0, atol=1e-9 * np.abs(d.qpos).max())
    assert np.abs(vm.data.qpos).max() > 0


def test_view_model_of_a_loaded_standing_scene():
    """--payload and --orientation reach the scene the viewer shows."""
    s = Scene("pedot-micro", orientation="up", payload="12.6mg@6.27mm", units=REAL_TIME_UNITS)
    vm = view_model(s)
    assert vm.model.body("payload").mass[0] == s.model.body("payload").mass[0]
    assert vm.model.body_mass.sum() == pytest.approx(s.model.body_mass.sum(), rel=1e-9)
    assert np.allclose(vm.model.opt.gravity, s.model.opt.gravity)


def test_a_drive_without_native_form_needs_a_waveform_and_is_stepped_by_mjeap():
    s = Scene("pvdf-60", units=REAL_TIME_UNITS)
    with pytest.raises(ParameterError, match="voltage"):
        view_model(s)
    vm = view_model(s, voltage="step:700V")
    assert vm.voltage_range is None and vm.drive is not None
    vm.advance(100)
    assert vm.time == pytest.approx(100 * s.timestep) and abs(s.tip_curvature()) > 0


def test_file_view_model_reads_the_units_and_the_slider():
    vm = file_view_model(path("pzt-hamr-small"))
    assert vm.units.time == 1.0 and vm.voltage_range == tuple(vm.model.actuator("drive").ctrlrange)


def test_a_robot_shows_its_actuators_voltages_on_sliders():
    """robobee-wing: its actuator's ctrl is the drive voltage (V, the drive's range), stepped
    by the System (what mjeap view ROBOT shows)."""
    from mjeap.robots import load
    wing = load("robobee-wing")
    vm = system_view_model(wing, "robot robobee-wing")
    drv = wing.actuators[0].drive
    assert vm.voltage_range == tuple(float(x) for x in drv.voltage_range())
    assert vm.units is wing.units and vm.timestep == wing.timestep
    vm.data.ctrl[0] = drv.voltage_range()[1]
    vm.advance(50)
    assert vm.time == pytest.approx(50 * wing.timestep) and wing.time == vm.time


def test_pacing_arithmetic():
    """Simulated time follows wall time / slow motion, whole steps, never backwards, capped."""
    assert steps_due(0.0, 0.01, 1.0, 1e-4) == 100              # real time: 10 ms of wall, 100 steps of 0.1 ms
    assert steps_due(0.0, 1.0, 100.0, 1e-4) == 100             # 100x slow motion: 1 s of wall is 10 ms
    assert steps_due(0.005, 1.0, 100.0, 1e-4) == 50            # half of it already simulated
    assert steps_due(0.02, 1.0, 100.0, 1e-4) == 0              # ahead of the wall: wait
    assert steps_due(0.0, 10.0, 1.0, 1e-4) == MAX_STEPS_PER_FRAME
    assert steps_due(0.0, 3 * 7.67e-5, 1.0, 7.67e-5) == 3      # no lost step to rounding


def test_mjcf_command_writes_the_driven_model_in_volts_and_seconds(tmp_path):
    """mjeap mjcf NAME: the model with its drive (actuator 'drive', ctrlrange the drive's
    range in V, the RC pole 1.8 /s of Dadras et al. 2021 as filter time constant in s); the same
    model as the shipped file."""
    out = tmp_path / "pedot.xml"
    assert main(["mjcf", "pedot-micro", "-o", str(out)]) == 0
    m = mujoco.MjModel.from_xml_path(str(out))
    u = read_units(m)
    assert (u.length, u.mass, u.time) == (1e-3, 1e-6, 1.0)
    a = m.actuator("drive")
    assert tuple(a.ctrlrange) == (-3.0, 3.0)
    assert a.dynprm[0] * u.time == pytest.approx(1 / 1.8)
    body = out.read_text().split("-->\n", 1)[1]
    assert body == path("pedot-micro").read_text().split("-->\n", 1)[1]


@pytest.mark.parametrize("argv,slider", [(["pzt-hamr-small", "--payload", "1mg@10mm"], (0.0, 200.0)),
                                         (["robobee-wing"], (0.0, 200.0)),
                                         (["pvdf-60", "--voltage", "step:700V"], None)])
def test_view_command_builds_what_it_would_show(monkeypatch, capsys, argv, slider):
    """The command up to the window (the window replaced): an actuator with its options, a
    robot, a drive without native form with a waveform; the fast piezo gets the hint to
    slow down."""
    from mjeap.simulation import viewer
    shown = {}

    def fake_view(vm, slow_motion=1.0, duration=None):
        shown["vm"], shown["slow"] = vm, slow_motion
        vm.advance(3)
        return {"simulated_s": vm.time, "wall_s": 0.0, "max_lag_s": 0.0}

    monkeypatch.setattr(viewer, "window_reason", lambda: None)
    monkeypatch.setattr(viewer, "view", fake_view)
    assert main(["view", *argv]) == 0
    vm = shown["vm"]
    assert vm.voltage_range == slider and vm.time > 0
    err = capsys.readouterr().err
    if argv[0] == "pzt-hamr-small":
        assert "1mg" not in err and vm.model.body("payload").mass[0] == pytest.approx(1.0)   # 1 mg, internal
        assert "--slow-motion 1000 shows it in ~0.5 s" in err
