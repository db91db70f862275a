"""The one writer (issue 43, trust round 3), tested at its shared mechanism: every command and
script that writes, against a table of what can stand at an output path.

:data:`COMMANDS` is the registry of writers: one line per output of a command, script or API,
saying how its path is given: a path the user names (``picked=None``: the target replaces it)
or a name mjeap picks itself in a folder the user names (``picked="NAME"``: the target is
planted at FOLDER/NAME). A new command (``mjeap frf``, ``optimize --pareto``'s files) is one
line here and meets every target.

:data:`TARGETS`: a character device, a FIFO nobody reads, a planted symbolic link, a path under
/proc and under /sys, a read-only mount, a full disk, a full device (/dev/full: every write
ENOSPC), one of the run's own inputs (and a hard link of it). Each is refused before any work with one line (``mjeap: error: ...``, exit 2),
never a traceback, and left as it was; a device under a name the user gives is written
through (exit 0) and stays a device. Each row reproduces a failure of the audit on the code
before this change (symlinks followed at picked names, inputs overwritten, tracebacks under
/sys, a read-only mount or a full device).
"""
import os
import shutil
import stat
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Optional

import numpy as np
import pytest

from mjeap.cli import main
from mjeap.model.catalog import CATALOG_DIR

ROOT = Path(__file__).resolve().parents[2]
ENV = {**os.environ, "PYTHONPATH": os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")])}
ROOT_ONLY = os.geteuid() == 0


@dataclass
class Inputs:
    """The input files a command reads, made fresh per test."""

    act: Path                      # an actuator file (pedot-micro's)
    wave: Path                     # a waveform CSV
    data: Path                     # a step response CSV (identify)


@dataclass
class Command:
    """How one output of one writer is given: ``argv(out, inputs)`` its command line, ``out``
    the output path (the user's) or the folder (``picked``: the name mjeap picks there).
    ``input``: which of its :class:`Inputs` an output may never be (its argv reads it).
    ``script``: run as ``python SCRIPT ARGV`` (else ``mjeap ARGV`` in this process).
    ``slow``: a run that accepts the target does minutes of work (a device under a user's name).
    ``needs``: an optional module the output cannot be written without (its test skips without it)."""

    argv: Callable[[str, Inputs], list]
    picked: Optional[str] = None
    input: Optional[str] = None
    script: Optional[str] = None
    slow: bool = False
    cwd: bool = False              # the picked name is relative to the working directory (a default --out)
    needs: Optional[str] = None


QUICK_ROLLOUT = ["--voltage", "step:1V", "--duration", "0.002", "--segments", "4", "--quiet"]
SWEEP = ["sweep", "--vary", "amplitude=0.5", "--set", "duration=0.002", "--set", "segments=4", "--metrics",
         "peak_to_peak", "--executor", "serial", "--quiet"]
OPTIMIZE = ["--vary", "actuator.length=5mm:7mm", "--minimize", "mass", "--max-evaluations", "4", "--quiet"]
VALIDATE = ["validate", "mechanics-section", "--quick", "--quiet", "--out"]


#: every writer of mjeap: one line per output (name -> Command)
COMMANDS = {
    "rollout --csv": Command(lambda o, f: ["rollout", str(f.act), *QUICK_ROLLOUT, "--csv", o], input="act"),
    "rollout --rrd": Command(lambda o, f: ["rollout", "pedot-micro", "--voltage", f"csv:{f.wave}", "--duration",
                                           "0.002", "--segments", "4", "--quiet", "--rrd", o], input="wave"),
    "mjcf -o": Command(lambda o, f: ["mjcf", str(f.act), "-o", o], input="act"),
    "identify step --out": Command(lambda o, f: ["identify", "step", str(f.data), "--voltage", "3", "--actuator",
                                                 "pedot-micro", "--out", o], input="data"),
    "identify step (out/identified.toml)": Command(
        lambda o, f: ["identify", "step", str(f.data), "--voltage", "3", "--actuator", "pedot-micro"],
        picked="out/identified.toml", cwd=True),
    "sweep --out": Command(lambda o, f: [*SWEEP, "--set", f"actuator={f.act}", "--out", o], input="act"),
    "sweep --record (point-ID.rrd)": Command(lambda o, f: [*SWEEP, "--record", "0", "--out", f"{o}/s.csv"],
                                             picked="s-rrd/RECORDED"),
    "optimize (result.json)": Command(lambda o, f: ["optimize", "pedot-micro", *OPTIMIZE, "--out", o],
                                      picked="result.json"),
    "optimize (optimum.toml)": Command(lambda o, f: ["optimize", str(f.act), *OPTIMIZE, "--out", o],
                                       picked="optimum.toml", input="act"),
    "optimize (evaluations.csv)": Command(lambda o, f: ["optimize", "pedot-micro", *OPTIMIZE, "--out", o],
                                          picked="evaluations.csv"),
    "optimize --pareto (pareto.csv)": Command(lambda o, f: ["optimize", "pedot-micro", "--vary",
                                                            "actuator.length=5mm:7mm", "--pareto", "mass,first_frequency",
                                                            "--max-evaluations", "6", "--quiet", "--out", o],
                                              picked="pareto.csv"),
    "frf (frf.csv)": Command(lambda o, f: ["frf", str(f.act), "--from", "1Hz", "--to", "50Hz", "--points", "5",
                                           "--out", o], picked="frf.csv", input="act"),
    "frf (frf.json)": Command(lambda o, f: ["frf", "pedot-micro", "--from", "1Hz", "--to", "50Hz", "--points", "5",
                                            "--out", o], picked="frf.json"),
    "identify piezo --out": Command(lambda o, f: ["identify", "piezo", "pzt-hamr-small", "--resonance", "1750Hz",
                                                  "--out", o]),
    "validate (report.md)": Command(lambda o, f: [*VALIDATE, o], picked="report.md"),
    "validate (validation.json)": Command(lambda o, f: [*VALIDATE, o], picked="validation.json"),
    "validate (EXPERIMENT.rrd)": Command(lambda o, f: [*VALIDATE, o], picked="mechanics-section.rrd"),
    "robot --out": Command(lambda o, f: ["robot", "robobee-wing", "--quick", "--out", o], slow=True),
    "examples DIR": Command(lambda o, f: ["examples", o], picked="design_study.py"),
    "scripts/stability_map.py (report.md)": Command(lambda o, f: ["--out", o, "--masses", "2", "--amplitudes", "1",
                                                                 "--periods", "1", "--executor", "serial"],
                                                    script="scripts/stability_map.py", picked="report.md", slow=True),
    "scripts/bench.py --json": Command(lambda o, f: ["--only", "models", "--min-seconds", "0.001", "--json", o],
                                       script="scripts/bench.py", slow=True),
    "examples/design_study.py --png": Command(lambda o, f: ["--png", o], script="examples/design_study.py",
                                              slow=True, needs="matplotlib"),
}


# ---------------------------------------------------------------- the targets
#: the tmpfs mounted by the test running now (unmounted by the ``mounts`` fixture, whatever happens)
MOUNTED: list = []


@pytest.fixture(autouse=True)
def mounts():
    yield MOUNTED
    while MOUNTED:
        subprocess.run(["umount", "-l", str(MOUNTED.pop())], capture_output=True)


def _mount(folder: Path, options: str) -> None:
    folder.mkdir(parents=True, exist_ok=True)
    if not ROOT_ONLY or subprocess.run(["mount", "-t", "tmpfs", "-o", options, "tmpfs", str(folder)],
                                       capture_output=True).returncode:
        pytest.skip("mounting a tmpfs needs root and a kernel that lets this sandbox mount")
    MOUNTED.append(folder)


@dataclass
class Planted:
    """A target planted at ``path``: ``intact()`` says it is as it was; ``accepted``: a
    command writing there succeeds (a device under the user's name), else it is refused."""

    path: Path
    intact: Callable[[], bool]
    accepted: bool = False
    message: str = ""                      # in the one-line error


def _device(tmp, where, cmd):
    if not ROOT_ONLY:
        pytest.skip("making a device node needs root")
    where.parent.mkdir(parents=True, exist_ok=True)
    os.mknod(where, stat.S_IFCHR | 0o666, os.makedev(1, 3))          # /dev/null's numbers
    return Planted(where, lambda: stat.S_ISCHR(os.lstat(where).st_mode), accepted=cmd.picked is None,
                   message="character device")


def _full_device(tmp, where, cmd):
    if not ROOT_ONLY:
        pytest.skip("making a device node needs root")
    where.parent.mkdir(parents=True, exist_ok=True)
    os.mknod(where, stat.S_IFCHR | 0o666, os.makedev(1, 7))          # /dev/full's: every write is ENOSPC
    return Planted(where, lambda: stat.S_ISCHR(os.lstat(where).st_mode),
                   message="No space left on device" if cmd.picked is None else "character device")


def _fifo(tmp, where, cmd):
    where.parent.mkdir(parents=True, exist_ok=True)
    os.mkfifo(where)
    return Planted(where, lambda: stat.S_ISFIFO(os.lstat(where).st_mode),
                   message="FIFO" if cmd.picked else "nobody reads it")


def _link(tmp, where, cmd):
    precious = tmp / "precious" / "keep.txt"
    precious.parent.mkdir()
    precious.write_text("keep me\n")
    where.parent.mkdir(parents=True, exist_ok=True)
    where.symlink_to(precious)
    return Planted(where, lambda: os.path.islink(where) and precious.read_text() == "keep me\n",
                   message="symbolic link")


def _proc(tmp, where, cmd):
    return Planted(Path("/proc/mjeap-test") / where.name, lambda: not os.path.exists("/proc/mjeap-test"))


def _sys(tmp, where, cmd):
    return Planted(Path("/sys/mjeap-test") / where.name, lambda: not os.path.exists("/sys/mjeap-test"))


def _read_only(tmp, where, cmd):
    disk = tmp / "ro"
    _mount(disk, "ro,size=64k")
    return Planted(disk / "d" / where.name, lambda: os.listdir(disk) == [], message="Read-only file system")


def _full(tmp, where, cmd):
    disk = tmp / "full"
    _mount(disk, "size=64k")
    fd = os.open(disk / "fill", os.O_WRONLY | os.O_CREAT)      # every block taken
    try:
        while os.write(fd, b"\0" * 4096):
            pass
    except OSError:
        pass
    finally:
        os.close(fd)
    size = (disk / "fill").stat().st_size
    files = lambda: sorted(str(p.relative_to(disk)) for p in disk.rglob("*") if not p.is_dir())   # noqa: E731
    return Planted(disk / where.name, lambda: files() == ["fill"] and (disk / "fill").stat().st_size == size,
                   message="No space left on device")       # no lock, temporary or part left


TARGETS = {"device node": _device, "full device": _full_device, "FIFO": _fifo, "planted link": _link, "/proc": _proc, "/sys": _sys,
           "read-only mount": _read_only, "full disk": _full, "an input": None, "an input's hard link": None}


# ---------------------------------------------------------------- running a command
def _inputs(tmp: Path) -> Inputs:
    d = tmp / "inputs"
    d.mkdir()
    act = d / "act.toml"
    shutil.copyfile(CATALOG_DIR / "pedot-micro.toml", act)
    wave = d / "wave.csv"
    wave.write_text("time,voltage\n0,0\n0.001,0.5\n0.01,1\n")
    from scipy import signal
    t = np.arange(0, 20, 0.01)
    _, y, _ = signal.lsim(signal.TransferFunction([63.0, 63.0 * 0.52], np.polymul([1, 0.3], [1, 1.8])),
                          3.0 * np.ones_like(t), t)
    data = d / "data.csv"
    data.write_text("time (s),tip_curvature (1/m)\n" + "\n".join(f"{a:.6g},{b:.9g}" for a, b in zip(t, y)))
    return Inputs(act, wave, data)


def _run(cmd: Command, argv, capsys, cwd: Path):
    if cmd.script is not None:
        p = subprocess.run([sys.executable, str(ROOT / cmd.script), *argv], capture_output=True, text=True, env=ENV,
                           timeout=600, cwd=str(cwd))
        return p.returncode, p.stderr
    capsys.readouterr()
    try:
        code = main(argv)
    except SystemExit as e:                          # argparse's refusal of a bad argument: usage and one line
        code = e.code
    return code, capsys.readouterr().err


def _one_line_refusal(code, err, message=""):
    lines = [l for l in err.splitlines() if l.strip()]
    errors = [l for l in lines if ": error: " in l]
    assert code == 2 and "Traceback" not in err, err
    assert len(errors) == 1, err
    assert message in errors[0], (message, err)


CASES = [pytest.param(c, t, marks=[pytest.mark.slow] if COMMANDS[c].slow or COMMANDS[c].script else [],
                      id=f"{c} | {t}") for c in COMMANDS for t in TARGETS]


@pytest.mark.parametrize("command,target", CASES)
def test_every_writer_against_every_target(tmp_path, capsys, monkeypatch, command, target):
    cmd = COMMANDS[command]
    if cmd.needs is not None:
        pytest.importorskip(cmd.needs, reason=f"{command} writes nothing without {cmd.needs}")
    f = _inputs(tmp_path)
    monkeypatch.chdir(tmp_path)
    folder = tmp_path / "out-folder"
    if target.startswith("an input"):
        _input_target(cmd, f, folder, target.endswith("hard link"), capsys, tmp_path)
        return
    if cmd.picked is not None and "RECORDED" in cmd.picked:
        cmd = Command(cmd.argv, picked=cmd.picked.replace("RECORDED", _recorded_name()), input=cmd.input,
                      script=cmd.script, slow=cmd.slow, cwd=cmd.cwd)
    base = tmp_path if cmd.cwd else folder
    where = base / (cmd.picked or "out.file")
    planted = TARGETS[target](tmp_path, where, cmd)
    if target in ("/proc", "/sys", "read-only mount", "full disk"):
        out = str(planted.path if cmd.picked is None else planted.path.parent)
        if cmd.cwd:                                   # a default name under the working directory
            monkeypatch.chdir(next(p for p in planted.path.parents if p.is_dir()))
    else:
        out = str(planted.path if cmd.picked is None else folder)
    code, err = _run(cmd, cmd.argv(out, f), capsys, Path(os.getcwd()))
    monkeypatch.chdir(tmp_path)
    if planted.accepted:
        assert code == 0 and "Traceback" not in err, err
    else:
        _one_line_refusal(code, err, planted.message)
    assert planted.intact()


def _input_target(cmd, f, folder, hard, capsys, tmp_path):
    """The output is one of the run's inputs (or a hard link of it): refused before any
    work, naming both, the input unchanged."""
    if cmd.input is None:
        pytest.skip("this writer reads no input file")
    source = getattr(f, cmd.input)
    if cmd.picked is None:
        out = str(source)
        if hard:
            out = str(tmp_path / "hard-link-of-the-input")
            os.link(source, out)
    else:                                        # the input lies where mjeap picks its output's name
        folder.mkdir()
        where = folder / cmd.picked
        if hard:
            os.link(source, where)
        else:
            shutil.copyfile(source, where)
            setattr(f, cmd.input, where)
            source = where
        out = str(folder)
    before = source.read_bytes()
    code, err = _run(cmd, cmd.argv(out, f), capsys, tmp_path)
    _one_line_refusal(code, err, "one of the run's inputs")
    assert source.read_bytes() == before


def _recorded_name() -> str:
    from mjeap.studies.parameters import to_value
    from mjeap.studies.sweep import grid, point_id
    base = {"duration": to_value("duration", "0.002"), "segments": to_value("segments", "4")}
    return f"point-{point_id(grid(amplitude=[0.5])[0], base, ['peak_to_peak'])}.rrd"


def test_the_table_covers_every_command_of_the_cli():
    """Every mjeap command that writes a file has a row (a new one must add its line)."""
    from mjeap.cli import build_parser
    writes = {"rollout", "mjcf", "identify", "sweep", "optimize", "validate", "robot", "examples", "frf"}
    commands = set(build_parser()._subparsers._group_actions[0].choices)
    assert writes <= commands
    covered = {c.split()[0] for c in COMMANDS if not COMMANDS[c].script}
    assert writes <= covered, writes - covered
    quiet = commands - writes                        # these print only
    assert quiet <= {"list", "show", "materials", "view"}, quiet
