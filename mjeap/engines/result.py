"""The results of runs, what every engine's samples become: one actuator's sampled SI arrays
(:class:`RolloutResult`, :meth:`mjeap.engines.frame.Samples.result`), a system's
(:class:`SystemResult`: one RolloutResult per actuator and every body's pose) and a run's
tip alone (:class:`TipPath`, what an accuracy target's companion runs give its metrics)."""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Dict, List, Optional, Union

import numpy as np

from ..errors import UnknownNameError
from ..io import csvio
from ..io.outputs import replacing

__all__ = ["RolloutResult", "SystemResult", "TipPath"]


@dataclass
class RolloutResult:
    """Sampled SI arrays of a rollout. Positions are in the clamp frame (x along the
    undeformed beam, y the deflection, z out of the bending plane). Sample i is the state
    after step k; its voltage is the one held over that step (zero-order hold), the same
    instant the drive signals describe."""

    time: np.ndarray                 # (n,) s
    voltage: np.ndarray              # (n,) V
    tip_position: np.ndarray         # (n, 3) m
    tip_angle: np.ndarray            # (n,) rad
    tip_curvature: np.ndarray        # (n,) 1/m, arc through clamp and tip (Dadras et al. 2021)
    centreline: np.ndarray           # (n, N + 2, 3) m
    payload_position: Optional[np.ndarray]
    signals: Dict[str, np.ndarray]   # drive quantities, 'name (unit)'
    reference_curvature: Optional[np.ndarray]
    meta: dict = field(default_factory=dict)

    def peak_to_peak(self, key: str = "tip_curvature", t_from: float = 0.0) -> float:
        y = getattr(self, key) if hasattr(self, key) else self.signals[key]
        sel = self.time >= t_from
        return float(np.max(y[sel]) - np.min(y[sel]))

    def to_csv(self, path: Union[str, Path]) -> None:
        """Time series (no centreline) as CSV with SI units in the header, written whole
        (:func:`mjeap.io.outputs.replacing`) and spreadsheet-safe (:class:`mjeap.io.csvio.writer`)."""
        cols = {"time (s)": self.time, "voltage (V)": self.voltage,
                "tip_x (m)": self.tip_position[:, 0], "tip_y (m)": self.tip_position[:, 1],
                "tip_z (m)": self.tip_position[:, 2], "tip_angle (rad)": self.tip_angle,
                "tip_curvature (1/m)": self.tip_curvature, **self.signals}
        if self.reference_curvature is not None:
            cols["reference_curvature (1/m)"] = self.reference_curvature
        with replacing(path, "csv_path") as tmp, open(tmp, "w", newline="") as fh:
            w = csvio.writer(fh)
            w.writerow(cols)
            w.writerows(np.column_stack([np.asarray(c, dtype=float) for c in cols.values()]))


@dataclass
class SystemResult:
    """A system rollout, SI: one :class:`RolloutResult` per actuator (by prefix, positions in
    its own clamp frame) and every body's world pose per sample."""

    time: np.ndarray                                  # (n,) s
    actuators: Dict[str, object]                      # prefix -> RolloutResult
    body_names: List[str]
    body_position: np.ndarray                         # (n, nbody, 3) m, world
    body_quat: np.ndarray                             # (n, nbody, 4) world (w x y z)
    contact_force: np.ndarray                         # (n, nbody, 3) N, net contact force on each body, world
    meta: dict = field(default_factory=dict)

    def body(self, name: str) -> int:
        try:
            return self.body_names.index(name)
        except ValueError:
            raise UnknownNameError("body", name, self.body_names) from None


class TipPath:
    """What a companion run gives the metrics: ``time`` (s), ``tip_position`` (n, 3; m,
    clamp frame) and ``tip_curvature`` (1/m), read as a RolloutResult reads them."""

    def __init__(self, time: np.ndarray, tip_position: np.ndarray, meta: Optional[dict] = None):
        from ..model.analytical import arc_curvature
        self.time, self.tip_position = time, tip_position
        self.tip_curvature = arc_curvature(tip_position[:, 0], tip_position[:, 1])
        self.meta = {} if meta is None else meta
