"""One contract, clear errors, before any work (issue sections 4 and 6): each test failed on
the code before it (eaac59e) with a raw traceback, a silent answer, a late failure, a hang or
a process left behind."""
import csv
import math
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import mujoco
import numpy as np
import pytest

from mjeap import ParameterError, Scene, rollout
from mjeap.cli import main
from mjeap.simulation.system import System, attach
import mjeap.studies.sweep
from mjeap.studies.sweep import grid, read_results, run_sweep

ROOT = Path(__file__).resolve().parents[2]
#: the sweep's point limit (read so: the module imports where the limit is missing)
MAX_POINTS = getattr(mjeap.studies.sweep, "MAX_POINTS", 1_000_000)


def _no_work(*a, **k):
    raise AssertionError("the work started before the arguments were checked")


def _system():
    spec = mujoco.MjSpec.from_string('<mujoco><option gravity="0 0 0"/><worldbody><site name="m"/></worldbody>'
                                     '</mujoco>')
    return System(spec, [attach(spec, "pedot-micro", site="m", prefix="act", contact=False)])


# ---------------------------------------------------------------- one controller contract
def test_one_controller_contract_for_rollout_and_system():
    """A plain function drives a scene's rollout as it drives a System; an object's
    ``reset``, ``interval`` and ``name`` are used by both (a System used to call every step
    and never reset); anything not callable is refused by both, naming the contract."""
    r = rollout(Scene("pedot-micro"), None, 0.01, controller=lambda t, scene: 1.0, progress=False)
    assert np.all(r.voltage[1:] == 1.0) and r.meta["controller"] == "<lambda>"

    class Counting:
        name, interval = "counting", None

        def __init__(self):
            self.calls, self.resets = 0, []

        def reset(self, target, drive):
            self.resets.append((type(target).__name__, drive))
            self.interval = 5 * target.timestep           # set in reset, read after it

        def __call__(self, t, target):
            self.calls += 1
            return 0.5

    s = _system()
    n = int(round(0.01 / s.timestep))
    c = Counting()
    res = s.rollout(None, 0.01, controller=c)
    assert c.resets == [("System", None)] and c.calls == -(-n // 5)
    assert res.meta["actuators"]["act"]["voltage"] == "controller: counting"
    c = Counting()
    rollout(Scene("pedot-micro"), None, 0.01, controller=c, progress=False)
    assert c.resets[0][0] == "Scene" and c.resets[0][1] is not None
    for run in (lambda: rollout(Scene("pedot-micro"), None, 0.01, controller=3.0),
                lambda: s.rollout(None, 0.01, controller=3.0)):
        with pytest.raises(ParameterError, match=r"controller=3.0.*callable controller\(t, scene_or_system\)"):
            run()
    with pytest.raises(ParameterError, match="controller.interval"):
        rollout(Scene("pedot-micro"), None, 0.01, controller=type("Bad", (), {"interval": -1.0,
                                                                               "__call__": lambda self, t, s: 0.0})())
    with pytest.raises(ParameterError, match="voltage='step:1V'.*None when a controller"):
        rollout(Scene("pedot-micro"), "step:1V", 0.01, controller=lambda t, scene: 1.0)


# ---------------------------------------------------------------- the CLI's model flags
def test_cli_rollout_refuses_model_flags_with_accuracy_alike(monkeypatch, capsys):
    """--accuracy chooses segments, integrator and timestep: each given with it is refused
    as --timestep was (--segments 50 used to run silently with 13 segments)."""
    import mjeap.simulation.rollout as ro
    monkeypatch.setattr(ro, "rollout", _no_work)
    for flag, value in (("--segments", "50"), ("--integrator", "discrete"), ("--timestep", "1e-5")):
        assert main(["rollout", "pedot-micro", "--voltage", "step:1V", "--duration", "0.1", "--accuracy", "1e-3",
                     flag, value]) == 2
        err = capsys.readouterr().err
        assert f"{flag}=" in err and "no " + flag + " with --accuracy" in err and "Traceback" not in err


# ---------------------------------------------------------------- sweeps
def _resave_as_spreadsheet(path: Path, header: bool = True) -> None:
    """The CSV as a spreadsheet saves it in a ';' locale: a UTF-8 BOM, ';' delimiters."""
    with open(path, newline="") as fh:
        rows = list(csv.reader(fh))
    with open(path, "w", newline="", encoding="utf-8-sig") as fh:
        csv.writer(fh, delimiter=";").writerows(rows if header else rows[1:])


BASE = {"duration": 0.01, "waveform": "step"}


def test_sweep_resumes_a_csv_resaved_by_a_spreadsheet(tmp_path):
    """A BOM and ';' delimiters are read as mjeap.io.csvio reads users' files (its points are
    skipped; new rows go on in the file's form); a file whose header was lost is refused
    naming the file and point_id (it was KeyError: 'point_id')."""
    out = tmp_path / "s.csv"
    assert run_sweep(grid(amplitude=[0.5]), out, base=BASE, executor="serial").done == 1
    _resave_as_spreadsheet(out)
    s = run_sweep(grid(amplitude=[0.5, 0.25]), out, base=BASE, executor="serial")
    assert (s.done, s.skipped) == (1, 1)
    rows = read_results(out)
    assert sorted(float(r["amplitude"]) for r in rows) == [0.25, 0.5] and all(not r["error"] for r in rows)
    assert out.read_bytes().startswith(b"\xef\xbb\xbf") and out.read_text("utf-8-sig").splitlines()[-1].count(";") > 3
    lost = tmp_path / "lost.csv"
    with open(out, newline="", encoding="utf-8-sig") as fh:
        body = list(csv.reader(fh, delimiter=";"))[1:]
    with open(lost, "w", newline="", encoding="utf-8-sig") as fh:
        csv.writer(fh, delimiter=";").writerows(body)
    with pytest.raises(ParameterError, match=r"path='.*lost\.csv'.*naming point_id.*header row was lost"):
        run_sweep(grid(amplitude=[0.5]), lost, base=BASE, executor="serial")
    with pytest.raises(ParameterError, match="point_id"):
        read_results(lost)


def test_a_design_beyond_the_point_limit_is_refused_before_it_is_built(monkeypatch, capsys, tmp_path):
    """--vary amplitude=0:1:1000000000 allocated until MemoryError: the count is refused
    from the spec's arithmetic, naming it and MAX_POINTS; a grid whose product is too large
    and a random design too."""
    import mjeap.cli.studies as cli
    import mjeap.studies.sweep as sweep
    monkeypatch.setattr(cli.np, "linspace", _no_work)
    monkeypatch.setattr(sweep, "run_sweep", _no_work)
    assert main(["sweep", "--vary", "amplitude=0:1:1000000000", "--out", str(tmp_path / "s.csv")]) == 2
    err = capsys.readouterr().err
    assert "1,000,000,000 points" in err and f"{MAX_POINTS:,}" in err and "Traceback" not in err
    monkeypatch.undo()
    with pytest.raises(ParameterError, match=r"grid='1,002,001 points'.*at most MAX_POINTS"):
        grid(amplitude=range(1001), frequency=range(1001))
    with pytest.raises(ParameterError, match=r"n='2,000,000 points'"):
        sweep.random_design(2 * MAX_POINTS, amplitude=(0.0, 1.0))


@pytest.mark.parametrize("setting, value, match", [
    ("accuracy", math.nan, r"accuracy \(--set / base\)=nan.*\[1e-05, 0.2\]"),
    ("duration", 1e9, r"duration \(--set / base\)='1e\+09 s'.*to 20,000,000 steps of"),
    ("waveform", "csv:volts.csv", r"waveform \(--set / base\)='csv:volts.csv'.*one of step, square, sine, triangle"),
])
def test_fixed_sweep_settings_are_checked_once_before_any_point(tmp_path, setting, value, match):
    """--set accuracy=nan, duration=1e9 or waveform=csv:FILE used to run every point and fail
    each one: refused once, before any point (no CSV written)."""
    out = tmp_path / "s.csv"
    with pytest.raises(ParameterError, match=match):
        run_sweep(grid(amplitude=[0.5, 0.6]), out, base={setting: value}, executor="serial")
    assert not out.exists() or out.stat().st_size == 0


def test_cli_sweep_set_refused_in_one_line(capsys, tmp_path):
    assert main(["sweep", "--vary", "amplitude=0.5", "--set", "accuracy=nan", "--out", str(tmp_path / "s.csv"),
                 "--executor", "serial"]) == 2
    err = capsys.readouterr().err
    assert "accuracy (--set / base)=nan" in err and "Traceback" not in err


# ---------------------------------------------------------------- attach, load_mjcf
def test_attach_refuses_xml_text_naming_how_to_make_a_spec():
    with pytest.raises(ParameterError, match=r"spec='<mujoco/>'.*mujoco.MjSpec.from_string\(xml\)"):
        attach("<mujoco/>", "pedot-micro", prefix="a", site="m")
    with pytest.raises(ParameterError, match="spec"):
        System("<mujoco/>", [])


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="FIFOs are POSIX")
@pytest.mark.slow
def test_load_mjcf_refuses_an_include_that_is_a_fifo(tmp_path):
    """An <include> naming a FIFO hung inside MuJoCo's reader; it is refused naming the
    include and what it is (run in a subprocess: the old code never returned)."""
    os.mkfifo(tmp_path / "pipe.xml")
    (tmp_path / "model.xml").write_text('<mujoco><include file="pipe.xml"/><worldbody/></mujoco>')
    code = ("import sys; from mjeap.model.fields import load_mjcf\n"
            "try:\n    load_mjcf(sys.argv[1])\nexcept Exception as e:\n    print(type(e).__name__, e)")
    env = {**os.environ, "MUJOCO_GL": "disable"}
    for name, match in (("model.xml", "<include file='pipe.xml'> in model.xml: .*pipe.xml is a FIFO"),
                        ("pipe.xml", "an existing MJCF file")):
        p = subprocess.run([sys.executable, "-c", code, str(tmp_path / name)], capture_output=True, text=True,
                           timeout=60, env=env, cwd=ROOT)
        assert p.stdout.startswith("ParameterError") and __import__("re").search(match, p.stdout), p.stdout + p.stderr


# ---------------------------------------------------------------- the Gymnasium environment
def _gym():
    return pytest.importorskip("mjeap.envs.gymnasium_env")


@pytest.mark.filterwarnings("ignore:MuJoCo:RuntimeWarning")
def test_gym_payload_range_in_the_wrong_unit_is_warned_and_not_blamed_on_the_drive():
    """payload_mass_range=(1, 2) kg (130,000 x nominal) gets the Scene's 'check its unit'
    warning when the env is made; the scene's payload is the drawn one; the blow-up names the
    payload, not the drive."""
    gym_env = _gym()
    with pytest.warns(UserWarning, match="payload_mass_range's upper mass 2 kg.*check its unit"):
        env = gym_env.CurvatureTrackingEnv(payload_mass_range=(1.0, 2.0), time_limit=1.0)
    _, info = env.reset(seed=0)
    assert env.scene.payload.mass == info["episode"]["payload_mass_kg"]
    mass = env.scene.model.body_mass[env.scene.payload_id] * env.scene.units.mass
    assert mass == pytest.approx(env.scene.payload.mass, rel=1e-12)
    for _ in range(100):
        _, _, terminated, _, info = env.step([0.5])
        if terminated:
            break
    assert terminated
    why = info["divergence"]
    assert "non-finite moment" not in why and "check its unit" in why and "diverged by step" in why


def test_gym_reference_returning_an_array_is_refused_naming_it():
    gym_env = _gym()
    with pytest.raises(ParameterError, match=r"reference='list of shape \(2,\)'.*one finite number.*t = 0 s"):
        gym_env.CurvatureTrackingEnv(reference=lambda t: [1.0, 2.0])
    env = gym_env.CurvatureTrackingEnv(reference=lambda t: np.array([2.0]))       # one value: accepted
    obs, _ = env.reset(seed=0)
    assert obs["reference"][0] == 2.0


def test_gym_bool_action_names_the_dtype_not_the_shape():
    gym_env = _gym()
    env = gym_env.CurvatureTrackingEnv()
    env.reset(seed=0)
    with pytest.raises(ParameterError, match=r"action='list of shape \(1,\) and dtype bool'.*not bool"):
        env.step([True])


# ---------------------------------------------------------------- small leftovers
def test_system_nyquist_message_names_the_system():
    """A voltage above a System's Nyquist frequency says to change the System's timestep
    (it said: pass a smaller timestep to the Scene)."""
    s = _system()
    with pytest.raises(ParameterError, match=r"Nyquist.*timestep to the System \(System\(spec, actuators, "
                                             r"timestep=\.\.\.\)\)") as e:
        s.rollout(["sine:1V@1000000Hz"], 0.01)
    assert "Scene" not in str(e.value)
    with pytest.raises(ParameterError, match=r"Nyquist.*timestep to the Scene"):
        rollout(Scene("pedot-micro"), "sine:1V@1000000Hz", 0.01)


def _alive(pid: int) -> bool:
    try:
        with open(f"/proc/{pid}/stat") as fh:
            return fh.read().rsplit(")", 1)[1].split()[0] != "Z"
    except FileNotFoundError:
        return False


@pytest.mark.skipif(not Path("/proc").is_dir(), reason="reads /proc")
@pytest.mark.slow
def test_render_recording_stops_the_viewer_the_wrapper_started(tmp_path):
    """`rerun` is a wrapper that starts the viewer as its child: stopping the wrapper alone
    left the viewer (~360 MB) running after the script exited. A fake wrapper here starts a
    child and waits, as rerun_cli does; after render_one nothing of it is left."""
    bin_dir, pidfile, site = tmp_path / "bin", tmp_path / "viewer.pid", tmp_path / "site"
    bin_dir.mkdir()
    site.mkdir()
    wrapper = bin_dir / "rerun"
    wrapper.write_text(f"#!/bin/sh\nsleep 300 &\necho $! > {pidfile}\nwait\n")
    wrapper.chmod(0o755)
    # the script runs as users run it, in its own process; its viewer client is a fake one
    # (sitecustomize), so that no real viewer is needed
    (site / "sitecustomize.py").write_text(
        "import rerun.experimental\nfrom pathlib import Path\n"
        "class State:\n    loading = False\n"
        "    recordings = [type('Rec', (), {'timelines': [], 'store_id': 'x'})()]\n"
        "class FakeViewer:\n"
        "    @classmethod\n    def connect(cls, url):\n        return cls()\n"
        "    def get_state(self):\n        return State()\n"
        "    def open(self, path):\n        pass\n"
        "    def save_screenshot(self, path):\n        Path(path).write_bytes(b'')\n"
        "rerun.experimental.ViewerClient = FakeViewer\n")
    rec = tmp_path / "a.rrd"
    rec.write_bytes(b"")
    env = {**os.environ, "PATH": f"{bin_dir}{os.pathsep}{os.environ['PATH']}",
           "PYTHONPATH": os.pathsep.join([str(site), str(ROOT), os.environ.get("PYTHONPATH", "")])}
    viewer = None
    try:
        subprocess.run([sys.executable, str(ROOT / "scripts" / "render_recording.py"), str(rec),
                        "--out-dir", str(tmp_path / "png"), "--timeout", "10"], env=env, capture_output=True, timeout=60)
        deadline = time.monotonic() + 10
        while viewer is None and time.monotonic() < deadline:
            viewer = int(pidfile.read_text()) if pidfile.exists() and pidfile.read_text().strip() else None
        assert viewer is not None
        while _alive(viewer) and time.monotonic() < deadline:
            time.sleep(0.05)
        assert not _alive(viewer), "the viewer the wrapper started is still running"
    finally:
        if viewer is not None and _alive(viewer):
            os.kill(viewer, signal.SIGKILL)
