"""Failure classes of the reliability issue: each test fails on the code before its fix.

Sweeps: a point's identity includes every setting that changes its row (class 1), fixed
settings and drive parameters are checked before the first point (class 2), a torn last
row is dropped before appending (class 9), a sweep in which every point failed exits
non-zero (class 10)."""
import pytest

from mjeap.cli import main
from mjeap.errors import UnknownNameError
from mjeap.sweep import grid, read_results, run_sweep

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
