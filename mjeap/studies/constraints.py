"""Constraints of an optimisation (``--subject-to``): ``metric >= bound`` or ``metric <= bound``,
SI or with the metric's unit, and how far a value lies on the feasible side."""
from __future__ import annotations

import dataclasses

import re
from typing import Union


from ..errors import ParameterError, UnknownNameError

__all__ = ["Constraint", "parse_constraint"]

_CONSTRAINT = re.compile(r"^\s*([A-Za-z0-9_-]+)\s*(>=|<=)\s*(.+?)\s*$")


@dataclasses.dataclass(frozen=True)
class Constraint:
    """``metric >= bound`` or ``metric <= bound`` (SI)."""

    metric: str
    sense: str
    bound: float

    @property
    def expression(self) -> str:
        return f"{self.metric}{self.sense}{self.bound:g}"

    def margin(self, value: float) -> float:
        """How far ``value`` lies on the feasible side, relative to the bound (>= 0: met)."""
        scale = abs(self.bound) if self.bound != 0 else 1.0
        return (value - self.bound) / scale if self.sense == ">=" else (self.bound - value) / scale


def parse_constraint(text: Union[str, Constraint, tuple]) -> Constraint:
    """``"NAME>=VALUE"`` or ``"NAME<=VALUE"`` (VALUE SI or with the metric's unit, e.g.
    ``first_frequency>=0.8kHz``), a (name, sense, value) tuple or a Constraint."""
    from ..model.quantity import to_si
    from .sweep import METRIC_UNITS, METRICS
    if isinstance(text, Constraint):
        c = text
    else:
        if isinstance(text, tuple) and len(text) == 3:
            name, sense, value = text
        else:
            m = _CONSTRAINT.match(str(text))
            if m is None:
                raise ParameterError("--subject-to", text, "NAME>=VALUE or NAME<=VALUE, e.g. first_frequency>=800")
            name, sense, value = m.groups()
        if name not in METRICS:
            raise UnknownNameError("metric (--subject-to)", str(name), METRICS)
        if sense not in (">=", "<="):
            raise ParameterError("--subject-to", text, "NAME>=VALUE or NAME<=VALUE")
        unit = METRIC_UNITS.get(name, "-")
        c = Constraint(str(name), sense, to_si(value if isinstance(value, str) else float(value), unit,
                                               f"--subject-to {name}"))
    return c
