"""Stopping a periodically driven run once its last period repeats the one before
(mjeap.simulation.periodic). The reference for the decision is the run itself continued to
its full duration: what the stopped run leaves out must repeat its last period within the
tolerance, and what it keeps must be the full run's own samples."""
import numpy as np
import pytest

from mjeap import ParameterError, Payload, Scene, rollout


def _pair(scene, wave, duration, tol, **kw):
    full = rollout(scene, wave, duration, progress=False, **kw)
    stopped = rollout(scene, wave, duration, progress=False, stop_when_periodic=tol, **kw)
    return full, stopped


@pytest.mark.parametrize("engine", ["loop", "native"])
def test_a_stopped_run_is_the_full_runs_start_and_its_rest_repeats_the_last_period(engine):
    s = Scene("pedot-micro", orientation="up", payload=Payload(15e-6, 6.27e-3), segments=8)
    tol, T = 2e-2, 2.0
    full, r = _pair(s, "square:1.5V@0.5Hz", 16.0, tol, sample_interval=0.01, engine=engine)
    assert "stopped_early" not in full.meta
    why = r.meta["stopped_early"]
    assert why.startswith("stopped at") and "periodic" in why
    t_stop = r.time[-1]
    assert 3 * T - 0.01 <= t_stop < 16.0 - T                  # at a boundary, periods before the end
    assert abs(t_stop / T - round(t_stop / T)) < 0.01
    n = len(r.time)
    assert np.array_equal(r.tip_curvature, full.tip_curvature[:n])   # the same run up to the stop
    assert r.meta["steps_run"] < full.meta["steps"]
    # the claim: every later period repeats the stopped run's last one within the tolerance
    last = r.time >= t_stop - T - 1e-9
    span = np.ptp(r.tip_curvature[last])
    for k in range(1, int((16.0 - t_stop) / T + 1e-9) + 1):
        later = np.interp(r.time[last] + k * T, full.time, full.tip_curvature)
        assert np.max(np.abs(later - r.tip_curvature[last])) <= tol * span, k
    # the scene is left where the run stopped
    assert s.time == pytest.approx(t_stop, abs=s.timestep)


@pytest.mark.slow
def test_a_run_still_relaxing_runs_on_until_its_drift_is_within_the_tolerance():
    """From a bent start (-300 1/m) the curvature relaxes on the mechanical pole, the
    zero-input term of Dadras et al. 2021's eq. (7): period to period it drifts by
    d = 300 exp(-p (t - T)) (1 - exp(-p T)) 1/m, shrinking by rho = exp(-p T) a period, against
    the swing of the sine's steady state, 2 x 0.5 V x |K(j w)| of eq. (8) (17.6 1/m). The stop
    must come at the first boundary (from the third) where d and all drift still to come,
    d rho / (1 - rho), are within the tolerance of the swing (the drive's own start transient,
    left out of this estimate, may add a period), and a run whose drift stays above it (1e-3:
    past 30 s) must run to its end."""
    k, z, p, a = 63.0, 0.52, 0.3, 1.8                     # eq. (8), Dadras et al. 2021
    T, w = 2.0, 2 * np.pi * 0.5
    swing = 2 * 0.5 * abs(k * (1j * w + z) / ((1j * w + p) * (1j * w + a)))

    def predicted(tol):
        t = np.arange(3, 30) * T
        rho = np.exp(-p * T)
        ok = 300 * np.exp(-p * (t - T)) * (1 - rho) * max(1.0, rho / (1 - rho)) <= tol * swing
        return t[ok][0] if ok.any() else np.inf

    s = Scene("pedot-micro", segments=8)
    kw = dict(sample_interval=0.01, initial_curvature=-300.0, progress=False)
    for tol in (1e-1, 1e-2):
        r = rollout(s, "sine:0.5V@0.5Hz", 30.0, stop_when_periodic=tol, **kw)
        assert "stopped_early" in r.meta
        assert predicted(tol) - 0.01 <= r.time[-1] <= predicted(tol) + T + 0.01, tol
    assert predicted(1e-3) > 30.0
    r = rollout(s, "sine:0.5V@0.5Hz", 30.0, stop_when_periodic=1e-3, **kw)
    assert "stopped_early" not in r.meta and r.time[-1] == pytest.approx(30.0, abs=0.01)


@pytest.mark.slow
def test_a_slow_creep_under_a_fast_drive_is_not_taken_for_periodic():
    """Relaxation at 0.3 1/s under a 5 Hz drive changes each period by little but adds up over
    many: wherever the run stops, every later period of the run continued to its end stays
    within the tolerance of the last one it kept (a stop on the last change alone came 15 x
    the tolerance off here)."""
    s = Scene("pedot-micro", segments=6)
    T, tol = 0.2, 0.1
    full, r = _pair(s, "sine:0.5V@5Hz", 30.0, tol, sample_interval=0.005, initial_curvature=-300.0)
    assert "stopped_early" in r.meta
    t_stop = r.time[-1]
    last = r.time >= t_stop - T - 1e-9
    span = np.ptp(r.tip_curvature[last])
    for k in range(1, int((30.0 - t_stop) / T)):
        later = np.interp(r.time[last] + k * T, full.time, full.tip_curvature)
        assert np.max(np.abs(later - r.tip_curvature[last])) <= tol * span, k


@pytest.mark.parametrize("wave,duration,kw,name", [
    ("step:1V", 10.0, {}, "stop_when_periodic"),
    ("chirp:1V@0.5Hz..2Hz", 10.0, {}, "stop_when_periodic"),
    ("chirp:1V@0.5Hz..0.5Hz,duration=12s", 24.0, {}, "stop_when_periodic"),   # ends at rest
    ("sine:1V@0.5Hz,delay=10s", 20.0, {}, "stop_when_periodic"),              # at rest until 10 s
    ("sine:1V@0.5Hz", 7.0, {}, "stop_when_periodic"),                      # under four periods
    ("sine:1V@0.5Hz", 10.0, {"sample_interval": 0.5}, "sample_interval"),   # 4 samples a period
    ("sine:1V@0.5Hz", 10.0, {"tol": 0.5}, "stop_when_periodic"),
    ("sine:1V@50Hz", 6.0, {"accuracy": 0.05}, "sample_interval"),           # the accuracy grid: 3 ms
])
def test_a_stop_that_cannot_work_is_refused_before_any_run(wave, duration, kw, name):
    s = Scene("pedot-micro", segments=4)
    kw = dict(kw)
    tol = kw.pop("tol", 1e-2)
    with pytest.raises(ParameterError, match=name):
        rollout(s, wave, duration, stop_when_periodic=tol, progress=False, **kw)
    assert s.time == 0.0


def test_a_sweep_row_says_where_its_point_stopped(tmp_path):
    from mjeap.studies.sweep import read_results, run_sweep
    base = dict(actuator="pedot-micro", segments=8, waveform="square", frequency=0.5, duration=16.0,
                stop_when_periodic=1e-2)
    run_sweep([dict(amplitude=1.0)], tmp_path / "s.csv", metrics=("returns", "stopped_early"), base=base,
              executor="serial", progress=False)
    (row,) = read_results(tmp_path / "s.csv")
    assert row["error"] == "" and row["stopped_early"].startswith("stopped at") and row["returns"] == "True"


def test_the_threaded_engine_stops_too():
    """An open-loop drive on mujoco.rollout (pvdf-60 driven at a third of its first
    frequency): the stopped run is the full run's start, the scene left at the stop."""
    s = Scene("pvdf-60", segments=6)
    T = 3.0 / float(s.choice.first_frequency)
    wave = f"sine:270V@{1.0 / T!r}Hz"
    full, r = _pair(s, wave, 100 * T, 1e-1, sample_interval=T / 40, engine="threaded")
    assert r.meta["engine"] == "threaded" and "stopped_early" in r.meta
    n = len(r.time)
    assert n < len(full.time) and np.array_equal(r.tip_curvature, full.tip_curvature[:n])
    assert s.time == pytest.approx(r.time[-1], abs=s.timestep)


def test_a_sweep_refuses_a_stop_its_points_cannot_make_once_before_any_point(tmp_path):
    from mjeap.studies.sweep import run_sweep
    base = dict(actuator="pedot-micro", segments=8, waveform="square", frequency=0.5, stop_when_periodic=1e-2)
    with pytest.raises(ParameterError, match="stop_when_periodic"):       # duration 2 / f: two periods
        run_sweep([dict(amplitude=1.0)], tmp_path / "s.csv", base=base, executor="serial", progress=False)
    assert not (tmp_path / "s.csv").exists()


def test_the_stop_reads_the_tip_not_the_payload_beyond_it():
    """A store whose tip moves periodically while its payload point creeps (slowly, within the
    shape tolerance, but its arc curvature far from periodic): the tip decides, so it stops."""
    from types import SimpleNamespace
    from mjeap.engines.frame import Decided
    from mjeap.simulation.periodic import PeriodicStop
    N, L, T, h = 4, 6e-3, 1.0, 1.0 / 40
    t = np.arange(0, 5 * T + h / 2, h)
    pts = np.zeros((len(t), N + 3, 3))
    pts[:, 1:N + 1, 0] = np.linspace(0, L, N + 2)[1:-1]
    pts[:, N + 1, 0], pts[:, N + 1, 1] = L, 1e-3 * np.sin(2 * np.pi * t / T)     # the tip: periodic
    pts[:, N + 2, 0], pts[:, N + 2, 1] = 1e-3, 1e-5 * t / T                        # the payload: creeping
    part = SimpleNamespace(layout=SimpleNamespace(segments=N), timestep=h)
    stop = PeriodicStop(T, 0.1, L)
    with pytest.raises(Decided):
        for n in range(2, len(t) + 1):
            stop(SimpleNamespace(n=n, t=t, part=part, clamp_frame=lambda idx: (pts[idx], None)))
