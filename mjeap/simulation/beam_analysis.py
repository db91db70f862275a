"""What a scene's timestep and damping are chosen from (:class:`BeamAnalysis`, shared by
scenes of one beam through a bounded cache, :data:`ANALYSES`) and how they were chosen
(:class:`TimestepChoice`, a scene's ``choice``)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..caching import BoundedCache
from ..model.catalog import Actuator

__all__ = ["TimestepChoice", "BeamAnalysis", "ANALYSES", "ANALYSIS_CACHE_SIZE", "ANALYSIS_CACHE_BYTES", "floor_sig"]


def floor_sig(x: float, digits: int) -> float:
    """``x`` rounded down to ``digits`` significant digits (a timestep a user reads)."""
    e = np.floor(np.log10(x)) - (digits - 1)
    return float(np.floor(x / 10**e * (1 + 1e-12)) * 10**e)


@dataclass(frozen=True)
class TimestepChoice:
    """How the timestep and damping were chosen (SI)."""

    timestep: float               # s
    stability_limit: float        # s (inf: none)
    accuracy_limit: float         # s, T_1 / STEPS_PER_PERIOD
    first_frequency: float        # Hz, scene's first bending mode (gravity included; past the
                                  # buckling load the straight column's growth rate / 2 pi)
    highest_frequency: float      # Hz, highest discrete mode (elastic)
    damping_ratio: float          # zeta_1
    rayleigh_beta: float          # s, the first mode's whole stiffness-proportional damping
    integrator_beta: float        # s, the part of it that 'discrete' adds itself (its timestep)
    integrator: str
    buckled: bool                 # reference configuration unstable under gravity
    reason: str

    def as_dict(self) -> dict:
        return dict(self.__dict__)


@dataclass(frozen=True)
class BeamAnalysis:
    """What a scene's timestep and damping are chosen from, the timestep aside (internal units)."""

    actuator: Actuator            # held: its id in the key stays its own while cached
    linearization: object         # mjeap.model.modes.Linearization of the spec as built
    w_el: float                   # first elastic mode (rad per time unit), gravity's load left out
    wmax: float                   # highest elastic mode
    w1: float                     # first mode's rate, gravity included (floored)
    buckled: bool
    pattern: np.ndarray           # Rayleigh damping per dof per unit beta
    beta: float                   # Rayleigh beta
    h_stab: float                 # stability limit under the integrator (inf: none)

    def nbytes(self) -> int:
        """Memory held by its matrices (bytes)."""
        return self.pattern.nbytes + sum(getattr(self.linearization, k).nbytes
                                         for k in ("M", "K_elastic", "K_gravity", "K_joint"))


#: the timestep-independent analysis of a scene (linearisation, modes, Rayleigh beta and
#: stability limit: two thirds of building one), keyed on everything that determines it,
#: ``Scene.build_key``: the actuator object (held, so its id is not reused while cached),
#: representation, segments, orientation, payload, units, gravity, damping ratio,
#: integrator and max_bend. An accuracy target's models of one beam at different steps, and
#: a sweep's points that differ only in their drive, share it. Oldest dropped past ANALYSIS_CACHE_SIZE
#: entries or ANALYSIS_CACHE_BYTES of matrices (a 1000-segment beam's take ~30 MB)
ANALYSIS_CACHE_SIZE = 256
ANALYSIS_CACHE_BYTES = 64 * 2**20
ANALYSES = BoundedCache("beam analyses", max_entries=ANALYSIS_CACHE_SIZE, max_bytes=ANALYSIS_CACHE_BYTES,
                         nbytes=BeamAnalysis.nbytes, locked=True)
