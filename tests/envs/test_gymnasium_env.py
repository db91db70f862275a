"""The Gymnasium environment (mjeap.envs.gymnasium_env): Gymnasium's own checks, seeding, vector
envs, divergence, parameter refusals, physics against eq. (8), rendering. MuJoCo 3.17 and 4.x."""
import subprocess
import sys
import warnings

import numpy as np
import pytest

gymnasium = pytest.importorskip("gymnasium")

from gymnasium.utils.env_checker import check_env  # noqa: E402

import mjeap.envs.gymnasium_env as ge  # noqa: E402
from mjeap import MjeapError, ParameterError, Scene, rollout  # noqa: E402
from mjeap.drives import DRIVES, Drive  # noqa: E402
from mjeap.envs.gymnasium_env import ENV_ID, CurvatureTrackingEnv  # noqa: E402
from mjeap.envs.registration import ENVS, register_envs  # noqa: E402
from mjeap.envs.rendering import render_modes  # noqa: E402

RANDOMISED = dict(payload_mass_range=(1e-6, 12.6e-6), initial_curvature_range=(-20.0, 20.0), time_limit=0.2)


@pytest.fixture(scope="module")
def gl():
    """Whether mujoco.Renderer works here (MUJOCO_GL=egl or osmesa; CI runs with 'disable')."""
    return "rgb_array" in render_modes()


@pytest.mark.parametrize("kw", [
    dict(actuator="pedot-micro", **RANDOMISED),
    dict(actuator="pzt-hamr-small", orientation="horizontal", payload=None, time_limit=2e-3, control_interval=1e-4,
         drive_params={"bias": 100.0}, reference=lambda t: 0.0)], ids=["pedot-micro", "pzt-hamr-small"])
def test_gymnasium_check_env_passes(kw):
    """gymnasium's env_checker with its defaults on the registered env (an ionic and a piezo
    drive; the render modes declared are those that work here); its only warnings are its
    advice on the spaces (infinite observation bounds, an action in volts rather than [-1, 1])."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        env = gymnasium.make(ENV_ID, **kw)
        check_env(env.unwrapped)
    advice = ("infinity", "symmetric and normalized")
    assert [str(w.message) for w in caught if not any(a in str(w.message) for a in advice)] == []
    env.close()


def test_seeded_reset_reproduces_episode_and_trajectory():
    """Same seed: the same draw, first observation and trajectory for the same actions; a
    new seed draws another episode. The draw is the one in the model (payload) and state."""
    a, b = CurvatureTrackingEnv(**RANDOMISED), CurvatureTrackingEnv(**RANDOMISED)
    actions = np.random.default_rng(0).uniform(-3, 3, (12, 1)).astype(np.float32)

    def run(env, seed):
        obs, info = env.reset(seed=seed)
        out = [obs]
        for u in actions:
            obs, r, te, tr, info = env.step(u)
            out.append({**obs, "reward": np.array([r])})
        return info["episode"], out

    ep_a, traj_a = run(a, 7)
    run(a, 8)                                        # the seed, not the history, decides
    ep_b, traj_b = run(b, 7)
    assert ep_a == ep_b
    for x, y in zip(traj_a, traj_b):
        for k in x:
            np.testing.assert_array_equal(x[k], y[k])
    ep_c, traj_c = run(b, 8)
    assert ep_c != ep_a and not np.array_equal(traj_c[0]["tip_curvature"], traj_a[0]["tip_curvature"])
    sc = b.scene
    assert b.scene.model.body_mass[sc.payload_id] * sc.units.mass == pytest.approx(ep_c["payload_mass_kg"])
    assert traj_c[0]["tip_curvature"][0] == pytest.approx(ep_c["initial_curvature_per_m"], rel=1e-5)


def test_make_and_make_vec_after_import():
    """gymnasium.make and a synchronous vector env of 2 from the registered id."""
    env = gymnasium.make(ENV_ID, actuator="pedot-micro", time_limit=0.1)
    assert isinstance(env.unwrapped, CurvatureTrackingEnv)
    env.close()
    venv = gymnasium.make_vec(ENV_ID, num_envs=2, vectorization_mode="sync", **RANDOMISED)
    obs, info = venv.reset(seed=3)
    assert obs["tip_curvature"].shape == (2, 1) and obs["drive_state"].shape[0] == 2
    assert obs["tip_curvature"][0, 0] != obs["tip_curvature"][1, 0]      # seeds 3 and 4
    obs, reward, terminated, truncated, info = venv.step(np.array([[1.0], [-1.0]], np.float32))
    assert reward.shape == (2,) and not terminated.any() and not truncated.any()
    assert np.all((0 <= reward) & (reward <= 1))
    venv.close()


def test_import_mjeap_registers_every_id_cheaply():
    """``import mjeap`` registers every id under mjeap/ as an entry-point string: no
    environment module, robot or dm_control is imported by it. In a fresh interpreter."""
    code = ("import sys, gymnasium, mjeap; "
            f"ids = sorted(i for i in gymnasium.registry if i.startswith('mjeap/')); assert ids == {sorted(ENVS)}, ids; "
            "bad = [m for m in sys.modules if m.startswith(('mjeap.envs.', 'mjeap.robots', 'dm_control', 'dm_env')) "
            "and m not in ('mjeap.envs.registration',)]; assert not bad, bad")
    subprocess.run([sys.executable, "-c", code], check=True, timeout=120)


@pytest.mark.slow
def test_module_colon_id_imports_mjeap():
    """Gymnasium 1.x's ``module:id`` form: ``gymnasium.make("mjeap:mjeap/CurvatureTracking-v0")``
    without importing mjeap first. In a fresh interpreter."""
    code = ("import gymnasium; env = gymnasium.make('mjeap:mjeap/CurvatureTracking-v0', time_limit=0.1); "
            "env.reset(seed=0); env.step(env.action_space.sample()); env.close()")
    subprocess.run([sys.executable, "-c", code], check=True, timeout=120)


def test_the_gymnasium_entry_point():
    """The package's ``gymnasium.envs`` entry point (Gymnasium 0.26-0.29's plugins) names
    register_envs, in pyproject.toml and, where the installed mjeap declares it, in its
    metadata; calling it again registers nothing new."""
    import tomllib
    from importlib import metadata
    from pathlib import Path
    project = tomllib.loads((Path(__file__).resolve().parents[2] / "pyproject.toml").read_text())["project"]
    assert project["entry-points"]["gymnasium.envs"] == {"mjeap": "mjeap.envs.registration:register_envs"}
    installed = [e for e in metadata.entry_points(group="gymnasium.envs") if e.name == "mjeap"]
    for e in installed:
        assert e.load() is register_envs
    assert register_envs() == []


def test_import_needs_no_dm_control_and_registers_once():
    """The module imports no dm_control (whose Physics fails on MuJoCo 4); a re-import does
    not register the id again (no warning). In a fresh interpreter."""
    code = ("import importlib, sys, warnings, mjeap.envs.gymnasium_env as ge; "
            "bad = [m for m in sys.modules if m.split('.')[0] in ('dm_control', 'dm_env')]; "
            "assert not bad, bad; "
            "warnings.simplefilter('error'); importlib.reload(ge)")
    subprocess.run([sys.executable, "-c", code], check=True, timeout=60)


@pytest.mark.filterwarnings("ignore:MuJoCo:RuntimeWarning")
@pytest.mark.parametrize("moment, cause", [(float("nan"), "applied a non-finite moment"),
                                           (1e30, "diverged by step")])
def test_divergence_terminates_with_the_cause(moment, cause):
    """A drive that blows the beam up 20 ms in: terminated (not truncated) on that step,
    the cause and MuJoCo's warning in info, reward 0, the last finite observation."""

    class Exploding(Drive):
        name = "test-gym-exploding"

        def step(self, voltage, dt):
            self.part.set_internal_moments(moment if self.scene.time > 0.02 else 0.0)

    DRIVES[Exploding.name] = Exploding
    try:
        env = CurvatureTrackingEnv(drive=Exploding.name, time_limit=1.0)
    finally:
        DRIVES.pop(Exploding.name)
    env.reset(seed=0)
    for n in range(1, 10):
        obs, reward, terminated, truncated, info = env.step(np.array([1.0], np.float32))
        if terminated:
            break
    assert terminated and not truncated and n == 3 and reward == 0.0
    assert cause in info["divergence"] and "mjWARN_BADQACC" in info["divergence"]
    assert obs in env.observation_space


def test_bad_parameters_refused_before_any_work(monkeypatch):
    """Each refusal names the parameter and its range, before a scene is built; those that
    need the scene's timestep (control_interval) before any step."""
    def no_scene(*a, **kw):
        raise AssertionError("a scene was built before the parameters were checked")
    monkeypatch.setattr(ge, "Scene", no_scene)
    L = 6e-3
    for kw, name, accepted in [
            (dict(initial_curvature_range=(0.0, 2000.0)), "initial_curvature_range", f"{2 * np.pi / L:.6g}"),
            (dict(initial_curvature_range=(5.0, -5.0)), "initial_curvature_range", "low <= high"),
            (dict(payload_mass_range=(2e-6, 1e-6)), "payload_mass_range", "0 < low <= high"),
            (dict(payload=None, payload_mass_range=(1e-6, 2e-6)), "payload_mass_range", "without a payload"),
            (dict(reward_margin=0.0), "reward_margin", "> 0"),
            (dict(time_limit=-1.0), "time_limit", "> 0"),
            (dict(control_interval=float("nan")), "control_interval", "> 0"),
            (dict(render_mode="bogus"), "render_mode", "in this process"),
            (dict(width=0), "width", "[1, 4096]"),
            (dict(reference=50.0), "reference", "callable")]:
        with pytest.raises(ParameterError, match=name) as e:
            CurvatureTrackingEnv(**kw)
        assert e.value.name == name and accepted in e.value.accepted
    with pytest.raises(ParameterError, match="initial_curvature_range"):
        gymnasium.make(ENV_ID, initial_curvature_range=(0.0, 2000.0))
    monkeypatch.undo()
    for kw in (dict(control_interval=1e-9), dict(control_interval=0.5, time_limit=0.1)):
        with pytest.raises(ParameterError, match="control_interval"):
            CurvatureTrackingEnv(**kw)
    env = CurvatureTrackingEnv(time_limit=0.1)
    with pytest.raises(ParameterError, match="options"):
        env.reset(seed=0, options={"initial_curvature": 5.0})
    env.reset(seed=0)
    with pytest.raises(ParameterError, match="action"):
        env.step(np.array([1.0, 2.0], np.float32))          # two values for one actuator: refused, not cut
    with pytest.warns(UserWarning, match="clipped"):
        obs, r, te, tr, info = env.step(np.array([10.0], np.float32))
    assert info["voltage_V"] == 3.0 and info["saturated_steps"] == 1


@pytest.mark.slow
def test_held_voltage_follows_rollout_and_eq8():
    """1 V held for 20 s on the unloaded beam lying flat. Consistency: the env's trajectory
    is mjeap.rollout's on the same model (both step the drive in lockstep). Independent
    reference: Dadras et al. 2021's eq. (8), K/V = 63 (s + 0.52) / ((s + 0.3)(s + 1.8)), whose step
    response in closed form is G0 + A exp(-0.3 t) + B exp(-1.8 t) with the steady gain
    G0 = 63 x 0.52 / (0.3 x 1.8) = 60.67 1/m per V: within 1e-4 of G0 all along, and at
    20 s within 0.2 % of G0 itself (the slow pole has decayed to 0.08 1/m)."""
    env = CurvatureTrackingEnv(orientation="horizontal", payload=None, control_interval=0.5, time_limit=20.0)
    obs, _ = env.reset(seed=0)
    t, k = [0.0], [obs["tip_curvature"][0]]
    done = False
    while not done:
        obs, _, terminated, truncated, info = env.step(np.array([1.0], np.float32))
        t.append(info["time_s"]), k.append(obs["tip_curvature"][0])
        done = terminated or truncated
    t, k = np.array(t), np.array(k)
    assert truncated and not terminated and t[-1] == pytest.approx(20.0, abs=env.control_timestep)
    # the same model through rollout, first 2 s (the trajectories agree step by step)
    r = rollout(Scene("pedot-micro", orientation="horizontal"), "step:1V", t[4], sample_interval=env.control_timestep,
                engine="loop")
    np.testing.assert_allclose(r.time, t[:5], atol=1e-9)
    np.testing.assert_allclose(r.tip_curvature, k[:5], rtol=1e-9, atol=1e-9)
    G0 = 63 * 0.52 / (0.3 * 1.8)
    A, B = 63 * (0.52 - 0.3) / (-0.3 * (1.8 - 0.3)), 63 * (0.52 - 1.8) / (-1.8 * (0.3 - 1.8))
    eq8 = G0 + A * np.exp(-0.3 * t) + B * np.exp(-1.8 * t)
    assert eq8[0] == pytest.approx(0.0, abs=1e-12)
    assert np.max(np.abs(k - eq8)) < 1e-4 * G0
    assert k[-1] == pytest.approx(G0, rel=2e-3)


def test_reward_is_the_dm_env_tasks():
    """Same Gaussian as dm_control's rewards.tolerance (the dm_env task's reward)."""
    rewards = pytest.importorskip("dm_control.utils.rewards")
    from mjeap.envs.tracking import tracking_reward
    for err in (0.0, 0.3, -2.0, 5.0, -17.0):
        ref = rewards.tolerance(err, bounds=(0.0, 0.0), margin=5.0, sigmoid="gaussian")
        assert tracking_reward(10.0 + err, 10.0, 5.0) == pytest.approx(float(ref), rel=1e-14, abs=1e-300)


def test_rgb_array_shows_the_beam(gl):
    """An (H, W, 3) uint8 image in which the beam (its blue colour) is seen, and seen to
    bend: bent to 150 1/m its pixels move; close() releases the renderer."""
    if not gl:
        pytest.skip("no OpenGL backend for mujoco.Renderer (set MUJOCO_GL=egl or osmesa)")
    images = []
    for kappa in (0.0, 150.0):
        env = CurvatureTrackingEnv(render_mode="rgb_array", width=320, height=240,
                                   initial_curvature_range=(kappa, kappa), time_limit=0.1)
        assert env.metadata["render_fps"] == pytest.approx(1 / env.control_timestep)
        env.reset(seed=0)
        images.append(env.render())
        env.close()
        env.close()
        with pytest.raises(MjeapError, match="close"):
            env.render()
    beams = []
    for img in images:
        assert img.shape == (240, 320, 3) and img.dtype == np.uint8
        blue = (img[..., 2].astype(int) - img[..., 0]) > 30
        assert blue.sum() > 100
        beams.append(np.argwhere(blue).mean(axis=0))
    assert np.linalg.norm(beams[1] - beams[0]) > 10          # pixels
    assert CurvatureTrackingEnv(time_limit=0.1).render() is None
