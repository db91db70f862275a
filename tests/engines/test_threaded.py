"""MuJoCo's native threaded rollout (mjeap.engines.threaded) against the lockstep loop.

The reference is the loop engine itself: both step the same model with the same moments,
so the trajectories, drive signals and final states must agree to round-off (1e-12 of
their range; the blocking-force history comes from scipy's lfilter, which may round
differently from the loop's in-place update)."""
import numpy as np
import pytest

from mjeap import Scene
from mjeap.errors import DivergenceError, ParameterError
from mjeap.simulation.rollout import rollout, rollout_batch
from mjeap.engines import threaded

OPEN_LOOP = [
    ("pzt-hamr-small", "hinge", "sine:20V@500Hz,offset=100V", 0.01, {}),
    ("pzt-robobee", "cable", "chirp:30V@50Hz..800Hz,offset=100V", 0.01, {}),
    ("ppy-trilayer", "hinge", "square:0.5V@0.5Hz", 3.0, {}),
    ("pvdf-60", "hinge", "square:600V@20Hz", 0.1, {"stiffening": False}),
]


def _assert_same(a, b, rtol=1e-12):
    assert len(a.time) == len(b.time)
    np.testing.assert_array_equal(a.time, b.time)
    np.testing.assert_array_equal(a.voltage, b.voltage)
    for key in ("tip_position", "tip_angle", "centreline"):
        x, y = getattr(a, key), getattr(b, key)
        np.testing.assert_allclose(x, y, rtol=0, atol=rtol * np.ptp(x) + 1e-300, err_msg=key)
    assert set(a.signals) == set(b.signals)
    for k in a.signals:
        x, y = a.signals[k], b.signals[k]
        np.testing.assert_allclose(x, y, rtol=0, atol=rtol * (np.ptp(x) + np.abs(x).max()) + 1e-300, err_msg=k)


@pytest.mark.parametrize("actuator,representation,voltage,duration,params", OPEN_LOOP)
def test_threaded_equals_loop(actuator, representation, voltage, duration, params):
    s = Scene(actuator, representation=representation)
    a = rollout(s, voltage, duration, drive_params=params, engine="loop", initial_curvature=5.0)
    qpos_loop, qfrc_loop = s.data.qpos.copy(), s.data.qfrc_applied.copy()
    b = rollout(s, voltage, duration, drive_params=params, engine="threaded", initial_curvature=5.0)
    assert a.meta["engine"] == "loop" and b.meta["engine"] == "threaded"
    _assert_same(a, b)
    # the scene is left as the loop leaves it: final state, last step's moments applied
    np.testing.assert_allclose(s.data.qpos, qpos_loop, rtol=0, atol=1e-12 * np.abs(qpos_loop).max())
    np.testing.assert_allclose(s.data.qfrc_applied, qfrc_loop, rtol=1e-12, atol=0)


@pytest.mark.cable
def test_auto_picks_threaded_only_where_it_applies():
    """auto: the drive compiled into the model where it has a native form (mjeap.drives.native),
    else threaded where it is open-loop, else the loop."""
    assert rollout(Scene("pzt-hamr-small"), "step:120V", 1e-3).meta["engine"] == "native"
    assert rollout(Scene("pzt-hamr-small", representation="cable"), "step:120V", 2e-4).meta["engine"] == "threaded"
    assert rollout(Scene("pedot-micro", representation="cable"), "step:1V", 0.01).meta["engine"] == "loop"


@pytest.mark.parametrize("actuator,params,words", [
    ("pedot-micro", {}, "back-relaxation"),
    ("pvdf-60", {"stiffening": True}, "stiffening"),
    ("ppy-trilayer", {"stiffness_table": [(0.0, 1.0), (1.0, 1.5)]}, "stiffness table")])
def test_closed_loop_drives_are_refused_with_the_reason(actuator, params, words):
    s = Scene(actuator)
    with pytest.raises(ParameterError, match=words):
        rollout(s, "step:0.5V", 0.01, drive_params=params, engine="threaded")


def test_controller_and_tip_load_are_refused():
    s = Scene("pzt-hamr-small")
    from mjeap.drives import make_drive
    drv = make_drive(None, s)
    assert "controller" in threaded.why_not(s, drv, controller=object())
    s.set_tip_force(1e-4)
    assert "tip load" in threaded.why_not(s, drv)
    with pytest.raises(ParameterError, match="engine"):
        rollout(s, "step:120V", 1e-3, engine="threaded")
    with pytest.raises(ParameterError, match="engine"):
        rollout(s, "step:120V", 1e-3, engine="no-such-engine")     # an unknown engine, refused by name


def test_batch_on_two_threads_equals_one_by_one():
    s = Scene("pzt-hamr-small")
    volts = [f"sine:{a}V@{f}Hz,offset=100V" for a, f in [(10, 200), (20, 700), (40, 1500)]]
    kappas = [0.0, 3.0, -3.0]
    batch = rollout_batch(s, volts, 0.005, initial_curvatures=kappas, nthread=2)
    for v, k0, b in zip(volts, kappas, batch):
        _assert_same(rollout(s, v, 0.005, initial_curvature=k0, engine="loop"), b)
        assert b.meta["nthread"] == 2 and b.meta["batch"] == 3


def test_chunked_rollout_equals_one_chunk(monkeypatch):
    s = Scene("pzt-hamr-small")
    a = rollout(s, "sine:20V@300Hz,offset=100V", 0.01, engine="threaded")
    monkeypatch.setattr(threaded, "CHUNK_BYTES", 8 * 333 * 60)   # chunks of a few hundred steps
    b = rollout(s, "sine:20V@300Hz,offset=100V", 0.01, engine="threaded")
    _assert_same(a, b, rtol=0)


def test_divergence_stops_at_the_same_step_with_the_reason():
    """A chain made 1e4 x stiffer than the timestep was chosen for diverges under
    implicitfast (explicit joint stiffness). Both engines stop with an error naming the
    step, the timestep and the drive, at the same step (mujoco.rollout stops on MuJoCo's
    warning and repeats its last state; the engine finds the step where time stops)."""
    import re
    steps = []
    for engine in ("loop", "threaded"):
        s = Scene("pzt-hamr-small")
        s.set_hinge_parameters(stiffness=s.hinge_stiffness() * 1e4)
        with pytest.raises(DivergenceError, match="diverged by step .*timestep .*piezo-bimorph") as err:
            rollout(s, "step:150V", 0.005, engine=engine)
        steps.append(int(re.search(r"by step (\d+)", str(err.value)).group(1)))
    assert steps[0] == steps[1]


@pytest.mark.parametrize("engine", ["threaded", "native"])
def test_pipelined_chunks_change_nothing(monkeypatch, engine):
    """The pipeline (the next chunk rolls while this one's samples are taken) hands each
    chunk's last state to the next: one chunk or many, with samples on chunk edges and off
    them, the results are the same to the bit."""
    s = Scene("ppy-trilayer")
    waves, k0 = ["square:0.5V@0.5Hz", "sine:0.3V@1Hz"], [0.0, 20.0]
    kw = dict(initial_curvatures=k0, nthread=2, engine=engine)
    monkeypatch.setattr(threaded, "PIPELINE_MIN_STEPS", 1)
    monkeypatch.setattr(threaded, "PIPELINE_CHUNKS", 1)
    one = rollout_batch(s, waves, 2.0, **kw)
    for chunks in (7, 64):
        monkeypatch.setattr(threaded, "PIPELINE_CHUNKS", chunks)
        for a, b in zip(one, rollout_batch(s, waves, 2.0, **kw)):
            _assert_same(a, b, rtol=0.0)
