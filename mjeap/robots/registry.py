"""The robot registry's entries: a :class:`Robot` and :func:`register` (the modules of
:mod:`mjeap.robots` call it at import)."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable, Dict, Mapping, Tuple

__all__ = ["Robot", "register", "summary"]


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


def summary(doc: str) -> str:
    """A module docstring's first paragraph on one line (a robot's summary, its CLI's description)."""
    return " ".join(doc.split("\n\n")[0].split())


def register(robot: Robot) -> Robot:
    """Add ``robot`` to the registry (a module calls this once, at import)."""
    _REGISTRY[robot.name] = robot
    return robot
