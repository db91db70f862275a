"""The dm_env environment (dm_control control.Environment + Task)."""
import numpy as np
import pytest
from absl.testing import absltest
from dm_env import test_utils

from mjeap import ParameterError, Payload, Scene, rollout
from mjeap.envs.environment import make_environment, run_episode
from mjeap.io.recording import read_recording

pytestmark = pytest.mark.dm_control  # dm_control's Physics: MuJoCo 3.x (mjeap.versions)


def short_env(**kw):
    kw.setdefault("time_limit", 0.2)
    return make_environment("pedot-micro", **kw)


class DmEnvConformance(test_utils.EnvironmentTestMixin, absltest.TestCase):
    """dm_env's own conformance checks (specs, step types, rewards, discounts)."""

    def make_object_under_test(self):
        return short_env(payload_mass_range=(1e-6, 12.6e-6), initial_curvature_range=(-20.0, 20.0), seed=1)


class PiezoConformance(DmEnvConformance):
    def make_object_under_test(self):
        return make_environment("pzt-hamr-small", orientation="horizontal", payload=None, time_limit=2e-3,
                                control_interval=1e-4, drive_params={"bias": 100.0}, seed=2,
                                reference=lambda t: 0.0)


def test_env_steps_the_drive_exactly_like_rollout():
    """The same 1 V step through the environment and through mjeap.rollout: identical
    trajectories (both step the drive once per MuJoCo step)."""
    env = short_env(time_limit=1.0, payload=Payload(12.6e-6, 6.27e-3))
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


def test_randomisation_is_seeded_and_changes_the_model():
    kw = dict(payload_mass_range=(1e-6, 12.6e-6), initial_curvature_range=(-20.0, 20.0))
    a, b = short_env(seed=5, **kw), short_env(seed=5, **kw)
    a.reset(), b.reset()
    assert a.task.episode == b.task.episode
    first = dict(a.task.episode)
    ts = a.reset()
    assert a.task.episode != first
    sc = a.physics.scene
    assert a.physics.model.body_mass[sc.payload_id] * sc.units.mass == pytest.approx(a.task.episode["payload_mass_kg"])
    # the chain starts as a uniform arc; the arc through clamp and tip reads it back to ~2e-6
    assert ts.observation["tip_curvature"][0] == pytest.approx(a.task.episode["initial_curvature_per_m"], rel=1e-5)


def test_out_of_range_action_is_clipped_with_a_warning():
    env = short_env()
    env.reset()
    with pytest.warns(UserWarning, match="clipped"):
        env.step(np.array([10.0]))
    assert env.task.saturated_steps == 1 and env.physics.voltage == 3.0


def test_bad_ranges_name_the_parameter():
    with pytest.raises(ParameterError, match="payload_mass_range"):
        short_env(payload_mass_range=(2e-6, 1e-6))
    with pytest.raises(ParameterError, match="payload_mass_range"):
        short_env(payload=None, payload_mass_range=(1e-6, 2e-6)).reset()
    with pytest.raises(ParameterError, match="control_interval"):
        short_env(control_interval=1e-9)


def test_episode_recording(tmp_path):
    env = short_env(seed=0)
    r = run_episode(env, lambda ts: np.array([0.5]), rrd=tmp_path / "ep.rrd")
    # the first observation, then one per control step until time_limit is reached
    steps = int(np.ceil(0.2 / env.control_timestep() - 1e-9))
    assert r.time.size == steps + 1 and np.isfinite(r.signals["reward (-)"][1:]).all()
    ents = read_recording(tmp_path / "ep.rrd")
    assert "/beam/centreline" in ents and "/plots/drive/reward" in ents


if __name__ == "__main__":
    absltest.main()


def test_an_episode_reset_keeps_the_tip_loads():
    """Physics.reset clears xfrc_applied; the scene's tip loads persist across episodes (as
    Scene.reset keeps them), so the next episode is the same question."""
    env = short_env(time_limit=0.01)
    sc = env.physics.scene
    sc.set_tip_force(1e-7)
    tip = sc.part.tip_load_id
    before = env.physics.data.xfrc_applied[tip].copy()
    assert before.any()
    env.reset()
    np.testing.assert_array_equal(env.physics.data.xfrc_applied[tip], before)
