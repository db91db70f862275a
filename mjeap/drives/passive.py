"""No drive: the beam moves under its own elasticity, damping, gravity and loads alone.

``rollout(scene, "step:0V", T, initial_curvature=k, drive="none")`` (or
:func:`mjeap.free_vibration`) releases a beam bent to a uniform arc of curvature k with
nothing holding it: a free vibration. The actuators' own drives would hold that shape (seed
000 starts its runs from a measured curvature the drive keeps).
"""
from __future__ import annotations

import numpy as np

from .base import Drive, OpenLoop, register_drive


@register_drive
class PassiveDrive(OpenLoop, Drive):
    name = "none"
    actuators = ()
    model_used = "no drive moment"

    def voltage_range(self):
        return (0.0, 0.0)

    def reset(self, initial_curvature: float = 0.0) -> None:
        self.part.set_internal_moments(0.0)

    def step(self, voltage: float, dt: float) -> None:
        """Nothing to apply: the internal moments stay zero."""

    def closed_loop_reason(self):
        return None

    def _moment_history(self, v):
        return np.zeros((len(v), self.scene.layout.segments))

    def small_signal(self, operating_voltage: float):
        """No input: a zero moment per volt and no current."""
        from .small_signal import SmallSignal
        n = self.scene.layout.segments
        return SmallSignal(float(operating_voltage), "V", np.zeros(n), current=False,
                           no_current="drive 'none' has no input and draws no current")

    def native_reason(self):
        return "no drive to compile: the threaded engine runs the free beam"
