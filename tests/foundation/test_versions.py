"""MuJoCo 3.17 and 4.x (mjeap.versions): what each offers, and clear refusals where one
lacks what the other has."""
import mujoco
import pytest

from mjeap import Scene, rollout
from mjeap.errors import MjeapError, ParameterError
from mjeap.versions import MUJOCO_VERSION, cable_available, dm_control_problem

on_4 = pytest.mark.skipif(cable_available(), reason="MuJoCo 3.x: the cable and dm_control run here")


def test_every_result_names_the_mujoco_it_ran_on():
    r = rollout(Scene("pedot-micro", segments=6), "step:1V", 0.005)
    assert r.meta["mujoco"] == mujoco.__version__ == MUJOCO_VERSION
    from mjeap.io.recording import _meta_markdown
    assert f"| mujoco | {mujoco.__version__} |" in _meta_markdown(r.meta)


def test_seed_000_heaviest_run_is_the_same_on_every_version():
    """The hinge chain gives bit-identical trajectories on 3.17 and 4.0 (measured): this
    number was printed by 3.17.0 and by 4.0.0 alike (the README's main job)."""
    s = Scene("pedot-micro", orientation="up", payload="12.6mg@6.27mm")
    r = rollout(s, "square:1.5V@0.1Hz", 20.0, initial_curvature=-303)
    assert float(r.tip_curvature[-1]) == pytest.approx(-86.277583963328, rel=1e-12)


@on_4
def test_cable_on_mujoco_4_is_refused_naming_the_alternative():
    """The refusal names the rod, the cable's replacement (a 1D flexcomp rod, mjeap.rod)."""
    with pytest.raises(ParameterError, match=r"representation='cable'.*'hinge' or 'rod' on MuJoCo 4.*cable plugin.*"
                                             r"representation='rod'"):
        Scene("pedot-micro", representation="cable")


@pytest.mark.skipif(not cable_available(), reason="MuJoCo 4.x: the rod runs here")
def test_rod_on_mujoco_3_is_refused_naming_the_reason():
    with pytest.raises(ParameterError, match=r"representation='rod'.*'hinge' or 'cable' on MuJoCo 3.*CG solver"):
        Scene("pedot-micro", representation="rod")


@on_4
def test_dm_control_on_mujoco_4_is_refused_naming_the_versions():
    """dm_control's Physics cannot load there: backend='dm_control' is refused naming the
    versions; the default runs the same task on dm_env's interface."""
    from mjeap.envs.dm_tracking import TrackingEnvironment
    from mjeap.envs.environment import make_environment
    with pytest.raises(MjeapError, match=r"dm-control .*MuJoCo 4.*mujoco>=3.17,<4.*dm_env backend runs here"):
        make_environment(time_limit=0.05, backend="dm_control")
    assert isinstance(make_environment(time_limit=0.05), TrackingEnvironment)
    assert "flex_vertedge" in dm_control_problem()


@on_4
def test_contact_system_runs_on_mujoco_4():
    """MuJoCo 4.0.0's sparse Cholesky bug made the Newton solver diverge on a gripping
    system (fixed upstream in 4.0.1); mjeap builds systems with a dense Jacobian there."""
    from mjeap.simulation.system import System, attach
    from hosts import GRIP, host
    spec = host(GRIP)
    s = System(spec, [attach(spec, "pedot-micro", site=n, prefix=n) for n in ("left", "right")])
    r = s.rollout(["step:3V", "step:3V"], 0.2, sample_interval=0.01)
    assert r.meta["mujoco"] == MUJOCO_VERSION
