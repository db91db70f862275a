"""The interface every engine implements (:mod:`mjeap.engines`)."""
from __future__ import annotations

from typing import Optional, Sequence

__all__ = ["Engine"]


class Engine:
    """One way of stepping a run of a scene (internal units, the scene's timestep)."""

    #: registry name
    name: str = ""
    #: runs several rollouts in one call (``rollout_batch``)
    batched: bool = False

    def why_not(self, scene, drive, controller=None) -> Optional[str]:
        """None where this engine applies to a run of ``scene`` with ``drive`` (and
        ``controller``); else the reason, in words."""
        return None

    def part(self, scene, drive):
        """The actuator part (:class:`mjeap.component.ActuatorPart`) whose state the samples
        read: the scene's own unless the engine steps another model."""
        return scene.part

    def run(self, scene, drives: Sequence, v_steps: Sequence, initial_curvatures: Sequence[float], sample_steps,
            samples: Sequence, *, nthread: int = 0, progress: Optional[bool] = None, check_every: int = 100,
            controller=None, meta: Optional[dict] = None) -> None:
        """Roll out one run per drive (its voltage per step, initial curvature 1/m and sample
        store), filling the stores; raises DivergenceError at the first diverged state and
        leaves the scene in the final state of the last run."""
        raise NotImplementedError
