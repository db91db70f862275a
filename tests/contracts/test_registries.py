"""Plug-ins and registries cannot fail silently: every registry (engines, drives, beam
builders, robots, sweep metrics) checks what is registered, refuses a taken name unless
``replace=True`` (a module re-imported or reloaded registers again), and what a plug-in
returns is checked at the run, with a ParameterError naming the plug-in."""
import dataclasses
import importlib

import mujoco
import numpy as np
import pytest

import mjeap.engines as engines
import mjeap.model.mjcf as mjcf
from mjeap import DRIVES, Drive, Scene, register_drive, robots, rollout, rollout_batch
from mjeap.engines import Engine, engine_names, get_engine, register_engine
from mjeap.engines.loop import LoopEngine
from mjeap.errors import ParameterError
from mjeap.model.mjcf import BUILDERS, HingeChainBuilder
from mjeap.robots import Robot
from mjeap.robots.registry import REGISTRY as ROBOTS
from mjeap.simulation.system import System, attach
from mjeap.studies.sweep import METRICS, evaluate, register_metric


@pytest.fixture(autouse=True)
def registries(monkeypatch):
    """Every registry as it was before the test (contents in place: modules hold them by name)."""
    robots.names()                      # the robots' modules imported, once, before the snapshot
    saved = [(d, dict(d)) for d in (engines._REGISTRY, DRIVES, BUILDERS, ROBOTS, METRICS)]
    monkeypatch.setattr(engines, "ENGINES", engines.ENGINES)
    monkeypatch.setattr(mjcf, "REPRESENTATIONS", mjcf.REPRESENTATIONS)
    yield
    for d, old in saved:
        d.clear()
        d.update(old)


def loop_then(change):
    """An engine class that runs the loop engine, then ``change(samples)``: a plug-in's fault."""
    class Faulty(LoopEngine):
        name = "test-faulty"

        def run(self, scene, drives, v_steps, initial_curvatures, sample_steps, samples, **kw):
            super().run(scene, drives, v_steps, initial_curvatures, sample_steps, samples, **kw)
            change(samples[0])
    return Faulty


# ---------------------------------------------------------------- engines
class Idle(Engine):
    """Runs nothing: takes no sample."""
    name, batched = "test-idle", True

    def run(self, *args, **kw):
        pass


def _named(name):
    """An engine called ``name`` (any value)."""
    return type("Named", (Idle,), {"name": name})()


def test_engine_that_fills_no_samples_is_refused_naming_it():
    register_engine(Idle())
    with pytest.raises(ParameterError, match=r"engine='test-idle'.*it took 0 of the 11 planned samples"):
        rollout(Scene("pedot-micro"), "step:1V", 0.01, engine="test-idle", sample_interval=1e-3)
    with pytest.raises(ParameterError, match=r"engine='test-idle'.*run 1 of 2: it took 0 of"):
        rollout_batch(Scene("pedot-micro"), ["step:1V", "step:2V"], 0.01, engine="test-idle")


@pytest.mark.parametrize("fault,change", [
    ("took 10 of the 11 planned samples", lambda smp: setattr(smp, "n", smp.n - 1)),
    ("non-finite times", lambda smp: smp.t.__setitem__(3, np.nan)),
    (r"voltages of shape \(10,\), not \(11,\)", lambda smp: setattr(smp, "v", smp.v[:-1])),
], ids=["too-few", "non-finite", "wrong-shape"])
def test_engine_that_leaves_too_few_non_finite_or_misshapen_samples_is_refused(fault, change):
    register_engine(loop_then(change)())
    with pytest.raises(ParameterError, match=rf"engine='test-faulty'.*{fault}"):
        rollout(Scene("pedot-micro"), "step:1V", 0.01, engine="test-faulty", sample_interval=1e-3)


def test_system_engine_that_skips_samples_is_refused_naming_it():
    class IdleSystem(Engine):
        name = "test-idle-system"

        def why_not(self, scene, drive, controller=None):
            return "it runs systems only"

        def system_reason(self, system, controller=None, on_sample=None):
            return None

        def run_system(self, system, n_steps, sample_steps, before, sample, check):
            sample(0, 0)                # the first sample, then nothing

    register_engine(IdleSystem())
    spec = mujoco.MjSpec.from_string('<mujoco><option gravity="0 0 -0.00980665"/><worldbody><site name="m"/>'
                                     '</worldbody></mujoco>')
    system = System(spec, [attach(spec, "pedot-micro", site="m", prefix="a", contact=False)])
    with pytest.raises(ParameterError, match=r"engine='test-idle-system'.*it took 1 of the 11 planned samples"):
        system.rollout(["step:1V"], 0.01, sample_interval=1e-3, engine="test-idle-system")


def test_engine_named_like_a_built_in_is_refused_unless_replace():
    importlib.reload(importlib.import_module("mjeap.engines.loop"))     # the same definition registers again
    register_engine(importlib.import_module("mjeap.engines.loop").LoopEngine())
    loop, order = get_engine("loop"), engine_names()
    with pytest.raises(ParameterError, match=r"engine name='loop'.*register_engine\(\.\.\., replace=True\)"):
        register_engine(_named("loop"))
    assert get_engine("loop") is loop
    mine = register_engine(_named("loop"), replace=True)
    assert get_engine("loop") is mine and engine_names() == order


@pytest.mark.parametrize("name", ["auto", "", "two words", 3])
def test_engine_names_auto_and_empty_are_refused(name):
    with pytest.raises(ParameterError, match=r"engine name=.*not 'auto'"):
        register_engine(_named(name))
    assert "auto" not in engine_names() and "" not in engine_names()


def test_engine_without_a_name_or_a_run_is_refused():
    class NoName:
        def run(self, *args, **kw):
            pass
    with pytest.raises(ParameterError, match=r"engine='.*NoName instance'.*not an instance of an Engine subclass"):
        register_engine(NoName())
    with pytest.raises(ParameterError, match="implements none of run, run_system and advance"):
        register_engine(type("RunsNothing", (Engine,), {"name": "test-nothing"})())
    with pytest.raises(ParameterError, match=r"a class, not an instance"):
        register_engine(Idle)


# ---------------------------------------------------------------- drives
def test_drive_registry_refuses_what_is_no_drive_and_a_taken_name():
    class NotADrive:
        name = "test-not-a-drive"

        def step(self, voltage, dt):
            pass

    class NoStep(Drive):
        name = "test-no-step"

    class Moment(Drive):
        name = "rc-relaxation"

        def step(self, voltage, dt):
            self.part.set_internal_moments(1e-7 * voltage)

    own = DRIVES["rc-relaxation"]
    for cls, why in [(NotADrive, "not a Drive"), (NoStep, "Drive.step's, which applies no moment"),
                     (object.__new__(Moment), "an instance, not the class")]:
        with pytest.raises(ParameterError, match=rf"drive=.*{why}"):
            register_drive(cls)
    with pytest.raises(ParameterError, match=r"drive name='rc-relaxation'.*replace=True"):
        register_drive(Moment)
    assert DRIVES["rc-relaxation"] is own
    with pytest.raises(ParameterError, match=r"drive name='two words'"):
        register_drive(type("Spaced", (Moment,), {"name": "two words"}))
    assert register_drive(replace=True)(Moment) is Moment and DRIVES["rc-relaxation"] is Moment
    importlib.reload(importlib.import_module("mjeap.drives.passive"))  # 'none' again, the same definition


# ---------------------------------------------------------------- beam builders
def test_beam_builder_registry_refuses_what_builds_nothing_and_a_taken_name():
    class Empty(mjcf.BeamBuilder):
        representation = "test-empty"

    class Hinge(HingeChainBuilder):
        representation = "hinge"

    for builder, why in [(object(), "not a BeamBuilder"), (Empty(), "build and view are BeamBuilder's"),
                         (HingeChainBuilder, "a class, not an instance")]:
        with pytest.raises(ParameterError, match=rf"beam builder=.*{why}"):
            mjcf.register(builder)
    with pytest.raises(ParameterError, match=r"beam builder name=''"):
        mjcf.register(type("Unnamed", (HingeChainBuilder,), {"representation": ""})())
    own = BUILDERS["hinge"]
    with pytest.raises(ParameterError, match=r"beam builder name='hinge'.*replace=True"):
        mjcf.register(Hinge())
    assert BUILDERS["hinge"] is own
    mine = mjcf.register(Hinge(), replace=True)
    assert BUILDERS["hinge"] is mine and mjcf.REPRESENTATIONS[0] == "hinge"
    importlib.reload(importlib.import_module("mjeap.model.rod"))       # 'rod' again, the same definition


def test_beam_builder_whose_build_returns_wrong_handles_is_refused_naming_it():
    class Short(HingeChainBuilder):
        representation = "test-short"

        def build(self, spec, layout, units):
            handles = super().build(spec, layout, units)
            return dataclasses.replace(handles, link_bodies=handles.link_bodies[:-1])

    mjcf.register(Short())
    with pytest.raises(ParameterError, match=r"representation='test-short'.*link bodies"):
        Scene("pedot-micro", representation="test-short", segments=4)


# ---------------------------------------------------------------- robots
def test_robot_registry_refuses_what_is_no_robot_and_a_taken_name():
    def build(**options):
        return None

    with pytest.raises(ParameterError, match=r"robot=.*not a Robot"):
        robots.register(object())
    with pytest.raises(ParameterError, match=r"robot=.*its build is not callable"):
        robots.register(Robot("test-robot", "", None, print))
    with pytest.raises(ParameterError, match=r"robot name=''"):
        robots.register(Robot("", "", build, print))
    importlib.reload(importlib.import_module("mjeap.robots.gripper"))  # 'gripper' again, the same definition
    own = robots.get("gripper")
    with pytest.raises(ParameterError, match=r"robot name='gripper'.*replace=True"):
        robots.register(Robot("gripper", "", build, print))
    assert robots.get("gripper") is own
    robots.register(Robot("gripper", "", build, print), replace=True)
    assert robots.get("gripper").build is build


def test_robot_whose_build_returns_no_system_is_refused_naming_it():
    robots.register(Robot("test-no-system", "", lambda **options: None, print))
    with pytest.raises(ParameterError, match=r"robot='test-no-system'.*its build returned NoneType"):
        robots.load("test-no-system")


# ---------------------------------------------------------------- sweep metrics
def _metric():
    def test_metric(result, point, scene):
        return 1.0
    return test_metric


def test_metric_registry_refuses_a_taken_or_reserved_name_and_no_callable():
    builtin = METRICS["peak_to_peak"]
    with pytest.raises(ParameterError, match=r"metric name='peak_to_peak'.*replace=True"):
        register_metric("peak_to_peak", _metric())
    assert METRICS["peak_to_peak"] is builtin
    for name in ("", "duration", "error", "two words"):
        with pytest.raises(ParameterError, match=r"metric name="):
            register_metric(name, _metric())
    with pytest.raises(ParameterError, match=r"metric=.*not callable"):
        register_metric("test-metric", 3.0)
    register_metric("test-metric", _metric())
    register_metric("test-metric", _metric())      # the same definition again (its module reloaded)
    with pytest.raises(ParameterError, match=r"metric name='test-metric'"):
        register_metric("test-metric", lambda result, point, scene: 2.0)
    register_metric("peak_to_peak", _metric(), replace=True)


@pytest.mark.parametrize("value", [np.nan, None, np.array([1.0, 2.0])], ids=["nan", "none", "array"])
def test_metric_that_returns_no_finite_number_fails_the_point_naming_it(value):
    register_metric("test-bad", lambda result, point, scene: value)
    row = evaluate({"amplitude": 1.0}, metrics=("test-bad",), base={"frequency": 10.0, "duration": 0.05,
                                                                      "segments": 4})
    assert "metric='test-bad'" in row["error"] and row["test-bad"] == ""
