"""The dm_env environments (mjeap.make_environment): the task on dm_env's interface (backend
'dm_env', any MuJoCo) and on dm_control's control.Environment (backend 'dm_control', MuJoCo
3.x: marked ``dm_control``, skipped on 4.x with the reason); dm_env's conformance checks on
both, the two backends' trajectories against each other, the documented example verbatim."""
import re
from pathlib import Path

import numpy as np
import pytest
from absl.testing import absltest
from dm_env import test_utils

import mjeap
from mjeap import ParameterError, Payload, Scene, rollout
from mjeap.envs.dm_tracking import TrackingEnvironment
from mjeap.envs.environment import make_environment, run_episode
from mjeap.io.recording import read_recording
from mjeap.versions import dm_control_problem

ROOT = Path(__file__).resolve().parents[2]
#: every test below runs on each backend: dm_env everywhere, dm_control where its Physics loads
BACKENDS = ["dm_env", pytest.param("dm_control", marks=pytest.mark.dm_control)]


@pytest.fixture(params=BACKENDS)
def backend(request):
    return request.param


def short_env(backend="dm_env", **kw):
    kw.setdefault("time_limit", 0.2)
    return make_environment("pedot-micro", backend=backend, **kw)


def piezo_env(backend):
    return make_environment("pzt-hamr-small", orientation="horizontal", payload=None, time_limit=2e-3,
                            control_interval=1e-4, drive_params={"bias": 100.0}, seed=2,
                            reference=lambda t: 0.0, backend=backend)


class DmEnvConformance(test_utils.EnvironmentTestMixin, absltest.TestCase):
    """dm_env's own conformance checks (specs, step types, rewards, discounts): PEDOT, dm_env backend."""
    backend = "dm_env"

    def make_object_under_test(self):
        return short_env(self.backend, payload_mass_range=(1e-6, 12.6e-6), initial_curvature_range=(-20.0, 20.0),
                         seed=1)


class PiezoConformance(DmEnvConformance):
    """The same on a piezo bimorph (pzt-hamr-small), dm_env backend."""

    def make_object_under_test(self):
        return piezo_env(self.backend)


@pytest.mark.dm_control
class DmControlConformance(DmEnvConformance):
    backend = "dm_control"


@pytest.mark.dm_control
class DmControlPiezoConformance(PiezoConformance):
    backend = "dm_control"


def test_env_steps_the_drive_exactly_like_rollout(backend):
    """The same 1 V step through the environment and through mjeap.rollout: identical
    trajectories (both step the drive once per MuJoCo step)."""
    env = short_env(backend, time_limit=1.0, payload=Payload(12.6e-6, 6.27e-3))
    ts = env.reset()
    k_env, t_env = [ts.observation["tip_curvature"][0]], [env.physics.time()]
    while not ts.last():
        ts = env.step(np.array([1.0]))
        k_env.append(ts.observation["tip_curvature"][0])
        t_env.append(env.physics.time())
    sc = Scene("pedot-micro", orientation="up", payload=Payload(12.6e-6, 6.27e-3))
    r = rollout(sc, "step:1V", t_env[-1], sample_interval=env.control_timestep(), engine="loop")
    np.testing.assert_allclose(r.time, t_env, atol=1e-12)
    np.testing.assert_allclose(r.tip_curvature, k_env, rtol=1e-9, atol=1e-9)


def test_randomisation_is_seeded_and_changes_the_model(backend):
    kw = dict(payload_mass_range=(1e-6, 12.6e-6), initial_curvature_range=(-20.0, 20.0))
    a, b = short_env(backend, seed=5, **kw), short_env(backend, seed=5, **kw)
    a.reset(), b.reset()
    assert a.task.episode == b.task.episode
    first = dict(a.task.episode)
    ts = a.reset()
    assert a.task.episode != first
    sc = a.physics.scene
    assert a.physics.model.body_mass[sc.payload_id] * sc.units.mass == pytest.approx(a.task.episode["payload_mass_kg"])
    # the chain starts as a uniform arc; the arc through clamp and tip reads it back to ~2e-6
    assert ts.observation["tip_curvature"][0] == pytest.approx(a.task.episode["initial_curvature_per_m"], rel=1e-5)


def test_out_of_range_action_is_clipped_with_a_warning(backend):
    env = short_env(backend)
    env.reset()
    with pytest.warns(UserWarning, match="clipped"):
        env.step(np.array([10.0]))
    assert env.task.saturated_steps == 1 and env.physics.voltage == 3.0


def test_bad_ranges_name_the_parameter(backend):
    with pytest.raises(ParameterError, match="payload_mass_range"):
        short_env(backend, payload_mass_range=(2e-6, 1e-6))
    with pytest.raises(ParameterError, match="payload_mass_range"):
        short_env(backend, payload=None, payload_mass_range=(1e-6, 2e-6)).reset()
    with pytest.raises(ParameterError, match="control_interval"):
        short_env(backend, control_interval=1e-9)
    with pytest.raises(ParameterError, match="backend"):
        short_env("gym")


def test_episode_recording(tmp_path, backend):
    env = short_env(backend, seed=0)
    r = run_episode(env, lambda ts: np.array([0.5]), rrd=tmp_path / "ep.rrd")
    # the first observation, then one per control step until time_limit is reached
    steps = int(np.ceil(0.2 / env.control_timestep() - 1e-9))
    assert r.time.size == steps + 1 and np.isfinite(r.signals["reward (-)"][1:]).all()
    ents = read_recording(tmp_path / "ep.rrd")
    assert "/beam/centreline" in ents and "/plots/drive/reward" in ents


def test_an_episode_reset_keeps_the_tip_loads(backend):
    """Physics.reset clears xfrc_applied; the scene's tip loads persist across episodes (as
    Scene.reset keeps them), so the next episode is the same question."""
    env = short_env(backend, time_limit=0.01)
    sc = env.physics.scene
    sc.set_tip_force(1e-7)
    tip = sc.part.tip_load_id
    before = env.physics.data.xfrc_applied[tip].copy()
    assert before.any()
    env.reset()
    np.testing.assert_array_equal(env.physics.data.xfrc_applied[tip], before)


@pytest.mark.dm_control
@pytest.mark.parametrize("make", [lambda b: short_env(b, payload_mass_range=(1e-6, 12.6e-6),
                                                      initial_curvature_range=(-20.0, 20.0), seed=4),
                                  piezo_env], ids=["pedot-micro", "pzt-hamr-small"])
def test_both_backends_give_the_same_trajectory(make):
    """dm_control's control.Environment and the dm_env one: the same episode draws, time steps,
    observations and rewards, bit for bit, for the same seed and actions (two episodes)."""
    envs = [make("dm_control"), make("dm_env")]
    assert not isinstance(envs[0], TrackingEnvironment) and isinstance(envs[1], TrackingEnvironment)
    spec = envs[1].action_spec()
    actions = np.random.default_rng(0).uniform(float(spec.minimum), float(spec.maximum), 40)   # inside the safe range
    runs = []
    for env in envs:
        steps = []
        for _ in range(2):
            ts = env.reset()
            steps.append((ts, dict(env.task.episode)))
            for a in actions:
                if ts.last():
                    break
                ts = env.step(np.array([a]))
                steps.append((ts, None))
        runs.append(steps)
    assert len(runs[0]) == len(runs[1])
    for (ta, ea), (tb, eb) in zip(*runs):
        assert ta.step_type == tb.step_type and ta.reward == tb.reward and ta.discount == tb.discount and ea == eb
        for k in ta.observation:
            np.testing.assert_array_equal(ta.observation[k], tb.observation[k])


def test_a_100_step_episode_on_the_default_backend():
    """mjeap.make_environment's default: dm_control where its Physics loads, else (MuJoCo 4)
    the dm_env backend; 100 agent steps (about 10 ms each: whole MuJoCo steps), the last one
    LAST, every reward in [0, 1]."""
    dt = mjeap.make_environment("pedot-micro", time_limit=1.0).control_timestep()
    env = mjeap.make_environment("pedot-micro", time_limit=100 * dt, seed=0)
    assert isinstance(env, TrackingEnvironment) == bool(dm_control_problem())
    ts, n = env.reset(), 0
    assert ts.first()
    while not ts.last():
        ts = env.step(np.array([0.5]))
        n += 1
        assert 0.0 <= ts.reward <= 1.0
    assert n == 100 and env.physics.time() == pytest.approx(100 * dt)
    assert np.isfinite(ts.observation["tip_curvature"]).all()


def test_the_documented_example_runs_verbatim():
    """The dm_env example of docs/concepts/environments.md, as written (MuJoCo 3.17 and 4.x)."""
    page = (ROOT / "docs" / "concepts" / "environments.md").read_text()
    section = page.split("## dm_env", 1)[1]
    code = re.search(r"```python\n(.*?)```", section, flags=re.S).group(1)
    namespace = {}
    exec(compile(code, "environments.md", "exec"), namespace)
    assert namespace["ts"].last()
