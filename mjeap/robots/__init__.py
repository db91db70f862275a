"""Robots built from mjeap's actuators, in the style of dm_control's suite: a registry of
named robots, each with its builder (returns a :class:`~mjeap.system.System`), its named
read-outs (SI) and its experiment's command line, tagged by what it shows.

    from mjeap import robots
    robots.names()                     # ['gripper', 'hamr-leg', 'hamr-walk', 'robobee-wing']
    system = robots.load("robobee-wing", bias=200.0)
    robots.get("robobee-wing").readouts["stroke_angle"](system)     # rad

``mjeap robot NAME [options]`` (or ``python scripts/NAME.py``) runs a robot's experiment.
A new robot is one module here that calls :func:`register`.
"""
from __future__ import annotations

import importlib
from dataclasses import dataclass, field
from typing import Callable, Dict, List, Mapping, Optional, Tuple

from ..errors import UnknownNameError

__all__ = ["Robot", "register", "names", "get", "load", "summary"]


@dataclass(frozen=True)
class Robot:
    """One robot: ``build(**options) -> System``; ``readouts``: name -> f(system), SI;
    ``main(argv) -> None``: its experiment's command line (prints JSON, writes a recording)."""

    name: str
    summary: str
    build: Callable
    main: Callable
    readouts: Mapping[str, Callable] = field(default_factory=dict)
    tags: Tuple[str, ...] = ()


_REGISTRY: Dict[str, Robot] = {}
#: the modules that register the robots, imported on first use (they import SciPy and MjSpec code)
_MODULES = ("gripper", "hamr_leg", "hamr_walk", "robobee_wing")


def summary(doc: str) -> str:
    """A module docstring's first paragraph on one line (a robot's summary, its CLI's description)."""
    return " ".join(doc.split("\n\n")[0].split())


def register(robot: Robot) -> Robot:
    """Add ``robot`` to the registry (a module calls this once, at import)."""
    _REGISTRY[robot.name] = robot
    return robot


def _loaded() -> Dict[str, Robot]:
    for m in _MODULES:
        importlib.import_module(f"{__name__}.{m}")
    return _REGISTRY


def names(tag: Optional[str] = None) -> List[str]:
    """The registered robots' names, sorted; with ``tag``: those carrying it."""
    return sorted(n for n, r in _loaded().items() if tag is None or tag in r.tags)


def get(name: str) -> Robot:
    """The registered robot ``name``."""
    reg = _loaded()
    if name not in reg:
        raise UnknownNameError("robot", name, sorted(reg))
    return reg[name]


def load(name: str, **options):
    """Build robot ``name``'s System with its builder's ``options``."""
    return get(name).build(**options)
