"""Clear errors before any work: each failure here was a raw traceback or a late failure
(after minutes of sweeps or a bisection). The script tests parse the arguments only: the
function that would start the work is replaced by one that fails the test if called. The
interrupt tests start a command in a subprocess and stop it a few seconds in."""
import importlib
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import mujoco
import numpy as np
import pytest

from mjeap import ParameterError, Scene, rollout, rollout_batch
from mjeap.cli import main
from mjeap.studies.sweep import grid, run_sweep
from mjeap.simulation.system import System, attach

ROOT = Path(__file__).resolve().parents[2]


#: the modules behind the scripts' command lines (the scripts themselves are thin)
SCRIPT_MODULES = {"hamr_leg": "mjeap.robots.hamr_leg.experiments", "robobee_wing": "mjeap.robots.robobee_wing.experiments",
                  "gripper": "mjeap.robots.gripper.experiments", "stability_map": "mjeap.studies.stability_map",
                  "env_episode": "mjeap.envs.environment"}


def _script(name):
    """The module whose ``main`` the script ``scripts/NAME.py`` runs."""
    return importlib.import_module(SCRIPT_MODULES[name])


def _no_work(*a, **k):
    raise AssertionError("the work started before the arguments were checked")


# ---------------------------------------------------------------- drives on the wrong actuator
def test_a_drive_refuses_an_actuator_it_does_not_apply_to(capsys):
    assert main(["rollout", "pzt-hamr-small", "--voltage", "step:100V", "--duration", "0.01",
                 "--drive", "electrostrictive"]) == 2
    err = capsys.readouterr().err
    assert "Traceback" not in err and len(err.strip().splitlines()) == 1
    assert all(w in err for w in ("drive='electrostrictive'", "'terpolymer'", "pvdf-60, pvdf-60-half, pvdf-130",
                                  "its own drive is 'piezo-bimorph'")), err
    with pytest.raises(ParameterError, match="piezo-bimorph.*'piezo' and 'core' layers.*pzt-hamr-large.*trilayer"):
        rollout(Scene("pedot-micro"), "step:1V", 0.01, drive="piezo-bimorph")
    # no defaults for this actuator: the parameters to give are named
    with pytest.raises(ParameterError, match="rc-relaxation.*every parameter given.*missing zero, pole_mechanical"):
        rollout(Scene("ppy-trilayer"), "step:0.5V", 0.01, drive="rc-relaxation", drive_params={"gain": 1.0})


# ---------------------------------------------------------------- controllers
class _Returns:
    name, interval = "returns-this", 1e-3

    def __init__(self, value):
        self.value = value

    def reset(self, scene, drive):
        pass

    def __call__(self, t, scene):
        return self.value


@pytest.mark.parametrize("value,shown", [("abc", "'abc'"), ("1.5", "'1.5'"), (None, "None"),
                                         (np.array([0.5, 0.5]), r"'ndarray of shape \(2,\)'"),
                                         ([[0.5], [0.5]], r"'list of shape \(2, 1\)'")])
def test_a_scene_controller_returning_no_number_is_named(value, shown):
    with pytest.raises(ParameterError, match=rf"controller command={shown}.*one number.*returns-this at t = 0 s"):
        rollout(Scene("pedot-micro"), None, 0.003, controller=_Returns(value))


def test_a_scene_controller_may_return_a_one_element_array():
    r = rollout(Scene("pedot-micro"), None, 0.003, controller=_Returns(np.array([0.5])))
    assert np.all(r.voltage[1:] == 0.5)         # the first sample is the state before the first command


def _two_actuators():
    spec = mujoco.MjSpec.from_string('<mujoco><option gravity="0 0 0"/><worldbody><site name="m"/>'
                                     '<site name="n" pos="0 0 5"/></worldbody></mujoco>')
    acts = [attach(spec, "pzt-hamr-small", site=s, prefix=p, contact=False) for s, p in (("m", "a"), ("n", "b"))]
    return System(spec, acts)


def test_a_system_controller_returning_the_wrong_shape_is_named():
    s = _two_actuators()
    cases = [("abc", r"controller voltages='abc'.*one per actuator \(2: a, b\).*at t = 0 s"),
             ([100.0, 100.0, 100.0], r"controller voltages='3 values'.*one per actuator \(2: a, b\)"),
             ([[100.0, 100.0], [100.0, 100.0]], r"controller voltage of 'a'='list of shape \(2,\)'.*one number"),
             ({"b": "x"}, r"controller voltage of 'b'='x'")]
    for value, match in cases:
        with pytest.raises(ParameterError, match=match):
            s.rollout(None, 2e-4, controller=lambda t, system, v=value: v)
    r = s.rollout(None, 2e-4, controller=lambda t, system: np.array([110.0, 90.0]))      # one per actuator
    assert r.actuators["a"].voltage[-1] == 110.0 and r.actuators["b"].voltage[-1] == 90.0


# ---------------------------------------------------------------- batches
@pytest.mark.parametrize("kappas,shown", [([0.0, 1.0, 2.0], "3 values"), ([], "0 values"),
                                          ([[0.0, 1.0]], r"an array of shape \(1, 2\)")])
def test_batch_initial_curvatures_one_for_all_or_one_per_voltage(kappas, shown):
    with pytest.raises(ParameterError, match=rf"initial_curvatures='{shown}'.*one per voltage \(2\)"):
        rollout_batch(Scene("pzt-hamr-small"), ["step:120V", "step:110V"], 1e-4, initial_curvatures=kappas)


@pytest.mark.parametrize("nthread", [0, -1, 1000, 2.5, True])
def test_batch_threads_are_bounded_by_the_cpus(nthread):
    with pytest.raises(ParameterError, match=rf"nthread={nthread!r}.*an integer in \[1, {os.cpu_count()}\]"):
        rollout_batch(Scene("pzt-hamr-small"), ["step:120V"], 1e-4, nthread=nthread)


# ---------------------------------------------------------------- sweeps
def test_a_recorded_point_outside_the_sweep_is_refused(tmp_path, capsys):
    out = tmp_path / "s.csv"
    with pytest.raises(ParameterError, match=r"record=99.*an integer in \[0, 0\].*1 point\)"):
        run_sweep(grid(amplitude=[0.5]), out, base={"duration": 0.02}, record=[99], executor="serial", progress=False)
    assert main(["sweep", "--vary", "amplitude=0.5", "--set", "duration=0.02", "--record", "-1", "--out", str(out),
                 "--executor", "serial", "--quiet"]) == 2
    assert "record=-1" in capsys.readouterr().err
    assert not out.exists()                                    # refused before any point


# ---------------------------------------------------------------- host models
def _host(body_pos="1 0 0"):
    return mujoco.MjSpec.from_string('<mujoco><option gravity="0 0 0"/><worldbody><site name="mount"/>'
                                     f'<body name="block" pos="{body_pos}"><freejoint/><geom size="1"/></body>'
                                     '</worldbody></mujoco>')


def test_non_finite_host_positions_are_named_not_blamed_on_the_timestep():
    spec = _host()
    spec.site("mount").pos = [np.nan, 0.0, 0.0]
    with pytest.raises(ParameterError, match=r"site 'mount' pos=\[nan, 0.0, 0.0\].*finite.*not a timestep"):
        attach(spec, "pzt-hamr-small", site="mount", prefix="p", contact=False)
    spec = _host()
    a = attach(spec, "pzt-hamr-small", site="mount", prefix="p", contact=False)
    spec.body("block").pos = [0.0, np.inf, 0.0]                # edited after attaching: caught at build
    with pytest.raises(ParameterError, match=r"body 'block' pos=\[0.0, inf, 0.0\].*finite"):
        System(spec, [a])


# ---------------------------------------------------------------- scripts: refused at parse time
def _refused(capsys, mod, argv, *words):
    with pytest.raises(SystemExit) as e:
        mod.main(argv)
    err = capsys.readouterr().err
    assert e.value.code == 2 and "Traceback" not in err, err
    assert all(w in err for w in words), err


def test_hamr_leg_cycles_are_checked_before_the_sweeps(tmp_path, capsys, monkeypatch):
    leg = _script("hamr_leg")
    monkeypatch.setattr(leg, "design", _no_work)
    out = str(tmp_path / "h.rrd")
    _refused(capsys, leg, ["--cycles", "0", "--out", out], "--cycles", "an integer in [3, 10000]")
    _refused(capsys, leg, ["--cycles", "40", "--open-loop-cycles", "40", "--out", out],
             "--open-loop-cycles=40", "[1, 38]")
    _refused(capsys, leg, ["--open-loop-cycles", "0", "--out", out], "--open-loop-cycles", ">= 1")


def test_gripper_voltage_is_checked_before_the_bisection(tmp_path, capsys, monkeypatch):
    grip = _script("gripper")
    for f in ("closed_form_min_lift_voltage", "min_lift_voltage", "held_run", "hard_finger_check"):
        monkeypatch.setattr(grip, f, _no_work)
    out = str(tmp_path / "g.rrd")
    _refused(capsys, grip, ["--voltage", "10", "--out", out], "--voltage=10.0", ", 3] V", "safe limit")
    _refused(capsys, grip, ["--voltage", "0.01", "--out", out], "--voltage=0.01", "just reach the bead")
    _refused(capsys, grip, ["--hold", "0", "--out", out], "--hold", "[1, 600] s")


@pytest.mark.parametrize("name,work,argv", [
    ("hamr_leg", "design", ["--out", "{file}/leg.rrd"]),
    ("robobee_wing", "build", ["--out", "{file}/wing.rrd"]),
    ("gripper", "closed_form_min_lift_voltage", ["--out", "{file}/g.rrd"]),
    ("stability_map", "run_sweep", ["--out", "{file}"]),
    ("env_episode", "make_environment", ["--out", "{file}/e.rrd"]),
])
def test_script_outputs_under_a_regular_file_are_refused_before_any_work(tmp_path, capsys, monkeypatch,
                                                                          name, work, argv):
    mod = _script(name)
    monkeypatch.setattr(mod, work, _no_work)
    blocker = tmp_path / "a-file"
    blocker.write_text("x")
    _refused(capsys, mod, [a.format(file=blocker) for a in argv], "argument --out", "cannot write")


def test_script_counts_and_durations_name_their_range(tmp_path, capsys, monkeypatch):
    smap = _script("stability_map")
    monkeypatch.setattr(smap, "run_sweep", _no_work)
    _refused(capsys, smap, ["--out", str(tmp_path), "--workers", "0"], "--workers", ">= 1")
    _refused(capsys, smap, ["--out", str(tmp_path), "--masses", "1"], "--masses", "[2, 1000]")
    env = _script("env_episode")
    monkeypatch.setattr(env, "make_environment", _no_work)
    _refused(capsys, env, ["--duration", "0", "--out", str(tmp_path / "e.rrd")], "--duration", "[0.01, 600] s")


# ---------------------------------------------------------------- interrupts
def _interrupt(argv, sig, after=4.0, group=False):
    """Start ``argv``, send ``sig`` after ``after`` s (to its process group, as a terminal's
    Ctrl-C does, with ``group``), and return (exit code, stderr, seconds it took to stop)."""
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")])}
    # the child takes SIGINT's default action (Python's KeyboardInterrupt) even where this run
    # inherited it ignored (started as a background job without job control, as a CI
    # runner's shell may): an ignored disposition passes through exec
    p = subprocess.Popen(argv, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, env=env,
                         start_new_session=group, preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    time.sleep(after)
    assert p.poll() is None, "finished before the interrupt"
    os.killpg(p.pid, sig) if group else p.send_signal(sig)
    t0 = time.time()
    _, err = p.communicate(timeout=60)
    return p.returncode, err, time.time() - t0


def _one_line(err, how):
    assert "Traceback" not in err, err
    lines = [x for x in err.splitlines() if x.strip() and "Warning" not in x and "warn(" not in x]
    assert len(lines) == 1 and f"interrupted ({how})" in lines[0], err


@pytest.mark.slow
def test_an_interrupted_rollout_exits_130_with_one_line_and_its_outputs(tmp_path):
    rrd, csvp = tmp_path / "r.rrd", tmp_path / "r.csv"
    code, err, _ = _interrupt([sys.executable, "-m", "mjeap.cli", "rollout", "pedot-micro", "--voltage", "step:1V",
                               "--duration", "500", "--engine", "loop", "--rrd", str(rrd), "--csv", str(csvp),
                               "--quiet"], signal.SIGINT)
    assert code == 130
    _one_line(err, "Ctrl-C")
    assert rrd.stat().st_size > 0 and len(csvp.read_text().splitlines()) > 2


@pytest.mark.slow
def test_an_interrupted_sweep_stops_its_workers_without_tracebacks(tmp_path):
    out = tmp_path / "s.csv"
    code, err, took = _interrupt([sys.executable, "-m", "mjeap.cli", "sweep", "--vary", "amplitude=0.5,0.6,0.7,0.8",
                                  "--set", "duration=60", "--workers", "2", "--out", str(out), "--quiet"],
                                 signal.SIGINT, group=True)
    assert code == 130 and took < 20
    _one_line(err, "Ctrl-C")                    # the workers print nothing either
    assert out.read_text().startswith("point_id")


@pytest.mark.slow
def test_a_terminated_validation_exits_143_with_one_line(tmp_path):
    """... and its report says it is incomplete and which experiments did not run (on
    eaac59e it said '0 failed' and validation.json '"passed": true')."""
    code, err, _ = _interrupt([sys.executable, "-m", "mjeap.cli", "validate", "--out", str(tmp_path / "v"), "--quiet"],
                              signal.SIGTERM)
    assert code == 143
    _one_line(err, "SIGTERM")
    doc = json.loads((tmp_path / "v" / "validation.json").read_text())
    assert doc["complete"] is False and doc["passed"] is False and doc["not_run"]
    md = (tmp_path / "v" / "report.md").read_text()
    assert "INCOMPLETE" in md and doc["not_run"][-1] in md


@pytest.mark.parametrize("script,argv", [("hamr_leg.py", []), ("gripper.py", ["--quick"])])
@pytest.mark.slow
def test_an_interrupted_script_exits_130_with_one_line(tmp_path, script, argv):
    code, err, took = _interrupt([sys.executable, str(ROOT / "scripts" / script), "--out", str(tmp_path / "x.rrd"),
                                  *argv], signal.SIGINT, group=True)
    assert code == 130 and took < 20            # the gripper's held run in its worker is not waited for
    _one_line(err, "Ctrl-C")
