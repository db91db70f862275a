"""Engines: the ways a run is stepped, behind one small interface and one registry.

An :class:`Engine` says whether it applies to a run (:meth:`Engine.why_not`: None, or the
reason in words), which actuator part its samples read (:meth:`Engine.part`) and runs it
(:meth:`Engine.run`) into sample stores of :mod:`mjeap.engines.frame`. :func:`choose` is
the one place a run picks its engine: :func:`mjeap.rollout` and :func:`mjeap.rollout_batch`
go through it, :meth:`mjeap.System.rollout` through :func:`choose_system` and the
environments through :func:`stepper`. Registered here:

* ``native``: the drive compiled into the model (:mod:`mjeap.drives.native`), stepped by
  ``mujoco.rollout`` in C, batches over threads;
* ``threaded``: an open-loop drive's moment history computed up front, applied by
  ``mujoco.rollout`` (:mod:`mjeap.engines.threaded`);
* ``loop``: the drive, then ``mj_step``, once per step from Python; serves every drive and
  closed-loop controllers (:mod:`mjeap.engines.loop`);
* ``warp``: the native engine's model on MuJoCo Warp, float32 batches (:mod:`mjeap.engines.warp`,
  the optional ``warp`` extra); ``auto`` never reaches it (native applies wherever it does).

``auto`` takes the first that applies in that order. A new engine (a batched GPU one, say)
is one module that calls :func:`register_engine`.
"""
from __future__ import annotations

from typing import Dict, List, Sequence, Tuple

import numpy as np

from ..errors import ParameterError, check_registration
from .base import Engine, SceneTarget, SystemTarget, Target
from .frame import Decided

__all__ = ["Engine", "Target", "SceneTarget", "SystemTarget", "register_engine", "get_engine", "engine_names", "choose",
           "choose_system", "stepper", "run_checked", "run_system_checked", "check_samples", "ENGINES"]


_REGISTRY: Dict[str, Engine] = {}


def _engine_lacks(engine):
    """Why ``engine`` cannot be registered (None: it can)."""
    if isinstance(engine, type):
        return ("a class, not an instance: register_engine(MyEngine())" if issubclass(engine, Engine)
                else "not an Engine")
    if not isinstance(engine, Engine):
        return "not an instance of an Engine subclass"
    own = [m for m in ("run", "run_system", "advance") if getattr(type(engine), m) is not getattr(Engine, m)]
    if not own:
        return "it implements none of run, run_system and advance: it runs nothing"
    if "run" not in own and type(engine).why_not is Engine.why_not:
        return "it has no run, yet its why_not (Engine's) says it applies to every run"
    if not isinstance(engine.batched, bool):
        return f"its batched is {engine.batched!r}, not a bool"
    return None


def register_engine(engine: Engine, *, replace: bool = False) -> Engine:
    """Add ``engine`` (an instance of an :class:`Engine` subclass that implements
    :meth:`Engine.run`, :meth:`Engine.run_system` or :meth:`Engine.advance`) under its name
    (letters, digits, '-', '_'; not ``auto``); :func:`choose`'s ``auto`` tries engines in
    the order they were registered. A name taken is refused unless ``replace`` (the
    replacement keeps its place in that order)."""
    global ENGINES
    check_registration("engine", _REGISTRY, getattr(engine, "name", None), engine, lacks=_engine_lacks(engine),
                       expected="an instance of an mjeap.engines.Engine subclass that implements run, run_system "
                       "or advance, with a name", reserved=("auto",), replace=replace, how="register_engine")
    _REGISTRY[engine.name] = engine
    ENGINES = ("auto", *_REGISTRY)
    return engine


def _refuse_run(engine: Engine, fault: str):
    """The ParameterError of an engine that broke its run's contract (``fault``, in words)."""
    return ParameterError("engine", engine.name, "an engine whose run takes every planned sample (fewer only where "
                          "a Decided stops it early), in order, of finite times, voltages and positions", fault)


def _samples_fault(smp, stopped_early: bool = False):
    """What is wrong with a sample store (:class:`mjeap.engines.frame.Samples`) after a run
    (None: nothing): too few samples, arrays of the wrong shape, non-finite values."""
    n, ns = smp.n, smp.ns
    if not isinstance(n, (int, np.integer)) or not (1 <= n <= ns if stopped_early else n == ns):
        return f"it took {n!r} of the {ns} planned samples" + (" before it stopped early" if stopped_early else "")
    arrays = smp.planned_arrays()
    wrong = [f"{k} of shape {np.shape(a)}, not {want}" for k, (a, want) in arrays.items() if np.shape(a) != want]
    wrong += [f"signal {k!r} of shape {np.shape(x)}, not ({n},) or longer"        # (n,): the native engine's
              for k, x in (smp.sig or {}).items() if np.ndim(x) != 1 or len(x) < n]
    if wrong:
        return "it left " + "; ".join(wrong)
    bad = [k for k, (a, _) in arrays.items() if not np.isfinite(a[:n]).all()]
    return f"it left non-finite {', '.join(bad)} in its {n} samples" if bad else None


def check_samples(engine: Engine, samples: Sequence, stopped_early: bool = False) -> None:
    """Refuse, naming ``engine``, sample stores its run left broken (:func:`_samples_fault`;
    ``stopped_early``: a :class:`Decided` ended the run, so fewer samples are fine). The
    stores of a refused run are emptied (``n = 0``): no result is built from them."""
    for b, smp in enumerate(samples):
        fault = _samples_fault(smp, stopped_early)
        if fault is not None:
            for emptied in samples:
                emptied.n = 0
            raise _refuse_run(engine, (f"run {b + 1} of {len(samples)}: " if len(samples) > 1 else "") + fault)


def run_checked(engine: Engine, scene: SceneTarget, drives: Sequence, v_steps: Sequence,
                initial_curvatures: Sequence[float], sample_steps, samples: Sequence, **kw) -> None:
    """``engine.run(...)`` (:meth:`Engine.run`) with its progress shown
    (:mod:`mjeap.engines.progress`: ``progress=`` in ``kw``), then its samples checked (:func:`check_samples`):
    a plug-in engine that fills too few samples or non-finite ones is refused naming it,
    not returned as an empty or NaN result. A :class:`Decided` goes on up."""
    from .progress import Progress
    progress = kw.pop("progress", None)
    total = len(v_steps[0]) * getattr(scene, "timestep", 0.0) if len(v_steps) else 0.0
    first = samples[0] if len(samples) else None
    what = getattr(getattr(scene, "actuator", None), "id", "run")
    with Progress(total, f"{what} ({engine.name})", progress) as shown:
        if first is not None and shown.mode is not False:
            def take(t, *a, **k):       # every engine takes its samples in time order
                first.__class__.take(first, t, *a, **k)
                shown.at(t)
            first.take = take
        try:
            engine.run(scene, drives, v_steps, initial_curvatures, sample_steps, samples, progress=False, **kw)
        except Decided:
            check_samples(engine, samples, stopped_early=True)
            raise
        finally:
            if first is not None:
                first.__dict__.pop("take", None)
        shown.at(total)
    check_samples(engine, samples)


def run_system_checked(engine: Engine, system: SystemTarget, n_steps: int, sample_steps, before, sample, check) -> None:
    """``engine.run_system(...)`` (:meth:`Engine.run_system`) with its sampling checked: a
    plug-in engine that skips, repeats or reorders a planned sample is refused naming it,
    and the state is checked (``check``) at every sample, so none is non-finite."""
    taken = 0

    def in_order(i, k):
        nonlocal taken
        due = (taken, int(sample_steps[taken])) if taken < len(sample_steps) else None
        if (i, k) != due:
            raise _refuse_run(engine, f"it took sample {i} after step {k}; due: " +
                              ("none" if due is None else f"sample {due[0]} after step {due[1]}"))
        check(k, k - 1)
        sample(i, k)
        taken += 1

    engine.run_system(system, n_steps, sample_steps, before, in_order, check)
    if taken != len(sample_steps):
        raise _refuse_run(engine, f"it took {taken} of the {len(sample_steps)} planned samples")


def engine_names() -> List[str]:
    """The registered engines, in ``auto``'s order of preference."""
    return list(_REGISTRY)


def get_engine(name: str) -> Engine:
    """The engine registered as ``name``."""
    if name not in _REGISTRY:
        raise ParameterError("engine", name, f"one of auto, {', '.join(_REGISTRY)}")
    return _REGISTRY[name]


def _pick(name: str, why_not, asked: str, none_applies: str, skip=lambda engine: False,
          hint: str = "") -> Tuple[Engine, str]:
    """The engine ``name``, refused with ``asked`` and its ``why_not(engine)`` where that is
    not None; or with ``auto`` the first registered one (not ``skip``-ped) that applies, the
    reasons of those before it said; refused with ``none_applies`` (and ``hint``) where none
    does."""
    if name != "auto":
        engine = get_engine(name)
        why = why_not(engine)
        if why is not None:
            raise ParameterError("engine", name, f"{asked}: {why}")
        return engine, "asked for"
    tried = []
    for engine in _REGISTRY.values():
        if skip(engine):
            continue
        why = why_not(engine)
        if why is None:
            return engine, "; ".join(["auto"] + tried)
        tried.append(f"not {engine.name}: {why}")
    raise ParameterError("engine", name, f"{none_applies}: " + "; ".join(tried), hint)


def choose(name: str, scene, drive, controller=None, batched: bool = False) -> Tuple[Engine, str]:
    """The engine for a run and why: ``name`` if it applies (refused with its reason if
    not), or with ``auto`` the first registered one that applies (``batched``: among those
    that run batches, refused naming each one's reason where none does)."""
    def why_not(engine):
        if batched and not engine.batched:
            return "it runs one rollout at a time (rollout_batch needs a batched engine)"
        return engine.why_not(scene, drive, controller)
    return _pick(name, why_not, "'auto' for this run" if batched else "'loop' or 'auto' for this run",
                 "an engine that runs this batch" if batched else "an engine that applies",
                 skip=lambda engine: batched and not engine.batched,
                 hint="rollout_batch needs the native or threaded engine; run the loop engine per rollout"
                 if batched else "")


def choose_system(name: str, system, controller=None, on_sample=None) -> Tuple[Engine, str]:
    """The engine for a run of a :class:`mjeap.System` and why (as :func:`choose`)."""
    return _pick(name, lambda engine: engine.system_reason(system, controller, on_sample),
                 "an engine that runs this system ('auto')", "an engine that runs this system")


def stepper(name: str = "loop") -> Engine:
    """The engine an environment steps with (:meth:`Engine.advance`): the loop engine, the
    one that steps a drive with its beam one step at a time."""
    return get_engine(name)


from . import native as _native, threaded as _threaded, loop as _loop, warp as _warp  # noqa: E402  auto's order

register_engine(_native.NativeEngine())
register_engine(_threaded.ThreadedEngine())
register_engine(_loop.LoopEngine())
register_engine(_warp.WarpEngine())
#: the engine names a run accepts
ENGINES = ("auto", *engine_names())
