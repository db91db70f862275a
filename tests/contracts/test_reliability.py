"""Failure classes of the reliability issue: each test fails on the code before its fix.

Sweeps: a point's identity includes every setting that changes its row (class 1), fixed
settings and drive parameters are checked before the first point (class 2), a torn last
row is dropped before appending (class 9), a sweep in which every point failed exits
non-zero (class 10)."""
import numpy as np
import pytest

from mjeap.cli import main
from mjeap.errors import UnknownNameError
from mjeap.studies.sweep import grid, read_results, run_sweep

POINTS = grid(amplitude=[0.5, 1.0])


def test_resumed_sweep_computes_points_whose_settings_changed(tmp_path):
    out = tmp_path / "s.csv"
    a = run_sweep(POINTS, out, base={"duration": 0.05}, executor="serial", progress=False)
    same = run_sweep(POINTS, out, base={"duration": 0.05}, executor="serial", progress=False)
    other = run_sweep(POINTS, out, base={"duration": 0.1}, executor="serial", progress=False)
    assert (a.done, same.skipped, same.done) == (2, 2, 0)
    assert other.done == 2 and other.skipped == 0             # not reused from the 0.05 s rows
    rows = read_results(out)
    assert len(rows) == 4 and len({r["point_id"] for r in rows}) == 4
    assert {'"duration": 0.05' in r["settings"] for r in rows} == {True, False}   # written to the file
    other_metrics = run_sweep(POINTS, out, base={"duration": 0.1}, metrics=("peak_to_peak", "returns"),
                              executor="serial", progress=False)
    assert other_metrics.skipped == 2


def test_unknown_fixed_settings_and_drive_parameters_are_named_before_any_point(tmp_path):
    out = tmp_path / "s.csv"
    with pytest.raises(UnknownNameError, match="duraton.*did you mean 'duration'"):
        run_sweep(POINTS, out, base={"duraton": 0.2}, executor="serial", progress=False)
    with pytest.raises(UnknownNameError, match="gian.*did you mean 'gain'"):
        run_sweep(POINTS, out, base={"drive.gian": 60.0}, executor="serial", progress=False)
    assert not out.exists()
    assert main(["sweep", "--vary", "amplitude=0.5", "--set", "duraton=0.2", "--out", str(out), "--quiet"]) == 2


def test_torn_last_row_is_dropped_and_its_point_runs_again(tmp_path):
    out = tmp_path / "s.csv"
    run_sweep(POINTS, out, base={"duration": 0.05}, executor="serial", progress=False)
    text = out.read_text()
    out.write_text(text[:-25])                                 # killed mid-line
    with pytest.warns(UserWarning, match="partial last row"):
        s = run_sweep(POINTS, out, base={"duration": 0.05}, executor="serial", progress=False)
    assert (s.done, s.skipped) == (1, 1)
    rows = read_results(out)
    assert len(rows) == 2 and all(len(r["point_id"]) == 12 and r["error"] == "" for r in rows)


def test_a_sweep_where_every_point_failed_exits_nonzero(tmp_path, capsys):
    out = tmp_path / "s.csv"
    code = main(["sweep", "--vary", "amplitude=0.5,1", "--set", "segments=1", "--set", "duration=0.05",
                 "--out", str(out), "--executor", "serial", "--quiet"])
    assert code == 1
    assert "every point that ran failed (2)" in capsys.readouterr().err


# ---------------------------------------------------------------- rollouts (classes 3, 5)
from mjeap import Scene, rollout                                     # noqa: E402
from mjeap.errors import ParameterError                              # noqa: E402


def test_a_waveform_above_the_nyquist_frequency_is_refused(tmp_path):
    s = Scene("pedot-micro")                                       # dt 76.7 us: Nyquist 6.52 kHz
    with pytest.raises(ParameterError, match=r"voltage.*Nyquist frequency 65\d\d Hz"):
        rollout(s, "sine:1V@13000Hz", 0.01)
    with pytest.raises(ParameterError, match="Nyquist"):
        rollout(s, "chirp:1V@10Hz..9000Hz", 0.01)
    rollout(s, "sine:1V@1000Hz", 0.002)                            # well below: runs
    # csv samples: refused where their content lies above the limit, not for a fine time base
    t = np.arange(0, 0.01, 1e-5)
    for name, v in (("fast", np.sin(2 * np.pi * 13000 * t)), ("slow", np.sin(2 * np.pi * 100 * t))):
        f = tmp_path / f"{name}.csv"
        f.write_text("time,voltage\n" + "\n".join(f"{a:.8g},{b:.8g}" for a, b in zip(t, v)))
        if name == "fast":
            with pytest.raises(ParameterError, match="csv signal's energy"):
                rollout(s, f"csv:{f}", 0.005)
        else:
            rollout(s, f"csv:{f}", 0.005)


def test_work_is_bounded_before_it_starts():
    s = Scene("pedot-micro")
    with pytest.raises(ParameterError, match=r"duration.*at most 20,000,000 steps.*max_steps"):
        rollout(s, "step:1V", 1e5)
    with pytest.raises(ParameterError, match=r"duration.*at least one timestep"):
        rollout(s, "step:1V", 1e-6)
    with pytest.raises(ParameterError, match="at most 100 steps"):
        rollout(s, "step:1V", 0.01, max_steps=100)
    assert rollout(s, "step:1V", 0.01, max_steps=200).meta["steps"] == 130


def test_a_payload_in_kilograms_where_milligrams_were_meant_is_warned():
    with pytest.warns(UserWarning, match="check its unit"):
        Scene("pedot-micro", payload="12.6kg@6.27mm")


# ---------------------------------------------------------------- outputs (class 4)
def test_outputs_are_checked_before_stepping_and_written_independently(tmp_path, monkeypatch, capsys):
    from mjeap.io import recording
    from mjeap.errors import DivergenceError, OutputError
    s = Scene("pedot-micro")
    blocker = tmp_path / "a-file"
    blocker.write_text("x")
    steps = []
    monkeypatch.setattr(s, "update_kinematics", lambda: steps.append(1), raising=False)
    with pytest.raises(ParameterError, match="rrd.*cannot write"):
        rollout(s, "step:1V", 0.01, rrd=blocker / "run.rrd", engine="loop")
    with pytest.raises(ParameterError, match="csv_path.*other than the rrd"):
        rollout(s, "step:1V", 0.01, rrd=tmp_path / "x.rrd", csv_path=tmp_path / "x.rrd")
    assert not steps                                          # refused before any step
    monkeypatch.undo()
    # a recording that fails while being written: the CSV is still written and the run's
    # result rides along with the error
    def broken(*a, **k):
        raise OSError("disk full")
    monkeypatch.setattr(recording, "write_recording", broken)
    with pytest.raises(OutputError, match="cannot write .*r.rrd: OSError: disk full") as e:
        rollout(s, "step:1V", 0.01, rrd=tmp_path / "r.rrd", csv_path=tmp_path / "r.csv")
    assert (tmp_path / "r.csv").stat().st_size > 0 and len(e.value.result.time) > 1
    # ... and it never masks the run's own error
    from mjeap.drives import DRIVES, Drive, register_drive

    @register_drive
    class Exploding(Drive):
        name = "test-exploding-outputs"

        def step(self, voltage, dt):
            self.part.set_internal_moments(1e30)
    try:
        with pytest.raises(DivergenceError) as e:
            rollout(s, "step:1V", 0.05, drive="test-exploding-outputs", rrd=tmp_path / "d.rrd",
                    csv_path=tmp_path / "d.csv", engine="loop")
        assert any("cannot write" in n for n in e.value.__notes__)
        assert (tmp_path / "d.csv").stat().st_size > 0
    finally:
        DRIVES.pop("test-exploding-outputs")
    monkeypatch.undo()
    assert main(["rollout", "pedot-micro", "--voltage", "step:1V", "--duration", "0.01",
                 "--rrd", str(blocker / "run.rrd")]) == 2
    err = capsys.readouterr().err
    assert "cannot write" in err and "Traceback" not in err


# ---------------------------------------------------------------- classes 13, 14, 17
def test_non_finite_drive_output_and_controller_command_are_named():
    from mjeap.drives import DRIVES, Drive, register_drive
    from mjeap.errors import DivergenceError

    @register_drive
    class NanDrive(Drive):
        name = "test-nan-moment"

        def step(self, voltage, dt):
            self.part.set_internal_moments(float("nan"))
    try:
        with pytest.raises(DivergenceError, match="test-nan-moment applied a non-finite moment.*not the timestep"):
            rollout(Scene("pedot-micro"), "step:1V", 0.05, drive="test-nan-moment", engine="loop")
    finally:
        DRIVES.pop("test-nan-moment")

    class NanController:
        name, interval = "nan-controller", 1e-3

        def reset(self, scene, drive):
            pass

        def __call__(self, t, scene):
            return float("nan") if t > 0.002 else 0.5
    with pytest.raises(ParameterError, match=r"controller command.*nan-controller at t = 0\.00"):
        rollout(Scene("pedot-micro"), None, 0.05, controller=NanController())


@pytest.mark.parametrize("kappa", [float("nan"), float("inf"), 1e6, -1.1e3])
def test_initial_curvature_beyond_a_full_circle_is_refused(kappa):
    with pytest.raises(ParameterError, match=r"initial_curvature.*\[-1047\.2, 1047\.2\] 1/m"):
        rollout(Scene("pedot-micro"), "step:1V", 0.01, initial_curvature=kappa)


def test_python_api_refuses_what_is_ambiguous_and_accepts_a_number_as_volts():
    with pytest.raises(ParameterError, match="payload.*MASS@POSITION"):
        Scene("pedot-micro", payload=5)
    with pytest.raises(ParameterError, match="units.*UnitSystem"):
        Scene("pedot-micro", units="mm")
    with pytest.raises(ParameterError, match="voltage.*None only with a controller"):
        rollout(Scene("pedot-micro"), None, 0.01)
    r = rollout(Scene("pedot-micro"), 1.5, 0.01)
    assert np.all(r.voltage == 1.5) and r.meta["voltage"] == "constant 1.5 V"


# ---------------------------------------------------------------- classes 11, 12
@pytest.mark.parametrize("params,words", [
    ({"gain": float("nan")}, "gain=nan.*finite number"),
    ({"pole_electrical": -5.0}, r"pole_electrical=-5.0.*\(0, inf\)"),
    ({"zero": 0.2}, "zero=0.2.*above pole_mechanical"),
    ({"gain": "abc"}, "gain='abc'.*finite number"),
])
def test_drive_parameters_are_checked_where_they_are_set(params, words):
    with pytest.raises(ParameterError, match=words):
        rollout(Scene("pedot-micro"), "step:1V", 0.01, drive_params=params)


def test_malformed_options_get_a_clear_error(tmp_path, capsys):
    s = Scene("pedot-micro")
    with pytest.raises(ParameterError, match="voltage option duty.*'abc'.*a number"):
        rollout(s, "square:1V@1Hz,duty=abc", 0.01)
    with pytest.raises(ParameterError, match="1e400V.*finite number"):
        rollout(s, "step:1e400V", 0.01)
    cases = [
        (["rollout", "pedot-micro", "--voltage", "step:1V", "--duration", "0.01", "--param", "gain"], "--param"),
        (["rollout", "pedot-micro", "--voltage", "step:1V", "--duration", "0.01", "--param", "gain=abc"], "gain"),
        (["sweep", "--vary", "amplitude=1:2:x", "--out", str(tmp_path / "s.csv")], "--vary"),
        (["sweep", "--vary", "amplitude=1", "--record", "a", "--out", str(tmp_path / "s.csv")], "--record"),
        (["sweep", "--vary", "amplitude=1", "--out", str(tmp_path)], "--out"),
    ]
    for argv, name in cases:
        assert main(argv) == 2, argv
        err = capsys.readouterr().err
        assert name in err and "Traceback" not in err, (argv, err)


def test_a_scene_past_the_buckling_load_says_so(tmp_path, capsys):
    """150 mg standing up is above the instantaneous column load (132 mg): the run's
    metadata, the CLI and the recording warn that it starts from an unstable equilibrium."""
    from mjeap.io.recording import read_recording
    s = Scene("pedot-micro", orientation="up", payload="150mg@6.27mm")
    assert s.choice.buckled
    r = rollout(s, "step:0V", 0.05, rrd=tmp_path / "b.rrd")
    assert any("unstable" in w for w in r.meta["warnings"])
    assert "/log" in read_recording(tmp_path / "b.rrd")
    assert main(["rollout", "pedot-micro", "--orientation", "up", "--payload", "150mg@6.27mm", "--voltage", "step:0V",
                 "--duration", "0.05", "--quiet"]) == 0
    assert "unstable" in capsys.readouterr().err
    ok = rollout(Scene("pedot-micro", orientation="up", payload="12.6mg@6.27mm"), "step:0V", 0.05)
    assert not ok.meta.get("warnings")


# ---------------------------------------------------------------- sweeps under faults (6, 7, 8)
def _killer_metric(r, point, scene):
    import os
    import signal
    if abs(point["amplitude"] - 0.7) < 1e-9:
        os.kill(os.getpid(), signal.SIGKILL)            # as the OOM killer would
    return 1.0


def test_a_killed_worker_fails_its_point_and_the_sweep_goes_on(tmp_path):
    from mjeap.studies.sweep import METRICS, register_metric
    register_metric("killer", _killer_metric)
    try:
        pts = grid(amplitude=[0.5, 0.7, 1.0, 1.2])
        s = run_sweep(pts, tmp_path / "k.csv", metrics=("killer",), base={"duration": 0.05}, workers=2,
                      progress=False)
    finally:
        METRICS.pop("killer")
    rows = {float(r["amplitude"]): r for r in read_results(tmp_path / "k.csv")}
    assert (s.done, s.failed) == (4, 1) and len(rows) == 4
    assert "WorkerDied" in rows[0.7]["error"] and all(rows[a]["error"] == "" for a in (0.5, 1.0, 1.2))


def test_a_second_sweep_on_the_same_file_is_refused(tmp_path):
    import fcntl
    out = tmp_path / "s.csv"
    with open(tmp_path / "s.csv.lock", "a+") as held:
        fcntl.flock(held, fcntl.LOCK_EX | fcntl.LOCK_NB)
        with pytest.raises(ParameterError, match="another mjeap sweep holds its lock"):
            run_sweep(POINTS, out, base={"duration": 0.05}, executor="serial", progress=False)
    assert run_sweep(POINTS, out, base={"duration": 0.05}, executor="serial", progress=False).done == 2


def _alive(pid: int) -> bool:
    """Running (a zombie waiting to be reaped counts as gone)."""
    try:
        with open(f"/proc/{pid}/status") as fh:
            return not any(line.startswith("State:") and "Z" in line.split()[1] for line in fh)
    except FileNotFoundError:
        return False


@pytest.mark.parametrize("how", ["SIGTERM", "SIGKILL"])
@pytest.mark.slow
def test_stopping_a_sweep_stops_its_workers_and_keeps_its_rows(tmp_path, how):
    """SIGTERM takes Ctrl-C's path (the workers are stopped, finished rows kept, no waiting
    for the 60 s points in flight); kill -9 of the sweep leaves no orphaned worker (they die
    with their parent)."""
    import os
    import signal
    import subprocess
    import sys
    import time
    pids = tmp_path / "pids"
    pids.mkdir()
    code = ("import os, sys, time\n"
            "from mjeap.studies.sweep import grid, run_sweep, register_metric\n"
            "def slow(r, p, s):\n"
            "    open(os.path.join(sys.argv[2], str(os.getpid())), 'w').close()\n"
            "    time.sleep(0.3 if p['amplitude'] < 0.6 else 60)\n"
            "    return 1.0\n"
            "register_metric('slow', slow)\n"
            "run_sweep(grid(amplitude=[0.5, 0.55, 0.9, 1.0, 1.1]), sys.argv[1], metrics=('slow',),"
            " base={'duration': 0.02}, workers=2, progress=False)\n")
    out = tmp_path / "t.csv"
    p = subprocess.Popen([sys.executable, "-c", code, str(out), str(pids)])
    t0 = time.time()
    while time.time() - t0 < 30 and (not out.exists() or len(read_results(out)) < 2):
        time.sleep(0.2)
    time.sleep(0.5)                                      # the 60 s points are in flight now
    p.send_signal(signal.SIGTERM if how == "SIGTERM" else signal.SIGKILL)
    p.wait(timeout=20)
    assert time.time() - t0 < 40 and p.returncode != 0
    assert len(read_results(out)) >= 2                   # finished rows kept
    workers = [int(x.name) for x in pids.iterdir()]
    deadline = time.time() + 10
    while time.time() < deadline and any(_alive(w) for w in workers):
        time.sleep(0.2)
    assert workers and not any(_alive(w) for w in workers), "orphaned sweep workers"


# ---------------------------------------------------------------- identify (class 16)
def _step_csv(path, kappa, header="time (s),tip_curvature (1/m)", delimiter=",", encoding="utf-8", bom=False):
    t = np.linspace(0, 15, 300)
    lines = [header.replace(",", delimiter)] + [f"{a:.6g}{delimiter}{b:.9g}" for a, b in zip(t, kappa(t))]
    data = ("\ufeff" if bom else "") + "\n".join(lines) + "\n"
    path.write_bytes(data.encode(encoding))
    return path


def test_identify_refuses_flat_noise_and_non_finite_fits(tmp_path, capsys):
    rng = np.random.default_rng(0)
    cases = {"flat": lambda t: np.full_like(t, 12.0), "noise": lambda t: rng.normal(0, 1, len(t)),
             "huge": lambda t: 1e300 * (181 - 90 * np.exp(-1.8 * t) - 265 * np.exp(-0.3 * t))}
    for name, k in cases.items():
        f = _step_csv(tmp_path / f"{name}.csv", k)
        assert main(["identify", "step", str(f), "--voltage", "3"]) == 2, name
        err = capsys.readouterr().err
        assert "mjeap: error: curvature" in err and "Infinity" not in err, (name, err)
    good = _step_csv(tmp_path / "good.csv", lambda t: 181 - 90 * np.exp(-1.8 * t) - 265 * np.exp(-0.3 * t))
    assert main(["identify", "step", str(good), "--voltage", "3"]) == 0


def test_csvs_are_read_as_users_save_them(tmp_path, capsys):
    k = lambda t: 181 - 90 * np.exp(-1.8 * t) - 265 * np.exp(-0.3 * t)      # noqa: E731
    for kw in ({"bom": True}, {"delimiter": ";"}, {"encoding": "latin-1", "header": "time (s),courbure \u00b5 (1/m)"}):
        f = _step_csv(tmp_path / "a.csv", k, **kw)
        col = ["--curvature-column", "courbure \u00b5"] if "header" in kw else []
        assert main(["identify", "step", str(f), "--voltage", "3", *col]) == 0, kw
        capsys.readouterr()
    binary = tmp_path / "b.csv"
    binary.write_bytes(b"\x00\x01\x02" * 100)
    assert main(["identify", "step", str(binary), "--voltage", "3"]) == 2
    assert "binary" in capsys.readouterr().err
    comma = tmp_path / "c.csv"
    comma.write_text("time;tip_curvature\n" + "\n".join(f"{i};{i},5" for i in range(30)))
    assert main(["identify", "step", str(comma), "--voltage", "3"]) == 2
    assert "decimal comma" in capsys.readouterr().err
    # the same reader serves csv: waveforms
    w = tmp_path / "w.csv"
    w.write_bytes(("\ufefftime;voltage\n" + "\n".join(f"{i * 1e-3};{0.5}" for i in range(20))).encode())
    r = rollout(Scene("pedot-micro"), f"csv:{w}", 0.005)
    assert np.allclose(r.voltage, 0.5)


# ---------------------------------------------------------------- smaller items
@pytest.mark.slow
def test_sigterm_ends_a_rollout_cleanly_with_its_outputs(tmp_path):
    import subprocess
    import sys
    import time
    rrd, csvp = tmp_path / "r.rrd", tmp_path / "r.csv"
    p = subprocess.Popen([sys.executable, "-m", "mjeap.cli", "rollout", "pedot-micro", "--voltage", "step:1V",
                          "--duration", "500", "--engine", "loop", "--rrd", str(rrd), "--csv", str(csvp), "--quiet"],
                         stderr=subprocess.PIPE, text=True)
    time.sleep(4)
    p.terminate()
    _, err = p.communicate(timeout=60)
    assert p.returncode != 0
    assert rrd.stat().st_size > 0 and len(csvp.read_text().splitlines()) > 2     # what was simulated is written
    from mjeap.io.recording import read_recording
    texts = [x for b in read_recording(rrd)["/log"] for x in b.column(b.schema.names.index("TextLog:text")).to_pylist()]
    assert any("Terminated" in str(t) for t in texts)


def test_mujoco_warnings_become_python_warnings_without_a_log_file(tmp_path, monkeypatch):
    import mujoco
    import mjeap.envs.environment  # noqa: F401  (dm_control installs a handler of its own on import)
    monkeypatch.chdir(tmp_path)
    m = mujoco.MjModel.from_xml_string('<mujoco><worldbody><body><freejoint/><geom size="1"/></body></worldbody></mujoco>')
    d = mujoco.MjData(m)
    d.qacc_warmstart[:] = np.nan
    d.qvel[0] = np.nan
    with pytest.warns(RuntimeWarning, match="MuJoCo: .*internal units"):
        mujoco.mj_step(m, d)
    assert not (tmp_path / "MUJOCO_LOG.TXT").exists()


def test_batches_check_initial_curvatures_as_rollout_does():
    from mjeap import rollout_batch
    with pytest.raises(ParameterError, match=r"initial_curvatures.*1/m"):
        rollout_batch(Scene("pzt-hamr-small"), ["step:120V"], 1e-4, initial_curvatures=[float("nan")])
