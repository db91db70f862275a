"""A drive's small-signal model: its linear response to a small voltage about an operating
point, what the frequency response (:mod:`mjeap.analysis.frf`) couples to the beam's
linearised mechanics.

About the operating input V0 a drive is, per volt of its input v = V - V0 (SI throughout)::

    x'  = A x + B v + F theta              internal states (charge, relaxation, force)
    M_j = b_j v + (G x)_j                  bending moment at hinge j (N m)
    I   = g v + C dv/dt + sum_j c_j theta_j' + h . x     current drawn (A)

theta the hinge angles (rad) about the operating shape. ``b`` is the moment per volt
(N m/V per hinge), ``g`` the conductance (S) and ``C`` the dielectric (blocked) capacitance
(F) of the current with the beam held, ``c`` the motional coupling per hinge (A s/rad,
numerically N m/V: by reciprocity a lossless transducer's c_j equals its b_j), and (A, B, F,
G, h) the drive's own dynamics as a small LTI system (no states: an empty one). A drive
whose model draws no current has ``current = False`` and says why in ``no_current``.

A drive states its model with :meth:`mjeap.drives.Drive.small_signal`; a new drive plugs
into ``mjeap frf`` by implementing it.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Optional

import numpy as np

from ..errors import ParameterError

__all__ = ["SmallSignal"]


@dataclass(frozen=True)
class SmallSignal:
    """The small-signal model of a drive about ``operating_voltage`` (module text); arrays
    per hinge of the scene's beam (``segments`` long)."""

    operating_voltage: float              # V0, V
    input_name: str                       # the input the volts are of, e.g. 'V_sig'
    moment_per_volt: np.ndarray           # b, N m/V per hinge
    conductance: float = 0.0              # g, S
    capacitance: float = 0.0              # C, F (dielectric, beam held)
    coupling: Optional[np.ndarray] = None  # c, A s/rad per hinge (None: zeros)
    current: bool = True                  # whether the drive's model draws a current at all
    no_current: str = ""                  # why not (current False)
    state_matrix: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))      # A, 1/s
    state_input: np.ndarray = field(default_factory=lambda: np.zeros(0))            # B, state/(s V)
    state_from_angles: Optional[np.ndarray] = None   # F, (states, hinges), state/(s rad)
    moment_from_state: Optional[np.ndarray] = None   # G, (hinges, states), N m per state
    current_from_state: Optional[np.ndarray] = None  # h, A per state
    notes: str = ""

    def __post_init__(self):
        b = np.atleast_1d(np.asarray(self.moment_per_volt, dtype=float))
        n, k = b.size, np.asarray(self.state_matrix).shape[0]
        fill = {"coupling": np.zeros(n), "state_from_angles": np.zeros((k, n)),
                "moment_from_state": np.zeros((n, k)), "current_from_state": np.zeros(k)}
        object.__setattr__(self, "moment_per_volt", b)
        for name, zero in fill.items():
            v = getattr(self, name)
            object.__setattr__(self, name, zero if v is None else np.asarray(v, dtype=float).reshape(zero.shape))
        object.__setattr__(self, "state_matrix", np.asarray(self.state_matrix, dtype=float).reshape(k, k))
        object.__setattr__(self, "state_input", np.asarray(self.state_input, dtype=float).reshape(k))
        arrays = (b, self.coupling, self.state_matrix, self.state_input, self.state_from_angles,
                  self.moment_from_state, self.current_from_state)
        if not all(np.all(np.isfinite(a)) for a in arrays) or not np.isfinite([self.conductance, self.capacitance]).all():
            raise ParameterError("small-signal model", "non-finite coefficients", "finite numbers (a drive's bug)")

    @property
    def states(self) -> int:
        return self.state_matrix.shape[0]

    def drive_response(self, s: complex) -> np.ndarray:
        """The moment per volt at every hinge (N m/V) at complex frequency ``s`` (1/s), the
        hinges held: b + G (sI - A)^-1 B."""
        if not self.states:
            return self.moment_per_volt.astype(complex)
        x = np.linalg.solve(s * np.eye(self.states) - self.state_matrix, self.state_input)
        return self.moment_per_volt + self.moment_from_state @ x

    def blocked_admittance(self, s: complex) -> complex:
        """The current per volt (S) at ``s`` with the hinges held: g + s C + h (sI - A)^-1 B."""
        y = self.conductance + s * self.capacitance
        if self.states:
            y = y + self.current_from_state @ np.linalg.solve(s * np.eye(self.states) - self.state_matrix,
                                                              self.state_input)
        return complex(y)
