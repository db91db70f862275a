"""The robot registry's entries: a :class:`Robot` and :func:`register` (each robot package of
:mod:`mjeap.robots` calls it at import, in its ``__init__.py``)."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable, Dict, Mapping, Optional, Tuple

from ..errors import check_registration, plugin_origin

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


REGISTRY: Dict[str, Robot] = {}


def summary(doc: str) -> str:
    """A module docstring's first paragraph on one line (a robot's summary, its CLI's description)."""
    return " ".join(doc.split("\n\n")[0].split())


def _robot_lacks(robot) -> Optional[str]:
    """Why ``robot`` cannot be registered (None: it can)."""
    if not isinstance(robot, Robot):
        return "not a Robot"
    bad = [k for k in ("build", "main") if not callable(getattr(robot, k))]
    if bad:
        return f"its {' and '.join(bad)} {'are' if len(bad) > 1 else 'is'} not callable"
    if not isinstance(robot.summary, str):
        return "its summary is not a str"
    if not isinstance(robot.readouts, Mapping) or not all(isinstance(k, str) and callable(f)
                                                          for k, f in robot.readouts.items()):
        return "its readouts is not a mapping of names to callables f(system)"
    if not isinstance(robot.tags, tuple) or not all(isinstance(t, str) for t in robot.tags):
        return f"its tags {robot.tags!r} is not a tuple of str"
    return None


def register(robot: Robot, *, replace: bool = False) -> Robot:
    """Add ``robot`` to the registry (a module calls this once, at import; the same module
    registering again, re-imported or reloaded, replaces its entry). Its name: letters,
    digits, '-' and '_'; a name taken is refused unless ``replace``."""
    check_registration("robot", REGISTRY, getattr(robot, "name", None), robot, lacks=_robot_lacks(robot),
                       expected="a mjeap.robots.Robot with a name, a build and a main", replace=replace,
                       how="mjeap.robots.register", origin=lambda r: plugin_origin(r.build))
    REGISTRY[robot.name] = robot
    return robot
