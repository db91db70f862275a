"""Validation records: a check (simulated value against a named reference), a curve (for the
report's figures and the recording) and an experiment (checks + curves + notes).

A check with a tolerance passes or fails; a check without one is a comparison that is
reported with its explanation (for example a published measurement the model is not expected
to reproduce). References are never computed from the simulator itself, and a toleranced
check names the kind of its reference (:data:`REFERENCE_KINDS`): a number printed in a
source, a formula transcribed from a source (with its equation), or a solution by a different
method. A reference that restates the code's own derivation is no check (issue 22): such a
row may be shown, as 'compare', never passed.
"""
from __future__ import annotations

from dataclasses import asdict, dataclass, field
from typing import Callable, Dict, List, Optional

import numpy as np


#: kinds of reference a toleranced check may have, as the report prints them
PUBLISHED_NUMBER = "published number"
PUBLISHED_FORMULA = "published formula"
INDEPENDENT_SOLUTION = "independent solution"
REFERENCE_KINDS = (PUBLISHED_NUMBER, PUBLISHED_FORMULA, INDEPENDENT_SOLUTION)


@dataclass
class Check:
    """One row of the validation table. ``error`` is relative ((sim - ref) / |ref|) unless
    ``error_kind`` is 'absolute' (then in ``unit``); ``tolerance`` is on |error|."""

    quantity: str
    unit: str
    simulated: float
    reference: float
    source: str                       # the reference, named (closed form, paper table, ...)
    tolerance: Optional[float] = None
    error_kind: str = "relative"
    note: str = ""
    experiment: str = ""
    kind: str = ""                    # one of REFERENCE_KINDS ('' for a compare row without one)

    @property
    def error(self) -> float:
        d = self.simulated - self.reference
        if self.error_kind == "absolute":
            return float(d)
        return float(d / abs(self.reference)) if self.reference != 0 else float("inf")

    @property
    def verdict(self) -> str:
        if self.tolerance is None:
            return "compare"
        ok = np.isfinite(self.error) and abs(self.error) <= self.tolerance
        return "pass" if ok else "FAIL"

    def as_dict(self) -> dict:
        d = asdict(self)
        d.update(error=self.error, verdict=self.verdict)
        return d


@dataclass
class Curve:
    """One curve of a figure panel; ``source`` names where it comes from (legend)."""

    panel: str
    source: str
    x: np.ndarray
    y: np.ndarray
    xlabel: str
    ylabel: str
    style: str = "-"                  # matplotlib format: '-' lines, 'o' markers

    def as_dict(self) -> dict:
        return {"panel": self.panel, "source": self.source, "xlabel": self.xlabel, "ylabel": self.ylabel,
                "x": np.asarray(self.x, float).tolist(), "y": np.asarray(self.y, float).tolist()}


@dataclass
class BeamShape:
    """A beam's centreline (m, clamp frame) at some times: what the recording draws of a run."""

    time: np.ndarray          # (n,) s
    centreline: np.ndarray    # (n, N + 2, 3) m


@dataclass
class Experiment:
    name: str                         # short id, e.g. 'dadras2021-payloads'
    title: str
    checks: List[Check] = field(default_factory=list)
    curves: List[Curve] = field(default_factory=list)
    notes: List[str] = field(default_factory=list)
    rollouts: list = field(default_factory=list)   # (label, RolloutResult, clamp rotation or None): beams in the .rrd
    seconds: float = 0.0

    def check(self, quantity, unit, simulated, reference, source, tolerance=None, **kw) -> Check:
        """Add a row; a row with a ``tolerance`` must say ``kind=`` (one of REFERENCE_KINDS)."""
        kind = kw.get("kind", "")
        if (tolerance is not None or kind) and kind not in REFERENCE_KINDS:
            raise ValueError(f"check {quantity!r} of {self.name}: kind={kind!r}; a toleranced check names its "
                             f"reference's kind, one of {', '.join(REFERENCE_KINDS)}")
        c = Check(quantity, unit, float(simulated), float(reference), source, tolerance,
                  experiment=self.name, **kw)
        self.checks.append(c)
        return c

    def beam(self, label: str, scene) -> None:
        """Keep the scene's present beam shape (a settled state) for the recording's 3D view."""
        self.rollouts.append((label, BeamShape(np.zeros(1), scene.centreline()[None]), scene.rotation))

    def curve(self, panel, source, x, y, xlabel, ylabel, style="-") -> None:
        self.curves.append(Curve(panel, source, np.asarray(x, float), np.asarray(y, float), xlabel, ylabel, style))

    @property
    def passed(self) -> bool:
        return all(c.verdict != "FAIL" for c in self.checks)


#: experiment name -> function(quick: bool) -> Experiment, in report order
REGISTRY: Dict[str, Callable[..., Experiment]] = {}


def experiment(name: str):
    def deco(fn):
        REGISTRY[name] = fn
        fn.experiment_name = name
        return fn
    return deco
