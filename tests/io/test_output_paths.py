"""Odd output paths (trust issue, section 2): nothing that is not a regular file of ours is
ever replaced, no path ends in a traceback, a full disk leaves the old file, and only our own
temporaries are removed. Each test fails on eaac59e, where the atomic writer renamed its
temporary over whatever was at the target (a device, a FIFO), followed a planted lock link,
crashed creating a lock in /proc, put a truncated file in place of the old one on ENOSPC and
deleted any file named like its temporaries.
"""
import errno
import os
import stat
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from mjeap import Scene, rollout
from mjeap.errors import OutputError, ParameterError
from mjeap.io import outputs
from mjeap.io.recording import read_recording

ROOT = Path(__file__).resolve().parents[2]
ENV = {**os.environ, "PYTHONPATH": os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")])}
root_only = pytest.mark.skipif(os.geteuid() != 0, reason="making a device node needs root")


def _run(**out):
    return rollout(Scene("pedot-micro", segments=4), "step:1V", 0.005, progress=False, **out)


def _cli(*args, **kw):
    return subprocess.run([sys.executable, "-m", "mjeap.cli", *args], capture_output=True, text=True, env=ENV,
                          timeout=120, **kw)


def _no_traceback(p):
    assert "Traceback" not in p.stderr, p.stderr
    return p


# ---------------------------------------------------------------- streams are written through
@root_only
def test_a_character_device_is_written_through_never_replaced(tmp_path):
    null = tmp_path / "null"
    os.mknod(null, stat.S_IFCHR | 0o666, os.makedev(1, 3))          # /dev/null's numbers
    _run(rrd=null, csv_path=tmp_path / "r.csv")
    assert stat.S_ISCHR(os.stat(null).st_mode)
    assert sorted(os.listdir(tmp_path)) == ["null", "r.csv"]


@root_only
@pytest.mark.slow
def test_a_full_device_is_an_output_error_and_stays_a_device(tmp_path):
    full = tmp_path / "full"
    os.mknod(full, stat.S_IFCHR | 0o666, os.makedev(1, 7))          # /dev/full: every write is ENOSPC
    with pytest.raises(OutputError, match="No space left on device"):
        _run(csv_path=full)
    assert stat.S_ISCHR(os.stat(full).st_mode)
    p = _no_traceback(_cli("rollout", "pedot-micro", "--voltage", "step:1V", "--duration", "0.005",
                           "--rrd", str(full)))
    assert p.returncode == 2 and "No space left on device" in p.stderr
    assert stat.S_ISCHR(os.stat(full).st_mode)


def test_a_fifo_gets_the_whole_output_and_stays_a_fifo(tmp_path):
    fifo = tmp_path / "f.csv"
    os.mkfifo(fifo)
    got = []
    reader = threading.Thread(target=lambda: got.append(open(fifo, "rb").read()))
    reader.start()
    try:
        for _ in range(100):        # until the reader's open() is under way (a loaded machine is slow to start it)
            try:
                r = _run(csv_path=fifo)
                break
            except ParameterError as e:
                assert "nobody reads it" in str(e)
                time.sleep(0.05)
    finally:
        reader.join(timeout=60)
    assert stat.S_ISFIFO(os.stat(fifo).st_mode)
    lines = got[0].decode().splitlines()
    assert lines[0].startswith("time (s)") and len(lines) == len(r.time) + 1


def test_a_fifo_nobody_reads_is_refused_before_any_work(tmp_path, monkeypatch):
    fifo = tmp_path / "f.rrd"
    os.mkfifo(fifo)
    s = Scene("pedot-micro", segments=4)
    steps = []
    monkeypatch.setattr(s, "update_kinematics", lambda: steps.append(1), raising=False)
    with pytest.raises(ParameterError, match="rrd.*nobody reads it"):
        rollout(s, "step:1V", 0.005, rrd=fifo, progress=False)
    assert not steps and stat.S_ISFIFO(os.stat(fifo).st_mode)


@pytest.mark.slow
def test_stdout_on_a_pipe_takes_the_csv():
    p = _no_traceback(_cli("rollout", "pedot-micro", "--voltage", "step:1V", "--duration", "0.005",
                           "--csv", "/dev/stdout", "--quiet"))
    assert p.returncode == 0 and p.stdout.startswith("time (s),voltage (V)")


@pytest.mark.parametrize("argv", [["list"], pytest.param(["show", "pzt-hamr-small"], marks=pytest.mark.slow)])
def test_a_reader_that_closes_stdout_ends_the_command_in_one_line(argv):
    """``mjeap list | head -1``: the reader goes away before mjeap writes; mjeap exits 141 (128
    + SIGPIPE, as a shell reports it) with one line on stderr, never a traceback or Python's
    'Exception ignored' at exit."""
    p = subprocess.Popen([sys.executable, "-m", "mjeap.cli", *argv], stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    p.stdout.close()                                  # the reader is gone before the first byte
    err = p.stderr.read().decode()
    assert p.wait(timeout=60) == 141, err
    assert "Traceback" not in err and "Exception ignored" not in err
    assert err.splitlines() == ["mjeap: stdout was closed by its reader; the rest of what was to go there is dropped"]



@pytest.mark.parametrize("where", ["/proc/mjeap-test.rrd", "/sys/mjeap-test.rrd", "DIR", "BLOCK"])
def test_paths_that_cannot_be_written_are_refused_naming_the_parameter(tmp_path, where):
    if where == "DIR":
        where = str(tmp_path)
    if where == "BLOCK":
        if os.geteuid() != 0:
            pytest.skip("making a device node needs root")
        where = str(tmp_path / "disk")
        os.mknod(where, stat.S_IFBLK | 0o600, os.makedev(7, 250))
    with pytest.raises(ParameterError, match=r"^rrd="):
        _run(rrd=where)
    p = _no_traceback(_cli("rollout", "pedot-micro", "--voltage", "step:1V", "--duration", "0.005", "--rrd", where))
    assert p.returncode == 2 and "rrd=" in p.stderr


# ---------------------------------------------------------------- locks
@pytest.mark.parametrize("plant", ["symlink", "hardlink", "foreign", "fifo"])
def test_a_lock_that_is_not_ours_is_refused_and_left_alone(tmp_path, plant):
    precious = tmp_path / "precious.txt"
    precious.write_text("keep me\n")
    lock = tmp_path / "r.rrd.lock"
    {"symlink": lambda: lock.symlink_to(precious), "hardlink": lambda: os.link(precious, lock),
     "foreign": lambda: lock.write_text("keep me too\n"), "fifo": lambda: os.mkfifo(lock)}[plant]()
    with pytest.raises(ParameterError, match=r"rrd=.*r\.rrd\.lock.*not overwritten"):
        _run(rrd=tmp_path / "r.rrd")
    assert precious.read_text() == "keep me\n"
    assert not (tmp_path / "r.rrd").exists()
    if plant == "foreign":
        assert lock.read_text() == "keep me too\n"


def test_files_named_like_temporaries_are_not_ours_and_stay(tmp_path):
    mine = [tmp_path / ".r.csv.abc.tmp.csv", tmp_path / ".r.csv.0123456789abcdef.tmp.csv"]
    for f in mine:
        f.write_text("a user's file\n")
    _run(csv_path=tmp_path / "r.csv")
    assert all(f.read_text() == "a user's file\n" for f in mine)


def test_a_killed_writers_temporary_is_removed_and_only_it(tmp_path):
    """A writer killed mid-write left its temporary and its lock (naming it): the next
    writer removes that temporary, nothing else."""
    target = tmp_path / "r.csv"
    code = ("import os, signal\nfrom mjeap.io.outputs import replacing\n"
            f"with replacing({str(target)!r}) as tmp:\n    tmp.write_text('part')\n"
            "    os.kill(os.getpid(), signal.SIGKILL)\n")
    subprocess.run([sys.executable, "-c", code], env=ENV, timeout=60)
    left = [f for f in os.listdir(tmp_path) if f.endswith(".tmp.csv")]
    assert len(left) == 1 and (tmp_path / "r.csv.lock").exists()
    other = tmp_path / ".r.csv.1111111111111111.tmp.csv"
    other.write_text("not named in the lock")
    _run(csv_path=target)
    assert sorted(os.listdir(tmp_path)) == [other.name, "r.csv"]


# ---------------------------------------------------------------- a full disk keeps the old file
def _enospc_after(monkeypatch, module, nbytes):
    """``module``'s open() gives files that raise ENOSPC once ``nbytes`` are written."""
    real = open

    class Full:
        def __init__(self, fh):
            self.fh, self.n = fh, 0

        def write(self, data):
            self.n += len(data)
            if self.n > nbytes:
                raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
            return self.fh.write(data)

        def __getattr__(self, name):
            return getattr(self.fh, name)

        def __enter__(self):
            return self

        def __exit__(self, *exc):
            self.fh.close()

    monkeypatch.setattr(module, "open", lambda *a, **k: Full(real(*a, **k)), raising=False)


@pytest.mark.parametrize("which", ["rrd", "csv_path"])
def test_a_full_disk_leaves_the_old_file_and_no_temporary(tmp_path, monkeypatch, which):
    from mjeap.engines import result          # RolloutResult.to_csv writes the CSV
    from mjeap.io import recording
    old = tmp_path / ("r.rrd" if which == "rrd" else "r.csv")
    old.write_bytes(b"the old file")
    _enospc_after(monkeypatch, recording if which == "rrd" else result, 2000)
    with pytest.raises(OutputError, match="No space left on device") as e:
        _run(**{which: old})
    assert e.value.result is not None                       # the finished run rides along
    assert old.read_bytes() == b"the old file"
    assert sorted(os.listdir(tmp_path)) == [old.name]


def _tmpfs(folder, size):
    folder.mkdir()
    if os.geteuid() != 0 or subprocess.run(["mount", "-t", "tmpfs", "-o", f"size={size}", "tmpfs", str(folder)],
                                           capture_output=True).returncode:
        pytest.skip("mounting a small tmpfs needs root and a kernel that lets this sandbox mount")


@pytest.mark.slow
def test_a_really_full_disk_keeps_the_old_outputs_and_a_sweep_its_whole_rows(tmp_path):
    disk = tmp_path / "disk"
    _tmpfs(disk, "160k")
    try:
        (disk / "r.rrd").write_bytes(b"old rrd")
        (disk / "r.csv").write_bytes(b"old csv")
        (disk / "fill").write_bytes(b"\0" * 120_000)
        p = _no_traceback(_cli("rollout", "pedot-micro", "--voltage", "step:1V", "--duration", "0.3",
                               "--rrd", str(disk / "r.rrd"), "--csv", str(disk / "r.csv"), cwd=str(tmp_path)))
        assert p.returncode == 2 and "No space left on device" in p.stderr
        assert (disk / "r.rrd").read_bytes() == b"old rrd" and (disk / "r.csv").read_bytes() == b"old csv"
        assert sorted(os.listdir(disk)) == ["fill", "r.csv", "r.rrd"]
        p = _no_traceback(_cli("sweep", "--vary", "amplitude=0.1:1.0:400", "--set", "duration=0.002",
                               "--set", "segments=4", "--metrics", "peak_to_peak", "--out", str(disk / "s.csv"),
                               "--executor", "serial", cwd=str(tmp_path)))
        assert p.returncode == 2 and "whole rows written so far are kept" in p.stderr
        data = (disk / "s.csv").read_bytes()
        assert data.endswith(b"\n") and data.count(b"\n") > 1
    finally:
        subprocess.run(["umount", str(disk)], capture_output=True)


def test_a_sweep_that_fills_the_disk_stops_with_its_rows_whole(tmp_path, monkeypatch):
    from mjeap.studies.sweep import grid, read_results, run_sweep
    out = tmp_path / "s.csv"
    real, state = os.write, {"rows": 0}

    def write(fd, data):
        try:
            mine = os.readlink(f"/proc/self/fd/{fd}") == str(out)
        except OSError:
            mine = False
        if mine:
            state["rows"] += 1
            if state["rows"] == 4:                 # the header and two rows fit, then the disk is full
                real(fd, bytes(data)[:7])          # a part of the row reached the disk
                raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        return real(fd, data)

    monkeypatch.setattr(os, "write", write)
    with pytest.raises(OutputError, match="2 whole rows written so far are kept"):
        run_sweep(grid(amplitude=[0.1, 0.2, 0.3, 0.4]), out, metrics=("peak_to_peak",),
                  base={"duration": 0.002, "segments": 4}, executor="serial")
    monkeypatch.undo()
    assert len(read_results(out)) == 2 and out.read_bytes().endswith(b"\n")
    s = run_sweep(grid(amplitude=[0.1, 0.2, 0.3, 0.4]), out, metrics=("peak_to_peak",),
                  base={"duration": 0.002, "segments": 4}, executor="serial")
    assert (s.done, s.skipped) == (2, 2)


# ---------------------------------------------------------------- robots
def test_robot_outputs_are_locked_and_told_apart(tmp_path):
    from mjeap.robots import robobee_wing
    rrd = tmp_path / "w.rrd"
    with outputs.hold(rrd, "rrd"):
        code = f"from mjeap.robots import robobee_wing as w\nw.main(['--out', {str(rrd)!r}, '--quick'])\n"
        p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=ENV, timeout=120)
    assert p.returncode != 0 and "holds its lock" in p.stderr
    del robobee_wing


def test_hamr_walk_refuses_one_path_for_both_recordings(tmp_path):
    p = _no_traceback(_cli("robot", "hamr-walk", "--quick", "--frequencies", "10", "--record-frequency", "10",
                           "--out", str(tmp_path / "x.rrd"), "--loop-out", str(tmp_path / "x.rrd")))
    assert p.returncode == 2 and "--loop-out" in p.stderr and "--out" in p.stderr
    assert os.listdir(tmp_path) == []


@pytest.mark.slow
def test_sigterm_on_a_robot_run_keeps_each_finished_study(tmp_path):
    """robobee-wing --quick: the recording holds the first voltage's study as soon as it is
    done; SIGTERM during the second keeps it (on eaac59e it was written after both)."""
    import signal
    import time
    rrd = tmp_path / "w.rrd"
    p = subprocess.Popen([sys.executable, "-m", "mjeap.cli", "robot", "robobee-wing", "--quick", "--out", str(rrd)],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=ENV)
    t0 = time.time()
    while not rrd.exists() and p.poll() is None and time.time() - t0 < 240:
        time.sleep(0.2)
    assert rrd.exists(), p.communicate()[1][-2000:]
    p.send_signal(signal.SIGTERM)
    _, err = p.communicate(timeout=120)
    assert p.returncode == 143 and "Traceback" not in err
    assert any(k.startswith("/wing/stroke_150Hz/100V") for k in read_recording(rrd))
