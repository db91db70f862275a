"""Parameter sweeps: designs, metrics, streaming CSV with resume, failures, executors."""
import numpy as np
import pytest

from mjeap.errors import ParameterError, UnknownNameError
from mjeap.studies.sweep import evaluate, grid, point_id, random_design, read_results, run_sweep

#: cheap points: the unloaded PEDOT actuator, two 1 Hz periods
BASE = dict(actuator="pedot-micro", frequency=1.0, duration=2.0)
POINTS = grid(amplitude=[0.5, 1.0], segments=[8, 12])


def test_designs():
    assert len(POINTS) == 4 and {p["amplitude"] for p in POINTS} == {0.5, 1.0}
    a = random_design(5, seed=3, amplitude=(0.1, 1.5), orientation=["up", "down"])
    assert a == random_design(5, seed=3, amplitude=(0.1, 1.5), orientation=["up", "down"])
    assert all(0.1 <= p["amplitude"] <= 1.5 and p["orientation"] in ("up", "down") for p in a)
    with pytest.raises(ParameterError, match="sweep parameter"):
        grid(amplitdue=[1.0])
    assert point_id({"a": 1, "b": 2}) == point_id({"b": 2, "a": 1})


@pytest.mark.slow
def test_peak_to_peak_metric_matches_the_drive_model():
    """Unloaded, the drive's own analytical curvature (eq. 8 under the same square wave)
    is the reference: within 1 % over the last period."""
    row = evaluate({"amplitude": 1.0}, metrics=("peak_to_peak",), base={**BASE, "frequency": 0.1, "duration": 20.0})
    from mjeap import Scene, rollout
    r = rollout(Scene("pedot-micro"), "square:1.0V@0.1Hz,offset=0.0V", 20.0, progress=False)
    ref = np.ptp(r.reference_curvature[r.time >= 10.0])
    assert row["error"] == "" and row["peak_to_peak"] == pytest.approx(ref, rel=0.01)


def test_failed_points_are_recorded_and_the_sweep_resumes(tmp_path):
    path = tmp_path / "s.csv"
    bad = {"amplitude": 1.0, "payload_mass": 1e-6, "payload_position": 1.0}      # 1 m: off the beam
    s1 = run_sweep(POINTS[:2] + [bad], path, base=BASE, executor="serial", progress=False)
    assert (s1.done, s1.skipped, s1.failed) == (3, 0, 1)
    rows = {r["point_id"]: r for r in read_results(path)}
    assert "payload.position" in rows[point_id(bad, BASE, ("peak_to_peak", "returns"))]["error"]
    # an interrupted sweep (two of four done) resumes without recomputing them
    s2 = run_sweep(POINTS + [bad], path, base=BASE, executor="serial", progress=False)
    assert (s2.done, s2.skipped) == (2, 3)
    assert len(read_results(path)) == 5


@pytest.mark.slow
def test_processes_and_serial_agree(tmp_path):
    serial = run_sweep(POINTS, tmp_path / "a.csv", base=BASE, executor="serial", progress=False)
    procs = run_sweep(POINTS, tmp_path / "b.csv", base=BASE, executor="processes", workers=2, progress=False,
                      record=[0])
    assert serial.failed == procs.failed == 0
    a = {r["point_id"]: float(r["peak_to_peak"]) for r in read_results(serial.path)}
    b = {r["point_id"]: float(r["peak_to_peak"]) for r in read_results(procs.path)}
    assert a == b
    assert (tmp_path / "b-rrd" / f"point-{point_id(POINTS[0], BASE, ('peak_to_peak', 'returns'))}.rrd").exists()


@pytest.mark.slow
def test_dask_local_cluster_agrees(tmp_path):
    pytest.importorskip("distributed")
    serial = run_sweep(POINTS[:2], tmp_path / "a.csv", base=BASE, executor="serial", progress=False)
    dask = run_sweep(POINTS[:2], tmp_path / "d.csv", base=BASE, executor="dask", workers=2, progress=False)
    a = {r["point_id"]: r["peak_to_peak"] for r in read_results(serial.path)}
    d = {r["point_id"]: r["peak_to_peak"] for r in read_results(dask.path)}
    assert dask.failed == 0 and a == d


def test_bad_sweep_input():
    with pytest.raises(UnknownNameError, match="metric"):
        run_sweep(POINTS, "/tmp/never.csv", metrics=("wobble",), progress=False)
    with pytest.raises(ParameterError, match="workers"):
        run_sweep(POINTS, "/tmp/never.csv", workers=0, progress=False)
    with pytest.raises(ParameterError, match="executor"):
        run_sweep(POINTS[:1], "/tmp/never-exec.csv", base=BASE, executor="mpi", progress=False)


@pytest.mark.slow
def test_at_a_target_a_family_shares_its_first_points_error_model(tmp_path, monkeypatch):
    """Points differing only in load sizes (amplitude here) start from the first one's error
    model: the others are handed the (a, b) the first ran with (the row says 'shared error
    model'; the first ran its pilots, and so does every point without sharing); another
    actuator is another family. A target on the trajectory (peak_power is no metric a target
    can be put on, mjeap.simulation.metric_accuracy): a target on the metrics alone forms no
    family (no pilots to share). Each point's estimated error is measured on it and
    meets the target, and its peak-to-peak agrees with pilots per point within what the two
    targets allow."""
    import mjeap.studies.sweep.runner as sw
    from mjeap.studies.sweep.runner import _family
    base = {"actuator": "pedot-micro", "orientation": "horizontal", "waveform": "sine", "frequency": 10.0,
            "duration": 0.2, "accuracy": 1e-3}
    pts = [{"amplitude": a} for a in (0.5, 1.0, 1.5)]
    metrics = ("peak_to_peak", "peak_power", "estimated_error")
    jobs = [(p, metrics, base, None) for p in pts]
    assert len({_family(j) for j in jobs}) == 1
    assert _family(({"actuator": "ppy-mutlu", "amplitude": 1.0}, metrics, base, None)) != _family(jobs[0])
    assert _family(({"amplitude": 1.0}, metrics, {**base, "accuracy": None}, None)) is None
    assert _family(({"amplitude": 1.0}, ("peak_to_peak", "first_frequency", "estimated_error"), base, None)) is None
    calls, evaluate = [], sw.evaluate

    def spy(point, metrics, base, rrd_dir, error_model=None):
        row = evaluate(point, metrics, base, rrd_dir, error_model)
        calls.append((point["amplitude"], error_model, row.get("_error_model")))
        return row
    monkeypatch.setattr(sw, "evaluate", spy)
    rows = {}
    for share in (True, False):
        path = tmp_path / f"share{share}.csv"
        run_sweep(pts, path, metrics=metrics, base=base, executor="serial", share_error_models=share)
        rows[share] = read_results(path)
    lead = calls[0]
    assert lead[1] is None and lead[2] is not None
    assert [c[1] for c in calls[1:3]] == [lead[2], lead[2]]          # the others got the lead's (a, b)
    assert all(c[1] is None for c in calls[3:])                         # pilots per point
    shared = [r["estimated_error"] for r in rows[True]]
    assert sum("shared error model" in e for e in shared) == 2 and "pilots" in shared[0]
    assert all("pilots" in r["estimated_error"] for r in rows[False])
    for a, b in zip(rows[True], rows[False]):
        assert float(a["estimated_error"].split()[0]) <= 1e-3 and float(b["estimated_error"].split()[0]) <= 1e-3
        # each run's curvature within 1e-3 of the swing: each peak-to-peak within 2 x that, the two within 4 x
        assert float(a["peak_to_peak"]) == pytest.approx(float(b["peak_to_peak"]), rel=4 * 1e-3)
