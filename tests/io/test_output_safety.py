"""Nothing written is lost or corrupted (each test fails on the code before the fix):

1. SIGTERM stops every stepping loop (a Scene rollout, a System rollout, a dm_control
   episode) as Ctrl-C does: the recording ends with the error, the CSV holds every sample.
2. Outputs are written to a temporary file and renamed into place whole; a second writer of
   the same path is refused before any work; a lock left by a killed process blocks nothing.
3. CSV cells a spreadsheet would run as formulas are neutralised with a leading quote;
   numbers stay as they are, and mjeap's own readers (sweep resume, csvio) read the values back.
"""
import csv
import json
import os
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

from mjeap import Scene, rollout
from mjeap.cli import main
from mjeap.errors import ParameterError
from mjeap.io.recording import read_recording

ENV = {**os.environ, "PYTHONPATH": os.pathsep.join([os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))),
                                                     os.environ.get("PYTHONPATH", "")])}

# each child prints 'ready' once its loop has taken a few steps, then runs for minutes
CHILD = {
    "scene": """
from mjeap import Scene, rollout
class Ready:
    interval, n = 1e-3, 0
    def reset(self, scene, drive): pass
    def __call__(self, t, scene):
        self.n += 1
        if self.n == 5: print('ready', flush=True)
        return 0.5
rollout(Scene('pedot-micro'), None, 500.0, controller=Ready(), engine='loop', sample_interval=0.01,
        rrd=RRD, csv_path=CSV)
""",
    "system": """
import mujoco
from mjeap.simulation.system import System, attach
spec = mujoco.MjSpec.from_string('<mujoco><option gravity="0 0 -0.00980665"/><worldbody><site name="m"/>'
                                 '</worldbody></mujoco>')
s = System(spec, [attach(spec, 'pedot-micro', site='m', prefix='a', contact=False)])
n = [0]
def on_sample(system):
    n[0] += 1
    if n[0] == 5: print('ready', flush=True)
s.rollout(['step:1V'], 500.0, sample_interval=0.01, rrd=RRD, on_sample=on_sample)
""",
    "episode": """
import numpy as np
from mjeap.envs.environment import make_environment, run_episode
env = make_environment(time_limit=500.0, control_interval=1e-2, segments=8)
n = [0]
def policy(ts):
    n[0] += 1
    if n[0] == 5: print('ready', flush=True)
    return np.array([0.5])
run_episode(env, policy, rrd=RRD)
""",
}


def _start(kind, rrd, csv_path=None):
    code = f"RRD, CSV = {str(rrd)!r}, {None if csv_path is None else str(csv_path)!r}\n" + CHILD[kind]
    p = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                         env=ENV)
    line = p.stdout.readline()
    if line.strip() != "ready":
        p.kill()
        raise AssertionError(f"child did not start: {line!r} {p.communicate()[1][-2000:]}")
    return p


def _log_texts(rrd):
    return [str(x) for b in read_recording(rrd).get("/log", [])
            for x in b.column(b.schema.names.index("TextLog:text")).to_pylist()]


def _leftovers(folder, keep):
    return sorted(f for f in os.listdir(folder) if f not in keep)


# ---------------------------------------------------------------- 1. SIGTERM takes Ctrl-C's path
@pytest.mark.parametrize("kind", ["system", "episode", "scene"])
@pytest.mark.slow
def test_sigterm_stops_every_stepping_loop_and_its_outputs_are_written(tmp_path, kind):
    rrd, csv_path = tmp_path / "r.rrd", (tmp_path / "r.csv" if kind == "scene" else None)
    p = _start(kind, rrd, csv_path)
    time.sleep(0.5)
    p.send_signal(signal.SIGTERM)
    _, err = p.communicate(timeout=60)
    assert p.returncode not in (0, -signal.SIGTERM), "SIGTERM killed the run before it wrote its outputs"
    assert "Terminated" in err
    assert any("Terminated" in t for t in _log_texts(rrd))          # the recording ends with the error
    if csv_path is not None:                                        # every sample, none torn
        rows = list(csv.reader(open(csv_path, newline="")))
        n = sum(b.num_rows for b in read_recording(rrd)["/plots/voltage"] if "time" in b.schema.names)
        assert len(rows) - 1 == n > 10 and all(len(r) == len(rows[0]) for r in rows)
        assert np.isfinite(np.array(rows[1:], dtype=float)).all()
    assert _leftovers(tmp_path, {"r.rrd", "r.csv"}) == []            # no temporary or lock file


@pytest.mark.slow
def test_sigterm_while_the_outputs_are_written_waits_for_them(tmp_path):
    """A stop that comes while the files are written is taken once they are complete."""
    rrd, csv_path = tmp_path / "r.rrd", tmp_path / "r.csv"
    code = ("import time\nfrom mjeap import Scene, rollout\nfrom mjeap.io import recording\n"
            "log = recording._log_outcome\n"
            "def slow(*a, **k):\n    print('ready', flush=True)\n    time.sleep(2)\n    return log(*a, **k)\n"
            "recording._log_outcome = slow\n"
            f"rollout(Scene('pedot-micro'), 'step:1V', 0.05, rrd={str(rrd)!r}, csv_path={str(csv_path)!r})\n"
            "print('not stopped', flush=True)\n")
    p = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                         env=ENV)
    assert p.stdout.readline().strip() == "ready"
    p.send_signal(signal.SIGTERM)
    out, err = p.communicate(timeout=60)
    assert p.returncode not in (0, -signal.SIGTERM) and "Terminated" in err and "not stopped" not in out
    assert "/plots/voltage" in read_recording(rrd)
    rows = list(csv.reader(open(csv_path, newline="")))
    assert len(rows) > 10 and all(len(r) == len(rows[0]) for r in rows)
    assert _leftovers(tmp_path, {"r.rrd", "r.csv"}) == []


# ---------------------------------------------------------------- 2. one writer, whole files
@pytest.mark.slow
def test_a_second_writer_of_an_output_is_refused_before_any_work(tmp_path, monkeypatch):
    rrd, csv_path = tmp_path / "r.rrd", tmp_path / "r.csv"
    p = _start("scene", rrd, csv_path)
    try:
        s = Scene("pedot-micro")
        steps = []
        monkeypatch.setattr(s, "reset", lambda *a, **k: steps.append(1))
        for kw, name in (({"rrd": rrd}, "rrd"), ({"csv_path": csv_path}, "csv_path"),
                         ({"rrd": tmp_path / "other.rrd", "csv_path": csv_path}, "csv_path")):
            with pytest.raises(ParameterError, match=f"{name}=.*{csv_path.stem}.*another mjeap run"):
                rollout(s, "step:1V", 0.01, engine="loop", **kw)
        assert not steps and not (tmp_path / "other.rrd").exists()
        assert main(["rollout", "pedot-micro", "--voltage", "step:1V", "--duration", "0.01",
                     "--rrd", str(rrd)]) == 2
    finally:
        time.sleep(0.5)         # as the SIGTERM test: the first run simulates a while (the checks above can be quick)
        p.send_signal(signal.SIGTERM)
        p.communicate(timeout=60)
    # the first run's outputs are whole
    assert any("Terminated" in t for t in _log_texts(rrd))
    rows = list(csv.reader(open(csv_path, newline="")))
    assert len(rows) > 10 and all(len(r) == len(rows[0]) for r in rows)
    assert _leftovers(tmp_path, {"r.rrd", "r.csv"}) == []
    # afterwards the path is free again
    rollout(Scene("pedot-micro"), "step:1V", 0.01, rrd=rrd, csv_path=csv_path)
    assert _leftovers(tmp_path, {"r.rrd", "r.csv"}) == []


def test_outputs_are_renamed_into_place_whole(tmp_path, monkeypatch):
    """While a run writes, its paths still hold the previous files (a reader never sees a
    part); the new files replace them whole, and nothing else is left beside them."""
    from mjeap.io import recording
    rrd, csv_path = tmp_path / "r.rrd", tmp_path / "r.csv"
    rrd.write_bytes(b"old recording")
    csv_path.write_text("old,csv\n")
    seen = []
    log_outcome, column_stack = recording._log_outcome, np.column_stack

    def logging_outcome(*a, **k):                 # the recording is being written
        seen.append(("rrd", rrd.read_bytes()))
        return log_outcome(*a, **k)

    def stacking(*a, **k):                        # the CSV's header is written, its rows next
        seen.append(("csv", csv_path.read_bytes()))
        return column_stack(*a, **k)

    monkeypatch.setattr(recording, "_log_outcome", logging_outcome)
    monkeypatch.setattr(np, "column_stack", stacking)
    r = rollout(Scene("pedot-micro"), "step:1V", 0.02, rrd=rrd, csv_path=csv_path)
    monkeypatch.undo()
    assert seen == [("rrd", b"old recording"), ("csv", b"old,csv\n")]
    assert "/plots/voltage" in read_recording(rrd)
    assert len(csv_path.read_text().splitlines()) == len(r.time) + 1
    assert _leftovers(tmp_path, {"r.rrd", "r.csv"}) == []


def test_a_lock_left_by_a_killed_writer_blocks_nothing(tmp_path):
    rrd = tmp_path / "r.rrd"
    holder = subprocess.Popen([sys.executable, "-c", "import fcntl, sys, time\n"
                               f"fh = open({str(rrd) + '.lock'!r}, 'a+')\n"
                               "fcntl.flock(fh, fcntl.LOCK_EX | fcntl.LOCK_NB)\n"
                               "print('ready', flush=True)\ntime.sleep(60)\n"],
                              stdout=subprocess.PIPE, text=True)
    assert holder.stdout.readline().strip() == "ready"
    holder.kill()                                  # as kill -9 or the OOM killer would
    holder.wait(timeout=10)
    assert (tmp_path / "r.rrd.lock").exists()
    rollout(Scene("pedot-micro"), "step:1V", 0.01, rrd=rrd)
    assert _leftovers(tmp_path, {"r.rrd"}) == []


# ---------------------------------------------------------------- 3. spreadsheet-safe CSVs
def test_csv_cells_a_spreadsheet_would_run_are_neutralised_and_read_back(tmp_path, capsys):
    from mjeap.studies.sweep import read_results
    out = tmp_path / "s.csv"
    args = ["sweep", "--vary", "actuator=pedot-micro,=1+1", "--vary", "amplitude=-0.5,0.5", "--set",
            "duration=0.02", "--executor", "serial", "--quiet", "--out", str(out)]
    assert main(args) == 0
    capsys.readouterr()
    raw = list(csv.reader(open(out, newline="")))
    cells = [c for row in raw for c in row]
    assert "'=1+1" in cells and "=1+1" not in cells
    for c in cells:                               # nothing a spreadsheet runs; numbers as they were
        if c[:1] in ("=", "+", "-", "@", "\t", "\r"):
            float(c)
    assert "-0.5" in cells
    rows = read_results(out)
    assert sorted(r["actuator"] for r in rows) == ["=1+1", "=1+1", "pedot-micro", "pedot-micro"]
    assert sorted(float(r["amplitude"]) for r in rows) == [-0.5, -0.5, 0.5, 0.5]
    assert all(r["error"].startswith("UnknownNameError") == (r["actuator"] == "=1+1") for r in rows)
    # the sweep resumed on its own file skips every point
    assert main(args) == 0
    summary = json.loads(capsys.readouterr().out)
    assert (summary["ran"], summary["skipped (already in the file)"]) == (0, 4) and len(read_results(out)) == 4


def test_rollout_csv_headers_are_neutralised_and_numbers_kept(tmp_path):
    from mjeap.io.csvio import read_rows
    r = rollout(Scene("pedot-micro"), "step:-1V", 0.02)
    evil = "=HYPERLINK(\"http://x\",\"y\") (V)"
    r.signals = {evil: np.full(len(r.time), -1.5), "@SUM(A1) (A)": np.zeros(len(r.time))}
    r.to_csv(tmp_path / "r.csv")
    raw = list(csv.reader(open(tmp_path / "r.csv", newline="")))
    assert "'" + evil in raw[0] and "'@SUM(A1) (A)" in raw[0]
    col = raw[0].index("'" + evil)
    assert all(row[col] == "-1.5" for row in raw[1:])            # numbers unchanged
    assert all(row[raw[0].index("voltage (V)")] == "-1.0" for row in raw[1:])
    back = read_rows(tmp_path / "r.csv")
    assert evil in back[0] and "@SUM(A1) (A)" in back[0]


def test_safe_cells_read_back_as_written():
    from mjeap.io.csvio import plain_cell, safe_cell
    texts = ["=1+1", "+1 x", "-x", "@SUM(A1)", "\t=1", "\r=1", "'=1", "''@x", "'", "'x", "x", "", "-", "+",
             "=", "pedot-micro", "{\"base\": 1}"]
    for t in texts:
        assert plain_cell(safe_cell(t)) == t, t
        cell = safe_cell(t)
        assert not (cell[:1] in "=+-@\t\r" and cell), t
    for number in (-1.5, 1e-7, -3, "-1.5", "+2e-3", "-inf", "nan"):
        assert safe_cell(number) == number and plain_cell(str(number)) == str(number)
