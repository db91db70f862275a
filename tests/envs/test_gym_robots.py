"""The robots as Gymnasium environments (mjeap.envs.hamr_walk, mjeap.envs.gripper_grasp) and
Gymnasium's own checker on every id under mjeap/: the open-loop trot through the environment
against the walker's own run, the grasp against the gripper's lift threshold, seeded resets
with contacts, vector envs, refusals. MuJoCo 3.17 and 4.x."""
import warnings

import numpy as np
import pytest

gymnasium = pytest.importorskip("gymnasium")

from gymnasium.utils.env_checker import check_env  # noqa: E402

import mjeap  # noqa: E402,F401  (registers the ids)
from mjeap import ParameterError  # noqa: E402
from mjeap.envs.registration import ENVS  # noqa: E402
from mjeap.envs.rendering import render_modes  # noqa: E402
from mjeap.envs.hamr_walk import HamrWalkEnv, leg_design, run_trot, trot_policy  # noqa: E402
from mjeap.envs.gripper_grasp import GripperGraspEnv  # noqa: E402

#: short episodes for the checks (the ids' defaults are for learning)
SHORT = {"mjeap/CurvatureTracking-v0": dict(time_limit=0.1),
         "mjeap/HamrWalk-v0": dict(time_limit=0.02),
         "mjeap/GripperGrasp-v0": dict(lift_at=0.05, hold=0.05)}
#: check_env's advice on the spaces, not a failure: infinite observation bounds, volts not [-1, 1]
ADVICE = ("infinity", "symmetric and normalized")
#: the quick trot: 40 Hz, full swing, 20 V lift (upright), 2 cycles of ramp, 1 measured (measured +0.8 %)
QUICK = (40.0, 20.0, 0.05, 0.025)


def test_every_mjeap_id_is_registered_by_import_and_listed():
    assert set(ENVS) == set(SHORT)
    assert {i for i in gymnasium.registry if i.startswith("mjeap/")} == set(ENVS)


@pytest.mark.parametrize("env_id", sorted(ENVS))
def test_check_env_passes_with_its_defaults(env_id):
    """gymnasium.utils.env_checker.check_env with its defaults (render check included: the env
    declares only the modes that work here, none under MUJOCO_GL=disable), through
    gymnasium.make; its only warnings are its advice on the spaces."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        env = gymnasium.make(env_id, **SHORT[env_id])
        assert env.unwrapped.metadata["render_modes"] == list(render_modes())
        check_env(env.unwrapped)
        env.close()
    assert [str(w.message) for w in caught if not any(a in str(w.message) for a in ADVICE)] == []


def test_render_modes_follow_the_process(monkeypatch):
    """No GL mode under MUJOCO_GL=disable (mjeap's default); no 'human' without a display on
    Linux (the probe itself, uncached)."""
    probe = render_modes.__wrapped__
    monkeypatch.setenv("MUJOCO_GL", "disable")
    assert probe() == ()
    monkeypatch.setenv("MUJOCO_GL", "egl")
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    monkeypatch.setattr("sys.platform", "linux")
    assert "human" not in probe()


def _trajectory(env, actions, seed):
    """Observations and rewards of a seeded episode, and the most contacts seen at a step's end."""
    obs, _ = env.reset(seed=seed)
    out, contacts = [np.append(obs, 0.0)], 0
    for a in actions:
        obs, r, te, tr, info = env.step(a)
        out.append(np.append(obs, r))
        contacts = max(contacts, env.system.data.ncon)
        assert not te, info
    return np.array(out), contacts


def test_hamr_walk_reset_is_deterministic_with_contacts():
    """A seeded reset after a trot with the feet on the ground replays the same trajectory
    bit for bit (contacts and warm starts cleared); the feet touch in it."""
    env = HamrWalkEnv(time_limit=0.05)
    policy = trot_policy(env, 40.0)
    actions = [policy(k * env.control_timestep) for k in range(24)]
    a, contacts = _trajectory(env, actions, 3)
    assert contacts >= 2                                               # feet on the ground
    _trajectory(env, actions[:8][::-1], 4)                             # another history between
    np.testing.assert_array_equal(a, _trajectory(env, actions, 3)[0])
    assert np.ptp(a[:, 0]) > 0                                         # it moved


def test_gripper_reset_is_deterministic_with_contacts():
    env = GripperGraspEnv(lift_at=0.05, hold=0.05)
    actions = [np.array([3.0, 2.5], np.float32)] * 6
    a, contacts = _trajectory(env, actions, 1)
    assert contacts > 0                                                # the bead on the table
    np.testing.assert_array_equal(a, _trajectory(env, actions, 1)[0])


def test_hamr_walk_spaces_and_standing():
    """Eight voltages in the drives' 0..200 V; at rest voltages it stands: no roll-over, no
    speed, the upright term of the reward."""
    env = gymnasium.make("mjeap/HamrWalk-v0", time_limit=0.01)
    e = env.unwrapped
    assert env.action_space.shape == (8,) and env.action_space.low.min() == 0.0 and env.action_space.high.max() == 200.0
    assert e.actuator_names[:2] == ["FL_swing", "FL_lift"] and len(e.observation_names) == env.observation_space.shape[0]
    env.reset(seed=0)
    rest = np.full(8, 100.0, np.float32)
    for _ in range(5):
        obs, r, te, tr, info = env.step(rest)
    assert not te and e.tilt_deg() < 1.0
    assert r == pytest.approx(e.upright_weight, abs=0.05)
    env.close()


def test_hamr_walk_terminates_on_roll_over():
    """A tilt beyond rollover_deg ends the episode, saying so (here a 0.5 deg limit that the
    trot's first cycles pass)."""
    env = HamrWalkEnv(time_limit=0.1, rollover_deg=0.5)
    policy = trot_policy(env, 40.0)
    env.reset(seed=0)
    for _ in range(200):
        _, _, te, tr, info = env.step(policy(env.time))
        if te or tr:
            break
    assert te and "rolled over" in info["ended"] and env.tilt_deg() > 0.5


def test_make_vec_sync():
    for env_id, kw in (("mjeap/HamrWalk-v0", SHORT["mjeap/HamrWalk-v0"]),
                       ("mjeap/GripperGrasp-v0", SHORT["mjeap/GripperGrasp-v0"])):
        venv = gymnasium.make_vec(env_id, num_envs=2, vectorization_mode="sync", **kw)
        obs, info = venv.reset(seed=5)
        n = venv.single_action_space.shape[0]
        assert obs.shape == (2,) + venv.single_observation_space.shape
        obs, reward, te, tr, info = venv.step(np.tile(venv.single_action_space.high, (2, 1)))
        assert reward.shape == (2,) and not te.any() and n in (2, 8)
        venv.close()


def test_refusals_name_the_parameter():
    with pytest.raises(ParameterError, match="control_interval"):
        HamrWalkEnv(control_interval=1e-9)
    with pytest.raises(ParameterError, match="rollover_deg"):
        HamrWalkEnv(rollover_deg=0.0)
    env = GripperGraspEnv(lift_at=0.05, hold=0.05)
    env.reset()
    with pytest.raises(ParameterError, match="action"):
        env.step(np.array([1.0]))
    with pytest.raises(ParameterError, match="options"):
        env.reset(options={"x": 1})
    if "rgb_array" not in render_modes():
        with pytest.raises(ParameterError, match="render_mode"):
            GripperGraspEnv(render_mode="rgb_array")


@pytest.mark.slow
@pytest.mark.parametrize("frequency", [10.0, 20.0, 40.0, 65.0])
def test_the_learning_model_trots_at_the_default_models_speed(frequency):
    """HamrWalk-v0's model (2 segments per actuator at a 100 us step sized for the loaded
    system, about real time on one core) against the default walker model (4 segments, the
    actuators' own 4.51 us step), the robot's trot drive (trot_drive) through the environment
    (its waveforms held over 0.5 ms control steps) and in the walker's own run, the same
    windows (0.3 s settling, 0.4 s measured: at 40 Hz the issue's 0.2 s after 0.1 s still
    carries the start, -6 %): within 5 % (measured -0.1, +0.1, -2.3, ... %), both upright."""
    from mjeap.robots.hamr_walk import build, trot_drive, walk, walk_metrics
    env = gymnasium.make("mjeap/HamrWalk-v0", time_limit=1.0)
    got = run_trot(env, frequency, settle=0.3, measure=0.4)
    s = build(d=leg_design())
    ref = walk_metrics(walk(s, frequency, settle=0.3, measure=0.4, **trot_drive(s, frequency)))
    assert ref["upright"] and not got["ended"] and got["max_tilt_deg"] < 30.0
    assert got["speed_m_s"] == pytest.approx(ref["speed_m_s"], rel=0.05)


def test_trot_through_the_env_quick():
    """The environment's stepping on the default model (4 segments, the actuators' own step),
    short (about 4 s here, kept in the quick loop as the baseline's check): QUICK's trot (the
    ramp, then one cycle measured) through the environment (the waveforms held over 0.5 ms
    control steps) and the walker's own run (every step): within 10 %."""
    from mjeap.robots.hamr_walk import build, walk, walk_metrics
    f, lift, settle, measure = QUICK
    env = HamrWalkEnv(time_limit=settle + measure + 0.01, segments=4, timestep=None)
    got = run_trot(env, f, amplitude=100.0, lift_amplitude=lift, settle=settle, measure=measure)
    ref = walk_metrics(walk(build(d=leg_design()), f, settle=settle, measure=measure, lift_amplitude=lift))
    assert not got["ended"] and ref["speed_m_s"] > 0.01
    assert got["speed_m_s"] == pytest.approx(ref["speed_m_s"], rel=0.10)


@pytest.mark.slow
def test_grasp_follows_the_grippers_lift_threshold():
    """Held fingers lift the bead at 1 s only above the gripper's measured 0.884 V
    (docs/robots/gripper.md): 1.0 V holds it to the top (reward 1 at the end, not
    terminated); 0.75 V drops it (terminated, 'dropped')."""
    env = gymnasium.make("mjeap/GripperGrasp-v0", hold=0.1)
    for volts, held in ((1.0, True), (0.75, False)):
        env.reset(seed=0)
        while True:
            _, r, te, tr, info = env.step(np.array([volts, volts], np.float32))
            if te or tr:
                break
        assert (not te) == held, (volts, info)
        if held:
            assert tr and r == pytest.approx(1.0, abs=0.02)
        else:
            assert "dropped" in info["ended"]
    env.close()
