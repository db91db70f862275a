"""Robots built from mjeap's actuators, in the style of dm_control's suite: a registry of
named robots, each with its builder (returns a :class:`~mjeap.System`), its named
read-outs (SI) and its experiment's command line, tagged by what it shows.

    from mjeap import robots
    robots.names()                     # ['gripper', 'hamr-leg', 'hamr-walk', 'robobee-wing']
    system = robots.load("robobee-wing", bias=200.0)
    robots.get("robobee-wing").readouts["stroke_angle"](system)     # rad

``mjeap robot NAME [options]`` (or ``python scripts/NAME.py``) runs a robot's experiment.
Each robot is a package here: its model (``model.py``: the builder and the read-outs, the
size of a dm_control suite domain), its experiments (``experiments.py``: the studies and the
command line) and its ``__init__.py``, which registers it (:func:`register`,
:mod:`mjeap.robots.registry`) and holds the public names of both. A new robot is one more
such package, named in ``_MODULES``; the list of robots is the registry's
(:func:`names`), wherever it is shown.
"""
from __future__ import annotations

import importlib
from typing import Dict, List, Optional

from ..errors import ParameterError, UnknownNameError
from .registry import REGISTRY, Robot, register, summary

#: the packages that register the robots, imported on first use (they import SciPy and MjSpec code)
_MODULES = ("gripper", "hamr_leg", "hamr_walk", "robobee_wing")

__all__ = ["Robot", "register", "names", "get", "load", "summary"]


def _loaded() -> Dict[str, Robot]:
    for m in _MODULES:
        importlib.import_module(f"{__name__}.{m}")
    return REGISTRY


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
    """Build robot ``name``'s System with its builder's ``options`` (a builder that returns
    anything else is refused, naming the robot)."""
    from ..simulation.system import System
    system = get(name).build(**options)
    if not isinstance(system, System):
        raise ParameterError("robot", name, "a robot whose build returns a mjeap.System",
                             f"its build returned {type(system).__name__}")
    return system
