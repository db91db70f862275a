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
  closed-loop controllers (:mod:`mjeap.engines.loop`).

``auto`` takes the first that applies in that order. A new engine (a batched GPU one, say)
is one module that calls :func:`register_engine`.
"""
from __future__ import annotations

from typing import Dict, List, Tuple

from ..errors import ParameterError
from .base import Engine

__all__ = ["Engine", "register_engine", "get_engine", "engine_names", "choose", "choose_system", "stepper",
           "ENGINES"]


_REGISTRY: Dict[str, Engine] = {}


def register_engine(engine: Engine) -> Engine:
    """Add ``engine`` under its name; :func:`choose`'s ``auto`` tries engines in the order
    they were registered."""
    _REGISTRY[engine.name] = engine
    return engine


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


from . import native as _native, threaded as _threaded, loop as _loop  # noqa: E402  registration order = auto's

register_engine(_native.NativeEngine())
register_engine(_threaded.ThreadedEngine())
register_engine(_loop.LoopEngine())
#: the engine names a run accepts
ENGINES = ("auto", *engine_names())
