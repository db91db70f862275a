"""The stability map of Dadras et al. 2021's inverted actuator (mjeap.studies.stability_map, mjeap.studies.stability_map, scripts/stability_map.py).

Physics claim: the simulated payload limit sits at the static column load with the relaxed
EI (76 mg at l_e = 6.27 mm), not at the paper's Region 3 model (46 mg) or the instantaneous
column load (132 mg): at 0.5 V a payload of 0.8 x the relaxed limit returns every half
period and 1.25 x does not; above the instantaneous column load nothing returns even at
the largest amplitude (1.5 V). Tolerance: the bracket +-20/25 % around the relaxed limit;
the measured edge is 82.5 mg (0.25-1 V) and 97.5 mg (1.25-1.5 V), see the script's report.
"""
import subprocess
import sys
from pathlib import Path

import pytest

from mjeap.studies.stability_map import MAP_BASE, column_limits, simulated_edges
from mjeap.studies.sweep import read_results, run_sweep

ROOT = Path(__file__).resolve().parents[2]


def test_theory_limits_are_ordered_and_match_the_closed_forms():
    lim = column_limits()
    relaxed, inst = lim["column, relaxed EI (static limit)"], lim["column, instantaneous EI"]
    assert relaxed == pytest.approx(0.3 / 0.52 * inst, rel=1e-12)
    assert lim["paper's Region 3 model (marginal)"] < relaxed < inst
    assert 70e-6 < relaxed < 80e-6        # 76 mg, stated in the validation report


def test_simulated_edge_sits_at_the_relaxed_column_load(tmp_path):
    lim = column_limits()
    relaxed, inst = lim["column, relaxed EI (static limit)"], lim["column, instantaneous EI"]
    points = [dict(payload_mass=0.8 * relaxed, amplitude=0.5), dict(payload_mass=1.25 * relaxed, amplitude=0.5),
              dict(payload_mass=1.15 * inst, amplitude=1.5)]
    s = run_sweep(points, tmp_path / "map.csv", metrics=("returns",), base=MAP_BASE, workers=2, progress=False)
    assert s.failed == 0
    rows = sorted(read_results(tmp_path / "map.csv"), key=lambda r: (float(r["amplitude"]), float(r["payload_mass"])))
    assert [r["returns"] for r in rows] == ["True", "False", "False"]
    edge = simulated_edges([float(r["payload_mass"]) for r in rows], [float(r["amplitude"]) for r in rows],
                           [r["returns"] == "True" for r in rows])[0.5]
    assert 0.8 * relaxed < edge < 1.25 * relaxed


@pytest.mark.slow
def test_script_writes_report_image_and_recording(tmp_path):
    pytest.importorskip("matplotlib")
    out = tmp_path / "map"
    subprocess.run([sys.executable, str(ROOT / "scripts" / "stability_map.py"), "--out", str(out),
                    "--masses", "3", "--amplitudes", "1", "--workers", "1"], check=True, cwd=ROOT,
                   capture_output=True, text=True)
    report = (out / "report.md").read_text()
    assert "![stability map](stability_map.png)" in report and "relaxed EI" in report
    assert (out / "stability_map.png").stat().st_size > 10_000
    from mjeap.io.recording import read_blueprint, read_recording
    rec = read_recording(out / "stability_map.rrd")
    assert "/figure" in rec and "/report" in rec
    # laid out: the report beside the figure (axes and units), no bare 2D scatter
    assert {(v["kind"], v["origin"]) for v in read_blueprint(out / "stability_map.rrd")} == \
        {("TextDocument", "/report"), ("2D", "/figure")}


@pytest.mark.slow
def test_script_stops_points_once_periodic_and_refuses_a_stop_its_periods_cannot_make(tmp_path):
    """--stop-when-periodic needs four periods: with the map's three it is refused before any
    point (no results file); with six, a light payload's point stops and its row says where."""
    out = tmp_path / "map"
    cmd = [sys.executable, str(ROOT / "scripts" / "stability_map.py"), "--masses", "2", "--amplitudes", "1",
           "--workers", "1", "--executor", "serial", "--stop-when-periodic", "0.01"]
    bad = subprocess.run(cmd + ["--out", str(tmp_path / "bad")], cwd=ROOT, capture_output=True, text=True)
    assert bad.returncode != 0 and "stop_when_periodic" in bad.stderr and "4 periods" in bad.stderr
    assert not (tmp_path / "bad" / "results.csv").exists()
    subprocess.run(cmd + ["--out", str(out), "--periods", "6"], check=True, cwd=ROOT, capture_output=True, text=True)
    (row,) = read_results(out / "results.csv")
    assert row["stopped_early"].startswith("stopped at")
    assert "of 6 periods" in (out / "report.md").read_text()
