"""One run pipeline (issue 35): :func:`mjeap.rollout` and :meth:`mjeap.System.rollout` are
thin front ends of :mod:`mjeap.simulation.pipeline` (plan, run, finish), and every engine
steps a declared target type (:class:`mjeap.engines.SceneTarget`, :class:`mjeap.engines.SystemTarget`)
whose step counter is public."""
import ast
import inspect
import textwrap

import mujoco
import pytest

import mjeap
from mjeap.engines import SceneTarget, SystemTarget, Target
from mjeap.engines.frame import Decided
from mjeap.simulation import pipeline
from mjeap.simulation.rollout import rollout
from mjeap.simulation.system import System

#: a front end's body below its docstring, at most (issue 35)
FRONT_END_LINES = 60


def body_lines(function) -> int:
    """Source lines of ``function``'s body below its docstring (decorators and signature not
    counted; blank lines and comments counted)."""
    source = textwrap.dedent(inspect.getsource(inspect.unwrap(function)))
    fn = ast.parse(source).body[0]
    body = fn.body[1:] if ast.get_docstring(fn) is not None else fn.body
    return body[-1].end_lineno - body[0].lineno + 1


@pytest.mark.parametrize("front_end", [rollout, System.rollout], ids=["rollout", "System.rollout"])
def test_the_front_ends_are_thin(front_end):
    n = body_lines(front_end)
    assert n <= FRONT_END_LINES, f"{front_end.__qualname__}: {n} lines below its docstring"


def test_the_line_count_counts():
    """The measure can fail: a function of 3 statements below its docstring is 3 lines."""
    def f(x):
        """Doc."""
        y = x
        y += 1
        return y
    assert body_lines(f) == 3


def test_scenes_and_systems_are_the_targets_engines_declare():
    scene = mjeap.Scene("pvdf-60", segments=4)
    assert isinstance(scene, SceneTarget) and isinstance(scene, Target) and not isinstance(scene, SystemTarget)
    rollout(scene, "step:1V", 20 * scene.timestep, engine="loop")
    assert scene.step_count == 20                      # public, advanced by the engine
    spec = mujoco.MjSpec.from_string('<mujoco><option gravity="0 0 0"/><worldbody><site name="m"/></worldbody>'
                                     '</mujoco>')
    system = System(spec, [mjeap.attach(spec, "pedot-micro", prefix="a", site="m", segments=4, contact=False)])
    assert isinstance(system, SystemTarget) and not isinstance(system, SceneTarget)
    system.rollout(["step:1V"], 20 * system.timestep)
    assert system.step_count == 20


def test_a_decision_ends_the_run_as_a_result_and_an_error_is_recorded_then_raised():
    meta, built, written = {}, [], []

    def decided():
        stop = Decided("repeats", 1.0)
        stop.step = 7
        raise stop
    out = pipeline.execute(meta, decided, lambda error: built.append(error) or "result",
                           lambda result, error: written.append((result, error)))
    assert out == "result" and meta["stopped_early"] == "repeats" and meta["steps_run"] == 7
    assert built == [None] and written == [("result", None)] and meta["wall_time_s"] >= 0
    meta, written = {}, []
    with pytest.raises(ZeroDivisionError):
        pipeline.execute(meta, lambda: 1 / 0, lambda error: "partial", lambda r, e: written.append((r, type(e))))
    assert meta["error"].startswith("ZeroDivisionError") and written == [("partial", ZeroDivisionError)]


def test_builders_state_capabilities_and_each_engine_words_its_refusal():
    """The model layer says what a beam's model is (capabilities in model terms) and carries
    no 'why not' per engine or feature above it; each engine words its own refusal."""
    from mjeap.engines.native import why_not as native_why_not
    from mjeap.engines.threaded import why_not as threaded_why_not
    from mjeap.model.mjcf import BUILDERS, CAPABILITIES, FIXED_BENDING_FORCES, HINGE_TENDON, BeamBuilder
    per_feature = [n for n in vars(BeamBuilder) if n.endswith("_reason") and
                   n not in ("unavailable_reason", "layout_reason", "integrator_reason")]
    assert not per_feature
    for rep, builder in BUILDERS.items():
        for capability in CAPABILITIES:
            assert builder.has(capability) == (builder.lacks(capability) is None)
            if not builder.has(capability):
                assert builder.instead[capability], (rep, capability)         # said in model terms
    assert BUILDERS["hinge"].lacks("a kernel on the GPU")           # what a builder does not state it lacks

    class Tendonless(type(BUILDERS["hinge"])):
        capabilities = frozenset({FIXED_BENDING_FORCES})
        instead = {HINGE_TENDON: "its hinges are gears"}

    class Stand:
        builder = Tendonless()
        part = type("Part", (), {"has_tip_load": lambda self: False})()
    drive = type("Drive", (), {"name": "x", "native_reason": lambda self: None,
                               "closed_loop_reason": lambda self: None})()
    assert native_why_not(Stand(), drive).endswith("its hinges are gears")
    assert "fixed tendon" in native_why_not(Stand(), drive)                       # the engine's own words
    assert threaded_why_not(Stand(), drive) is None
